/* Runtime track layout shared by src/curve.c and src/clip.c (never installed).
 * A clip embeds one ak_track per channel in its single allocation, so the struct is
 * defined here rather than in curve.c. */
#ifndef ANIMKIT_CURVE_TRACK_H
#define ANIMKIT_CURVE_TRACK_H

#include <animkit/curve.h>

/* How the runtime evaluates a segment (several ak_interp modes share one evaluator). */
typedef enum akp_eval {
    AKP_EVAL_STEP = 0,
    AKP_EVAL_LINEAR,   /* componentwise lerp */
    AKP_EVAL_SLERP,    /* rotations */
    AKP_EVAL_NLERP,    /* rotations */
    AKP_EVAL_HERMITE,  /* (in, value, out) per key; rotations renormalised */
    AKP_EVAL_SQUAD,    /* (inner-in, value, inner-out) per key, rotations */
    AKP_EVAL_LAGRANGE  /* Newton form through all keys */
} akp_eval;

struct ak_track {
    const float* times;    /* [key_count] strictly increasing */
    const float* values;   /* [key_count * stride] */
    const double* newton;  /* LAGRANGE: divided differences [key_count * component_count] */
    ak_allocator alloc;    /* standalone tracks: allocator to free with */
    uint32_t key_count;
    uint32_t component_count;
    uint32_t stride;       /* floats per key: component_count, or 3 * component_count */
    uint32_t value_offset; /* floats from a key's start to its value (0 or component_count) */
    ak_interp interp;      /* as given, DEFAULT resolved to LINEAR */
    akp_eval eval;
    float tension;         /* CARDINAL: resolved mu */
    bool is_rotation;
    bool standalone;       /* built by ak_track_build (owns its block) */
};

/* Checks everything that does not need sorted times; resolves component_count and interp
 * into *out_resolved. prefix names the channel in diag messages. */
ak_result akp_track_check(const ak_raw_track* raw, ak_raw_track* out_resolved, ak_diag* diag,
                          const char* prefix);
/* Bytes of track data (times, values, coefficients) for a resolved raw track, 16-aligned. */
size_t akp_track_data_size(const ak_raw_track* resolved);
/* Build into track using data (akp_track_data_size bytes, 16-aligned). Temporary memory for
 * sorting and solving comes from alloc and is freed before returning. Reports unsorted
 * duplicates, bad values and zero quaternions. */
ak_result akp_track_build_into(const ak_raw_track* resolved, ak_track* track, void* data,
                               const ak_allocator* alloc, ak_diag* diag, const char* prefix);

/* Segment for time: the largest k <= key_count - 2 with times[k] <= t, else 0. */
size_t akp_track_find(const ak_track* track, float t);
/* Same result as akp_track_find, starting from a previous segment (O(1) for small moves). */
size_t akp_track_find_from(const ak_track* track, float t, size_t hint);
/* sin(x) for x in [0, pi/2] (the slerp weights' range): the odd Taylor polynomial through
 * x^13 in Horner form. Truncation error <= (pi/2)^15 / 15! < 6.7e-10; with float rounding the
 * result is within a few float ulps of sin(x) (tests/test_clip.c checks 2e-7 against sin()). */
static inline float akp_sin_half_pi(float x) {
    float x2 = x * x;
    float p = 1.0f / 6227020800.0f;
    p = p * x2 - 1.0f / 39916800.0f;
    p = p * x2 + 1.0f / 362880.0f;
    p = p * x2 - 1.0f / 5040.0f;
    p = p * x2 + 1.0f / 120.0f;
    p = p * x2 - 1.0f / 6.0f;
    return x + x * (x2 * p);
}

/* Value at t on segment seg (from akp_track_find*): writes component_count floats. */
void akp_track_eval(const ak_track* track, size_t seg, float t, float* out);



/* d value / dt of a plain track on segment seg at t (component_count floats): the segment's
 * own derivative, so at a key the caller picks the side by its choice of segment. */
void akp_track_velocity(const ak_track* track, size_t seg, float t, float* out);

#endif

/* animkit curve: keyframe tracks, interpolation, time warping and arc length.
 *
 * What it does: turns editable keys (time, value) into immutable runtime tracks and samples
 * them. A track holds scalars, vectors of N components (vec3 for paths) or unit quaternions.
 * Interpolation modes (ak_interp): step, linear, Lagrange (one polynomial through all keys),
 * cubic Hermite with explicit in/out tangents, cardinal splines with tension on non-uniform
 * times, cubic Bezier segments, glTF CUBICSPLINE, and the natural C2 cubic spline. Rotations:
 * step, NLERP, SLERP, SQUAD (C1) and glTF CUBICSPLINE (renormalised). It also evaluates
 * first and second derivatives, wraps time (clamp, loop, ping-pong), eases time ("slow in,
 * slow out") and reparametrises a 3D path by arc length (constant speed along the path).
 *
 * What it does NOT do: bind tracks to joints (that is clip.h), blend poses, or fit curves to
 * data. Keys outside a track's range are never extrapolated: times before the first key give
 * the first key's value, times after the last key give the last key's value.
 *
 * Usage:
 *     float times[]  = {0.0f, 0.5f, 2.0f};
 *     float values[] = {0.0f, 1.0f, 0.0f};
 *     ak_raw_track raw = {.interp = AK_INTERP_CARDINAL, .key_count = 3,
 *                         .times = times, .values = values};     // scalar, Catmull-Rom
 *     ak_track* track = NULL;
 *     if (ak_track_build(&raw, NULL, &track, NULL) != AK_OK) return 1;
 *     float v, dv;
 *     ak_f32_span value = {&v, 1}, velocity = {&dv, 1};
 *     ak_track_sample(track, 1.25f, value);                      // value at t = 1.25 s
 *     ak_track_derivative(track, 1.25f, 1, velocity);            // d value / dt
 *     float u = ak_ease(AK_EASE_SINE_IN_OUT, 0.3f);              // slow in, slow out
 *     ak_track_destroy(track);
 *
 * Ownership and threading: ak_track_build / ak_arc_table_create allocate one block through
 * the given allocator (NULL -> malloc/free); the object is immutable afterwards and may be
 * sampled from any number of threads. Raw keys are copied: the caller may free them after
 * the build. Tracks owned by a clip (ak_clip_channel_track) must not be destroyed.
 *
 * Units: time in seconds; tangents (HERMITE, CUBICSPLINE) in value units per second.
 */
#ifndef ANIMKIT_CURVE_H
#define ANIMKIT_CURVE_H

#include "math.h"

#ifdef __cplusplus
extern "C" {
#endif

/* How values between keys are computed. In the cubic modes (CUBICSPLINE, HERMITE, CARDINAL,
 * BEZIER, NATURAL) the segment [t_k, t_k+1] of duration D = t_k+1 - t_k is the cubic Hermite
 * curve with u = (t - t_k) / D:
 *     p(u) = (2u^3-3u^2+1) p_k + (u^3-2u^2+u) D m_k + (-2u^3+3u^2) p_k+1 + (u^3-u^2) D m_k+1
 * where m_k is key k's out-tangent and m_k+1 key k+1's in-tangent (per second). The modes
 * differ in where the tangents come from. */
typedef enum ak_interp {
    AK_INTERP_DEFAULT = 0,  /* -> LINEAR (SLERP for rotations) */
    AK_INTERP_STEP,         /* hold the previous key's value */
    AK_INTERP_LINEAR,       /* lerp; for rotation tracks SLERP (glTF LINEAR) */
    AK_INTERP_CUBICSPLINE,  /* glTF CUBICSPLINE: (in-tangent, value, out-tangent) per key,
                               tangents per second, scaled by the key interval */
    AK_INTERP_HERMITE,      /* explicit in/out tangents per key (per second); same layout and
                               curve as CUBICSPLINE */
    AK_INTERP_CARDINAL,     /* cardinal spline, tension mu (1 -> Catmull-Rom), non-uniform
                               times: m_i = mu (p_i+1 - p_i-1) / (t_i+1 - t_i-1); end keys use
                               the one-sided m_0 = mu (p_1 - p_0) / (t_1 - t_0) (and likewise
                               at the last key) */
    AK_INTERP_BEZIER,       /* cubic Bezier: (value, out-control, in-control) per key: segment k
                               has control points p_k, out_k, in_k+1, p_k+1 at u = 0, 1/3, 2/3, 1
                               (the controls are values; time stays uniform in u) */
    AK_INTERP_NATURAL,      /* natural C2 cubic spline (global tridiagonal solve, second
                               derivative zero at both end keys) */
    AK_INTERP_LAGRANGE,     /* one polynomial through all keys (teaching; oscillates, Runge's
                               phenomenon; outputs are clamped to the float range) */
    AK_INTERP_NLERP,        /* rotations: normalised lerp, shortest path */
    AK_INTERP_SQUAD,        /* rotations: C1 spherical cubic (SQUAD, with inner quadrangle
                               points corrected for non-uniform key spacing) */
    AK_INTERP_COUNT
} ak_interp;

/* Name of an interpolation mode ("linear", "cubicspline", ...); never NULL. */
AK_API const char* ak_interp_name(ak_interp interp);

/* ---- tracks ------------------------------------------------------------------------- */

/* Editable track: keys in any order; ak_track_build sorts and checks them. */
typedef struct ak_raw_track {
    uint32_t component_count; /* values per key: 1 scalar, 3 vec3, 4 for rotations, up to 64;
                                 0 -> 4 when is_rotation, else 1 */
    bool is_rotation;         /* values are quaternions (x, y, z, w); false -> plain vectors */
    ak_interp interp;         /* 0 -> LINEAR (SLERP for rotations) */
    float tension;            /* CARDINAL only: mu, 0 -> 1 (Catmull-Rom) */
    size_t key_count;         /* required, >= 1 */
    const float* times;       /* [key_count] seconds, any order, finite, no duplicates */
    const float* values;      /* [key_count * component_count]; CUBICSPLINE and HERMITE:
                                 [key_count * 3 * component_count] as (in-tangent, value,
                                 out-tangent) per key, glTF order; BEZIER: [key_count * 3 *
                                 component_count] as (value, out-control, in-control) */
} ak_raw_track;

/* Immutable runtime track (sorted keys, precomputed tangents). */
typedef struct ak_track ak_track;

/* Largest component_count a track or clip channel may have. */
#define AK_TRACK_MAX_COMPONENTS 64

/* Check a raw track and build the runtime track (one allocation through alloc).
 * Rules, in order: raw/out_track NULL -> AK_ERR_NULL_ARG; key_count 0 -> AK_ERR_EMPTY; times
 * or values NULL -> AK_ERR_NULL_ARG; interp out of range, component_count above
 * AK_TRACK_MAX_COMPONENTS, a rotation track without 4 components, a rotation-only mode
 * (NLERP, SQUAD) on plain values, or a negative / non-finite tension -> AK_ERR_BAD_ARG;
 * CARDINAL, BEZIER, NATURAL or LAGRANGE on a rotation track -> AK_ERR_UNSUPPORTED; a NaN or
 * infinite time or value -> AK_ERR_BAD_DATA; two keys at the same time -> AK_ERR_DUPLICATE;
 * a zero rotation key, or a LAGRANGE polynomial whose coefficients overflow double (hundreds
 * of closely spaced keys) -> AK_ERR_BAD_DATA; allocation failure -> AK_ERR_NO_MEMORY.
 * diag (optional) receives which key is wrong. *out_track is NULL on failure.
 * Rotation keys of STEP/LINEAR/NLERP/SQUAD tracks are normalised at build time. */
AK_API ak_result ak_track_build(const ak_raw_track* raw, const ak_allocator* alloc,
                                ak_track** out_track, ak_diag* diag);

/* Free a track built by ak_track_build (with the same allocator); NULL is a no-op. */
AK_API void ak_track_destroy(ak_track* track);

/* Values per key (1, 3, 4, ...). NULL -> 0. */
AK_API uint32_t ak_track_component_count(const ak_track* track);
/* True for quaternion tracks. NULL -> false. */
AK_API bool ak_track_is_rotation(const ak_track* track);
/* The interpolation mode given at build time (DEFAULT resolved to LINEAR). NULL -> DEFAULT. */
AK_API ak_interp ak_track_interp(const ak_track* track);
/* Number of keys (>= 1). NULL -> 0. */
AK_API size_t ak_track_key_count(const ak_track* track);
/* Sorted key times, [key_count] seconds. NULL -> empty span. */
AK_API ak_f32_cspan ak_track_times(const ak_track* track);
/* Time of the first and of the last key (equal with one key). NULL -> 0. */
AK_API float ak_track_start_time(const ak_track* track);
AK_API float ak_track_end_time(const ak_track* track);

/* Key key_index's value and tangents (for curve-editor views).
 * out_value: count >= component_count, or empty to skip. out_in_tangent / out_out_tangent:
 * count >= component_count or empty to skip; they receive the per-second tangents the
 * curve uses (the given ones for HERMITE/CUBICSPLINE, the derived ones for CARDINAL,
 * NATURAL and BEZIER, the one-sided slopes of the neighbouring segments for LINEAR and
 * LAGRANGE (its derivative), zeros for STEP and rotation tracks other than CUBICSPLINE/HERMITE).
 * Returns AK_ERR_NULL_ARG (track NULL), AK_ERR_BAD_INDEX (key_index >= key_count),
 * AK_ERR_SPAN_SMALL (a non-empty span shorter than component_count). */
AK_API ak_result ak_track_key(const ak_track* track, size_t key_index, ak_f32_span out_value,
                              ak_f32_span out_in_tangent, ak_f32_span out_out_tangent);

/* Value at time (clamped to the key range). out_value.count >= component_count.
 * Rotations come out unit length. A NaN time gives the first key's value.
 * Returns AK_ERR_NULL_ARG or AK_ERR_SPAN_SMALL (nothing written). */
AK_API ak_result ak_track_sample(const ak_track* track, float time, ak_f32_span out_value);

/* Derivative of the given order (1: velocity, 2: acceleration) at time.
 * Plain tracks: out.count >= component_count, in value units per second (per second^2).
 * Rotation tracks: order 1 only, out.count >= 3: the angular velocity w (radians per
 * second, in the track's parent space: dq/dt = 0.5 w q). Exact for all modes except SQUAD
 * (central difference, about 1e-4 relative).
 * At a key the derivative of the segment that starts there is used; outside the key range
 * the track is constant, so the derivative is zero. STEP and the second derivative of LINEAR
 * are zero (their true derivatives are Dirac pulses at the keys).
 * Returns AK_ERR_NULL_ARG, AK_ERR_SPAN_SMALL, AK_ERR_BAD_ARG (order not 1 or 2),
 * AK_ERR_UNSUPPORTED (order 2 on a rotation track). */
AK_API ak_result ak_track_derivative(const ak_track* track, float time, int order,
                                     ak_f32_span out);

/* Sample the track at out_times.count uniformly spaced times from start_time to end_time
 * (both included; one sample -> start_time), for plotting. Writes the times to out_times and
 * the values to out_values ([out_times.count * component_count], key after key).
 * Returns AK_ERR_NULL_ARG, AK_ERR_EMPTY (out_times empty), AK_ERR_SPAN_SMALL,
 * AK_ERR_BAD_DATA (start or end not finite). */
AK_API ak_result ak_track_sample_uniform(const ak_track* track, float start_time,
                                         float end_time, ak_f32_span out_times,
                                         ak_f32_span out_values);

/* ---- time --------------------------------------------------------------------------- */

/* What happens to time outside [0, duration]. */
typedef enum ak_wrap_mode {
    AK_WRAP_DEFAULT = 0, /* -> CLAMP */
    AK_WRAP_CLAMP,       /* hold the ends */
    AK_WRAP_LOOP,        /* t mod duration, in [0, duration) */
    AK_WRAP_PING_PONG,   /* forward, then backward, period 2 * duration */
    AK_WRAP_COUNT
} ak_wrap_mode;

/* Time t mapped into [0, duration] by mode. duration <= 0 or not finite, or t NaN -> 0;
 * t = +-infinity -> the matching end for CLAMP, 0 otherwise. */
AK_API float ak_time_wrap(float t, float duration, ak_wrap_mode mode);

/* Standard easing curves e(u) on u in [0, 1] with e(0) = 0 and e(1) = 1. */
typedef enum ak_ease_kind {
    AK_EASE_LINEAR = 0,     /* u */
    AK_EASE_SMOOTHSTEP,     /* 3u^2 - 2u^3: slow in, slow out, C1 */
    AK_EASE_SMOOTHERSTEP,   /* 6u^5 - 15u^4 + 10u^3: C2 */
    AK_EASE_SINE_IN,        /* 1 - cos(u pi/2) */
    AK_EASE_SINE_OUT,       /* sin(u pi/2) */
    AK_EASE_SINE_IN_OUT,    /* (1 - cos(u pi)) / 2 */
    AK_EASE_QUAD_IN,        /* u^2 */
    AK_EASE_QUAD_OUT,       /* 1 - (1-u)^2 */
    AK_EASE_QUAD_IN_OUT,    /* 2u^2 below 1/2, mirrored above */
    AK_EASE_CUBIC_IN,       /* u^3 */
    AK_EASE_CUBIC_OUT,      /* 1 - (1-u)^3 */
    AK_EASE_CUBIC_IN_OUT,   /* 4u^3 below 1/2, mirrored above */
    AK_EASE_QUART_IN,       /* u^4 */
    AK_EASE_QUART_OUT,      /* 1 - (1-u)^4 */
    AK_EASE_QUART_IN_OUT,   /* 8u^4 below 1/2, mirrored above */
    AK_EASE_EXPO_IN,        /* (2^(10u) - 1) / 1023 (exactly 0 and 1 at the ends) */
    AK_EASE_EXPO_OUT,       /* 1 - EXPO_IN(1 - u) */
    AK_EASE_COUNT
} ak_ease_kind;

/* e(u) with u clamped to [0, 1] (NaN -> 0). An out-of-range kind behaves as LINEAR. */
AK_API float ak_ease(ak_ease_kind kind, float u);

/* d e / d u at u (clamped to [0, 1]); handy for velocities of eased motion. */
AK_API float ak_ease_derivative(ak_ease_kind kind, float u);

/* Eased time: duration * e(t / duration), so the motion starts and ends slowly but takes the
 * same total time. duration <= 0 or not finite -> t unchanged. */
AK_API float ak_ease_time(ak_ease_kind kind, float t, float duration);

/* User warp curve t' = w(t): the value of a scalar track at t (clamped to its keys).
 * A warp should be non-decreasing (a decreasing part plays the animation backwards); use
 * ak_track_is_monotonic to check. NULL or a non-scalar track -> t unchanged. */
AK_API float ak_time_warp(const ak_track* warp, float t);

/* True when a scalar track is non-decreasing over its key range, checked on the keys and
 * on 16 samples per segment (exact for STEP/LINEAR). NULL or non-scalar -> false. */
AK_API bool ak_track_is_monotonic(const ak_track* track);

/* ---- arc length --------------------------------------------------------------------- */

/* Cumulative arc-length table of a 3D path (a 3-component plain track) with its inverse, so
 * an object can move along the path at constant speed: position(s) = path(time_at(s)).
 * Each table cell is integrated with 5-point Gauss-Legendre quadrature, and the inverse
 * s -> t uses cubic Hermite interpolation with dt/ds = 1 / speed at the cell ends, so the
 * speed along the path stays within 0.5% of constant at the default size (tested). */
typedef struct ak_arc_table ak_arc_table;

typedef struct ak_arc_table_desc {
    const ak_track* path; /* required: 3 components, not a rotation; read at create only */
    size_t cell_count;    /* table cells over the whole path; 0 -> 256; at least one cell per
                             key segment is always used */
} ak_arc_table_desc;

/* The desc with its defaults filled in (cell_count 0 -> 256); desc NULL -> all defaults. */
AK_API ak_arc_table_desc ak_arc_table_desc_resolved(const ak_arc_table_desc* desc);

/* Build the table. Returns AK_ERR_NULL_ARG (desc, path or out NULL), AK_ERR_BAD_ARG (path not
 * a 3-component plain track, cell_count above 1 << 20), AK_ERR_NO_MEMORY. A path whose keys are
 * all equal, or a STEP path (it jumps, it does not travel), has length 0 (time_at then returns
 * the start time). */
AK_API ak_result ak_arc_table_create(const ak_arc_table_desc* desc, const ak_allocator* alloc,
                                     ak_arc_table** out_table);
/* Free; NULL is a no-op. */
AK_API void ak_arc_table_destroy(ak_arc_table* table);
/* Total path length (units of the path). NULL -> 0. */
AK_API float ak_arc_table_length(const ak_arc_table* table);
/* Path time at which the travelled distance is s (clamped to [0, length]). NULL -> 0. */
AK_API float ak_arc_table_time_at(const ak_arc_table* table, float distance);
/* Distance travelled from the path's start time to time (clamped to the path's key range). */
AK_API float ak_arc_table_distance_at(const ak_arc_table* table, float time);

#ifdef __cplusplus
}
#endif
#endif /* ANIMKIT_CURVE_H */

/* animkit noise: gradient noise, fractal sums and batch evaluation for procedural animation.
 *
 * What it does:
 *   - Perlin's improved gradient noise (Perlin 2002, "Improving Noise") in 1D to 4D with the
 *     quintic fade 6t^5 - 15t^4 + 10t^3, its analytic gradient, and a periodic (tileable)
 *     variant. With seed 0 the permutation is Perlin's published one and the 3D gradients are
 *     his 12 cube-edge directions picked by `hash & 15`, so ak_noise_perlin3 equals his
 *     reference ImprovedNoise.noise(x, y, z) (to float rounding). Other seeds shuffle the
 *     permutation with ak_rng (Fisher-Yates). 1D, 2D and 4D follow the same scheme with their
 *     own gradient sets (documented at each function);
 *   - fractal sums over any basis: fBm, turbulence, ridged multifractal, domain warping, each
 *     with octaves, lacunarity and gain and a documented output range;
 *   - a batch job over coordinate arrays and a grid job over a 2D lattice of points, on
 *     threads, 16 points at a time with AVX-512 or 8 with AVX2 where the CPU has it (chosen
 *     at run time, scalar reference always built; AK_NO_SIMD, skip_simd or simd_limit force
 *     it) for Perlin, simplex, value and Worley noise in 2D and 3D and every fractal type;
 *     1D, 4D and domain warping run the scalar reference. The SIMD paths give the same bits
 *     as the scalar one (no implicit FMA contraction on either side).
 *
 * What it does NOT do: sparse convolution or wavelet noise, anti-aliasing of the sum (octaves
 * above the sampling rate are the caller's business), textures or images (see terrain.h).
 *
 * Usage:
 *     ak_noise n = ak_noise_make(0);                       // Perlin's own permutation
 *     float g[3];
 *     float v = ak_noise_perlin3(&n, 3.14f, 42.0f, 7.0f, g); // 0.13692005 (Perlin: 0.136919959)
 *     ak_fractal_desc fd = { .type = AK_FRACTAL_FBM, .octaves = 8 };  // lacunarity 2, gain 0.5
 *     float p[2] = { 0.3f, 1.7f };
 *     float h = ak_fractal_eval(&n, &fd, 2, p, NULL);
 *     float xs[1024], ys[1024], out[1024];                 // ... filled by the caller
 *     ak_noise_job job = { .noise = &n, .fractal = fd, .dimensions = 2,
 *                          .x = { xs, 1024 }, .y = { ys, 1024 }, .out_values = { out, 1024 },
 *                          .thread_count = 2 };
 *     ak_result r = ak_noise_job_run(&job);
 *
 * Ranges: every basis function returns values in a documented interval ("range" at each
 * function) and the fractal range is ak_fractal_range(). Coordinates are lattice units; noise
 * repeats every 256 units (the permutation size) along each axis. Inputs are expected finite
 * with |coordinate| < 2^24; at or beyond that (where floats have no fractional part) and for
 * non-finite inputs every basis gives 0 and a zero gradient, never NaN.
 *
 * Ownership and threading: ak_noise is a plain value (520 bytes), read-only after
 * ak_noise_make and safe to share between threads. Nothing here allocates; jobs with
 * thread_count > 1 start pthreads and join them before returning.
 */
#ifndef ANIMKIT_NOISE_H
#define ANIMKIT_NOISE_H

#include "math.h"

#ifdef __cplusplus
extern "C" {
#endif

/* ---- the noise state ------------------------------------------------------------------ */

/* A permutation of 0..255 stored twice (so hashes need no wrap) and the seed it came from. */
typedef struct ak_noise {
    uint8_t perm[512];
    uint64_t seed;
} ak_noise;

/* Seed 0: Perlin's published permutation. Other seeds: 0..255 shuffled with
 * ak_rng_make(seed) (Fisher-Yates, i from 255 down to 1, j = ak_rng_u32 % (i + 1)). */
AK_API ak_noise ak_noise_make(uint64_t seed);

/* ---- Perlin's improved gradient noise --------------------------------------------------
 * Each function returns the noise at the point and, when out_gradient is not NULL, writes
 * its analytic gradient (d/dx, d/dy, ...) there (1, 2, 3 or 4 floats). The value is 0 at every
 * integer lattice point, C2 across cell borders (quintic fade). noise == NULL gives 0. */

/* 1D: gradients g = +-(1 + (h & 7)) / 4 from hash h (sign: h & 8). Range [-1, 1]. */
AK_API float ak_noise_perlin1(const ak_noise* noise, float x, float* out_gradient);
/* 2D: 8 gradients (+-1, +-1), (+-1, 0), (0, +-1) from h & 7. Range [-1, 1]. */
AK_API float ak_noise_perlin2(const ak_noise* noise, float x, float y, float* out_gradient);
/* 3D: Perlin's reference (12 edge gradients via h & 15). Range [-1.04, 1.04] (a local
 * maximisation finds values near 1.02; 10^7 random points stay within +-1.0). */
AK_API float ak_noise_perlin3(const ak_noise* noise, float x, float y, float z, float* out_gradient);
/* 4D: 32 gradients with one zero and three +-1 components (zero slot h >> 3 & 3, signs from
 * bits 0..2). Range [-1.5, 1.5] (a local maximisation finds values near 1.26). */
AK_API float ak_noise_perlin4(const ak_noise* noise, float x, float y, float z, float w, float* out_gradient);

/* Periodic Perlin noise in `dimensions` (1..4) dimensions: the lattice wraps every
 * period[i] cells along axis i (1..256), so noise(p + period[i] * e_i) == noise(p) exactly
 * (the same lattice corners and the same fractional offsets when p and the shifted point have
 * the same fraction in float). Same gradients and ranges as the plain functions; with every
 * period 256 it equals them. Out-of-range arguments (dimensions, a period outside 1..256, NULL
 * point or period) give 0. */
AK_API float ak_noise_perlin_periodic(const ak_noise* noise, uint32_t dimensions, const float* point,
                                      const int* period, float* out_gradient);

/* ---- bases and fractal sums ----------------------------------------------------------- */

/* ---- other bases -------------------------------------------------------------------- */

/* Simplex noise (Perlin 2001, in Gustavson's 2005 formulation): the skewed simplex grid,
 * radial kernels (0.5 - r^2)^4, scaled by 70 (2D) and 76 (3D). (Gustavson's 3D kernel
 * 0.6 - r^2 reaches past the simplex and makes the noise jump across simplex faces.) 2D
 * gradients: the 8 of ak_noise_perlin2 (hash perm[perm[i] + j] & 7); 3D: Perlin's 12 edge
 * gradients (hash & 15). C2 everywhere; analytic gradient as for Perlin. Ranges [-1.05, 1.05]
 * (2D) and [-1.1, 1.1] (3D); a local maximisation finds suprema near 0.998 and 0.99. */
AK_API float ak_noise_simplex2(const ak_noise* noise, float x, float y, float* out_gradient);
AK_API float ak_noise_simplex3(const ak_noise* noise, float x, float y, float z, float* out_gradient);

/* Value noise in 1..4 dimensions: a hashed value v = perm-hash / 127.5 - 1 in [-1, 1] at each
 * lattice point, blended with the quintic fade (C2). Range [-1, 1] (the value is clamped there
 * against float rounding; the gradient is not affected). Gradient as above;
 * bad arguments give 0. */
AK_API float ak_noise_value(const ak_noise* noise, uint32_t dimensions, const float* point, float* out_gradient);

/* Worley (cellular) noise in 1..3 dimensions: one feature point per unit cell, placed by a hash
 * of the cell and the seed; returns F1, the distance to the nearest feature point, and writes
 * F2, the distance to the second nearest, to out_f2 when not NULL. Exact: cells are searched
 * ring by ring until no closer point can exist. out_gradient: the gradient of F1, the unit
 * vector from the nearest point (0 on it). F1 lies in [0, sqrt(dimensions)]. Bad arguments
 * give 0. */
AK_API float ak_noise_worley(const ak_noise* noise, uint32_t dimensions, const float* point, float* out_f2,
                             float* out_gradient);

/* ---- bases and fractal sums ----------------------------------------------------------- */

typedef enum ak_noise_basis {
    AK_NOISE_BASIS_DEFAULT = 0, /* -> PERLIN */
    AK_NOISE_BASIS_PERLIN,      /* 1..4 dimensions */
    AK_NOISE_BASIS_SIMPLEX,     /* 2..3 dimensions (1D: the 2D noise at y = 0) */
    AK_NOISE_BASIS_VALUE,       /* 1..4 dimensions */
    AK_NOISE_BASIS_WORLEY,      /* F1, 1..3 dimensions */
    AK_NOISE_BASIS_COUNT
} ak_noise_basis;

/* True when the basis is defined in this many dimensions (table above). */
AK_API bool ak_noise_basis_supports(ak_noise_basis basis, uint32_t dimensions);

/* One basis function at `point` (dimensions floats); gradient as above. Bad arguments, or a
 * dimension the basis does not support, give 0. */
AK_API float ak_noise_eval(const ak_noise* noise, ak_noise_basis basis, uint32_t dimensions, const float* point,
                           float* out_gradient);
/* The documented range [*out_lo, *out_hi] of a basis in a dimension. */
AK_API void ak_noise_range(ak_noise_basis basis, uint32_t dimensions, float* out_lo, float* out_hi);

typedef enum ak_fractal_type {
    AK_FRACTAL_DEFAULT = 0, /* -> FBM */
    AK_FRACTAL_FBM,         /* sum_i a_i n(f_i p)                                   */
    AK_FRACTAL_TURBULENCE,  /* sum_i a_i |n(f_i p)|  (Perlin 1985)                    */
    AK_FRACTAL_RIDGED,      /* sum_i a_i w_i s_i, s_i = (1 - min(|n(f_i p)|, 1))^2,
                               w_0 = 1, w_{i+1} = clamp(2 s_i, 0, 1): Musgrave's ridged
                               multifractal (Texturing & Modeling ch. 16) with offset 1 and
                               weight gain 2                                               */
    AK_FRACTAL_TYPE_COUNT
} ak_fractal_type;

/* A fractal sum: octave i samples the basis at frequency * lacunarity^i with amplitude
 * gain^i (a_i), unnormalised. Domain warping (Quilez) first moves the point by
 * warp * (F(p + o_1), ..., F(p + o_d)) where F is the same sum and o_k fixed offsets
 * (5.2 k, 1.3 k, 7.1 k, 2.9 k), then evaluates the sum there. */
typedef struct ak_fractal_desc {
    ak_fractal_type type; /* DEFAULT -> FBM */
    ak_noise_basis basis; /* DEFAULT -> PERLIN */
    uint32_t octaves;     /* 1..16; 0 -> 6 */
    float lacunarity;     /* frequency ratio between octaves, (0, 16]; 0 -> 2 */
    float gain;           /* amplitude ratio between octaves, (0, 2]; 0 -> 0.5 */
    float frequency;      /* first octave's frequency, lattice cells per unit; 0 -> 1 */
    float warp;           /* domain-warp strength in units of p; 0 -> no warping */
} ak_fractal_desc;

/* The desc with zero fields replaced by their defaults (NULL -> all defaults). */
AK_API ak_fractal_desc ak_fractal_desc_resolved(const ak_fractal_desc* desc);
/* AK_OK or AK_ERR_BAD_ARG when a field is outside its documented range (after resolving). */
AK_API ak_result ak_fractal_desc_validate(const ak_fractal_desc* desc);

/* Evaluate the fractal at `point` (dimensions floats, 1..4), gradient by the chain rule when
 * out_gradient is not NULL. A desc that fails validation, or bad arguments, give 0. */
AK_API float ak_fractal_eval(const ak_noise* noise, const ak_fractal_desc* desc, uint32_t dimensions,
                             const float* point, float* out_gradient);

/* The documented output range of the fractal: with S = sum_{i<octaves} gain^i and [lo, hi]
 * the basis range, FBM and warped FBM give [lo S, hi S]; TURBULENCE gives [0, max(|lo|, hi) S];
 * RIDGED gives [0, S]. */
AK_API void ak_fractal_range(const ak_fractal_desc* desc, uint32_t dimensions, float* out_lo, float* out_hi);

/* ---- batch evaluation ---------------------------------------------------------------- */

/* Upper limit on the SIMD kernel the batch and grid jobs may pick (the widest this CPU has up
 * to the limit is used; tests and benchmarks run every path side by side with it). The SIMD
 * kernels cover Perlin, simplex, value and Worley (F1) noise in 2D and 3D without warping
 * (every fractal type, with or without gradient); 1D, 4D and domain warping run the scalar
 * reference. Every kernel gives the scalar reference's bits. A one-octave fBm job at frequency
 * 1 gives the per-point functions' bits too, except one case: the octave sum starts at +0.0, so
 * where a per-point call returns -0.0 the job returns +0.0 (equal as numbers; test_noise
 * per_point_matches_job_signed_zero). */
typedef enum ak_noise_simd {
    AK_NOISE_SIMD_DEFAULT = 0, /* -> the widest kernel this CPU has (AK_NOISE_SIMD_AVX512) */
    AK_NOISE_SIMD_SCALAR,      /* scalar code (as skip_simd) */
    AK_NOISE_SIMD_AVX2,        /* 8 points per block, where the CPU has AVX2 and FMA */
    AK_NOISE_SIMD_AVX512,      /* 16 points per block, where the CPU has AVX-512 F and DQ, else AVX2 */
    AK_NOISE_SIMD_COUNT
} ak_noise_simd;

/* Evaluate a fractal at many points given as separate coordinate arrays. */
typedef struct ak_noise_job {
    const ak_noise* noise;     /* required */
    ak_fractal_desc fractal;   /* the function; {.octaves = 1} for the plain basis */
    uint32_t dimensions;       /* 1..4; 0 -> 3 */
    ak_f32_cspan x, y, z, w;   /* coordinates; the first `dimensions` are required, each
                                  count >= out_values.count */
    ak_f32_span out_values;    /* required; its count is the number of points */
    ak_f32_span out_gradient_x, out_gradient_y, out_gradient_z, out_gradient_w;
                               /* optional (empty -> not computed); when any is given, the
                                  first `dimensions` are required with count >= points */
    uint32_t thread_count;     /* 0 or 1 -> calling thread only; at most 64 */
    bool skip_simd;            /* false -> SIMD when the CPU has it (as simd_limit SCALAR) */
    ak_noise_simd simd_limit;  /* the widest kernel allowed; DEFAULT -> the widest this CPU has */
} ak_noise_job;

/* AK_OK, AK_ERR_NULL_ARG (noise, out_values or a needed coordinate/gradient span missing),
 * AK_ERR_BAD_ARG (dimensions, thread_count, simd_limit, or the fractal desc out of range),
 * AK_ERR_SPAN_SMALL (a coordinate or gradient span shorter than out_values). */
AK_API ak_result ak_noise_job_validate(const ak_noise_job* job);
/* Validate, then fill the outputs (nothing is written on error). Results are identical for any
 * thread_count and with or without SIMD. */
AK_API ak_result ak_noise_job_run(const ak_noise_job* job);
/* The kernel ak_noise_job_run runs for this job on this CPU: AK_NOISE_SIMD_AVX512, _AVX2 or
 * _SCALAR (never DEFAULT); SCALAR for a job that fails validation. */
AK_API ak_noise_simd ak_noise_job_kernel(const ak_noise_job* job);

/* Evaluate a fractal on a width x height grid of 2D points
 * p(i, j) = (origin_x + i * spacing_x, origin_y + j * spacing_y), row-major (j rows of i). */
typedef struct ak_noise_grid_job {
    const ak_noise* noise;   /* required */
    ak_fractal_desc fractal;
    uint32_t width, height;  /* samples per row and rows; both required (> 0) */
    float origin_x, origin_y;
    float spacing_x, spacing_y; /* 0 -> 1 */
    ak_f32_span out_values;  /* required; count >= width * height */
    ak_f32_span out_gradient_x, out_gradient_y; /* optional; both or neither, count >= width * height */
    uint32_t thread_count;   /* 0 or 1 -> calling thread only; at most 64 */
    bool skip_simd;          /* false -> SIMD when the CPU has it (as simd_limit SCALAR) */
    ak_noise_simd simd_limit; /* the widest kernel allowed; DEFAULT -> the widest this CPU has */
} ak_noise_grid_job;

/* AK_OK, AK_ERR_NULL_ARG, AK_ERR_BAD_ARG (zero size, width * height overflow, simd_limit, non-finite
 * origin or spacing, thread_count > 64, bad fractal), AK_ERR_SPAN_SMALL. */
AK_API ak_result ak_noise_grid_job_validate(const ak_noise_grid_job* job);
/* Validate, then fill the grid (nothing is written on error); same results for any thread
 * count, with or without SIMD. */
AK_API ak_result ak_noise_grid_job_run(const ak_noise_grid_job* job);

/* ---- curl noise and wind ------------------------------------------------------------- */

/* Curl noise (Bridson et al. 2007): the curl of a vector potential made of the fractal at
 * three offset points, psi(p) = (F(p), F(p + (31.4, 0, 0)), F(p + (0, 47.2, 0))); computed from
 * the analytic gradients, so it is divergence-free up to float rounding. NULL desc -> the
 * default fractal. Bad arguments give zero. */
AK_API ak_vec3 ak_noise_curl3(const ak_noise* noise, const ak_fractal_desc* desc, ak_vec3 p);
/* 2D: v = (dF/dy, -dF/dx), divergence-free in the plane. */
AK_API ak_vec2 ak_noise_curl2(const ak_noise* noise, const ak_fractal_desc* desc, ak_vec2 p);

/* Noise wind for cloth and particles: a mean wind whose strength gusts in time, plus a
 * divergence-free curl-noise swirl drifting with the wind. The swirl's potential is 2-octave
 * 4D Perlin fBm with time as the fourth coordinate (times evolution), so the pattern changes
 * shape as it drifts; only spatial derivatives enter the curl. */
typedef struct ak_noise_wind_desc {
    ak_vec3 direction;      /* world; need not be unit; zero -> +x */
    float speed;            /* mean speed, m/s; 0 -> calm (only the swirl) */
    float gust;             /* gust strength: speed * (1 + gust * n(t * gust_frequency)), n the
                               1D Perlin noise in [-1, 1]; 0 -> steady */
    float gust_frequency;   /* Hz; 0 -> 0.25 */
    float turbulence;       /* swirl amplitude, m/s per unit curl; 0 -> none */
    float turbulence_scale; /* metres per noise cell of the swirl; 0 -> 2 */
    float evolution;        /* how fast the swirl changes shape: noise cells per second along the
                               potential's time axis; 0 -> 0.3 */
} ak_noise_wind_desc;

/* Wind velocity (m/s, world) at world point p and time t (seconds); smooth in p and t. NULL
 * noise or desc, or non-finite input, gives zero. */
AK_API ak_vec3 ak_noise_wind(const ak_noise* noise, const ak_noise_wind_desc* desc, ak_vec3 p, float t);

/* ---- procedural motion ----------------------------------------------------------------- */

/* A noise layer added on top of a local pose (after sampling a clip): each joint turns by a
 * small rotation whose axis-angle vector is amplitude * (n_x, n_y, n_z), n_k 2D Perlin noise at
 * (time * frequency, a per-joint, per-axis offset), and optionally moves by
 * translation_amplitude * (n_x, n_y, n_z) (other offsets). The delta is applied in the joint's
 * local frame: rotation = pose.rotation * delta, translation = pose.translation + offset. Idle
 * breathing and sway: a spine at 0.02 rad / 0.3 Hz, a head at 0.04 rad / 0.5 Hz. */
typedef struct ak_noise_sway_job {
    const ak_noise* noise;             /* required */
    float time;                        /* seconds, finite */
    ak_transform_cspan pose;           /* required: local pose, count = joint count */
    ak_f32_cspan amplitudes;           /* radians per joint (0 -> that joint still); required,
                                          count >= pose.count */
    ak_f32_cspan frequencies;          /* Hz per joint, >= 0; empty -> 0.5 Hz for every joint */
    ak_f32_cspan translation_amplitudes; /* metres per joint; empty -> no translation */
    ak_transform_span out_pose;        /* count >= pose.count; may be the same array as pose */
} ak_noise_sway_job;

/* AK_OK, AK_ERR_NULL_ARG (noise, pose, amplitudes, out_pose), AK_ERR_SPAN_SMALL,
 * AK_ERR_BAD_DATA (a non-finite time, amplitude or frequency, or a negative frequency). */
AK_API ak_result ak_noise_sway_validate(const ak_noise_sway_job* job);
/* Validate, then write out_pose (nothing written on error). */
AK_API ak_result ak_noise_sway_run(const ak_noise_sway_job* job);

/* True when this build and CPU run a SIMD batch kernel (AVX2 or AVX-512). */
AK_API bool ak_noise_simd_available(void);
/* Name of the widest batch kernel this build and CPU run: "avx512", "avx2" or "scalar". */
AK_API const char* ak_noise_simd_name(void);

#ifdef __cplusplus
}
#endif
#endif /* ANIMKIT_NOISE_H */

/* Internals shared by the noise files (never installed). */
#ifndef ANIMKIT_NOISE_INTERNAL_H
#define ANIMKIT_NOISE_INTERNAL_H

#include <animkit/noise.h>

/* Coordinates at or beyond this magnitude (and NaN) give 0: their floor would not fit the
 * integer lattice arithmetic, and floats there have no fractional part anyway. */
#define AKP_NOISE_LIMIT 16777216.0f

/* Scalar reference of the batch kernels: one point of a resolved, valid fractal desc. */
float akp_fractal_point(const ak_noise* noise, const ak_fractal_desc* d, uint32_t dims, const float* p, float* grad);

/* True when the SIMD kernels handle this desc and dimension (Perlin, simplex, value and
 * Worley, 2D and 3D, without warp; the AVX2 and AVX-512 kernels handle the same set). */
bool akp_noise_simd_handles(const ak_fractal_desc* d, uint32_t dims);
/* CPU checks (false in builds without the kernels). */
bool akp_noise_have_avx2(void);
bool akp_noise_have_avx512(void);
/* count % 8 == 0 (AVX2) or % 16 == 0 (AVX-512). xs[d] (d < dims) coordinates; grad[d] may all
 * be NULL (no gradient). */
void akp_noise_fractal_avx2(const ak_noise* noise, const ak_fractal_desc* d, uint32_t dims, const float* const* xs,
                            size_t count, float* out, float* const* grad);
void akp_noise_fractal_avx512(const ak_noise* noise, const ak_fractal_desc* d, uint32_t dims, const float* const* xs,
                              size_t count, float* out, float* const* grad);

#endif

/* Internals shared by the noise files (never installed). */
#ifndef ANIMKIT_NOISE_INTERNAL_H
#define ANIMKIT_NOISE_INTERNAL_H

#include <animkit/noise.h>

/* Coordinates at or beyond this magnitude (and NaN) give 0: their floor would not fit the
 * integer lattice arithmetic, and floats there have no fractional part anyway. */
#define AKP_NOISE_LIMIT 16777216.0f

/* Scalar reference of the batch kernels: one point of a resolved, valid fractal desc. */
float akp_fractal_point(const ak_noise* noise, const ak_fractal_desc* d, uint32_t dims, const float* p, float* grad);

/* True when the AVX2 kernel handles this desc and dimension (Perlin 2D/3D without warp). */
bool akp_noise_avx2_handles(const ak_fractal_desc* d, uint32_t dims);
/* CPU check (false in builds without the kernel). */
bool akp_noise_have_avx2(void);
/* count % 8 == 0. xs[d] (d < dims) coordinates; grad[d] may all be NULL (no gradient). */
void akp_noise_fractal_avx2(const ak_noise* noise, const ak_fractal_desc* d, uint32_t dims, const float* const* xs,
                            size_t count, float* out, float* const* grad);

#endif

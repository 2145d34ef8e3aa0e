/* Basis dispatch and fractal sums (fBm, turbulence, ridged multifractal, domain warping).
 *
 * The octave loop here is the scalar reference of the SIMD kernels in simd_body.h: the same
 * float operations in the same order (frequency and amplitude by repeated multiplication,
 * sign-bit tests for |n|), so both give the same bits. */
#include <math.h>
#include <string.h>

#include "noise_internal.h"

/* Perlin noise with a run-time dims (1..4) and optional gradient, through the public
 * functions (one compiled body per dimension, shared by every caller). */
static inline float perlin_any(const ak_noise* noise, uint32_t dims, const float* p, float* grad) {
    switch (dims) {
    case 1: return ak_noise_perlin1(noise, p[0], grad);
    case 2: return ak_noise_perlin2(noise, p[0], p[1], grad);
    case 3: return ak_noise_perlin3(noise, p[0], p[1], p[2], grad);
    default: return ak_noise_perlin4(noise, p[0], p[1], p[2], p[3], grad);
    }
}

bool ak_noise_basis_supports(ak_noise_basis basis, uint32_t dimensions) {
    if (basis == AK_NOISE_BASIS_DEFAULT) basis = AK_NOISE_BASIS_PERLIN;
    switch (basis) {
    case AK_NOISE_BASIS_PERLIN:
    case AK_NOISE_BASIS_VALUE: return dimensions >= 1 && dimensions <= 4;
    case AK_NOISE_BASIS_SIMPLEX:
    case AK_NOISE_BASIS_WORLEY: return dimensions >= 1 && dimensions <= 3;
    default: return false;
    }
}

/* One basis function, arguments already checked (the octave loop's path). */
static inline float basis_eval(const ak_noise* noise, ak_noise_basis basis, uint32_t dims, const float* q, float* g) {
    switch (basis) {
    case AK_NOISE_BASIS_SIMPLEX:
        if (dims == 1) {
            float g2[2];
            const float v = ak_noise_simplex2(noise, q[0], 0.0f, g ? g2 : NULL);
            if (g) g[0] = g2[0];
            return v;
        }
        return dims == 2 ? ak_noise_simplex2(noise, q[0], q[1], g) : ak_noise_simplex3(noise, q[0], q[1], q[2], g);
    case AK_NOISE_BASIS_VALUE: return ak_noise_value(noise, dims, q, g);
    case AK_NOISE_BASIS_WORLEY: return ak_noise_worley(noise, dims, q, NULL, g);
    default: return perlin_any(noise, dims, q, g);
    }
}

float ak_noise_eval(const ak_noise* noise, ak_noise_basis basis, uint32_t dimensions, const float* point,
                    float* out_gradient) {
    if (out_gradient && dimensions <= 4)
        for (uint32_t k = 0; k < dimensions; ++k) out_gradient[k] = 0.0f;
    if (basis == AK_NOISE_BASIS_DEFAULT) basis = AK_NOISE_BASIS_PERLIN;
    if (!noise || !point || !ak_noise_basis_supports(basis, dimensions)) return 0.0f;
    return basis_eval(noise, basis, dimensions, point, out_gradient);
}

void ak_noise_range(ak_noise_basis basis, uint32_t dimensions, float* out_lo, float* out_hi) {
    float lo = -1.0f, hi = 1.0f;
    switch (basis) {
    case AK_NOISE_BASIS_SIMPLEX:
        lo = dimensions >= 3 ? -1.1f : -1.05f;
        hi = -lo;
        break;
    case AK_NOISE_BASIS_VALUE: break;
    case AK_NOISE_BASIS_WORLEY:
        lo = 0.0f;
        hi = sqrtf((float)(dimensions < 1 ? 1 : dimensions > 3 ? 3 : dimensions));
        break;
    default:
        if (dimensions == 3) lo = -1.04f, hi = 1.04f;
        if (dimensions >= 4) lo = -1.5f, hi = 1.5f;
        break;
    }
    if (out_lo) *out_lo = lo;
    if (out_hi) *out_hi = hi;
}

/* The desc with defaults filled in, and its checks (inlined into ak_fractal_eval, which is
 * called per point). */
static inline ak_fractal_desc resolve(const ak_fractal_desc* desc) {
    ak_fractal_desc d;
    if (desc) d = *desc;
    else memset(&d, 0, sizeof d);
    if (d.type == AK_FRACTAL_DEFAULT) d.type = AK_FRACTAL_FBM;
    if (d.basis == AK_NOISE_BASIS_DEFAULT) d.basis = AK_NOISE_BASIS_PERLIN;
    if (d.octaves == 0) d.octaves = 6;
    if (d.lacunarity == 0.0f) d.lacunarity = 2.0f;
    if (d.gain == 0.0f) d.gain = 0.5f;
    if (d.frequency == 0.0f) d.frequency = 1.0f;
    return d;
}

static inline ak_result validate_resolved(const ak_fractal_desc* d) {
    if ((unsigned)d->type >= AK_FRACTAL_TYPE_COUNT || (unsigned)d->basis >= AK_NOISE_BASIS_COUNT) return AK_ERR_BAD_ARG;
    if (d->octaves > 16) return AK_ERR_BAD_ARG;
    if (!(d->lacunarity > 0.0f && d->lacunarity <= 16.0f)) return AK_ERR_BAD_ARG;
    if (!(d->gain > 0.0f && d->gain <= 2.0f)) return AK_ERR_BAD_ARG;
    if (!(d->frequency > 0.0f && d->frequency <= 1e6f)) return AK_ERR_BAD_ARG;
    if (!(fabsf(d->warp) <= 1e6f)) return AK_ERR_BAD_ARG;
    return AK_OK;
}

ak_fractal_desc ak_fractal_desc_resolved(const ak_fractal_desc* desc) { return resolve(desc); }

ak_result ak_fractal_desc_validate(const ak_fractal_desc* desc) {
    const ak_fractal_desc d = resolve(desc);
    return validate_resolved(&d);
}

/* The octave sum at p (no warping). */
static float octaves(const ak_noise* noise, const ak_fractal_desc* d, uint32_t dims, const float* p, float* grad) {
    float freq = d->frequency, amp = 1.0f, sum = 0.0f, weight = 1.0f;
    float gs[4] = {0, 0, 0, 0}, gw[4] = {0, 0, 0, 0};
    for (uint32_t o = 0; o < d->octaves; ++o) {
        float q[4], g[4];
        for (uint32_t k = 0; k < dims; ++k) q[k] = p[k] * freq;
        const float n = basis_eval(noise, d->basis, dims, q, grad ? g : NULL);
        if (d->type == AK_FRACTAL_FBM) {
            sum = sum + amp * n;
            if (grad)
                for (uint32_t k = 0; k < dims; ++k) gs[k] = gs[k] + (amp * freq) * g[k];
        } else if (d->type == AK_FRACTAL_TURBULENCE) {
            const bool neg = signbit(n);
            sum = sum + amp * fabsf(n);
            if (grad)
                for (uint32_t k = 0; k < dims; ++k) gs[k] = gs[k] + (amp * freq) * (neg ? -g[k] : g[k]);
        } else {
            const bool neg = signbit(n), clipped = !(fabsf(n) < 1.0f);
            const float s = 1.0f - fminf(fabsf(n), 1.0f);
            const float s2 = s * s;
            sum = sum + amp * (weight * s2);
            float nw = 2.0f * s2;
            const bool open = nw > 0.0f && nw < 1.0f;
            nw = fminf(fmaxf(nw, 0.0f), 1.0f);
            if (grad) {
                for (uint32_t k = 0; k < dims; ++k) {
                    /* d(s^2) = -2 s sign(n) grad n * freq (0 where |n| is clipped) */
                    float ds2 = clipped ? 0.0f : (-2.0f * s) * (freq * (neg ? -g[k] : g[k]));
                    gs[k] = gs[k] + amp * (weight * ds2 + s2 * gw[k]);
                    gw[k] = open ? 2.0f * ds2 : 0.0f;
                }
            }
            weight = nw;
        }
        freq = freq * d->lacunarity;
        amp = amp * d->gain;
    }
    if (grad)
        for (uint32_t k = 0; k < dims; ++k) grad[k] = gs[k];
    return sum;
}

/* akp_fractal_point's every case (the function keeps the common one in front). */
static __attribute__((noinline)) float fractal_point_any(const ak_noise* noise, const ak_fractal_desc* d, uint32_t dims,
                                                         const float* p, float* grad) {
    if (d->warp == 0.0f) {
        /* fBm without gradient, the common case, in loops specialised per basis and dimension */
        if (!grad && d->type == AK_FRACTAL_FBM)
            return d->basis == AK_NOISE_BASIS_PERLIN ? akp_fbm_perlin(noise, d, dims, p)
                                                     : akp_fbm_other(noise, d, dims, p);
        if (d->type == AK_FRACTAL_FBM && d->basis == AK_NOISE_BASIS_PERLIN && (dims == 2 || dims == 3))
            return akp_fbm_perlin_grad(noise, d, dims, p, grad);
        return octaves(noise, d, dims, p, grad);
    }
    static const float offset[4] = {5.2f, 1.3f, 7.1f, 2.9f};
    float q[4] = {0, 0, 0, 0}, wg[4][4];
    for (uint32_t k = 0; k < dims; ++k) {
        float s[4];
        for (uint32_t m = 0; m < dims; ++m) s[m] = p[m] + offset[m] * (float)(k + 1);
        q[k] = p[k] + d->warp * octaves(noise, d, dims, s, grad ? wg[k] : NULL);
    }
    float gq[4];
    const float v = octaves(noise, d, dims, q, grad ? gq : NULL);
    if (grad) {
        /* q = p + warp F(p + o): dv/dp_j = gq_j + warp sum_k gq_k dF_k/dp_j */
        for (uint32_t j = 0; j < dims; ++j) {
            float acc = 0.0f;
            for (uint32_t k = 0; k < dims; ++k) acc += gq[k] * wg[k][j];
            grad[j] = gq[j] + d->warp * acc;
        }
    }
    return v;
}

float akp_fractal_point(const ak_noise* noise, const ak_fractal_desc* d, uint32_t dims, const float* p, float* grad) {
    /* fBm without gradient or warp, the common call, first: the function holding the warp
     * and the general octave loop inline pushed six registers and set up a frame per point */
    if (!grad && d->warp == 0.0f && d->type == AK_FRACTAL_FBM)
        return d->basis == AK_NOISE_BASIS_PERLIN ? akp_fbm_perlin(noise, d, dims, p) : akp_fbm_other(noise, d, dims, p);
    return fractal_point_any(noise, d, dims, p, grad);
}

/* ak_fractal_eval's every case. */
static __attribute__((noinline)) float fractal_eval_any(const ak_noise* noise, const ak_fractal_desc* desc,
                                                        uint32_t dimensions, const float* point, float* out_gradient) {
    if (out_gradient && dimensions <= 4)
        for (uint32_t k = 0; k < dimensions; ++k) out_gradient[k] = 0.0f;
    if (!noise || !point) return 0.0f;
    /* A desc with no field left to its default is its own resolved form: checked where it is.
     * The copy that resolve() builds field by field and its callee then read back as vectors
     * stalled store forwarding, about a tenth of a 5-octave Perlin fBm per point. */
    if (desc && desc->type != AK_FRACTAL_DEFAULT && desc->basis != AK_NOISE_BASIS_DEFAULT && desc->octaves != 0 &&
        desc->lacunarity != 0.0f && desc->gain != 0.0f && desc->frequency != 0.0f) {
        if (validate_resolved(desc) != AK_OK || !ak_noise_basis_supports(desc->basis, dimensions)) return 0.0f;
        return akp_fractal_point(noise, desc, dimensions, point, out_gradient);
    }
    const ak_fractal_desc d = resolve(desc);
    if (validate_resolved(&d) != AK_OK || !ak_noise_basis_supports(d.basis, dimensions)) return 0.0f;
    return akp_fractal_point(noise, &d, dimensions, point, out_gradient);
}

float ak_fractal_eval(const ak_noise* noise, const ak_fractal_desc* desc, uint32_t dimensions, const float* point,
                      float* out_gradient) {
    /* No gradient and no field left to its default, the common call, first (no frame). */
    if (!out_gradient && noise && point && desc && desc->type != AK_FRACTAL_DEFAULT &&
        desc->basis != AK_NOISE_BASIS_DEFAULT && desc->octaves != 0 && desc->lacunarity != 0.0f && desc->gain != 0.0f &&
        desc->frequency != 0.0f) {
        if (validate_resolved(desc) != AK_OK || !ak_noise_basis_supports(desc->basis, dimensions)) return 0.0f;
        return akp_fractal_point(noise, desc, dimensions, point, NULL);
    }
    return fractal_eval_any(noise, desc, dimensions, point, out_gradient);
}

void ak_fractal_range(const ak_fractal_desc* desc, uint32_t dimensions, float* out_lo, float* out_hi) {
    const ak_fractal_desc d = ak_fractal_desc_resolved(desc);
    float lo, hi, s = 0.0f, a = 1.0f;
    ak_noise_range(d.basis, dimensions, &lo, &hi);
    for (uint32_t o = 0; o < d.octaves && o < 16; ++o) {
        s += a;
        a *= d.gain;
    }
    float rlo = lo * s, rhi = hi * s;
    if (d.type == AK_FRACTAL_TURBULENCE) {
        rlo = 0.0f;
        rhi = fmaxf(-lo, hi) * s;
    } else if (d.type == AK_FRACTAL_RIDGED) {
        rlo = 0.0f;
        rhi = s;
    }
    if (out_lo) *out_lo = rlo;
    if (out_hi) *out_hi = rhi;
}

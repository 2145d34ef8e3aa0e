/* AVX2 fractal kernel: 2D and 3D Perlin noise (value and gradient) for 8 points at a time,
 * summed as fBm, turbulence or ridged multifractal.
 *
 * It repeats the scalar reference (perlin.c lattice + fractal.c octaves) operation for
 * operation: the same floor, hash chain, corner dots ((+-u) + (+-v) by sign-bit flips), the
 * same fade and lerp evaluation order, no FMA, min/max where the scalar code has fminf/fmaxf
 * (equal for non-NaN values, and NaN never reaches them: out-of-range points are masked to
 * 0 first). So its results equal the scalar ones bit for bit; test_noise checks it.
 *
 * Permutation lookups are 32-bit gathers from the byte table with scale 1; the low byte is
 * perm[i] and the next one perm[i + 1], the upper corner's hash. An index is at most
 * 255 + 255, so a gather reads at most perm[513]: inside ak_noise, whose 8-byte seed follows
 * perm[512].
 *
 * Compiled only for GCC/Clang on x86-64 without AK_NO_SIMD; selected at run time with
 * __builtin_cpu_supports. */
#include "noise_internal.h"

#if defined(__GNUC__) && defined(__x86_64__) && !defined(AK_NO_SIMD)
#define AKP_HAVE_NOISE_AVX2 1
#include <immintrin.h>
#define AKP_AVX2 __attribute__((target("avx2")))
#define AKP_AVX2_INLINE __attribute__((target("avx2"), always_inline))
#else
#define AKP_HAVE_NOISE_AVX2 0
#endif

bool akp_noise_avx2_handles(const ak_fractal_desc* d, uint32_t dims) {
    return AKP_HAVE_NOISE_AVX2 && (dims == 2 || dims == 3) && d->warp == 0.0f && d->basis == AK_NOISE_BASIS_PERLIN &&
           (d->type == AK_FRACTAL_FBM || d->type == AK_FRACTAL_TURBULENCE || d->type == AK_FRACTAL_RIDGED);
}

#if AKP_HAVE_NOISE_AVX2

bool akp_noise_have_avx2(void) { return __builtin_cpu_supports("avx2"); }

/* The 4 bytes perm[idx .. idx + 3] of each lane (little-endian: perm[idx] in the low byte). */
AKP_AVX2_INLINE static inline __m256i gather4(const uint8_t* perm, __m256i idx) {
    return _mm256_i32gather_epi32((const int*)(const void*)perm, idx, 1);
}

AKP_AVX2_INLINE static inline __m256 lerp8(__m256 t, __m256 a, __m256 b) {
    return _mm256_add_ps(a, _mm256_mul_ps(t, _mm256_sub_ps(b, a)));
}

AKP_AVX2_INLINE static inline __m256 fade8(__m256 t) {
    const __m256 t3 = _mm256_mul_ps(_mm256_mul_ps(t, t), t);
    const __m256 in = _mm256_add_ps(
        _mm256_mul_ps(t, _mm256_sub_ps(_mm256_mul_ps(t, _mm256_set1_ps(6.0f)), _mm256_set1_ps(15.0f))),
        _mm256_set1_ps(10.0f));
    return _mm256_mul_ps(t3, in);
}

AKP_AVX2_INLINE static inline __m256 dfade8(__m256 t) {
    const __m256 a = _mm256_mul_ps(_mm256_mul_ps(_mm256_set1_ps(30.0f), t), t);
    const __m256 b =
        _mm256_add_ps(_mm256_mul_ps(t, _mm256_sub_ps(t, _mm256_set1_ps(2.0f))), _mm256_set1_ps(1.0f));
    return _mm256_mul_ps(a, b);
}

AKP_AVX2_INLINE static inline __m256 as_mask(__m256i m) { return _mm256_castsi256_ps(m); }
AKP_AVX2_INLINE static inline __m256i eq(__m256i a, int v) { return _mm256_cmpeq_epi32(a, _mm256_set1_epi32(v)); }
AKP_AVX2_INLINE static inline __m256i lt(__m256i a, int v) { return _mm256_cmpgt_epi32(_mm256_set1_epi32(v), a); }

/* Corner value (and gradient vector) for hash h and offsets d (dims 2 or 3). */
AKP_AVX2_INLINE static inline __m256 corner8(int dims, __m256i h, const __m256* d, __m256* g, bool want_grad) {
    const __m256 one = _mm256_set1_ps(1.0f);
    const __m256i su_bits = _mm256_slli_epi32(_mm256_and_si256(h, _mm256_set1_epi32(1)), 31);
    const __m256i sv_bits = _mm256_slli_epi32(_mm256_and_si256(h, _mm256_set1_epi32(2)), 30);
    const __m256 su = _mm256_castsi256_ps(su_bits), sv = _mm256_castsi256_ps(sv_bits);
    if (dims == 2) {
        h = _mm256_and_si256(h, _mm256_set1_epi32(7));
        const __m256i low = lt(h, 4);
        const __m256i bit2 = _mm256_cmpeq_epi32(_mm256_and_si256(h, _mm256_set1_epi32(2)), _mm256_set1_epi32(2));
        const __m256i u_is_y = _mm256_andnot_si256(low, bit2);
        const __m256 u = _mm256_blendv_ps(d[0], d[1], as_mask(u_is_y));
        const __m256 v = _mm256_and_ps(d[1], as_mask(low));
        if (want_grad) {
            const __m256 pu = _mm256_xor_ps(one, su), pv = _mm256_xor_ps(one, sv);
            g[0] = _mm256_andnot_ps(as_mask(u_is_y), pu);
            g[1] = _mm256_blendv_ps(_mm256_and_ps(pu, as_mask(u_is_y)), pv, as_mask(low));
        }
        return _mm256_add_ps(_mm256_xor_ps(u, su), _mm256_xor_ps(v, sv));
    }
    h = _mm256_and_si256(h, _mm256_set1_epi32(15));
    const __m256i u_is_x = lt(h, 8), v_is_y = lt(h, 4);
    const __m256i v_is_x = _mm256_andnot_si256(v_is_y, _mm256_or_si256(eq(h, 12), eq(h, 14)));
    const __m256 u = _mm256_blendv_ps(d[1], d[0], as_mask(u_is_x));
    const __m256 v = _mm256_blendv_ps(_mm256_blendv_ps(d[2], d[0], as_mask(v_is_x)), d[1], as_mask(v_is_y));
    if (want_grad) {
        const __m256 pu = _mm256_xor_ps(one, su), pv = _mm256_xor_ps(one, sv);
        const __m256i v_is_z = _mm256_andnot_si256(_mm256_or_si256(v_is_y, v_is_x), _mm256_set1_epi32(-1));
        g[0] = _mm256_add_ps(_mm256_and_ps(pu, as_mask(u_is_x)), _mm256_and_ps(pv, as_mask(v_is_x)));
        g[1] = _mm256_add_ps(_mm256_andnot_ps(as_mask(u_is_x), pu), _mm256_and_ps(pv, as_mask(v_is_y)));
        g[2] = _mm256_and_ps(pv, as_mask(v_is_z));
    }
    return _mm256_add_ps(_mm256_xor_ps(u, su), _mm256_xor_ps(v, sv));
}

/* Perlin noise at 8 points p[0..dims-1]; value returned, gradient into grad when want_grad. */
AKP_AVX2_INLINE static inline __m256 perlin8(const uint8_t* perm, int dims, const __m256* p, __m256* grad,
                                             bool want_grad) {
    const __m256 limit = _mm256_set1_ps(AKP_NOISE_LIMIT);
    const __m256 absmask = _mm256_castsi256_ps(_mm256_set1_epi32(0x7fffffff));
    __m256 valid = _mm256_castsi256_ps(_mm256_set1_epi32(-1));
    __m256i lo[3];
    __m256 f[3];
    for (int k = 0; k < dims; ++k) {
        valid = _mm256_and_ps(valid, _mm256_cmp_ps(_mm256_and_ps(p[k], absmask), limit, _CMP_LT_OQ));
        const __m256 fl = _mm256_floor_ps(p[k]);
        const __m256i i = _mm256_cvttps_epi32(fl);
        f[k] = _mm256_sub_ps(p[k], fl);
        lo[k] = _mm256_and_si256(i, _mm256_set1_epi32(255));
    }
    /* Perlin's chain with the upper corner at index + 1 unwrapped (p[A + 1] in his code: the
     * doubled table makes it equal to the wrapped index): one 32-bit gather at perm + i reads
     * perm[i] and perm[i + 1] together, so 3D takes 1 + 2 + 4 gathers instead of 14. */
    const __m256i m8 = _mm256_set1_epi32(255);
    const int corners = 1 << dims;
    __m256 val[8], gv[8][3];
    __m256i hash[8];
    {
        const __m256i g = gather4(perm, lo[0]);
        hash[0] = _mm256_and_si256(g, m8);
        hash[1] = _mm256_and_si256(_mm256_srli_epi32(g, 8), m8);
    }
    for (int k = 1; k < dims; ++k) {
        const int half = 1 << k;
        for (int c = 0; c < half; ++c) {
            const __m256i g = gather4(perm, _mm256_add_epi32(hash[c], lo[k]));
            hash[c] = _mm256_and_si256(g, m8);
            hash[c + half] = _mm256_and_si256(_mm256_srli_epi32(g, 8), m8);
        }
    }
    for (int c = 0; c < corners; ++c) {
        __m256 d[3];
        for (int k = 0; k < dims; ++k) d[k] = ((c >> k) & 1) ? _mm256_sub_ps(f[k], _mm256_set1_ps(1.0f)) : f[k];
        val[c] = corner8(dims, hash[c], d, gv[c], want_grad);
    }
    for (int k = 0; k < dims; ++k) {
        const __m256 t = fade8(f[k]);
        const __m256 dt = want_grad ? dfade8(f[k]) : _mm256_setzero_ps();
        const int step = 1 << k;
        for (int c = 0; c < corners; c += 2 * step) {
            const __m256 a = val[c], b = val[c + step];
            val[c] = lerp8(t, a, b);
            if (want_grad) {
                for (int m = 0; m < dims; ++m) gv[c][m] = lerp8(t, gv[c][m], gv[c + step][m]);
                gv[c][k] = _mm256_add_ps(gv[c][k], _mm256_mul_ps(_mm256_sub_ps(b, a), dt));
            }
        }
    }
    if (want_grad)
        for (int m = 0; m < dims; ++m) grad[m] = _mm256_and_ps(gv[0][m], valid);
    return _mm256_and_ps(val[0], valid);
}

AKP_AVX2_INLINE static inline void fractal8(const ak_noise* noise, const ak_fractal_desc* d, int dims, const __m256* p,
                                            __m256* out, __m256* gout, bool want_grad) {
    const __m256 signmask = _mm256_castsi256_ps(_mm256_set1_epi32((int)0x80000000u));
    const __m256 one = _mm256_set1_ps(1.0f), zero = _mm256_setzero_ps();
    float freq = d->frequency, amp = 1.0f;
    __m256 sum = zero, weight = one, gs[3] = {zero, zero, zero}, gw[3] = {zero, zero, zero};
    for (uint32_t o = 0; o < d->octaves; ++o) {
        __m256 q[3], g[3];
        const __m256 vf = _mm256_set1_ps(freq), va = _mm256_set1_ps(amp);
        for (int k = 0; k < dims; ++k) q[k] = _mm256_mul_ps(p[k], vf);
        const __m256 n = perlin8(noise->perm, dims, q, g, want_grad);
        if (d->type == AK_FRACTAL_FBM) {
            sum = _mm256_add_ps(sum, _mm256_mul_ps(va, n));
            if (want_grad) {
                const __m256 af = _mm256_set1_ps(amp * freq);
                for (int k = 0; k < dims; ++k) gs[k] = _mm256_add_ps(gs[k], _mm256_mul_ps(af, g[k]));
            }
        } else if (d->type == AK_FRACTAL_TURBULENCE) {
            const __m256 sign = _mm256_and_ps(n, signmask);
            sum = _mm256_add_ps(sum, _mm256_mul_ps(va, _mm256_andnot_ps(signmask, n)));
            if (want_grad) {
                const __m256 af = _mm256_set1_ps(amp * freq);
                for (int k = 0; k < dims; ++k)
                    gs[k] = _mm256_add_ps(gs[k], _mm256_mul_ps(af, _mm256_xor_ps(g[k], sign)));
            }
        } else {
            const __m256 sign = _mm256_and_ps(n, signmask);
            const __m256 an = _mm256_andnot_ps(signmask, n);
            const __m256 unclipped = _mm256_cmp_ps(an, one, _CMP_LT_OQ);
            const __m256 s = _mm256_sub_ps(one, _mm256_min_ps(an, one));
            const __m256 s2 = _mm256_mul_ps(s, s);
            sum = _mm256_add_ps(sum, _mm256_mul_ps(va, _mm256_mul_ps(weight, s2)));
            __m256 nw = _mm256_mul_ps(_mm256_set1_ps(2.0f), s2);
            const __m256 open = _mm256_and_ps(_mm256_cmp_ps(nw, zero, _CMP_GT_OQ), _mm256_cmp_ps(nw, one, _CMP_LT_OQ));
            nw = _mm256_min_ps(_mm256_max_ps(nw, zero), one);
            if (want_grad) {
                const __m256 m2s = _mm256_mul_ps(_mm256_set1_ps(-2.0f), s);
                for (int k = 0; k < dims; ++k) {
                    const __m256 ds2 = _mm256_and_ps(_mm256_mul_ps(m2s, _mm256_mul_ps(vf, _mm256_xor_ps(g[k], sign))),
                                                     unclipped);
                    gs[k] = _mm256_add_ps(
                        gs[k], _mm256_mul_ps(va, _mm256_add_ps(_mm256_mul_ps(weight, ds2), _mm256_mul_ps(s2, gw[k]))));
                    gw[k] = _mm256_and_ps(_mm256_mul_ps(_mm256_set1_ps(2.0f), ds2), open);
                }
            }
            weight = nw;
        }
        freq = freq * d->lacunarity;
        amp = amp * d->gain;
    }
    *out = sum;
    if (want_grad)
        for (int k = 0; k < dims; ++k) gout[k] = gs[k];
}

AKP_AVX2_INLINE static inline void run_dims(const ak_noise* noise, const ak_fractal_desc* d, int dims, const float* const* xs,
                              size_t count, float* out, float* const* grad) {
    for (size_t i = 0; i < count; i += 8) {
        __m256 p[3], v, g[3];
        for (int k = 0; k < dims; ++k) p[k] = _mm256_loadu_ps(xs[k] + i);
        if (grad) {
            fractal8(noise, d, dims, p, &v, g, true);
            for (int k = 0; k < dims; ++k) _mm256_storeu_ps(grad[k] + i, g[k]);
        } else {
            fractal8(noise, d, dims, p, &v, g, false);
        }
        _mm256_storeu_ps(out + i, v);
    }
}

AKP_AVX2 static void run2(const ak_noise* noise, const ak_fractal_desc* d, const float* const* xs, size_t count,
                          float* out, float* const* grad) {
    run_dims(noise, d, 2, xs, count, out, grad);
}
AKP_AVX2 static void run3(const ak_noise* noise, const ak_fractal_desc* d, const float* const* xs, size_t count,
                          float* out, float* const* grad) {
    run_dims(noise, d, 3, xs, count, out, grad);
}

void akp_noise_fractal_avx2(const ak_noise* noise, const ak_fractal_desc* d, uint32_t dims, const float* const* xs,
                            size_t count, float* out, float* const* grad) {
    if (dims == 2) run2(noise, d, xs, count, out, grad);
    else run3(noise, d, xs, count, out, grad);
}

#else

bool akp_noise_have_avx2(void) { return false; }
void akp_noise_fractal_avx2(const ak_noise* noise, const ak_fractal_desc* d, uint32_t dims, const float* const* xs,
                            size_t count, float* out, float* const* grad) {
    (void)noise, (void)d, (void)dims, (void)xs, (void)count, (void)out, (void)grad;
}

#endif

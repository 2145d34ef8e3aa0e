/* AVX2 + FMA skinning kernel, vectorized across vertices (8 per block).
 *
 * Each block runs in two stages. Per vertex, the joint data are blended with contiguous
 * loads (matrix columns for LBS, or 3x4 rows from a per-range copy of palettes up to 256
 * joints for packed 1, 2, 4 and 8 influences; rotation|dual quaternion pairs for DQS, matrix
 * columns with the rotation in their w slots for CoR), which avoids gathers (slow on every
 * x86 core we target); the 8 blended results are then transposed into structure-of-arrays registers and
 * the transform, normal and normalisation run 8-wide. The joint offsets of a block are
 * computed with SIMD ahead of it (LBS: 4 influences; DQS/CoR: 2, 3, 4 or 8, which also compute
 * the hemisphere signs one block ahead); other counts run the blends vertex by vertex.
 * DQS/CoR never normalise the blended quaternion: the rotation formulas take 2 / |q|^2.
 * Positions and normals are deinterleaved with shuffles when tightly packed (stride 12).
 *
 * Handled here: LBS, DQS, CoR with positions and optional normals, rigid or stretched
 * palettes for LBS, rigid palettes for DQS/CoR. Tangents and stretched DQS/CoR palettes go
 * to the scalar code (akp_skin_range_avx2 returns false). The block tail (< 8 vertices) also
 * runs the scalar code.
 *
 * Compiled only for GCC/Clang on x86-64 without AK_NO_SIMD; selected at run time with
 * __builtin_cpu_supports, so the library still runs on CPUs without AVX2. */
#include "skin_internal.h"

#if defined(__GNUC__) && defined(__x86_64__) && !defined(AK_NO_SIMD)
#define AKP_HAVE_AVX2_KERNEL 1
#include <immintrin.h>
#define AKP_AVX2 __attribute__((target("avx2,fma")))
/* helpers must inline into the block functions at -O2 too (registers, not memory) */
#define AKP_AVX2_INLINE __attribute__((target("avx2,fma"), always_inline))
#else
#define AKP_HAVE_AVX2_KERNEL 0
#endif

#if AKP_HAVE_AVX2_KERNEL

bool akp_skin_have_avx2(void) { return __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma"); }

/* Transpose 8 rows of 8 floats (rows r[0..7]) into columns o[0..7]. */
AKP_AVX2_INLINE static inline void transpose8(const __m256* r, __m256* o) {
    __m256 t0 = _mm256_unpacklo_ps(r[0], r[1]), t1 = _mm256_unpackhi_ps(r[0], r[1]);
    __m256 t2 = _mm256_unpacklo_ps(r[2], r[3]), t3 = _mm256_unpackhi_ps(r[2], r[3]);
    __m256 t4 = _mm256_unpacklo_ps(r[4], r[5]), t5 = _mm256_unpackhi_ps(r[4], r[5]);
    __m256 t6 = _mm256_unpacklo_ps(r[6], r[7]), t7 = _mm256_unpackhi_ps(r[6], r[7]);
    __m256 s0 = _mm256_shuffle_ps(t0, t2, 0x44), s1 = _mm256_shuffle_ps(t0, t2, 0xEE);
    __m256 s2 = _mm256_shuffle_ps(t1, t3, 0x44), s3 = _mm256_shuffle_ps(t1, t3, 0xEE);
    __m256 s4 = _mm256_shuffle_ps(t4, t6, 0x44), s5 = _mm256_shuffle_ps(t4, t6, 0xEE);
    __m256 s6 = _mm256_shuffle_ps(t5, t7, 0x44), s7 = _mm256_shuffle_ps(t5, t7, 0xEE);
    o[0] = _mm256_permute2f128_ps(s0, s4, 0x20);
    o[1] = _mm256_permute2f128_ps(s1, s5, 0x20);
    o[2] = _mm256_permute2f128_ps(s2, s6, 0x20);
    o[3] = _mm256_permute2f128_ps(s3, s7, 0x20);
    o[4] = _mm256_permute2f128_ps(s0, s4, 0x31);
    o[5] = _mm256_permute2f128_ps(s1, s5, 0x31);
    o[6] = _mm256_permute2f128_ps(s2, s6, 0x31);
    o[7] = _mm256_permute2f128_ps(s3, s7, 0x31);
}

/* Load 8 xyz triples (stride bytes apart) as x, y, z vectors. Stride 12 uses shuffles: per
 * 128-bit lane the three quads a = (x0 y0 z0 x1), b = (y1 z1 x2 y2), c = (z2 x3 y3 z3). */
AKP_AVX2_INLINE static inline void load_xyz8(const char* p, size_t stride, __m256* x, __m256* y, __m256* z) {
    if (stride == 12) {
        const float* f = (const float*)(const void*)p;
        __m256 a = _mm256_insertf128_ps(_mm256_castps128_ps256(_mm_loadu_ps(f)), _mm_loadu_ps(f + 12), 1);
        __m256 b = _mm256_insertf128_ps(_mm256_castps128_ps256(_mm_loadu_ps(f + 4)), _mm_loadu_ps(f + 16), 1);
        __m256 c = _mm256_insertf128_ps(_mm256_castps128_ps256(_mm_loadu_ps(f + 8)), _mm_loadu_ps(f + 20), 1);
        __m256 t = _mm256_shuffle_ps(b, c, _MM_SHUFFLE(2, 1, 3, 2)); /* x2 y2 x3 y3 */
        __m256 u = _mm256_shuffle_ps(a, b, _MM_SHUFFLE(1, 0, 2, 1)); /* y0 z0 y1 z1 */
        *x = _mm256_shuffle_ps(a, t, _MM_SHUFFLE(2, 0, 3, 0));
        *y = _mm256_shuffle_ps(u, t, _MM_SHUFFLE(3, 1, 2, 0));
        *z = _mm256_shuffle_ps(u, c, _MM_SHUFFLE(3, 0, 3, 1));
        return;
    }
    float v[8][3];
    for (int i = 0; i < 8; ++i) memcpy(v[i], p + (size_t)i * stride, 12);
    *x = _mm256_setr_ps(v[0][0], v[1][0], v[2][0], v[3][0], v[4][0], v[5][0], v[6][0], v[7][0]);
    *y = _mm256_setr_ps(v[0][1], v[1][1], v[2][1], v[3][1], v[4][1], v[5][1], v[6][1], v[7][1]);
    *z = _mm256_setr_ps(v[0][2], v[1][2], v[2][2], v[3][2], v[4][2], v[5][2], v[6][2], v[7][2]);
}

/* Inverse of load_xyz8. */
AKP_AVX2_INLINE static inline void store_xyz8(char* p, size_t stride, __m256 x, __m256 y, __m256 z) {
    if (stride == 12) {
        float* f = (float*)(void*)p;
        __m256 pp = _mm256_shuffle_ps(x, y, _MM_SHUFFLE(2, 0, 2, 0)); /* x0 x2 y0 y2 */
        __m256 q = _mm256_shuffle_ps(y, z, _MM_SHUFFLE(3, 1, 3, 1));  /* y1 y3 z1 z3 */
        __m256 r = _mm256_shuffle_ps(z, x, _MM_SHUFFLE(3, 1, 2, 0));  /* z0 z2 x1 x3 */
        __m256 a = _mm256_shuffle_ps(pp, r, _MM_SHUFFLE(2, 0, 2, 0));
        __m256 b = _mm256_shuffle_ps(q, pp, _MM_SHUFFLE(3, 1, 2, 0));
        __m256 c = _mm256_shuffle_ps(r, q, _MM_SHUFFLE(3, 1, 3, 1));
        _mm_storeu_ps(f, _mm256_castps256_ps128(a));
        _mm_storeu_ps(f + 4, _mm256_castps256_ps128(b));
        _mm_storeu_ps(f + 8, _mm256_castps256_ps128(c));
        _mm_storeu_ps(f + 12, _mm256_extractf128_ps(a, 1));
        _mm_storeu_ps(f + 16, _mm256_extractf128_ps(b, 1));
        _mm_storeu_ps(f + 20, _mm256_extractf128_ps(c, 1));
        return;
    }
    float vx[8], vy[8], vz[8];
    _mm256_storeu_ps(vx, x);
    _mm256_storeu_ps(vy, y);
    _mm256_storeu_ps(vz, z);
    for (int i = 0; i < 8; ++i) {
        float v[3] = {vx[i], vy[i], vz[i]};
        memcpy(p + (size_t)i * stride, v, 12);
    }
}

/* (x, y, z) / |(x, y, z)| with rsqrt + one Newton step, its sign flipped where sign is -0
 * (sign: 0 or -0 per lane); a zero vector stays zero. */
AKP_AVX2_INLINE static inline void normalize8_signed(__m256* x, __m256* y, __m256* z, __m256 sign) {
    /* three independent squares and two adds (7 cycles to l2) rather than a multiply and two
     * dependent FMAs (11): this is the tail of each block's longest dependency chain */
    __m256 l2 = _mm256_add_ps(_mm256_add_ps(_mm256_mul_ps(*x, *x), _mm256_mul_ps(*y, *y)), _mm256_mul_ps(*z, *z));
    l2 = _mm256_max_ps(l2, _mm256_set1_ps(1e-30f));
    const __m256 r = _mm256_rsqrt_ps(l2), a = _mm256_mul_ps(_mm256_set1_ps(0.5f), l2);
    /* v r (1.5 - 0.5 l2 r^2), with the signed v r beside the Newton factor: after the
     * estimate, the chain is a multiply, an FMA and a multiply */
    const __m256 t = _mm256_fnmadd_ps(a, _mm256_mul_ps(r, r), _mm256_set1_ps(1.5f));
    const __m256 rs = _mm256_xor_ps(r, sign);
    *x = _mm256_mul_ps(_mm256_mul_ps(*x, rs), t);
    *y = _mm256_mul_ps(_mm256_mul_ps(*y, rs), t);
    *z = _mm256_mul_ps(_mm256_mul_ps(*z, rs), t);
}

/* a x b, componentwise vectors. */
#define AKP_CROSS(ax, ay, az, bx, by, bz, ox, oy, oz)                                      \
    do {                                                                                   \
        ox = _mm256_fmsub_ps(ay, bz, _mm256_mul_ps(az, by));                               \
        oy = _mm256_fmsub_ps(az, bx, _mm256_mul_ps(ax, bz));                               \
        oz = _mm256_fmsub_ps(ax, by, _mm256_mul_ps(ay, bx));                               \
    } while (0)

static inline uint32_t clamp_joint(uint32_t j, size_t count) { return j < count ? j : (uint32_t)(count - 1); }

/* Joints and weights of vertex i, element by element (fixed-size copies become plain loads;
 * a variable-length memcpy would be a library call per vertex). */
static inline void load_influences(const akp_skin_ctx* c, size_t i, uint32_t K, uint16_t* jj, float* ww) {
    const char* jp = c->jnt + i * c->jnt_stride;
    const char* wp = c->wgt + i * c->wgt_stride;
    for (uint32_t k = 0; k < K; ++k) {
        memcpy(&jj[k], jp + 2u * k, sizeof(uint16_t));
        memcpy(&ww[k], wp + 4u * k, sizeof(float));
    }
}

/* Blend the palette matrices of vertex i: rows out[0] = (c0, c1), out[1] = (c2, c3), each
 * column with its w row (which holds 0 for affine matrices and is overwritten by CoR). */
AKP_AVX2_INLINE static inline void blend_matrix_vertex(const akp_skin_ctx* c, size_t i, uint32_t K, __m256* out01,
                                                __m256* out23) {
    uint16_t jj[AK_MAX_INFLUENCES];
    float ww[AK_MAX_INFLUENCES];
    load_influences(c, i, K, jj, ww);
    __m256 a01 = _mm256_setzero_ps(), a23 = _mm256_setzero_ps();
    for (uint32_t k = 0; k < K; ++k) {
        const float* m = c->palette[clamp_joint(jj[k], c->palette_count)].m;
        __m256 w = _mm256_set1_ps(ww[k]);
        a01 = _mm256_fmadd_ps(_mm256_loadu_ps(m), w, a01);
        a23 = _mm256_fmadd_ps(_mm256_loadu_ps(m + 8), w, a23);
    }
    *out01 = a01;
    *out23 = a23;
}

#include "skin_avx2_shared.h" /* joint offsets, DQS/CoR phase 1 */

/* Blend of two 8-float rows at base + off[k] with the K weights of vertex i: the palette
 * matrices for LBS (offsets from joint_offsets with AKP_MAT_SHIFT), the CoR rows for CoR. Each
 * weight is broadcast straight from memory and each offset is its own 32-bit load (as one
 * 64-bit word, each costs a move, a shift and a register broadcast). */
AKP_AVX2_INLINE static inline void blend_matrix_rows_w(const char* wp, const char* base, const uint32_t* off,
                                                        __m256* out01, __m256* out23, const uint32_t K) {
    float wk;
    memcpy(&wk, wp, 4);
    __m256 w = _mm256_set1_ps(wk);
    const char* base2 = base + 32;
    size_t o = off[0];
    __m256 a01 = _mm256_mul_ps(_mm256_loadu_ps((const float*)(const void*)(base + o)), w);
    __m256 a23 = _mm256_mul_ps(_mm256_loadu_ps((const float*)(const void*)(base2 + o)), w);
    for (uint32_t k = 1; k < K; ++k) {
        o = off[k];
        memcpy(&wk, wp + 4u * k, 4);
        w = _mm256_set1_ps(wk);
        a01 = _mm256_fmadd_ps(_mm256_loadu_ps((const float*)(const void*)(base + o)), w, a01);
        a23 = _mm256_fmadd_ps(_mm256_loadu_ps((const float*)(const void*)(base2 + o)), w, a23);
    }
    *out01 = a01;
    *out23 = a23;
}
AKP_AVX2_INLINE static inline void blend_matrix_rows(const akp_skin_ctx* c, size_t i, const char* base,
                                                      const uint32_t* off, __m256* out01, __m256* out23,
                                                      const uint32_t K) {
    blend_matrix_rows_w(c->wgt + i * c->wgt_stride, base, off, out01, out23, K);
}

/* Packed joints and weights (strides 2 K and 4 K bytes), K = 2, 4 or 8: the palette byte
 * offsets of 8 vertices, off[K v + k], from K loads of 8 indices (widen, clamp, shift) instead
 * of joint_offsets' two loads, an unpack and a convert per pair of vertices (block_lbs then
 * reads vertex v's weights 4 K v bytes after the block's). */
AKP_AVX2_INLINE static inline void offsets8_dense(const akp_skin_ctx* c, size_t i0, uint32_t* off, const uint32_t K) {
    const char* jp = c->jnt + i0 * 2u * K;
    const size_t last = c->palette_count - 1;
    const __m256i lim = _mm256_set1_epi32((int)(last > 65535u ? 65535u : last));
    for (uint32_t q = 0; q < K; ++q) {
        const __m256i j = _mm256_cvtepu16_epi32(_mm_loadu_si128((const __m128i*)(const void*)(jp + 16u * q)));
        const __m256i o = _mm256_slli_epi32(_mm256_min_epu32(j, lim), AKP_MAT_SHIFT);
        _mm256_storeu_si256((__m256i*)(void*)(off + 8u * q), o);
    }
}

/* Palette matrices as 3x4 rows, 64 bytes a joint: (m00 m01 m02 t0 | m10 m11 m12 t1) then
 * (m20 m21 m22 t2 | 0 0 0 0). The dense LBS path copies the palette into this layout on its
 * stack (once per range) when it has at most AKP_ROWS3_MAX joints. */
#define AKP_ROWS3_MAX 256u
AKP_AVX2_INLINE static inline void palette_rows3(const ak_mat4* pal, size_t count, float* out) {
    for (size_t j = 0; j < count; ++j) {
        __m128 c0 = _mm_loadu_ps(pal[j].m), c1 = _mm_loadu_ps(pal[j].m + 4);
        __m128 c2 = _mm_loadu_ps(pal[j].m + 8), c3 = _mm_loadu_ps(pal[j].m + 12);
        _MM_TRANSPOSE4_PS(c0, c1, c2, c3);
        _mm_storeu_ps(out + 16 * j, c0);
        _mm_storeu_ps(out + 16 * j + 4, c1);
        _mm_storeu_ps(out + 16 * j + 8, c2);
        _mm_storeu_ps(out + 16 * j + 12, _mm_setzero_ps());
    }
}

/* Blend of the 3x4-row palette (palette_rows3, at base) for the 8 vertices of a dense block
 * (weights at wb, 4 K bytes a vertex; offsets off[K v + k]): rows 0 and 1 of a vertex are one
 * 8-float FMA per influence, and the third rows of vertices v and v + 4 share one (their
 * weights joined with a blend), so 12 K FMAs a block instead of 16 K. Out: m[0..3] the first
 * row (m00, m01, m02, t0) of the 8 vertices, m[4..7] the second, m[8..11] the third. */
AKP_AVX2_INLINE static inline void blend_rows3_block(const char* wb, const char* base, const uint32_t* off,
                                                     __m256* m, const uint32_t K) {
    __m256 r01[8], r2[4];
    /* unrolled: as a loop, GCC keeps r01 and r2 on the stack (K = 4: 12% slower) */
#pragma GCC unroll 4
    for (uint32_t v = 0; v < 4; ++v) {
        const char *wa = wb + 4u * K * v, *wc = wb + 4u * K * (v + 4u);
        const uint32_t *oa = off + K * v, *oc = off + K * (v + 4u);
        __m256 a = _mm256_setzero_ps(), c = _mm256_setzero_ps(), p = _mm256_setzero_ps();
        for (uint32_t k = 0; k < K; ++k) {
            float fa, fc;
            memcpy(&fa, wa + 4u * k, 4);
            memcpy(&fc, wc + 4u * k, 4);
            const __m256 w0 = _mm256_set1_ps(fa), w1 = _mm256_set1_ps(fc);
            const size_t ja = oa[k], jc = oc[k];
            const __m256 ra = _mm256_loadu_ps((const float*)(const void*)(base + ja));
            const __m256 rc = _mm256_loadu_ps((const float*)(const void*)(base + jc));
            const __m256 rp = _mm256_insertf128_ps(
                _mm256_castps128_ps256(_mm_loadu_ps((const float*)(const void*)(base + 32 + ja))),
                _mm_loadu_ps((const float*)(const void*)(base + 32 + jc)), 1);
            const __m256 wp = _mm256_blend_ps(w0, w1, 0xF0);
            if (k == 0) {
                a = _mm256_mul_ps(ra, w0), c = _mm256_mul_ps(rc, w1), p = _mm256_mul_ps(rp, wp);
            } else {
                a = _mm256_fmadd_ps(ra, w0, a), c = _mm256_fmadd_ps(rc, w1, c), p = _mm256_fmadd_ps(rp, wp, p);
            }
        }
        r01[v] = a, r01[v + 4] = c, r2[v] = p;
    }
    transpose8(r01, m);
    /* 4x4 transpose in each 128-bit lane: lane 0 holds vertices 0-3, lane 1 vertices 4-7 */
    const __m256 t0 = _mm256_unpacklo_ps(r2[0], r2[1]), t1 = _mm256_unpackhi_ps(r2[0], r2[1]);
    const __m256 t2 = _mm256_unpacklo_ps(r2[2], r2[3]), t3 = _mm256_unpackhi_ps(r2[2], r2[3]);
    m[8] = _mm256_shuffle_ps(t0, t2, 0x44);
    m[9] = _mm256_shuffle_ps(t0, t2, 0xEE);
    m[10] = _mm256_shuffle_ps(t1, t3, 0x44);
    m[11] = _mm256_shuffle_ps(t1, t3, 0xEE);
}

/* Hemisphere-aligned blend of (real | dual) quaternions of vertex i. */
AKP_AVX2_INLINE static inline __m256 blend_dq_vertex(const akp_skin_ctx* c, size_t i, uint32_t K) {
    uint16_t jj[AK_MAX_INFLUENCES];
    float ww[AK_MAX_INFLUENCES];
    load_influences(c, i, K, jj, ww);
    uint32_t best = 0;
    for (uint32_t k = 1; k < K; ++k) best = ww[k] > ww[best] ? k : best;
    const __m128 ref = _mm_loadu_ps(c->joints_prep[clamp_joint(jj[best], c->palette_count)].real);
    const __m128 sign = _mm_set1_ps(-0.0f);
    __m256 acc = _mm256_setzero_ps();
    for (uint32_t k = 0; k < K; ++k) {
        __m256 d = _mm256_loadu_ps(c->joints_prep[clamp_joint(jj[k], c->palette_count)].real);
        __m128 pr = _mm_mul_ps(_mm256_castps256_ps128(d), ref);
        pr = _mm_add_ps(pr, _mm_movehl_ps(pr, pr));
        pr = _mm_add_ss(pr, _mm_shuffle_ps(pr, pr, 1));
        __m128 w = _mm_xor_ps(_mm_load_ss(&ww[k]), _mm_and_ps(pr, sign));
        acc = _mm256_fmadd_ps(d, _mm256_broadcastss_ps(w), acc);
    }
    return acc;
}

/* Blended (real | dual) of the 8 vertices of a block: from the phase-1 data p (K = 2, 3, 4
 * or 8) when given, else vertex by vertex. */
AKP_AVX2_INLINE static inline void blend_dq_block(const akp_skin_ctx* c, size_t i0, uint32_t K, const dq_prep* p,
                                                  __m256* rows) {
    if (p) {
        for (int v = 0; v < 8; ++v)
            rows[v] = dq_accumulate(c, p->off + AKP_SLOTS(K) * v, p->sw + AKP_SLOTS(K) * v, K);
        return;
    }
    for (int v = 0; v < 8; ++v) rows[v] = blend_dq_vertex(c, i0 + (size_t)v, K);
}


/* off: with 2, 3, 4 or 8 influences, the block's palette offsets (joint_offsets, AKP_SLOTS(K)
 * per vertex), computed a block ahead by the caller so that they are read back from memory as
 * plain loads; NULL otherwise. */
/* io: AKP_IO_ANY reads the strides and normals flag from c; AKP_IO_P and AKP_IO_PN are the
 * packed layouts (every stream 12 bytes a vertex) without and with normals, as compile-time
 * constants: no stride multiplies and no per-block branches on the layout. */
enum { AKP_IO_ANY, AKP_IO_P, AKP_IO_PN };
/* The blend and transpose of block_lbs from the 4x4 palette: the blended matrices' columns
 * a, b, c (linear part) and t (translation), one vector per component. */
AKP_AVX2_INLINE static inline void block_lbs_blend(const akp_skin_ctx* c, size_t i0, uint32_t K, const uint32_t* off,
                                                   bool dense, __m256* ax, __m256* ay, __m256* az, __m256* bx,
                                                   __m256* by, __m256* bz, __m256* cx, __m256* cy, __m256* cz,
                                                   __m256* tx, __m256* ty, __m256* tz) {
    __m256 rows[8], cols[8];
    __m256 c01[8], c23[8];
    if (off && dense) {
        const char* wb = c->wgt + i0 * 4u * K;
        for (uint32_t v = 0; v < 8; ++v)
            blend_matrix_rows_w(wb + 4u * K * v, (const char*)c->palette, off + K * v, &c01[v], &c23[v], K);
    } else if (off) {
        for (int v = 0; v < 8; ++v)
            blend_matrix_rows(c, i0 + (size_t)v, (const char*)c->palette, off + AKP_SLOTS(K) * v, &c01[v], &c23[v], K);
    } else {
        for (int v = 0; v < 8; ++v) blend_matrix_vertex(c, i0 + (size_t)v, K, &c01[v], &c23[v]);
    }
    for (int v = 0; v < 8; ++v) rows[v] = c01[v];
    transpose8(rows, cols);
    *ax = cols[0], *ay = cols[1], *az = cols[2], *bx = cols[4], *by = cols[5], *bz = cols[6];
    for (int v = 0; v < 8; ++v) rows[v] = c23[v];
    transpose8(rows, cols);
    *cx = cols[0], *cy = cols[1], *cz = cols[2], *tx = cols[4], *ty = cols[5], *tz = cols[6];
}

/* rows3: a palette_rows3 copy of the palette (dense blocks only), else NULL. */
AKP_AVX2_INLINE static inline void block_lbs(const akp_skin_ctx* c, size_t i0, uint32_t K, const uint32_t* off,
                                             bool dense, const float* rows3, const int io) {
    const size_t ps = io ? 12u : c->pos_stride, ops = io ? 12u : c->out_pos_stride;
    const size_t ns = io ? 12u : c->nrm_stride, ons = io ? 12u : c->out_nrm_stride;
    const bool normals = io == AKP_IO_ANY ? c->do_normals : io == AKP_IO_PN;
    __m256 ax, ay, az, bx, by, bz, cx, cy, cz, tx, ty, tz;
    if (rows3) {
        __m256 m[12];
        blend_rows3_block(c->wgt + i0 * 4u * K, (const char*)rows3, off, m, K);
        ax = m[0], bx = m[1], cx = m[2], tx = m[3];
        ay = m[4], by = m[5], cy = m[6], ty = m[7];
        az = m[8], bz = m[9], cz = m[10], tz = m[11];
    } else {
        block_lbs_blend(c, i0, K, off, dense, &ax, &ay, &az, &bx, &by, &bz, &cx, &cy, &cz, &tx, &ty, &tz);
    }

    __m256 px, py, pz;
    load_xyz8(c->pos + i0 * ps, ps, &px, &py, &pz);
    __m256 ox = _mm256_fmadd_ps(ax, px, _mm256_fmadd_ps(bx, py, _mm256_fmadd_ps(cx, pz, tx)));
    __m256 oy = _mm256_fmadd_ps(ay, px, _mm256_fmadd_ps(by, py, _mm256_fmadd_ps(cy, pz, ty)));
    __m256 oz = _mm256_fmadd_ps(az, px, _mm256_fmadd_ps(bz, py, _mm256_fmadd_ps(cz, pz, tz)));
    store_xyz8(c->out_pos + i0 * ops, ops, ox, oy, oz);
    if (!normals) return;

    __m256 nx, ny, nz, k0x, k0y, k0z, k1x, k1y, k1z;
    load_xyz8(c->nrm + i0 * ns, ns, &nx, &ny, &nz);
    /* cof(M) n = nx (b x c) + ny (c x a) + nz (a x b) = nx (b x c) + (ny c - nz b) x a: two
     * cross products instead of three; sign(det) goes on the Newton factor */
    AKP_CROSS(bx, by, bz, cx, cy, cz, k0x, k0y, k0z);
    const __m256 ux = _mm256_fmsub_ps(ny, cx, _mm256_mul_ps(nz, bx));
    const __m256 uy = _mm256_fmsub_ps(ny, cy, _mm256_mul_ps(nz, by));
    const __m256 uz = _mm256_fmsub_ps(ny, cz, _mm256_mul_ps(nz, bz));
    AKP_CROSS(ux, uy, uz, ax, ay, az, k1x, k1y, k1z);
    const __m256 det = _mm256_fmadd_ps(ax, k0x, _mm256_fmadd_ps(ay, k0y, _mm256_mul_ps(az, k0z)));
    __m256 mx = _mm256_fmadd_ps(k0x, nx, k1x), my = _mm256_fmadd_ps(k0y, nx, k1y), mz = _mm256_fmadd_ps(k0z, nx, k1z);
    normalize8_signed(&mx, &my, &mz, _mm256_and_ps(det, _mm256_set1_ps(-0.0f)));
    store_xyz8(c->out_nrm + i0 * ons, ons, mx, my, mz);
}

/* LBS with 1 influence (ctx.rigid_single: no normals, or a rigid palette): p' = w (M p) and
 * n' = sign(w) R n, without the blend, the cofactor and the renormalisation (R is a rotation:
 * a unit normal stays unit; w = 1 for checked data). */
/* rows3: a palette_rows3 copy of the palette (the 8 matrices then take a 12-row transpose
 * instead of two 8-row ones), or NULL. */
AKP_AVX2_INLINE static inline void block_lbs_rigid1(const akp_skin_ctx* c, size_t i0, const float* rows3,
                                                    const int io) {
    const size_t ps = io ? 12u : c->pos_stride, ops = io ? 12u : c->out_pos_stride;
    const size_t ns = io ? 12u : c->nrm_stride, ons = io ? 12u : c->out_nrm_stride;
    const bool normals = io == AKP_IO_ANY ? c->do_normals : io == AKP_IO_PN;
    __m256 ax, ay, az, bx, by, bz, cx, cy, cz, tx, ty, tz;
    if (rows3) {
        const char* base = (const char*)rows3;
        size_t o[8];
        for (int v = 0; v < 8; ++v) {
            uint16_t j;
            memcpy(&j, c->jnt + (i0 + (size_t)v) * c->jnt_stride, sizeof j);
            o[v] = (size_t)clamp_joint(j, c->palette_count) * 64u;
        }
        __m256 r01[8], r2[4], m[8];
        for (int v = 0; v < 8; ++v) r01[v] = _mm256_loadu_ps((const float*)(const void*)(base + o[v]));
        for (int v = 0; v < 4; ++v)
            r2[v] = _mm256_insertf128_ps(
                _mm256_castps128_ps256(_mm_loadu_ps((const float*)(const void*)(base + 32 + o[v]))),
                _mm_loadu_ps((const float*)(const void*)(base + 32 + o[v + 4])), 1);
        transpose8(r01, m);
        ax = m[0], bx = m[1], cx = m[2], tx = m[3], ay = m[4], by = m[5], cy = m[6], ty = m[7];
        const __m256 t0 = _mm256_unpacklo_ps(r2[0], r2[1]), t1 = _mm256_unpackhi_ps(r2[0], r2[1]);
        const __m256 t2 = _mm256_unpacklo_ps(r2[2], r2[3]), t3 = _mm256_unpackhi_ps(r2[2], r2[3]);
        az = _mm256_shuffle_ps(t0, t2, 0x44), bz = _mm256_shuffle_ps(t0, t2, 0xEE);
        cz = _mm256_shuffle_ps(t1, t3, 0x44), tz = _mm256_shuffle_ps(t1, t3, 0xEE);
    } else {
        __m256 r01[8], r23[8], cols[8];
        for (int v = 0; v < 8; ++v) {
            uint16_t j;
            memcpy(&j, c->jnt + (i0 + (size_t)v) * c->jnt_stride, sizeof j);
            const float* m = c->palette[clamp_joint(j, c->palette_count)].m;
            r01[v] = _mm256_loadu_ps(m);
            r23[v] = _mm256_loadu_ps(m + 8);
        }
        transpose8(r01, cols);
        ax = cols[0], ay = cols[1], az = cols[2], bx = cols[4], by = cols[5], bz = cols[6];
        transpose8(r23, cols);
        cx = cols[0], cy = cols[1], cz = cols[2], tx = cols[4], ty = cols[5], tz = cols[6];
    }
    __m256 w;
    if (c->wgt_stride == 4) {
        w = _mm256_loadu_ps((const float*)(const void*)(c->wgt + i0 * 4));
    } else {
        float t[8];
        for (int v = 0; v < 8; ++v) memcpy(&t[v], c->wgt + (i0 + (size_t)v) * c->wgt_stride, 4);
        w = _mm256_loadu_ps(t);
    }
    __m256 px, py, pz;
    load_xyz8(c->pos + i0 * ps, ps, &px, &py, &pz);
    const __m256 ox = _mm256_mul_ps(w, _mm256_fmadd_ps(ax, px, _mm256_fmadd_ps(bx, py, _mm256_fmadd_ps(cx, pz, tx))));
    const __m256 oy = _mm256_mul_ps(w, _mm256_fmadd_ps(ay, px, _mm256_fmadd_ps(by, py, _mm256_fmadd_ps(cy, pz, ty))));
    const __m256 oz = _mm256_mul_ps(w, _mm256_fmadd_ps(az, px, _mm256_fmadd_ps(bz, py, _mm256_fmadd_ps(cz, pz, tz))));
    store_xyz8(c->out_pos + i0 * ops, ops, ox, oy, oz);
    if (!normals) return;
    __m256 nx, ny, nz;
    load_xyz8(c->nrm + i0 * ns, ns, &nx, &ny, &nz);
    /* sign(w): 0 where w is 0 (or NaN: only with unchecked data), negated where w < 0 */
    const __m256 keep = _mm256_cmp_ps(w, _mm256_setzero_ps(), _CMP_NEQ_OQ);
    const __m256 sign = _mm256_and_ps(w, _mm256_set1_ps(-0.0f));
    __m256 mx = _mm256_fmadd_ps(ax, nx, _mm256_fmadd_ps(bx, ny, _mm256_mul_ps(cx, nz)));
    __m256 my = _mm256_fmadd_ps(ay, nx, _mm256_fmadd_ps(by, ny, _mm256_mul_ps(cy, nz)));
    __m256 mz = _mm256_fmadd_ps(az, nx, _mm256_fmadd_ps(bz, ny, _mm256_mul_ps(cz, nz)));
    mx = _mm256_xor_ps(_mm256_and_ps(mx, keep), sign);
    my = _mm256_xor_ps(_mm256_and_ps(my, keep), sign);
    mz = _mm256_xor_ps(_mm256_and_ps(mz, keep), sign);
    store_xyz8(c->out_nrm + i0 * ons, ons, mx, my, mz);
}

/* 2 / |q|^2 for 8 blended quaternions, and 0 where the blend vanished (|q|^2 <= 1e-30: the
 * scalar code's identity). The blends are not normalised: the rotation and translation
 * formulas below divide by |q|^2 through this factor, so the division runs in parallel with
 * the cross products instead of ahead of them. */
AKP_AVX2_INLINE static inline __m256 quat_scale8(__m256 x, __m256 y, __m256 z, __m256 w) {
    __m256 n2 = _mm256_fmadd_ps(x, x, _mm256_fmadd_ps(y, y, _mm256_fmadd_ps(z, z, _mm256_mul_ps(w, w))));
    __m256 ok = _mm256_cmp_ps(n2, _mm256_set1_ps(1e-30f), _CMP_GT_OQ);
    __m256 s = _mm256_div_ps(_mm256_set1_ps(2.0f), _mm256_max_ps(n2, _mm256_set1_ps(1e-30f)));
    return _mm256_and_ps(s, ok);
}

/* Rotate (px, py, pz) by q / |q| for any nonzero q, given s = 2 / |q|^2 (quat_scale8):
 * p + s (w (v x p) + v x (v x p)); s = 0 leaves p unchanged. */
AKP_AVX2_INLINE static inline void rotate8_scaled(__m256 qx, __m256 qy, __m256 qz, __m256 qw, __m256 s, __m256* px,
                                                  __m256* py, __m256* pz) {
    __m256 tx, ty, tz, ux, uy, uz;
    AKP_CROSS(qx, qy, qz, *px, *py, *pz, tx, ty, tz);
    AKP_CROSS(qx, qy, qz, tx, ty, tz, ux, uy, uz);
    *px = _mm256_fmadd_ps(s, _mm256_fmadd_ps(qw, tx, ux), *px);
    *py = _mm256_fmadd_ps(s, _mm256_fmadd_ps(qw, ty, uy), *py);
    *pz = _mm256_fmadd_ps(s, _mm256_fmadd_ps(qw, tz, uz), *pz);
}

AKP_AVX2_INLINE static inline void block_dqs(const akp_skin_ctx* c, size_t i0, uint32_t K, const dq_prep* p) {
    __m256 rows[8], q[8];
    blend_dq_block(c, i0, K, p, rows);
    transpose8(rows, q);
    const __m256 qx = q[0], qy = q[1], qz = q[2], qw = q[3], dx = q[4], dy = q[5], dz = q[6], dw = q[7];
    const __m256 sc = quat_scale8(qx, qy, qz, qw);
    /* translation of the normalised dual quaternion: (2 / |q|^2) (w dv - dw v + v x dv) */
    __m256 cx, cy, cz;
    AKP_CROSS(qx, qy, qz, dx, dy, dz, cx, cy, cz);
    __m256 tx = _mm256_add_ps(_mm256_fmsub_ps(qw, dx, _mm256_mul_ps(dw, qx)), cx);
    __m256 ty = _mm256_add_ps(_mm256_fmsub_ps(qw, dy, _mm256_mul_ps(dw, qy)), cy);
    __m256 tz = _mm256_add_ps(_mm256_fmsub_ps(qw, dz, _mm256_mul_ps(dw, qz)), cz);
    __m256 px, py, pz;
    load_xyz8(c->pos + i0 * c->pos_stride, c->pos_stride, &px, &py, &pz);
    rotate8_scaled(qx, qy, qz, qw, sc, &px, &py, &pz);
    px = _mm256_fmadd_ps(sc, tx, px);
    py = _mm256_fmadd_ps(sc, ty, py);
    pz = _mm256_fmadd_ps(sc, tz, pz);
    store_xyz8(c->out_pos + i0 * c->out_pos_stride, c->out_pos_stride, px, py, pz);
    if (!c->do_normals) return;
    __m256 nx, ny, nz;
    load_xyz8(c->nrm + i0 * c->nrm_stride, c->nrm_stride, &nx, &ny, &nz);
    rotate8_scaled(qx, qy, qz, qw, sc, &nx, &ny, &nz); /* a rotation: lengths are kept */
    store_xyz8(c->out_nrm + i0 * c->out_nrm_stride, c->out_nrm_stride, nx, ny, nz);
}

AKP_AVX2_INLINE static inline void block_cor(const akp_skin_ctx* c, size_t i0, uint32_t K, const dq_prep* p) {
    __m256 r01[8], r23[8], cols[8];
    const __m256i lo = _mm256_setr_epi32(0, 0, 0, 0, 1, 1, 1, 1), hi = _mm256_setr_epi32(2, 2, 2, 2, 3, 3, 3, 3);
    if (p) {
        /* one blend of the joints' cor_rows, as LBS blends matrices: the offsets already point
         * at the copies whose rotation (w lanes) is on the reference's hemisphere */
        for (int v = 0; v < 8; ++v) {
            blend_matrix_rows(c, i0 + (size_t)v, (const char*)c->joints_prep + offsetof(akp_skin_joint, cor_rows),
                              p->off + AKP_SLOTS(K) * v, &r01[v], &r23[v], K);
        }
    } else {
        __m256 q[8];
        blend_dq_block(c, i0, K, p, q);
        for (int v = 0; v < 8; ++v) {
            blend_matrix_vertex(c, i0 + (size_t)v, K, &r01[v], &r23[v]);
            /* the rotation blend goes into the unused w rows: (qx, qy) and (qz, qw) */
            r01[v] = _mm256_blend_ps(r01[v], _mm256_permutevar8x32_ps(q[v], lo), 0x88);
            r23[v] = _mm256_blend_ps(r23[v], _mm256_permutevar8x32_ps(q[v], hi), 0x88);
        }
    }
    transpose8(r01, cols);
    const __m256 ax = cols[0], ay = cols[1], az = cols[2], bx = cols[4], by = cols[5], bz = cols[6];
    const __m256 qx = cols[3], qy = cols[7];
    transpose8(r23, cols);
    const __m256 cx = cols[0], cy = cols[1], cz = cols[2], tx = cols[4], ty = cols[5], tz = cols[6];
    const __m256 qz = cols[3], qw = cols[7];
    const __m256 sc = quat_scale8(qx, qy, qz, qw);

    __m256 sx, sy, sz, px, py, pz;
    load_xyz8(c->ctr + i0 * c->ctr_stride, c->ctr_stride, &sx, &sy, &sz);
    load_xyz8(c->pos + i0 * c->pos_stride, c->pos_stride, &px, &py, &pz);
    __m256 mx = _mm256_fmadd_ps(ax, sx, _mm256_fmadd_ps(bx, sy, _mm256_fmadd_ps(cx, sz, tx)));
    __m256 my = _mm256_fmadd_ps(ay, sx, _mm256_fmadd_ps(by, sy, _mm256_fmadd_ps(cy, sz, ty)));
    __m256 mz = _mm256_fmadd_ps(az, sx, _mm256_fmadd_ps(bz, sy, _mm256_fmadd_ps(cz, sz, tz)));
    px = _mm256_sub_ps(px, sx);
    py = _mm256_sub_ps(py, sy);
    pz = _mm256_sub_ps(pz, sz);
    rotate8_scaled(qx, qy, qz, qw, sc, &px, &py, &pz);
    store_xyz8(c->out_pos + i0 * c->out_pos_stride, c->out_pos_stride, _mm256_add_ps(px, mx),
               _mm256_add_ps(py, my), _mm256_add_ps(pz, mz));
    if (!c->do_normals) return;
    __m256 nx, ny, nz;
    load_xyz8(c->nrm + i0 * c->nrm_stride, c->nrm_stride, &nx, &ny, &nz);
    rotate8_scaled(qx, qy, qz, qw, sc, &nx, &ny, &nz); /* a rotation: lengths are kept */
    store_xyz8(c->out_nrm + i0 * c->out_nrm_stride, c->out_nrm_stride, nx, ny, nz);
}

/* The LBS block loop, specialised for 2, 3, 4 and 8 influences so the compiler unrolls; the
 * palette offsets of the next block are computed before the current block runs (two buffers in
 * turn), so the blend reads them back as plain loads: extracting 32 offsets from SIMD registers
 * costs more, and reading them right after the vector store stalls. Pipelined like 4, 2 and 8
 * influences went from 1.07x / 1.10x to 1.08x / 1.29x ozz's rate (LBS with normals, 100k, Zen 5).
 * Other counts (1 without the rigid path, 5, 6, 7) run vertex by vertex through the blends;
 * with the count a compile-time constant for 1 the compiler unrolls them (measured in cache
 * before this: 1 and 2 influences ran slower than 4, 8 at a third of 4's speed). */
#define AKP_K_DISPATCH(RUN)                                                                \
    switch (c->k) {                                                                        \
    case 1: RUN(1u); break;                                                                \
    case 2: RUN(2u); break;                                                                \
    case 3: RUN(3u); break;                                                                \
    case 8: RUN(8u); break;                                                                \
    default: RUN(c->k); break;                                                             \
    }

AKP_AVX2 static void block_lbs_range(const akp_skin_ctx* c, size_t begin, size_t end) {
    /* every position and normal stream packed (12 bytes a vertex) */
    const bool packed = c->pos_stride == 12u && c->out_pos_stride == 12u &&
                        (!c->do_normals || (c->nrm_stride == 12u && c->out_nrm_stride == 12u));
    /* the palette as 3x4 rows (blend_rows3_block, block_lbs_rigid1), for up to AKP_ROWS3_MAX
     * joints */
    _Alignas(64) float rows3_buf[AKP_ROWS3_MAX * 16];
    const float* rows3 = NULL;
    const bool dense = (c->k == 2 || c->k == 4 || c->k == 8) && c->jnt_stride == 2u * c->k &&
                       c->wgt_stride == 4u * c->k; /* AKP_LBS_PIPELINE's dense blocks */
    if ((c->rigid_single || dense) && c->palette_count <= AKP_ROWS3_MAX) {
        palette_rows3(c->palette, c->palette_count, rows3_buf);
        rows3 = rows3_buf;
    }
    if (c->rigid_single) {
#define AKP_RIGID1(IO) for (size_t i = begin; i < end; i += 8) block_lbs_rigid1(c, i, rows3, (IO))
        if (packed && c->do_normals) AKP_RIGID1(AKP_IO_PN);
        else if (packed) AKP_RIGID1(AKP_IO_P);
        else AKP_RIGID1(AKP_IO_ANY);
#undef AKP_RIGID1
    } else if (c->k == 2 || c->k == 3 || c->k == 4 || c->k == 8) {
#define AKP_LBS_DENSE(K, IO)                                                               \
    do {                                                                                   \
        offsets8_dense(c, begin, off[0], (K));                                             \
        unsigned b = 0;                                                                    \
        for (size_t i = begin; i < end; i += 8, b ^= 1u) {                                 \
            if (i + 8 < end) offsets8_dense(c, i + 8, off[b ^ 1u], (K));                   \
            block_lbs(c, i, (K), off[b], true, rows3, (IO));                               \
        }                                                                                  \
    } while (0)
#define AKP_LBS_PIPELINE(K)                                                                \
    do {                                                                                   \
        uint32_t off[2][64];                                                               \
        if ((K) != 3u && c->jnt_stride == 2u * (K) && c->wgt_stride == 4u * (K)) {         \
            if (packed && c->do_normals) AKP_LBS_DENSE((K), AKP_IO_PN);                    \
            else if (packed) AKP_LBS_DENSE((K), AKP_IO_P);                                 \
            else AKP_LBS_DENSE((K), AKP_IO_ANY);                                           \
            break;                                                                         \
        }                                                                                  \
        joint_offsets(c, begin, AKP_MAT_SHIFT, off[0], (K));                              \
        unsigned b = 0;                                                                    \
        for (size_t i = begin; i < end; i += 8, b ^= 1u) {                                 \
            if (i + 8 < end) joint_offsets(c, i + 8, AKP_MAT_SHIFT, off[b ^ 1u], (K));    \
            block_lbs(c, i, (K), off[b], false, NULL, AKP_IO_ANY);                         \
        }                                                                                  \
    } while (0)
        if (c->k == 2) AKP_LBS_PIPELINE(2u);
        else if (c->k == 3) AKP_LBS_PIPELINE(3u);
        else if (c->k == 4) AKP_LBS_PIPELINE(4u);
        else AKP_LBS_PIPELINE(8u);
#undef AKP_LBS_DENSE
#undef AKP_LBS_PIPELINE
    } else {
#define AKP_LBS_K(K)                                                                       \
    for (size_t i = begin; i < end; i += 8) block_lbs(c, i, (K), NULL, false, NULL, AKP_IO_ANY)
        AKP_K_DISPATCH(AKP_LBS_K)
#undef AKP_LBS_K
    }
}

/* DQS and CoR: with 2, 3, 4 or 8 influences, the joint offsets are computed two blocks ahead
 * and phase 1 (the signs) one block ahead, three buffers in turn: phase 1 reads the offsets
 * back as plain loads, and reading them right after their vector store would stall on the
 * store forwarding (measured: the signs then cost 40% of DQS). */
#define AKP_DQ_PIPELINE(fn, neg, K)                                                        \
    do {                                                                                   \
        dq_prep p[3];                                                                      \
        joint_offsets(c, begin, AKP_JOINT_SHIFT, p[0].off, (K));                          \
        if (begin + 8 < end) joint_offsets(c, begin + 8, AKP_JOINT_SHIFT, p[1].off, (K)); \
        dq_signs_block(c, begin, &p[0], (neg), (K));                                       \
        unsigned b = 0;                                                                    \
        for (size_t i = begin; i < end; i += 8, b = b == 2u ? 0u : b + 1u) {               \
            const unsigned b1 = b == 2u ? 0u : b + 1u, b2 = b1 == 2u ? 0u : b1 + 1u;       \
            if (i + 16 < end) joint_offsets(c, i + 16, AKP_JOINT_SHIFT, p[b2].off, (K));  \
            if (i + 8 < end) dq_signs_block(c, i + 8, &p[b1], (neg), (K));                 \
            fn(c, i, (K), &p[b]);                                                          \
        }                                                                                  \
    } while (0)
/* 2 and 3 influences run the same pipeline with the missing slots zero-padded (joint 0,
 * weight 0) in the sign pass and skipped in the blends, 8 with 8 slots per vertex: vertex by
 * vertex, DQS ran 2 and 3 influences slower than 4 and 8 at a third of 4's speed. */
#define AKP_DQ_BLOCK_LOOP(fn, cor_neg)                                                     \
    AKP_AVX2 static void fn##_range(const akp_skin_ctx* c, size_t begin, size_t end) {     \
        const uint32_t neg = (cor_neg);                                                    \
        switch (c->k) {                                                                    \
        case 2: AKP_DQ_PIPELINE(fn, neg, 2u); break;                                       \
        case 3: AKP_DQ_PIPELINE(fn, neg, 3u); break;                                       \
        case 4: AKP_DQ_PIPELINE(fn, neg, 4u); break;                                       \
        case 8: AKP_DQ_PIPELINE(fn, neg, 8u); break;                                       \
        case 1: AKP_DQ_K_##fn(1u); break;                                                  \
        default: AKP_DQ_K_##fn(c->k); break; /* 5, 6, 7 */                                 \
        }                                                                                  \
    }
#define AKP_DQ_K_block_dqs(K) for (size_t i = begin; i < end; i += 8) block_dqs(c, i, (K), NULL)
#define AKP_DQ_K_block_cor(K) for (size_t i = begin; i < end; i += 8) block_cor(c, i, (K), NULL)
AKP_DQ_BLOCK_LOOP(block_dqs, 0u)
/* CoR: offset from joint 0's cor_rows to joint 0's negated rows (see akp_skin_cor_neg_rows) */
AKP_DQ_BLOCK_LOOP(block_cor, (uint32_t)(c->palette_count * sizeof(akp_skin_joint) - offsetof(akp_skin_joint, cor_rows)))

bool akp_skin_range_avx2(const akp_skin_ctx* c, size_t begin, size_t end) {
    if (c->do_tangents || !akp_skin_have_avx2()) return false;
    if (c->method != AK_SKIN_LBS && c->any_stretch) return false;
    /* DQS/CoR address their per-joint records with 32-bit offsets (CoR: past the whole
     * table); joint indices are 16-bit, so only absurd palettes get here, and take the
     * scalar code */
    if (c->method != AK_SKIN_LBS && c->palette_count > 65536u) return false;
    size_t blocks_end = begin + ((end - begin) & ~(size_t)7u);
    if (blocks_end > begin) {
        if (c->method == AK_SKIN_LBS) block_lbs_range(c, begin, blocks_end);
        else if (c->method == AK_SKIN_DQS) block_dqs_range(c, begin, blocks_end);
        else block_cor_range(c, begin, blocks_end);
    }
    if (blocks_end < end) akp_skin_range_scalar(c, blocks_end, end);
    return true;
}

#else /* no AVX2 kernel in this build */

bool akp_skin_have_avx2(void) { return false; }
bool akp_skin_range_avx2(const akp_skin_ctx* c, size_t begin, size_t end) {
    (void)c;
    (void)begin;
    (void)end;
    return false;
}

#endif

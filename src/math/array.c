/* Math functions over whole arrays. Each has a scalar reference loop (the inline function
 * per element) and, when src/simd.h selects SSE2, a 4-wide kernel that handles the bulk and
 * leaves the remainder to the scalar loop. The kernels follow the inline formulas term by
 * term, so both paths agree to float rounding. */
#include <animkit/math.h>

#include "simd.h"

/* Shared span checks: the spans' counts against the number n the function works on. */
static ak_result check_in(const void* ptr, size_t count, size_t n) {
    if (count > 0 && !ptr) return AK_ERR_NULL_ARG;
    return count < n ? AK_ERR_SPAN_SMALL : AK_OK;
}

#if AK_SIMD_SSE2
/* Four quaternions (AoS) transposed to x, y, z, w lanes. */
static inline void load_quat4(const ak_quat* q, __m128* x, __m128* y, __m128* z, __m128* w) {
    __m128 r0 = _mm_loadu_ps(&q[0].x), r1 = _mm_loadu_ps(&q[1].x);
    __m128 r2 = _mm_loadu_ps(&q[2].x), r3 = _mm_loadu_ps(&q[3].x);
    AKP_SIMD_TRANSPOSE4(r0, r1, r2, r3);
    *x = r0, *y = r1, *z = r2, *w = r3;
}
static inline void store_quat4(ak_quat* q, __m128 x, __m128 y, __m128 z, __m128 w) {
    AKP_SIMD_TRANSPOSE4(x, y, z, w);
    _mm_storeu_ps(&q[0].x, x);
    _mm_storeu_ps(&q[1].x, y);
    _mm_storeu_ps(&q[2].x, z);
    _mm_storeu_ps(&q[3].x, w);
}
#endif

ak_result ak_quat_normalize_array(ak_quat_cspan q, ak_quat_span out) {
    ak_result r = check_in(q.ptr, q.count, 0);
    if (r == AK_OK) r = check_in(out.ptr, out.count, q.count);
    if (r != AK_OK) return r;
    size_t i = 0;
#if AK_SIMD_SSE2
    const __m128 tiny = _mm_set1_ps(1e-30f), inf = _mm_set1_ps(INFINITY);
    const __m128 zero = _mm_setzero_ps(), one = _mm_set1_ps(1.0f);
    for (; i + 4 <= q.count; i += 4) {
        __m128 x, y, z, w;
        load_quat4(q.ptr + i, &x, &y, &z, &w);
        __m128 n2 = _mm_add_ps(_mm_add_ps(_mm_mul_ps(x, x), _mm_mul_ps(y, y)),
                               _mm_add_ps(_mm_mul_ps(z, z), _mm_mul_ps(w, w)));
        /* n2 > tiny is false for NaN, n2 < inf rejects infinity: ak_quat_normalize's test. */
        __m128 ok = _mm_and_ps(_mm_cmpgt_ps(n2, tiny), _mm_cmplt_ps(n2, inf));
        if (_mm_movemask_ps(_mm_cmpeq_ps(n2, inf))) {
            /* A norm overflowing float (or an infinite component): the scalar rescaling path. */
            for (size_t k = 0; k < 4; ++k) out.ptr[i + k] = ak_quat_normalize(q.ptr[i + k]);
            continue;
        }
        __m128 inv = _mm_div_ps(one, _mm_sqrt_ps(n2));
        x = akp_simd_select(ok, _mm_mul_ps(x, inv), zero);
        y = akp_simd_select(ok, _mm_mul_ps(y, inv), zero);
        z = akp_simd_select(ok, _mm_mul_ps(z, inv), zero);
        w = akp_simd_select(ok, _mm_mul_ps(w, inv), one);
        store_quat4(out.ptr + i, x, y, z, w);
    }
#endif
    for (; i < q.count; ++i) out.ptr[i] = ak_quat_normalize(q.ptr[i]);
    return AK_OK;
}

ak_result ak_quat_mul_array(ak_quat_cspan a, ak_quat_cspan b, ak_quat_span out) {
    ak_result r = check_in(a.ptr, a.count, 0);
    if (r == AK_OK) r = check_in(b.ptr, b.count, a.count);
    if (r == AK_OK) r = check_in(out.ptr, out.count, a.count);
    if (r != AK_OK) return r;
    size_t i = 0;
#if AK_SIMD_SSE2
    for (; i + 4 <= a.count; i += 4) {
        __m128 ax, ay, az, aw, bx, by, bz, bw;
        load_quat4(a.ptr + i, &ax, &ay, &az, &aw);
        load_quat4(b.ptr + i, &bx, &by, &bz, &bw);
        __m128 x = _mm_sub_ps(_mm_add_ps(_mm_add_ps(_mm_mul_ps(aw, bx), _mm_mul_ps(ax, bw)), _mm_mul_ps(ay, bz)),
                              _mm_mul_ps(az, by));
        __m128 y = _mm_add_ps(_mm_add_ps(_mm_sub_ps(_mm_mul_ps(aw, by), _mm_mul_ps(ax, bz)), _mm_mul_ps(ay, bw)),
                              _mm_mul_ps(az, bx));
        __m128 z = _mm_add_ps(_mm_sub_ps(_mm_add_ps(_mm_mul_ps(aw, bz), _mm_mul_ps(ax, by)), _mm_mul_ps(ay, bx)),
                              _mm_mul_ps(az, bw));
        __m128 w = _mm_sub_ps(_mm_sub_ps(_mm_sub_ps(_mm_mul_ps(aw, bw), _mm_mul_ps(ax, bx)), _mm_mul_ps(ay, by)),
                              _mm_mul_ps(az, bz));
        store_quat4(out.ptr + i, x, y, z, w);
    }
#endif
    for (; i < a.count; ++i) out.ptr[i] = ak_quat_mul(a.ptr[i], b.ptr[i]);
    return AK_OK;
}

#if AK_SIMD_SSE2
/* c = a x b on lanes. */
#define CROSS4(cx, cy, cz, ax, ay, az, bx, by, bz)                   \
    do {                                                             \
        cx = _mm_sub_ps(_mm_mul_ps(ay, bz), _mm_mul_ps(az, by));     \
        cy = _mm_sub_ps(_mm_mul_ps(az, bx), _mm_mul_ps(ax, bz));     \
        cz = _mm_sub_ps(_mm_mul_ps(ax, by), _mm_mul_ps(ay, bx));     \
    } while (0)
#endif

ak_result ak_quat_rotate_array(ak_quat_cspan q, ak_vec3_cspan v, ak_vec3_span out) {
    ak_result r = check_in(v.ptr, v.count, 0);
    int broadcast = q.count == 1 && v.count > 1;
    if (r == AK_OK) r = check_in(q.ptr, q.count, broadcast ? 1 : v.count);
    if (r == AK_OK) r = check_in(out.ptr, out.count, v.count);
    if (r != AK_OK) return r;
    size_t i = 0;
#if AK_SIMD_SSE2
    const __m128 two = _mm_set1_ps(2.0f);
    __m128 qx = _mm_setzero_ps(), qy = qx, qz = qx, qw = qx;
    if (broadcast) {
        qx = _mm_set1_ps(q.ptr[0].x), qy = _mm_set1_ps(q.ptr[0].y);
        qz = _mm_set1_ps(q.ptr[0].z), qw = _mm_set1_ps(q.ptr[0].w);
    }
    for (; i + 4 <= v.count; i += 4) {
        if (!broadcast) load_quat4(q.ptr + i, &qx, &qy, &qz, &qw);
        __m128 vx, vy, vz, tx, ty, tz, cx, cy, cz;
        akp_simd_load_vec3x4(&v.ptr[i].x, &vx, &vy, &vz);
        /* v + w t + u x t with t = 2 (u x v), as ak_quat_rotate. */
        CROSS4(tx, ty, tz, qx, qy, qz, vx, vy, vz);
        tx = _mm_mul_ps(tx, two), ty = _mm_mul_ps(ty, two), tz = _mm_mul_ps(tz, two);
        CROSS4(cx, cy, cz, qx, qy, qz, tx, ty, tz);
        vx = _mm_add_ps(_mm_add_ps(vx, _mm_mul_ps(tx, qw)), cx);
        vy = _mm_add_ps(_mm_add_ps(vy, _mm_mul_ps(ty, qw)), cy);
        vz = _mm_add_ps(_mm_add_ps(vz, _mm_mul_ps(tz, qw)), cz);
        akp_simd_store_vec3x4(&out.ptr[i].x, vx, vy, vz);
    }
#endif
    for (; i < v.count; ++i) out.ptr[i] = ak_quat_rotate(q.ptr[broadcast ? 0 : i], v.ptr[i]);
    return AK_OK;
}

ak_result ak_mat4_mul_array(ak_mat4_cspan a, ak_mat4_cspan b, ak_mat4_span out) {
    ak_result r = check_in(b.ptr, b.count, 0);
    int broadcast = a.count == 1 && b.count > 1;
    if (r == AK_OK) r = check_in(a.ptr, a.count, broadcast ? 1 : b.count);
    if (r == AK_OK) r = check_in(out.ptr, out.count, b.count);
    if (r != AK_OK) return r;
    /* A copy of the broadcast matrix, so that out may be the array a[0] lives in. */
    const ak_mat4 a0 = a.count > 0 ? a.ptr[0] : ak_mat4_identity();
#if AK_SIMD_SSE2
    for (size_t i = 0; i < b.count; ++i) {
        const float* am = broadcast ? a0.m : a.ptr[i].m;
        const float* bm = b.ptr[i].m;
        __m128 a0 = _mm_loadu_ps(am), a1 = _mm_loadu_ps(am + 4);
        __m128 a2 = _mm_loadu_ps(am + 8), a3 = _mm_loadu_ps(am + 12);
        __m128 c[4];
        /* Column c of the product is A times column c of B; all of B is read before any
         * store, so out may be b itself. */
        for (int col = 0; col < 4; ++col) {
            __m128 bc = _mm_loadu_ps(bm + 4 * col);
            c[col] = _mm_add_ps(_mm_add_ps(_mm_mul_ps(a0, AKP_SIMD_SPLAT(bc, 0)), _mm_mul_ps(a1, AKP_SIMD_SPLAT(bc, 1))),
                                _mm_add_ps(_mm_mul_ps(a2, AKP_SIMD_SPLAT(bc, 2)), _mm_mul_ps(a3, AKP_SIMD_SPLAT(bc, 3))));
        }
        float* om = out.ptr[i].m;
        for (int col = 0; col < 4; ++col) _mm_storeu_ps(om + 4 * col, c[col]);
    }
#else
    for (size_t i = 0; i < b.count; ++i) out.ptr[i] = ak_mat4_mul(broadcast ? a0 : a.ptr[i], b.ptr[i]);
#endif
    return AK_OK;
}

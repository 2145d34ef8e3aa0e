/* Simplex noise (Perlin 2001 as formulated by Gustavson 2005, "Simplex noise demystified"),
 * value noise and Worley cellular noise (Worley 1996, "A cellular texture basis function"). */
#include <math.h>
#include <string.h>

#include "noise_internal.h"

static bool all_finite(uint32_t dims, const float* p) {
    for (uint32_t k = 0; k < dims; ++k)
        if (!(fabsf(p[k]) < AKP_NOISE_LIMIT)) return false;
    return true;
}

static void zero_grad(float* g, uint32_t dims) {
    if (g)
        for (uint32_t k = 0; k < dims; ++k) g[k] = 0.0f;
}

/* ---- simplex ----------------------------------------------------------------------------- */

static const float simplex_g2[8][2] = {{1, 1}, {-1, 1}, {1, -1}, {-1, -1}, {1, 0}, {-1, 0}, {0, 1}, {0, -1}};
static const float simplex_g3[16][3] = {{1, 1, 0}, {-1, 1, 0}, {1, -1, 0}, {-1, -1, 0}, {1, 0, 1},  {-1, 0, 1},
                                        {1, 0, -1}, {-1, 0, -1}, {0, 1, 1}, {0, -1, 1}, {0, 1, -1}, {0, -1, -1},
                                        {1, 1, 0}, {0, -1, 1}, {-1, 1, 0}, {0, -1, -1}};

/* One corner's kernel (r0 - |d|^2)^4 (g . d) and its gradient t^4 g - 8 t^3 (g . d) d. */
static float simplex_corner(uint32_t dims, float r0, const float* d, const float* g, float* grad) {
    float r2 = 0.0f, gd = 0.0f;
    for (uint32_t k = 0; k < dims; ++k) r2 += d[k] * d[k], gd += g[k] * d[k];
    const float t = r0 - r2;
    if (t <= 0.0f) return 0.0f;
    const float t2 = t * t, t4 = t2 * t2;
    if (grad)
        for (uint32_t k = 0; k < dims; ++k) grad[k] += t4 * g[k] - 8.0f * t2 * t * gd * d[k];
    return t4 * gd;
}

/* simplex_corner's value without the branch (r0 = 1/2): where t <= 0 the term is t^4 gd with t
 * = 0, a zero of either sign instead of +0.0, which leaves the sum unchanged: the sum starts at
 * +0.0 and a round-to-nearest sum is -0.0 only when both terms are, so it is never -0.0, and
 * s + (+-0.0) is s. */
static inline __attribute__((always_inline)) float simplex_corner_value(uint32_t dims, const float* d, const float* g) {
    float r2 = 0.0f, gd = 0.0f;
    for (uint32_t k = 0; k < dims; ++k) r2 += d[k] * d[k], gd += g[k] * d[k];
    const float t = akp_max0(0.5f - r2);
    const float t2 = t * t;
    return t2 * t2 * gd;
}

float ak_noise_simplex2(const ak_noise* noise, float x, float y, float* out_gradient) {
    const float p[2] = {x, y};
    zero_grad(out_gradient, 2);
    if (!noise || !all_finite(2, p)) return 0.0f;
    const float F2 = 0.36602540378f, G2 = 0.2113248654f; /* (sqrt 3 - 1) / 2, (3 - sqrt 3) / 6 */
    const float s = (x + y) * F2;
    int ii, jj;
    const float fi = akp_floor(x + s, &ii), fj = akp_floor(y + s, &jj);
    const float t = (fi + fj) * G2;
    const float x0 = x - (fi - t), y0 = y - (fj - t);
    const int i1 = x0 > y0 ? 1 : 0, j1 = 1 - i1;
    ii &= 255, jj &= 255;
    const uint8_t* perm = noise->perm;
    const int h[3] = {perm[perm[ii] + jj], perm[perm[ii + i1] + jj + j1], perm[perm[ii + 1] + jj + 1]};
    const float d[3][2] = {{x0, y0}, {x0 - (float)i1 + G2, y0 - (float)j1 + G2}, {x0 - 1.0f + 2.0f * G2, y0 - 1.0f + 2.0f * G2}};
    float sum = 0.0f, g[2] = {0, 0};
    for (int c = 0; c < 3; ++c)
        sum += out_gradient ? simplex_corner(2, 0.5f, d[c], simplex_g2[h[c] & 7], g)
                            : simplex_corner_value(2, d[c], simplex_g2[h[c] & 7]);
    if (out_gradient) out_gradient[0] = 70.0f * g[0], out_gradient[1] = 70.0f * g[1];
    return 70.0f * sum;
}

/* simplex_corner_value for 3D with the offset in three scalars (an array here made gcc store
 * the floats one by one and load them back as a pair, a store-forwarding stall). */
static inline __attribute__((always_inline)) float simplex3_corner_value(float dx, float dy, float dz, const float* g) {
    const float r2 = ((0.0f + dx * dx) + dy * dy) + dz * dz;
    const float gd = ((0.0f + g[0] * dx) + g[1] * dy) + g[2] * dz;
    float t = 0.5f - r2;
    t = akp_max0(t); /* as simplex_corner_value: a zero term of either sign, no branch */
    const float t2 = t * t;
    return t2 * t2 * gd;
}

/* simplex3's o1 and o2 as floats, by (x0 >= y0) | (y0 >= z0) << 1 | (x0 >= z0) << 2 (two of the
 * eight cannot occur: the comparisons of finite floats are transitive). */
static const float simplex3_steps[8][2][3] = {
    {{0.0f, 0.0f, 1.0f}, {0.0f, 1.0f, 1.0f}},
    {{0.0f, 0.0f, 1.0f}, {1.0f, 0.0f, 1.0f}},
    {{0.0f, 1.0f, 0.0f}, {0.0f, 1.0f, 1.0f}},
    {{0.0f, 0.0f, 0.0f}, {1.0f, 1.0f, 1.0f}},
    {{0.0f, 0.0f, 0.0f}, {1.0f, 1.0f, 1.0f}},
    {{1.0f, 0.0f, 0.0f}, {1.0f, 0.0f, 1.0f}},
    {{0.0f, 1.0f, 0.0f}, {1.0f, 1.0f, 0.0f}},
    {{1.0f, 0.0f, 0.0f}, {1.0f, 1.0f, 0.0f}},
};

/* ak_noise_simplex3's value without the gradient for finite x, y, z: the same operations, the
 * corner offsets from simplex3_steps (no branches on the order: random points mispredict
 * them) and the corner terms from simplex3_corner_value. */
static inline __attribute__((always_inline)) float simplex3_value_v(const uint8_t* perm, float x, float y, float z,
                                                                    bool vex) {
    const float F3 = 1.0f / 3.0f, G3 = 1.0f / 6.0f;
    const float s = (x + y + z) * F3;
    int ii, jj, kk;
    /* a floor of -0.0 only when x, y and z are all -0.0; then fi - t is +0.0 with either zero */
    const float fi = vex ? akp_floor_unsigned_zero_vex(x + s, &ii) : akp_floor_unsigned_zero(x + s, &ii),
                fj = vex ? akp_floor_unsigned_zero_vex(y + s, &jj) : akp_floor_unsigned_zero(y + s, &jj),
                fk = vex ? akp_floor_unsigned_zero_vex(z + s, &kk) : akp_floor_unsigned_zero(z + s, &kk);
    const float t = (fi + fj + fk) * G3;
    const float x0 = x - (fi - t), y0 = y - (fj - t), z0 = z - (fk - t);
    const int xy = x0 >= y0, yz = y0 >= z0, xz = x0 >= z0;
    const float(*st)[3] = simplex3_steps[xy | yz << 1 | xz << 2];
    const int o1[3] = {xy & xz, (xy ^ 1) & yz, (xz ^ 1) & (yz ^ 1)};
    const int o2[3] = {xy | xz, (xy ^ 1) | yz, (xz ^ 1) | (yz ^ 1)};
    ii &= 255, jj &= 255, kk &= 255;
    const int h0 = perm[perm[perm[ii] + jj] + kk];
    const int h1 = perm[perm[perm[ii + o1[0]] + jj + o1[1]] + kk + o1[2]];
    const int h2 = perm[perm[perm[ii + o2[0]] + jj + o2[1]] + kk + o2[2]];
    const int h3 = perm[perm[perm[ii + 1] + jj + 1] + kk + 1];
    const float k1 = 1.0f * G3, k2 = 2.0f * G3, k3 = 3.0f * G3;
    float sum = 0.0f;
    sum += simplex3_corner_value(x0 - 0.0f + 0.0f, y0 - 0.0f + 0.0f, z0 - 0.0f + 0.0f, simplex_g3[h0 & 15]);
    sum += simplex3_corner_value(x0 - st[0][0] + k1, y0 - st[0][1] + k1, z0 - st[0][2] + k1, simplex_g3[h1 & 15]);
    sum += simplex3_corner_value(x0 - st[1][0] + k2, y0 - st[1][1] + k2, z0 - st[1][2] + k2, simplex_g3[h2 & 15]);
    sum += simplex3_corner_value(x0 - 1.0f + k3, y0 - 1.0f + k3, z0 - 1.0f + k3, simplex_g3[h3 & 15]);
    return 76.0f * sum;
}

static inline __attribute__((always_inline)) float simplex3_value(const uint8_t* perm, float x, float y, float z) {
    return simplex3_value_v(perm, x, y, z, false);
}
#ifdef AKP_HAVE_VEX
/* the VEX build (AKP_VEX, noise_internal.h), chosen where the CPU has AVX */
AKP_VEX static __attribute__((noinline)) float simplex3_value_vex(const uint8_t* perm, float x, float y, float z) {
    return simplex3_value_v(perm, x, y, z, true);
}
#endif

/* ak_noise_simplex3 with the gradient at a finite point, out of line (the value-only call
 * then needs no frame for its registers). */
static __attribute__((noinline)) float simplex3_grad(const ak_noise* noise, float x, float y, float z,
                                                     float* out_gradient) {
    const float F3 = 1.0f / 3.0f, G3 = 1.0f / 6.0f;
    const float s = (x + y + z) * F3;
    int ii, jj, kk;
    const float fi = akp_floor(x + s, &ii), fj = akp_floor(y + s, &jj), fk = akp_floor(z + s, &kk);
    const float t = (fi + fj + fk) * G3;
    const float x0 = x - (fi - t), y0 = y - (fj - t), z0 = z - (fk - t);
    /* the simplex: the order of x0, y0, z0 from largest to smallest, as Gustavson's six
     * branches give it (the comparisons of finite floats are transitive, so o1 is the
     * largest axis, o2 the two largest), without branches: random points mispredict them */
    const int xy = x0 >= y0, yz = y0 >= z0, xz = x0 >= z0;
    const int o1[3] = {xy & xz, (xy ^ 1) & yz, (xz ^ 1) & (yz ^ 1)};
    const int o2[3] = {xy | xz, (xy ^ 1) | yz, (xz ^ 1) | (yz ^ 1)};
    ii &= 255, jj &= 255, kk &= 255;
    const uint8_t* perm = noise->perm;
    const int offs[4][3] = {{0, 0, 0}, {o1[0], o1[1], o1[2]}, {o2[0], o2[1], o2[2]}, {1, 1, 1}};
    float sum = 0.0f, g[3] = {0, 0, 0};
    for (int c = 0; c < 4; ++c) {
        const int h = perm[perm[perm[ii + offs[c][0]] + jj + offs[c][1]] + kk + offs[c][2]];
        const float k = (float)c * G3;
        const float d[3] = {x0 - (float)offs[c][0] + k, y0 - (float)offs[c][1] + k, z0 - (float)offs[c][2] + k};
        sum += simplex_corner(3, 0.5f, d, simplex_g3[h & 15], out_gradient ? g : NULL);
    }
    if (out_gradient)
        for (int k = 0; k < 3; ++k) out_gradient[k] = 76.0f * g[k];
    return 76.0f * sum;
}

float ak_noise_simplex3(const ak_noise* noise, float x, float y, float z, float* out_gradient) {
    const float p[3] = {x, y, z};
    if (!out_gradient) {
        if (!noise || !all_finite(3, p)) return 0.0f;
#ifdef AKP_HAVE_VEX
        if (__builtin_cpu_supports("avx")) return simplex3_value_vex(noise->perm, x, y, z);
#endif
        return simplex3_value(noise->perm, x, y, z);
    }
    zero_grad(out_gradient, 3);
    if (!noise || !all_finite(3, p)) return 0.0f;
    return simplex3_grad(noise, x, y, z, out_gradient);
}

/* ---- value noise --------------------------------------------------------------------------- */

static inline float fade(float t) { return t * t * t * (t * (t * 6.0f - 15.0f) + 10.0f); }
static inline float dfade(float t) { return 30.0f * t * t * (t * (t - 2.0f) + 1.0f); }

/* value_of[h] = (float)h / 127.5f - 1.0f, the corner value of hash h, written out (hex floats,
 * exact) so that a corner costs a load instead of a division; the SIMD kernels divide and get
 * the same bits (test_noise compares them). */
static const float value_of[256] = {
    -0x1p+0f, -0x1.fbfbfcp-1f, -0x1.f7f7f8p-1f, -0x1.f3f3f4p-1f, -0x1.efeffp-1f, -0x1.ebebecp-1f,
    -0x1.e7e7e8p-1f, -0x1.e3e3e4p-1f, -0x1.dfdfep-1f, -0x1.dbdbdcp-1f, -0x1.d7d7d8p-1f, -0x1.d3d3d4p-1f,
    -0x1.cfcfdp-1f, -0x1.cbcbccp-1f, -0x1.c7c7c8p-1f, -0x1.c3c3c4p-1f, -0x1.bfbfcp-1f, -0x1.bbbbbcp-1f,
    -0x1.b7b7b8p-1f, -0x1.b3b3b4p-1f, -0x1.afafbp-1f, -0x1.ababacp-1f, -0x1.a7a7a8p-1f, -0x1.a3a3a4p-1f,
    -0x1.9f9fap-1f, -0x1.9b9b9cp-1f, -0x1.979798p-1f, -0x1.939394p-1f, -0x1.8f8f9p-1f, -0x1.8b8b8cp-1f,
    -0x1.878788p-1f, -0x1.838384p-1f, -0x1.7f7f8p-1f, -0x1.7b7b7cp-1f, -0x1.777778p-1f, -0x1.737374p-1f,
    -0x1.6f6f7p-1f, -0x1.6b6b6cp-1f, -0x1.676768p-1f, -0x1.636364p-1f, -0x1.5f5f6p-1f, -0x1.5b5b5cp-1f,
    -0x1.575758p-1f, -0x1.535354p-1f, -0x1.4f4f5p-1f, -0x1.4b4b4cp-1f, -0x1.474748p-1f, -0x1.434344p-1f,
    -0x1.3f3f4p-1f, -0x1.3b3b3cp-1f, -0x1.373738p-1f, -0x1.333334p-1f, -0x1.2f2f3p-1f, -0x1.2b2b2cp-1f,
    -0x1.272728p-1f, -0x1.232324p-1f, -0x1.1f1f2p-1f, -0x1.1b1b1cp-1f, -0x1.171718p-1f, -0x1.131314p-1f,
    -0x1.0f0f1p-1f, -0x1.0b0b0cp-1f, -0x1.070708p-1f, -0x1.030304p-1f, -0x1.fdfdfcp-2f, -0x1.f5f5f4p-2f,
    -0x1.ededecp-2f, -0x1.e5e5e4p-2f, -0x1.dddddcp-2f, -0x1.d5d5d4p-2f, -0x1.cdcdccp-2f, -0x1.c5c5c4p-2f,
    -0x1.bdbdbcp-2f, -0x1.b5b5b4p-2f, -0x1.adadacp-2f, -0x1.a5a5a4p-2f, -0x1.9d9d9cp-2f, -0x1.959594p-2f,
    -0x1.8d8d8cp-2f, -0x1.858584p-2f, -0x1.7d7d7cp-2f, -0x1.757574p-2f, -0x1.6d6d6cp-2f, -0x1.656564p-2f,
    -0x1.5d5d5cp-2f, -0x1.555554p-2f, -0x1.4d4d4cp-2f, -0x1.454544p-2f, -0x1.3d3d3cp-2f, -0x1.353534p-2f,
    -0x1.2d2d2cp-2f, -0x1.252524p-2f, -0x1.1d1d1cp-2f, -0x1.151514p-2f, -0x1.0d0d0cp-2f, -0x1.050504p-2f,
    -0x1.f9f9f8p-3f, -0x1.e9e9e8p-3f, -0x1.d9d9d8p-3f, -0x1.c9c9c8p-3f, -0x1.b9b9b8p-3f, -0x1.a9a9a8p-3f,
    -0x1.999998p-3f, -0x1.898988p-3f, -0x1.797978p-3f, -0x1.696968p-3f, -0x1.595958p-3f, -0x1.494948p-3f,
    -0x1.393938p-3f, -0x1.292928p-3f, -0x1.191918p-3f, -0x1.090908p-3f, -0x1.f1f1fp-4f, -0x1.d1d1dp-4f,
    -0x1.b1b1bp-4f, -0x1.91919p-4f, -0x1.71717p-4f, -0x1.51515p-4f, -0x1.31313p-4f, -0x1.11111p-4f,
    -0x1.e1e1ep-5f, -0x1.a1a1ap-5f, -0x1.61616p-5f, -0x1.21212p-5f, -0x1.c1c1cp-6f, -0x1.41414p-6f,
    -0x1.81818p-7f, -0x1.0101p-8f, 0x1.0102p-8f, 0x1.8182p-7f, 0x1.41418p-6f, 0x1.c1c2p-6f,
    0x1.21214p-5f, 0x1.61618p-5f, 0x1.a1a1cp-5f, 0x1.e1e2p-5f, 0x1.11112p-4f, 0x1.31314p-4f,
    0x1.51516p-4f, 0x1.71718p-4f, 0x1.9191ap-4f, 0x1.b1b1cp-4f, 0x1.d1d1ep-4f, 0x1.f1f2p-4f,
    0x1.09091p-3f, 0x1.19192p-3f, 0x1.29293p-3f, 0x1.39394p-3f, 0x1.49495p-3f, 0x1.59596p-3f,
    0x1.69697p-3f, 0x1.79798p-3f, 0x1.89899p-3f, 0x1.9999ap-3f, 0x1.a9a9bp-3f, 0x1.b9b9cp-3f,
    0x1.c9c9dp-3f, 0x1.d9d9ep-3f, 0x1.e9e9fp-3f, 0x1.f9fap-3f, 0x1.050508p-2f, 0x1.0d0d1p-2f,
    0x1.151518p-2f, 0x1.1d1d2p-2f, 0x1.252528p-2f, 0x1.2d2d3p-2f, 0x1.353538p-2f, 0x1.3d3d4p-2f,
    0x1.454548p-2f, 0x1.4d4d5p-2f, 0x1.555558p-2f, 0x1.5d5d6p-2f, 0x1.656568p-2f, 0x1.6d6d7p-2f,
    0x1.757578p-2f, 0x1.7d7d8p-2f, 0x1.858588p-2f, 0x1.8d8d9p-2f, 0x1.959598p-2f, 0x1.9d9dap-2f,
    0x1.a5a5a8p-2f, 0x1.adadbp-2f, 0x1.b5b5b8p-2f, 0x1.bdbdcp-2f, 0x1.c5c5c8p-2f, 0x1.cdcddp-2f,
    0x1.d5d5d8p-2f, 0x1.ddddep-2f, 0x1.e5e5e8p-2f, 0x1.ededfp-2f, 0x1.f5f5f8p-2f, 0x1.fdfep-2f,
    0x1.030304p-1f, 0x1.070708p-1f, 0x1.0b0b0cp-1f, 0x1.0f0f1p-1f, 0x1.131314p-1f, 0x1.171718p-1f,
    0x1.1b1b1cp-1f, 0x1.1f1f2p-1f, 0x1.232324p-1f, 0x1.272728p-1f, 0x1.2b2b2cp-1f, 0x1.2f2f3p-1f,
    0x1.333334p-1f, 0x1.373738p-1f, 0x1.3b3b3cp-1f, 0x1.3f3f4p-1f, 0x1.434344p-1f, 0x1.474748p-1f,
    0x1.4b4b4cp-1f, 0x1.4f4f5p-1f, 0x1.535354p-1f, 0x1.575758p-1f, 0x1.5b5b5cp-1f, 0x1.5f5f6p-1f,
    0x1.636364p-1f, 0x1.676768p-1f, 0x1.6b6b6cp-1f, 0x1.6f6f7p-1f, 0x1.737374p-1f, 0x1.777778p-1f,
    0x1.7b7b7cp-1f, 0x1.7f7f8p-1f, 0x1.838384p-1f, 0x1.878788p-1f, 0x1.8b8b8cp-1f, 0x1.8f8f9p-1f,
    0x1.939394p-1f, 0x1.979798p-1f, 0x1.9b9b9cp-1f, 0x1.9f9fap-1f, 0x1.a3a3a4p-1f, 0x1.a7a7a8p-1f,
    0x1.ababacp-1f, 0x1.afafbp-1f, 0x1.b3b3b4p-1f, 0x1.b7b7b8p-1f, 0x1.bbbbbcp-1f, 0x1.bfbfcp-1f,
    0x1.c3c3c4p-1f, 0x1.c7c7c8p-1f, 0x1.cbcbccp-1f, 0x1.cfcfdp-1f, 0x1.d3d3d4p-1f, 0x1.d7d7d8p-1f,
    0x1.dbdbdcp-1f, 0x1.dfdfep-1f, 0x1.e3e3e4p-1f, 0x1.e7e7e8p-1f, 0x1.ebebecp-1f, 0x1.efeffp-1f,
    0x1.f3f3f4p-1f, 0x1.f7f7f8p-1f, 0x1.fbfbfcp-1f, 0x1p+0f,
};

/* Value noise with a constant dims (inlined per dimension) and the gradient only when asked
 * for (it does not change the value). */
static inline __attribute__((always_inline)) float value_nv(const ak_noise* noise, uint32_t dims, const float* point,
                                                            float* out_gradient, bool vex) {
    int lo[4], hi[4];
    float f[4];
#pragma GCC unroll 4
    for (uint32_t k = 0; k < dims; ++k) {
        int i;
        f[k] = vex ? akp_floor_frac_vex(point[k], &i) : akp_floor_frac(point[k], &i);
        lo[k] = i & 255;
        hi[k] = (i + 1) & 255;
    }
    const uint32_t corners = 1u << dims;
    /* corner c (bit k: hi along axis k) hashes perm[...perm[perm[x_c] + y_c]... + w_c], the
     * shared prefixes looked up once (2 + 4 + 8 loads in 3D instead of 24) */
    uint32_t hash[16] = {0}; /* unsigned: the index arithmetic needs no sign extension */
#pragma GCC unroll 4
    for (uint32_t k = 0, count = 1; k < dims; ++k, count *= 2)
#pragma GCC unroll 8
        for (uint32_t c = 0; c < count; ++c) {
            hash[c + count] = noise->perm[hash[c] + (uint32_t)hi[k]];
            hash[c] = noise->perm[hash[c] + (uint32_t)lo[k]];
        }
    float val[16], gv[16][4];
#pragma GCC unroll 16
    for (uint32_t c = 0; c < corners; ++c) {
        val[c] = value_of[hash[c]];
        if (out_gradient)
            for (uint32_t m = 0; m < dims; ++m) gv[c][m] = 0.0f;
    }
#pragma GCC unroll 4
    for (uint32_t k = 0; k < dims; ++k) {
        const float t = fade(f[k]);
        const float dt = out_gradient ? dfade(f[k]) : 0.0f;
        const uint32_t step = 1u << k;
#pragma GCC unroll 8
        for (uint32_t c = 0; c < corners; c += 2u * step) {
            const float a = val[c], b = val[c + step];
            val[c] = a + t * (b - a);
            if (out_gradient) {
                for (uint32_t m = 0; m < dims; ++m) gv[c][m] = gv[c][m] + t * (gv[c + step][m] - gv[c][m]);
                gv[c][k] += (b - a) * dt;
            }
        }
    }
    if (out_gradient)
        for (uint32_t m = 0; m < dims; ++m) out_gradient[m] = gv[0][m];
    /* fminf(fmaxf(v, -1), 1) for the finite v here, without the libm calls */
    const float v = val[0];
    /* written as max then min, which gcc makes maxss and minss (the nested ?: was a compare and
     * branch before a minss); the same value for every v but NaN, which never comes here */
    const float v1 = v > -1.0f ? v : -1.0f;
    return v1 < 1.0f ? v1 : 1.0f;
}

static inline __attribute__((always_inline)) float value_n(const ak_noise* noise, uint32_t dims, const float* point,
                                                           float* out_gradient) {
    return value_nv(noise, dims, point, out_gradient, false);
}

/* The value-only paths of 2D and 3D, each its own compiled body (no derivative work, and
 * not sharing one function's registers with the other seven variants), and again in the VEX
 * build (AKP_VEX, noise_internal.h) for CPUs with AVX: value 3D per point 1.08x -> 0.94x
 * FastNoiseLite's time (docs/BENCHMARKS.md, noise). */
static __attribute__((noinline)) float value2_value(const ak_noise* noise, const float* point) {
    return value_n(noise, 2, point, NULL);
}
static __attribute__((noinline)) float value3_value(const ak_noise* noise, const float* point) {
    return value_n(noise, 3, point, NULL);
}
#ifdef AKP_HAVE_VEX
AKP_VEX static __attribute__((noinline)) float value2_value_vex(const ak_noise* noise, const float* point) {
    return value_nv(noise, 2, point, NULL, true);
}
AKP_VEX static __attribute__((noinline)) float value3_value_vex(const ak_noise* noise, const float* point) {
    return value_nv(noise, 3, point, NULL, true);
}
#endif

/* ak_noise_value's every case (the public function keeps the common one in front). */
static __attribute__((noinline)) float value_any(const ak_noise* noise, uint32_t dimensions, const float* point,
                                                 float* out_gradient) {
    if (dimensions < 1 || dimensions > 4) return 0.0f;
    zero_grad(out_gradient, dimensions);
    if (!noise || !point || !all_finite(dimensions, point)) return 0.0f;
    switch (dimensions) {
    case 1: return out_gradient ? value_n(noise, 1, point, out_gradient) : value_n(noise, 1, point, NULL);
    case 2: return out_gradient ? value_n(noise, 2, point, out_gradient) : value2_value(noise, point);
    case 3: return out_gradient ? value_n(noise, 3, point, out_gradient) : value3_value(noise, point);
    default: return out_gradient ? value_n(noise, 4, point, out_gradient) : value_n(noise, 4, point, NULL);
    }
}

float ak_noise_value(const ak_noise* noise, uint32_t dimensions, const float* point, float* out_gradient) {
    /* The value alone in 2D or 3D, the common call, first: with every variant inlined here the
     * function pushed five registers and set up a stack frame on every call. */
    if (!out_gradient && noise && point && (dimensions == 2 || dimensions == 3)) {
        if (!all_finite(dimensions, point)) return 0.0f;
#ifdef AKP_HAVE_VEX
        if (__builtin_cpu_supports("avx"))
            return dimensions == 3 ? value3_value_vex(noise, point) : value2_value_vex(noise, point);
#endif
        return dimensions == 3 ? value3_value(noise, point) : value2_value(noise, point);
    }
    return value_any(noise, dimensions, point, out_gradient);
}

float akp_value_baseline(const ak_noise* noise, uint32_t dims, const float* p) {
    return dims == 3 ? value3_value(noise, p) : value2_value(noise, p);
}

/* ---- Worley ------------------------------------------------------------------------------- */

/* A 32-bit hash of a cell and the seed (murmur3 finaliser over a linear mix). */
static uint32_t cell_hash(const int* cell, uint32_t dims, uint64_t seed) {
    uint32_t h = (uint32_t)seed * 0x9E3779B1u ^ (uint32_t)(seed >> 32);
    static const uint32_t mul[3] = {0x8DA6B343u, 0xD8163841u, 0xCB1AB31Fu};
    for (uint32_t k = 0; k < dims; ++k) h ^= (uint32_t)cell[k] * mul[k];
    h ^= h >> 16;
    h *= 0x85EBCA6Bu;
    h ^= h >> 13;
    h *= 0xC2B2AE35u;
    h ^= h >> 16;
    return h;
}

/* The nearest (d1, near) and second nearest (d2) squared distances found so far. */
typedef struct worley_best {
    float d1, d2, near[3];
} worley_best;

/* Visit the cell base + off: its feature point, then the running minimum with strict "<" (the
 * first of equal distances stays; written as selects, which give the branches' values). h is
 * the cell's hash. */
/* The offset dv = f - (feature point of the cell at offset off, hash h) and its squared
 * length. */
static inline __attribute__((always_inline)) float worley_offset(uint32_t dims, uint32_t h, const float* f,
                                                                 const int* off, float* dv) {
    float dist2 = 0.0f;
    for (uint32_t k = 0; k < dims; ++k) {
        /* The feature point's coordinate k in the cell is (m + 1/2) / 1024, m = bits 10 k ..
         * 10 k + 9 of h; off[k] + that is exact in float, and equals (1 + (2 m + 1) / 2048) -
         * (1 - off[k]), whose first term is the float with exponent 0 and m in mantissa bits
         * 13..22 (one bit operation instead of a conversion, a multiply and two adds). */
        const uint32_t bits = 0x3F801000u | ((h >> (10 * k)) & 1023u) << 13;
        float fp;
        memcpy(&fp, &bits, sizeof fp);
        dv[k] = f[k] - (fp - (float)(1 - off[k]));
        dist2 += dv[k] * dv[k];
    }
    return dist2;
}

/* Visit a cell: the running minimum with strict "<" (the first of equal distances stays). */
static inline __attribute__((always_inline)) void worley_visit(uint32_t dims, uint32_t h, const float* f,
                                                               const int* off, worley_best* b) {
    float dv[3] = {0, 0, 0};
    const float dist2 = worley_offset(dims, h, f, off, dv);
    if (dist2 < b->d1) {
        b->d2 = b->d1;
        b->d1 = dist2;
        memcpy(b->near, dv, sizeof dv);
    } else if (dist2 < b->d2) {
        b->d2 = dist2;
    }
}

/* Rings 0 and 1 (the 3^dims cells around the point): ring 0 first, then ring 1 in the order
 * c = 0, 1, ... (axis 0 fastest), each axis's share cell_k * mul_k of cell_hash computed once.
 * The updates are selects: d1 = min(d1, dist2), d2 = min(max(dist2, d1), d2) and the step of
 * the nearest cell (kept on strict "<") are the values of worley_visit's branches; the nearest
 * offset is computed again at the end. Inlined with a constant dims; the SIMD kernels
 * (simd_body.h) visit the same cells in the same order without skipping any (a skipped cell
 * cannot change the result). */
static inline __attribute__((always_inline)) void worley_near_rings(uint32_t dims, uint64_t seed, const int* base,
                                                                    const float* f, bool want_f2, worley_best* b) {
    static const uint32_t mul[3] = {0x8DA6B343u, 0xD8163841u, 0xCB1AB31Fu};
    const uint32_t seed_mix = (uint32_t)seed * 0x9E3779B1u ^ (uint32_t)(seed >> 32);
    uint32_t axis[3][3] = {{0, 0, 0}, {0, 0, 0}, {0, 0, 0}};
    for (uint32_t k = 0; k < dims; ++k)
        for (int o = 0; o < 3; ++o) axis[k][o] = (uint32_t)(base[k] + o - 1) * mul[k];
    const int cells = dims == 1 ? 3 : dims == 2 ? 9 : 27, center = cells / 2;
    /* gap[k][o]: the squared distance along axis k from the point to the cell at offset o - 1
     * (f^2, 0, (1 - f)^2); a cell whose sum is at least the distance that matters (F1, or F2
     * when asked for) cannot change the result (its feature point is farther by at least
     * 1/2048 along each such axis) and is skipped. */
    float gap[3][3] = {{0, 0, 0}, {0, 0, 0}, {0, 0, 0}};
    for (uint32_t k = 0; k < dims; ++k) {
        const float e = 1.0f - f[k];
        gap[k][0] = f[k] * f[k];
        gap[k][2] = e * e;
    }
    float d1 = b->d1, d2 = b->d2;
    int best = 0;
    uint32_t best_h = 0;
#pragma GCC unroll 27
    for (int step = 0; step < cells; ++step) {
        const int c = step == 0 ? center : step <= center ? step - 1 : step;
        const int o[3] = {c % 3, c / 3 % 3, c / 9};
        if (step > 0) {
            float lower = 0.0f;
            for (uint32_t k = 0; k < dims; ++k) lower += gap[k][o[k]];
            if (lower >= (want_f2 ? d2 : d1)) continue;
        }
        uint32_t h = seed_mix;
        for (uint32_t k = 0; k < dims; ++k) h ^= axis[k][o[k]];
        h ^= h >> 16;
        h *= 0x85EBCA6Bu;
        h ^= h >> 13;
        h *= 0xC2B2AE35u;
        h ^= h >> 16;
        const int off[3] = {o[0] - 1, o[1] - 1, o[2] - 1};
        float dv[3];
        const float dist2 = worley_offset(dims, h, f, off, dv);
        const bool closer = dist2 < d1;
        best = closer ? c : best;
        best_h = closer ? h : best_h;
        const float hi = dist2 > d1 ? dist2 : d1;
        d2 = hi < d2 ? hi : d2;
        d1 = closer ? dist2 : d1;
    }
    const int off[3] = {best % 3 - 1, best / 3 % 3 - 1, best / 9 - 1};
    float dv[3] = {0, 0, 0};
    worley_offset(dims, best_h, f, off, dv);
    memcpy(b->near, dv, sizeof dv);
    b->d1 = d1;
    b->d2 = d2;
}

/* Rings 0 and 1 for F1 alone (no F2 asked for): worley_near_rings's nearest cell without the
 * second distance and without skipping cells (random points mispredict the skip test; a cell
 * it passes over is not closer). The running minimum with strict "<" in visiting order is the
 * first cell in that order among those at the least distance; it is kept here as three running
 * minima over the first, second and last third of the visiting order (three short dependency
 * chains instead of one of 27 compares), merged in order, a later third winning only when
 * strictly closer: the same cell and the same d1. */
static inline __attribute__((always_inline)) void worley_f1_rings(uint32_t dims, uint64_t seed, const int* base,
                                                                  const float* f, worley_best* b) {
    static const uint32_t mul[3] = {0x8DA6B343u, 0xD8163841u, 0xCB1AB31Fu};
    const uint32_t seed_mix = (uint32_t)seed * 0x9E3779B1u ^ (uint32_t)(seed >> 32);
    uint32_t axis[3][3] = {{0, 0, 0}, {0, 0, 0}, {0, 0, 0}};
    for (uint32_t k = 0; k < dims; ++k)
        for (int o = 0; o < 3; ++o) axis[k][o] = (uint32_t)(base[k] + o - 1) * mul[k];
    const int cells = dims == 1 ? 3 : dims == 2 ? 9 : 27, center = cells / 2;
    float d1[3] = {b->d1, b->d1, b->d1};
    int best[3] = {0, 0, 0};
    uint32_t best_h[3] = {0, 0, 0};
#pragma GCC unroll 27
    for (int step = 0; step < cells; ++step) {
        const int c = step == 0 ? center : step <= center ? step - 1 : step;
        const int o[3] = {c % 3, c / 3 % 3, c / 9};
        const int chain = step * 3 / cells;
        uint32_t h = seed_mix;
        for (uint32_t k = 0; k < dims; ++k) h ^= axis[k][o[k]];
        h ^= h >> 16;
        h *= 0x85EBCA6Bu;
        h ^= h >> 13;
        h *= 0xC2B2AE35u;
        h ^= h >> 16;
        const int off[3] = {o[0] - 1, o[1] - 1, o[2] - 1};
        float dv[3];
        const float dist2 = worley_offset(dims, h, f, off, dv);
        /* selects as masks: gcc turned the ?: forms into branches */
        const uint32_t m = 0u - (uint32_t)(dist2 < d1[chain]);
        best[chain] = (int)(((uint32_t)c & m) | ((uint32_t)best[chain] & ~m));
        best_h[chain] = (h & m) | (best_h[chain] & ~m);
        d1[chain] = dist2 < d1[chain] ? dist2 : d1[chain];
    }
#pragma GCC unroll 2
    for (int chain = 1; chain < 3; ++chain) {
        const bool closer = d1[chain] < d1[0];
        best[0] = closer ? best[chain] : best[0];
        best_h[0] = closer ? best_h[chain] : best_h[0];
        d1[0] = closer ? d1[chain] : d1[0];
    }
    const int off[3] = {best[0] % 3 - 1, best[0] / 3 % 3 - 1, best[0] / 9 - 1};
    float dv[3] = {0, 0, 0};
    worley_offset(dims, best_h[0], f, off, dv);
    memcpy(b->near, dv, sizeof dv);
    b->d1 = d1[0];
}

/* Rings 2 to 6, when rings 0 and 1 left a nearest (or second nearest, want_f2) distance that
 * a farther cell could beat: ring r holds the cells at Chebyshev distance r from the point's
 * cell; their feature points are at least (r - 1) + margin (+ 1/2048) away, so the search
 * stops once that exceeds F2 (or F1 when F2 is not asked for: a farther cell cannot change the
 * nearest). Rare, so out of line. */
static __attribute__((noinline)) void worley_far_rings(uint32_t dims, uint64_t seed, const int* base, const float* f,
                                                       float margin, bool want_f2, worley_best* b) {
    for (int r = 2; r <= 6; ++r) {
        const float bound = (float)(r - 1) + margin;
        if (bound * bound >= (want_f2 ? b->d2 : b->d1)) break;
        const int span = 2 * r + 1;
        const int cells = dims == 1 ? span : dims == 2 ? span * span : span * span * span;
        for (int c = 0; c < cells; ++c) {
            int off[3] = {0, 0, 0}, cc = c, cheb = 0;
            for (uint32_t k = 0; k < dims; ++k) {
                off[k] = cc % span - r;
                cc /= span;
                cheb = off[k] < 0 ? (-off[k] > cheb ? -off[k] : cheb) : (off[k] > cheb ? off[k] : cheb);
            }
            if (cheb != r) continue;
            int cell[3];
            for (uint32_t k = 0; k < dims; ++k) cell[k] = base[k] + off[k];
            worley_visit(dims, cell_hash(cell, dims, seed), f, off, b);
        }
    }
}

/* Worley noise at a finite point with a constant dims and want_f2 (out_f2 != NULL) when
 * inlined: rings 0 and 1 (worley_near_rings, or worley_f1_rings for F1 alone), then the far
 * rings when they could matter. */
static inline __attribute__((always_inline)) float worley_n(const ak_noise* noise, uint32_t dims, bool want_f2,
                                                            const float* point, float* out_f2, float* out_gradient) {
    int base[3] = {0, 0, 0};
    float f[3] = {0, 0, 0}, margin = 1.0f;
    for (uint32_t k = 0; k < dims; ++k) {
        f[k] = akp_floor_frac(point[k], &base[k]);
        const float g = f[k] < 1.0f - f[k] ? f[k] : 1.0f - f[k]; /* fminf without the libm call */
        margin = g < margin ? g : margin;
    }
    worley_best b = {INFINITY, INFINITY, {0, 0, 0}};
    if (want_f2) worley_near_rings(dims, noise->seed, base, f, true, &b);
#ifdef AKP_HAVE_POINT_AVX2
    /* the value alone (no nearest offset to keep): the cells in AVX2 lanes */
    else if (dims >= 2 && !out_gradient && __builtin_cpu_supports("avx2"))
        b.d1 = akp_worley_d1_avx2(dims, noise->seed, base, f);
#endif
    else worley_f1_rings(dims, noise->seed, base, f, &b);
    const float bound = 1.0f + margin; /* ring 2's */
    if (bound * bound < (want_f2 ? b.d2 : b.d1)) worley_far_rings(dims, noise->seed, base, f, margin, want_f2, &b);
    const float f1 = sqrtf(b.d1);
    if (want_f2) *out_f2 = sqrtf(b.d2);
    if (out_gradient && f1 > 0.0f)
        for (uint32_t k = 0; k < dims; ++k) out_gradient[k] = b.near[k] / f1;
    return f1;
}

/* One compiled body per dimension and F2 choice (a single body holding all six was not
 * unrolled as well). */
#define AKP_WORLEY_VARIANT(name, dims, want_f2)                                                                    \
    static __attribute__((noinline)) float name(const ak_noise* noise, const float* point, float* out_f2,          \
                                                float* out_gradient) {                                             \
        return worley_n(noise, dims, want_f2, point, out_f2, out_gradient);                                        \
    }
/* F1 alone and no gradient: the common call */
static __attribute__((noinline)) float worley3_value(const ak_noise* noise, const float* point) {
    return worley_n(noise, 3, false, point, NULL, NULL);
}
static __attribute__((noinline)) float worley2_value(const ak_noise* noise, const float* point) {
    return worley_n(noise, 2, false, point, NULL, NULL);
}
AKP_WORLEY_VARIANT(worley1_f1, 1, false)
AKP_WORLEY_VARIANT(worley2_f1, 2, false)
AKP_WORLEY_VARIANT(worley3_f1, 3, false)
AKP_WORLEY_VARIANT(worley1_f2, 1, true)
AKP_WORLEY_VARIANT(worley2_f2, 2, true)
AKP_WORLEY_VARIANT(worley3_f2, 3, true)

float ak_noise_worley(const ak_noise* noise, uint32_t dimensions, const float* point, float* out_f2,
                      float* out_gradient) {
    if (dimensions < 1 || dimensions > 3) {
        if (out_f2) *out_f2 = 0.0f;
        return 0.0f;
    }
    zero_grad(out_gradient, dimensions);
    if (out_f2) *out_f2 = 0.0f;
    if (!noise || !point || !all_finite(dimensions, point)) return 0.0f;
    switch (dimensions) {
    case 1:
        return out_f2 ? worley1_f2(noise, point, out_f2, out_gradient)
                      : worley1_f1(noise, point, NULL, out_gradient);
    case 2:
        return out_f2         ? worley2_f2(noise, point, out_f2, out_gradient)
               : out_gradient ? worley2_f1(noise, point, NULL, out_gradient)
                              : worley2_value(noise, point);
    default:
        return out_f2         ? worley3_f2(noise, point, out_f2, out_gradient)
               : out_gradient ? worley3_f1(noise, point, NULL, out_gradient)
                              : worley3_value(noise, point);
    }
}

/* ---- fBm over simplex, value and Worley noise ---------------------------------------------- */

/* One octave's basis value, as fractal.c's basis_eval gives it without gradient. */
static inline __attribute__((always_inline)) float basis_value(const ak_noise* noise, ak_noise_basis basis,
                                                               uint32_t dims, const float* q, bool vex) {
    switch (basis) {
    case AK_NOISE_BASIS_SIMPLEX:
        if (dims == 3) return all_finite(3, q) ? simplex3_value(noise->perm, q[0], q[1], q[2]) : 0.0f;
        return ak_noise_simplex2(noise, q[0], dims == 1 ? 0.0f : q[1], NULL);
    case AK_NOISE_BASIS_VALUE: return all_finite(dims, q) ? value_nv(noise, dims, q, NULL, vex) : 0.0f;
    default: return all_finite(dims, q) ? worley_n(noise, dims, false, q, NULL, NULL) : 0.0f;
    }
}

static inline __attribute__((always_inline)) float fbm_other_n(const ak_noise* noise, const ak_fractal_desc* d,
                                                               ak_noise_basis basis, uint32_t dims, const float* p,
                                                               bool vex) {
    float freq = d->frequency, amp = 1.0f, sum = 0.0f;
    const float lacunarity = d->lacunarity, gain = d->gain;
    for (uint32_t o = 0; o < d->octaves; ++o) {
        float q[4];
#pragma GCC unroll 4
        for (uint32_t k = 0; k < dims; ++k) q[k] = p[k] * freq;
        sum = sum + amp * basis_value(noise, basis, dims, q, vex);
        freq = freq * lacunarity;
        amp = amp * gain;
    }
    return sum;
}

/* One compiled body per basis and dimension. */
#define AKP_FBM_OTHER(name, basis, dims)                                                            \
    static __attribute__((noinline)) float name(const ak_noise* noise, const ak_fractal_desc* d,   \
                                                const float* p) {                                  \
        return fbm_other_n(noise, d, basis, dims, p, false);                                       \
    }
AKP_FBM_OTHER(fbm_simplex1, AK_NOISE_BASIS_SIMPLEX, 1)
AKP_FBM_OTHER(fbm_simplex2, AK_NOISE_BASIS_SIMPLEX, 2)
AKP_FBM_OTHER(fbm_simplex3, AK_NOISE_BASIS_SIMPLEX, 3)
AKP_FBM_OTHER(fbm_value1, AK_NOISE_BASIS_VALUE, 1)
AKP_FBM_OTHER(fbm_value2, AK_NOISE_BASIS_VALUE, 2)
AKP_FBM_OTHER(fbm_value3, AK_NOISE_BASIS_VALUE, 3)
AKP_FBM_OTHER(fbm_value4, AK_NOISE_BASIS_VALUE, 4)
AKP_FBM_OTHER(fbm_worley1, AK_NOISE_BASIS_WORLEY, 1)
AKP_FBM_OTHER(fbm_worley2, AK_NOISE_BASIS_WORLEY, 2)
AKP_FBM_OTHER(fbm_worley3, AK_NOISE_BASIS_WORLEY, 3)
#ifdef AKP_HAVE_VEX
/* fBm over value noise in 2D/3D, the VEX build (as value3_value_vex) */
AKP_VEX static __attribute__((noinline)) float fbm_value2_vex(const ak_noise* noise, const ak_fractal_desc* d,
                                                              const float* p) {
    return fbm_other_n(noise, d, AK_NOISE_BASIS_VALUE, 2, p, true);
}
AKP_VEX static __attribute__((noinline)) float fbm_value3_vex(const ak_noise* noise, const ak_fractal_desc* d,
                                                              const float* p) {
    return fbm_other_n(noise, d, AK_NOISE_BASIS_VALUE, 3, p, true);
}
#endif

float akp_fbm_value_baseline(const ak_noise* noise, const ak_fractal_desc* d, uint32_t dims, const float* p) {
    return dims == 3 ? fbm_value3(noise, d, p) : fbm_value2(noise, d, p);
}

float akp_fbm_other(const ak_noise* noise, const ak_fractal_desc* d, uint32_t dims, const float* p) {
    switch (d->basis) {
    case AK_NOISE_BASIS_SIMPLEX:
        return dims == 1 ? fbm_simplex1(noise, d, p) : dims == 2 ? fbm_simplex2(noise, d, p) : fbm_simplex3(noise, d, p);
    case AK_NOISE_BASIS_VALUE:
#ifdef AKP_HAVE_VEX
        if ((dims == 2 || dims == 3) && __builtin_cpu_supports("avx"))
            return dims == 3 ? fbm_value3_vex(noise, d, p) : fbm_value2_vex(noise, d, p);
#endif
        return dims == 1   ? fbm_value1(noise, d, p)
               : dims == 2 ? fbm_value2(noise, d, p)
               : dims == 3 ? fbm_value3(noise, d, p)
                           : fbm_value4(noise, d, p);
    default:
        return dims == 1 ? fbm_worley1(noise, d, p) : dims == 2 ? fbm_worley2(noise, d, p) : fbm_worley3(noise, d, p);
    }
}

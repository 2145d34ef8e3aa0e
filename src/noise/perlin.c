/* Perlin's improved gradient noise (Perlin 2002, "Improving Noise", SIGGRAPH), 1D to 4D, its
 * analytic gradient and the periodic variant; the seeded permutation.
 *
 * One generic lattice routine serves every dimension: the 2^N corner hashes are
 * perm[perm[perm[ix] + iy] + iz]... (Perlin's A/AA/AB chain written for any N), the corner
 * values are gradient . offset, and the corners are blended axis by axis in Perlin's order (x
 * first, then y, z, w) with the quintic fade. The gradient rides along the same blend:
 * lerp(t, a, b) has derivative lerp(t, da, db) + (b - a) dt. The SIMD kernels (simd_body.h)
 * repeat these float operations in the same order, so all give the same bits. */
#include <math.h>
#include <string.h>

#include "noise_internal.h"

/* Perlin's permutation from the reference implementation (ImprovedNoise, 2002). */
static const uint8_t perlin_permutation[256] = {
    151, 160, 137, 91,  90,  15,  131, 13,  201, 95,  96,  53,  194, 233, 7,   225, 140, 36,  103, 30,  69,  142,
    8,   99,  37,  240, 21,  10,  23,  190, 6,   148, 247, 120, 234, 75,  0,   26,  197, 62,  94,  252, 219, 203,
    117, 35,  11,  32,  57,  177, 33,  88,  237, 149, 56,  87,  174, 20,  125, 136, 171, 168, 68,  175, 74,  165,
    71,  134, 139, 48,  27,  166, 77,  146, 158, 231, 83,  111, 229, 122, 60,  211, 133, 230, 220, 105, 92,  41,
    55,  46,  245, 40,  244, 102, 143, 54,  65,  25,  63,  161, 1,   216, 80,  73,  209, 76,  132, 187, 208, 89,
    18,  169, 200, 196, 135, 130, 116, 188, 159, 86,  164, 100, 109, 198, 173, 186, 3,   64,  52,  217, 226, 250,
    124, 123, 5,   202, 38,  147, 118, 126, 255, 82,  85,  212, 207, 206, 59,  227, 47,  16,  58,  17,  182, 189,
    28,  42,  223, 183, 170, 213, 119, 248, 152, 2,   44,  154, 163, 70,  221, 153, 101, 155, 167, 43,  172, 9,
    129, 22,  39,  253, 19,  98,  108, 110, 79,  113, 224, 232, 178, 185, 112, 104, 218, 246, 97,  228, 251, 34,
    242, 193, 238, 210, 144, 12,  191, 179, 162, 241, 81,  51,  145, 235, 249, 14,  239, 107, 49,  192, 214, 31,
    181, 199, 106, 157, 184, 84,  204, 176, 115, 121, 50,  45,  127, 4,   150, 254, 138, 236, 205, 93,  222, 114,
    67,  29,  24,  72,  243, 141, 128, 195, 78,  66,  215, 61,  156, 180,
};

ak_noise ak_noise_make(uint64_t seed) {
    ak_noise n;
    memset(&n, 0, sizeof n);
    n.seed = seed;
    if (seed == 0) {
        memcpy(n.perm, perlin_permutation, 256);
    } else {
        for (int i = 0; i < 256; ++i) n.perm[i] = (uint8_t)i;
        ak_rng rng = ak_rng_make(seed);
        for (int i = 255; i > 0; --i) {
            uint32_t j = ak_rng_u32(&rng) % (uint32_t)(i + 1);
            uint8_t t = n.perm[i];
            n.perm[i] = n.perm[j];
            n.perm[j] = t;
        }
    }
    memcpy(n.perm + 256, n.perm, 256);
    return n;
}

static inline float fade(float t) { return t * t * t * (t * (t * 6.0f - 15.0f) + 10.0f); }
/* d/dt fade = 30 t^2 (t - 1)^2 */
static inline float dfade(float t) { return 30.0f * t * t * (t * (t - 2.0f) + 1.0f); }
static inline float lerp(float t, float a, float b) { return a + t * (b - a); }

/* Gradient tables by hash: corner value = sign_u * d[index_u] + sign_v * d[index_v] (3D, 2D;
 * 2D's axis gradients read the zero in d[2] as v), which is Perlin's (+-u) + (+-v) bit for bit
 * (multiplying by -1 is an exact negation, signed zeros included) without branches. */
static const uint8_t g3_u[16] = {0, 0, 0, 0, 0, 0, 0, 0, 1, 1, 1, 1, 1, 1, 1, 1}, g3_v[16] = {1, 1, 1, 1, 2, 2, 2, 2, 2, 2, 2, 2, 0, 2, 0, 2};
static const float g3_su[16] = {1.0f, -1.0f, 1.0f, -1.0f, 1.0f, -1.0f, 1.0f, -1.0f, 1.0f, -1.0f, 1.0f, -1.0f, 1.0f, -1.0f, 1.0f, -1.0f};
static const float g3_sv[16] = {1.0f, 1.0f, -1.0f, -1.0f, 1.0f, 1.0f, -1.0f, -1.0f, 1.0f, 1.0f, -1.0f, -1.0f, 1.0f, 1.0f, -1.0f, -1.0f};
static const uint8_t g2_u[8] = {0, 0, 0, 0, 0, 0, 1, 1}, g2_v[8] = {1, 1, 1, 1, 2, 2, 2, 2};
static const float g2_su[8] = {1.0f, -1.0f, 1.0f, -1.0f, 1.0f, -1.0f, 1.0f, -1.0f}, g2_sv[8] = {1.0f, 1.0f, -1.0f, -1.0f, 1.0f, 1.0f, -1.0f, -1.0f};
/* 4D: the three non-zero slots in order and their signs. */
static const uint8_t g4_i[32][3] = {{1, 2, 3}, {1, 2, 3}, {1, 2, 3}, {1, 2, 3}, {1, 2, 3}, {1, 2, 3}, {1, 2, 3}, {1, 2, 3}, {0, 2, 3}, {0, 2, 3}, {0, 2, 3}, {0, 2, 3}, {0, 2, 3}, {0, 2, 3}, {0, 2, 3}, {0, 2, 3}, {0, 1, 3}, {0, 1, 3}, {0, 1, 3}, {0, 1, 3}, {0, 1, 3}, {0, 1, 3}, {0, 1, 3}, {0, 1, 3}, {0, 1, 2}, {0, 1, 2}, {0, 1, 2}, {0, 1, 2}, {0, 1, 2}, {0, 1, 2}, {0, 1, 2}, {0, 1, 2}};
static const float g4_s[32][3] = {{1.0f, 1.0f, 1.0f}, {-1.0f, 1.0f, 1.0f}, {1.0f, -1.0f, 1.0f}, {-1.0f, -1.0f, 1.0f}, {1.0f, 1.0f, -1.0f}, {-1.0f, 1.0f, -1.0f}, {1.0f, -1.0f, -1.0f}, {-1.0f, -1.0f, -1.0f}, {1.0f, 1.0f, 1.0f}, {-1.0f, 1.0f, 1.0f}, {1.0f, -1.0f, 1.0f}, {-1.0f, -1.0f, 1.0f}, {1.0f, 1.0f, -1.0f}, {-1.0f, 1.0f, -1.0f}, {1.0f, -1.0f, -1.0f}, {-1.0f, -1.0f, -1.0f}, {1.0f, 1.0f, 1.0f}, {-1.0f, 1.0f, 1.0f}, {1.0f, -1.0f, 1.0f}, {-1.0f, -1.0f, 1.0f}, {1.0f, 1.0f, -1.0f}, {-1.0f, 1.0f, -1.0f}, {1.0f, -1.0f, -1.0f}, {-1.0f, -1.0f, -1.0f}, {1.0f, 1.0f, 1.0f}, {-1.0f, 1.0f, 1.0f}, {1.0f, -1.0f, 1.0f}, {-1.0f, -1.0f, 1.0f}, {1.0f, 1.0f, -1.0f}, {-1.0f, 1.0f, -1.0f}, {1.0f, -1.0f, -1.0f}, {-1.0f, -1.0f, -1.0f}};

/* g . d with Perlin's operation order for 3D ((+-u) + (+-v)); 2D the same with v = 0 for the
 * axis gradients; 1D g x; 4D ((a + b) + c) over the three non-zero slots. d has room for a
 * zero in d[dims] (2D reads it). */
static inline float corner_dot(uint32_t dims, int h, const float* d) {
    switch (dims) {
    case 1: {
        const float s = (float)(1 + (h & 7)) * 0.25f;
        return ((h & 8) ? -s : s) * d[0];
    }
    case 2: h &= 7; return g2_su[h] * d[g2_u[h]] + g2_sv[h] * d[g2_v[h]];
    case 3: h &= 15; return g3_su[h] * d[g3_u[h]] + g3_sv[h] * d[g3_v[h]];
    default:
        h &= 31;
        return (g4_s[h][0] * d[g4_i[h][0]] + g4_s[h][1] * d[g4_i[h][1]]) + g4_s[h][2] * d[g4_i[h][2]];
    }
}

/* The same gradients as vectors (for the analytic gradient). */
static const float g3_vec[16][3] = {{1.0f, 1.0f, 0.0f}, {-1.0f, 1.0f, 0.0f}, {1.0f, -1.0f, 0.0f}, {-1.0f, -1.0f, 0.0f}, {1.0f, 0.0f, 1.0f}, {-1.0f, 0.0f, 1.0f}, {1.0f, 0.0f, -1.0f}, {-1.0f, 0.0f, -1.0f}, {0.0f, 1.0f, 1.0f}, {0.0f, -1.0f, 1.0f}, {0.0f, 1.0f, -1.0f}, {0.0f, -1.0f, -1.0f}, {1.0f, 1.0f, 0.0f}, {0.0f, -1.0f, 1.0f}, {-1.0f, 1.0f, 0.0f}, {0.0f, -1.0f, -1.0f}};
static const float g2_vec[8][2] = {{1.0f, 1.0f}, {-1.0f, 1.0f}, {1.0f, -1.0f}, {-1.0f, -1.0f}, {1.0f, 0.0f}, {-1.0f, 0.0f}, {0.0f, 1.0f}, {0.0f, -1.0f}};

/* Gradient of corner hash h in `dims` dimensions as a vector g (components -1..1, or the 1D
 * slope). */
static inline void corner_gradient(uint32_t dims, int h, float* g) {
    switch (dims) {
    case 1: {
        const float s = (float)(1 + (h & 7)) * 0.25f;
        g[0] = (h & 8) ? -s : s;
        break;
    }
    case 2: memcpy(g, g2_vec[h & 7], 2 * sizeof(float)); break;
    case 3: memcpy(g, g3_vec[h & 15], 3 * sizeof(float)); break;
    default:
        h &= 31;
        g[0] = g[1] = g[2] = g[3] = 0.0f;
        for (int k = 0; k < 3; ++k) g[g4_i[h][k]] = g4_s[h][k];
        break;
    }
}

/* Loops over dimensions and corners are unrolled (dims is a constant in every caller), so the
 * corner values stay in registers. */
#define AKP_PRAGMA(x) _Pragma(#x)
#define AKP_UNROLL AKP_PRAGMA(GCC unroll 16)

/* The lattice routine: lo[k], hi[k] the wrapped lattice indices (0..255) of the cell's two
 * corners along axis k, f[k] the fractional offset in [0, 1). */
static inline __attribute__((always_inline)) float lattice(const uint8_t* perm, uint32_t dims, const int* lo,
                                                           const int* hi, const float* f, float* grad) {
    float val[16], gv[16][4];
    const uint32_t corners = 1u << dims;
    /* Perlin's hash chain, shared between corners: level k holds the 2^(k+1) partial hashes */
    int hash[16];
    hash[0] = perm[lo[0]];
    hash[1] = perm[hi[0]];
    AKP_UNROLL
    for (uint32_t k = 1; k < dims; ++k) {
        const uint32_t half = 1u << k;
        AKP_UNROLL
        for (uint32_t c = 0; c < half; ++c) {
            hash[c + half] = perm[hash[c] + hi[k]];
            hash[c] = perm[hash[c] + lo[k]];
        }
    }
    AKP_UNROLL
    for (uint32_t c = 0; c < corners; ++c) {
        float d[5] = {0, 0, 0, 0, 0};
        AKP_UNROLL
        for (uint32_t k = 0; k < dims; ++k) d[k] = ((c >> k) & 1u) ? f[k] - 1.0f : f[k];
        val[c] = corner_dot(dims, hash[c], d);
        if (grad) corner_gradient(dims, hash[c], gv[c]);
    }
    AKP_UNROLL
    for (uint32_t k = 0; k < dims; ++k) {
        const float t = fade(f[k]);
        const float dt = grad ? dfade(f[k]) : 0.0f;
        const uint32_t step = 1u << k;
        AKP_UNROLL
        for (uint32_t c = 0; c < corners; c += 2u * step) {
            const float a = val[c], b = val[c + step];
            val[c] = lerp(t, a, b);
            if (grad) {
                AKP_UNROLL
                for (uint32_t m = 0; m < dims; ++m) gv[c][m] = lerp(t, gv[c][m], gv[c + step][m]);
                gv[c][k] = gv[c][k] + (b - a) * dt;
            }
        }
    }
    if (grad)
        AKP_UNROLL
        for (uint32_t m = 0; m < dims; ++m) grad[m] = gv[0][m];
    return val[0];
}

/* The value-only lattice of 2D and 3D (no gradient asked for): the same corner values with
 * fewer loads. slots[c][h] names, for corner c and hash h, the two terms of Perlin's
 * (+-u) + (+-v) in a 16-float table D of the corner offsets: D[2 k + b] = f[k] - b (axis k,
 * corner bit b; 2D's slot for axis 2 holds the zero its axis gradients read), D[8 + i] =
 * -D[i]; low nibble the u term, high nibble the v term. D[u] + D[v] is the sign-times-offset
 * sum of corner_dot exactly (multiplying by -1 is negation); generated from g3_u/g3_v
 * (g2_u/g2_v) and the sign bits h & 1 (u) and h & 2 (v). */
static const uint8_t corner_slots3[8][16] = {
    {0x20, 0x28, 0xA0, 0xA8, 0x40, 0x48, 0xC0, 0xC8, 0x42, 0x4A, 0xC2, 0xCA, 0x02, 0x4A, 0x82, 0xCA},
    {0x21, 0x29, 0xA1, 0xA9, 0x41, 0x49, 0xC1, 0xC9, 0x42, 0x4A, 0xC2, 0xCA, 0x12, 0x4A, 0x92, 0xCA},
    {0x30, 0x38, 0xB0, 0xB8, 0x40, 0x48, 0xC0, 0xC8, 0x43, 0x4B, 0xC3, 0xCB, 0x03, 0x4B, 0x83, 0xCB},
    {0x31, 0x39, 0xB1, 0xB9, 0x41, 0x49, 0xC1, 0xC9, 0x43, 0x4B, 0xC3, 0xCB, 0x13, 0x4B, 0x93, 0xCB},
    {0x20, 0x28, 0xA0, 0xA8, 0x50, 0x58, 0xD0, 0xD8, 0x52, 0x5A, 0xD2, 0xDA, 0x02, 0x5A, 0x82, 0xDA},
    {0x21, 0x29, 0xA1, 0xA9, 0x51, 0x59, 0xD1, 0xD9, 0x52, 0x5A, 0xD2, 0xDA, 0x12, 0x5A, 0x92, 0xDA},
    {0x30, 0x38, 0xB0, 0xB8, 0x50, 0x58, 0xD0, 0xD8, 0x53, 0x5B, 0xD3, 0xDB, 0x03, 0x5B, 0x83, 0xDB},
    {0x31, 0x39, 0xB1, 0xB9, 0x51, 0x59, 0xD1, 0xD9, 0x53, 0x5B, 0xD3, 0xDB, 0x13, 0x5B, 0x93, 0xDB},
};
static const uint8_t corner_slots2[4][8] = {
    {0x20, 0x28, 0xA0, 0xA8, 0x40, 0x48, 0xC2, 0xCA},
    {0x21, 0x29, 0xA1, 0xA9, 0x41, 0x49, 0xC2, 0xCA},
    {0x30, 0x38, 0xB0, 0xB8, 0x40, 0x48, 0xC3, 0xCB},
    {0x31, 0x39, 0xB1, 0xB9, 0x41, 0x49, 0xC3, 0xCB},
};

static inline __attribute__((always_inline)) float lattice_value(const uint8_t* perm, uint32_t dims, const int* lo,
                                                                 const int* hi, const float* f) {
    uint32_t hash[8]; /* unsigned: the index arithmetic needs no sign extension */
    hash[0] = perm[lo[0]];
    hash[1] = perm[hi[0]];
    AKP_UNROLL
    for (uint32_t k = 1; k < dims; ++k) {
        const uint32_t half = 1u << k;
        AKP_UNROLL
        for (uint32_t c = 0; c < half; ++c) {
            hash[c + half] = perm[hash[c] + (uint32_t)hi[k]];
            hash[c] = perm[hash[c] + (uint32_t)lo[k]];
        }
    }
    float D[16] = {0};
    AKP_UNROLL
    for (uint32_t k = 0; k < dims; ++k) D[2 * k] = f[k], D[2 * k + 1] = f[k] - 1.0f;
    AKP_UNROLL
    for (int i = 0; i < 8; ++i) D[8 + i] = -D[i];
    float val[8];
    const uint32_t corners = 1u << dims;
    AKP_UNROLL
    for (uint32_t c = 0; c < corners; ++c) {
        const uint32_t s = dims == 3 ? corner_slots3[c][hash[c] & 15] : corner_slots2[c][hash[c] & 7];
        val[c] = D[s & 15u] + D[s >> 4];
    }
    AKP_UNROLL
    for (uint32_t k = 0; k < dims; ++k) {
        const float t = fade(f[k]);
        const uint32_t step = 1u << k;
        AKP_UNROLL
        for (uint32_t c = 0; c < corners; c += 2u * step) val[c] = lerp(t, val[c], val[c + step]);
    }
    return val[0];
}

static inline __attribute__((always_inline)) float perlin_nv(const ak_noise* noise, uint32_t dims, const float* p,
                                                             const int* period, float* grad, bool vex) {
    int lo[4], hi[4];
    float f[4];
    AKP_UNROLL
    for (uint32_t k = 0; k < dims; ++k) {
        if (!(fabsf(p[k]) < AKP_NOISE_LIMIT)) {
            if (grad)
                AKP_UNROLL
                for (uint32_t m = 0; m < dims; ++m) grad[m] = 0.0f;
            return 0.0f;
        }
        int i;
        f[k] = vex ? akp_floor_frac_vex(p[k], &i) : akp_floor_frac(p[k], &i);
        if (period) {
            const int per = period[k];
            int w = i % per;
            if (w < 0) w += per;
            lo[k] = w;
            hi[k] = w + 1 == per ? 0 : w + 1;
        } else {
            lo[k] = i & 255;
            hi[k] = (i + 1) & 255;
        }
    }
    if (!grad && (dims == 2 || dims == 3)) return lattice_value(noise->perm, dims, lo, hi, f);
    return lattice(noise->perm, dims, lo, hi, f, grad);
}

static inline __attribute__((always_inline)) float perlin_n(const ak_noise* noise, uint32_t dims, const float* p,
                                                            const int* period, float* grad) {
    return perlin_nv(noise, dims, p, period, grad, false);
}

float ak_noise_perlin1(const ak_noise* noise, float x, float* out_gradient) {
    if (!noise) {
        if (out_gradient) out_gradient[0] = 0.0f;
        return 0.0f;
    }
    const float p[1] = {x};
    return perlin_n(noise, 1, p, NULL, out_gradient);
}

/* 2D and 3D with the gradient, out of line: the value-only call then needs no frame for the
 * gradient's registers (ak_noise_perlin3 pushed six and reserved 192 bytes per call). */
static __attribute__((noinline)) float perlin2_grad(const ak_noise* noise, const float* p, float* grad) {
    return perlin_n(noise, 2, p, NULL, grad);
}
static __attribute__((noinline)) float perlin3_grad(const ak_noise* noise, const float* p, float* grad) {
    return perlin_n(noise, 3, p, NULL, grad);
}

float ak_noise_perlin2(const ak_noise* noise, float x, float y, float* out_gradient) {
    if (!noise) {
        if (out_gradient) out_gradient[0] = out_gradient[1] = 0.0f;
        return 0.0f;
    }
    const float p[2] = {x, y};
    return out_gradient ? perlin2_grad(noise, p, out_gradient) : perlin_n(noise, 2, p, NULL, NULL);
}

float ak_noise_perlin3(const ak_noise* noise, float x, float y, float z, float* out_gradient) {
    if (!noise) {
        if (out_gradient) out_gradient[0] = out_gradient[1] = out_gradient[2] = 0.0f;
        return 0.0f;
    }
    const float p[3] = {x, y, z};
    return out_gradient ? perlin3_grad(noise, p, out_gradient) : perlin_n(noise, 3, p, NULL, NULL);
}

float ak_noise_perlin4(const ak_noise* noise, float x, float y, float z, float w, float* out_gradient) {
    if (!noise) {
        if (out_gradient) out_gradient[0] = out_gradient[1] = out_gradient[2] = out_gradient[3] = 0.0f;
        return 0.0f;
    }
    const float p[4] = {x, y, z, w};
    return perlin_n(noise, 4, p, NULL, out_gradient);
}

float ak_noise_perlin_periodic(const ak_noise* noise, uint32_t dimensions, const float* point, const int* period,
                               float* out_gradient) {
    bool ok = noise && point && period && dimensions >= 1 && dimensions <= 4;
    for (uint32_t k = 0; ok && k < dimensions; ++k) ok = period[k] >= 1 && period[k] <= 256;
    if (!ok) {
        if (out_gradient && dimensions <= 4)
            for (uint32_t k = 0; k < dimensions; ++k) out_gradient[k] = 0.0f;
        return 0.0f;
    }
    switch (dimensions) {
    case 1: return perlin_n(noise, 1, point, period, out_gradient);
    case 2: return perlin_n(noise, 2, point, period, out_gradient);
    case 3: return perlin_n(noise, 3, point, period, out_gradient);
    default: return perlin_n(noise, 4, point, period, out_gradient);
    }
}

/* fBm over Perlin noise with a constant dims (akp_fbm_perlin). */
static inline __attribute__((always_inline)) float fbm_perlin_n(const ak_noise* noise, const ak_fractal_desc* d,
                                                                uint32_t dims, const float* p, bool vex) {
    float freq = d->frequency, amp = 1.0f, sum = 0.0f;
    const float lacunarity = d->lacunarity, gain = d->gain;
    for (uint32_t o = 0; o < d->octaves; ++o) {
        float q[4];
        AKP_UNROLL
        for (uint32_t k = 0; k < dims; ++k) q[k] = p[k] * freq;
        sum = sum + amp * perlin_nv(noise, dims, q, NULL, NULL, vex);
        freq = freq * lacunarity;
        amp = amp * gain;
    }
    return sum;
}

/* fBm over Perlin noise with its gradient (octaves()'s FBM branch: the same operations). */
static inline __attribute__((always_inline)) float fbm_perlin_grad_n(const ak_noise* noise, const ak_fractal_desc* d,
                                                                     uint32_t dims, const float* p, float* grad) {
    float freq = d->frequency, amp = 1.0f, sum = 0.0f, gs[4] = {0, 0, 0, 0};
    const float lacunarity = d->lacunarity, gain = d->gain;
    for (uint32_t o = 0; o < d->octaves; ++o) {
        float q[4], g[4];
        AKP_UNROLL
        for (uint32_t k = 0; k < dims; ++k) q[k] = p[k] * freq;
        const float n = perlin_n(noise, dims, q, NULL, g);
        sum = sum + amp * n;
        AKP_UNROLL
        for (uint32_t k = 0; k < dims; ++k) gs[k] = gs[k] + (amp * freq) * g[k];
        freq = freq * lacunarity;
        amp = amp * gain;
    }
    AKP_UNROLL
    for (uint32_t k = 0; k < dims; ++k) grad[k] = gs[k];
    return sum;
}

static __attribute__((noinline)) float fbm_perlin2_grad(const ak_noise* noise, const ak_fractal_desc* d,
                                                        const float* p, float* grad) {
    return fbm_perlin_grad_n(noise, d, 2, p, grad);
}
static __attribute__((noinline)) float fbm_perlin3_grad(const ak_noise* noise, const ak_fractal_desc* d,
                                                        const float* p, float* grad) {
    return fbm_perlin_grad_n(noise, d, 3, p, grad);
}

float akp_fbm_perlin_grad(const ak_noise* noise, const ak_fractal_desc* d, uint32_t dims, const float* p,
                          float* grad) {
    return dims == 2 ? fbm_perlin2_grad(noise, d, p, grad) : fbm_perlin3_grad(noise, d, p, grad);
}

/* One compiled body per dimension (sharing one function cost the loop its registers). */
#define AKP_FBM_PERLIN(name, dims)                                                                  \
    static __attribute__((noinline)) float name(const ak_noise* noise, const ak_fractal_desc* d,   \
                                                const float* p) {                                  \
        return fbm_perlin_n(noise, d, dims, p, false);                                             \
    }
AKP_FBM_PERLIN(fbm_perlin1, 1)
AKP_FBM_PERLIN(fbm_perlin2, 2)
AKP_FBM_PERLIN(fbm_perlin3, 3)
AKP_FBM_PERLIN(fbm_perlin4, 4)
#ifdef AKP_HAVE_VEX
/* 2D and 3D again in the VEX build (noise_internal.h, AKP_VEX), chosen where the CPU has AVX */
AKP_VEX static __attribute__((noinline)) float fbm_perlin2_vex(const ak_noise* noise, const ak_fractal_desc* d,
                                                               const float* p) {
    return fbm_perlin_n(noise, d, 2, p, true);
}
AKP_VEX static __attribute__((noinline)) float fbm_perlin3_vex(const ak_noise* noise, const ak_fractal_desc* d,
                                                               const float* p) {
    return fbm_perlin_n(noise, d, 3, p, true);
}
#endif

float akp_fbm_perlin_baseline(const ak_noise* noise, const ak_fractal_desc* d, uint32_t dims, const float* p) {
    return dims == 3 ? fbm_perlin3(noise, d, p) : fbm_perlin2(noise, d, p);
}

float akp_fbm_perlin(const ak_noise* noise, const ak_fractal_desc* d, uint32_t dims, const float* p) {
#ifdef AKP_HAVE_VEX
    if ((dims == 2 || dims == 3) && __builtin_cpu_supports("avx"))
        return dims == 3 ? fbm_perlin3_vex(noise, d, p) : fbm_perlin2_vex(noise, d, p);
#endif
    switch (dims) {
    case 1: return fbm_perlin1(noise, d, p);
    case 2: return fbm_perlin2(noise, d, p);
    case 3: return fbm_perlin3(noise, d, p);
    default: return fbm_perlin4(noise, d, p);
    }
}

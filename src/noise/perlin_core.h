/* The Perlin lattice routine shared by perlin.c (the public functions) and fractal.c (the
 * octave loop, so the scalar batch path inlines it). See perlin.c for the scheme. */
#ifndef ANIMKIT_PERLIN_CORE_H
#define ANIMKIT_PERLIN_CORE_H

#include <math.h>
#include <string.h>

#include "noise_internal.h"

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
    for (uint32_t k = 1; k < dims; ++k) {
        const uint32_t half = 1u << k;
        for (uint32_t c = 0; c < half; ++c) {
            hash[c + half] = perm[hash[c] + hi[k]];
            hash[c] = perm[hash[c] + lo[k]];
        }
    }
    for (uint32_t c = 0; c < corners; ++c) {
        float d[5] = {0, 0, 0, 0, 0};
        for (uint32_t k = 0; k < dims; ++k) d[k] = ((c >> k) & 1u) ? f[k] - 1.0f : f[k];
        val[c] = corner_dot(dims, hash[c], d);
        if (grad) corner_gradient(dims, hash[c], gv[c]);
    }
    for (uint32_t k = 0; k < dims; ++k) {
        const float t = fade(f[k]);
        const float dt = grad ? dfade(f[k]) : 0.0f;
        const uint32_t step = 1u << k;
        for (uint32_t c = 0; c < corners; c += 2u * step) {
            const float a = val[c], b = val[c + step];
            val[c] = lerp(t, a, b);
            if (grad) {
                for (uint32_t m = 0; m < dims; ++m) gv[c][m] = lerp(t, gv[c][m], gv[c + step][m]);
                gv[c][k] = gv[c][k] + (b - a) * dt;
            }
        }
    }
    if (grad)
        for (uint32_t m = 0; m < dims; ++m) grad[m] = gv[0][m];
    return val[0];
}

static inline __attribute__((always_inline)) float perlin_n(const ak_noise* noise, uint32_t dims, const float* p,
                                                            const int* period, float* grad) {
    int lo[4], hi[4];
    float f[4];
    for (uint32_t k = 0; k < dims; ++k) {
        if (!(fabsf(p[k]) < AKP_NOISE_LIMIT)) {
            if (grad)
                for (uint32_t m = 0; m < dims; ++m) grad[m] = 0.0f;
            return 0.0f;
        }
        const float fl = floorf(p[k]);
        const int i = (int)fl;
        f[k] = p[k] - fl;
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
    return lattice(noise->perm, dims, lo, hi, f, grad);
}

/* Perlin noise of any basis dimension with a run-time dims; each (dims, gradient or not)
 * pair is its own specialised copy of the lattice routine. */
static inline float perlin_any(const ak_noise* noise, uint32_t dims, const float* p, float* grad) {
    if (grad) {
        switch (dims) {
        case 1: return perlin_n(noise, 1, p, NULL, grad);
        case 2: return perlin_n(noise, 2, p, NULL, grad);
        case 3: return perlin_n(noise, 3, p, NULL, grad);
        default: return perlin_n(noise, 4, p, NULL, grad);
        }
    }
    switch (dims) {
    case 1: return perlin_n(noise, 1, p, NULL, NULL);
    case 2: return perlin_n(noise, 2, p, NULL, NULL);
    case 3: return perlin_n(noise, 3, p, NULL, NULL);
    default: return perlin_n(noise, 4, p, NULL, NULL);
    }
}

#endif

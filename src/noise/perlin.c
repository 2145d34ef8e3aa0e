/* Perlin's improved gradient noise (Perlin 2002, "Improving Noise", SIGGRAPH), 1D to 4D, its
 * analytic gradient and the periodic variant; the seeded permutation.
 *
 * One generic lattice routine serves every dimension: the 2^N corner hashes are
 * perm[perm[perm[ix] + iy] + iz]... (Perlin's A/AA/AB chain written for any N), the corner
 * values are gradient . offset, and the corners are blended axis by axis in Perlin's order (x
 * first, then y, z, w) with the quintic fade. The gradient rides along the same blend:
 * lerp(t, a, b) has derivative lerp(t, da, db) + (b - a) dt. The AVX2 kernel (batch_avx2.c)
 * repeats these float operations in the same order, so both give the same bits. */
#include <string.h>

#include "perlin_core.h"

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

float ak_noise_perlin1(const ak_noise* noise, float x, float* out_gradient) {
    if (!noise) {
        if (out_gradient) out_gradient[0] = 0.0f;
        return 0.0f;
    }
    const float p[1] = {x};
    return perlin_n(noise, 1, p, NULL, out_gradient);
}

float ak_noise_perlin2(const ak_noise* noise, float x, float y, float* out_gradient) {
    if (!noise) {
        if (out_gradient) out_gradient[0] = out_gradient[1] = 0.0f;
        return 0.0f;
    }
    const float p[2] = {x, y};
    return perlin_n(noise, 2, p, NULL, out_gradient);
}

float ak_noise_perlin3(const ak_noise* noise, float x, float y, float z, float* out_gradient) {
    if (!noise) {
        if (out_gradient) out_gradient[0] = out_gradient[1] = out_gradient[2] = 0.0f;
        return 0.0f;
    }
    const float p[3] = {x, y, z};
    return perlin_n(noise, 3, p, NULL, out_gradient);
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

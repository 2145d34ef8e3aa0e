/* Independent double-precision reference of improved Perlin noise for tests.
 *
 * 3D: Ken Perlin's published reference implementation of improved noise, "Improving Noise"
 * (SIGGRAPH 2002) and its Java listing ImprovedNoise.java (mrl.nyu.edu/~perlin/noise/):
 *     X = floor(x) & 255, ...; x -= floor(x); u = fade(x) ...
 *     A = p[X] + Y, AA = p[A] + Z, AB = p[A + 1] + Z, B = p[X + 1] + Y, BA = p[B] + Z, BB = ...
 *     lerp(w, lerp(v, lerp(u, grad(p[AA], x, y, z), grad(p[BA], x-1, y, z)), ...), ...)
 *     grad: h = hash & 15; u = h < 8 ? x : y; v = h < 4 ? y : h == 12 || h == 14 ? x : z;
 *           ((h & 1) == 0 ? u : -u) + ((h & 2) == 0 ? v : -v)
 * written here in double with Perlin's nested structure (not animkit's corner loop), and the
 * permutation typed from the paper's listing. Its published value
 * noise(3.14, 42, 7) = 0.13691995878400012 (Rosetta Code "Perlin noise" task, computed with
 * Perlin's Java code) is checked by test_noise.
 *
 * 1D, 2D and 4D: animkit's documented extensions of the same scheme (gradient sets in
 * include/animkit/noise.h), written from that text with explicit gradient tables.
 *
 * Every function takes the permutation (256 entries, indices wrap mod 256), so tests can
 * pass a seeded table. Header-only. */
#ifndef ANIMKIT_REF_NOISE_H
#define ANIMKIT_REF_NOISE_H

#include <math.h>
#include <stdint.h>

static const int ref_perlin_p[256] = {
    151, 160, 137, 91, 90, 15, 131, 13, 201, 95, 96, 53, 194, 233, 7, 225, 140, 36, 103, 30, 69, 142, 8, 99, 37,
    240, 21, 10, 23, 190, 6, 148, 247, 120, 234, 75, 0, 26, 197, 62, 94, 252, 219, 203, 117, 35, 11, 32, 57, 177,
    33, 88, 237, 149, 56, 87, 174, 20, 125, 136, 171, 168, 68, 175, 74, 165, 71, 134, 139, 48, 27, 166, 77, 146,
    158, 231, 83, 111, 229, 122, 60, 211, 133, 230, 220, 105, 92, 41, 55, 46, 245, 40, 244, 102, 143, 54, 65, 25,
    63, 161, 1, 216, 80, 73, 209, 76, 132, 187, 208, 89, 18, 169, 200, 196, 135, 130, 116, 188, 159, 86, 164, 100,
    109, 198, 173, 186, 3, 64, 52, 217, 226, 250, 124, 123, 5, 202, 38, 147, 118, 126, 255, 82, 85, 212, 207, 206,
    59, 227, 47, 16, 58, 17, 182, 189, 28, 42, 223, 183, 170, 213, 119, 248, 152, 2, 44, 154, 163, 70, 221, 153,
    101, 155, 167, 43, 172, 9, 129, 22, 39, 253, 19, 98, 108, 110, 79, 113, 224, 232, 178, 185, 112, 104, 218,
    246, 97, 228, 251, 34, 242, 193, 238, 210, 144, 12, 191, 179, 162, 241, 81, 51, 145, 235, 249, 14, 239, 107,
    49, 192, 214, 31, 181, 199, 106, 157, 184, 84, 204, 176, 115, 121, 50, 45, 127, 4, 150, 254, 138, 236, 205, 93,
    222, 114, 67, 29, 24, 72, 243, 141, 128, 195, 78, 66, 215, 61, 156, 180};

static inline double ref_fade(double t) { return t * t * t * (t * (t * 6 - 15) + 10); }
static inline double ref_lerp(double t, double a, double b) { return a + t * (b - a); }
static inline int ref_p(const uint8_t* perm, int i) { return perm[i & 255]; }

static inline double ref_grad3(int hash, double x, double y, double z) {
    int h = hash & 15;
    double u = h < 8 ? x : y;
    double v = h < 4 ? y : (h == 12 || h == 14) ? x : z;
    return ((h & 1) == 0 ? u : -u) + ((h & 2) == 0 ? v : -v);
}

/* Perlin's ImprovedNoise.noise(x, y, z) with permutation perm. */
static inline double ref_perlin3(const uint8_t* perm, double x, double y, double z) {
    int X = (int)floor(x) & 255, Y = (int)floor(y) & 255, Z = (int)floor(z) & 255;
    x -= floor(x);
    y -= floor(y);
    z -= floor(z);
    double u = ref_fade(x), v = ref_fade(y), w = ref_fade(z);
    int A = ref_p(perm, X) + Y, AA = ref_p(perm, A) + Z, AB = ref_p(perm, A + 1) + Z;
    int B = ref_p(perm, X + 1) + Y, BA = ref_p(perm, B) + Z, BB = ref_p(perm, B + 1) + Z;
    return ref_lerp(w,
                    ref_lerp(v, ref_lerp(u, ref_grad3(ref_p(perm, AA), x, y, z), ref_grad3(ref_p(perm, BA), x - 1, y, z)),
                             ref_lerp(u, ref_grad3(ref_p(perm, AB), x, y - 1, z),
                                      ref_grad3(ref_p(perm, BB), x - 1, y - 1, z))),
                    ref_lerp(v,
                             ref_lerp(u, ref_grad3(ref_p(perm, AA + 1), x, y, z - 1),
                                      ref_grad3(ref_p(perm, BA + 1), x - 1, y, z - 1)),
                             ref_lerp(u, ref_grad3(ref_p(perm, AB + 1), x, y - 1, z - 1),
                                      ref_grad3(ref_p(perm, BB + 1), x - 1, y - 1, z - 1))));
}

/* 1D: slopes +-(1 + (h & 7)) / 4, sign from h & 8. */
static inline double ref_perlin1(const uint8_t* perm, double x) {
    static const double slope[16] = {0.25, 0.5, 0.75, 1, 1.25, 1.5, 1.75, 2, -0.25, -0.5, -0.75, -1, -1.25, -1.5, -1.75, -2};
    int X = (int)floor(x) & 255;
    x -= floor(x);
    return ref_lerp(ref_fade(x), slope[ref_p(perm, X) & 15] * x, slope[ref_p(perm, X + 1) & 15] * (x - 1));
}

/* 2D: the 8 gradients in the order of h & 7. */
static inline double ref_perlin2(const uint8_t* perm, double x, double y) {
    static const double g[8][2] = {{1, 1}, {-1, 1}, {1, -1}, {-1, -1}, {1, 0}, {-1, 0}, {0, 1}, {0, -1}};
    int X = (int)floor(x) & 255, Y = (int)floor(y) & 255;
    x -= floor(x);
    y -= floor(y);
    int A = ref_p(perm, X) + Y, B = ref_p(perm, X + 1) + Y;
    int h00 = ref_p(perm, A) & 7, h10 = ref_p(perm, B) & 7, h01 = ref_p(perm, A + 1) & 7, h11 = ref_p(perm, B + 1) & 7;
    double n00 = g[h00][0] * x + g[h00][1] * y, n10 = g[h10][0] * (x - 1) + g[h10][1] * y;
    double n01 = g[h01][0] * x + g[h01][1] * (y - 1), n11 = g[h11][0] * (x - 1) + g[h11][1] * (y - 1);
    double u = ref_fade(x), v = ref_fade(y);
    return ref_lerp(v, ref_lerp(u, n00, n10), ref_lerp(u, n01, n11));
}

/* 4D: gradient for h & 31: slot (h >> 3) & 3 is zero, the other three in order take signs
 * from bits 0, 1, 2 (set = negative). */
static inline void ref_grad4_vec(int h, double g[4]) {
    h &= 31;
    int zero = (h >> 3) & 3, bit = 0;
    for (int k = 0; k < 4; ++k) {
        if (k == zero) g[k] = 0;
        else g[k] = ((h >> bit++) & 1) ? -1.0 : 1.0;
    }
}

static inline double ref_perlin4(const uint8_t* perm, double x, double y, double z, double w) {
    double p[4] = {x, y, z, w}, f[4];
    int I[4];
    for (int k = 0; k < 4; ++k) {
        I[k] = (int)floor(p[k]) & 255;
        f[k] = p[k] - floor(p[k]);
    }
    double n[16];
    for (int c = 0; c < 16; ++c) {
        int h = ref_p(perm, I[0] + (c & 1));
        h = ref_p(perm, h + I[1] + ((c >> 1) & 1));
        h = ref_p(perm, h + I[2] + ((c >> 2) & 1));
        h = ref_p(perm, h + I[3] + ((c >> 3) & 1));
        double g[4], s = 0;
        ref_grad4_vec(h, g);
        for (int k = 0; k < 4; ++k) s += g[k] * (f[k] - ((c >> k) & 1));
        n[c] = s;
    }
    /* multilinear blend with fade weights, as a weighted sum over the 16 corners */
    double sum = 0;
    for (int c = 0; c < 16; ++c) {
        double wgt = 1;
        for (int k = 0; k < 4; ++k) {
            double t = ref_fade(f[k]);
            wgt *= ((c >> k) & 1) ? t : 1 - t;
        }
        sum += wgt * n[c];
    }
    return sum;
}

#endif

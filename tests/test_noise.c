/* Tests for animkit noise: Perlin against an independent double-precision reference
 * (tests/ref/ref_noise.h) and Perlin's published value, lattice zeros, gradients against
 * central differences, C2 continuity across cell borders, documented ranges, periodic tiling,
 * fractal octave scaling, batch jobs (SIMD == scalar bit for bit, any thread count). */
#include <stdlib.h>
#include <string.h>

#include <animkit/noise.h>

#include "ak_test.h"
#include "noise/noise_internal.h" /* akp_floor, akp_floor_frac */
#include "ref/ref_noise.h"

/* Big runs (10^7 points for the ranges) only in optimised builds outside valgrind;
 * AK_NOISE_RANGE_POINTS overrides. Valgrind is detected through its preload library. */
static size_t range_points(void) {
    const char* env = getenv("AK_NOISE_RANGE_POINTS");
    if (env && atol(env) > 0) return (size_t)atol(env);
    const char* pre = getenv("LD_PRELOAD");
    if (pre && strstr(pre, "vgpreload")) return 100000;
#if defined(NDEBUG)
    return 10000000;
#else
    return 300000;
#endif
}

static float frand(ak_rng* r, float lo, float hi) { return ak_rng_range(r, lo, hi); }

static double ref_value(const ak_noise* n, uint32_t dims, const double* p) {
    switch (dims) {
    case 1: return ref_perlin1(n->perm, p[0]);
    case 2: return ref_perlin2(n->perm, p[0], p[1]);
    case 3: return ref_perlin3(n->perm, p[0], p[1], p[2]);
    default: return ref_perlin4(n->perm, p[0], p[1], p[2], p[3]);
    }
}

static float perlin(const ak_noise* n, uint32_t dims, const float* p, float* g) {
    return ak_noise_eval(n, AK_NOISE_BASIS_PERLIN, dims, p, g);
}

AK_TEST(permutations) {
    ak_noise n0 = ak_noise_make(0);
    for (int i = 0; i < 256; ++i) AK_CHECK_EQ(n0.perm[i], ref_perlin_p[i]);
    for (int i = 0; i < 256; ++i) AK_CHECK_EQ(n0.perm[i + 256], n0.perm[i]);
    const uint64_t seeds[] = {1, 2, 99, 0xFFFFFFFFFFFFFFFFull};
    for (size_t s = 0; s < 4; ++s) {
        ak_noise n = ak_noise_make(seeds[s]), again = ak_noise_make(seeds[s]);
        int seen[256] = {0}, same = 0;
        for (int i = 0; i < 256; ++i) {
            seen[n.perm[i]]++;
            same += n.perm[i] == n0.perm[i];
        }
        for (int i = 0; i < 256; ++i) AK_CHECK_EQ(seen[i], 1);
        AK_CHECK(same < 32); /* a shuffle, not Perlin's table */
        AK_CHECK(memcmp(n.perm, again.perm, 512) == 0);
    }
}

AK_TEST(perlin3_published_value) {
    /* Perlin's Java ImprovedNoise gives these (Rosetta Code "Perlin noise"; ports quote both). */
    AK_CHECK_NEAR(ref_perlin3(ak_noise_make(0).perm, 3.14, 42, 7), 0.13691995878400012, 1e-15);
    AK_CHECK_NEAR(ref_perlin3(ak_noise_make(0).perm, -4.2, 10, 6), 0.14208000000000043, 1e-15);
    ak_noise n = ak_noise_make(0);
    AK_CHECK_NEAR(ak_noise_perlin3(&n, 3.14f, 42.0f, 7.0f, NULL), 0.13691995878400012, 2e-6);
    AK_CHECK_NEAR(ak_noise_perlin3(&n, -4.2f, 10.0f, 6.0f, NULL), 0.14208000000000043, 2e-6);
}

AK_TEST(perlin_matches_reference) {
    ak_rng rng = ak_rng_make(17);
    const uint64_t seeds[] = {0, 7, 12345};
    double worst = 0;
    for (size_t s = 0; s < 3; ++s) {
        ak_noise n = ak_noise_make(seeds[s]);
        for (uint32_t dims = 1; dims <= 4; ++dims) {
            for (int i = 0; i < 4000; ++i) {
                float p[4];
                double pd[4];
                const float span = i < 2000 ? 8.0f : 600.0f; /* small cells and the 256 wrap */
                for (uint32_t k = 0; k < dims; ++k) pd[k] = p[k] = frand(&rng, -span, span);
                const double err = fabs(perlin(&n, dims, p, NULL) - ref_value(&n, dims, pd));
                if (err > worst) worst = err;
                AK_CHECK_MSG(err <= 1e-5, "dims %u seed %llu: err %.3g", dims, (unsigned long long)seeds[s], err);
            }
        }
    }
    printf("  worst |float - double reference| = %.3g\n", worst);
}

AK_TEST(zero_at_lattice) {
    ak_noise n = ak_noise_make(3);
    ak_rng rng = ak_rng_make(5);
    for (uint32_t dims = 1; dims <= 4; ++dims) {
        for (int i = 0; i < 500; ++i) {
            float p[4], g[4];
            for (uint32_t k = 0; k < dims; ++k) p[k] = (float)((int)(ak_rng_u32(&rng) % 1001) - 500);
            AK_CHECK(perlin(&n, dims, p, g) == 0.0f);
        }
    }
}

AK_TEST(gradient_matches_central_differences) {
    ak_rng rng = ak_rng_make(23);
    for (uint32_t dims = 1; dims <= 4; ++dims) {
        ak_noise n = ak_noise_make(dims == 3 ? 0 : 9);
        for (int i = 0; i < 2000; ++i) {
            float p[4], g[4];
            double pd[4];
            for (uint32_t k = 0; k < dims; ++k) pd[k] = p[k] = frand(&rng, -20.0f, 20.0f);
            perlin(&n, dims, p, g);
            for (uint32_t k = 0; k < dims; ++k) {
                const double h = 1e-5;
                double a[4], b[4];
                memcpy(a, pd, sizeof a);
                memcpy(b, pd, sizeof b);
                a[k] += h;
                b[k] -= h;
                const double cd = (ref_value(&n, dims, a) - ref_value(&n, dims, b)) / (2 * h);
                AK_CHECK_MSG(fabs(g[k] - cd) <= 1e-4, "dims %u axis %u: %.7g vs %.7g", dims, k, g[k], cd);
            }
        }
    }
}

/* Across a cell border x_k = integer: the value, the gradient and the gradient's derivative
 * along x_k agree from both sides (second-order one-sided differences of the analytic
 * gradient). A cubic fade (1985 noise) jumps by O(1) in the second derivative here. */
AK_TEST(c2_across_cell_borders) {
    ak_noise n = ak_noise_make(0);
    ak_rng rng = ak_rng_make(31);
    const float h = 1.0f / 256.0f;
    double worst = 0;
    for (uint32_t dims = 1; dims <= 4; ++dims) {
        for (int i = 0; i < 300; ++i) {
            float p[4];
            for (uint32_t k = 0; k < dims; ++k) p[k] = frand(&rng, -30.0f, 30.0f);
            const uint32_t axis = ak_rng_u32(&rng) % dims;
            p[axis] = (float)((int)(ak_rng_u32(&rng) % 61) - 30);
            float g[5][4], v[5];
            for (int s = -2; s <= 2; ++s) {
                float q[4];
                memcpy(q, p, sizeof q);
                q[axis] = p[axis] + (float)s * h;
                v[s + 2] = perlin(&n, dims, q, g[s + 2]);
            }
            AK_CHECK(v[2] == 0.0f || dims > 1);
            AK_CHECK_NEAR(v[1], v[3] - 2.0f * h * g[2][axis], 1e-3); /* C0 + C1 smoke check */
            for (uint32_t m = 0; m < dims; ++m) {
                const double left = (3.0 * g[2][m] - 4.0 * g[1][m] + g[0][m]) / (2.0 * h);
                const double right = (-3.0 * g[2][m] + 4.0 * g[3][m] - g[4][m]) / (2.0 * h);
                const double d = fabs(left - right);
                if (d > worst) worst = d;
                AK_CHECK_MSG(d <= 0.05, "dims %u axis %u comp %u: d2 left %.5g right %.5g", dims, axis, m, left, right);
            }
        }
    }
    printf("  worst second-derivative jump across a border = %.3g\n", worst);
}

static void check_range_job(const ak_noise* n, ak_fractal_desc fd, uint32_t dims, size_t count, const char* what) {
    enum { B = 1 << 16 };
    float* buf = (float*)malloc(sizeof(float) * B * 5);
    ak_rng rng = ak_rng_make(99 + dims);
    float lo, hi, mn = INFINITY, mx = -INFINITY;
    ak_fractal_range(&fd, dims, &lo, &hi);
    for (size_t done = 0; done < count; done += B) {
        for (size_t i = 0; i < (size_t)B * dims; ++i) buf[i] = frand(&rng, -256.0f, 256.0f);
        ak_noise_job job = {.noise = n, .fractal = fd, .dimensions = dims, .x = {buf, B}, .y = {buf + B, B},
                            .z = {buf + 2 * B, B}, .w = {buf + 3 * B, B}, .out_values = {buf + 4 * B, B},
                            .thread_count = 2};
        AK_CHECK_EQ(ak_noise_job_run(&job), AK_OK);
        for (size_t i = 0; i < B; ++i) {
            const float v = buf[4 * B + i];
            mn = v < mn ? v : mn;
            mx = v > mx ? v : mx;
        }
    }
    printf("  %-10s %uD: observed [%.4f, %.4f] within documented [%.4f, %.4f] over %zu points\n", what, dims,
           (double)mn, (double)mx, (double)lo, (double)hi, (count + B - 1) / B * B);
    AK_CHECK(mn >= lo && mx <= hi && isfinite(mn) && isfinite(mx));
    free(buf);
}

AK_TEST(documented_ranges_hold) {
    const size_t count = range_points();
    ak_noise n = ak_noise_make(0);
    for (uint32_t dims = 1; dims <= 4; ++dims) check_range_job(&n, (ak_fractal_desc){.octaves = 1}, dims, count, "perlin");
    const ak_fractal_type types[] = {AK_FRACTAL_FBM, AK_FRACTAL_TURBULENCE, AK_FRACTAL_RIDGED};
    const char* names[] = {"fbm", "turbulence", "ridged"};
    for (int t = 0; t < 3; ++t)
        for (uint32_t dims = 2; dims <= 3; ++dims)
            check_range_job(&n, (ak_fractal_desc){.type = types[t], .octaves = 5, .gain = 0.6f}, dims, count / 10,
                            names[t]);
    check_range_job(&n, (ak_fractal_desc){.octaves = 3, .warp = 0.8f}, 2, count / 100, "warped");
}

AK_TEST(periodic_tiles_exactly) {
    ak_noise n = ak_noise_make(4);
    ak_rng rng = ak_rng_make(8);
    for (uint32_t dims = 1; dims <= 4; ++dims) {
        for (int i = 0; i < 400; ++i) {
            int per[4];
            float p[4], g0[4], g1[4];
            for (uint32_t k = 0; k < dims; ++k) {
                const int choices[] = {1, 2, 3, 5, 16, 100, 255, 256};
                per[k] = i < 100 ? choices[ak_rng_u32(&rng) % 8] : 1 + (int)(ak_rng_u32(&rng) % 256);
                p[k] = (float)((int)(ak_rng_u32(&rng) % 4096) - 2048) / 64.0f; /* exact in float */
            }
            const float v0 = ak_noise_perlin_periodic(&n, dims, p, per, g0);
            for (uint32_t k = 0; k < dims; ++k) {
                float q[4];
                memcpy(q, p, sizeof q);
                q[k] += (float)per[k] * (float)(1 + (int)(ak_rng_u32(&rng) % 3)) * ((i & 1) ? -1.0f : 1.0f);
                const float v1 = ak_noise_perlin_periodic(&n, dims, q, per, g1);
                AK_CHECK_MSG(v0 == v1, "dims %u period %d: %.9g vs %.9g", dims, per[k], v0, v1);
                AK_CHECK(memcmp(g0, g1, dims * sizeof(float)) == 0);
            }
        }
        /* period 256 everywhere is the plain noise */
        int p256[4] = {256, 256, 256, 256};
        for (int i = 0; i < 100; ++i) {
            float p[4];
            for (uint32_t k = 0; k < dims; ++k) p[k] = frand(&rng, -600.0f, 600.0f);
            AK_CHECK(ak_noise_perlin_periodic(&n, dims, p, p256, NULL) == perlin(&n, dims, p, NULL));
        }
    }
    int bad[4] = {0, 4, 4, 4};
    float p[4] = {0.5f, 0.5f, 0.5f, 0.5f};
    AK_CHECK(ak_noise_perlin_periodic(&n, 2, p, bad, NULL) == 0.0f);
}

AK_TEST(bad_inputs_give_zero) {
    ak_noise n = ak_noise_make(0);
    const float bad[] = {NAN, INFINITY, -INFINITY, 3e7f, -1e30f};
    for (int i = 0; i < 5; ++i) {
        float g[3] = {9, 9, 9};
        AK_CHECK(ak_noise_perlin3(&n, 0.3f, bad[i], 0.7f, g) == 0.0f);
        AK_CHECK(g[0] == 0.0f && g[1] == 0.0f && g[2] == 0.0f);
        float p[2] = {bad[i], 0.5f};
        ak_fractal_desc fd = {.type = AK_FRACTAL_RIDGED};
        AK_CHECK(isfinite(ak_fractal_eval(&n, &fd, 2, p, g)));
    }
    AK_CHECK(ak_noise_perlin2(NULL, 0.5f, 0.5f, NULL) == 0.0f);
    ak_fractal_desc bad_desc = {.octaves = 17};
    float p[2] = {0.3f, 0.4f};
    AK_CHECK_EQ(ak_fractal_desc_validate(&bad_desc), AK_ERR_BAD_ARG);
    AK_CHECK(ak_fractal_eval(&n, &bad_desc, 2, p, NULL) == 0.0f);
    AK_CHECK_EQ(ak_fractal_desc_validate(&(ak_fractal_desc){.gain = -1}), AK_ERR_BAD_ARG);
    AK_CHECK_EQ(ak_fractal_desc_validate(&(ak_fractal_desc){.lacunarity = NAN}), AK_ERR_BAD_ARG);
    AK_CHECK_EQ(ak_fractal_desc_validate(&(ak_fractal_desc){.type = AK_FRACTAL_TYPE_COUNT}), AK_ERR_BAD_ARG);
    AK_CHECK_EQ(ak_fractal_desc_validate(NULL), AK_OK);
    ak_fractal_desc r = ak_fractal_desc_resolved(NULL);
    AK_CHECK(r.type == AK_FRACTAL_FBM && r.octaves == 6 && r.lacunarity == 2.0f && r.gain == 0.5f && r.frequency == 1.0f);
}

/* Octave k of the sum is gain^k * basis(frequency * lacunarity^k * p): checked point by point
 * (F_{k+1} - F_k) and statistically (RMS ratio of consecutive octave contributions = gain). */
AK_TEST(fractal_octaves_scale_by_gain) {
    ak_noise n = ak_noise_make(2);
    const float gains[] = {0.5f, 0.7f}, lacs[] = {2.0f, 1.87f};
    const ak_fractal_type types[] = {AK_FRACTAL_FBM, AK_FRACTAL_TURBULENCE};
    for (int t = 0; t < 2; ++t) {
        for (int c = 0; c < 2; ++c) {
            ak_rng rng = ak_rng_make(40 + (uint64_t)c);
            double ss[6] = {0};
            const int samples = 20000;
            for (int i = 0; i < samples; ++i) {
                float p[3] = {frand(&rng, -50, 50), frand(&rng, -50, 50), frand(&rng, -50, 50)};
                float prev = 0.0f;
                for (uint32_t o = 1; o <= 6; ++o) {
                    ak_fractal_desc fd = {.type = types[t], .octaves = o, .gain = gains[c], .lacunarity = lacs[c]};
                    const float f = ak_fractal_eval(&n, &fd, 3, p, NULL);
                    const double d = (double)f - prev;
                    ss[o - 1] += d * d;
                    if (i < 200) {
                        const float fr = powf(lacs[c], (float)(o - 1));
                        float q[3] = {p[0] * fr, p[1] * fr, p[2] * fr};
                        double b = ak_noise_perlin3(&n, q[0], q[1], q[2], NULL);
                        if (types[t] == AK_FRACTAL_TURBULENCE) b = fabs(b);
                        AK_CHECK_NEAR(d, pow(gains[c], o - 1) * b, 2e-5);
                    }
                    prev = f;
                }
            }
            for (int o = 1; o < 6; ++o) {
                const double ratio = sqrt(ss[o] / ss[o - 1]);
                AK_CHECK_MSG(fabs(ratio / gains[c] - 1.0) < 0.04, "type %d gain %.2f octave %d: rms ratio %.4f", t,
                             (double)gains[c], o, ratio);
            }
        }
    }
}

/* ak_fractal_eval reads a desc with every field given where it is and fills in the defaults of
 * one that leaves fields at 0: the documented defaults written out give the same bits as the
 * zeros, with and without gradient, and an out-of-range field given explicitly still gives 0. */
AK_TEST(fractal_eval_explicit_fields_equal_defaults) {
    const ak_noise n = ak_noise_make(9);
    const ak_fractal_desc zero = {.type = AK_FRACTAL_DEFAULT}; /* FBM, Perlin, 6 octaves, 2, 0.5, 1 */
    const ak_fractal_desc full = {.type = AK_FRACTAL_FBM, .basis = AK_NOISE_BASIS_PERLIN, .octaves = 6,
                                  .lacunarity = 2.0f, .gain = 0.5f, .frequency = 1.0f};
    ak_rng rng = ak_rng_make(19);
    long bad = 0;
    for (int i = 0; i < 2000; ++i) {
        const float p[3] = {frand(&rng, -40, 40), frand(&rng, -40, 40), frand(&rng, -40, 40)};
        for (uint32_t dims = 2; dims <= 3; ++dims) {
            float ga[3] = {0, 0, 0}, gb[3] = {0, 0, 0};
            const float a = ak_fractal_eval(&n, &zero, dims, p, NULL), b = ak_fractal_eval(&n, &full, dims, p, NULL);
            const float c = ak_fractal_eval(&n, &zero, dims, p, ga), d = ak_fractal_eval(&n, &full, dims, p, gb);
            bad += memcmp(&a, &b, sizeof a) != 0 || memcmp(&c, &d, sizeof c) != 0 || memcmp(ga, gb, sizeof ga) != 0;
            bad += a == 0.0f; /* a non-trivial value (Perlin fBm is 0 only on the lattice) */
        }
    }
    AK_CHECK_MSG(bad == 0, "%ld of 4000 points differ", bad);
    const float p[3] = {0.3f, 0.7f, 0.1f};
    ak_fractal_desc wrong = full;
    wrong.octaves = 17;
    AK_CHECK_EQ(ak_fractal_eval(&n, &wrong, 3, p, NULL), 0.0f);
    wrong = full;
    wrong.gain = 2.5f;
    AK_CHECK_EQ(ak_fractal_eval(&n, &wrong, 3, p, NULL), 0.0f);
    wrong = full;
    wrong.basis = AK_NOISE_BASIS_SIMPLEX;
    AK_CHECK_EQ(ak_fractal_eval(&n, &wrong, 4, (const float[4]){0.3f, 0.7f, 0.1f, 0.2f}, NULL), 0.0f);
    AK_CHECK(ak_fractal_eval(&n, &full, 3, p, NULL) != 0.0f);
}

/* Analytic fractal gradients (chain rule through |n|, the ridged weights, the warp) against
 * central differences; points within h of a kink of |n| (where two step sizes disagree) are
 * skipped, and they must be rare. */
AK_TEST(fractal_gradient_matches_differences) {
    ak_noise n = ak_noise_make(6);
    const ak_fractal_desc descs[] = {
        {.type = AK_FRACTAL_FBM, .octaves = 4},
        {.type = AK_FRACTAL_TURBULENCE, .octaves = 4},
        {.type = AK_FRACTAL_RIDGED, .octaves = 4, .gain = 0.6f},
        {.type = AK_FRACTAL_FBM, .octaves = 3, .warp = 0.7f},
        {.type = AK_FRACTAL_RIDGED, .octaves = 3, .warp = 0.4f},
    };
    ak_rng rng = ak_rng_make(77);
    for (size_t di = 0; di < sizeof descs / sizeof descs[0]; ++di) {
        for (uint32_t dims = 2; dims <= 3; ++dims) {
            int skipped = 0, tested = 0;
            for (int i = 0; i < 300; ++i) {
                float p[3], g[3];
                for (uint32_t k = 0; k < dims; ++k) p[k] = frand(&rng, -10, 10);
                ak_fractal_eval(&n, &descs[di], dims, p, g);
                for (uint32_t k = 0; k < dims; ++k) {
                    /* central, forward and backward differences at h = 2^-12 */
                    const float h = 1.0f / 4096.0f;
                    float a[3], b[3];
                    memcpy(a, p, sizeof a);
                    memcpy(b, p, sizeof b);
                    a[k] += h;
                    b[k] -= h;
                    const double f0 = ak_fractal_eval(&n, &descs[di], dims, p, NULL);
                    const double fa = ak_fractal_eval(&n, &descs[di], dims, a, NULL);
                    const double fb = ak_fractal_eval(&n, &descs[di], dims, b, NULL);
                    const double cd = (fa - fb) / (2.0 * h), fwd = (fa - f0) / h, bwd = (f0 - fb) / h;
                    const double tol = 0.02 * (1.0 + fabs(cd));
                    ++tested;
                    if (fabs(g[k] - cd) <= tol) continue;
                    /* a kink of |n| or of the ridged weight clamp within h: the analytic value is
                     * one of the one-sided slopes */
                    const bool kink = fabs(fwd - bwd) > tol;
                    const double tol1 = 0.1 * (1.0 + fabs(g[k]));
                    if (kink && (fabs(g[k] - fwd) <= tol1 || fabs(g[k] - bwd) <= tol1)) {
                        ++skipped;
                        continue;
                    }
                    AK_CHECK_MSG(false, "desc %zu dims %u axis %u: %.6g vs %.6g (fwd %.6g bwd %.6g)", di, dims, k,
                                 (double)g[k], cd, fwd, bwd);
                }
            }
            AK_CHECK_MSG(skipped * 20 < tested, "desc %zu: %d skipped of %d", di, skipped, tested);
        }
    }
}

/* Every SIMD kernel build the CPU can run, called directly (a job picks one build per path: AVX2
 * with scalar loads or gathers, AVX-512 with or without VBMI byte permutes), against the scalar
 * reference point by point: the same bits of values and gradients for every basis, 2D and 3D,
 * every fractal type, with out-of-range and lattice points among them. */
AK_TEST(simd_kernels_equal_scalar) {
    typedef void (*kernel_fn)(const ak_noise*, const ak_fractal_desc*, uint32_t, const float* const*, size_t, float*,
                              float* const*);
    kernel_fn kernels[4];
    int nk = 0;
    if (akp_noise_have_avx2()) kernels[nk++] = akp_noise_fractal_avx2, kernels[nk++] = akp_noise_fractal_avx2gather;
    if (akp_noise_have_avx512()) kernels[nk++] = akp_noise_fractal_avx512;
    if (akp_noise_have_avx512vbmi()) kernels[nk++] = akp_noise_fractal_avx512vbmi;
    printf("  SIMD kernel builds compared: %d\n", nk);
    ak_noise n = ak_noise_make(23);
    enum { N = 512 };
    static float x[N], y[N], z[N], v[N], g[3][N];
    ak_rng rng = ak_rng_make(5);
    for (int i = 0; i < N; ++i) {
        x[i] = frand(&rng, -600, 600);
        y[i] = frand(&rng, -300, 300);
        z[i] = frand(&rng, -40, 40);
    }
    x[3] = NAN, y[4] = 3e7f, z[5] = -INFINITY;
    x[6] = 255.0f, y[6] = 256.0f, z[6] = -1.0f;
    x[7] = -0.0f, y[7] = 511.5f, z[7] = 1e-30f;
    const ak_fractal_type types[] = {AK_FRACTAL_FBM, AK_FRACTAL_TURBULENCE, AK_FRACTAL_RIDGED};
    const ak_noise_basis bases[] = {AK_NOISE_BASIS_PERLIN, AK_NOISE_BASIS_SIMPLEX, AK_NOISE_BASIS_VALUE,
                                    AK_NOISE_BASIS_WORLEY};
    int bad = 0;
    for (int k = 0; k < nk; ++k)
        for (int bi = 0; bi < 4; ++bi)
            for (uint32_t dims = 2; dims <= 3; ++dims)
                for (int t = 0; t < 3; ++t) {
                    const ak_fractal_desc raw = {.type = types[t], .basis = bases[bi], .octaves = 4, .gain = 0.5f,
                                                 .lacunarity = 1.97f, .frequency = 0.9f};
                    const ak_fractal_desc fd = ak_fractal_desc_resolved(&raw);
                    const float* xs[4] = {x, y, z, NULL};
                    float* gs[4] = {g[0], g[1], g[2], NULL};
                    kernels[k](&n, &fd, dims, xs, N, v, gs);
                    for (int i = 0; i < N; ++i) {
                        const float p[3] = {x[i], y[i], z[i]};
                        float e[3];
                        const float want = akp_fractal_point(&n, &fd, dims, p, e);
                        int differ = memcmp(&want, &v[i], sizeof want) != 0;
                        for (uint32_t d = 0; d < dims; ++d) differ |= memcmp(&e[d], &g[d][i], sizeof want) != 0;
                        if (differ && bad++ < 5)
                            printf("  kernel %d basis %d dims %u type %d point %d: %.9g vs %.9g\n", k, bi,
                                   (unsigned)dims, t, i, (double)v[i], (double)want);
                    }
                }
    AK_CHECK_EQ(bad, 0);
}

/* The batch paths this CPU has: [0] scalar reference, then AVX2 and AVX-512 where present. */
static int simd_paths(ak_noise_simd* paths) {
    int n = 0;
    paths[n++] = AK_NOISE_SIMD_SCALAR;
    const char* widest = ak_noise_simd_name();
    if (strcmp(widest, "scalar") != 0) paths[n++] = AK_NOISE_SIMD_AVX2;
    if (strcmp(widest, "avx512") == 0) paths[n++] = AK_NOISE_SIMD_AVX512;
    return n;
}

/* Every SIMD path this CPU has, each selected explicitly with simd_limit, against the scalar
 * job and against ak_fractal_eval point by point: the same bits (values and gradients), for
 * Perlin, simplex, value and Worley noise, 2D and 3D, every fractal type, 1 and 3 threads, with
 * and without gradients, a length that leaves a padded tail, out-of-range and tied
 * (x0 = y0 = z0) points; the job reports the kernel it was asked for. */
AK_TEST(batch_simd_equals_scalar) {
    printf("  widest noise kernel: %s\n", ak_noise_simd_name());
    ak_noise n = ak_noise_make(11);
    enum { N = 1003 };
    static float x[N], y[N], z[N], v[5][N], gx[5][N], gy[5][N], gz[5][N];
    ak_rng rng = ak_rng_make(1);
    for (int i = 0; i < N; ++i) {
        x[i] = frand(&rng, -300, 300);
        y[i] = frand(&rng, -3, 3);
        z[i] = frand(&rng, -300, 300);
    }
    x[5] = NAN;
    y[6] = INFINITY;
    z[7] = 4e7f;
    x[8] = y[8] = z[8] = 1.5f;
    x[9] = y[9] = 2.0f, z[9] = -1.0f;
    x[10] = 0.25f, y[10] = z[10] = 0.75f;
    x[11] = -16777215.0f;
    /* the paths: [0] scalar reference; then AVX2 and AVX-512 where the CPU has them */
    ak_noise_simd paths[3];
    const int npaths = simd_paths(paths);
    printf("  paths compared with scalar: %d\n", npaths - 1);
    const ak_fractal_type types[] = {AK_FRACTAL_FBM, AK_FRACTAL_TURBULENCE, AK_FRACTAL_RIDGED};
    const ak_noise_basis bases[] = {AK_NOISE_BASIS_PERLIN, AK_NOISE_BASIS_SIMPLEX, AK_NOISE_BASIS_VALUE,
                                    AK_NOISE_BASIS_WORLEY};
    for (int bi = 0; bi < 4; ++bi)
        for (uint32_t dims = 2; dims <= 3; ++dims) {
            for (int t = 0; t < 3; ++t) {
                const ak_fractal_desc fd = {.type = types[t], .basis = bases[bi], .octaves = 5, .gain = 0.55f,
                                            .lacunarity = 2.03f, .frequency = 0.7f};
                for (int pi = 1; pi < npaths; ++pi) {
                    /* run 0 scalar, 1 the path, 2 the path without gradient, 3 the path on 3 threads */
                    for (int run = 0; run < 4; ++run) {
                        ak_noise_job job = {.noise = &n, .fractal = fd, .dimensions = dims, .x = {x, N}, .y = {y, N},
                                            .z = {z, N}, .out_values = {v[run], N}, .out_gradient_x = {gx[run], N},
                                            .out_gradient_y = {gy[run], N},
                                            .out_gradient_z = {dims == 3 ? gz[run] : NULL, N},
                                            .thread_count = (uint32_t)(run == 3 ? 3 : 1),
                                            .simd_limit = run == 0 ? AK_NOISE_SIMD_SCALAR : paths[pi]};
                        if (run == 2) job.out_gradient_x = job.out_gradient_y = job.out_gradient_z = (ak_f32_span){0};
                        AK_CHECK_EQ(ak_noise_job_kernel(&job), run == 0 ? AK_NOISE_SIMD_SCALAR : paths[pi]);
                        AK_CHECK_EQ(ak_noise_job_run(&job), AK_OK);
                    }
                    AK_CHECK_MSG(memcmp(v[0], v[1], sizeof v[0]) == 0, "basis %d dims %u type %d path %d", bi,
                                 (unsigned)dims, t, (int)paths[pi]);
                    AK_CHECK(memcmp(v[0], v[2], sizeof v[0]) == 0);
                    AK_CHECK(memcmp(v[0], v[3], sizeof v[0]) == 0);
                    AK_CHECK(memcmp(gx[0], gx[1], sizeof gx[0]) == 0 && memcmp(gy[0], gy[1], sizeof gy[0]) == 0);
                    AK_CHECK(memcmp(gx[0], gx[3], sizeof gx[0]) == 0 && memcmp(gy[0], gy[3], sizeof gy[0]) == 0);
                    if (dims == 3) AK_CHECK(memcmp(gz[0], gz[1], sizeof gz[0]) == 0);
                }
                /* the scalar job (or the only path) against the per-point reference */
                if (npaths == 1) {
                    ak_noise_job job = {.noise = &n, .fractal = fd, .dimensions = dims, .x = {x, N}, .y = {y, N},
                                        .z = {z, N}, .out_values = {v[0], N}, .out_gradient_x = {gx[0], N},
                                        .out_gradient_y = {gy[0], N}, .out_gradient_z = {dims == 3 ? gz[0] : NULL, N}};
                    AK_CHECK_EQ(ak_noise_job_run(&job), AK_OK);
                }
                for (int i = 0; i < N; ++i) {
                    const float p[3] = {x[i], y[i], z[i]};
                    float g[3];
                    const float e = ak_fractal_eval(&n, &fd, dims, p, g);
                    AK_CHECK(memcmp(&e, &v[0][i], sizeof e) == 0 && isfinite(v[0][i]));
                    AK_CHECK(memcmp(&g[0], &gx[0][i], sizeof e) == 0 && memcmp(&g[1], &gy[0][i], sizeof e) == 0);
                }
            }
        }
    /* a simd_limit out of range is an argument error */
    ak_noise_job bad = {.noise = &n, .dimensions = 2, .x = {x, 8}, .y = {y, 8}, .out_values = {v[0], 8},
                        .simd_limit = AK_NOISE_SIMD_COUNT};
    AK_CHECK_EQ(ak_noise_job_validate(&bad), AK_ERR_BAD_ARG);
}

/* The plain value and Worley bases (one octave) through every batch path against the scalar
 * per-point functions, bit for bit, on points built to hit the edge cases: lattice/cell
 * borders (integers, one ulp either side, halves; lattice points giving every corner value), negative and huge coordinates up to
 * 2^24 - 1 (and beyond it, NaN, infinity: 0), tiny and signed-zero coordinates, and random
 * points (which include Worley points whose nearest feature point lies two cells away). */
AK_TEST(batch_value_worley_edges) {
    enum { N = 4099 };
    static float c[3][N], v[N], g[3][N];
    static const float edge[] = {0.0f, -0.0f, 1.0f, -1.0f, 0.5f, -0.5f, 255.0f, 256.0f, -256.0f, 1e-30f, -1e-30f,
                                 8388607.5f, -8388607.5f, 8388608.0f, 16777215.0f, -16777215.0f, 12345.0f, -777.0f,
                                 16777216.0f, -16777216.0f, 4e9f, NAN, INFINITY, -INFINITY};
    const int nedge = (int)(sizeof edge / sizeof edge[0]);
    ak_rng rng = ak_rng_make(77);
    for (int i = 0; i < N; ++i)
        for (int k = 0; k < 3; ++k) {
            const uint32_t kind = ak_rng_u32(&rng) % 6;
            float x = frand(&rng, -1000.0f, 1000.0f);
            if (kind == 0) x = edge[ak_rng_u32(&rng) % (uint32_t)(nedge - 6)]; /* finite, in range */
            else if (kind == 1) x = floorf(x);
            else if (kind == 2) x = nextafterf(floorf(x), -INFINITY);
            else if (kind == 3) x = nextafterf(floorf(x), INFINITY);
            else if (kind == 4) x = floorf(x) + 0.5f;
            c[k][i] = x;
        }
    for (int i = 0; i < 40; ++i) c[i % 3][i * 97 % N] = edge[nedge - 6 + i % 6]; /* out of range */
    /* lattice points (-3, j, 5), j = 0..255: value noise there is the corner value of hash
     * perm[perm[perm[-3 & 255] + j] + 5], every one of the 256 hash values once */
    for (int j = 0; j < 256; ++j) c[0][N - 1 - j] = -3.0f, c[1][N - 1 - j] = (float)j, c[2][N - 1 - j] = 5.0f;
    ak_noise_simd paths[3];
    const int npaths = simd_paths(paths);
    const ak_noise_basis bases[2] = {AK_NOISE_BASIS_VALUE, AK_NOISE_BASIS_WORLEY};
    const uint64_t seeds[2] = {0, 0x123456789ABCDEFull};
    int compared = 0, far = 0;
    static float rv[N], rg[3][N];
    for (int si = 0; si < 2; ++si) {
        const ak_noise n = ak_noise_make(seeds[si]);
        for (int bi = 0; bi < 2; ++bi)
            for (uint32_t dims = 2; dims <= 3; ++dims) {
                /* the per-point reference */
                for (int i = 0; i < N; ++i) {
                    const float p[3] = {c[0][i], c[1][i], c[2][i]};
                    float e[3] = {0, 0, 0};
                    rv[i] = ak_noise_eval(&n, bases[bi], dims, p, e);
                    for (int k = 0; k < 3; ++k) rg[k][i] = e[k];
                    /* F1 beyond 1: a feature point two cells away may win */
                    if (bi == 1 && rv[i] > 1.0f) ++far;
                }
                for (int pi = 0; pi < npaths; ++pi)
                    for (int grad = 0; grad < 2; ++grad) {
                        ak_noise_job job = {.noise = &n, .fractal = {.basis = bases[bi], .octaves = 1},
                                            .dimensions = dims, .x = {c[0], N}, .y = {c[1], N}, .z = {c[2], N},
                                            .out_values = {v, N}, .simd_limit = paths[pi]};
                        if (grad) {
                            job.out_gradient_x = (ak_f32_span){g[0], N};
                            job.out_gradient_y = (ak_f32_span){g[1], N};
                            if (dims == 3) job.out_gradient_z = (ak_f32_span){g[2], N};
                        }
                        AK_CHECK_EQ(ak_noise_job_kernel(&job), paths[pi]);
                        AK_CHECK_EQ(ak_noise_job_run(&job), AK_OK);
                        int bad = 0;
                        for (int i = 0; i < N; ++i) {
                            bool same = memcmp(&rv[i], &v[i], sizeof v[i]) == 0;
                            for (uint32_t k = 0; grad && k < dims; ++k)
                                same = same && memcmp(&rg[k][i], &g[k][i], sizeof v[i]) == 0;
                            if (!same && bad++ < 3)
                                AK_CHECK_MSG(false, "seed %d basis %d dims %u path %d grad %d point %d (%.9g %.9g %.9g): %.9g vs %.9g",
                                             si, bi, (unsigned)dims, (int)paths[pi], grad, i, (double)c[0][i],
                                             (double)c[1][i], (double)c[2][i], (double)v[i], (double)rv[i]);
                        }
                        compared += N;
                    }
            }
    }
    printf("  %d points compared, %d Worley points with F1 > 1\n", compared, far);
    AK_CHECK(far > 0);
}

AK_TEST(grid_job_equals_points) {
    ak_noise n = ak_noise_make(0);
    enum { W = 37, H = 11 };
    static float v[4][W * H], gx[4][W * H], gy[4][W * H];
    const ak_fractal_desc fd = {.octaves = 4};
    /* run 0 skip_simd, 1 the widest path on 4 threads, 2 AVX2, 3 AVX-512 (each where the CPU has it) */
    for (int run = 0; run < 4; ++run) {
        ak_noise_grid_job job = {.noise = &n, .fractal = fd, .width = W, .height = H, .origin_x = -3.5f,
                                 .origin_y = 1.25f, .spacing_x = 0.173f, .spacing_y = 0.31f, .out_values = {v[run], W * H},
                                 .out_gradient_x = {gx[run], W * H}, .out_gradient_y = {gy[run], W * H},
                                 .thread_count = (uint32_t)(run == 1 ? 4 : 1), .skip_simd = run == 0,
                                 .simd_limit = run == 2 ? AK_NOISE_SIMD_AVX2 : run == 3 ? AK_NOISE_SIMD_AVX512
                                                                                      : AK_NOISE_SIMD_DEFAULT};
        AK_CHECK_EQ(ak_noise_grid_job_run(&job), AK_OK);
    }
    for (int run = 1; run < 4; ++run)
        AK_CHECK_MSG(memcmp(v[0], v[run], sizeof v[0]) == 0 && memcmp(gx[0], gx[run], sizeof gx[0]) == 0 &&
                         memcmp(gy[0], gy[run], sizeof gy[0]) == 0,
                     "grid run %d", run);
    for (int j = 0; j < H; ++j)
        for (int i = 0; i < W; ++i) {
            /* two statements: a compiler allowed to contract must not fuse into an FMA here */
            const float dx = (float)i * 0.173f, dy = (float)j * 0.31f;
            const float p[2] = {-3.5f + dx, 1.25f + dy};
            float g[2];
            const float e = ak_fractal_eval(&n, &fd, 2, p, g);
            AK_CHECK(e == v[0][j * W + i] && g[1] == gy[0][j * W + i]);
        }
}

AK_TEST(job_validity) {
    ak_noise n = ak_noise_make(0);
    float a[8] = {0}, b[8] = {0}, out[8], g[8];
    AK_CHECK_EQ(ak_noise_job_validate(NULL), AK_ERR_NULL_ARG);
    AK_CHECK_EQ(ak_noise_job_validate(&(ak_noise_job){0}), AK_ERR_NULL_ARG);
    ak_noise_job ok = {.noise = &n, .dimensions = 2, .x = {a, 8}, .y = {b, 8}, .out_values = {out, 8}};
    AK_CHECK_EQ(ak_noise_job_validate(&ok), AK_OK);
    ak_noise_job j = ok;
    j.dimensions = 0; /* -> 3: z missing */
    AK_CHECK_EQ(ak_noise_job_validate(&j), AK_ERR_NULL_ARG);
    j = ok;
    j.dimensions = 5;
    AK_CHECK_EQ(ak_noise_job_validate(&j), AK_ERR_BAD_ARG);
    j = ok;
    j.thread_count = 65;
    AK_CHECK_EQ(ak_noise_job_validate(&j), AK_ERR_BAD_ARG);
    j = ok;
    j.fractal.octaves = 17;
    AK_CHECK_EQ(ak_noise_job_validate(&j), AK_ERR_BAD_ARG);
    j = ok;
    j.y.count = 7;
    AK_CHECK_EQ(ak_noise_job_validate(&j), AK_ERR_SPAN_SMALL);
    j = ok;
    j.out_gradient_x = (ak_f32_span){g, 8};
    AK_CHECK_EQ(ak_noise_job_validate(&j), AK_ERR_NULL_ARG);
    j.out_gradient_y = (ak_f32_span){g, 7};
    AK_CHECK_EQ(ak_noise_job_validate(&j), AK_ERR_SPAN_SMALL);
    j = ok;
    j.noise = NULL;
    AK_CHECK_EQ(ak_noise_job_run(&j), AK_ERR_NULL_ARG);

    ak_noise_grid_job gok = {.noise = &n, .width = 4, .height = 2, .out_values = {out, 8}};
    AK_CHECK_EQ(ak_noise_grid_job_validate(&gok), AK_OK);
    AK_CHECK_EQ(ak_noise_grid_job_validate(&(ak_noise_grid_job){0}), AK_ERR_NULL_ARG);
    ak_noise_grid_job gj = gok;
    gj.width = 0;
    AK_CHECK_EQ(ak_noise_grid_job_validate(&gj), AK_ERR_BAD_ARG);
    gj = gok;
    gj.height = 3;
    AK_CHECK_EQ(ak_noise_grid_job_validate(&gj), AK_ERR_SPAN_SMALL);
    gj = gok;
    gj.origin_x = NAN;
    AK_CHECK_EQ(ak_noise_grid_job_validate(&gj), AK_ERR_BAD_ARG);
    gj = gok;
    gj.out_gradient_x = (ak_f32_span){g, 8};
    AK_CHECK_EQ(ak_noise_grid_job_validate(&gj), AK_ERR_NULL_ARG);
    gj = gok;
    gj.thread_count = 65;
    AK_CHECK_EQ(ak_noise_grid_job_validate(&gj), AK_ERR_BAD_ARG);
    gj = gok;
    gj.fractal.gain = 3.0f;
    AK_CHECK_EQ(ak_noise_grid_job_validate(&gj), AK_ERR_BAD_ARG);
}


static double cd_of(const ak_noise* n, ak_noise_basis basis, uint32_t dims, const float* p, uint32_t k, float h) {
    float a[4], b[4];
    memcpy(a, p, sizeof a);
    memcpy(b, p, sizeof b);
    a[k] += h;
    b[k] -= h;
    return ((double)ak_noise_eval(n, basis, dims, a, NULL) - ak_noise_eval(n, basis, dims, b, NULL)) / (2.0 * h);
}

/* Simplex and value noise: gradients against central differences; simplex 1D/4D and Worley 4D
 * are outside their domains. */
AK_TEST(other_bases_gradients) {
    ak_noise n = ak_noise_make(21);
    ak_rng rng = ak_rng_make(3);
    const struct {
        ak_noise_basis basis;
        uint32_t dims;
    } cases[] = {{AK_NOISE_BASIS_SIMPLEX, 2}, {AK_NOISE_BASIS_SIMPLEX, 3}, {AK_NOISE_BASIS_VALUE, 1},
                 {AK_NOISE_BASIS_VALUE, 2},   {AK_NOISE_BASIS_VALUE, 3},   {AK_NOISE_BASIS_VALUE, 4}};
    for (size_t c = 0; c < sizeof cases / sizeof cases[0]; ++c) {
        double worst = 0;
        for (int i = 0; i < 1500; ++i) {
            float p[4] = {0, 0, 0, 0}, g[4];
            for (uint32_t k = 0; k < cases[c].dims; ++k) p[k] = frand(&rng, -40, 40);
            ak_noise_eval(&n, cases[c].basis, cases[c].dims, p, g);
            for (uint32_t k = 0; k < cases[c].dims; ++k) {
                const double cd = cd_of(&n, cases[c].basis, cases[c].dims, p, k, 1.0f / 1024.0f);
                worst = fmax(worst, fabs(g[k] - cd));
                AK_CHECK_MSG(fabs(g[k] - cd) <= 0.01 * (1.0 + fabs(cd)), "basis %d dims %u: %.6g vs %.6g",
                             (int)cases[c].basis, cases[c].dims, (double)g[k], cd);
            }
        }
        printf("  basis %d %uD: worst |gradient - central difference| = %.3g\n", (int)cases[c].basis, cases[c].dims,
               worst);
    }
    const float p[4] = {0.3f, 0.4f, 0.5f, 0.6f};
    AK_CHECK(ak_noise_eval(&n, AK_NOISE_BASIS_SIMPLEX, 4, p, NULL) == 0.0f);
    AK_CHECK(ak_noise_eval(&n, AK_NOISE_BASIS_WORLEY, 4, p, NULL) == 0.0f);
    AK_CHECK(!ak_noise_basis_supports(AK_NOISE_BASIS_SIMPLEX, 4) && ak_noise_basis_supports(AK_NOISE_BASIS_VALUE, 4));
    AK_CHECK(ak_noise_eval(&n, AK_NOISE_BASIS_SIMPLEX, 1, p, NULL) == ak_noise_simplex2(&n, 0.3f, 0.0f, NULL));
    AK_CHECK(ak_noise_simplex3(&n, NAN, 0, 0, NULL) == 0.0f);
}

AK_TEST(other_bases_ranges) {
    ak_noise n = ak_noise_make(0);
    const size_t count = range_points() / 4;
    const ak_noise_basis bases[] = {AK_NOISE_BASIS_SIMPLEX, AK_NOISE_BASIS_SIMPLEX, AK_NOISE_BASIS_VALUE,
                                    AK_NOISE_BASIS_VALUE, AK_NOISE_BASIS_WORLEY, AK_NOISE_BASIS_WORLEY};
    const uint32_t dims[] = {2, 3, 2, 3, 2, 3};
    const char* names[] = {"simplex", "simplex", "value", "value", "worley", "worley"};
    for (int c = 0; c < 6; ++c)
        check_range_job(&n, (ak_fractal_desc){.basis = bases[c], .octaves = 1}, dims[c],
                        bases[c] == AK_NOISE_BASIS_WORLEY ? count / 8 : count, names[c]);
}

/* Worley against brute force: the nearest feature point of a probe p is p - F1 * grad F1, so a
 * dense grid of probes collects every feature point of a region; F1 and F2 of test points
 * inside it must equal the two smallest distances to that collected set. */
AK_TEST(worley_matches_brute_force) {
    ak_noise n = ak_noise_make(13);
    for (uint32_t dims = 1; dims <= 3; ++dims) {
        enum { MAXP = 4096 };
        static float pts[MAXP][3];
        int count = 0;
        const float lo = -3.0f, hi = 3.0f, step = dims == 3 ? 0.2f : 0.1f;
        const int steps = (int)((hi - lo) / step) + 1;
        const int total = dims == 1 ? steps : dims == 2 ? steps * steps : steps * steps * steps;
        for (int s = 0; s < total; ++s) {
            float p[3] = {0, 0, 0}, g[3];
            int r = s;
            for (uint32_t k = 0; k < dims; ++k) p[k] = lo + step * (float)(r % steps), r /= steps;
            const float f1 = ak_noise_worley(&n, dims, p, NULL, g);
            float q[3];
            for (uint32_t k = 0; k < dims; ++k) q[k] = p[k] - f1 * g[k];
            AK_CHECK(ak_noise_worley(&n, dims, q, NULL, NULL) < 1e-4f); /* q is a feature point */
            int found = 0;
            for (int i = 0; i < count && !found; ++i) {
                float d = 0;
                for (uint32_t k = 0; k < dims; ++k) d += fabsf(pts[i][k] - q[k]);
                found = d < 1e-3f;
            }
            if (!found && count < MAXP) {
                for (uint32_t k = 0; k < 3; ++k) pts[count][k] = k < dims ? q[k] : 0.0f;
                ++count;
            }
        }
        ak_rng rng = ak_rng_make(dims);
        for (int t = 0; t < 300; ++t) {
            float p[3] = {0, 0, 0}, f2 = 0;
            for (uint32_t k = 0; k < dims; ++k) p[k] = frand(&rng, -1.0f, 1.0f);
            double b1 = INFINITY, b2 = INFINITY;
            for (int i = 0; i < count; ++i) {
                double d = 0;
                for (uint32_t k = 0; k < dims; ++k) d += ((double)p[k] - pts[i][k]) * ((double)p[k] - pts[i][k]);
                d = sqrt(d);
                if (d < b1) b2 = b1, b1 = d;
                else if (d < b2) b2 = d;
            }
            const float f1 = ak_noise_worley(&n, dims, p, &f2, NULL);
            AK_CHECK_NEAR(f1, b1, 2e-4);
            AK_CHECK_NEAR(f2, b2, 2e-4);
            AK_CHECK(f1 <= f2 && f1 <= sqrtf((float)dims));
        }
        printf("  worley %uD: %d feature points collected\n", dims, count);
    }
}

/* Worley F1 without gradient (on AVX2 CPUs: the 3^dims near cells side by side in vector
 * lanes, point_avx2.c) against F1 with gradient (the scalar ring search, which keeps the
 * nearest cell): the same bits, 2D and 3D, two seeds, points of every magnitude up to 2^22
 * and of either sign, some on cell borders and corners (where the far rings are searched). */
AK_TEST(worley_value_path_matches_gradient_path) {
    long bad = 0, count = 0;
    for (uint64_t seed = 0; seed < 2; ++seed) {
        const ak_noise n = ak_noise_make(seed * 0x9E3779B97F4A7C15ull + 5);
        ak_rng rng = ak_rng_make(11 + seed);
        for (int i = 0; i < 40000; ++i) {
            float p[3];
            for (int k = 0; k < 3; ++k) {
                const float scale = ldexpf(1.0f, (int)(ak_rng_u32(&rng) % 23)); /* 1 .. 2^22 */
                p[k] = frand(&rng, -scale, scale);
                if (i % 4 == 0) p[k] = floorf(p[k]) + (i % 8 == 0 ? 0.0f : 1e-3f); /* borders */
            }
            for (uint32_t dims = 2; dims <= 3; ++dims) {
                float g[3];
                const float v = ak_noise_worley(&n, dims, p, NULL, NULL), w = ak_noise_worley(&n, dims, p, NULL, g);
                bad += memcmp(&v, &w, sizeof v) != 0, ++count;
            }
        }
    }
#ifdef AKP_HAVE_POINT_AVX2
    printf("  value-only path: %s\n", __builtin_cpu_supports("avx2") ? "AVX2 lanes" : "scalar rings (no AVX2)");
#endif
    AK_CHECK_MSG(bad == 0, "%ld of %ld Worley values differ between the two paths", bad, count);
}

static float comp(ak_vec3 v, int k) { return k == 0 ? v.x : k == 1 ? v.y : v.z; }
static void set_comp(ak_vec3* v, int k, float x) {
    if (k == 0) v->x = x;
    else if (k == 1) v->y = x;
    else v->z = x;
}

/* div v = sum_k dv_k/dx_k by central differences is ~0 while its terms are O(1). */
AK_TEST(curl_noise_is_divergence_free) {
    ak_noise n = ak_noise_make(8);
    ak_rng rng = ak_rng_make(12);
    const ak_fractal_desc fd = {.octaves = 3};
    const float h = 1.0f / 2048.0f;
    double worst = 0, terms = 0;
    for (int i = 0; i < 300; ++i) {
        const ak_vec3 p = ak_vec3_make(frand(&rng, -20, 20), frand(&rng, -20, 20), frand(&rng, -20, 20));
        double div = 0, mag = 0;
        for (int k = 0; k < 3; ++k) {
            ak_vec3 a = p, b = p;
            set_comp(&a, k, comp(a, k) + h);
            set_comp(&b, k, comp(b, k) - h);
            const ak_vec3 va = ak_noise_curl3(&n, &fd, a), vb = ak_noise_curl3(&n, &fd, b);
            const double d = ((double)comp(va, k) - comp(vb, k)) / (2.0 * h);
            div += d;
            mag += fabs(d);
        }
        worst = fmax(worst, fabs(div));
        terms += mag / 300.0;
        AK_CHECK_MSG(fabs(div) <= 1e-3 * mag + 5e-3, "div %.4g (terms %.3g)", div, mag);
    }
    printf("  3D curl: worst |div| %.3g, mean sum of |dv_k/dx_k| %.3g\n", worst, terms);
    AK_CHECK(terms > 0.5);
    for (int i = 0; i < 300; ++i) {
        const ak_vec2 p = ak_vec2_make(frand(&rng, -20, 20), frand(&rng, -20, 20));
        const ak_vec2 ax = ak_noise_curl2(&n, &fd, ak_vec2_make(p.x + h, p.y)),
                      bx = ak_noise_curl2(&n, &fd, ak_vec2_make(p.x - h, p.y));
        const ak_vec2 ay = ak_noise_curl2(&n, &fd, ak_vec2_make(p.x, p.y + h)),
                      by = ak_noise_curl2(&n, &fd, ak_vec2_make(p.x, p.y - h));
        const double dx = ((double)ax.x - bx.x) / (2 * h), dy = ((double)ay.y - by.y) / (2 * h);
        AK_CHECK_MSG(fabs(dx + dy) <= 1e-3 * (fabs(dx) + fabs(dy)) + 5e-3, "2D div %.4g", dx + dy);
    }
    AK_CHECK(ak_vec3_length(ak_noise_curl3(NULL, &fd, ak_vec3_zero())) == 0.0f);
}

AK_TEST(wind) {
    ak_noise n = ak_noise_make(1);
    const ak_vec3 p = ak_vec3_make(1, 2, 3);
    ak_noise_wind_desc calm = {0};
    AK_CHECK(ak_vec3_length(ak_noise_wind(&n, &calm, p, 1.0f)) == 0.0f);
    ak_noise_wind_desc steady = {.direction = ak_vec3_make(0, 0, 2), .speed = 3};
    const ak_vec3 v = ak_noise_wind(&n, &steady, p, 7.0f);
    AK_CHECK_NEAR(v.x, 0, 1e-6);
    AK_CHECK_NEAR(v.z, 3, 1e-6);
    ak_noise_wind_desc gusty = {.direction = ak_vec3_make(1, 0, 0), .speed = 5, .gust = 0.4f};
    float mn = 1e9f, mx = -1e9f;
    for (int i = 0; i < 2000; ++i) {
        const float s = ak_noise_wind(&n, &gusty, p, (float)i * 0.05f).x;
        mn = fminf(mn, s), mx = fmaxf(mx, s);
        AK_CHECK(s >= 5.0f * 0.6f - 1e-4f && s <= 5.0f * 1.4f + 1e-4f);
    }
    AK_CHECK(mx - mn > 1.0f); /* it does gust */
    /* the swirl is divergence-free and smooth in time */
    ak_noise_wind_desc swirl = {.direction = ak_vec3_make(1, 0, 1), .speed = 2, .turbulence = 1.5f};
    ak_rng rng = ak_rng_make(4);
    const float h = 1.0f / 256.0f;
    const ak_vec3 mean_wind = ak_vec3_scale(ak_vec3_normalize(swirl.direction), swirl.speed);
    float swirl_max = 0.0f;
    for (int i = 0; i < 100; ++i) {
        const ak_vec3 q = ak_vec3_make(frand(&rng, -5, 5), frand(&rng, -5, 5), frand(&rng, -5, 5));
        const float t = frand(&rng, 0, 10);
        swirl_max = fmaxf(swirl_max, ak_vec3_length(ak_vec3_sub(ak_noise_wind(&n, &swirl, q, t), mean_wind)));
        double div = 0;
        for (int k = 0; k < 3; ++k) {
            ak_vec3 a = q, b = q;
            set_comp(&a, k, comp(a, k) + h);
            set_comp(&b, k, comp(b, k) - h);
            div += ((double)comp(ak_noise_wind(&n, &swirl, a, t), k) - comp(ak_noise_wind(&n, &swirl, b, t), k)) / (2.0 * h);
        }
        AK_CHECK_MSG(fabs(div) < 0.02, "wind div %.4g", div);
        const ak_vec3 w0 = ak_noise_wind(&n, &swirl, q, t), w1 = ak_noise_wind(&n, &swirl, q, t + 1e-3f);
        AK_CHECK(ak_vec3_length(ak_vec3_sub(w0, w1)) < 0.05f);
    }
    AK_CHECK(swirl_max > 0.3f); /* the swirl is there, so its zero divergence means something */
    AK_CHECK(ak_vec3_length(ak_noise_wind(&n, &swirl, ak_vec3_make(NAN, 0, 0), 0)) == 0.0f);
}

AK_TEST(sway_layer) {
    ak_noise n = ak_noise_make(2);
    enum { J = 5 };
    ak_transform pose[J], out[J], out2[J];
    for (int j = 0; j < J; ++j) {
        pose[j].translation = ak_vec3_make((float)j, 0, 0);
        pose[j].rotation = ak_quat_from_axis_angle(ak_vec3_make(0, 1, 0), 0.3f * (float)j);
        pose[j].scale = ak_vec3_make(1, 1, 1);
    }
    const float amp[J] = {0, 0.05f, 0.1f, 0.2f, 0.02f}, freq[J] = {1, 0.3f, 0.5f, 2, 0.25f};
    const float tamp[J] = {0, 0, 0.01f, 0, 0};
    ak_noise_sway_job job = {.noise = &n, .time = 3.7f, .pose = {pose, J}, .amplitudes = {amp, J},
                             .frequencies = {freq, J}, .translation_amplitudes = {tamp, J}, .out_pose = {out, J}};
    AK_CHECK_EQ(ak_noise_sway_run(&job), AK_OK);
    AK_CHECK(memcmp(&out[0], &pose[0], sizeof pose[0]) == 0); /* amplitude 0: untouched */
    for (int j = 1; j < J; ++j) {
        /* delta = pose^-1 * out, its angle within amplitude * |n|, |n| <= sqrt 3 */
        const ak_quat d = ak_quat_mul(ak_quat_conjugate(pose[j].rotation), out[j].rotation);
        const float angle = 2.0f * acosf(fminf(1.0f, fabsf(d.w)));
        AK_CHECK(angle <= amp[j] * sqrtf(3.0f) + 1e-5f);
        AK_CHECK(angle > 0.0f);
    }
    AK_CHECK(ak_vec3_length(ak_vec3_sub(out[2].translation, pose[2].translation)) <= 0.01f * sqrtf(3.0f) + 1e-6f);
    AK_CHECK(memcmp(&out[3].translation, &pose[3].translation, sizeof(ak_vec3)) == 0);
    /* time * frequency is what matters: doubling one and halving the other changes nothing */
    float freq2[J];
    for (int j = 0; j < J; ++j) freq2[j] = freq[j] * 0.5f;
    ak_noise_sway_job job2 = job;
    job2.time = 7.4f;
    job2.frequencies = (ak_f32_cspan){freq2, J};
    job2.out_pose = (ak_transform_span){out2, J};
    AK_CHECK_EQ(ak_noise_sway_run(&job2), AK_OK);
    AK_CHECK(memcmp(out, out2, sizeof out) == 0);
    /* smooth in time; in place works; zero mean over a long time */
    job2 = job;
    job2.time = 3.7f + 1e-3f;
    job2.out_pose = (ak_transform_span){out2, J};
    ak_noise_sway_run(&job2);
    for (int j = 0; j < J; ++j) AK_CHECK(fabsf(ak_quat_dot(out[j].rotation, out2[j].rotation)) > 0.99999f);
    ak_transform inplace[J];
    memcpy(inplace, pose, sizeof pose);
    job2 = job;
    job2.pose = (ak_transform_cspan){inplace, J};
    job2.out_pose = (ak_transform_span){inplace, J};
    AK_CHECK_EQ(ak_noise_sway_run(&job2), AK_OK);
    AK_CHECK(memcmp(inplace, out, sizeof out) == 0);
    double mean = 0, mean_abs = 0;
    for (int i = 0; i < 4000; ++i) {
        job2 = job;
        job2.time = (float)i * 0.37f;
        job2.out_pose = (ak_transform_span){out2, J};
        ak_noise_sway_run(&job2);
        const ak_quat d = ak_quat_mul(ak_quat_conjugate(pose[3].rotation), out2[3].rotation);
        mean += d.x / 4000.0, mean_abs += fabs(d.x) / 4000.0;
    }
    AK_CHECK(fabs(mean) < 0.25 * mean_abs);
    /* validation */
    AK_CHECK_EQ(ak_noise_sway_validate(&(ak_noise_sway_job){0}), AK_ERR_NULL_ARG);
    job2 = job;
    job2.amplitudes.count = J - 1;
    AK_CHECK_EQ(ak_noise_sway_validate(&job2), AK_ERR_SPAN_SMALL);
    job2 = job;
    job2.time = INFINITY;
    AK_CHECK_EQ(ak_noise_sway_run(&job2), AK_ERR_BAD_DATA);
    const float badf[J] = {1, -1, 1, 1, 1};
    job2 = job;
    job2.frequencies = (ak_f32_cspan){badf, J};
    AK_CHECK_EQ(ak_noise_sway_validate(&job2), AK_ERR_BAD_DATA);
}

/* akp_floor / akp_floor_frac (the per-point functions' floor) give libm's floorf bit for bit,
 * and so do both floors they choose between (truncation; roundss on SSE4.1 CPUs):
 * every 61st float pattern below the 2^24 limit of either sign, and around every integer
 * within 4096 of zero the integer itself, both neighbours and +-0. */
static int floor_mismatch(float x) {
    int i = 7, j = 7;
    const float fl = akp_floor(x, &i), fr = akp_floor_frac(x, &j);
    const float want = floorf(x), want_fr = x - want;
    /* both variants akp_floor chooses between: +0.0 where floorf gives -0.0 */
    const float want_u = want + 0.0f;
    int k = 7;
    const float tr = akp_floor_trunc(x, &k);
    int bad = memcmp(&tr, &want_u, sizeof tr) != 0 || k != (int)want;
#ifdef AKP_HAVE_FLOOR_ROUNDSS
    if (__builtin_cpu_supports("sse4.1")) {
        k = 7;
        const float rs = akp_floor_roundss(x, &k);
        bad |= memcmp(&rs, &want_u, sizeof rs) != 0 || k != (int)want;
    }
#endif
    return bad || memcmp(&fl, &want, sizeof fl) != 0 || memcmp(&fr, &want_fr, sizeof fr) != 0 || i != (int)want ||
           j != (int)want;
}

AK_TEST(floor_matches_libm) {
    long bad = 0, count = 0;
    for (uint32_t bits = 0; bits < 0x4B800000u; bits += 61u)
        for (uint32_t sign = 0; sign < 2; ++sign) {
            const uint32_t b = bits | sign << 31;
            float x;
            memcpy(&x, &b, sizeof x);
            bad += floor_mismatch(x), ++count;
        }
    for (int k = -4096; k <= 4096; ++k) {
        const float x = (float)k;
        bad += floor_mismatch(x) + floor_mismatch(nextafterf(x, -INFINITY)) + floor_mismatch(nextafterf(x, INFINITY));
        count += 3;
    }
    bad += floor_mismatch(0.0f) + floor_mismatch(-0.0f) + floor_mismatch(nextafterf(16777216.0f, 0.0f)) +
           floor_mismatch(-nextafterf(16777216.0f, 0.0f));
    AK_CHECK_MSG(bad == 0, "%ld of %ld floors differ from floorf", bad, count + 4);
    float x = -0.0f; /* the one case truncation alone gets wrong in sign */
    int i;
    AK_CHECK(signbit(akp_floor(x, &i)) && i == 0 && !signbit(akp_floor_frac(x, &i)));
}

/* Value noise written out from its definition, one corner at a time: corner c (bit k: the upper
 * lattice line along axis k) hashes perm[...perm[perm[x_c] + y_c]... + w_c], its value is
 * h / 127.5 - 1, the corners are blended along axis 0, then 1, ... with a + s (b - a),
 * s = t^3 (t (6 t - 15) + 10), and the sum is clamped to [-1, 1]: the float operations the
 * library documents, in their order, so the bits must agree. */
static float value_naive(const ak_noise* n, uint32_t dims, const float* p) {
    int cell[4];
    float t[4];
    for (uint32_t k = 0; k < dims; ++k) {
        const float fl = floorf(p[k]);
        cell[k] = (int)fl;
        t[k] = p[k] - fl;
    }
    float v[16];
    for (uint32_t c = 0; c < (1u << dims); ++c) {
        uint32_t h = 0;
        for (uint32_t k = 0; k < dims; ++k) h = n->perm[h + (uint32_t)((cell[k] + (int)(c >> k & 1u)) & 255)];
        v[c] = (float)h / 127.5f - 1.0f;
    }
    for (uint32_t k = 0; k < dims; ++k) {
        const float s = t[k] * t[k] * t[k] * (t[k] * (t[k] * 6.0f - 15.0f) + 10.0f);
        for (uint32_t c = 0; c < (1u << dims); c += 2u << k) v[c] = v[c] + s * (v[c + (1u << k)] - v[c]);
    }
    return v[0] < -1.0f ? -1.0f : v[0] > 1.0f ? 1.0f : v[0];
}

static int bits_differ(float a, float b) { return memcmp(&a, &b, sizeof a) != 0; }

/* ak_noise_value (the build this CPU runs, with and without gradient, and the baseline x86-64
 * build of the 2D/3D bodies) and fBm over value noise (the CPU's build and the baseline one)
 * against value_naive, bit for bit: random points, points near integers and signed zeros. */
AK_TEST(value_matches_naive_definition) {
    ak_rng rng = ak_rng_make(77);
    long bad = 0, count = 0;
    for (uint32_t dims = 1; dims <= 4; ++dims) {
        const ak_noise n = ak_noise_make(dims * 5 + 1);
        for (int i = 0; i < 20000; ++i) {
            float p[4], g[4];
            for (uint32_t k = 0; k < dims; ++k) {
                const float r = frand(&rng, -300.0f, 300.0f);
                /* every 4th point on or next to an integer (and +-0) */
                p[k] = i % 4 ? r : i % 8 == 0 ? nextafterf(roundf(r), (float)(i % 3) - 1.0f) : (i & 16 ? -0.0f : roundf(r));
            }
            const float want = value_naive(&n, dims, p);
            bad += bits_differ(ak_noise_value(&n, dims, p, NULL), want) + bits_differ(ak_noise_value(&n, dims, p, g), want);
            count += 2;
            if (dims == 2 || dims == 3) bad += bits_differ(akp_value_baseline(&n, dims, p), want), ++count;
            if ((dims == 2 || dims == 3) && i % 8 == 1) {
                /* fBm 4 octaves: sum = sum + amp * noise(p * freq), from freq 1.5, amp 1 */
                const ak_fractal_desc d = {.type = AK_FRACTAL_FBM, .basis = AK_NOISE_BASIS_VALUE, .octaves = 4,
                                           .lacunarity = 2.0f, .gain = 0.5f, .frequency = 1.5f};
                float sum = 0.0f, freq = 1.5f, amp = 1.0f;
                for (int o = 0; o < 4; ++o) {
                    float q[3];
                    for (uint32_t k = 0; k < dims; ++k) q[k] = p[k] * freq;
                    sum = sum + amp * value_naive(&n, dims, q);
                    freq = freq * 2.0f, amp = amp * 0.5f;
                }
                bad += bits_differ(ak_fractal_eval(&n, &d, dims, p, NULL), sum) +
                       bits_differ(akp_fbm_value_baseline(&n, &d, dims, p), sum);
                count += 2;
            }
        }
    }
    AK_CHECK_MSG(bad == 0, "%ld of %ld value noise results differ from the definition", bad, count);
}

/* fBm over Perlin noise in 2D/3D, the build this CPU runs (ak_fractal_eval) and the baseline
 * x86-64 one (akp_fbm_perlin_baseline), against the octave sum written out over the per-point
 * calls (sum = sum + amp * perlin(p * freq)), bit for bit. */
AK_TEST(fbm_perlin_builds_match_octave_sum) {
    ak_rng rng = ak_rng_make(78);
    long bad = 0, count = 0;
    const ak_fractal_desc d = {.type = AK_FRACTAL_FBM, .basis = AK_NOISE_BASIS_PERLIN, .octaves = 5,
                               .lacunarity = 2.0f, .gain = 0.5f, .frequency = 0.75f};
    for (uint32_t dims = 2; dims <= 3; ++dims) {
        const ak_noise n = ak_noise_make(dims + 40);
        for (int i = 0; i < 4000; ++i) {
            float p[3];
            for (uint32_t k = 0; k < dims; ++k) p[k] = i % 4 ? frand(&rng, -200.0f, 200.0f) : (float)(i % 7) - 3.0f;
            float sum = 0.0f, freq = 0.75f, amp = 1.0f;
            for (int o = 0; o < 5; ++o) {
                const float x = p[0] * freq, y = p[1] * freq, z = dims == 3 ? p[2] * freq : 0.0f;
                sum = sum + amp * (dims == 3 ? ak_noise_perlin3(&n, x, y, z, NULL) : ak_noise_perlin2(&n, x, y, NULL));
                freq = freq * 2.0f, amp = amp * 0.5f;
            }
            bad += bits_differ(ak_fractal_eval(&n, &d, dims, p, NULL), sum) +
                   bits_differ(akp_fbm_perlin_baseline(&n, &d, dims, p), sum);
            count += 2;
        }
    }
    AK_CHECK_MSG(bad == 0, "%ld of %ld fBm Perlin results differ from the octave sum", bad, count);
}

/* The per-point calls (ak_noise_perlin2/3, simplex2/3, value, worley F1) against a one-octave
 * fBm job at frequency 1 on every path this CPU has: the same value for every point, the same
 * bits except one documented case. The job sums octaves from +0.0 (0.0f + 1 * n), so where the
 * per-point value is -0.0 the job gives +0.0 (equal as numbers; this test pins that down, it
 * does not change it). Random points, the integer lattice (where Perlin noise is a signed zero)
 * and coordinates of -0.0. */
static float per_point(const ak_noise* n, ak_noise_basis b, uint32_t dims, const float* p) {
    switch (b) {
    case AK_NOISE_BASIS_PERLIN:
        return dims == 2 ? ak_noise_perlin2(n, p[0], p[1], NULL) : ak_noise_perlin3(n, p[0], p[1], p[2], NULL);
    case AK_NOISE_BASIS_SIMPLEX:
        return dims == 2 ? ak_noise_simplex2(n, p[0], p[1], NULL) : ak_noise_simplex3(n, p[0], p[1], p[2], NULL);
    case AK_NOISE_BASIS_VALUE: return ak_noise_value(n, dims, p, NULL);
    default: return ak_noise_worley(n, dims, p, NULL, NULL);
    }
}

AK_TEST(per_point_matches_job_signed_zero) {
    ak_noise n = ak_noise_make(3);
    enum { N = 6000 };
    static float x[N], y[N], z[N], out[N];
    ak_rng rng = ak_rng_make(7);
    for (int i = 0; i < N; ++i) {
        if (i % 3 == 0) { /* integer lattice points, some coordinates -0.0 */
            x[i] = (float)((int)(ak_rng_u32(&rng) % 41) - 20);
            y[i] = (float)((int)(ak_rng_u32(&rng) % 41) - 20);
            z[i] = (float)((int)(ak_rng_u32(&rng) % 41) - 20);
            if (i % 9 == 0) x[i] = -0.0f;
            if (i % 27 == 0) y[i] = z[i] = -0.0f;
        } else {
            x[i] = frand(&rng, -60, 60), y[i] = frand(&rng, -60, 60), z[i] = frand(&rng, -60, 60);
        }
    }
    ak_noise_simd paths[3];
    const int npaths = simd_paths(paths);
    const ak_noise_basis bases[] = {AK_NOISE_BASIS_PERLIN, AK_NOISE_BASIS_SIMPLEX, AK_NOISE_BASIS_VALUE,
                                    AK_NOISE_BASIS_WORLEY};
    long neg_zero = 0;
    for (int bi = 0; bi < 4; ++bi)
        for (uint32_t dims = 2; dims <= 3; ++dims)
            for (int pi = 0; pi < npaths; ++pi) {
                ak_noise_job job = {.noise = &n, .fractal = {.type = AK_FRACTAL_FBM, .basis = bases[bi], .octaves = 1},
                                    .dimensions = dims, .x = {x, N}, .y = {y, N}, .z = {dims == 3 ? z : NULL, N},
                                    .out_values = {out, N}, .thread_count = 1, .simd_limit = paths[pi]};
                AK_CHECK_EQ(ak_noise_job_run(&job), AK_OK);
                long other = 0;
                for (int i = 0; i < N; ++i) {
                    const float p[3] = {x[i], y[i], z[i]};
                    const float v = per_point(&n, bases[bi], dims, p);
                    if (memcmp(&v, &out[i], sizeof v) == 0) continue;
                    if (v == 0.0f && signbit(v) && out[i] == 0.0f && !signbit(out[i])) ++neg_zero;
                    else if (other++ < 3)
                        AK_CHECK_MSG(false, "basis %d, %uD, path %d, point %d: per point %a, job %a", bi, dims,
                                     (int)paths[pi], i, v, out[i]);
                }
                AK_CHECK_MSG(other == 0, "basis %d, %uD, path %d: %ld values differ", bi, dims, (int)paths[pi], other);
            }
    /* the documented case occurs (Perlin noise at lattice points), so the rule above is exercised */
    printf("  per-point -0.0 where the job gives +0.0: %ld values over %d paths\n", neg_zero, npaths);
    AK_CHECK(neg_zero > 0);
}

int main(void) {
    AK_RUN(permutations);
    AK_RUN(floor_matches_libm);
    AK_RUN(value_matches_naive_definition);
    AK_RUN(fbm_perlin_builds_match_octave_sum);
    AK_RUN(worley_value_path_matches_gradient_path);
    AK_RUN(fractal_eval_explicit_fields_equal_defaults);
    AK_RUN(perlin3_published_value);
    AK_RUN(perlin_matches_reference);
    AK_RUN(zero_at_lattice);
    AK_RUN(gradient_matches_central_differences);
    AK_RUN(c2_across_cell_borders);
    AK_RUN(periodic_tiles_exactly);
    AK_RUN(bad_inputs_give_zero);
    AK_RUN(fractal_octaves_scale_by_gain);
    AK_RUN(fractal_gradient_matches_differences);
    AK_RUN(batch_simd_equals_scalar);
    AK_RUN(simd_kernels_equal_scalar);
    AK_RUN(per_point_matches_job_signed_zero);
    AK_RUN(batch_value_worley_edges);
    AK_RUN(grid_job_equals_points);
    AK_RUN(job_validity);
    AK_RUN(other_bases_gradients);
    AK_RUN(worley_matches_brute_force);
    AK_RUN(curl_noise_is_divergence_free);
    AK_RUN(wind);
    AK_RUN(sway_layer);
    AK_RUN_SLOW(documented_ranges_hold);
    AK_RUN(other_bases_ranges);
    return ak_test_finish();
}

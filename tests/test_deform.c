/* deform: squash volume, bend/twist closed forms, normals, bouncing ball, squash tracker, and
 * jiggle dynamics (rest, overshoot/decay against the damped-oscillator closed form, frame-rate
 * independence, length preservation). References are computed here in double. */
#include <animkit/deform.h>
#include <animkit/mesh.h>

#include "ak_test.h"

static const double PI_D = 3.14159265358979323846;

/* ---- helpers ------------------------------------------------------------------------------ */

/* Three draws in a fixed order (argument evaluation order is unspecified in C, so
 * make(rng(), rng(), rng()) would give different data under gcc and clang). */
static ak_vec3 rand3(ak_rng* r, float lx, float hx, float ly, float hy, float lz, float hz) {
    float x = ak_rng_range(r, lx, hx);
    float y = ak_rng_range(r, ly, hy);
    float z = ak_rng_range(r, lz, hz);
    return ak_vec3_make(x, y, z);
}

/* Closed UV sphere (radius r, centre c), counter-clockwise from outside. */
enum { SLICES = 48, STACKS = 32, SPHERE_V = (STACKS - 1) * SLICES + 2, SPHERE_T = 2 * SLICES * (STACKS - 1) };
static void make_sphere(ak_vec3 c, float r, ak_vec3* pos, ak_vec3* nrm, uint32_t* idx) {
    size_t v = 0;
    pos[v] = ak_vec3_make(c.x, c.y + r, c.z), nrm[v++] = ak_vec3_make(0, 1, 0);
    for (int i = 1; i < STACKS; ++i) {
        double th = PI_D * i / STACKS;
        for (int j = 0; j < SLICES; ++j) {
            double ph = 2.0 * PI_D * j / SLICES;
            ak_vec3 n = ak_vec3_make((float)(sin(th) * cos(ph)), (float)cos(th), (float)(sin(th) * sin(ph)));
            nrm[v] = n;
            pos[v++] = ak_vec3_madd(c, n, r);
        }
    }
    pos[v] = ak_vec3_make(c.x, c.y - r, c.z), nrm[v++] = ak_vec3_make(0, -1, 0);
    size_t t = 0;
    const uint32_t south = (uint32_t)v - 1;
    for (uint32_t j = 0; j < SLICES; ++j) {
        uint32_t j1 = (j + 1) % SLICES;
        idx[t++] = 0, idx[t++] = 1 + j1, idx[t++] = 1 + j;
    }
    for (uint32_t i = 0; i + 2 < STACKS; ++i)
        for (uint32_t j = 0; j < SLICES; ++j) {
            uint32_t j1 = (j + 1) % SLICES;
            uint32_t a = 1 + i * SLICES + j, b = 1 + i * SLICES + j1;
            uint32_t cc = 1 + (i + 1) * SLICES + j, d = 1 + (i + 1) * SLICES + j1;
            idx[t++] = a, idx[t++] = b, idx[t++] = d;
            idx[t++] = a, idx[t++] = d, idx[t++] = cc;
        }
    for (uint32_t j = 0; j < SLICES; ++j) {
        uint32_t j1 = (j + 1) % SLICES;
        uint32_t base = 1 + (STACKS - 2) * SLICES;
        idx[t++] = south, idx[t++] = base + j, idx[t++] = base + j1;
    }
}

/* Signed volume by the divergence theorem, in double (the test's own oracle). */
static double volume(const ak_vec3* p, const uint32_t* idx, size_t tris) {
    double v = 0.0;
    for (size_t t = 0; t < tris; ++t) {
        const ak_vec3 a = p[idx[3 * t]], b = p[idx[3 * t + 1]], c = p[idx[3 * t + 2]];
        v += (double)a.x * ((double)b.y * c.z - (double)b.z * c.y) - (double)a.y * ((double)b.x * c.z - (double)b.z * c.x) +
             (double)a.z * ((double)b.x * c.y - (double)b.y * c.x);
    }
    return v / 6.0;
}

typedef struct dvec {
    double x, y, z;
} dvec;
static dvec dv(ak_vec3 v) { return (dvec){v.x, v.y, v.z}; }
static dvec dadd(dvec a, dvec b) { return (dvec){a.x + b.x, a.y + b.y, a.z + b.z}; }
static dvec dsc(dvec a, double s) { return (dvec){a.x * s, a.y * s, a.z * s}; }
static double ddot(dvec a, dvec b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
static double ddist(ak_vec3 a, dvec b) { return sqrt((a.x - b.x) * (a.x - b.x) + (a.y - b.y) * (a.y - b.y) + (a.z - b.z) * (a.z - b.z)); }

/* ---- squash & stretch -------------------------------------------------------------------- */

AK_TEST(squash_preserves_volume_exactly) {
    static ak_vec3 pos[SPHERE_V], nrm[SPHERE_V], out[SPHERE_V], outn[SPHERE_V];
    static uint32_t idx[3 * SPHERE_T];
    make_sphere(ak_vec3_make(0.3f, 1.2f, -0.4f), 0.8f, pos, nrm, idx);
    const double v0 = volume(pos, idx, SPHERE_T);
    AK_CHECK(v0 > 0.0);
    const float stretches[] = {0.25f, 0.6f, 1.0f, 1.7f, 3.5f};
    const ak_vec3 axes[] = {{0, 1, 0}, {1, 2, -0.5f}, {-3, 0.1f, 1}};
    for (size_t a = 0; a < 3; ++a)
        for (size_t s = 0; s < 5; ++s) {
            ak_deformer d = {.type = AK_DEFORMER_SQUASH, .origin = {0.5f, 0.1f, 0.2f}, .axis = axes[a],
                             .amount = stretches[s]};
            ak_deform_job job = {.deformers = &d, .deformer_count = 1, .positions = {pos, SPHERE_V},
                                 .normals = {nrm, SPHERE_V}, .out_positions = {out, SPHERE_V},
                                 .out_normals = {outn, SPHERE_V}};
            AK_CHECK_EQ(ak_deform_run(&job), AK_OK);
            const double v1 = volume(out, idx, SPHERE_T);
            AK_CHECK_NEAR(v1 / v0, 1.0, 1e-4);
            /* The mesh module's volume agrees. */
            double vm = ak_volume_compute((ak_vec3_cspan){out, SPHERE_V}, (ak_u32_cspan){idx, 3 * SPHERE_T});
            AK_CHECK_NEAR(vm / v0, 1.0, 1e-4);
            /* Closed form per point: c + s u a + (r - u a) / sqrt(s). */
            dvec ax = dv(ak_vec3_normalize(axes[a])), c = dv(d.origin);
            double e = 0.0;
            for (int i = 0; i < SPHERE_V; i += 7) {
                dvec r = {pos[i].x - c.x, pos[i].y - c.y, pos[i].z - c.z};
                double u = ddot(r, ax);
                dvec perp = dadd(r, dsc(ax, -u));
                dvec ref = dadd(c, dadd(dsc(ax, stretches[s] * u), dsc(perp, 1.0 / sqrt(stretches[s]))));
                double x = ddist(out[i], ref);
                if (x > e) e = x;
            }
            AK_CHECK_NEAR(e, 0.0, 5e-6);
        }
    /* Squash along X by s = 0.5: the sphere becomes an ellipsoid with semi-axes (0.4, 0.8 sqrt2, ...). */
    ak_mat4 m = ak_squash_matrix(ak_vec3_make(1, 2, 3), ak_vec3_make(0, 0, 2), 2.25f);
    AK_CHECK_NEAR(ak_mat4_determinant(m), 1.0, 1e-6);
    ak_vec3 p = ak_mat4_transform_point(m, ak_vec3_make(1.5f, 2.0f, 4.0f));
    AK_CHECK_NEAR(p.x, 1.0 + 0.5 / 1.5, 1e-6);
    AK_CHECK_NEAR(p.z, 3.0 + 2.25, 1e-6);
    ak_vec3 fixed = ak_mat4_transform_point(m, ak_vec3_make(1, 2, 3));
    AK_CHECK_NEAR(ak_vec3_distance(fixed, ak_vec3_make(1, 2, 3)), 0.0, 1e-6);
    /* Invalid stretch -> identity. */
    ak_mat4 id = ak_squash_matrix(ak_vec3_zero(), ak_vec3_make(0, 1, 0), -1.0f);
    AK_CHECK_NEAR(id.m[5], 1.0, 0.0);
}

/* Normals must stay perpendicular to the deformed surface: for tangents t of the input surface
 * at p, (f(p + e t) - f(p - e t)) . n' ~ 0. Checked for every deformer type. */
AK_TEST(normals_stay_perpendicular_to_deformed_surface) {
    ak_deformer ds[] = {
        {.type = AK_DEFORMER_SQUASH, .origin = {0, 0.5f, 0}, .axis = {0.3f, 1, 0}, .amount = 1.8f},
        {.type = AK_DEFORMER_BEND, .origin = {0, -0.8f, 0}, .axis = {0, 1, 0}, .bend_direction = {1, 0, 0.3f},
         .amount = 1.2f, .length = 1.4f},
        {.type = AK_DEFORMER_TWIST, .origin = {0, -0.8f, 0}, .axis = {0, 1, 0.2f}, .amount = 2.0f, .length = 1.5f},
    };
    ak_rng rng = ak_rng_make(3);
    for (size_t k = 0; k < 3; ++k) {
        double worst = 0.0;
        for (int i = 0; i < 300; ++i) {
            ak_vec3 n = ak_vec3_normalize(rand3(&rng, -1, 1, -1, 1, -1, 1));
            if (ak_vec3_length_sq(n) == 0.0f) continue;
            ak_vec3 p = rand3(&rng, -0.4f, 0.4f, -1.0f, 1.0f, -0.4f, 0.4f);
            if (ds[k].type != AK_DEFORMER_SQUASH) {
                /* Bend and twist are only C0 where the region starts and ends (the Jacobian
                 * jumps), so a finite difference straddling u = 0 or u = L is not a tangent. */
                ak_deformer rd = ak_deformer_resolved(ds[k]);
                float u = ak_vec3_dot(ak_vec3_sub(p, rd.origin), rd.axis);
                if (fabsf(u) < 0.01f || fabsf(u - rd.length) < 0.01f) continue;
            }
            ak_vec3 pn = p, nn = n;
            ak_deform_job job = {.deformers = &ds[k], .deformer_count = 1, .positions = {&p, 1}, .normals = {&n, 1},
                                 .out_positions = {&pn, 1}, .out_normals = {&nn, 1}};
            AK_CHECK_EQ(ak_deform_run(&job), AK_OK);
            AK_CHECK_NEAR(ak_vec3_length(nn), 1.0, 1e-5);
            ak_vec3 t1 = ak_vec3_any_perpendicular(n), t2 = ak_vec3_cross(n, t1);
            const float e = 1e-3f;
            for (int q = 0; q < 2; ++q) {
                ak_vec3 t = q ? t2 : t1;
                ak_vec3 a = ak_deformer_apply_point(&ds[k], ak_vec3_madd(p, t, e));
                ak_vec3 b = ak_deformer_apply_point(&ds[k], ak_vec3_madd(p, t, -e));
                ak_vec3 ft = ak_vec3_sub(a, b);
                double c = fabs(ak_vec3_dot(ak_vec3_normalize(ft), nn));
                if (c > worst) worst = c;
            }
        }
        AK_CHECK_MSG(worst < 2e-3, "deformer %d: normal not perpendicular, |cos| = %g", (int)k, worst);
    }
}

/* ---- bend & twist ------------------------------------------------------------------------ */

AK_TEST(bend_closed_form) {
    const dvec c = {0.2, -0.1, 0.5};
    const double L = 1.5;
    const double thetas[] = {0.3, 1.0, AK_HALF_PI, 2.5, -1.1};
    for (size_t q = 0; q < 5; ++q) {
        const double th = thetas[q];
        ak_deformer d = {.type = AK_DEFORMER_BEND, .origin = {0.2f, -0.1f, 0.5f}, .axis = {0, 0, 2},
                         .bend_direction = {0, 3, 0}, .amount = (float)th, .length = (float)L};
        const dvec a = {0, 0, 1}, b = {0, 1, 0};
        /* The axis point at distance L lands on the arc: c + (L/theta)(sin th a + (1 - cos th) b). */
        ak_vec3 p = ak_deformer_apply_point(&d, ak_vec3_make(0.2f, -0.1f, 0.5f + (float)L));
        dvec ref = dadd(c, dsc(dadd(dsc(a, sin(th)), dsc(b, 1.0 - cos(th))), L / th));
        AK_CHECK_NEAR(ddist(p, ref), 0.0, 2e-6);
        /* A point at u = 0.4 L, offset w along b, and an out-of-plane offset e:
         * C + (R - w)(sin phi a - cos phi b) + e, with C = c + R b, R = L / theta, phi = 0.4 theta. */
        const double R = L / th, phi = 0.4 * th, w = 0.15, e = -0.07;
        ak_vec3 in = ak_vec3_make(0.2f + (float)e, -0.1f + (float)w, 0.5f + (float)(0.4 * L));
        ak_vec3 p2 = ak_deformer_apply_point(&d, in);
        dvec ref2 = dadd(dadd(c, dsc(b, R)), dsc(dadd(dsc(a, sin(phi)), dsc(b, -cos(phi))), R - w));
        ref2.x += e;
        AK_CHECK_NEAR(ddist(p2, ref2), 0.0, 3e-6);
        /* Past the end: rigid continuation along the end tangent (cos th a + sin th b). */
        ak_vec3 p3 = ak_deformer_apply_point(&d, ak_vec3_make(0.2f, -0.1f, 0.5f + (float)L + 0.5f));
        dvec ref3 = dadd(ref, dsc(dadd(dsc(a, cos(th)), dsc(b, sin(th))), 0.5));
        AK_CHECK_NEAR(ddist(p3, ref3), 0.0, 3e-6);
        /* Before the start: unchanged. */
        ak_vec3 p4 = ak_deformer_apply_point(&d, ak_vec3_make(1.0f, 2.0f, 0.0f));
        AK_CHECK_NEAR(ak_vec3_distance(p4, ak_vec3_make(1.0f, 2.0f, 0.0f)), 0.0, 0.0);
        /* The centre line keeps its length: sum of chords over the arc ~ L. */
        double len = 0.0;
        ak_vec3 prev = ak_deformer_apply_point(&d, ak_vec3_make(0.2f, -0.1f, 0.5f));
        for (int i = 1; i <= 200; ++i) {
            ak_vec3 cur = ak_deformer_apply_point(&d, ak_vec3_make(0.2f, -0.1f, 0.5f + (float)(L * i / 200)));
            len += ak_vec3_distance(prev, cur);
            prev = cur;
        }
        AK_CHECK_NEAR(len, L, 1e-4);
    }
    /* A tiny angle is (numerically) the identity, not a division by ~0. */
    ak_deformer z = {.type = AK_DEFORMER_BEND, .axis = {0, 1, 0}, .amount = 1e-9f, .length = 2.0f};
    ak_vec3 q = ak_deformer_apply_point(&z, ak_vec3_make(0.3f, 1.0f, 0.2f));
    AK_CHECK_NEAR(ak_vec3_distance(q, ak_vec3_make(0.3f, 1.0f, 0.2f)), 0.0, 1e-6);
}

AK_TEST(twist_closed_form) {
    const double L = 2.0, tau = 1.9;
    ak_deformer d = {.type = AK_DEFORMER_TWIST, .origin = {1, 0, 0}, .axis = {1, 0, 0}, .amount = (float)tau,
                     .length = (float)L};
    /* A point at u = L/2 with radial offset r along +Y turns by tau/2 about +X. */
    const double r = 0.3;
    ak_vec3 p = ak_deformer_apply_point(&d, ak_vec3_make(1.0f + (float)(L / 2), (float)r, 0.0f));
    dvec ref = {1.0 + L / 2, r * cos(tau / 2), r * sin(tau / 2)};
    AK_CHECK_NEAR(ddist(p, ref), 0.0, 1e-6);
    /* Beyond L the full angle, before the origin nothing. */
    ak_vec3 p2 = ak_deformer_apply_point(&d, ak_vec3_make(1.0f + (float)L + 1.0f, 0.0f, (float)r));
    dvec ref2 = {1.0 + L + 1.0, -r * sin(tau), r * cos(tau)};
    AK_CHECK_NEAR(ddist(p2, ref2), 0.0, 1e-6);
    ak_vec3 p3 = ak_deformer_apply_point(&d, ak_vec3_make(0.5f, 0.2f, 0.1f));
    AK_CHECK_NEAR(ak_vec3_distance(p3, ak_vec3_make(0.5f, 0.2f, 0.1f)), 0.0, 0.0);
    /* Distance from the axis is preserved everywhere. */
    ak_rng rng = ak_rng_make(5);
    double worst = 0.0;
    for (int i = 0; i < 200; ++i) {
        ak_vec3 q = rand3(&rng, 0, 4, -1, 1, -1, 1);
        ak_vec3 o = ak_deformer_apply_point(&d, q);
        double e = fabs(hypot(o.y, o.z) - hypot(q.y, q.z)) + fabs(o.x - q.x);
        if (e > worst) worst = e;
    }
    AK_CHECK_NEAR(worst, 0.0, 2e-6);
}

AK_TEST(deformer_stack_and_in_place) {
    /* Twist then bend, in place, equals applying the two one after another. */
    ak_deformer st[2] = {
        {.type = AK_DEFORMER_TWIST, .axis = {0, 1, 0}, .amount = 0.8f, .length = 1.0f},
        {.type = AK_DEFORMER_BEND, .axis = {0, 1, 0}, .bend_direction = {0, 0, 1}, .amount = 0.9f, .length = 1.0f},
    };
    ak_vec3 pts[16], ref[16];
    ak_rng rng = ak_rng_make(6);
    for (int i = 0; i < 16; ++i) {
        pts[i] = rand3(&rng, -0.2f, 0.2f, 0, 1.5f, -0.2f, 0.2f);
        ref[i] = ak_deformer_apply_point(&st[1], ak_deformer_apply_point(&st[0], pts[i]));
    }
    ak_deform_job job = {.deformers = st, .deformer_count = 2, .positions = {pts, 16}, .out_positions = {pts, 16}};
    AK_CHECK_EQ(ak_deform_run(&job), AK_OK);
    double e = 0.0;
    for (int i = 0; i < 16; ++i) e = fmax(e, ak_vec3_distance(pts[i], ref[i]));
    AK_CHECK_NEAR(e, 0.0, 0.0);
    /* Defaults: zero axis -> +Y, zero squash amount -> 1 (identity), zero length -> 1. */
    ak_deformer z = {0};
    ak_deformer r = ak_deformer_resolved(z);
    AK_CHECK_NEAR(r.axis.y, 1.0, 0.0);
    AK_CHECK_NEAR(r.amount, 1.0, 0.0);
    AK_CHECK_NEAR(r.length, 1.0, 0.0);
    AK_CHECK_NEAR(fabs(ak_vec3_dot(r.bend_direction, r.axis)), 0.0, 0.0);
    ak_vec3 q = ak_deformer_apply_point(&z, ak_vec3_make(1, 2, 3));
    AK_CHECK_NEAR(ak_vec3_distance(q, ak_vec3_make(1, 2, 3)), 0.0, 1e-6);
}

AK_TEST(deform_bad_input_codes) {
    ak_vec3 p[4] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}}, n[4], out[4], outn[4];
    for (int i = 0; i < 4; ++i) n[i] = ak_vec3_make(0, 1, 0), out[i] = ak_vec3_splat(7.0f);
    ak_deformer d = {.type = AK_DEFORMER_SQUASH, .amount = 2.0f};
    ak_deform_job zero = {0};
    AK_CHECK_EQ(ak_deform_run(&zero), AK_ERR_NULL_ARG);
    AK_CHECK_EQ(ak_deform_run(NULL), AK_ERR_NULL_ARG);
    ak_deform_job ok = {.deformers = &d, .deformer_count = 1, .positions = {p, 4}, .normals = {n, 4},
                        .out_positions = {out, 4}, .out_normals = {outn, 4}};
    ak_deform_job j = ok;
    j.deformer_count = 0;
    AK_CHECK_EQ(ak_deform_run(&j), AK_ERR_NULL_ARG);
    j = ok, j.normals = (ak_vec3_cspan){NULL, 0};
    AK_CHECK_EQ(ak_deform_run(&j), AK_ERR_NULL_ARG);
    j = ok, j.normals.count = 3;
    AK_CHECK_EQ(ak_deform_run(&j), AK_ERR_BAD_ARG);
    j = ok, j.out_positions.count = 3;
    AK_CHECK_EQ(ak_deform_run(&j), AK_ERR_SPAN_SMALL);
    j = ok, j.out_normals.count = 3;
    AK_CHECK_EQ(ak_deform_run(&j), AK_ERR_SPAN_SMALL);
    ak_deformer bad = d;
    bad.amount = -1.0f;
    j = ok, j.deformers = &bad;
    AK_CHECK_EQ(ak_deform_run(&j), AK_ERR_BAD_ARG);
    bad = d, bad.axis.x = NAN;
    AK_CHECK_EQ(ak_deform_run(&j), AK_ERR_BAD_ARG);
    bad = d, bad.type = AK_DEFORMER_TYPE_COUNT;
    AK_CHECK_EQ(ak_deform_run(&j), AK_ERR_BAD_ARG);
    bad = d, bad.type = AK_DEFORMER_BEND, bad.length = -2.0f;
    AK_CHECK_EQ(ak_deform_run(&j), AK_ERR_BAD_ARG);
    bad = d, bad.type = AK_DEFORMER_TWIST, bad.amount = INFINITY;
    AK_CHECK_EQ(ak_deform_run(&j), AK_ERR_BAD_ARG);
    AK_CHECK_NEAR(out[2].y, 7.0, 0.0); /* nothing written on failure */
    /* apply_point leaves p unchanged for an invalid deformer. */
    ak_vec3 q = ak_deformer_apply_point(&bad, ak_vec3_make(1, 2, 3));
    AK_CHECK_NEAR(q.z, 3.0, 0.0);
    AK_CHECK_EQ(ak_deform_run(&ok), AK_OK);
}

/* ---- bouncing ball & squash tracker ------------------------------------------------------- */

AK_TEST(bouncing_ball) {
    ak_bounce_desc desc = {.height = 1.2f, .radius = 0.3f, .forward_speed = 0.5f, .start = {0, 0.1f, 0}};
    const float period = ak_bounce_period(&desc);
    const double g = 9.81, v0 = sqrt(2 * g * 1.2);
    AK_CHECK_NEAR(period, 2 * v0 / g + 0.1, 1e-5);
    int contacts = 0, flights = 0;
    double apex = 0.0;
    for (int i = 0; i <= 1000; ++i) {
        float t = period * 2.0f * (float)i / 1000.0f;
        ak_bounce_state s = ak_bounce_sample(&desc, t);
        /* Lowest point of the ellipsoid along -Y (support function, double). */
        double ay = s.axis.y, st = s.stretch;
        double half = 0.3 * sqrt(st * st * ay * ay + (1 - ay * ay) / st);
        double bottom = s.center.y - half;
        AK_CHECK(bottom >= 0.1 - 1e-5);
        if (s.in_contact) {
            ++contacts;
            AK_CHECK_NEAR(bottom, 0.1, 1e-6);
            AK_CHECK(s.stretch <= 1.0f && s.stretch >= 0.6f - 1e-6f);
        } else {
            ++flights;
            AK_CHECK(s.stretch >= 1.0f);
            AK_CHECK_NEAR(ak_vec3_length(s.axis), 1.0, 1e-6);
        }
        if (bottom > apex) apex = bottom;
        /* Volume: det(model) = r^3. */
        AK_CHECK_NEAR(ak_mat4_determinant(s.model) / (0.3 * 0.3 * 0.3), 1.0, 1e-4);
        AK_CHECK_NEAR(s.center.x, 0.5 * t, 1e-5);
    }
    AK_CHECK(contacts > 10 && flights > 10);
    AK_CHECK_NEAR(apex, 0.1 + 1.2, 2e-3); /* the apex of the bottom (sampled) */
    /* Periodic, and the deepest squash is the desc's value. */
    ak_bounce_state a = ak_bounce_sample(&desc, 0.3f), b = ak_bounce_sample(&desc, 0.3f + period);
    AK_CHECK_NEAR(a.center.y, b.center.y, 1e-4);
    ak_bounce_state deep = ak_bounce_sample(&desc, (float)(2 * v0 / g) + 0.05f);
    AK_CHECK(deep.in_contact);
    AK_CHECK_NEAR(deep.stretch, 0.6, 1e-4);
    ak_bounce_state dflt = ak_bounce_sample(NULL, NAN);
    AK_CHECK(ak_vec3_is_finite(dflt.center));
    /* Defaults. */
    ak_bounce_desc r = ak_bounce_desc_resolved(NULL);
    AK_CHECK_NEAR(r.height, 1.0, 0.0);
    AK_CHECK_NEAR(r.radius, 0.25, 0.0);
    AK_CHECK_NEAR(r.gravity, 9.81, 1e-6);
    AK_CHECK_NEAR(r.contact_time, 0.1, 1e-7);
    AK_CHECK_NEAR(r.squash, 0.6, 1e-7);
    AK_CHECK_NEAR(r.stretch_per_speed, 0.04, 1e-7);
    ak_bounce_desc odd = {.squash = 0.001f, .forward_speed = INFINITY, .height = -3.0f};
    r = ak_bounce_desc_resolved(&odd);
    AK_CHECK_NEAR(r.squash, 0.05, 1e-7);
    AK_CHECK_NEAR(r.forward_speed, 0.0, 0.0);
    AK_CHECK_NEAR(r.height, 1.0, 0.0);
}

AK_TEST(squash_tracker_from_motion) {
    ak_squash_tracker_desc desc = {.speed_gain = 0.1f, .accel_gain = 0.01f, .gravity = {0, -9.81f, 0},
                                   .accel_dead_zone = 10.0f};
    ak_squash_tracker tr = {0};
    ak_deformer d;
    const float dt = 1.0f / 60.0f;
    /* At rest, with the dead zone above g: no deformation. */
    for (int i = 0; i < 5; ++i) AK_CHECK_EQ(ak_squash_tracker_update(&tr, &desc, ak_vec3_make(1, 2, 3), dt, &d), AK_OK);
    AK_CHECK_NEAR(d.amount, 1.0, 1e-6);
    AK_CHECK_EQ(d.type, AK_DEFORMER_SQUASH);
    /* Without the dead zone a resting point carries its weight: s = 1 / (1 + 0.01 g) along Y. */
    ak_squash_tracker_desc nodz = desc;
    nodz.accel_dead_zone = 0.0f;
    ak_squash_tracker t0 = {0};
    for (int i = 0; i < 5; ++i) AK_CHECK_EQ(ak_squash_tracker_update(&t0, &nodz, ak_vec3_make(1, 2, 3), dt, &d), AK_OK);
    AK_CHECK_NEAR(d.amount, 1.0 / (1.0 + 0.01 * 9.81), 1e-5);
    AK_CHECK_NEAR(fabs(d.axis.y), 1.0, 1e-6);
    /* Constant velocity 4 m/s along +X: stretch 1 + 0.1 * 4 along X. */
    ak_squash_tracker t2 = {0};
    for (int i = 0; i < 10; ++i)
        AK_CHECK_EQ(ak_squash_tracker_update(&t2, &desc, ak_vec3_make(4.0f * dt * (float)i, 0, 0), dt, &d), AK_OK);
    AK_CHECK_NEAR(d.amount, 1.4, 1e-3);
    AK_CHECK_NEAR(fabs(d.axis.x), 1.0, 1e-5);
    AK_CHECK_NEAR(d.origin.x, 4.0 * dt * 9, 1e-5);
    /* Free fall: gravity is compensated, so only the speed stretches (along Y). */
    ak_squash_tracker t3 = {0};
    for (int i = 0; i < 30; ++i) {
        float t = dt * (float)i;
        AK_CHECK_EQ(ak_squash_tracker_update(&t3, &desc, ak_vec3_make(0, -0.5f * 9.81f * t * t, 0), dt, &d), AK_OK);
    }
    double v = 9.81 * dt * 29 - 0.5 * 9.81 * dt; /* finite-difference speed at the last step */
    AK_CHECK_NEAR(d.amount, 1.0 + 0.1 * v, 2e-3);
    AK_CHECK_NEAR(fabs(d.axis.y), 1.0, 1e-4);
    /* A hard stop squashes along a - g = (-240, 9.81, 0): s = 1 / (1 + 0.01 (|a - g| - 10)). */
    ak_squash_tracker t2b = t2;
    ak_squash_tracker_desc wide = desc;
    wide.min_stretch = 0.1f;
    AK_CHECK_EQ(ak_squash_tracker_update(&t2, &wide, ak_vec3_make(4.0f * dt * 9, 0, 0), dt, &d), AK_OK);
    const double am = hypot(240.0, 9.81);
    AK_CHECK_NEAR(d.amount, 1.0 / (1.0 + 0.01 * (am - 10.0)), 1e-3);
    AK_CHECK_NEAR(fabs(d.axis.x), 240.0 / am, 1e-4);
    /* With the default clamp (min 0.5) the same stop gives exactly 0.5. */
    AK_CHECK_EQ(ak_squash_tracker_update(&t2b, &desc, ak_vec3_make(4.0f * dt * 9, 0, 0), dt, &d), AK_OK);
    AK_CHECK_NEAR(d.amount, 0.5, 1e-6);
    /* Response time smooths: one step closes 1 - exp(-dt / T) of the gap in ln s. */
    ak_squash_tracker_desc sm = desc;
    sm.response_time = 0.1f;
    ak_squash_tracker t4 = {0};
    AK_CHECK_EQ(ak_squash_tracker_update(&t4, &sm, ak_vec3_zero(), dt, &d), AK_OK);
    AK_CHECK_EQ(ak_squash_tracker_update(&t4, &sm, ak_vec3_make(4.0f * dt, 0, 0), dt, &d), AK_OK);
    AK_CHECK_NEAR(log(d.amount), log(1.4) * (1.0 - exp(-dt / 0.1)), 1e-4);
    ak_squash_tracker_desc rd = ak_squash_tracker_desc_resolved(NULL);
    AK_CHECK_NEAR(rd.min_stretch, 0.5, 0.0);
    AK_CHECK_NEAR(rd.max_stretch, 2.0, 0.0);
    /* Bad input; the tracker is untouched on failure. */
    ak_squash_tracker before = t4;
    AK_CHECK_EQ(ak_squash_tracker_update(NULL, &desc, ak_vec3_zero(), dt, &d), AK_ERR_NULL_ARG);
    AK_CHECK_EQ(ak_squash_tracker_update(&t4, &desc, ak_vec3_zero(), 0.0f, &d), AK_ERR_BAD_ARG);
    AK_CHECK_EQ(ak_squash_tracker_update(&t4, &desc, ak_vec3_zero(), NAN, &d), AK_ERR_BAD_ARG);
    AK_CHECK_EQ(ak_squash_tracker_update(&t4, &desc, ak_vec3_make(NAN, 0, 0), dt, &d), AK_ERR_BAD_DATA);
    ak_squash_tracker_desc bd = desc;
    bd.speed_gain = -1.0f;
    AK_CHECK_EQ(ak_squash_tracker_update(&t4, &bd, ak_vec3_zero(), dt, &d), AK_ERR_BAD_ARG);
    bd = desc, bd.min_stretch = 3.0f, bd.max_stretch = 2.0f;
    AK_CHECK_EQ(ak_squash_tracker_update(&t4, &bd, ak_vec3_zero(), dt, &d), AK_ERR_BAD_ARG);
    AK_CHECK(memcmp(&before, &t4, sizeof(t4)) == 0);
}

/* ---- jiggle ------------------------------------------------------------------------------- */

/* A small rig: 0 root, 1 body (translation jiggle), 2..4 a tail chain along -Z (rotation jiggle),
 * 5 a non-jiggling tip under joint 4. Model matrices come from the root transform only. */
enum { RIG_N = 6 };
static const int32_t rig_parents[RIG_N] = {-1, 0, 0, 2, 3, 4};
static const ak_vec3 rig_local[RIG_N] = {{0, 0, 0}, {0, 1, 0}, {0, 1, -0.3f}, {0, 0, -0.4f}, {0, 0, -0.4f}, {0, 0, -0.4f}};

static void rig_model(ak_mat4 root, ak_mat4* out) {
    for (int i = 0; i < RIG_N; ++i) {
        ak_mat4 local = ak_mat4_translation(rig_local[i]);
        out[i] = rig_parents[i] < 0 ? ak_mat4_mul(root, local) : ak_mat4_mul(out[rig_parents[i]], local);
    }
}

typedef struct rig_sim {
    ak_jiggle_joint joints[4];
    ak_jiggle_state states[4];
    ak_mat4 model[RIG_N], out[RIG_N];
    ak_jiggle_params params;
} rig_sim;

static void rig_init(rig_sim* s, ak_jiggle_params params) {
    memset(s, 0, sizeof(*s));
    s->params = params;
    s->joints[0] = (ak_jiggle_joint){.joint = 1};                        /* body: translation */
    s->joints[1] = (ak_jiggle_joint){.joint = 2, .tip = {0, 0, -0.4f}};  /* tail: rotation */
    s->joints[2] = (ak_jiggle_joint){.joint = 3, .tip = {0, 0, -0.4f}};
    s->joints[3] = (ak_jiggle_joint){.joint = 4, .tip = {0, 0, -0.4f}};
}

static ak_result rig_step(rig_sim* s, ak_mat4 root, float dt) {
    rig_model(root, s->model);
    ak_jiggle_job job = {.params = s->params, .parents = {rig_parents, RIG_N}, .joints = s->joints,
                         .joint_count = 4, .states = AK_SPAN(s->states), .model = {s->model, RIG_N}, .dt = dt,
                         .out_model = {s->out, RIG_N}};
    return ak_jiggle_run(&job);
}

static double mat_diff(const ak_mat4* a, const ak_mat4* b) {
    double e = 0.0;
    for (int i = 0; i < 16; ++i) e = fmax(e, fabs(a->m[i] - b->m[i]));
    return e;
}

AK_TEST(jiggle_static_parent_stays_at_rest) {
    rig_sim s;
    rig_init(&s, (ak_jiggle_params){.stiffness = 200.0f, .damping = 5.0f});
    ak_mat4 root = ak_mat4_mul(ak_mat4_translation(ak_vec3_make(1, 0, 2)),
                               ak_mat4_from_quat(ak_quat_from_axis_angle(ak_vec3_make(0, 1, 0), 0.7f)));
    double worst = 0.0;
    for (int f = 0; f < 120; ++f) {
        AK_CHECK_EQ(rig_step(&s, root, 1.0f / 60.0f), AK_OK);
        for (int i = 0; i < RIG_N; ++i) worst = fmax(worst, mat_diff(&s.out[i], &s.model[i]));
    }
    AK_CHECK_NEAR(worst, 0.0, 1e-6);
}

AK_TEST(jiggle_gravity_sag_equilibrium) {
    /* Translation jiggle under gravity settles at target + g / k (closed form). */
    rig_sim s;
    rig_init(&s, (ak_jiggle_params){.stiffness = 100.0f, .damping = 8.0f, .gravity = {0, -9.81f, 0}});
    for (int f = 0; f < 60 * 6; ++f) AK_CHECK_EQ(rig_step(&s, ak_mat4_identity(), 1.0f / 60.0f), AK_OK);
    AK_CHECK_NEAR(s.out[1].m[13] - s.model[1].m[13], -9.81 / 100.0, 1e-4);
    AK_CHECK_NEAR(s.out[1].m[12] - s.model[1].m[12], 0.0, 1e-6);
    /* The tail droops: its tip is below the rest tip, and bone lengths are kept. */
    AK_CHECK(s.out[5].m[13] < s.model[5].m[13] - 0.01f);
    for (int i = 3; i <= 5; ++i) {
        ak_vec3 a = ak_mat4_get_translation(s.out[i - 1]), b = ak_mat4_get_translation(s.out[i]);
        AK_CHECK_NEAR(ak_vec3_distance(a, b), 0.4, 1e-5);
    }
}

/* Offset of the body particle from its target after a unit step of the root along +X at t = 0. */
static void step_response(float fps, float seconds, double* out, int* out_count) {
    rig_sim s;
    rig_init(&s, (ak_jiggle_params){.stiffness = 100.0f, .damping = 4.0f});
    const float dt = 1.0f / fps;
    AK_CHECK_EQ(rig_step(&s, ak_mat4_identity(), dt), AK_OK);
    int n = (int)(seconds * fps + 0.5f);
    for (int f = 0; f < n; ++f) {
        AK_CHECK_EQ(rig_step(&s, ak_mat4_translation(ak_vec3_make(1, 0, 0)), dt), AK_OK);
        out[f] = s.out[1].m[12] - 1.0; /* model-space x of the body minus its new rest x */
    }
    *out_count = n;
}

AK_TEST(jiggle_step_overshoots_and_decays) {
    static double x[200 * 8];
    int n = 0;
    step_response(240.0f, 6.0f, x, &n);
    /* Damped oscillator x'' = -k x - c x': omega = 10, zeta = c / (2 omega) = 0.2. */
    const double k = 100.0, c = 4.0, w = sqrt(k), zeta = c / (2 * w), wd = w * sqrt(1 - zeta * zeta);
    double peak = 0.0, worst = 0.0;
    int crossings = 0;
    for (int f = 0; f < n; ++f) {
        double t = (f + 1) / 240.0;
        double ref = -exp(-zeta * w * t) * (cos(wd * t) + zeta * w / wd * sin(wd * t));
        worst = fmax(worst, fabs(x[f] - ref));
        peak = fmax(peak, x[f]);
        if (f > 0 && (x[f] > 0) != (x[f - 1] > 0)) ++crossings;
    }
    const double overshoot = exp(-zeta * PI_D / sqrt(1 - zeta * zeta)); /* 0.527 */
    AK_CHECK(peak > 0.0);
    AK_CHECK_NEAR(peak, overshoot, 0.02);
    AK_CHECK_NEAR(worst, 0.0, 0.03); /* whole trajectory near the closed form */
    AK_CHECK(crossings >= 4);         /* oscillates */
    /* Decays below 1% once the envelope exp(-zeta w t) is below 1%: t > ln(100) / 2 = 2.3 s. */
    double late = 0.0;
    for (int f = (int)(2.5 * 240); f < n; ++f) late = fmax(late, fabs(x[f]));
    AK_CHECK(late < 0.01);
    /* Successive positive peaks decrease. */
    double prev_peak = 1e9, cur = 0.0;
    int peaks = 0;
    for (int f = 1; f < n; ++f) {
        if (x[f] > 0) cur = fmax(cur, x[f]);
        if (x[f] <= 0 && x[f - 1] > 0) {
            AK_CHECK(cur < prev_peak);
            prev_peak = cur, cur = 0.0, ++peaks;
        }
    }
    AK_CHECK(peaks >= 2);
    /* The same step at 30, 60 and 144 fps: the same overshoot. */
    const float rates[3] = {30.0f, 60.0f, 144.0f};
    for (int r = 0; r < 3; ++r) {
        static double y[200 * 8];
        int m = 0;
        step_response(rates[r], 3.0f, y, &m);
        double pk = 0.0;
        for (int f = 0; f < m; ++f) pk = fmax(pk, y[f]);
        AK_CHECK_MSG(fabs(pk - peak) < 0.02, "overshoot at %g fps %g vs %g at 240 fps", rates[r], pk, peak);
    }
}

AK_TEST(jiggle_frame_rate_independent) {
    /* Smooth swaying (the same input curve at every rate), sampled at common times t = m/6 s
     * at 30, 60 and 144 fps. A step input is checked separately (its sampling itself differs). */
    const float rates[3] = {30.0f, 60.0f, 144.0f};
    enum { SAMPLES = 18 };
    double body[3][SAMPLES], tail[3][SAMPLES];
    for (int r = 0; r < 3; ++r) {
        rig_sim s;
        rig_init(&s, (ak_jiggle_params){.stiffness = 150.0f, .damping = 3.0f, .gravity = {0, -4.0f, 0}});
        const float dt = 1.0f / rates[r];
        const int per_sample = (int)(rates[r] / 6.0f + 0.5f);
        int frame = 0;
        /* Frame 0 at t = 0 starts every run in the same state (the first run only snaps). */
        ak_mat4 root0 = ak_mat4_identity();
        AK_CHECK_EQ(rig_step(&s, root0, dt), AK_OK);
        for (int m = 0; m < SAMPLES; ++m) {
            for (int f = 0; f < per_sample; ++f, ++frame) {
                double t = (frame + 1) * (double)dt;
                float x = (float)(0.4 * sin(5.0 * t));
                ak_quat q = ak_quat_from_axis_angle(ak_vec3_make(0, 1, 0), (float)(0.6 * sin(2.5 * t)));
                ak_mat4 root = ak_mat4_mul(ak_mat4_translation(ak_vec3_make(x, 0, 0)), ak_mat4_from_quat(q));
                AK_CHECK_EQ(rig_step(&s, root, dt), AK_OK);
            }
            body[r][m] = s.out[1].m[12] - s.model[1].m[12];
            tail[r][m] = ak_vec3_distance(ak_mat4_get_translation(s.out[5]), ak_mat4_get_translation(s.model[5]));
        }
    }
    double amp = 0.0, tamp = 0.0, d_body[2] = {0, 0}, d_tail[2] = {0, 0};
    for (int m = 0; m < SAMPLES; ++m) {
        amp = fmax(amp, fabs(body[2][m]));
        tamp = fmax(tamp, tail[2][m]);
        for (int r = 0; r < 2; ++r) {
            d_body[r] = fmax(d_body[r], fabs(body[r][m] - body[2][m]));
            d_tail[r] = fmax(d_tail[r], fabs(tail[r][m] - tail[2][m]));
        }
    }
    printf("  vs 144 fps: body 30 fps %.2g, 60 fps %.2g (amplitude %.2g); tail tip 30 fps %.2g, 60 fps %.2g "
           "(amplitude %.2g)\n", d_body[0], d_body[1], amp, d_tail[0], d_tail[1], tamp);
    AK_CHECK(amp > 0.05 && tamp > 0.1); /* the motion really jiggles */
    AK_CHECK(d_body[0] < 0.01 * amp && d_body[1] < 0.01 * amp);
    AK_CHECK(d_tail[0] < 0.01 * tamp && d_tail[1] < 0.01 * tamp);
}

AK_TEST(jiggle_descendants_follow_and_lengths_kept) {
    rig_sim s;
    rig_init(&s, (ak_jiggle_params){.stiffness = 80.0f, .damping = 2.0f});
    AK_CHECK_EQ(rig_step(&s, ak_mat4_identity(), 1.0f / 60.0f), AK_OK);
    double worst_len = 0.0, worst_local = 0.0, lag = 0.0;
    for (int f = 0; f < 60; ++f) {
        ak_quat q = ak_quat_from_axis_angle(ak_vec3_make(0, 1, 0), 1.2f); /* sudden turn */
        AK_CHECK_EQ(rig_step(&s, ak_mat4_from_quat(q), 1.0f / 60.0f), AK_OK);
        for (int i = 3; i <= 5; ++i) {
            ak_vec3 a = ak_mat4_get_translation(s.out[i - 1]), b = ak_mat4_get_translation(s.out[i]);
            worst_len = fmax(worst_len, fabs(ak_vec3_distance(a, b) - 0.4));
        }
        /* Joint 5 does not jiggle: its local transform relative to its jiggled parent is kept. */
        ak_mat4 l_out = ak_mat4_mul(ak_mat4_inverse_affine(s.out[4]), s.out[5]);
        ak_mat4 l_in = ak_mat4_mul(ak_mat4_inverse_affine(s.model[4]), s.model[5]);
        worst_local = fmax(worst_local, mat_diff(&l_out, &l_in));
        if (f == 2) lag = ak_vec3_distance(ak_mat4_get_translation(s.out[5]), ak_mat4_get_translation(s.model[5]));
    }
    AK_CHECK_NEAR(worst_len, 0.0, 1e-5);
    AK_CHECK_NEAR(worst_local, 0.0, 1e-5);
    AK_CHECK(lag > 0.1); /* the tail lags behind the turn */
    /* Rotation parts stay orthonormal (pure rotations applied to rigid frames). */
    ak_mat3 r = ak_mat4_to_mat3(s.out[3]);
    AK_CHECK_NEAR(ak_mat3_determinant(r), 1.0, 1e-5);
}

AK_TEST(jiggle_bad_input_codes) {
    rig_sim s;
    rig_init(&s, (ak_jiggle_params){.stiffness = 100.0f, .damping = 1.0f});
    rig_model(ak_mat4_identity(), s.model);
    for (int i = 0; i < RIG_N; ++i) s.out[i] = ak_mat4_scaling(ak_vec3_splat(9.0f));
    ak_jiggle_job zero = {0};
    AK_CHECK_EQ(ak_jiggle_run(&zero), AK_ERR_NULL_ARG);
    AK_CHECK_EQ(ak_jiggle_run(NULL), AK_ERR_NULL_ARG);
    ak_jiggle_job ok = {.params = s.params, .parents = {rig_parents, RIG_N}, .joints = s.joints, .joint_count = 4,
                        .states = AK_SPAN(s.states), .model = {s.model, RIG_N}, .dt = 0.01f,
                        .out_model = {s.out, RIG_N}};
    ak_jiggle_job j = ok;
    j.states = (ak_jiggle_state_span){NULL, 0};
    AK_CHECK_EQ(ak_jiggle_run(&j), AK_ERR_NULL_ARG);
    j = ok, j.joint_count = 0;
    AK_CHECK_EQ(ak_jiggle_run(&j), AK_ERR_NULL_ARG);
    j = ok, j.params.stiffness = -1.0f;
    AK_CHECK_EQ(ak_jiggle_run(&j), AK_ERR_BAD_ARG);
    j = ok, j.params.damping = NAN;
    AK_CHECK_EQ(ak_jiggle_run(&j), AK_ERR_BAD_ARG);
    j = ok, j.params.gravity.y = INFINITY;
    AK_CHECK_EQ(ak_jiggle_run(&j), AK_ERR_BAD_ARG);
    j = ok, j.model.count = RIG_N - 1;
    AK_CHECK_EQ(ak_jiggle_run(&j), AK_ERR_BAD_ARG);
    ak_jiggle_joint unsorted[4] = {s.joints[0], s.joints[2], s.joints[1], s.joints[3]};
    j = ok, j.joints = unsorted;
    AK_CHECK_EQ(ak_jiggle_run(&j), AK_ERR_BAD_ARG);
    ak_jiggle_joint oob[1] = {{.joint = RIG_N}};
    j = ok, j.joints = oob, j.joint_count = 1;
    AK_CHECK_EQ(ak_jiggle_run(&j), AK_ERR_BAD_INDEX);
    oob[0].joint = -1;
    AK_CHECK_EQ(ak_jiggle_run(&j), AK_ERR_BAD_INDEX);
    const int32_t loop[RIG_N] = {-1, 0, 3, 2, 3, 4};
    j = ok, j.parents = (ak_i32_cspan){loop, RIG_N};
    AK_CHECK_EQ(ak_jiggle_run(&j), AK_ERR_BAD_HIERARCHY);
    j = ok, j.states.count = 3;
    AK_CHECK_EQ(ak_jiggle_run(&j), AK_ERR_SPAN_SMALL);
    j = ok, j.out_model.count = RIG_N - 1;
    AK_CHECK_EQ(ak_jiggle_run(&j), AK_ERR_SPAN_SMALL);
    j = ok, j.dt = -0.01f;
    AK_CHECK_EQ(ak_jiggle_run(&j), AK_ERR_BAD_DATA);
    j = ok, j.dt = NAN;
    AK_CHECK_EQ(ak_jiggle_run(&j), AK_ERR_BAD_DATA);
    s.model[3].m[5] = NAN;
    AK_CHECK_EQ(ak_jiggle_run(&ok), AK_ERR_BAD_DATA);
    s.model[3].m[5] = 1.0f;
    /* Nothing was written: states still zero, outputs untouched. */
    ak_jiggle_state zs;
    memset(&zs, 0, sizeof(zs));
    AK_CHECK(memcmp(&s.states[0], &zs, sizeof(zs)) == 0);
    AK_CHECK_NEAR(s.out[2].m[0], 9.0, 0.0);
    AK_CHECK_EQ(ak_jiggle_run(&ok), AK_OK);
    AK_CHECK_EQ(s.states[0].initialized, 1);
    /* Defaults and the stability shortening of the substep. */
    ak_jiggle_params jp = ak_jiggle_params_resolved((ak_jiggle_params){.stiffness = 100.0f});
    AK_CHECK_NEAR(jp.substep, 1.0 / 240.0, 1e-9);
    AK_CHECK_EQ(jp.max_substeps, 64);
    jp = ak_jiggle_params_resolved((ak_jiggle_params){.stiffness = 1e4f, .substep = 0.01f});
    AK_CHECK_NEAR(jp.substep, 0.25 / 100.0, 1e-9);
    jp = ak_jiggle_params_resolved((ak_jiggle_params){.damping = 100.0f, .max_substeps = 5});
    AK_CHECK_NEAR(jp.substep, 0.25 / 100.0, 1e-9);
    AK_CHECK_EQ(jp.max_substeps, 5);
    /* A huge hitch is bounded by max_substeps and stays finite. */
    j = ok, j.dt = 1000.0f;
    AK_CHECK_EQ(ak_jiggle_run(&j), AK_OK);
    AK_CHECK(ak_mat4_is_finite(&s.out[5]));
}

int main(void) {
    AK_RUN(squash_preserves_volume_exactly);
    AK_RUN(normals_stay_perpendicular_to_deformed_surface);
    AK_RUN(bend_closed_form);
    AK_RUN(twist_closed_form);
    AK_RUN(deformer_stack_and_in_place);
    AK_RUN(deform_bad_input_codes);
    AK_RUN(bouncing_ball);
    AK_RUN(squash_tracker_from_motion);
    AK_RUN(jiggle_static_parent_stays_at_rest);
    AK_RUN(jiggle_gravity_sag_equilibrium);
    AK_RUN(jiggle_step_overshoots_and_decays);
    AK_RUN(jiggle_frame_rate_independent);
    AK_RUN(jiggle_descendants_follow_and_lengths_kept);
    AK_RUN(jiggle_bad_input_codes);
    return ak_test_finish();
}

/* Convex hull bodies against closed forms, brute-force references and physics. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <animkit/rigid.h>

#include "ak_test.h"
#include "rigid_world.h"
#include "rigid/rigid_impl.h"


/* Deterministic uniform numbers in [0, 1). */
static uint32_t rng_state = 12345u;
static float frand(void) {
    rng_state = rng_state * 1664525u + 1013904223u;
    return (float)(rng_state >> 8) / 16777216.0f;
}


static bool world_run(world* wd, float seconds, float* max_pen) {
    int steps = (int)lroundf(seconds * 60.0f);
    *max_pen = 0.0f;
    for (int s = 0; s < steps; ++s) {
        if (ak_rigid_step_run(&wd->job) != AK_OK) return false;
        *max_pen = ak_maxf(*max_pen, wd->pen);
    }
    return true;
}


static void box_corners(ak_vec3 he, ak_vec3* out) {
    for (int i = 0; i < 8; ++i)
        out[i] = ak_vec3_make(i & 1 ? he.x : -he.x, i & 2 ? he.y : -he.y, i & 4 ? he.z : -he.z);
}

/* A prism of k sides (radius r, half height h along Y). */
static size_t prism(int k, float r, float h, ak_vec3* out) {
    for (int i = 0; i < k; ++i) {
        float a = 6.2831853f * (float)i / (float)k;
        out[2 * i] = ak_vec3_make(r * cosf(a), -h, r * sinf(a));
        out[2 * i + 1] = ak_vec3_make(r * cosf(a), h, r * sinf(a));
    }
    return (size_t)(2 * k);
}

static int cmp_float(const void* a, const void* b) {
    float x = *(const float*)a, y = *(const float*)b;
    return x < y ? -1 : (x > y);
}

AK_TEST(box_corners_hull_inertia_is_the_box_closed_form) {
    /* a box's 8 corners plus interior points and repeats, in a shape frame offset from the
     * centre: mass, volume and principal moments of the solid box, no rotation */
    ak_vec3 he = {1.0f, 0.5f, 0.25f}, off = {3.0f, -1.0f, 2.0f};
    ak_vec3 pts[20];
    box_corners(he, pts);
    for (int i = 0; i < 8; ++i) pts[8 + i] = ak_vec3_scale(pts[i], 0.3f);
    pts[16] = pts[0], pts[17] = pts[5], pts[18] = ak_vec3_zero(), pts[19] = pts[7];
    for (int i = 0; i < 20; ++i) pts[i] = ak_vec3_add(pts[i], off);
    ak_rigid_body_desc b = {.shape = {.type = AK_RIGID_HULL, .points = {pts, 20}},
                            .mass = 6.0f,
                            .position = {0.0f, 1.0f, 0.0f}};
    ak_rigid_model* m = NULL;
    ak_rigid_model_desc md = {.bodies = {&b, 1}};
    AK_CHECK_EQ(ak_rigid_model_create(&md, NULL, &m), AK_OK);
    AK_CHECK_NEAR(ak_rigid_body_volume(m, 0), 8.0 * 1.0 * 0.5 * 0.25, 1e-5);
    ak_vec3 in = ak_rigid_body_inertia(m, 0);
    float mass = 6.0f;
    AK_CHECK_NEAR(in.x, mass * (0.25f + 0.0625f) / 3.0f, 1e-5f);
    AK_CHECK_NEAR(in.y, mass * (1.0f + 0.0625f) / 3.0f, 1e-5f);
    AK_CHECK_NEAR(in.z, mass * (1.0f + 0.25f) / 3.0f, 1e-5f);
    ak_rigid_body_desc r = ak_rigid_body_get_desc(m, 0);
    /* the body sits at the centre of mass: the shape frame's position plus the offset */
    AK_CHECK_NEAR(r.position.x, 3.0f, 1e-5f);
    AK_CHECK_NEAR(r.position.y, 0.0f, 1e-5f);
    AK_CHECK_NEAR(r.position.z, 2.0f, 1e-5f);
    AK_CHECK_NEAR(fabsf(r.orientation.w), 1.0f, 1e-6f);
    AK_CHECK_EQ(r.shape.points.count, (size_t)8); /* interior points dropped */
    ak_transform sf = ak_rigid_body_shape_frame(m, 0);
    AK_CHECK_NEAR(sf.translation.x, -3.0f, 1e-5f);
    AK_CHECK_NEAR(sf.translation.y, 1.0f, 1e-5f);
    const akp_hull* h = m->bodies[0].hull;
    AK_CHECK_EQ(h->nf, 6u); /* coplanar triangles merged into the box's 6 faces */
    AK_CHECK_EQ(h->ne, 12u);
    ak_rigid_model_destroy(m);

    /* the same box turned by an arbitrary rotation: the inertia tensor in the points' frame is
     * full; its principal moments are the box's, and the body frame's axes are the box's */
    ak_quat rot = ak_quat_normalize((ak_quat){0.3f, -0.5f, 0.2f, 0.8f});
    box_corners(he, pts);
    for (int i = 0; i < 8; ++i) pts[i] = ak_quat_rotate(rot, pts[i]);
    b.shape.points = (ak_vec3_cspan){pts, 8};
    AK_CHECK_EQ(ak_rigid_model_create(&md, NULL, &m), AK_OK);
    in = ak_rigid_body_inertia(m, 0);
    float got[3] = {in.x, in.y, in.z};
    float want[3] = {mass * (0.25f + 0.0625f) / 3.0f, mass * (1.0f + 0.0625f) / 3.0f,
                     mass * (1.0f + 0.25f) / 3.0f};
    qsort(got, 3, sizeof got[0], cmp_float);
    for (int k = 0; k < 3; ++k) AK_CHECK_NEAR(got[k], want[k], 1e-4f);
    /* the body axis with the smallest moment is the box's long axis, rot * X */
    r = ak_rigid_body_get_desc(m, 0);
    int kmin = in.x <= in.y && in.x <= in.z ? 0 : (in.y <= in.z ? 1 : 2);
    ak_vec3 e = {kmin == 0, kmin == 1, kmin == 2};
    ak_vec3 long_axis = ak_quat_rotate(r.orientation, e);
    AK_CHECK_NEAR(fabsf(ak_vec3_dot(long_axis, ak_quat_rotate(rot, ak_vec3_make(1, 0, 0)))), 1.0f,
                  1e-4f);
    ak_rigid_model_destroy(m);
}

AK_TEST(sampled_sphere_hull_approaches_the_sphere) {
    /* 600 points on a unit sphere (Fibonacci lattice): the inscribed polyhedron's volume and
     * moment per mass approach 4/3 pi and 2/5 from below (measured 0.990 and 0.3974) */
    enum { N = 600 };
    static ak_vec3 pts[N];
    for (int i = 0; i < N; ++i) {
        float y = 1.0f - 2.0f * ((float)i + 0.5f) / (float)N, r = sqrtf(1.0f - y * y);
        float ph = 2.39996323f * (float)i;
        pts[i] = ak_vec3_make(r * cosf(ph), y, r * sinf(ph));
    }
    ak_rigid_body_desc b = {.shape = {.type = AK_RIGID_HULL, .points = {pts, N}}, .density = 1.0f};
    ak_rigid_model* m = NULL;
    ak_rigid_model_desc md = {.bodies = {&b, 1}};
    AK_CHECK_EQ(ak_rigid_model_create(&md, NULL, &m), AK_OK);
    double vol = ak_rigid_body_volume(m, 0), sphere = 4.0 / 3.0 * 3.14159265358979;
    AK_CHECK_MSG(vol < sphere && vol > 0.985 * sphere, "volume %g vs %g", vol, sphere);
    ak_vec3 in = ak_rigid_body_inertia(m, 0);
    float mass = ak_rigid_body_mass(m, 0);
    for (int k = 0; k < 3; ++k) {
        float ipm = (k == 0 ? in.x : (k == 1 ? in.y : in.z)) / mass;
        AK_CHECK_MSG(fabsf(ipm - 0.4f) < 0.01f * 0.4f, "I/m %g vs 0.4", ipm);
    }
    AK_CHECK_EQ(m->bodies[0].hull->nv, (uint32_t)N); /* every point is a vertex */
    ak_rigid_model_destroy(m);
}

AK_TEST(degenerate_hulls_are_refused) {
    ak_vec3 flat[6] = {{0, 0, 0}, {1, 0, 0}, {0, 0, 1}, {1, 0, 1}, {0.5f, 0, 0.5f}, {2, 0, 3}};
    ak_vec3 line[5] = {{0, 0, 0}, {1, 1, 1}, {2, 2, 2}, {3, 3, 3}, {0.5f, 0.5f, 0.5f}};
    const char* why = NULL;
    AK_CHECK_EQ(ak_rigid_hull_check((ak_vec3_cspan){flat, 6}, &why), AK_ERR_BAD_ARG);
    AK_CHECK(strstr(why, "plane") != NULL);
    AK_CHECK_EQ(ak_rigid_hull_check((ak_vec3_cspan){line, 5}, &why), AK_ERR_BAD_ARG);
    AK_CHECK(strstr(why, "line") != NULL);
    AK_CHECK_EQ(ak_rigid_hull_check((ak_vec3_cspan){flat, 3}, &why), AK_ERR_BAD_ARG);
    flat[2].y = NAN;
    ak_rigid_body_desc b = {.shape = {.type = AK_RIGID_HULL, .points = {flat, 6}}};
    ak_rigid_model* m = NULL;
    ak_rigid_model_desc md = {.bodies = {&b, 1}};
    AK_CHECK_EQ(ak_rigid_model_create(&md, NULL, &m), AK_ERR_BAD_DATA);
    flat[2].y = 0.0f;
    AK_CHECK_EQ(ak_rigid_model_create(&md, NULL, &m), AK_ERR_BAD_ARG);
    AK_CHECK(m == NULL);
    b.shape.points.count = AK_RIGID_HULL_MAX_POINTS + 1;
    AK_CHECK_EQ(ak_rigid_model_create(&md, NULL, &m), AK_ERR_BAD_ARG);
    b.shape.points = (ak_vec3_cspan){NULL, 8};
    AK_CHECK_EQ(ak_rigid_model_create(&md, NULL, &m), AK_ERR_NULL_ARG);
    /* hard but valid: a 4 x 4 x 4 grid (collinear and coplanar points everywhere) and points
     * scattered on a box's faces; the hull is the cube, 6 faces */
    static ak_vec3 grid[64 + 200];
    for (int i = 0; i < 64; ++i) grid[i] = ak_vec3_make((float)(i % 4), (float)(i / 4 % 4), (float)(i / 16));
    for (int i = 0; i < 200; ++i) {
        float u = 3.0f * frand(), v = 3.0f * frand();
        int f = i % 6;
        float c = f & 1 ? 3.0f : 0.0f;
        grid[64 + i] = f < 2 ? ak_vec3_make(c, u, v) : (f < 4 ? ak_vec3_make(u, c, v) : ak_vec3_make(u, v, c));
    }
    b.shape.points = (ak_vec3_cspan){grid, 64 + 200};
    AK_CHECK_EQ(ak_rigid_model_create(&md, NULL, &m), AK_OK);
    AK_CHECK_NEAR(ak_rigid_body_volume(m, 0), 27.0, 1e-4);
    AK_CHECK_EQ(m->bodies[0].hull->nf, 6u);
    ak_rigid_model_destroy(m);
    /* nearly flat: 1e-9 m of relief on a 1 m square is no volume */
    ak_vec3 thin[5] = {{0, 0, 0}, {1, 0, 0}, {0, 0, 1}, {1, 0, 1}, {0.5f, 1e-9f, 0.5f}};
    AK_CHECK_EQ(ak_rigid_hull_check((ak_vec3_cspan){thin, 5}, &why), AK_ERR_BAD_ARG);
}

/* ---- GJK against brute force ---- */

static ak_vec3 closest_on_seg(ak_vec3 p, ak_vec3 a, ak_vec3 b) {
    ak_vec3 ab = ak_vec3_sub(b, a);
    float t = ak_vec3_dot(ak_vec3_sub(p, a), ab) / ak_vec3_dot(ab, ab);
    return ak_vec3_madd(a, ab, ak_clampf(t, 0.0f, 1.0f));
}

/* Distance from p to triangle abc: inside the prism over the triangle, the plane distance;
 * otherwise the nearest of the three edges. */
static double point_triangle(ak_vec3 p, ak_vec3 a, ak_vec3 b, ak_vec3 c) {
    ak_vec3 n = ak_vec3_cross(ak_vec3_sub(b, a), ak_vec3_sub(c, a));
    float nl = ak_vec3_length(n);
    double best = INFINITY;
    if (nl > 1e-9f) {
        n = ak_vec3_scale(n, 1.0f / nl);
        float s = ak_vec3_dot(ak_vec3_sub(p, a), n);
        ak_vec3 q = ak_vec3_madd(p, n, -s);
        bool in = ak_vec3_dot(ak_vec3_cross(ak_vec3_sub(b, a), ak_vec3_sub(q, a)), n) >= 0 &&
                  ak_vec3_dot(ak_vec3_cross(ak_vec3_sub(c, b), ak_vec3_sub(q, b)), n) >= 0 &&
                  ak_vec3_dot(ak_vec3_cross(ak_vec3_sub(a, c), ak_vec3_sub(q, c)), n) >= 0;
        if (in) best = fabsf(s);
    }
    const ak_vec3 v[3] = {a, b, c};
    for (int k = 0; k < 3; ++k)
        best = fmin(best, ak_vec3_distance(p, closest_on_seg(p, v[k], v[(k + 1) % 3])));
    return best;
}

/* Segment-segment distance by ternary search of the convex function of one parameter. */
static double seg_seg(ak_vec3 a0, ak_vec3 a1, ak_vec3 b0, ak_vec3 b1) {
    double lo = 0.0, hi = 1.0;
    for (int it = 0; it < 60; ++it) {
        double m1 = lo + (hi - lo) / 3.0, m2 = hi - (hi - lo) / 3.0;
        ak_vec3 p1 = ak_vec3_lerp(a0, a1, (float)m1), p2 = ak_vec3_lerp(a0, a1, (float)m2);
        double f1 = ak_vec3_distance(p1, closest_on_seg(p1, b0, b1));
        double f2 = ak_vec3_distance(p2, closest_on_seg(p2, b0, b1));
        if (f1 < f2)
            hi = m2;
        else
            lo = m1;
    }
    ak_vec3 p = ak_vec3_lerp(a0, a1, (float)(0.5 * (lo + hi)));
    return ak_vec3_distance(p, closest_on_seg(p, b0, b1));
}

/* Distance between the hulls of two point sets: every point against every triangle of the
 * other's points, every segment against every segment. */
static double brute_distance(const ak_vec3* a, int na, const ak_vec3* b, int nb) {
    double best = INFINITY;
    for (int pass = 0; pass < 2; ++pass) {
        const ak_vec3* p = pass ? b : a;
        const ak_vec3* t = pass ? a : b;
        int np = pass ? nb : na, nt = pass ? na : nb;
        for (int i = 0; i < np; ++i)
            for (int j = 0; j < nt; ++j)
                for (int k = j + 1; k < nt; ++k)
                    for (int l = k + 1; l < nt; ++l)
                        best = fmin(best, point_triangle(p[i], t[j], t[k], t[l]));
    }
    for (int i = 0; i < na; ++i)
        for (int j = i + 1; j < na; ++j)
            for (int k = 0; k < nb; ++k)
                for (int l = k + 1; l < nb; ++l) best = fmin(best, seg_seg(a[i], a[j], b[k], b[l]));
    return best;
}

static ak_quat random_quat(void) {
    ak_quat q = {frand() - 0.5f, frand() - 0.5f, frand() - 0.5f, frand() - 0.5f};
    return ak_quat_normalize(q);
}

AK_TEST(gjk_distance_matches_brute_force) {
    enum { NP = 7 };
    size_t hs = akp_rigid_hull_size(NP), ss = akp_rigid_hull_scratch_size(NP);
    void* mem_a = malloc(hs);
    void* mem_b = malloc(hs);
    void* scratch = malloc(ss);
    AK_CHECK(mem_a && mem_b && scratch);
    double worst = 0.0;
    int pairs = 0;
    for (int trial = 0; trial < 60; ++trial) {
        ak_vec3 pa[NP], pb[NP];
        for (int i = 0; i < NP; ++i) {
            pa[i] = ak_vec3_make(frand() - 0.5f, frand() - 0.5f, frand() - 0.5f);
            pb[i] = ak_vec3_make(frand() - 0.5f, 0.5f * (frand() - 0.5f), frand() - 0.5f);
        }
        akp_hull *ha, *hb;
        const char* why;
        if (akp_rigid_hull_build((ak_vec3_cspan){pa, NP}, mem_a, scratch, &ha, &why) != AK_OK ||
            akp_rigid_hull_build((ak_vec3_cspan){pb, NP}, mem_b, scratch, &hb, &why) != AK_OK)
            continue;
        ak_rigid_shape sa = {.type = AK_RIGID_HULL}, sb = {.type = AK_RIGID_HULL};
        ak_vec3 dir = ak_vec3_normalize(ak_vec3_make(frand() - 0.5f, frand() - 0.5f, frand() - 0.5f));
        rigid_pose posea = {ak_vec3_make(0.2f, 1.0f, -0.3f), random_quat()};
        rigid_pose poseb = {ak_vec3_madd(posea.x, dir, 1.9f + frand()), random_quat()};
        /* the hull's vertices in the world (body frame = centre of mass, principal axes) */
        ak_vec3 wa[NP], wb[NP];
        for (uint32_t i = 0; i < ha->nv; ++i)
            wa[i] = ak_vec3_add(posea.x, ak_quat_rotate(posea.q, ha->verts[i]));
        for (uint32_t i = 0; i < hb->nv; ++i)
            wb[i] = ak_vec3_add(poseb.x, ak_quat_rotate(poseb.q, hb->verts[i]));
        ak_vec3 ca, cb;
        bool apart = akp_rigid_gjk(&sa, ha, posea, &sb, hb, poseb, &ca, &cb);
        double ref = brute_distance(wa, (int)ha->nv, wb, (int)hb->nv);
        if (ref < 1e-3) continue;
        AK_CHECK(apart);
        double d = ak_vec3_distance(ca, cb);
        worst = fmax(worst, fabs(d - ref));
        ++pairs;
        /* a sphere's centre (a point core) against the hull, too */
        ak_rigid_shape sp = {.type = AK_RIGID_SPHERE, .radius = 0.1f};
        rigid_pose posep = {poseb.x, ak_quat_identity()};
        apart = akp_rigid_gjk(&sa, ha, posea, &sp, NULL, posep, &ca, &cb);
        double ref_p = INFINITY;
        for (uint32_t j = 0; j < ha->nv; ++j)
            for (uint32_t k = j + 1; k < ha->nv; ++k)
                for (uint32_t l = k + 1; l < ha->nv; ++l)
                    ref_p = fmin(ref_p, point_triangle(poseb.x, wa[j], wa[k], wa[l]));
        AK_CHECK(apart);
        worst = fmax(worst, fabs(ak_vec3_distance(ca, cb) - ref_p));
    }
    AK_CHECK_MSG(pairs >= 40, "only %d pairs", pairs);
    AK_CHECK_MSG(worst < 1e-4, "worst GJK error %g m", worst);
    if (getenv("AK_TEST_VERBOSE")) printf("GJK: %d pairs, worst error %g m\n", pairs, worst);
    /* overlapping hulls are reported as such */
    {
        ak_vec3 c8[8];
        box_corners(ak_vec3_make(0.5f, 0.5f, 0.5f), c8);
        akp_hull *ha, *hb;
        const char* why;
        akp_rigid_hull_build((ak_vec3_cspan){c8, 8}, mem_a, scratch, &ha, &why);
        akp_rigid_hull_build((ak_vec3_cspan){c8, 8}, mem_b, scratch, &hb, &why);
        ak_rigid_shape s = {.type = AK_RIGID_HULL};
        rigid_pose p0 = {ak_vec3_zero(), ak_quat_identity()};
        rigid_pose p1 = {ak_vec3_make(0.9f, 0.2f, 0.0f), random_quat()};
        ak_vec3 ca, cb;
        AK_CHECK(!akp_rigid_gjk(&s, ha, p0, &s, hb, p1, &ca, &cb));
    }
    free(mem_a);
    free(mem_b);
    free(scratch);
}

/* ---- dynamics ---- */

static ak_rigid_body_desc ground(void) {
    ak_rigid_body_desc g = {.shape = {.type = AK_RIGID_PLANE}, .is_static = true};
    return g;
}

AK_TEST(hull_rests_on_a_plane) {
    /* a hexagonal prism (12 points, radius 0.4, height 0.6) set down on its hex face */
    ak_vec3 pts[12];
    prism(6, 0.4f, 0.3f, pts);
    ak_rigid_body_desc b[2] = {ground(),
                               {.shape = {.type = AK_RIGID_HULL, .points = {pts, 12}},
                                .position = {1.0f, 0.305f, -2.0f}}};
    world wd;
    AK_CHECK(world_init(&wd, b, 2, 20));
    float pen;
    AK_CHECK(world_run(&wd, 3.0f, &pen));
    float drift = sqrtf((wd.x[1].x - 1.0f) * (wd.x[1].x - 1.0f) +
                        (wd.x[1].z + 2.0f) * (wd.x[1].z + 2.0f));
    AK_CHECK_MSG(drift < 1e-3f, "slid %g m", drift);
    if (getenv("AK_TEST_VERBOSE")) printf("prism: slid %g m, height %g\n", drift, wd.x[1].y);
    AK_CHECK_MSG(fabsf(wd.x[1].y - 0.3f) < 0.01f, "height %g vs 0.3", wd.x[1].y);
    AK_CHECK_MSG(pen < 0.01f, "penetration %g", pen);
    ak_vec3 up = ak_quat_rotate(wd.q[1], ak_vec3_make(0, 1, 0));
    AK_CHECK_MSG(fabsf(up.y) > 0.9999f, "tilted: up.y %g", up.y);
    world_free(&wd);
}

AK_TEST(hull_stack_stands) {
    /* five hexagonal prisms stacked (hull on hull: face clipping, 6-point manifolds), 3 s */
    enum { K = 5 };
    ak_vec3 pts[12];
    prism(6, 0.5f, 0.25f, pts);
    ak_rigid_body_desc b[K + 1];
    b[0] = ground();
    for (int i = 1; i <= K; ++i)
        b[i] = (ak_rigid_body_desc){.shape = {.type = AK_RIGID_HULL, .points = {pts, 12}},
                                    .position = {0.0f, 0.25f + 0.5f * (float)(i - 1), 0.0f}};
    world wd;
    AK_CHECK(world_init(&wd, b, K + 1, 30));
    float pen;
    AK_CHECK(world_run(&wd, 3.0f, &pen));
    float drift = 0.0f;
    for (int i = 1; i <= K; ++i) {
        drift = ak_maxf(drift, sqrtf(wd.x[i].x * wd.x[i].x + wd.x[i].z * wd.x[i].z));
        drift = ak_maxf(drift, fabsf(wd.x[i].y - (0.25f + 0.5f * (float)(i - 1))));
    }
    AK_CHECK_MSG(drift < 1e-3f, "drift %g m", drift);
    AK_CHECK_MSG(pen < 0.01f, "penetration %g m (contact offset 0.01)", pen);
    if (getenv("AK_TEST_VERBOSE")) printf("hull stack: drift %g m, penetration %g m\n", drift, pen);
    world_free(&wd);
}

AK_TEST(tetrahedron_lands_on_a_face) {
    /* a regular tetrahedron (edge a) dropped corner first: it ends on a face, its centre of
     * mass at the inradius a / (2 sqrt 6) */
    float a = 0.6f, s = a / (2.0f * sqrtf(2.0f));
    ak_vec3 pts[4] = {{s, s, s}, {s, -s, -s}, {-s, s, -s}, {-s, -s, s}};
    ak_quat tilt = ak_quat_normalize((ak_quat){0.2f, 0.1f, -0.3f, 0.9f});
    ak_rigid_body_desc b[2] = {ground(),
                               {.shape = {.type = AK_RIGID_HULL, .points = {pts, 4}},
                                .position = {0.0f, 0.8f, 0.0f},
                                .orientation = tilt,
                                .friction = 0.8f}};
    world wd;
    AK_CHECK(world_init(&wd, b, 2, 20));
    float pen;
    AK_CHECK(world_run(&wd, 4.0f, &pen));
    float inr = a / (2.0f * sqrtf(6.0f));
    AK_CHECK_MSG(fabsf(wd.x[1].y - inr) < 3e-3f, "height %g vs inradius %g", wd.x[1].y, inr);
    if (getenv("AK_TEST_VERBOSE")) printf("tetrahedron: height %g vs inradius %g\n", wd.x[1].y, inr);
    /* three corners on the ground, one at the tetrahedron's height above it */
    ak_rigid_body_desc r = ak_rigid_body_get_desc(wd.model, 1);
    int low = 0;
    float top = 0.0f;
    for (size_t i = 0; i < r.shape.points.count; ++i) {
        float y = wd.x[1].y + ak_quat_rotate(wd.q[1], r.shape.points.ptr[i]).y;
        if (fabsf(y) < 3e-3f) ++low;
        top = ak_maxf(top, y);
    }
    AK_CHECK_EQ(low, 3);
    AK_CHECK_NEAR(top, a * sqrtf(2.0f / 3.0f), 4e-3f);
    world_free(&wd);
}

AK_TEST(shapes_rest_on_a_static_hull) {
    /* a static hull (a 4 x 1 x 4 box's corners, top at y = 0.5) carries a sphere, a capsule lying
     * down, a box and a hull tetrahedron... each comes to rest at its closed-form height */
    ak_vec3 slab[8];
    box_corners(ak_vec3_make(2.0f, 0.5f, 2.0f), slab);
    ak_vec3 cube[8];
    box_corners(ak_vec3_make(0.2f, 0.2f, 0.2f), cube);
    ak_quat lying = ak_quat_from_axis_angle(ak_vec3_make(0, 0, 1), 1.5707963f);
    ak_rigid_body_desc b[5] = {
        {.shape = {.type = AK_RIGID_HULL, .points = {slab, 8}}, .is_static = true},
        {.shape = {.type = AK_RIGID_SPHERE, .radius = 0.2f}, .position = {-1.2f, 0.72f, 0.0f}},
        {.shape = {.type = AK_RIGID_CAPSULE, .radius = 0.15f, .half_height = 0.3f},
         .position = {0.0f, 0.66f, -1.0f},
         .orientation = lying},
        {.shape = {.type = AK_RIGID_BOX, .half_extents = {0.2f, 0.2f, 0.2f}},
         .position = {1.2f, 0.71f, 0.0f}},
        {.shape = {.type = AK_RIGID_HULL, .points = {cube, 8}}, .position = {0.0f, 0.71f, 1.0f}},
    };
    const float want[5] = {0.0f, 0.7f, 0.65f, 0.7f, 0.7f};
    world wd;
    AK_CHECK(world_init(&wd, b, 5, 20));
    float pen;
    AK_CHECK(world_run(&wd, 2.0f, &pen));
    for (int i = 1; i < 5; ++i) {
        AK_CHECK_MSG(fabsf(wd.x[i].y - want[i]) < 0.01f, "body %d at %g, want %g", i, wd.x[i].y,
                     want[i]);
        AK_CHECK_MSG(ak_vec3_length(wd.v[i]) < 0.02f, "body %d still moving %g", i,
                     ak_vec3_length(wd.v[i]));
    }
    AK_CHECK_MSG(pen < 0.01f, "penetration %g", pen);
    world_free(&wd);
}

AK_TEST(deep_overlaps_with_a_hull_push_out_through_the_nearest_face) {
    /* a sphere whose centre, a capsule whose segment and a hull cube whose centre lie inside a
     * static hull slab, just under its top face (the separating axis path, not GJK's): their
     * contacts push them up through the top, by the depth of their lowest points (the solver
     * would turn such an overlap into a launch: XPBD derives velocities from positions, so this
     * checks the narrow phase itself) */
    ak_vec3 slab[8];
    box_corners(ak_vec3_make(2.0f, 0.5f, 2.0f), slab);
    ak_vec3 cube[8];
    box_corners(ak_vec3_make(0.2f, 0.2f, 0.2f), cube);
    ak_quat lying = ak_quat_from_axis_angle(ak_vec3_make(0, 0, 1), 1.5707963f);
    ak_rigid_body_desc b[4] = {
        {.shape = {.type = AK_RIGID_HULL, .points = {slab, 8}}, .is_static = true},
        {.shape = {.type = AK_RIGID_SPHERE, .radius = 0.2f}, .position = {-1.2f, 0.45f, 0.0f}},
        {.shape = {.type = AK_RIGID_CAPSULE, .radius = 0.15f, .half_height = 0.3f},
         .position = {0.0f, 0.4f, -1.0f},
         .orientation = lying},
        {.shape = {.type = AK_RIGID_HULL, .points = {cube, 8}}, .position = {0.3f, 0.42f, 1.0f}},
    };
    const float depth[4] = {0.0f, 0.25f, 0.25f, 0.28f};
    const int points[4] = {0, 1, 2, 4};
    ak_rigid_model* m = NULL;
    ak_rigid_model_desc md = {.bodies = {b, 4}};
    AK_CHECK_EQ(ak_rigid_model_create(&md, NULL, &m), AK_OK);
    ak_rigid_body_desc d0 = ak_rigid_body_get_desc(m, 0);
    rigid_pose pb = {d0.position, d0.orientation};
    for (uint32_t i = 1; i < 4; ++i) {
        ak_rigid_body_desc d = ak_rigid_body_get_desc(m, i);
        rigid_pose pa = {d.position, d.orientation};
        rigid_contact c[AKP_RIGID_MAX_PAIR_CONTACTS];
        int n = akp_rigid_collide(m, i, 0, pa, pb, 0.01f, c, AKP_RIGID_MAX_PAIR_CONTACTS);
        AK_CHECK_EQ(n, points[i]);
        for (int k = 0; k < n; ++k) {
            AK_CHECK_MSG(c[k].n.y > 0.9999f, "body %u: normal %g %g %g", i, c[k].n.x, c[k].n.y,
                         c[k].n.z);
            AK_CHECK_NEAR(c[k].depth, depth[i], 1e-4f);
        }
    }
    ak_rigid_model_destroy(m);
}

AK_TEST(hull_scene_keys) {
    const char* good =
        "{\"bodies\": [{\"shape\": {\"type\": \"plane\"}},"
        " {\"shape\": {\"type\": \"hull\", \"points\": [[0,0,0],[1,0,0],[0,1,0],[0,0,1]]},"
        "  \"position\": [0, 2, 0]}]}";
    ak_rigid_scene sc;
    ak_diag diag;
    ak_rigid_scene_defaults(&sc);
    AK_CHECK_EQ(ak_rigid_scene_load_bytes(good, strlen(good), "t", &sc, &diag), AK_OK);
    AK_CHECK_EQ(sc.body_count, (size_t)2);
    AK_CHECK_EQ(sc.bodies[1].shape.type, AK_RIGID_HULL);
    AK_CHECK_EQ(sc.bodies[1].shape.points.count, (size_t)4);
    ak_rigid_scene_run run;
    AK_CHECK_EQ(ak_rigid_scene_run_init(&run, &sc, "t", &diag), AK_OK);
    /* the corner tetrahedron's centre of mass is at a quarter of each axis */
    AK_CHECK_NEAR(run.positions[1].y, 2.25f, 1e-5f);
    ak_rigid_scene_run_free(&run);
    ak_rigid_scene_free(&sc);
    const char* comp =
        "{\"bodies\": [{\"shape\": {\"type\": \"compound\", \"children\": ["
        " {\"shape\": {\"type\": \"box\", \"half_extents\": [1, 0.25, 0.5]}},"
        " {\"shape\": {\"type\": \"hull\", \"points\": [[0,0,0],[1,0,0],[0,1,0],[0,0,1]]},"
        "  \"position\": [0.75, 1, 0], \"orientation\": [0, 0, 0, 1]}]}}]}";
    ak_rigid_scene_defaults(&sc);
    AK_CHECK_EQ(ak_rigid_scene_load_bytes(comp, strlen(comp), "t", &sc, &diag), AK_OK);
    AK_CHECK_EQ(sc.bodies[0].shape.type, AK_RIGID_COMPOUND);
    AK_CHECK_EQ(sc.bodies[0].shape.child_count, (size_t)2);
    AK_CHECK_EQ(sc.bodies[0].shape.children[1].shape.points.count, (size_t)4);
    AK_CHECK_NEAR(sc.bodies[0].shape.children[1].position.x, 0.75f, 0.0f);
    AK_CHECK_EQ(ak_rigid_scene_run_init(&run, &sc, "t", &diag), AK_OK);
    ak_rigid_scene_run_free(&run);
    ak_rigid_scene_free(&sc);
    const char* bad[] = {
        "{\"bodies\": [{\"shape\": {\"type\": \"compound\", \"children\": [{\"shape\": {\"type\": \"plane\"}}]}}]}",
        "{\"bodies\": [{\"shape\": {\"type\": \"compound\", \"children\": []}}]}",
        "{\"bodies\": [{\"shape\": {\"type\": \"compound\", \"children\": [{\"shape\": {\"type\": \"sphere\", \"radius\": 1}, \"mass\": 1}]}}]}",
        "{\"bodies\": [{\"shape\": {\"type\": \"hull\", \"points\": [[0,0,0],[1,0,0],[0,0,1],[1,0,1]]}}]}",
        "{\"bodies\": [{\"shape\": {\"type\": \"hull\", \"points\": [[0,0,0],[1,0,0],[0,1,0]]}}]}",
        "{\"bodies\": [{\"shape\": {\"type\": \"hull\", \"points\": [[0,0,0],[1,0,0],[0,1,0],[0,0]]}}]}",
        "{\"bodies\": [{\"shape\": {\"type\": \"hull\"}}]}",
        "{\"bodies\": [{\"shape\": {\"type\": \"hull\", \"radius\": 1, \"points\": []}}]}",
    };
    const char* where[] = {"bodies[0].shape.children[0].shape.type: a compound's child",
                           "bodies[0].shape.children: is required",
                           "bodies[0].shape.children[0]: unknown key \"mass\"",
                           "bodies[0].shape.points: the points are all in one plane",
                           "bodies[0].shape.points", "bodies[0].shape.points[3]",
                           "bodies[0].shape.points", "bodies[0].shape.radius"};
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; ++i) {
        ak_rigid_scene_defaults(&sc);
        AK_CHECK_EQ(ak_rigid_scene_load_bytes(bad[i], strlen(bad[i]), "t", &sc, &diag), AK_ERR_PARSE);
        AK_CHECK_MSG(strstr(diag.message, where[i]) != NULL, "%s", diag.message);
        ak_rigid_scene_free(&sc);
    }
}

/* Eigenvalues of a symmetric 3x3 by the trigonometric solution of its characteristic cubic
 * (Smith 1961), ascending. */
static void sym_eigenvalues(double a[3][3], double out[3]) {
    double p1 = a[0][1] * a[0][1] + a[0][2] * a[0][2] + a[1][2] * a[1][2];
    double q = (a[0][0] + a[1][1] + a[2][2]) / 3.0;
    double p2 = (a[0][0] - q) * (a[0][0] - q) + (a[1][1] - q) * (a[1][1] - q) +
                (a[2][2] - q) * (a[2][2] - q) + 2.0 * p1;
    double p = sqrt(p2 / 6.0);
    double b[3][3];
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) b[i][j] = (a[i][j] - (i == j ? q : 0.0)) / p;
    double det = b[0][0] * (b[1][1] * b[2][2] - b[1][2] * b[2][1]) -
                 b[0][1] * (b[1][0] * b[2][2] - b[1][2] * b[2][0]) +
                 b[0][2] * (b[1][0] * b[2][1] - b[1][1] * b[2][0]);
    double r = det / 2.0;
    double phi = r <= -1.0 ? 3.14159265358979 / 3.0 : (r >= 1.0 ? 0.0 : acos(r) / 3.0);
    double e1 = q + 2.0 * p * cos(phi), e3 = q + 2.0 * p * cos(phi + 2.0 * 3.14159265358979 / 3.0);
    out[2] = e1, out[0] = e3, out[1] = 3.0 * q - e1 - e3;
}

AK_TEST(compound_l_shape_inertia) {
    /* an L of two boxes (2 x 0.5 x 1 lying, 0.5 x 1.5 x 1 standing at its end), density 1000,
     * against an independent reference: the solid's mass, centre and inertia tensor integrated
     * over a 0.02 m voxel grid, and its principal moments from the characteristic cubic */
    ak_rigid_child kids[2] = {
        {.shape = {.type = AK_RIGID_BOX, .half_extents = {1.0f, 0.25f, 0.5f}}, .position = {0, 0, 0}},
        {.shape = {.type = AK_RIGID_BOX, .half_extents = {0.25f, 0.75f, 0.5f}},
         .position = {0.75f, 1.0f, 0.0f}},
    };
    ak_rigid_body_desc b = {.shape = {.type = AK_RIGID_COMPOUND, .children = kids, .child_count = 2},
                            .position = {5.0f, 0.0f, 0.0f}};
    ak_rigid_model* m = NULL;
    ak_rigid_model_desc md = {.bodies = {&b, 1}};
    AK_CHECK_EQ(ak_rigid_model_create(&md, NULL, &m), AK_OK);
    const double hstep = 0.02, rho = 1000.0;
    double mass = 0.0, c[3] = {0, 0, 0}, sxx[3][3] = {{0}};
    for (double x = -1.0 + hstep / 2; x < 1.0; x += hstep)
        for (double y = -0.25 + hstep / 2; y < 1.75; y += hstep)
            for (double z = -0.5 + hstep / 2; z < 0.5; z += hstep) {
                bool in = y < 0.25 || x > 0.5;
                if (!in) continue;
                double dm = rho * hstep * hstep * hstep, p[3] = {x, y, z};
                mass += dm;
                for (int i = 0; i < 3; ++i) {
                    c[i] += dm * p[i];
                    for (int j = 0; j < 3; ++j) sxx[i][j] += dm * p[i] * p[j];
                }
            }
    for (int i = 0; i < 3; ++i) c[i] /= mass;
    double in[3][3];
    double tr = 0.0;
    double cov[3][3];
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) cov[i][j] = sxx[i][j] - mass * c[i] * c[j];
    for (int i = 0; i < 3; ++i) tr += cov[i][i];
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) in[i][j] = (i == j ? tr : 0.0) - cov[i][j];
    double eig[3];
    sym_eigenvalues(in, eig);
    AK_CHECK_NEAR(ak_rigid_body_mass(m, 0), mass, 1e-4 * mass);
    ak_rigid_body_desc r = ak_rigid_body_get_desc(m, 0);
    AK_CHECK_NEAR(r.position.x, 5.0 + c[0], 1e-4);
    AK_CHECK_NEAR(r.position.y, c[1], 1e-4);
    AK_CHECK_NEAR(r.position.z, c[2], 1e-4);
    ak_vec3 got = ak_rigid_body_inertia(m, 0);
    float g[3] = {got.x, got.y, got.z};
    qsort(g, 3, sizeof g[0], cmp_float);
    for (int k = 0; k < 3; ++k) {
        AK_CHECK_MSG(fabs(g[k] - eig[k]) < 2e-3 * eig[2], "moment %d: %g vs %g", k, g[k], eig[k]);
        if (getenv("AK_TEST_VERBOSE")) printf("L: moment %d %g vs voxels %g\n", k, g[k], eig[k]);
    }
    /* the L's tensor has an xy term: the body frame is turned about z */
    AK_CHECK(fabsf(r.orientation.z) > 0.01f);
    ak_rigid_model_destroy(m);
}

AK_TEST(compound_rests_on_its_children) {
    /* a dumbbell (two spheres on a capsule bar) and an L of two boxes, dropped on the ground:
     * they come to rest on their children, at the closed-form heights */
    ak_rigid_child bell[3] = {
        {.shape = {.type = AK_RIGID_SPHERE, .radius = 0.2f}, .position = {-0.5f, 0, 0}},
        {.shape = {.type = AK_RIGID_SPHERE, .radius = 0.2f}, .position = {0.5f, 0, 0}},
        {.shape = {.type = AK_RIGID_CAPSULE, .radius = 0.05f, .half_height = 0.4f},
         .orientation = {0.0f, 0.0f, 0.7071068f, 0.7071068f}},
    };
    ak_rigid_child ell[2] = {
        {.shape = {.type = AK_RIGID_BOX, .half_extents = {1.0f, 0.25f, 0.5f}}},
        {.shape = {.type = AK_RIGID_BOX, .half_extents = {0.25f, 0.75f, 0.5f}},
         .position = {0.75f, 1.0f, 0.0f}},
    };
    ak_rigid_body_desc b[3] = {
        ground(),
        {.shape = {.type = AK_RIGID_COMPOUND, .children = bell, .child_count = 3},
         .position = {0.0f, 0.5f, 0.0f}},
        {.shape = {.type = AK_RIGID_COMPOUND, .children = ell, .child_count = 2},
         .position = {0.0f, 0.27f, 3.0f}},
    };
    world wd;
    AK_CHECK(world_init(&wd, b, 3, 20));
    float pen;
    AK_CHECK(world_run(&wd, 2.0f, &pen));
    /* the dumbbell's centre is its bar's: 0.2 above the ground */
    AK_CHECK_MSG(fabsf(wd.x[1].y - 0.2f) < 3e-3f, "dumbbell at %g", wd.x[1].y);
    /* the L's shape frame: its lying box's centre 0.25 above the ground, not turned */
    ak_transform sf = ak_rigid_body_shape_frame(wd.model, 2);
    ak_vec3 origin = ak_vec3_add(wd.x[2], ak_quat_rotate(wd.q[2], sf.translation));
    ak_quat q = ak_quat_mul(wd.q[2], sf.rotation);
    AK_CHECK_MSG(fabsf(origin.y - 0.25f) < 3e-3f, "L's base at %g", origin.y);
    AK_CHECK_MSG(fabsf(ak_quat_rotate(q, ak_vec3_make(0, 1, 0)).y) > 0.9999f, "L tipped");
    AK_CHECK_MSG(ak_vec3_distance(ak_vec3_make(origin.x, 0, origin.z), ak_vec3_make(0, 0, 3)) < 1e-3f,
                 "L slid to %g %g", origin.x, origin.z);
    AK_CHECK_MSG(pen < 0.01f, "penetration %g", pen);
    /* invalid compounds */
    ak_rigid_child bad = {.shape = {.type = AK_RIGID_PLANE}};
    ak_rigid_body_desc bd = {.shape = {.type = AK_RIGID_COMPOUND, .children = &bad, .child_count = 1}};
    ak_rigid_model* m = NULL;
    ak_rigid_model_desc md = {.bodies = {&bd, 1}};
    AK_CHECK_EQ(ak_rigid_model_create(&md, NULL, &m), AK_ERR_BAD_ARG);
    bd.shape.child_count = 0;
    AK_CHECK_EQ(ak_rigid_model_create(&md, NULL, &m), AK_ERR_BAD_ARG);
    world_free(&wd);
}

int main(void) {
    AK_RUN(box_corners_hull_inertia_is_the_box_closed_form);
    AK_RUN(sampled_sphere_hull_approaches_the_sphere);
    AK_RUN(degenerate_hulls_are_refused);
    AK_RUN(gjk_distance_matches_brute_force);
    AK_RUN(hull_rests_on_a_plane);
    AK_RUN(hull_stack_stands);
    AK_RUN(tetrahedron_lands_on_a_face);
    AK_RUN(shapes_rest_on_a_static_hull);
    AK_RUN(deep_overlaps_with_a_hull_push_out_through_the_nearest_face);
    AK_RUN(hull_scene_keys);
    AK_RUN(compound_l_shape_inertia);
    AK_RUN(compound_rests_on_its_children);
    return ak_test_finish();
}

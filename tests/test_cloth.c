/* Tests of the cloth module: closed forms (a hanging spring's static stretch, the hinge
 * pendulum's elliptic-integral period, the spring solver's stability bound), an independent
 * double-precision Newton minimum of a pinned sheet's energy, invariance to the substep count and
 * to a 1 km translation, properties
 * (no particle inside a collider, pins and attachments exact, thread-count determinism, finite
 * state under strong wind), and the XPBD-vs-PBD substep comparison. */
#include <animkit/cloth.h>

#include "ak_test.h"
#include "cloth/cloth_impl.h" /* akp_dihedral, for its gradient check */

#define G 9.81f

typedef struct sim {
    ak_cloth* cloth;
    size_t n;
    ak_vec3* x;
    ak_vec3* v;
    ak_cloth_step_job job;
} sim;

static bool sim_init(sim* s, const ak_cloth_desc* d) {
    memset(s, 0, sizeof *s);
    if (ak_cloth_create(d, NULL, &s->cloth) != AK_OK) return false;
    s->n = ak_cloth_vertex_count(s->cloth);
    s->x = malloc(s->n * sizeof(ak_vec3));
    s->v = calloc(s->n, sizeof(ak_vec3));
    ak_cloth_rest_positions(s->cloth, (ak_vec3_span){s->x, s->n});
    s->job = (ak_cloth_step_job){.cloth = s->cloth, .dt = 1.0f / 60.0f, .gravity = {0, -G, 0},
                                 .positions = {s->x, s->n}, .velocities = {s->v, s->n}};
    return true;
}

/* (Re)size the scratch for the job as configured now. */
static void sim_scratch(sim* s) {
    free(s->job.scratch.ptr);
    size_t size = ak_cloth_step_scratch_size(&s->job);
    s->job.scratch = (ak_u8_span){malloc(size), size};
}

static void sim_free(sim* s) {
    free(s->job.scratch.ptr);
    free(s->x);
    free(s->v);
    ak_cloth_destroy(s->cloth);
}

/* ---- colouring ---------------------------------------------------------------------------- */

/* Checks the colours of one constraint list (stride particles each, at parts(k, q)): every colour
 * but the serial one holds no particle twice, and the serial colour is empty. Returns the number
 * of non-empty colours and the smallest and largest of them; *bound gets the most constraints
 * holding one particle (they pairwise share it, so no colouring has fewer colours). */
typedef uint32_t (*part_fn)(const ak_cloth* c, size_t k, int q);
static uint32_t bend_part(const ak_cloth* c, size_t k, int q) { return c->bend[k].p[q]; }
static uint32_t dist_part(const ak_cloth* c, size_t k, int q) { return q ? c->dist[k].j : c->dist[k].i; }

static int check_colors(const ak_cloth* c, const uint32_t* starts, size_t count, int stride, part_fn part,
                        int* bound, size_t* smallest, size_t* largest) {
    uint32_t* stamp = calloc(c->n, sizeof(uint32_t)); /* colour + 1 that last held the particle */
    uint32_t* holds = calloc(c->n, sizeof(uint32_t));
    int colors = 0;
    *smallest = SIZE_MAX, *largest = 0;
    AK_CHECK(starts[0] == 0 && starts[AKP_MAX_COLORS + 1] == count);
    AK_CHECK_MSG(starts[AKP_SERIAL_COLOR] == starts[AKP_SERIAL_COLOR + 1], "serial colour used");
    for (int col = 0; col < AKP_SERIAL_COLOR; ++col) {
        const size_t size = starts[col + 1] - starts[col];
        if (!size) continue;
        ++colors;
        if (size < *smallest) *smallest = size;
        if (size > *largest) *largest = size;
        for (size_t k = starts[col]; k < starts[col + 1]; ++k)
            for (int q = 0; q < stride; ++q) {
                const uint32_t v = part(c, k, q);
                AK_CHECK_MSG(stamp[v] != (uint32_t)col + 1, "colour %d holds particle %u twice", col, v);
                stamp[v] = (uint32_t)col + 1;
            }
    }
    *bound = 0;
    for (size_t k = 0; k < count; ++k)
        for (int q = 0; q < stride; ++q) holds[part(c, k, q)]++;
    for (size_t v = 0; v < c->n; ++v)
        if ((int)holds[v] > *bound) *bound = (int)holds[v];
    free(stamp), free(holds);
    return colors;
}

/* The constraint colouring of grids (and of a mesh): no colour holds a particle twice; a grid's
 * bending elements (dihedral and isometric) take exactly as many colours as the most elements on
 * one particle, which is 16 inside a grid of at least 5 x 5 vertices (a vertex with i + j even is on
 * 8 edges and 8 triangles: 8 elements along an edge, 8 as a wing), so the colouring is minimal;
 * the distance constraints take 8 (4 edges and 4 cell diagonals at a vertex), 12 with bending
 * springs (4 more, two apart; greedy took 13). The bound
 * is counted here from the elements, and the element count is checked against the grid's
 * interior edges. A mesh (the same triangles given as positions) is coloured greedily: valid. */
AK_TEST(constraint_coloring_valid_and_minimal) {
    const uint32_t sizes[][2] = {{2, 2}, {2, 5}, {3, 3}, {4, 4}, {5, 7}, {7, 5}, {33, 17}, {64, 64}, {97, 50}};
    const ak_cloth_bending kinds[3] = {AK_CLOTH_BEND_DIHEDRAL, AK_CLOTH_BEND_ISOMETRIC, AK_CLOTH_BEND_SPRINGS};
    for (int bend = 0; bend < 3; ++bend)
        for (size_t g = 0; g < sizeof sizes / sizeof sizes[0]; ++g) {
            const uint32_t w = sizes[g][0], h = sizes[g][1];
            const bool springs = kinds[bend] == AK_CLOTH_BEND_SPRINGS;
            ak_cloth_desc d = {.solver = AK_CLOTH_XPBD, .grid_width = w, .grid_height = h, .spacing = 0.1f,
                               .bending = kinds[bend]};
            ak_cloth* c = NULL;
            AK_CHECK_EQ(ak_cloth_create(&d, NULL, &c), AK_OK);
            const size_t edges = (size_t)(w - 1) * h + (size_t)w * (h - 1) + (size_t)(w - 1) * (h - 1);
            AK_CHECK_EQ(c->bend_count, springs ? 0 : edges - 2 * (size_t)(w - 1) - 2 * (size_t)(h - 1));
            int bound = 0;
            size_t lo, hi;
            const int colors = check_colors(c, c->bend_color, c->bend_count, 4, bend_part, &bound, &lo, &hi);
            AK_CHECK_MSG(colors <= 16 && colors >= bound, "%ux%u: %d bending colours, bound %d", w, h, colors, bound);
            if (w >= 5 && h >= 5 && !springs) AK_CHECK_EQ(bound, 16); /* then minimal: colors == bound */
            /* a diagonal's colour holds a quarter of the cells, an edge's about a sixth */
            if (w >= 64 && h >= 64) AK_CHECK_MSG(5 * hi <= 8 * lo, "colour sizes %zu..%zu", lo, hi);
            const int dcolors = check_colors(c, c->dist_color, c->dist_count, 2, dist_part, &bound, &lo, &hi);
            AK_CHECK_MSG(dcolors >= bound && dcolors <= (springs ? 12 : 8), "%ux%u: %d distance colours, bound %d", w, h,
                         dcolors, bound);
            if (w >= 5 && h >= 5) AK_CHECK_EQ(bound, springs ? 12 : 8); /* then minimal */
            if (g + 1 == sizeof sizes / sizeof sizes[0] && !springs) {
                /* the same triangles as a mesh: greedy, still valid */
                const ak_u32_cspan idx = ak_cloth_indices(c);
                ak_vec3* rest = malloc(c->n * sizeof(ak_vec3));
                ak_cloth_rest_positions(c, (ak_vec3_span){rest, c->n});
                ak_cloth_desc m = {.solver = AK_CLOTH_XPBD, .positions = {rest, c->n}, .indices = idx,
                                   .bending = d.bending};
                ak_cloth* mc = NULL;
                AK_CHECK_EQ(ak_cloth_create(&m, NULL, &mc), AK_OK);
                AK_CHECK_EQ(mc->bend_count, c->bend_count);
                const int mcolors = check_colors(mc, mc->bend_color, mc->bend_count, 4, bend_part, &bound, &lo, &hi);
                AK_CHECK(mcolors >= bound && mcolors <= AKP_MAX_COLORS);
                ak_cloth_destroy(mc);
                free(rest);
            }
            ak_cloth_destroy(c);
        }
}

/* ---- validity ----------------------------------------------------------------------------- */

AK_TEST(desc_defaults) {
    ak_cloth_desc d = ak_cloth_desc_resolved(NULL);
    AK_CHECK_EQ(d.solver, AK_CLOTH_XPBD);
    AK_CHECK_NEAR(d.spacing, 0.05f, 0);
    AK_CHECK_NEAR(d.stretch_stiffness, 5000.0f, 0);
    AK_CHECK_NEAR(d.shear_stiffness, 5000.0f, 0);
    AK_CHECK_NEAR(d.bend_stiffness, 50.0f, 0);
    AK_CHECK_NEAR(d.dihedral_stiffness, 1e-4f, 0);
    AK_CHECK_NEAR(d.area_density, 0.2f, 0);
    AK_CHECK_NEAR(d.pbd_stiffness, 1.0f, 0);
    AK_CHECK_EQ(d.bending, AK_CLOTH_BEND_DIHEDRAL);
    AK_CHECK_NEAR(d.grid_axis_v.z, -1.0f, 0);
    ak_cloth_desc s = {.solver = AK_CLOTH_SPRINGS};
    AK_CHECK_EQ(ak_cloth_desc_resolved(&s).bending, AK_CLOTH_BEND_SPRINGS);
}

AK_TEST(create_rules) {
    ak_cloth* c = (ak_cloth*)1;
    AK_CHECK_EQ(ak_cloth_create(NULL, NULL, &c), AK_ERR_NULL_ARG);
    AK_CHECK(c == NULL);
    ak_cloth_desc zero = {0};
    AK_CHECK_EQ(ak_cloth_create(&zero, NULL, &c), AK_ERR_EMPTY);
    ak_cloth_desc d = {.grid_width = 1, .grid_height = 4};
    AK_CHECK_EQ(ak_cloth_create(&d, NULL, &c), AK_ERR_BAD_ARG);
    d = (ak_cloth_desc){.grid_width = 4, .grid_height = 4, .stretch_stiffness = -1};
    AK_CHECK_EQ(ak_cloth_create(&d, NULL, &c), AK_ERR_BAD_ARG);
    d = (ak_cloth_desc){.grid_width = 4, .grid_height = 4, .solver = AK_CLOTH_SPRINGS, .stretch_stiffness = INFINITY};
    AK_CHECK_EQ(ak_cloth_create(&d, NULL, &c), AK_ERR_BAD_ARG);
    d = (ak_cloth_desc){.grid_width = 4, .grid_height = 4, .pbd_stiffness = 1.5f};
    AK_CHECK_EQ(ak_cloth_create(&d, NULL, &c), AK_ERR_BAD_ARG);
    uint32_t pins[2] = {3, 16};
    d = (ak_cloth_desc){.grid_width = 4, .grid_height = 4, .pins = AK_SPAN(pins)};
    AK_CHECK_EQ(ak_cloth_create(&d, NULL, &c), AK_ERR_BAD_INDEX);
    uint32_t twice[2] = {3, 3};
    d = (ak_cloth_desc){.grid_width = 4, .grid_height = 4, .pins = AK_SPAN(twice)};
    AK_CHECK_EQ(ak_cloth_create(&d, NULL, &c), AK_ERR_BAD_INDEX);
    ak_vec3 p[3] = {{0, 0, 0}, {1, 0, 0}, {0, NAN, 0}};
    uint32_t tri[3] = {0, 1, 2};
    d = (ak_cloth_desc){.positions = AK_SPAN(p), .indices = AK_SPAN(tri)};
    AK_CHECK_EQ(ak_cloth_create(&d, NULL, &c), AK_ERR_BAD_DATA);
    p[2].y = 1.0f;
    uint32_t bad[3] = {0, 1, 3};
    d.indices = (ak_u32_cspan)AK_SPAN(bad);
    AK_CHECK_EQ(ak_cloth_create(&d, NULL, &c), AK_ERR_BAD_INDEX);
    /* a vertex on no triangle needs an explicit mass */
    uint32_t edge[2] = {0, 1};
    d = (ak_cloth_desc){.positions = AK_SPAN(p), .edges = AK_SPAN(edge)};
    AK_CHECK_EQ(ak_cloth_create(&d, NULL, &c), AK_ERR_BAD_ARG);
    /* allocation failures at every point fail cleanly */
    for (int k = 1; k < 12; ++k) {
        ak_test_counter cnt = {.fail_from = k};
        ak_allocator a = ak_test_counting_allocator(&cnt);
        ak_cloth_desc g = {.grid_width = 5, .grid_height = 5};
        ak_result r = ak_cloth_create(&g, &a, &c);
        if (r == AK_OK) ak_cloth_destroy(c);
        else AK_CHECK_EQ(r, AK_ERR_NO_MEMORY);
        AK_CHECK_EQ(cnt.live, 0);
    }
}

AK_TEST(step_rules) {
    AK_CHECK_EQ(ak_cloth_step_validate(NULL), AK_ERR_NULL_ARG);
    ak_cloth_step_job zero = {0};
    AK_CHECK_EQ(ak_cloth_step_validate(&zero), AK_ERR_NULL_ARG);
    ak_cloth_desc d = {.grid_width = 4, .grid_height = 3};
    sim s;
    AK_CHECK(sim_init(&s, &d));
    sim_scratch(&s);
    AK_CHECK_EQ(ak_cloth_step_validate(&s.job), AK_OK);
    ak_cloth_step_job j = s.job;
    j.dt = 0;
    AK_CHECK_EQ(ak_cloth_step_validate(&j), AK_ERR_BAD_ARG);
    j = s.job, j.thread_count = 65;
    AK_CHECK_EQ(ak_cloth_step_validate(&j), AK_ERR_BAD_ARG);
    j = s.job, j.friction = -1;
    AK_CHECK_EQ(ak_cloth_step_validate(&j), AK_ERR_BAD_ARG);
    j = s.job, j.positions.count--;
    AK_CHECK_EQ(ak_cloth_step_validate(&j), AK_ERR_BAD_ARG);
    j = s.job, j.scratch.count--;
    AK_CHECK_EQ(ak_cloth_step_validate(&j), AK_ERR_SPAN_SMALL);
    j = s.job, j.sphere_count = 1;
    AK_CHECK_EQ(ak_cloth_step_validate(&j), AK_ERR_NULL_ARG);
    ak_cloth_sphere sp = {{0, 0, 0}, -1};
    j.spheres = &sp;
    AK_CHECK_EQ(ak_cloth_step_validate(&j), AK_ERR_BAD_ARG);
    j = s.job, j.gravity.y = NAN;
    AK_CHECK_EQ(ak_cloth_step_validate(&j), AK_ERR_BAD_DATA);
    ak_vec3 res[12] = {{0, 0, 0}};
    j = s.job, j.position_residuals = (ak_vec3_span){res, 11};
    AK_CHECK_EQ(ak_cloth_step_validate(&j), AK_ERR_BAD_ARG);
    j.position_residuals.count = 12;
    AK_CHECK_EQ(ak_cloth_step_validate(&j), AK_OK);
    res[3].z = NAN;
    AK_CHECK_EQ(ak_cloth_step_validate(&j), AK_ERR_BAD_DATA);
    ak_vec3 mp[3] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
    uint32_t mi[3] = {0, 1, 3};
    j = s.job, j.mesh = (ak_cloth_collider_mesh){AK_SPAN(mp), AK_SPAN(mi)};
    size_t need = ak_cloth_step_scratch_size(&j);
    AK_CHECK(need > s.job.scratch.count);
    AK_CHECK_EQ(ak_cloth_step_validate(&j), AK_ERR_SPAN_SMALL);
    s.x[5].x = INFINITY;
    AK_CHECK_EQ(ak_cloth_step_run(&s.job), AK_ERR_BAD_DATA);
    AK_CHECK(isinf(s.x[5].x)); /* nothing written */
    sim_free(&s);
}

/* ---- closed forms ----------------------------------------------------------------------- */

/* One particle of mass m hanging from a pinned one by a spring of stiffness k settles at
 * rest + m g / k (both solvers; XPBD with compliance 1/k). */
static float hanging_spring(ak_cloth_solver solver, float m, float k) {
    /* hung near the origin: float positions there resolve the per-substep displacement g h^2
     * (7e-6 m at h = 1/1200) finely; near |x| = 1 its rounding alone biases the rest point by
     * about 0.5% */
    ak_vec3 p[2] = {{0, 0.5f, 0}, {0, 0, 0}};
    uint32_t e[2] = {0, 1};
    float w[2] = {0.0f, 1.0f / m};
    ak_cloth_desc d = {.solver = solver, .positions = AK_SPAN(p), .edges = AK_SPAN(e), .inverse_masses = AK_SPAN(w),
                       .stretch_stiffness = k};
    sim s;
    if (!sim_init(&s, &d)) return NAN;
    s.job.substeps = 20;
    s.job.damping = 3.0f;
    sim_scratch(&s);
    for (int f = 0; f < 600; ++f)
        if (ak_cloth_step_run(&s.job) != AK_OK) break;
    const float stretch = ak_vec3_distance(s.x[0], s.x[1]) - 0.5f;
    AK_CHECK_NEAR(s.x[0].y, 0.5f, 0.0f);
    sim_free(&s);
    return stretch;
}

AK_TEST(single_spring_static_stretch) {
    const float m = 0.5f, k = 200.0f, expect = m * G / k;
    const float springs = hanging_spring(AK_CLOTH_SPRINGS, m, k);
    const float xpbd = hanging_spring(AK_CLOTH_XPBD, m, k);
    printf("  static stretch mg/k = %.6f: springs %.6f, XPBD %.6f\n", (double)expect, (double)springs, (double)xpbd);
    AK_CHECK_NEAR(springs, expect, 0.01f * expect);
    AK_CHECK_NEAR(xpbd, expect, 0.01f * expect);
    /* a stiffer spring: the stretch follows 1/k */
    const float stiff = hanging_spring(AK_CLOTH_XPBD, m, 4.0f * k);
    AK_CHECK_NEAR(stiff, expect / 4.0f, 0.01f * expect / 4.0f);
}

AK_TEST(dihedral_gradient) {
    /* the analytic gradient of the dihedral angle against central differences in double-ish
     * steps, at several folds (including past 90 degrees) */
    ak_vec3 x[4] = {{0.1f, 0.3f, 0.9f}, {0.2f, -0.4f, -0.8f}, {0, 0, 0}, {1.1f, 0.1f, 0.05f}};
    float worst = 0.0f;
    for (int fold = 0; fold < 4; ++fold) {
        x[0].y = -0.6f + 0.5f * (float)fold;
        ak_vec3 g[4];
        akp_dihedral(x, g);
        for (int q = 0; q < 4; ++q)
            for (int c = 0; c < 3; ++c) {
                float* p = &x[q].x + c;
                const float o = *p;
                *p = o + 1e-3f;
                const float hi = akp_dihedral(x, NULL);
                *p = o - 1e-3f;
                const float lo = akp_dihedral(x, NULL);
                *p = o;
                worst = ak_maxf(worst, fabsf((hi - lo) / 2e-3f - (&g[q].x)[c]));
            }
    }
    AK_CHECK(worst < 2e-3f);
    /* the angle itself: a pair folded by 0.5 rad about the shared diagonal */
    ak_vec3 flat[4] = {{0, 0, 0}, {1, 0, 0}, {0, 0, -1}, {1, 0, -1}};
    uint32_t tris[6] = {0, 1, 3, 0, 3, 2};
    ak_cloth_desc d = {.positions = AK_SPAN(flat), .indices = AK_SPAN(tris), .dihedral_stiffness = 2.0f};
    ak_cloth* c = NULL;
    AK_CHECK_EQ(ak_cloth_create(&d, NULL, &c), AK_OK);
    ak_vec3 v[4] = {{0}};
    ak_cloth_energy e;
    AK_CHECK_EQ(ak_cloth_energy_compute(c, (ak_vec3_cspan)AK_SPAN(flat), (ak_vec3_cspan)AK_SPAN(v), ak_vec3_make(0, 0, 0), &e),
                AK_OK);
    AK_CHECK_NEAR(e.elastic, 0.0, 1e-9);
    const ak_quat q = ak_quat_from_axis_angle(ak_vec3_normalize(ak_vec3_make(1, 0, -1)), 0.5f);
    ak_vec3 folded[4] = {flat[0], flat[1], ak_quat_rotate(q, flat[2]), flat[3]};
    AK_CHECK_EQ(ak_cloth_energy_compute(c, (ak_vec3_cspan)AK_SPAN(folded), (ak_vec3_cspan)AK_SPAN(v), ak_vec3_make(0, 0, 0), &e),
                AK_OK);
    /* the springs 0-2 and 2-3 keep their length under a turn about 0-3: only bending, 1/2 k 0.5^2 */
    AK_CHECK_NEAR(e.elastic, 0.5 * 2.0 * 0.25, 1e-5);
    ak_cloth_destroy(c);
}

/* Isometric bending: zero energy for any flat or rigidly moved configuration, k |b|^2 3 / (2 (A0 +
 * A1)) for a fold, with b computed here from the cotangent weights (Bergou et al. 2006). */
AK_TEST(isometric_bending) {
    ak_vec3 flat[4] = {{0, 0, 0}, {1.1f, 0, 0.1f}, {0.2f, 0, -0.9f}, {1, 0, -1.2f}};
    uint32_t tris[6] = {0, 1, 3, 0, 3, 2};
    ak_cloth_desc d = {.positions = AK_SPAN(flat), .indices = AK_SPAN(tris), .dihedral_stiffness = 2.0f,
                       .bending = AK_CLOTH_BEND_ISOMETRIC, .stretch_stiffness = INFINITY, .shear_stiffness = INFINITY};
    ak_cloth* c = NULL;
    AK_CHECK_EQ(ak_cloth_create(&d, NULL, &c), AK_OK);
    ak_vec3 v[4] = {{0}}, moved[4];
    ak_cloth_energy e;
    const ak_quat q = ak_quat_from_axis_angle(ak_vec3_normalize(ak_vec3_make(1, 2, 3)), 0.7f);
    for (int k = 0; k < 4; ++k) moved[k] = ak_vec3_add(ak_quat_rotate(q, flat[k]), ak_vec3_make(3, -1, 2));
    AK_CHECK_EQ(ak_cloth_energy_compute(c, (ak_vec3_cspan)AK_SPAN(moved), (ak_vec3_cspan)AK_SPAN(v), ak_vec3_make(0, 0, 0), &e),
                AK_OK);
    AK_CHECK_NEAR(e.elastic, 0.0, 1e-9);
    /* fold vertex 2 about the edge 0-3 by 0.4 rad: b = K2 (x2' - x2) as only x2 moved (the
     * weights sum to zero), K2 = -(cot of the angles at 0 and 3 in triangle 0-3-2) */
    const ak_vec3 axis = ak_vec3_normalize(ak_vec3_sub(flat[3], flat[0]));
    ak_vec3 folded[4] = {flat[0], flat[1], ak_vec3_add(flat[0], ak_quat_rotate(ak_quat_from_axis_angle(axis, 0.4f),
                                                                                ak_vec3_sub(flat[2], flat[0]))), flat[3]};
    AK_CHECK_EQ(ak_cloth_energy_compute(c, (ak_vec3_cspan)AK_SPAN(folded), (ak_vec3_cspan)AK_SPAN(v), ak_vec3_make(0, 0, 0), &e),
                AK_OK);
    double cot0, cot3, area0, area1;
    {
        const ak_vec3 a = flat[0], b = flat[3], w = flat[2], o = flat[1];
        ak_vec3 u = ak_vec3_sub(b, a), t = ak_vec3_sub(w, a);
        cot0 = ak_vec3_dot(u, t) / ak_vec3_length(ak_vec3_cross(u, t));
        u = ak_vec3_sub(a, b), t = ak_vec3_sub(w, b);
        cot3 = ak_vec3_dot(u, t) / ak_vec3_length(ak_vec3_cross(u, t));
        area0 = 0.5 * ak_vec3_length(ak_vec3_cross(ak_vec3_sub(b, a), ak_vec3_sub(w, a)));
        area1 = 0.5 * ak_vec3_length(ak_vec3_cross(ak_vec3_sub(b, a), ak_vec3_sub(o, a)));
    }
    const double db = (cot0 + cot3) * ak_vec3_distance(folded[2], flat[2]);
    AK_CHECK_NEAR(e.elastic, 3.0 * 2.0 * db * db / (2.0 * (area0 + area1)), 1e-5);
    ak_cloth_destroy(c);
    /* a drape with isometric bending stays finite and out of the sphere */
    ak_cloth_desc g = {.grid_width = 10, .grid_height = 10, .spacing = 0.1f, .grid_origin = {-0.45f, 1, 0.45f},
                       .bending = AK_CLOTH_BEND_ISOMETRIC};
    sim s;
    AK_CHECK(sim_init(&s, &g));
    const ak_cloth_sphere sp = {{0, 0.5f, 0}, 0.3f};
    s.job.spheres = &sp, s.job.sphere_count = 1;
    sim_scratch(&s);
    for (int f = 0; f < 90; ++f) AK_CHECK_EQ(ak_cloth_step_run(&s.job), AK_OK);
    for (size_t i = 0; i < s.n; ++i) AK_CHECK(ak_vec3_distance(s.x[i], sp.center) >= sp.radius);
    sim_free(&s);
}

/* ---- substeps and translation: the hinge pendulum ----------------------------------------- */

/* Complete elliptic integral of the first kind K(k) = pi / (2 AGM(1, sqrt(1 - k^2))), in double. */
static double elliptic_k(double k) {
    double a = 1.0, b = sqrt(1.0 - k * k);
    for (int i = 0; i < 40 && fabs(a - b) > 1e-16 * a; ++i) {
        const double m = 0.5 * (a + b);
        b = sqrt(a * b);
        a = m;
    }
    return 3.14159265358979323846 / (2.0 * a);
}

typedef struct swing {
    double period;    /* s: mean time between upward zero crossings */
    double amplitude; /* rad: largest |angle| after the release */
    double last_amplitude; /* rad: largest |angle| over the last full period */
    int crossings;
} swing;

#define HINGE_L 0.5
#define HINGE_THETA0 0.35

/* A 2 x 2 cloth (spacing L) pinned along its top edge and released at theta0 from the vertical:
 * a rigid hinge pendulum (rigid constraints). The angle is that of the bottom edge's midpoint
 * about the hinge, in double from the float positions. Runs `seconds` of 0.01 s steps. */
static swing hinge_pendulum(uint32_t substeps, ak_vec3 offset, float seconds) {
    swing out = {0, 0, 0, 0};
    const float L = (float)HINGE_L, th0 = (float)HINGE_THETA0;
    /* the float geometry as it lands 1 km away (the farthest offset the test uses), moved to
     * `offset` by exact float subtractions and additions: every scene has the same edge vectors
     * and rest lengths to the bit, so only where it is differs */
    const ak_vec3 far = ak_vec3_make(577.35f, 577.35f, -577.35f), u = {L, 0, 0}, v = {0, -L * cosf(th0), L * sinf(th0)};
    ak_vec3 p[4] = {far, ak_vec3_add(far, u), ak_vec3_add(far, v), ak_vec3_add(ak_vec3_add(far, u), v)};
    for (int k = 0; k < 4; ++k) p[k] = ak_vec3_add(ak_vec3_sub(p[k], far), offset);
    uint32_t tris[6] = {0, 3, 1, 0, 2, 3}; /* facing u x v, like a grid's */
    uint32_t pins[2] = {0, 1};
    ak_cloth_desc d = {.positions = AK_SPAN(p), .indices = AK_SPAN(tris), .pins = AK_SPAN(pins),
                       .stretch_stiffness = INFINITY};
    sim s;
    if (!sim_init(&s, &d)) return out;
    ak_vec3 res[4] = {{0, 0, 0}, {0, 0, 0}, {0, 0, 0}, {0, 0, 0}};
    s.job.dt = 0.01f;
    s.job.substeps = substeps;
    s.job.position_residuals = (ak_vec3_span)AK_SPAN(res);
    sim_scratch(&s);
    const int steps = (int)(seconds / 0.01f + 0.5f);
    double prev = HINGE_THETA0, first = -1, last = -1, since = 0;
    for (int f = 1; f <= steps; ++f) {
        if (ak_cloth_step_run(&s.job) != AK_OK) return out;
        /* bottom midpoint relative to the hinge's midpoint, in double */
        const double y = 0.5 * (((double)s.x[2].y - s.x[0].y) + ((double)s.x[3].y - s.x[1].y) + res[2].y + res[3].y);
        const double z = 0.5 * (((double)s.x[2].z - s.x[0].z) + ((double)s.x[3].z - s.x[1].z) + res[2].z + res[3].z);
        const double th = atan2(z, -y);
        out.amplitude = fmax(out.amplitude, fabs(th));
        since = fmax(since, fabs(th));
        if (prev < 0.0 && th >= 0.0) { /* upward crossing, linearly interpolated */
            const double t = 0.01 * ((double)(f - 1) + prev / (prev - th));
            if (first < 0) first = t;
            else out.last_amplitude = since;
            last = t;
            out.crossings++;
            since = 0;
        }
        prev = th;
    }
    out.period = out.crossings > 1 ? (last - first) / (out.crossings - 1) : 0.0;
    sim_free(&s);
    return out;
}

/* The period within 0.5% of the exact 4 sqrt(L/g) K(sin(theta0/2)) for 5 to 100 substeps, the
 * amplitude not growing; 1 km from the origin the same within 1e-4 relative. */
AK_TEST(hinge_pendulum_period_substeps_translation) {
    const double exact = 4.0 * sqrt(HINGE_L / (double)G) * elliptic_k(sin(0.5 * HINGE_THETA0));
    const uint32_t subs[] = {5, 10, 20, 40, 80, 100};
    for (size_t k = 0; k < sizeof subs / sizeof subs[0]; ++k) {
        const swing w = hinge_pendulum(subs[k], ak_vec3_make(0, 0, 0), 6.0f);
        const double err = w.period / exact - 1.0;
        printf("  %3u substeps: period %.5f s (exact %.5f, %+.3f%%), amplitude %.4f rad, last period %.4f\n", subs[k],
               w.period, exact, 100.0 * err, w.amplitude, w.last_amplitude);
        AK_CHECK_MSG(w.crossings >= 3, "%u substeps: %d crossings", subs[k], w.crossings);
        AK_CHECK_MSG(fabs(err) < 0.005, "%u substeps: period off by %.3f%%", subs[k], 100.0 * err);
        AK_CHECK_MSG(w.amplitude < HINGE_THETA0 * 1.001, "%u substeps: amplitude grew to %.4f", subs[k], w.amplitude);
        AK_CHECK_MSG(w.last_amplitude < HINGE_THETA0 * 1.001, "%u substeps: amplitude grew to %.4f", subs[k], w.last_amplitude);
    }
    const ak_vec3 far[2] = {{0, 1000, 0}, {577.35f, 577.35f, -577.35f}};
    const uint32_t far_subs[2] = {10, 100};
    for (int q = 0; q < 2; ++q)
        for (int k = 0; k < 2; ++k) {
            const swing a = hinge_pendulum(far_subs[k], ak_vec3_make(0, 0, 0), 12.0f);
            const swing b = hinge_pendulum(far_subs[k], far[q], 12.0f);
            const double dp = fabs(b.period / a.period - 1.0), da = fabs(b.amplitude / a.amplitude - 1.0);
            printf("  1 km away (%g, %g, %g), %u substeps: period %.6f vs %.6f s (%.1e), amplitude %.5f vs %.5f (%.1e)\n",
                   (double)far[q].x, (double)far[q].y, (double)far[q].z, far_subs[k], b.period, a.period, dp,
                   b.amplitude, a.amplitude, da);
            AK_CHECK_MSG(dp < 1e-4 && da < 1e-4, "1 km away, %u substeps: period %.2e, amplitude %.2e relative", far_subs[k],
                         dp, da);
        }
}

/* ---- rest shape against an independent energy minimum ----------------------------------- */

enum { SW = 6, SH = 6 };
#define SHEET_SPACING 0.1

/* The sheet's material: stretch and shear stiffness k (N/m), bending springs k / 100, density. */
typedef struct sheet_material {
    double k, density;
} sheet_material;

typedef struct spring_ref {
    int i, j;
    double k, rest;
} spring_ref;

/* The sheet's springs and masses as docs/cloth.md describes a grid (rows, columns, both
 * diagonals of each quad, bending springs two apart; a third of each triangle's mass on each
 * corner, the quad (i, j) cut along a -> d when i + j is even, b -> c when odd). */
static int sheet_springs(sheet_material mat, spring_ref* out, double* mass) {
    int n = 0;
    const double a = SHEET_SPACING;
    for (int j = 0; j < SH; ++j)
        for (int i = 0; i < SW; ++i) {
            const int v = j * SW + i;
            if (i + 1 < SW) out[n++] = (spring_ref){v, v + 1, mat.k, a};
            if (j + 1 < SH) out[n++] = (spring_ref){v, v + SW, mat.k, a};
            if (i + 1 < SW && j + 1 < SH) {
                out[n++] = (spring_ref){v, v + SW + 1, mat.k, a * sqrt(2.0)};
                out[n++] = (spring_ref){v + 1, v + SW, mat.k, a * sqrt(2.0)};
            }
            if (i + 2 < SW) out[n++] = (spring_ref){v, v + 2, mat.k / 100.0, 2 * a};
            if (j + 2 < SH) out[n++] = (spring_ref){v, v + 2 * SW, mat.k / 100.0, 2 * a};
        }
    for (int v = 0; v < SW * SH; ++v) mass[v] = 0.0;
    const double third = 0.5 * a * a * mat.density / 3.0;
    for (int j = 0; j + 1 < SH; ++j)
        for (int i = 0; i + 1 < SW; ++i) {
            const int qa = j * SW + i, qb = qa + 1, qc = qa + SW, qd = qc + 1;
            /* two triangles: each corner gets a third of each triangle it is on */
            const int t[6] = {qa, qb, (i + j) & 1 ? qc : qd, (i + j) & 1 ? qb : qa, qd, qc};
            for (int k = 0; k < 6; ++k) mass[t[k]] += third;
        }
    return n;
}

/* Dense Cholesky of the m x m matrix A (lower, in place); false if not positive definite. */
static bool cholesky(double* A, int m) {
    for (int j = 0; j < m; ++j) {
        double d = A[j * m + j];
        for (int k = 0; k < j; ++k) d -= A[j * m + k] * A[j * m + k];
        if (!(d > 0.0)) return false;
        d = sqrt(d);
        A[j * m + j] = d;
        for (int i = j + 1; i < m; ++i) {
            double s = A[i * m + j];
            for (int k = 0; k < j; ++k) s -= A[i * m + k] * A[j * m + k];
            A[i * m + j] = s / d;
        }
    }
    return true;
}

static void cholesky_solve(const double* L, int m, double* b) {
    for (int i = 0; i < m; ++i) {
        for (int k = 0; k < i; ++k) b[i] -= L[i * m + k] * b[k];
        b[i] /= L[i * m + i];
    }
    for (int i = m - 1; i >= 0; --i) {
        for (int k = i + 1; k < m; ++k) b[i] -= L[k * m + i] * b[k];
        b[i] /= L[i * m + i];
    }
}

/* Energy, gradient and Hessian (geometric term clamped at >= 0 when `clamp`) over the free
 * coordinates (index map col[v], -1 for pinned). */
static double sheet_energy(const double* x, const spring_ref* sp, int ns, const double* mass, const int* col, int m,
                           double* grad, double* hess, bool clamp) {
    double e = 0.0;
    if (grad) memset(grad, 0, (size_t)m * sizeof(double));
    if (hess) memset(hess, 0, (size_t)m * m * sizeof(double));
    for (int v = 0; v < SW * SH; ++v)
        if (col[v] >= 0) {
            e += mass[v] * (double)G * x[3 * v + 1];
            if (grad) grad[col[v] + 1] += mass[v] * (double)G;
        }
    for (int s = 0; s < ns; ++s) {
        const double* a = x + 3 * sp[s].i;
        const double* b = x + 3 * sp[s].j;
        const double d[3] = {a[0] - b[0], a[1] - b[1], a[2] - b[2]};
        const double l = sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]), u[3] = {d[0] / l, d[1] / l, d[2] / l};
        const double c = l - sp[s].rest;
        e += 0.5 * sp[s].k * c * c;
        double g = 1.0 - sp[s].rest / l;
        if (clamp && g < 0.0) g = 0.0;
        const int ci = col[sp[s].i], cj = col[sp[s].j];
        for (int p = 0; p < 3; ++p) {
            if (grad && ci >= 0) grad[ci + p] += sp[s].k * c * u[p];
            if (grad && cj >= 0) grad[cj + p] -= sp[s].k * c * u[p];
            if (!hess) continue;
            for (int q = 0; q < 3; ++q) {
                const double h = sp[s].k * (u[p] * u[q] + g * ((p == q) - u[p] * u[q]));
                if (ci >= 0) hess[(ci + p) * m + ci + q] += h;
                if (cj >= 0) hess[(cj + p) * m + cj + q] += h;
                if (ci >= 0 && cj >= 0) hess[(ci + p) * m + cj + q] -= h, hess[(cj + p) * m + ci + q] -= h;
            }
        }
    }
    return e;
}

/* The minimum of the sheet's energy (springs + gravity) with pins fixed, by damped Newton
 * (Levenberg-Marquardt on the clamped Hessian, then plain Newton) from the flat sheet; false
 * unless it converged to a point whose full Hessian is positive definite. */
static bool sheet_minimum(sheet_material mat, const uint32_t* pins, int pin_count, double* x) {
    spring_ref sp[400];
    double mass[SW * SH];
    const int ns = sheet_springs(mat, sp, mass);
    int col[SW * SH], m = 0;
    for (int v = 0; v < SW * SH; ++v) {
        bool pinned = false;
        for (int k = 0; k < pin_count; ++k) pinned = pinned || (int)pins[k] == v;
        col[v] = pinned ? -1 : 3 * (m++);
        x[3 * v] = SHEET_SPACING * (v % SW), x[3 * v + 1] = 1.0, x[3 * v + 2] = -SHEET_SPACING * (v / SW);
    }
    m *= 3;
    double* H = malloc((size_t)m * m * sizeof(double));
    double* gvec = malloc((size_t)m * sizeof(double));
    double* step = malloc((size_t)m * sizeof(double));
    double* trial = malloc(3 * SW * SH * sizeof(double));
    double mu = 1.0, e = sheet_energy(x, sp, ns, mass, col, m, NULL, NULL, true), gnorm = INFINITY;
    for (int it = 0; it < 2000 && gnorm > 1e-10; ++it) {
        sheet_energy(x, sp, ns, mass, col, m, gvec, H, true);
        gnorm = 0.0;
        for (int k = 0; k < m; ++k) gnorm = fmax(gnorm, fabs(gvec[k]));
        for (int k = 0; k < m; ++k) H[k * m + k] += mu, step[k] = -gvec[k];
        if (!cholesky(H, m)) {
            mu *= 4.0;
            continue;
        }
        cholesky_solve(H, m, step);
        memcpy(trial, x, 3 * SW * SH * sizeof(double));
        for (int v = 0; v < SW * SH; ++v)
            if (col[v] >= 0)
                for (int p = 0; p < 3; ++p) trial[3 * v + p] += step[col[v] + p];
        const double et = sheet_energy(trial, sp, ns, mass, col, m, NULL, NULL, true);
        if (et <= e + 1e-13 * fabs(e)) { /* (energy rounding: near the minimum the gradient decides) */
            memcpy(x, trial, 3 * SW * SH * sizeof(double));
            e = et;
            mu = fmax(mu / 3.0, 1e-12);
        } else {
            mu *= 4.0;
        }
    }
    sheet_energy(x, sp, ns, mass, col, m, gvec, H, false);
    const bool pd = cholesky(H, m), ok = gnorm <= 1e-10 && pd;
    if (!ok) printf("  Newton: gradient %.3g, Hessian %s\n", gnorm, pd ? "positive definite" : "not positive definite");
    free(H), free(gvec), free(step), free(trial);
    return ok;
}

/* A 6 x 6 sheet pinned at two corners settles where its energy is smallest: within 0.5% of its
 * largest displacement of the Newton minimum above, for 5 and 50 substeps and every spring
 * integrator: mass-spring, implicit Euler, and XPBD with bending distance constraints
 * (compliance 1/k, 20 sweeps per substep so that each substep's solve converges). Two
 * materials: a soft heavy sheet (k = 100 N/m, 1 kg/m^2: the spring solver is stable at 5
 * substeps), and the library's default (k = 5000 N/m, 0.2 kg/m^2: the spring solver runs at its
 * stable count); the soft one also 20 m up (where XPBD's rest point
 * was 2.4% off at 50 substeps while positions were integrated as floats). */
AK_TEST(pinned_sheet_rest_shape_is_energy_minimum) {
    uint32_t pins[2] = {0, SW - 1};
    const sheet_material mats[2] = {{100.0, 1.0}, {5000.0, 0.2}};
    for (int mi = 0; mi < 2; ++mi) {
        double ref[3 * SW * SH];
        AK_CHECK(sheet_minimum(mats[mi], pins, 2, ref));
        double largest = 0.0;
        for (int v = 0; v < SW * SH; ++v)
            largest = fmax(largest, sqrt(pow(ref[3 * v] - SHEET_SPACING * (v % SW), 2) + pow(ref[3 * v + 1] - 1.0, 2) +
                                         pow(ref[3 * v + 2] + SHEET_SPACING * (v / SW), 2)));
        const ak_cloth_solver solvers[3] = {AK_CLOTH_SPRINGS, AK_CLOTH_IMPLICIT, AK_CLOTH_XPBD};
        const char* names[3] = {"springs", "implicit", "xpbd"};
        const uint32_t subs[2] = {5, 50};
        for (int up = 0; up < (mi == 0 ? 2 : 1); ++up) /* the soft sheet also 19 m higher */
        for (int q = 0; q < 3; ++q)
            for (int k = 0; k < 2; ++k) {
                const double lift = up ? 19.0 : 0.0;
                ak_cloth_desc d = {.solver = solvers[q], .grid_width = SW, .grid_height = SH,
                                   .spacing = (float)SHEET_SPACING, .grid_origin = {0, 1.0f + (float)lift, 0},
                                   .pins = AK_SPAN(pins),
                                   .stretch_stiffness = (float)mats[mi].k, .area_density = (float)mats[mi].density,
                                   .bending = AK_CLOTH_BEND_SPRINGS};
                sim s;
                AK_CHECK(sim_init(&s, &d));
                s.job.substeps = subs[k];
                s.job.iterations = solvers[q] == AK_CLOTH_XPBD ? 20 : 0;
                s.job.damping = 3.0f;
                if (solvers[q] == AK_CLOTH_SPRINGS) {
                    const uint32_t need = (uint32_t)ceilf(s.job.dt / (0.9f * ak_cloth_stable_substep(s.cloth)));
                    if (mi == 0) AK_CHECK(need <= 5);
                    if (need > s.job.substeps) {
                        if (k > 0) { /* both counts are below the stable one: ran at it already */
                            sim_free(&s);
                            continue;
                        }
                        s.job.substeps = need;
                    }
                }
                sim_scratch(&s);
                for (int f = 0; f < 360; ++f) /* 6 s: motion decays by exp(-3 t) */
                    if (ak_cloth_step_run(&s.job) != AK_OK) break;
                /* the sheet hangs in the plane z = 0 of its pins, and the energy is the same
                 * mirrored in it: a minimum's mirror image (z -> -z) is one too, and a stiff sheet
                 * buckles slightly out of that plane to either side. Compare with the nearer. */
                double worst = INFINITY;
                for (int mirror = 0; mirror < 2; ++mirror) {
                    double w = 0.0;
                    for (int v = 0; v < SW * SH; ++v)
                        w = fmax(w, sqrt(pow(s.x[v].x - ref[3 * v], 2) + pow(s.x[v].y - lift - ref[3 * v + 1], 2) +
                                         pow(s.x[v].z - (mirror ? -ref[3 * v + 2] : ref[3 * v + 2]), 2)));
                    worst = fmin(worst, w);
                }
                printf("  sheet (k %g N/m, %g kg/m^2) pinned at two corners %2.0f m up, %-8s %3u substeps: %.3f%% of the "
                       "largest displacement (%.3f m) from the energy minimum\n",
                       mats[mi].k, mats[mi].density, 1.0 + lift, names[q], s.job.substeps, 100.0 * worst / largest,
                       largest);
                AK_CHECK_MSG(worst < 0.005 * largest, "%s, %u substeps, %g m up: %.3f%%", names[q], s.job.substeps,
                             1.0 + lift, 100.0 * worst / largest);
                sim_free(&s);
            }
    }
}

/* ---- XPBD vs PBD ------------------------------------------------------------------------ */

/* Mean stretch of the vertical structural edges of a hanging cloth at rest. */
static float hanging_cloth_stretch(ak_cloth_solver solver, uint32_t substeps, uint32_t iterations) {
    enum { W = 8, H = 8 };
    uint32_t pins[W];
    for (uint32_t i = 0; i < W; ++i) pins[i] = i;
    ak_cloth_desc d = {.solver = solver, .grid_width = W, .grid_height = H, .spacing = 0.05f,
                       .grid_axis_v = {0, -1, 0}, .pins = AK_SPAN(pins), .stretch_stiffness = 20.0f,
                       .shear_stiffness = 20.0f, .bending = AK_CLOTH_BEND_NONE, .pbd_stiffness = 0.05f,
                       .area_density = 1.0f};
    sim s;
    if (!sim_init(&s, &d)) return NAN;
    s.job.substeps = substeps;
    s.job.iterations = iterations;
    s.job.damping = 4.0f;
    sim_scratch(&s);
    for (int f = 0; f < 300; ++f)
        if (ak_cloth_step_run(&s.job) != AK_OK) break;
    double sum = 0;
    for (uint32_t j = 0; j + 1 < H; ++j)
        for (uint32_t i = 0; i < W; ++i) sum += ak_vec3_distance(s.x[j * W + i], s.x[(j + 1) * W + i]) / 0.05f - 1.0f;
    sim_free(&s);
    return (float)(sum / ((H - 1) * W));
}

AK_TEST(xpbd_stretch_independent_of_substeps) {
    /* 4 Gauss-Seidel sweeps per substep (the paper's solver iterates to convergence; with one
     * sweep this stiff cloth, h omega > 1, ends 8% stiffer at 20 substeps than at 5:
     * docs/cloth.md) */
    const float x5 = hanging_cloth_stretch(AK_CLOTH_XPBD, 5, 4), x20 = hanging_cloth_stretch(AK_CLOTH_XPBD, 20, 4);
    const float p5 = hanging_cloth_stretch(AK_CLOTH_PBD, 5, 4), p20 = hanging_cloth_stretch(AK_CLOTH_PBD, 20, 4);
    const float xc = fabsf(x20 - x5) / x20, pc = fabsf(p20 - p5) / p20;
    printf("  settled mean stretch, 5 -> 20 substeps: XPBD %.4f -> %.4f (%.2f%%), PBD %.4f -> %.4f (%.1f%%)\n",
           (double)x5, (double)x20, 100.0 * (double)xc, (double)p5, (double)p20, 100.0 * (double)pc);
    AK_CHECK(x5 > 0.01f);
    AK_CHECK(xc < 0.02f);
    AK_CHECK(pc > 0.5f); /* plain PBD: the same parameters, a very different cloth */
}


/* ---- collisions ------------------------------------------------------------------------- */

/* The drape: a 1 m square dropped on a sphere over a floor; no particle may be inside the
 * sphere, the capsule beside it, or under the floor after any step; then the cloth comes to rest:
 * kinetic energy below DRAPE_REST_KE (docs/cloth.md). */
#define DRAPE_REST_KE 1e-3
AK_TEST(drape_no_penetration_and_rest) {
    enum { N = 12 };
    ak_cloth_desc d = {.grid_width = N, .grid_height = N, .spacing = 1.0f / (N - 1),
                       .grid_origin = {-0.5f, 1.0f, 0.5f}, .stretch_stiffness = 2000.0f};
    sim s;
    AK_CHECK(sim_init(&s, &d));
    const ak_cloth_sphere sphere = {{0, 0.5f, 0}, 0.3f};
    const ak_cloth_capsule capsule = {{0.35f, 0.15f, -0.3f}, {0.35f, 0.15f, 0.3f}, 0.15f};
    const ak_cloth_plane floor = {{0, 1, 0}, 0.0f};
    s.job.spheres = &sphere, s.job.sphere_count = 1;
    s.job.capsules = &capsule, s.job.capsule_count = 1;
    s.job.planes = &floor, s.job.plane_count = 1;
    s.job.friction = 0.5f;
    s.job.damping = 1.0f;
    s.job.self_collision = true;
    sim_scratch(&s);
    int inside = 0;
    double ke = 0;
    for (int f = 0; f < 240; ++f) {
        AK_CHECK_EQ(ak_cloth_step_run(&s.job), AK_OK);
        for (size_t v = 0; v < s.n; ++v) {
            const ak_vec3 x = s.x[v];
            const ak_vec3 ab = ak_vec3_sub(capsule.b, capsule.a);
            const float t = ak_clampf(ak_vec3_dot(ak_vec3_sub(x, capsule.a), ab) / ak_vec3_length_sq(ab), 0, 1);
            if (ak_vec3_distance(x, sphere.center) < sphere.radius || x.y < 0.0f ||
                ak_vec3_distance(x, ak_vec3_madd(capsule.a, ab, t)) < capsule.radius)
                ++inside;
        }
        ak_cloth_energy e;
        ak_cloth_energy_compute(s.cloth, (ak_vec3_cspan){s.x, s.n}, (ak_vec3_cspan){s.v, s.n}, s.job.gravity, &e);
        ke = e.kinetic;
    }
    printf("  drape: kinetic energy after 4 s %.3g J (bound %.0e), particles inside: %d\n", ke, DRAPE_REST_KE, inside);
    AK_CHECK_EQ(inside, 0);
    AK_CHECK(ke < DRAPE_REST_KE);
    /* it draped: the centre rests on the sphere's top (radius + thickness) */
    AK_CHECK_NEAR(s.x[(N / 2) * N + N / 2].y, 0.8f, 0.03f);
    sim_free(&s);
}

/* A closed box as a collider mesh (outward triangles): a cloth dropped on it stays outside. */
AK_TEST(mesh_collider) {
    const ak_vec3 bp[8] = {{-0.3f, 0, -0.3f}, {0.3f, 0, -0.3f}, {0.3f, 0, 0.3f}, {-0.3f, 0, 0.3f},
                           {-0.3f, 0.5f, -0.3f}, {0.3f, 0.5f, -0.3f}, {0.3f, 0.5f, 0.3f}, {-0.3f, 0.5f, 0.3f}};
    const uint32_t bi[36] = {0, 1, 2, 0, 2, 3, 4, 6, 5, 4, 7, 6, 0, 4, 5, 0, 5, 1,
                             1, 5, 6, 1, 6, 2, 2, 6, 7, 2, 7, 3, 3, 7, 4, 3, 4, 0};
    ak_cloth_desc d = {.grid_width = 12, .grid_height = 12, .spacing = 0.08f, .grid_origin = {-0.44f, 0.8f, 0.44f}};
    sim s;
    AK_CHECK(sim_init(&s, &d));
    s.job.mesh = (ak_cloth_collider_mesh){AK_SPAN(bp), AK_SPAN(bi)};
    s.job.damping = 1.0f;
    sim_scratch(&s);
    int inside = 0;
    for (int f = 0; f < 120; ++f) {
        AK_CHECK_EQ(ak_cloth_step_run(&s.job), AK_OK);
        for (size_t v = 0; v < s.n; ++v) {
            const ak_vec3 x = s.x[v];
            if (fabsf(x.x) < 0.3f && fabsf(x.z) < 0.3f && x.y > 0.0f && x.y < 0.5f) ++inside;
        }
    }
    AK_CHECK_EQ(inside, 0);
    /* the middle rests on the lid */
    AK_CHECK_NEAR(s.x[6 * 12 + 6].y, 0.51f, 0.01f);
    sim_free(&s);
}

/* ---- pins and attachments ------------------------------------------------------------- */

AK_TEST(pins_and_attachments_exact) {
    uint32_t pins[1] = {0}, att[2] = {9, 99};
    ak_vec3 pin_at[1] = {{-0.01f, 0.02f, 0}};
    ak_cloth_desc d = {.grid_width = 10, .grid_height = 10, .grid_axis_v = {0, -1, 0}, .pins = AK_SPAN(pins),
                       .pin_positions = AK_SPAN(pin_at), .attachments = AK_SPAN(att),
                       .stretch_stiffness = 500.0f};
    for (int solver = 0; solver < 3; ++solver) {
        d.solver = (ak_cloth_solver)solver;
        sim s;
        AK_CHECK(sim_init(&s, &d));
        AK_CHECK(s.x[0].x == -0.01f && s.x[0].y == 0.02f);
        ak_vec3 targets[2];
        s.job.attachment_targets = (ak_vec3_cspan)AK_SPAN(targets);
        s.job.wind = ak_vec3_make(3, 0, 2), s.job.drag = 1, s.job.lift = 1;
        s.job.substeps = solver == AK_CLOTH_SPRINGS ? 40 : 10;
        sim_scratch(&s);
        ak_f32_cspan w = ak_cloth_inverse_masses(s.cloth);
        AK_CHECK(w.ptr[0] == 0.0f && w.ptr[9] == 0.0f && w.ptr[99] == 0.0f && w.ptr[50] > 0.0f);
        int bad = 0;
        for (int f = 0; f < 90; ++f) {
            const float t = (float)f / 60.0f;
            /* a skinned vertex and a joint moving on circles */
            targets[0] = ak_vec3_make(0.45f + 0.2f * sinf(3 * t), 0.1f * cosf(2 * t), 0.1f * t);
            targets[1] = ak_vec3_make(0.45f, -0.45f + 0.1f * sinf(5 * t), 0.2f * sinf(t));
            AK_CHECK_EQ(ak_cloth_step_run(&s.job), AK_OK);
            bad += memcmp(&s.x[9], &targets[0], sizeof(ak_vec3)) != 0;
            bad += memcmp(&s.x[99], &targets[1], sizeof(ak_vec3)) != 0;
            bad += s.x[0].x != -0.01f || s.x[0].y != 0.02f || s.x[0].z != 0.0f;
            bad += s.v[0].x != 0.0f || s.v[0].y != 0.0f || s.v[0].z != 0.0f;
        }
        AK_CHECK_EQ(bad, 0);
        sim_free(&s);
    }
}

/* ---- robustness, threads ------------------------------------------------------------- */

/* 10,000 steps of a small flag in strong gusty wind: finite state, bounded stretch. */
AK_TEST(flag_strong_wind_10000_steps) {
    enum { W = 8, H = 5 };
    uint32_t pins[2] = {0, (H - 1) * W};
    ak_cloth_desc d = {.grid_width = W, .grid_height = H, .spacing = 0.1f, .grid_axis_v = {0, -1, 0},
                       .pins = AK_SPAN(pins), .long_range_attachments = true, .long_range_slack = 0.1f};
    sim s;
    AK_CHECK(sim_init(&s, &d));
    s.job.drag = 1.2f, s.job.lift = 0.8f;
    s.job.substeps = 4;
    sim_scratch(&s);
    float worst = 0.0f;
    int finite = 1;
    for (int f = 0; f < 10000 && finite; ++f) {
        const float t = (float)f / 60.0f;
        s.job.wind = ak_vec3_make(15.0f + 5.0f * sinf(1.3f * t), 2.0f * sinf(0.7f * t), 5.0f * sinf(2.1f * t));
        if (ak_cloth_step_run(&s.job) != AK_OK) finite = 0;
        const float st = ak_cloth_max_stretch(s.cloth, (ak_vec3_cspan){s.x, s.n});
        if (!ak_finitef(st)) finite = 0;
        worst = ak_maxf(worst, st);
    }
    printf("  flag in 10-20 m/s gusts: worst max stretch over 10,000 steps %.3f\n", (double)worst);
    AK_CHECK(finite);
    AK_CHECK(worst < 0.5f);
    sim_free(&s);
}

/* The spring solver with far too large a step blows up; the step says so. */
AK_TEST(springs_blow_up_reported) {
    ak_cloth_desc d = {.solver = AK_CLOTH_SPRINGS, .grid_width = 8, .grid_height = 8, .stretch_stiffness = 1e6f};
    sim s;
    AK_CHECK(sim_init(&s, &d));
    s.job.substeps = 1;
    sim_scratch(&s);
    s.x[5].y += 0.01f;
    ak_result r = AK_OK;
    for (int f = 0; f < 200 && r == AK_OK; ++f) r = ak_cloth_step_run(&s.job);
    AK_CHECK_EQ(r, AK_ERR_NO_CONVERGENCE);
    sim_free(&s);
}

/* One free spring (two equal masses m, no gravity) is the harmonic oscillator omega^2 = 2 k / m,
 * gamma = 2 c / m, whose semi-implicit Euler is stable exactly while h^2 omega^2 + 2 h gamma < 4:
 * ak_cloth_stable_substep gives that bound (closed form), the step holds at 0.95 of it and
 * blows up at 1.05. A sheet at the bound's substep count (with the command's 0.9 margin) stays
 * finite and unstretched; at half of it, it blows up (the bound is within 2x of the truth:
 * measured, this sheet holds down to 75 substeps where the bound asks for 115). */
static ak_result one_spring_run(float c, float h_scale, float* out_h) {
    const float m = 0.01f, k = 100.0f;
    ak_vec3 p[2] = {{0, 0, 0}, {0.5f, 0, 0}};
    uint32_t e[2] = {0, 1};
    float w[2] = {1.0f / m, 1.0f / m};
    ak_cloth_desc d = {.solver = AK_CLOTH_SPRINGS, .positions = AK_SPAN(p), .edges = AK_SPAN(e),
                       .inverse_masses = AK_SPAN(w), .stretch_stiffness = k, .spring_damping = c};
    sim s;
    if (!sim_init(&s, &d)) return AK_ERR_BAD_ARG;
    *out_h = ak_cloth_stable_substep(s.cloth);
    s.job.gravity = ak_vec3_make(0, 0, 0);
    s.job.dt = *out_h * h_scale;
    s.job.substeps = 1;
    sim_scratch(&s);
    s.x[1].x = 0.51f;
    ak_result r = AK_OK;
    for (int f = 0; f < 3000 && r == AK_OK; ++f) {
        r = ak_cloth_step_run(&s.job);
        /* growing (a marginally stable orbit reaches about 3x its start at 0.95) */
        if (r == AK_OK && !(fabsf(s.x[1].x - s.x[0].x - 0.5f) < 0.1f)) r = AK_ERR_NO_CONVERGENCE;
    }
    sim_free(&s);
    return r;
}

AK_TEST(springs_stable_substep) {
    const double m = 0.01, k = 100.0;
    for (int damped = 0; damped < 2; ++damped) {
        const double c = damped ? 0.05 : 0.0, om2 = 2.0 * k / m, ga = 2.0 * c / m;
        const double expect = (sqrt(ga * ga + 4.0 * om2) - ga) / om2;
        float h = 0.0f;
        AK_CHECK_EQ(one_spring_run((float)c, 0.95f, &h), AK_OK);
        AK_CHECK_NEAR(h, expect, 1e-6 * expect);
        AK_CHECK_EQ(one_spring_run((float)c, 1.05f, &h), AK_ERR_NO_CONVERGENCE);
    }
    /* the other solvers: unconditionally stable */
    ak_cloth_desc x = {.grid_width = 4, .grid_height = 4};
    ak_cloth* cx = NULL;
    AK_CHECK_EQ(ak_cloth_create(&x, NULL, &cx), AK_OK);
    AK_CHECK(isinf(ak_cloth_stable_substep(cx)));
    ak_cloth_destroy(cx);
    AK_CHECK_EQ(ak_cloth_stable_substep(NULL), 0.0f);
    /* a falling 16 x 16 sheet on a sphere, 1 s */
    for (int half = 0; half < 2; ++half) {
        ak_cloth_desc d = {.solver = AK_CLOTH_SPRINGS, .grid_width = 16, .grid_height = 16, .spacing = 1.0f / 15.0f,
                           .grid_origin = {-0.5f, 1.0f, 0.5f}};
        sim s;
        AK_CHECK(sim_init(&s, &d));
        const ak_cloth_sphere sp = {{0, 0.5f, 0}, 0.3f};
        s.job.spheres = &sp, s.job.sphere_count = 1;
        const uint32_t need = (uint32_t)ceilf(s.job.dt / (0.9f * ak_cloth_stable_substep(s.cloth)));
        s.job.substeps = half ? need / 2 : need;
        sim_scratch(&s);
        ak_result r = AK_OK;
        float stretch = 0.0f;
        for (int f = 0; f < 60 && r == AK_OK && stretch < 1.0f; ++f) {
            r = ak_cloth_step_run(&s.job);
            stretch = ak_cloth_max_stretch(s.cloth, (ak_vec3_cspan){s.x, s.n});
            if (!(stretch < 1.0f)) stretch = INFINITY; /* NaN: overflowed */
        }
        printf("  16 x 16 springs sheet: %u substeps per 1/60 s (stable bound); at %u: %s, max stretch %g\n", need,
               s.job.substeps, r == AK_OK ? "finite" : "non-finite", (double)stretch);
        AK_CHECK(half ? (r != AK_OK || stretch >= 1.0f) : (r == AK_OK && stretch < 0.05f));
        sim_free(&s);
    }
}

/* Every solver gives bit-identical states on 1, 2 and 3 threads (collisions, wind,
 * self-collision and attachments on). */
AK_TEST(deterministic_for_any_thread_count) {
    uint32_t att[1] = {0};
    for (int solver = 0; solver < 3; ++solver) {
        ak_cloth_desc d = {.solver = (ak_cloth_solver)solver, .grid_width = 9, .grid_height = 7,
                           .grid_origin = {-0.4f, 0.7f, 0.3f}, .attachments = AK_SPAN(att),
                           .stretch_stiffness = 500.0f};
        ak_vec3* out[3] = {NULL, NULL, NULL};
        for (int k = 0; k < 3; ++k) {
            sim s;
            AK_CHECK(sim_init(&s, &d));
            const ak_cloth_sphere sp = {{0, 0.4f, 0}, 0.25f};
            ak_vec3 target = s.x[0];
            s.job.spheres = &sp, s.job.sphere_count = 1;
            s.job.wind = ak_vec3_make(2, 0, 1), s.job.drag = 1, s.job.lift = 0.5f;
            s.job.self_collision = true;
            s.job.friction = 0.3f;
            s.job.attachment_targets = (ak_vec3_cspan){&target, 1};
            s.job.thread_count = (uint32_t)(k + 1);
            s.job.exact_thread_count = true; /* a 9 x 7 cloth would otherwise run on one thread */
            s.job.substeps = solver == AK_CLOTH_SPRINGS ? 40 : 8;
            sim_scratch(&s);
            for (int f = 0; f < 20; ++f) {
                target.x += 0.01f;
                AK_CHECK_EQ(ak_cloth_step_run(&s.job), AK_OK);
            }
            out[k] = malloc(s.n * sizeof(ak_vec3));
            memcpy(out[k], s.x, s.n * sizeof(ak_vec3));
            if (k > 0) AK_CHECK_MSG(memcmp(out[0], out[k], s.n * sizeof(ak_vec3)) == 0, "solver %d: %d threads differ", solver, k + 1);
            sim_free(&s);
        }
        for (int k = 0; k < 3; ++k) free(out[k]);
    }
}

/* The default thread bound (no exact_thread_count: one thread per 1024 constraints of an
 * average colour, so a 128 x 128 XPBD sheet takes several) with 1, 2, 3 and 16 threads asked
 * for: bit-identical positions, velocities and residuals, the set-up and the finish of the step
 * (residuals in, start + displacement out) being split over the threads too. Pinned vertices
 * end exactly at their pins with zero residuals. */
AK_TEST(default_thread_bound_bit_identical) {
    enum { W = 128, STEPS = 6 };
    const uint32_t counts[4] = {1, 2, 3, 16};
    uint32_t pins[2] = {0, W - 1};
    ak_cloth_desc d = {.solver = AK_CLOTH_XPBD, .grid_width = W, .grid_height = W, .spacing = 1.0f / (W - 1),
                       .grid_origin = {-0.5f, 1.0f, 0.5f}, .pins = AK_SPAN(pins)};
    ak_vec3* out[4] = {NULL, NULL, NULL, NULL};
    for (int k = 0; k < 4; ++k) {
        sim s;
        AK_CHECK(sim_init(&s, &d));
        ak_vec3* res = calloc(s.n, sizeof(ak_vec3));
        const ak_cloth_sphere sp = {{0, 0.5f, 0}, 0.3f};
        s.job.spheres = &sp, s.job.sphere_count = 1, s.job.friction = 0.3f, s.job.damping = 0.5f;
        s.job.substeps = 4;
        s.job.position_residuals = (ak_vec3_span){res, s.n};
        s.job.thread_count = counts[k];
        sim_scratch(&s);
        for (int f = 0; f < STEPS; ++f) AK_CHECK_EQ(ak_cloth_step_run(&s.job), AK_OK);
        out[k] = malloc(3 * s.n * sizeof(ak_vec3));
        memcpy(out[k], s.x, s.n * sizeof(ak_vec3));
        memcpy(out[k] + s.n, s.v, s.n * sizeof(ak_vec3));
        memcpy(out[k] + 2 * s.n, res, s.n * sizeof(ak_vec3));
        for (int p = 0; p < 2; ++p) {
            const ak_vec3 r0 = res[pins[p]];
            AK_CHECK(r0.x == 0.0f && r0.y == 0.0f && r0.z == 0.0f);
        }
        /* the sheet moved: not a trivially equal rest state */
        AK_CHECK(s.x[W * W / 2].y < 1.0f - 1e-3f);
        if (k > 0)
            AK_CHECK_MSG(memcmp(out[0], out[k], 3 * s.n * sizeof(ak_vec3)) == 0, "%u threads differ from 1", counts[k]);
        free(res);
        sim_free(&s);
    }
    for (int k = 0; k < 4; ++k) free(out[k]);
}

/* XPBD without wind or self-collision runs a substep's collisions and velocities and the next
 * substep's prediction and kinematic placement as one phase per thread, each thread placing the
 * pins and attachments of its own vertices, and checks the vertices' data on the threads. With
 * pins in the first and last thirds of the sheet and a moving attachment in the middle one, on
 * 1, 2, 3 and 8 threads: the same bits (positions, velocities, residuals); pins and the attachment
 * exactly at their targets; the attachment's velocity its target's speed (it moves 0.01 m a
 * step in equal parts per substep, so every substep's velocity is 0.01 / dt); and a non-finite
 * velocity in the last thread's vertices reported as AK_ERR_BAD_DATA with nothing written. */
AK_TEST(fused_substeps_kinematic_bit_identical) {
    enum { W = 40, STEPS = 5 };
    uint32_t pins[3] = {0, W - 1, W * W - 1};
    uint32_t att[1] = {W * (W / 2) + W / 2};
    ak_cloth_desc d = {.solver = AK_CLOTH_XPBD, .grid_width = W, .grid_height = W, .spacing = 1.0f / (W - 1),
                       .grid_origin = {-0.5f, 1.0f, 0.5f}, .pins = AK_SPAN(pins), .attachments = AK_SPAN(att)};
    const uint32_t counts[4] = {1, 2, 3, 8};
    ak_vec3* out[4] = {NULL, NULL, NULL, NULL};
    for (int k = 0; k < 4; ++k) {
        sim s;
        AK_CHECK(sim_init(&s, &d));
        ak_vec3* res = calloc(s.n, sizeof(ak_vec3));
        ak_vec3 target = s.x[att[0]];
        const ak_vec3 pin_at[3] = {s.x[pins[0]], s.x[pins[1]], s.x[pins[2]]};
        const ak_cloth_sphere sp = {{0, 0.6f, 0}, 0.3f};
        s.job.spheres = &sp, s.job.sphere_count = 1, s.job.friction = 0.3f, s.job.damping = 0.5f;
        s.job.substeps = 6;
        s.job.position_residuals = (ak_vec3_span){res, s.n};
        s.job.attachment_targets = (ak_vec3_cspan){&target, 1};
        s.job.thread_count = counts[k];
        s.job.exact_thread_count = true;
        sim_scratch(&s);
        for (int f = 0; f < STEPS; ++f) {
            target.x += 0.01f;
            AK_CHECK_EQ(ak_cloth_step_run(&s.job), AK_OK);
            AK_CHECK(memcmp(&s.x[att[0]], &target, sizeof(ak_vec3)) == 0);
            for (int p = 0; p < 3; ++p) AK_CHECK(memcmp(&s.x[pins[p]], &pin_at[p], sizeof(ak_vec3)) == 0);
            AK_CHECK_NEAR(s.v[att[0]].x, 0.01f / s.job.dt, 1e-3f);
            AK_CHECK_NEAR(s.v[att[0]].y, 0.0f, 1e-3f);
        }
        AK_CHECK(s.x[W * W / 2 + 3].y < 1.0f - 1e-3f); /* the sheet fell: not a rest state */
        out[k] = malloc(3 * s.n * sizeof(ak_vec3));
        memcpy(out[k], s.x, s.n * sizeof(ak_vec3));
        memcpy(out[k] + s.n, s.v, s.n * sizeof(ak_vec3));
        memcpy(out[k] + 2 * s.n, res, s.n * sizeof(ak_vec3));
        if (k > 0)
            AK_CHECK_MSG(memcmp(out[0], out[k], 3 * s.n * sizeof(ak_vec3)) == 0, "%u threads differ from 1", counts[k]);
        /* bad data in the last thread's share: nothing written */
        s.v[s.n - 2].z = NAN;
        target.x += 0.01f;
        AK_CHECK_EQ(ak_cloth_step_run(&s.job), AK_ERR_BAD_DATA);
        AK_CHECK(memcmp(out[k], s.x, s.n * sizeof(ak_vec3)) == 0);
        AK_CHECK(memcmp(out[k] + 2 * s.n, res, s.n * sizeof(ak_vec3)) == 0);
        for (size_t v = 0; v < s.n; ++v)
            if (v != s.n - 2) AK_CHECK(memcmp(&out[k][s.n + v], &s.v[v], sizeof(ak_vec3)) == 0);
        free(res);
        sim_free(&s);
    }
    for (int k = 0; k < 4; ++k) free(out[k]);
    /* A sheet translating rigidly: every border vertex attached to a target moving by dx per
     * step, every vertex starting at velocity dx / dt, no gravity or damping. Each substep then
     * moves the free vertices by the prediction and the attachments by their share of dx
     * alike, so no constraint is violated and the sheet ends translated by dx per step (a
     * placement at the wrong fraction of the step would pull the interior back by about dx /
     * substeps). */
    enum { B = 24 };
    uint32_t border[4 * (B - 1)];
    size_t nb = 0;
    for (uint32_t i = 0; i < B; ++i)
        for (uint32_t j = 0; j < B; ++j)
            if (i == 0 || j == 0 || i == B - 1 || j == B - 1) border[nb++] = j * B + i;
    ak_cloth_desc dr = {.solver = AK_CLOTH_XPBD, .grid_width = B, .grid_height = B, .spacing = 0.04f,
                        .attachments = {border, nb}};
    const ak_vec3 dx = ak_vec3_make(0.01f, -0.004f, 0.006f);
    for (uint32_t threads = 1; threads <= 3; ++threads) {
        sim s;
        AK_CHECK(sim_init(&s, &dr));
        ak_vec3* x0 = malloc(s.n * sizeof(ak_vec3));
        ak_vec3* targets = malloc(nb * sizeof(ak_vec3));
        memcpy(x0, s.x, s.n * sizeof(ak_vec3));
        for (size_t v = 0; v < s.n; ++v) s.v[v] = ak_vec3_scale(dx, 1.0f / s.job.dt);
        s.job.gravity = ak_vec3_make(0, 0, 0);
        s.job.substeps = 6;
        s.job.attachment_targets = (ak_vec3_cspan){targets, nb};
        s.job.thread_count = threads;
        s.job.exact_thread_count = true;
        sim_scratch(&s);
        float worst = 0.0f;
        for (int f = 1; f <= 3; ++f) {
            for (size_t k = 0; k < nb; ++k) targets[k] = ak_vec3_madd(x0[border[k]], dx, (float)f);
            AK_CHECK_EQ(ak_cloth_step_run(&s.job), AK_OK);
            for (size_t v = 0; v < s.n; ++v)
                worst = ak_maxf(worst, ak_vec3_distance(s.x[v], ak_vec3_madd(x0[v], dx, (float)f)));
        }
        AK_CHECK_MSG(worst < 2e-5f, "%u threads: the translated sheet is off by %g m", threads, (double)worst);
        free(x0), free(targets);
        sim_free(&s);
    }
}

/* Smooth normals of a flat sheet are u x v; of a folded one, unit and area-weighted. */
AK_TEST(normals) {
    ak_cloth_desc d = {.grid_width = 5, .grid_height = 4, .grid_axis_u = {0, 0, 1}, .grid_axis_v = {0, 1, 0}};
    sim s;
    AK_CHECK(sim_init(&s, &d));
    ak_vec3 nrm[20];
    AK_CHECK_EQ(ak_cloth_normals(s.cloth, (ak_vec3_cspan){s.x, s.n}, (ak_vec3_span)AK_SPAN(nrm)), AK_OK);
    for (int v = 0; v < 20; ++v) AK_CHECK_NEAR(nrm[v].x, -1.0f, 1e-6f);
    AK_CHECK_EQ(ak_cloth_normals(s.cloth, (ak_vec3_cspan){s.x, s.n}, (ak_vec3_span){nrm, 19}), AK_ERR_SPAN_SMALL);
    sim_free(&s);
}

/* Wind pushes a free sheet facing it downwind; a sheet edge-on to the wind feels no drag. */
AK_TEST(wind_drag_direction) {
    ak_cloth_desc d = {.grid_width = 4, .grid_height = 4, .grid_axis_u = {0, 0, 1}, .grid_axis_v = {0, 1, 0}};
    sim s;
    AK_CHECK(sim_init(&s, &d));
    s.job.gravity = ak_vec3_make(0, 0, 0);
    s.job.wind = ak_vec3_make(5, 0, 0);
    s.job.drag = 1.0f;
    sim_scratch(&s);
    AK_CHECK_EQ(ak_cloth_step_run(&s.job), AK_OK);
    /* drag on the sheet: 1/2 rho |w - v|^2 C_d A over its mass 0.2 A is dv/dt = K (w - v)^2 with
     * K = 0.5 * 1.2 / 0.2 = 3 1/m, so w - v(t) = 1 / (1/w + K t): v(1/60) = 5 - 4 = 1 m/s */
    AK_CHECK_NEAR(s.v[5].x, 1.0f, 0.03f);
    AK_CHECK_NEAR(s.v[5].y, 0.0f, 1e-4f);
    s.job.wind = ak_vec3_make(0, 0, 5);
    memset(s.v, 0, s.n * sizeof(ak_vec3));
    AK_CHECK_EQ(ak_cloth_step_run(&s.job), AK_OK);
    AK_CHECK_NEAR(s.v[5].z, 0.0f, 1e-6f);
    sim_free(&s);
}

/* ---- SIMD paths -------------------------------------------------------------------------- */

static uint32_t rng_next(uint32_t* s) {
    *s ^= *s << 13, *s ^= *s >> 17, *s ^= *s << 5;
    return *s;
}
static float rng_unit(uint32_t* s) { return (float)(rng_next(s) >> 8) / 16777216.0f; } /* [0, 1) */

/* One random cloth case: a jittered mesh or a generated grid, with its bending kind, solver and
 * damping; its start state is disturbed (random velocities, a collapsed edge and a collapsed
 * triangle so the solves' degenerate-lane masks are exercised). Runs `frames` frames with the
 * given SIMD limit and threads, and returns positions then velocities (2 n vec3, malloc'd). */
typedef struct simd_case {
    bool mesh;
    ak_cloth_bending bending;
    ak_cloth_solver solver;
    float damping;
    uint32_t seed;
} simd_case;

static ak_vec3* run_simd_case(const simd_case* sc, ak_cloth_simd simd, uint32_t threads, size_t* out_n) {
    enum { W = 14, H = 12 };
    ak_vec3 pos[W * H];
    uint32_t tris[(W - 1) * (H - 1) * 6];
    uint32_t rng = sc->seed;
    size_t t = 0;
    for (uint32_t j = 0; j < H; ++j)
        for (uint32_t i = 0; i < W; ++i)
            pos[j * W + i] = ak_vec3_make(0.05f * ((float)i + 0.3f * rng_unit(&rng)), 0.6f + 0.02f * rng_unit(&rng),
                                          -0.05f * ((float)j + 0.3f * rng_unit(&rng)));
    for (uint32_t j = 0; j + 1 < H; ++j)
        for (uint32_t i = 0; i + 1 < W; ++i) {
            const uint32_t a = j * W + i, b = a + 1, c = a + W, d = c + 1;
            if (rng_next(&rng) & 1) {
                const uint32_t o[6] = {a, b, c, b, d, c};
                memcpy(tris + 6 * t++, o, sizeof o);
            } else {
                const uint32_t o[6] = {a, b, d, a, d, c};
                memcpy(tris + 6 * t++, o, sizeof o);
            }
        }
    uint32_t pins[3] = {0, W - 1, 7 * W + 3};
    ak_cloth_desc d = {.solver = sc->solver, .bending = sc->bending, .constraint_damping = sc->damping,
                       .pins = AK_SPAN(pins), .stretch_stiffness = 800.0f, .dihedral_stiffness = 2e-3f,
                       .pbd_stiffness = 0.7f};
    if (sc->mesh) {
        d.positions = (ak_vec3_cspan)AK_SPAN(pos);
        d.indices = (ak_u32_cspan)AK_SPAN(tris);
    } else {
        d.grid_width = W, d.grid_height = H, d.grid_origin = ak_vec3_make(-0.3f, 0.6f, 0.2f);
    }
    sim s;
    if (!sim_init(&s, &d)) return NULL;
    for (size_t v = 0; v < s.n; ++v)
        s.v[v] = ak_vec3_make(rng_unit(&rng) - 0.5f, rng_unit(&rng) - 0.5f, rng_unit(&rng) - 0.5f);
    s.x[2 * W + 5] = s.x[2 * W + 6];                     /* a collapsed edge */
    s.x[5 * W + 8] = s.x[5 * W + 9] = s.x[6 * W + 8];    /* a collapsed triangle */
    const ak_cloth_sphere sp = {{0.3f, 0.35f, -0.25f}, 0.2f};
    s.job.spheres = &sp, s.job.sphere_count = 1;
    s.job.friction = 0.2f;
    s.job.substeps = 6;
    s.job.iterations = 2;
    s.job.simd_limit = simd;
    s.job.thread_count = threads;
    s.job.exact_thread_count = true;
    sim_scratch(&s);
    bool ok = true;
    for (int f = 0; f < 12 && ok; ++f) ok = ak_cloth_step_run(&s.job) == AK_OK;
    ak_vec3* out = ok ? malloc(2 * s.n * sizeof(ak_vec3)) : NULL;
    if (out) {
        memcpy(out, s.x, s.n * sizeof(ak_vec3));
        memcpy(out + s.n, s.v, s.n * sizeof(ak_vec3));
    }
    *out_n = s.n;
    sim_free(&s);
    return out;
}

/* The SIMD constraint solves give the scalar solve's bits: every path this CPU has, on random
 * cloths with every constraint kind (stretch, shear, bending distance constraints, dihedral,
 * isometric), XPBD with and without damping and PBD, on 1 to 3 threads. */
AK_TEST(simd_paths_bit_identical) {
    const char* widest = ak_cloth_simd_name();
    const bool have512 = strcmp(widest, "avx512") == 0, have2 = have512 || strcmp(widest, "avx2") == 0;
    printf("  widest constraint solve on this CPU: %s\n", widest);
    if (!have2) printf("  SKIP: AVX2 path (this CPU or build has none)\n");
    if (!have512) printf("  SKIP: AVX-512 path (this CPU or build has none)\n");
    const simd_case cases[] = {
        {false, AK_CLOTH_BEND_DIHEDRAL, AK_CLOTH_XPBD, 0.0f, 11u},   {false, AK_CLOTH_BEND_ISOMETRIC, AK_CLOTH_XPBD, 0.0f, 12u},
        {false, AK_CLOTH_BEND_SPRINGS, AK_CLOTH_XPBD, 0.01f, 13u},   {false, AK_CLOTH_BEND_NONE, AK_CLOTH_PBD, 0.0f, 14u},
        {true, AK_CLOTH_BEND_DIHEDRAL, AK_CLOTH_XPBD, 0.01f, 15u},   {true, AK_CLOTH_BEND_ISOMETRIC, AK_CLOTH_XPBD, 0.01f, 16u},
        {true, AK_CLOTH_BEND_SPRINGS, AK_CLOTH_XPBD, 0.0f, 17u},     {true, AK_CLOTH_BEND_DIHEDRAL, AK_CLOTH_PBD, 0.0f, 18u},
        {true, AK_CLOTH_BEND_ISOMETRIC, AK_CLOTH_PBD, 0.0f, 19u},
    };
    const ak_cloth_simd paths[2] = {AK_CLOTH_SIMD_AVX2, AK_CLOTH_SIMD_AVX512};
    const bool have[2] = {have2, have512};
    for (size_t c = 0; c < sizeof cases / sizeof cases[0]; ++c) {
        size_t n = 0;
        ak_vec3* ref = run_simd_case(&cases[c], AK_CLOTH_SIMD_SCALAR, 1, &n);
        AK_CHECK_MSG(ref != NULL, "case %zu: scalar run failed", c);
        if (!ref) continue;
        /* the state moved, and stayed finite */
        bool finite = true;
        for (size_t v = 0; v < 2 * n; ++v) finite = finite && ak_vec3_is_finite(ref[v]);
        AK_CHECK_MSG(finite, "case %zu: non-finite state", c);
        for (int p = 0; p < 2; ++p) {
            if (!have[p]) continue;
            for (uint32_t th = 1; th <= 3; th += 2) {
                size_t m = 0;
                ak_vec3* got = run_simd_case(&cases[c], paths[p], th, &m);
                AK_CHECK_MSG(got && m == n && memcmp(ref, got, 2 * n * sizeof(ak_vec3)) == 0,
                             "case %zu: %s path on %u threads differs from the scalar path", c, p ? "AVX-512" : "AVX2", th);
                free(got);
            }
        }
        size_t m = 0;
        ak_vec3* got = run_simd_case(&cases[c], AK_CLOTH_SIMD_SCALAR, 2, &m);
        AK_CHECK_MSG(got && memcmp(ref, got, 2 * n * sizeof(ak_vec3)) == 0, "case %zu: scalar path on 2 threads differs", c);
        free(got);
        free(ref);
    }
    /* simd_limit out of range */
    ak_cloth_desc d = {.grid_width = 4, .grid_height = 4};
    sim s;
    AK_CHECK(sim_init(&s, &d));
    sim_scratch(&s);
    s.job.simd_limit = AK_CLOTH_SIMD_COUNT;
    AK_CHECK_EQ(ak_cloth_step_validate(&s.job), AK_ERR_BAD_ARG);
    sim_free(&s);
}

int main(void) {
    AK_RUN(desc_defaults);
    AK_RUN(create_rules);
    AK_RUN(step_rules);
    AK_RUN(constraint_coloring_valid_and_minimal);
    AK_RUN(single_spring_static_stretch);
    AK_RUN(dihedral_gradient);
    AK_RUN(isometric_bending);
    AK_RUN(hinge_pendulum_period_substeps_translation);
    AK_RUN_SLOW(pinned_sheet_rest_shape_is_energy_minimum); /* 4.3 s: make test stays under a minute */
    AK_RUN(xpbd_stretch_independent_of_substeps);
    AK_RUN(drape_no_penetration_and_rest);
    AK_RUN(mesh_collider);
    AK_RUN(pins_and_attachments_exact);
    AK_RUN_HEAVY(flag_strong_wind_10000_steps); /* valgrind: the other cases step the same code */
    AK_RUN(springs_blow_up_reported);
    AK_RUN(springs_stable_substep);
    AK_RUN(deterministic_for_any_thread_count);
    AK_RUN(default_thread_bound_bit_identical);
    AK_RUN(fused_substeps_kinematic_bit_identical);
    AK_RUN(normals);
    AK_RUN(wind_drag_direction);
    AK_RUN(simd_paths_bit_identical);
    return ak_test_finish();
}

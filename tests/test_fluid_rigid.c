/* The fluid colliding one-way with rigid bodies: the fluid's box and convex colliders against
 * closed forms, ak_rigid_fluid_colliders against the bodies' shapes and motion, and PBF liquid
 * poured on a static box and a tilted hull (no particle ever inside, checked with each body's
 * own geometry independently of the colliders; hydrostatic rest on the box) and pushed by a
 * moving box. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <animkit/animkit.h>

#include "ak_test.h"
#include "fluid_fit.h"

/* One step of a single particle with no gravity: PBF moves it only by the projection (alone it
 * has less than rest density, so the unilateral constraint is inactive). */
static ak_vec3 project_one(const ak_fluid_collider* col, ak_vec3 p) {
    ak_fluid_desc d = {.h = 0.1f, .particle_mass = 0.001f};
    ak_vec3 pos[1] = {p}, vel[1] = {{0, 0, 0}};
    size_t n = 1, bytes = ak_fluid_scratch_size(1, &d);
    void* mem = malloc(bytes);
    ak_fluid_step_job job = {.desc = &d,
                             .dt = 0.01f,
                             .positions = {pos, 1},
                             .velocities = {vel, 1},
                             .particle_count = &n,
                             .colliders = {col, 1},
                             .scratch = {mem, bytes}};
    ak_result r = ak_fluid_step_run(&job);
    free(mem);
    return r == AK_OK ? pos[0] : ak_vec3_make(NAN, NAN, NAN);
}

AK_TEST(box_and_convex_colliders_project_to_the_nearest_face) {
    /* a box turned 40 deg about (1, 2, 0.5), half extents (0.3, 0.2, 0.25); a particle at local
     * (0.1, 0.05, -0.02) is 0.2, 0.15 and 0.23 under the x, y and z faces: it goes to local
     * (0.1, 0.2, -0.02), through +y */
    const ak_quat q =
        ak_quat_from_axis_angle(ak_vec3_normalize(ak_vec3_make(1, 2, 0.5f)), 0.6981317f);
    const ak_vec3 a = {0.4f, -0.3f, 1.2f}, he = {0.3f, 0.2f, 0.25f};
    const ak_vec3 inside = ak_vec3_add(a, ak_quat_rotate(q, ak_vec3_make(0.1f, 0.05f, -0.02f)));
    const ak_vec3 want = ak_vec3_add(a, ak_quat_rotate(q, ak_vec3_make(0.1f, 0.2f, -0.02f)));
    ak_fluid_collider box = {.shape = AK_FLUID_BOX, .a = a, .orientation = q, .half_extents = he};
    ak_vec3 got = project_one(&box, inside);
    AK_CHECK_MSG(ak_vec3_distance(got, want) < 1e-5f, "box: (%g %g %g)", got.x, got.y, got.z);
    /* the same box as six planes */
    ak_vec4 planes[6] = {{1, 0, 0, 0.3f},  {-1, 0, 0, 0.3f}, {0, 1, 0, 0.2f},
                         {0, -1, 0, 0.2f}, {0, 0, 1, 0.25f}, {0, 0, -1, 0.25f}};
    ak_fluid_collider cvx = {
        .shape = AK_FLUID_CONVEX, .a = a, .orientation = q, .planes = planes, .plane_count = 6};
    got = project_one(&cvx, inside);
    AK_CHECK_MSG(ak_vec3_distance(got, want) < 1e-5f, "convex: (%g %g %g)", got.x, got.y, got.z);
    /* a point outside stays where it is */
    const ak_vec3 out = ak_vec3_add(a, ak_quat_rotate(q, ak_vec3_make(0.35f, 0.0f, 0.0f)));
    AK_CHECK(ak_vec3_distance(project_one(&box, out), out) < 1e-6f);
    AK_CHECK(ak_vec3_distance(project_one(&cvx, out), out) < 1e-6f);
    /* bad colliders */
    ak_fluid_desc d = {.h = 0.1f, .particle_mass = 0.001f};
    ak_vec3 pos[1] = {{0, 0, 0}}, vel[1] = {{0, 0, 0}};
    size_t n = 1;
    unsigned char mem[4096];
    ak_fluid_step_job job = {.desc = &d,
                             .dt = 0.01f,
                             .positions = {pos, 1},
                             .velocities = {vel, 1},
                             .particle_count = &n,
                             .colliders = {&cvx, 1},
                             .scratch = {mem, sizeof mem}};
    cvx.plane_count = 0;
    AK_CHECK_EQ(ak_fluid_step_validate(&job), AK_ERR_BAD_ARG);
    cvx.plane_count = 6, cvx.planes = NULL;
    AK_CHECK_EQ(ak_fluid_step_validate(&job), AK_ERR_NULL_ARG);
    planes[2].y = 2.0f, cvx.planes = planes;
    AK_CHECK_EQ(ak_fluid_step_validate(&job), AK_ERR_BAD_ARG);
    box.half_extents.z = -1.0f;
    job.colliders = (ak_fluid_collider_cspan){&box, 1};
    AK_CHECK_EQ(ak_fluid_step_validate(&job), AK_ERR_BAD_ARG);
    box.half_extents.z = 0.25f, box.angular_velocity.x = NAN;
    AK_CHECK_EQ(ak_fluid_step_validate(&job), AK_ERR_BAD_ARG);
}

/* Height of a heightfield's surface at local (x, z) from its two triangles per cell, written
 * independently of the solver (rigid.h's split: (00, 01, 11) where v >= u, else (00, 11, 10)). */
static float hf_height(const float* h, uint32_t cols, float spacing, float x, float z) {
    float fx = x / spacing, fz = z / spacing;
    uint32_t i = (uint32_t)floorf(fx), j = (uint32_t)floorf(fz);
    float u = fx - (float)i, v = fz - (float)j;
    float h00 = h[j * cols + i], h10 = h[j * cols + i + 1], h01 = h[(j + 1) * cols + i],
          h11 = h[(j + 1) * cols + i + 1];
    if (v >= u) return h00 + v * (h01 - h00) + u * (h11 - h01);
    return h00 + u * (h10 - h00) + v * (h11 - h10);
}

AK_TEST(heightfield_collider_projects_onto_its_triangle) {
    /* the plane y = 0.5 x sampled 3 x 3, 1 m apart, in a frame turned 30 deg about Y at (2, -1,
     * 3): a particle 0.15 m under the surface at local (1.3, _, 0.7) goes along the normal
     * (-0.5, 1, 0)/sqrt(1.25) by 0.15/sqrt(1.25) onto the plane; one off the grid stays */
    const float h[9] = {0, 0.5f, 1, 0, 0.5f, 1, 0, 0.5f, 1};
    const ak_quat q = ak_quat_from_axis_angle(ak_vec3_make(0, 1, 0), 0.5235988f);
    const ak_vec3 a = {2, -1, 3};
    ak_fluid_collider hf = {.shape = AK_FLUID_HEIGHTFIELD,
                            .a = a,
                            .orientation = q,
                            .heights = h,
                            .rows = 3,
                            .cols = 3,
                            .spacing = 1};
    const ak_vec3 in_l = {1.3f, 0.5f, 0.7f};
    const ak_vec3 nl = ak_vec3_scale(ak_vec3_make(-0.5f, 1, 0), 1.0f / sqrtf(1.25f));
    const ak_vec3 want_l = ak_vec3_add(in_l, ak_vec3_scale(nl, 0.15f / sqrtf(1.25f)));
    const ak_vec3 got = project_one(&hf, ak_vec3_add(a, ak_quat_rotate(q, in_l)));
    const ak_vec3 got_l = ak_quat_rotate(ak_quat_conjugate(q), ak_vec3_sub(got, a));
    AK_CHECK_MSG(ak_vec3_distance(got_l, want_l) < 1e-5f, "(%g %g %g)", got_l.x, got_l.y, got_l.z);
    AK_CHECK_NEAR(got_l.y, 0.5f * got_l.x, 1e-5f);
    const ak_vec3 off = ak_vec3_add(a, ak_quat_rotate(q, ak_vec3_make(2.5f, -3, 1)));
    AK_CHECK(ak_vec3_distance(project_one(&hf, off), off) < 1e-6f);
    const ak_vec3 above = ak_vec3_add(a, ak_quat_rotate(q, ak_vec3_make(1.3f, 0.7f, 0.7f)));
    AK_CHECK(ak_vec3_distance(project_one(&hf, above), above) < 1e-6f);
    /* bad heightfields */
    ak_fluid_desc d = {.h = 0.1f, .particle_mass = 0.001f};
    ak_vec3 pos[1] = {{0, 0, 0}}, vel[1] = {{0, 0, 0}};
    size_t n = 1, bytes = ak_fluid_scratch_size(1, &d);
    unsigned char* mem = malloc(bytes);
    ak_fluid_step_job job = {.desc = &d,
                             .dt = 0.01f,
                             .positions = {pos, 1},
                             .velocities = {vel, 1},
                             .particle_count = &n,
                             .colliders = {&hf, 1},
                             .scratch = {mem, bytes}};
    AK_CHECK_EQ(ak_fluid_step_validate(&job), AK_OK);
    hf.rows = 1;
    AK_CHECK_EQ(ak_fluid_step_validate(&job), AK_ERR_BAD_ARG);
    hf.rows = 3, hf.spacing = 0;
    AK_CHECK_EQ(ak_fluid_step_validate(&job), AK_ERR_BAD_ARG);
    hf.spacing = 1, hf.heights = NULL;
    AK_CHECK_EQ(ak_fluid_step_validate(&job), AK_ERR_NULL_ARG);
    const float bad[9] = {0, 0, 0, 0, NAN, 0, 0, 0, 0};
    hf.heights = bad;
    AK_CHECK_EQ(ak_fluid_step_validate(&job), AK_ERR_BAD_ARG);
    free(mem);
}

AK_TEST(a_turning_collider_gives_its_surface_velocity) {
    /* SPH (velocities are the solver's own, not derived from positions): a particle resting on
     * top of a box spinning at 2 rad/s about +Y, 0.3 m from the axis, with friction 1, takes the
     * surface's velocity w x r = (0, 0, -0.6) m/s at r = (0.3, 0, 0) */
    ak_fluid_desc d = {
        .solver = AK_FLUID_SPH, .h = 0.1f, .particle_mass = 0.001f, .friction = 1.0f};
    ak_fluid_collider box = {.shape = AK_FLUID_BOX,
                             .a = {0, 0, 0},
                             .half_extents = {1, 0.5f, 1},
                             .angular_velocity = {0, 2, 0}};
    ak_vec3 pos[1] = {{0.3f, 0.499f, 0}}, vel[1] = {{0, -0.1f, 0}};
    size_t n = 1, bytes = ak_fluid_scratch_size(1, &d);
    void* mem = malloc(bytes);
    ak_fluid_step_job job = {.desc = &d,
                             .dt = 1e-4f,
                             .positions = {pos, 1},
                             .velocities = {vel, 1},
                             .particle_count = &n,
                             .colliders = {&box, 1},
                             .scratch = {mem, bytes}};
    AK_CHECK_EQ(ak_fluid_step_run(&job), AK_OK);
    free(mem);
    AK_CHECK_NEAR(pos[0].y, 0.5f, 1e-5f);
    AK_CHECK_NEAR(vel[0].x, 0.0f, 1e-3f);
    AK_CHECK_NEAR(vel[0].y, 0.0f, 1e-5f);
    AK_CHECK_NEAR(vel[0].z, -0.6f, 2e-3f);
}

AK_TEST(rigid_bodies_become_fluid_colliders) {
    const ak_vec3 tet[4] = {{0, 0, 0}, {0.4f, 0, 0}, {0, 0.4f, 0}, {0, 0, 0.4f}};
    const ak_rigid_child kids[2] = {
        {.shape = {.type = AK_RIGID_SPHERE, .radius = 0.2f}, .position = {-1, 0, 0}},
        {.shape = {.type = AK_RIGID_BOX, .half_extents = {0.2f, 0.2f, 0.2f}},
         .position = {1, 0, 0}}};
    static float hts[4] = {0, 0, 0, 0};
    ak_rigid_body_desc b[5] = {
        {.shape = {.type = AK_RIGID_PLANE}, .is_static = true},
        {.shape = {.type = AK_RIGID_CAPSULE, .radius = 0.1f, .half_height = 0.5f},
         .position = {0, 2, 0}},
        {.shape = {.type = AK_RIGID_HULL, .points = {tet, 4}}, .position = {3, 1, 0}},
        {.shape = {.type = AK_RIGID_COMPOUND, .children = kids, .child_count = 2},
         .position = {0, 5, 0}},
        {.shape = {.type = AK_RIGID_HEIGHTFIELD,
                   .heights = {hts, 4},
                   .rows = 2,
                   .cols = 2,
                   .spacing = 1}}};
    ak_rigid_model* m = NULL;
    AK_CHECK_EQ(ak_rigid_model_create(&(ak_rigid_model_desc){.bodies = {b, 5}}, NULL, &m), AK_OK);
    if (!m) return;
    size_t nc = 0, np = 0;
    ak_rigid_fluid_colliders_size(m, &nc, &np);
    AK_CHECK_EQ(nc, 6u); /* plane, capsule, hull, sphere and box children, heightfield */
    AK_CHECK_EQ(np, 4u);
    ak_vec3 x[5], v[5], w[5];
    ak_quat q[5];
    ak_rigid_initial_state(m, (ak_vec3_span){x, 5}, (ak_quat_span){q, 5}, (ak_vec3_span){v, 5},
                           (ak_vec3_span){w, 5});
    /* the capsule turned 90 deg about Z, moving and spinning about Z */
    q[1] = ak_quat_from_axis_angle(ak_vec3_make(0, 0, 1), 1.5707963f);
    v[1] = ak_vec3_make(1, 0, 0), w[1] = ak_vec3_make(0, 0, 3);
    v[0] = ak_vec3_make(5, 5, 5); /* a static body's state velocity is ignored */
    ak_fluid_collider cols[8];
    ak_vec4 planes[8];
    size_t got = 0;
    AK_CHECK_EQ(ak_rigid_fluid_colliders(m, (ak_vec3_cspan){x, 5}, (ak_quat_cspan){q, 5},
                                         (ak_vec3_cspan){v, 5}, (ak_vec3_cspan){w, 5},
                                         (ak_fluid_collider_span){cols, 8},
                                         (ak_vec4_span){planes, 8}, &got),
                AK_OK);
    AK_CHECK_EQ(got, 6u);
    AK_CHECK_EQ(cols[5].shape, AK_FLUID_HEIGHTFIELD);
    AK_CHECK(cols[5].rows == 2 && cols[5].cols == 2 && cols[5].spacing == 1.0f &&
             cols[5].heights != NULL);
    AK_CHECK(cols[5].heights != hts); /* the model's copy */
    AK_CHECK_EQ(cols[0].shape, AK_FLUID_PLANE);
    AK_CHECK(ak_vec3_length(cols[0].velocity) == 0.0f);
    AK_CHECK_NEAR(cols[0].normal.y, 1.0f, 1e-6f);
    /* capsule: the segment's ends at x -+ R (0, 0.5, 0) = (+-0.5, 2, 0) ... (0.5, 2, 0) first */
    AK_CHECK_EQ(cols[1].shape, AK_FLUID_CAPSULE);
    AK_CHECK(ak_vec3_distance(cols[1].a, ak_vec3_make(0.5f, 2, 0)) < 1e-5f);
    AK_CHECK(ak_vec3_distance(cols[1].b, ak_vec3_make(-0.5f, 2, 0)) < 1e-5f);
    /* velocity at a = v + w x (a - x) = (1, 0, 0) + (0, 0, 3) x (0.5, 0, 0) = (1, 1.5, 0) */
    AK_CHECK(ak_vec3_distance(cols[1].velocity, ak_vec3_make(1, 1.5f, 0)) < 1e-5f);
    AK_CHECK(ak_vec3_distance(cols[1].angular_velocity, w[1]) == 0.0f);
    /* hull: 4 planes; each of the tetrahedron's corners on 3 of them, under the 4th */
    AK_CHECK_EQ(cols[2].shape, AK_FLUID_CONVEX);
    AK_CHECK_EQ(cols[2].plane_count, 4u);
    const ak_transform sf = ak_rigid_body_shape_frame(m, 2);
    for (int c = 0; c < 4; ++c) {
        ak_vec3 p = ak_vec3_add(sf.translation, ak_quat_rotate(sf.rotation, tet[c]));
        int on = 0, under = 0;
        for (uint32_t k = 0; k < 4; ++k) {
            const ak_vec4 pl = cols[2].planes[k];
            float e = pl.x * p.x + pl.y * p.y + pl.z * p.z - pl.w;
            on += fabsf(e) < 1e-5f, under += e < -1e-3f;
        }
        AK_CHECK(on == 3 && under == 1);
    }
    /* compound: the sphere child centred 1 m from the box child, 2 m apart, around x */
    AK_CHECK_EQ(cols[3].shape, AK_FLUID_SPHERE);
    AK_CHECK_EQ(cols[4].shape, AK_FLUID_BOX);
    AK_CHECK_NEAR(ak_vec3_distance(cols[3].a, cols[4].a), 2.0f, 1e-5f);
    AK_CHECK_NEAR(cols[3].radius, 0.2f, 1e-7f);
    AK_CHECK_NEAR(cols[4].half_extents.x, 0.2f, 1e-7f);
    AK_CHECK(ak_vec3_distance(ak_vec3_scale(ak_vec3_add(cols[3].a, cols[4].a), 0.5f),
                              ak_vec3_make(0, 5, 0)) < 1e-5f);
    /* errors */
    AK_CHECK_EQ(ak_rigid_fluid_colliders(m, (ak_vec3_cspan){x, 5}, (ak_quat_cspan){q, 5},
                                         (ak_vec3_cspan){v, 5}, (ak_vec3_cspan){w, 5},
                                         (ak_fluid_collider_span){cols, 5},
                                         (ak_vec4_span){planes, 8}, &got),
                AK_ERR_SPAN_SMALL);
    AK_CHECK_EQ(ak_rigid_fluid_colliders(m, (ak_vec3_cspan){x, 5}, (ak_quat_cspan){q, 5},
                                         (ak_vec3_cspan){v, 5}, (ak_vec3_cspan){w, 5},
                                         (ak_fluid_collider_span){cols, 8},
                                         (ak_vec4_span){planes, 3}, &got),
                AK_ERR_SPAN_SMALL);
    v[2].x = NAN;
    AK_CHECK_EQ(ak_rigid_fluid_colliders(m, (ak_vec3_cspan){x, 5}, (ak_quat_cspan){q, 5},
                                         (ak_vec3_cspan){v, 5}, (ak_vec3_cspan){w, 5},
                                         (ak_fluid_collider_span){cols, 8},
                                         (ak_vec4_span){planes, 8}, &got),
                AK_ERR_BAD_DATA);
    AK_CHECK_EQ(ak_rigid_fluid_colliders(NULL, (ak_vec3_cspan){x, 5}, (ak_quat_cspan){q, 5},
                                         (ak_vec3_cspan){v, 5}, (ak_vec3_cspan){w, 5},
                                         (ak_fluid_collider_span){cols, 8},
                                         (ak_vec4_span){planes, 8}, &got),
                AK_ERR_NULL_ARG);
    ak_rigid_model_destroy(m);
}

/* A liquid and a rigid world stepped together as the header shows: the rigid step, the bodies
 * as colliders, the fluid step. */
typedef struct coupled {
    ak_rigid_model* model;
    size_t nb;
    ak_vec3 x[4], v[4], w[4];
    ak_quat q[4];
    ak_rigid_step_job rjob;
    ak_fluid_desc fd;
    ak_vec3 *pos, *vel;
    size_t n;
    void* scratch;
    ak_fluid_step_job fjob;
    ak_fluid_collider cols[8];
    ak_vec4 planes[64];
} coupled;

static bool coupled_init(coupled* c, const ak_rigid_body_desc* bodies, size_t nb, ak_vec3 rigid_g,
                         ak_vec3 box_lo, ak_vec3 box_hi, ak_vec3 block_lo, ak_vec3 block_hi) {
    memset(c, 0, sizeof *c);
    if (ak_rigid_model_create(&(ak_rigid_model_desc){.bodies = {bodies, nb}}, NULL, &c->model) !=
        AK_OK)
        return false;
    c->nb = nb;
    ak_rigid_initial_state(c->model, (ak_vec3_span){c->x, nb}, (ak_quat_span){c->q, nb},
                           (ak_vec3_span){c->v, nb}, (ak_vec3_span){c->w, nb});
    c->rjob = (ak_rigid_step_job){.model = c->model,
                                  .dt = 1.0f / 200.0f,
                                  .substeps = 4,
                                  .gravity = rigid_g,
                                  .positions = {c->x, nb},
                                  .orientations = {c->q, nb},
                                  .velocities = {c->v, nb},
                                  .angular_velocities = {c->w, nb}};
    size_t rs = ak_rigid_step_scratch_size(&c->rjob);
    c->rjob.scratch = (ak_u8_span){malloc(rs), rs};
    const float s = 0.04f; /* rest spacing: 64 g particles of water */
    c->fd = (ak_fluid_desc){.h = 2.0f * s,
                            .particle_mass = s * s * s * 1000.0f,
                            .gravity = {0, -9.81f, 0},
                            .box_min = box_lo,
                            .box_max = box_hi,
                            .iterations = 4};
    size_t cap = ak_fluid_fill_box(&c->fd, block_lo, block_hi, (ak_vec3_span){NULL, 0});
    c->pos = malloc(cap * sizeof *c->pos);
    c->vel = calloc(cap, sizeof *c->vel);
    c->n = ak_fluid_fill_box(&c->fd, block_lo, block_hi, (ak_vec3_span){c->pos, cap});
    size_t fs = ak_fluid_scratch_size(cap, &c->fd);
    c->scratch = malloc(fs);
    c->fjob = (ak_fluid_step_job){.desc = &c->fd,
                                  .dt = 1.0f / 200.0f,
                                  .positions = {c->pos, cap},
                                  .velocities = {c->vel, cap},
                                  .particle_count = &c->n,
                                  .scratch = {c->scratch, fs}};
    return c->rjob.scratch.ptr && c->pos && c->vel && c->scratch;
}

static bool coupled_step(coupled* c) {
    if (ak_rigid_step_run(&c->rjob) != AK_OK) return false;
    size_t nc = 0;
    if (ak_rigid_fluid_colliders(c->model, (ak_vec3_cspan){c->x, c->nb},
                                 (ak_quat_cspan){c->q, c->nb}, (ak_vec3_cspan){c->v, c->nb},
                                 (ak_vec3_cspan){c->w, c->nb}, (ak_fluid_collider_span){c->cols, 8},
                                 (ak_vec4_span){c->planes, 64}, &nc) != AK_OK)
        return false;
    c->fjob.colliders = (ak_fluid_collider_cspan){c->cols, nc};
    return ak_fluid_step_run(&c->fjob) == AK_OK;
}

static void coupled_free(coupled* c) {
    free(c->rjob.scratch.ptr), free(c->pos), free(c->vel), free(c->scratch);
    ak_rigid_model_destroy(c->model);
}

/* Deepest a particle is inside a box of half extents he at (x, q): > 0 inside (m). */
static float box_depth(ak_vec3 p, ak_vec3 x, ak_quat q, ak_vec3 he) {
    ak_vec3 l = ak_quat_rotate(ak_quat_conjugate(q), ak_vec3_sub(p, x));
    return fminf(fminf(he.x - fabsf(l.x), he.y - fabsf(l.y)), he.z - fabsf(l.z));
}

AK_TEST(liquid_poured_on_a_static_box_lands_as_on_a_raised_floor) {
    /* a static box 0.2 m tall covers the floor of a 0.24 x 0.24 m tank (it reaches 4 cm past
     * the walls: a face flush with a wall would leave a crease); 216 particles (6^3 at 4 cm)
     * dropped from 0.2 m above it. Oracle: the same liquid in the same tank with its floor raised
     * to the box's top (the tank's own boundary, no body), which the fluid tests check against
     * hydrostatics: no particle is ever inside the box, and every particle follows the raised
     * floor's run (1 mm after 0.8 s), resting on the box's top. */
    const ak_vec3 he = {0.16f, 0.1f, 0.16f}, bx = {0.12f, 0.1f, 0.12f};
    ak_rigid_body_desc b[1] = {
        {.shape = {.type = AK_RIGID_BOX, .half_extents = he}, .position = bx, .is_static = true}};
    ak_rigid_body_desc far[1] = {{.shape = {.type = AK_RIGID_SPHERE, .radius = 0.1f},
                                  .position = {50, 50, 50},
                                  .is_static = true}};
    coupled c, ref;
    AK_CHECK(coupled_init(&c, b, 1, ak_vec3_make(0, -9.81f, 0), ak_vec3_make(0, 0, 0),
                          ak_vec3_make(0.24f, 2, 0.24f), ak_vec3_make(0, 0.4f, 0),
                          ak_vec3_make(0.24f, 0.64f, 0.24f)));
    AK_CHECK(coupled_init(&ref, far, 1, ak_vec3_make(0, -9.81f, 0), ak_vec3_make(0, 0.2f, 0),
                          ak_vec3_make(0.24f, 2, 0.24f), ak_vec3_make(0, 0.4f, 0),
                          ak_vec3_make(0.24f, 0.64f, 0.24f)));
    AK_CHECK_EQ(c.n, 216u);
    AK_CHECK_EQ(ref.n, 216u);
    float deepest = -INFINITY, miny = INFINITY;
    for (int s = 0; s < 160 && !ak_test_cur_failed_; ++s) {
        AK_CHECK(coupled_step(&c));
        AK_CHECK(coupled_step(&ref));
        for (size_t i = 0; i < c.n; ++i) {
            deepest = fmaxf(deepest, box_depth(c.pos[i], bx, c.q[0], he));
            miny = fminf(miny, c.pos[i].y);
        }
    }
    AK_CHECK_MSG(deepest <= 1e-5f, "a particle %g m inside the box", deepest);
    AK_CHECK_MSG(miny >= 0.2f - 1e-5f, "a particle at %g m, under the box's top", miny);
    float worst = 0.0f;
    for (size_t i = 0; i < c.n; ++i) worst = fmaxf(worst, ak_vec3_distance(c.pos[i], ref.pos[i]));
    printf("  static box: deepest %g m, lowest %g m, %g m from the raised floor's run\n",
           (double)deepest, (double)miny, (double)worst);
    AK_CHECK_MSG(worst < 1e-3f, "%g m from the raised floor's run", worst);
    coupled_free(&c);
    coupled_free(&ref);
}

AK_TEST(liquid_poured_on_a_tilted_hull_never_enters_it) {
    /* a static hull: a 0.24 x 0.1 x 0.24 m box's 8 corners turned 30 deg about Z, in the middle
     * of the tank; checked against the box's own inside test in its frame */
    const ak_vec3 he = {0.12f, 0.05f, 0.12f};
    ak_vec3 corners[8];
    for (int k = 0; k < 8; ++k)
        corners[k] = ak_vec3_make(k & 1 ? he.x : -he.x, k & 2 ? he.y : -he.y, k & 4 ? he.z : -he.z);
    const ak_quat tilt = ak_quat_from_axis_angle(ak_vec3_make(0, 0, 1), 0.5235988f);
    const ak_vec3 at = {0.2f, 0.25f, 0.16f};
    ak_rigid_body_desc b[1] = {{.shape = {.type = AK_RIGID_HULL, .points = {corners, 8}},
                                .position = at,
                                .orientation = tilt,
                                .is_static = true}};
    coupled c;
    AK_CHECK(coupled_init(&c, b, 1, ak_vec3_make(0, -9.81f, 0), ak_vec3_make(0, 0, 0),
                          ak_vec3_make(0.4f, 2, 0.32f), ak_vec3_make(0.08f, 0.45f, 0.04f),
                          ak_vec3_make(0.32f, 0.77f, 0.28f)));
    float deepest = -INFINITY;
    for (int s = 0; s < 100 && !ak_test_cur_failed_; ++s) {
        AK_CHECK(coupled_step(&c));
        for (size_t i = 0; i < c.n; ++i)
            deepest = fmaxf(deepest, box_depth(c.pos[i], at, tilt, he));
    }
    AK_CHECK_MSG(deepest <= 1e-5f, "a particle %g m inside the hull", deepest);
    printf("  tilted hull: deepest %g m\n", (double)deepest);
    /* the liquid reached the hull: some particle lies within a spacing of its surface */
    float nearest = INFINITY;
    for (size_t i = 0; i < c.n; ++i) nearest = fminf(nearest, -box_depth(c.pos[i], at, tilt, he));
    AK_CHECK_MSG(nearest < 0.04f, "no particle near the hull (%g m)", nearest);
    coupled_free(&c);
}

AK_TEST(liquid_poured_on_a_heightfield_stays_above_it) {
    /* a static heightfield bowl h = 0.3 + 1.5 ((x - 0.2)^2 + (z - 0.2)^2), 11 x 11 samples 5 cm
     * apart from x, z = -0.05 (it reaches past the 0.4 x 0.4 m tank's walls: the tank's clamp
     * must not put a particle back over the grid under its rim); 4 cm particles dropped on it:
     * at every step no particle is under the surface (the same triangles interpolated
     * independently, 1e-4 m), and the liquid gathers at the bottom: its mean height under the
     * rim's */
    static float bowl[121];
    for (int j = 0; j < 11; ++j)
        for (int i = 0; i < 11; ++i) {
            float x = 0.05f * (float)i - 0.25f, z = 0.05f * (float)j - 0.25f;
            bowl[j * 11 + i] = 0.3f + 1.5f * (x * x + z * z);
        }
    ak_rigid_body_desc b[1] = {{.shape = {.type = AK_RIGID_HEIGHTFIELD,
                                          .heights = {bowl, 121},
                                          .rows = 11,
                                          .cols = 11,
                                          .spacing = 0.05f},
                                .position = {-0.05f, 0, -0.05f}}};
    coupled c;
    AK_CHECK(coupled_init(&c, b, 1, ak_vec3_make(0, -9.81f, 0), ak_vec3_make(0, 0, 0),
                          ak_vec3_make(0.4f, 2, 0.4f), ak_vec3_make(0.04f, 0.6f, 0.04f),
                          ak_vec3_make(0.36f, 0.76f, 0.36f)));
    float worst = -INFINITY;
    for (int s = 0; s < 120 && !ak_test_cur_failed_; ++s) {
        AK_CHECK(coupled_step(&c));
        for (size_t i = 0; i < c.n; ++i)
            worst =
                fmaxf(worst, hf_height(bowl, 11, 0.05f, c.pos[i].x + 0.05f, c.pos[i].z + 0.05f) -
                                 c.pos[i].y);
    }
    double my = 0.0;
    for (size_t i = 0; i < c.n; ++i) my += c.pos[i].y;
    my /= (double)c.n;
    printf(
        "  heightfield bowl: %zu particles, deepest under the surface %g m, mean height %.3f m\n",
        c.n, (double)worst, my);
    AK_CHECK_MSG(worst <= 1e-4f, "a particle %g m under the surface", worst);
    AK_CHECK_MSG(my < 0.3 + 1.5 * 0.08, "mean height %g m: over the rim", my);
    coupled_free(&c);
}

AK_TEST(a_moving_box_pushes_the_liquid) {
    /* a box 0.12 m wide moving at 1 m/s along +X (no gravity on the bodies, no contacts: it keeps
     * its speed) through a layer of liquid resting on the tank's floor: no particle inside it at
     * any step, the particles just ahead of its front face move at its speed, and the liquid
     * gains +X momentum */
    const ak_vec3 he = {0.06f, 0.2f, 0.2f};
    ak_rigid_body_desc b[1] = {{.shape = {.type = AK_RIGID_BOX, .half_extents = he},
                                .position = {-0.07f, 0.16f, 0.2f},
                                .velocity = {1, 0, 0}}};
    coupled c;
    AK_CHECK(coupled_init(&c, b, 1, ak_vec3_make(0, 0, 0), ak_vec3_make(-0.2f, 0, 0),
                          ak_vec3_make(0.8f, 1, 0.4f), ak_vec3_make(0, 0, 0),
                          ak_vec3_make(0.4f, 0.16f, 0.4f)));
    float deepest = -INFINITY;
    for (int s = 0; s < 30 && !ak_test_cur_failed_; ++s) {
        AK_CHECK(coupled_step(&c));
        for (size_t i = 0; i < c.n; ++i)
            deepest = fmaxf(deepest, box_depth(c.pos[i], c.x[0], c.q[0], he));
    }
    AK_CHECK_MSG(deepest <= 1e-5f, "a particle %g m inside the moving box", deepest);
    AK_CHECK_NEAR(c.x[0].x, -0.07f + 0.15f, 1e-4f);
    double px = 0.0, front_v = 0.0;
    int front = 0;
    const float face = c.x[0].x + he.x;
    for (size_t i = 0; i < c.n; ++i) {
        px += c.vel[i].x;
        if (c.pos[i].x >= face && c.pos[i].x < face + 0.02f && fabsf(c.pos[i].z - 0.2f) < 0.15f &&
            c.pos[i].y < 0.3f)
            front_v += c.vel[i].x, ++front;
    }
    AK_CHECK_MSG(front > 10, "%d particles at the front face", front);
    if (front) front_v /= front;
    printf("  moving box: deepest %g m; %d particles at its front at %.3f m/s; mean %.3f m/s\n",
           (double)deepest, front, front_v, px / (double)c.n);
    AK_CHECK_MSG(front_v > 0.8 && front_v < 1.3, "front particles at %g m/s, the box at 1",
                 front_v);
    AK_CHECK_MSG(px / (double)c.n > 0.05, "mean x velocity %g", px / (double)c.n);
    coupled_free(&c);
}

AK_TEST(fluid_scene_box_colliders) {
    ak_fluid_scene* sc = malloc(sizeof *sc);
    ak_diag diag;
    const char* good = "{\"blocks\": [{\"min\": [0, 0, 0], \"max\": [0.1, 0.1, 0.1]}], "
                       "\"colliders\": [{\"shape\": \"box\", \"a\": [1, 2, 3], "
                       "\"half_extents\": [0.1, 0.2, 0.3], \"orientation\": [0, 0, 2, 0]}]}";
    AK_CHECK_EQ(ak_fluid_scene_load_bytes(good, strlen(good), "t", sc, &diag), AK_OK);
    AK_CHECK_EQ(sc->collider_count, 1u);
    AK_CHECK_EQ(sc->colliders[0].shape, AK_FLUID_BOX);
    AK_CHECK_NEAR(sc->colliders[0].half_extents.z, 0.3f, 1e-7f);
    AK_CHECK_NEAR(sc->colliders[0].orientation.z, 1.0f, 1e-7f); /* normalised */
    const char* bad[] = {
        "{\"colliders\": [{\"shape\": \"box\", \"a\": [1, 2, 3]}]}",
        "{\"colliders\": [{\"shape\": \"box\", \"half_extents\": [0.1, -0.2, 0.3]}]}",
        "{\"colliders\": [{\"shape\": \"box\", \"half_extents\": [1, 1, 1], \"orientation\": [0, 0, 0, 0]}]}",
        "{\"colliders\": [{\"shape\": \"sphere\", \"radius\": 1, \"half_extents\": [1, 1, 1]}]}",
        "{\"colliders\": [{\"shape\": \"cone\"}]}",
    };
    const char* where[] = {"colliders[0].half_extents: required for a box",
                           "colliders[0].half_extents", "colliders[0].orientation: is the zero",
                           "colliders[0].half_extents: only a box", "colliders[0].shape"};
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; ++i) {
        AK_CHECK_EQ(ak_fluid_scene_load_bytes(bad[i], strlen(bad[i]), "t", sc, &diag),
                    AK_ERR_PARSE);
        AK_CHECK_MSG(strstr(diag.message, where[i]) != NULL, "%s", diag.message);
    }
    free(sc);
}

/* Hydrostatic rest on a body: a WCSPH column (6 x 6 x 16 particles at 1 cm, as test_fluid.c's
 * hydrostatic column) standing on a static box body 5 cm tall that covers the tank's floor (and
 * reaches past its walls). The fitted slope of pressure against height, over the particles more
 * than h from the box's top and from the surface, averaged over the last 500 of 1300 steps of
 * 3e-4 s, is rho0 g within 5% (the same bound as on the tank's own floor), and no particle is
 * ever inside the box. */
AK_TEST(column_on_a_box_body_is_hydrostatic) {
    ak_fluid_desc d = {.solver = AK_FLUID_WCSPH,
                       .particle_mass = 0.001f,
                       .gravity = {0, -9.81f, 0},
                       .viscosity = 0.2f,
                       .sound_speed = 15.0f};
    const float s = ak_fluid_rest_spacing(&d), top_of_box = 0.05f;
    const int w = 6, ht = 16;
    d.h = 2.0f * s;
    d.box_min = ak_vec3_make(0, 0, 0);
    d.box_max = ak_vec3_make((float)w * s, top_of_box + 3.0f * (float)ht * s, (float)w * s);
    const ak_vec3 he = {(float)w * s, 0.5f * top_of_box, (float)w * s};
    const ak_vec3 bx = {0.5f * (float)w * s, 0.5f * top_of_box, 0.5f * (float)w * s};
    ak_rigid_body_desc b[1] = {
        {.shape = {.type = AK_RIGID_BOX, .half_extents = he}, .position = bx, .is_static = true}};
    ak_rigid_model* m = NULL;
    AK_CHECK_EQ(ak_rigid_model_create(&(ak_rigid_model_desc){.bodies = {b, 1}}, NULL, &m), AK_OK);
    if (!m) return;
    ak_vec3 x[1], v[1], wv[1];
    ak_quat q[1];
    ak_rigid_initial_state(m, (ak_vec3_span){x, 1}, (ak_quat_span){q, 1}, (ak_vec3_span){v, 1},
                           (ak_vec3_span){wv, 1});
    ak_fluid_collider col[1];
    size_t nc = 0;
    AK_CHECK_EQ(ak_rigid_fluid_colliders(m, (ak_vec3_cspan){x, 1}, (ak_quat_cspan){q, 1},
                                         (ak_vec3_cspan){v, 1}, (ak_vec3_cspan){wv, 1},
                                         (ak_fluid_collider_span){col, 1}, (ak_vec4_span){NULL, 0},
                                         &nc),
                AK_OK);
    const size_t cap = (size_t)w * w * ht;
    ak_vec3* pos = malloc(cap * sizeof *pos);
    ak_vec3* vel = calloc(cap, sizeof *vel);
    float* pres = malloc(cap * sizeof *pres);
    size_t n =
        ak_fluid_fill_box(&d, ak_vec3_make(0, top_of_box, 0),
                          ak_vec3_make((float)w * s, top_of_box + (float)ht * s, (float)w * s),
                          (ak_vec3_span){pos, cap});
    size_t bytes = ak_fluid_scratch_size(cap, &d);
    void* mem = malloc(bytes);
    ak_fluid_step_job job = {.desc = &d,
                             .dt = 3e-4f,
                             .positions = {pos, cap},
                             .velocities = {vel, cap},
                             .particle_count = &n,
                             .colliders = {col, nc},
                             .scratch = {mem, bytes},
                             .out_pressures = {pres, cap}};
    double sum = 0.0;
    int fits = 0;
    float deepest = -INFINITY;
    const int steps = 1300, window = 500;
    for (int step = 0; step < steps && !ak_test_cur_failed_; ++step) {
        AK_CHECK_EQ(ak_fluid_step_run(&job), AK_OK);
        for (size_t i = 0; i < n; ++i) deepest = fmaxf(deepest, box_depth(pos[i], bx, q[0], he));
        if (step < steps - window) continue;
        double slope;
        if (fluid_pressure_slope(pos, pres, n, top_of_box + d.h, d.h, &slope)) sum += slope, ++fits;
    }
    const double slope = fits ? sum / fits : NAN;
    printf("  column on a box body: pressure slope %.1f Pa/m against rho g %.1f; deepest %g m\n",
           slope, 1000.0 * 9.81, (double)deepest);
    AK_CHECK_MSG(fabs(slope / (1000.0 * 9.81) - 1.0) < 0.05, "slope %.1f Pa/m", slope);
    AK_CHECK_MSG(deepest <= 1e-5f, "a particle %g m inside the box", deepest);
    free(mem), free(pres), free(vel), free(pos);
    ak_rigid_model_destroy(m);
}

int main(void) {
    AK_RUN(box_and_convex_colliders_project_to_the_nearest_face);
    AK_RUN(heightfield_collider_projects_onto_its_triangle);
    AK_RUN(a_turning_collider_gives_its_surface_velocity);
    AK_RUN(rigid_bodies_become_fluid_colliders);
    AK_RUN(liquid_poured_on_a_static_box_lands_as_on_a_raised_floor);
    AK_RUN(liquid_poured_on_a_tilted_hull_never_enters_it);
    AK_RUN(liquid_poured_on_a_heightfield_stays_above_it);
    AK_RUN(a_moving_box_pushes_the_liquid);
    AK_RUN(fluid_scene_box_colliders);
    AK_RUN_SLOW(column_on_a_box_body_is_hydrostatic); /* 1300 WCSPH steps: about 1 s */
    return ak_test_finish();
}

/* Rigid bodies against physics: closed forms and conservation laws. */
#include <math.h>
#include <stdlib.h>

#include <animkit/rigid.h>

#include "ak_test.h"

/* A world: model plus state and scratch. */
typedef struct world {
    ak_rigid_model* model;
    size_t n;
    ak_vec3 x[64], v[64], w[64];
    ak_quat q[64];
    float sleep[64];
    ak_rigid_contact_anchor anchors[256];
    uint32_t anchor_count;
    ak_rigid_step_job job;
} world;

/* Keep the step's persistent contacts (ak_rigid_contact_anchor) between the world's steps. */
static void world_keep_anchors(world* wd) {
    wd->anchor_count = 0;
    wd->job.contact_anchors = (ak_rigid_contact_anchor_span){wd->anchors, 256};
    wd->job.contact_anchor_count = &wd->anchor_count;
}

static bool world_init(world* wd, const ak_rigid_body_desc* bodies, size_t n,
                       const ak_rigid_model_desc* extra, float dt, uint32_t substeps, ak_vec3 g) {
    memset(wd, 0, sizeof *wd);
    ak_rigid_model_desc md = {0};
    if (extra) md = *extra;
    md.bodies = (ak_rigid_body_desc_cspan){bodies, n};
    if (ak_rigid_model_create(&md, NULL, &wd->model) != AK_OK) return false;
    wd->n = n;
    ak_rigid_initial_state(wd->model, (ak_vec3_span){wd->x, n}, (ak_quat_span){wd->q, n},
                           (ak_vec3_span){wd->v, n}, (ak_vec3_span){wd->w, n});
    wd->job = (ak_rigid_step_job){.model = wd->model,
                                  .dt = dt,
                                  .substeps = substeps,
                                  .gravity = g,
                                  .positions = {wd->x, n},
                                  .orientations = {wd->q, n},
                                  .velocities = {wd->v, n},
                                  .angular_velocities = {wd->w, n}};
    size_t size = ak_rigid_step_scratch_size(&wd->job);
    wd->job.scratch = (ak_u8_span){malloc(size), size};
    return wd->job.scratch.ptr != NULL;
}

static void world_free(world* wd) {
    free(wd->job.scratch.ptr);
    ak_rigid_model_destroy(wd->model);
}

static const ak_vec3 G = {0.0f, -9.81f, 0.0f};

AK_TEST(mass_and_inertia_closed_forms) {
    ak_rigid_body_desc b[3] = {
        {.shape = {.type = AK_RIGID_SPHERE, .radius = 0.5f}},
        {.shape = {.type = AK_RIGID_BOX, .half_extents = {1.0f, 0.5f, 0.25f}}, .mass = 6.0f},
        {.shape = {.type = AK_RIGID_CAPSULE, .radius = 0.1f, .half_height = 0.0f},
         .density = 500.0f},
    };
    ak_rigid_model* m = NULL;
    ak_rigid_model_desc md = {.bodies = {b, 3}};
    AK_CHECK_EQ(ak_rigid_model_create(&md, NULL, &m), AK_OK);
    double ms = 1000.0 * 4.0 / 3.0 * 3.14159265358979 * 0.125;
    AK_CHECK_NEAR(ak_rigid_body_mass(m, 0), ms, 1e-3 * ms);
    AK_CHECK_NEAR(ak_rigid_body_inertia(m, 0).y, 0.4 * ms * 0.25, 1e-3 * ms);
    /* box 2 x 1 x 0.5 m, 6 kg: I_x = 6 (1 + 0.25) / 12 */
    AK_CHECK_NEAR(ak_rigid_body_inertia(m, 1).x, 6.0 * (1.0 + 0.25) / 12.0, 1e-5);
    AK_CHECK_NEAR(ak_rigid_body_inertia(m, 1).z, 6.0 * (4.0 + 1.0) / 12.0, 1e-5);
    /* a capsule of zero length is a sphere */
    double mc = 500.0 * 4.0 / 3.0 * 3.14159265358979 * 0.001;
    AK_CHECK_NEAR(ak_rigid_body_mass(m, 2), mc, 1e-4 * mc);
    AK_CHECK_NEAR(ak_rigid_body_inertia(m, 2).x, 0.4 * mc * 0.01, 1e-4 * 0.4 * mc * 0.01);
    AK_CHECK_NEAR(ak_rigid_body_inertia(m, 2).y, 0.4 * mc * 0.01, 1e-4 * 0.4 * mc * 0.01);
    ak_rigid_model_destroy(m);
}

AK_TEST(model_validity) {
    ak_rigid_model* m = NULL;
    ak_rigid_model_desc md = {0};
    AK_CHECK_EQ(ak_rigid_model_create(NULL, NULL, &m), AK_ERR_NULL_ARG);
    AK_CHECK_EQ(ak_rigid_model_create(&md, NULL, &m), AK_ERR_EMPTY);
    ak_rigid_body_desc b = {.shape = {.type = AK_RIGID_SPHERE}};
    md.bodies = (ak_rigid_body_desc_cspan){&b, 1};
    AK_CHECK_EQ(ak_rigid_model_create(&md, NULL, &m), AK_ERR_BAD_ARG); /* radius 0 */
    b.shape.radius = NAN;
    AK_CHECK_EQ(ak_rigid_model_create(&md, NULL, &m), AK_ERR_BAD_DATA);
    b.shape.radius = 1.0f;
    b.restitution = 1.5f;
    AK_CHECK_EQ(ak_rigid_model_create(&md, NULL, &m), AK_ERR_BAD_ARG);
    b.restitution = 0.0f;
    b.friction = -0.5f;
    AK_CHECK_EQ(ak_rigid_model_create(&md, NULL, &m), AK_ERR_BAD_ARG);
    b.friction = 0.0f;
    b.shape.type = AK_RIGID_SHAPE_COUNT;
    AK_CHECK_EQ(ak_rigid_model_create(&md, NULL, &m), AK_ERR_BAD_ARG);
    AK_CHECK(m == NULL);
    b.shape.type = AK_RIGID_SPHERE;
    ak_rigid_body_desc two[2] = {b, b};
    ak_rigid_joint_desc jd = {.body_a = 0, .body_b = 0};
    ak_rigid_model_desc mj = {.bodies = {two, 2}, .joints = {&jd, 1}};
    AK_CHECK_EQ(ak_rigid_model_create(&mj, NULL, &m),
                AK_ERR_BAD_INDEX); /* a body joined to itself */
    jd.body_b = 2;
    AK_CHECK_EQ(ak_rigid_model_create(&mj, NULL, &m), AK_ERR_BAD_INDEX);
    jd.body_b = 1;
    jd.limited = true, jd.lower = 1.0f, jd.upper = 0.5f;
    AK_CHECK_EQ(ak_rigid_model_create(&mj, NULL, &m), AK_ERR_BAD_ARG);
    jd.lower = 0.0f, jd.compliance = -1.0f;
    AK_CHECK_EQ(ak_rigid_model_create(&mj, NULL, &m), AK_ERR_BAD_ARG);
    jd.compliance = 0.0f, jd.type = AK_RIGID_JOINT_TYPE_COUNT;
    AK_CHECK_EQ(ak_rigid_model_create(&mj, NULL, &m), AK_ERR_BAD_ARG);
    jd.type = AK_RIGID_JOINT_HINGE, jd.anchor.x = INFINITY;
    AK_CHECK_EQ(ak_rigid_model_create(&mj, NULL, &m), AK_ERR_BAD_DATA);
    jd.anchor.x = 0.0f;
    AK_CHECK_EQ(ak_rigid_model_create(&mj, NULL, &m), AK_OK);
    AK_CHECK_EQ(ak_rigid_joint_count(m), 1);
    ak_rigid_model_destroy(m);
    m = NULL;
    AK_CHECK_EQ(ak_rigid_model_create(&md, NULL, &m), AK_OK);
    ak_rigid_step_job job = {0};
    AK_CHECK_EQ(ak_rigid_step_validate(&job), AK_ERR_NULL_ARG);
    job.model = m;
    AK_CHECK_EQ(ak_rigid_step_validate(&job), AK_ERR_BAD_ARG); /* dt 0 */
    job.dt = 0.01f;
    AK_CHECK_EQ(ak_rigid_step_validate(&job), AK_ERR_NULL_ARG);
    ak_vec3 x = {0, 0, 0}, v = {NAN, 0, 0}, w = {0, 0, 0};
    ak_quat q = {0, 0, 0, 1};
    unsigned char scratch[8];
    job.positions = (ak_vec3_span){&x, 1};
    job.orientations = (ak_quat_span){&q, 1};
    job.velocities = (ak_vec3_span){&v, 1};
    job.angular_velocities = (ak_vec3_span){&w, 1};
    job.scratch = (ak_u8_span){scratch, sizeof scratch};
    AK_CHECK_EQ(ak_rigid_step_validate(&job), AK_ERR_SPAN_SMALL);
    size_t size = ak_rigid_step_scratch_size(&job);
    job.scratch = (ak_u8_span){malloc(size), size};
    AK_CHECK_EQ(ak_rigid_step_validate(&job), AK_ERR_BAD_DATA);
    v.x = 0.0f;
    AK_CHECK_EQ(ak_rigid_step_run(&job), AK_OK);
    free(job.scratch.ptr);
    ak_rigid_model_destroy(m);
}

/* Free fall and a thrown body: x(t) = x0 + v0 t + g t^2 / 2, up to semi-implicit Euler's
 * error of g h t / 2 in position (16 mm after 2 s with h = 1/600 s); velocities exact. */
AK_TEST(free_fall_and_parabola) {
    ak_rigid_body_desc b[2] = {
        {.shape = {.type = AK_RIGID_BOX, .half_extents = {0.1f, 0.2f, 0.3f}},
         .position = {0, 100, 0}},
        {.shape = {.type = AK_RIGID_SPHERE, .radius = 0.1f},
         .position = {0, 50, 0},
         .velocity = {3, 8, -1}},
    };
    world wd;
    AK_CHECK(world_init(&wd, b, 2, NULL, 1.0f / 60.0f, 10, G));
    for (int f = 0; f < 120; ++f) AK_CHECK_EQ(ak_rigid_step_run(&wd.job), AK_OK);
    float t = 2.0f;
    const float euler = 9.81f * (1.0f / 600.0f) * t / 2.0f;
    AK_CHECK_NEAR(wd.x[0].y, 100.0f - 0.5f * 9.81f * t * t - euler, 1e-3);
    AK_CHECK_NEAR(wd.v[0].y, -9.81f * t, 1e-3);
    AK_CHECK_NEAR(wd.x[1].x, 3.0f * t, 1e-4);
    AK_CHECK_NEAR(wd.x[1].y, 50.0f + 8.0f * t - 0.5f * 9.81f * t * t - euler, 1e-3);
    AK_CHECK_NEAR(wd.x[1].z, -t, 1e-4);
    AK_CHECK_NEAR(ak_quat_angle_between(wd.q[0], ak_quat_identity()), 0.0f, 1e-5);
    world_free(&wd);
}

/* A box on a plane inclined by theta: stays when tan(theta) < mu, else slides with
 * a = g (sin theta - mu cos theta). */
static float incline_accel(float theta, float mu, float* out_drift) {
    ak_vec3 nrm = {-sinf(theta), cosf(theta), 0.0f};
    ak_quat rot = ak_quat_from_axis_angle(ak_vec3_make(0, 0, 1), theta);
    ak_vec3 start = ak_vec3_scale(nrm, 0.1f);
    ak_rigid_body_desc b[2] = {
        {.shape = {.type = AK_RIGID_PLANE, .normal = nrm}},
        {.shape = {.type = AK_RIGID_BOX, .half_extents = {0.2f, 0.1f, 0.2f}},
         .position = start,
         .orientation = rot,
         .friction = mu},
    };
    b[0].friction = mu;
    world wd;
    if (!world_init(&wd, b, 2, NULL, 1.0f / 60.0f, 20, G)) return NAN;
    /* settle 0.25 s, then measure the distance along the slope over 1 s */
    ak_vec3 down = {-cosf(theta), -sinf(theta), 0.0f};
    for (int f = 0; f < 15; ++f) ak_rigid_step_run(&wd.job);
    float s0 = ak_vec3_dot(wd.x[1], down), v0 = ak_vec3_dot(wd.v[1], down);
    for (int f = 0; f < 60; ++f) ak_rigid_step_run(&wd.job);
    float s1 = ak_vec3_dot(wd.x[1], down);
    *out_drift = s1 - s0;
    world_free(&wd);
    /* s1 - s0 = v0 T + a T^2 / 2 with T = 1 */
    return 2.0f * (s1 - s0 - v0);
}

AK_TEST(incline_stays_or_slides) {
    float drift;
    /* tan(20 deg) = 0.364 < 0.5: stays */
    incline_accel(ak_radians(20.0f), 0.5f, &drift);
    AK_CHECK_MSG(fabsf(drift) < 1e-3f, "drift %g m", drift);
    /* tan(35 deg) = 0.700 > 0.3: slides */
    float th = ak_radians(35.0f), mu = 0.3f;
    float a = incline_accel(th, mu, &drift);
    float want = 9.81f * (sinf(th) - mu * cosf(th));
    AK_CHECK_MSG(fabsf(a - want) < 0.01f * want, "a %g want %g", a, want);
    /* frictionless slope: g sin theta */
    th = ak_radians(25.0f);
    a = incline_accel(th, AK_RIGID_FRICTIONLESS, &drift);
    want = 9.81f * sinf(th);
    AK_CHECK_MSG(fabsf(a - want) < 0.01f * want, "a %g want %g", a, want);
}

/* Torque-free box (5 rad/s, h = 1/1200 s): world angular momentum conserved; spin about the
 * intermediate axis flips, spins about the major and minor axes stay. Box half extents 0.5, 0.3,
 * 0.1: I_z < I_y < I_x? I_x ~ (0.09 + 0.01), I_y ~ (0.25 + 0.01), I_z ~ (0.25 + 0.09): minor x,
 * intermediate y, major z. */
static void spin(int axis, float* out_l_err, float* out_min_comp, float* out_max_comp) {
    ak_vec3 w = {0.01f, 0.01f, 0.01f};
    if (axis == 0)
        w.x = 5.0f;
    else if (axis == 1)
        w.y = 5.0f;
    else
        w.z = 5.0f;
    ak_rigid_body_desc b = {.shape = {.type = AK_RIGID_BOX, .half_extents = {0.5f, 0.3f, 0.1f}},
                            .angular_velocity = w};
    world wd;
    world_init(&wd, &b, 1, NULL, 1.0f / 60.0f, 20, ak_vec3_zero());
    ak_vec3 l0 = ak_rigid_angular_momentum(wd.model, 0, wd.q[0], wd.w[0]);
    float worst = 0.0f, lo = 1.0f, hi = -1.0f;
    for (int f = 0; f < 600; ++f) {
        ak_rigid_step_run(&wd.job);
        ak_vec3 l = ak_rigid_angular_momentum(wd.model, 0, wd.q[0], wd.w[0]);
        worst = ak_maxf(worst, ak_vec3_length(ak_vec3_sub(l, l0)) / ak_vec3_length(l0));
        /* the spin axis's direction in the body: component along the starting axis */
        ak_vec3 wl = ak_vec3_normalize(ak_quat_rotate(ak_quat_conjugate(wd.q[0]), wd.w[0]));
        float c = axis == 0 ? wl.x : (axis == 1 ? wl.y : wl.z);
        lo = ak_minf(lo, c);
        hi = ak_maxf(hi, c);
    }
    *out_l_err = worst;
    *out_min_comp = lo;
    *out_max_comp = hi;
    world_free(&wd);
}

AK_TEST(torque_free_spin) {
    float err, lo, hi;
    spin(1, &err, &lo, &hi);
    AK_CHECK_MSG(err < 0.01f, "intermediate: |dL|/|L| %g", err);
    AK_CHECK_MSG(lo < -0.9f, "intermediate axis did not flip: min component %g", lo);
    spin(0, &err, &lo, &hi);
    AK_CHECK_MSG(err < 0.01f, "minor: |dL|/|L| %g", err);
    AK_CHECK_MSG(lo > 0.99f, "minor axis wandered: min component %g", lo);
    spin(2, &err, &lo, &hi);
    AK_CHECK_MSG(err < 0.01f, "major: |dL|/|L| %g", err);
    AK_CHECK_MSG(lo > 0.99f, "major axis wandered: min component %g", lo);
}

/* A sphere dropped from h on a plane with restitution e rebounds to e^2 h. */
AK_TEST(restitution_rebound) {
    const float h = 1.0f, e = 0.6f, r = 0.1f;
    ak_rigid_body_desc b[2] = {
        {.shape = {.type = AK_RIGID_PLANE}},
        {.shape = {.type = AK_RIGID_SPHERE, .radius = r},
         .position = {0, h + r, 0},
         .restitution = e},
    };
    world wd;
    AK_CHECK(world_init(&wd, b, 2, NULL, 1.0f / 60.0f, 20, G));
    float peak = 0.0f;
    bool bounced = false;
    for (int f = 0; f < 120; ++f) {
        ak_rigid_step_run(&wd.job);
        if (wd.v[1].y > 0.0f) bounced = true;
        if (bounced) peak = ak_maxf(peak, wd.x[1].y - r);
        if (bounced && wd.v[1].y < 0.0f) break;
    }
    AK_CHECK(bounced);
    AK_CHECK_MSG(fabsf(peak - e * e * h) < 0.02f * e * e * h, "peak %g want %g", peak, e * e * h);
    world_free(&wd);
}

/* Contacts are found once per step with margins for the step's motion: a box thrown at 15 m/s
 * (0.25 m a step, 25 times the contact offset) onto a resting box, and another onto the ground,
 * must be caught in the step they arrive, not after they have sunk in. */
AK_TEST(fast_boxes_are_caught) {
    ak_rigid_body_desc b[4] = {
        {.shape = {.type = AK_RIGID_PLANE}},
        {.shape = {.type = AK_RIGID_BOX, .half_extents = {0.5f, 0.5f, 0.5f}},
         .position = {0, 0.5f, 0}},
        {.shape = {.type = AK_RIGID_BOX, .half_extents = {0.5f, 0.5f, 0.5f}},
         .position = {0, 2.6f, 0},
         .velocity = {0, -15.0f, 0}},
        {.shape = {.type = AK_RIGID_BOX, .half_extents = {0.5f, 0.5f, 0.5f}},
         .position = {5.0f, 1.6f, 0},
         .velocity = {0, -15.0f, 0}},
    };
    world wd;
    AK_CHECK(world_init(&wd, b, 4, NULL, 1.0f / 60.0f, 10, G));
    float pen = 0.0f, pen_max = 0.0f, low_b = INFINITY, low_c = INFINITY;
    wd.job.out_max_penetration = &pen;
    for (int f = 0; f < 30; ++f) {
        AK_CHECK(ak_rigid_step_run(&wd.job) == AK_OK);
        pen_max = ak_maxf(pen_max, pen);
        low_b = ak_minf(low_b, wd.x[2].y - wd.x[1].y);
        low_c = ak_minf(low_c, wd.x[3].y);
    }
    AK_CHECK_MSG(pen_max < 0.01f, "penetration %g m (contact offset 0.01)", pen_max);
    AK_CHECK_MSG(low_b > 0.98f, "the thrown box came within %g m of the resting one's centre", low_b);
    AK_CHECK_MSG(low_c > 0.48f, "the box thrown at the ground sank to %g m", low_c);
    AK_CHECK_MSG(fabsf(wd.x[2].y - 1.5f) < 0.01f && fabsf(wd.x[3].y - 0.5f) < 0.01f,
                 "resting at %g and %g m", wd.x[2].y, wd.x[3].y);
    world_free(&wd);
}

/* The pairs are found once per step on the step's start velocities: a body at rest that an
 * impact launches within a step must still meet the body ahead of it in that step. A Newton's
 * cradle without gravity: sphere A at 12 m/s (0.2 m a step) hits B at rest 5 cm away, and B,
 * elastic, must pass its speed on to C 3 cm beyond it (three times the contact offset, so B and
 * C at rest are no pair at the step's start) in the same step: B may not sink into C deeper
 * than the contact offset at any step (measured from the centres, not from the contacts the
 * solver saw), and C leaves with A's momentum. */
AK_TEST(body_launched_mid_step_meets_the_next) {
    const float r = 0.1f, v0 = 12.0f;
    ak_rigid_body_desc b[3] = {
        {.shape = {.type = AK_RIGID_SPHERE, .radius = r},
         .position = {-2.0f * r - 0.05f, 0, 0},
         .velocity = {v0, 0, 0},
         .restitution = 1.0f},
        {.shape = {.type = AK_RIGID_SPHERE, .radius = r}, .restitution = 1.0f},
        {.shape = {.type = AK_RIGID_SPHERE, .radius = r},
         .position = {2.0f * r + 0.03f, 0, 0},
         .restitution = 1.0f},
    };
    world wd;
    AK_CHECK(world_init(&wd, b, 3, NULL, 1.0f / 60.0f, 10, ak_vec3_make(0, 0, 0)));
    float sink = 0.0f;
    for (int f = 0; f < 20; ++f) {
        AK_CHECK(ak_rigid_step_run(&wd.job) == AK_OK);
        sink = ak_maxf(sink, 2.0f * r - ak_vec3_distance(wd.x[0], wd.x[1]));
        sink = ak_maxf(sink, 2.0f * r - ak_vec3_distance(wd.x[1], wd.x[2]));
    }
    AK_CHECK_MSG(sink < 0.01f, "a sphere sank %g m into the next (contact offset 0.01)", sink);
    AK_CHECK_MSG(wd.x[0].x < wd.x[1].x && wd.x[1].x < wd.x[2].x, "order lost: %g %g %g", wd.x[0].x,
                 wd.x[1].x, wd.x[2].x);
    float p = wd.v[0].x + wd.v[1].x + wd.v[2].x;
    AK_CHECK_MSG(fabsf(p - v0) < 0.01f * v0, "momentum %g want %g (per unit mass)", p, v0);
    AK_CHECK_MSG(wd.v[2].x > 0.9f * v0, "C leaves at %g m/s, A came at %g", wd.v[2].x, v0);
    world_free(&wd);
}

/* A column of boxes on the ground, stepped for `seconds`: the largest horizontal drift of any
 * box and the deepest penetration seen. */
static void stack_run(int count, float seconds, uint32_t substeps, bool sleep, float* out_drift,
                      float* out_pen, bool* out_ok) {
    ak_rigid_body_desc b[64];
    memset(b, 0, sizeof b);
    b[0].shape.type = AK_RIGID_PLANE;
    for (int i = 1; i <= count; ++i) {
        b[i].shape.type = AK_RIGID_BOX;
        b[i].shape.half_extents = ak_vec3_make(0.5f, 0.5f, 0.5f);
        b[i].position = ak_vec3_make(0.0f, 0.5f + 1.0f * (float)(i - 1), 0.0f);
    }
    world wd;
    *out_ok = world_init(&wd, b, (size_t)count + 1, NULL, 1.0f / 60.0f, substeps, G);
    if (sleep) wd.job.sleep_timers = (ak_f32_span){wd.sleep, (size_t)count + 1};
    float pen_max = 0.0f, drift = 0.0f, pen;
    wd.job.out_max_penetration = &pen;
    int frames = (int)(seconds * 60.0f);
    for (int f = 0; f < frames; ++f) {
        if (ak_rigid_step_run(&wd.job) != AK_OK) *out_ok = false;
        pen_max = ak_maxf(pen_max, pen);
    }
    for (int i = 1; i <= count; ++i) {
        float dx = wd.x[i].x, dz = wd.x[i].z;
        drift = ak_maxf(drift, sqrtf(dx * dx + dz * dz));
        drift = ak_maxf(drift, fabsf(wd.x[i].y - (0.5f + (float)(i - 1))));
    }
    *out_drift = drift;
    *out_pen = pen_max;
    world_free(&wd);
}

AK_TEST(box_stack_stands) {
    float drift, pen;
    bool ok;
    /* with sleeping, as a scene would run: the stack falls asleep once it has settled */
    stack_run(10, 3.0f, 40, true, &drift, &pen, &ok);
    AK_CHECK(ok);
    AK_CHECK_MSG(drift < 1e-3f, "drift %g m", drift);
    AK_CHECK_MSG(pen < 0.01f, "penetration %g m (contact offset 0.01)", pen);
}

AK_TEST(box_stack_stands_20s) {
    float drift, pen;
    bool ok;
    /* awake for all 20 s: the solver alone holds it (40 substeps) */
    stack_run(10, 20.0f, 40, false, &drift, &pen, &ok);
    AK_CHECK(ok);
    AK_CHECK_MSG(drift < 1e-3f, "drift %g m", drift);
    AK_CHECK_MSG(pen < 0.01f, "penetration %g m (contact offset 0.01)", pen);
}

/* A 2D pyramid of unit boxes (layer k holds layers - k boxes, 0.1 m apart): the largest
 * horizontal displacement of any box from where it started and the deepest penetration. */
static void pyramid_run(int layers, float seconds, uint32_t substeps, bool sleep, bool anchors,
                        float* out_drift, float* out_pen, bool* out_ok) {
    size_t n = 1 + (size_t)layers * (size_t)(layers + 1) / 2;
    ak_rigid_body_desc* b = calloc(n, sizeof *b);
    ak_vec3 *x = calloc(n, sizeof *x), *v = calloc(n, sizeof *v), *w = calloc(n, sizeof *w);
    ak_quat* q = calloc(n, sizeof *q);
    float* timers = calloc(n, sizeof *timers);
    ak_rigid_contact_anchor* an = calloc(4 * n, sizeof *an);
    uint32_t an_count = 0;
    *out_ok = b && x && v && w && q && timers && an;
    if (!*out_ok) goto done;
    b[0].shape.type = AK_RIGID_PLANE;
    size_t k = 1;
    for (int layer = 0; layer < layers; ++layer)
        for (int i = 0; i < layers - layer; ++i, ++k) {
            b[k].shape.type = AK_RIGID_BOX;
            b[k].shape.half_extents = ak_vec3_make(0.5f, 0.5f, 0.5f);
            b[k].position = ak_vec3_make(1.1f * ((float)i - 0.5f * (float)(layers - layer - 1)),
                                         0.5f + (float)layer, 0.0f);
        }
    ak_rigid_model* m = NULL;
    ak_rigid_model_desc md = {.bodies = {b, n}};
    *out_ok = ak_rigid_model_create(&md, NULL, &m) == AK_OK;
    if (!*out_ok) goto done;
    ak_rigid_initial_state(m, (ak_vec3_span){x, n}, (ak_quat_span){q, n}, (ak_vec3_span){v, n},
                           (ak_vec3_span){w, n});
    float pen = 0.0f, pen_max = 0.0f, drift = 0.0f;
    ak_rigid_step_job job = {.model = m,
                             .dt = 1.0f / 60.0f,
                             .substeps = substeps,
                             .gravity = G,
                             .positions = {x, n},
                             .orientations = {q, n},
                             .velocities = {v, n},
                             .angular_velocities = {w, n},
                             .out_max_penetration = &pen};
    if (sleep) job.sleep_timers = (ak_f32_span){timers, n};
    if (anchors) {
        job.contact_anchors = (ak_rigid_contact_anchor_span){an, 4 * n};
        job.contact_anchor_count = &an_count;
    }
    size_t size = ak_rigid_step_scratch_size(&job);
    job.scratch = (ak_u8_span){malloc(size), size};
    int frames = (int)(seconds * 60.0f);
    for (int f = 0; f < frames && *out_ok; ++f) {
        *out_ok = ak_rigid_step_run(&job) == AK_OK;
        pen_max = ak_maxf(pen_max, pen);
    }
    /* horizontal: the column's vertical give is the contacts' penetration, checked apart */
    for (size_t i = 1; i < n; ++i) {
        float dx = x[i].x - b[i].position.x, dz = x[i].z - b[i].position.z;
        drift = ak_maxf(drift, sqrtf(dx * dx + dz * dz));
    }
    *out_drift = drift;
    *out_pen = pen_max;
    free(job.scratch.ptr);
    ak_rigid_model_destroy(m);
done:
    free(b), free(x), free(v), free(w), free(q), free(timers), free(an);
}

AK_TEST(pyramid_stands) {
    float drift, pen;
    bool ok;
    pyramid_run(6, 2.0f, 40, true, false, &drift, &pen, &ok);
    AK_CHECK(ok);
    AK_CHECK_MSG(drift < 1e-3f, "drift %g m", drift);
    AK_CHECK_MSG(pen < 0.01f, "penetration %g m (contact offset 0.01)", pen);
}

/* Static friction on a face pressed on a face must not turn the solver's small tilts into
 * sideways steps: a 10-layer pyramid awake for 5 s at only 10 substeps stays within 6 mm of where
 * it started (it measured 2.5 mm; reading the tilt as slip walked it 31 mm). */
AK_TEST(pyramid_does_not_walk_at_10_substeps) {
    float drift, pen;
    bool ok;
    pyramid_run(10, 5.0f, 10, false, false, &drift, &pen, &ok);
    AK_CHECK(ok);
    AK_CHECK_MSG(drift < 6e-3f, "drift %g m", drift);
    AK_CHECK_MSG(pen < 0.01f, "penetration %g m (contact offset 0.01)", pen);
}

/* A tall box (half extents 0.1, 0.5, 0.3) sent sliding along x at 3 m/s on a floor: friction
 * mu g at the base against gravity's moment about the front edge tips it when mu > 0.1 / 0.5 =
 * 0.2 (mu 0.5: it falls on its face, 90 degrees), and it slides upright below (mu 0.15). */
static float slide_tilt(float mu) {
    ak_rigid_body_desc b[2] = {
        {.shape = {.type = AK_RIGID_PLANE, .normal = {0, 1, 0}}, .friction = mu},
        {.shape = {.type = AK_RIGID_BOX, .half_extents = {0.1f, 0.5f, 0.3f}},
         .position = {0, 0.5f, 0},
         .friction = mu},
    };
    world wd;
    if (!world_init(&wd, b, 2, NULL, 1.0f / 60.0f, 10, G)) return NAN;
    wd.v[1] = ak_vec3_make(3.0f, 0, 0);
    float tilt = 0.0f;
    for (int f = 0; f < 120; ++f) {
        ak_rigid_step_run(&wd.job);
        ak_vec3 up = ak_quat_rotate(wd.q[1], ak_vec3_make(0, 1, 0));
        tilt = ak_maxf(tilt, acosf(ak_clampf(up.y, -1.0f, 1.0f)));
    }
    world_free(&wd);
    return tilt;
}

AK_TEST(sliding_tall_box_tips_when_mu_exceeds_its_aspect) {
    float t = slide_tilt(0.5f);
    AK_CHECK_MSG(t > ak_radians(80.0f), "mu 0.5: tilt %g deg, should tip", t * 57.29578f);
    t = slide_tilt(0.15f);
    AK_CHECK_MSG(t < ak_radians(5.0f), "mu 0.15: tilt %g deg, should slide upright", t * 57.29578f);
}

/* Coulomb: boxes on a slope of 20 degrees with mu = 0.6 > tan 20 = 0.364 never move, and three
 * flat boxes (0.4 x 0.2 x 0.4 m) stacked on it neither. At 4 substeps each step leaves a little
 * slip between the two moving boxes that their static friction has not undone (the solve's
 * later pairs move a box after its friction ran); without the contact anchors it added up, the
 * top box creeping 191 mm down the slope in 10 s (1.5 m at 2 substeps; the lowest box alone on
 * the slope stays: a static body's pair is not a patch). The anchors carry it into the next step. */
static float incline_stack_creep(bool anchors, uint32_t substeps, float seconds) {
    float theta = ak_radians(20.0f), mu = 0.6f;
    ak_vec3 nrm = {-sinf(theta), cosf(theta), 0.0f};
    ak_rigid_body_desc b[4] = {{.shape = {.type = AK_RIGID_PLANE, .normal = nrm}, .friction = mu}};
    for (int i = 1; i <= 3; ++i)
        b[i] = (ak_rigid_body_desc){
            .shape = {.type = AK_RIGID_BOX, .half_extents = {0.2f, 0.1f, 0.2f}},
            .position = ak_vec3_scale(nrm, 0.1f + 0.2f * (float)(i - 1)),
            .orientation = ak_quat_from_axis_angle(ak_vec3_make(0, 0, 1), theta),
            .friction = mu};
    world wd;
    if (!world_init(&wd, b, 4, NULL, 1.0f / 60.0f, substeps, G)) return NAN;
    if (anchors) world_keep_anchors(&wd);
    ak_vec3 down = {-cosf(theta), -sinf(theta), 0.0f};
    for (int f = 0; f < 15; ++f) ak_rigid_step_run(&wd.job); /* settle 0.25 s */
    float s0 = ak_vec3_dot(wd.x[3], down);
    for (int f = 0; f < (int)(seconds * 60.0f); ++f) ak_rigid_step_run(&wd.job);
    float creep = ak_vec3_dot(wd.x[3], down) - s0;
    world_free(&wd);
    return creep;
}

AK_TEST(incline_stack_does_not_creep_at_4_substeps) {
    float creep = incline_stack_creep(true, 4, 10.0f);
    printf("  3 boxes stacked on 20 deg, mu 0.6, 4 substeps, 10 s: the top crept %.3g mm (without "
           "anchors %.3g mm)\n", 1e3f * creep, 1e3f * incline_stack_creep(false, 4, 10.0f));
    AK_CHECK_MSG(fabsf(creep) < 1e-3f, "the top box crept %g m down the slope", creep);
}

/* A 10-box stack, awake for 10 s at 4 substeps: the top box stays where it was put (the
 * stack's horizontal creep, 1.4 mm/s without the anchors, does not add up). */
static float stack_top_drift(bool anchors, uint32_t substeps, float seconds) {
    ak_rigid_body_desc b[11];
    memset(b, 0, sizeof b);
    b[0].shape.type = AK_RIGID_PLANE;
    for (int i = 1; i <= 10; ++i) {
        b[i].shape.type = AK_RIGID_BOX;
        b[i].shape.half_extents = ak_vec3_make(0.5f, 0.5f, 0.5f);
        b[i].position = ak_vec3_make(0.0f, 0.5f + (float)(i - 1), 0.0f);
    }
    world wd;
    if (!world_init(&wd, b, 11, NULL, 1.0f / 60.0f, substeps, G)) return NAN;
    if (anchors) world_keep_anchors(&wd);
    for (int f = 0; f < (int)(seconds * 60.0f); ++f) ak_rigid_step_run(&wd.job);
    float drift = sqrtf(wd.x[10].x * wd.x[10].x + wd.x[10].z * wd.x[10].z);
    world_free(&wd);
    return drift;
}

AK_TEST(stack_top_does_not_creep_at_4_substeps) {
    float drift = stack_top_drift(true, 4, 10.0f);
    printf("  10-box stack, 4 substeps, awake 10 s: top box drifted %.3g mm (without anchors %.3g "
           "mm)\n", 1e3f * drift, 1e3f * stack_top_drift(false, 4, 10.0f));
    AK_CHECK_MSG(drift < 2e-3f, "top box drifted %g m", drift);
}

/* The 20-layer pyramid (210 boxes) awake for 5 s at only 4 substeps, with contact anchors: Bullet
 * at its defaults drifts 55 mm here (bench_rigid_vs_bullet --sweep); main before the two-point
 * patch rule drifted 66 mm. */
AK_TEST(pyramid_does_not_walk_at_4_substeps) {
    float drift, pen;
    bool ok;
    pyramid_run(20, 5.0f, 4, false, true, &drift, &pen, &ok);
    AK_CHECK(ok);
    printf("  20-layer pyramid, awake 5 s, 4 substeps, anchors: drift %.3g mm, penetration %.3g mm\n",
           1e3f * drift, 1e3f * pen);
    AK_CHECK_MSG(drift < 0.02f, "drift %g m", drift);
}

/* The anchors are written in the step's pair order and sorted by key, whatever thread solved
 * an island: three stacks and a small pyramid (four islands), 1 s at 4 substeps with anchors,
 * give the same bits with 1, 2 and 3 threads (state and anchors). */
static bool anchors_run(uint32_t threads, world* wd) {
    ak_rigid_body_desc b[19] = {{.shape = {.type = AK_RIGID_PLANE}}};
    size_t k = 1;
    for (int s = 0; s < 3; ++s)
        for (int i = 0; i < 4; ++i, ++k)
            b[k] = (ak_rigid_body_desc){
                .shape = {.type = AK_RIGID_BOX, .half_extents = {0.5f, 0.5f, 0.5f}},
                .position = {3.0f * (float)(s - 1) + 0.01f * (float)i, 0.5f + (float)i, 0.0f}};
    for (int layer = 0; layer < 3; ++layer)
        for (int i = 0; i < 3 - layer; ++i, ++k)
            b[k] = (ak_rigid_body_desc){
                .shape = {.type = AK_RIGID_BOX, .half_extents = {0.5f, 0.5f, 0.5f}},
                .position = {1.1f * ((float)i - 0.5f * (float)(2 - layer)), 0.5f + (float)layer,
                             5.0f}};
    /* (sleep_time 2 s: the piles, set down at rest, would otherwise sleep within the second and
     * keep no anchors) */
    ak_rigid_model_desc md = {.sleep_time = 2.0f};
    if (!world_init(wd, b, k, &md, 1.0f / 60.0f, 4, G)) return false;
    world_keep_anchors(wd);
    wd->job.thread_count = threads;
    wd->job.sleep_timers = (ak_f32_span){wd->sleep, k};
    bool ok = true;
    for (int f = 0; f < 60 && ok; ++f) ok = ak_rigid_step_run(&wd->job) == AK_OK;
    return ok;
}

AK_TEST(contact_anchors_bit_identical_for_any_thread_count) {
    static world one, other;
    AK_CHECK(anchors_run(1, &one));
    AK_CHECK_MSG(one.anchor_count >= 12, "%u anchors kept", one.anchor_count);
    for (uint32_t t = 2; t <= 3; ++t) {
        AK_CHECK(anchors_run(t, &other));
        size_t n = one.n;
        AK_CHECK(memcmp(one.x, other.x, n * sizeof one.x[0]) == 0);
        AK_CHECK(memcmp(one.q, other.q, n * sizeof one.q[0]) == 0);
        AK_CHECK(memcmp(one.v, other.v, n * sizeof one.v[0]) == 0);
        AK_CHECK(memcmp(one.w, other.w, n * sizeof one.w[0]) == 0);
        AK_CHECK_EQ(one.anchor_count, other.anchor_count);
        AK_CHECK(memcmp(one.anchors, other.anchors, one.anchor_count * sizeof one.anchors[0]) == 0);
        world_free(&other);
    }
    world_free(&one);
}

/* A box resting on the ground and a 5-box stack beside it (two groups), 4 substeps, the default
 * sleep thresholds (0.05 m/s, 0.05 rad/s, 0.5 s) and contact anchors. Awake, after 1.5 s of
 * settling, every body's speed stays under g h / 10 (4.1 mm/s: a tenth of what one substep of
 * gravity adds, h = 1/240 s) and its angular speed under that over its half extent; with sleep
 * timers both groups are asleep within 2 s (velocities exactly zero, timers at sleep_time) and
 * stay where they were set down (horizontally, 1 mm). Before the sleep fix (rigid28i) a body slow for 0.5 s
 * whose group was not was frozen alone for a step, then woken: the stack never slept. */
static bool resting_run(bool sleeping, float seconds, float* vmax, float* wmax, float* drift,
                        float* asleep_at) {
    static world wd;
    ak_rigid_body_desc b[7] = {{.shape = {.type = AK_RIGID_PLANE}}};
    b[1] = (ak_rigid_body_desc){.shape = {.type = AK_RIGID_BOX, .half_extents = {0.5f, 0.5f, 0.5f}},
                                .position = {-3.0f, 0.5f, 0.0f}};
    for (int i = 0; i < 5; ++i)
        b[2 + i] = (ak_rigid_body_desc){
            .shape = {.type = AK_RIGID_BOX, .half_extents = {0.5f, 0.5f, 0.5f}},
            .position = {0.0f, 0.5f + (float)i, 0.0f}};
    size_t n = 7;
    if (!world_init(&wd, b, n, NULL, 1.0f / 60.0f, 4, G)) return false;
    world_keep_anchors(&wd);
    if (sleeping) wd.job.sleep_timers = (ak_f32_span){wd.sleep, n};
    *vmax = *wmax = *drift = 0.0f;
    *asleep_at = -1.0f;
    bool ok = true;
    int steps = (int)(seconds * 60.0f + 0.5f);
    for (int f = 1; f <= steps && ok; ++f) {
        ok = ak_rigid_step_run(&wd.job) == AK_OK;
        bool all = true;
        for (size_t i = 1; i < n; ++i) {
            float v = ak_vec3_length(wd.v[i]), w = ak_vec3_length(wd.w[i]);
            if (f > 90) *vmax = ak_maxf(*vmax, v), *wmax = ak_maxf(*wmax, w);
            all = all && v == 0.0f && w == 0.0f && (!sleeping || wd.sleep[i] >= 0.5f);
            *drift = ak_maxf(*drift, hypotf(wd.x[i].x - b[i].position.x,
                                            wd.x[i].z - b[i].position.z));
        }
        if (sleeping && all && *asleep_at < 0.0f) *asleep_at = (float)f / 60.0f;
        if (sleeping && !all) *asleep_at = -1.0f; /* woke again */
    }
    world_free(&wd);
    return ok;
}

/* A 10-layer pyramid (55 boxes 0.1 m apart) set down at rest, 4 substeps, contact anchors: awake,
 * every body's speed from 1.5 to 4 s stays under g h / 4 (10 mm/s; a quarter of what one substep
 * of gravity adds: before rigid28i the pile kept about g h, the velocity of each substep's push,
 * since one velocity pass hands it down a contact at a time) and its angular speed under that
 * over the half extent (the anchors' twist, undone twice, rocked it about the vertical); with
 * the default sleep thresholds it is asleep within 2 s. */
static bool pyramid_rest_run(uint32_t velocity_iterations, bool sleeping, float* vmax, float* wmax,
                             float* asleep_at) {
    static world wd;
    ak_rigid_body_desc b[56] = {{.shape = {.type = AK_RIGID_PLANE}}};
    size_t k = 1;
    for (int l = 0; l < 10; ++l)
        for (int i = 0; i < 10 - l; ++i, ++k)
            b[k] = (ak_rigid_body_desc){
                .shape = {.type = AK_RIGID_BOX, .half_extents = {0.5f, 0.5f, 0.5f}},
                .position = {1.1f * ((float)i - 0.5f * (float)(9 - l)), 0.5f + (float)l, 0.0f}};
    ak_rigid_model_desc md = {.velocity_iterations = velocity_iterations};
    if (!world_init(&wd, b, k, &md, 1.0f / 60.0f, 4, G)) return false;
    world_keep_anchors(&wd);
    if (sleeping) wd.job.sleep_timers = (ak_f32_span){wd.sleep, k};
    *vmax = *wmax = 0.0f;
    *asleep_at = -1.0f;
    bool ok = true;
    for (int f = 1; f <= 240 && ok; ++f) {
        ok = ak_rigid_step_run(&wd.job) == AK_OK;
        bool all = true;
        for (size_t i = 1; i < k; ++i) {
            float v = ak_vec3_length(wd.v[i]), w = ak_vec3_length(wd.w[i]);
            if (f > 90) *vmax = ak_maxf(*vmax, v), *wmax = ak_maxf(*wmax, w);
            all = all && v == 0.0f && w == 0.0f;
        }
        if (sleeping && all && *asleep_at < 0.0f) *asleep_at = (float)f / 60.0f;
        if (sleeping && !all) *asleep_at = -1.0f;
    }
    world_free(&wd);
    return ok;
}

AK_TEST(pyramid_at_rest_stays_still_and_sleeps) {
    float vmax, wmax, asleep, v1, w1, a1;
    AK_CHECK(pyramid_rest_run(0, false, &vmax, &wmax, &asleep));
    AK_CHECK(pyramid_rest_run(1, false, &v1, &w1, &a1));
    float bound = 9.81f / 240.0f / 4.0f;
    printf("  10-layer pyramid, 4 substeps, awake 1.5 to 4 s: speeds up to %.3g m/s, %.3g rad/s "
           "(bound %.3g, %.3g; one velocity pass: %.3g, %.3g)\n", vmax, wmax, bound, bound / 0.5f,
           v1, w1);
    AK_CHECK_MSG(vmax < bound, "speed %g m/s", vmax);
    AK_CHECK_MSG(wmax < bound / 0.5f, "angular speed %g rad/s", wmax);
    AK_CHECK(pyramid_rest_run(0, true, &vmax, &wmax, &asleep));
    printf("  with sleep timers: asleep from %.3g s\n", asleep);
    AK_CHECK_MSG(asleep > 0.0f && asleep <= 2.0f, "asleep at %g s (-1: not asleep at 4 s)", asleep);
}

AK_TEST(resting_box_and_stack_stay_still_and_sleep) {
    float vmax, wmax, drift, asleep;
    AK_CHECK(resting_run(false, 4.0f, &vmax, &wmax, &drift, &asleep));
    float bound = 9.81f / 240.0f / 10.0f;
    printf("  box and 5-box stack, 4 substeps, awake 1.5 to 4 s: speeds up to %.3g m/s, %.3g rad/s "
           "(bound %.3g, %.3g); horizontal drift %.3g mm\n", vmax, wmax, bound, bound / 0.5f, 1e3f * drift);
    AK_CHECK_MSG(vmax < bound, "speed %g m/s", vmax);
    AK_CHECK_MSG(wmax < bound / 0.5f, "angular speed %g rad/s", wmax);
    AK_CHECK(resting_run(true, 4.0f, &vmax, &wmax, &drift, &asleep));
    printf("  with sleep timers: asleep from %.3g s (stayed asleep to 4 s), drift %.3g mm\n",
           asleep, 1e3f * drift);
    AK_CHECK_MSG(asleep > 0.0f && asleep <= 2.0f, "asleep at %g s (-1: not asleep at 4 s)", asleep);
    AK_CHECK_MSG(drift < 1e-3f, "drift %g m", drift);
}

/* Bad anchors are refused before anything is written. */
AK_TEST(contact_anchors_validated) {
    ak_rigid_body_desc b[3] = {{.shape = {.type = AK_RIGID_PLANE}},
                               {.shape = {.type = AK_RIGID_BOX, .half_extents = {0.5f, 0.5f, 0.5f}},
                                .position = {0, 0.5f, 0}},
                               {.shape = {.type = AK_RIGID_BOX, .half_extents = {0.5f, 0.5f, 0.5f}},
                                .position = {0, 1.5f, 0}}};
    world wd;
    AK_CHECK(world_init(&wd, b, 3, NULL, 1.0f / 60.0f, 4, G));
    world_keep_anchors(&wd);
    for (int f = 0; f < 5; ++f) AK_CHECK_EQ(ak_rigid_step_run(&wd.job), AK_OK);
    AK_CHECK_EQ(wd.anchor_count, 2u);
    AK_CHECK(wd.anchors[0].body_a == 0 && wd.anchors[0].body_b == 1);
    AK_CHECK(wd.anchors[1].body_a == 1 && wd.anchors[1].body_b == 2);
    ak_rigid_contact_anchor keep = wd.anchors[0];
    wd.anchors[0].body_a = 2; /* not body_a < body_b */
    AK_CHECK_EQ(ak_rigid_step_validate(&wd.job), AK_ERR_BAD_DATA);
    wd.anchors[0] = keep;
    wd.anchors[0].drift.x = NAN;
    AK_CHECK_EQ(ak_rigid_step_run(&wd.job), AK_ERR_BAD_DATA);
    wd.anchors[0] = wd.anchors[1];
    wd.anchors[1] = keep; /* out of order */
    AK_CHECK_EQ(ak_rigid_step_validate(&wd.job), AK_ERR_BAD_DATA);
    wd.anchor_count = 300; /* over the span */
    AK_CHECK_EQ(ak_rigid_step_validate(&wd.job), AK_ERR_BAD_DATA);
    wd.job.contact_anchor_count = NULL;
    AK_CHECK_EQ(ak_rigid_step_validate(&wd.job), AK_ERR_NULL_ARG);
    world_free(&wd);
}

AK_TEST(pyramid_20_layers_20s) {
    float drift, pen;
    bool ok;
    pyramid_run(20, 20.0f, 40, true, false, &drift, &pen, &ok);
    AK_CHECK(ok);
    AK_CHECK_MSG(drift < 1e-3f, "drift %g m", drift);
    AK_CHECK_MSG(pen < 0.01f, "penetration %g m (contact offset 0.01)", pen);
    printf("  20-layer pyramid, 20 s, 40 substeps, sleeping on: drift %.3g m, penetration %.3g m\n",
           drift, pen);
}

/* A chain of 8 capsules (r 3 cm, 0.4 m long) on ball joints end to end, hung from a static
 * body and released horizontal, 1 s at 10 substeps: the worst anchor gap over every step
 * (ak_rigid_joint_error) for joint_tolerance 0 (default), 1e-4 (the default, given), 1e-3 and
 * 1e-1 (the sweeps after the contacts stop once a sweep corrects no joint by more than it). The
 * default must hold the chain within 1 mm and give the same bits as 1e-4; 1e-3 opens the gaps
 * more than twice as wide (here 0.42 against 0.08 mm: the sweeps stop after the first), 1e-1
 * no less, and the chain still hangs together within 5 cm; a negative or NaN tolerance is
 * refused. */
static float chain_gap(float tolerance, ak_vec3* out_end) {
    enum { LINKS = 8 };
    ak_rigid_body_desc b[LINKS + 1] = {
        {.shape = {.type = AK_RIGID_SPHERE, .radius = 0.01f}, .is_static = true}};
    ak_rigid_joint_desc j[LINKS];
    const ak_quat lying = ak_quat_from_axis_angle(ak_vec3_make(0, 0, 1), 1.5707963f);
    for (int k = 0; k < LINKS; ++k) {
        b[k + 1] = (ak_rigid_body_desc){
            .shape = {.type = AK_RIGID_CAPSULE, .radius = 0.03f, .half_height = 0.17f},
            .position = {0.2f + 0.4f * (float)k, 0, 0},
            .orientation = lying};
        j[k] = (ak_rigid_joint_desc){.type = AK_RIGID_JOINT_BALL,
                                     .body_a = (uint32_t)k,
                                     .body_b = (uint32_t)k + 1,
                                     .anchor = {0.4f * (float)k, 0, 0}};
    }
    ak_rigid_model_desc md = {.joints = {j, LINKS}, .joint_tolerance = tolerance};
    world wd;
    if (!world_init(&wd, b, LINKS + 1, &md, 1.0f / 60.0f, 10, G)) return INFINITY;
    float worst = 0.0f;
    for (int f = 0; f < 60; ++f) {
        if (ak_rigid_step_run(&wd.job) != AK_OK) worst = INFINITY;
        for (size_t k = 0; k < LINKS; ++k) {
            float gap = 0.0f, excess = 0.0f;
            ak_rigid_joint_error(wd.model, k, (ak_vec3_cspan){wd.x, wd.n},
                                 (ak_quat_cspan){wd.q, wd.n}, &gap, &excess);
            worst = ak_maxf(worst, gap);
        }
    }
    *out_end = wd.x[LINKS];
    world_free(&wd);
    return worst;
}

AK_TEST(joint_tolerance_trades_gap_for_sweeps) {
    ak_vec3 e0, e4, e3, e1;
    float g0 = chain_gap(0.0f, &e0), g4 = chain_gap(1e-4f, &e4), g3 = chain_gap(1e-3f, &e3),
          g1 = chain_gap(1e-1f, &e1);
    printf("  8-link chain, worst anchor gap: default %.3g m, 1e-4 %.3g, 1e-3 %.3g, 1e-1 %.3g\n",
           g0, g4, g3, g1);
    AK_CHECK_MSG(g0 < 1e-3f, "default: gap %g m", g0);
    AK_CHECK_MSG(g0 == g4 && memcmp(&e0, &e4, sizeof e0) == 0, "default and 1e-4 differ");
    AK_CHECK_MSG(g3 > 2.0f * g0 && g1 >= g3, "gaps %g %g %g: the tolerance does not act", g0, g3,
                 g1);
    AK_CHECK_MSG(g1 < 0.05f, "1e-1: gap %g m", g1);
    ak_rigid_body_desc b = {.shape = {.type = AK_RIGID_SPHERE, .radius = 0.1f}};
    ak_rigid_model* m = NULL;
    ak_rigid_model_desc md = {.bodies = {&b, 1}, .joint_tolerance = -1e-3f};
    AK_CHECK_EQ(ak_rigid_model_create(&md, NULL, &m), AK_ERR_BAD_ARG);
    md.joint_tolerance = NAN;
    AK_CHECK_EQ(ak_rigid_model_create(&md, NULL, &m), AK_ERR_BAD_DATA);
    AK_CHECK(m == NULL);
}

/* A compound pendulum on a ball joint: a sphere of radius r at distance L below a static
 * anchor, released at 5 degrees, swings with T = 2 pi sqrt(I_pivot / (m g L)), I_pivot =
 * 2/5 m r^2 + m L^2 (small-amplitude closed form; 5 degrees adds 0.05%). */
AK_TEST(pendulum_period_ball_joint) {
    const float L = 1.0f, r = 0.05f, th0 = ak_radians(5.0f);
    ak_rigid_body_desc b[2] = {
        {.shape = {.type = AK_RIGID_SPHERE, .radius = 0.01f}, .is_static = true},
        {.shape = {.type = AK_RIGID_SPHERE, .radius = r},
         .position = {L * sinf(th0), -L * cosf(th0), 0}},
    };
    ak_rigid_joint_desc jd = {.type = AK_RIGID_JOINT_BALL, .body_a = 0, .body_b = 1};
    ak_rigid_model_desc md = {.joints = {&jd, 1}};
    world wd;
    AK_CHECK(world_init(&wd, b, 2, &md, 1.0f / 240.0f, 10, G));
    float prev_x = wd.x[1].x, t = 0.0f, crossings[3];
    int nc = 0;
    float worst_gap = 0.0f;
    for (int f = 0; f < 240 * 5 && nc < 3; ++f) {
        ak_rigid_step_run(&wd.job);
        t += 1.0f / 240.0f;
        float gap, excess;
        ak_rigid_joint_error(wd.model, 0, (ak_vec3_cspan){wd.x, 2}, (ak_quat_cspan){wd.q, 2}, &gap,
                             &excess);
        worst_gap = ak_maxf(worst_gap, gap);
        /* downward zero crossings of x, interpolated */
        if (prev_x > 0.0f && wd.x[1].x <= 0.0f)
            crossings[nc++] = t - (1.0f / 240.0f) * wd.x[1].x / (wd.x[1].x - prev_x);
        prev_x = wd.x[1].x;
    }
    AK_CHECK_EQ(nc, 3);
    double m_i = 0.4 * r * r + L * L; /* I_pivot / m */
    double T = 2.0 * 3.14159265358979 * sqrt(m_i / (9.81 * L));
    if (nc == 3) {
        double got = (double)(crossings[2] - crossings[0]) / 2.0;
        AK_CHECK_MSG(fabs(got - T) < 0.01 * T, "period %g want %g", got, T);
    }
    AK_CHECK_MSG(worst_gap < 1e-4f, "joint gap %g m", worst_gap);
    world_free(&wd);
}

/* A box hinged at one end to a static body, limits [-30, 30] degrees, released horizontal
 * with the hinge's zero at 0: gravity pulls it to the lower limit, where it must stop within
 * 2 degrees; swinging about any other axis is forbidden. */
AK_TEST(hinge_limits_hold) {
    ak_rigid_body_desc b[2] = {
        {.shape = {.type = AK_RIGID_SPHERE, .radius = 0.05f}, .is_static = true},
        {.shape = {.type = AK_RIGID_BOX, .half_extents = {0.5f, 0.05f, 0.1f}},
         .position = {0.5f, 0, 0},
         .angular_velocity = {1.0f, 2.0f, 0.0f}},
    };
    ak_rigid_joint_desc jd = {.type = AK_RIGID_JOINT_HINGE,
                              .body_a = 0,
                              .body_b = 1,
                              .axis = {0, 0, 1},
                              .limited = true,
                              .lower = ak_radians(-30.0f),
                              .upper = ak_radians(30.0f)};
    ak_rigid_model_desc md = {.joints = {&jd, 1}};
    world wd;
    AK_CHECK(world_init(&wd, b, 2, &md, 1.0f / 60.0f, 20, G));
    float worst_excess = 0.0f, worst_gap = 0.0f, worst_tilt = 0.0f;
    for (int f = 0; f < 120; ++f) {
        ak_rigid_step_run(&wd.job);
        float gap, excess;
        ak_rigid_joint_error(wd.model, 0, (ak_vec3_cspan){wd.x, 2}, (ak_quat_cspan){wd.q, 2}, &gap,
                             &excess);
        worst_excess = ak_maxf(worst_excess, excess);
        worst_gap = ak_maxf(worst_gap, gap);
        ak_vec3 z = ak_quat_rotate(wd.q[1], ak_vec3_make(0, 0, 1));
        worst_tilt = ak_maxf(worst_tilt, acosf(ak_clampf(z.z, -1.0f, 1.0f)));
    }
    /* at rest on the limit: the bar points 30 degrees below the horizontal */
    ak_vec3 bar = ak_quat_rotate(wd.q[1], ak_vec3_make(1, 0, 0));
    AK_CHECK_NEAR(atan2f(bar.y, bar.x), ak_radians(-30.0f), ak_radians(2.0f));
    AK_CHECK_MSG(worst_excess < ak_radians(2.0f), "limit exceeded by %g deg",
                 ak_degrees(worst_excess));
    AK_CHECK_MSG(worst_tilt < ak_radians(2.0f), "hinge axis tilted by %g deg",
                 ak_degrees(worst_tilt));
    AK_CHECK_MSG(worst_gap < 1e-3f, "joint gap %g m", worst_gap);
    world_free(&wd);
}

/* A box on a frictionless prismatic joint along x under gravity (3, -9.81, 0): the joint holds
 * it up and it slides at 3 m/s^2 (x = 1.5 t^2 less Euler's 1.5 h t); limits stop it at 1 m. */
AK_TEST(prismatic_slides_along_its_axis) {
    ak_rigid_body_desc b[2] = {
        {.shape = {.type = AK_RIGID_SPHERE, .radius = 0.05f}, .is_static = true},
        {.shape = {.type = AK_RIGID_BOX, .half_extents = {0.1f, 0.1f, 0.1f}}},
    };
    ak_rigid_joint_desc jd = {
        .type = AK_RIGID_JOINT_PRISMATIC, .body_a = 0, .body_b = 1, .axis = {1, 0, 0}};
    ak_rigid_model_desc md = {.joints = {&jd, 1}};
    world wd;
    AK_CHECK(world_init(&wd, b, 2, &md, 1.0f / 60.0f, 10, ak_vec3_make(3.0f, -9.81f, 0.0f)));
    for (int f = 0; f < 30; ++f) ak_rigid_step_run(&wd.job);
    float t = 0.5f;
    AK_CHECK_NEAR(wd.x[1].x, 1.5f * t * t + 1.5f * t / 600.0f, 2e-3);
    AK_CHECK_NEAR(wd.x[1].y, 0.0f, 1e-4);
    AK_CHECK_NEAR(ak_quat_angle_between(wd.q[1], ak_quat_identity()), 0.0f, 1e-3);
    world_free(&wd);
    jd.limited = true, jd.lower = -1.0f, jd.upper = 0.2f;
    AK_CHECK(world_init(&wd, b, 2, &md, 1.0f / 60.0f, 10, ak_vec3_make(3.0f, -9.81f, 0.0f)));
    for (int f = 0; f < 60; ++f) ak_rigid_step_run(&wd.job);
    AK_CHECK_NEAR(wd.x[1].x, 0.2f, 1e-3);
    world_free(&wd);
}

/* Two boxes welded by a fixed joint, thrown spinning: they keep their relative pose, and with
 * no gravity the pair's total angular momentum about its centre of mass is conserved. */
AK_TEST(fixed_joint_keeps_the_pose) {
    ak_rigid_body_desc b[2] = {
        {.shape = {.type = AK_RIGID_BOX, .half_extents = {0.2f, 0.1f, 0.1f}},
         .position = {-0.2f, 0, 0},
         .angular_velocity = {0.3f, 0.2f, 2.0f}},
        {.shape = {.type = AK_RIGID_BOX, .half_extents = {0.2f, 0.1f, 0.1f}},
         .position = {0.2f, 0, 0},
         .angular_velocity = {0.3f, 0.2f, 2.0f}},
    };
    /* the bodies move as one: v = w x r about the common centre */
    b[0].velocity = ak_vec3_cross(b[0].angular_velocity, b[0].position);
    b[1].velocity = ak_vec3_cross(b[1].angular_velocity, b[1].position);
    ak_rigid_joint_desc jd = {
        .type = AK_RIGID_JOINT_FIXED, .body_a = 0, .body_b = 1, .anchor = {0, 0, 0}};
    ak_rigid_model_desc md = {.joints = {&jd, 1}};
    world wd;
    AK_CHECK(world_init(&wd, b, 2, &md, 1.0f / 60.0f, 20, ak_vec3_zero()));
    ak_vec3 l0 = ak_vec3_zero();
    for (int i = 0; i < 2; ++i)
        l0 = ak_vec3_add(
            l0, ak_vec3_add(ak_rigid_angular_momentum(wd.model, (size_t)i, wd.q[i], wd.w[i]),
                            ak_vec3_scale(ak_vec3_cross(wd.x[i], wd.v[i]),
                                          ak_rigid_body_mass(wd.model, (size_t)i))));
    for (int f = 0; f < 120; ++f) ak_rigid_step_run(&wd.job);
    AK_CHECK_NEAR(ak_quat_angle_between(wd.q[0], wd.q[1]), 0.0f, ak_radians(0.5f));
    AK_CHECK_NEAR(ak_vec3_distance(wd.x[0], wd.x[1]), 0.4f, 1e-3);
    ak_vec3 l1 = ak_vec3_zero(), c = ak_vec3_scale(ak_vec3_add(wd.x[0], wd.x[1]), 0.5f);
    ak_vec3 vc = ak_vec3_scale(ak_vec3_add(wd.v[0], wd.v[1]), 0.5f);
    for (int i = 0; i < 2; ++i)
        l1 = ak_vec3_add(
            l1, ak_vec3_add(
                    ak_rigid_angular_momentum(wd.model, (size_t)i, wd.q[i], wd.w[i]),
                    ak_vec3_scale(ak_vec3_cross(ak_vec3_sub(wd.x[i], c), ak_vec3_sub(wd.v[i], vc)),
                                  ak_rigid_body_mass(wd.model, (size_t)i))));
    AK_CHECK_MSG(ak_vec3_length(ak_vec3_sub(l1, l0)) < 0.02f * ak_vec3_length(l0),
                 "L %g %g %g vs %g %g %g", l1.x, l1.y, l1.z, l0.x, l0.y, l0.z);
    world_free(&wd);
}

/* Spheres of radius 0.1 poured as a tall block (8 x 8 per layer, 0.25 m apart, every other
 * layer shifted by 1 cm) into an open 4 x 4 m box: the ground and four walls. The bodies 0..4
 * are the planes. */
typedef struct pour_stats {
    bool ok;            /* every step returned AK_OK and the state stayed finite */
    uint64_t dropped;   /* out_dropped_contacts summed over the run */
    float outside;      /* the furthest a sphere's surface got past a wall or the ground */
    float pen_reported; /* the deepest out_max_penetration of any step */
    float overlap;      /* the deepest overlap of two spheres at the end (all pairs, naive) */
    double ke_peak, ke_end;
} pour_stats;

static pour_stats pour_run(int count, uint32_t max_contacts, int frames) {
    pour_stats st = {0};
    const float r = 0.1f;
    size_t n = 5 + (size_t)count;
    ak_rigid_body_desc* b = calloc(n, sizeof *b);
    ak_vec3 *x = calloc(n, sizeof *x), *v = calloc(n, sizeof *v), *w = calloc(n, sizeof *w);
    ak_quat* q = calloc(n, sizeof *q);
    float* timers = calloc(n, sizeof *timers);
    st.ok = b && x && v && w && q && timers;
    if (!st.ok) goto done;
    const ak_vec3 normals[5] = {{0, 1, 0}, {1, 0, 0}, {-1, 0, 0}, {0, 0, 1}, {0, 0, -1}};
    const ak_vec3 points[5] = {{0, 0, 0}, {-2, 0, 0}, {2, 0, 0}, {0, 0, -2}, {0, 0, 2}};
    for (int k = 0; k < 5; ++k) {
        b[k].shape.type = AK_RIGID_PLANE;
        b[k].shape.normal = normals[k];
        b[k].position = points[k];
    }
    for (int i = 0; i < count; ++i) {
        int ix = i % 8, iz = (i / 8) % 8, iy = i / 64;
        b[5 + i].shape.type = AK_RIGID_SPHERE;
        b[5 + i].shape.radius = r;
        b[5 + i].position = ak_vec3_make(-0.875f + 0.25f * (float)ix + 0.01f * (float)(iy % 2),
                                         0.3f + 0.25f * (float)iy, -0.875f + 0.25f * (float)iz);
    }
    ak_rigid_model* m = NULL;
    ak_rigid_model_desc md = {.bodies = {b, n}, .max_contacts = max_contacts};
    st.ok = ak_rigid_model_create(&md, NULL, &m) == AK_OK;
    if (!st.ok) goto done;
    ak_rigid_initial_state(m, (ak_vec3_span){x, n}, (ak_quat_span){q, n}, (ak_vec3_span){v, n},
                           (ak_vec3_span){w, n});
    float pen = 0.0f;
    uint32_t dropped = 0;
    ak_rigid_step_job job = {.model = m,
                             .dt = 1.0f / 60.0f,
                             .gravity = G,
                             .positions = {x, n},
                             .orientations = {q, n},
                             .velocities = {v, n},
                             .angular_velocities = {w, n},
                             .sleep_timers = {timers, n},
                             .out_max_penetration = &pen,
                             .out_dropped_contacts = &dropped};
    size_t size = ak_rigid_step_scratch_size(&job);
    job.scratch = (ak_u8_span){malloc(size), size};
    st.ok = job.scratch.ptr != NULL;
    double mass = ak_rigid_body_mass(m, 5);
    for (int f = 0; f < frames && st.ok; ++f) {
        st.ok = ak_rigid_step_run(&job) == AK_OK;
        st.dropped += dropped;
        st.pen_reported = ak_maxf(st.pen_reported, pen);
        double ke = 0.0;
        for (size_t i = 5; i < n; ++i) {
            st.ok = st.ok && ak_vec3_is_finite(x[i]) && ak_vec3_is_finite(v[i]);
            ke += 0.5 * mass * (double)ak_vec3_dot(v[i], v[i]);
            /* the surface past each plane: r - (distance of the centre from the plane) */
            for (int k = 0; k < 5; ++k)
                st.outside =
                    ak_maxf(st.outside, r - ak_vec3_dot(ak_vec3_sub(x[i], points[k]), normals[k]));
        }
        if (ke > st.ke_peak) st.ke_peak = ke;
        st.ke_end = ke;
    }
    for (size_t i = 5; i < n && st.ok; ++i)
        for (size_t j = i + 1; j < n; ++j)
            st.overlap = ak_maxf(st.overlap, 2.0f * r - ak_vec3_distance(x[i], x[j]));
    free(job.scratch.ptr);
    ak_rigid_model_destroy(m);
done:
    free(b), free(x), free(v), free(w), free(q), free(timers);
    return st;
}

/* 2,000 spheres poured into the box with the default max_contacts: the step keeps every pair
 * (none dropped), nothing leaves the box, the pile does not interpenetrate and comes to rest.
 * (Before the per-pair relative-motion test, the falling block paired every sphere with all its
 * neighbours within ~0.5 m, the pairs overflowed max_contacts and the pile blew up.) */
AK_TEST(sphere_pour_keeps_every_contact) {
    pour_stats st = pour_run(2000, 0, 150);
    AK_CHECK(st.ok);
    AK_CHECK_MSG(st.dropped == 0, "%llu contacts dropped", (unsigned long long)st.dropped);
    AK_CHECK_MSG(st.outside < 0.01f, "a sphere %g m past a wall or the ground", st.outside);
    AK_CHECK_MSG(st.pen_reported < 0.01f, "penetration %g m", st.pen_reported);
    AK_CHECK_MSG(st.overlap < 0.02f, "two spheres overlap by %g m", st.overlap);
    AK_CHECK_MSG(st.ke_end < 0.02 * st.ke_peak, "kinetic energy %g J at the end, peak %g J",
                 st.ke_end, st.ke_peak);
}

/* The same pour with max_contacts forced far too small: the step drops pairs and says so, but
 * the pairs with the walls and the ground are kept first, so nothing leaves the box and
 * nothing goes non-finite. */
AK_TEST(sphere_pour_overflow_degrades_gracefully) {
    pour_stats st = pour_run(2000, 4000, 90);
    AK_CHECK(st.ok);
    AK_CHECK_MSG(st.dropped > 0, "nothing dropped: the test no longer forces an overflow");
    AK_CHECK_MSG(st.outside < 0.01f, "a sphere %g m past a wall or the ground", st.outside);
}

/* contacts_after_joints: a chain of 6 capsules (r 4 cm, 0.4 m long, the middle two five times
 * denser) on ball joints end to end, lying tilted 15 degrees and dropped from 0.5 m onto the
 * ground, 1 s at 1 substep. The depth is measured from the poses alone, independently of the
 * solver's contacts: a capsule's lowest point is its centre's height minus |axis . up| times
 * its half height minus its radius. Without the pass the joint sweeps, solved after the
 * contacts, pull the links that land first back into the ground (here 15 mm); with it the
 * deepest point over every step stays within 5 mm (here 2.7) and under a third of the depth
 * without, and the chain still hangs together, its worst anchor gap under 2 cm (here 9.4 mm
 * against 0.1 without: the pass is the last word, so the joints give way instead). */
static void drop_chain(bool after, float* out_depth, float* out_gap) {
    enum { LINKS = 6 };
    ak_rigid_body_desc b[LINKS + 1] = {{.shape = {.type = AK_RIGID_PLANE, .normal = {0, 1, 0}}}};
    ak_rigid_joint_desc j[LINKS - 1];
    const float tilt = 0.2617994f, c = cosf(tilt), sn = sinf(tilt);
    const ak_quat lying = ak_quat_mul(ak_quat_from_axis_angle(ak_vec3_make(0, 0, 1), tilt),
                                      ak_quat_from_axis_angle(ak_vec3_make(0, 0, 1), 1.5707963f));
    for (int k = 0; k < LINKS; ++k) {
        float t = 0.2f + 0.4f * (float)k;
        b[k + 1] = (ak_rigid_body_desc){
            .shape = {.type = AK_RIGID_CAPSULE, .radius = 0.04f, .half_height = 0.16f},
            .position = {t * c, 0.6f + t * sn, 0},
            .orientation = lying,
            .density = k == 2 || k == 3 ? 5000.0f : 1000.0f};
        if (k)
            j[k - 1] = (ak_rigid_joint_desc){.type = AK_RIGID_JOINT_BALL,
                                             .body_a = (uint32_t)k,
                                             .body_b = (uint32_t)k + 1,
                                             .anchor = {0.4f * (float)k * c,
                                                        0.6f + 0.4f * (float)k * sn, 0}};
    }
    ak_rigid_model_desc md = {.joints = {j, LINKS - 1}, .contacts_after_joints = after};
    world wd;
    *out_depth = *out_gap = INFINITY;
    if (!world_init(&wd, b, LINKS + 1, &md, 1.0f / 60.0f, 1, G)) return;
    float depth = 0.0f, gap = 0.0f;
    for (int f = 0; f < 60; ++f) {
        if (ak_rigid_step_run(&wd.job) != AK_OK) depth = INFINITY;
        for (size_t k = 1; k <= LINKS; ++k) {
            ak_vec3 axis = ak_quat_rotate(wd.q[k], ak_vec3_make(0, 1, 0));
            float low = wd.x[k].y - fabsf(axis.y) * 0.16f - 0.04f;
            depth = ak_maxf(depth, -low);
        }
        for (size_t k = 0; k + 1 < LINKS; ++k) {
            float g = 0.0f, excess = 0.0f;
            ak_rigid_joint_error(wd.model, k, (ak_vec3_cspan){wd.x, wd.n},
                                 (ak_quat_cspan){wd.q, wd.n}, &g, &excess);
            gap = ak_maxf(gap, g);
        }
    }
    *out_depth = depth, *out_gap = gap;
    world_free(&wd);
}

AK_TEST(contacts_after_joints_keeps_a_landing_chain_out) {
    float d0, g0, d1, g1;
    drop_chain(false, &d0, &g0);
    drop_chain(true, &d1, &g1);
    printf("  6-link chain dropped, 1 substep: deepest point %.3g m, gap %.3g m without the pass; "
           "%.3g m, %.3g m with it\n",
           d0, g0, d1, g1);
    AK_CHECK_MSG(d1 < 5e-3f && d1 < d0 / 3.0f, "with the pass %g m, without %g m", d1, d0);
    AK_CHECK_MSG(g1 < 0.02f, "with the pass: gap %g m", g1);
}

/* contact_iterations: a column of 12 boxes (0.5 m cubes) set down touching on the ground, 1 s at
 * 2 substeps. Each substep's single pass solves the pairs from the top down, so the pile's weight
 * reaches the ground one layer per substep and the column sinks into itself at the start; further
 * passes over the normals carry it down sooner. The depth is read from the poses alone (the
 * column stays upright and aligned: the ground's is 0.25 m minus the lowest centre's height, a
 * pair's 0.5 m minus their centres' distance): with 3 iterations the deepest over every step must
 * be under half of that with 1 (here 4.2 against 13.7 mm), and the top may move sideways no more
 * (15 against 28 mm); the default (0) is 1, to the bit; 65 is refused. */
static float column_depth(uint32_t iterations, ak_vec3* out_top) {
    enum { BOXES = 12 };
    ak_rigid_body_desc b[BOXES + 1] = {{.shape = {.type = AK_RIGID_PLANE, .normal = {0, 1, 0}}}};
    for (int k = 0; k < BOXES; ++k)
        b[k + 1] = (ak_rigid_body_desc){
            .shape = {.type = AK_RIGID_BOX, .half_extents = {0.25f, 0.25f, 0.25f}},
            .position = {0, 0.25f + 0.5f * (float)k, 0}};
    ak_rigid_model_desc md = {.contact_iterations = iterations};
    world wd;
    if (!world_init(&wd, b, BOXES + 1, &md, 1.0f / 60.0f, 2, G)) return INFINITY;
    float depth = 0.0f;
    for (int f = 0; f < 60; ++f) {
        if (ak_rigid_step_run(&wd.job) != AK_OK) depth = INFINITY;
        depth = ak_maxf(depth, 0.25f - wd.x[1].y);
        for (size_t k = 1; k < BOXES; ++k)
            depth = ak_maxf(depth, 0.5f - ak_vec3_distance(wd.x[k + 1], wd.x[k]));
    }
    *out_top = wd.x[BOXES];
    world_free(&wd);
    return depth;
}

AK_TEST(contact_iterations_carry_a_column_down_sooner) {
    ak_vec3 t0, t1, t3;
    float d0 = column_depth(0, &t0), d1 = column_depth(1, &t1), d3 = column_depth(3, &t3);
    printf("  12-box column, 2 substeps: deepest %.3g m with 1 contact iteration, %.3g m with 3; "
           "top moved sideways %.3g, %.3g m\n",
           d1, d3, hypotf(t1.x, t1.z), hypotf(t3.x, t3.z));
    AK_CHECK_MSG(d0 == d1 && memcmp(&t0, &t1, sizeof t0) == 0, "default and 1 differ");
    AK_CHECK_MSG(d3 < 0.5f * d1, "3 iterations: %g m, 1: %g m", d3, d1);
    AK_CHECK_MSG(hypotf(t3.x, t3.z) <= hypotf(t1.x, t1.z), "3 iterations: the top moved %g m, "
                 "1: %g m", hypotf(t3.x, t3.z), hypotf(t1.x, t1.z));
    ak_rigid_body_desc b = {.shape = {.type = AK_RIGID_SPHERE, .radius = 0.1f}};
    ak_rigid_model* m = NULL;
    ak_rigid_model_desc md = {.bodies = {&b, 1},
                              .contact_iterations = AK_RIGID_MAX_CONTACT_ITERATIONS + 1};
    AK_CHECK_EQ(ak_rigid_model_create(&md, NULL, &m), AK_ERR_BAD_ARG);
    AK_CHECK(m == NULL);
}

int main(void) {
    AK_RUN(mass_and_inertia_closed_forms);
    AK_RUN(model_validity);
    AK_RUN(free_fall_and_parabola);
    AK_RUN(incline_stays_or_slides);
    AK_RUN(torque_free_spin);
    AK_RUN(restitution_rebound);
    AK_RUN(fast_boxes_are_caught);
    AK_RUN(body_launched_mid_step_meets_the_next);
    AK_RUN(joint_tolerance_trades_gap_for_sweeps);
    AK_RUN(contacts_after_joints_keeps_a_landing_chain_out);
    AK_RUN(contact_iterations_carry_a_column_down_sooner);
    AK_RUN(box_stack_stands);
    AK_RUN(sphere_pour_keeps_every_contact);
    AK_RUN(sphere_pour_overflow_degrades_gracefully);
    AK_RUN_SLOW(pyramid_stands);
    AK_RUN(pyramid_does_not_walk_at_10_substeps);
    AK_RUN(sliding_tall_box_tips_when_mu_exceeds_its_aspect);
    AK_RUN(incline_stack_does_not_creep_at_4_substeps);
    AK_RUN(stack_top_does_not_creep_at_4_substeps);
    AK_RUN_HEAVY(pyramid_does_not_walk_at_4_substeps);
    AK_RUN(contact_anchors_bit_identical_for_any_thread_count);
    AK_RUN(resting_box_and_stack_stay_still_and_sleep);
    AK_RUN(pyramid_at_rest_stays_still_and_sleeps);
    AK_RUN(contact_anchors_validated);
    AK_RUN(pendulum_period_ball_joint);
    AK_RUN(hinge_limits_hold);
    AK_RUN(prismatic_slides_along_its_axis);
    AK_RUN(fixed_joint_keeps_the_pose);
    AK_RUN_SLOW(box_stack_stands_20s);
    AK_RUN_SLOW(pyramid_20_layers_20s);
    return ak_test_finish();
}

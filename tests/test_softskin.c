/* Volumetric (soft-tissue) skinning: bind-pose reproduction, convergence under a held pose,
 * volume under bends (the enclosed volume by the divergence theorem, an independent measure),
 * no collapse under a twist, bit-identical results across thread counts, bad input. */
#include <animkit/animkit.h>

#include "ak_test.h"

typedef struct rig {
    ak_mat4 previous[8];    /* the palette of the previous step */
    ak_scene* scene;
    const ak_mesh* mesh;
    size_t joints;          /* skeleton joints */
    size_t slots;           /* skin slots (palette size) */
    ak_skin_bone bones[16];
    size_t bone_count;
    ak_transform local[8];
    ak_mat4 world[8], palette[8];
} rig;

static void rig_pose(rig* g, ak_quat q);

static bool rig_load(rig* g, uint32_t rings, uint32_t segments) {
    memset(g, 0, sizeof *g);
    ak_builtin_desc bd = {.rings = rings, .segments = segments};
    if (ak_builtin_create("builtin:cylinder", &bd, NULL, &g->scene) != AK_OK) return false;
    g->mesh = g->scene->meshes[0].mesh;
    g->joints = ak_scene_joint_count(g->scene);
    const ak_scene_skin* sk = &g->scene->skins[0];
    g->slots = sk->joint_count;
    if (g->joints > 8 || g->slots > 8) return false;
    /* bones from the skin's bind positions: slot k -> child slot, point bones for leaves */
    ak_vec3 pos[8];
    int32_t parent[8];
    ak_i32_cspan par = ak_skeleton_parents(g->scene->skeleton);
    for (size_t k = 0; k < g->slots; ++k) {
        pos[k] = ak_mat4_get_translation(ak_mat4_inverse_affine(sk->inverse_binds[k]));
        parent[k] = -1;
        int pj = par.ptr[sk->joints[k]];
        for (size_t q = 0; q < g->slots; ++q)
            if (sk->joints[q] == pj) parent[k] = (int32_t)q;
    }
    if (ak_skin_bones_from_joints((ak_vec3_cspan){pos, g->slots}, (ak_i32_cspan){parent, g->slots}, false,
                                  (ak_skin_bone_span){g->bones, 16}, &g->bone_count) != AK_OK)
        return false;
    rig_pose(g, ak_quat_identity()); /* twice: the previous palette is the bind pose too */
    rig_pose(g, ak_quat_identity());
    return true;
}

/* Palette with joint1 rotated by q (identity: the bind pose). */
static void rig_pose(rig* g, ak_quat q) {
    memcpy(g->previous, g->palette, sizeof g->palette);
    ak_scene_rest_pose(g->scene, (ak_transform_span){g->local, g->joints});
    int mid = ak_skeleton_find_joint(g->scene->skeleton, "joint1");
    g->local[mid].rotation = ak_quat_mul(g->local[mid].rotation, q);
    ak_scene_world_matrices(g->scene, (ak_transform_cspan){g->local, g->joints}, (ak_mat4_span){g->world, g->joints});
    ak_scene_skin_palette(g->scene, 0, (ak_mat4_cspan){g->world, g->joints}, (ak_mat4_span){g->palette, g->slots});
}

static ak_skin_soft_desc rig_desc(const rig* g, uint32_t resolution) {
    const ak_mesh* m = g->mesh;
    size_t wn = m->vertex_count * m->influence_count;
    ak_skin_soft_desc d = {.positions = {m->positions, m->vertex_count},
                           .indices = {m->indices, 3 * m->triangle_count},
                           .joints = {m->joints, wn},
                           .weights = {m->weights, wn},
                           .influence_count = m->influence_count,
                           .bones = {g->bones, g->bone_count},
                           .resolution = resolution};
    return d;
}

typedef struct sim {
    ak_skin_soft* soft;
    ak_vec3 *x, *v, *out;
    uint8_t* scratch;
    ak_skin_soft_step_job job;
} sim;

static bool sim_init(sim* s, const rig* g, const ak_skin_soft_desc* d) {
    memset(s, 0, sizeof *s);
    if (ak_skin_soft_create(d, NULL, &s->soft) != AK_OK) return false;
    size_t n = ak_skin_soft_node_count(s->soft), ss = ak_skin_soft_step_scratch_size(s->soft);
    s->x = malloc(n * sizeof(ak_vec3));
    s->v = malloc(n * sizeof(ak_vec3));
    s->out = malloc(g->mesh->vertex_count * sizeof(ak_vec3));
    s->scratch = malloc(ss);
    if (!s->x || !s->v || !s->out || !s->scratch) return false;
    s->job = (ak_skin_soft_step_job){.soft = s->soft,
                                     .palette = {g->palette, g->slots},
                                     .previous_palette = {g->previous, g->slots},
                                     .node_positions = {s->x, n},
                                     .node_velocities = {s->v, n},
                                     .scratch = {s->scratch, ss},
                                     .out_positions = {s->out, g->mesh->vertex_count}};
    return ak_skin_soft_state_init(s->soft, (ak_mat4_cspan){g->palette, g->slots}, (ak_vec3_span){s->x, n},
                                   (ak_vec3_span){s->v, n}) == AK_OK;
}

static void sim_free(sim* s) {
    ak_skin_soft_destroy(s->soft);
    free(s->x);
    free(s->v);
    free(s->out);
    free(s->scratch);
}

static double volume_of(const rig* g, const ak_vec3* p) {
    return ak_volume_compute((ak_vec3_cspan){p, g->mesh->vertex_count},
                             (ak_u32_cspan){g->mesh->indices, 3 * g->mesh->triangle_count});
}

static float bbox_diag(const ak_mesh* m) {
    ak_vec3 lo, hi;
    ak_mesh_bounds(m, &lo, &hi);
    return ak_vec3_distance(lo, hi);
}

/* Frames at 60 Hz holding the current palette; returns the last kinetic energy. The previous
 * palette is the held one (the skeleton does not move: the step's contract, and the step moves
 * its colliders from the previous palette's pose to this one's across the substeps). */
static float hold(sim* s, rig* g, int frames) {
    memcpy(g->previous, g->palette, sizeof g->palette);
    float ke = 0.0f;
    s->job.out_kinetic_energy = &ke;
    for (int f = 0; f < frames; ++f)
        if (ak_skin_soft_step_run(&s->job) != AK_OK) ke = INFINITY;
    s->job.out_kinetic_energy = NULL;
    return ke;
}

/* Ramp joint1's rotation about axis from 0 to angle over `frames`, then hold `hold_frames`. */
static float ramp(sim* s, rig* g, ak_vec3 axis, float angle, int frames, int hold_frames) {
    float last = 0.0f;
    for (int f = 1; f <= frames; ++f) {
        rig_pose(g, ak_quat_from_axis_angle(axis, angle * (float)f / (float)frames));
        float ke = 0.0f;
        s->job.out_kinetic_energy = &ke;
        ak_result r = ak_skin_soft_step_run(&s->job);
        s->job.out_kinetic_energy = NULL;
        if (r != AK_OK) return INFINITY;
        if (f == frames) last = ke;
    }
    return hold_frames ? hold(s, g, hold_frames) : last;
}

AK_TEST(bind_pose_reproduces_the_mesh) {
    rig g;
    AK_CHECK(rig_load(&g, 24, 16));
    rig_pose(&g, ak_quat_identity());
    ak_skin_soft_desc d = rig_desc(&g, 12);
    sim s;
    AK_CHECK(sim_init(&s, &g, &d));
    AK_CHECK(ak_skin_soft_kinematic_count(s.soft) > 0);
    AK_CHECK(ak_skin_soft_kinematic_count(s.soft) < ak_skin_soft_node_count(s.soft));
    float tol = 1e-4f * bbox_diag(g.mesh), err = 0.0f;
    size_t nv = g.mesh->vertex_count;
    AK_CHECK_EQ(ak_skin_soft_surface(s.soft, (ak_vec3_cspan){s.x, ak_skin_soft_node_count(s.soft)}, (ak_vec3_span){s.out, nv}), AK_OK);
    for (size_t v = 0; v < nv; ++v) err = ak_maxf(err, ak_vec3_distance(s.out[v], g.mesh->positions[v]));
    AK_CHECK_MSG(err <= tol, "init: error %g > %g", (double)err, (double)tol);
    /* held at the bind pose the rest state stays put (Neo-Hookean rest is stress-free) */
    hold(&s, &g, 10);
    err = 0.0f;
    for (size_t v = 0; v < nv; ++v) err = ak_maxf(err, ak_vec3_distance(s.out[v], g.mesh->positions[v]));
    AK_CHECK_MSG(err <= tol, "after 10 frames: error %g > %g", (double)err, (double)tol);
    sim_free(&s);
    ak_scene_destroy(g.scene);
}

AK_TEST(held_pose_converges_and_keeps_volume) {
    rig g;
    AK_CHECK(rig_load(&g, 24, 16));
    rig_pose(&g, ak_quat_identity());
    double v0 = volume_of(&g, g.mesh->positions);
    ak_skin_soft_desc d = rig_desc(&g, 16);
    sim s;
    AK_CHECK(sim_init(&s, &g, &d));
    float ke_moving = ramp(&s, &g, ak_vec3_make(0, 0, 1), AK_HALF_PI, 20, 0);
    float ke = hold(&s, &g, 90);
    /* bound: 1e-4 of the kinetic energy while bending */
    AK_CHECK_MSG(ke < 1e-4f * ke_moving + 1e-9f, "kinetic energy %g after 1.5 s held (moving %g)", (double)ke, (double)ke_moving);
    double vr = volume_of(&g, s.out) / v0;
    AK_CHECK_MSG(fabs(vr - 1.0) < 0.005, "volume ratio %g", vr);
    sim_free(&s);
    ak_scene_destroy(g.scene);
}

static size_t intersections(const rig* g, const ak_vec3* p) {
    size_t count = 0;
    ak_result r = ak_mesh_self_intersections((ak_vec3_cspan){p, g->mesh->vertex_count},
                                             (ak_u32_cspan){g->mesh->indices, 3 * g->mesh->triangle_count},
                                             (ak_u32_span){NULL, 0}, &count);
    return r == AK_OK ? count : SIZE_MAX;
}

/* The rig's mesh skinned by LBS or DQS at its current palette. */
static bool skin_mesh(const rig* g, ak_skin_method method, ak_vec3* out) {
    const ak_mesh* m = g->mesh;
    size_t n = m->vertex_count;
    uint8_t scratch[64 + 192 * 8];
    ak_skin_job job = {.method = method,
                       .influence_count = m->influence_count,
                       .palette = {g->palette, g->slots},
                       .positions = {m->positions, n, 0},
                       .joints = {m->joints, n, 0},
                       .weights = {m->weights, n, 0},
                       .scratch = {scratch, sizeof scratch},
                       .out_positions = {out, n, 0}};
    return ak_skin_job_run(&job) == AK_OK;
}

/* Volume (and self-intersecting pairs) of the mesh skinned by LBS or DQS at the rig's current
 * palette (shown beside). */
static double skinned_volume(const rig* g, ak_skin_method method, size_t* out_pairs) {
    ak_vec3* out = malloc(g->mesh->vertex_count * sizeof(ak_vec3));
    double v = out && skin_mesh(g, method, out) ? volume_of(g, out) : NAN;
    *out_pairs = out ? intersections(g, out) : SIZE_MAX;
    free(out);
    return v;
}

/* Degrees between the cylinder's two halves' axes in the surface p: the lower half's axis runs
 * from the centroid of the vertices in the bottom fifth of the rest height to that of the 30-45%
 * band, the upper half's from the 55-70% band to the top fifth (0: straight). */
static double half_axes_angle(const rig* g, const ak_vec3* p) {
    const ak_mesh* m = g->mesh;
    float ylo = INFINITY, yhi = -INFINITY;
    for (size_t q = 0; q < m->vertex_count; ++q) ylo = ak_minf(ylo, m->positions[q].y), yhi = ak_maxf(yhi, m->positions[q].y);
    static const float band[4][2] = {{0.0f, 0.2f}, {0.3f, 0.45f}, {0.55f, 0.7f}, {0.8f, 1.0f}};
    ak_vec3 cen[4] = {{0}};
    float count[4] = {0};
    for (size_t q = 0; q < m->vertex_count; ++q) {
        float t = (m->positions[q].y - ylo) / (yhi - ylo);
        for (int b = 0; b < 4; ++b)
            if (t >= band[b][0] && t <= band[b][1]) cen[b] = ak_vec3_add(cen[b], p[q]), count[b] += 1.0f;
    }
    for (int b = 0; b < 4; ++b) cen[b] = ak_vec3_scale(cen[b], 1.0f / count[b]);
    ak_vec3 lo = ak_vec3_normalize(ak_vec3_sub(cen[1], cen[0])), hi = ak_vec3_normalize(ak_vec3_sub(cen[3], cen[2]));
    return acos((double)ak_clampf(ak_vec3_dot(lo, hi), -1.0f, 1.0f)) * 180.0 / AK_PI;
}

/* The largest distance of a kinematic node in the state x from its skinned position under
 * palette: the nodes the cone rule released for the step (the others are there). */
static double released_offset(const ak_skin_soft* soft, ak_mat4_cspan palette, const ak_vec3* x) {
    size_t nn = ak_skin_soft_node_count(soft);
    uint8_t* kin = malloc(nn);
    ak_vec3 *sk = malloc(nn * sizeof(ak_vec3)), *sv = malloc(nn * sizeof(ak_vec3));
    double off = NAN;
    if (kin && sk && sv && ak_skin_soft_kinematic_flags(soft, (ak_u8_span){kin, nn}) == AK_OK &&
        ak_skin_soft_state_init(soft, palette, (ak_vec3_span){sk, nn}, (ak_vec3_span){sv, nn}) == AK_OK) {
        off = 0.0;
        for (size_t n = 0; n < nn; ++n)
            if (kin[n]) off = fmax(off, ak_vec3_distance(sk[n], x[n]));
    }
    free(kin), free(sk), free(sv);
    return off;
}

static void bend_case(float degrees, int res, bool print) {
    rig g;
    AK_CHECK(rig_load(&g, 48, 32));
    rig_pose(&g, ak_quat_identity());
    double v0 = volume_of(&g, g.mesh->positions);
    ak_skin_soft_desc d = rig_desc(&g, (uint32_t)res);
    sim s;
    AK_CHECK(sim_init(&s, &g, &d));
    ramp(&s, &g, ak_vec3_make(0, 0, 1), ak_radians(degrees), 20, 60);
    double vr = volume_of(&g, s.out) / v0;
    {
        size_t nn = ak_skin_soft_node_count(s.soft), nt = ak_skin_soft_tet_count(s.soft);
        ak_vec3* rest = malloc(nn * sizeof(ak_vec3));
        uint32_t* tt = malloc(4 * nt * sizeof(uint32_t));
        ak_skin_soft_rest_nodes(s.soft, (ak_vec3_span){rest, nn});
        ak_skin_soft_tets(s.soft, (ak_u32_span){tt, 4 * nt});
        double v_rest = 0, v_now = 0, jmin = 1e9, jmax = -1e9;
        for (size_t q = 0; q < nt; ++q) {
            const ak_vec3* X[2] = {rest, s.x};
            double vol[2];
            for (int k = 0; k < 2; ++k) {
                ak_vec3 a = X[k][tt[4 * q]];
                vol[k] = ak_vec3_dot(ak_vec3_sub(X[k][tt[4 * q + 1]], a), ak_vec3_cross(ak_vec3_sub(X[k][tt[4 * q + 2]], a), ak_vec3_sub(X[k][tt[4 * q + 3]], a))) / 6.0;
            }
            v_rest += vol[0];
            v_now += vol[1];
            double J = vol[1] / vol[0];
            if (J < jmin) jmin = J;
            if (J > jmax) jmax = J;
        }
        if (print) printf("  lattice volume ratio %.5f, J in [%.4f, %.4f]\n", v_now / v_rest, jmin, jmax);
        AK_CHECK_MSG(jmin > 0.0, "bend %g: an inverted tetrahedron (J = %g)", (double)degrees, jmin);
        free(rest);
        free(tt);
    }
    /* the cylinder follows the pose: the angle between its two halves' axes at least 3/4 of the
     * joint's. At 150 deg the cone rule releases every kinematic node of both bones near the
     * joint; untied (before the tether) the held cylinder stayed straight (3 deg; its tets kept
     * their volume within 1.4% because they were hardly deformed), the released nodes 0.90 off
     * their skinned positions (docs/softskin.md) */
    double bend_soft = half_axes_angle(&g, s.out);
    {
        ak_vec3* dq = malloc(g.mesh->vertex_count * sizeof(ak_vec3));
        double bend_dqs = dq && skin_mesh(&g, AK_SKIN_DQS, dq) ? half_axes_angle(&g, dq) : NAN;
        if (print)
            printf("  bend %.0f: angle between the halves' axes soft %.1f deg, DQS %.1f; kinematic nodes up to %.3f off their skinned"
                   " positions (diagonal %.3f)\n",
                   (double)degrees, bend_soft, bend_dqs, released_offset(s.soft, (ak_mat4_cspan){g.palette, g.slots}, s.x),
                   (double)bbox_diag(g.mesh));
        free(dq);
    }
    AK_CHECK_MSG(bend_soft >= 0.75 * (double)degrees, "bend %g: the soft cylinder bends %g deg", (double)degrees, bend_soft);
    size_t lbs_pairs = 0, dqs_pairs = 0, soft_pairs = intersections(&g, s.out);
    double lbs_v = skinned_volume(&g, AK_SKIN_LBS, &lbs_pairs) / v0, dqs_v = skinned_volume(&g, AK_SKIN_DQS, &dqs_pairs) / v0;
    if (print)
        printf("  bend %.0f: volume ratio soft %.5f LBS %.5f DQS %.5f; intersecting pairs soft %zu LBS %zu DQS %zu (%zu nodes, %zu tets)\n",
               (double)degrees, vr, lbs_v, dqs_v, soft_pairs, lbs_pairs, dqs_pairs, ak_skin_soft_node_count(s.soft),
               ak_skin_soft_tet_count(s.soft));
    AK_CHECK_MSG(lbs_pairs + dqs_pairs > 0, "bend %g: LBS and DQS should interpenetrate", (double)degrees);
    AK_CHECK_MSG(soft_pairs == 0, "bend %g: %zu self-intersecting pairs", (double)degrees, soft_pairs);
    AK_CHECK_MSG(fabs(vr - 1.0) < 0.01, "bend %g: volume ratio %g", (double)degrees, vr);
    sim_free(&s);
    ak_scene_destroy(g.scene);
}

/* Smallest distance of the side vertices from the Y axis, over the rest radius. */
static float min_radius(const rig* g, const ak_vec3* p) {
    float r0 = 0.0f, rmin = INFINITY;
    for (size_t v = 0; v < g->mesh->vertex_count; ++v) {
        ak_vec3 q = g->mesh->positions[v];
        r0 = ak_maxf(r0, sqrtf(q.x * q.x + q.z * q.z));
    }
    for (size_t v = 0; v < g->mesh->vertex_count; ++v) {
        ak_vec3 q = g->mesh->positions[v];
        if (sqrtf(q.x * q.x + q.z * q.z) < 0.99f * r0) continue; /* the caps */
        rmin = ak_minf(rmin, sqrtf(p[v].x * p[v].x + p[v].z * p[v].z));
    }
    return rmin / r0;
}

AK_TEST(twist_180_does_not_collapse) {
    rig g;
    AK_CHECK(rig_load(&g, 48, 32));
    rig_pose(&g, ak_quat_identity());
    ak_skin_soft_desc d = rig_desc(&g, 16);
    sim s;
    AK_CHECK(sim_init(&s, &g, &d));
    ramp(&s, &g, ak_vec3_make(0, 1, 0), AK_PI * 0.999f, 20, 30);
    float soft_r = min_radius(&g, s.out);
    /* LBS at the same palette collapses to (almost) the axis */
    const ak_mesh* m = g.mesh;
    size_t n = m->vertex_count;
    ak_vec3* lbs = malloc(n * sizeof(ak_vec3));
    ak_skin_job job = {.influence_count = m->influence_count,
                       .palette = {g.palette, g.slots},
                       .positions = {m->positions, n, 0},
                       .joints = {m->joints, n, 0},
                       .weights = {m->weights, n, 0},
                       .out_positions = {lbs, n, 0}};
    AK_CHECK_EQ(ak_skin_job_run(&job), AK_OK);
    float lbs_r = min_radius(&g, lbs);
    printf("  twist 180: min radius soft %.3f, LBS %.3f\n", (double)soft_r, (double)lbs_r);
    AK_CHECK_MSG(lbs_r < 0.1f, "LBS min radius %g (the reference collapse)", (double)lbs_r);
    AK_CHECK_MSG(soft_r > 0.5f, "soft min radius %g", (double)soft_r);
    free(lbs);
    sim_free(&s);
    ak_scene_destroy(g.scene);
}

/* Same steps with 1 and 3 threads: bit-identical state (tets solved colour by colour). */
AK_TEST(threads_give_identical_results) {
    rig g;
    AK_CHECK(rig_load(&g, 12, 8));
    rig_pose(&g, ak_quat_identity());
    ak_skin_soft_desc d = rig_desc(&g, 64);
    d.substeps = 2; /* the same arithmetic per substep: two are enough to compare */
    sim a, b;
    AK_CHECK(sim_init(&a, &g, &d));
    AK_CHECK(sim_init(&b, &g, &d));
    size_t nn = ak_skin_soft_node_count(a.soft);
    AK_CHECK(nn >= 3 * 4096); /* large enough that 3 threads really run (one per 4096 nodes) */
    b.job.thread_count = 3;
    for (int f = 1; f <= 4; ++f) {
        rig_pose(&g, ak_quat_from_axis_angle(ak_vec3_make(0, 0, 1), 0.3f * (float)f));
        AK_CHECK_EQ(ak_skin_soft_step_run(&a.job), AK_OK);
        AK_CHECK_EQ(ak_skin_soft_step_run(&b.job), AK_OK);
    }
    AK_CHECK(memcmp(a.x, b.x, nn * sizeof(ak_vec3)) == 0);
    AK_CHECK(memcmp(a.v, b.v, nn * sizeof(ak_vec3)) == 0);
    /* and the flesh moved: the test would notice a no-op */
    AK_CHECK(ak_vec3_distance(a.out[0], g.mesh->positions[0]) > 0.0f || ak_vec3_distance(a.out[g.mesh->vertex_count - 1], g.mesh->positions[g.mesh->vertex_count - 1]) > 0.01f);
    sim_free(&a);
    sim_free(&b);
    ak_scene_destroy(g.scene);
}

AK_TEST(bad_input_gets_clear_errors) {
    rig g;
    AK_CHECK(rig_load(&g, 8, 8));
    rig_pose(&g, ak_quat_identity());
    ak_skin_soft* soft = NULL;
    AK_CHECK_EQ(ak_skin_soft_create(NULL, NULL, &soft), AK_ERR_NULL_ARG);
    ak_skin_soft_desc d = rig_desc(&g, 8);
    d.resolution = 1000;
    AK_CHECK_EQ(ak_skin_soft_create(&d, NULL, &soft), AK_ERR_BAD_ARG);
    d = rig_desc(&g, 8);
    d.joint_zone = -1.0f;
    AK_CHECK_EQ(ak_skin_soft_create(&d, NULL, &soft), AK_ERR_BAD_ARG);
    d = rig_desc(&g, 8);
    d.poisson_ratio = 0.5f;
    AK_CHECK_EQ(ak_skin_soft_create(&d, NULL, &soft), AK_ERR_BAD_ARG);
    d = rig_desc(&g, 8);
    d.youngs_modulus = NAN;
    AK_CHECK_EQ(ak_skin_soft_create(&d, NULL, &soft), AK_ERR_BAD_ARG);
    d = rig_desc(&g, 256);
    d.memory_budget = 1 << 20;
    AK_CHECK_EQ(ak_skin_soft_create(&d, NULL, &soft), AK_ERR_BUDGET);
    /* NaN position */
    size_t n = g.mesh->vertex_count;
    ak_vec3* p = malloc(n * sizeof(ak_vec3));
    memcpy(p, g.mesh->positions, n * sizeof(ak_vec3));
    p[3].y = NAN;
    d = rig_desc(&g, 8);
    d.positions.ptr = p;
    AK_CHECK_EQ(ak_skin_soft_create(&d, NULL, &soft), AK_ERR_BAD_DATA);
    /* a triangle index out of range */
    uint32_t bad_idx[3] = {0, 1, (uint32_t)n};
    d = rig_desc(&g, 8);
    d.indices = (ak_u32_cspan){bad_idx, 3};
    AK_CHECK_EQ(ak_skin_soft_create(&d, NULL, &soft), AK_ERR_BAD_INDEX);
    AK_CHECK(soft == NULL);
    free(p);
    /* the step: NaN palette, too small a palette, bad dt */
    d = rig_desc(&g, 8);
    sim s;
    AK_CHECK(sim_init(&s, &g, &d));
    ak_mat4 pal[8];
    memcpy(pal, g.palette, sizeof pal);
    pal[1].m[5] = NAN;
    s.job.palette = (ak_mat4_cspan){pal, g.slots};
    AK_CHECK_EQ(ak_skin_soft_step_run(&s.job), AK_ERR_BAD_DATA);
    s.job.palette = (ak_mat4_cspan){g.palette, 1};
    AK_CHECK_EQ(ak_skin_soft_step_run(&s.job), AK_ERR_SPAN_SMALL);
    s.job.palette = (ak_mat4_cspan){g.palette, g.slots};
    s.job.dt = 2.0f;
    AK_CHECK_EQ(ak_skin_soft_step_run(&s.job), AK_ERR_BAD_ARG);
    s.job.dt = 0.0f;
    s.job.scratch.count = 1;
    AK_CHECK_EQ(ak_skin_soft_step_run(&s.job), AK_ERR_SPAN_SMALL);
    sim_free(&s);
    ak_scene_destroy(g.scene);
}


/* ---- CesiumMan (assets via ANIMKIT_ASSETS or ../shared/assets; SKIP when absent) ---------- */

typedef struct cman {
    ak_scene* sc;
    const ak_mesh* m;
    size_t mi, nv, nj, ns, nb;
    ak_skin_bone* bones;
    ak_vec3* jp;    /* [slot] bind positions of the joints */
    int32_t* par;   /* [slot] nearest ancestor slot */
    float diag;
} cman;

static void cman_free(cman* c) {
    free(c->bones), free(c->jp), free(c->par);
    ak_scene_destroy(c->sc);
}

/* Reads CesiumMan at path into c (cman_load below). */
static bool cman_read(cman* c, const char* path) {
    if (ak_io_load(path, NULL, NULL, &c->sc, NULL) != AK_OK || !c->sc) return false;
    ak_scene* sc = c->sc;
    while (c->mi < sc->mesh_count && (sc->meshes[c->mi].skin < 0 || !sc->meshes[c->mi].mesh->triangle_count)) ++c->mi;
    if (c->mi == sc->mesh_count || sc->clip_count == 0) return false;
    c->m = sc->meshes[c->mi].mesh;
    const ak_scene_skin* sk = &sc->skins[sc->meshes[c->mi].skin];
    c->nv = c->m->vertex_count, c->nj = ak_scene_joint_count(sc), c->ns = sk->joint_count;
    /* bones: slot -> nearest ancestor slot (point bones for leaves) */
    c->bones = calloc(2 * c->ns + 1, sizeof(ak_skin_bone));
    c->jp = calloc(c->ns, sizeof(ak_vec3));
    c->par = calloc(c->ns, sizeof(int32_t));
    if (!c->bones || !c->jp || !c->par) return false;
    ak_i32_cspan sp = ak_skeleton_parents(sc->skeleton);
    bool ordered = true; /* ak_skin_bones_from_joints wants parents first: CesiumMan's are */
    for (size_t k = 0; k < c->ns; ++k) {
        c->jp[k] = ak_mat4_get_translation(ak_mat4_inverse_affine(sk->inverse_binds[k]));
        c->par[k] = -1;
        for (int j = sp.ptr[sk->joints[k]]; j >= 0 && c->par[k] < 0; j = sp.ptr[j])
            for (size_t q = 0; q < c->ns; ++q)
                if (sk->joints[q] == j) c->par[k] = (int32_t)q;
        ordered = ordered && c->par[k] < (int32_t)k;
    }
    ak_vec3 lo, hi;
    ak_mesh_bounds(c->m, &lo, &hi);
    c->diag = ak_vec3_distance(lo, hi);
    return ordered && ak_skin_bones_from_joints((ak_vec3_cspan){c->jp, c->ns}, (ak_i32_cspan){c->par, c->ns}, false,
                                                (ak_skin_bone_span){c->bones, 2 * c->ns + 1}, &c->nb) == AK_OK;
}

/* CesiumMan's skinned mesh, skin slots and bones. False after a SKIP line when the asset is
 * absent, or a failed check when it is there but does not load as expected; c is freed then. */
static bool cman_load(cman* c) {
    memset(c, 0, sizeof *c);
    char path[1200];
    if (!ak_test_asset(path, sizeof path, "gltf/CesiumMan/glTF-Binary/CesiumMan.glb")) {
        AK_SKIP("CesiumMan.glb not found (ANIMKIT_ASSETS or ../shared/assets)");
        return false;
    }
    const bool ok = cman_read(c, path);
    AK_CHECK_MSG(ok, "%s: not the skinned, animated CesiumMan these cases expect", path);
    if (!ok) cman_free(c);
    return ok;
}

/* Skin slot of the joint named `name`, -1 when absent. */
static int cman_slot(const cman* c, const char* name) {
    int j = ak_skeleton_find_joint(c->sc->skeleton, name);
    const ak_scene_skin* sk = &c->sc->skins[c->sc->meshes[c->mi].skin];
    for (size_t k = 0; k < c->ns; ++k)
        if (j >= 0 && (int)sk->joints[k] == j) return (int)k;
    return -1;
}

static ak_skin_soft_desc cman_desc(const cman* c) {
    size_t wn = c->nv * c->m->influence_count;
    ak_skin_soft_desc d = {.positions = {c->m->positions, c->nv},
                           .indices = {c->m->indices, 3 * c->m->triangle_count},
                           .joints = {c->m->joints, wn},
                           .weights = {c->m->weights, wn},
                           .influence_count = c->m->influence_count,
                           .bones = {c->bones, c->nb}};
    return d;
}

static void cman_skin(const cman* c, ak_skin_method method, const ak_mat4* pal, ak_vec3* out) {
    uint8_t scratch[64 + 192 * 32];
    ak_skin_job lj = {.method = method,
                      .influence_count = c->m->influence_count,
                      .palette = {pal, c->ns},
                      .positions = {c->m->positions, c->nv, 0},
                      .joints = {c->m->joints, c->nv, 0},
                      .weights = {c->m->weights, c->nv, 0},
                      .scratch = {scratch, sizeof scratch},
                      .out_positions = {out, c->nv, 0}};
    AK_CHECK_EQ(ak_skin_job_run(&lj), AK_OK);
}

/* Lattice tets whose four nodes lie below the middle of the thighs and that have nodes on both
 * sides of the body's mid-plane between the hips: tets that bridge the two legs (the gap
 * between the legs is wider than zero there, so no tet of one leg crosses the plane). */
static size_t cman_leg_bridges(const cman* c, const ak_skin_soft* soft) {
    int hl = cman_slot(c, "leg_joint_L_1"), hr = cman_slot(c, "leg_joint_R_1");
    int kl = cman_slot(c, "leg_joint_L_2"), kr = cman_slot(c, "leg_joint_R_2");
    AK_CHECK(hl >= 0 && hr >= 0 && kl >= 0 && kr >= 0);
    if (hl < 0 || hr < 0 || kl < 0 || kr < 0) return SIZE_MAX;
    ak_vec3 hip = ak_vec3_scale(ak_vec3_add(c->jp[hl], c->jp[hr]), 0.5f);
    ak_vec3 knee = ak_vec3_scale(ak_vec3_add(c->jp[kl], c->jp[kr]), 0.5f);
    ak_vec3 side = ak_vec3_normalize(ak_vec3_sub(c->jp[hl], c->jp[hr]));
    ak_vec3 down = ak_vec3_sub(knee, hip);
    float thigh = ak_vec3_length(down);
    down = ak_vec3_scale(down, 1.0f / thigh);
    size_t nn = ak_skin_soft_node_count(soft), nt = ak_skin_soft_tet_count(soft), bridges = 0;
    ak_vec3* rest = malloc(nn * sizeof(ak_vec3));
    uint32_t* tt = malloc(4 * nt * sizeof(uint32_t));
    ak_skin_soft_rest_nodes(soft, (ak_vec3_span){rest, nn});
    ak_skin_soft_tets(soft, (ak_u32_span){tt, 4 * nt});
    for (size_t q = 0; q < nt; ++q) {
        bool low = true, left = false, right = false;
        for (int k = 0; k < 4; ++k) {
            ak_vec3 r = ak_vec3_sub(rest[tt[4 * q + k]], hip);
            low = low && ak_vec3_dot(r, down) > 0.5f * thigh;
            left = left || ak_vec3_dot(r, side) > 0.0f;
            right = right || ak_vec3_dot(r, side) < 0.0f;
        }
        bridges += low && left && right;
    }
    free(rest);
    free(tt);
    return bridges;
}

/* The first `frames` frames of the walk at 60 Hz: largest and mean distance of the soft
 * surface from LBS's, over the bounding-box diagonal; false if not finite. */
static bool cman_walk(const cman* c, const ak_skin_soft_desc* d, int frames, double* out_max, double* out_mean, size_t* out_bridges) {
    ak_skin_soft* soft = NULL;
    AK_CHECK_EQ(ak_skin_soft_create(d, NULL, &soft), AK_OK);
    if (!soft) return false;
    *out_bridges = cman_leg_bridges(c, soft);
    size_t nn = ak_skin_soft_node_count(soft), ss = ak_skin_soft_step_scratch_size(soft), nv = c->nv, ns = c->ns, nj = c->nj;
    ak_vec3 *x = malloc(nn * sizeof(ak_vec3)), *v = malloc(nn * sizeof(ak_vec3)), *out = malloc(nv * sizeof(ak_vec3));
    ak_vec3* lbs = malloc(nv * sizeof(ak_vec3));
    ak_mat4 *pal = malloc(ns * sizeof(ak_mat4)), *prev = malloc(ns * sizeof(ak_mat4)), *world = malloc(nj * sizeof(ak_mat4));
    ak_transform* local = malloc(nj * sizeof(ak_transform));
    uint8_t* scratch = malloc(ss);
    double worst = 0.0, sum = 0.0;
    size_t count = 0;
    bool finite = true;
    for (int f = 0; f <= frames; ++f) {
        memcpy(prev, pal, ns * sizeof(ak_mat4));
        ak_scene_rest_pose(c->sc, (ak_transform_span){local, nj});
        ak_clip_sample(c->sc->clips[0], fmodf((float)f / 60.0f, ak_clip_duration(c->sc->clips[0])), NULL,
                       (ak_transform_span){local, nj}, (ak_f32_span){0}, (ak_f32_span){0});
        ak_scene_world_matrices(c->sc, (ak_transform_cspan){local, nj}, (ak_mat4_span){world, nj});
        ak_scene_skin_palette(c->sc, (size_t)c->sc->meshes[c->mi].skin, (ak_mat4_cspan){world, nj}, (ak_mat4_span){pal, ns});
        if (f == 0) {
            ak_skin_soft_state_init(soft, (ak_mat4_cspan){pal, ns}, (ak_vec3_span){x, nn}, (ak_vec3_span){v, nn});
            continue;
        }
        ak_skin_soft_step_job job = {.soft = soft,
                                     .palette = {pal, ns},
                                     .previous_palette = {prev, ns},
                                     .node_positions = {x, nn},
                                     .node_velocities = {v, nn},
                                     .scratch = {scratch, ss},
                                     .out_positions = {out, nv}};
        AK_CHECK_EQ(ak_skin_soft_step_run(&job), AK_OK);
        cman_skin(c, AK_SKIN_LBS, pal, lbs);
        for (size_t q = 0; q < nv; ++q) {
            finite = finite && ak_vec3_is_finite(out[q]);
            double dist = ak_vec3_distance(out[q], lbs[q]);
            worst = dist > worst ? dist : worst;
            sum += dist;
            ++count;
        }
    }
    *out_max = worst / c->diag;
    *out_mean = count ? sum / (double)count / c->diag : 0.0;
    free(x), free(v), free(out), free(lbs), free(pal), free(prev), free(world), free(local), free(scratch);
    ak_skin_soft_destroy(soft);
    return finite;
}

/* Bind pose reproduced within 1e-4 of the bounding-box diagonal; no tet bridges the legs
 * (while the lattice that keeps every cell has such tets: the check can fail). */
AK_TEST(cesiumman_bind_and_legs_apart) {
    cman c;
    if (!cman_load(&c)) return;
    ak_skin_soft_desc d = cman_desc(&c);
    /* resolution 16: cubes wide enough to span the gap between the legs (at the default 32
     * even the lattice that keeps every cube has no such tet, and the check could not fail) */
    d.resolution = 16;
    ak_skin_soft* soft = NULL;
    AK_CHECK_EQ(ak_skin_soft_create(&d, NULL, &soft), AK_OK);
    size_t nn = ak_skin_soft_node_count(soft), nv = c.nv;
    ak_vec3 *x = malloc(nn * sizeof(ak_vec3)), *v = malloc(nn * sizeof(ak_vec3)), *out = malloc(nv * sizeof(ak_vec3));
    ak_mat4* pal = malloc(c.ns * sizeof(ak_mat4));
    /* bind pose: the inverse binds undo the joints' bind world matrices: the palette is identity */
    for (size_t k = 0; k < c.ns; ++k) pal[k] = ak_mat4_identity();
    AK_CHECK_EQ(ak_skin_soft_state_init(soft, (ak_mat4_cspan){pal, c.ns}, (ak_vec3_span){x, nn}, (ak_vec3_span){v, nn}), AK_OK);
    AK_CHECK_EQ(ak_skin_soft_surface(soft, (ak_vec3_cspan){x, nn}, (ak_vec3_span){out, nv}), AK_OK);
    float err = 0.0f;
    for (size_t q = 0; q < nv; ++q) err = ak_maxf(err, ak_vec3_distance(out[q], c.m->positions[q]));
    AK_CHECK_MSG(err <= 1e-4f * c.diag, "bind error %g > %g", (double)err, (double)(1e-4f * c.diag));
    size_t bridges = cman_leg_bridges(&c, soft);
    d.join_distant_parts = true;
    ak_skin_soft* joined = NULL;
    AK_CHECK_EQ(ak_skin_soft_create(&d, NULL, &joined), AK_OK);
    size_t bridges_joined = joined ? cman_leg_bridges(&c, joined) : 0;
    printf("  CesiumMan: %zu nodes, %zu tets, %zu cells cut; tets bridging the legs %zu (%zu when every cell is kept)\n", nn,
           ak_skin_soft_tet_count(soft), ak_skin_soft_cut_cell_count(soft), bridges, bridges_joined);
    AK_CHECK_MSG(bridges_joined > 0, "the joined lattice should bridge the legs (the check could not fail)");
    AK_CHECK_MSG(bridges == 0, "%zu tets bridge the legs", bridges);
    free(x), free(v), free(out), free(pal);
    ak_skin_soft_destroy(soft);
    ak_skin_soft_destroy(joined);
    cman_free(&c);
}

/* 2 s of the walk at 60 Hz stay finite; distance from LBS with the limbs kept apart and joined
 * (join_distant_parts): the largest is printed, not bounded (0.10 of the diagonal: the toes of
 * the small feet, one or two cubes of the lattice); the mean must be smaller apart. */
AK_TEST(cesiumman_walk) {
    cman c;
    if (!cman_load(&c)) return;
    ak_skin_soft_desc d = cman_desc(&c);
    double mx[2], mean[2];
    size_t br[2];
    for (int joined = 0; joined < 2; ++joined) {
        d.join_distant_parts = joined;
        AK_CHECK(cman_walk(&c, &d, 120, &mx[joined], &mean[joined], &br[joined]));
    }
    printf("  CesiumMan walk 2 s, distance from LBS / diagonal %.3f: limbs apart max %.4f mean %.5f (%zu leg bridges);"
           " joined max %.4f mean %.5f (%zu)\n",
           (double)c.diag, mx[0], mean[0], br[0], mx[1], mean[1], br[1]);
    /* keeping the legs apart brings the flesh closer to the skeleton's motion on average */
    AK_CHECK_MSG(mean[0] < mean[1], "mean distance %g with the limbs apart, %g joined", mean[0], mean[1]);
    cman_free(&c);
}

/* Bind-space palette that turns the joint of `slot` and every slot below it by `angle` about
 * `axis` through the joint (the rest of the body at the bind pose). */
static void cman_flex_palette(const cman* c, int slot, ak_vec3 axis, float angle, ak_mat4* pal) {
    ak_mat4 turn = ak_mat4_mul(ak_mat4_translation(c->jp[slot]),
                               ak_mat4_mul(ak_mat4_from_quat(ak_quat_from_axis_angle(axis, angle)),
                                           ak_mat4_translation(ak_vec3_neg(c->jp[slot]))));
    for (size_t k = 0; k < c->ns; ++k) {
        bool below = false;
        for (int j = (int)k; j >= 0 && !below; j = c->par[j]) below = j == slot;
        pal[k] = below ? turn : ak_mat4_identity();
    }
}

static size_t cman_pairs(const cman* c, const ak_vec3* p) {
    size_t count = 0;
    ak_result r = ak_mesh_self_intersections((ak_vec3_cspan){p, c->nv}, (ak_u32_cspan){c->m->indices, 3 * c->m->triangle_count},
                                             (ak_u32_span){NULL, 0}, &count);
    return r == AK_OK ? count : SIZE_MAX;
}

/* The joint named `joint` (child `child` sets the limb's direction) turned to `degrees` over 20
 * frames at 60 Hz and held 1 s, with the default desc. Soft: no self-intersecting
 * triangle pair more than the bind pose has (0), while LBS and DQS interpenetrate; the enclosed
 * volume of the body (divergence theorem; CesiumMan is not closed, but its openings do not
 * move in this pose, so the change is the limb's) within 1% of the rest. */
static void cman_flex_case(const char* joint, const char* child, float degrees, double lattice_tol, double volume_tol) {
    cman c;
    if (!cman_load(&c)) return;
    int slot = cman_slot(&c, joint), cs = cman_slot(&c, child);
    AK_CHECK(slot >= 0 && cs >= 0);
    if (slot < 0 || cs < 0) {
        cman_free(&c);
        return;
    }
    /* flexion: the limb below the joint swings towards the front (+X: the toes point there)
     * and folds onto the limb above */
    ak_vec3 limb = ak_vec3_sub(c.jp[cs], c.jp[slot]);
    ak_vec3 axis = ak_vec3_normalize(ak_vec3_cross(limb, ak_vec3_make(1, 0, 0)));
    if (strstr(joint, "leg")) axis = ak_vec3_neg(axis); /* a knee folds backwards */
    ak_skin_soft_desc d = cman_desc(&c);
    /* the default desc (resolution 32, joint_zone 1.5, 40 substeps) */
    struct timespec t0, t1;
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t0);
    ak_skin_soft* soft = NULL;
    AK_CHECK_EQ(ak_skin_soft_create(&d, NULL, &soft), AK_OK);
    size_t nn = ak_skin_soft_node_count(soft), nt = ak_skin_soft_tet_count(soft), ss = ak_skin_soft_step_scratch_size(soft), nv = c.nv;
    ak_vec3 *x = malloc(nn * sizeof(ak_vec3)), *v = malloc(nn * sizeof(ak_vec3)), *out = malloc(nv * sizeof(ak_vec3));
    ak_vec3 *lbs = malloc(nv * sizeof(ak_vec3)), *dqs = malloc(nv * sizeof(ak_vec3)), *rest = malloc(nn * sizeof(ak_vec3));
    ak_mat4 *pal = malloc(c.ns * sizeof(ak_mat4)), *prev = malloc(c.ns * sizeof(ak_mat4));
    uint32_t* tt = malloc(4 * nt * sizeof(uint32_t));
    uint8_t* scratch = malloc(ss);
    cman_flex_palette(&c, slot, axis, 0.0f, pal);
    AK_CHECK_EQ(ak_skin_soft_state_init(soft, (ak_mat4_cspan){pal, c.ns}, (ak_vec3_span){x, nn}, (ak_vec3_span){v, nn}), AK_OK);
    /* the flesh moving with its skeleton, computed here from the lattice and the mesh alone:
     * each node's lumped mass (a quarter of each of its tets' rest volume times the density)
     * moving as the nearest vertex of the rest mesh skinned by LBS, differenced between frames */
    struct timespec r0, r1; /* the reference's set-up is not the step's cost: left out of ms */
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &r0);
    ak_skin_soft_rest_nodes(soft, (ak_vec3_span){rest, nn});
    ak_skin_soft_tets(soft, (ak_u32_span){tt, 4 * nt});
    double* node_mass = calloc(nn, sizeof(double));
    uint32_t* node_vertex = malloc(nn * sizeof(uint32_t));
    const double density = (double)ak_skin_soft_desc_resolved(&d).density;
    for (size_t q = 0; q < nt; ++q) {
        ak_vec3 a = rest[tt[4 * q]];
        double vol = fabs((double)ak_vec3_dot(ak_vec3_sub(rest[tt[4 * q + 1]], a),
                                              ak_vec3_cross(ak_vec3_sub(rest[tt[4 * q + 2]], a), ak_vec3_sub(rest[tt[4 * q + 3]], a)))) / 6.0;
        for (int k = 0; k < 4; ++k) node_mass[tt[4 * q + k]] += 0.25 * density * vol;
    }
    for (size_t n = 0; n < nn; ++n) {
        float best = INFINITY;
        for (size_t q = 0; q < nv; ++q) {
            float d2 = ak_vec3_length_sq(ak_vec3_sub(c.m->positions[q], rest[n]));
            if (d2 < best) best = d2, node_vertex[n] = (uint32_t)q;
        }
    }
    double ke_skeleton = 0.0; /* largest while bending */
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &r1);
    t0.tv_sec += r1.tv_sec - r0.tv_sec, t0.tv_nsec += r1.tv_nsec - r0.tv_nsec;
    float ke = 0.0f, ke_moving = 0.0f;
    /* the fastest point of the mesh moved rigidly with its bones (LBS of the rest mesh at two
     * frames, differenced; dqs holds the previous frame's LBS until the DQS below), and the
     * fastest lattice node of the soft state, over every frame */
    double skin_speed = 0.0, node_speed = 0.0;
    int node_frame = 0;
    cman_skin(&c, AK_SKIN_LBS, pal, dqs);
    /* AK_SOFT_FRAMES: bend over 20 frames and hold to that many in all (80: 1 s held) */
    const int frames = getenv("AK_SOFT_FRAMES") && atoi(getenv("AK_SOFT_FRAMES")) > 20 ? atoi(getenv("AK_SOFT_FRAMES")) : 80;
    for (int f = 1; f <= frames; ++f) {
        memcpy(prev, pal, c.ns * sizeof(ak_mat4));
        cman_flex_palette(&c, slot, axis, ak_radians(degrees) * (float)(f < 20 ? f : 20) / 20.0f, pal);
        cman_skin(&c, AK_SKIN_LBS, pal, lbs);
        for (size_t q = 0; q < nv; ++q) skin_speed = fmax(skin_speed, 60.0 * ak_vec3_distance(lbs[q], dqs[q]));
        double ke_skel = 0.0;
        for (size_t n = 0; n < nn; ++n) {
            const double sp = 60.0 * (double)ak_vec3_distance(lbs[node_vertex[n]], dqs[node_vertex[n]]);
            ke_skel += 0.5 * node_mass[n] * sp * sp;
        }
        if (f <= 20) ke_skeleton = fmax(ke_skeleton, ke_skel);
        memcpy(dqs, lbs, nv * sizeof(ak_vec3));
        ak_skin_soft_step_job job = {.soft = soft,
                                     .palette = {pal, c.ns},
                                     .previous_palette = {prev, c.ns},
                                     .node_positions = {x, nn},
                                     .node_velocities = {v, nn},
                                     .scratch = {scratch, ss},
                                     .out_positions = {out, nv},
                                     .out_kinetic_energy = &ke};
        AK_CHECK_EQ(ak_skin_soft_step_run(&job), AK_OK);
        if (f <= 20) ke_moving = ke > ke_moving ? ke : ke_moving;
        for (size_t n = 0; n < nn; ++n)
            if (ak_vec3_length(v[n]) > node_speed) node_speed = ak_vec3_length(v[n]), node_frame = f;
    }
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t1);
    const double ms = ((double)(t1.tv_sec - t0.tv_sec) * 1e3 + (double)(t1.tv_nsec - t0.tv_nsec) * 1e-6) / (double)frames;
    /* the pose is a flexion: the child joint moved to the front (arm) or the back (leg) */
    ak_vec3 tip = ak_mat4_transform_point(pal[cs], c.jp[cs]);
    AK_CHECK(strstr(joint, "leg") ? tip.x < c.jp[slot].x : tip.x > c.jp[slot].x);
    cman_skin(&c, AK_SKIN_LBS, pal, lbs);
    cman_skin(&c, AK_SKIN_DQS, pal, dqs);
    ak_u32_cspan idx = {c.m->indices, 3 * c.m->triangle_count};
    double v0 = ak_volume_compute((ak_vec3_cspan){c.m->positions, nv}, idx);
    double vs = ak_volume_compute((ak_vec3_cspan){out, nv}, idx) / v0, vl = ak_volume_compute((ak_vec3_cspan){lbs, nv}, idx) / v0,
           vd = ak_volume_compute((ak_vec3_cspan){dqs, nv}, idx) / v0;
    size_t p0 = cman_pairs(&c, c.m->positions), ps = cman_pairs(&c, out), pl = cman_pairs(&c, lbs), pd = cman_pairs(&c, dqs);
    /* lattice volume near the joint: tets with a node within the limb's length of the joint */
    double lr = 0.0, ln = 0.0, reach = ak_vec3_length(limb), jmin = INFINITY;
    for (size_t q = 0; q < nt; ++q) {
        bool near = false;
        for (int k = 0; k < 4; ++k) near = near || ak_vec3_distance(rest[tt[4 * q + k]], c.jp[slot]) < reach;
        if (!near) continue;
        const ak_vec3* X[2] = {rest, x};
        double vol[2];
        for (int k = 0; k < 2; ++k) {
            ak_vec3 a = X[k][tt[4 * q]];
            vol[k] = ak_vec3_dot(ak_vec3_sub(X[k][tt[4 * q + 1]], a),
                                 ak_vec3_cross(ak_vec3_sub(X[k][tt[4 * q + 2]], a), ak_vec3_sub(X[k][tt[4 * q + 3]], a))) / 6.0;
        }
        lr += vol[0], ln += vol[1];
        if (vol[0] > 0.0 && vol[1] / vol[0] < jmin) jmin = vol[1] / vol[0];
    }
    const double released_off = released_offset(soft, (ak_mat4_cspan){pal, c.ns}, x);
    printf("  CesiumMan %s %.0f deg: intersecting pairs soft %zu LBS %zu DQS %zu (bind %zu); volume ratio soft %.5f LBS %.5f DQS %.5f;"
           " lattice near the joint %.5f (smallest tet %.3f of its rest volume); kinetic energy held 1 s %.3g (largest while bending %.3g; the flesh moving with its skeleton %.3g); fastest node %.2f m/s (frame %d), fastest skinned vertex %.2f m/s; kinematic nodes up to %.3f m off their skinned"
           " positions; %zu nodes, %.2f ms per frame (thread CPU)\n",
           joint, (double)degrees, ps, pl, pd, p0, vs, vl, vd, lr > 0.0 ? ln / lr : 0.0, jmin, (double)ke, (double)ke_moving, ke_skeleton, node_speed,
           node_frame, skin_speed, released_off, nn, ms);
    AK_CHECK_MSG(ke < 1e-3f * ke_moving, "soft: kinetic energy %g after 1 s held (%g while bending)", (double)ke, (double)ke_moving);
    /* no node of the flesh moves faster than 3 times the fastest point of the mesh moved rigidly
     * with its bones (the flesh whips to about twice that as a bend starts at full speed). The
     * elbow at 150 deg had nodes at 18.9 m/s (6.5 times; 219 J) before the contact plane's
     * normal was made the halfway rotation of the bind bisector (issue 29, docs/softskin.md) */
    AK_CHECK_MSG(node_speed <= 3.0 * skin_speed, "soft: a node at %g m/s (frame %d), the skinned mesh at most %g m/s", node_speed,
                 node_frame, skin_speed);
    /* the flesh's largest kinetic energy while bending: at most 4 times that of the flesh moving
     * with its skeleton (each node at its nearest skinned vertex's speed, ke_skeleton): the flesh
     * may move at up to twice its bone's speed (it whips to about that as a bend starts at full
     * speed). The knees folding to 150 deg reached 54 and 59 J against 11.7 (4.6 and 5.0 times)
     * before the bone nodes beyond a joint's two bones were let go by degrees (SOFT_LET_GO, issue
     * 29: freed at once, the strain stored against them threw them off their bone) */
    AK_CHECK_MSG(ke_moving <= 4.0 * ke_skeleton, "soft: %g J while bending, the flesh moving with its skeleton %g J", (double)ke_moving,
                 ke_skeleton);
    AK_CHECK_MSG(pl > p0 && pd > p0, "LBS and DQS should interpenetrate (%zu, %zu; bind %zu)", pl, pd, p0);
    AK_CHECK_MSG(ps <= p0, "soft: %zu self-intersecting pairs (bind %zu)", ps, p0);
    AK_CHECK_MSG(fabs(vs - 1.0) < volume_tol, "soft: volume ratio %g (tolerance %g)", vs, volume_tol);
    /* the lattice volume near the joint (the flesh there, not diluted by the body): within
     * lattice_tol (the 1% at 130 deg; the elbow kept 97.3% before the cone rule) */
    AK_CHECK_MSG(lr > 0.0 && fabs(ln / lr - 1.0) < lattice_tol, "soft: lattice volume near the joint %g", lr > 0.0 ? ln / lr : 0.0);
    free(x), free(v), free(out), free(lbs), free(dqs), free(rest), free(pal), free(prev), free(tt), free(scratch);
    free(node_mass), free(node_vertex);
    ak_skin_soft_destroy(soft);
    cman_free(&c);
}

/* issue 29: lattice volume within 1%, enclosed volume within 0.5% held at 130 deg */
AK_TEST(cesiumman_knee_130) { cman_flex_case("leg_joint_L_2", "leg_joint_L_3", 130.0f, 0.01, 0.005); }
AK_TEST(cesiumman_elbow_130) { cman_flex_case("Skeleton_arm_joint_L__3_", "Skeleton_arm_joint_L__2_", 130.0f, 0.01, 0.005); }
/* issue 29: held at 140 deg the elbow rang longest (1.8e-3 of its bending energy left after 1 s
 * before the released nodes' tether; the forearm's released flesh slid up to 0.29 m from its
 * bone, docs/softskin.md) */
AK_TEST(cesiumman_elbow_140) { cman_flex_case("Skeleton_arm_joint_L__3_", "Skeleton_arm_joint_L__2_", 140.0f, 0.01, 0.005); }
/* full flexion: no self-intersecting pair (the base code had 89, LBS 97) */
AK_TEST(cesiumman_elbow_150) { cman_flex_case("Skeleton_arm_joint_L__3_", "Skeleton_arm_joint_L__2_", 150.0f, 0.01, 0.005); }
/* issue 29, the knees folded: the heel and calf against the thigh and buttock (before the
 * contact beyond the joint's two bones: 56, 81 and 44 pairs; LBS 118, 102, 120). The 1%
 * on the enclosed volume too (LBS loses 1.2-1.3% there) */
AK_TEST(cesiumman_knee_140) { cman_flex_case("leg_joint_L_2", "leg_joint_L_3", 140.0f, 0.01, 0.01); }
AK_TEST(cesiumman_knee_150) { cman_flex_case("leg_joint_L_2", "leg_joint_L_3", 150.0f, 0.01, 0.01); }
AK_TEST(cesiumman_right_knee_140) { cman_flex_case("leg_joint_R_2", "leg_joint_R_3", 140.0f, 0.01, 0.01); }
/* the knees' kinetic-energy peak at full fold (issue 29): 59 J, 5.0 times the flesh moving with
 * its skeleton, before SOFT_LET_GO */
AK_TEST(cesiumman_right_knee_150) { cman_flex_case("leg_joint_R_2", "leg_joint_R_3", 150.0f, 0.01, 0.01); }

/* the default desc (resolution 32, 40 substeps, the default free zone around the joint) */
AK_TEST(bend_120_keeps_volume) { bend_case(120.0f, 0, true); }
AK_TEST(bend_150_keeps_volume) { bend_case(150.0f, 0, true); }

int main(void) {
    /* AK_SOFT_FLEX=JOINT:CHILD:DEGREES runs that CesiumMan flexion alone (the measurements of
     * docs/softskin.md at other angles; its checks are the 130 deg ones, failures expected) */
    const char* flex = getenv("AK_SOFT_FLEX");
    if (flex) {
        char joint[128], child[128];
        float degrees = 0.0f;
        if (sscanf(flex, "%127[^:]:%127[^:]:%f", joint, child, &degrees) != 3) return 2;
        ak_test_cur_name_ = "flex";
        cman_flex_case(joint, child, degrees, 0.01, 0.005);
        return ak_test_finish();
    }
    /* AK_SOFT_BEND=DEGREES runs builtin:cylinder's bend to that angle alone (default desc) */
    const char* bend = getenv("AK_SOFT_BEND");
    if (bend) {
        ak_test_cur_name_ = "bend";
        bend_case((float)atof(bend), 0, true);
        return ak_test_finish();
    }
    AK_RUN(bind_pose_reproduces_the_mesh);
    AK_RUN(held_pose_converges_and_keeps_volume);
    AK_RUN(threads_give_identical_results);
    AK_RUN(bad_input_gets_clear_errors);
    AK_RUN_SLOW(bend_120_keeps_volume);
    AK_RUN_SLOW(bend_150_keeps_volume);
    AK_RUN_SLOW(twist_180_does_not_collapse);
    AK_RUN(cesiumman_bind_and_legs_apart);
    AK_RUN_SLOW(cesiumman_walk);
    AK_RUN_SLOW(cesiumman_knee_130);
    AK_RUN_SLOW(cesiumman_elbow_130);
    AK_RUN_SLOW(cesiumman_elbow_140);
    AK_RUN_SLOW(cesiumman_elbow_150);
    AK_RUN_SLOW(cesiumman_knee_140);
    AK_RUN_SLOW(cesiumman_knee_150);
    AK_RUN_SLOW(cesiumman_right_knee_140);
    AK_RUN_SLOW(cesiumman_right_knee_150);
    return ak_test_finish();
}

/* Crowd characters (crowd.h, "characters"): the walk clip measured, clip time following the
 * distance walked, heading, idle, and foot sliding measured in the world. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <animkit/animkit.h>

#include "ak_test.h"

/* One humanoid for every case (built once: valgrind runs these cases too). Its mesh only
 * matters to bake_scene: coarse is quick. */
static ak_scene* g_humanoid;

static ak_scene* humanoid(void) {
    if (!g_humanoid) {
        ak_builtin_desc bd = {.cell_size = 0.1f};
        if (ak_builtin_create("builtin:humanoid", &bd, NULL, &g_humanoid) != AK_OK) return NULL;
    }
    return g_humanoid;
}

static bool gait_of(const ak_scene* sc, ak_crowd_gait* g) {
    ak_crowd_gait_desc d = {.scene = sc, .clip_index = ak_scene_find_clip(sc, "walk")};
    ak_diag diag;
    const ak_result r = ak_crowd_gait_measure(&d, NULL, g, &diag);
    if (r != AK_OK) fprintf(stderr, "gait: %s\n", diag.message);
    return r == AK_OK;
}

/* World positions of the two feet of a character at ground position p. */
static void feet_world(const ak_crowd_gait* g, const ak_crowd_character* c, ak_vec2 p, ak_transform* local,
                       ak_mat4* world, size_t n, ak_vec3 out[2]) {
    ak_crowd_character_pose(g, c, (ak_transform_span){local, n});
    ak_scene_world_matrices(g->scene, (ak_transform_cspan){local, n}, (ak_mat4_span){world, n});
    const ak_mat4 root = ak_crowd_character_root(g, c, p);
    for (int f = 0; f < 2; ++f)
        out[f] = ak_mat4_transform_point(root, ak_mat4_get_translation(world[g->feet[f]]));
}

/* How the clip time is chosen in a sliding run. */
typedef enum { TIME_GAIT, TIME_RATE_ONE, TIME_CONSTANT_RATE, TIME_SHARED } time_mode;
static uint32_t g_phase_buckets = AK_CROWD_PHASE_BUCKETS; /* TIME_SHARED: the gait's time, posed by bucket */

/* The agent's path: a straight line at speed along dir, or a circle of radius R. */
typedef struct path {
    float speed;
    ak_vec2 dir;
    float radius; /* 0 -> straight */
} path;

static ak_vec2 path_pos(const path* pa, float t) {
    if (pa->radius <= 0.0f) return ak_vec2_scale(pa->dir, pa->speed * t);
    const float a = pa->speed * t / pa->radius;
    return ak_vec2_make(pa->radius * cosf(a), pa->radius * sinf(a));
}
static ak_vec2 path_vel(const path* pa, float t) {
    if (pa->radius <= 0.0f) return ak_vec2_scale(pa->dir, pa->speed);
    const float a = pa->speed * t / pa->radius;
    return ak_vec2_make(-pa->speed * sinf(a), pa->speed * cosf(a));
}

/* Walk the path for seconds and measure foot sliding independently of the gait's own notion of
 * stance: a foot is in stance while its world height is within stance_band of the lowest height
 * it reaches over the run (after the first second); over each stance the largest horizontal
 * distance from where the stance began is its slide. Returns the largest slide (m). */
static double max_slide(const ak_crowd_gait* g, const path* pa, time_mode mode, float seconds, float stance_band,
                        int* out_stances, double* out_along) {
    const size_t n = ak_scene_joint_count(g->scene);
    ak_transform* local = malloc(n * sizeof *local);
    ak_mat4* world = malloc(n * sizeof *world);
    const float dt = 1.0f / 120.0f;
    const int steps = (int)(seconds / dt);
    ak_vec3(*feet)[2] = malloc((size_t)steps * sizeof *feet);
    ak_crowd_character c = ak_crowd_character_init(g, path_vel(pa, 0.0f), 0.0f);
    c.walk_weight = 1.0f;
    for (int s = 0; s < steps; ++s) {
        const float t = dt * (float)(s + 1);
        ak_vec2 v = path_vel(pa, t);
        ak_crowd_characters_job job = {.gait = g, .dt = dt, .velocities = {&v, 1}, .characters = {&c, 1}};
        AK_CHECK_EQ(ak_crowd_characters_update(&job), AK_OK);
        if (mode == TIME_RATE_ONE) c.clip_time = fmodf(t, g->duration);
        if (mode == TIME_CONSTANT_RATE) c.clip_time = fmodf(t * pa->speed / g->stride_speed, g->duration);
        ak_crowd_character q = c;
        if (mode == TIME_SHARED) ak_crowd_character_bucket(g, &c, g_phase_buckets, AK_CROWD_WEIGHT_LEVELS, &q);
        feet_world(g, &q, path_pos(pa, t), local, world, n, feet[s]);
    }
    const int skip = (int)(1.0f / dt);
    double worst = 0.0, along = 0.0;
    int stances = 0;
    for (int f = 0; f < 2; ++f) {
        float low = INFINITY;
        for (int s = skip; s < steps; ++s) low = fminf(low, feet[s][f].y);
        int start = -1;
        for (int s = skip; s < steps; ++s) {
            const bool st = feet[s][f].y <= low + stance_band;
            if (st && start < 0) start = s, ++stances;
            if (!st) start = -1;
            if (start >= 0) {
                const double dx = feet[s][f].x - feet[start][f].x, dz = feet[s][f].z - feet[start][f].z;
                worst = fmax(worst, sqrt(dx * dx + dz * dz));
                along = fmax(along, fabs(dx * pa->dir.x + dz * pa->dir.y));
            }
        }
    }
    free(local);
    free(world);
    free(feet);
    if (out_stances) *out_stances = stances;
    if (out_along) *out_along = along;
    return worst;
}

/* ---- cases ---------------------------------------------------------------------------------- */

AK_TEST(gait_of_builtin_walk) {
    ak_scene* sc = humanoid();
    AK_CHECK(sc);
    if (!sc) return;
    ak_crowd_gait g;
    AK_CHECK(gait_of(sc, &g));
    /* The automatic feet are the ankles (the lowest joints of each side). */
    AK_CHECK_STREQ(ak_skeleton_joint_name(sc->skeleton, (size_t)g.feet[0]), "left_ankle");
    AK_CHECK_STREQ(ak_skeleton_joint_name(sc->skeleton, (size_t)g.feet[1]), "right_ankle");
    /* builtin.h: the humanoid faces +z. */
    AK_CHECK_NEAR(g.forward.x, 0.0f, 0.02f);
    AK_CHECK_NEAR(g.forward.z, 1.0f, 1e-3f);
    AK_CHECK_NEAR(g.duration, 1.0f, 1e-6f);
    /* Reference: the stance foot's backward travel, sampled 16x finer than the gait's table
     * with the forward axis builtin.h states (+z); the lower ankle at each sample is in stance. */
    const size_t n = ak_scene_joint_count(sc);
    ak_mat4* w = malloc(n * sizeof *w);
    ak_transform* l = malloc(n * sizeof *l);
    const int la = ak_skeleton_find_joint(sc->skeleton, "left_ankle"), ra = ak_skeleton_find_joint(sc->skeleton, "right_ankle");
    double travel = 0.0, prev_z[2] = {0, 0};
    for (int k = 0; k <= 4096; ++k) {
        ak_scene_rest_pose(sc, (ak_transform_span){l, n});
        ak_clip_sample(sc->clips[ak_scene_find_clip(sc, "walk")], (float)k / 4096.0f, NULL, (ak_transform_span){l, n},
                       (ak_f32_span){0}, (ak_f32_span){0});
        ak_scene_world_matrices(sc, (ak_transform_cspan){l, n}, (ak_mat4_span){w, n});
        const ak_vec3 a = ak_mat4_get_translation(w[la]), b = ak_mat4_get_translation(w[ra]);
        const int f = a.y <= b.y ? 0 : 1;
        const double z = f ? b.z : a.z;
        if (k > 0 && z < prev_z[f]) travel += prev_z[f] - z;
        prev_z[0] = a.z, prev_z[1] = b.z;
    }
    free(w);
    free(l);
    printf("  stride %.4f m per cycle (reference %.4f), stride speed %.3f m/s\n", (double)g.stride_length, travel,
           (double)g.stride_speed);
    AK_CHECK_MSG(fabs(g.stride_length - travel) < 0.01 * travel, "stride %g vs %g", (double)g.stride_length, travel);
    AK_CHECK_NEAR(g.stride_speed, g.stride_length / g.duration, 1e-6f);
    /* The table inverts: distance[k] maps back to sample k's time where the foot moves. */
    int checked = 0;
    for (unsigned k = 0; k < AK_CROWD_GAIT_SAMPLES; ++k) {
        if (!(g.distance[k + 1] > g.distance[k])) continue;
        const float mid = 0.5f * (g.distance[k] + g.distance[k + 1]);
        const float t = ak_crowd_gait_clip_time(&g, mid), expect_t = g.duration * ((float)k + 0.5f) / AK_CROWD_GAIT_SAMPLES;
        AK_CHECK_NEAR(t, expect_t, 1e-4f);
        ++checked;
    }
    AK_CHECK(checked > (int)AK_CROWD_GAIT_SAMPLES / 2);
    /* Periodic: a whole stride later, the same time. */
    AK_CHECK_NEAR(ak_crowd_gait_clip_time(&g, 0.3f), ak_crowd_gait_clip_time(&g, 0.3f + 2.0f * g.stride_length), 1e-4f);
    AK_CHECK_EQ(ak_crowd_gait_clip_time(&g, NAN), 0.0f);
}

/* The acceptance test: a foot in stance moves < 2 cm in the world. It can fail: the same run
 * with the clip at rate 1, or at the mean rate speed / stride_speed without the distance
 * table, slides by decimetres. */
AK_TEST(foot_sliding_straight) {
    ak_scene* sc = humanoid();
    AK_CHECK(sc);
    if (!sc) return;
    ak_crowd_gait g;
    AK_CHECK(gait_of(sc, &g));
    const float speeds[3] = {0.7f, 1.3f, 1.9f};
    for (int k = 0; k < 3; ++k) {
        const float l = sqrtf(1.0f + 0.36f);
        const path pa = {speeds[k], {1.0f / l, 0.6f / l}, 0.0f};
        int stances = 0;
        double along = 0.0, along2 = 0.0;
        const float secs = 1.0f + 3.05f * g.stride_length / speeds[k]; /* 1 s, then three cycles */
        const double slide = max_slide(&g, &pa, TIME_GAIT, secs, 0.01f, &stances, &along);
        const double slide2 = max_slide(&g, &pa, TIME_GAIT, secs, 0.02f, NULL, &along2);
        const double one = max_slide(&g, &pa, TIME_RATE_ONE, secs, 0.01f, NULL, NULL);
        const double constant = max_slide(&g, &pa, TIME_CONSTANT_RATE, secs, 0.01f, NULL, NULL);
        /* shared poses (ak_crowd_character_bucket): the clip time quantised adds a sawtooth
         * along the path; AK_CROWD_PHASE_BUCKETS keeps the slide under 2 cm, 32 would not */
        double shared_along = 0.0, shared_along32 = 0.0;
        const double shared = max_slide(&g, &pa, TIME_SHARED, secs, 0.01f, NULL, &shared_along);
        g_phase_buckets = 32;
        const double shared32 = max_slide(&g, &pa, TIME_SHARED, secs, 0.01f, NULL, &shared_along32);
        g_phase_buckets = AK_CROWD_PHASE_BUCKETS;
        printf("  shared poses: %u buckets %.2f cm (along %.2f cm); 32 buckets %.2f cm (along %.2f cm)\n",
               AK_CROWD_PHASE_BUCKETS, 100 * shared, 100 * shared_along, 100 * shared32, 100 * shared_along32);
        AK_CHECK_MSG(shared < 0.02, "%.1f m/s: shared poses slide %.2f cm", (double)speeds[k], 100 * shared);
        AK_CHECK_MSG(shared32 > 0.02, "32 buckets should slide (%.2f cm)", 100 * shared32);
        printf("  %.1f m/s: %d stances, slide %.2f cm (along the path %.2f cm); 2 cm band: %.2f cm (along %.2f cm); "
               "rate 1: %.1f cm; constant rate: %.1f cm\n",
               (double)speeds[k], stances, 100 * slide, 100 * along, 100 * slide2, 100 * along2, 100 * one,
               100 * constant);
        AK_CHECK(stances >= 6);
        AK_CHECK_MSG(slide < 0.02, "%.1f m/s: a stance foot slides %.2f cm", (double)speeds[k], 100 * slide);
        AK_CHECK_MSG(one > 0.02, "rate 1 should slide at %.1f m/s (%.2f cm)", (double)speeds[k], 100 * one);
        AK_CHECK_MSG(constant > 0.02, "the constant mean rate should slide (%.2f cm)", 100 * constant);
    }
}

/* Turning on a circle of 4 m radius: the heading follows the velocity. */
AK_TEST(turning_and_idle) {
    ak_scene* sc = humanoid();
    AK_CHECK(sc);
    if (!sc) return;
    ak_crowd_gait g;
    AK_CHECK(gait_of(sc, &g));
    const path pa = {1.3f, {0, 0}, 4.0f};
    const double slide = max_slide(&g, &pa, TIME_GAIT, 4.0f, 0.01f, NULL, NULL);
    printf("  circle r = 4 m at 1.3 m/s: slide %.2f cm\n", 100 * slide);
    /* The root turns under the planted foot (0.33 rad/s here) and the heading lags the
     * velocity by about omega * turn_time: measured 3.1 cm, bounded at 4 cm. */
    AK_CHECK_MSG(slide < 0.04, "turning: %.2f cm", 100 * slide);
    /* The heading converges to the velocity's direction (smoothing only, no lag left). */
    ak_crowd_character c = ak_crowd_character_init(&g, ak_vec2_make(1, 0), 0.25f);
    AK_CHECK_NEAR(c.heading.x, 1.0f, 1e-6f);
    ak_vec2 v = {0.0f, -1.2f};
    ak_crowd_characters_job job = {.gait = &g, .dt = 0.05f, .velocities = {&v, 1}, .characters = {&c, 1}};
    AK_CHECK_EQ(ak_crowd_characters_update(&job), AK_OK);
    /* one step turns by at most max_turn_rate * dt (6 rad/s default) */
    AK_CHECK(atan2f(-c.heading.y, c.heading.x) <= 0.3f + 1e-5f);
    for (int s = 0; s < 40; ++s) ak_crowd_characters_update(&job);
    AK_CHECK_NEAR(c.heading.x, 0.0f, 1e-3f);
    AK_CHECK_NEAR(c.heading.y, -1.0f, 1e-3f);
    AK_CHECK_NEAR(c.walk_weight, 1.0f, 1e-6f);
    /* The root matrix turns the model's forward (+z) onto the heading and stands on p. */
    const ak_mat4 m = ak_crowd_character_root(&g, &c, ak_vec2_make(2, 3));
    const ak_vec3 f = ak_mat4_transform_vector(m, g.forward), o = ak_mat4_transform_point(m, ak_vec3_zero());
    AK_CHECK_NEAR(f.x, c.heading.x, 1e-5f);
    AK_CHECK_NEAR(f.z, c.heading.y, 1e-5f);
    AK_CHECK_NEAR(o.x, 2.0f, 1e-6f);
    AK_CHECK_NEAR(o.z, 3.0f, 1e-6f);
    /* Stopped: the clip freezes, the heading stays, the pose is the rest pose. */
    const ak_vec2 h = c.heading;
    const float t = c.clip_time;
    v = ak_vec2_make(0, 0);
    AK_CHECK_EQ(ak_crowd_characters_update(&job), AK_OK);
    AK_CHECK_EQ(c.walk_weight, 0.0f);
    AK_CHECK_EQ(c.clip_time, t);
    AK_CHECK_EQ(c.heading.x, h.x);
    AK_CHECK_EQ(c.heading.y, h.y);
    const size_t n = ak_scene_joint_count(sc);
    ak_transform* local = malloc(n * sizeof *local);
    AK_CHECK_EQ(ak_crowd_character_pose(&g, &c, (ak_transform_span){local, n}), AK_OK);
    const ak_transform_cspan rest = ak_skeleton_rest_pose(sc->skeleton);
    AK_CHECK(memcmp(local, rest.ptr, n * sizeof *local) == 0);
    /* Half the idle speed: halfway (smoothstep(0.5) = 0.5) between rest and walk. */
    v = ak_vec2_make(0.075f, 0);
    ak_crowd_characters_update(&job);
    AK_CHECK_NEAR(c.walk_weight, 0.5f, 1e-6f);
    free(local);
}

/* Skinned positions of the character's mesh (model space), by a naive LBS written here in
 * double: sum over influences of weight x (joint world x inverse bind) x rest vertex. */
static void skin_naive(const ak_crowd_gait* g, const ak_crowd_character* c, ak_transform* local, ak_mat4* world,
                       size_t n, double* out /* [3 * vertex_count] */) {
    const ak_scene* sc = g->scene;
    const ak_mesh* m = sc->meshes[0].mesh;
    const ak_scene_skin* sk = &sc->skins[sc->meshes[0].skin];
    ak_crowd_character_pose(g, c, (ak_transform_span){local, n});
    ak_scene_world_matrices(sc, (ak_transform_cspan){local, n}, (ak_mat4_span){world, n});
    for (size_t v = 0; v < m->vertex_count; ++v) {
        double acc[3] = {0, 0, 0};
        const ak_vec3 p = m->positions[v];
        for (uint32_t k = 0; k < m->influence_count; ++k) {
            const double w = m->weights[v * m->influence_count + k];
            if (w == 0.0) continue;
            const uint16_t slot = m->joints[v * m->influence_count + k];
            const ak_mat4 M = ak_mat4_mul(world[sk->joints[slot]], sk->inverse_binds[slot]);
            const double q[3] = {p.x, p.y, p.z};
            for (int r = 0; r < 3; ++r) {
                double x = M.m[12 + r]; /* column-major */
                for (int cc = 0; cc < 3; ++cc) x += (double)M.m[4 * cc + r] * q[cc];
                acc[r] += w * x;
            }
        }
        for (int r = 0; r < 3; ++r) out[3 * v + r] = acc[r];
    }
}

/* Shared poses (ak_crowd_character_bucket): a walking character's bucket pose is within the
 * documented phase error of its exact pose: every skinned vertex within (largest vertex speed
 * in the clip, measured here by finite differences over 1,024 samples) x (duration / (2 x
 * AK_CROWD_PHASE_BUCKETS)), with 10% for the sampling of that speed. Also: the bucket index is
 * in range and determines the snapped pose; weights round to the nearest level. */
AK_TEST(shared_pose_phase_error) {
    ak_crowd_gait g;
    AK_CHECK(gait_of(humanoid(), &g));
    const ak_mesh* m = g.scene->meshes[0].mesh;
    const size_t n = ak_scene_joint_count(g.scene), V = m->vertex_count;
    AK_CHECK(m->influence_count > 0 && g.scene->meshes[0].skin >= 0);
    ak_transform* local = malloc(n * sizeof *local);
    ak_mat4* world = malloc(n * sizeof *world);
    double *a = malloc(3 * V * sizeof *a), *b = malloc(3 * V * sizeof *b);
    const int S = 1024;
    double vmax = 0.0;
    ak_crowd_character c = ak_crowd_character_init(&g, ak_vec2_make(0, 1), 0.0f);
    c.walk_weight = 1.0f;
    c.clip_time = 0.0f;
    skin_naive(&g, &c, local, world, n, a);
    for (int k = 1; k <= S; ++k) {
        c.clip_time = g.duration * (float)k / (float)S;
        skin_naive(&g, &c, local, world, n, b);
        for (size_t v = 0; v < V; ++v) {
            const double d = sqrt((a[3 * v] - b[3 * v]) * (a[3 * v] - b[3 * v]) +
                                  (a[3 * v + 1] - b[3 * v + 1]) * (a[3 * v + 1] - b[3 * v + 1]) +
                                  (a[3 * v + 2] - b[3 * v + 2]) * (a[3 * v + 2] - b[3 * v + 2]));
            vmax = fmax(vmax, d / (g.duration / S));
        }
        double* t = a;
        a = b;
        b = t;
    }
    const double bound = 1.1 * vmax * g.duration / (2.0 * AK_CROWD_PHASE_BUCKETS) + 1e-5;
    const size_t count = ak_crowd_character_bucket_count(AK_CROWD_PHASE_BUCKETS, AK_CROWD_WEIGHT_LEVELS);
    AK_CHECK_EQ(count, 1u + 3u * AK_CROWD_PHASE_BUCKETS);
    double worst = 0.0;
    uint32_t rng = 12345u;
    for (int trial = 0; trial < 64; ++trial) {
        rng = rng * 1664525u + 1013904223u;
        ak_crowd_character e = ak_crowd_character_init(&g, ak_vec2_make(1, 0), 0.0f), q;
        e.walk_weight = 1.0f;
        e.clip_time = g.duration * (float)(rng >> 8) / 16777216.0f;
        const size_t k = ak_crowd_character_bucket(&g, &e, AK_CROWD_PHASE_BUCKETS, AK_CROWD_WEIGHT_LEVELS, &q);
        AK_CHECK(k >= 1 && k < count);
        AK_CHECK_EQ(q.walk_weight, 1.0f);
        /* the bucket's pose is the clip at the bucket's phase: its index says which */
        const double tq = (double)g.duration * (double)((k - 1) % AK_CROWD_PHASE_BUCKETS) / AK_CROWD_PHASE_BUCKETS;
        AK_CHECK(fabs(q.clip_time - tq) < 1e-6);
        skin_naive(&g, &e, local, world, n, a);
        skin_naive(&g, &q, local, world, n, b);
        for (size_t v = 0; v < 3 * V; v += 3) {
            const double d = sqrt((a[v] - b[v]) * (a[v] - b[v]) + (a[v + 1] - b[v + 1]) * (a[v + 1] - b[v + 1]) +
                                  (a[v + 2] - b[v + 2]) * (a[v + 2] - b[v + 2]));
            worst = fmax(worst, d);
        }
    }
    printf("shared poses: largest vertex speed %.3f m/s, bound %.2f cm, worst of 64 random phases %.2f cm\n", vmax,
           100.0 * bound, 100.0 * worst);
    AK_CHECK(worst <= bound);
    AK_CHECK(worst > 0.25 * bound); /* the measure sees the quantisation at all */
    /* weights: nearest of 0, 1/3, 2/3, 1; 0 is one bucket whatever the phase */
    ak_crowd_character e = ak_crowd_character_init(&g, ak_vec2_make(1, 0), 0.3f), q;
    e.walk_weight = 0.1f;
    AK_CHECK_EQ(ak_crowd_character_bucket(&g, &e, AK_CROWD_PHASE_BUCKETS, AK_CROWD_WEIGHT_LEVELS, &q), 0u);
    AK_CHECK_EQ(q.walk_weight, 0.0f);
    e.walk_weight = 0.6f;
    AK_CHECK(ak_crowd_character_bucket(&g, &e, AK_CROWD_PHASE_BUCKETS, AK_CROWD_WEIGHT_LEVELS, &q) >=
             1u + AK_CROWD_PHASE_BUCKETS);
    AK_CHECK(fabsf(q.walk_weight - 2.0f / 3.0f) < 1e-6f);
    e.clip_time = g.duration * 0.999f; /* the cycle's end is its start */
    e.walk_weight = 1.0f;
    AK_CHECK_EQ(ak_crowd_character_bucket(&g, &e, AK_CROWD_PHASE_BUCKETS, AK_CROWD_WEIGHT_LEVELS, &q),
                1u + 2u * AK_CROWD_PHASE_BUCKETS);
    AK_CHECK_EQ(q.clip_time, 0.0f);
    AK_CHECK_EQ(ak_crowd_character_bucket(NULL, &e, 32, 4, &q), SIZE_MAX);
    AK_CHECK_EQ(ak_crowd_character_bucket(&g, &e, 0, 4, &q), SIZE_MAX);
    AK_CHECK_EQ(ak_crowd_character_bucket(&g, &e, 32, 1, &q), SIZE_MAX);
    AK_CHECK_EQ(ak_crowd_character_bucket_count(32, 1), 0u);
    free(local);
    free(world);
    free(a);
    free(b);
}

AK_TEST(validation) {
    ak_scene* sc = humanoid();
    AK_CHECK(sc);
    if (!sc) return;
    ak_crowd_gait g;
    ak_diag diag;
    AK_CHECK_EQ(ak_crowd_gait_measure(NULL, NULL, &g, &diag), AK_ERR_NULL_ARG);
    ak_crowd_gait_desc d = {.scene = sc, .clip_index = 7};
    AK_CHECK_EQ(ak_crowd_gait_measure(&d, NULL, &g, &diag), AK_ERR_BAD_INDEX);
    d.clip_index = ak_scene_find_clip(sc, "walk");
    d.left_foot = 3, d.right_foot = 3;
    AK_CHECK_EQ(ak_crowd_gait_measure(&d, NULL, &g, &diag), AK_ERR_BAD_INDEX);
    /* the wave clip does not walk: its feet do not move */
    d = (ak_crowd_gait_desc){.scene = sc, .clip_index = ak_scene_find_clip(sc, "wave")};
    AK_CHECK_EQ(ak_crowd_gait_measure(&d, NULL, &g, &diag), AK_ERR_BAD_DATA);
    AK_CHECK(strstr(diag.message, "not a walk") != NULL);
    AK_CHECK(gait_of(sc, &g));
    ak_crowd_character c = ak_crowd_character_init(&g, ak_vec2_make(NAN, 0), 0.5f);
    AK_CHECK_EQ(c.heading.y, 1.0f);
    ak_vec2 v = {NAN, 0};
    ak_crowd_characters_job job = {.gait = &g, .dt = 0.1f, .velocities = {&v, 1}, .characters = {&c, 1}};
    const ak_crowd_character before = c;
    AK_CHECK_EQ(ak_crowd_characters_update(&job), AK_ERR_BAD_DATA);
    AK_CHECK(memcmp(&before, &c, sizeof c) == 0);
    v.x = 1;
    job.dt = 0;
    AK_CHECK_EQ(ak_crowd_characters_update(&job), AK_ERR_BAD_ARG);
    job.dt = 0.1f;
    job.turn_time = -1;
    AK_CHECK_EQ(ak_crowd_characters_update(&job), AK_ERR_BAD_ARG);
    job.turn_time = 0;
    job.velocities.count = 0;
    AK_CHECK_EQ(ak_crowd_characters_update(&job), AK_ERR_SPAN_SMALL);
    job.gait = NULL;
    AK_CHECK_EQ(ak_crowd_characters_update(&job), AK_ERR_NULL_ARG);
    ak_transform one;
    AK_CHECK_EQ(ak_crowd_character_pose(&g, &c, (ak_transform_span){&one, 1}), AK_ERR_SPAN_SMALL);
}

/* ak_crowd_bake_scene: every agent's joints in the baked scene, posed by its clip at frame k,
 * sit where the character's own forward kinematics, placed by the root matrix, puts them. */
/* The largest distance between a baked (or read-back) crowd's joints, posed by its clip at every
 * frame, and where each agent's character puts them by its own FK placed under the agent's root
 * matrix. via_skins false: agent a's joint j is node a * (J + 1) + 1 + j (the bake's layout);
 * true: the joints are found through each agent's skin, whose names must be "a/<joint>"
 * (mismatches counted in *misnamed). *checked counts the joints compared. */
static double baked_joint_error(const ak_crowd_gait* g, const ak_scene* sc, const ak_scene* rd,
                                const ak_crowd_character* ch, const ak_vec2* pos, int N, int F, bool via_skins,
                                size_t* checked, size_t* misnamed) {
    const size_t J = ak_scene_joint_count(sc), n = ak_scene_joint_count(rd);
    const ak_scene_skin* cskin = &sc->skins[0];
    ak_transform* lb = malloc(n * sizeof *lb);
    ak_mat4* wb = malloc(n * sizeof *wb);
    ak_transform* lc = malloc(J * sizeof *lc);
    ak_mat4* wc = malloc(J * sizeof *wc);
    double worst = 0.0;
    *checked = *misnamed = 0;
    for (int f = 0; lb && wb && lc && wc && f < F; ++f) {
        ak_scene_rest_pose(rd, (ak_transform_span){lb, n});
        ak_clip_sample(rd->clips[0], 0.1f * (float)f, NULL, (ak_transform_span){lb, n}, (ak_f32_span){0},
                       (ak_f32_span){0});
        ak_scene_world_matrices(rd, (ak_transform_cspan){lb, n}, (ak_mat4_span){wb, n});
        for (int a = 0; a < N; ++a) {
            ak_crowd_character_pose(g, &ch[f * N + a], (ak_transform_span){lc, J});
            ak_scene_world_matrices(sc, (ak_transform_cspan){lc, J}, (ak_mat4_span){wc, J});
            const ak_mat4 root = ak_crowd_character_root(g, &ch[f * N + a], pos[f * N + a]);
            const ak_scene_skin* sk = &rd->skins[a];
            if (via_skins && sk->joint_count != cskin->joint_count) {
                ++*misnamed;
                continue;
            }
            const size_t count = via_skins ? sk->joint_count : J;
            for (size_t k = 0; k < count; ++k) {
                const size_t cj = via_skins ? (size_t)cskin->joints[k] : k;
                const size_t bj = via_skins ? (size_t)sk->joints[k] : (size_t)a * (J + 1) + 1 + k;
                if (via_skins && f == 0) {
                    char want_name[AK_NAME_SIZE];
                    snprintf(want_name, sizeof want_name, "%d/%s", a, ak_skeleton_joint_name(sc->skeleton, cj));
                    *misnamed += strcmp(ak_skeleton_joint_name(rd->skeleton, bj), want_name) != 0;
                }
                const ak_vec3 want = ak_mat4_transform_point(root, ak_mat4_get_translation(wc[cj]));
                const ak_vec3 got = ak_mat4_get_translation(wb[bj]);
                worst = fmax(worst, (double)ak_vec3_length(ak_vec3_sub(want, got)));
                ++*checked;
            }
        }
    }
    free(lb), free(wb), free(lc), free(wc);
    return worst;
}

AK_TEST(bake_scene) {
    ak_scene* sc = humanoid();
    AK_CHECK(sc);
    if (!sc) return;
    ak_crowd_gait g;
    AK_CHECK(gait_of(sc, &g));
    enum { N = 3, F = 5 };
    ak_vec2 pos[F * N];
    ak_crowd_character ch[F * N];
    for (int a = 0; a < N; ++a) {
        ak_crowd_character c = ak_crowd_character_init(&g, ak_vec2_make(1, (float)a), 0.3f * (float)a);
        ak_vec2 v = ak_vec2_make(1.2f, 0.4f * (float)(a - 1));
        ak_crowd_characters_job job = {.gait = &g, .dt = 0.1f, .velocities = {&v, 1}, .characters = {&c, 1}};
        for (int f = 0; f < F; ++f) {
            pos[f * N + a] = ak_vec2_make(0.12f * (float)f + 2.0f * (float)a, 0.04f * (float)f * (float)(a - 1));
            ch[f * N + a] = c;
            ak_crowd_characters_update(&job);
        }
    }
    ak_crowd_bake_desc bd = {.gait = &g, .agent_count = N, .frame_count = F, .positions = pos, .characters = ch,
                             .frame_time = 0.1f};
    ak_scene* baked = NULL;
    ak_diag diag;
    AK_CHECK_EQ(ak_crowd_bake_scene(&bd, NULL, &baked, &diag), AK_OK);
    if (!baked) return;
    const size_t J = ak_scene_joint_count(sc), n = ak_scene_joint_count(baked);
    AK_CHECK_EQ(n, (size_t)N * (J + 1));
    AK_CHECK_EQ(baked->mesh_count, (size_t)N * sc->mesh_count);
    AK_CHECK_EQ(baked->skin_count, (size_t)N * sc->skin_count);
    AK_CHECK_EQ(baked->clip_count, 1u);
    AK_CHECK_NEAR(ak_clip_duration(baked->clips[0]), 0.4f, 1e-6f);
    size_t checked, misnamed;
    const double worst = baked_joint_error(&g, sc, baked, ch, pos, N, F, false, &checked, &misnamed);
    printf("  baked joints vs the characters' own: %.2g m at most\n", worst);
    AK_CHECK(worst < 1e-4);
    AK_CHECK_EQ(checked, (size_t)N * F * J);
    /* each skin names its agent's joints */
    AK_CHECK_EQ(baked->skins[N - 1].joints[0], (int32_t)((N - 1) * (J + 1) + 1) + sc->skins[0].joints[0]);
    ak_scene_destroy(baked);
    /* errors, checked before allocating */
    bd.memory_budget = 1000;
    AK_CHECK_EQ(ak_crowd_bake_scene(&bd, NULL, &baked, &diag), AK_ERR_UNSUPPORTED);
    AK_CHECK(baked == NULL && strstr(diag.message, "budget") != NULL);
    /* ak_crowd_bake_max_frames agrees with the check: at every budget where it allows 1..4
     * frames, that many bake and one more is refused (budget), nothing allocated */
    size_t seen = 0;
    for (size_t b = 100000; b < 4000000 && seen < 4; b += 512) {
        const size_t fit = ak_crowd_bake_max_frames(&g, N, b);
        if (fit == 0 || fit > 4 || fit == seen) continue;
        seen = fit;
        bd.memory_budget = b;
        bd.frame_count = fit;
        AK_CHECK_EQ(ak_crowd_bake_scene(&bd, NULL, &baked, &diag), AK_OK);
        ak_scene_destroy(baked);
        bd.frame_count = fit + 1;
        AK_CHECK_EQ(ak_crowd_bake_scene(&bd, NULL, &baked, &diag), AK_ERR_UNSUPPORTED);
        AK_CHECK(baked == NULL && strstr(diag.message, "budget") != NULL);
    }
    AK_CHECK_EQ(seen, 4u);
    bd.frame_count = F;
    AK_CHECK_EQ(ak_crowd_bake_max_frames(&g, 60000, 0), 0u); /* the nodes */
    AK_CHECK_EQ(ak_crowd_bake_max_frames(NULL, 1, 0), 0u);
    printf("  bake frames within the default budget: 2,000 agents %zu, 10,000 agents %zu\n",
           ak_crowd_bake_max_frames(&g, 2000, 0), ak_crowd_bake_max_frames(&g, 10000, 0));
    bd.memory_budget = 0;
    bd.frame_count = AK_SCENE_BAKE_MAX_FRAMES + 1;
    AK_CHECK_EQ(ak_crowd_bake_scene(&bd, NULL, &baked, &diag), AK_ERR_UNSUPPORTED);
    bd.frame_count = 0;
    AK_CHECK_EQ(ak_crowd_bake_scene(&bd, NULL, &baked, &diag), AK_ERR_EMPTY);
    bd.frame_count = F;
    bd.frame_time = 0;
    AK_CHECK_EQ(ak_crowd_bake_scene(&bd, NULL, &baked, &diag), AK_ERR_BAD_ARG);
    bd.frame_time = 0.1f;
    pos[4].x = NAN;
    AK_CHECK_EQ(ak_crowd_bake_scene(&bd, NULL, &baked, &diag), AK_ERR_BAD_DATA);
    bd.agent_count = 60000; /* 60,000 x 19 nodes: more than a skeleton holds (checked first) */
    AK_CHECK_EQ(ak_crowd_bake_scene(&bd, NULL, &baked, &diag), AK_ERR_UNSUPPORTED);
    AK_CHECK(strstr(diag.message, "nodes") != NULL);
    AK_CHECK_EQ(ak_crowd_bake_scene(NULL, NULL, &baked, &diag), AK_ERR_NULL_ARG);
    /* one frame: no clip, the nodes rest in that frame */
    pos[4].x = 0;
    bd.agent_count = N;
    bd.frame_count = 1;
    AK_CHECK_EQ(ak_crowd_bake_scene(&bd, NULL, &baked, &diag), AK_OK);
    if (baked) AK_CHECK_EQ(baked->clip_count, 0u);
    ak_scene_destroy(baked);
}

/* Occurrences of needle in the n bytes at s. */
static size_t count_in(const char* s, size_t n, const char* needle) {
    size_t c = 0, k = strlen(needle);
    for (size_t i = 0; i + k <= n; ++i) c += memcmp(s + i, needle, k) == 0;
    return c;
}

/* A crowd above the 32767 nodes of the old int16 skeletons (2,000 agents x 19 nodes), baked,
 * written as .glb and read back with ak_io_load: the file holds one mesh and 2,000 skins (its
 * JSON counted by hand), and every agent's joints, posed by the read clip at each frame, sit
 * where the character's own FK placed by the agent's root matrix puts them. */
AK_TEST(bake_gltf_2000_agents) {
    ak_scene* sc = humanoid();
    AK_CHECK(sc);
    if (!sc) return;
    ak_crowd_gait g;
    AK_CHECK(gait_of(sc, &g));
    enum { N = 2000, F = 3 };
    ak_vec2* pos = malloc(sizeof(ak_vec2) * N * F);
    ak_crowd_character* ch = malloc(sizeof(ak_crowd_character) * N * F);
    for (int a = 0; a < N; ++a) {
        const float ang = 0.37f * (float)a;
        ak_crowd_character c = ak_crowd_character_init(&g, ak_vec2_make(cosf(ang), sinf(ang)), (float)(a % 7) / 7.0f);
        ak_vec2 v = ak_vec2_make(1.3f * cosf(ang), 1.3f * sinf(ang));
        ak_crowd_characters_job job = {.gait = &g, .dt = 0.1f, .velocities = {&v, 1}, .characters = {&c, 1}};
        for (int f = 0; f < F; ++f) {
            pos[f * N + a] = ak_vec2_make((float)(a % 50) * 1.5f + 0.13f * (float)f * cosf(ang),
                                          (float)(a / 50) * 1.5f + 0.13f * (float)f * sinf(ang));
            ch[f * N + a] = c;
            ak_crowd_characters_update(&job);
        }
    }
    ak_crowd_bake_desc bd = {.gait = &g, .agent_count = N, .frame_count = F, .positions = pos, .characters = ch,
                             .frame_time = 0.1f};
    ak_scene* baked = NULL;
    ak_diag diag;
    AK_CHECK_EQ(ak_crowd_bake_scene(&bd, NULL, &baked, &diag), AK_OK);
    if (baked) {
        AK_CHECK_EQ(baked->mesh_count, (size_t)N);
        AK_CHECK(!baked->meshes[0].shares_mesh && baked->meshes[N - 1].shares_mesh);
        AK_CHECK(baked->meshes[N - 1].mesh == baked->meshes[0].mesh);
        AK_CHECK_EQ(ak_io_save("crowd_2000.glb", baked, NULL, &diag), AK_OK);
    }
    ak_scene_destroy(baked);
    /* the JSON chunk, counted without the library's reader */
    FILE* fp = fopen("crowd_2000.glb", "rb");
    uint8_t head[20] = {0};
    AK_CHECK(fp && fread(head, 1, 20, fp) == 20);
    const size_t jn = (size_t)head[12] | (size_t)head[13] << 8 | (size_t)head[14] << 16 | (size_t)head[15] << 24;
    char* json = malloc(jn + 1);
    AK_CHECK(fp && json && fread(json, 1, jn, fp) == jn);
    if (fp) fclose(fp);
    if (json) {
        AK_CHECK_EQ(count_in(json, jn, "\"primitives\""), 1u);         /* one glTF mesh */
        AK_CHECK_EQ(count_in(json, jn, "\"POSITION\""), 1u);           /* its vertices once */
        AK_CHECK_EQ(count_in(json, jn, "\"inverseBindMatrices\""), (size_t)N); /* N skins */
        AK_CHECK_EQ(count_in(json, jn, "\"skin\":"), (size_t)N);       /* N skinned nodes */
        AK_CHECK_EQ(count_in(json, jn, "\"mesh\":"), (size_t)N);       /* placing that mesh */
    }
    free(json);
    ak_scene* rd = NULL;
    AK_CHECK_EQ(ak_io_load("crowd_2000.glb", NULL, NULL, &rd, &diag), AK_OK);
    if (!rd) {
        free(pos), free(ch);
        return;
    }
    const size_t J = ak_scene_joint_count(sc), n = ak_scene_joint_count(rd);
    AK_CHECK(n >= (size_t)N * (J + 1) && n > 32767);
    AK_CHECK_EQ(rd->skin_count, (size_t)N);
    AK_CHECK_EQ(rd->mesh_count, (size_t)N);
    AK_CHECK_EQ(rd->clip_count, 1u);
    size_t shared = 0;
    for (size_t m = 1; m < rd->mesh_count; ++m) shared += rd->meshes[m].shares_mesh && rd->meshes[m].mesh == rd->meshes[0].mesh;
    AK_CHECK_EQ(shared, (size_t)N - 1); /* the reader keeps one mesh too */
    size_t checked, misnamed;
    const double worst = baked_joint_error(&g, sc, rd, ch, pos, N, F, true, &checked, &misnamed);
    printf("  2,000 agents read back: %zu joint positions vs the characters' own FK, %.2g m at most\n", checked, worst);
    AK_CHECK_EQ(misnamed, 0u);
    AK_CHECK_EQ(checked, (size_t)N * F * sc->skins[0].joint_count);
    AK_CHECK(worst < 1e-4);
    free(pos), free(ch);
    ak_scene_destroy(rd);
    remove("crowd_2000.glb");
}

/* Foot planting on one standing character: pins, the IK holding them, the step, the errors. */
AK_TEST(foot_planting_unit) {
    ak_scene* sc = humanoid();
    AK_CHECK(sc);
    if (!sc) return;
    ak_crowd_gait g;
    AK_CHECK(gait_of(sc, &g));
    const size_t J = ak_scene_joint_count(sc);
    ak_transform* local = malloc(J * sizeof *local);
    ak_mat4* world = malloc(J * sizeof *world);
    const size_t bytes = ak_crowd_characters_scratch_size(&g);
    AK_CHECK(bytes >= J * sizeof(ak_transform));
    AK_CHECK_EQ(ak_crowd_characters_scratch_size(NULL), 0u);
    uint8_t* scratch = malloc(bytes);
    ak_crowd_character c = ak_crowd_character_init(&g, ak_vec2_make(1, 0), 0.0f);
    ak_vec2 v = {0, 0}, p = {2, 3};
    ak_crowd_characters_job job = {.gait = &g, .dt = 1.0f / 60.0f, .velocities = {&v, 1}, .characters = {&c, 1},
                                   .positions = {&p, 1}, .scratch = {scratch, bytes}};
    /* errors: no scratch, too small, short positions, a NaN position (nothing written) */
    job.scratch.count = bytes - 17;
    AK_CHECK_EQ(ak_crowd_characters_update(&job), AK_ERR_SPAN_SMALL);
    job.scratch.count = bytes;
    job.positions.count = 0;
    AK_CHECK_EQ(ak_crowd_characters_update(&job), AK_ERR_SPAN_SMALL);
    job.positions.count = 1;
    p.x = NAN;
    const ak_crowd_character before = c;
    AK_CHECK_EQ(ak_crowd_characters_update(&job), AK_ERR_BAD_DATA);
    AK_CHECK(memcmp(&before, &c, sizeof c) == 0);
    p.x = 2;
    /* standing still: both feet come down in the rest pose and are pinned where they are */
    AK_CHECK_EQ(ak_crowd_characters_update(&job), AK_OK);
    ak_vec3 feet[2], feet0[2];
    feet_world(&g, &c, p, local, world, J, feet0);
    for (int f = 0; f < 2; ++f) {
        AK_CHECK_EQ(c.foot_state[f], AK_CROWD_FOOT_PINNED);
        AK_CHECK_NEAR(c.foot_pin[f].x, feet0[f].x, 1e-5f);
        AK_CHECK_NEAR(c.foot_pin[f].y, feet0[f].z, 1e-5f);
    }
    /* pushed 8 cm sideways without walking: the planted pose keeps the ankles on their pins
     * (forward kinematics of the returned pose, independent of the solver), the clip's pose
     * moved them with the body */
    p.y += 0.08f;
    AK_CHECK_EQ(ak_crowd_characters_update(&job), AK_OK);
    feet_world(&g, &c, p, local, world, J, feet);
    AK_CHECK_NEAR(feet[0].z - feet0[0].z, 0.08f, 1e-5f); /* unplanted */
    AK_CHECK_EQ(ak_crowd_character_pose_planted(&g, &c, p, (ak_transform_span){local, J}), AK_OK);
    ak_scene_world_matrices(sc, (ak_transform_cspan){local, J}, (ak_mat4_span){world, J});
    const ak_mat4 root = ak_crowd_character_root(&g, &c, p);
    for (int f = 0; f < 2; ++f) {
        AK_CHECK_EQ(c.foot_state[f], AK_CROWD_FOOT_PINNED);
        const ak_vec3 w = ak_mat4_transform_point(root, ak_mat4_get_translation(world[g.feet[f]]));
        AK_CHECK_MSG(hypotf(w.x - feet0[f].x, w.z - feet0[f].z) < 1e-4f, "foot %d moved %g m", f,
                     (double)hypotf(w.x - feet0[f].x, w.z - feet0[f].z));
        AK_CHECK_NEAR(w.y, feet0[f].y, 1e-4f);
    }
    /* 20 cm (beyond AK_CROWD_PLANT_MAX_OFFSET): one foot steps, the other stays pinned */
    p.y += 0.12f;
    AK_CHECK_EQ(ak_crowd_characters_update(&job), AK_OK);
    AK_CHECK_EQ((c.foot_state[0] == AK_CROWD_FOOT_STEPPING) + (c.foot_state[1] == AK_CROWD_FOOT_STEPPING), 1);
    /* the step lifts the foot: half-way it is well above the ground */
    const int stepping = c.foot_state[0] == AK_CROWD_FOOT_STEPPING ? 0 : 1;
    for (int k = 0; k < 7; ++k) AK_CHECK_EQ(ak_crowd_characters_update(&job), AK_OK);
    AK_CHECK_EQ(c.foot_state[stepping], AK_CROWD_FOOT_STEPPING);
    AK_CHECK_EQ(ak_crowd_character_pose_planted(&g, &c, p, (ak_transform_span){local, J}), AK_OK);
    ak_scene_world_matrices(sc, (ak_transform_cspan){local, J}, (ak_mat4_span){world, J});
    const ak_vec3 lifted = ak_mat4_transform_point(root, ak_mat4_get_translation(world[g.feet[stepping]]));
    AK_CHECK_MSG(lifted.y > feet0[stepping].y + 0.04f, "stepping foot at %g m (ground %g m)", (double)lifted.y,
                 (double)feet0[stepping].y);
    /* a character with free feet: the planted pose is the clip's pose, exactly */
    ak_crowd_character free_c = ak_crowd_character_init(&g, ak_vec2_make(0, 1), 0.3f);
    free_c.walk_weight = 1.0f;
    ak_transform* a = malloc(J * sizeof *a);
    AK_CHECK_EQ(ak_crowd_character_pose(&g, &free_c, (ak_transform_span){a, J}), AK_OK);
    AK_CHECK_EQ(ak_crowd_character_pose_planted(&g, &free_c, p, (ak_transform_span){local, J}), AK_OK);
    AK_CHECK(memcmp(a, local, J * sizeof *a) == 0);
    free(a);
    free(scratch);
    free(local);
    free(world);
}

/* ---- foot sliding in crowds ----------------------------------------------------------------- */

typedef struct crowd_slide {
    double max, p95;  /* largest and 95th percentile slide over every stance (m) */
    double max2;      /* the largest with a 2 cm stance band */
    size_t stances;   /* stances measured */
    size_t steps;     /* forced steps (planting only) */
    size_t home, agents;
    long frames;
} crowd_slide;

static int cmp_double(const void* a, const void* b) {
    const double x = *(const double*)a, y = *(const double*)b;
    return x < y ? -1 : x > y;
}

/* A preset run with ORCA (default step) at dt 1/60 s, every agent driving a character; the
 * ankles' world positions come from the pose (planted or not) and the root. A foot is in
 * stance while its world height is within 1 cm of the lowest that foot reaches within 3 s either
 * side (after the first second; every frame counts, walking or idle); a stance's slide is the
 * largest horizontal distance from where it began. The run stops one second after
 * everyone is home (or at the preset's duration). */
static bool crowd_slide_run(const ak_crowd_gait* g, const char* preset, size_t agents, bool plant, crowd_slide* out) {
    memset(out, 0, sizeof *out);
    ak_crowd_scene sc;
    ak_diag diag;
    if (ak_crowd_scene_preset(preset, agents, &sc, &diag) != AK_OK) return false;
    const size_t n = sc.agent_count;
    const float dt = 1.0f / 60.0f;
    const long max_frames = (long)ceilf(sc.duration / dt);
    ak_crowd_desc d = {.agents = {sc.agents, n}, .obstacles = sc.obstacles, .obstacle_count = (uint32_t)sc.obstacle_count};
    ak_crowd* crowd = NULL;
    if (ak_crowd_create(&d, NULL, &crowd) != AK_OK) {
        ak_crowd_scene_free(&sc);
        return false;
    }
    const size_t J = ak_scene_joint_count(g->scene);
    ak_vec2 *p = malloc(n * sizeof *p), *v = calloc(n, sizeof *v), *p2 = malloc(n * sizeof *p2), *v2 = malloc(n * sizeof *v2);
    uint32_t* wp = calloc(n, sizeof *wp);
    ak_crowd_character* ch = malloc(n * sizeof *ch);
    ak_transform* local = malloc(J * sizeof *local);
    ak_mat4* world = malloc(J * sizeof *world);
    size_t cap = 1024, len = 0;
    float* rec = malloc(cap * n * 6 * sizeof *rec); /* per frame, agent, foot: x, y, z */
    const size_t cs_bytes = ak_crowd_characters_scratch_size(g);
    uint8_t* cscr = malloc(cs_bytes);
    memcpy(p, sc.positions, n * sizeof *p);
    for (size_t i = 0; i < n; ++i) {
        const ak_vec2 goal = sc.agents[i].goals.ptr[sc.agents[i].goals.count - 1];
        ch[i] = ak_crowd_character_init(g, ak_vec2_sub(goal, p[i]), (float)((i * 0.618033988749895) - floor(i * 0.618033988749895)));
    }
    ak_crowd_step_job job = {.crowd = crowd, .dt = dt};
    job.positions = (ak_vec2_cspan){p, n};
    job.velocities = (ak_vec2_cspan){v, n};
    job.waypoints = (ak_u32_span){wp, n};
    job.out_positions = (ak_vec2_span){p2, n};
    job.out_velocities = (ak_vec2_span){v2, n};
    const size_t sb = ak_crowd_step_scratch_size(&job);
    uint8_t* scratch = malloc(sb);
    job.scratch = (ak_u8_span){scratch, sb};
    long after_home = -1, f = 0;
    uint8_t prev_state[2 * 4096] = {0};
    for (; f < max_frames; ++f) {
        job.positions = (ak_vec2_cspan){p, n};
        job.velocities = (ak_vec2_cspan){v, n};
        job.out_positions = (ak_vec2_span){p2, n};
        job.out_velocities = (ak_vec2_span){v2, n};
        job.step_index = (uint64_t)f;
        if (ak_crowd_step_run(&job) != AK_OK) break;
        ak_vec2* t = p;
        p = p2, p2 = t;
        t = v, v = v2, v2 = t;
        ak_crowd_characters_job cj = {.gait = g, .dt = dt, .velocities = {v, n}, .characters = {ch, n}};
        if (plant) cj.positions = (ak_vec2_cspan){p, n}, cj.scratch = (ak_u8_span){cscr, cs_bytes};
        if (ak_crowd_characters_update(&cj) != AK_OK) break;
        if (len == cap) {
            cap *= 2;
            float* r2 = realloc(rec, cap * n * 6 * sizeof *rec);
            if (!r2) break;
            rec = r2;
        }
        for (size_t i = 0; i < n; ++i) {
            if (plant) ak_crowd_character_pose_planted(g, &ch[i], p[i], (ak_transform_span){local, J});
            else ak_crowd_character_pose(g, &ch[i], (ak_transform_span){local, J});
            ak_scene_world_matrices(g->scene, (ak_transform_cspan){local, J}, (ak_mat4_span){world, J});
            const ak_mat4 root = ak_crowd_character_root(g, &ch[i], p[i]);
            for (int k = 0; k < 2; ++k) {
                const ak_vec3 w = ak_mat4_transform_point(root, ak_mat4_get_translation(world[g->feet[k]]));
                float* r = rec + (len * n + i) * 6 + 3 * k;
                r[0] = w.x, r[1] = w.y, r[2] = w.z;
                if (i < 4096) {
                    out->steps += ch[i].foot_state[k] == AK_CROWD_FOOT_STEPPING && prev_state[2 * i + k] != AK_CROWD_FOOT_STEPPING;
                    prev_state[2 * i + k] = ch[i].foot_state[k];
                }
            }
        }
        ++len;
        size_t home = 0;
        for (size_t i = 0; i < n; ++i) home += ak_crowd_goal_reached(crowd, i, p[i], wp[i]);
        out->home = home;
        if (home == n && after_home < 0) after_home = f;
        if (after_home >= 0 && f - after_home >= 60) break;
    }
    out->agents = n;
    out->frames = (long)len;
    /* stances and their slides: with the 1 cm band, and a 2 cm band as a check. The ground
     * reference is the lowest the foot is within 3 s either side (a sliding minimum): a
     * standing character's ankle rests higher or lower than a walking one's in stance, and one
     * lowest height over a whole run of walking and standing would leave the other's stances
     * out of the band */
    const size_t skip = 60, W = 180;
    float* low = malloc(len * sizeof *low);
    size_t* dq = malloc(len * sizeof *dq);
    for (int band = 0; band < 2; ++band) {
        size_t scap = 1024, sl = 0;
        double* slides = malloc(scap * sizeof *slides);
        for (size_t i = 0; i < n; ++i)
            for (int k = 0; k < 2; ++k) {
#define Y(s) rec[((s) * n + i) * 6 + 3 * k + 1]
                /* low[s] = min of Y over [s - W, s + W] (a monotonic deque) */
                size_t head = 0, tail = 0, next = 0;
                for (size_t s = 0; s < len; ++s) {
                    for (; next < len && next <= s + W; ++next) {
                        while (tail > head && Y(dq[tail - 1]) >= Y(next)) --tail;
                        dq[tail++] = next;
                    }
                    while (dq[head] + W < s) ++head;
                    low[s] = Y(dq[head]);
                }
                long start = -1;
                double worst = 0.0;
                for (size_t s = skip; s <= len; ++s) {
                    const float* r = s < len ? rec + (s * n + i) * 6 + 3 * k : NULL;
                    const bool st = r && r[1] <= low[s] + (band ? 0.02f : 0.01f);
#undef Y
                    if (st && start < 0) start = (long)s, worst = 0.0;
                    if (st) {
                        const float* r0 = rec + ((size_t)start * n + i) * 6 + 3 * k;
                        worst = fmax(worst, hypot((double)r[0] - r0[0], (double)r[2] - r0[2]));
                    } else if (start >= 0) {
                        if (sl == scap) slides = realloc(slides, (scap *= 2) * sizeof *slides);
                        slides[sl++] = worst;
                        start = -1;
                    }
                }
            }
        qsort(slides, sl, sizeof *slides, cmp_double);
        if (band) {
            out->max2 = sl ? slides[sl - 1] : 0.0;
        } else {
            out->stances = sl;
            out->max = sl ? slides[sl - 1] : 0.0;
            out->p95 = sl ? slides[(size_t)(0.95 * (double)(sl - 1))] : 0.0;
        }
        free(slides);
    }
    free(low);
    free(dq);
    free(rec);
    free(cscr);
    free(scratch);
    free(local);
    free(world);
    free(ch);
    free(p), free(v), free(p2), free(v2), free(wp);
    ak_crowd_destroy(crowd);
    ak_crowd_scene_free(&sc);
    return true;
}

static void crowd_slide_case(const char* preset, size_t agents, double limit) {
    ak_scene* sc = humanoid();
    AK_CHECK(sc);
    if (!sc) return;
    ak_crowd_gait g;
    AK_CHECK(gait_of(sc, &g));
    crowd_slide off, on;
    AK_CHECK(crowd_slide_run(&g, preset, agents, false, &off));
    AK_CHECK(crowd_slide_run(&g, preset, agents, true, &on));
    printf("  %s %zu: %zu/%zu home in %ld frames; stance slide without planting max %.2f cm, p95 %.2f cm (%zu "
           "stances; 2 cm band: max %.2f cm); planted max %.2f cm, p95 %.2f cm (%zu stances, %zu forced steps; 2 cm "
           "band: max %.2f cm)\n",
           preset, agents, on.home, on.agents, on.frames, 100 * off.max, 100 * off.p95, off.stances, 100 * off.max2,
           100 * on.max, 100 * on.p95, on.stances, on.steps, 100 * on.max2);
    AK_CHECK(on.stances >= 4 * on.agents);
    AK_CHECK_MSG(on.max < limit, "%s %zu: a planted stance foot slides %.2f cm", preset, agents, 100 * on.max);
    /* the measure can fail: without planting the same run slides more than the limit */
    AK_CHECK_MSG(off.max > limit, "%s %zu: unplanted slide %.2f cm", preset, agents, 100 * off.max);
}

AK_TEST(foot_sliding_crowd_crossing) { crowd_slide_case("crossing", 12, 0.02); }
AK_TEST(foot_sliding_crowd_slow) {
    crowd_slide_case("circle", 250, 0.02);
    crowd_slide_case("crossing", 100, 0.02);
    crowd_slide_case("corridor", 100, 0.02);
    crowd_slide_case("evacuation", 100, 0.02);
}

int main(void) {
    AK_RUN(gait_of_builtin_walk);
    AK_RUN(foot_sliding_straight);
    AK_RUN(turning_and_idle);
    AK_RUN(shared_pose_phase_error);
    AK_RUN(validation);
    AK_RUN(bake_scene);
    AK_RUN(bake_gltf_2000_agents);
    AK_RUN(foot_planting_unit);
    AK_RUN(foot_sliding_crowd_crossing);
    AK_RUN_SLOW(foot_sliding_crowd_slow);
    ak_scene_destroy(g_humanoid);
    return ak_test_finish();
}

/* Baking simulations into glTF (scene.h ak_scene_bake_mesh_frames / ak_scene_bake_point_frames,
 * io.h ak_io_save): a real cloth run and a real particle run are recorded, baked, written as
 * .glb and .gltf, read back with ak_io_load, and the read-back scene is sampled at every frame
 * time: the visible morph block's vertices (cloth) and the particle nodes' translations and
 * visibility must equal the simulated positions within 1e-6 relative. Between frames LINEAR
 * gives the midpoint. Bounds and bad input are checked, and the Khronos validator runs on the
 * written files when node and build-tools/node_modules/gltf-validator exist (else SKIP). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "ak_test.h"
#include "gltf_validate.h"
#include "animkit/animkit.h"

static char g_tmp[400];
static char g_written[8][1024];
static int g_written_count;

static const char* tmp_path(char* buf, size_t n, const char* name) {
    snprintf(buf, n, "%s/%s", g_tmp, name);
    return buf;
}

static bool close_rel(double a, double b, double scale) {
    return fabs(a - b) <= 1e-6 * (fabs(a) > scale ? fabs(a) : scale);
}

/* Sample clip 0 (or the rest pose) at t: local transforms, world matrices and morph weights. */
typedef struct posed {
    size_t nj, nw;
    ak_transform* local;
    ak_mat4* world;
    float* weights;
} posed;

static void pose_at(const ak_scene* s, float t, posed* p) {
    p->nj = ak_scene_joint_count(s);
    p->nw = 0;
    for (size_t m = 0; m < s->mesh_count; ++m) p->nw += s->meshes[m].mesh->morph_target_count;
    p->local = realloc(p->local, (p->nj + 1) * sizeof(ak_transform));
    p->world = realloc(p->world, (p->nj + 1) * sizeof(ak_mat4));
    p->weights = realloc(p->weights, (p->nw + 1) * sizeof(float));
    ak_scene_rest_pose(s, (ak_transform_span){p->local, p->nj});
    size_t o = 0;
    for (size_t m = 0; m < s->mesh_count; ++m)
        for (size_t k = 0; k < s->meshes[m].mesh->morph_target_count; ++k) p->weights[o++] = s->meshes[m].mesh->morph_weights[k];
    if (s->clip_count)
        ak_clip_sample(s->clips[0], t, NULL, (ak_transform_span){p->local, p->nj}, (ak_f32_span){p->weights, p->nw},
                       (ak_f32_span){0});
    ak_scene_world_matrices(s, (ak_transform_cspan){p->local, p->nj}, (ak_mat4_span){p->world, p->nj});
}

static void posed_free(posed* p) { free(p->local), free(p->world), free(p->weights); }

/* The cloth as the read-back scene shows it at t: exactly one mesh visible (node scale not 0);
 * its vertices = world * (base + sum_k w_k delta_k), in double. Returns the visible count. */
static int shown_mesh(const ak_scene* s, float t, posed* p, double* out) {
    pose_at(s, t, p);
    int visible = 0;
    size_t wb = 0;
    for (size_t m = 0; m < s->mesh_count; ++m) {
        const ak_mesh* mesh = s->meshes[m].mesh;
        const ak_mat4 w = p->world[s->meshes[m].node];
        double sx = sqrt((double)w.m[0] * w.m[0] + (double)w.m[1] * w.m[1] + (double)w.m[2] * w.m[2]);
        if (sx > 0.5) {
            ++visible;
            for (size_t v = 0; v < mesh->vertex_count; ++v) {
                double q[3] = {mesh->positions[v].x, mesh->positions[v].y, mesh->positions[v].z};
                for (size_t k = 0; k < mesh->morph_target_count; ++k) {
                    const ak_vec3 d = mesh->morph_positions[k * mesh->vertex_count + v];
                    q[0] += (double)p->weights[wb + k] * d.x;
                    q[1] += (double)p->weights[wb + k] * d.y;
                    q[2] += (double)p->weights[wb + k] * d.z;
                }
                for (int r = 0; r < 3; ++r)
                    out[3 * v + (size_t)r] =
                        (double)w.m[r] * q[0] + (double)w.m[4 + r] * q[1] + (double)w.m[8 + r] * q[2] + (double)w.m[12 + r];
            }
        }
        wb += mesh->morph_target_count;
    }
    return visible;
}

/* ---- cloth ------------------------------------------------------------------------------ */

#define CW 10
#define CH 7
#define CLOTH_FRAMES 150 /* three morph blocks: 0..64, 64..128, 128..149 */

AK_TEST(cloth_round_trip) {
    ak_cloth_desc cd = {.grid_width = CW, .grid_height = CH, .spacing = 0.1f, .grid_axis_v = {0, -1, 0}};
    uint32_t pins[2] = {0, CW * (CH - 1)};
    cd.pins = (ak_u32_cspan)AK_SPAN(pins);
    ak_cloth* cloth = NULL;
    AK_CHECK_EQ(ak_cloth_create(&cd, NULL, &cloth), AK_OK);
    if (!cloth) return;
    const size_t n = ak_cloth_vertex_count(cloth);
    ak_vec3* frames = malloc(CLOTH_FRAMES * n * sizeof(ak_vec3));
    ak_vec3* normals = malloc(CLOTH_FRAMES * n * sizeof(ak_vec3));
    ak_vec3* vel = calloc(n, sizeof(ak_vec3));
    ak_vec3* x = malloc(n * sizeof(ak_vec3));
    ak_cloth_rest_positions(cloth, (ak_vec3_span){x, n});
    const float dt = 1.0f / 30.0f;
    ak_cloth_step_job job = {.cloth = cloth, .dt = dt, .gravity = {0, -9.81f, 0}, .wind = {5, 0, 1}, .drag = 1.0f,
                             .lift = 0.5f, .positions = {x, n}, .velocities = {vel, n}};
    size_t ssz = ak_cloth_step_scratch_size(&job);
    job.scratch = (ak_u8_span){malloc(ssz), ssz};
    for (int f = 0; f < CLOTH_FRAMES; ++f) {
        if (f) AK_CHECK_EQ(ak_cloth_step_run(&job), AK_OK);
        memcpy(frames + (size_t)f * n, x, n * sizeof(ak_vec3));
        ak_cloth_normals(cloth, (ak_vec3_cspan){x, n}, (ak_vec3_span){normals + (size_t)f * n, n});
    }
    ak_scene_bake_mesh_desc bd = {.name = "flag", .vertex_count = n, .frame_count = CLOTH_FRAMES, .positions = frames,
                                  .normals = normals, .indices = ak_cloth_indices(cloth), .frame_time = dt,
                                  .base_color = {0.7f, 0.2f, 0.2f, 1}};
    ak_scene* baked = NULL;
    ak_diag diag;
    ak_result r = ak_scene_bake_mesh_frames(&bd, NULL, &baked, &diag);
    AK_CHECK_MSG(r == AK_OK, "%s", diag.message);
    if (baked) {
        AK_CHECK_EQ(baked->mesh_count, 3u);
        AK_CHECK_EQ(ak_scene_joint_count(baked), 4u);
        AK_CHECK_NEAR(ak_clip_duration(baked->clips[0]), (CLOTH_FRAMES - 1) * dt, 1e-5);
    }
    double* got = malloc(3 * n * sizeof(double));
    posed p = {0};
    for (int f = 0; f < 2 && baked; ++f) {
        char out[1024];
        tmp_path(out, sizeof out, f ? "cloth.gltf" : "cloth.glb");
        r = ak_io_save(out, baked, NULL, &diag);
        AK_CHECK_MSG(r == AK_OK, "save: %s", diag.message);
        ak_scene* b = NULL;
        r = ak_io_load(out, NULL, NULL, &b, &diag);
        AK_CHECK_MSG(r == AK_OK, "reload: %s", diag.message);
        if (!b) continue;
        snprintf(g_written[g_written_count++], sizeof g_written[0], "%s", out);
        AK_CHECK_EQ(b->mesh_count, 3u);
        AK_CHECK_EQ(b->clip_count, 1u);
        double worst = 0;
        for (int k = 0; k < CLOTH_FRAMES; ++k) {
            /* the frame time as a reader computes it (float k * dt) */
            float t = (float)((double)k * dt);
            int vis = shown_mesh(b, t, &p, got);
            if (vis != 1) {
                AK_FAIL_("%s frame %d: %d meshes visible", out, k, vis);
                break;
            }
            const ak_vec3* want = frames + (size_t)k * n;
            for (size_t v = 0; v < n; ++v) {
                const double w3[3] = {want[v].x, want[v].y, want[v].z};
                for (int c = 0; c < 3; ++c) {
                    double e = fabs(got[3 * v + (size_t)c] - w3[c]) / fmax(fabs(w3[c]), 1.0);
                    worst = fmax(worst, e);
                    if (!close_rel(got[3 * v + (size_t)c], w3[c], 1.0)) {
                        AK_FAIL_("%s frame %d vertex %zu: %.9g vs simulated %.9g", out, k, v, got[3 * v + (size_t)c], w3[c]);
                        k = CLOTH_FRAMES, v = n;
                        break;
                    }
                }
            }
            /* LINEAR weights: halfway between frames shows the mean of the two frames */
            if (k + 1 < CLOTH_FRAMES && k % 9 == 4) {
                shown_mesh(b, (float)(((double)k + 0.5) * dt), &p, got);
                const ak_vec3* w2 = frames + (size_t)(k + 1) * n;
                for (size_t v = 0; v < n; ++v) {
                    double mid = 0.5 * ((double)want[v].y + (double)w2[v].y);
                    AK_CHECK_MSG(fabs(got[3 * v + 1] - mid) <= 2e-6 * fmax(fabs(mid), 1.0),
                                 "frame %d.5 vertex %zu: %.9g vs %.9g", k, v, got[3 * v + 1], mid);
                }
            }
        }
        printf("  %s: %d frames x %zu vertices, largest relative error %.2g\n", out, CLOTH_FRAMES, n, worst);
        ak_scene_destroy(b);
    }
    posed_free(&p);
    free(got);
    ak_scene_destroy(baked);
    free(job.scratch.ptr), free(frames), free(normals), free(vel), free(x);
    ak_cloth_destroy(cloth);
}

/* ---- particles -------------------------------------------------------------------------- */

#define PF 60

AK_TEST(particles_round_trip) {
    ak_particles* ps = NULL;
    AK_CHECK_EQ(ak_particles_create(&(ak_particles_desc){.capacity = 200, .seed = 7}, NULL, &ps), AK_OK);
    if (!ps) return;
    /* short lifetimes: particles are born and die during the run */
    ak_particle_emitter em = {.shape = AK_EMITTER_POINT, .rate = 60, .direction = {0, 1, 0}, .cone_angle = 0.4f,
                              .speed_min = 2, .speed_max = 3, .lifetime_min = 0.3f, .lifetime_max = 0.6f};
    ak_particle_plane floor = {.normal = {0, 1, 0}, .restitution = 0.5f, .friction = 0.2f};
    ak_particles_world world = {.gravity = {0, -9.81f, 0}, .planes = {&floor, 1}};
    const float dt = 0.02f;
    ak_scene_bake_points frames[PF];
    ak_vec3* pos[PF];
    uint32_t* ids[PF];
    for (int k = 0; k < PF; ++k) {
        if (k) {
            ak_particles_emit(ps, &em, dt, NULL);
            ak_particles_step(ps, &world, dt);
        }
        ak_particles_state st = ak_particles_get_state(ps);
        pos[k] = malloc((st.count + 1) * sizeof(ak_vec3));
        ids[k] = malloc((st.count + 1) * sizeof(uint32_t));
        if (st.count) memcpy(pos[k], st.position, st.count * sizeof(ak_vec3));
        if (st.count) memcpy(ids[k], st.id, st.count * sizeof(uint32_t));
        frames[k] = (ak_scene_bake_points){.positions = pos[k], .ids = ids[k], .count = st.count};
    }
    ak_particles_destroy(ps);
    ak_scene_bake_points_desc pd = {.name = "spray", .frames = frames, .frame_count = PF, .frame_time = dt,
                                    .marker_size = 0.02f};
    ak_scene* baked = NULL;
    ak_diag diag;
    ak_result r = ak_scene_bake_point_frames(&pd, NULL, &baked, &diag);
    AK_CHECK_MSG(r == AK_OK, "%s", diag.message);
    if (!baked) goto done;
    size_t np = ak_scene_joint_count(baked) - 1;
    AK_CHECK(np > 20);
    char out[1024];
    tmp_path(out, sizeof out, "particles.glb");
    r = ak_io_save(out, baked, NULL, &diag);
    AK_CHECK_MSG(r == AK_OK, "save: %s", diag.message);
    ak_scene* b = NULL;
    r = ak_io_load(out, NULL, NULL, &b, &diag);
    AK_CHECK_MSG(r == AK_OK, "reload: %s", diag.message);
    if (!b) goto done;
    snprintf(g_written[g_written_count++], sizeof g_written[0], "%s", out);
    posed p = {0};
    size_t born = 0, died = 0, checked = 0;
    for (int k = 0; k < PF; ++k) {
        pose_at(b, (float)((double)k * dt), &p);
        /* every simulated particle: its node (found by name) shows its position, scale 1 */
        size_t shown = 0;
        for (size_t i = 0; i < frames[k].count; ++i) {
            char name[64];
            snprintf(name, sizeof name, "spray_%u", frames[k].ids[i]);
            int j = ak_skeleton_find_joint(b->skeleton, name);
            if (j < 0) {
                AK_FAIL_("frame %d: node %s missing", k, name);
                continue;
            }
            const ak_mat4 w = p.world[j];
            const ak_vec3 want = frames[k].positions[i];
            bool ok = close_rel(w.m[12], want.x, 1.0) && close_rel(w.m[13], want.y, 1.0) && close_rel(w.m[14], want.z, 1.0) &&
                      fabsf(w.m[0] - 1.0f) < 1e-6f;
            if (!ok) AK_FAIL_("frame %d particle %u: (%.9g %.9g %.9g) scale %g vs simulated (%.9g %.9g %.9g)", k,
                              frames[k].ids[i], w.m[12], w.m[13], w.m[14], w.m[0], want.x, want.y, want.z);
            ++checked;
        }
        /* every particle node not alive now has scale 0 */
        for (size_t j = 1; j <= np; ++j)
            if (fabsf(p.world[j].m[0]) > 0.5f) ++shown;
        AK_CHECK_MSG(shown == frames[k].count, "frame %d: %zu nodes visible, %zu particles alive", k, shown,
                     frames[k].count);
    }
    for (int k = 1; k < PF; ++k) { /* ids missing from the next frame died, new ones were born */
        for (size_t i = 0; i < frames[k - 1].count; ++i) {
            bool found = false;
            for (size_t q = 0; q < frames[k].count && !found; ++q) found = frames[k].ids[q] == frames[k - 1].ids[i];
            died += !found;
        }
        for (size_t i = 0; i < frames[k].count; ++i) {
            bool found = false;
            for (size_t q = 0; q < frames[k - 1].count && !found; ++q) found = frames[k - 1].ids[q] == frames[k].ids[i];
            born += !found;
        }
    }
    AK_CHECK(died > 0 && born > 0); /* the run exercised both visibility edges */
    printf("  %s: %d frames, %zu particle nodes, %zu positions compared, %zu births, %zu deaths\n", out, PF, np, checked,
           born, died);
    posed_free(&p);
    ak_scene_destroy(b);
done:
    ak_scene_destroy(baked);
    for (int k = 0; k < PF; ++k) free(pos[k]), free(ids[k]);
}

/* ---- bounds and bad input ---------------------------------------------------------------- */

AK_TEST(bounds_and_bad_input) {
    ak_vec3 pts[8] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {1, 1, 0}, {0, 0, 1}, {1, 0, 1}, {0, 1, 1}, {1, 1, 1}};
    uint32_t tri[3] = {0, 1, 2}, bad_tri[3] = {0, 1, 9};
    ak_scene* s = NULL;
    ak_diag diag;
    ak_scene_bake_mesh_desc d = {.vertex_count = 4, .frame_count = 2, .positions = pts, .frame_time = 0.1f,
                                 .indices = {tri, 3}};
    AK_CHECK_EQ(ak_scene_bake_mesh_frames(&d, NULL, &s, &diag), AK_OK);
    AK_CHECK(s && s->mesh_count == 1 && s->meshes[0].mesh->morph_target_count == 1 && s->clip_count == 1);
    ak_scene_destroy(s);
    s = NULL;
    ak_scene_bake_mesh_desc e = d;
    e.max_frames = 1;
    AK_CHECK_EQ(ak_scene_bake_mesh_frames(&e, NULL, &s, &diag), AK_ERR_UNSUPPORTED);
    AK_CHECK(strstr(diag.message, "limit") != NULL);
    e = d, e.memory_budget = 100;
    AK_CHECK_EQ(ak_scene_bake_mesh_frames(&e, NULL, &s, &diag), AK_ERR_UNSUPPORTED);
    AK_CHECK(strstr(diag.message, "budget") != NULL);
    e = d, e.frame_time = 0;
    AK_CHECK_EQ(ak_scene_bake_mesh_frames(&e, NULL, &s, &diag), AK_ERR_BAD_ARG);
    e = d, e.interp = AK_INTERP_CUBICSPLINE;
    AK_CHECK_EQ(ak_scene_bake_mesh_frames(&e, NULL, &s, &diag), AK_ERR_BAD_ARG);
    e = d, e.indices = (ak_u32_cspan){bad_tri, 3};
    AK_CHECK_EQ(ak_scene_bake_mesh_frames(&e, NULL, &s, &diag), AK_ERR_BAD_INDEX);
    e = d, e.frame_count = 0;
    AK_CHECK_EQ(ak_scene_bake_mesh_frames(&e, NULL, &s, &diag), AK_ERR_EMPTY);
    pts[5].y = NAN;
    AK_CHECK_EQ(ak_scene_bake_mesh_frames(&d, NULL, &s, &diag), AK_ERR_BAD_DATA);
    AK_CHECK(strstr(diag.message, "frame 1 vertex 1") != NULL);
    pts[5].y = 0;
    AK_CHECK_EQ(ak_scene_bake_mesh_frames(NULL, NULL, &s, &diag), AK_ERR_NULL_ARG);
    AK_CHECK(s == NULL);
    /* points */
    uint32_t id2[2] = {4, 4}, id1[2] = {3, 5};
    ak_scene_bake_points f[2] = {{pts, id1, 2}, {pts, id2, 2}};
    ak_scene_bake_points_desc pd = {.frames = f, .frame_count = 2, .frame_time = 0.1f};
    AK_CHECK_EQ(ak_scene_bake_point_frames(&pd, NULL, &s, &diag), AK_ERR_DUPLICATE);
    id2[1] = 6;
    AK_CHECK_EQ(ak_scene_bake_point_frames(&pd, NULL, &s, &diag), AK_OK);
    AK_CHECK(s && ak_scene_joint_count(s) == 5 && s->mesh_count == 0);
    ak_scene_destroy(s);
    s = NULL;
    /* an empty frame may have NULL arrays; the two points then start hidden (scale 0 at t=0) */
    ak_scene_bake_points f2[2] = {{NULL, NULL, 0}, {pts, id1, 2}};
    ak_scene_bake_points_desc pe = {.frames = f2, .frame_count = 2, .frame_time = 0.1f};
    AK_CHECK_EQ(ak_scene_bake_point_frames(&pe, NULL, &s, &diag), AK_OK);
    if (s) {
        ak_transform loc[3];
        ak_scene_rest_pose(s, (ak_transform_span)AK_SPAN(loc));
        ak_clip_sample(s->clips[0], 0.0f, NULL, (ak_transform_span)AK_SPAN(loc), (ak_f32_span){0}, (ak_f32_span){0});
        AK_CHECK(loc[1].scale.x == 0.0f && loc[2].scale.x == 0.0f);
        ak_clip_sample(s->clips[0], 0.1f, NULL, (ak_transform_span)AK_SPAN(loc), (ak_f32_span){0}, (ak_f32_span){0});
        AK_CHECK(loc[1].scale.x == 1.0f && loc[2].translation.x == 1.0f);
    }
    ak_scene_destroy(s);
    s = NULL;
    pd.max_points = 3;
    AK_CHECK_EQ(ak_scene_bake_point_frames(&pd, NULL, &s, &diag), AK_ERR_UNSUPPORTED);
    pd.max_points = 40000;
    AK_CHECK_EQ(ak_scene_bake_point_frames(&pd, NULL, &s, &diag), AK_ERR_BAD_ARG);
    pd.max_points = 0, pd.marker_size = -1;
    AK_CHECK_EQ(ak_scene_bake_point_frames(&pd, NULL, &s, &diag), AK_ERR_BAD_ARG);
    pd.marker_size = 0;
    f[1].ids = NULL;
    AK_CHECK_EQ(ak_scene_bake_point_frames(&pd, NULL, &s, &diag), AK_ERR_NULL_ARG);
    AK_CHECK(s == NULL);
}

/* ---- the CLI: animkit cloth / particles -o OUT.glb ---------------------------------------- */

#ifdef AK_CLI_PATH
AK_TEST(cli_output) {
    char out[1024], json[1024], cmd[3000];
    tmp_path(out, sizeof out, "cli_flag.glb");
    tmp_path(json, sizeof json, "cli_flag.json");
    snprintf(cmd, sizeof cmd, "'%s' cloth --preset flag --steps 40 --json '%s' -o '%s' >/dev/null 2>&1", AK_CLI_PATH,
             json, out);
    AK_CHECK_EQ(system(cmd), 0);
    ak_scene* s = NULL;
    ak_diag diag;
    AK_CHECK_EQ(ak_io_load(out, NULL, NULL, &s, &diag), AK_OK);
    /* the last frame equals the final state --json reports */
    FILE* fp = fopen(json, "r");
    char* text = calloc(1, 1 << 20);
    if (fp) fread(text, 1, (1 << 20) - 1, fp), fclose(fp);
    char* at = strstr(text, "\"positions\": [");
    float t_end = 0;
    sscanf(text, "{\"time\": %f", &t_end);
    if (s && at) {
        AK_CHECK_NEAR(ak_clip_duration(s->clips[0]), t_end, 1e-5);
        posed p = {0};
        size_t nv = s->meshes[0].mesh->vertex_count;
        double* got = malloc(3 * nv * sizeof(double));
        AK_CHECK_EQ(shown_mesh(s, ak_clip_duration(s->clips[0]), &p, got), 1);
        at += strlen("\"positions\": [");
        for (size_t v = 0; v < nv; ++v) {
            double x, y, z;
            int used = 0;
            if (sscanf(at, " [%lf, %lf, %lf]%n", &x, &y, &z, &used) != 3) {
                AK_FAIL_("json vertex %zu unreadable", v);
                break;
            }
            at += used;
            if (*at == ',') ++at;
            AK_CHECK_MSG(close_rel(got[3 * v], x, 1) && close_rel(got[3 * v + 1], y, 1) && close_rel(got[3 * v + 2], z, 1),
                         "cli flag vertex %zu: %.9g %.9g %.9g vs json %.9g %.9g %.9g", v, got[3 * v], got[3 * v + 1],
                         got[3 * v + 2], x, y, z);
        }
        free(got);
        posed_free(&p);
    }
    free(text);
    ak_scene_destroy(s);
    s = NULL;
    snprintf(g_written[g_written_count++], sizeof g_written[0], "%s", out);
    tmp_path(out, sizeof out, "cli_fountain.gltf");
    snprintf(cmd, sizeof cmd, "'%s' particles --preset fountain --steps 30 -o '%s' >/dev/null 2>&1", AK_CLI_PATH, out);
    AK_CHECK_EQ(system(cmd), 0);
    AK_CHECK_EQ(ak_io_load(out, NULL, NULL, &s, &diag), AK_OK);
    AK_CHECK(s && ak_scene_joint_count(s) > 1);
    ak_scene_destroy(s);
    snprintf(g_written[g_written_count++], sizeof g_written[0], "%s", out);
    /* bad extension: usage error, exit 2 */
    snprintf(cmd, sizeof cmd, "'%s' cloth --preset flag --steps 2 -o '%s/x.fbx' >/dev/null 2>&1", AK_CLI_PATH, g_tmp);
    int st = system(cmd);
    AK_CHECK(WIFEXITED(st) && WEXITSTATUS(st) == 2);
}
#endif

AK_TEST(validator) {
    const char* names[sizeof g_written / sizeof g_written[0]];
    for (int i = 0; i < g_written_count; ++i) names[i] = g_written[i];
    ak_test_gltf_validate(names, g_written_count, "baked files");
}

int main(void) {
    snprintf(g_tmp, sizeof g_tmp, "%s/test_scene_bake.XXXXXX", getenv("TMPDIR") ? getenv("TMPDIR") : "/tmp");
    if (!mkdtemp(g_tmp)) {
        perror("mkdtemp");
        return 1;
    }
    AK_RUN(cloth_round_trip);
    AK_RUN(particles_round_trip);
    AK_RUN(bounds_and_bad_input);
#ifdef AK_CLI_PATH
    AK_RUN(cli_output);
#endif
    AK_RUN(validator);
    char cmd[600];
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", g_tmp);
    if (system(cmd) != 0) printf("could not remove %s\n", g_tmp);
    return ak_test_finish();
}

/* glTF writer (ak_io_save): round trips of every shared glTF asset (same sampled poses,
 * morph weights and skinned vertices, compared with a double-precision reference skinning
 * written here), STEP/CUBICSPLINE kept exactly, the Khronos validator on the output, bad
 * input, `animkit export -o OUT.glb|.gltf`, and the writer's streaming JSON (src/io/json_write.h)
 * against cJSON's printing of the same values. */
#include <animkit/animkit.h>
#include <dirent.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cjson/cJSON.h> /* the reference the streaming JSON writer must match byte for byte */

#include "ak_test.h"
#include "gltf_validate.h"
#include "io/json_write.h"

static char g_tmp[400];

static const char* tmp_path(char* buf, size_t n, const char* name) {
    snprintf(buf, n, "%s/%s", g_tmp, name);
    return buf;
}

/* |a - b| <= 1e-6 relative (absolute near zero). */
static bool close_rel(double a, double b, double scale) { return fabs(a - b) <= 1e-6 * (fabs(a) > scale ? fabs(a) : scale); }

/* ---- scene comparison ------------------------------------------------------------------- */

/* Posed vertices of scene mesh m (morphs, then skinning or the node's world matrix), in double. */
static void pose_mesh(const ak_scene* s, size_t m, const ak_mat4* world, const float* weights, size_t wbase,
                      double* out) {
    const ak_scene_mesh* sm = &s->meshes[m];
    const ak_mesh* mesh = sm->mesh;
    ak_mat4* pal = NULL;
    if (sm->skin >= 0) {
        size_t jc = s->skins[sm->skin].joint_count;
        pal = malloc(jc * sizeof *pal);
        ak_scene_skin_palette(s, (size_t)sm->skin, (ak_mat4_cspan){world, ak_scene_joint_count(s)}, (ak_mat4_span){pal, jc});
    }
    for (size_t v = 0; v < mesh->vertex_count; ++v) {
        double p[3] = {mesh->positions[v].x, mesh->positions[v].y, mesh->positions[v].z};
        for (size_t t = 0; t < mesh->morph_target_count; ++t) {
            const ak_vec3 d = mesh->morph_positions[t * mesh->vertex_count + v];
            double w = weights[wbase + t];
            p[0] += w * d.x, p[1] += w * d.y, p[2] += w * d.z;
        }
        double q[3] = {0, 0, 0};
        if (pal && mesh->influence_count) {
            for (uint32_t k = 0; k < mesh->influence_count; ++k) {
                double w = mesh->weights[v * mesh->influence_count + k];
                if (w == 0.0) continue;
                const float* M = pal[mesh->joints[v * mesh->influence_count + k]].m;
                for (int r = 0; r < 3; ++r) q[r] += w * (M[r] * p[0] + M[4 + r] * p[1] + M[8 + r] * p[2] + M[12 + r]);
            }
        } else if (sm->node >= 0) {
            const float* M = world[sm->node].m;
            for (int r = 0; r < 3; ++r) q[r] = M[r] * p[0] + M[4 + r] * p[1] + M[8 + r] * p[2] + M[12 + r];
        } else {
            memcpy(q, p, sizeof q);
        }
        memcpy(out + 3 * v, q, sizeof q);
    }
    free(pal);
}

static size_t total_weights(const ak_scene* s) {
    size_t n = 0;
    for (size_t m = 0; m < s->mesh_count; ++m) n += s->meshes[m].mesh->morph_target_count;
    return n;
}

/* Pose of clip k at time t (rest pose / default weights first). */
static void sample(const ak_scene* s, size_t k, float t, ak_transform* local, float* weights) {
    size_t n = ak_scene_joint_count(s);
    ak_scene_rest_pose(s, (ak_transform_span){local, n});
    size_t w = 0;
    for (size_t m = 0; m < s->mesh_count; ++m)
        for (size_t i = 0; i < s->meshes[m].mesh->morph_target_count; ++i) weights[w++] = s->meshes[m].mesh->morph_weights[i];
    if (k < s->clip_count)
        ak_clip_sample(s->clips[k], t, NULL, (ak_transform_span){local, n}, (ak_f32_span){weights, w}, (ak_f32_span){0});
}

/* Compare scene b (written and read back) with a: every joint of a by name, every clip at
 * times between keys and outside the range, weights, posed vertices. Returns failures. */
static int compare_scenes_n(const ak_scene* a, const ak_scene* b, const char* what, size_t time_count) {
    int bad = 0;
    size_t na = ak_scene_joint_count(a), nb = ak_scene_joint_count(b);
    AK_CHECK_MSG(nb >= na, "%s: %zu joints, was %zu", what, nb, na);
    AK_CHECK_EQ(a->mesh_count, b->mesh_count);
    AK_CHECK_EQ(a->clip_count, b->clip_count);
    AK_CHECK_EQ(a->skin_count, b->skin_count);
    if (nb < na || a->mesh_count != b->mesh_count || a->clip_count != b->clip_count) return 1;
    int* map = malloc((na ? na : 1) * sizeof *map);
    for (size_t j = 0; j < na; ++j) {
        map[j] = ak_skeleton_find_joint(b->skeleton, ak_skeleton_joint_name(a->skeleton, j));
        AK_CHECK_MSG(map[j] >= 0, "%s: joint %s lost", what, ak_skeleton_joint_name(a->skeleton, j));
        if (map[j] < 0) bad = 1;
    }
    for (size_t m = 0; m < a->mesh_count && !bad; ++m) {
        AK_CHECK_EQ(a->meshes[m].mesh->vertex_count, b->meshes[m].mesh->vertex_count);
        AK_CHECK_EQ(a->meshes[m].mesh->morph_target_count, b->meshes[m].mesh->morph_target_count);
        AK_CHECK_EQ(a->meshes[m].skin, b->meshes[m].skin);
        AK_CHECK_EQ(a->meshes[m].has_material, b->meshes[m].has_material);
        if (a->meshes[m].has_material && b->meshes[m].has_material)
            AK_CHECK_MSG(!memcmp(&a->meshes[m].base_color, &b->meshes[m].base_color, sizeof(ak_vec4)),
                         "%s mesh %zu: base colour differs", what, m);
        /* base colour textures kept: same texels, wrap modes and filters */
        int32_t ta = a->meshes[m].texture, tb = b->meshes[m].texture;
        AK_CHECK_MSG((ta >= 0) == (tb >= 0), "%s mesh %zu: texture %s", what, m, ta >= 0 ? "lost" : "appeared");
        if (ta >= 0 && tb >= 0 && (size_t)tb < b->texture_count) {
            const ak_scene_texture *xa = &a->textures[ta], *xb = &b->textures[tb];
            AK_CHECK_MSG(xa->width == xb->width && xa->height == xb->height && xb->pixels &&
                             !memcmp(xa->pixels, xb->pixels, (size_t)xa->width * (size_t)xa->height * 4u),
                         "%s mesh %zu: texture pixels differ", what, m);
            AK_CHECK(xa->wrap_s == xb->wrap_s && xa->wrap_t == xb->wrap_t && xa->mag_filter == xb->mag_filter &&
                     xa->min_filter == xb->min_filter);
        }
        if (a->meshes[m].mesh->vertex_count != b->meshes[m].mesh->vertex_count ||
            a->meshes[m].mesh->morph_target_count != b->meshes[m].mesh->morph_target_count)
            bad = 1;
        /* tangents (TANGENT, and morph TANGENT deltas) kept: xyz within 1e-6, w the same sign */
        const ak_mesh *ma = a->meshes[m].mesh, *mb = b->meshes[m].mesh;
        if (!bad && ma->normals) {
            AK_CHECK_MSG((ma->tangents != NULL) == (mb->tangents != NULL), "%s mesh %zu: tangents %s", what, m,
                         ma->tangents ? "lost" : "appeared");
            AK_CHECK_MSG((ma->morph_tangents != NULL) == (mb->morph_tangents != NULL), "%s mesh %zu: morph tangents %s",
                         what, m, ma->morph_tangents ? "lost" : "appeared");
            for (size_t v = 0; ma->tangents && mb->tangents && v < ma->vertex_count; ++v) {
                const ak_vec4 x = ma->tangents[v], y = mb->tangents[v];
                if (!close_rel(x.x, y.x, 1.0) || !close_rel(x.y, y.y, 1.0) || !close_rel(x.z, y.z, 1.0) ||
                    (x.w < 0) != (y.w < 0) || fabsf(y.w) != 1.0f) {
                    AK_FAIL_("%s mesh %zu tangent %zu: (%g %g %g %g) vs (%g %g %g %g)", what, m, v, x.x, x.y, x.z, x.w,
                             y.x, y.y, y.z, y.w);
                    bad = 1;
                    break;
                }
            }
            size_t nmt = ma->vertex_count * ma->morph_target_count;
            for (size_t i = 0; ma->morph_tangents && mb->morph_tangents && i < nmt; ++i)
                if (!close_rel(ma->morph_tangents[i].x, mb->morph_tangents[i].x, 1.0) ||
                    !close_rel(ma->morph_tangents[i].y, mb->morph_tangents[i].y, 1.0) ||
                    !close_rel(ma->morph_tangents[i].z, mb->morph_tangents[i].z, 1.0)) {
                    AK_FAIL_("%s mesh %zu morph tangent %zu differs", what, m, i);
                    bad = 1;
                    break;
                }
        }
    }
    size_t nw = total_weights(a);
    ak_transform *la = malloc((na + 1) * sizeof *la), *lb = malloc((nb + 1) * sizeof *lb);
    ak_mat4 *wa = malloc((na + 1) * sizeof *wa), *wb = malloc((nb + 1) * sizeof *wb);
    float *ga = malloc((nw + 1) * sizeof(float)), *gb = malloc((nw + 1) * sizeof(float));
    size_t clips = a->clip_count ? a->clip_count : 1;
    for (size_t k = 0; k < clips && !bad; ++k) {
        float d = k < a->clip_count ? ak_clip_duration(a->clips[k]) : 0.0f;
        if (k < a->clip_count) AK_CHECK_NEAR(ak_clip_duration(b->clips[k]), d, 1e-6 * (d > 1 ? d : 1));
        const float fr[] = {-0.5f, 0.013f, 0.37f, 0.77f, 1.0f, 1.5f}; /* before, between keys, end, after */
        for (size_t ti = 0; ti < sizeof fr / sizeof fr[0] && ti < time_count && !bad; ++ti) {
            float t = fr[ti] < 0 ? fr[ti] : fr[ti] * d + (fr[ti] > 1 ? 0.25f : 0.0f);
            sample(a, k, t, la, ga);
            sample(b, k, t, lb, gb);
            for (size_t j = 0; j < na && !bad; ++j) {
                ak_transform x = la[j], y = lb[map[j]];
                float sgn = ak_quat_dot(x.rotation, y.rotation) < 0 ? -1.0f : 1.0f;
                const float xa[10] = {x.translation.x, x.translation.y, x.translation.z, x.rotation.x, x.rotation.y,
                                      x.rotation.z, x.rotation.w, x.scale.x, x.scale.y, x.scale.z};
                const float ya[10] = {y.translation.x, y.translation.y, y.translation.z, sgn * y.rotation.x,
                                      sgn * y.rotation.y, sgn * y.rotation.z, sgn * y.rotation.w, y.scale.x, y.scale.y, y.scale.z};
                for (int c = 0; c < 10; ++c)
                    if (!close_rel(xa[c], ya[c], 1.0)) {
                        AK_FAIL_("%s clip %zu t=%g joint %s component %d: %.9g vs %.9g", what, k, t,
                                 ak_skeleton_joint_name(a->skeleton, j), c, xa[c], ya[c]);
                        bad = 1;
                        break;
                    }
            }
            for (size_t i = 0; i < nw && !bad; ++i)
                if (!close_rel(ga[i], gb[i], 1.0)) {
                    AK_FAIL_("%s clip %zu t=%g morph weight %zu: %.9g vs %.9g", what, k, t, i, ga[i], gb[i]);
                    bad = 1;
                }
            if (na) ak_scene_world_matrices(a, (ak_transform_cspan){la, na}, (ak_mat4_span){wa, na});
            if (nb) ak_scene_world_matrices(b, (ak_transform_cspan){lb, nb}, (ak_mat4_span){wb, nb});
            size_t base = 0;
            for (size_t m = 0; m < a->mesh_count && !bad; ++m) {
                size_t nv = a->meshes[m].mesh->vertex_count;
                double *pa = malloc(3 * nv * sizeof(double)), *pb = malloc(3 * nv * sizeof(double));
                pose_mesh(a, m, wa, ga, base, pa);
                pose_mesh(b, m, wb, gb, base, pb);
                double scale = 1e-3;
                for (size_t i = 0; i < 3 * nv; ++i) scale = fabs(pa[i]) > scale ? fabs(pa[i]) : scale;
                for (size_t i = 0; i < 3 * nv; ++i)
                    if (!close_rel(pa[i], pb[i], scale)) {
                        AK_FAIL_("%s clip %zu t=%g mesh %zu vertex %zu: %.9g vs %.9g", what, k, t, m, i / 3, pa[i], pb[i]);
                        bad = 1;
                        break;
                    }
                base += a->meshes[m].mesh->morph_target_count;
                free(pa);
                free(pb);
            }
        }
    }
    free(map), free(la), free(lb), free(wa), free(wb), free(ga), free(gb);
    return bad;
}

static int compare_scenes(const ak_scene* a, const ak_scene* b, const char* what) { return compare_scenes_n(a, b, what, 6); }

/* ---- the validator ---------------------------------------------------------------------- */

/* Files written by the tests, validated together at the end (node starts once). */
static char g_written[64][1024];
static int g_written_count;

static void queue_validate(const char* file) {
    if (g_written_count < 64) snprintf(g_written[g_written_count++], sizeof g_written[0], "%s", file);
}

/* Run the validator on every queued file: each must have 0 errors and 0 warnings.
 * SKIP when node or build-tools/node_modules/gltf-validator is absent. */
AK_TEST(validator) {
    const char* names[sizeof g_written / sizeof g_written[0]];
    for (int i = 0; i < g_written_count; ++i) names[i] = g_written[i];
    ak_test_gltf_validate(names, g_written_count, "written files");
}

/* ---- tests ------------------------------------------------------------------------------ */

static const ak_io_desc k_load = {.max_influences = 8};

AK_TEST(round_trip_assets) {
    const char* dir = ak_test_assets_dir();
    char gdir[1100];
    if (!dir) {
        AK_SKIP("no glTF assets (set ANIMKIT_ASSETS or provide ../shared/assets)");
        return;
    }
    snprintf(gdir, sizeof gdir, "%s/gltf", dir);
    DIR* d = opendir(gdir);
    if (!d) {
        AK_SKIP("%s absent", gdir);
        return;
    }
    int done = 0;
    struct dirent* e;
    while ((e = readdir(d)) != NULL) {
        if (e->d_name[0] == '.') continue;
        const char* variants[] = {"glTF-Binary", "glTF"};
        const char* exts[] = {"glb", "gltf"};
        char src[2048] = "";
        struct stat st;
        for (int v = 0; v < 2 && !src[0]; ++v) {
            snprintf(src, sizeof src, "%s/%s/%s/%s.%s", gdir, e->d_name, variants[v], e->d_name, exts[v]);
            if (stat(src, &st) != 0) src[0] = '\0';
        }
        if (!src[0]) continue;
        ak_scene* a = NULL;
        ak_diag diag;
        ak_result r = ak_io_load(src, &k_load, NULL, &a, &diag);
        AK_CHECK_MSG(r == AK_OK, "%s: %s", src, diag.message);
        if (r != AK_OK) continue;
        for (int f = 0; f < 2; ++f) {
            char out[1024], name[300];
            snprintf(name, sizeof name, "%s.%s", e->d_name, f ? "gltf" : "glb");
            tmp_path(out, sizeof out, name);
            r = ak_io_save(out, a, NULL, &diag);
            AK_CHECK_MSG(r == AK_OK, "save %s: %s (%s)", out, diag.message, ak_result_string(r));
            if (r != AK_OK) continue;
            ak_scene* b = NULL;
            r = ak_io_load(out, &k_load, NULL, &b, &diag);
            AK_CHECK_MSG(r == AK_OK, "reload %s: %s", out, diag.message);
            if (r == AK_OK) {
                /* .gltf holds the same buffer as .glb: 3 times keep valgrind runs short */
                AK_CHECK_MSG(compare_scenes_n(a, b, name, f ? 3 : 6) == 0, "%s round trip differs", name);
                ++done;
            }
            ak_scene_destroy(b);
            queue_validate(out);
        }
        ak_scene_destroy(a);
    }
    closedir(d);
    AK_CHECK(done > 0);
    printf("  %d round trips\n", done);
}

/* A hand-made scene: 6 joints, one skinned mesh with 6 influences (JOINTS_1) and 2 morph
 * targets, and a clip with STEP, LINEAR, CUBICSPLINE (translation, rotation, weights) and
 * HERMITE channels. */
static ak_scene* make_scene(ak_interp rot_interp) {
    ak_scene* s = NULL;
    if (ak_scene_alloc(1, 1, 1, NULL, &s) != AK_OK) return NULL;
    snprintf(s->name, sizeof s->name, "handmade");
    ak_joint_desc j[6] = {
        {.name = "root", .parent = -1, .rest = ak_transform_identity()},
        {.name = "a", .parent = 0, .rest = ak_transform_make(ak_vec3_make(1, 0, 0), ak_quat_identity(), ak_vec3_make(1, 1, 1))},
        {.name = "b", .parent = 1, .rest = ak_transform_make(ak_vec3_make(1, 0, 0), ak_quat_identity(), ak_vec3_make(1, 1, 1))},
        {.name = "c", .parent = 0, .rest = ak_transform_make(ak_vec3_make(-1, 0, 0), ak_quat_identity(), ak_vec3_make(1, 1, 1))},
        {.name = "mid", .parent = 3, .rest = ak_transform_make(ak_vec3_make(0, 1, 0), ak_quat_from_axis_angle(ak_vec3_make(0, 0, 1), 0.3f), ak_vec3_make(1, 1, 1))},
        {.name = "tip", .parent = 4, .rest = ak_transform_make(ak_vec3_make(0, 1, 0), ak_quat_identity(), ak_vec3_make(1, 2, 1))},
    };
    ak_skeleton_create(&(ak_skeleton_desc){.joints = j, .joint_count = 6, .palette_from_skins = true}, NULL, &s->skeleton, NULL);
    ak_mesh_desc md = {.vertex_count = 4, .triangle_count = 2, .influence_count = 6, .morph_target_count = 2,
                       .has_normals = true, .has_uvs = true, .has_morph_normals = true, .name = "quad",
                       .has_tangents = true, .has_morph_tangents = true};
    ak_mesh_create(&md, NULL, &s->meshes[0].mesh);
    ak_mesh* m = s->meshes[0].mesh;
    for (size_t v = 0; v < 4; ++v) {
        m->positions[v] = ak_vec3_make((float)(v & 1), (float)(v >> 1) * 2.0f, 0.1f * (float)v);
        m->normals[v] = ak_vec3_make(0, 0, 1);
        m->uvs[v] = ak_vec2_make((float)(v & 1), (float)(v >> 1));
        for (uint32_t k = 0; k < 6; ++k) {
            m->joints[v * 6 + k] = (uint16_t)k;
            m->weights[v * 6 + k] = k < 3 ? 0.25f : 0.25f / 3.0f;
        }
        m->morph_positions[v] = ak_vec3_make(0.5f, 0, 0);
        m->morph_positions[4 + v] = ak_vec3_make(0, 0, (float)v);
        m->morph_normals[v] = ak_vec3_make(0, 0.1f, 0);
        /* unit tangents in the quad's plane, two of each handedness */
        float ang = 0.4f * (float)v;
        m->tangents[v] = ak_vec4_make(cosf(ang), sinf(ang), 0, v < 2 ? 1.0f : -1.0f);
        m->morph_tangents[4 + v] = ak_vec3_make(0.05f * (float)v, 0, -0.02f);
    }
    const uint32_t idx[6] = {0, 1, 3, 0, 3, 2};
    memcpy(m->indices, idx, sizeof idx);
    m->morph_weights[0] = 0.25f;
    snprintf(m->morph_names[0], AK_NAME_SIZE, "wide");
    snprintf(m->morph_names[1], AK_NAME_SIZE, "deep");
    s->meshes[0].node = -1;
    s->meshes[0].skin = 0;
    ak_scene_skin_alloc(s, 0, 6);
    ak_mat4_cspan ib = ak_skeleton_inverse_binds(s->skeleton);
    for (int k = 0; k < 6; ++k) s->skins[0].joints[k] = k, s->skins[0].inverse_binds[k] = ib.ptr[k];
    static const float t3[3] = {0.0f, 0.4f, 1.0f};
    static const float step_v[9] = {0, 0, 0, 1, 2, 3, -1, 0.5f, 2};
    /* CUBICSPLINE: (in, value, out) x 3 keys */
    static const float cub_v[27] = {0, 0, 0, 0, 1, 0, 1, 0, 0, -2, 0, 0, 0, 2, 0, 0, 0, 3, 1, 1, 1, 0, 0, 0, 0, 0, 0};
    static float rot_v[36];
    for (int k = 0; k < 3; ++k) {
        ak_quat q = ak_quat_from_axis_angle(ak_vec3_make(0, 1, 0), 0.7f * (float)k);
        float* o = rot_v + 12 * k;
        o[0] = 0.1f, o[1] = 0.2f, o[2] = 0, o[3] = 0;             /* in-tangent */
        o[4] = q.x, o[5] = q.y, o[6] = q.z, o[7] = q.w;            /* value */
        o[8] = 0, o[9] = -0.3f, o[10] = 0.05f, o[11] = 0;          /* out-tangent */
    }
    static float rot_lin[12];
    for (int k = 0; k < 3; ++k) memcpy(rot_lin + 4 * k, rot_v + 12 * k + 4, 4 * sizeof(float));
    static const float w_v[18] = {0, 0, 0.2f, 0.8f, 1, -1, 0.5f, 0.5f, 0.7f, 0.1f, 0, 0, 0, 0, 1, 0, 0, 0};
    static const float sc_v[27] = {0, 0, 0, 1, 1, 1, 0.5f, 0, 0, 0, 0, 0, 2, 1, 1, 0, 0, 0, 0, 0, 0, 1, 1, 3, 0, 1, 0};
    bool cubic_rot = rot_interp == AK_INTERP_CUBICSPLINE;
    ak_raw_channel ch[5] = {
        {.target = AK_CHANNEL_TRANSLATION, .index = 0, .interp = AK_INTERP_STEP, .key_count = 3, .times = t3, .values = step_v},
        {.target = AK_CHANNEL_TRANSLATION, .index = 4, .interp = AK_INTERP_CUBICSPLINE, .key_count = 3, .times = t3, .values = cub_v},
        {.target = AK_CHANNEL_ROTATION, .index = 5, .interp = rot_interp, .key_count = 3, .times = t3, .values = cubic_rot ? rot_v : rot_lin},
        {.target = AK_CHANNEL_MORPH_WEIGHTS, .index = 0, .component_count = 2, .interp = AK_INTERP_CUBICSPLINE, .key_count = 3, .times = t3, .values = w_v},
        {.target = AK_CHANNEL_SCALE, .index = 5, .interp = AK_INTERP_HERMITE, .key_count = 3, .times = t3, .values = sc_v},
    };
    ak_raw_clip raw = {.name = "mix", .channels = ch, .channel_count = 5, .joint_count = 6, .morph_weight_count = 2};
    if (ak_clip_build(&raw, NULL, &s->clips[0], NULL) != AK_OK) {
        ak_scene_destroy(s);
        return NULL;
    }
    return s;
}

AK_TEST(interpolation_kept) {
    ak_scene* a = make_scene(AK_INTERP_CUBICSPLINE);
    AK_CHECK(a != NULL);
    if (!a) return;
    char out[1024];
    for (int f = 0; f < 2; ++f) {
        tmp_path(out, sizeof out, f ? "handmade.gltf" : "handmade.glb");
        ak_diag diag;
        ak_result r = ak_io_save(out, a, NULL, &diag);
        AK_CHECK_MSG(r == AK_OK, "%s", diag.message);
        ak_scene* b = NULL;
        r = ak_io_load(out, &k_load, NULL, &b, &diag);
        AK_CHECK_MSG(r == AK_OK, "%s", diag.message);
        if (!b) continue;
        AK_CHECK_EQ(compare_scenes(a, b, out), 0);
        AK_CHECK(b->meshes[0].mesh->influence_count >= 6u); /* JOINTS_1 read back as 8 slots */
        AK_CHECK_STREQ(b->meshes[0].mesh->morph_names[1], "deep");
        AK_CHECK_NEAR(b->meshes[0].mesh->morph_weights[0], 0.25, 0);
        /* every channel: same interpolation (HERMITE is written as CUBICSPLINE, the same
         * curve), same key times, values and tangents, bit for bit */
        const ak_clip* ca = a->clips[0];
        const ak_clip* cb = b->clips[0];
        AK_CHECK_EQ(ak_clip_channel_count(cb), ak_clip_channel_count(ca));
        for (size_t i = 0; i < ak_clip_channel_count(ca); ++i) {
            size_t jb = SIZE_MAX;
            for (size_t k = 0; k < ak_clip_channel_count(cb); ++k)
                if (ak_clip_channel_target(cb, k) == ak_clip_channel_target(ca, i) &&
                    ak_clip_channel_index(cb, k) == ak_clip_channel_index(ca, i))
                    jb = k;
            AK_CHECK(jb != SIZE_MAX);
            if (jb == SIZE_MAX) continue;
            ak_interp ia = ak_clip_channel_interp(ca, i);
            AK_CHECK_EQ(ak_clip_channel_interp(cb, jb), ia == AK_INTERP_HERMITE ? AK_INTERP_CUBICSPLINE : ia);
            const ak_track* ta = ak_clip_channel_track(ca, i);
            const ak_track* tb = ak_clip_channel_track(cb, jb);
            AK_CHECK_EQ(ak_track_key_count(tb), ak_track_key_count(ta));
            for (size_t k = 0; k < ak_track_key_count(ta) && k < ak_track_key_count(tb); ++k) {
                float va[3][4], vb[3][4];
                ak_track_key(ta, k, (ak_f32_span){va[0], 4}, (ak_f32_span){va[1], 4}, (ak_f32_span){va[2], 4});
                ak_track_key(tb, k, (ak_f32_span){vb[0], 4}, (ak_f32_span){vb[1], 4}, (ak_f32_span){vb[2], 4});
                AK_CHECK_EQ(ak_track_times(ta).ptr[k], ak_track_times(tb).ptr[k]);
                for (uint32_t c = 0; c < ak_track_component_count(ta); ++c)
                    for (int p = 0; p < 3; ++p) AK_CHECK_EQ(va[p][c], vb[p][c]);
            }
        }
        ak_scene_destroy(b);
        queue_validate(out);
    }
    ak_scene_destroy(a);
}

AK_TEST(bad_input) {
    ak_scene* a = make_scene(AK_INTERP_CUBICSPLINE);
    ak_diag diag;
    char out[1024];
    AK_CHECK_EQ(ak_io_save(NULL, a, NULL, &diag), AK_ERR_NULL_ARG);
    AK_CHECK_EQ(ak_io_save(tmp_path(out, sizeof out, "x.glb"), NULL, NULL, &diag), AK_ERR_NULL_ARG);
    AK_CHECK_EQ(ak_io_save(tmp_path(out, sizeof out, "x.obj"), a, NULL, &diag), AK_ERR_BAD_ARG);
    AK_CHECK_EQ(ak_io_save("/nonexistent-dir/x.glb", a, NULL, &diag), AK_ERR_IO);
    AK_CHECK(strstr(diag.message, "cannot create") != NULL);
    /* a mesh naming a skin the scene lacks */
    a->meshes[0].skin = 3;
    AK_CHECK_EQ(ak_io_save(tmp_path(out, sizeof out, "badskin.glb"), a, NULL, &diag), AK_ERR_BAD_INDEX);
    a->meshes[0].skin = 0;
    /* a NaN position: nothing written */
    a->meshes[0].mesh->positions[2].y = NAN;
    tmp_path(out, sizeof out, "nan.glb");
    AK_CHECK_EQ(ak_io_save(out, a, NULL, &diag), AK_ERR_BAD_DATA);
    struct stat st;
    AK_CHECK(stat(out, &st) != 0);
    ak_scene_destroy(a);
    /* NLERP rotations have no glTF form */
    a = make_scene(AK_INTERP_NLERP);
    AK_CHECK(a != NULL);
    if (a) {
        AK_CHECK_EQ(ak_io_save(tmp_path(out, sizeof out, "nlerp.glb"), a, NULL, &diag), AK_ERR_UNSUPPORTED);
        AK_CHECK(strstr(diag.message, "nlerp") != NULL);
    }
    ak_scene_destroy(a);
}

/* TANGENT read from a real asset (AnimatedMorphCube has TANGENT and morph TANGENT deltas):
 * VEC4, w = +1 or -1, xyz unit; and a tangent whose w is not +-1, or a VEC3 TANGENT, refused. */
static void b64(const unsigned char* in, size_t n, char* out) {
    static const char t[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    size_t o = 0;
    for (size_t i = 0; i < n; i += 3) {
        uint32_t v = (uint32_t)in[i] << 16 | (i + 1 < n ? (uint32_t)in[i + 1] << 8 : 0) | (i + 2 < n ? in[i + 2] : 0);
        out[o++] = t[v >> 18 & 63];
        out[o++] = t[v >> 12 & 63];
        out[o++] = i + 1 < n ? t[v >> 6 & 63] : '=';
        out[o++] = i + 2 < n ? t[v & 63] : '=';
    }
    out[o] = '\0';
}

static ak_result load_tangent_doc(float w, int comps, ak_scene** out, ak_diag* diag) {
    float data[9 + 3 * 4 + 3 * 3] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
    for (int v = 0; v < 3; ++v) {
        data[9 + 3 * v] = 0, data[10 + 3 * v] = 0, data[11 + 3 * v] = 1; /* normals +Z */
        float* t = data + 18 + comps * v;
        t[0] = 1, t[1] = 0, t[2] = 0;
        if (comps == 4) t[3] = w;
    }
    size_t bytes = (size_t)(18 + 3 * comps) * sizeof(float);
    char enc[400], doc[2000];
    b64((const unsigned char*)data, bytes, enc);
    snprintf(doc, sizeof doc,
             "{\"asset\":{\"version\":\"2.0\"},\"buffers\":[{\"byteLength\":%zu,\"uri\":\"data:application/"
             "octet-stream;base64,%s\"}],\"bufferViews\":[{\"buffer\":0,\"byteLength\":36},{\"buffer\":0,"
             "\"byteOffset\":36,\"byteLength\":36},{\"buffer\":0,\"byteOffset\":72,\"byteLength\":%d}],"
             "\"accessors\":[{\"bufferView\":0,\"componentType\":5126,\"count\":3,\"type\":\"VEC3\",\"min\":[0,0,0],"
             "\"max\":[1,1,0]},{\"bufferView\":1,\"componentType\":5126,\"count\":3,\"type\":\"VEC3\"},{\"bufferView\":2,"
             "\"componentType\":5126,\"count\":3,\"type\":\"%s\"}],\"meshes\":[{\"primitives\":[{\"attributes\":"
             "{\"POSITION\":0,\"NORMAL\":1,\"TANGENT\":2}}]}],\"nodes\":[{\"mesh\":0}],\"scenes\":[{\"nodes\":[0]}]}",
             bytes, enc, 12 * comps, comps == 4 ? "VEC4" : "VEC3");
    return ak_io_load_memory(doc, strlen(doc), "tangents.gltf", NULL, NULL, NULL, out, diag);
}

AK_TEST(tangents) {
    ak_scene* s = NULL;
    ak_diag diag;
    AK_CHECK_EQ(load_tangent_doc(-1.0f, 4, &s, &diag), AK_OK);
    if (s) {
        AK_CHECK(s->meshes[0].mesh->tangents != NULL);
        if (s->meshes[0].mesh->tangents) AK_CHECK_EQ(s->meshes[0].mesh->tangents[2].w, -1.0f);
        ak_scene_destroy(s);
        s = NULL;
    }
    AK_CHECK_EQ(load_tangent_doc(0.5f, 4, &s, &diag), AK_ERR_BAD_DATA);
    AK_CHECK_MSG(strstr(diag.message, "TANGENT") != NULL, "%s", diag.message);
    AK_CHECK_EQ(load_tangent_doc(1.0f, 3, &s, &diag), AK_ERR_PARSE);
    AK_CHECK(s == NULL);
    char src[1200];
    if (!ak_test_asset(src, sizeof src, "gltf/AnimatedMorphCube/glTF/AnimatedMorphCube.gltf")) {
        AK_SKIP("AnimatedMorphCube absent");
        return;
    }
    AK_CHECK_EQ(ak_io_load(src, &k_load, NULL, &s, &diag), AK_OK);
    if (!s) return;
    const ak_mesh* m = s->meshes[0].mesh;
    AK_CHECK(m->tangents != NULL && m->morph_tangents != NULL);
    size_t flips = 0;
    for (size_t v = 0; m->tangents && v < m->vertex_count; ++v) {
        ak_vec4 t = m->tangents[v];
        AK_CHECK(fabsf(t.w) == 1.0f);
        AK_CHECK_NEAR(sqrt((double)t.x * t.x + (double)t.y * t.y + (double)t.z * t.z), 1.0, 1e-3);
        flips += t.w < 0;
    }
    printf("  AnimatedMorphCube: %zu tangents (%zu with w = -1), %zu morph targets with TANGENT deltas\n",
           m->vertex_count, flips, m->morph_target_count);
    ak_scene_destroy(s);
}

AK_TEST(builtin_round_trip) {
    const char* names[] = {"humanoid", "cylinder"};
    for (int i = 0; i < 2; ++i) {
        ak_scene* a = NULL;
        if (ak_builtin_create(names[i], NULL, NULL, &a) != AK_OK) {
            AK_FAIL_("builtin %s", names[i]);
            continue;
        }
        char out[1024], name[64];
        snprintf(name, sizeof name, "builtin_%s.glb", names[i]);
        ak_diag diag;
        AK_CHECK_EQ(ak_io_save(tmp_path(out, sizeof out, name), a, NULL, &diag), AK_OK);
        ak_scene* b = NULL;
        AK_CHECK_EQ(ak_io_load(out, &k_load, NULL, &b, &diag), AK_OK);
        if (b) AK_CHECK_EQ(compare_scenes(a, b, name), 0);
        queue_validate(out);
        ak_scene_destroy(a);
        ak_scene_destroy(b);
    }
}

/* Occurrences of needle in the n bytes at s. */
static size_t count_in(const char* s, size_t n, const char* needle) {
    size_t c = 0, k = strlen(needle);
    for (size_t i = 0; i + k <= n; ++i) c += memcmp(s + i, needle, k) == 0;
    return c;
}

/* Vertex-attribute bufferViews (target 34962), glTF meshes, materials and skinned nodes in a
 * written .glb's JSON, counted by hand (not with the library's reader). */
typedef struct glb_counts {
    size_t vertex_views, meshes, materials, skinned;
} glb_counts;

static glb_counts glb_count(const char* path) {
    glb_counts c = {0, 0, 0, 0};
    FILE* fp = fopen(path, "rb");
    unsigned char head[20] = {0};
    if (!fp || fread(head, 1, 20, fp) != 20) {
        if (fp) fclose(fp);
        return c;
    }
    const size_t jn = (size_t)head[12] | (size_t)head[13] << 8 | (size_t)head[14] << 16 | (size_t)head[15] << 24;
    char* json = malloc(jn + 1);
    if (json && fread(json, 1, jn, fp) == jn) {
        c.vertex_views = count_in(json, jn, "34962");
        c.meshes = count_in(json, jn, "\"primitives\"");
        c.materials = count_in(json, jn, "\"baseColorFactor\"");
        c.skinned = count_in(json, jn, "\"skin\":");
    }
    free(json);
    fclose(fp);
    return c;
}

/* Instances (scene.h shares_mesh): the humanoid's mesh placed three times with its skin, twice
 * red and once blue. The file holds the vertices once (as many vertex views as the humanoid
 * written alone) and two glTF meshes (one per colour); read back, the posed vertices match,
 * the two red entries share one ak_mesh and the blue one is blue. */
AK_TEST(instances_round_trip) {
    ak_scene* h = NULL;
    AK_CHECK_EQ(ak_builtin_create("humanoid", NULL, NULL, &h), AK_OK);
    ak_scene* a = NULL;
    AK_CHECK_EQ(ak_scene_alloc(3, 1, 0, NULL, &a), AK_OK);
    if (!h || !a || h->mesh_count != 1 || h->skin_count != 1) {
        ak_scene_destroy(h);
        ak_scene_destroy(a);
        return;
    }
    char one[1024], out[1024];
    ak_diag diag;
    AK_CHECK_EQ(ak_io_save(tmp_path(one, sizeof one, "instances_one.glb"), h, NULL, &diag), AK_OK);
    const glb_counts c1 = glb_count(one);
    /* the instanced scene takes the humanoid's skeleton and mesh */
    a->skeleton = h->skeleton, h->skeleton = NULL;
    AK_CHECK_EQ(ak_scene_skin_alloc(a, 0, h->skins[0].joint_count), AK_OK);
    memcpy(a->skins[0].joints, h->skins[0].joints, h->skins[0].joint_count * sizeof(int32_t));
    memcpy(a->skins[0].inverse_binds, h->skins[0].inverse_binds, h->skins[0].joint_count * sizeof(ak_mat4));
    const ak_vec4 red = {1, 0, 0, 1}, blue = {0, 0, 1, 1};
    for (int m = 0; m < 3; ++m) {
        a->meshes[m] = h->meshes[0];
        a->meshes[m].shares_mesh = m > 0;
        a->meshes[m].has_material = true;
        a->meshes[m].base_color = m == 2 ? blue : red;
        a->meshes[m].texture = -1;
    }
    h->meshes[0].mesh = NULL;
    ak_scene_destroy(h);
    AK_CHECK_EQ(ak_io_save(tmp_path(out, sizeof out, "instances.glb"), a, NULL, &diag), AK_OK);
    const glb_counts c3 = glb_count(out);
    AK_CHECK(c1.vertex_views >= 2);
    AK_CHECK_EQ(c3.vertex_views, c1.vertex_views); /* the vertices once */
    AK_CHECK_EQ(c3.meshes, 2u);                     /* a glTF mesh per colour */
    AK_CHECK_EQ(c3.materials, 2u);
    AK_CHECK_EQ(c3.skinned, 3u);                    /* three instances */
    ak_scene* b = NULL;
    AK_CHECK_EQ(ak_io_load(out, &k_load, NULL, &b, &diag), AK_OK);
    if (b) {
        AK_CHECK_EQ(compare_scenes(a, b, "instances"), 0);
        int red_shared = 0, blue_own = 0, blue_is_blue = 0;
        for (size_t m = 0; m < b->mesh_count; ++m) {
            const bool is_blue = b->meshes[m].base_color.z > 0.5f;
            if (!is_blue && b->meshes[m].shares_mesh) red_shared += b->meshes[m].mesh != NULL;
            if (is_blue) blue_own += !b->meshes[m].shares_mesh, blue_is_blue += b->meshes[m].base_color.x < 0.5f;
        }
        AK_CHECK_EQ(red_shared, 1);
        AK_CHECK_EQ(blue_own, 1);
        AK_CHECK_EQ(blue_is_blue, 1);
    }
    queue_validate(out);
    ak_scene_destroy(a);
    ak_scene_destroy(b);
}

/* ---- memory budget (ak_io_save_desc.memory_budget, ak_io_save_size) --------------------- */

/* Size of a file in bytes, -1 when it does not exist. */
static long long file_size(const char* path) {
    struct stat st;
    return stat(path, &st) == 0 ? (long long)st.st_size : -1;
}

/* The whole file (malloc'd, *n bytes), NULL when it cannot be read. */
static unsigned char* read_all(const char* path, size_t* n) {
    FILE* fp = fopen(path, "rb");
    if (!fp) return NULL;
    fseek(fp, 0, SEEK_END);
    long len = ftell(fp);
    fseek(fp, 0, SEEK_SET);
    unsigned char* b = len >= 0 ? malloc((size_t)len + 1) : NULL;
    if (b && fread(b, 1, (size_t)len, fp) != (size_t)len) free(b), b = NULL;
    fclose(fp);
    *n = (size_t)len;
    return b;
}

/* Files in the test directory whose name starts with prefix (the writer's temporaries are
 * ".NAME.XXXXXX"). */
static int count_prefixed(const char* prefix) {
    DIR* d = opendir(g_tmp);
    int n = 0;
    for (struct dirent* e; d && (e = readdir(d)) != NULL;) n += strncmp(e->d_name, prefix, strlen(prefix)) == 0;
    if (d) closedir(d);
    return n;
}

/* The humanoid's skinned mesh placed three times (shares_mesh), twice red, once blue. */
static ak_scene* make_instances(void) {
    ak_scene *h = NULL, *a = NULL;
    if (ak_builtin_create("humanoid", NULL, NULL, &h) != AK_OK || ak_scene_alloc(3, 1, 0, NULL, &a) != AK_OK ||
        h->mesh_count != 1 || h->skin_count != 1 || ak_scene_skin_alloc(a, 0, h->skins[0].joint_count) != AK_OK) {
        ak_scene_destroy(h);
        ak_scene_destroy(a);
        return NULL;
    }
    a->skeleton = h->skeleton, h->skeleton = NULL;
    memcpy(a->skins[0].joints, h->skins[0].joints, h->skins[0].joint_count * sizeof(int32_t));
    memcpy(a->skins[0].inverse_binds, h->skins[0].inverse_binds, h->skins[0].joint_count * sizeof(ak_mat4));
    for (int m = 0; m < 3; ++m) {
        a->meshes[m] = h->meshes[0];
        a->meshes[m].shares_mesh = m > 0;
        a->meshes[m].has_material = true;
        a->meshes[m].base_color = m == 2 ? ak_vec4_make(0, 0, 1, 1) : ak_vec4_make(1, 0, 0, 1);
        a->meshes[m].texture = -1;
    }
    h->meshes[0].mesh = NULL;
    ak_scene_destroy(h);
    return a;
}

/* One scene, .glb and .gltf (file names of one length: a .gltf holds its .bin's name): the size
 * ak_io_save_size gives ahead is the size of what
 * ak_io_save writes (stat of the .glb, or of the .gltf plus its .bin; for a .glb also the
 * length in its own header); a budget one byte below it is refused (AK_ERR_UNSUPPORTED, the
 * message naming both numbers) with no file and no temporary left; a budget of exactly that
 * size, and a large one, write the same bytes as the default. formats 1: only .glb. Returns
 * the .glb size. */
static size_t check_budget(const ak_scene* s, const char* tag, int formats) {
    size_t glb_size = 0;
    for (int f = 0; f < formats; ++f) {
        const char* ext = f ? "gltf" : "glb";
        char name[128], out[1024], bin[1040], refused[1024], exact[1024], prefix[160];
        ak_diag diag;
        snprintf(name, sizeof name, "budget_%s_D.%s", tag, ext);
        tmp_path(out, sizeof out, name);
        snprintf(bin, sizeof bin, "%.*s.bin", (int)(strlen(out) - 5), out);
        size_t ahead = 0;
        ak_result r = ak_io_save_size(out, s, NULL, &ahead, &diag);
        AK_CHECK_MSG(r == AK_OK, "%s: %s", name, diag.message);
        AK_CHECK_MSG(file_size(out) < 0, "%s: ak_io_save_size wrote a file", name);
        AK_CHECK_EQ(ak_io_save(out, s, NULL, &diag), AK_OK);
        long long written = file_size(out);
        if (f) written += file_size(bin) > 0 ? file_size(bin) : 0;
        AK_CHECK_MSG(written == (long long)ahead, "%s: %zu bytes computed ahead, %lld written", name, ahead, written);
        if (!f) {
            glb_size = ahead;
            size_t n = 0;
            unsigned char* b = read_all(out, &n);
            size_t hl = b && n >= 12 ? (size_t)b[8] | (size_t)b[9] << 8 | (size_t)b[10] << 16 | (size_t)b[11] << 24 : 0;
            AK_CHECK_MSG(hl == n, "%s: GLB header says %zu bytes, the file has %zu", name, hl, n);
            free(b);
        }
        /* one byte short: refused before any file exists */
        snprintf(name, sizeof name, "budget_%s_R.%s", tag, ext);
        tmp_path(refused, sizeof refused, name);
        snprintf(prefix, sizeof prefix, ".budget_%s_R.", tag);
        ak_io_save_desc small = {.memory_budget = ahead - 1};
        r = ak_io_save(refused, s, &small, &diag);
        AK_CHECK_MSG(r == AK_ERR_UNSUPPORTED, "%s: budget %zu below %zu gave %s", name, ahead - 1, ahead, ak_result_string(r));
        char num_a[32], num_b[32];
        snprintf(num_a, sizeof num_a, "%zu", ahead);
        snprintf(num_b, sizeof num_b, "%zu", ahead - 1);
        AK_CHECK_MSG(strstr(diag.message, num_a) && strstr(diag.message, num_b) && strstr(diag.message, "budget"),
                     "%s: message '%s' should name %s and %s", name, diag.message, num_a, num_b);
        AK_CHECK_MSG(file_size(refused) < 0, "%s: a refused save left a file", name);
        snprintf(name, sizeof name, "budget_%s_R.bin", tag);
        AK_CHECK_MSG(file_size(tmp_path(refused, sizeof refused, name)) < 0, "%s: a refused save left a .bin", name);
        AK_CHECK_MSG(count_prefixed(prefix) == 0, "%s: a refused save left a temporary", prefix);
        /* exactly the size, and far above it: the same bytes as the default */
        const size_t budgets[2] = {ahead, (size_t)1 << 40};
        for (int k = 0; k < 2; ++k) {
            snprintf(name, sizeof name, "budget_%s_%d.%s", tag, k, ext);
            tmp_path(exact, sizeof exact, name);
            ak_io_save_desc big = {.memory_budget = budgets[k]};
            r = ak_io_save(exact, s, &big, &diag);
            AK_CHECK_MSG(r == AK_OK, "%s: budget %zu: %s", name, budgets[k], diag.message);
            size_t na = 0, nb = 0;
            unsigned char* a = read_all(out, &na);
            unsigned char* b = read_all(exact, &nb);
            /* a .gltf names its own .bin: compare the binary files, and the JSON up to the uri */
            if (f) {
                char bin2[1040];
                snprintf(bin2, sizeof bin2, "%.*s.bin", (int)(strlen(exact) - 5), exact);
                size_t ma = 0, mb = 0;
                unsigned char* x = read_all(bin, &ma);
                unsigned char* y = read_all(bin2, &mb);
                AK_CHECK_MSG((!x && !y) || (x && y && ma == mb && memcmp(x, y, ma) == 0), "%s: the .bin differs", name);
                free(x);
                free(y);
                /* the same length of name: the JSON differs only in the .bin's uri, one byte */
                size_t differ = 0;
                for (size_t i = 0; a && b && i < na && i < nb; ++i) differ += a[i] != b[i];
                AK_CHECK_MSG(a && b && na == nb && differ == 1, "%s: %zu JSON bytes, %zu without a budget, %zu differ",
                             name, nb, na, differ);
            } else {
                AK_CHECK_MSG(a && b && na == nb && memcmp(a, b, na) == 0, "%s: bytes differ from the default's", name);
            }
            free(a);
            free(b);
        }
    }
    return glb_size;
}

/* ak_io_save_size against the files ak_io_save writes, and the budget refusing and allowing,
 * on: the hand-made scene (skinned, 6 influences, morph targets, STEP/LINEAR/CUBICSPLINE/HERMITE
 * keys), a shared mesh placed three times, the builtin humanoid, and the shared assets
 * (CesiumMan: skinned, animated, a texture; AnimatedMorphCube: morph targets; Fox). */
AK_TEST(save_budget) {
    ak_scene* s = make_scene(AK_INTERP_CUBICSPLINE);
    if (s) check_budget(s, "handmade", 2);
    ak_scene_destroy(s);
    s = make_instances();
    AK_CHECK(s != NULL);
    if (s) check_budget(s, "instances", 2);
    ak_scene_destroy(s);
    s = NULL;
    AK_CHECK_EQ(ak_builtin_create("humanoid", NULL, NULL, &s), AK_OK);
    if (s) {
        size_t n = 0;
        ak_diag diag;
        check_budget(s, "humanoid", 2);
        AK_CHECK_EQ(ak_io_save_size("x.glb", s, NULL, NULL, &diag), AK_ERR_NULL_ARG);
        AK_CHECK_EQ(ak_io_save_size("x.obj", s, NULL, &n, &diag), AK_ERR_BAD_ARG);
        AK_CHECK_EQ(ak_io_save_size("x.glb", NULL, NULL, &n, &diag), AK_ERR_NULL_ARG);
    }
    ak_scene_destroy(s);
    const char* dir = ak_test_assets_dir();
    const char* assets[] = {"CesiumMan", "AnimatedMorphCube", "Fox"};
    for (int i = 0; dir && i < 3; ++i) {
        char src[1200];
        snprintf(src, sizeof src, "%s/gltf/%s/glTF-Binary/%s.glb", dir, assets[i], assets[i]);
        if (file_size(src) < 0) {
            printf("  %s absent\n", src);
            continue;
        }
        ak_diag diag;
        s = NULL;
        AK_CHECK_MSG(ak_io_load(src, &k_load, NULL, &s, &diag) == AK_OK, "%s: %s", src, diag.message);
        /* .gltf on the small one only: the textured ones spend their time encoding PNGs */
        if (s) printf("  %s: %zu bytes as .glb\n", assets[i], check_budget(s, assets[i], i == 1 ? 2 : 1));
        ak_scene_destroy(s);
    }
}

/* BVH motion capture (Euler channels, no mesh) written as glTF: the same poses. */
AK_TEST(bvh_round_trip) {
    char src[1200];
    if (!ak_test_asset(src, sizeof src, "bvh/02_01.bvh")) {
        AK_SKIP("bvh/02_01.bvh absent");
        return;
    }
    ak_scene *a = NULL, *b = NULL;
    ak_diag diag;
    AK_CHECK_EQ(ak_io_load(src, NULL, NULL, &a, &diag), AK_OK);
    char out[1024];
    tmp_path(out, sizeof out, "02_01.glb");
    if (a) AK_CHECK_EQ(ak_io_save(out, a, NULL, &diag), AK_OK);
    AK_CHECK_EQ(ak_io_load(out, NULL, NULL, &b, &diag), AK_OK);
    if (a && b) AK_CHECK_EQ(compare_scenes(a, b, "02_01.bvh"), 0);
    queue_validate(out);
    ak_scene_destroy(a);
    ak_scene_destroy(b);
}

#ifdef AK_CLI_PATH
AK_TEST(cli_export) {
    char out[1024], cmd[4096];
    const char* exts[] = {"glb", "gltf"};
    for (int f = 0; f < 2; ++f) {
        char name[64];
        snprintf(name, sizeof name, "cli_humanoid.%s", exts[f]);
        tmp_path(out, sizeof out, name);
        snprintf(cmd, sizeof cmd, "'%s' export builtin:humanoid -o '%s' >/dev/null 2>&1", AK_CLI_PATH, out);
        AK_CHECK_EQ(system(cmd), 0);
        ak_scene* b = NULL;
        ak_diag diag;
        AK_CHECK_EQ(ak_io_load(out, NULL, NULL, &b, &diag), AK_OK);
        ak_scene* a = NULL;
        ak_builtin_create("humanoid", NULL, NULL, &a);
        if (a && b) {
            AK_CHECK_EQ(ak_scene_joint_count(b) >= ak_scene_joint_count(a), true);
            AK_CHECK_EQ(b->clip_count, a->clip_count);
        }
        ak_scene_destroy(a);
        ak_scene_destroy(b);
        queue_validate(out);
    }
    /* OBJ stays OBJ */
    tmp_path(out, sizeof out, "cli_humanoid.obj");
    snprintf(cmd, sizeof cmd, "'%s' export builtin:humanoid -o '%s' >/dev/null 2>&1", AK_CLI_PATH, out);
    AK_CHECK_EQ(system(cmd), 0);
    FILE* fp = fopen(out, "r");
    char line[256] = "";
    AK_CHECK(fp && fgets(line, sizeof line, fp) && strncmp(line, "# animkit OBJ", 13) == 0);
    if (fp) fclose(fp);
}
#endif

/* ---- the streaming JSON writer against cJSON ------------------------------------------- */

static uint64_t g_jrng = 0x9E3779B97F4A7C15ull;
static uint64_t jrand(void) {
    g_jrng ^= g_jrng << 13, g_jrng ^= g_jrng >> 7, g_jrng ^= g_jrng << 17;
    return g_jrng;
}

/* A number of the kinds the glTF writer prints (floats widened, indices, byte counts) and
 * the edges of cJSON's printing: -0, integers past 2^31 and 10^15, random bit patterns,
 * denormals, NaN and infinities (null). */
static double jnumber(void) {
    switch (jrand() % 10) {
    case 0: return (double)(int32_t)(jrand() % 200000) - 100000;
    case 1: return -0.0;
    case 2: return (double)(jrand() % 100000000000000000ull);
    case 3: {
        uint32_t b = (uint32_t)jrand();
        float f;
        memcpy(&f, &b, 4);
        return f;
    }
    case 4: {
        uint64_t b = jrand();
        double d;
        memcpy(&d, &b, 8);
        return d;
    }
    case 5: return (double)(float)((double)(jrand() % 2000001) / 1000000.0 - 1.0);
    case 6: return (jrand() & 1 ? 1 : -1) * 4.9e-324 * (double)(jrand() % 1000);
    case 7: return (double)(jrand() % 4096) / 64.0;
    case 8: return jrand() % 3 == 0 ? NAN : jrand() & 1 ? INFINITY : -INFINITY;
    default: return (double)(float)((double)(int64_t)jrand() * 1e-12);
    }
}

/* A string of bytes 1..255: quotes, backslashes, control characters, UTF-8 and stray bytes. */
static void jstring(char* s, size_t cap) {
    size_t n = jrand() % (cap - 1);
    static const char special[] = "\"\\\b\f\n\r\t/\x01\x1f\x7f";
    for (size_t i = 0; i < n; ++i) {
        uint64_t r = jrand() % 4;
        s[i] = r == 0 ? special[jrand() % (sizeof special - 1)] : r == 1 ? (char)(1 + jrand() % 255) : (char)('a' + jrand() % 26);
    }
    s[n] = '\0';
}

/* Build the same random value into the cJSON tree (under parent, as key when parent is an
 * object) and into two writers (w[0] to a file, w[1] counting). */
static void jvalue(cJSON* parent, akp_jw* w, int depth) {
    char key[24], str[24];
    const char* k = NULL;
    if (cJSON_IsObject(parent)) {
        jstring(key, sizeof key);
        k = key;
    }
    cJSON* item;
    uint64_t kind = depth >= 5 ? 2 + jrand() % 2 : jrand() % 4;
    if (kind < 2) {
        item = kind == 0 ? cJSON_CreateObject() : cJSON_CreateArray();
        if (kind == 0) for (int i = 0; i < 2; ++i) akp_jw_object(&w[i], k);
        else for (int i = 0; i < 2; ++i) akp_jw_array(&w[i], k);
        size_t n = jrand() % 5;
        for (size_t i = 0; i < n; ++i) jvalue(item, w, depth + 1);
        for (int i = 0; i < 2; ++i) akp_jw_end(&w[i]);
    } else if (kind == 2) {
        double v = jnumber();
        item = cJSON_CreateNumber(v);
        for (int i = 0; i < 2; ++i) akp_jw_number(&w[i], k, v);
    } else {
        jstring(str, sizeof str);
        item = cJSON_CreateString(str);
        for (int i = 0; i < 2; ++i) akp_jw_string(&w[i], k, str);
    }
    if (k) cJSON_AddItemToObject(parent, k, item);
    else cJSON_AddItemToArray(parent, item);
}

/* Random documents written by akp_jw (to a file, and counted) are cJSON_Print's and
 * cJSON_PrintUnformatted's bytes for the same tree. */
AK_TEST(json_writer_matches_cjson) {
    char path[512];
    tmp_path(path, sizeof path, "jw.json");
    int bad = 0;
    for (int doc = 0; doc < AK_TEST_REPS(600, 100) && bad < 3; ++doc) {
        const bool format = doc & 1;
        FILE* f = fopen(path, "wb");
        AK_CHECK(f != NULL);
        if (!f) return;
        akp_jw* w = (akp_jw*)malloc(2 * sizeof *w);
        AK_CHECK(w != NULL);
        if (!w) return;
        akp_jw_init(&w[0], f, format);
        akp_jw_init(&w[1], NULL, format);
        cJSON* root = cJSON_CreateObject();
        for (int i = 0; i < 2; ++i) akp_jw_object(&w[i], NULL);
        size_t n = jrand() % 8;
        for (size_t i = 0; i < n; ++i) jvalue(root, w, 1);
        for (int i = 0; i < 2; ++i) akp_jw_end(&w[i]);
        AK_CHECK(akp_jw_flush(&w[0]));
        fclose(f);
        char* want = format ? cJSON_Print(root) : cJSON_PrintUnformatted(root);
        size_t got_n = 0;
        unsigned char* got = read_all(path, &got_n);
        if (got) got[got_n] = '\0';
        bool same = want && got && got_n == strlen(want) && !memcmp(got, want, got_n) && w[0].bytes == got_n &&
                    w[1].bytes == got_n;
        if (!same && bad++ < 3)
            AK_CHECK_MSG(same, "document %d (%s): %zu bytes written, cJSON prints %zu:\n%.300s\n%.300s", doc,
                         format ? "formatted" : "unformatted", got_n, want ? strlen(want) : 0, got ? (const char*)got : "",
                         want ? want : "");
        free(got);
        cJSON_free(want);
        cJSON_Delete(root);
        free(w);
    }
    AK_CHECK_EQ(bad, 0);
}

int main(void) {
    snprintf(g_tmp, sizeof g_tmp, "%s/test_io_write.XXXXXX", getenv("TMPDIR") ? getenv("TMPDIR") : "/tmp");
    if (!mkdtemp(g_tmp)) {
        perror("mkdtemp");
        return 1;
    }
    AK_RUN(round_trip_assets);
    AK_RUN(interpolation_kept);
    AK_RUN(bad_input);
    AK_RUN(tangents);
    AK_RUN(builtin_round_trip);
    AK_RUN(instances_round_trip);
    AK_RUN(bvh_round_trip);
    AK_RUN(save_budget);
    AK_RUN(json_writer_matches_cjson);
#ifdef AK_CLI_PATH
    AK_RUN_SLOW(cli_export);
#endif
    AK_RUN(validator);
    char cmd[600];
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", g_tmp);
    if (system(cmd) != 0) printf("could not remove %s\n", g_tmp);
    return ak_test_finish();
}

/* Tests of the io module: every glTF in the shared assets checked against the file's own JSON
 * (read here with cJSON, independently of the loader), variants agreeing, bind poses, BVH
 * against a hand FK from the file's OFFSETs and channels, truncation and malformed input with
 * exact codes, synthetic files for each glTF feature, the OBJ writer, allocator failures. */
#include <animkit/io.h>
#include <cjson/cJSON.h>
#include <ctype.h>
#include <dirent.h>
#include <stdint.h>

#include <sys/stat.h>
#include <unistd.h>

#include "ak_test.h"
#include "ref/ref_clip.h" /* double slerp and per-track check of ak_clip_sample */
#include "ref/ref_gltf.h"

/* Assimp 5.2.5 leaks one small object when an import fails (the garbage.bvh case below).
 * The leak is inside libassimp, not animkit, so LeakSanitizer is told to skip that library. */
const char* __lsan_default_suppressions(void);
const char* __lsan_default_suppressions(void) { return "leak:libassimp.so\n"; }

/* The loader's documented joint names: node name, "node_<i>", "<name>#<i>" when taken. */
static void expected_names(const doc* d, char (*names)[AK_NAME_SIZE], int n) {
    for (int i = 0; i < n; ++i) {
        const cJSON* nm = jget(jat(d->root, "nodes", i), "name");
        if (cJSON_IsString(nm) && nm->valuestring[0]) snprintf(names[i], AK_NAME_SIZE, "%s", nm->valuestring);
        else snprintf(names[i], AK_NAME_SIZE, "node_%d", i);
        for (int j = 0; j < i; ++j)
            if (strcmp(names[j], names[i]) == 0) {
                char tmp[AK_NAME_SIZE];
                snprintf(tmp, sizeof tmp, "%.50s#%d", cJSON_IsString(nm) && nm->valuestring[0] ? nm->valuestring : "node", i);
                memcpy(names[i], tmp, sizeof tmp);
                break;
            }
    }
}

/* Every .gltf / .glb under dir (recursive), sorted. */
static int list_gltf(const char* dir, char paths[][512], int max, int n) {
    DIR* dp = opendir(dir);
    if (!dp) return n;
    struct dirent* e;
    while ((e = readdir(dp)) && n < max) {
        if (e->d_name[0] == '.') continue;
        char p[512];
        snprintf(p, sizeof p, "%.400s/%.100s", dir, e->d_name);
        size_t l = strlen(p);
        struct stat st;
        if (stat(p, &st) != 0) continue;
        if (S_ISDIR(st.st_mode)) n = list_gltf(p, paths, max, n);
        else if ((l > 5 && strcmp(p + l - 5, ".gltf") == 0) || (l > 4 && strcmp(p + l - 4, ".glb") == 0))
            snprintf(paths[n++], 512, "%s", p);
    }
    closedir(dp);
    return n;
}

static int cmp_paths(const void* a, const void* b) { return strcmp((const char*)a, (const char*)b); }

static char g_paths[64][512];
static int g_path_count = -1;

static int gltf_assets(void) {
    if (g_path_count >= 0) return g_path_count;
    const char* dir = ak_test_assets_dir();
    g_path_count = 0;
    if (!dir) return 0;
    char gdir[1100];
    snprintf(gdir, sizeof gdir, "%s/gltf", dir);
    g_path_count = list_gltf(gdir, g_paths, 64, 0);
    qsort(g_paths, (size_t)g_path_count, sizeof g_paths[0], cmp_paths);
    return g_path_count;
}

static ak_scene* load(const char* path, ak_result* out_r) {
    ak_scene* s = NULL;
    ak_diag diag;
    ak_result r = ak_io_load(path, NULL, NULL, &s, &diag);
    if (out_r) *out_r = r;
    if (r != AK_OK) printf("  load %s: %s: %s\n", path, ak_result_name(r), diag.message);
    return s;
}

/* ---- desc ---------------------------------------------------------------------------- */

AK_TEST(desc_defaults) {
    ak_io_desc d = ak_io_desc_resolved(NULL);
    AK_CHECK_EQ(d.max_influences, 4);
    AK_CHECK_EQ(d.format, AK_IO_FORMAT_AUTO);
    AK_CHECK(d.min_weight == 0.0f);
    ak_io_desc big = {.max_influences = 99, .min_weight = -1.0f};
    d = ak_io_desc_resolved(&big);
    AK_CHECK_EQ(d.max_influences, AK_MAX_INFLUENCES);
    AK_CHECK(d.min_weight == 0.0f);
    ak_io_desc nan = {.min_weight = NAN};
    AK_CHECK(ak_io_desc_resolved(&nan).min_weight == 0.0f);
}

/* ---- every glTF asset against its own JSON ----------------------------------------------- */

static void check_gltf_file(const char* path) {
    doc d;
    if (!doc_open(&d, path)) {
        AK_FAIL_("test could not read %s", path);
        return;
    }
    ak_scene* s = load(path, NULL);
    AK_CHECK_MSG(s != NULL, "%s did not load", path);
    if (!s) {
        doc_close(&d);
        return;
    }
    const cJSON* root = d.root;
    int n_nodes = jsize(root, "nodes");
    AK_CHECK_EQ(ak_scene_joint_count(s), n_nodes);

    /* Joints: names, parents and rest translations per node. */
    char(*names)[AK_NAME_SIZE] = (char(*)[AK_NAME_SIZE])calloc((size_t)n_nodes + 1, AK_NAME_SIZE);
    int* joint = (int*)calloc((size_t)n_nodes + 1, sizeof(int));
    int* parent = (int*)malloc(((size_t)n_nodes + 1) * sizeof(int));
    expected_names(&d, names, n_nodes);
    for (int i = 0; i < n_nodes; ++i) parent[i] = -1;
    for (int i = 0; i < n_nodes; ++i) {
        cJSON* ch;
        cJSON_ArrayForEach(ch, jget(jat(root, "nodes", i), "children")) parent[ch->valueint] = i;
    }
    int bad_joint = 0;
    for (int i = 0; i < n_nodes; ++i) {
        joint[i] = ak_skeleton_find_joint(s->skeleton, names[i]);
        if (joint[i] < 0) ++bad_joint;
    }
    AK_CHECK_MSG(bad_joint == 0, "%s: %d nodes not found by name", path, bad_joint);
    if (bad_joint == 0 && n_nodes) {
        ak_i32_cspan par = ak_skeleton_parents(s->skeleton);
        ak_transform_cspan rest = ak_skeleton_rest_pose(s->skeleton);
        int bad_parent = 0, bad_rest = 0;
        for (int i = 0; i < n_nodes; ++i) {
            int want = parent[i] < 0 ? -1 : joint[parent[i]];
            if (par.ptr[joint[i]] != want) ++bad_parent;
            const cJSON* t = jget(jat(root, "nodes", i), "translation");
            if (t) {
                ak_vec3 r = rest.ptr[joint[i]].translation;
                double e = fabs(r.x - cJSON_GetArrayItem(t, 0)->valuedouble) +
                           fabs(r.y - cJSON_GetArrayItem(t, 1)->valuedouble) +
                           fabs(r.z - cJSON_GetArrayItem(t, 2)->valuedouble);
                if (e > 1e-6 * (1.0 + ak_vec3_length(r))) ++bad_rest;
            }
        }
        AK_CHECK_MSG(bad_parent == 0, "%s: %d joints with the wrong parent", path, bad_parent);
        AK_CHECK_MSG(bad_rest == 0, "%s: %d rest translations differ", path, bad_rest);
    }

    /* is_joint: exactly the nodes some skin lists. */
    if (bad_joint == 0 && n_nodes) {
        int bad = 0;
        AK_CHECK(s->is_joint != NULL);
        for (int i = 0; s->is_joint && i < n_nodes; ++i) {
            bool listed = false;
            for (int k = 0; k < jsize(root, "skins"); ++k) {
                const cJSON* e;
                cJSON_ArrayForEach(e, jget(jat(root, "skins", k), "joints")) listed = listed || e->valueint == i;
            }
            bad += s->is_joint[joint[i]] != listed;
        }
        AK_CHECK_MSG(bad == 0, "%s: %d joints with the wrong is_joint flag", path, bad);
    }

    /* Skins. */
    AK_CHECK_EQ(s->skin_count, jsize(root, "skins"));
    for (int k = 0; k < jsize(root, "skins") && k < (int)s->skin_count; ++k) {
        const cJSON* sk = jat(root, "skins", k);
        AK_CHECK_EQ(s->skins[k].joint_count, jsize(sk, "joints"));
        int bad = 0;
        for (int j = 0; j < jsize(sk, "joints") && bad_joint == 0; ++j)
            bad += s->skins[k].joints[j] != joint[jat(sk, "joints", j)->valueint];
        AK_CHECK_MSG(bad == 0, "%s skin %d: %d slots map to the wrong joint", path, k, bad);
    }

    /* Meshes: mesh-major, then instancing nodes, then primitives. */
    size_t sm = 0;
    int bad_pos = 0, checked_pos = 0;
    for (int m = 0; m < jsize(root, "meshes"); ++m) {
        const cJSON* mesh = jat(root, "meshes", m);
        int inst[1024], ni = 0;
        for (int i = 0; i < n_nodes && ni < 1024; ++i)
            if (jint(jat(root, "nodes", i), "mesh", -1) == m) inst[ni++] = i;
        if (ni == 0) inst[ni++] = -1;
        for (int k = 0; k < ni; ++k) {
            for (int p = 0; p < jsize(mesh, "primitives"); ++p, ++sm) {
                if (sm >= s->mesh_count) continue;
                const cJSON* prim = jat(mesh, "primitives", p);
                const ak_scene_mesh* got = &s->meshes[sm];
                int pa = jint(jget(prim, "attributes"), "POSITION", -1);
                int vc = accessor_count(&d, pa);
                AK_CHECK_EQ(got->mesh->vertex_count, vc);
                int ia = jint(prim, "indices", -1);
                AK_CHECK_EQ(jint(prim, "mode", 4), 4);
                AK_CHECK_EQ(got->mesh->triangle_count, (ia >= 0 ? accessor_count(&d, ia) : vc) / 3);
                AK_CHECK_EQ(got->node, inst[k] >= 0 ? joint[inst[k]] : -1);
                AK_CHECK_EQ(got->skin, inst[k] >= 0 ? jint(jat(root, "nodes", inst[k]), "skin", -1) : -1);
                AK_CHECK_EQ(got->mesh->morph_target_count, jsize(prim, "targets"));
                AK_CHECK_EQ(got->mesh->normals != NULL, jget(jget(prim, "attributes"), "NORMAL") != NULL);
                if (jget(jget(prim, "attributes"), "JOINTS_0"))
                    AK_CHECK_EQ(got->mesh->influence_count, 4);
                float* raw = (float*)malloc((size_t)vc * 3 * sizeof(float));
                if (doc_floats(&d, pa, 3, raw)) {
                    ++checked_pos;
                    for (int v = 0; v < vc; ++v)
                        if (memcmp(&got->mesh->positions[v], raw + 3 * v, 3 * sizeof(float)) != 0) ++bad_pos;
                }
                free(raw);
            }
        }
    }
    AK_CHECK_EQ(s->mesh_count, sm);
    AK_CHECK_MSG(checked_pos > 0 || jsize(root, "meshes") == 0, "%s: no POSITION accessor could be checked", path);
    AK_CHECK_MSG(bad_pos == 0, "%s: %d positions differ from the file's floats", path, bad_pos);

    /* Clips: names, durations (largest sampler input max) and channel counts. */
    AK_CHECK_EQ(s->clip_count, jsize(root, "animations"));
    for (int a = 0; a < jsize(root, "animations") && a < (int)s->clip_count; ++a) {
        const cJSON* an = jat(root, "animations", a);
        double dur = 0.0;
        const cJSON* smp;
        cJSON_ArrayForEach(smp, jget(an, "samplers")) {
            double mx = jat(jat(root, "accessors", jint(smp, "input", 0)), "max", 0)->valuedouble;
            if (mx > dur) dur = mx;
        }
        AK_CHECK_NEAR(ak_clip_duration(s->clips[a]), dur, 1e-6 * (1.0 + dur));
        size_t channels = 0;
        const cJSON* ch;
        cJSON_ArrayForEach(ch, jget(an, "channels")) {
            const cJSON* tg = jget(ch, "target");
            if (strcmp(jget(tg, "path")->valuestring, "weights") != 0) {
                ++channels;
                continue;
            }
            int node = jint(tg, "node", -1), mesh = jint(jat(root, "nodes", node), "mesh", -1);
            channels += (size_t)jsize(jat(root, "meshes", mesh), "primitives");
        }
        AK_CHECK_EQ(ak_clip_channel_count(s->clips[a]), channels);
        const cJSON* nm = jget(an, "name");
        char want[AK_NAME_SIZE];
        if (cJSON_IsString(nm) && nm->valuestring[0]) snprintf(want, sizeof want, "%s", nm->valuestring);
        else snprintf(want, sizeof want, "animation_%d", a);
        AK_CHECK_STREQ(ak_clip_name(s->clips[a]), want);
    }
    free(names);
    free(joint);
    free(parent);
    ak_scene_destroy(s);
    doc_close(&d);
}

AK_TEST(gltf_assets_match_their_json) {
    int n = gltf_assets();
    if (n == 0) {
        AK_SKIP("no glTF assets (set ANIMKIT_ASSETS or provide ../shared/assets)");
        return;
    }
    for (int i = 0; i < n; ++i) check_gltf_file(g_paths[i]);
    printf("  checked %d glTF files\n", n);
}

/* ---- variants agree ------------------------------------------------------------------- */

/* Equal values (so -0 == 0: CesiumMan's variants write rotations as -0.0 and 0). */
static bool same_floats(const float* a, const float* b, size_t n) {
    for (size_t i = 0; i < n; ++i)
        if (!(a[i] == b[i])) return false;
    return true;
}

static void compare_scenes(const char* what, const ak_scene* a, const ak_scene* b, bool clips) {
    AK_CHECK_MSG(ak_scene_joint_count(a) == ak_scene_joint_count(b), "%s: joint counts differ", what);
    AK_CHECK_MSG(a->mesh_count == b->mesh_count && a->skin_count == b->skin_count && a->clip_count == b->clip_count,
                 "%s: mesh/skin/clip counts differ", what);
    if (ak_scene_joint_count(a) == ak_scene_joint_count(b) && a->skeleton) {
        ak_transform_cspan ra = ak_skeleton_rest_pose(a->skeleton), rb = ak_skeleton_rest_pose(b->skeleton);
        AK_CHECK_MSG(same_floats((const float*)ra.ptr, (const float*)rb.ptr, ra.count * 10), "%s: rest poses differ",
                     what);
    }
    for (size_t m = 0; m < a->mesh_count && m < b->mesh_count; ++m) {
        const ak_mesh *x = a->meshes[m].mesh, *y = b->meshes[m].mesh;
        AK_CHECK_MSG(x->vertex_count == y->vertex_count && x->triangle_count == y->triangle_count &&
                         x->influence_count == y->influence_count && x->morph_target_count == y->morph_target_count,
                     "%s mesh %zu: sizes differ", what, m);
        if (x->vertex_count != y->vertex_count) continue;
        AK_CHECK_MSG(same_floats((const float*)x->positions, (const float*)y->positions, 3 * x->vertex_count),
                     "%s mesh %zu: positions differ", what, m);
        AK_CHECK_MSG(x->triangle_count != y->triangle_count ||
                         memcmp(x->indices, y->indices, 12 * x->triangle_count) == 0,
                     "%s mesh %zu: indices differ", what, m);
        size_t w = x->vertex_count * x->influence_count;
        AK_CHECK_MSG(x->influence_count != y->influence_count ||
                         (same_floats(x->weights, y->weights, w) && (w == 0 || memcmp(x->joints, y->joints, 2 * w) == 0)),
                     "%s mesh %zu: skin weights differ", what, m);
        if (x->morph_target_count == y->morph_target_count)
            AK_CHECK_MSG(same_floats((const float*)x->morph_positions, (const float*)y->morph_positions,
                                     3 * x->vertex_count * x->morph_target_count),
                         "%s mesh %zu: morph targets differ", what, m);
    }
    for (size_t k = 0; k < a->skin_count && k < b->skin_count; ++k)
        AK_CHECK_MSG(a->skins[k].joint_count == b->skins[k].joint_count &&
                         same_floats((const float*)a->skins[k].inverse_binds, (const float*)b->skins[k].inverse_binds,
                                     16 * a->skins[k].joint_count),
                     "%s skin %zu: inverse binds differ", what, k);
    for (size_t c = 0; clips && c < a->clip_count && c < b->clip_count; ++c) {
        AK_CHECK_MSG(ak_clip_duration(a->clips[c]) == ak_clip_duration(b->clips[c]), "%s clip %zu: durations differ",
                     what, c);
        size_t nc = ak_clip_channel_count(a->clips[c]);
        AK_CHECK_MSG(nc == ak_clip_channel_count(b->clips[c]), "%s clip %zu: channel counts differ", what, c);
        for (size_t ch = 0; ch < nc && ch < ak_clip_channel_count(b->clips[c]); ++ch) {
            const ak_track *ta = ak_clip_channel_track(a->clips[c], ch), *tb = ak_clip_channel_track(b->clips[c], ch);
            ak_f32_cspan xa = ak_track_times(ta), xb = ak_track_times(tb);
            AK_CHECK_MSG(xa.count == xb.count && same_floats(xa.ptr, xb.ptr, xa.count),
                         "%s clip %zu channel %zu: key times differ", what, c, ch);
            float va[16], vb[16];
            size_t keys = ak_track_key_count(ta);
            for (size_t k = 0; k < keys && k < ak_track_key_count(tb); ++k) {
                ak_track_key(ta, k, (ak_f32_span)AK_SPAN(va), (ak_f32_span){NULL, 0}, (ak_f32_span){NULL, 0});
                ak_track_key(tb, k, (ak_f32_span)AK_SPAN(vb), (ak_f32_span){NULL, 0}, (ak_f32_span){NULL, 0});
                if (!same_floats(va, vb, ak_track_component_count(ta))) {
                    AK_FAIL_("%s clip %zu channel %zu key %zu: values differ", what, c, ch, k);
                    break;
                }
            }
        }
    }
}

AK_TEST(gltf_variants_agree) {
    static const struct {
        const char* a;
        const char* b;
        bool clips;
    } pairs[] = {
        {"gltf/RiggedSimple/glTF-Binary/RiggedSimple.glb", "gltf/RiggedSimple/glTF-Embedded/RiggedSimple.gltf", true},
        {"gltf/RiggedSimple/glTF-Binary/RiggedSimple.glb", "gltf/RiggedSimple/glTF/RiggedSimple.gltf", true},
        {"gltf/RiggedFigure/glTF-Binary/RiggedFigure.glb", "gltf/RiggedFigure/glTF-Embedded/RiggedFigure.gltf", true},
        {"gltf/RiggedFigure/glTF-Binary/RiggedFigure.glb", "gltf/RiggedFigure/glTF/RiggedFigure.gltf", true},
        /* CesiumMan's two variants carry different animations (README): geometry only. */
        {"gltf/CesiumMan/glTF-Binary/CesiumMan.glb", "gltf/CesiumMan/glTF-Embedded/CesiumMan.gltf", false},
        {"gltf/Fox/glTF-Binary/Fox.glb", "gltf/Fox/glTF/Fox.gltf", true},
        {"gltf/SimpleSkin/glTF-Embedded/SimpleSkin.gltf", "gltf/SimpleSkin/glTF/SimpleSkin.gltf", true},
        {"gltf/SimpleMorph/glTF-Embedded/SimpleMorph.gltf", "gltf/SimpleMorph/glTF/SimpleMorph.gltf", true},
        {"gltf/AnimatedMorphCube/glTF-Binary/AnimatedMorphCube.glb", "gltf/AnimatedMorphCube/glTF/AnimatedMorphCube.gltf",
         true},
        {"gltf/MorphPrimitivesTest/glTF-Binary/MorphPrimitivesTest.glb",
         "gltf/MorphPrimitivesTest/glTF/MorphPrimitivesTest.gltf", true},
    };
    int done = 0;
    for (size_t i = 0; i < sizeof pairs / sizeof pairs[0]; ++i) {
        char pa[2048], pb[2048];
        if (!ak_test_asset(pa, sizeof pa, pairs[i].a) || !ak_test_asset(pb, sizeof pb, pairs[i].b)) continue;
        ak_scene *a = load(pa, NULL), *b = load(pb, NULL);
        AK_CHECK(a && b);
        if (a && b) compare_scenes(pairs[i].b, a, b, pairs[i].clips);
        ak_scene_destroy(a);
        ak_scene_destroy(b);
        ++done;
    }
    if (done == 0) AK_SKIP("no glTF assets");
}

/* ---- bind poses ------------------------------------------------------------------------ */


/* Double-precision 4x4 inverse (Gauss-Jordan with partial pivoting), column-major. */
static bool inverse4d(const double* m, double* out) {
    double a[4][8];
    for (int r = 0; r < 4; ++r)
        for (int c = 0; c < 4; ++c) {
            a[r][c] = m[c * 4 + r];
            a[r][c + 4] = r == c;
        }
    for (int c = 0; c < 4; ++c) {
        int p = c;
        for (int r = c + 1; r < 4; ++r)
            if (fabs(a[r][c]) > fabs(a[p][c])) p = r;
        if (fabs(a[p][c]) < 1e-300) return false;
        for (int k = 0; k < 8; ++k) {
            double t = a[c][k];
            a[c][k] = a[p][k];
            a[p][k] = t;
        }
        double inv = 1.0 / a[c][c];
        for (int k = 0; k < 8; ++k) a[c][k] *= inv;
        for (int r = 0; r < 4; ++r)
            if (r != c) {
                double f = a[r][c];
                for (int k = 0; k < 8; ++k) a[r][k] -= f * a[c][k];
            }
    }
    for (int r = 0; r < 4; ++r)
        for (int c = 0; c < 4; ++c) out[c * 4 + r] = a[r][c + 4];
    return true;
}

/* Largest relative deviation of world(joint) from B * inverse(IBM) over the file's first
 * skin, the IBMs read from the file independently; B = the rest world matrix of the node
 * named bind_node, or the identity when bind_node is NULL. */
static double bind_pose_error(const char* path, const char* bind_node) {
    doc d;
    if (!doc_open(&d, path)) return -1.0;
    ak_scene* s = load(path, NULL);
    double worst = -1.0;
    if (s && s->skin_count) {
        size_t n = ak_scene_joint_count(s);
        ak_transform* local = (ak_transform*)malloc(n * sizeof *local);
        ak_mat4* world = (ak_mat4*)malloc(n * sizeof *world);
        ak_scene_rest_pose(s, (ak_transform_span){local, n});
        ak_scene_world_matrices(s, (ak_transform_cspan){local, n}, (ak_mat4_span){world, n});
        const cJSON* skin = jat(d.root, "skins", 0);
        int jc = jsize(skin, "joints");
        float* ibm = (float*)malloc((size_t)jc * 16 * sizeof(float));
        double place[16] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
        int bn = bind_node ? ak_skeleton_find_joint(s->skeleton, bind_node) : -1;
        for (int e = 0; bn >= 0 && e < 16; ++e) place[e] = world[bn].m[e];
        if ((!bind_node || bn >= 0) && doc_floats(&d, jint(skin, "inverseBindMatrices", -1), 16, ibm)) {
            worst = 0.0;
            for (int k = 0; k < jc; ++k) {
                double m[16], inv[16] = {0};
                for (int e = 0; e < 16; ++e) m[e] = ibm[16 * k + e];
                if (!inverse4d(m, inv)) {
                    worst = 1e30;
                    continue;
                }
                ref_mat4d_mul(place, inv, inv);
                const ak_mat4* w = &world[s->skins[0].joints[k]];
                double scale = 0.0;
                for (int e = 0; e < 16; ++e) scale = fmax(scale, fabs(inv[e]));
                for (int e = 0; e < 16; ++e) worst = fmax(worst, fabs(w->m[e] - inv[e]) / fmax(1.0, scale));
            }
        }
        free(ibm);
        free(local);
        free(world);
    }
    ak_scene_destroy(s);
    doc_close(&d);
    return worst;
}

AK_TEST(gltf_bind_pose_fk) {
    /* Files whose node transforms are their bind pose. The strict relation
     * world(joint) = inverse(IBM) holds where the IBMs were made in model space (SimpleSkin,
     * Fox). RiggedSimple, RiggedFigure and CesiumMan made theirs in the space of an ancestor
     * node: there world(joint) = world(node) * inverse(IBM) for every joint, with node "Z_UP"
     * (RiggedSimple, RiggedFigure) or the skinned mesh node "Cesium_Man" (CesiumMan), and the
     * strict relation must fail. */
    static const struct {
        const char* path;
        const char* bind_node; /* NULL: model space */
    } files[] = {{"gltf/RiggedSimple/glTF-Binary/RiggedSimple.glb", "Z_UP"},
                 {"gltf/RiggedFigure/glTF-Binary/RiggedFigure.glb", "Z_UP"},
                 {"gltf/CesiumMan/glTF-Binary/CesiumMan.glb", "Cesium_Man"},
                 {"gltf/SimpleSkin/glTF/SimpleSkin.gltf", NULL},
                 {"gltf/Fox/glTF-Binary/Fox.glb", NULL}};
    int done = 0;
    for (size_t i = 0; i < sizeof files / sizeof files[0]; ++i) {
        char p[2048];
        if (!ak_test_asset(p, sizeof p, files[i].path)) continue;
        double e_strict = bind_pose_error(p, NULL);
        double e_space = files[i].bind_node ? bind_pose_error(p, files[i].bind_node) : e_strict;
        printf("  %s: relative error %.3g against inverse(IBM), %.3g against world(%s) * inverse(IBM)\n",
               files[i].path, e_strict, e_space, files[i].bind_node ? files[i].bind_node : "-");
        AK_CHECK_MSG(e_space >= 0.0 && e_space <= 1e-4, "%s: bind pose error %.3g", files[i].path, e_space);
        if (files[i].bind_node) AK_CHECK_MSG(e_strict > 1e-2, "%s: expected IBMs outside model space", files[i].path);
        ++done;
    }
    if (done == 0) AK_SKIP("no glTF assets");
}

/* ---- BVH through Assimp ------------------------------------------------------------------ */

typedef struct bvh_joint {
    char name[64];
    int parent;
    double offset[3];
    int nch, ch0;
    char ch[6][12];
} bvh_joint;

typedef struct bvh_file {
    bvh_joint j[128];
    int count, joints, end_sites, channels, frames;
    double frame_time;
    double* motion;
} bvh_file;

static bool bvh_parse(const char* path, bvh_file* b) {
    memset(b, 0, sizeof *b);
    size_t size;
    char* text = (char*)slurp(path, &size);
    if (!text) return false;
    int stack[64], depth = 0, last = -1;
    char* save = NULL;
    for (char* tok = strtok_r(text, " \t\r\n", &save); tok; tok = strtok_r(NULL, " \t\r\n", &save)) {
        if (!strcmp(tok, "ROOT") || !strcmp(tok, "JOINT") || !strcmp(tok, "End")) {
            bvh_joint* j = &b->j[b->count];
            bool end = !strcmp(tok, "End");
            snprintf(j->name, sizeof j->name, "%s", strtok_r(NULL, " \t\r\n", &save));
            if (end) b->end_sites++;
            else b->joints++;
            j->parent = depth ? stack[depth - 1] : -1;
            last = b->count++;
        } else if (!strcmp(tok, "{")) {
            stack[depth++] = last;
        } else if (!strcmp(tok, "}")) {
            --depth;
        } else if (!strcmp(tok, "OFFSET")) {
            for (int k = 0; k < 3; ++k) b->j[last].offset[k] = strtod(strtok_r(NULL, " \t\r\n", &save), NULL);
        } else if (!strcmp(tok, "CHANNELS")) {
            bvh_joint* j = &b->j[last];
            j->nch = atoi(strtok_r(NULL, " \t\r\n", &save));
            j->ch0 = b->channels;
            b->channels += j->nch;
            for (int k = 0; k < j->nch; ++k) snprintf(j->ch[k], sizeof j->ch[k], "%s", strtok_r(NULL, " \t\r\n", &save));
        } else if (!strcmp(tok, "Frames:")) {
            b->frames = atoi(strtok_r(NULL, " \t\r\n", &save));
        } else if (!strcmp(tok, "Time:")) {
            b->frame_time = strtod(strtok_r(NULL, " \t\r\n", &save), NULL);
            size_t n = (size_t)b->frames * (size_t)b->channels;
            b->motion = (double*)malloc(n * sizeof(double));
            for (size_t i = 0; i < n; ++i) {
                char* v = strtok_r(NULL, " \t\r\n", &save);
                b->motion[i] = v ? strtod(v, NULL) : NAN;
            }
        }
    }
    free(text);
    return b->frames > 0;
}

/* World matrix of joint j at frame f: parent * T(offset or position channels) * R(ch1) R(ch2) R(ch3). */
static void bvh_world(const bvh_file* b, int j, int f, double* out) {
    double m[16] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
    const bvh_joint* jt = &b->j[j];
    const double* vals = b->motion + (size_t)f * (size_t)b->channels + jt->ch0;
    m[12] = jt->offset[0];
    m[13] = jt->offset[1];
    m[14] = jt->offset[2];
    for (int k = 0; k < jt->nch; ++k) {
        const char* c = jt->ch[k];
        int axis = c[0] - 'X';
        if (strstr(c, "position")) {
            m[12 + axis] = vals[k]; /* the CMU roots have OFFSET 0: the channel is the position */
        } else {
            double a = vals[k] * 3.14159265358979323846 / 180.0, cs = cos(a), sn = sin(a);
            double r[16] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
            int u = (axis + 1) % 3, v = (axis + 2) % 3;
            r[u * 4 + u] = cs;
            r[u * 4 + v] = sn;
            r[v * 4 + u] = -sn;
            r[v * 4 + v] = cs;
            ref_mat4d_mul(m, r, m);
        }
    }
    if (jt->parent >= 0) {
        double p[16];
        bvh_world(b, jt->parent, f, p);
        ref_mat4d_mul(p, m, m);
    }
    memcpy(out, m, sizeof m);
}

static void check_bvh(const char* rel) {
    char path[2048];
    if (!ak_test_asset(path, sizeof path, rel)) {
        AK_SKIP("%s absent", rel);
        return;
    }
    bvh_file* b = (bvh_file*)calloc(1, sizeof *b);
    AK_CHECK(bvh_parse(path, b));
    ak_scene* s = load(path, NULL);
    AK_CHECK(s != NULL);
    if (!s) {
        free(b->motion);
        free(b);
        return;
    }
    AK_CHECK_EQ(ak_scene_joint_count(s), b->joints + b->end_sites);
    /* joints are the ROOT and JOINT entries; End Sites are nodes but not joints */
    size_t marked = 0;
    for (size_t j = 0; s->is_joint && j < ak_scene_joint_count(s); ++j) marked += s->is_joint[j];
    AK_CHECK(s->is_joint != NULL);
    AK_CHECK_EQ(marked, b->joints);
    AK_CHECK_EQ(s->mesh_count, 0); /* the bone-visualisation mesh is dropped by default */
    AK_CHECK_EQ(s->clip_count, 1);
    const ak_clip* clip = s->clips[0];
    int root = ak_skeleton_find_joint(s->skeleton, b->j[0].name);
    AK_CHECK(root >= 0);
    /* The root's rotation channel: one key per frame, frame_time apart. */
    const ak_track* rt = NULL;
    for (size_t c = 0; c < ak_clip_channel_count(clip); ++c)
        if (ak_clip_channel_index(clip, c) == (uint32_t)root && ak_clip_channel_target(clip, c) == AK_CHANNEL_ROTATION)
            rt = ak_clip_channel_track(clip, c);
    AK_CHECK(rt != NULL);
    if (rt) {
        ak_f32_cspan times = ak_track_times(rt);
        AK_CHECK_EQ(times.count, b->frames);
        AK_CHECK_NEAR(times.ptr[1] - times.ptr[0], b->frame_time, 1e-6);
        AK_CHECK_NEAR(times.ptr[times.count - 1], (b->frames - 1) * b->frame_time, 1e-4);
    }
    AK_CHECK_NEAR(ak_clip_duration(clip), (b->frames - 1) * b->frame_time, 1e-3);
    /* World positions of every joint at a few frames against the hand FK. */
    size_t n = ak_scene_joint_count(s);
    ak_transform* local = (ak_transform*)malloc(n * sizeof *local);
    ak_mat4* world = (ak_mat4*)malloc(n * sizeof *world);
    int frames[3] = {1, b->frames / 2, b->frames - 1};
    double worst = 0.0;
    for (int fi = 0; fi < 3 && rt; ++fi) {
        int f = frames[fi];
        ak_scene_rest_pose(s, (ak_transform_span){local, n});
        ak_clip_sample(clip, ak_track_times(rt).ptr[f], NULL, (ak_transform_span){local, n}, (ak_f32_span){NULL, 0},
                       (ak_f32_span){NULL, 0});
        ak_scene_world_matrices(s, (ak_transform_cspan){local, n}, (ak_mat4_span){world, n});
        for (int j = 0; j < b->count; ++j) {
            if (!strcmp(b->j[j].name, "Site")) continue;
            int k = ak_skeleton_find_joint(s->skeleton, b->j[j].name);
            if (k < 0) {
                AK_FAIL_("%s: joint %s not found", rel, b->j[j].name);
                continue;
            }
            double m[16];
            bvh_world(b, j, f, m);
            for (int e = 0; e < 3; ++e) worst = fmax(worst, fabs(world[k].m[12 + e] - m[12 + e]));
        }
    }
    printf("  %s: %d joints, %d frames, max world position error %.3g\n", rel, b->joints, b->frames, worst);
    AK_CHECK_MSG(worst < 2e-3, "%s: world positions differ from the hand FK by %.3g", rel, worst);
    free(local);
    free(world);
    ak_scene_destroy(s);
    free(b->motion);
    free(b);
}

AK_TEST(bvh_header_and_fk) {
    check_bvh("bvh/49_04.bvh");  /* ZYX everywhere, CRLF */
    check_bvh("bvh/131_03.bvh"); /* ZXY on the arms, CRLF */
    check_bvh("bvh/02_01.bvh");
    check_bvh("bvh/01_01.bvh");  /* 2 MB, 2752 frames */
}

/* ---- OBJ through Assimp ------------------------------------------------------------------ */

AK_TEST(obj_through_assimp) {
    char path[2048];
    if (!ak_test_asset(path, sizeof path, "obj/makehuman/base.obj")) {
        AK_SKIP("obj/makehuman/base.obj absent");
        return;
    }
    /* Independent count: each "f" line of n corners becomes n vertices and n - 2 triangles. */
    size_t size;
    char* text = (char*)slurp(path, &size);
    size_t corners = 0, tris = 0;
    for (char* line = text; line && *line;) {
        char* nl = strchr(line, '\n');
        if (line[0] == 'f' && line[1] == ' ') {
            size_t n = 0;
            for (char* p = line + 1; p < (nl ? nl : line + strlen(line)); ++p)
                if (*p != ' ' && (p[-1] == ' ')) ++n;
            corners += n;
            tris += n - 2;
        }
        line = nl ? nl + 1 : NULL;
    }
    free(text);
    /* animkit's own reader (AUTO for .obj) and Assimp (in its child process) give the same
     * counts, and the same meshes vertex for vertex */
    ak_scene* both[2] = {NULL, NULL};
    for (int k = 0; k < 2; ++k) {
        ak_io_desc desc = {.format = k ? AK_IO_FORMAT_ASSIMP : AK_IO_FORMAT_AUTO};
        ak_diag diag;
        AK_CHECK_EQ(ak_io_load(path, &desc, NULL, &both[k], &diag), AK_OK);
        ak_scene* s = both[k];
        AK_CHECK(s != NULL);
        if (!s) continue;
        size_t v = 0, t = 0;
        for (size_t m = 0; m < s->mesh_count; ++m) {
            v += s->meshes[m].mesh->vertex_count;
            t += s->meshes[m].mesh->triangle_count;
        }
        AK_CHECK_EQ(v, corners);
        AK_CHECK_EQ(t, tris);
        AK_CHECK_EQ(s->clip_count, 0);
    }
    if (both[0] && both[1]) {
        AK_CHECK_EQ(both[0]->mesh_count, both[1]->mesh_count);
        AK_CHECK_EQ(ak_scene_joint_count(both[0]), ak_scene_joint_count(both[1]));
        for (size_t j = 0; j < ak_scene_joint_count(both[0]) && j < ak_scene_joint_count(both[1]); ++j)
            AK_CHECK_STREQ(ak_skeleton_joint_name(both[0]->skeleton, j), ak_skeleton_joint_name(both[1]->skeleton, j));
        for (size_t m = 0; m < both[0]->mesh_count && m < both[1]->mesh_count; ++m) {
            const ak_mesh *a = both[0]->meshes[m].mesh, *b = both[1]->meshes[m].mesh;
            AK_CHECK_STREQ(a->name, b->name);
            AK_CHECK_EQ(both[0]->meshes[m].node, both[1]->meshes[m].node);
            AK_CHECK_EQ(a->vertex_count, b->vertex_count);
            AK_CHECK_EQ(a->uvs != NULL, b->uvs != NULL);
            if (a->vertex_count != b->vertex_count) continue;
            /* Assimp's fast_atof is not correctly rounded: the last bit may differ */
            double worst = 0.0;
            for (size_t i = 0; i < a->vertex_count; ++i) {
                const float* pa = &a->positions[i].x;
                const float* pb = &b->positions[i].x;
                for (int k = 0; k < 3; ++k) worst = fmax(worst, fabs((double)pa[k] - pb[k]) / fmax(1.0, fabs(pb[k])));
                if (a->uvs && b->uvs)
                    worst = fmax(worst, fmax(fabs((double)a->uvs[i].x - b->uvs[i].x), fabs((double)a->uvs[i].y - b->uvs[i].y)));
            }
            AK_CHECK_MSG(worst < 1e-6, "mesh %zu differs by %g", m, worst);
            AK_CHECK(memcmp(a->indices, b->indices, 3 * a->triangle_count * sizeof(uint32_t)) == 0);
        }
    }
    ak_scene_destroy(both[0]);
    ak_scene_destroy(both[1]);
}

/* BVH headers the Assimp path must not turn into nonsense: "Frames: 0" (Assimp's duration
 * wraps to 2^32 - 1 ticks), and a zero or negative Frame Time (1 / Frame Time ticks per
 * second: infinite or negative). */
static ak_result load_bvh_text(const char* frames, const char* frame_time, const char* motion, ak_scene** out) {
    char text[1024];
    snprintf(text, sizeof text,
             "HIERARCHY\nROOT a\n{\nOFFSET 0 0 0\nCHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation "
             "Yrotation\nJOINT b\n{\nOFFSET 0 1 0\nCHANNELS 3 Zrotation Xrotation Yrotation\nEnd Site\n{\nOFFSET 0 1 "
             "0\n}\n}\n}\nMOTION\nFrames: %s\nFrame Time: %s\n%s",
             frames, frame_time, motion);
    FILE* f = fopen("degenerate.bvh", "wb");
    if (!f) return AK_ERR_IO;
    fputs(text, f);
    fclose(f);
    ak_diag diag;
    memset(&diag, 0, sizeof diag);
    ak_result r = ak_io_load("degenerate.bvh", NULL, NULL, out, &diag);
    if (r != AK_OK) printf("  Frames %s, Frame Time %s: %s (%s)\n", frames, frame_time, ak_result_name(r), diag.message);
    return r;
}

AK_TEST(bvh_degenerate_headers) {
    const char* two = "0 0 0 0 0 0 0 0 0\n1 2 3 10 20 30 1 2 3\n";
    ak_scene* s = NULL;
    /* control: 2 frames 0.25 s apart end at 0.25 s */
    AK_CHECK_EQ(load_bvh_text("2", "0.25", two, &s), AK_OK);
    if (s) {
        AK_CHECK_EQ(s->clip_count, 1);
        if (s->clip_count) AK_CHECK_NEAR(ak_clip_duration(s->clips[0]), 0.25, 1e-6);
        ak_scene_destroy(s);
        s = NULL;
    }
    /* no frames: whatever loads must not claim a 4e8-second clip */
    if (load_bvh_text("0", "0.1", "", &s) == AK_OK) {
        for (size_t c = 0; c < s->clip_count; ++c) AK_CHECK_NEAR(ak_clip_duration(s->clips[c]), 0.0, 0);
        ak_scene_destroy(s);
        s = NULL;
    }
    AK_CHECK_EQ(load_bvh_text("2", "0", two, &s), AK_ERR_BAD_DATA);
    AK_CHECK(s == NULL);
    AK_CHECK_EQ(load_bvh_text("2", "-0.1", two, &s), AK_ERR_BAD_DATA);
    AK_CHECK(s == NULL);
    remove("degenerate.bvh");
}

/* ---- synthetic glTF documents ----------------------------------------------------------- */

/* Load a glTF JSON text in which "@BUF@" stands for a base64 data URI of bin. */
static ak_result load_doc(const char* json, const void* bin, size_t bin_size, const ak_io_desc* desc, ak_scene** out,
                          ak_diag* diag) {
    char* b64 = b64_encode(bin, bin_size);
    size_t cap = strlen(json) + strlen(b64) + 64;
    char* text = (char*)malloc(cap);
    const char* at = strstr(json, "@BUF@");
    if (at) snprintf(text, cap, "%.*sdata:application/octet-stream;base64,%s%s", (int)(at - json), json, b64, at + 5);
    else snprintf(text, cap, "%s", json);
    ak_result r = ak_io_load_memory(text, strlen(text), "test.gltf", NULL, desc, NULL, out, diag);
    free(text);
    free(b64);
    return r;
}

static ak_result load_expect(const char* json, const void* bin, size_t bin_size, ak_result want) {
    ak_scene* s = NULL;
    ak_diag diag;
    memset(&diag, 0, sizeof diag);
    ak_result r = load_doc(json, bin, bin_size, NULL, &s, &diag);
    if (r != want) printf("  got %s (%s), wanted %s\n", ak_result_name(r), diag.message, ak_result_name(want));
    if (r != AK_OK) {
        AK_CHECK(s == NULL);
        AK_CHECK(diag.message[0] != 0);
        AK_CHECK_STREQ(diag.path, "test.gltf");
    }
    ak_scene_destroy(s);
    return r;
}

/* One triangle: positions (3 x vec3 float, 36 bytes) then u16 indices 0,1,2 (6 bytes, +2 pad). */
typedef struct tri_bin {
    float pos[9];
    uint16_t idx[4];
} tri_bin;

static const tri_bin k_tri = {{0, 0, 0, 1, 0, 0, 0, 1, 0}, {0, 1, 2, 0}};

#define TRI_BUFFERS                                                                                         \
    "\"buffers\":[{\"byteLength\":44,\"uri\":\"@BUF@\"}],"                                                 \
    "\"bufferViews\":[{\"buffer\":0,\"byteLength\":36},{\"buffer\":0,\"byteOffset\":36,\"byteLength\":6}],"

#define TRI_ACCESSORS                                                                                       \
    "\"accessors\":[{\"bufferView\":0,\"componentType\":5126,\"count\":3,\"type\":\"VEC3\"},"              \
    "{\"bufferView\":1,\"componentType\":5123,\"count\":3,\"type\":\"SCALAR\"}],"

AK_TEST(malformed_gltf_exact_codes) {
    const char* asset = "\"asset\":{\"version\":\"2.0\"}";
    char doc_text[4096];
    /* JSON and header problems */
    load_expect("", NULL, 0, AK_ERR_PARSE);
    load_expect("{\"asset\":{\"version\":\"2.0\"}", NULL, 0, AK_ERR_PARSE); /* unterminated */
    load_expect("[1,2]", NULL, 0, AK_ERR_PARSE);
    load_expect("{}", NULL, 0, AK_ERR_PARSE); /* no asset */
    load_expect("{\"asset\":{\"version\":\"1.0\"}}", NULL, 0, AK_ERR_UNSUPPORTED);
    load_expect("{\"asset\":{\"version\":\"2.0\"},\"extensionsRequired\":[\"KHR_draco_mesh_compression\"]}", NULL, 0,
                AK_ERR_UNSUPPORTED);
    AK_CHECK_EQ(load_expect("{\"asset\":{\"version\":\"2.0\"}}", NULL, 0, AK_OK), AK_OK); /* empty but valid */
    load_expect("{\"asset\":{\"version\":\"2.0\"},\"nodes\":{}}", NULL, 0, AK_ERR_PARSE);
    load_expect("{\"asset\":{\"version\":\"2.0\"},\"scene\":0}", NULL, 0, AK_ERR_BAD_INDEX);
    /* nodes */
    snprintf(doc_text, sizeof doc_text, "{%s,\"nodes\":[{\"children\":[5]}]}", asset);
    load_expect(doc_text, NULL, 0, AK_ERR_BAD_INDEX);
    snprintf(doc_text, sizeof doc_text, "{%s,\"nodes\":[{\"children\":[1]},{\"children\":[0]}]}", asset);
    load_expect(doc_text, NULL, 0, AK_ERR_BAD_HIERARCHY); /* cycle */
    snprintf(doc_text, sizeof doc_text, "{%s,\"nodes\":[{\"children\":[2]},{\"children\":[2]},{}]}", asset);
    load_expect(doc_text, NULL, 0, AK_ERR_BAD_HIERARCHY); /* two parents */
    snprintf(doc_text, sizeof doc_text, "{%s,\"nodes\":[{\"translation\":[0,1e999,0]}]}", asset);
    load_expect(doc_text, NULL, 0, AK_ERR_BAD_DATA);
    snprintf(doc_text, sizeof doc_text, "{%s,\"nodes\":[{\"rotation\":[0,0,0,0]}]}", asset);
    load_expect(doc_text, NULL, 0, AK_ERR_BAD_DATA);
    snprintf(doc_text, sizeof doc_text, "{%s,\"nodes\":[{\"matrix\":[1,0,0,0]}]}", asset);
    load_expect(doc_text, NULL, 0, AK_ERR_PARSE);
    snprintf(doc_text, sizeof doc_text, "{%s,\"nodes\":[{\"mesh\":0}]}", asset);
    load_expect(doc_text, NULL, 0, AK_ERR_BAD_INDEX);
    /* a valid triangle, then broken variants of it */
    const char* mesh = "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0},\"indices\":1}]}],"
                       "\"nodes\":[{\"mesh\":0}]";
    snprintf(doc_text, sizeof doc_text, "{%s," TRI_BUFFERS TRI_ACCESSORS "%s}", asset, mesh);
    AK_CHECK_EQ(load_expect(doc_text, &k_tri, sizeof k_tri, AK_OK), AK_OK);
    tri_bin bad = k_tri;
    bad.idx[2] = 3; /* vertex index out of range */
    load_expect(doc_text, &bad, sizeof bad, AK_ERR_BAD_INDEX);
    bad = k_tri;
    bad.pos[4] = NAN;
    load_expect(doc_text, &bad, sizeof bad, AK_ERR_BAD_DATA);
    load_expect(doc_text, &k_tri, 20, AK_ERR_PARSE); /* buffer shorter than byteLength */
    /* accessor past its bufferView */
    snprintf(doc_text, sizeof doc_text,
             "{%s," TRI_BUFFERS
             "\"accessors\":[{\"bufferView\":0,\"componentType\":5126,\"count\":4,\"type\":\"VEC3\"}],"
             "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0}}]}]}",
             asset);
    load_expect(doc_text, &k_tri, sizeof k_tri, AK_ERR_BAD_INDEX);
    /* bufferView past its buffer */
    snprintf(doc_text, sizeof doc_text,
             "{%s,\"buffers\":[{\"byteLength\":44,\"uri\":\"@BUF@\"}],\"bufferViews\":[{\"buffer\":0,\"byteOffset\":40,"
             "\"byteLength\":36}],"
             "\"accessors\":[{\"bufferView\":0,\"componentType\":5126,\"count\":3,\"type\":\"VEC3\"}],"
             "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0}}]}]}",
             asset);
    load_expect(doc_text, &k_tri, sizeof k_tri, AK_ERR_BAD_INDEX);
    /* bad accessor type and component type */
    snprintf(doc_text, sizeof doc_text,
             "{%s," TRI_BUFFERS "\"accessors\":[{\"bufferView\":0,\"componentType\":5127,\"count\":3,\"type\":\"VEC3\"}],"
             "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0}}]}]}",
             asset);
    load_expect(doc_text, &k_tri, sizeof k_tri, AK_ERR_PARSE);
    /* bad base64 */
    snprintf(doc_text, sizeof doc_text,
             "{%s,\"buffers\":[{\"byteLength\":4,\"uri\":\"data:application/octet-stream;base64,AB!D\"}]," 
             "\"bufferViews\":[{\"buffer\":0,\"byteLength\":4}],"
             "\"accessors\":[{\"bufferView\":0,\"componentType\":5126,\"count\":1,\"type\":\"SCALAR\"}],"
             "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0}}]}]}",
             asset);
    load_expect(doc_text, NULL, 0, AK_ERR_PARSE);
    /* animations: unsorted times, a node path animated twice, no usable channel */
    {
        const float anim[12] = {0, 1, 2, 0, 0, 0, 1, 1, 1, 2, 2, 2};
        const char* fmt = "{%s,\"buffers\":[{\"byteLength\":48,\"uri\":\"@BUF@\"}],"
                          "\"bufferViews\":[{\"buffer\":0,\"byteLength\":12},{\"buffer\":0,\"byteOffset\":12,"
                          "\"byteLength\":36}],\"accessors\":[{\"bufferView\":0,\"componentType\":5126,\"count\":3,"
                          "\"type\":\"SCALAR\"},{\"bufferView\":1,\"componentType\":5126,\"count\":3,\"type\":"
                          "\"VEC3\"}],\"nodes\":[{}],\"animations\":[{\"samplers\":[{\"input\":0,\"output\":1}],"
                          "\"channels\":[%s]}]}";
        const char* one = "{\"sampler\":0,\"target\":{\"node\":0,\"path\":\"translation\"}}";
        snprintf(doc_text, sizeof doc_text, fmt, asset, one);
        AK_CHECK_EQ(load_expect(doc_text, anim, sizeof anim, AK_OK), AK_OK);
        float unsorted[12];
        memcpy(unsorted, anim, sizeof anim);
        unsorted[2] = 0.5f;
        load_expect(doc_text, unsorted, sizeof unsorted, AK_ERR_UNSORTED);
        char two[512];
        snprintf(two, sizeof two, "%s,%s", one, one);
        snprintf(doc_text, sizeof doc_text, fmt, asset, two);
        load_expect(doc_text, anim, sizeof anim, AK_ERR_DUPLICATE);
        snprintf(doc_text, sizeof doc_text, fmt, asset, "{\"sampler\":0,\"target\":{\"node\":0,\"path\":\"pointer\"}}");
        load_expect(doc_text, anim, sizeof anim, AK_ERR_UNSUPPORTED);
        snprintf(doc_text, sizeof doc_text, fmt, asset, "{\"sampler\":0,\"target\":{\"node\":0,\"path\":\"rotation\"}}");
        load_expect(doc_text, anim, sizeof anim, AK_ERR_PARSE); /* 3 values per key for a rotation */
        snprintf(doc_text, sizeof doc_text, fmt, asset, "{\"sampler\":0,\"target\":{\"node\":0,\"path\":\"weights\"}}");
        load_expect(doc_text, anim, sizeof anim, AK_ERR_PARSE); /* node without morph targets */
        snprintf(doc_text, sizeof doc_text, fmt, asset, "{\"sampler\":1,\"target\":{\"node\":0,\"path\":\"scale\"}}");
        load_expect(doc_text, anim, sizeof anim, AK_ERR_BAD_INDEX);
    }
    /* external buffer without a base directory */
    snprintf(doc_text, sizeof doc_text,
             "{%s,\"buffers\":[{\"byteLength\":4,\"uri\":\"missing.bin\"}],\"bufferViews\":[{\"buffer\":0,"
             "\"byteLength\":4}],\"accessors\":[{\"bufferView\":0,\"componentType\":5126,\"count\":1,\"type\":"
             "\"SCALAR\"}],\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0}}]}]}",
             asset);
    load_expect(doc_text, NULL, 0, AK_ERR_IO);
}

/* A skinned triangle: positions, u16 indices, u8 joints, float weights; skin of `slots` joints. */
typedef struct skin_bin {
    float pos[9];
    uint16_t idx[4];
    uint8_t joints[12];
    float weights[12];
    float ibm[32];
} skin_bin;

static void skin_doc(char* out, size_t cap, int slots) {
    snprintf(out, cap,
             "{\"asset\":{\"version\":\"2.0\"},"
             "\"buffers\":[{\"byteLength\":%zu,\"uri\":\"@BUF@\"}],"
             "\"bufferViews\":[{\"buffer\":0,\"byteLength\":36},{\"buffer\":0,\"byteOffset\":36,\"byteLength\":6},"
             "{\"buffer\":0,\"byteOffset\":44,\"byteLength\":12},{\"buffer\":0,\"byteOffset\":56,\"byteLength\":48},"
             "{\"buffer\":0,\"byteOffset\":104,\"byteLength\":128}],"
             "\"accessors\":[{\"bufferView\":0,\"componentType\":5126,\"count\":3,\"type\":\"VEC3\"},"
             "{\"bufferView\":1,\"componentType\":5123,\"count\":3,\"type\":\"SCALAR\"},"
             "{\"bufferView\":2,\"componentType\":5121,\"count\":3,\"type\":\"VEC4\"},"
             "{\"bufferView\":3,\"componentType\":5126,\"count\":3,\"type\":\"VEC4\"},"
             "{\"bufferView\":4,\"componentType\":5126,\"count\":%d,\"type\":\"MAT4\"}],"
             "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0,\"JOINTS_0\":2,\"WEIGHTS_0\":3},"
             "\"indices\":1}]}],"
             "\"skins\":[{\"joints\":[%s],\"inverseBindMatrices\":4}],"
             "\"nodes\":[{\"mesh\":0,\"skin\":0},{\"name\":\"a\",\"children\":[2]},{\"name\":\"b\",\"translation\":[0,1,0]}]}",
             sizeof(skin_bin), slots, slots == 2 ? "1,2" : "1");
}

static skin_bin make_skin_bin(void) {
    skin_bin b;
    memset(&b, 0, sizeof b);
    memcpy(b.pos, k_tri.pos, sizeof b.pos);
    memcpy(b.idx, k_tri.idx, sizeof b.idx);
    for (int v = 0; v < 3; ++v) {
        b.joints[4 * v] = 0;
        b.joints[4 * v + 1] = 1;
        b.weights[4 * v] = 0.75f;
        b.weights[4 * v + 1] = 0.25f;
    }
    for (int k = 0; k < 2; ++k)
        for (int e = 0; e < 16; e += 5) b.ibm[16 * k + e] = 1.0f;
    b.ibm[16 + 13] = -1.0f; /* joint b sits at y = 1 */
    return b;
}

AK_TEST(gltf_skin_weights_and_slots) {
    char text[4096];
    skin_bin b = make_skin_bin();
    skin_doc(text, sizeof text, 2);
    ak_scene* s = NULL;
    ak_diag diag;
    AK_CHECK_EQ(load_doc(text, &b, sizeof b, NULL, &s, &diag), AK_OK);
    if (s) {
        AK_CHECK_EQ(s->skin_count, 1);
        AK_CHECK_EQ(s->skins[0].joints[0], ak_skeleton_find_joint(s->skeleton, "a"));
        AK_CHECK_EQ(s->skins[0].joints[1], ak_skeleton_find_joint(s->skeleton, "b"));
        AK_CHECK_NEAR(s->skins[0].inverse_binds[1].m[13], -1.0f, 0);
        const ak_mesh* m = s->meshes[0].mesh;
        AK_CHECK_EQ(m->influence_count, 4);
        AK_CHECK_NEAR(m->weights[0], 0.75f, 1e-7);
        AK_CHECK_NEAR(m->weights[1], 0.25f, 1e-7);
        AK_CHECK_EQ(m->joints[1], 1);
        AK_CHECK_EQ(s->meshes[0].skin, 0);
        AK_CHECK(s->is_joint && s->is_joint[s->skins[0].joints[1]] && !s->is_joint[s->meshes[0].node]);
        /* Skeleton inverse binds come from the skin. */
        AK_CHECK_NEAR(ak_skeleton_inverse_binds(s->skeleton).ptr[s->skins[0].joints[1]].m[13], -1.0f, 0);
        ak_scene_destroy(s);
    }
    /* max_influences = 1: the larger weight kept, renormalised to 1. */
    ak_io_desc one = {.max_influences = 1};
    s = NULL;
    AK_CHECK_EQ(load_doc(text, &b, sizeof b, &one, &s, &diag), AK_OK);
    if (s) {
        AK_CHECK_EQ(s->meshes[0].mesh->influence_count, 1);
        AK_CHECK_NEAR(s->meshes[0].mesh->weights[0], 1.0f, 1e-6);
        AK_CHECK_EQ(s->meshes[0].mesh->joints[0], 0);
        ak_scene_destroy(s);
    }
    /* A weight on a slot the skin does not have. */
    skin_doc(text, sizeof text, 1);
    load_expect(text, &b, sizeof b, AK_ERR_BAD_INDEX);
    /* A zero weight on a missing slot is harmless (its joint index becomes 0). */
    skin_bin z = b;
    for (int v = 0; v < 3; ++v) {
        z.weights[4 * v] = 1.0f;
        z.weights[4 * v + 1] = 0.0f;
    }
    AK_CHECK_EQ(load_expect(text, &z, sizeof z, AK_OK), AK_OK);
    /* Negative weights. */
    z.weights[0] = -1.0f;
    load_expect(text, &z, sizeof z, AK_ERR_BAD_WEIGHTS);
}

/* Feature file: interleaved (byteStride) positions + normals, normalized u8 weights with
 * JOINTS_1/WEIGHTS_1, a sparse accessor, a matrix node, a strip, STEP and CUBICSPLINE samplers,
 * morph targets with weights animation and names. */
typedef struct feat_bin {
    float inter[4 * 6];      /* 0: 4 vertices x (pos, normal), stride 24 */
    uint8_t j0[16], j1[16];  /* 96, 112 */
    uint8_t w0[16], w1[16];  /* 128, 144: normalized u8 */
    uint16_t sp_idx[2];      /* 160 */
    float sp_val[6];         /* 164 */
    float times[3];          /* 188 */
    float cubic[3 * 3 * 3];  /* 200: 3 keys x (in, value, out) x vec3 */
    float step[3 * 3];       /* 308 */
    float morph_w[3 * 2];    /* 344 */
    float ibm[16 * 8];       /* 368 */
} feat_bin;

AK_TEST(gltf_features) {
    feat_bin b;
    memset(&b, 0, sizeof b);
    const float p[4][3] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {1, 1, 0}};
    for (int v = 0; v < 4; ++v) {
        memcpy(&b.inter[6 * v], p[v], 12);
        b.inter[6 * v + 5] = 1.0f;
        for (int k = 0; k < 4; ++k) {
            b.j0[4 * v + k] = (uint8_t)k;
            b.j1[4 * v + k] = (uint8_t)(4 + k);
        }
        /* weights 51,51,51,0 | 102,0,0,0 (u8/255): the largest is slot 4 (0.4) */
        b.w0[4 * v] = b.w0[4 * v + 1] = b.w0[4 * v + 2] = 51;
        b.w1[4 * v] = 102;
    }
    b.sp_idx[0] = 1;
    b.sp_idx[1] = 3;
    const float spv[6] = {0, 0, 1, 0, 0, 2};
    memcpy(b.sp_val, spv, sizeof spv);
    const float t[3] = {0.0f, 0.5f, 2.0f};
    memcpy(b.times, t, sizeof t);
    for (int i = 0; i < 27; ++i) b.cubic[i] = (float)i;
    for (int i = 0; i < 9; ++i) b.step[i] = (float)(i + 1);
    const float mw[6] = {0, 1, 0.5f, 0.5f, 1, 0};
    memcpy(b.morph_w, mw, sizeof mw);
    for (int k = 0; k < 8; ++k)
        for (int e = 0; e < 16; e += 5) b.ibm[16 * k + e] = 1.0f;
    char text[8192];
    snprintf(text, sizeof text,
        "{\"asset\":{\"version\":\"2.0\"},\"scene\":0,\"scenes\":[{\"nodes\":[0,1]}],"
        "\"buffers\":[{\"byteLength\":%zu,\"uri\":\"@BUF@\"}],"
        "\"bufferViews\":[{\"buffer\":0,\"byteLength\":96,\"byteStride\":24},"
        "{\"buffer\":0,\"byteOffset\":96,\"byteLength\":32},{\"buffer\":0,\"byteOffset\":128,\"byteLength\":32},"
        "{\"buffer\":0,\"byteOffset\":160,\"byteLength\":4},{\"buffer\":0,\"byteOffset\":164,\"byteLength\":24},"
        "{\"buffer\":0,\"byteOffset\":188,\"byteLength\":12},{\"buffer\":0,\"byteOffset\":200,\"byteLength\":108},"
        "{\"buffer\":0,\"byteOffset\":308,\"byteLength\":36},{\"buffer\":0,\"byteOffset\":344,\"byteLength\":24},"
        "{\"buffer\":0,\"byteOffset\":368,\"byteLength\":512}],"
        "\"accessors\":["
        "{\"bufferView\":0,\"componentType\":5126,\"count\":4,\"type\":\"VEC3\"},"                       /* 0 pos */
        "{\"bufferView\":0,\"byteOffset\":12,\"componentType\":5126,\"count\":4,\"type\":\"VEC3\"},"     /* 1 nrm */
        "{\"bufferView\":1,\"componentType\":5121,\"count\":4,\"type\":\"VEC4\"},"                       /* 2 j0 */
        "{\"bufferView\":1,\"byteOffset\":16,\"componentType\":5121,\"count\":4,\"type\":\"VEC4\"},"     /* 3 j1 */
        "{\"bufferView\":2,\"componentType\":5121,\"normalized\":true,\"count\":4,\"type\":\"VEC4\"},"   /* 4 w0 */
        "{\"bufferView\":2,\"byteOffset\":16,\"componentType\":5121,\"normalized\":true,\"count\":4,\"type\":\"VEC4\"}," /* 5 w1 */
        "{\"componentType\":5126,\"count\":4,\"type\":\"VEC3\",\"sparse\":{\"count\":2,"
        "\"indices\":{\"bufferView\":3,\"componentType\":5123},\"values\":{\"bufferView\":4}}},"        /* 6 morph delta */
        "{\"bufferView\":5,\"componentType\":5126,\"count\":3,\"type\":\"SCALAR\",\"max\":[2.0]},"      /* 7 times */
        "{\"bufferView\":6,\"componentType\":5126,\"count\":9,\"type\":\"VEC3\"},"                       /* 8 cubic */
        "{\"bufferView\":7,\"componentType\":5126,\"count\":3,\"type\":\"VEC3\"},"                       /* 9 step */
        "{\"bufferView\":8,\"componentType\":5126,\"count\":6,\"type\":\"SCALAR\"},"                     /* 10 weights */
        "{\"bufferView\":9,\"componentType\":5126,\"count\":8,\"type\":\"MAT4\"}],"                      /* 11 ibm */
        "\"meshes\":[{\"name\":\"quad\",\"weights\":[0.25,0.5],\"extras\":{\"targetNames\":[\"up\",\"down\"]},"
        "\"primitives\":[{\"mode\":5,\"attributes\":{\"POSITION\":0,\"NORMAL\":1,\"JOINTS_0\":2,\"JOINTS_1\":3,"
        "\"WEIGHTS_0\":4,\"WEIGHTS_1\":5},\"targets\":[{\"POSITION\":6},{\"POSITION\":6}]}]}],"
        "\"skins\":[{\"joints\":[1,2,3,4,5,6,7,8],\"inverseBindMatrices\":11}],"
        "\"nodes\":[{\"name\":\"m\",\"mesh\":0,\"skin\":0},"
        "{\"name\":\"r\",\"children\":[2],\"matrix\":[0,1,0,0, -2,0,0,0, 0,0,2,0, 5,6,7,1]},"
        "{\"name\":\"c\",\"children\":[3]},{\"children\":[4]},{\"children\":[5]},{\"children\":[6]},{\"name\":\"r\","
        "\"children\":[7]},{\"children\":[8]},{}],"
        "\"animations\":[{\"channels\":[{\"sampler\":0,\"target\":{\"node\":2,\"path\":\"translation\"}},"
        "{\"sampler\":1,\"target\":{\"node\":3,\"path\":\"scale\"}},{\"sampler\":2,\"target\":{\"node\":0,\"path\":\"weights\"}}],"
        "\"samplers\":[{\"input\":7,\"output\":8,\"interpolation\":\"CUBICSPLINE\"},{\"input\":7,\"output\":9,"
        "\"interpolation\":\"STEP\"},{\"input\":7,\"output\":10}]}]}",
        sizeof b);
    ak_scene* s = NULL;
    ak_diag diag;
    ak_result r = load_doc(text, &b, sizeof b, NULL, &s, &diag);
    AK_CHECK_EQ(r, AK_OK);
    if (r != AK_OK) {
        printf("  %s\n", diag.message);
        return;
    }
    /* names: duplicates and nameless nodes */
    AK_CHECK(ak_skeleton_find_joint(s->skeleton, "r") >= 0);
    AK_CHECK(ak_skeleton_find_joint(s->skeleton, "r#6") >= 0);
    AK_CHECK(ak_skeleton_find_joint(s->skeleton, "node_3") >= 0);
    /* matrix node: columns (0,1,0)*1, (-2,0,0)... -> rotation 90 deg about z, scale (1,2,2) */
    ak_transform rt = ak_skeleton_rest_pose(s->skeleton).ptr[ak_skeleton_find_joint(s->skeleton, "r")];
    AK_CHECK_NEAR(rt.translation.x, 5, 1e-6);
    AK_CHECK_NEAR(rt.translation.z, 7, 1e-6);
    AK_CHECK_NEAR(rt.scale.x, 1, 1e-6);
    AK_CHECK_NEAR(rt.scale.y, 2, 1e-6);
    AK_CHECK_NEAR(rt.scale.z, 2, 1e-6);
    ak_vec3 xr = ak_quat_rotate(rt.rotation, ak_vec3_make(1, 0, 0));
    AK_CHECK_NEAR(xr.y, 1, 1e-6);
    /* strip of 4 vertices -> triangles (0,1,2), (1,3,2) */
    const ak_mesh* m = s->meshes[0].mesh;
    AK_CHECK_EQ(m->triangle_count, 2);
    const uint32_t want_idx[6] = {0, 1, 2, 1, 3, 2};
    for (int i = 0; i < 6; ++i) AK_CHECK_EQ(m->indices[i], want_idx[i]);
    /* interleaved normals */
    AK_CHECK_NEAR(m->normals[3].z, 1, 0);
    AK_CHECK_NEAR(m->positions[3].x, 1, 0);
    /* 8 influences (0.2,0.2,0.2,0,0.4,0,0,0) limited to 4: slot 4 first, then three 0.2 */
    AK_CHECK_EQ(m->influence_count, 4);
    AK_CHECK_EQ(m->joints[0], 4);
    AK_CHECK_NEAR(m->weights[0], 0.4, 1e-6);
    float sum = m->weights[0] + m->weights[1] + m->weights[2] + m->weights[3];
    AK_CHECK_NEAR(sum, 1.0, 1e-6);
    /* sparse morph delta: zeros except vertices 1 and 3 */
    AK_CHECK_EQ(m->morph_target_count, 2);
    AK_CHECK_NEAR(m->morph_positions[1].z, 1, 0);
    AK_CHECK_NEAR(m->morph_positions[3].z, 2, 0);
    AK_CHECK_NEAR(m->morph_positions[2].z, 0, 0);
    AK_CHECK_NEAR(m->morph_positions[4 + 3].z, 2, 0);
    AK_CHECK_NEAR(m->morph_weights[1], 0.5f, 0);
    AK_CHECK_STREQ(m->morph_names[1], "down");
    /* clip: interpolation kept, cubic tangents passed through, weights channel */
    AK_CHECK_EQ(s->clip_count, 1);
    const ak_clip* c = s->clips[0];
    AK_CHECK_STREQ(ak_clip_name(c), "animation_0");
    AK_CHECK_NEAR(ak_clip_duration(c), 2.0, 0);
    AK_CHECK_EQ(ak_clip_channel_count(c), 3);
    AK_CHECK_EQ(ak_clip_channel_interp(c, 0), AK_INTERP_CUBICSPLINE);
    AK_CHECK_EQ(ak_clip_channel_interp(c, 1), AK_INTERP_STEP);
    AK_CHECK_EQ(ak_clip_channel_target(c, 2), AK_CHANNEL_MORPH_WEIGHTS);
    AK_CHECK_EQ(ak_clip_channel_index(c, 2), 0);
    AK_CHECK_EQ(ak_clip_channel_index(c, 0), ak_skeleton_find_joint(s->skeleton, "c"));
    float v[3], tin[3], tout[3];
    ak_track_key(ak_clip_channel_track(c, 0), 1, (ak_f32_span)AK_SPAN(v), (ak_f32_span)AK_SPAN(tin),
                 (ak_f32_span)AK_SPAN(tout));
    /* key 1 = floats 9..17: in (9,10,11), value (12,13,14), out (15,16,17) */
    AK_CHECK_NEAR(tin[0], 9, 0);
    AK_CHECK_NEAR(v[1], 13, 0);
    AK_CHECK_NEAR(tout[2], 17, 0);
    /* STEP holds the previous key; weights channel at t = 0.25 is halfway (0,1)->(0.5,0.5) */
    ak_vec3 scl[16];
    ak_transform local[16];
    float w[2] = {9, 9};
    size_t n = ak_scene_joint_count(s);
    ak_scene_rest_pose(s, (ak_transform_span){local, n});
    ak_clip_sample(c, 0.25f, NULL, (ak_transform_span){local, n}, (ak_f32_span)AK_SPAN(w), (ak_f32_span){NULL, 0});
    (void)scl;
    int j3 = ak_skeleton_find_joint(s->skeleton, "node_3");
    AK_CHECK_NEAR(local[j3].scale.x, 1, 0);
    AK_CHECK_NEAR(w[0], 0.25, 1e-6);
    AK_CHECK_NEAR(w[1], 0.75, 1e-6);
    ak_scene_destroy(s);
}

/* A mesh with two primitives instanced by two nodes: scene meshes come in the documented order
 * (mesh, then instancing node, then primitive), each node's primitives together, node.weights
 * per instance, and a weights channel on the second node writes that node's morph indices. */
AK_TEST(gltf_instanced_primitives_order) {
    float b[16] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 1, 1, 0, /* 4 positions */ 0, 1, /* times */ 0.25f, 1};
    const char* json =
        "{\"asset\":{\"version\":\"2.0\"},\"buffers\":[{\"byteLength\":64,\"uri\":\"@BUF@\"}],"
        "\"bufferViews\":[{\"buffer\":0,\"byteLength\":48},{\"buffer\":0,\"byteOffset\":48,\"byteLength\":8},"
        "{\"buffer\":0,\"byteOffset\":56,\"byteLength\":8}],"
        "\"accessors\":[{\"bufferView\":0,\"componentType\":5126,\"count\":3,\"type\":\"VEC3\"},"
        "{\"bufferView\":0,\"componentType\":5126,\"count\":4,\"type\":\"VEC3\"},"
        "{\"componentType\":5126,\"count\":3,\"type\":\"VEC3\"},{\"componentType\":5126,\"count\":4,\"type\":\"VEC3\"},"
        "{\"bufferView\":1,\"componentType\":5126,\"count\":2,\"type\":\"SCALAR\"},"
        "{\"bufferView\":2,\"componentType\":5126,\"count\":2,\"type\":\"SCALAR\"}],"
        "\"meshes\":[{\"name\":\"two\",\"weights\":[0.5],\"primitives\":["
        "{\"attributes\":{\"POSITION\":0},\"targets\":[{\"POSITION\":2}]},"
        "{\"attributes\":{\"POSITION\":1},\"mode\":6,\"targets\":[{\"POSITION\":3}]}]}],"
        "\"nodes\":[{\"name\":\"a\",\"mesh\":0},{\"name\":\"b\",\"mesh\":0,\"weights\":[0.125]}],"
        "\"animations\":[{\"channels\":[{\"sampler\":0,\"target\":{\"node\":1,\"path\":\"weights\"}}],"
        "\"samplers\":[{\"input\":4,\"output\":5}]}]}";
    ak_scene* s = NULL;
    ak_diag diag;
    ak_result r = load_doc(json, b, sizeof b, NULL, &s, &diag);
    AK_CHECK_EQ(r, AK_OK);
    if (r != AK_OK) {
        printf("  %s\n", diag.message);
        return;
    }
    AK_CHECK_EQ(s->mesh_count, 4);
    if (s->mesh_count == 4) {
        const int na = ak_skeleton_find_joint(s->skeleton, "a"), nb = ak_skeleton_find_joint(s->skeleton, "b");
        const int want_node[4] = {na, na, nb, nb};
        const size_t want_vertices[4] = {3, 4, 3, 4};
        const float want_w[4] = {0.5f, 0.5f, 0.125f, 0.125f};
        for (int m = 0; m < 4; ++m) {
            AK_CHECK_MSG(s->meshes[m].node == want_node[m], "scene mesh %d: node %d, want %d", m, s->meshes[m].node,
                         want_node[m]);
            AK_CHECK_EQ(s->meshes[m].mesh->vertex_count, want_vertices[m]);
            AK_CHECK_NEAR(s->meshes[m].mesh->morph_weights[0], want_w[m], 0);
        }
        /* the weights channel animates node b: morph indices 2 and 3, one channel per primitive */
        const ak_clip* c = s->clips[0];
        AK_CHECK_EQ(ak_clip_channel_count(c), 2);
        float w[4] = {9, 9, 9, 9};
        ak_clip_sample(c, 0.5f, NULL, (ak_transform_span){NULL, 0}, (ak_f32_span)AK_SPAN(w), (ak_f32_span){NULL, 0});
        AK_CHECK_NEAR(w[0], 9, 0);
        AK_CHECK_NEAR(w[1], 9, 0);
        AK_CHECK_NEAR(w[2], 0.625, 1e-6);
        AK_CHECK_NEAR(w[3], 0.625, 1e-6);
    }
    ak_scene_destroy(s);
}

/* ---- truncation -------------------------------------------------------------------------- */

static int cut_everywhere(const char* rel, size_t step) {
    char path[2048];
    if (!ak_test_asset(path, sizeof path, rel)) return 0;
    size_t size;
    uint8_t* data = slurp(path, &size);
    /* a .gltf stays valid JSON when only trailing whitespace is cut */
    size_t valid_from = size;
    if (data[0] == '{')
        while (valid_from > 0 && data[valid_from - 1] != '}') --valid_from;
    int failures = 0, cuts = 0;
    bool glb = size >= 12 && memcmp(data, "glTF", 4) == 0;
    uint8_t* copy = (uint8_t*)malloc(size);
    for (size_t len = 0; len < valid_from; len += (len < 64 ? 1 : step)) {
        ak_scene* s = NULL;
        ak_result r = ak_io_load_memory(data, len, rel, NULL, NULL, NULL, &s, NULL);
        if (r == AK_OK) ++failures;
        ak_scene_destroy(s);
        ++cuts;
        if (glb && len >= 12) {
            /* the same cut with the header's length field fixed, so the chunk checks run */
            memcpy(copy, data, len);
            uint32_t l32 = (uint32_t)len;
            for (int k = 0; k < 4; ++k) copy[8 + k] = (uint8_t)(l32 >> (8 * k));
            s = NULL;
            r = ak_io_load_memory(copy, len, rel, NULL, NULL, NULL, &s, NULL);
            if (r == AK_OK) ++failures;
            ak_scene_destroy(s);
            ++cuts;
        }
    }
    /* Random byte corruption: any outcome but a crash, a leak or a NaN in the scene. */
    ak_rng rng = ak_rng_make(7);
    size_t json_end = size; /* half the corruptions hit the JSON (a GLB's first chunk) */
    if (glb && size >= 20) json_end = 20 + ((size_t)data[12] | (size_t)data[13] << 8 | (size_t)data[14] << 16);
    if (json_end > size) json_end = size;
    static const char alphabet[] = "0123456789{}[]\",:-.eE ";
    for (int trial = 0; trial < 1500; ++trial) {
        memcpy(copy, data, size);
        for (int k = 0; k < 4; ++k) {
            uint32_t pick = ak_rng_u32(&rng);
            if (pick & 1) copy[pick / 2 % json_end] = (uint8_t)alphabet[ak_rng_u32(&rng) % (sizeof alphabet - 1)];
            else copy[pick / 2 % size] = (uint8_t)ak_rng_u32(&rng);
        }
        ak_scene* s = NULL;
        if (ak_io_load_memory(copy, size, rel, NULL, NULL, NULL, &s, NULL) == AK_OK) {
            for (size_t m = 0; m < s->mesh_count; ++m)
                AK_CHECK(ak_mesh_validate(s->meshes[m].mesh, NULL) == AK_OK);
        }
        ak_scene_destroy(s);
    }
    free(copy);
    ak_scene* s = NULL;
    AK_CHECK_EQ(ak_io_load_memory(data, size, rel, NULL, NULL, NULL, &s, NULL), AK_OK);
    ak_scene_destroy(s);
    AK_CHECK_MSG(failures == 0, "%s: %d of %d truncated copies loaded", rel, failures, cuts);
    free(data);
    return cuts;
}

AK_TEST(truncated_files_fail_cleanly) {
    int cuts = 0;
    const size_t every = AK_TEST_REPS(1, 5); /* under valgrind every fifth cut past 64 bytes */
    cuts += cut_everywhere("gltf/SimpleSkin/glTF-Embedded/SimpleSkin.gltf", every);
    cuts += cut_everywhere("gltf/SimpleMorph/glTF-Embedded/SimpleMorph.gltf", every);
    cuts += cut_everywhere("gltf/AnimatedMorphCube/glTF-Binary/AnimatedMorphCube.glb", every);
    cuts += cut_everywhere("gltf/RiggedSimple/glTF-Binary/RiggedSimple.glb", 7 * every);
    if (cuts == 0) AK_SKIP("no glTF assets");
    else printf("  %d truncated copies rejected\n", cuts);
    /* GLB header lies */
    uint8_t glb[12] = {'g', 'l', 'T', 'F', 2, 0, 0, 0, 12, 0, 0, 0};
    ak_scene* s = NULL;
    AK_CHECK_EQ(ak_io_load_memory(glb, 12, "x.glb", NULL, NULL, NULL, &s, NULL), AK_ERR_PARSE); /* no JSON chunk */
    glb[8] = 200;
    AK_CHECK_EQ(ak_io_load_memory(glb, 12, "x.glb", NULL, NULL, NULL, &s, NULL), AK_ERR_PARSE);
    glb[4] = 1;
    AK_CHECK_EQ(ak_io_load_memory(glb, 12, "x.glb", NULL, NULL, NULL, &s, NULL), AK_ERR_UNSUPPORTED);
    AK_CHECK(s == NULL);
}

/* ---- files and arguments ------------------------------------------------------------------ */

AK_TEST(load_arguments_and_missing_files) {
    ak_scene* s = (ak_scene*)1;
    ak_diag diag;
    AK_CHECK_EQ(ak_io_load(NULL, NULL, NULL, &s, &diag), AK_ERR_NULL_ARG);
    AK_CHECK(s == NULL);
    AK_CHECK_EQ(ak_io_load("x.gltf", NULL, NULL, NULL, &diag), AK_ERR_NULL_ARG);
    AK_CHECK_EQ(ak_io_load_memory(NULL, 5, NULL, NULL, NULL, NULL, &s, &diag), AK_ERR_NULL_ARG);
    AK_CHECK_EQ(ak_io_load("no/such/file.gltf", NULL, NULL, &s, &diag), AK_ERR_IO);
    AK_CHECK_STREQ(diag.path, "no/such/file.gltf");
    AK_CHECK_EQ(ak_io_load("no/such/file.bvh", NULL, NULL, &s, &diag), AK_ERR_IO);
    ak_io_desc bvh = {.format = AK_IO_FORMAT_ASSIMP};
    AK_CHECK_EQ(ak_io_load_memory("{}", 2, NULL, NULL, &bvh, NULL, &s, &diag), AK_ERR_UNSUPPORTED);
    /* a garbage BVH: animkit's reader names the line; Assimp (asked for explicitly) rejects it
     * with its own message */
    FILE* f = fopen("garbage.bvh", "wb");
    fputs("HIERARCHY\nROOT x {\n OFFSET 1 2\n", f);
    fclose(f);
    AK_CHECK_EQ(ak_io_load("garbage.bvh", NULL, NULL, &s, &diag), AK_ERR_PARSE);
    AK_CHECK(strstr(diag.message, "OFFSET") != NULL);
    AK_CHECK_STREQ(diag.path, "garbage.bvh");
    ak_io_desc via_assimp = {.format = AK_IO_FORMAT_ASSIMP};
    AK_CHECK_EQ(ak_io_load("garbage.bvh", &via_assimp, NULL, &s, &diag), AK_ERR_PARSE);
    AK_CHECK(strstr(diag.message, "Assimp") != NULL);
    AK_CHECK_STREQ(diag.path, "garbage.bvh");
    remove("garbage.bvh");
    /* a GLB under another extension is still read as glTF (the magic decides) */
    char glbp[2048];
    if (ak_test_asset(glbp, sizeof glbp, "gltf/AnimatedMorphCube/glTF-Binary/AnimatedMorphCube.glb")) {
        size_t n;
        uint8_t* bytes = slurp(glbp, &n);
        f = fopen("cube.bin3d", "wb");
        fwrite(bytes, 1, n, f);
        fclose(f);
        free(bytes);
        AK_CHECK_EQ(ak_io_load("cube.bin3d", NULL, NULL, &s, &diag), AK_OK);
        AK_CHECK(s && s->mesh_count == 1 && s->meshes[0].mesh->morph_target_count == 2);
        ak_scene_destroy(s);
        remove("cube.bin3d");
    }
    /* external .bin missing next to a .gltf */
    f = fopen("ext.gltf", "wb");
    fputs("{\"asset\":{\"version\":\"2.0\"},\"buffers\":[{\"byteLength\":4,\"uri\":\"ext%20missing.bin\"}],"
          "\"bufferViews\":[{\"buffer\":0,\"byteLength\":4}],\"accessors\":[{\"bufferView\":0,\"componentType\":5126,"
          "\"count\":1,\"type\":\"SCALAR\"}],\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0}}]}]}",
          f);
    fclose(f);
    AK_CHECK_EQ(ak_io_load("ext.gltf", NULL, NULL, &s, &diag), AK_ERR_IO);
    AK_CHECK(strstr(diag.message, "ext missing.bin") != NULL); /* percent-decoded */
    /* a directory is not a file: AK_ERR_IO, as the model and as an external buffer (glibc
     * opens a directory and reports a size of LONG_MAX, which once read as out of memory) */
    mkdir("ext missing.bin", 0777);
    AK_CHECK_EQ(ak_io_load("ext.gltf", NULL, NULL, &s, &diag), AK_ERR_IO);
    AK_CHECK(s == NULL);
    AK_CHECK_MSG(strstr(diag.message, "directory") != NULL, "%s", diag.message);
    AK_CHECK_EQ(ak_io_load("ext missing.bin", NULL, NULL, &s, &diag), AK_ERR_IO);
    AK_CHECK(s == NULL);
    rmdir("ext missing.bin");
    remove("ext.gltf");
    /* a FIFO is not a file either (opening it would wait for a writer) */
    remove("fifo.glb");
    if (mkfifo("fifo.glb", 0600) == 0) {
        AK_CHECK_EQ(ak_io_load("fifo.glb", NULL, NULL, &s, &diag), AK_ERR_IO);
        AK_CHECK(s == NULL);
        remove("fifo.glb");
    }
}

/* ---- OBJ writer -------------------------------------------------------------------------- */

AK_TEST(obj_writer) {
    char text[4096];
    skin_bin b = make_skin_bin();
    skin_doc(text, sizeof text, 2);
    ak_scene* s = NULL;
    ak_diag diag;
    AK_CHECK_EQ(load_doc(text, &b, sizeof b, NULL, &s, &diag), AK_OK);
    if (!s) return;
    AK_CHECK_EQ(ak_io_write_obj("io_test.obj", s, NULL, NULL, &diag), AK_OK);
    size_t size;
    char* out = (char*)slurp("io_test.obj", &size);
    AK_CHECK(out && strstr(out, "o mesh_0\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n") != NULL);
    free(out);
    /* posed positions and normals replace the stored ones */
    ak_vec3 posed[3] = {{0.5f, 0, 0}, {1, 2, 3}, {-1, 0.25f, 0}};
    ak_vec3 nrm[3] = {{0, 0, 1}, {0, 0, 1}, {0, 0, 1}};
    const ak_vec3* pp[1] = {posed};
    const ak_vec3* np[1] = {nrm};
    AK_CHECK_EQ(ak_io_write_obj("io_test.obj", s, pp, np, &diag), AK_OK);
    out = (char*)slurp("io_test.obj", &size);
    AK_CHECK(out && strstr(out, "v 0.5 0 0\nv 1 2 3\nv -1 0.25 0\nvn 0 0 1\nvn 0 0 1\nvn 0 0 1\nf 1//1 2//2 3//3\n"));
    free(out);
    posed[1].y = NAN;
    AK_CHECK_EQ(ak_io_write_obj("io_test2.obj", s, pp, NULL, &diag), AK_ERR_BAD_DATA);
    FILE* f = fopen("io_test2.obj", "rb");
    AK_CHECK(f == NULL);
    if (f) fclose(f);
    AK_CHECK_EQ(ak_io_write_obj("no/such/dir/x.obj", s, NULL, NULL, &diag), AK_ERR_IO);
    AK_CHECK_EQ(ak_io_write_obj(NULL, s, NULL, NULL, &diag), AK_ERR_NULL_ARG);
    remove("io_test.obj");
    ak_scene_destroy(s);
}

AK_TEST(obj_writer_offsets_and_round_trip) {
    /* Two meshes: the first without normals or UVs, the second with both, so v/vt/vn offsets
     * differ (v: 3 + 3, vt and vn: only the second mesh's 3). */
    ak_scene* s = NULL;
    AK_CHECK_EQ(ak_scene_alloc(2, 0, 0, NULL, &s), AK_OK);
    if (!s) return;
    ak_mesh_desc d0 = {.vertex_count = 3, .triangle_count = 1, .name = "plain mesh"};
    ak_mesh_desc d1 = {.vertex_count = 3, .triangle_count = 1, .has_normals = true, .has_uvs = true};
    AK_CHECK_EQ(ak_mesh_create(&d0, NULL, &s->meshes[0].mesh), AK_OK);
    AK_CHECK_EQ(ak_mesh_create(&d1, NULL, &s->meshes[1].mesh), AK_OK);
    for (int m = 0; m < 2; ++m)
        for (uint32_t k = 0; k < 3; ++k) {
            s->meshes[m].mesh->indices[k] = 2 - k;
            s->meshes[m].mesh->positions[k] = ak_vec3_make((float)k, (float)m, 0.1f);
        }
    for (int k = 0; k < 3; ++k) {
        s->meshes[1].mesh->normals[k] = ak_vec3_make(0, 0, 1);
        s->meshes[1].mesh->uvs[k] = ak_vec2_make(0.25f * (float)k, 1);
    }
    ak_diag diag;
    AK_CHECK_EQ(ak_io_write_obj("io_offsets.obj", s, NULL, NULL, &diag), AK_OK);
    size_t size;
    char* out = (char*)slurp("io_offsets.obj", &size);
    AK_CHECK(out && strstr(out, "o plain_mesh\nv 0 0 0.100000001\n") != NULL);
    AK_CHECK(out && strstr(out, "f 3 2 1\no mesh_1\n") != NULL);
    AK_CHECK(out && strstr(out, "vt 0.5 1\n") != NULL);
    AK_CHECK(out && strstr(out, "f 6/3/3 5/2/2 4/1/1\n") != NULL);
    free(out);
    remove("io_offsets.obj");
    ak_scene_destroy(s);

    /* Real data: the file's POSITION floats come back bit for bit from the "v" lines. */
    char path[2048];
    if (!ak_test_asset(path, sizeof path, "gltf/Fox/glTF-Binary/Fox.glb")) {
        AK_SKIP("Fox.glb absent");
        return;
    }
    doc dc;
    AK_CHECK(doc_open(&dc, path));
    s = load(path, NULL);
    if (!s) {
        doc_close(&dc);
        return;
    }
    AK_CHECK_EQ(ak_io_write_obj("io_fox.obj", s, NULL, NULL, &diag), AK_OK);
    const cJSON* prim0 = jat(jat(dc.root, "meshes", 0), "primitives", 0);
    int pa = jint(jget(prim0, "attributes"), "POSITION", -1);
    int vc = accessor_count(&dc, pa);
    float* raw = (float*)malloc((size_t)vc * 3 * sizeof(float));
    AK_CHECK(doc_floats(&dc, pa, 3, raw));
    out = (char*)slurp("io_fox.obj", &size);
    int v = 0, bad = 0, faces = 0;
    for (char* line = out; line && *line; line = strchr(line, '\n') ? strchr(line, '\n') + 1 : NULL) {
        if (line[0] == 'v' && line[1] == ' ' && v < vc) {
            char* e = line + 2;
            for (int k = 0; k < 3; ++k) {
                float f = strtof(e, &e);
                bad += memcmp(&f, &raw[3 * v + k], sizeof f) != 0;
            }
            ++v;
        }
        faces += line[0] == 'f';
    }
    AK_CHECK_EQ(v, vc);
    AK_CHECK_EQ(bad, 0);
    AK_CHECK_EQ(faces, vc / 3); /* non-indexed: one face per three vertices, none welded */
    free(out);
    free(raw);
    remove("io_fox.obj");
    ak_scene_destroy(s);
    doc_close(&dc);
}

/* Assimp's bone-visualisation mesh of a BVH: a skinned mesh through the Assimp skin path. */
AK_TEST(bvh_mesh_skin_through_assimp) {
    char path[2048];
    if (!ak_test_asset(path, sizeof path, "bvh/49_04.bvh")) {
        AK_SKIP("bvh/49_04.bvh absent");
        return;
    }
    ak_io_desc desc = {.keep_bvh_mesh = true, .format = AK_IO_FORMAT_ASSIMP};
    ak_scene* s = NULL;
    ak_diag diag;
    ak_result lr = ak_io_load(path, &desc, NULL, &s, &diag);
    AK_CHECK_MSG(lr == AK_OK, "%s: %s", ak_result_name(lr), diag.message);
    if (!s) return;
    AK_CHECK_EQ(s->mesh_count, 1);
    AK_CHECK_EQ(s->skin_count, 1);
    if (s->mesh_count == 1 && s->skin_count == 1) {
        const ak_mesh* m = s->meshes[0].mesh;
        AK_CHECK_EQ(s->meshes[0].skin, 0);
        AK_CHECK(s->skins[0].joint_count > 0);
        AK_CHECK(m->influence_count >= 1 && m->influence_count <= 4);
        AK_CHECK_EQ(ak_mesh_validate_weights(m, s->skins[0].joint_count, 1e-5f, NULL), AK_OK);
        /* Every bone slot names a node; the bind relation world(joint) * offset is the same
         * matrix for all slots (the mesh's bind space). */
        size_t n = ak_scene_joint_count(s);
        ak_transform* local = (ak_transform*)malloc(n * sizeof *local);
        ak_mat4* world = (ak_mat4*)malloc(n * sizeof *world);
        ak_scene_rest_pose(s, (ak_transform_span){local, n});
        ak_scene_world_matrices(s, (ak_transform_cspan){local, n}, (ak_mat4_span){world, n});
        ak_mat4 b0 = ak_mat4_mul(world[s->skins[0].joints[0]], s->skins[0].inverse_binds[0]);
        double worst = 0.0;
        for (size_t k = 0; k < s->skins[0].joint_count; ++k) {
            ak_mat4 b = ak_mat4_mul(world[s->skins[0].joints[k]], s->skins[0].inverse_binds[k]);
            for (int e = 0; e < 16; ++e) worst = fmax(worst, fabs(b.m[e] - b0.m[e]));
        }
        printf("  bone-visualisation mesh: %zu vertices, %zu slots, bind spread %.3g\n", m->vertex_count,
               s->skins[0].joint_count, worst);
        AK_CHECK(worst < 1e-3);
        free(local);
        free(world);
    }
    ak_scene_destroy(s);
}

/* ---- allocator: every allocation failing in turn ------------------------------------------- */


AK_TEST(allocation_failures) {
    char text[4096];
    skin_bin b = make_skin_bin();
    skin_doc(text, sizeof text, 2);
    char* b64 = b64_encode(&b, sizeof b);
    char doc_text[8192];
    const char* at = strstr(text, "@BUF@");
    snprintf(doc_text, sizeof doc_text, "%.*sdata:application/octet-stream;base64,%s%s", (int)(at - text), text, b64,
             at + 5);
    free(b64);
    int ok_at = -1;
    for (int n = 0; n < 400 && ok_at < 0; ++n) {
        ak_test_counter fa = {.fail_from = n + 1};
        ak_allocator a = ak_test_counting_allocator(&fa);
        ak_scene* s = NULL;
        ak_result r = ak_io_load_memory(doc_text, strlen(doc_text), "t.gltf", NULL, NULL, &a, &s, NULL);
        if (r == AK_OK) ok_at = n;
        else AK_CHECK_MSG(r == AK_ERR_NO_MEMORY, "failing allocation %d gave %s", n, ak_result_name(r));
        ak_scene_destroy(s);
        AK_CHECK_MSG(fa.live == 0, "failing allocation %d leaked %d blocks", n, fa.live);
    }
    AK_CHECK(ok_at > 0);
}

/* ---- untrusted input (issue 19) ------------------------------------------------------------ */

/* An allocator that records the largest request and refuses anything above 256 MiB, so a
 * loader that would allocate gigabytes fails the test instead of the machine. */
typedef struct capped_alloc {
    size_t largest;
    int live;
} capped_alloc;
static void* capped_malloc(size_t size, void* user) {
    capped_alloc* c = (capped_alloc*)user;
    if (size > c->largest) c->largest = size;
    if (size > ((size_t)256 << 20)) return NULL;
    void* p = malloc(size);
    if (p) c->live++;
    return p;
}
static void capped_free(void* p, void* user) {
    ((capped_alloc*)user)->live--;
    free(p);
}

static void write_file(const char* path, const void* data, size_t size) {
    FILE* f = fopen(path, "wb");
    AK_CHECK(f != NULL);
    if (!f) return;
    fwrite(data, 1, size, f);
    fclose(f);
}

/* A one-triangle glTF whose buffer is the external uri. */
static void tri_doc_with_uri(char* out, size_t cap, const char* uri, size_t byte_length) {
    snprintf(out, cap,
             "{\"asset\":{\"version\":\"2.0\"},\"buffers\":[{\"byteLength\":%zu,\"uri\":\"%s\"}],"
             "\"bufferViews\":[{\"buffer\":0,\"byteLength\":36},{\"buffer\":0,\"byteOffset\":36,\"byteLength\":6}],"
             TRI_ACCESSORS "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0},\"indices\":1}]}]}",
             byte_length, uri);
}

static ak_result load_tri_file(const char* gltf_path, const char* uri, const ak_io_desc* desc, ak_diag* diag) {
    char text[2048];
    tri_doc_with_uri(text, sizeof text, uri, sizeof k_tri);
    write_file(gltf_path, text, strlen(text));
    ak_scene* s = NULL;
    memset(diag, 0, sizeof *diag);
    ak_result r = ak_io_load(gltf_path, desc, NULL, &s, diag);
    if (r == AK_OK) {
        AK_CHECK_EQ(s->mesh_count, 1);
        if (s->mesh_count) AK_CHECK_NEAR(s->meshes[0].mesh->positions[1].x, 1.0, 0);
    }
    ak_scene_destroy(s);
    return r;
}

/* A buffer uri must not reach outside the model's folder: plain "..", percent-encoded "..",
 * an absolute-looking path, a symlink; explicit roots or allow_any_path let it. */
AK_TEST(gltf_uri_stays_inside_model_dir) {
    mkdir("trav", 0755);
    mkdir("trav/model", 0755);
    write_file("trav/secret.bin", &k_tri, sizeof k_tri);
    write_file("trav/model/inside.bin", &k_tri, sizeof k_tri);
    remove("trav/model/link.bin");
    AK_CHECK_EQ(symlink("../secret.bin", "trav/model/link.bin"), 0);
    ak_diag diag;
    AK_CHECK_EQ(load_tri_file("trav/model/m.gltf", "inside.bin", NULL, &diag), AK_OK);
    AK_CHECK_EQ(load_tri_file("trav/model/m.gltf", "./sub/../inside.bin", NULL, &diag), AK_ERR_IO); /* no sub/ */
    const char* outside[] = {"../secret.bin", "%2E%2E/secret.bin", "%2e%2e%2fsecret.bin", "link.bin",
                             "../model/../secret.bin"};
    for (size_t i = 0; i < sizeof outside / sizeof outside[0]; ++i) {
        ak_result r = load_tri_file("trav/model/m.gltf", outside[i], NULL, &diag);
        AK_CHECK_MSG(r == AK_ERR_IO, "uri %s: %s (%s)", outside[i], ak_result_name(r), diag.message);
        AK_CHECK_MSG(strstr(diag.message, outside[i]) != NULL, "the message names the uri: %s", diag.message);
    }
    printf("  %s\n", diag.message);
    /* the same through ak_io_load_memory with a base directory */
    char text[2048];
    tri_doc_with_uri(text, sizeof text, "%2E%2E/secret.bin", sizeof k_tri);
    ak_scene* s = NULL;
    AK_CHECK_EQ(ak_io_load_memory(text, strlen(text), "m.gltf", "trav/model", NULL, NULL, &s, &diag), AK_ERR_IO);
    /* explicit permission */
    const char* roots[] = {"trav"};
    ak_io_desc extra = {.extra_roots = roots, .extra_root_count = 1};
    AK_CHECK_EQ(load_tri_file("trav/model/m.gltf", "../secret.bin", &extra, &diag), AK_OK);
    AK_CHECK_EQ(load_tri_file("trav/model/m.gltf", "link.bin", &extra, &diag), AK_OK);
    const char* other[] = {"trav/model/inside.bin"}; /* a root that does not hold the file */
    ak_io_desc wrong = {.extra_roots = other, .extra_root_count = 1};
    AK_CHECK_EQ(load_tri_file("trav/model/m.gltf", "../secret.bin", &wrong, &diag), AK_ERR_IO);
    ak_io_desc any = {.allow_any_path = true};
    AK_CHECK_EQ(load_tri_file("trav/model/m.gltf", "%2E%2E/secret.bin", &any, &diag), AK_OK);
    /* a FIFO inside the folder is refused, not waited on (the load used to block forever in
     * fopen; the alarm kills the test instead of hanging it) */
    remove("trav/model/fifo.bin");
    if (mkfifo("trav/model/fifo.bin", 0600) == 0) {
        alarm(30);
        AK_CHECK_EQ(load_tri_file("trav/model/m.gltf", "fifo.bin", NULL, &diag), AK_ERR_IO);
        alarm(0);
        AK_CHECK_MSG(strstr(diag.message, "not a regular file") != NULL, "%s", diag.message);
        remove("trav/model/fifo.bin");
    }
    remove("trav/model/link.bin");
    remove("trav/model/inside.bin");
    remove("trav/model/m.gltf");
    remove("trav/secret.bin");
    rmdir("trav/model");
    rmdir("trav");
}

/* A 170-byte file that declares 2^26 vertices without a bufferView (all zeros, legal) must be
 * refused before the gigabytes are allocated; an explicit small budget is honoured; an
 * external buffer is read for its byteLength only. */
AK_TEST(gltf_memory_budget) {
    const char* tiny = "{\"asset\":{\"version\":\"2.0\"},\"accessors\":[{\"componentType\":5126,\"count\":67108864,"
                       "\"type\":\"VEC3\"}],\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0}}]}]}";
    AK_CHECK(strlen(tiny) <= 170);
    capped_alloc ca = {0, 0};
    ak_allocator a = {capped_malloc, capped_free, &ca};
    ak_scene* s = NULL;
    ak_diag diag;
    ak_result r = ak_io_load_memory(tiny, strlen(tiny), "tiny.gltf", NULL, NULL, &a, &s, &diag);
    printf("  %zu-byte file: %s (%s), largest allocation %zu bytes\n", strlen(tiny), ak_result_name(r), diag.message,
           ca.largest);
    AK_CHECK_EQ(r, AK_ERR_UNSUPPORTED);
    AK_CHECK(strstr(diag.message, "memory budget") != NULL);
    AK_CHECK(ca.largest < ((size_t)1 << 20));
    AK_CHECK_EQ(ca.live, 0);
    ak_scene_destroy(s);
    /* a budget the caller chose: a real file over it fails, under it loads */
    char path[2048];
    if (ak_test_asset(path, sizeof path, "gltf/Fox/glTF-Binary/Fox.glb")) {
        ak_io_desc small = {.memory_budget = 64 * 1024};
        s = NULL;
        AK_CHECK_EQ(ak_io_load(path, &small, NULL, &s, &diag), AK_ERR_UNSUPPORTED);
        AK_CHECK(s == NULL);
        ak_io_desc enough = {.memory_budget = 64 << 20};
        AK_CHECK_EQ(ak_io_load(path, &enough, NULL, &s, &diag), AK_OK);
        ak_scene_destroy(s);
    }
    /* 44 declared bytes of a 4 MiB file: only 44 are read */
    mkdir("budget", 0755);
    size_t big = (size_t)4 << 20;
    uint8_t* bytes = (uint8_t*)calloc(1, big);
    memcpy(bytes, &k_tri, sizeof k_tri);
    write_file("budget/big.bin", bytes, big);
    free(bytes);
    char text[2048];
    tri_doc_with_uri(text, sizeof text, "big.bin", sizeof k_tri);
    ca.largest = 0;
    s = NULL;
    AK_CHECK_EQ(ak_io_load_memory(text, strlen(text), "m.gltf", "budget", NULL, &a, &s, &diag), AK_OK);
    printf("  %zu-byte buffer in a %zu-byte file: largest allocation %zu bytes\n", sizeof k_tri, big, ca.largest);
    AK_CHECK(ca.largest < 65536);
    ak_scene_destroy(s);
    /* a file shorter than byteLength */
    write_file("budget/short.bin", &k_tri, 20);
    tri_doc_with_uri(text, sizeof text, "short.bin", sizeof k_tri);
    s = NULL;
    AK_CHECK_EQ(ak_io_load_memory(text, strlen(text), "m.gltf", "budget", NULL, NULL, &s, &diag), AK_ERR_PARSE);
    AK_CHECK(strstr(diag.message, "short.bin") != NULL);
    remove("budget/big.bin");
    remove("budget/short.bin");
    rmdir("budget");
}

/* One sampler of 65,536 keys shared by 3,000 channels (legal: each on its own node): the clip
 * copies the keys per channel, 3 GB from a 1 MB file. Refused by the budget, before the
 * copies; an allocator that stops at 512 MiB live keeps a failing loader from taking the
 * machine down. */
typedef struct live_cap {
    size_t live_bytes;
    int live;
} live_cap;
static void* live_cap_malloc(size_t size, void* user) {
    live_cap* c = (live_cap*)user;
    if (c->live_bytes + size > ((size_t)512 << 20)) return NULL;
    size_t* p = (size_t*)malloc(size + 16);
    if (!p) return NULL;
    p[0] = size;
    c->live_bytes += size;
    c->live++;
    return (char*)p + 16;
}
static void live_cap_free(void* q, void* user) {
    live_cap* c = (live_cap*)user;
    size_t* p = (size_t*)((char*)q - 16);
    c->live_bytes -= p[0];
    c->live--;
    free(p);
}

AK_TEST(gltf_shared_sampler_amplification) {
    const size_t keys = 65536, nodes = 3000;
    float* bin = (float*)malloc(keys * 4 * sizeof(float));
    for (size_t k = 0; k < keys; ++k) {
        bin[k] = (float)k * 0.01f;
        bin[keys + 3 * k] = bin[keys + 3 * k + 1] = bin[keys + 3 * k + 2] = (float)k;
    }
    mkdir("amp", 0755);
    write_file("amp/anim.bin", bin, keys * 4 * sizeof(float));
    free(bin);
    size_t cap = nodes * 120 + 2048, o = 0;
    char* text = (char*)malloc(cap);
    o += (size_t)snprintf(text + o, cap - o,
                          "{\"asset\":{\"version\":\"2.0\"},\"buffers\":[{\"byteLength\":%zu,\"uri\":\"anim.bin\"}],"
                          "\"bufferViews\":[{\"buffer\":0,\"byteLength\":%zu},{\"buffer\":0,\"byteOffset\":%zu,"
                          "\"byteLength\":%zu}],\"accessors\":[{\"bufferView\":0,\"componentType\":5126,\"count\":%zu,"
                          "\"type\":\"SCALAR\"},{\"bufferView\":1,\"componentType\":5126,\"count\":%zu,\"type\":"
                          "\"VEC3\"}],\"nodes\":[",
                          keys * 16, keys * 4, keys * 4, keys * 12, keys, keys);
    for (size_t n = 0; n < nodes; ++n) o += (size_t)snprintf(text + o, cap - o, "%s{}", n ? "," : "");
    o += (size_t)snprintf(text + o, cap - o, "],\"animations\":[{\"samplers\":[{\"input\":0,\"output\":1}],\"channels\":[");
    for (size_t n = 0; n < nodes; ++n)
        o += (size_t)snprintf(text + o, cap - o, "%s{\"sampler\":0,\"target\":{\"node\":%zu,\"path\":\"translation\"}}",
                              n ? "," : "", n);
    snprintf(text + o, cap - o, "]}]}");
    live_cap lc = {0, 0};
    ak_allocator a = {live_cap_malloc, live_cap_free, &lc};
    ak_scene* s = NULL;
    ak_diag diag;
    ak_result r = ak_io_load_memory(text, strlen(text), "amp.gltf", "amp", NULL, &a, &s, &diag);
    printf("  3000 channels on one 65536-key sampler: %s (%s)\n", ak_result_name(r), diag.message);
    AK_CHECK_EQ(r, AK_ERR_UNSUPPORTED);
    AK_CHECK(strstr(diag.message, "memory budget") != NULL);
    AK_CHECK_EQ(lc.live, 0);
    ak_scene_destroy(s);
    /* the same file with 30 channels loads */
    char* cut = strstr(text, "\"channels\":[");
    char* thirty = cut;
    for (int k = 0; k < 31 && thirty; ++k) thirty = strstr(thirty + 1, "{\"sampler\"");
    if (thirty) {
        snprintf(thirty - 1, 5, "]}]}");
        s = NULL;
        AK_CHECK_EQ(ak_io_load_memory(text, strlen(text), "amp.gltf", "amp", NULL, &a, &s, &diag), AK_OK);
        if (s) AK_CHECK_EQ(s->clip_count, 1);
        ak_scene_destroy(s);
    }
    free(text);
    remove("amp/anim.bin");
    rmdir("amp");
}

/* glTF requires key times >= 0: a negative first time is refused like decreasing times. */
AK_TEST(gltf_negative_key_times) {
    const float anim[12] = {-1, 0, 1, 0, 0, 0, 1, 1, 1, 2, 2, 2};
    const char* doc_text = "{\"asset\":{\"version\":\"2.0\"},\"buffers\":[{\"byteLength\":48,\"uri\":\"@BUF@\"}],"
                           "\"bufferViews\":[{\"buffer\":0,\"byteLength\":12},{\"buffer\":0,\"byteOffset\":12,"
                           "\"byteLength\":36}],\"accessors\":[{\"bufferView\":0,\"componentType\":5126,\"count\":3,"
                           "\"type\":\"SCALAR\"},{\"bufferView\":1,\"componentType\":5126,\"count\":3,\"type\":"
                           "\"VEC3\"}],\"nodes\":[{}],\"animations\":[{\"samplers\":[{\"input\":0,\"output\":1}],"
                           "\"channels\":[{\"sampler\":0,\"target\":{\"node\":0,\"path\":\"translation\"}}]}]}";
    AK_CHECK_EQ(load_expect(doc_text, anim, sizeof anim, AK_ERR_UNSORTED), AK_ERR_UNSORTED);
    float ok[12];
    memcpy(ok, anim, sizeof ok);
    ok[0] = 0.0f, ok[1] = 0.5f; /* 0 is allowed */
    AK_CHECK_EQ(load_expect(doc_text, ok, sizeof ok, AK_OK), AK_OK);
}

/* An empty or random .glb is "not a GLB", not "invalid JSON". */
AK_TEST(glb_bad_magic) {
    const uint8_t junk[16] = {0x89, 'P', 'N', 'G', 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12};
    const struct {
        const void* data;
        size_t size;
    } cases[] = {{"", 0}, {junk, sizeof junk}, {"glTX\2\0\0\0", 8}};
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; ++i) {
        ak_scene* s = NULL;
        ak_diag diag;
        AK_CHECK_EQ(ak_io_load_memory(cases[i].data, cases[i].size, "x.glb", NULL, NULL, NULL, &s, &diag), AK_ERR_PARSE);
        AK_CHECK_MSG(strstr(diag.message, "not a GLB (bad magic") != NULL, "case %zu: %s", i, diag.message);
    }
    write_file("empty.glb", "", 0);
    ak_scene* s = NULL;
    ak_diag diag;
    AK_CHECK_EQ(ak_io_load("empty.glb", NULL, NULL, &s, &diag), AK_ERR_PARSE);
    AK_CHECK(strstr(diag.message, "not a GLB") != NULL);
    remove("empty.glb");
}

/* A BVH text with a chain of depth joints and the given motion header and data. */
static char* bvh_chain(size_t depth, const char* frames, const char* data) {
    size_t cap = depth * 100 + strlen(data) + 512;
    char* t = (char*)malloc(cap);
    size_t o = (size_t)snprintf(t, cap, "HIERARCHY\nROOT j0\n{\nOFFSET 0 0 0\nCHANNELS 6 Xposition Yposition "
                                        "Zposition Zrotation Xrotation Yrotation\n");
    for (size_t i = 1; i < depth; ++i)
        o += (size_t)snprintf(t + o, cap - o, "JOINT j%zu\n{\nOFFSET 0 1 0\nCHANNELS 3 Zrotation Xrotation Yrotation\n", i);
    o += (size_t)snprintf(t + o, cap - o, "End Site\n{\nOFFSET 0 1 0\n}\n");
    for (size_t i = 0; i < depth; ++i) t[o++] = '}', t[o++] = '\n';
    snprintf(t + o, cap - o, "MOTION\nFrames: %s\nFrame Time: 0.1\n%s", frames, data);
    return t;
}

static ak_result load_bvh_mem(const char* text, size_t size, const ak_io_desc* desc, capped_alloc* ca, ak_diag* diag) {
    ak_allocator a = {capped_malloc, capped_free, ca};
    ak_scene* s = NULL;
    memset(diag, 0, sizeof *diag);
    ak_result r = ak_io_load_memory(text, size, "t.bvh", NULL, desc, &a, &s, diag);
    ak_scene_destroy(s);
    AK_CHECK_MSG(ca->live == 0, "%d blocks leaked", ca->live);
    return r;
}

/* The attacks Assimp's BVH importer failed: deep nesting, a huge Frames count, leaks on
 * failure; and truncated motion data. Through ak_io_load (file, streamed) and from memory. */
AK_TEST(bvh_hostile_files) {
    ak_io_desc as_bvh = {.format = AK_IO_FORMAT_BVH};
    capped_alloc ca = {0, 0};
    ak_diag diag;
    /* 30,000 nested JOINTs: a clean error, no recursion */
    char* deep = bvh_chain(30000, "1", "");
    AK_CHECK_EQ(load_bvh_mem(deep, strlen(deep), &as_bvh, &ca, &diag), AK_ERR_UNSUPPORTED);
    printf("  30000 nested joints: %s\n", diag.message);
    write_file("deep.bvh", deep, strlen(deep));
    ak_scene* s = NULL;
    AK_CHECK_EQ(ak_io_load("deep.bvh", NULL, NULL, &s, &diag), AK_ERR_UNSUPPORTED);
    AK_CHECK(strstr(diag.message, "deeper") != NULL);
    remove("deep.bvh");
    free(deep);
    /* the documented depth limit itself loads */
    const char* frame = "0 0 0 0 0 0";
    size_t d = AK_IO_BVH_MAX_DEPTH - 1; /* the End Site is one level deeper */
    char* data = (char*)malloc(d * 16 + 64);
    size_t o = (size_t)sprintf(data, "%s", frame);
    for (size_t i = 1; i < d; ++i) o += (size_t)sprintf(data + o, " 0 0 0");
    data[o++] = '\n';
    data[o] = 0;
    char* ok = bvh_chain(d, "1", data);
    AK_CHECK_EQ(load_bvh_mem(ok, strlen(ok), &as_bvh, &ca, &diag), AK_OK);
    free(ok);
    free(data);
    /* an End Site that is the 65th node (the node array grows as it is added; found by
     * fuzz_bvh: its name was read from the array just freed) */
    char* grow = bvh_chain(64, "0", "");
    s = NULL;
    AK_CHECK_EQ(ak_io_load_memory(grow, strlen(grow), "t.bvh", NULL, &as_bvh, NULL, &s, &diag), AK_OK);
    if (s) {
        AK_CHECK_EQ(ak_scene_joint_count(s), 65);
        if (ak_scene_joint_count(s) == 65) AK_CHECK_STREQ(ak_skeleton_joint_name(s->skeleton, 64), "EndSite_j63");
    }
    ak_scene_destroy(s);
    free(grow);
    /* Frames: 4000000000 with two lines: refused without allocating for the claim */
    const char* two = "0 0 0 0 0 0 0 0 0\n1 2 3 10 20 30 1 2 3\n";
    char* huge = bvh_chain(2, "4000000000", two);
    ca.largest = 0;
    AK_CHECK_EQ(load_bvh_mem(huge, strlen(huge), &as_bvh, &ca, &diag), AK_ERR_UNSUPPORTED);
    printf("  Frames: 4000000000: %s (largest allocation %zu bytes)\n", diag.message, ca.largest);
    AK_CHECK(ca.largest < ((size_t)1 << 20));
    write_file("huge.bvh", huge, strlen(huge));
    AK_CHECK_EQ(ak_io_load("huge.bvh", NULL, NULL, &s, &diag), AK_ERR_UNSUPPORTED);
    remove("huge.bvh");
    free(huge);
    /* a count within the budget but more than the data: the data decides (an error) */
    char* more = bvh_chain(2, "1000000", two);
    ca.largest = 0;
    AK_CHECK_EQ(load_bvh_mem(more, strlen(more), &as_bvh, &ca, &diag), AK_ERR_PARSE);
    AK_CHECK(strstr(diag.message, "after 2 complete frames") != NULL);
    AK_CHECK(ca.largest < ((size_t)1 << 20));
    free(more);
    /* extra values after the declared frames, a non-number, an infinite value */
    char* extra = bvh_chain(2, "1", two);
    AK_CHECK_EQ(load_bvh_mem(extra, strlen(extra), &as_bvh, &ca, &diag), AK_ERR_PARSE);
    free(extra);
    char* word = bvh_chain(2, "1", "0 0 0 0 0 0 0 0 x\n");
    AK_CHECK_EQ(load_bvh_mem(word, strlen(word), &as_bvh, &ca, &diag), AK_ERR_PARSE);
    free(word);
    char* long_time = bvh_chain(2, "2", two); /* Frame Time 0.1 -> 1e38: the second key is at 1e38 */
    char* ft = strstr(long_time, "0.1\n");
    if (ft) {
        memmove(ft + 4, ft + 3, strlen(ft + 3) + 1);
        memcpy(ft, "4e38", 4);
        AK_CHECK_EQ(load_bvh_mem(long_time, strlen(long_time), &as_bvh, &ca, &diag), AK_ERR_BAD_DATA);
    }
    free(long_time);
    char* inf = bvh_chain(2, "1", "0 0 0 0 0 0 0 0 1e999\n");
    AK_CHECK_EQ(load_bvh_mem(inf, strlen(inf), &as_bvh, &ca, &diag), AK_ERR_BAD_DATA);
    free(inf);
    /* Frames: 0 -> the skeleton and no clip */
    char* none = bvh_chain(2, "0", "");
    s = NULL;
    AK_CHECK_EQ(ak_io_load_memory(none, strlen(none), "t.bvh", NULL, NULL, NULL, &s, &diag), AK_OK); /* AUTO */
    if (s) {
        AK_CHECK_EQ(ak_scene_joint_count(s), 3);
        AK_CHECK_EQ(s->clip_count, 0);
    }
    ak_scene_destroy(s);
    free(none);
    /* every allocation failing in turn: AK_ERR_NO_MEMORY, nothing leaked */
    char* small = bvh_chain(3, "2", "0 0 0 0 0 0 0 0 0 0 0 0\n1 2 3 10 20 30 1 2 3 4 5 6\n");
    int ok_at = -1;
    for (int n = 0; n < 100 && ok_at < 0; ++n) {
        ak_test_counter fa = {.fail_from = n + 1};
        ak_allocator a = ak_test_counting_allocator(&fa);
        s = NULL;
        ak_result r = ak_io_load_memory(small, strlen(small), "t.bvh", NULL, NULL, &a, &s, NULL);
        if (r == AK_OK) ok_at = n;
        else AK_CHECK_MSG(r == AK_ERR_NO_MEMORY, "failing allocation %d gave %s", n, ak_result_name(r));
        ak_scene_destroy(s);
        AK_CHECK_MSG(fa.live == 0, "failing allocation %d leaked %d blocks", n, fa.live);
    }
    AK_CHECK(ok_at > 0);
    free(small);
}

/* Rotation channels apply in the order listed, intrinsically (R = R1 R2 R3 on column
 * vectors); position channels replace the OFFSET's axes they name, also on a JOINT. Checked
 * against rotations written out by hand for 90-degree angles. */
AK_TEST(bvh_channel_semantics) {
    const char* text = "HIERARCHY\nROOT r\n{\nOFFSET 5 5 5\nCHANNELS 3 Zrotation Xrotation Yrotation\n"
                       "JOINT c\n{\nOFFSET 1 0 0\nCHANNELS 2 Yposition Xrotation\nEnd Site\n{\nOFFSET 0 0 1\n}\n}\n}\n"
                       "MOTION\nFrames: 1\nFrame Time: 0.5\n90 90 0 7 0\n";
    ak_scene* s = NULL;
    ak_diag diag;
    AK_CHECK_EQ(ak_io_load_memory(text, strlen(text), "t.bvh", NULL, NULL, NULL, &s, &diag), AK_OK);
    if (!s) return;
    size_t n = ak_scene_joint_count(s);
    AK_CHECK_EQ(n, 3);
    AK_CHECK_STREQ(ak_skeleton_joint_name(s->skeleton, 2), "EndSite_c");
    ak_transform local[3];
    ak_mat4 world[3];
    ak_scene_rest_pose(s, (ak_transform_span){local, 3});
    ak_clip_sample(s->clips[0], 0.0f, NULL, (ak_transform_span){local, 3}, (ak_f32_span){NULL, 0},
                   (ak_f32_span){NULL, 0});
    ak_scene_world_matrices(s, (ak_transform_cspan){local, 3}, (ak_mat4_span){world, 3});
    /* Rz(90) Rx(90): x -> (0,1,0), y -> (0,0,1), z -> (1,0,0). Child at 5 + R (1, 7, 0)
     * (Yposition 7 replaces the OFFSET's y) = (5,5,5) + (0,1,0) + 7 (0,0,1) = (5, 6, 12). */
    AK_CHECK_NEAR(world[1].m[12], 5.0, 1e-5);
    AK_CHECK_NEAR(world[1].m[13], 6.0, 1e-5);
    AK_CHECK_NEAR(world[1].m[14], 12.0, 1e-5);
    /* End Site: child rotation Rz Rx (child Rx 0) -> its (0,0,1) maps to (1,0,0). */
    AK_CHECK_NEAR(world[2].m[12], 6.0, 1e-5);
    AK_CHECK_NEAR(world[2].m[13], 6.0, 1e-5);
    AK_CHECK_NEAR(world[2].m[14], 12.0, 1e-5);
    ak_scene_destroy(s);
}

/* animkit's reader against Assimp's on the shared files (while Assimp can still read them):
 * same names, parents, channel count, duration, and world joint positions at several frames. */
static void compare_bvh_readers(const char* rel) {
    char path[2048];
    if (!ak_test_asset(path, sizeof path, rel)) {
        AK_SKIP("%s absent", rel);
        return;
    }
    ak_io_desc via_assimp = {.format = AK_IO_FORMAT_ASSIMP};
    ak_scene *own = NULL, *ref = NULL;
    ak_diag diag;
    AK_CHECK_EQ(ak_io_load(path, NULL, NULL, &own, &diag), AK_OK);
    ak_result lr = ak_io_load(path, &via_assimp, NULL, &ref, &diag);
    AK_CHECK_MSG(lr == AK_OK, "%s: %s", ak_result_name(lr), diag.message);
    if (!own || !ref) {
        ak_scene_destroy(own);
        ak_scene_destroy(ref);
        return;
    }
    size_t n = ak_scene_joint_count(own);
    AK_CHECK_EQ(n, ak_scene_joint_count(ref));
    for (size_t j = 0; j < n && j < ak_scene_joint_count(ref); ++j) {
        AK_CHECK_STREQ(ak_skeleton_joint_name(own->skeleton, j), ak_skeleton_joint_name(ref->skeleton, j));
        AK_CHECK_EQ(ak_skeleton_parents(own->skeleton).ptr[j], ak_skeleton_parents(ref->skeleton).ptr[j]);
        AK_CHECK_EQ(own->is_joint[j], ref->is_joint[j]);
    }
    AK_CHECK_EQ(own->clip_count, 1);
    AK_CHECK_EQ(ref->clip_count, 1);
    const ak_clip *a = own->clips[0], *b = ref->clips[0];
    AK_CHECK_STREQ(ak_clip_name(a), ak_clip_name(b));
    AK_CHECK_EQ(ak_clip_channel_count(a), ak_clip_channel_count(b));
    AK_CHECK_NEAR(ak_clip_duration(a), ak_clip_duration(b), 1e-5);
    ak_transform* la = (ak_transform*)malloc(n * sizeof *la);
    ak_transform* lb = (ak_transform*)malloc(n * sizeof *lb);
    ak_mat4* wa = (ak_mat4*)malloc(n * sizeof *wa);
    ak_mat4* wb = (ak_mat4*)malloc(n * sizeof *wb);
    double worst = 0.0, scale = 1e-9;
    for (int k = 0; k <= 6; ++k) {
        float t = ak_clip_duration(a) * (float)k / 6.0f;
        ak_scene_rest_pose(own, (ak_transform_span){la, n});
        ak_scene_rest_pose(ref, (ak_transform_span){lb, n});
        ak_clip_sample(a, t, NULL, (ak_transform_span){la, n}, (ak_f32_span){NULL, 0}, (ak_f32_span){NULL, 0});
        ak_clip_sample(b, t, NULL, (ak_transform_span){lb, n}, (ak_f32_span){NULL, 0}, (ak_f32_span){NULL, 0});
        ak_scene_world_matrices(own, (ak_transform_cspan){la, n}, (ak_mat4_span){wa, n});
        ak_scene_world_matrices(ref, (ak_transform_cspan){lb, n}, (ak_mat4_span){wb, n});
        for (size_t j = 0; j < n; ++j)
            for (int e = 12; e < 15; ++e) {
                worst = fmax(worst, fabs(wa[j].m[e] - wb[j].m[e]));
                scale = fmax(scale, fabs(wb[j].m[e]));
            }
    }
    printf("  %s: %zu nodes, largest world position difference to Assimp %.3g (positions up to %.3g)\n", rel, n, worst,
           scale);
    AK_CHECK(worst <= 1e-5 * scale);
    free(la);
    free(lb);
    free(wa);
    free(wb);
    ak_scene_destroy(own);
    ak_scene_destroy(ref);
}

AK_TEST(bvh_reader_matches_assimp) {
    compare_bvh_readers("bvh/49_04.bvh");
    compare_bvh_readers("bvh/02_01.bvh");
    compare_bvh_readers("bvh/131_03.bvh");
}

/* Every prefix of a BVH fails cleanly (49_04's hierarchy and first 20 frames: every cut in
 * the hierarchy and the first 2 KiB of motion, every 61st byte after). A cut inside the last
 * number can still be a valid file; every earlier cut must fail. */
AK_TEST(bvh_truncated_prefixes_fail) {
    char path[2048];
    if (!ak_test_asset(path, sizeof path, "bvh/49_04.bvh")) {
        AK_SKIP("bvh/49_04.bvh absent");
        return;
    }
    size_t size;
    char* text = (char*)slurp(path, &size);
    char* motion = strstr(text, "MOTION");
    char* first = motion ? strstr(motion, "Time:") : NULL;
    first = first ? strchr(first, '\n') : NULL;
    AK_CHECK(first != NULL);
    if (!first) {
        free(text);
        return;
    }
    ++first;
    char* end = first;
    for (int f = 0; f < 20 && end; ++f) end = strchr(end, '\n') ? strchr(end, '\n') + 1 : NULL;
    AK_CHECK(end != NULL);
    if (!end) {
        free(text);
        return;
    }
    /* rebuild: hierarchy, "Frames: 20", the frame time line, 20 frames */
    size_t cap = (size_t)(end - text) + 64;
    char* small = (char*)malloc(cap);
    char* time_line = strstr(motion, "Frame Time:");
    int len = snprintf(small, cap, "%.*sMOTION\nFrames: 20\n%.*s%.*s", (int)(motion - text), text,
                       (int)(first - time_line), time_line, (int)(end - first), first);
    size_t n = (size_t)len;
    size_t last = n;
    while (last > 0 && isspace((unsigned char)small[last - 1])) --last;
    while (last > 0 && !isspace((unsigned char)small[last - 1])) --last; /* start of the last number */
    ak_scene* s = NULL;
    AK_CHECK_EQ(ak_io_load_memory(small, n, "cut.bvh", NULL, NULL, NULL, &s, NULL), AK_OK);
    ak_scene_destroy(s);
    size_t hier = (size_t)(motion - text) + 2048;
    int loaded = 0, cuts = 0;
    const size_t every = AK_TEST_REPS(1, 5); /* under valgrind every fifth cut in the hierarchy */
    for (size_t l = 0; l < last; l += l < hier ? every : 61) {
        ak_io_desc as_bvh = {.format = AK_IO_FORMAT_BVH};
        s = NULL;
        if (ak_io_load_memory(small, l, "cut.bvh", NULL, &as_bvh, NULL, &s, NULL) == AK_OK) ++loaded;
        ak_scene_destroy(s);
        ++cuts;
    }
    printf("  %d truncated BVH copies, %d loaded\n", cuts, loaded);
    AK_CHECK_EQ(loaded, 0);
    /* issue 26 item 11a: cut inside the last number ("-19.3215" -> "-19.3" or "-1"), or just
     * before the final newline: the last frame line has no newline, refused naming the frame */
    size_t nl_at = n;
    while (nl_at > 0 && (small[nl_at - 1] == '\n' || small[nl_at - 1] == '\r')) --nl_at;
    AK_CHECK(nl_at > last + 1);
    for (size_t l = last + 1; l <= nl_at; ++l) {
        ak_io_desc as_bvh = {.format = AK_IO_FORMAT_BVH};
        ak_diag diag;
        s = NULL;
        ak_result r = ak_io_load_memory(small, l, "cut.bvh", NULL, &as_bvh, NULL, &s, &diag);
        AK_CHECK_MSG(r == AK_ERR_PARSE, "cut at %zu of %zu: %s", l, n, ak_result_name(r));
        if (r != AK_OK)
            AK_CHECK_MSG(strstr(diag.message, "the file ends inside frame 20 (truncated?)") != NULL, "%s", diag.message);
        ak_scene_destroy(s);
    }
    /* with its newline (LF or CRLF) the same text loads */
    char* crlf = (char*)malloc(nl_at + 3);
    memcpy(crlf, small, nl_at);
    memcpy(crlf + nl_at, "\r\n", 3);
    s = NULL;
    AK_CHECK_EQ(ak_io_load_memory(crlf, nl_at + 2, "cut.bvh", NULL, NULL, NULL, &s, NULL), AK_OK);
    ak_scene_destroy(s);
    s = NULL;
    AK_CHECK_EQ(ak_io_load_memory(crlf, nl_at + 1, "cut.bvh", NULL, NULL, NULL, &s, NULL), AK_ERR_PARSE); /* a lone CR */
    ak_scene_destroy(s);
    free(crlf);
    free(small);
    free(text);
}

/* Assimp formats: cheap checks before Assimp runs (nesting depth of XML and brace formats,
 * file size against an explicit budget); an ordinary file still loads. */
AK_TEST(assimp_prechecks) {
    size_t depth = AK_IO_ASSIMP_MAX_DEPTH + 10, cap = depth * 40 + 512, o = 0;
    char* x = (char*)malloc(cap);
    o += (size_t)snprintf(x + o, cap - o, "<?xml version=\"1.0\"?>\n<!-- a comment <a> -->\n<COLLADA "
                                          "xmlns=\"http://www.collada.org/2005/11/COLLADASchema\" version=\"1.4.1\">\n");
    for (size_t i = 0; i < depth; ++i) o += (size_t)snprintf(x + o, cap - o, "<node id=\"n%zu\">", i);
    for (size_t i = 0; i < depth; ++i) o += (size_t)snprintf(x + o, cap - o, "</node>");
    snprintf(x + o, cap - o, "</COLLADA>\n");
    write_file("deep.dae", x, strlen(x));
    free(x);
    ak_scene* s = NULL;
    ak_diag diag;
    AK_CHECK_EQ(ak_io_load("deep.dae", NULL, NULL, &s, &diag), AK_ERR_UNSUPPORTED);
    AK_CHECK(strstr(diag.message, "nested deeper") != NULL);
    remove("deep.dae");
    const char* obj = "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
    write_file("tri.obj", obj, strlen(obj));
    AK_CHECK_EQ(ak_io_load("tri.obj", NULL, NULL, &s, &diag), AK_OK);
    if (s) AK_CHECK_EQ(s->mesh_count, 1);
    ak_scene_destroy(s);
    s = NULL;
    ak_io_desc tight = {.memory_budget = 100};
    AK_CHECK_EQ(ak_io_load("tri.obj", &tight, NULL, &s, &diag), AK_ERR_UNSUPPORTED);
    remove("tri.obj");
}

/* OBJ through Assimp: a number that overflows float ("1e39") is infinity, and "nan" parses
 * as NaN; a position or normal that is not finite is AK_ERR_BAD_DATA naming the vertex and
 * the attribute (fuzz_obj found "vn 0 0 1e39" loading with an infinite normal). Assimp
 * itself replaces a non-finite OBJ "vt" by 0, so UVs are not tried here. */
AK_TEST(assimp_non_finite_attributes) {
    const ak_io_desc as_assimp = {.format = AK_IO_FORMAT_ASSIMP}; /* .obj is animkit's own reader now */
    static const struct {
        const char* text;
        const char* message;
    } cases[] = {
        {"v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 0 1e39\nf 1//1 2//1 3//1\n", "vertex 0: the normal is not finite"},
        {"v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 0 1\nvn 0 nan 1\nf 1//1 2//1 3//2\n", "vertex 2: the normal is not finite"},
        {"v 0 0 0\nv 1 0 0\nv 0 1e39 0\nf 1 2 3\n", "vertex 2: the position is not finite"},
    };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; ++i) {
        write_file("nonfinite.obj", cases[i].text, strlen(cases[i].text));
        ak_scene* s = NULL;
        ak_diag diag;
        memset(&diag, 0, sizeof diag);
        AK_CHECK_EQ(ak_io_load("nonfinite.obj", &as_assimp, NULL, &s, &diag), AK_ERR_BAD_DATA);
        AK_CHECK(s == NULL);
        AK_CHECK(strstr(diag.message, cases[i].message) != NULL);
        if (!strstr(diag.message, cases[i].message)) printf("  case %zu: '%s'\n", i, diag.message);
        ak_scene_destroy(s);
    }
    /* the same files with finite values load, normals and UVs as written */
    const char* ok = "v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0.25 0.5\nvn 0 0 1\nf 1/1/1 2/1/1 3/1/1\n";
    write_file("nonfinite.obj", ok, strlen(ok));
    ak_scene* s = NULL;
    ak_diag diag;
    AK_CHECK_EQ(ak_io_load("nonfinite.obj", &as_assimp, NULL, &s, &diag), AK_OK);
    if (s && s->mesh_count == 1) {
        const ak_mesh* m = s->meshes[0].mesh;
        AK_CHECK_EQ(ak_mesh_validate(m, NULL), AK_OK);
        AK_CHECK(m->normals != NULL && m->uvs != NULL);
        for (size_t v = 0; m->normals && m->uvs && v < m->vertex_count; ++v) {
            AK_CHECK_NEAR(m->normals[v].z, 1.0, 0);
            AK_CHECK_NEAR(m->uvs[v].x, 0.25, 0);
        }
    } else {
        AK_CHECK(s != NULL && s->mesh_count == 1);
    }
    ak_scene_destroy(s);
    remove("nonfinite.obj");
}

/* Files an Assimp model names itself (an OBJ's mtllib) open only inside the model's folder:
 * "../secret.mtl" and a symlink out are refused with one warning (the mesh still loads),
 * a material file beside the model opens without one, and allow_any_path lets the outside
 * one through. */
static void count_warnings(ak_log_level level, const char* message, void* user) {
    if (level == AK_LOG_WARN && strstr(message, "not opening")) ++*(int*)user;
}

static int load_obj_warnings(const char* path, bool any_path) {
    int warnings = 0;
    ak_io_desc desc = {.logger = {count_warnings, &warnings}, .allow_any_path = any_path, .format = AK_IO_FORMAT_ASSIMP};
    ak_scene* s = NULL;
    ak_diag diag;
    AK_CHECK_EQ(ak_io_load(path, &desc, NULL, &s, &diag), AK_OK);
    if (s) AK_CHECK_EQ(s->mesh_count, 1);
    ak_scene_destroy(s);
    return warnings;
}

AK_TEST(assimp_companion_files_stay_inside_model_dir) {
    mkdir("mtl", 0755);
    mkdir("mtl/model", 0755);
    write_file("mtl/secret.mtl", "newmtl red\nKd 1 0 0\n", 20);
    write_file("mtl/model/inside.mtl", "newmtl red\nKd 1 0 0\n", 20);
    remove("mtl/model/link.mtl");
    AK_CHECK_EQ(symlink("../secret.mtl", "mtl/model/link.mtl"), 0);
    const char* tri = "v 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl red\nf 1 2 3\n";
    char text[256];
    snprintf(text, sizeof text, "mtllib ../secret.mtl\n%s", tri);
    write_file("mtl/model/out.obj", text, strlen(text));
    snprintf(text, sizeof text, "mtllib link.mtl\n%s", tri);
    write_file("mtl/model/link.obj", text, strlen(text));
    snprintf(text, sizeof text, "mtllib inside.mtl\n%s", tri);
    write_file("mtl/model/in.obj", text, strlen(text));
    AK_CHECK_EQ(load_obj_warnings("mtl/model/out.obj", false), 1);
    AK_CHECK_EQ(load_obj_warnings("mtl/model/link.obj", false), 1);
    AK_CHECK_EQ(load_obj_warnings("mtl/model/in.obj", false), 0);
    AK_CHECK_EQ(load_obj_warnings("mtl/model/out.obj", true), 0);
    const char* files[] = {"mtl/model/out.obj", "mtl/model/link.obj", "mtl/model/in.obj", "mtl/model/link.mtl",
                           "mtl/model/inside.mtl", "mtl/secret.mtl", "mtl/model", "mtl"};
    for (size_t i = 0; i < sizeof files / sizeof files[0]; ++i) remove(files[i]);
}

/* ---- clip sampler on real clips (the inline path of ak_clip_sample, see test_clip.c) ---- */

AK_TEST(inline_sampler_on_gltf_assets) {
    static const char* files[] = {"gltf/Fox/glTF/Fox.gltf", "gltf/RiggedSimple/glTF/RiggedSimple.gltf",
                                  "gltf/RiggedFigure/glTF/RiggedFigure.gltf",
                                  "gltf/CesiumMan/glTF-Binary/CesiumMan.glb"};
    int loaded = 0;
    double worst = 0.0;
    for (size_t f = 0; f < sizeof files / sizeof files[0]; ++f) {
        char path[4096];
        if (!ak_test_asset(path, sizeof path, files[f])) continue;
        ak_scene* s = NULL;
        if (ak_io_load(path, NULL, NULL, &s, NULL) != AK_OK || !s) {
            AK_FAIL_("%s did not load", path);
            continue;
        }
        ++loaded;
        size_t nj = ak_scene_joint_count(s);
        for (size_t a = 0; a < s->clip_count; ++a) {
            const ak_clip* c = s->clips[a];
            size_t nc = ak_clip_cursor_storage_count(c);
            uint32_t* seg = (uint32_t*)calloc(nc + 1, sizeof *seg);
            ak_clip_cursor cur;
            ak_clip_cursor_init(&cur, c, (ak_u32_span){seg, nc});
            float dur = ak_clip_duration(c);
            size_t T = (size_t)(dur * 60.0f) + 40;
            float* times = (float*)malloc(T * sizeof *times);
            for (size_t i = 0; i < T; ++i) times[i] = -0.25f + (float)i / 60.0f;
            AK_CHECK_EQ(ref_clip_check_against_tracks(c, &cur, times, T, nj ? nj : 1, &worst), 0);
            for (size_t i = 0; i < T; ++i) times[i] = dur + 0.25f - (float)i / 60.0f;
            AK_CHECK_EQ(ref_clip_check_against_tracks(c, &cur, times, T, nj ? nj : 1, &worst), 0);
            free(times);
            free(seg);
        }
        ak_scene_destroy(s);
    }
    if (!loaded) AK_SKIP("no glTF assets (set ANIMKIT_ASSETS or place ../shared/assets)");
    else printf("  assets: max |component| error of LINEAR rotations vs double slerp: %.2e\n", worst);
    AK_CHECK(worst < 1e-6);
}

/* ---- animkit's own OBJ reader ------------------------------------------------------------ */

static ak_result load_obj_text(const char* path, const char* text, const ak_io_desc* desc, ak_scene** out,
                               ak_diag* diag) {
    write_file(path, text, strlen(text));
    *out = NULL;
    memset(diag, 0, sizeof *diag);
    return ak_io_load(path, desc, NULL, out, diag);
}

/* Issue 26 item 2: Assimp 5.2.5 crashes (SIGSEGV) on this four-line OBJ whose .mtl has
 * map_Kd before any newmtl. animkit's reader loads it: one triangle, no material. */
AK_TEST(obj_four_line_crash_file) {
    write_file("s.mtl", "map_Kd t.png\n", 13);
    ak_scene* s = NULL;
    ak_diag diag;
    AK_CHECK_EQ(load_obj_text("crash4.obj", "mtllib s.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n", NULL, &s, &diag), AK_OK);
    AK_CHECK(s != NULL && s->mesh_count == 1);
    if (s && s->mesh_count == 1) {
        const ak_mesh* m = s->meshes[0].mesh;
        AK_CHECK_EQ(m->vertex_count, 3);
        AK_CHECK_EQ(m->triangle_count, 1);
        AK_CHECK_NEAR(m->positions[1].x, 1.0, 0);
        AK_CHECK_NEAR(m->positions[2].y, 1.0, 0);
        AK_CHECK(!s->meshes[0].has_material);
        AK_CHECK_EQ(s->skin_count, 0);
        AK_CHECK_EQ(s->clip_count, 0);
    }
    ak_scene_destroy(s);
    /* Assimp on the same file, named explicitly: its crash stays in the child process and
     * comes back as an error naming the signal */
    ak_io_desc as_assimp = {.format = AK_IO_FORMAT_ASSIMP};
    s = NULL;
    ak_result r = ak_io_load("crash4.obj", &as_assimp, NULL, &s, &diag);
    AK_CHECK(s == NULL);
    if (r != AK_OK) {
        AK_CHECK_EQ(r, AK_ERR_IO);
        /* SIGSEGV (11); under AddressSanitizer its handler turns the crash into an abort (6) */
        AK_CHECK_MSG(strstr(diag.message, "Assimp crashed reading") != NULL &&
                         (strstr(diag.message, "signal 11") || strstr(diag.message, "signal 6")),
                     "%s", diag.message);
    } else {
        printf("  (this Assimp does not crash on the file)\n");
    }
    ak_scene_destroy(s);
    remove("crash4.obj");
    remove("s.mtl");
}

/* A unit cube written as 8 positions, 6 normals and 6 quads (CCW from outside): 24 vertices
 * (no welding), 12 triangles, each corner at the position and with the normal the test
 * computed, and each triangle's winding agreeing with its face normal. */
AK_TEST(obj_cube_geometry) {
    float p[8][3];
    for (int i = 0; i < 8; ++i) p[i][0] = (float)(i & 1), p[i][1] = (float)((i >> 1) & 1), p[i][2] = (float)((i >> 2) & 1);
    /* faces: axis, sign, four corners CCW seen from outside */
    static const int quads[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
    static const float normals[6][3] = {{0, 0, -1}, {0, 0, 1}, {0, -1, 0}, {0, 1, 0}, {-1, 0, 0}, {1, 0, 0}};
    char text[2048];
    size_t o = 0;
    for (int i = 0; i < 8; ++i) o += (size_t)snprintf(text + o, sizeof text - o, "v %g %g %g\n", p[i][0], p[i][1], p[i][2]);
    for (int f = 0; f < 6; ++f)
        o += (size_t)snprintf(text + o, sizeof text - o, "vn %g %g %g\n", normals[f][0], normals[f][1], normals[f][2]);
    o += (size_t)snprintf(text + o, sizeof text - o, "o cube\ns 1\n");
    for (int f = 0; f < 6; ++f)
        o += (size_t)snprintf(text + o, sizeof text - o, "f %d//%d %d//%d %d//%d %d//%d\n", quads[f][0] + 1, f + 1,
                              quads[f][1] + 1, f + 1, quads[f][2] + 1, f + 1, quads[f][3] + 1, f + 1);
    ak_scene* s = NULL;
    ak_diag diag;
    AK_CHECK_EQ(load_obj_text("cube.obj", text, NULL, &s, &diag), AK_OK);
    AK_CHECK(s != NULL && s->mesh_count == 1);
    if (s && s->mesh_count == 1) {
        const ak_mesh* m = s->meshes[0].mesh;
        AK_CHECK_STREQ(m->name, "cube");
        AK_CHECK_EQ(m->vertex_count, 24);
        AK_CHECK_EQ(m->triangle_count, 12);
        AK_CHECK(m->normals != NULL && m->uvs == NULL);
        AK_CHECK_EQ(ak_mesh_validate(m, NULL), AK_OK);
        for (int f = 0; f < 6 && m->vertex_count == 24 && m->normals; ++f)
            for (int k = 0; k < 4; ++k) {
                const ak_vec3 v = m->positions[4 * f + k], n = m->normals[4 * f + k];
                AK_CHECK(v.x == p[quads[f][k]][0] && v.y == p[quads[f][k]][1] && v.z == p[quads[f][k]][2]);
                AK_CHECK(n.x == normals[f][0] && n.y == normals[f][1] && n.z == normals[f][2]);
            }
        for (size_t t = 0; t < m->triangle_count && m->normals; ++t) {
            const uint32_t* tri = m->indices + 3 * t;
            ak_vec3 e1 = ak_vec3_sub(m->positions[tri[1]], m->positions[tri[0]]);
            ak_vec3 e2 = ak_vec3_sub(m->positions[tri[2]], m->positions[tri[0]]);
            AK_CHECK(ak_vec3_dot(ak_vec3_cross(e1, e2), m->normals[tri[0]]) > 0.5f);
        }
        /* quads are fans: (0,1,2) and (0,2,3) of each face's four vertices */
        static const uint32_t fan[6] = {0, 1, 2, 0, 2, 3};
        for (size_t i = 0; i < 6 && m->triangle_count == 12; ++i) AK_CHECK_EQ(m->indices[i], fan[i]);
        for (size_t i = 0; i < 6 && m->triangle_count == 12; ++i) AK_CHECK_EQ(m->indices[6 * 5 + i], 20 + fan[i]);
        /* the scene: a root named by the file, one node per object, plain nodes */
        AK_CHECK_EQ(ak_scene_joint_count(s), 2);
        AK_CHECK_STREQ(ak_skeleton_joint_name(s->skeleton, 0), "cube.obj");
        AK_CHECK_STREQ(ak_skeleton_joint_name(s->skeleton, 1), "cube");
        AK_CHECK_EQ(s->meshes[0].node, 1);
        AK_CHECK(s->is_joint && !s->is_joint[0] && !s->is_joint[1]);
    }
    ak_scene_destroy(s);
    remove("cube.obj");
}

/* Negative (relative) indices name the same corners as positive ones; v/vt, v/vt/vn forms;
 * a pentagon becomes 3 triangles; "v x y z w" and vertex colours are ignored. */
AK_TEST(obj_negative_indices_and_forms) {
    const char* pos = "v 0 0 0 1\nv 2 0 0 1\nv 2 2 0 0.5 0.5 0.5\nv 0 2 0\nv -1 1 0\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nvt 0.5 0.5\n"
                      "vn 0 0 1\n";
    char a[1024], b[1024];
    snprintf(a, sizeof a, "%sf 1/1/1 2/2/1 3/3/1 4/4/1 5/5/1\n", pos);
    snprintf(b, sizeof b, "%sf -5/-5/-1 -4/-4/-1 -3/-3/-1 -2/-2/-1 -1/-1/-1\n", pos);
    ak_scene *sa = NULL, *sb = NULL;
    ak_diag diag;
    AK_CHECK_EQ(load_obj_text("pos.obj", a, NULL, &sa, &diag), AK_OK);
    AK_CHECK_EQ(load_obj_text("neg.obj", b, NULL, &sb, &diag), AK_OK);
    if (sa && sb && sa->mesh_count == 1 && sb->mesh_count == 1) {
        const ak_mesh *ma = sa->meshes[0].mesh, *mb = sb->meshes[0].mesh;
        AK_CHECK_EQ(ma->vertex_count, 5);
        AK_CHECK_EQ(ma->triangle_count, 3);
        AK_CHECK(ma->uvs && ma->normals && mb->uvs && mb->normals);
        AK_CHECK_EQ(mb->vertex_count, 5);
        for (size_t v = 0; v < 5 && mb->vertex_count == 5 && ma->uvs && mb->uvs; ++v) {
            AK_CHECK(memcmp(&ma->positions[v], &mb->positions[v], sizeof(ak_vec3)) == 0);
            AK_CHECK(memcmp(&ma->uvs[v], &mb->uvs[v], sizeof(ak_vec2)) == 0);
        }
        AK_CHECK_NEAR(ma->positions[2].x, 2.0, 0);
        AK_CHECK_NEAR(ma->positions[4].x, -1.0, 0);
        AK_CHECK_NEAR(ma->uvs[4].x, 0.5, 0);
    } else {
        AK_CHECK(!"both files load with one mesh");
    }
    ak_scene_destroy(sa);
    ak_scene_destroy(sb);
    /* a corner without vt drops the mesh's UVs (no invented values) */
    snprintf(a, sizeof a, "%sf 1/1 2/2 3\n", pos);
    AK_CHECK_EQ(load_obj_text("pos.obj", a, NULL, &sa, &diag), AK_OK);
    if (sa && sa->mesh_count == 1) AK_CHECK(sa->meshes[0].mesh->uvs == NULL && sa->meshes[0].mesh->normals == NULL);
    ak_scene_destroy(sa);
    remove("pos.obj");
    remove("neg.obj");
}

/* Errors: the file, the line, the reason; never a raw byte of the file. */
AK_TEST(obj_errors_name_the_line) {
    static const struct {
        const char* text;
        ak_result r;
        long line;
        const char* message;
    } cases[] = {
        {"v 0 0 0\nv 1 0 0\nv 0 1 0\n# comment\nf 1 2 4\n", AK_ERR_BAD_INDEX, 5, "position index 4 is out of range (3 positions)"},
        {"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 -4\n", AK_ERR_BAD_INDEX, 4, "index -4 is out of range"},
        {"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 0 1 2\n", AK_ERR_BAD_INDEX, 4, "index is 0"},
        {"v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 0 1\nf 1//1 2//2 3//1\n", AK_ERR_BAD_INDEX, 5, "normal index 2"},
        {"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1/7 2 3\n", AK_ERR_BAD_INDEX, 4, "UV index 7"},
        {"v 0 0 0\nv nan 0 0\nv 0 1 0\nf 1 2 3\n", AK_ERR_BAD_DATA, 2, "'nan' is not finite"},
        {"v 0 0 0\nv 1 0 0\nv 0 1e39 0\nf 1 2 3\n", AK_ERR_BAD_DATA, 3, "not finite"},
        {"v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 0 inf\n", AK_ERR_BAD_DATA, 4, "not finite"},
        {"v 0 0 0\nv 1 0\n", AK_ERR_PARSE, 2, "v has 2 values, 3 expected"},
        {"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3x\n", AK_ERR_PARSE, 4, "'3x' is not v, v/vt, v//vn or v/vt/vn"},
        {"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 \x1b[31m\n", AK_ERR_PARSE, 4, "\\x1B[31m"},
        {"v 0 0 0\r\ng bad\xff\xfe\r\n", AK_ERR_PARSE, 2, "group name is not valid UTF-8"},
        {"v 0 0 0\ng a\x01z\n", AK_ERR_PARSE, 2, "control byte"},
    };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; ++i) {
        ak_scene* s = NULL;
        ak_diag diag;
        ak_result r = load_obj_text("bad.obj", cases[i].text, NULL, &s, &diag);
        AK_CHECK_MSG(r == cases[i].r, "case %zu: %s (%s)", i, ak_result_name(r), diag.message);
        AK_CHECK(s == NULL);
        AK_CHECK_MSG(diag.line == cases[i].line, "case %zu: line %ld", i, diag.line);
        char want[32];
        snprintf(want, sizeof want, "line %ld:", cases[i].line);
        AK_CHECK_MSG(strstr(diag.message, want) && strstr(diag.message, cases[i].message), "case %zu: '%s'", i, diag.message);
        AK_CHECK_MSG(strstr(diag.path, "bad.obj") != NULL, "case %zu: path '%s'", i, diag.path);
        for (const char* c = diag.message; *c; ++c) AK_CHECK((unsigned char)*c >= 0x20 && (unsigned char)*c < 0x7F);
        ak_scene_destroy(s);
    }
    /* a tight budget is refused before the arrays are allocated */
    ak_io_desc tight = {.memory_budget = 200};
    ak_scene* s = NULL;
    ak_diag diag;
    AK_CHECK_EQ(load_obj_text("bad.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\nf 1 2 3\nf 1 2 3\n", &tight, &s, &diag),
                AK_ERR_UNSUPPORTED);
    remove("bad.obj");
}

/* Objects, groups and materials split meshes as Assimp's importer did (compared with Assimp
 * in its child process), and a .mtl beside the model gives the base colours. */
AK_TEST(obj_groups_and_materials) {
    mkdir("objm", 0755);
    write_file("objm/s.mtl", "# c\nnewmtl red\nKd 1 0 0\nd 0.5\nnewmtl blue\nKd 0 0 1\nmap_Kd x.png\n", 62);
    const char* text = "mtllib s.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nvn 0 0 1\nvt 0.5 0.25\nf 1 2 3\ng grp\n"
                       "usemtl red\nf 1/1/1 2/1/1 3/1/1 4/1/1\nusemtl blue\nf 1 2 3\ng grp\nf 2 3 4\no obj\n"
                       "usemtl nomat\nf -1 -2 -3\n";
    ak_scene *mine = NULL, *theirs = NULL;
    ak_diag diag;
    AK_CHECK_EQ(load_obj_text("objm/m.obj", text, NULL, &mine, &diag), AK_OK);
    ak_io_desc as_assimp = {.format = AK_IO_FORMAT_ASSIMP};
    AK_CHECK_EQ(ak_io_load("objm/m.obj", &as_assimp, NULL, &theirs, &diag), AK_OK);
    static const char* names[4] = {"defaultobject", "grp", "blue", "obj"};
    static const size_t verts[4] = {3, 4, 6, 3};
    if (mine && theirs && mine->mesh_count == 4 && theirs->mesh_count == 4) {
        for (size_t m = 0; m < 4; ++m) {
            AK_CHECK_STREQ(mine->meshes[m].mesh->name, names[m]);
            AK_CHECK_STREQ(theirs->meshes[m].mesh->name, names[m]);
            AK_CHECK_EQ(mine->meshes[m].mesh->vertex_count, verts[m]);
            AK_CHECK_EQ(theirs->meshes[m].mesh->vertex_count, verts[m]);
            AK_CHECK_EQ(mine->meshes[m].node, theirs->meshes[m].node);
            if (mine->meshes[m].mesh->vertex_count == verts[m] && theirs->meshes[m].mesh->vertex_count == verts[m])
                AK_CHECK(memcmp(mine->meshes[m].mesh->positions, theirs->meshes[m].mesh->positions,
                                verts[m] * sizeof(ak_vec3)) == 0);
        }
        AK_CHECK(!mine->meshes[0].has_material);
        AK_CHECK(mine->meshes[1].has_material && mine->meshes[1].base_color.x == 1.0f &&
                 mine->meshes[1].base_color.z == 0.0f && mine->meshes[1].base_color.w == 0.5f);
        AK_CHECK(mine->meshes[2].has_material && mine->meshes[2].base_color.z == 1.0f &&
                 mine->meshes[2].base_color.w == 1.0f);
        AK_CHECK(!mine->meshes[3].has_material); /* "nomat" is in no library */
    } else {
        AK_CHECK_MSG(0, "mesh counts %zu and %zu, 4 expected", mine ? mine->mesh_count : 0,
                     theirs ? theirs->mesh_count : 0);
    }
    ak_scene_destroy(mine);
    ak_scene_destroy(theirs);
    /* a file of vertices only is one point mesh (ak_io_write_obj writes point clouds so) */
    AK_CHECK_EQ(load_obj_text("objm/p.obj", "v 0 0 0\nv 1 2 3\n", NULL, &mine, &diag), AK_OK);
    if (mine && mine->mesh_count == 1) {
        AK_CHECK_EQ(mine->meshes[0].mesh->vertex_count, 2);
        AK_CHECK_EQ(mine->meshes[0].mesh->triangle_count, 0);
        AK_CHECK_NEAR(mine->meshes[0].mesh->positions[1].z, 3.0, 0);
    } else {
        AK_CHECK(mine && mine->mesh_count == 1);
    }
    ak_scene_destroy(mine);
    remove("objm/p.obj");
    remove("objm/m.obj");
    remove("objm/s.mtl");
    rmdir("objm");
}

/* mtllib stays inside the model's folder: "../x.mtl", an absolute path and a symlink out are
 * not read (the model loads without materials, one warning saying only that the path leaves
 * the folder: the same words whether or not the target exists); a FIFO is not waited on. */
typedef struct warn_log {
    int count;
    char last[700];
} warn_log;

static void log_warning(ak_log_level level, const char* message, void* user) {
    warn_log* w = (warn_log*)user;
    if (level != AK_LOG_WARN) return;
    ++w->count;
    snprintf(w->last, sizeof w->last, "%s", message);
}

static bool obj_mtl_red(const char* path, const char* mtllib, warn_log* w) {
    char text[2048];
    snprintf(text, sizeof text, "mtllib %s\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl red\nf 1 2 3\n", mtllib);
    memset(w, 0, sizeof *w);
    ak_io_desc desc = {.logger = {log_warning, w}};
    ak_scene* s = NULL;
    ak_diag diag;
    AK_CHECK_EQ(load_obj_text(path, text, &desc, &s, &diag), AK_OK);
    bool red = s && s->mesh_count == 1 && s->meshes[0].has_material && s->meshes[0].base_color.x == 1.0f;
    ak_scene_destroy(s);
    return red;
}

AK_TEST(obj_mtllib_stays_inside_model_dir) {
    mkdir("omtl", 0755);
    mkdir("omtl/model", 0755);
    write_file("omtl/secret.mtl", "newmtl red\nKd 1 0 0\n", 20);
    write_file("omtl/model/inside.mtl", "newmtl red\nKd 1 0 0\n", 20);
    remove("omtl/model/link.mtl");
    remove("omtl/model/dangling.mtl");
    AK_CHECK_EQ(symlink("../secret.mtl", "omtl/model/link.mtl"), 0);
    AK_CHECK_EQ(symlink("../nothing_here.mtl", "omtl/model/dangling.mtl"), 0);
    char cwd[2048], abs_secret[2300], abs_missing[2300];
    AK_CHECK(getcwd(cwd, sizeof cwd) != NULL);
    snprintf(abs_secret, sizeof abs_secret, "%s/omtl/secret.mtl", cwd);
    snprintf(abs_missing, sizeof abs_missing, "%s/omtl/missing.mtl", cwd);
    warn_log w;
    AK_CHECK(obj_mtl_red("omtl/model/m.obj", "inside.mtl", &w));
    AK_CHECK_EQ(w.count, 0);
    const char* out[] = {"../secret.mtl", abs_secret, "link.mtl", "sub/../../secret.mtl", "../missing.mtl", abs_missing,
                         "dangling.mtl"};
    for (size_t i = 0; i < sizeof out / sizeof out[0]; ++i) {
        AK_CHECK_MSG(!obj_mtl_red("omtl/model/m.obj", out[i], &w), "mtllib %s was read", out[i]);
        AK_CHECK_EQ(w.count, 1);
        AK_CHECK_MSG(strstr(w.last, "the path leaves the model's folder") != NULL, "%s: %s", out[i], w.last);
        AK_CHECK_MSG(!strstr(w.last, "cannot open") && !strstr(w.last, "No such"), "%s: %s", out[i], w.last);
    }
    /* a missing file inside the folder: not fatal either */
    AK_CHECK(!obj_mtl_red("omtl/model/m.obj", "nope.mtl", &w));
    AK_CHECK_EQ(w.count, 1);
    /* explicit permission */
    ak_io_desc any = {.allow_any_path = true};
    ak_scene* s = NULL;
    ak_diag diag;
    AK_CHECK_EQ(load_obj_text("omtl/model/m.obj", "mtllib ../secret.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl red\nf 1 2 3\n",
                              &any, &s, &diag), AK_OK);
    AK_CHECK(s && s->mesh_count == 1 && s->meshes[0].has_material);
    ak_scene_destroy(s);
    remove("omtl/model/fifo.mtl");
    if (mkfifo("omtl/model/fifo.mtl", 0600) == 0) {
        alarm(30);
        AK_CHECK(!obj_mtl_red("omtl/model/m.obj", "fifo.mtl", &w));
        alarm(0);
        AK_CHECK_MSG(strstr(w.last, "not a regular file") != NULL, "%s", w.last);
        remove("omtl/model/fifo.mtl");
    }
    mkdir("omtl/model/dir.mtl", 0755);
    AK_CHECK(!obj_mtl_red("omtl/model/m.obj", "dir.mtl", &w));
    AK_CHECK_MSG(strstr(w.last, "directory") != NULL, "%s", w.last);
    rmdir("omtl/model/dir.mtl");
    const char* files[] = {"omtl/model/m.obj", "omtl/model/link.mtl", "omtl/model/dangling.mtl", "omtl/model/inside.mtl",
                           "omtl/secret.mtl"};
    for (size_t i = 0; i < sizeof files / sizeof files[0]; ++i) remove(files[i]);
    rmdir("omtl/model");
    rmdir("omtl");
}

/* The same reader from memory (mtllib relative to base_dir; none without one). */
AK_TEST(obj_from_memory) {
    const char* text = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nf 1 2 4 3\n";
    ak_io_desc desc = {.format = AK_IO_FORMAT_OBJ};
    ak_scene* s = NULL;
    ak_diag diag;
    AK_CHECK_EQ(ak_io_load_memory(text, strlen(text), "quad.obj", NULL, &desc, NULL, &s, &diag), AK_OK);
    if (s && s->mesh_count == 1) {
        AK_CHECK_EQ(s->meshes[0].mesh->vertex_count, 4);
        AK_CHECK_EQ(s->meshes[0].mesh->triangle_count, 2);
    } else {
        AK_CHECK(s && s->mesh_count == 1);
    }
    ak_scene_destroy(s);
}

/* The Assimp child's limits through the test hook (AK_IO_TEST_ASSIMP_CHILD): a crash and a
 * hang (the parent's wall clock, shortened to 1 s by the hook) come back as errors. */
AK_TEST(assimp_child_crash_and_hang) {
    write_file("child.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n", 32);
    ak_io_desc as_assimp = {.format = AK_IO_FORMAT_ASSIMP};
    static const char* hooks[2] = {"segv", "hang"};
    static const char* want[2] = {"Assimp crashed reading child.obj (signal ", "Assimp ran out of its time limit"};
    for (int i = 0; i < 2; ++i) {
        setenv("AK_IO_TEST_ASSIMP_CHILD", hooks[i], 1);
        ak_scene* s = NULL;
        ak_diag diag;
        ak_result r = ak_io_load("child.obj", &as_assimp, NULL, &s, &diag);
        unsetenv("AK_IO_TEST_ASSIMP_CHILD");
        AK_CHECK_EQ(r, AK_ERR_IO);
        AK_CHECK(s == NULL);
        AK_CHECK_MSG(strstr(diag.message, want[i]) != NULL, "%s", diag.message);
        ak_scene_destroy(s);
    }
    ak_scene* s = NULL;
    ak_diag diag;
    AK_CHECK_EQ(ak_io_load("child.obj", &as_assimp, NULL, &s, &diag), AK_OK); /* and without the hook it loads */
    ak_scene_destroy(s);
    remove("child.obj");
}

/* Issue 26 item 7c: a glTF uri that leaves the model's folder gets one message whether or not
 * its target exists (here: an existing and a missing file, a symlink to each, and an absolute
 * path to each), naming the uri but never the resolved path. */
static void uri_message_without_uri(const char* message, const char* uri, char* out, size_t cap) {
    const char* at = strstr(message, uri);
    if (!at) {
        snprintf(out, cap, "%s", message);
        return;
    }
    snprintf(out, cap, "%.*s<uri>%s", (int)(at - message), message, at + strlen(uri));
}

AK_TEST(gltf_outside_uri_reveals_nothing) {
    mkdir("leak", 0755);
    mkdir("leak/model", 0755);
    write_file("leak/secret.bin", &k_tri, sizeof k_tri);
    remove("leak/model/l1.bin");
    remove("leak/model/l2.bin");
    AK_CHECK_EQ(symlink("../secret.bin", "leak/model/l1.bin"), 0);
    AK_CHECK_EQ(symlink("../missing.bin", "leak/model/l2.bin"), 0);
    char cwd[2048], a1[2300], a2[2300];
    AK_CHECK(getcwd(cwd, sizeof cwd) != NULL);
    snprintf(a1, sizeof a1, "%s/leak/secret.bin", cwd);
    snprintf(a2, sizeof a2, "%s/leak/missing.bin", cwd);
    const char* pairs[][2] = {{"../secret.bin", "../missing.bin"}, {"l1.bin", "l2.bin"}, {a1, a2},
                              {"../../leak/secret.bin", "../../leak/missing.bin"}, {"/etc/passwd", "/etc/no_such_file_x"}};
    for (size_t i = 0; i < sizeof pairs / sizeof pairs[0]; ++i) {
        char m[2][700];
        for (int k = 0; k < 2; ++k) {
            ak_diag diag;
            AK_CHECK_EQ(load_tri_file("leak/model/m.gltf", pairs[i][k], NULL, &diag), AK_ERR_IO);
            AK_CHECK_MSG(strstr(diag.message, "leaves the model's folder") != NULL, "%s", diag.message);
            AK_CHECK_MSG(!strstr(diag.message, "resolves") && (!strstr(diag.message, cwd) || strstr(pairs[i][k], cwd)),
                         "%s", diag.message);
            uri_message_without_uri(diag.message, pairs[i][k], m[k], sizeof m[k]);
        }
        AK_CHECK_MSG(strcmp(m[0], m[1]) == 0, "'%s' vs '%s'", m[0], m[1]);
    }
    remove("leak/model/l1.bin");
    remove("leak/model/l2.bin");
    remove("leak/model/m.gltf");
    remove("leak/secret.bin");
    rmdir("leak/model");
    rmdir("leak");
}

/* Issue 26 item 4: names with invalid UTF-8 or control bytes are refused (BVH: naming the
 * line; glTF: naming the element), and error messages never carry a raw byte of the file. */
AK_TEST(names_valid_utf8) {
    static const char* bad_names[] = {"bad\xff\xfe", "esc\x1b[31m", "over\xc0\xaf", "sur\xed\xa0\x80"};
    for (size_t i = 0; i < sizeof bad_names / sizeof bad_names[0]; ++i) {
        char text[512];
        snprintf(text, sizeof text,
                 "HIERARCHY\nROOT a\n{\nOFFSET 0 0 0\nCHANNELS 3 Zrotation Xrotation Yrotation\nJOINT %s\n{\nOFFSET 0 1 0\n"
                 "End Site\n{\nOFFSET 0 1 0\n}\n}\n}\nMOTION\nFrames: 1\nFrame Time: 0.1\n0 0 0\n",
                 bad_names[i]);
        ak_scene* s = NULL;
        ak_diag diag;
        ak_result r = ak_io_load_memory(text, strlen(text), "n.bvh", NULL, NULL, NULL, &s, &diag);
        AK_CHECK_MSG(r == AK_ERR_PARSE, "bvh name %zu: %s", i, ak_result_name(r));
        AK_CHECK_MSG(strstr(diag.message, "line 6: the joint name") != NULL, "%s", diag.message);
        for (const char* c = diag.message; *c; ++c) AK_CHECK((unsigned char)*c >= 0x20 && (unsigned char)*c < 0x7F);
        ak_scene_destroy(s);
    }
    /* a valid non-ASCII name loads and is kept */
    const char* ok = "HIERARCHY\nROOT h\xc3\xbc" "fte\n{\nOFFSET 0 0 0\nCHANNELS 3 Zrotation Xrotation Yrotation\nEnd Site\n{\n"
                     "OFFSET 0 1 0\n}\n}\nMOTION\nFrames: 1\nFrame Time: 0.1\n0 0 0\n";
    ak_scene* s = NULL;
    AK_CHECK_EQ(ak_io_load_memory(ok, strlen(ok), "ok.bvh", NULL, NULL, NULL, &s, NULL), AK_OK);
    if (s) AK_CHECK_STREQ(ak_skeleton_joint_name(s->skeleton, 0), "h\xc3\xbc" "fte");
    ak_scene_destroy(s);
    /* glTF: raw bytes and \u escapes to control characters, in node, mesh and animation names */
    static const char* gl[] = {
        "{\"asset\":{\"version\":\"2.0\"},\"nodes\":[{\"name\":\"a\xff\xfe\"}]}",
        "{\"asset\":{\"version\":\"2.0\"},\"nodes\":[{\"name\":\"ok\"},{\"name\":\"a\\u001b[2J\"}]}",
        "{\"asset\":{\"version\":\"2.0\"},\"meshes\":[{\"name\":\"m\\u0007\",\"primitives\":[]}]}",
        "{\"asset\":{\"version\":\"2.0\"},\"meshes\":[{\"primitives\":[],\"extras\":{\"targetNames\":[\"t\\u0001\"]}}]}",
    };
    static const char* where[] = {"nodes[0].name is not valid UTF-8", "nodes[1].name holds a control character",
                                  "meshes[0].name holds", "meshes[0].extras.targetNames holds"};
    for (size_t i = 0; i < sizeof gl / sizeof gl[0]; ++i) {
        ak_diag diag;
        s = NULL;
        ak_result r = ak_io_load_memory(gl[i], strlen(gl[i]), "n.gltf", NULL, NULL, NULL, &s, &diag);
        AK_CHECK_MSG(r == AK_ERR_PARSE, "gltf %zu: %s (%s)", i, ak_result_name(r), diag.message);
        AK_CHECK_MSG(strstr(diag.message, where[i]) != NULL, "%s", diag.message);
        ak_scene_destroy(s);
    }
    const char* fine = "{\"asset\":{\"version\":\"2.0\"},\"nodes\":[{\"name\":\"\\u00fc\xc3\xbc\"}]}";
    s = NULL;
    AK_CHECK_EQ(ak_io_load_memory(fine, strlen(fine), "n.gltf", NULL, NULL, NULL, &s, NULL), AK_OK);
    if (s) AK_CHECK_STREQ(ak_skeleton_joint_name(s->skeleton, 0), "\xc3\xbc\xc3\xbc");
    ak_scene_destroy(s);
}

int main(void) {
    AK_RUN(desc_defaults);
    AK_RUN(gltf_assets_match_their_json);
    AK_RUN(gltf_variants_agree);
    AK_RUN(gltf_bind_pose_fk);
    AK_RUN(bvh_header_and_fk);
    AK_RUN(obj_through_assimp);
    AK_RUN(bvh_degenerate_headers);
    AK_RUN(malformed_gltf_exact_codes);
    AK_RUN(gltf_skin_weights_and_slots);
    AK_RUN(gltf_features);
    AK_RUN(gltf_instanced_primitives_order);
    AK_RUN(truncated_files_fail_cleanly);
    AK_RUN(load_arguments_and_missing_files);
    AK_RUN(obj_writer);
    AK_RUN(obj_writer_offsets_and_round_trip);
    AK_RUN(bvh_mesh_skin_through_assimp);
    AK_RUN(allocation_failures);
    AK_RUN(gltf_uri_stays_inside_model_dir);
    AK_RUN(gltf_memory_budget);
    AK_RUN(gltf_shared_sampler_amplification);
    AK_RUN(gltf_negative_key_times);
    AK_RUN(glb_bad_magic);
    AK_RUN(bvh_hostile_files);
    AK_RUN(bvh_channel_semantics);
    AK_RUN(bvh_reader_matches_assimp);
    AK_RUN(bvh_truncated_prefixes_fail);
    AK_RUN(assimp_prechecks);
    AK_RUN(assimp_non_finite_attributes);
    AK_RUN(assimp_companion_files_stay_inside_model_dir);
    AK_RUN(inline_sampler_on_gltf_assets);
    AK_RUN(obj_four_line_crash_file);
    AK_RUN(obj_cube_geometry);
    AK_RUN(obj_negative_indices_and_forms);
    AK_RUN(obj_errors_name_the_line);
    AK_RUN(obj_groups_and_materials);
    AK_RUN(obj_mtllib_stays_inside_model_dir);
    AK_RUN(obj_from_memory);
    AK_RUN(assimp_child_crash_and_hang);
    AK_RUN(gltf_outside_uri_reveals_nothing);
    AK_RUN(names_valid_utf8);
    return ak_test_finish();
}

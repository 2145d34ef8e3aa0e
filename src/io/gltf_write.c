/* glTF 2.0 writer: a scene as .glb or as .gltf + .bin (io.h, docs/io.md "Writing glTF").
 * One bufferView per accessor (so no byteStride is ever needed), every view 4-byte aligned,
 * one buffer. The document is held as compact tables (w_ctx below), never as a JSON tree,
 * and its text is streamed by json_write.h: counted to size the file, then written into it. */
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>

#include "io_internal.h"
#include "json_write.h"

/* ---- private types ---------------------------------------------------------------------- */

#define GL_UNSIGNED_BYTE 5121
#define GL_UNSIGNED_SHORT 5123
#define GL_UNSIGNED_INT 5125
#define GL_FLOAT 5126
#define GL_ARRAY_BUFFER 34962
#define GL_ELEMENT_ARRAY_BUFFER 34963

typedef struct w_view {
    size_t offset, length;
    int target;
} w_view;

typedef struct w_accessor {
    int view, ctype, comps;
    int32_t minmax; /* first of comps minima then comps maxima in w_ctx.minmax, -1 none */
    size_t count;
} w_accessor;

/* A node: a joint (TRS from the rest pose) or a node made for a mesh (named, identity). Keys
 * are written name, translation, rotation, scale, then children, mesh and skin in the order
 * they were given (children_last: the first child came after the mesh). */
typedef struct w_node {
    int32_t joint; /* skeleton joint, -1 for a mesh node */
    char* name;    /* a mesh node's name (owned) */
    int32_t first_child, last_child, next_sibling, parent;
    int32_t mesh, skin;
    bool children_last;
} w_node;

enum { W_POSITION, W_NORMAL, W_TANGENT, W_TEXCOORD_0, W_COLOR_0, W_JOINTS_0, W_WEIGHTS_0, W_JOINTS_1, W_WEIGHTS_1, W_ATTRS };
static const char* const k_attr_names[W_ATTRS] = {"POSITION", "NORMAL",    "TANGENT",  "TEXCOORD_0", "COLOR_0",
                                                  "JOINTS_0", "WEIGHTS_0", "JOINTS_1", "WEIGHTS_1"};

typedef struct w_prim {
    int32_t attr[W_ATTRS]; /* accessor per attribute, -1 absent */
    int32_t indices, mode, material; /* -1 absent */
    size_t target_first, target_count; /* in w_ctx.targets, 3 accessors (POSITION NORMAL TANGENT) each */
} w_prim;

typedef struct w_mesh {
    char name[AK_NAME_SIZE];
    size_t prim_first, prim_count; /* in w_ctx.prims */
    const ak_mesh* morph;          /* default weights and target names from it; NULL none */
} w_mesh;

typedef struct w_material {
    float v[4];
    int texture;
} w_material;

typedef struct w_texture {
    size_t scene_texture;
    int view;
} w_texture;

typedef struct w_skin {
    size_t scene_skin;
    int accessor;
} w_skin;

typedef struct w_channel {
    int sampler;
    int32_t node;
    const char* path;
} w_channel;

typedef struct w_sampler {
    int input, output;
    ak_interp interp;
} w_sampler;

typedef struct w_anim {
    const char* name;
    size_t channel_first, channel_count, sampler_first, sampler_count;
} w_anim;

/* A growable array: ptr, count and cap of one table. */
#define W_TABLE(type, name) \
    type* name;             \
    size_t name##_count, name##_cap

typedef struct w_ctx {
    const ak_scene* scene;
    const char* path;
    ak_diag* diag;
    const ak_logger* logger;
    /* the binary chunk is never held whole: a measuring pass (sink NULL) only adds up its
     * size and offsets; the writing pass streams each view to sink */
    FILE* sink;
    bool sink_failed; /* a write to sink failed (errno in sink_err) */
    int sink_err;
    size_t bin_size;
    /* the document, table by table */
    W_TABLE(w_view, views);
    W_TABLE(w_accessor, accessors);
    W_TABLE(float, minmax);
    W_TABLE(w_node, nodes);
    W_TABLE(w_prim, prims);
    W_TABLE(int32_t, targets);
    W_TABLE(w_mesh, meshes);
    W_TABLE(w_material, materials);
    W_TABLE(w_texture, textures);
    W_TABLE(w_skin, skins);
    W_TABLE(w_channel, channels);
    W_TABLE(w_sampler, samplers);
    W_TABLE(w_anim, anims);
    int32_t* gltf_texture; /* [scene texture_count] glTF texture written for it, -1 not yet */
    uint8_t** png;         /* [scene texture_count] its PNG, encoded once for both passes
                              (owned by the w_plan), NULL not yet */
    size_t* png_size;
    size_t n_nodes; /* written so far (joints, then extra mesh nodes) */
    int n_samplers; /* of the clip being written */
    int32_t* node_of_mesh; /* [mesh_count] glTF node carrying scene mesh m's glTF mesh, -1 none */
    int32_t* group_of_mesh; /* [mesh_count] first scene mesh of m's group (one glTF mesh) */
    size_t* morph_base; /* [mesh_count] first morph weight index of scene mesh m */
    /* instanced meshes (one ak_mesh placed by several scene meshes): accessors written once */
    int32_t* owner_of_mesh; /* [mesh_count] first scene mesh with m's ak_mesh pointer */
    bool* instanced;        /* [mesh_count] that pointer is placed more than once */
    int32_t* gltf_mesh_of;  /* [mesh_count] glTF mesh written for m, -1 not yet */
    int32_t* prim_of_mesh;  /* [mesh_count] the primitive (in prims) written for an instanced owner */
    /* the last animation input written: channels keyed at the same times share it */
    int last_times_accessor;
    float* last_times; /* a copy of its keys */
    size_t last_times_keys, last_times_cap;
} w_ctx;

/* One morph-weight sampler as written: key times, values in glTF layout. */
typedef struct w_morph {
    bool present;
    ak_interp interp;
    size_t keys;
    float* times;
    float* values; /* keys * (cubic ? 3 : 1) * targets */
} w_morph;

/* ---- static helpers --------------------------------------------------------------------- */

#define WTRY(x)                          \
    do {                                 \
        ak_result r_ = (x);              \
        if (r_ != AK_OK) return r_;      \
    } while (0)

static ak_result oom(w_ctx* c) {
    akp_diag_set(c->diag, c->path, "out of memory");
    return AK_ERR_NO_MEMORY;
}

/* Room for one more element in a table (*p holds *count of elem bytes, *cap allocated);
 * false when out of memory. */
static bool table_grow(void** p, size_t count, size_t* cap, size_t elem, size_t more) {
    if (count + more <= *cap) return true;
    size_t want = *cap ? 2 * *cap : 16;
    while (want < count + more) want *= 2;
    if (want > SIZE_MAX / elem) return false;
    void* q = realloc(*p, want * elem);
    if (!q) return false;
    *p = q, *cap = want;
    return true;
}

/* Append to table name of c: evaluates to a pointer to the new (uninitialised) element or NULL. */
#define W_PUSH(c, name)                                                                                    \
    (table_grow((void**)&(c)->name, (c)->name##_count, &(c)->name##_cap, sizeof *(c)->name, 1)             \
         ? &(c)->name[(c)->name##_count++]                                                                \
         : NULL)

/* Append data as a new bufferView (4-byte aligned, zero padded): written to c->sink when
 * there is one (a failed write is remembered in sink_failed), else only counted. Returns its
 * index or -1 (out of memory). */
static int add_view(w_ctx* c, const void* data, size_t bytes, int target) {
    size_t padded = (bytes + 3u) & ~(size_t)3u;
    if (padded < bytes || padded > SIZE_MAX / 2 - c->bin_size) return -1;
    size_t offset = c->bin_size;
    if (c->sink && !c->sink_failed) {
        static const uint8_t zeros[4] = {0, 0, 0, 0};
        if ((bytes && fwrite(data, 1, bytes, c->sink) != bytes) ||
            (padded > bytes && fwrite(zeros, 1, padded - bytes, c->sink) != padded - bytes)) {
            c->sink_failed = true;
            c->sink_err = errno ? errno : EIO;
        }
    }
    c->bin_size += padded;
    if (c->views_count >= INT32_MAX) return -1;
    w_view* v = W_PUSH(c, views);
    if (!v) return -1;
    *v = (w_view){offset, bytes, target};
    return (int)(c->views_count - 1);
}

static size_t ctype_size(int ctype) {
    return ctype == GL_FLOAT || ctype == GL_UNSIGNED_INT ? 4 : ctype == GL_UNSIGNED_SHORT ? 2 : 1;
}

static const char* type_name(int comps) {
    switch (comps) {
    case 1: return "SCALAR";
    case 2: return "VEC2";
    case 3: return "VEC3";
    case 4: return "VEC4";
    default: return "MAT4";
    }
}

/* Add an accessor over count elements of comps components (float data gets min/max when
 * minmax is set, as POSITION and animation inputs require). Returns its index or -1. */
static int add_accessor(w_ctx* c, const void* data, size_t count, int ctype, int comps, int target, bool minmax) {
    size_t bytes = count * (size_t)comps * ctype_size(ctype);
    int view = add_view(c, data, bytes, target);
    if (view < 0 || c->accessors_count >= INT32_MAX) return -1;
    w_accessor* a = W_PUSH(c, accessors);
    if (!a) return -1;
    *a = (w_accessor){.view = view, .ctype = ctype, .comps = comps, .minmax = -1, .count = count};
    const int index = (int)(c->accessors_count - 1);
    if (minmax && ctype == GL_FLOAT && count && !c->sink) { /* the writing pass: only the data matters */
        if (c->minmax_count > INT32_MAX - 32 ||
            !table_grow((void**)&c->minmax, c->minmax_count, &c->minmax_cap, sizeof(float), 2 * (size_t)comps))
            return -1;
        float* mn = c->minmax + c->minmax_count;
        float* mx = mn + comps;
        a->minmax = (int32_t)c->minmax_count;
        c->minmax_count += 2 * (size_t)comps;
        const float* f = (const float*)data;
        for (int k = 0; k < comps; ++k) {
            float lo = f[k], hi = f[k];
            for (size_t i = 1; i < count; ++i) {
                float x = f[i * (size_t)comps + (size_t)k];
                lo = x < lo ? x : lo;
                hi = x > hi ? x : hi;
            }
            mn[k] = lo, mx[k] = hi;
        }
    }
    return index;
}

static bool finite_floats(const float* f, size_t n) {
    for (size_t i = 0; i < n; ++i)
        if (!ak_finitef(f[i])) return false;
    return true;
}

#define BAD(c, code, ...) (akp_diag_set((c)->diag, (c)->path, __VA_ARGS__), (code))

/* ---- nodes ------------------------------------------------------------------------------ */

/* Append a node (joint, or -1 with an owned copy of name); out of memory -> NULL. */
static w_node* push_node(w_ctx* c, int32_t joint, const char* name) {
    if (c->nodes_count >= INT32_MAX) return NULL;
    char* copy = NULL;
    if (joint < 0) {
        size_t n = strlen(name);
        if (!(copy = (char*)malloc(n + 1))) return NULL;
        memcpy(copy, name, n + 1);
    }
    w_node* node = W_PUSH(c, nodes);
    if (!node) {
        free(copy);
        return NULL;
    }
    *node = (w_node){.joint = joint, .name = copy, .first_child = -1, .last_child = -1, .next_sibling = -1,
                     .parent = -1, .mesh = -1, .skin = -1};
    return node;
}

static w_node* node_at(const w_ctx* c, int32_t i) {
    return i >= 0 && (size_t)i < c->nodes_count ? &c->nodes[i] : NULL;
}

static ak_result add_child(w_ctx* c, int32_t parent, size_t child) {
    w_node* p = node_at(c, parent);
    if (!p) return BAD(c, AK_ERR_BAD_INDEX, "node %d is out of range", (int)parent);
    if (p->last_child < 0) {
        p->first_child = (int32_t)child;
        p->children_last = p->mesh >= 0;
    } else {
        c->nodes[p->last_child].next_sibling = (int32_t)child;
    }
    p->last_child = (int32_t)child;
    c->nodes[child].parent = parent;
    return AK_OK;
}

static ak_result write_skeleton(w_ctx* c) {
    const ak_skeleton* sk = c->scene->skeleton;
    size_t n = sk ? ak_skeleton_joint_count(sk) : 0;
    ak_i32_cspan parents = ak_skeleton_parents(sk);
    ak_transform_cspan rest = ak_skeleton_rest_pose(sk);
    for (size_t j = 0; j < n; ++j) {
        if (!push_node(c, (int32_t)j, NULL) || !ak_skeleton_joint_name(sk, j)) return oom(c);
        if (!ak_transform_is_finite(rest.ptr[j])) return BAD(c, AK_ERR_BAD_DATA, "joint %zu: rest transform is not finite", j);
        if (parents.ptr[j] >= 0) WTRY(add_child(c, parents.ptr[j], j));
    }
    c->n_nodes = n;
    return AK_OK;
}

/* A new node with identity transform for a mesh (a root unless parent >= 0), named
 * "<mesh_name>_node". */
static ak_result add_mesh_node(w_ctx* c, const char* mesh_name, int32_t parent, int32_t* out_node) {
    char name[AK_NAME_SIZE + 8];
    snprintf(name, sizeof name, "%s_node", mesh_name[0] ? mesh_name : "mesh");
    if (!push_node(c, -1, name)) return oom(c);
    *out_node = (int32_t)c->n_nodes++;
    if (parent >= 0) WTRY(add_child(c, parent, (size_t)*out_node));
    return AK_OK;
}

/* ---- morph-weight samplers ------------------------------------------------------------- */

static void morph_free(w_morph* m) {
    free(m->times);
    free(m->values);
    memset(m, 0, sizeof *m);
}

static bool is_cubic(ak_interp i) { return i != AK_INTERP_STEP && i != AK_INTERP_LINEAR; }

/* glTF interpolation a track is written with, or AK_INTERP_COUNT when it has none:
 * HERMITE, CARDINAL, NATURAL and BEZIER are cubic Hermite segments with per-second tangents
 * (curve.h), written as CUBICSPLINE with those tangents; the curve is the same. */
static ak_interp gltf_interp(const ak_track* t) {
    ak_interp i = ak_track_interp(t);
    switch (i) {
    case AK_INTERP_STEP:
    case AK_INTERP_LINEAR: return i;
    case AK_INTERP_CUBICSPLINE:
    case AK_INTERP_HERMITE: return AK_INTERP_CUBICSPLINE;
    case AK_INTERP_CARDINAL:
    case AK_INTERP_NATURAL:
    case AK_INTERP_BEZIER: return ak_track_is_rotation(t) ? AK_INTERP_COUNT : AK_INTERP_CUBICSPLINE;
    default: return AK_INTERP_COUNT;
    }
}

/* Output values of a track in glTF layout for interp (cubic: in, value, out per key).
 * comps components of the track land at [first, first + comps) of stride floats per element,
 * the rest of the element is filled from fill (NULL -> untouched). */
static ak_result track_values(w_ctx* c, const ak_track* t, ak_interp interp, float* out, size_t stride,
                              size_t first, const float* fill) {
    size_t keys = ak_track_key_count(t);
    uint32_t comps = ak_track_component_count(t);
    float v[AK_TRACK_MAX_COMPONENTS], ti[AK_TRACK_MAX_COMPONENTS], to[AK_TRACK_MAX_COMPONENTS];
    size_t parts = is_cubic(interp) ? 3 : 1;
    for (size_t k = 0; k < keys; ++k) {
        ak_result r = ak_track_key(t, k, (ak_f32_span){v, comps}, (ak_f32_span){ti, comps}, (ak_f32_span){to, comps});
        if (r != AK_OK) return r;
        for (size_t p = 0; p < parts; ++p) {
            const float* src = parts == 1 ? v : p == 0 ? ti : p == 1 ? v : to;
            float* dst = out + (k * parts + p) * stride;
            if (fill)
                for (size_t i = 0; i < stride; ++i) dst[i] = (parts == 3 && p != 1) ? 0.0f : fill[i];
            memcpy(dst + first, src, comps * sizeof(float));
        }
    }
    if (!finite_floats(out, keys * parts * stride)) return BAD(c, AK_ERR_BAD_DATA, "a key value or tangent is not finite");
    return AK_OK;
}

/* The morph-weight sampler of scene mesh m in clip: the one channel overlapping its weights,
 * padded with the default weights for targets the channel does not cover. */
static ak_result morph_sampler(w_ctx* c, const ak_clip* clip, size_t m, w_morph* out) {
    memset(out, 0, sizeof *out);
    const ak_mesh* mesh = c->scene->meshes[m].mesh;
    size_t base = c->morph_base[m], tc = mesh->morph_target_count;
    if (!tc) return AK_OK;
    size_t found = SIZE_MAX;
    for (size_t ch = 0; ch < ak_clip_channel_count(clip); ++ch) {
        if (ak_clip_channel_target(clip, ch) != AK_CHANNEL_MORPH_WEIGHTS) continue;
        size_t lo = ak_clip_channel_index(clip, ch);
        size_t hi = lo + ak_track_component_count(ak_clip_channel_track(clip, ch));
        if (hi <= base || lo >= base + tc) continue;
        if (found != SIZE_MAX) {
            akp_diag_set(c->diag, c->path,
                         "clip '%s': two channels animate the morph weights of mesh %zu; glTF has one per mesh",
                         ak_clip_name(clip), m);
            return AK_ERR_UNSUPPORTED;
        }
        found = ch;
    }
    if (found == SIZE_MAX) return AK_OK;
    const ak_track* t = ak_clip_channel_track(clip, found);
    size_t lo = ak_clip_channel_index(clip, found);
    uint32_t comps = ak_track_component_count(t);
    ak_interp interp = gltf_interp(t);
    if (interp == AK_INTERP_COUNT) {
        akp_diag_set(c->diag, c->path, "clip '%s' channel %zu: %s interpolation has no glTF form (bake it first)",
                     ak_clip_name(clip), found, ak_interp_name(ak_track_interp(t)));
        return AK_ERR_UNSUPPORTED;
    }
    size_t keys = ak_track_key_count(t), parts = is_cubic(interp) ? 3 : 1;
    /* the channel may start before this mesh or run past it: take the overlap */
    size_t first = lo > base ? lo - base : 0;
    size_t skip = base > lo ? base - lo : 0;
    size_t take = comps - skip < tc - first ? comps - skip : tc - first;
    float* full = (float*)malloc(keys * parts * comps * sizeof(float));
    out->times = (float*)malloc(keys * sizeof(float));
    out->values = (float*)malloc(keys * parts * tc * sizeof(float));
    if (!full || !out->times || !out->values) {
        free(full);
        morph_free(out);
        return oom(c);
    }
    ak_result r = track_values(c, t, interp, full, comps, 0, NULL);
    if (r == AK_OK) {
        for (size_t e = 0; e < keys * parts; ++e) {
            bool tangent = parts == 3 && e % 3 != 1;
            for (size_t i = 0; i < tc; ++i) out->values[e * tc + i] = tangent ? 0.0f : mesh->morph_weights[i];
            memcpy(out->values + e * tc + first, full + e * comps + skip, take * sizeof(float));
        }
        memcpy(out->times, ak_track_times(t).ptr, keys * sizeof(float));
        out->present = true;
        out->interp = interp;
        out->keys = keys;
    } else {
        morph_free(out);
    }
    free(full);
    return r;
}

static bool morph_equal(const w_morph* a, const w_morph* b, size_t tc) {
    if (a->present != b->present) return false;
    if (!a->present) return true;
    size_t parts = is_cubic(a->interp) ? 3 : 1;
    return a->interp == b->interp && a->keys == b->keys &&
           !memcmp(a->times, b->times, a->keys * sizeof(float)) &&
           !memcmp(a->values, b->values, a->keys * parts * tc * sizeof(float));
}

/* ---- meshes ------------------------------------------------------------------------------ */

static bool same_group(w_ctx* c, size_t a, size_t b, ak_result* err) {
    const ak_scene_mesh* ma = &c->scene->meshes[a];
    const ak_scene_mesh* mb = &c->scene->meshes[b];
    if (c->instanced[a] || c->instanced[b]) return false; /* an instance is a glTF mesh of its own */
    if (ma->node != mb->node || ma->skin != mb->skin || ma->node < 0) return false;
    size_t tc = ma->mesh->morph_target_count;
    if (tc != mb->mesh->morph_target_count) return false;
    if (tc && memcmp(ma->mesh->morph_weights, mb->mesh->morph_weights, tc * sizeof(float))) return false;
    if ((ma->mesh->influence_count == 0) != (mb->mesh->influence_count == 0)) return false;
    for (size_t k = 0; k < c->scene->clip_count && tc; ++k) {
        w_morph wa, wb;
        if ((*err = morph_sampler(c, c->scene->clips[k], a, &wa)) != AK_OK) return false;
        if ((*err = morph_sampler(c, c->scene->clips[k], b, &wb)) != AK_OK) {
            morph_free(&wa);
            return false;
        }
        bool eq = morph_equal(&wa, &wb, tc);
        morph_free(&wa);
        morph_free(&wb);
        if (!eq) return false;
    }
    return true;
}

static ak_result write_primitive(w_ctx* c, size_t m, w_prim* prim) {
    const ak_mesh* mesh = c->scene->meshes[m].mesh;
    size_t nv = mesh->vertex_count;
    char what[AK_NAME_SIZE + 32];
    snprintf(what, sizeof what, "mesh %zu (%s)", m, mesh->name);
    if (!finite_floats(&mesh->positions[0].x, nv * 3)) return BAD(c, AK_ERR_BAD_DATA, "%s: a position is not finite", what);
    int a = add_accessor(c, mesh->positions, nv, GL_FLOAT, 3, GL_ARRAY_BUFFER, true);
    if (a < 0) return oom(c);
    prim->attr[W_POSITION] = a;
    if (mesh->normals) {
        /* glTF requires unit normals: renormalise the ones that are off by more than float
         * rounding (a zero normal becomes +Y, as ak_normals_compute does) */
        ak_vec3* n = (ak_vec3*)malloc(nv * sizeof(ak_vec3));
        if (!n) return oom(c);
        for (size_t v = 0; v < nv; ++v) {
            ak_vec3 x = mesh->normals[v];
            float len = ak_vec3_length(x);
            if (!ak_vec3_is_finite(x)) {
                free(n);
                return BAD(c, AK_ERR_BAD_DATA, "%s: normal %zu is not finite", what, v);
            }
            n[v] = fabsf(len - 1.0f) <= 1e-5f ? x : len > 0.0f ? ak_vec3_scale(x, 1.0f / len) : ak_vec3_make(0, 1, 0);
        }
        a = add_accessor(c, n, nv, GL_FLOAT, 3, GL_ARRAY_BUFFER, false);
        free(n);
        if (a < 0) return oom(c);
        prim->attr[W_NORMAL] = a;
    }
    const bool tangents = mesh->tangents && mesh->normals; /* glTF: TANGENT needs NORMAL */
    if (mesh->tangents && !mesh->normals) {
        char msg[AK_NAME_SIZE + 96];
        snprintf(msg, sizeof msg, "%s: tangents without normals are not written", what);
        akp_log(c->logger, AK_LOG_WARN, msg);
    }
    if (tangents) {
        /* xyz unit (renormalised as normals are; a zero one becomes +X), w exactly +1 or -1 */
        ak_vec4* tg = (ak_vec4*)malloc(nv * sizeof(ak_vec4));
        if (!tg) return oom(c);
        for (size_t v = 0; v < nv; ++v) {
            ak_vec4 x = mesh->tangents[v];
            if (!finite_floats(&x.x, 4)) {
                free(tg);
                return BAD(c, AK_ERR_BAD_DATA, "%s: tangent %zu is not finite", what, v);
            }
            ak_vec3 d = ak_vec3_make(x.x, x.y, x.z);
            float len = ak_vec3_length(d);
            d = fabsf(len - 1.0f) <= 1e-5f ? d : len > 0.0f ? ak_vec3_scale(d, 1.0f / len) : ak_vec3_make(1, 0, 0);
            tg[v] = ak_vec4_make(d.x, d.y, d.z, x.w < 0.0f ? -1.0f : 1.0f);
        }
        a = add_accessor(c, tg, nv, GL_FLOAT, 4, GL_ARRAY_BUFFER, false);
        free(tg);
        if (a < 0) return oom(c);
        prim->attr[W_TANGENT] = a;
    }
    if (mesh->uvs) {
        if (!finite_floats(&mesh->uvs[0].x, nv * 2)) return BAD(c, AK_ERR_BAD_DATA, "%s: a UV is not finite", what);
        if ((a = add_accessor(c, mesh->uvs, nv, GL_FLOAT, 2, GL_ARRAY_BUFFER, false)) < 0) return oom(c);
        prim->attr[W_TEXCOORD_0] = a;
    }
    if (mesh->colors) {
        if (!finite_floats(&mesh->colors[0].x, nv * 4)) return BAD(c, AK_ERR_BAD_DATA, "%s: a colour is not finite", what);
        if ((a = add_accessor(c, mesh->colors, nv, GL_FLOAT, 4, GL_ARRAY_BUFFER, false)) < 0) return oom(c);
        prim->attr[W_COLOR_0] = a;
    }
    if (mesh->influence_count && c->scene->meshes[m].skin >= 0) { /* glTF skins need JOINTS_0 */
        uint32_t infl = mesh->influence_count, sets = infl > 4 ? 2 : 1;
        uint16_t maxj = 0;
        for (size_t i = 0; i < nv * infl; ++i) maxj = mesh->joints[i] > maxj ? mesh->joints[i] : maxj;
        bool wide = maxj > 255;
        uint8_t* jb = (uint8_t*)calloc(nv * 4, wide ? 2 : 1);
        float* wb = (float*)calloc(nv * 4, sizeof(float));
        if (!jb || !wb) {
            free(jb);
            free(wb);
            return oom(c);
        }
        ak_result r = AK_OK;
        for (uint32_t s = 0; s < sets && r == AK_OK; ++s) {
            memset(jb, 0, nv * 4 * (wide ? 2 : 1));
            memset(wb, 0, nv * 4 * sizeof(float));
            for (size_t v = 0; v < nv; ++v) {
                for (uint32_t k = 0; k < 4 && s * 4 + k < infl; ++k) {
                    size_t src = v * infl + s * 4 + k;
                    float w = mesh->weights[src];
                    if (!(w >= 0.0f) || !ak_finitef(w)) {
                        r = BAD(c, AK_ERR_BAD_WEIGHTS, "%s: vertex %zu has a negative or non-finite weight", what, v);
                        break;
                    }
                    /* a zero weight keeps joint 0 (glTF: unused influences are 0/0) */
                    uint16_t j = w > 0.0f ? mesh->joints[src] : 0;
                    if (wide) ((uint16_t*)(void*)jb)[v * 4 + k] = j;
                    else jb[v * 4 + k] = (uint8_t)j;
                    wb[v * 4 + k] = w > 0.0f ? w : 0.0f;
                }
            }
            if (r != AK_OK) break;
            int ja = add_accessor(c, jb, nv, wide ? GL_UNSIGNED_SHORT : GL_UNSIGNED_BYTE, 4, GL_ARRAY_BUFFER, false);
            int wa = add_accessor(c, wb, nv, GL_FLOAT, 4, GL_ARRAY_BUFFER, false);
            if (ja < 0 || wa < 0) r = oom(c);
            else {
                prim->attr[W_JOINTS_0 + 2 * s] = ja;
                prim->attr[W_WEIGHTS_0 + 2 * s] = wa;
            }
        }
        free(jb);
        free(wb);
        if (r != AK_OK) return r;
    }
    if (mesh->triangle_count) {
        size_t ni = mesh->triangle_count * 3;
        for (size_t i = 0; i < ni; ++i)
            if (mesh->indices[i] >= nv) return BAD(c, AK_ERR_BAD_INDEX, "%s: index %zu is out of range", what, i);
        if (nv <= 65535) { /* 65535 is the primitive restart value, never an index */
            uint16_t* ix = (uint16_t*)malloc(ni * sizeof(uint16_t));
            if (!ix) return oom(c);
            for (size_t i = 0; i < ni; ++i) ix[i] = (uint16_t)mesh->indices[i];
            a = add_accessor(c, ix, ni, GL_UNSIGNED_SHORT, 1, GL_ELEMENT_ARRAY_BUFFER, false);
            free(ix);
        } else {
            a = add_accessor(c, mesh->indices, ni, GL_UNSIGNED_INT, 1, GL_ELEMENT_ARRAY_BUFFER, false);
        }
        if (a < 0) return oom(c);
        prim->indices = a;
        prim->mode = 4;
    } else {
        prim->mode = 0; /* a point cloud */
    }
    if (mesh->morph_target_count) {
        prim->target_first = c->targets_count;
        for (size_t t = 0; t < mesh->morph_target_count; ++t) {
            if (!table_grow((void**)&c->targets, c->targets_count, &c->targets_cap, sizeof(int32_t), 3)) return oom(c);
            int32_t* tg = c->targets + c->targets_count;
            tg[0] = tg[1] = tg[2] = -1;
            c->targets_count += 3;
            ++prim->target_count;
            const ak_vec3* d = mesh->morph_positions + t * nv;
            if (!finite_floats(&d[0].x, nv * 3)) return BAD(c, AK_ERR_BAD_DATA, "%s: morph target %zu is not finite", what, t);
            if ((a = add_accessor(c, d, nv, GL_FLOAT, 3, GL_ARRAY_BUFFER, true)) < 0) return oom(c);
            tg[0] = a;
            if (mesh->morph_normals) {
                d = mesh->morph_normals + t * nv;
                if (!finite_floats(&d[0].x, nv * 3)) return BAD(c, AK_ERR_BAD_DATA, "%s: morph target %zu is not finite", what, t);
                if ((a = add_accessor(c, d, nv, GL_FLOAT, 3, GL_ARRAY_BUFFER, false)) < 0) return oom(c);
                tg[1] = a;
            }
            if (tangents && mesh->morph_tangents) {
                d = mesh->morph_tangents + t * nv;
                if (!finite_floats(&d[0].x, nv * 3)) return BAD(c, AK_ERR_BAD_DATA, "%s: morph target %zu is not finite", what, t);
                if ((a = add_accessor(c, d, nv, GL_FLOAT, 3, GL_ARRAY_BUFFER, false)) < 0) return oom(c);
                tg[2] = a;
            }
        }
    }
    return AK_OK;
}

/* The glTF texture of scene texture ti, written on first use: its pixels as an embedded PNG
 * (a bufferView, also for .gltf), a sampler with its wrap modes and filters, the texture
 * (image, sampler and texture n are written for glTF texture n). Returns the index, -1 when
 * out of memory or the PNG cannot be encoded. */
static int texture_index(w_ctx* c, size_t ti) {
    if (c->gltf_texture[ti] >= 0) return c->gltf_texture[ti];
    const ak_scene_texture* st = &c->scene->textures[ti];
    if (!c->png[ti] && akp_image_encode_png(st->pixels, st->width, st->height, &c->png[ti], &c->png_size[ti]) != AK_OK)
        return -1;
    int view = add_view(c, c->png[ti], c->png_size[ti], 0);
    if (view < 0) return -1;
    w_texture* t = W_PUSH(c, textures);
    if (!t) return -1;
    *t = (w_texture){ti, view};
    c->gltf_texture[ti] = (int32_t)(c->textures_count - 1);
    return c->gltf_texture[ti];
}

/* Index of a material with this base colour and base colour texture (-1: none) (made on
 * first use; channels clamped to [0, 1], the range glTF allows); -1 when out of memory. */
static int material_index(w_ctx* c, ak_vec4 col, int texture) {
    float v[4] = {col.x, col.y, col.z, col.w};
    for (int k = 0; k < 4; ++k) v[k] = v[k] < 0.0f ? 0.0f : v[k] > 1.0f ? 1.0f : v[k];
    for (size_t i = 0; i < c->materials_count; ++i) {
        const w_material* m = &c->materials[i];
        if (m->texture != texture) continue;
        int k = 0;
        while (k < 4 && m->v[k] == v[k]) ++k;
        if (k == 4) return (int)i;
    }
    w_material* m = W_PUSH(c, materials);
    if (!m) return -1;
    *m = (w_material){{v[0], v[1], v[2], v[3]}, texture};
    return (int)(c->materials_count - 1);
}

/* The glTF mesh name of a group: the reader names primitive p of mesh "M" "M_p", so a group
 * whose first name ends in "_0" takes the name without it. */
static void group_name(const char* first, size_t members, char out[AK_NAME_SIZE]) {
    snprintf(out, AK_NAME_SIZE, "%s", first);
    size_t n = strlen(out);
    if (members > 1 && n > 2 && out[n - 1] == '0' && out[n - 2] == '_') out[n - 2] = '\0';
}

typedef struct mesh_ref {
    uintptr_t ptr;
    size_t index;
} mesh_ref;

static int mesh_ref_cmp(const void* a, const void* b) {
    const mesh_ref *x = (const mesh_ref*)a, *y = (const mesh_ref*)b;
    if (x->ptr != y->ptr) return x->ptr < y->ptr ? -1 : 1;
    return x->index < y->index ? -1 : x->index > y->index;
}

/* owner_of_mesh and instanced: scene meshes that place the same ak_mesh, by sorting pointers
 * (a scene may hold thousands of instances). */
static ak_result find_instances(w_ctx* c) {
    const ak_scene* s = c->scene;
    const size_t n = s->mesh_count;
    mesh_ref* refs = (mesh_ref*)malloc((n ? n : 1) * sizeof *refs);
    if (!refs) return oom(c);
    for (size_t m = 0; m < n; ++m) refs[m] = (mesh_ref){(uintptr_t)s->meshes[m].mesh, m};
    qsort(refs, n, sizeof *refs, mesh_ref_cmp);
    for (size_t i = 0; i < n;) {
        size_t e = i + 1;
        while (e < n && refs[e].ptr == refs[i].ptr) ++e;
        for (size_t k = i; k < e; ++k) {
            c->owner_of_mesh[refs[k].index] = (int32_t)refs[i].index;
            c->instanced[refs[k].index] = e - i > 1;
        }
        i = e;
    }
    free(refs);
    for (size_t m = 0; m < n; ++m)
        if (s->meshes[m].shares_mesh && c->owner_of_mesh[m] == (int32_t)m)
            return BAD(c, AK_ERR_BAD_DATA, "mesh %zu (%s) shares its mesh but no earlier entry places it", m,
                       s->meshes[m].mesh->name);
    return AK_OK;
}

static bool same_material(const ak_scene_mesh* a, const ak_scene_mesh* b) {
    return a->has_material == b->has_material && a->texture == b->texture &&
           (!a->has_material || !memcmp(&a->base_color, &b->base_color, sizeof a->base_color));
}

/* The material of scene mesh k's primitive (none, a colour, a texture). */
static ak_result set_material(w_ctx* c, size_t k, w_prim* prim) {
    const ak_scene* s = c->scene;
    const ak_scene_mesh* sk = &s->meshes[k];
    bool textured = sk->texture >= 0 && (size_t)sk->texture < s->texture_count && s->textures[sk->texture].pixels &&
                    sk->mesh->uvs;
    if (!sk->has_material && !textured) return AK_OK;
    int ti = textured ? texture_index(c, (size_t)sk->texture) : -1;
    int mi = textured && ti < 0 ? -1 : material_index(c, sk->has_material ? sk->base_color : ak_vec4_make(1, 1, 1, 1), ti);
    if (mi < 0) return oom(c);
    prim->material = mi;
    return AK_OK;
}

/* A new glTF mesh (its primitives to be appended to prims); NULL when out of memory. */
static w_mesh* push_mesh(w_ctx* c, const char* name) {
    if (c->meshes_count >= INT32_MAX) return NULL;
    w_mesh* gm = W_PUSH(c, meshes);
    if (!gm) return NULL;
    *gm = (w_mesh){.prim_first = c->prims_count};
    snprintf(gm->name, sizeof gm->name, "%s", name);
    return gm;
}

/* A new primitive of the last glTF mesh, nothing in it yet; NULL when out of memory. */
static w_prim* push_prim(w_ctx* c) {
    w_prim* p = W_PUSH(c, prims);
    if (!p) return NULL;
    *p = (w_prim){.indices = -1, .mode = -1, .material = -1};
    for (int k = 0; k < W_ATTRS; ++k) p->attr[k] = -1;
    ++c->meshes[c->meshes_count - 1].prim_count;
    return p;
}

/* An instanced scene mesh m whose owner was written: the glTF mesh of an earlier instance
 * with the same material, else a new glTF mesh whose primitive reads the owner's accessors. */
static ak_result instance_mesh(w_ctx* c, size_t m, int* out_mesh) {
    const ak_scene* s = c->scene;
    const size_t owner = (size_t)c->owner_of_mesh[m];
    for (size_t k = owner; k < m; ++k)
        if (c->owner_of_mesh[k] == (int32_t)owner && c->gltf_mesh_of[k] >= 0 && same_material(&s->meshes[k], &s->meshes[m])) {
            *out_mesh = c->gltf_mesh_of[k];
            return AK_OK;
        }
    w_mesh* gm = push_mesh(c, s->meshes[owner].mesh->name);
    if (!gm) return oom(c);
    gm->morph = c->meshes[c->gltf_mesh_of[owner]].morph; /* its weights and target names */
    w_prim* prim = push_prim(c);
    if (!prim) return oom(c);
    *prim = c->prims[c->prim_of_mesh[owner]];
    prim->material = -1;
    WTRY(set_material(c, m, prim));
    *out_mesh = (int)(c->meshes_count - 1);
    return AK_OK;
}

static void set_node_mesh(w_ctx* c, int32_t node, int mesh, int32_t skin) {
    w_node* nj = node_at(c, node);
    if (!nj) return;
    nj->mesh = mesh;
    nj->skin = skin;
}

static ak_result write_meshes(w_ctx* c) {
    const ak_scene* s = c->scene;
    WTRY(find_instances(c));
    size_t base = 0;
    for (size_t m = 0; m < s->mesh_count; ++m) {
        c->morph_base[m] = base;
        base += s->meshes[m].mesh->morph_target_count;
        c->node_of_mesh[m] = -1;
    }
    bool* used = (bool*)calloc(c->n_nodes ? c->n_nodes : 1, sizeof(bool));
    if (!used) return oom(c);
    ak_i32_cspan parents = ak_skeleton_parents(s->skeleton);
    size_t n_joints = c->n_nodes;
    ak_result r = AK_OK;
    for (size_t m = 0; m < s->mesh_count && r == AK_OK;) {
        size_t end = m + 1;
        while (end < s->mesh_count && same_group(c, m, end, &r)) ++end;
        if (r != AK_OK) break;
        const ak_scene_mesh* sm = &s->meshes[m];
        const ak_mesh* mesh = sm->mesh;
        /* the node that carries the glTF mesh: the scene's node where glTF allows it, else a new
         * identity node (a skinned mesh ignores its node's transform, so it gets a root node:
         * glTF warns about skinned meshes below other nodes) */
        int32_t node = -1;
        bool skinned = sm->skin >= 0 && mesh->influence_count > 0;
        if (sm->node >= 0 && (size_t)sm->node < n_joints && !used[sm->node] && (!skinned || parents.ptr[sm->node] < 0))
            node = sm->node;
        else {
            char nn[AK_NAME_SIZE]; /* instances: node names that tell them apart */
            if (c->instanced[m]) snprintf(nn, sizeof nn, "%.40s_%zu", mesh->name[0] ? mesh->name : "mesh", m);
            if ((r = add_mesh_node(c, c->instanced[m] ? nn : mesh->name, skinned ? -1 : sm->node, &node)) != AK_OK)
                break;
        }
        if ((size_t)node < n_joints) used[node] = true;
        if (c->instanced[m] && c->owner_of_mesh[m] != (int32_t)m) { /* the owner's accessors */
            int gi = -1;
            if ((r = instance_mesh(c, m, &gi)) != AK_OK) break;
            c->gltf_mesh_of[m] = gi;
            c->node_of_mesh[m] = node;
            c->group_of_mesh[m] = (int32_t)m;
            set_node_mesh(c, node, gi, skinned ? sm->skin : -1);
            m = end;
            continue;
        }
        char gname[AK_NAME_SIZE];
        group_name(mesh->name, end - m, gname);
        if (!push_mesh(c, gname)) {
            r = oom(c);
            break;
        }
        const int gi = (int)(c->meshes_count - 1);
        for (size_t k = m; k < end && r == AK_OK; ++k) {
            w_prim* prim = push_prim(c);
            if (!prim) r = oom(c);
            else r = write_primitive(c, k, prim);
            /* write_primitive may grow prims no further: prim is still valid */
            if (r == AK_OK) r = set_material(c, k, prim);
            c->node_of_mesh[k] = node;
            c->group_of_mesh[k] = (int32_t)m;
            c->gltf_mesh_of[k] = gi;
            c->prim_of_mesh[k] = (int32_t)(c->prims_count - 1);
        }
        if (r == AK_OK && mesh->morph_target_count) {
            for (size_t t = 0; r == AK_OK && t < mesh->morph_target_count; ++t)
                if (!ak_finitef(mesh->morph_weights[t])) r = BAD(c, AK_ERR_BAD_DATA, "mesh %s: default weight %zu is not finite", mesh->name, t);
            c->meshes[gi].morph = mesh;
        }
        if (r == AK_OK) set_node_mesh(c, node, gi, skinned ? sm->skin : -1);
        m = end;
    }
    free(used);
    return r;
}

static ak_result write_skins(w_ctx* c) {
    const ak_scene* s = c->scene;
    for (size_t i = 0; i < s->skin_count; ++i) {
        const ak_scene_skin* sk = &s->skins[i];
        for (size_t k = 0; k < sk->joint_count; ++k) {
            if (sk->joints[k] < 0 || (size_t)sk->joints[k] >= ak_scene_joint_count(s))
                return BAD(c, AK_ERR_BAD_INDEX, "skin %s: slot %zu names no joint", sk->name, k);
            if (!ak_mat4_is_finite(&sk->inverse_binds[k])) return BAD(c, AK_ERR_BAD_DATA, "skin %s: inverse bind %zu is not finite", sk->name, k);
        }
        int a = add_accessor(c, sk->inverse_binds, sk->joint_count, GL_FLOAT, 16, 0, false);
        w_skin* js = a < 0 ? NULL : W_PUSH(c, skins);
        if (!js) return oom(c);
        *js = (w_skin){i, a};
    }
    return AK_OK;
}

/* ---- animations ------------------------------------------------------------------------ */

/* A sampler of the clip being written (its input shared with the previous one when keyed at
 * the same times); *out_index is its index in the clip. */
static ak_result add_sampler(w_ctx* c, const float* times, size_t keys, const float* values, size_t value_count,
                             int comps, ak_interp interp, int* out_index) {
    /* channels keyed at the same times (a baked crowd: all of them) share one input */
    int in = c->last_times_accessor;
    if (in < 0 || keys != c->last_times_keys || (keys && memcmp(c->last_times, times, keys * sizeof(float)))) {
        if (keys > c->last_times_cap) {
            float* t = (float*)realloc(c->last_times, keys * sizeof(float));
            if (!t) return oom(c);
            c->last_times = t, c->last_times_cap = keys;
        }
        if (keys) memcpy(c->last_times, times, keys * sizeof(float));
        in = add_accessor(c, times, keys, GL_FLOAT, 1, 0, true);
        c->last_times_accessor = in, c->last_times_keys = keys;
    }
    int outa = add_accessor(c, values, value_count, GL_FLOAT, comps, 0, false);
    w_sampler* sm = in < 0 || outa < 0 ? NULL : W_PUSH(c, samplers);
    if (!sm) return oom(c);
    *sm = (w_sampler){in, outa, interp};
    *out_index = c->n_samplers++;
    return AK_OK;
}

static ak_result add_channel(w_ctx* c, int sampler, int32_t node, const char* path) {
    w_channel* ch = W_PUSH(c, channels);
    if (!ch) return oom(c);
    *ch = (w_channel){sampler, node, path};
    return AK_OK;
}

static ak_result write_clip(w_ctx* c, const ak_clip* clip, size_t ci) {
    c->n_samplers = 0;
    const size_t channel_first = c->channels_count, sampler_first = c->samplers_count;
    ak_result r = AK_OK;
    size_t joints = ak_scene_joint_count(c->scene);
    for (size_t ch = 0; ch < ak_clip_channel_count(clip) && r == AK_OK; ++ch) {
        ak_channel_target tgt = ak_clip_channel_target(clip, ch);
        if (tgt == AK_CHANNEL_MORPH_WEIGHTS) continue; /* per mesh below */
        if (tgt == AK_CHANNEL_SCALAR) {
            char msg[200];
            snprintf(msg, sizeof msg, "glTF writer: clip '%s' channel %zu animates free scalars; not written",
                     ak_clip_name(clip), ch);
            akp_log(c->logger, AK_LOG_WARN, msg);
            continue;
        }
        const ak_track* t = ak_clip_channel_track(clip, ch);
        uint32_t joint = ak_clip_channel_index(clip, ch);
        if (joint >= joints) {
            akp_diag_set(c->diag, c->path, "clip '%s' channel %zu: joint %u is not in the skeleton", ak_clip_name(clip), ch, joint);
            r = AK_ERR_BAD_INDEX;
            break;
        }
        ak_interp interp = gltf_interp(t);
        if (interp == AK_INTERP_COUNT) {
            akp_diag_set(c->diag, c->path, "clip '%s' channel %zu: %s interpolation has no glTF form (bake it first)",
                         ak_clip_name(clip), ch, ak_interp_name(ak_track_interp(t)));
            r = AK_ERR_UNSUPPORTED;
            break;
        }
        size_t keys = ak_track_key_count(t), parts = is_cubic(interp) ? 3 : 1;
        uint32_t comps = ak_track_component_count(t);
        float* v = (float*)malloc(keys * parts * comps * sizeof(float));
        if (!v) return oom(c);
        r = track_values(c, t, interp, v, comps, 0, NULL);
        int si = -1;
        if (r == AK_OK)
            r = add_sampler(c, ak_track_times(t).ptr, keys, v, keys * parts, (int)comps, interp, &si);
        free(v);
        if (r == AK_OK)
            r = add_channel(c, si, (int32_t)joint, tgt == AK_CHANNEL_TRANSLATION ? "translation"
                                                       : tgt == AK_CHANNEL_ROTATION ? "rotation" : "scale");
    }
    for (size_t m = 0; m < c->scene->mesh_count && r == AK_OK; ++m) {
        if (c->group_of_mesh[m] != (int32_t)m) continue; /* one channel per glTF mesh */
        w_morph w;
        if ((r = morph_sampler(c, clip, m, &w)) != AK_OK || !w.present) continue;
        size_t tc = c->scene->meshes[m].mesh->morph_target_count, parts = is_cubic(w.interp) ? 3 : 1;
        int si = -1;
        r = add_sampler(c, w.times, w.keys, w.values, w.keys * parts * tc, 1, w.interp, &si);
        if (r == AK_OK) r = add_channel(c, si, c->node_of_mesh[m], "weights");
        morph_free(&w);
    }
    if (r == AK_OK && c->channels_count == channel_first) {
        char msg[200];
        snprintf(msg, sizeof msg, "glTF writer: clip %zu ('%s') has nothing glTF can hold; not written", ci,
                 ak_clip_name(clip));
        akp_log(c->logger, AK_LOG_WARN, msg);
        return AK_OK;
    }
    w_anim* an = r == AK_OK ? W_PUSH(c, anims) : NULL;
    if (!an) return r != AK_OK ? r : oom(c);
    *an = (w_anim){ak_clip_name(clip), channel_first, c->channels_count - channel_first, sampler_first,
                   c->samplers_count - sampler_first};
    return AK_OK;
}

/* ---- output ----------------------------------------------------------------------------- */

static bool ends_with(const char* s, const char* suffix) {
    size_t n = strlen(s), k = strlen(suffix);
    if (n < k) return false;
    for (size_t i = 0; i < k; ++i)
        if ((s[n - k + i] | 0x20) != suffix[i]) return false;
    return true;
}

static void put_u32(uint8_t* p, uint32_t v) {
    p[0] = (uint8_t)v;
    p[1] = (uint8_t)(v >> 8);
    p[2] = (uint8_t)(v >> 16);
    p[3] = (uint8_t)(v >> 24);
}

/* Put a closed temporary in place; the diag names path when that fails. */
static ak_result rename_into_place(w_ctx* c, ak_atomic_file* out) {
    if (ak_atomic_file_rename(out) == AK_OK) return AK_OK;
    akp_diag_set(c->diag, out->path, "cannot write file (%s)", strerror(out->err ? out->err : EIO));
    return AK_ERR_IO;
}

/* Percent-encode a file name for a URI (RFC 3986 unreserved characters kept). */
static void uri_encode(const char* s, char* out, size_t cap) {
    static const char hex[] = "0123456789ABCDEF";
    size_t o = 0;
    for (; *s && o + 4 < cap; ++s) {
        unsigned char ch = (unsigned char)*s;
        if ((ch >= 'A' && ch <= 'Z') || (ch >= 'a' && ch <= 'z') || (ch >= '0' && ch <= '9') || ch == '-' ||
            ch == '_' || ch == '.' || ch == '~') {
            out[o++] = (char)ch;
        } else {
            out[o++] = '%';
            out[o++] = hex[ch >> 4];
            out[o++] = hex[ch & 15];
        }
    }
    out[o] = '\0';
}


static ak_result build_document(w_ctx* c) {
    const ak_scene* s = c->scene;
    c->gltf_texture = (int32_t*)malloc((s->texture_count ? s->texture_count : 1) * sizeof(int32_t));
    if (!c->gltf_texture) return oom(c);
    for (size_t t = 0; t < s->texture_count; ++t) c->gltf_texture[t] = -1;
    size_t mc = s->mesh_count ? s->mesh_count : 1;
    c->node_of_mesh = (int32_t*)calloc(mc, sizeof(int32_t));
    c->group_of_mesh = (int32_t*)calloc(mc, sizeof(int32_t));
    c->morph_base = (size_t*)calloc(mc, sizeof(size_t));
    c->owner_of_mesh = (int32_t*)calloc(mc, sizeof(int32_t));
    c->instanced = (bool*)calloc(mc, sizeof(bool));
    c->gltf_mesh_of = (int32_t*)malloc(mc * sizeof(int32_t));
    c->prim_of_mesh = (int32_t*)calloc(mc, sizeof(int32_t));
    if (!c->owner_of_mesh || !c->instanced || !c->gltf_mesh_of || !c->prim_of_mesh) return oom(c);
    for (size_t m = 0; m < mc; ++m) c->gltf_mesh_of[m] = -1;
    c->last_times_accessor = -1;
    if (!c->node_of_mesh || !c->group_of_mesh || !c->morph_base) return oom(c);
    for (size_t m = 0; m < s->mesh_count; ++m) {
        if (!s->meshes[m].mesh) return BAD(c, AK_ERR_NULL_ARG, "mesh %zu has no data", m);
        if (s->meshes[m].skin >= (int32_t)s->skin_count || s->meshes[m].skin < -1 ||
            s->meshes[m].node >= (int32_t)ak_scene_joint_count(s) || s->meshes[m].node < -1)
            return BAD(c, AK_ERR_BAD_INDEX, "mesh %zu: skin %d or node %d out of range", m, (int)s->meshes[m].skin,
                       (int)s->meshes[m].node);
    }
    WTRY(write_skeleton(c));
    WTRY(write_skins(c));
    WTRY(write_meshes(c));
    for (size_t k = 0; k < s->clip_count; ++k)
        if (s->clips[k]) WTRY(write_clip(c, s->clips[k], k));
    return AK_OK;
}

/* ---- the JSON text ---------------------------------------------------------------------- */

static void emit_floats(akp_jw* w, const char* key, const float* v, size_t n) {
    akp_jw_array(w, key);
    for (size_t i = 0; i < n; ++i) akp_jw_number(w, NULL, v[i]);
    akp_jw_end(w);
}

static void emit_node(akp_jw* w, const w_ctx* c, const w_node* n) {
    akp_jw_object(w, NULL);
    if (n->joint >= 0) {
        const ak_skeleton* sk = c->scene->skeleton;
        ak_transform t = ak_skeleton_rest_pose(sk).ptr[n->joint];
        akp_jw_string(w, "name", ak_skeleton_joint_name(sk, (size_t)n->joint));
        ak_quat q = ak_quat_normalize(t.rotation);
        if (t.translation.x != 0.0f || t.translation.y != 0.0f || t.translation.z != 0.0f)
            emit_floats(w, "translation", (const float[3]){t.translation.x, t.translation.y, t.translation.z}, 3);
        if (q.x != 0.0f || q.y != 0.0f || q.z != 0.0f || q.w != 1.0f)
            emit_floats(w, "rotation", (const float[4]){q.x, q.y, q.z, q.w}, 4);
        if (t.scale.x != 1.0f || t.scale.y != 1.0f || t.scale.z != 1.0f)
            emit_floats(w, "scale", (const float[3]){t.scale.x, t.scale.y, t.scale.z}, 3);
    } else {
        akp_jw_string(w, "name", n->name);
    }
    for (int pass = 0; pass < 2; ++pass) {
        if (n->first_child >= 0 && pass == (n->children_last ? 1 : 0)) {
            akp_jw_array(w, "children");
            for (int32_t ch = n->first_child; ch >= 0; ch = c->nodes[ch].next_sibling) akp_jw_number(w, NULL, ch);
            akp_jw_end(w);
        }
        if (pass == 0 && n->mesh >= 0) {
            akp_jw_number(w, "mesh", n->mesh);
            if (n->skin >= 0) akp_jw_number(w, "skin", n->skin);
        }
    }
    akp_jw_end(w);
}

static void emit_prim(akp_jw* w, const w_ctx* c, const w_prim* p) {
    akp_jw_object(w, NULL);
    akp_jw_object(w, "attributes");
    for (int k = 0; k < W_ATTRS; ++k)
        if (p->attr[k] >= 0) akp_jw_number(w, k_attr_names[k], p->attr[k]);
    akp_jw_end(w);
    if (p->indices >= 0) akp_jw_number(w, "indices", p->indices);
    akp_jw_number(w, "mode", p->mode);
    if (p->target_count) {
        akp_jw_array(w, "targets");
        for (size_t t = 0; t < p->target_count; ++t) {
            const int32_t* tg = c->targets + p->target_first + 3 * t;
            akp_jw_object(w, NULL);
            for (int k = 0; k < 3; ++k)
                if (tg[k] >= 0) akp_jw_number(w, k_attr_names[k], tg[k]);
            akp_jw_end(w);
        }
        akp_jw_end(w);
    }
    if (p->material >= 0) akp_jw_number(w, "material", p->material);
    akp_jw_end(w);
}

static void emit_mesh(akp_jw* w, const w_ctx* c, const w_mesh* m) {
    akp_jw_object(w, NULL);
    akp_jw_array(w, "primitives");
    for (size_t p = 0; p < m->prim_count; ++p) emit_prim(w, c, &c->prims[m->prim_first + p]);
    akp_jw_end(w);
    akp_jw_string(w, "name", m->name);
    if (m->morph) {
        const ak_mesh* mesh = m->morph;
        emit_floats(w, "weights", mesh->morph_weights, mesh->morph_target_count);
        akp_jw_object(w, "extras");
        akp_jw_array(w, "targetNames");
        for (size_t t = 0; t < mesh->morph_target_count; ++t)
            akp_jw_string(w, NULL, mesh->morph_names ? mesh->morph_names[t] : "");
        akp_jw_end(w);
        akp_jw_end(w);
    }
    akp_jw_end(w);
}

static void emit_anim(akp_jw* w, const w_ctx* c, const w_anim* a) {
    akp_jw_object(w, NULL);
    akp_jw_array(w, "channels");
    for (size_t i = 0; i < a->channel_count; ++i) {
        const w_channel* ch = &c->channels[a->channel_first + i];
        akp_jw_object(w, NULL);
        akp_jw_number(w, "sampler", ch->sampler);
        akp_jw_object(w, "target");
        akp_jw_number(w, "node", ch->node);
        akp_jw_string(w, "path", ch->path);
        akp_jw_end(w);
        akp_jw_end(w);
    }
    akp_jw_end(w);
    akp_jw_array(w, "samplers");
    for (size_t i = 0; i < a->sampler_count; ++i) {
        const w_sampler* sm = &c->samplers[a->sampler_first + i];
        akp_jw_object(w, NULL);
        akp_jw_number(w, "input", sm->input);
        akp_jw_number(w, "output", sm->output);
        akp_jw_string(w, "interpolation", sm->interp == AK_INTERP_STEP     ? "STEP"
                                          : sm->interp == AK_INTERP_LINEAR ? "LINEAR"
                                                                           : "CUBICSPLINE");
        akp_jw_end(w);
    }
    akp_jw_end(w);
    if (a->name[0]) akp_jw_string(w, "name", a->name);
    akp_jw_end(w);
}

/* The whole document, in the order readers expect to find its arrays (empty ones left out),
 * with the one buffer (its uri when bin_uri is not NULL). */
static void emit_document(akp_jw* w, const w_ctx* c, const char* bin_uri) {
    const ak_scene* s = c->scene;
    akp_jw_object(w, NULL);
    akp_jw_object(w, "asset");
    akp_jw_string(w, "version", "2.0");
    akp_jw_string(w, "generator", "animkit");
    akp_jw_end(w);
    if (c->nodes_count) {
        akp_jw_array(w, "scenes");
        akp_jw_object(w, NULL);
        akp_jw_array(w, "nodes");
        for (size_t i = 0; i < c->nodes_count; ++i)
            if (c->nodes[i].parent < 0) akp_jw_number(w, NULL, (double)i);
        akp_jw_end(w);
        akp_jw_end(w);
        akp_jw_end(w);
        akp_jw_number(w, "scene", 0);
        akp_jw_array(w, "nodes");
        for (size_t i = 0; i < c->nodes_count; ++i) emit_node(w, c, &c->nodes[i]);
        akp_jw_end(w);
    }
    if (c->meshes_count) {
        akp_jw_array(w, "meshes");
        for (size_t i = 0; i < c->meshes_count; ++i) emit_mesh(w, c, &c->meshes[i]);
        akp_jw_end(w);
    }
    if (c->materials_count) {
        akp_jw_array(w, "materials");
        for (size_t i = 0; i < c->materials_count; ++i) {
            const w_material* m = &c->materials[i];
            akp_jw_object(w, NULL);
            akp_jw_object(w, "pbrMetallicRoughness");
            emit_floats(w, "baseColorFactor", m->v, 4);
            if (m->texture >= 0) {
                akp_jw_object(w, "baseColorTexture");
                akp_jw_number(w, "index", m->texture);
                akp_jw_end(w);
            }
            akp_jw_end(w);
            akp_jw_end(w);
        }
        akp_jw_end(w);
    }
    if (c->textures_count) {
        static const int wraps[3] = {10497, 33071, 33648};
        akp_jw_array(w, "textures");
        for (size_t i = 0; i < c->textures_count; ++i) {
            akp_jw_object(w, NULL);
            akp_jw_number(w, "sampler", (double)i);
            akp_jw_number(w, "source", (double)i);
            akp_jw_end(w);
        }
        akp_jw_end(w);
        akp_jw_array(w, "images");
        for (size_t i = 0; i < c->textures_count; ++i) {
            const ak_scene_texture* st = &s->textures[c->textures[i].scene_texture];
            akp_jw_object(w, NULL);
            akp_jw_number(w, "bufferView", c->textures[i].view);
            akp_jw_string(w, "mimeType", "image/png");
            if (st->name[0] && akp_io_utf8_valid(st->name, strlen(st->name))) akp_jw_string(w, "name", st->name);
            akp_jw_end(w);
        }
        akp_jw_end(w);
        akp_jw_array(w, "samplers");
        for (size_t i = 0; i < c->textures_count; ++i) {
            const ak_scene_texture* st = &s->textures[c->textures[i].scene_texture];
            akp_jw_object(w, NULL);
            akp_jw_number(w, "magFilter", st->mag_filter == AK_TEXTURE_FILTER_NEAREST ? 9728 : 9729);
            akp_jw_number(w, "minFilter", st->min_filter == AK_TEXTURE_FILTER_NEAREST ? 9728 : 9729);
            akp_jw_number(w, "wrapS", wraps[(unsigned)st->wrap_s < 3u ? st->wrap_s : 0]);
            akp_jw_number(w, "wrapT", wraps[(unsigned)st->wrap_t < 3u ? st->wrap_t : 0]);
            akp_jw_end(w);
        }
        akp_jw_end(w);
    }
    if (c->skins_count) {
        akp_jw_array(w, "skins");
        for (size_t i = 0; i < c->skins_count; ++i) {
            const ak_scene_skin* sk = &s->skins[c->skins[i].scene_skin];
            akp_jw_object(w, NULL);
            if (sk->name[0]) akp_jw_string(w, "name", sk->name);
            akp_jw_array(w, "joints");
            for (size_t k = 0; k < sk->joint_count; ++k) akp_jw_number(w, NULL, sk->joints[k]);
            akp_jw_end(w);
            akp_jw_number(w, "inverseBindMatrices", c->skins[i].accessor);
            akp_jw_end(w);
        }
        akp_jw_end(w);
    }
    if (c->anims_count) {
        akp_jw_array(w, "animations");
        for (size_t i = 0; i < c->anims_count; ++i) emit_anim(w, c, &c->anims[i]);
        akp_jw_end(w);
    }
    if (c->accessors_count) {
        akp_jw_array(w, "accessors");
        for (size_t i = 0; i < c->accessors_count; ++i) {
            const w_accessor* a = &c->accessors[i];
            akp_jw_object(w, NULL);
            akp_jw_number(w, "bufferView", a->view);
            akp_jw_number(w, "componentType", a->ctype);
            akp_jw_number(w, "count", (double)a->count);
            akp_jw_string(w, "type", type_name(a->comps));
            if (a->minmax >= 0) {
                emit_floats(w, "min", c->minmax + a->minmax, (size_t)a->comps);
                emit_floats(w, "max", c->minmax + a->minmax + a->comps, (size_t)a->comps);
            }
            akp_jw_end(w);
        }
        akp_jw_end(w);
    }
    if (c->views_count) {
        akp_jw_array(w, "bufferViews");
        for (size_t i = 0; i < c->views_count; ++i) {
            const w_view* v = &c->views[i];
            akp_jw_object(w, NULL);
            akp_jw_number(w, "buffer", 0);
            if (v->offset) akp_jw_number(w, "byteOffset", (double)v->offset);
            akp_jw_number(w, "byteLength", (double)v->length);
            if (v->target) akp_jw_number(w, "target", v->target);
            akp_jw_end(w);
        }
        akp_jw_end(w);
    }
    if (c->bin_size) {
        akp_jw_array(w, "buffers");
        akp_jw_object(w, NULL);
        akp_jw_number(w, "byteLength", (double)c->bin_size);
        if (bin_uri) akp_jw_string(w, "uri", bin_uri);
        akp_jw_end(w);
        akp_jw_end(w);
    }
    akp_jw_end(w);
}

/* Free everything a pass built and zero the context's tables (scene, path, diag kept). */
static void ctx_free(w_ctx* c) {
    for (size_t i = 0; i < c->nodes_count; ++i) free(c->nodes[i].name);
    free(c->views);
    free(c->accessors);
    free(c->minmax);
    free(c->nodes);
    free(c->prims);
    free(c->targets);
    free(c->meshes);
    free(c->materials);
    free(c->textures);
    free(c->skins);
    free(c->channels);
    free(c->samplers);
    free(c->anims);
    free(c->gltf_texture);
    free(c->node_of_mesh);
    free(c->group_of_mesh);
    free(c->morph_base);
    free(c->owner_of_mesh);
    free(c->instanced);
    free(c->gltf_mesh_of);
    free(c->prim_of_mesh);
    free(c->last_times);
    *c = (w_ctx){.scene = c->scene, .path = c->path, .diag = c->diag, .logger = c->logger, .png = c->png,
                 .png_size = c->png_size};
}

/* What the measuring pass found: the document's tables and the sizes of what will be written. */
typedef struct w_plan {
    bool glb;
    w_ctx doc;    /* the document (its binary chunk only counted) */
    size_t json_size, bin_size;
    size_t total; /* bytes of every file written: the .glb, or the .gltf and its .bin */
    uint8_t** png; /* [texture_count] the textures' PNGs (w_ctx.png) */
    size_t* png_size;
    char bin_path[4096], bin_uri[4096];
} w_plan;

/* Write (f) or count (f NULL) the document's JSON text: cJSON_PrintUnformatted's bytes for a
 * .glb, cJSON_Print's for a .gltf. Returns the bytes; *err gets errno when a write fails. */
static size_t plan_json(const w_plan* plan, FILE* f, int* err) {
    akp_jw* w = (akp_jw*)malloc(sizeof *w);
    if (!w) {
        *err = ENOMEM;
        return 0;
    }
    akp_jw_init(w, f, !plan->glb);
    emit_document(w, &plan->doc, plan->glb ? NULL : plan->bin_uri);
    akp_jw_flush(w);
    size_t n = w->bytes;
    *err = w->failed ? (w->err ? w->err : EIO) : 0;
    free(w);
    return n;
}

/* The measuring pass: the whole document built with the binary chunk only counted and its
 * JSON text counted; plan gets the document and the exact sizes. */
static ak_result plan_save(const char* path, const ak_scene* scene, const ak_logger* logger, ak_diag* diag,
                           w_plan* plan) {
    memset(plan, 0, sizeof *plan);
    plan->glb = ends_with(path, ".glb");
    const size_t tc = scene->texture_count ? scene->texture_count : 1;
    plan->png = (uint8_t**)calloc(tc, sizeof *plan->png);
    plan->png_size = (size_t*)calloc(tc, sizeof *plan->png_size);
    w_ctx* c = &plan->doc;
    *c = (w_ctx){.scene = scene, .path = path, .diag = diag, .logger = logger, .png = plan->png, .png_size = plan->png_size};
    ak_result r = plan->png && plan->png_size ? build_document(c) : oom(c);
    /* the file name of the .bin beside a .gltf: the .gltf's name with .bin */
    if (r == AK_OK && !plan->glb && c->bin_size) {
        size_t n = strlen(path);
        if (n + 1 > sizeof plan->bin_path) {
            akp_diag_set(diag, path, "path is too long");
            r = AK_ERR_BAD_ARG;
        } else {
            memcpy(plan->bin_path, path, n - 5);
            memcpy(plan->bin_path + n - 5, ".bin", 5);
            const char* base = strrchr(plan->bin_path, '/');
            uri_encode(base ? base + 1 : plan->bin_path, plan->bin_uri, sizeof plan->bin_uri);
        }
    }
    if (r == AK_OK) {
        int err = 0;
        plan->json_size = plan_json(plan, NULL, &err);
        if (err) r = oom(c);
    }
    if (r == AK_OK) {
        plan->bin_size = c->bin_size;
        if (plan->glb) {
            size_t jpad = (plan->json_size + 3u) & ~(size_t)3u;
            plan->total = 12 + 8 + jpad + (c->bin_size ? 8 + c->bin_size : 0);
            if (plan->total > UINT32_MAX) {
                akp_diag_set(diag, path, "%zu bytes is more than a GLB file can hold", plan->total);
                r = AK_ERR_UNSUPPORTED;
            }
        } else {
            plan->total = plan->json_size + 1 + c->bin_size; /* the .gltf ends in a newline */
        }
    }
    return r;
}

/* Free what plan_save left in plan. */
static void plan_free(const ak_scene* scene, w_plan* plan) {
    ctx_free(&plan->doc);
    for (size_t t = 0; plan->png && t < scene->texture_count; ++t) free(plan->png[t]);
    free(plan->png);
    free(plan->png_size);
    memset(plan, 0, sizeof *plan);
}

/* The writing pass: the document built again (the same scene gives the same views in the
 * same order), every view streamed to f as it is made; the tables of this pass are thrown away. */
static ak_result stream_bin(const char* path, const ak_scene* scene, ak_diag* diag, const w_plan* plan, FILE* f) {
    ak_logger none = {0}; /* the measuring pass gave the warnings */
    w_ctx c = {.scene = scene, .path = path, .diag = diag, .logger = &none, .sink = f, .png = plan->png,
               .png_size = plan->png_size};
    ak_result r = build_document(&c);
    if (r == AK_OK && c.sink_failed) {
        akp_diag_set(diag, path, "cannot write file (%s)", strerror(c.sink_err));
        r = AK_ERR_IO;
    }
    if (r == AK_OK && c.bin_size != plan->bin_size) {
        akp_diag_set(diag, path, "the binary chunk came out %zu bytes instead of %zu (the scene changed while written?)",
                     c.bin_size, plan->bin_size);
        r = AK_ERR_IO;
    }
    ctx_free(&c);
    return r;
}

/* ---- public ---------------------------------------------------------------------------- */

static ak_result check_args(const char* path, const ak_scene* scene, ak_diag* diag) {
    if (!path || !scene) {
        akp_diag_set(diag, path, "path and scene are required");
        return AK_ERR_NULL_ARG;
    }
    if (!ends_with(path, ".glb") && !ends_with(path, ".gltf")) {
        akp_diag_set(diag, path, "the file name must end in .glb or .gltf");
        return AK_ERR_BAD_ARG;
    }
    return AK_OK;
}

ak_result ak_io_save_size(const char* path, const ak_scene* scene, const ak_io_save_desc* desc, size_t* out_bytes,
                          ak_diag* diag) {
    if (out_bytes) *out_bytes = 0;
    if (!out_bytes) {
        akp_diag_set(diag, path, "out_bytes is required");
        return AK_ERR_NULL_ARG;
    }
    WTRY(check_args(path, scene, diag));
    ak_logger none = {0};
    w_plan* plan = (w_plan*)malloc(sizeof *plan);
    if (!plan) {
        akp_diag_set(diag, path, "out of memory");
        return AK_ERR_NO_MEMORY;
    }
    ak_result r = plan_save(path, scene, desc ? &desc->logger : &none, diag, plan);
    if (r == AK_OK) *out_bytes = plan->total;
    plan_free(scene, plan);
    free(plan);
    return r;
}

ak_result ak_io_save(const char* path, const ak_scene* scene, const ak_io_save_desc* desc, ak_diag* diag) {
    WTRY(check_args(path, scene, diag));
    ak_logger none = {0};
    const size_t budget = desc && desc->memory_budget ? desc->memory_budget : AK_IO_SAVE_DEFAULT_BUDGET;
    /* the plan (8 KiB of paths) and the temporaries of the file and its .bin: off the stack */
    w_plan* plan = (w_plan*)malloc(sizeof *plan);
    ak_atomic_file* out = (ak_atomic_file*)calloc(2, sizeof *out);
    if (!plan || !out) {
        free(plan);
        free(out);
        akp_diag_set(diag, path, "out of memory");
        return AK_ERR_NO_MEMORY;
    }
    ak_result r = plan_save(path, scene, desc ? &desc->logger : &none, diag, plan);
    if (r == AK_OK && plan->total > budget) {
        akp_diag_set(diag, path,
                     "the glTF output is %zu bytes (JSON %zu, binary %zu), over the writer's memory budget of %zu "
                     "bytes (ak_io_save_desc.memory_budget); nothing written",
                     plan->total, plan->json_size, plan->bin_size, budget);
        r = AK_ERR_UNSUPPORTED;
    }
    if (r == AK_OK && plan->glb) {
        if (ak_atomic_file_open(out, path) != AK_OK) {
            akp_diag_set(diag, path, "cannot create file (%s)", strerror(out->err));
            r = AK_ERR_IO;
        } else {
            size_t jn = plan->json_size, jpad = (jn + 3u) & ~(size_t)3u;
            uint8_t head[20], pad[3] = {' ', ' ', ' '}, binh[8];
            put_u32(head, 0x46546C67u); /* "glTF" */
            put_u32(head + 4, 2);
            put_u32(head + 8, (uint32_t)plan->total);
            put_u32(head + 12, (uint32_t)jpad);
            put_u32(head + 16, 0x4E4F534Au); /* "JSON" */
            put_u32(binh, (uint32_t)plan->bin_size);
            put_u32(binh + 4, 0x004E4942u); /* "BIN\0": views are 4-byte padded with zeros */
            int err = 0;
            bool ok = fwrite(head, 1, 20, out->f) == 20;
            if (ok && (plan_json(plan, out->f, &err) != jn || err)) ok = false, errno = err ? err : EIO;
            ok = ok && fwrite(pad, 1, jpad - jn, out->f) == jpad - jn && /* JSON chunk padding: spaces */
                 (!plan->bin_size || fwrite(binh, 1, 8, out->f) == 8);
            ctx_free(&plan->doc); /* the JSON is in the file: its tables are not held while the binary is made */
            if (!ok) {
                akp_diag_set(diag, path, "cannot write file (%s)", strerror(errno ? errno : EIO));
                r = AK_ERR_IO;
            }
            if (r == AK_OK && plan->bin_size) r = stream_bin(path, scene, diag, plan, out->f);
            if (r == AK_OK && ak_atomic_file_close(out) != AK_OK) {
                akp_diag_set(diag, path, "cannot write file (%s)", strerror(out->err ? out->err : EIO));
                r = AK_ERR_IO;
            }
            if (r == AK_OK) {
                w_ctx c = {.scene = scene, .path = path, .diag = diag};
                r = rename_into_place(&c, out);
            }
            ak_atomic_file_abort(out);
        }
    } else if (r == AK_OK) {
        /* both files are written in full (the .gltf first, so the document's tables are freed
         * before the binary is made) before either is renamed into place: the .bin first, so a
         * reader never sees a new .gltf beside an old .bin */
        w_ctx c = {.scene = scene, .path = path, .diag = diag};
        if (ak_atomic_file_open(out, path) != AK_OK) {
            akp_diag_set(diag, path, "cannot create file (%s)", strerror(out->err));
            r = AK_ERR_IO;
        } else {
            int err = 0;
            if (plan_json(plan, out->f, &err) != plan->json_size || err || fwrite("\n", 1, 1, out->f) != 1) {
                out->err = err ? err : errno;
                r = AK_ERR_IO;
            }
            if (r == AK_OK && ak_atomic_file_close(out) != AK_OK) r = AK_ERR_IO;
            if (r != AK_OK) akp_diag_set(diag, path, "cannot write file (%s)", strerror(out->err ? out->err : EIO));
        }
        ctx_free(&plan->doc); /* the JSON is in its file: its tables are not held while the binary is made */
        if (r == AK_OK && plan->bin_size) {
            if (ak_atomic_file_open(&out[1], plan->bin_path) != AK_OK) {
                akp_diag_set(diag, plan->bin_path, "cannot create file (%s)", strerror(out[1].err));
                r = AK_ERR_IO;
            }
            if (r == AK_OK) r = stream_bin(plan->bin_path, scene, diag, plan, out[1].f);
            if (r == AK_OK && ak_atomic_file_close(&out[1]) != AK_OK) {
                akp_diag_set(diag, plan->bin_path, "cannot write file (%s)", strerror(out[1].err ? out[1].err : EIO));
                r = AK_ERR_IO;
            }
        }
        if (r == AK_OK && plan->bin_size) r = rename_into_place(&c, &out[1]);
        if (r == AK_OK) r = rename_into_place(&c, out);
        ak_atomic_file_abort(&out[1]);
        ak_atomic_file_abort(out);
    }
    free(out);
    plan_free(scene, plan);
    free(plan);
    return r;
}

/* Everything but glTF (BVH, FBX, Collada, OBJ, ...) through Assimp's C API: the node tree
 * becomes the skeleton (depth-first, so parents come first), aiAnimation channels become
 * clips (ticks -> seconds), meshes with bones get one skin each. */
#define _XOPEN_SOURCE 700 /* realpath */
#include <assimp/cfileio.h>
#include <assimp/cimport.h> /* Debian libassimp-dev (5.2.5) */
#include <assimp/postprocess.h>
#include <assimp/scene.h>
#include <ctype.h>
#include <errno.h>
#include <limits.h>
#include <math.h>
#include <poll.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include "io_internal.h"

/* ---- private types ------------------------------------------------------------------- */

typedef struct as_ctx {
    const ak_allocator* alloc;
    const ak_io_desc* desc;
    const char* path;
    ak_diag* diag;
    const struct aiScene* ai;
    const struct aiNode** nodes; /* depth-first */
    size_t node_count;
    int32_t* joint_of_node;
    ak_scene* scene;
    struct as_wbuf* clip_sink; /* in the child: each raw clip, serialised for the parent */
} as_ctx;

/* A growing byte buffer (the child's message to the parent). */
typedef struct as_wbuf {
    uint8_t* p;
    size_t n, cap;
    bool oom;
} as_wbuf;

static void wb_put(as_wbuf* b, const void* data, size_t size) {
    if (b->oom || size == 0) return;
    if (size > SIZE_MAX / 2 - b->n) {
        b->oom = true;
        return;
    }
    if (b->n + size > b->cap) {
        size_t cap = b->cap ? b->cap : 4096;
        while (cap < b->n + size) cap *= 2;
        uint8_t* q = (uint8_t*)realloc(b->p, cap);
        if (!q) {
            b->oom = true;
            return;
        }
        b->p = q;
        b->cap = cap;
    }
    memcpy(b->p + b->n, data, size);
    b->n += size;
}

static void wb_u64(as_wbuf* b, uint64_t v) { wb_put(b, &v, sizeof v); }

static void put_raw_clip(as_wbuf* b, const ak_raw_clip* raw) {
    char name[AK_NAME_SIZE];
    akp_io_copy_name(name, raw->name);
    wb_put(b, name, sizeof name);
    wb_put(b, &raw->duration, sizeof raw->duration);
    wb_u64(b, raw->channel_count);
    for (size_t i = 0; i < raw->channel_count; ++i) {
        const ak_raw_channel* ch = &raw->channels[i];
        uint32_t head[4] = {(uint32_t)ch->target, ch->index, ch->component_count, (uint32_t)ch->interp};
        wb_put(b, head, sizeof head);
        wb_u64(b, ch->key_count);
        wb_put(b, ch->times, ch->key_count * sizeof(float));
        wb_put(b, ch->values, ch->key_count * ch->component_count * sizeof(float));
    }
}

/* ---- static helpers ------------------------------------------------------------------ */

static ak_mat4 to_mat4(const struct aiMatrix4x4* m) {
    /* aiMatrix4x4 is row-major (a1..a4 the first row); ak_mat4 is column-major. */
    ak_mat4 r = {{m->a1, m->b1, m->c1, m->d1, m->a2, m->b2, m->c2, m->d2, m->a3, m->b3, m->c3, m->d3, m->a4, m->b4,
                  m->c4, m->d4}};
    return r;
}

static size_t count_nodes(const struct aiNode* n, unsigned depth) {
    if (!n || depth > 4096) return 0;
    size_t c = 1;
    for (unsigned i = 0; i < n->mNumChildren; ++i) c += count_nodes(n->mChildren[i], depth + 1);
    return c;
}

static void collect_nodes(as_ctx* c, const struct aiNode* n, int32_t parent, int32_t* parents, unsigned depth) {
    if (!n || depth > 4096 || c->node_count >= AKP_IO_MAX_NODES + 1) return;
    size_t me = c->node_count++;
    c->nodes[me] = n;
    parents[me] = parent;
    for (unsigned i = 0; i < n->mNumChildren; ++i) collect_nodes(c, n->mChildren[i], (int32_t)me, parents, depth + 1);
}

static int32_t find_node(const as_ctx* c, const struct aiString* name) {
    for (size_t i = 0; i < c->node_count; ++i)
        if (strcmp(c->nodes[i]->mName.data, name->data) == 0) return (int32_t)i;
    return -1;
}

static bool is_bvh(const char* path) {
    size_t n = strlen(path);
    return n >= 4 && path[n - 4] == '.' && tolower((unsigned char)path[n - 3]) == 'b' &&
           tolower((unsigned char)path[n - 2]) == 'v' && tolower((unsigned char)path[n - 1]) == 'h';
}

static ak_result build_skeleton(as_ctx* c) {
    size_t total = count_nodes(c->ai->mRootNode, 0);
    if (total > AKP_IO_MAX_NODES) {
        akp_diag_set(c->diag, c->path, "%zu nodes; at most %u are supported", total, AKP_IO_MAX_NODES);
        return AK_ERR_UNSUPPORTED;
    }
    c->nodes = (const struct aiNode**)akp_alloc(c->alloc, (total ? total : 1) * sizeof(*c->nodes));
    int32_t* parents = (int32_t*)akp_alloc(c->alloc, (total ? total : 1) * sizeof(int32_t));
    akp_io_node* desc = (akp_io_node*)akp_calloc(c->alloc, (total ? total : 1) * sizeof(akp_io_node));
    c->joint_of_node = (int32_t*)akp_alloc(c->alloc, (total ? total : 1) * sizeof(int32_t));
    ak_result r = AK_ERR_NO_MEMORY;
    if (!c->nodes || !parents || !desc || !c->joint_of_node) {
        akp_diag_set(c->diag, c->path, "out of memory");
        goto done;
    }
    collect_nodes(c, c->ai->mRootNode, -1, parents, 0);
    for (size_t i = 0; i < c->node_count; ++i) {
        ak_mat4 m = to_mat4(&c->nodes[i]->mTransformation);
        if (!ak_mat4_is_finite(&m)) {
            akp_diag_set(c->diag, c->path, "node '%.100s' has a non-finite transform", c->nodes[i]->mName.data);
            r = AK_ERR_BAD_DATA;
            goto done;
        }
        desc[i].name = c->nodes[i]->mName.data;
        desc[i].parent = parents[i];
        desc[i].rest = akp_io_decompose(m);
    }
    r = akp_io_build_skeleton(c->scene, desc, c->node_count, c->joint_of_node, c->path, c->diag);
done:
    akp_free(c->alloc, parents);
    akp_free(c->alloc, desc);
    return r;
}

static ak_result make_mesh(as_ctx* c, const struct aiMesh* am, size_t mi, ak_mesh** out) {
    size_t nv = am->mNumVertices, tris = 0;
    if (nv == 0 || nv > AKP_IO_MAX_ELEMENTS || !am->mVertices) {
        akp_diag_set(c->diag, c->path, "mesh %zu has %zu vertices", mi, nv);
        return nv ? AK_ERR_UNSUPPORTED : AK_ERR_EMPTY;
    }
    for (unsigned f = 0; f < am->mNumFaces; ++f) tris += am->mFaces[f].mNumIndices == 3;
    /* Influences: the most any vertex has (the clean-up keeps the largest max_influences). */
    uint32_t* per_vertex = NULL;
    uint32_t stride = 0;
    if (am->mNumBones) {
        per_vertex = (uint32_t*)akp_calloc(c->alloc, nv * sizeof(uint32_t));
        if (!per_vertex) goto oom;
        for (unsigned b = 0; b < am->mNumBones; ++b) {
            const struct aiBone* bone = am->mBones[b];
            for (unsigned w = 0; w < bone->mNumWeights; ++w) {
                unsigned v = bone->mWeights[w].mVertexId;
                if (v >= nv) {
                    akp_free(c->alloc, per_vertex);
                    akp_diag_set(c->diag, c->path, "mesh %zu bone '%.100s' weights vertex %u of %zu", mi,
                                 bone->mName.data, v, nv);
                    return AK_ERR_BAD_INDEX;
                }
                if (++per_vertex[v] > stride) stride = per_vertex[v];
            }
        }
    }
    ak_mesh_desc d = {
        .vertex_count = nv,
        .triangle_count = tris,
        .influence_count = stride ? (stride < c->desc->max_influences ? stride : c->desc->max_influences) : 0,
        .has_normals = am->mNormals != NULL,
        .has_uvs = am->mTextureCoords[0] != NULL,
        .has_colors = am->mColors[0] != NULL,
        .name = am->mName.data,
    };
    ak_mesh* m = NULL;
    ak_result r = ak_mesh_create(&d, c->alloc, &m);
    if (r != AK_OK) {
        akp_free(c->alloc, per_vertex);
        akp_diag_set(c->diag, c->path, "mesh %zu: cannot create a mesh of %zu vertices", mi, nv);
        return r;
    }
    for (size_t v = 0; v < nv; ++v) {
        const struct aiVector3D* p = &am->mVertices[v];
        m->positions[v] = ak_vec3_make(p->x, p->y, p->z);
        const char* bad = ak_vec3_is_finite(m->positions[v]) ? NULL : "position";
        if (am->mNormals) {
            m->normals[v] = ak_vec3_make(am->mNormals[v].x, am->mNormals[v].y, am->mNormals[v].z);
            if (!bad && !ak_vec3_is_finite(m->normals[v])) bad = "normal";
        }
        if (am->mTextureCoords[0]) {
            m->uvs[v] = ak_vec2_make(am->mTextureCoords[0][v].x, am->mTextureCoords[0][v].y);
            if (!bad && !(ak_finitef(m->uvs[v].x) && ak_finitef(m->uvs[v].y))) bad = "UV";
        }
        if (am->mColors[0]) {
            const struct aiColor4D* col = &am->mColors[0][v];
            m->colors[v] = ak_vec4_make(col->r, col->g, col->b, col->a);
            if (!bad && !(ak_finitef(col->r) && ak_finitef(col->g) && ak_finitef(col->b) && ak_finitef(col->a)))
                bad = "colour";
        }
        /* Like the glTF reader: a non-finite attribute (an OBJ "vn 0 0 1e39" overflows to
         * infinity) is bad data, not something to pass on to skinning or the writers. */
        if (bad && r == AK_OK) {
            akp_diag_set(c->diag, c->path, "mesh %zu vertex %zu: the %s is not finite", mi, v, bad);
            r = AK_ERR_BAD_DATA;
        }
    }
    size_t t = 0;
    for (unsigned f = 0; f < am->mNumFaces && r == AK_OK; ++f) {
        const struct aiFace* face = &am->mFaces[f];
        if (face->mNumIndices != 3) continue; /* points and lines carry no surface */
        for (int k = 0; k < 3; ++k) {
            if (face->mIndices[k] >= nv) {
                akp_diag_set(c->diag, c->path, "mesh %zu face %u uses vertex %u of %zu", mi, f, face->mIndices[k], nv);
                r = AK_ERR_BAD_INDEX;
            }
            m->indices[3 * t + (size_t)k] = face->mIndices[k];
        }
        ++t;
    }
    if (r == AK_OK && stride) {
        uint16_t* joints = (uint16_t*)akp_calloc(c->alloc, nv * stride * sizeof(uint16_t));
        float* weights = (float*)akp_calloc(c->alloc, nv * stride * sizeof(float));
        if (!joints || !weights || am->mNumBones > 65535) {
            akp_diag_set(c->diag, c->path, "mesh %zu: out of memory or more than 65535 bones", mi);
            r = joints && weights ? AK_ERR_UNSUPPORTED : AK_ERR_NO_MEMORY;
        } else {
            memset(per_vertex, 0, nv * sizeof(uint32_t));
            for (unsigned b = 0; b < am->mNumBones; ++b) {
                const struct aiBone* bone = am->mBones[b];
                for (unsigned w = 0; w < bone->mNumWeights; ++w) {
                    size_t v = bone->mWeights[w].mVertexId, o = v * stride + per_vertex[v]++;
                    joints[o] = (uint16_t)b;
                    weights[o] = bone->mWeights[w].mWeight;
                }
            }
            akp_io_store_weights(m, joints, weights, stride, c->desc);
        }
        akp_free(c->alloc, joints);
        akp_free(c->alloc, weights);
    }
    akp_free(c->alloc, per_vertex);
    if (r != AK_OK) {
        ak_mesh_destroy(m);
        return r;
    }
    *out = m;
    return AK_OK;
oom:
    akp_diag_set(c->diag, c->path, "out of memory");
    return AK_ERR_NO_MEMORY;
}

/* Keys of one Assimp key array: times in seconds, strictly increasing (later duplicates are
 * dropped), values of comps floats. Returns the kept key count. */
static size_t copy_keys(const double* key_times, size_t key_stride, size_t n, double tps, float* times) {
    size_t kept = 0;
    for (size_t k = 0; k < n; ++k) {
        double t = *(const double*)((const uint8_t*)key_times + k * key_stride);
        float s = (float)(t / tps);
        if (kept && !(s > times[kept - 1])) continue;
        times[kept++] = s;
    }
    return kept;
}

static ak_result build_clip(as_ctx* c, const struct aiAnimation* an, size_t ai) {
    /* A BVH's ticks per second is 1 / Frame Time: a zero or negative Frame Time gives an
     * infinite or negative rate, which would silently collapse or misplace every key. */
    if (!(an->mTicksPerSecond >= 0.0) || !isfinite(an->mTicksPerSecond)) {
        akp_diag_set(c->diag, c->path, "animation %zu: %g ticks per second (a BVH Frame Time must be positive)", ai,
                     an->mTicksPerSecond);
        return AK_ERR_BAD_DATA;
    }
    double tps = an->mTicksPerSecond > 0.0 ? an->mTicksPerSecond : 25.0; /* Assimp's documented default */
    double last_key = 0.0; /* the latest key time kept */
    size_t max_ch = (size_t)an->mNumChannels * 3;
    ak_raw_channel* ch = (ak_raw_channel*)akp_calloc(c->alloc, (max_ch ? max_ch : 1) * sizeof(ak_raw_channel));
    float** bufs = (float**)akp_calloc(c->alloc, (max_ch ? max_ch : 1) * 2 * sizeof(float*));
    size_t nch = 0, nbuf = 0;
    ak_result r = AK_OK;
    if (!ch || !bufs) {
        r = AK_ERR_NO_MEMORY;
        akp_diag_set(c->diag, c->path, "out of memory");
    }
    for (unsigned i = 0; r == AK_OK && i < an->mNumChannels; ++i) {
        const struct aiNodeAnim* na = an->mChannels[i];
        int32_t node = find_node(c, &na->mNodeName);
        if (node < 0) {
            akp_diag_set(c->diag, c->path, "animation %zu channel %u targets unknown node '%.100s'", ai, i,
                         na->mNodeName.data);
            r = AK_ERR_NOT_FOUND;
            break;
        }
        for (int kind = 0; kind < 3 && r == AK_OK; ++kind) {
            size_t n = kind == 0 ? na->mNumPositionKeys : kind == 1 ? na->mNumRotationKeys : na->mNumScalingKeys;
            if (n == 0) continue;
            if (n > AKP_IO_MAX_ELEMENTS) {
                r = AK_ERR_UNSUPPORTED;
                akp_diag_set(c->diag, c->path, "animation %zu channel %u has %zu keys", ai, i, n);
                break;
            }
            uint32_t comps = kind == 1 ? 4 : 3;
            float* times = (float*)akp_alloc(c->alloc, n * sizeof(float));
            float* vals = (float*)akp_alloc(c->alloc, n * comps * sizeof(float));
            bufs[nbuf++] = times;
            bufs[nbuf++] = vals;
            if (!times || !vals) {
                r = AK_ERR_NO_MEMORY;
                akp_diag_set(c->diag, c->path, "out of memory");
                break;
            }
            size_t kept = 0;
            if (kind == 1) {
                kept = copy_keys(&na->mRotationKeys[0].mTime, sizeof(struct aiQuatKey), n, tps, times);
                for (size_t k = 0, o = 0; k < n && o < kept; ++k) {
                    float t = (float)(na->mRotationKeys[k].mTime / tps);
                    if (t != times[o]) continue;
                    const struct aiQuaternion* q = &na->mRotationKeys[k].mValue;
                    float v[4] = {q->x, q->y, q->z, q->w};
                    memcpy(vals + 4 * o++, v, sizeof v);
                }
            } else {
                const struct aiVectorKey* keys = kind == 0 ? na->mPositionKeys : na->mScalingKeys;
                kept = copy_keys(&keys[0].mTime, sizeof(struct aiVectorKey), n, tps, times);
                for (size_t k = 0, o = 0; k < n && o < kept; ++k) {
                    float t = (float)(keys[k].mTime / tps);
                    if (t != times[o]) continue;
                    float v[3] = {keys[k].mValue.x, keys[k].mValue.y, keys[k].mValue.z};
                    memcpy(vals + 3 * o++, v, sizeof v);
                }
            }
            if (kept < n) {
                char msg[200];
                snprintf(msg, sizeof msg, "%s: animation %zu channel '%.60s': %zu keys at repeated times dropped",
                         c->path, ai, na->mNodeName.data, n - kept);
                akp_log(&c->desc->logger, AK_LOG_WARN, msg);
            }
            if (kept && times[kept - 1] > last_key) last_key = times[kept - 1];
            ak_raw_channel* rc = &ch[nch++];
            rc->target = kind == 0 ? AK_CHANNEL_TRANSLATION : kind == 1 ? AK_CHANNEL_ROTATION : AK_CHANNEL_SCALE;
            rc->index = (uint32_t)c->joint_of_node[node];
            rc->component_count = comps;
            rc->interp = AK_INTERP_LINEAR;
            rc->key_count = kept;
            rc->times = times;
            rc->values = vals;
        }
    }
    if (r == AK_OK && an->mNumMorphMeshChannels) {
        char msg[160];
        snprintf(msg, sizeof msg, "%s: animation %zu: morph channels are not imported through Assimp", c->path, ai);
        akp_log(&c->desc->logger, AK_LOG_WARN, msg);
    }
    if (r == AK_OK) {
        char name[AK_NAME_SIZE];
        if (an->mName.length) akp_io_copy_name(name, an->mName.data);
        else snprintf(name, sizeof name, "animation_%zu", ai);
        double dur = an->mDuration / tps;
        /* A BVH clip ends at its last frame, (Frames - 1) x Frame Time. Assimp computes its
         * duration as the unsigned Frames - 1, which wraps to 2^32 - 1 ticks for "Frames: 0". */
        if (is_bvh(c->path)) dur = last_key;
        ak_raw_clip raw = {
            .name = name,
            .duration = dur > 0.0 && dur < 1e30 ? (float)dur : 0.0f,
            .channels = ch,
            .channel_count = nch,
            .joint_count = ak_scene_joint_count(c->scene),
        };
        ak_diag sub;
        r = ak_clip_build(&raw, c->alloc, &c->scene->clips[ai], &sub);
        if (r != AK_OK) akp_diag_set(c->diag, c->path, "animation %zu: %s", ai, sub.message);
        else if (c->clip_sink) put_raw_clip(c->clip_sink, &raw);
    }
    for (size_t i = 0; i < nbuf; ++i) akp_free(c->alloc, bufs[i]);
    akp_free(c->alloc, bufs);
    akp_free(c->alloc, ch);
    return r;
}

static ak_result convert(as_ctx* c) {
    const struct aiScene* ai = c->ai;
    bool drop_meshes = is_bvh(c->path) && !c->desc->keep_bvh_mesh;
    ak_result r = AK_OK;
    /* Scene meshes: meshes in file order x instancing nodes (depth-first order). */
    size_t n_meshes = drop_meshes ? 0 : ai->mNumMeshes;
    size_t* inst = (size_t*)akp_calloc(c->alloc, (n_meshes ? n_meshes : 1) * sizeof(size_t));
    size_t* skin_of_mesh = (size_t*)akp_calloc(c->alloc, (n_meshes ? n_meshes : 1) * sizeof(size_t));
    if (!inst || !skin_of_mesh) {
        akp_free(c->alloc, inst);
        akp_free(c->alloc, skin_of_mesh);
        akp_diag_set(c->diag, c->path, "out of memory");
        return AK_ERR_NO_MEMORY;
    }
    /* A provisional scene holds the skeleton while node indices are gathered. */
    size_t clip_count = c->desc->skip_animations ? 0 : ai->mNumAnimations;
    r = ak_scene_alloc(0, 0, 0, c->alloc, &c->scene);
    if (r == AK_OK) {
        const char* base = strrchr(c->path, '/');
        akp_io_copy_name(c->scene->name, base ? base + 1 : c->path);
        r = build_skeleton(c);
    }
    size_t mesh_total = 0, skin_total = 0;
    for (size_t i = 0; r == AK_OK && i < c->node_count; ++i)
        for (unsigned k = 0; k < c->nodes[i]->mNumMeshes; ++k) {
            unsigned mi = c->nodes[i]->mMeshes[k];
            if (mi >= ai->mNumMeshes) {
                akp_diag_set(c->diag, c->path, "node '%.100s' refers to mesh %u of %u", c->nodes[i]->mName.data, mi,
                             ai->mNumMeshes);
                r = AK_ERR_BAD_INDEX;
            } else if (mi < n_meshes) {
                ++inst[mi];
            }
        }
    for (size_t m = 0; r == AK_OK && m < n_meshes; ++m) {
        mesh_total += inst[m] ? inst[m] : 1;
        skin_of_mesh[m] = ai->mMeshes[m]->mNumBones ? skin_total++ : (size_t)-1;
    }
    /* Re-home the skeleton in a scene with the final array sizes. */
    ak_scene* full = NULL;
    if (r == AK_OK) r = ak_scene_alloc(mesh_total, skin_total, clip_count, c->alloc, &full);
    if (r == AK_OK) {
        memcpy(full->name, c->scene->name, sizeof full->name);
        full->skeleton = c->scene->skeleton;
        c->scene->skeleton = NULL;
        ak_scene_destroy(c->scene);
        c->scene = full;
    } else if (r == AK_ERR_NO_MEMORY) {
        akp_diag_set(c->diag, c->path, "out of memory");
    }
    size_t out = 0;
    for (size_t m = 0; r == AK_OK && m < n_meshes; ++m) {
        const struct aiMesh* am = ai->mMeshes[m];
        if (skin_of_mesh[m] != (size_t)-1) {
            size_t s = skin_of_mesh[m];
            r = ak_scene_skin_alloc(c->scene, s, am->mNumBones);
            if (r != AK_OK) {
                akp_diag_set(c->diag, c->path, "out of memory");
                break;
            }
            ak_scene_skin* sk = &c->scene->skins[s];
            akp_io_copy_name(sk->name, am->mName.data);
            for (unsigned b = 0; b < am->mNumBones && r == AK_OK; ++b) {
                int32_t node = find_node(c, &am->mBones[b]->mName);
                if (node < 0) {
                    akp_diag_set(c->diag, c->path, "mesh %zu bone '%.100s' names no node", m, am->mBones[b]->mName.data);
                    r = AK_ERR_NOT_FOUND;
                    break;
                }
                sk->joints[b] = c->joint_of_node[node];
                sk->inverse_binds[b] = to_mat4(&am->mBones[b]->mOffsetMatrix);
                if (!ak_mat4_is_finite(&sk->inverse_binds[b])) {
                    akp_diag_set(c->diag, c->path, "bone '%.100s' has a non-finite offset matrix", am->mBones[b]->mName.data);
                    r = AK_ERR_BAD_DATA;
                }
            }
        }
        size_t first = out;
        for (size_t i = 0; r == AK_OK && i <= c->node_count; ++i) {
            bool uses = false;
            if (i < c->node_count) {
                for (unsigned k = 0; k < c->nodes[i]->mNumMeshes; ++k) uses = uses || c->nodes[i]->mMeshes[k] == m;
                if (!uses) continue;
            } else if (out > first) {
                break;
            }
            ak_scene_mesh* sm = &c->scene->meshes[out++];
            sm->node = i < c->node_count ? c->joint_of_node[i] : -1;
            sm->skin = skin_of_mesh[m] != (size_t)-1 ? (int32_t)skin_of_mesh[m] : -1;
            r = make_mesh(c, am, m, &sm->mesh);
        }
    }
    /* Joints are the nodes bones name; in a BVH file without a skin they are the nodes the
     * motion animates (ROOT and JOINT entries), so End Sites (leaf offsets) are not joints. */
    if (r == AK_OK && (skin_total || !is_bvh(c->path) || clip_count)) {
        size_t nj = ak_scene_joint_count(c->scene);
        c->scene->is_joint = (bool*)akp_calloc(&c->scene->alloc, (nj ? nj : 1) * sizeof(bool));
        if (!c->scene->is_joint) r = AK_ERR_NO_MEMORY;
        for (size_t s = 0; r == AK_OK && s < skin_total; ++s)
            for (size_t j = 0; j < c->scene->skins[s].joint_count; ++j) c->scene->is_joint[c->scene->skins[s].joints[j]] = true;
        for (size_t a = 0; r == AK_OK && !skin_total && is_bvh(c->path) && a < clip_count; ++a) {
            const struct aiAnimation* an = ai->mAnimations[a];
            for (unsigned i = 0; i < an->mNumChannels; ++i) {
                int32_t node = find_node(c, &an->mChannels[i]->mNodeName);
                if (node >= 0 && (size_t)node < c->node_count) c->scene->is_joint[c->joint_of_node[node]] = true;
            }
        }
    }
    for (size_t a = 0; r == AK_OK && a < clip_count; ++a) r = build_clip(c, ai->mAnimations[a], a);
    akp_free(c->alloc, inst);
    akp_free(c->alloc, skin_of_mesh);
    return r;
}

/* Cheap checks before Assimp sees a file: its size must fit the memory budget (times
 * AK_IO_BUDGET_INPUT_FACTOR, Assimp's own use is not bounded), and text formats with nesting
 * (XML: Collada, ...; braces: ASCII FBX, .x) must not nest deeper than AK_IO_ASSIMP_MAX_DEPTH,
 * since Assimp's readers recurse per level. One streaming pass; binary FBX is not scanned. */
static ak_result precheck(FILE* f, const char* path, const ak_io_desc* desc, ak_diag* diag) {
    long end = -1;
    if (fseek(f, 0, SEEK_END) == 0) end = ftell(f);
    if (end < 0 || fseek(f, 0, SEEK_SET) != 0) {
        akp_diag_set(diag, path, "cannot determine the file size (not a regular file?)");
        return AK_ERR_IO;
    }
    akp_budget b = akp_io_budget(desc, (size_t)end);
    if (!akp_budget_take(&b, (size_t)end, AK_IO_BUDGET_INPUT_FACTOR)) {
        akp_diag_set(diag, path, "%ld bytes: %u x the file size exceeds the memory budget of %zu bytes", end,
                     AK_IO_BUDGET_INPUT_FACTOR, b.limit);
        return AK_ERR_UNSUPPORTED;
    }
    static const char fbx_binary[] = "Kaydara FBX Binary";
    char buf[65536];
    size_t got, total = 0;
    long depth = 0, max_depth = 0;
    int prev = 0;
    bool in_string = false;
    while ((got = fread(buf, 1, sizeof buf, f)) > 0) {
        if (total == 0 && got >= sizeof fbx_binary - 1 && memcmp(buf, fbx_binary, sizeof fbx_binary - 1) == 0) break;
        for (size_t i = 0; i < got; ++i) {
            int ch = (unsigned char)buf[i];
            if (ch == '"') in_string = !in_string;
            else if (ch == '\n') in_string = false;
            if (in_string) {
                prev = ch;
                continue;
            }
            /* an element opens at '<' + name, closes at "</" or "/>"; a brace block at '{' */
            if (ch == '{' || (prev == '<' && (isalpha(ch) || ch == '_'))) ++depth;
            else if (ch == '}' || (prev == '<' && ch == '/') || (prev == '/' && ch == '>')) --depth;
            if (depth > max_depth) max_depth = depth;
            if (max_depth > (long)AK_IO_ASSIMP_MAX_DEPTH) {
                akp_diag_set(diag, path, "nested deeper than %u levels near byte %zu (AK_IO_ASSIMP_MAX_DEPTH)",
                             AK_IO_ASSIMP_MAX_DEPTH, total + i);
                return AK_ERR_UNSUPPORTED;
            }
            prev = ch;
        }
        total += got;
    }
    return AK_OK;
}

/* ---- the files Assimp may open ----------------------------------------------------------- */

/* Assimp opens the files a model names itself (an OBJ's "mtllib ../../x.mtl", ...) through its
 * default file system, anywhere. Every open goes through these callbacks instead: the model
 * file itself, or a regular file whose canonical path (symlinks resolved) lies inside the
 * model's directory or desc->extra_roots (anywhere with desc->allow_any_path), and whose size
 * fits the memory budget as the model's must (AK_IO_BUDGET_INPUT_FACTOR x its size; each file
 * alone, since Assimp opens some files more than once). A refused file is reported to Assimp
 * as missing (an OBJ then loads without its materials) and logged as a warning. */
typedef struct as_fs {
    const ak_io_desc* desc;
    const char* path;     /* the model, as given */
    char self[PATH_MAX];  /* its canonical path */
    char root[PATH_MAX];  /* its canonical directory */
    akp_budget budget;    /* the load's, nothing taken */
    char refused[PATH_MAX]; /* the last file refused (Assimp retries a name; warn once) */
} as_fs;

typedef struct as_file {
    FILE* f;
    size_t size;
} as_file;

static bool path_inside(const char* p, const char* root) {
    size_t n = strlen(root);
    if (n == 1 && root[0] == '/') return p[0] == '/';
    return strncmp(p, root, n) == 0 && (p[n] == '/' || p[n] == 0);
}

static size_t fs_read(struct aiFile* file, char* buf, size_t size, size_t count) {
    return fread(buf, size, count, ((as_file*)(void*)file->UserData)->f);
}

static size_t fs_write(struct aiFile* file, const char* buf, size_t size, size_t count) {
    (void)file, (void)buf, (void)size, (void)count;
    return 0;
}

static size_t fs_tell(struct aiFile* file) {
    long at = ftell(((as_file*)(void*)file->UserData)->f);
    return at < 0 ? 0 : (size_t)at;
}

static size_t fs_size(struct aiFile* file) { return ((as_file*)(void*)file->UserData)->size; }

static enum aiReturn fs_seek(struct aiFile* file, size_t offset, enum aiOrigin origin) {
    int whence = origin == aiOrigin_CUR ? SEEK_CUR : origin == aiOrigin_END ? SEEK_END : SEEK_SET;
    if (offset > LONG_MAX) return aiReturn_FAILURE;
    return fseek(((as_file*)(void*)file->UserData)->f, (long)offset, whence) == 0 ? aiReturn_SUCCESS
                                                                                 : aiReturn_FAILURE;
}

static void fs_flush(struct aiFile* file) { (void)file; }

static void fs_refuse(as_fs* fs, const char* real, const char* name, const char* why) {
    if (strcmp(real, fs->refused) == 0) return;
    snprintf(fs->refused, sizeof fs->refused, "%s", real);
    char msg[PATH_MAX + 200];
    snprintf(msg, sizeof msg, "%s: not opening '%.*s' for Assimp: %s", fs->path, PATH_MAX, name, why);
    akp_log(&fs->desc->logger, AK_LOG_WARN, msg);
}

static struct aiFile* fs_open(struct aiFileIO* io, const char* name, const char* mode) {
    as_fs* fs = (as_fs*)(void*)io->UserData;
    char real[PATH_MAX];
    struct stat st;
    if (!name || !mode || mode[0] != 'r' || !realpath(name, real) || stat(real, &st) != 0) return NULL;
    bool allowed = strcmp(real, fs->self) == 0 || fs->desc->allow_any_path || path_inside(real, fs->root);
    for (size_t i = 0; !allowed && fs->desc->extra_roots && i < fs->desc->extra_root_count; ++i) {
        char root[PATH_MAX];
        allowed = fs->desc->extra_roots[i] && realpath(fs->desc->extra_roots[i], root) && path_inside(real, root);
    }
    if (!allowed) {
        fs_refuse(fs, real, name, "outside the model's directory (ak_io_desc.extra_roots, allow_any_path)");
        return NULL;
    }
    if (!S_ISREG(st.st_mode)) {
        fs_refuse(fs, real, name, "not a regular file");
        return NULL;
    }
    akp_budget b = fs->budget;
    if (strcmp(real, fs->self) != 0 && !akp_budget_take(&b, (size_t)st.st_size, AK_IO_BUDGET_INPUT_FACTOR)) {
        fs_refuse(fs, real, name, "over the memory budget");
        return NULL;
    }
    struct aiFile* file = (struct aiFile*)calloc(1, sizeof *file);
    as_file* af = (as_file*)calloc(1, sizeof *af);
    FILE* f = fopen(real, "rb");
    if (!file || !af || !f) {
        if (f) fclose(f);
        free(af);
        free(file);
        return NULL;
    }
    af->f = f;
    af->size = (size_t)st.st_size;
    file->ReadProc = fs_read;
    file->WriteProc = fs_write;
    file->TellProc = fs_tell;
    file->FileSizeProc = fs_size;
    file->SeekProc = fs_seek;
    file->FlushProc = fs_flush;
    file->UserData = (aiUserData)(void*)af;
    return file;
}

static void fs_close(struct aiFileIO* io, struct aiFile* file) {
    (void)io;
    if (!file) return;
    as_file* af = (as_file*)(void*)file->UserData;
    if (af) fclose(af->f);
    free(af);
    free(file);
}

/* ---- the reader ------------------------------------------------------------------------ */

/* Assimp's import and the conversion, in the calling process (the child's work). */
static ak_result import_here(const char* path, const ak_io_desc* desc, const ak_allocator* alloc, as_wbuf* clip_sink,
                             ak_scene** out_scene, ak_diag* diag) {
    as_fs fs;
    memset(&fs, 0, sizeof fs);
    fs.desc = desc;
    fs.path = path;
    struct stat st;
    fs.budget = akp_io_budget(desc, stat(path, &st) == 0 && st.st_size > 0 ? (size_t)st.st_size : 0);
    char dir[PATH_MAX];
    const char* slash = strrchr(path, '/');
    snprintf(dir, sizeof dir, "%.*s", slash ? (int)(slash - path) + (slash == path) : 1, slash ? path : ".");
    if (!realpath(path, fs.self) || !realpath(dir, fs.root)) {
        akp_diag_set(diag, path, "cannot resolve the file's directory");
        return AK_ERR_IO;
    }
    struct aiFileIO io = {fs_open, fs_close, (aiUserData)(void*)&fs};
    const struct aiScene* ai = aiImportFileEx(path, aiProcess_Triangulate | aiProcess_ValidateDataStructure, &io);
    if (!ai) {
        akp_diag_set(diag, path, "Assimp: %s", aiGetErrorString());
        return AK_ERR_PARSE;
    }
    if (!ai->mRootNode) {
        aiReleaseImport(ai);
        akp_diag_set(diag, path, "Assimp returned a scene without nodes");
        return AK_ERR_PARSE;
    }
    as_ctx c;
    memset(&c, 0, sizeof c);
    c.alloc = alloc;
    c.desc = desc;
    c.path = path;
    c.diag = diag;
    c.ai = ai;
    c.clip_sink = clip_sink;
    ak_result r = convert(&c);
    aiReleaseImport(ai);
    akp_free(alloc, (void*)c.nodes);
    akp_free(alloc, c.joint_of_node);
    if (r != AK_OK) {
        ak_scene_destroy(c.scene);
        return r;
    }
    *out_scene = c.scene;
    return AK_OK;
}

/* ---- Assimp in a child process ------------------------------------------------------------
 * Assimp is not safe on untrusted files (5.2.5 dies of SIGSEGV on a four-line OBJ whose .mtl
 * has map_Kd before newmtl), so it runs in a forked child under resource limits: address
 * space (RLIMIT_AS, the memory budget plus AS_HEADROOM; not under the sanitizers, whose
 * shadow memory needs terabytes of address space), CPU time (RLIMIT_CPU,
 * AK_IO_ASSIMP_SECONDS), no file writes (RLIMIT_FSIZE 0), few descriptors (RLIMIT_NOFILE),
 * no core dumps; under valgrind neither the address-space nor the file-size limit (valgrind
 * needs the space and writes files of its own). The parent waits at most AK_IO_ASSIMP_SECONDS + AS_GRACE seconds of wall
 * time, then kills it. The child converts the scene as before and sends it back over a pipe
 * (warnings first, then the scene or the error); the parent checks every count and index
 * while it rebuilds the scene with its own allocator, so a child that went wrong cannot make
 * the parent read out of bounds. */

#define AS_MAGIC 0x53414b41u /* "AKAS" */
#define AS_HEADROOM ((size_t)768 << 20) /* the program's own mappings and Assimp's code */
#define AS_GRACE 5
enum { AS_REC_LOG = 1, AS_REC_ERROR = 2, AS_REC_SCENE = 3 };

#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__)
#define AS_SANITIZED 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer) || __has_feature(memory_sanitizer) || __has_feature(thread_sanitizer)
#define AS_SANITIZED 1
#endif
#endif
#ifndef AS_SANITIZED
#define AS_SANITIZED 0
#endif

static void write_all(int fd, const void* data, size_t size) {
    const uint8_t* p = (const uint8_t*)data;
    while (size > 0) {
        ssize_t w = write(fd, p, size);
        if (w < 0 && errno == EINTR) continue;
        if (w <= 0) _exit(3);
        p += w;
        size -= (size_t)w;
    }
}

static void put_record(int fd, uint8_t tag, const void* data, size_t size) {
    uint8_t head[9];
    uint64_t n = size;
    head[0] = tag;
    memcpy(head + 1, &n, sizeof n);
    write_all(fd, head, sizeof head);
    if (size) write_all(fd, data, size);
}

static void child_log(ak_log_level level, const char* message, void* user) {
    char buf[1024];
    buf[0] = (char)level;
    size_t n = strlen(message);
    if (n > sizeof buf - 2) n = sizeof buf - 2;
    memcpy(buf + 1, message, n);
    put_record(*(const int*)user, AS_REC_LOG, buf, n + 1);
}

static void put_scene(as_wbuf* b, const ak_scene* s, const as_wbuf* clips) {
    uint32_t magic = AS_MAGIC;
    wb_put(b, &magic, sizeof magic);
    wb_put(b, s->name, AK_NAME_SIZE);
    size_t nj = ak_scene_joint_count(s);
    uint64_t counts[4] = {nj, s->mesh_count, s->skin_count, s->clip_count};
    wb_put(b, counts, sizeof counts);
    uint8_t has_is_joint = s->is_joint != NULL;
    wb_put(b, &has_is_joint, 1);
    ak_i32_cspan parents = nj ? ak_skeleton_parents(s->skeleton) : (ak_i32_cspan){NULL, 0};
    ak_transform_cspan rest = nj ? ak_skeleton_rest_pose(s->skeleton) : (ak_transform_cspan){NULL, 0};
    ak_mat4_cspan ibind = nj ? ak_skeleton_inverse_binds(s->skeleton) : (ak_mat4_cspan){NULL, 0};
    for (size_t j = 0; j < nj; ++j) {
        char name[AK_NAME_SIZE];
        akp_io_copy_name(name, ak_skeleton_joint_name(s->skeleton, j));
        int32_t parent = parents.ptr[j];
        wb_put(b, name, sizeof name);
        wb_put(b, &parent, sizeof parent);
        wb_put(b, &rest.ptr[j], sizeof(ak_transform));
        wb_put(b, &ibind.ptr[j], sizeof(ak_mat4));
    }
    for (size_t j = 0; has_is_joint && j < nj; ++j) {
        uint8_t v = s->is_joint[j];
        wb_put(b, &v, 1);
    }
    for (size_t k = 0; k < s->skin_count; ++k) {
        const ak_scene_skin* sk = &s->skins[k];
        wb_put(b, sk->name, AK_NAME_SIZE);
        wb_u64(b, sk->joint_count);
        wb_put(b, sk->joints, sk->joint_count * sizeof(int32_t));
        wb_put(b, sk->inverse_binds, sk->joint_count * sizeof(ak_mat4));
    }
    for (size_t m = 0; m < s->mesh_count; ++m) {
        const ak_scene_mesh* sm = &s->meshes[m];
        const ak_mesh* me = sm->mesh;
        int32_t ns[2] = {sm->node, sm->skin};
        uint8_t flags[4] = {sm->has_material, me->normals != NULL, me->uvs != NULL, me->colors != NULL};
        uint64_t sizes[2] = {me->vertex_count, me->triangle_count};
        wb_put(b, ns, sizeof ns);
        wb_put(b, flags, sizeof flags);
        wb_put(b, &sm->base_color, sizeof sm->base_color);
        wb_put(b, me->name, AK_NAME_SIZE);
        wb_put(b, sizes, sizeof sizes);
        wb_put(b, &me->influence_count, sizeof me->influence_count);
        size_t v = me->vertex_count;
        wb_put(b, me->positions, v * sizeof(ak_vec3));
        if (me->normals) wb_put(b, me->normals, v * sizeof(ak_vec3));
        if (me->uvs) wb_put(b, me->uvs, v * sizeof(ak_vec2));
        if (me->colors) wb_put(b, me->colors, v * sizeof(ak_vec4));
        wb_put(b, me->indices, 3 * me->triangle_count * sizeof(uint32_t));
        wb_put(b, me->joints, v * me->influence_count * sizeof(uint16_t));
        wb_put(b, me->weights, v * me->influence_count * sizeof(float));
    }
    wb_put(b, clips->p, clips->n);
}

/* The child: limits, import, one message, _exit (no atexit handlers, no leak checks). */
static void child_main(int fd, const char* path, const ak_io_desc* desc, size_t memory) {
    /* Under valgrind (its preload library in LD_PRELOAD) the tool itself writes files (its
     * gdbserver's shared memory) and needs far more address space than the budget, as the
     * sanitizers do: no file-size and address-space limits then. */
    const char* preload = getenv("LD_PRELOAD");
    const bool under_valgrind = preload && strstr(preload, "vgpreload") != NULL;
    struct rlimit lim;
    lim.rlim_cur = lim.rlim_max = 0;
    setrlimit(RLIMIT_CORE, &lim);
    if (!under_valgrind) setrlimit(RLIMIT_FSIZE, &lim);
    lim.rlim_cur = lim.rlim_max = AK_IO_ASSIMP_SECONDS;
    setrlimit(RLIMIT_CPU, &lim);
    lim.rlim_cur = lim.rlim_max = 64;
    setrlimit(RLIMIT_NOFILE, &lim);
    if (!AS_SANITIZED && !under_valgrind) {
        lim.rlim_cur = lim.rlim_max = (rlim_t)memory;
        setrlimit(RLIMIT_AS, &lim);
    }
    signal(SIGPIPE, SIG_DFL);
    const char* hook = getenv("AK_IO_TEST_ASSIMP_CHILD"); /* tests only: fake a crash or a hang */
    if (hook && strcmp(hook, "segv") == 0) raise(SIGSEGV);
    if (hook && strcmp(hook, "hang") == 0)
        for (volatile unsigned long i = 0;; i = i + 1) {
        }
    ak_io_desc d = *desc;
    int log_fd = fd;
    if (desc->logger.func) d.logger = (ak_logger){child_log, &log_fd};
    as_wbuf clips = {0}, out = {0};
    ak_scene* scene = NULL;
    ak_diag diag;
    memset(&diag, 0, sizeof diag);
    ak_result r = import_here(path, &d, NULL, &clips, &scene, &diag);
    if (r == AK_OK) {
        put_scene(&out, scene, &clips);
        if (out.oom || clips.oom) {
            r = AK_ERR_NO_MEMORY;
            akp_diag_set(&diag, path, "out of memory sending the scene to the parent process");
        }
    }
    if (r == AK_OK) {
        put_record(fd, AS_REC_SCENE, out.p, out.n);
    } else {
        int32_t code = (int32_t)r;
        uint8_t msg[sizeof code + sizeof diag];
        memcpy(msg, &code, sizeof code);
        memcpy(msg + sizeof code, &diag, sizeof diag);
        put_record(fd, AS_REC_ERROR, msg, sizeof msg);
    }
    _exit(0);
}

/* ---- the parent: reading the child's message back ---------------------------------------- */

typedef struct as_rbuf {
    const uint8_t* p;
    size_t n, at;
    bool bad;
} as_rbuf;

static bool rb_get(as_rbuf* b, void* out, size_t size) {
    if (size == 0) return !b->bad; /* out may be NULL then (an empty array) */
    if (b->bad || size > b->n - b->at) {
        b->bad = true;
        memset(out, 0, size);
        return false;
    }
    memcpy(out, b->p + b->at, size);
    b->at += size;
    return true;
}

/* Room for count elements of size bytes left in the message? */
static bool rb_has(as_rbuf* b, uint64_t count, size_t size) {
    if (b->bad || (size && count > (b->n - b->at) / size)) b->bad = true;
    return !b->bad;
}

static void rb_name(as_rbuf* b, char name[AK_NAME_SIZE]) {
    rb_get(b, name, AK_NAME_SIZE);
    name[AK_NAME_SIZE - 1] = 0;
}

static ak_result read_clip(as_rbuf* b, ak_scene* s, size_t index, size_t joint_count, const ak_allocator* alloc,
                           ak_diag* diag, const char* path) {
    char name[AK_NAME_SIZE];
    float duration = 0.0f;
    uint64_t nch = 0;
    rb_name(b, name);
    rb_get(b, &duration, sizeof duration);
    rb_get(b, &nch, sizeof nch);
    if (!rb_has(b, nch, 4 * sizeof(uint32_t) + sizeof(uint64_t))) return AK_ERR_PARSE;
    ak_raw_channel* ch = (ak_raw_channel*)akp_calloc(alloc, (nch ? nch : 1) * sizeof(ak_raw_channel));
    if (!ch) return AK_ERR_NO_MEMORY;
    ak_result r = AK_OK;
    size_t done = 0;
    for (; done < nch && r == AK_OK; ++done) {
        uint32_t head[4];
        uint64_t keys = 0;
        rb_get(b, head, sizeof head);
        rb_get(b, &keys, sizeof keys);
        if (head[2] == 0 || head[2] > AK_TRACK_MAX_COMPONENTS || !rb_has(b, keys, sizeof(float) * (1 + head[2]))) {
            r = AK_ERR_PARSE;
            break;
        }
        float* times = (float*)akp_alloc(alloc, (keys ? keys : 1) * sizeof(float));
        float* values = (float*)akp_alloc(alloc, (keys ? keys : 1) * head[2] * sizeof(float));
        ch[done] = (ak_raw_channel){.target = (ak_channel_target)head[0], .index = head[1], .component_count = head[2],
                                    .interp = (ak_interp)head[3], .key_count = keys, .times = times, .values = values};
        if (!times || !values) {
            r = AK_ERR_NO_MEMORY;
            ++done;
            break;
        }
        rb_get(b, times, keys * sizeof(float));
        rb_get(b, values, keys * head[2] * sizeof(float));
    }
    if (r == AK_OK) {
        ak_raw_clip raw = {.name = name, .duration = duration, .channels = ch, .channel_count = nch,
                           .joint_count = joint_count};
        ak_diag sub;
        r = ak_clip_build(&raw, alloc, &s->clips[index], &sub);
        if (r != AK_OK) akp_diag_set(diag, path, "animation %zu: %s", index, sub.message);
    }
    for (size_t i = 0; i < done; ++i) {
        akp_free(alloc, (void*)ch[i].times);
        akp_free(alloc, (void*)ch[i].values);
    }
    akp_free(alloc, ch);
    return r;
}

static ak_result read_scene(as_rbuf* b, const char* path, const ak_allocator* alloc, ak_scene** out_scene,
                            ak_diag* diag) {
    uint32_t magic = 0;
    uint64_t counts[4] = {0, 0, 0, 0};
    char name[AK_NAME_SIZE];
    uint8_t has_is_joint = 0;
    rb_get(b, &magic, sizeof magic);
    rb_name(b, name);
    rb_get(b, counts, sizeof counts);
    rb_get(b, &has_is_joint, 1);
    const size_t joint_rec = AK_NAME_SIZE + sizeof(int32_t) + sizeof(ak_transform) + sizeof(ak_mat4);
    if (magic != AS_MAGIC || counts[0] > AKP_IO_MAX_NODES || !rb_has(b, counts[0], joint_rec) ||
        !rb_has(b, counts[1], 8) || !rb_has(b, counts[2], 8) || !rb_has(b, counts[3], 8)) {
        akp_diag_set(diag, path, "the Assimp process sent a malformed scene");
        return AK_ERR_IO;
    }
    size_t nj = counts[0];
    ak_scene* s = NULL;
    ak_result r = ak_scene_alloc(counts[1], counts[2], counts[3], alloc, &s);
    if (r != AK_OK) {
        akp_diag_set(diag, path, "out of memory");
        return r;
    }
    memcpy(s->name, name, sizeof name);
    ak_joint_desc* joints = (ak_joint_desc*)akp_calloc(alloc, (nj ? nj : 1) * sizeof(ak_joint_desc));
    char(*names)[AK_NAME_SIZE] = (char(*)[AK_NAME_SIZE])akp_alloc(alloc, (nj ? nj : 1) * AK_NAME_SIZE);
    ak_mat4* ibind = (ak_mat4*)akp_alloc(alloc, (nj ? nj : 1) * sizeof(ak_mat4));
    if (!joints || !names || !ibind) r = AK_ERR_NO_MEMORY;
    for (size_t j = 0; r == AK_OK && j < nj; ++j) {
        int32_t parent = 0;
        rb_name(b, names[j]);
        rb_get(b, &parent, sizeof parent);
        rb_get(b, &joints[j].rest, sizeof(ak_transform));
        rb_get(b, &ibind[j], sizeof(ak_mat4));
        joints[j].name = names[j];
        joints[j].parent = parent;
        joints[j].inverse_bind = &ibind[j];
    }
    if (r == AK_OK && nj) {
        ak_skeleton_desc sd = {.joints = joints, .joint_count = nj, .name = s->name, .palette_from_skins = true};
        ak_diag sub;
        r = ak_skeleton_create(&sd, alloc, &s->skeleton, &sub);
        if (r != AK_OK) akp_diag_set(diag, path, "skeleton from the Assimp process: %.400s", sub.message);
    }
    akp_free(alloc, joints);
    akp_free(alloc, names);
    akp_free(alloc, ibind);
    if (r == AK_OK && has_is_joint) {
        s->is_joint = (bool*)akp_calloc(alloc, (nj ? nj : 1) * sizeof(bool));
        if (!s->is_joint) r = AK_ERR_NO_MEMORY;
        for (size_t j = 0; r == AK_OK && j < nj; ++j) {
            uint8_t v = 0;
            rb_get(b, &v, 1);
            s->is_joint[j] = v != 0;
        }
    }
    for (size_t k = 0; r == AK_OK && k < s->skin_count; ++k) {
        char sk_name[AK_NAME_SIZE];
        uint64_t jc = 0;
        rb_name(b, sk_name);
        rb_get(b, &jc, sizeof jc);
        if (!rb_has(b, jc, sizeof(int32_t) + sizeof(ak_mat4)) || jc == 0) break;
        r = ak_scene_skin_alloc(s, k, jc);
        if (r != AK_OK) break;
        ak_scene_skin* sk = &s->skins[k];
        memcpy(sk->name, sk_name, sizeof sk_name);
        rb_get(b, sk->joints, jc * sizeof(int32_t));
        rb_get(b, sk->inverse_binds, jc * sizeof(ak_mat4));
        for (size_t i = 0; i < jc; ++i)
            if (sk->joints[i] < 0 || (size_t)sk->joints[i] >= nj) b->bad = true;
    }
    for (size_t m = 0; r == AK_OK && !b->bad && m < s->mesh_count; ++m) {
        ak_scene_mesh* sm = &s->meshes[m];
        int32_t ns[2];
        uint8_t flags[4];
        uint64_t sizes[2];
        uint32_t infl = 0;
        char me_name[AK_NAME_SIZE];
        rb_get(b, ns, sizeof ns);
        rb_get(b, flags, sizeof flags);
        rb_get(b, &sm->base_color, sizeof sm->base_color);
        rb_name(b, me_name);
        rb_get(b, sizes, sizeof sizes);
        rb_get(b, &infl, sizeof infl);
        size_t per_vertex = sizeof(ak_vec3) * (1 + (flags[1] != 0)) + (flags[2] ? sizeof(ak_vec2) : 0) +
                            (flags[3] ? sizeof(ak_vec4) : 0) + (size_t)infl * (sizeof(uint16_t) + sizeof(float));
        if (ns[0] < -1 || ns[0] >= (int64_t)nj || ns[1] < -1 || ns[1] >= (int64_t)s->skin_count ||
            infl > AK_MAX_INFLUENCES || (infl && ns[1] < 0) || sizes[0] == 0 || !rb_has(b, sizes[0], per_vertex) ||
            !rb_has(b, sizes[1], 3 * sizeof(uint32_t))) {
            b->bad = true;
            break;
        }
        sm->node = ns[0];
        sm->skin = ns[1];
        sm->has_material = flags[0] != 0;
        ak_mesh_desc d = {.vertex_count = sizes[0], .triangle_count = sizes[1], .influence_count = infl,
                          .has_normals = flags[1], .has_uvs = flags[2], .has_colors = flags[3], .name = me_name};
        r = ak_mesh_create(&d, alloc, &sm->mesh);
        if (r != AK_OK) break;
        ak_mesh* me = sm->mesh;
        size_t v = me->vertex_count;
        rb_get(b, me->positions, v * sizeof(ak_vec3));
        if (me->normals) rb_get(b, me->normals, v * sizeof(ak_vec3));
        if (me->uvs) rb_get(b, me->uvs, v * sizeof(ak_vec2));
        if (me->colors) rb_get(b, me->colors, v * sizeof(ak_vec4));
        rb_get(b, me->indices, 3 * me->triangle_count * sizeof(uint32_t));
        rb_get(b, me->joints, v * infl * sizeof(uint16_t));
        rb_get(b, me->weights, v * infl * sizeof(float));
        if (!b->bad && ak_mesh_validate(me, NULL) != AK_OK) b->bad = true;
        size_t slots = ns[1] >= 0 ? s->skins[ns[1]].joint_count : 0;
        for (size_t i = 0; !b->bad && i < v * infl; ++i)
            if (me->joints[i] >= slots) b->bad = true;
    }
    for (size_t a = 0; r == AK_OK && !b->bad && a < s->clip_count; ++a) {
        r = read_clip(b, s, a, nj, alloc, diag, path);
        if (r == AK_ERR_PARSE) b->bad = true, r = AK_OK;
    }
    if (r == AK_OK && (b->bad || b->at != b->n)) {
        akp_diag_set(diag, path, "the Assimp process sent a malformed scene");
        r = AK_ERR_IO;
    } else if (r == AK_ERR_NO_MEMORY) {
        akp_diag_set(diag, path, "out of memory");
    }
    if (r != AK_OK) {
        ak_scene_destroy(s);
        return r;
    }
    *out_scene = s;
    return AK_OK;
}

static double now_seconds(void) {
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

ak_result akp_io_load_assimp(const char* path, const ak_io_desc* desc, const ak_allocator* alloc,
                             ak_scene** out_scene, ak_diag* diag) {
    FILE* f = fopen(path, "rb");
    if (!f) {
        akp_diag_set(diag, path, "cannot open file");
        return AK_ERR_IO;
    }
    ak_result pr = precheck(f, path, desc, diag);
    fclose(f);
    if (pr != AK_OK) return pr;
    struct stat st;
    akp_budget budget = akp_io_budget(desc, stat(path, &st) == 0 && st.st_size > 0 ? (size_t)st.st_size : 0);
    size_t memory = budget.limit > SIZE_MAX / 4 ? SIZE_MAX / 2 : 2 * budget.limit + AS_HEADROOM;
    const char* hook = getenv("AK_IO_TEST_ASSIMP_CHILD");
    double limit = hook && strcmp(hook, "hang") == 0 ? 1.0 : (double)(AK_IO_ASSIMP_SECONDS + AS_GRACE);
    int fds[2];
    if (pipe(fds) != 0) {
        akp_diag_set(diag, path, "cannot create a pipe for the Assimp process");
        return AK_ERR_IO;
    }
    fflush(NULL); /* the child must not write the parent's buffered output a second time */
    pid_t pid = fork();
    if (pid < 0) {
        close(fds[0]);
        close(fds[1]);
        akp_diag_set(diag, path, "cannot start the Assimp process");
        return AK_ERR_IO;
    }
    if (pid == 0) {
        close(fds[0]);
        child_main(fds[1], path, desc, memory);
    }
    close(fds[1]);
    /* read everything the child sends, within the wall-clock limit and the memory budget */
    as_wbuf msg = {0};
    const double deadline = now_seconds() + limit;
    bool timed_out = false, too_big = false;
    for (;;) {
        double left = deadline - now_seconds();
        if (left <= 0.0) {
            timed_out = true;
            break;
        }
        struct pollfd pfd = {fds[0], POLLIN, 0};
        int pr2 = poll(&pfd, 1, (int)(left * 1000.0) + 1);
        if (pr2 < 0 && errno == EINTR) continue;
        if (pr2 == 0) continue;
        uint8_t buf[65536];
        ssize_t got = read(fds[0], buf, sizeof buf);
        if (got < 0 && errno == EINTR) continue;
        if (got <= 0) break;
        if (msg.n + (size_t)got > budget.limit) {
            too_big = true;
            break;
        }
        wb_put(&msg, buf, (size_t)got);
        if (msg.oom) break;
    }
    close(fds[0]);
    if (timed_out || too_big || msg.oom) kill(pid, SIGKILL);
    int status = 0;
    while (waitpid(pid, &status, 0) < 0 && errno == EINTR) {
    }
    ak_result r = AK_OK;
    if (timed_out || (WIFSIGNALED(status) && WTERMSIG(status) == SIGXCPU)) {
        akp_diag_set(diag, path, "Assimp ran out of its time limit (%d s, AK_IO_ASSIMP_SECONDS) reading %s",
                     AK_IO_ASSIMP_SECONDS, path);
        r = AK_ERR_IO;
    } else if (too_big || msg.oom) {
        akp_diag_set(diag, path, "the scene Assimp read from %s exceeds the memory budget of %zu bytes", path,
                     budget.limit);
        r = AK_ERR_UNSUPPORTED;
    } else if (WIFSIGNALED(status)) {
        akp_diag_set(diag, path, "Assimp crashed reading %s (signal %d%s)", path, WTERMSIG(status),
                     AS_SANITIZED ? "" : "; or it ran out of its memory limit");
        r = AK_ERR_IO;
    }
    /* the records: log lines (passed on in order), then the scene or the error */
    as_rbuf rb = {msg.p, msg.n, 0, false};
    bool answered = false;
    while (r == AK_OK && rb.at < rb.n && !answered) {
        uint8_t tag = 0;
        uint64_t len = 0;
        rb_get(&rb, &tag, 1);
        rb_get(&rb, &len, sizeof len);
        if (rb.bad || len > rb.n - rb.at) break;
        as_rbuf rec = {rb.p + rb.at, (size_t)len, 0, false};
        rb.at += (size_t)len;
        if (tag == AS_REC_LOG && len >= 1) {
            char line[1024];
            size_t n = len - 1 < sizeof line - 1 ? (size_t)len - 1 : sizeof line - 1;
            memcpy(line, rec.p + 1, n);
            line[n] = 0;
            akp_io_sanitize(line, sizeof line);
            akp_log(&desc->logger, (ak_log_level)rec.p[0] <= AK_LOG_ERROR ? (ak_log_level)rec.p[0] : AK_LOG_WARN, line);
        } else if (tag == AS_REC_ERROR && len == sizeof(int32_t) + sizeof(ak_diag)) {
            int32_t code = 0;
            ak_diag d;
            rb_get(&rec, &code, sizeof code);
            rb_get(&rec, &d, sizeof d);
            d.path[sizeof d.path - 1] = 0;
            d.message[sizeof d.message - 1] = 0;
            akp_io_sanitize(d.path, sizeof d.path);
            akp_io_sanitize(d.message, sizeof d.message);
            if (diag) *diag = d;
            r = code > 0 && code < (int32_t)AK_RESULT_COUNT ? (ak_result)code : AK_ERR_IO;
            answered = true;
        } else if (tag == AS_REC_SCENE) {
            r = read_scene(&rec, path, alloc, out_scene, diag);
            answered = true;
        } else {
            break;
        }
    }
    if (r == AK_OK && !answered) {
        akp_diag_set(diag, path, "the Assimp process ended without an answer reading %s (exit status %d)", path,
                     WIFEXITED(status) ? WEXITSTATUS(status) : -1);
        r = AK_ERR_IO;
    }
    free(msg.p);
    return r;
}

/* io: format dispatch, file reading and the pieces both readers share (skeleton building,
 * matrix decomposition, skin weight clean-up). The readers are in src/io/. */
#ifndef _XOPEN_SOURCE
#define _XOPEN_SOURCE 700 /* realpath */
#endif
#include "io/io_internal.h"

#include <ctype.h>
#include <errno.h>
#include <fcntl.h>
#include <limits.h>
#include <stdlib.h>
#include <sys/stat.h>
#include <unistd.h>

/* ---- static helpers ------------------------------------------------------------------ */

static uint32_t name_hash(const char* s) {
    uint32_t h = 2166136261u; /* FNV-1a */
    for (; *s; ++s) h = (h ^ (uint8_t)*s) * 16777619u;
    return h;
}

/* Open-addressing set of names (indices into a names array). */
typedef struct name_set {
    int32_t* slots; /* -1 empty */
    size_t mask;
    char (*names)[AK_NAME_SIZE];
} name_set;

static bool name_set_has(const name_set* s, const char* name) {
    for (size_t i = name_hash(name) & s->mask;; i = (i + 1) & s->mask) {
        if (s->slots[i] < 0) return false;
        if (strcmp(s->names[s->slots[i]], name) == 0) return true;
    }
}

static void name_set_add(name_set* s, int32_t index) {
    size_t i = name_hash(s->names[index]) & s->mask;
    while (s->slots[i] >= 0) i = (i + 1) & s->mask;
    s->slots[i] = index;
}

static bool has_extension(const char* path, const char* ext) {
    size_t n = strlen(path), e = strlen(ext);
    if (n < e) return false;
    for (size_t i = 0; i < e; ++i)
        if (tolower((unsigned char)path[n - e + i]) != ext[i]) return false;
    return true;
}

/* Is the canonical path p inside (or equal to) the canonical directory root? */
static bool path_inside(const char* p, const char* root) {
    size_t n = strlen(root);
    if (n == 1 && root[0] == '/') return p[0] == '/';
    return strncmp(p, root, n) == 0 && (p[n] == '/' || p[n] == 0);
}

/* Is p a proper ancestor directory of root (so it exists and is no symlink)? */
static bool path_above(const char* p, const char* root) {
    size_t n = strlen(p);
    if (n == 1 && p[0] == '/') return root[1] != 0;
    return strncmp(root, p, n) == 0 && root[n] == '/';
}

/* Does dir (canonical) followed by the components of rest, ".." taken lexically, end
 * outside every root? */
static bool lexically_leaves(const char* dir, const char* rest, const char (*roots)[PATH_MAX], size_t root_count) {
    char p[PATH_MAX];
    snprintf(p, sizeof p, "%s", dir);
    for (const char* r = rest; *r;) {
        while (*r == '/') ++r;
        const char* e = r;
        while (*e && *e != '/') ++e;
        size_t len = (size_t)(e - r), pl = strlen(p);
        if (len == 2 && r[0] == '.' && r[1] == '.') {
            char* slash = strrchr(p, '/');
            if (slash == p) p[1] = 0;
            else if (slash) *slash = 0;
        } else if (len > 0 && !(len == 1 && r[0] == '.')) {
            if (pl + 1 + len >= sizeof p) return false;
            if (pl != 1) p[pl++] = '/';
            memcpy(p + pl, r, len);
            p[pl + len] = 0;
        }
        r = e;
    }
    for (size_t i = 0; i < root_count; ++i)
        if (path_inside(p, roots[i])) return false;
    return true;
}

/* ---- shared internals ---------------------------------------------------------------- */

ak_result akp_io_resolve_inside(const char* base_dir, const char* path, const ak_io_desc* desc, char* out,
                                size_t out_size, bool* out_leaves) {
    *out_leaves = false;
    if (out_size) out[0] = 0;
    size_t n_roots = 1 + (desc->extra_roots ? desc->extra_root_count : 0);
    if (n_roots > 64) n_roots = 64;
    char(*roots)[PATH_MAX] = (char(*)[PATH_MAX])malloc(n_roots * PATH_MAX);
    char* rest = (char*)malloc(2 * PATH_MAX);
    char* cur = (char*)malloc(PATH_MAX);
    char* link = (char*)malloc(PATH_MAX);
    ak_result r = AK_ERR_IO;
    if (!roots || !rest || !cur || !link) goto done;
    size_t have = 0;
    if (realpath(base_dir && base_dir[0] ? base_dir : ".", roots[0])) have = 1;
    for (size_t i = 1; i < n_roots; ++i)
        if (desc->extra_roots[i - 1] && realpath(desc->extra_roots[i - 1], roots[have])) ++have;
    if (have == 0 || strlen(path) >= PATH_MAX) goto done;
    if (desc->allow_any_path) { /* anywhere: the ordinary resolution */
        snprintf(rest, 2 * PATH_MAX, "%s%s%s", path[0] == '/' ? "" : base_dir && base_dir[0] ? base_dir : ".",
                 path[0] == '/' ? "" : "/", path);
        if (realpath(rest, cur) && strlen(cur) < out_size) {
            snprintf(out, out_size, "%s", cur);
            r = AK_OK;
        }
        goto done;
    }
    snprintf(cur, PATH_MAX, "%s", path[0] == '/' ? "/" : roots[0]);
    snprintf(rest, 2 * PATH_MAX, "%s", path);
    unsigned links = 0;
    for (;;) {
        char* p = rest;
        while (*p == '/') ++p;
        if (!*p) break;
        char* e = strchr(p, '/');
        size_t len = e ? (size_t)(e - p) : strlen(p);
        char comp[NAME_MAX + 1];
        if (len > NAME_MAX) goto done;
        memcpy(comp, p, len);
        comp[len] = 0;
        memmove(rest, p + len, strlen(p + len) + 1);
        if (strcmp(comp, ".") == 0) continue;
        if (strcmp(comp, "..") == 0) { /* cur is canonical: its parent is lexical */
            char* slash = strrchr(cur, '/');
            if (slash == cur) cur[1] = 0;
            else if (slash) *slash = 0;
            continue;
        }
        size_t cl = strlen(cur);
        if (cl + 1 + len >= PATH_MAX) goto done;
        char* cand = link; /* reuse: cand is consumed before link is read into */
        memcpy(cand, cur, cl);
        if (cl != 1) cand[cl++] = '/';
        memcpy(cand + cl, comp, len + 1);
        bool inside = false, above = false;
        for (size_t i = 0; i < have; ++i) {
            inside = inside || path_inside(cand, roots[i]);
            above = above || path_above(cand, roots[i]);
        }
        if (!inside && !above) {
            *out_leaves = true;
            goto done;
        }
        struct stat st;
        if (above || lstat(cand, &st) != 0) {
            if (!above) { /* missing, inside the folder; "missing/../../x" still leaves it */
                *out_leaves = lexically_leaves(cand, rest, (const char(*)[PATH_MAX])roots, have);
                goto done;
            }
            snprintf(cur, PATH_MAX, "%s", cand);
            continue;
        }
        if (S_ISLNK(st.st_mode)) {
            char target[PATH_MAX];
            if (++links > 40) goto done;
            ssize_t tl = readlink(cand, target, sizeof target - 1);
            if (tl <= 0) goto done;
            target[tl] = 0;
            if (strlen(rest) + (size_t)tl + 2 >= 2 * PATH_MAX) goto done;
            memmove(rest + tl + 1, rest, strlen(rest) + 1);
            memcpy(rest, target, (size_t)tl);
            rest[tl] = '/';
            if (target[0] == '/') snprintf(cur, PATH_MAX, "/");
            continue;
        }
        snprintf(cur, PATH_MAX, "%s", cand);
        const char* more = rest;
        while (*more == '/') ++more;
        if (*more && !S_ISDIR(st.st_mode)) goto done;
    }
    bool inside = false;
    for (size_t i = 0; i < have; ++i) inside = inside || path_inside(cur, roots[i]);
    if (!inside) {
        *out_leaves = true;
        goto done;
    }
    if (strlen(cur) >= out_size) goto done;
    snprintf(out, out_size, "%s", cur);
    r = AK_OK;
done:
    free(roots);
    free(rest);
    free(cur);
    free(link);
    return r;
}

bool akp_io_utf8_valid(const char* s, size_t n) {
    const unsigned char* u = (const unsigned char*)s;
    for (size_t i = 0; i < n;) {
        size_t l = ak_utf8_char(u + i, n - i);
        if (l == 0) return false;
        i += l;
    }
    return true;
}

void akp_io_sanitize(char* msg, size_t size) {
    if (!msg || size == 0) return;
    char tmp[2048];
    size_t n = strlen(msg), o = 0;
    bool changed = false;
    for (size_t i = 0; i < n && o + 1 < sizeof tmp;) {
        const unsigned char c = (unsigned char)msg[i];
        size_t l = c < 0x20 || c == 0x7F ? 0 : ak_utf8_char(msg + i, n - i);
        if (l == 0) {
            if (o + 5 >= sizeof tmp) break;
            snprintf(tmp + o, 5, "\\x%02X", c);
            o += 4;
            ++i;
            changed = true;
        } else {
            if (o + l >= sizeof tmp) break;
            memcpy(tmp + o, msg + i, l);
            o += l;
            i += l;
        }
    }
    if (!changed) return;
    tmp[o] = 0;
    /* truncate on a character boundary */
    size_t keep = o < size - 1 ? o : size - 1;
    while (keep > 0 && keep < o && ((unsigned char)tmp[keep] & 0xC0) == 0x80) --keep;
    memcpy(msg, tmp, keep);
    msg[keep] = 0;
}

void akp_io_copy_name(char dst[AK_NAME_SIZE], const char* src) {
    snprintf(dst, AK_NAME_SIZE, "%s", src ? src : "");
    size_t n = strlen(dst);
    if (src && n == AK_NAME_SIZE - 1 && ((unsigned char)src[n] & 0xC0) == 0x80) { /* cut inside a character */
        while (n > 0 && ((unsigned char)src[n] & 0xC0) == 0x80) --n;
        dst[n] = 0;
    }
}

akp_budget akp_io_budget(const ak_io_desc* desc, size_t input_size) {
    akp_budget b = {desc ? desc->memory_budget : 0, 0};
    if (b.limit == 0) {
        b.limit = AK_IO_DEFAULT_BUDGET;
        if (input_size <= SIZE_MAX / AK_IO_BUDGET_INPUT_FACTOR && input_size * AK_IO_BUDGET_INPUT_FACTOR > b.limit)
            b.limit = input_size * AK_IO_BUDGET_INPUT_FACTOR;
        else if (input_size > SIZE_MAX / AK_IO_BUDGET_INPUT_FACTOR)
            b.limit = SIZE_MAX;
    }
    return b;
}

bool akp_budget_take(akp_budget* b, size_t a, size_t n) {
    if (a != 0 && n > SIZE_MAX / a) return false;
    size_t bytes = a * n;
    if (bytes > b->limit - b->used) return false;
    b->used += bytes;
    return true;
}

ak_result akp_io_image_decode(const ak_io_desc* desc, const uint8_t* data, size_t size,
                              akp_budget* budget, const ak_allocator* alloc, uint8_t** out_pixels,
                              int* out_width, int* out_height, char* msg, size_t msg_size) {
    *out_pixels = NULL;
    *out_width = *out_height = 0;
    msg[0] = 0;
    if (desc && desc->image_decoder) {
        ak_io_image_view v = {NULL, 0, 0};
        ak_result r = desc->image_decoder(desc->image_decoder_user, data, size, &v);
        if (r == AK_OK) {
            if (!v.pixels || v.width <= 0 || v.height <= 0 || v.width > AKP_IO_MAX_IMAGE_SIDE ||
                v.height > AKP_IO_MAX_IMAGE_SIDE) {
                snprintf(msg, msg_size,
                         "the caller's image decoder gave %d x %d pixels%s (1..%d per side)",
                         v.width, v.height, v.pixels ? "" : " at NULL", AKP_IO_MAX_IMAGE_SIDE);
                return AK_ERR_BAD_DATA;
            }
            size_t bytes =
                (size_t)v.width * (size_t)v.height * 4u; /* <= 2^30: fits 32-bit size_t */
            if (budget && !akp_budget_take(budget, bytes, 1)) {
                snprintf(msg, msg_size,
                         "image of %d x %d pixels would exceed the memory budget of %zu bytes",
                         v.width, v.height, budget->limit);
                return AK_ERR_UNSUPPORTED;
            }
            uint8_t* px = (uint8_t*)akp_alloc(alloc, bytes);
            if (!px) {
                snprintf(msg, msg_size, "out of memory");
                return AK_ERR_NO_MEMORY;
            }
            memcpy(px, v.pixels, bytes);
            *out_pixels = px;
            *out_width = v.width;
            *out_height = v.height;
            return AK_OK;
        }
        if (r != AK_ERR_UNSUPPORTED) {
            snprintf(msg, msg_size, "the caller's image decoder refused it (%s)",
                     ak_result_string(r));
            return r == AK_ERR_NO_MEMORY ? r : AK_ERR_PARSE;
        }
    }
    return akp_image_decode(data, size, budget, alloc, out_pixels, out_width, out_height, msg,
                            msg_size);
}

ak_result akp_io_read_file(const char* path, const ak_allocator* alloc, size_t want, akp_budget* budget,
                           uint8_t** out_data, size_t* out_size, ak_diag* diag) {
    *out_data = NULL;
    *out_size = 0;
    /* opened non-blocking and checked before reading: a FIFO (e.g. a glTF buffer uri naming
     * one in the model's folder) would otherwise block the load forever in fopen; fopen also
     * succeeds on a directory on Linux, and ftell then reports LONG_MAX */
    const int fd = open(path, O_RDONLY | O_NONBLOCK | O_CLOEXEC);
    struct stat st;
    memset(&st, 0, sizeof st);
    if (fd < 0) {
        akp_diag_set(diag, path, "cannot open file");
        return AK_ERR_IO;
    }
    if (fstat(fd, &st) != 0 || !S_ISREG(st.st_mode)) {
        close(fd);
        akp_diag_set(diag, path, "%s", S_ISDIR(st.st_mode) ? "is a directory, not a file" : "not a regular file");
        return AK_ERR_IO;
    }
    FILE* f = fdopen(fd, "rb");
    if (!f) {
        close(fd);
        akp_diag_set(diag, path, "cannot open file");
        return AK_ERR_IO;
    }
    long end = -1;
    if (fseek(f, 0, SEEK_END) == 0) end = ftell(f);
    if (end < 0 || fseek(f, 0, SEEK_SET) != 0) {
        fclose(f);
        akp_diag_set(diag, path, "cannot determine the file size (not a regular file?)");
        return AK_ERR_IO;
    }
    size_t size = (size_t)end;
    if (want) {
        if (size < want) {
            fclose(f);
            akp_diag_set(diag, path, "has %zu bytes, fewer than the %zu declared", size, want);
            return AK_ERR_PARSE;
        }
        size = want; /* only the declared bytes are read, whatever follows them */
    }
    if (budget && !akp_budget_take(budget, 1, size + 1)) {
        fclose(f);
        akp_diag_set(diag, path, "%zu bytes exceed the memory budget of %zu bytes (ak_io_desc.memory_budget)", size,
                     budget->limit);
        return AK_ERR_UNSUPPORTED;
    }
    uint8_t* data = (uint8_t*)akp_alloc(alloc, size + 1); /* +1: never a zero-size alloc */
    if (!data) {
        fclose(f);
        akp_diag_set(diag, path, "out of memory reading %zu bytes", size);
        return AK_ERR_NO_MEMORY;
    }
    size_t got = fread(data, 1, size, f);
    fclose(f);
    if (got != size) {
        akp_free(alloc, data);
        akp_diag_set(diag, path, "read %zu of %zu bytes", got, size);
        return AK_ERR_IO;
    }
    data[size] = 0;
    *out_data = data;
    *out_size = size;
    return AK_OK;
}

ak_result akp_io_build_skeleton(ak_scene* scene, const akp_io_node* nodes, size_t count, int32_t* out_joint_of_node,
                                const char* path, ak_diag* diag) {
    const ak_allocator* a = &scene->alloc;
    if (count == 0) return AK_OK;
    if (count > AKP_IO_MAX_NODES) {
        akp_diag_set(diag, path, "%zu nodes; at most %u are supported", count, AKP_IO_MAX_NODES);
        return AK_ERR_UNSUPPORTED;
    }
    size_t table = 1;
    while (table < 2 * count) table <<= 1;
    int32_t* parents = (int32_t*)akp_alloc(a, count * sizeof(int32_t));
    int32_t* order = (int32_t*)akp_alloc(a, count * sizeof(int32_t));
    ak_joint_desc* joints = (ak_joint_desc*)akp_calloc(a, count * sizeof(ak_joint_desc));
    char(*names)[AK_NAME_SIZE] = (char(*)[AK_NAME_SIZE])akp_alloc(a, count * AK_NAME_SIZE);
    name_set set = {(int32_t*)akp_alloc(a, table * sizeof(int32_t)), table - 1, names};
    ak_result r = AK_ERR_NO_MEMORY;
    if (!parents || !order || !joints || !names || !set.slots) {
        akp_diag_set(diag, path, "out of memory building a skeleton of %zu nodes", count);
        goto done;
    }
    for (size_t i = 0; i < table; ++i) set.slots[i] = -1;
    for (size_t i = 0; i < count; ++i) parents[i] = nodes[i].parent;
    r = ak_skeleton_reorder((ak_i32_cspan){parents, count}, (ak_i32_span){order, count});
    if (r != AK_OK) {
        akp_diag_set(diag, path, "the node hierarchy has a cycle or a parent out of range");
        goto done;
    }
    /* Unique names in file order, so the first node keeps its name whatever the reordering. */
    for (size_t i = 0; i < count; ++i) {
        char* nm = names[i];
        if (nodes[i].name && nodes[i].name[0]) akp_io_copy_name(nm, nodes[i].name);
        else snprintf(nm, AK_NAME_SIZE, "node_%zu", i);
        for (unsigned k = 0; name_set_has(&set, nm); ++k) {
            char suffix[32];
            int sl = k == 0 ? snprintf(suffix, sizeof suffix, "#%zu", i) : snprintf(suffix, sizeof suffix, "#%zu_%u", i, k);
            const char* base = (nodes[i].name && nodes[i].name[0]) ? nodes[i].name : "node";
            int keep = (int)AK_NAME_SIZE - 1 - sl;
            snprintf(nm, AK_NAME_SIZE, "%.*s%s", keep, base, suffix);
        }
        name_set_add(&set, (int32_t)i);
    }
    for (size_t k = 0; k < count; ++k) out_joint_of_node[order[k]] = (int32_t)k;
    for (size_t k = 0; k < count; ++k) {
        const akp_io_node* n = &nodes[order[k]];
        joints[k].name = names[order[k]];
        joints[k].parent = n->parent < 0 ? -1 : out_joint_of_node[n->parent];
        joints[k].rest = n->rest;
        joints[k].inverse_bind = n->inverse_bind;
    }
    /* A loaded mesh's joint indices are slots of its skin (scene.h), so a palette indexed by
     * skeleton joint is refused (ak_skeleton_skinning_matrices) rather than silently wrong. */
    ak_skeleton_desc sd = {.joints = joints, .joint_count = count, .name = scene->name, .palette_from_skins = true};
    r = ak_skeleton_create(&sd, a, &scene->skeleton, diag);
    if (r != AK_OK && diag) {
        char msg[sizeof diag->message];
        memcpy(msg, diag->message, sizeof msg);
        akp_diag_set(diag, path, "skeleton: %.480s", msg);
    }
done:
    akp_free(a, parents);
    akp_free(a, order);
    akp_free(a, joints);
    akp_free(a, names);
    akp_free(a, set.slots);
    return r;
}

ak_transform akp_io_decompose(ak_mat4 m) {
    ak_transform t = ak_transform_identity();
    t.translation = ak_mat4_get_translation(m);
    ak_vec3 c[3];
    float s[3];
    for (int i = 0; i < 3; ++i) {
        c[i] = ak_vec3_make(m.m[i * 4], m.m[i * 4 + 1], m.m[i * 4 + 2]);
        s[i] = ak_vec3_length(c[i]);
    }
    ak_mat3 lin = ak_mat3_from_cols(c[0], c[1], c[2]);
    if (ak_mat3_determinant(lin) < 0.0f) {
        s[0] = -s[0];
        c[0] = ak_vec3_neg(c[0]);
    }
    t.scale = ak_vec3_make(s[0], s[1], s[2]);
    /* Rebuild an orthonormal frame (Gram-Schmidt) so rounding and degenerate axes still give a
     * unit quaternion. */
    ak_vec3 x = ak_vec3_normalize(c[0]);
    ak_vec3 y = ak_vec3_sub(c[1], ak_vec3_scale(x, ak_vec3_dot(x, c[1])));
    y = ak_vec3_normalize(y);
    if (ak_vec3_length_sq(x) == 0.0f && ak_vec3_length_sq(y) == 0.0f) return t;
    if (ak_vec3_length_sq(x) == 0.0f) x = ak_vec3_normalize(ak_vec3_any_perpendicular(y));
    if (ak_vec3_length_sq(y) == 0.0f) y = ak_vec3_normalize(ak_vec3_cross(ak_vec3_normalize(c[2]), x));
    if (ak_vec3_length_sq(y) == 0.0f) y = ak_vec3_normalize(ak_vec3_any_perpendicular(x));
    ak_vec3 z = ak_vec3_cross(x, y);
    t.rotation = ak_quat_normalize(ak_quat_from_mat3(ak_mat3_from_cols(x, y, z)));
    return t;
}

void akp_io_store_weights(ak_mesh* mesh, uint16_t* joints, float* weights, uint32_t src_influences,
                          const ak_io_desc* desc) {
    uint32_t k = mesh->influence_count;
    ak_weights_normalize(joints, weights, mesh->vertex_count, src_influences, k, desc->min_weight);
    for (size_t v = 0; v < mesh->vertex_count; ++v) {
        for (uint32_t i = 0; i < k; ++i) {
            float w = weights[v * src_influences + i];
            /* an unused slot points at joint 0, so no reader indexes past a palette */
            mesh->joints[v * k + i] = w > 0.0f ? joints[v * src_influences + i] : 0;
            mesh->weights[v * k + i] = w;
        }
    }
}

/* ---- public -------------------------------------------------------------------------- */

ak_io_desc ak_io_desc_resolved(const ak_io_desc* desc) {
    ak_io_desc d;
    memset(&d, 0, sizeof d);
    if (desc) d = *desc;
    if (d.max_influences == 0) d.max_influences = AK_IO_DEFAULT_INFLUENCES;
    if (d.max_influences > AK_MAX_INFLUENCES) d.max_influences = AK_MAX_INFLUENCES;
    if (!(d.min_weight > 0.0f) || !ak_finitef(d.min_weight)) d.min_weight = 0.0f;
    if ((int)d.format < 0 || d.format >= AK_IO_FORMAT_COUNT) d.format = AK_IO_FORMAT_AUTO;
    return d;
}

ak_result ak_io_load(const char* path, const ak_io_desc* desc, const ak_allocator* alloc, ak_scene** out_scene,
                     ak_diag* diag) {
    if (out_scene) *out_scene = NULL;
    if (!path || !out_scene) {
        akp_diag_set(diag, path, "path and out_scene are required");
        return AK_ERR_NULL_ARG;
    }
    if (desc && ((int)desc->format < 0 || desc->format >= AK_IO_FORMAT_COUNT)) {
        akp_diag_set(diag, path, "unknown format %d", (int)desc->format);
        return AK_ERR_BAD_ARG;
    }
    /* A directory would be an Assimp parse error; opening a FIFO would block. */
    struct stat st;
    memset(&st, 0, sizeof st);
    if (stat(path, &st) == 0 && !S_ISREG(st.st_mode)) {
        akp_diag_set(diag, path, "%s", S_ISDIR(st.st_mode) ? "is a directory, not a file" : "not a regular file");
        return AK_ERR_IO;
    }
    ak_io_desc d = ak_io_desc_resolved(desc);
    ak_io_format fmt = d.format;
    if (fmt == AK_IO_FORMAT_AUTO) {
        fmt = (has_extension(path, ".gltf") || has_extension(path, ".glb")) ? AK_IO_FORMAT_GLTF
              : has_extension(path, ".bvh")                                 ? AK_IO_FORMAT_BVH
              : has_extension(path, ".obj")                                 ? AK_IO_FORMAT_OBJ
                                                                            : AK_IO_FORMAT_ASSIMP;
        char magic[4] = {0};
        FILE* f = fmt == AK_IO_FORMAT_ASSIMP ? fopen(path, "rb") : NULL;
        if (f) { /* a GLB under another extension */
            if (fread(magic, 1, 4, f) == 4 && memcmp(magic, "glTF", 4) == 0) fmt = AK_IO_FORMAT_GLTF;
            fclose(f);
        }
    }
    if (fmt == AK_IO_FORMAT_ASSIMP) return akp_io_load_assimp(path, &d, alloc, out_scene, diag);
    const char* base = strrchr(path, '/');
    if (fmt == AK_IO_FORMAT_BVH) return akp_io_load_bvh(path, NULL, 0, base ? base + 1 : path, &d, alloc, out_scene, diag);

    uint8_t* data = NULL;
    size_t size = 0;
    akp_budget budget = akp_io_budget(&d, (size_t)st.st_size);
    ak_result r = akp_io_read_file(path, alloc, 0, &budget, &data, &size, diag);
    if (r != AK_OK) return r;
    /* External buffers are relative to the file's directory. */
    char dir[4096];
    if (base && base == path) snprintf(dir, sizeof dir, "/");
    else if (base) snprintf(dir, sizeof dir, "%.*s", (int)(base - path), path);
    else snprintf(dir, sizeof dir, ".");
    if (fmt == AK_IO_FORMAT_OBJ) r = akp_io_load_obj(data, size, path, dir, &d, alloc, out_scene, diag);
    else r = akp_io_load_gltf(data, size, base ? base + 1 : path, dir, &d, alloc, out_scene, diag);
    if (r != AK_OK && diag) snprintf(diag->path, sizeof diag->path, "%s", path);
    akp_free(alloc, data);
    return r;
}

ak_result ak_io_load_memory(const void* data, size_t size, const char* name, const char* base_dir,
                            const ak_io_desc* desc, const ak_allocator* alloc, ak_scene** out_scene, ak_diag* diag) {
    if (out_scene) *out_scene = NULL;
    if (!name) name = "memory";
    if (!out_scene || (!data && size > 0)) {
        akp_diag_set(diag, name, "data and out_scene are required");
        return AK_ERR_NULL_ARG;
    }
    ak_io_desc d = ak_io_desc_resolved(desc);
    if (desc && desc->format != AK_IO_FORMAT_AUTO && desc->format != AK_IO_FORMAT_GLTF &&
        desc->format != AK_IO_FORMAT_BVH && desc->format != AK_IO_FORMAT_OBJ) {
        akp_diag_set(diag, name, "ak_io_load_memory reads glTF, BVH and OBJ only");
        return AK_ERR_UNSUPPORTED;
    }
    if (d.format == AK_IO_FORMAT_OBJ) { /* the reader wants the text NUL-terminated */
        akp_budget b = akp_io_budget(&d, size);
        if (!akp_budget_take(&b, 1, size + 1)) {
            akp_diag_set(diag, name, "%zu bytes exceed the memory budget of %zu bytes", size, b.limit);
            return AK_ERR_UNSUPPORTED;
        }
        uint8_t* copy = (uint8_t*)akp_alloc(alloc, size + 1);
        if (!copy) {
            akp_diag_set(diag, name, "out of memory");
            return AK_ERR_NO_MEMORY;
        }
        if (size) memcpy(copy, data, size);
        copy[size] = 0;
        ak_result r = akp_io_load_obj(copy, size, name, base_dir, &d, alloc, out_scene, diag);
        akp_free(alloc, copy);
        return r;
    }
    static const uint8_t empty[1] = {0};
    bool bvh = d.format == AK_IO_FORMAT_BVH;
    if (d.format == AK_IO_FORMAT_AUTO && data) { /* BVH text starts with HIERARCHY */
        size_t i = 0;
        const uint8_t* p = (const uint8_t*)data;
        if (size >= 3 && p[0] == 0xEF && p[1] == 0xBB && p[2] == 0xBF) i = 3;
        while (i < size && isspace(p[i])) ++i;
        bvh = size - i >= 9 && memcmp(p + i, "HIERARCHY", 9) == 0;
    }
    if (bvh) return akp_io_load_bvh(NULL, data ? (const uint8_t*)data : empty, size, name, &d, alloc, out_scene, diag);
    return akp_io_load_gltf(data ? (const uint8_t*)data : empty, size, name, base_dir, &d, alloc, out_scene, diag);
}

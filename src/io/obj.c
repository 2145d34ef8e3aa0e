/* Wavefront OBJ (+ MTL) reader, animkit's own: safe on untrusted files (Assimp 5.2.5's OBJ
 * importer crashes on a four-line OBJ whose .mtl says "map_Kd" before "newmtl").
 *
 * Two passes over the bytes: the first counts the statements, so every array is charged to
 * the load's memory budget and allocated once, at its final size; the second parses. Nothing
 * recurses. Every error names the file and the line; messages quote the file's words only
 * through akp_io_sanitize (control bytes and invalid UTF-8 come out as \xNN).
 *
 * The scene has the layout Assimp's OBJ importer gave (so files load as before):
 *   - a root node named by the file name, one child node per object: an "o" or "g" line
 *     whose name differs from the current object's starts a new object, and faces before
 *     any object go to one named "defaultobject";
 *   - one mesh per (object, material) run: an object starts with one mesh of its name; a
 *     "usemtl" naming another material starts a new mesh named by the material, unless the
 *     current mesh has no face yet (it then only takes the material); meshes without faces
 *     are dropped; meshes in creation order, each placed on its object's node;
 *   - no welding: each face corner is one vertex (in file order), polygons are fans
 *     (0, i, i + 1) over their corners; faces of fewer than 3 corners are skipped;
 *   - normals (UVs) when every corner of the mesh has a "vn" ("vt") index, as written;
 *   - is_joint all false, no skins, no clips.
 * Beyond Assimp: a mesh whose material a read .mtl defines gets has_material and base_color
 * (Kd, alpha = d, or 1 - Tr), and, when the mesh has UVs, the material's map_Kd image as its
 * texture (PNG or JPEG, the last word of the line, relative to the .mtl's folder and read only
 * inside the model's folder; stored with its rows flipped, since OBJ puts v = 0 at the
 * image's bottom and animkit at its top, so the UVs stay as written; REPEAT, LINEAR; an image
 * that cannot be read is a warning and no texture); a file with vertices and no faces gives one point mesh
 * "defaultobject" holding every "v" (Assimp refused it).
 * mtllib: read only inside the model's folder (akp_io_resolve_inside); a refused, missing or
 * unreadable .mtl is not an error (viewers ignore it): the meshes then have no material and
 * desc->logger gets a warning. At most OB_MAX_MTLLIB distinct libraries are read. */
#include <errno.h>
#include <limits.h>
#include <math.h>
#include <stdarg.h>
#include <stdlib.h>

#include "io_internal.h"

/* ---- private types ------------------------------------------------------------------- */

#define OB_MAX_MTLLIB 16
#define OB_DEFAULT_OBJECT "defaultobject"

typedef struct ob_corner {
    int32_t v, vt, vn; /* 0-based; -1 none */
} ob_corner;

typedef struct ob_mesh {
    char name[AK_NAME_SIZE];
    char material[AK_NAME_SIZE]; /* "" none */
    size_t object;
    size_t first_face, face_count;
    size_t first_corner, corner_count;
    size_t triangle_count;
    bool all_vt, all_vn;
} ob_mesh;

#define OB_MAP_SIZE 512

typedef struct ob_material {
    char name[AK_NAME_SIZE];
    ak_vec4 color;
    char map_kd[OB_MAP_SIZE]; /* map_Kd file relative to the model's folder, "" none */
} ob_material;

typedef struct ob_ctx {
    const ak_allocator* alloc;
    const ak_io_desc* desc;
    const char* name;     /* in diag */
    const char* base_dir; /* NULL -> no mtllib */
    ak_diag* diag;
    akp_budget budget;
    size_t tot_v, tot_vt, tot_vn, tot_corner, tot_face, tot_group; /* pass 1 */
    size_t n_v, n_vt, n_vn, n_corner, n_face;                      /* pass 2 so far */
    ak_vec3* pos;
    ak_vec2* tex;
    ak_vec3* nrm;
    ob_corner* corners;
    uint32_t* face_size;
    ob_mesh* meshes;
    size_t mesh_count;
    char (*objects)[AK_NAME_SIZE];
    size_t object_count;
    ob_material* materials;
    size_t material_count, material_cap;
    char libs[OB_MAX_MTLLIB][AK_NAME_SIZE];
    size_t lib_count;
    char current_material[AK_NAME_SIZE];
    bool has_material;
} ob_ctx;

/* ---- static helpers: errors and lines --------------------------------------------------- */

#if defined(__GNUC__)
__attribute__((format(printf, 5, 6)))
#endif
static ak_result fail_at(ob_ctx* c, const char* file, long line, ak_result r, const char* fmt, ...) {
    if (c->diag) {
        memset(c->diag, 0, sizeof *c->diag);
        c->diag->byte_offset = -1;
        c->diag->line = line;
        snprintf(c->diag->path, sizeof c->diag->path, "%s", file);
        char msg[sizeof c->diag->message - 40];
        va_list ap;
        va_start(ap, fmt);
        vsnprintf(msg, sizeof msg, fmt, ap);
        va_end(ap);
        if (line > 0) snprintf(c->diag->message, sizeof c->diag->message, "line %ld: %s", line, msg);
        else snprintf(c->diag->message, sizeof c->diag->message, "%s", msg);
        akp_io_sanitize(c->diag->path, sizeof c->diag->path);
        akp_io_sanitize(c->diag->message, sizeof c->diag->message);
    }
    return r;
}

#if defined(__GNUC__)
__attribute__((format(printf, 2, 3)))
#endif
static void warn(ob_ctx* c, const char* fmt, ...) {
    if (!c->desc->logger.func) return;
    char msg[700];
    int n = snprintf(msg, sizeof msg, "%.300s: ", c->name);
    size_t at = n > 0 && (size_t)n < sizeof msg ? (size_t)n : 0;
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(msg + at, sizeof msg - at, fmt, ap);
    va_end(ap);
    akp_io_sanitize(msg, sizeof msg);
    akp_log(&c->desc->logger, AK_LOG_WARN, msg);
}

#define TRY(expr)                                                                          \
    do {                                                                                   \
        ak_result tr_ = (expr);                                                            \
        if (tr_ != AK_OK) return tr_;                                                      \
    } while (0)

/* A cursor over the lines of a text. */
typedef struct ob_text {
    const char* p;
    const char* end;
    long line;
} ob_text;

/* The next line (without its '\n' and a '\r' before it) -> [*b, *e); false at the end. */
static bool next_line(ob_text* t, const char** b, const char** e) {
    if (t->p >= t->end) return false;
    const char* nl = (const char*)memchr(t->p, '\n', (size_t)(t->end - t->p));
    const char* stop = nl ? nl : t->end;
    *b = t->p;
    *e = stop;
    if (*e > *b && (*e)[-1] == '\r') --*e;
    t->p = nl ? nl + 1 : t->end;
    ++t->line;
    return true;
}

static bool is_space(char ch) { return ch == ' ' || ch == '\t' || ch == '\f' || ch == '\v' || ch == '\r'; }

/* The next word of [*p, e) -> [*wb, *we); false when none. */
static bool next_word(const char** p, const char* e, const char** wb, const char** we) {
    const char* s = *p;
    while (s < e && is_space(*s)) ++s;
    if (s >= e) return false;
    *wb = s;
    while (s < e && !is_space(*s)) ++s;
    *we = s;
    *p = s;
    return true;
}

static bool word_is(const char* b, const char* e, const char* w) {
    size_t n = strlen(w);
    return (size_t)(e - b) == n && memcmp(b, w, n) == 0;
}

/* The rest of a line, trimmed, as a name: valid UTF-8, no control bytes (a tab becomes a
 * space), cut to AK_NAME_SIZE - 1 bytes on a character boundary. */
static ak_result rest_name(ob_ctx* c, const char* file, long line, const char* p, const char* e, const char* what,
                           char out[AK_NAME_SIZE]) {
    while (p < e && is_space(*p)) ++p;
    while (e > p && is_space(e[-1])) --e;
    if (!akp_io_utf8_valid(p, (size_t)(e - p)))
        return fail_at(c, file, line, AK_ERR_PARSE, "the %s is not valid UTF-8", what);
    size_t n = 0, len = (size_t)(e - p);
    for (const char* s = p; s < e; ++s) {
        unsigned char ch = (unsigned char)*s;
        if ((ch < 0x20 && ch != '\t') || ch == 0x7F)
            return fail_at(c, file, line, AK_ERR_PARSE, "the %s holds a control byte", what);
        if (n + 1 < AK_NAME_SIZE) out[n++] = ch == '\t' ? ' ' : (char)ch;
    }
    if (n < len) /* cut inside a character: drop its first bytes too */
        while (n > 0 && ((unsigned char)p[n] & 0xC0) == 0x80) --n;
    out[n] = 0;
    return AK_OK;
}

/* A finite float filling [b, e). */
static ak_result parse_float(ob_ctx* c, const char* file, long line, const char* b, const char* e, const char* what,
                             float* out) {
    char buf[64];
    size_t n = (size_t)(e - b);
    if (n == 0 || n >= sizeof buf) return fail_at(c, file, line, AK_ERR_PARSE, "%s is not a number", what);
    memcpy(buf, b, n);
    buf[n] = 0;
    char* end = NULL;
    errno = 0;
    double v = strtod(buf, &end);
    if (end == buf || *end != 0) return fail_at(c, file, line, AK_ERR_PARSE, "%s '%.60s' is not a number", what, buf);
    if (!isfinite(v) || !ak_finitef((float)v))
        return fail_at(c, file, line, AK_ERR_BAD_DATA, "%s '%.60s' is not finite", what, buf);
    *out = (float)v;
    return AK_OK;
}

/* Up to count floats from the words of [p, e): the first need are required. */
static ak_result parse_floats(ob_ctx* c, long line, const char* p, const char* e, size_t need, size_t count,
                              const char* what, float* out) {
    for (size_t k = 0; k < count; ++k) {
        const char *wb, *we;
        if (!next_word(&p, e, &wb, &we) || *wb == '#') {
            if (k < need) return fail_at(c, c->name, line, AK_ERR_PARSE, "%s has %zu values, %zu expected", what, k, need);
            break;
        }
        TRY(parse_float(c, c->name, line, wb, we, what, &out[k]));
    }
    return AK_OK;
}

/* ---- static helpers: mtllib ------------------------------------------------------------- */

static int material_cmp(const void* a, const void* b) {
    return strcmp(((const ob_material*)a)->name, ((const ob_material*)b)->name);
}

static const ob_material* find_material(const ob_ctx* c, const char* name) {
    if (c->material_count == 0) return NULL; /* bsearch on a NULL array is undefined even for 0 */
    ob_material key;
    snprintf(key.name, sizeof key.name, "%s", name);
    return (const ob_material*)bsearch(&key, c->materials, c->material_count, sizeof key, material_cmp);
}

/* Parse one .mtl text (NUL-terminated) into c->materials: newmtl, Kd, d, Tr; anything else,
 * and anything before the first newmtl, is ignored. */
static ak_result parse_mtl(ob_ctx* c, const char* lib, const char* data, size_t size) {
    ob_text t = {data, data + size, 0};
    const char *b, *e;
    size_t count = 0;
    while (next_line(&t, &b, &e)) {
        const char *p = b, *wb, *we;
        if (next_word(&p, e, &wb, &we) && word_is(wb, we, "newmtl")) ++count;
    }
    if (count == 0) return AK_OK;
    if (count > AKP_IO_MAX_ELEMENTS || !akp_budget_take(&c->budget, c->material_count + count, sizeof(ob_material)))
        return fail_at(c, lib, 0, AK_ERR_UNSUPPORTED, "%zu materials exceed the memory budget of %zu bytes", count,
                       c->budget.limit);
    ob_material* m = (ob_material*)akp_alloc(c->alloc, (c->material_count + count) * sizeof(ob_material));
    if (!m) return fail_at(c, lib, 0, AK_ERR_NO_MEMORY, "out of memory for %zu materials", count);
    if (c->material_count) memcpy(m, c->materials, c->material_count * sizeof(ob_material));
    akp_free(c->alloc, c->materials);
    c->materials = m;
    ob_material* cur = NULL;
    t = (ob_text){data, data + size, 0};
    while (next_line(&t, &b, &e)) {
        const char *p = b, *wb, *we;
        if (memchr(b, 0, (size_t)(e - b)))
            return fail_at(c, lib, t.line, AK_ERR_PARSE, "a NUL byte (not a text file)");
        if (!next_word(&p, e, &wb, &we) || *wb == '#') continue;
        if (word_is(wb, we, "newmtl")) {
            cur = &c->materials[c->material_count++];
            memset(cur, 0, sizeof *cur);
            TRY(rest_name(c, lib, t.line, p, e, "material name", cur->name));
            cur->color = ak_vec4_make(1.0f, 1.0f, 1.0f, 1.0f);
        } else if (!cur) {
            continue; /* map_Kd and friends before any newmtl: nothing to attach them to */
        } else if (word_is(wb, we, "Kd")) {
            const char *vb[3], *ve[3];
            size_t n = 0;
            while (n < 3 && next_word(&p, e, &vb[n], &ve[n]) && *vb[n] != '#') ++n;
            if (n > 0 && (word_is(vb[0], ve[0], "spectral") || word_is(vb[0], ve[0], "xyz"))) continue; /* not RGB */
            if (n != 1 && n != 3) return fail_at(c, lib, t.line, AK_ERR_PARSE, "Kd has %zu values, 1 or 3 expected", n);
            float v[3];
            for (size_t k = 0; k < n; ++k) TRY(parse_float(c, lib, t.line, vb[k], ve[k], "a Kd value", &v[k]));
            if (n == 1) v[1] = v[2] = v[0]; /* "Kd g" is grey g */
            cur->color.x = v[0], cur->color.y = v[1], cur->color.z = v[2];
        } else if (word_is(wb, we, "d") || word_is(wb, we, "Tr")) {
            bool tr = wb[0] == 'T';
            float a = 1.0f;
            if (!next_word(&p, e, &wb, &we)) return fail_at(c, lib, t.line, AK_ERR_PARSE, "%s has no value", tr ? "Tr" : "d");
            if (word_is(wb, we, "-halo") && !next_word(&p, e, &wb, &we))
                return fail_at(c, lib, t.line, AK_ERR_PARSE, "d -halo has no value");
            TRY(parse_float(c, lib, t.line, wb, we, tr ? "Tr" : "d", &a));
            cur->color.w = tr ? 1.0f - a : a;
        } else if (word_is(wb, we, "map_Kd")) {
            /* options (-s u v w, -clamp on, ...) come first: the file is the last word */
            const char *fb = NULL, *fe = NULL;
            while (next_word(&p, e, &wb, &we) && *wb != '#') fb = wb, fe = we;
            const char* slash = strrchr(lib, '/');
            size_t dir = slash ? (size_t)(slash - lib) + 1 : 0;
            if (!fb || dir + (size_t)(fe - fb) >= OB_MAP_SIZE) {
                warn(c, "%.200s line %ld: map_Kd without a usable file name; ignored", lib, t.line);
                continue;
            }
            memcpy(cur->map_kd, lib, dir);
            memcpy(cur->map_kd + dir, fb, (size_t)(fe - fb));
            cur->map_kd[dir + (size_t)(fe - fb)] = 0;
            if (memchr(cur->map_kd, 0, dir + (size_t)(fe - fb)) || !akp_io_utf8_valid(cur->map_kd, strlen(cur->map_kd)))
                cur->map_kd[0] = 0;
        }
    }
    return AK_OK;
}

/* Decode material mat's map_Kd into scene texture ti (rows flipped: OBJ's v runs up from the
 * image's bottom). Failures are warnings; the texture then stays absent. */
static void load_map_kd(ob_ctx* c, ak_scene* s, size_t ti, const ob_material* mat) {
    char real[PATH_MAX];
    bool leaves = false;
    if (!c->base_dir) {
        warn(c, "map_Kd '%.200s' not read: the OBJ came from memory without a base directory", mat->map_kd);
        return;
    }
    if (akp_io_resolve_inside(c->base_dir, mat->map_kd, c->desc, real, sizeof real, &leaves) != AK_OK) {
        warn(c, "map_Kd '%.200s' not read: %s", mat->map_kd,
             leaves ? "the path leaves the model's folder (ak_io_desc.extra_roots, allow_any_path)" : "cannot open it");
        return;
    }
    uint8_t* data = NULL;
    size_t size = 0;
    ak_diag sub;
    ak_result r = akp_io_read_file(real, c->alloc, 0, &c->budget, &data, &size, &sub);
    if (r != AK_OK) {
        warn(c, "map_Kd '%.200s' not read: %s", mat->map_kd, sub.message);
        return;
    }
    char msg[200];
    uint8_t* px = NULL;
    int w = 0, h = 0;
    r = akp_io_image_decode(c->desc, data, size, &c->budget, &s->alloc, &px, &w, &h, msg,
                            sizeof msg);
    akp_free(c->alloc, data);
    if (r != AK_OK) {
        warn(c, "map_Kd '%.200s' not read: %s", mat->map_kd, msg);
        return;
    }
    size_t row = (size_t)w * 4u;
    for (int y = 0; y < h / 2; ++y) {
        uint8_t* a = px + (size_t)y * row;
        uint8_t* b = px + (size_t)(h - 1 - y) * row;
        for (size_t k = 0; k < row; ++k) {
            uint8_t tmp = a[k];
            a[k] = b[k];
            b[k] = tmp;
        }
    }
    ak_scene_texture* t = &s->textures[ti];
    const char* base = strrchr(mat->map_kd, '/');
    akp_io_copy_name(t->name, base ? base + 1 : mat->map_kd);
    akp_io_sanitize(t->name, sizeof t->name);
    t->pixels = px;
    t->width = w;
    t->height = h;
}

static void read_mtllib(ob_ctx* c, const char* lib) {
    for (size_t i = 0; i < c->lib_count; ++i)
        if (strcmp(c->libs[i], lib) == 0) return;
    if (c->lib_count >= OB_MAX_MTLLIB) {
        warn(c, "mtllib '%.200s' not read: more than %d material libraries", lib, OB_MAX_MTLLIB);
        return;
    }
    snprintf(c->libs[c->lib_count++], AK_NAME_SIZE, "%s", lib);
    if (!c->base_dir) {
        warn(c, "mtllib '%.200s' not read: the OBJ came from memory without a base directory", lib);
        return;
    }
    char real[PATH_MAX];
    bool leaves = false;
    if (akp_io_resolve_inside(c->base_dir, lib, c->desc, real, sizeof real, &leaves) != AK_OK) {
        if (leaves)
            warn(c, "mtllib '%.200s' not read: the path leaves the model's folder (ak_io_desc.extra_roots, "
                    "allow_any_path)", lib);
        else warn(c, "mtllib '%.200s' not read: cannot open it", lib);
        return;
    }
    uint8_t* data = NULL;
    size_t size = 0;
    ak_diag sub;
    ak_result r = akp_io_read_file(real, c->alloc, 0, &c->budget, &data, &size, &sub);
    if (r != AK_OK) {
        warn(c, "mtllib '%.200s' not read: %s", lib, sub.message);
        return;
    }
    ak_diag saved;
    memset(&saved, 0, sizeof saved);
    if (c->diag) saved = *c->diag;
    size_t had = c->material_count;
    r = parse_mtl(c, lib, (const char*)data, size);
    akp_free(c->alloc, data);
    if (r != AK_OK) {
        /* a broken .mtl is as good as a missing one: warn and go on without its materials */
        c->material_count = had;
        if (c->diag) {
            warn(c, "mtllib '%.200s' not read: %s", lib, c->diag->message);
            *c->diag = saved;
        } else {
            warn(c, "mtllib '%.200s' not read: it is malformed", lib);
        }
    }
}

/* ---- static helpers: the OBJ ------------------------------------------------------------ */

/* Pass 1: counts, so that every array is charged and allocated once. */
static ak_result count_pass(ob_ctx* c, const char* data, size_t size) {
    ob_text t = {data, data + size, 0};
    const char *b, *e;
    while (next_line(&t, &b, &e)) {
        const char *p = b, *wb, *we;
        if (!next_word(&p, e, &wb, &we)) continue;
        if (word_is(wb, we, "v")) ++c->tot_v;
        else if (word_is(wb, we, "vt")) ++c->tot_vt;
        else if (word_is(wb, we, "vn")) ++c->tot_vn;
        else if (word_is(wb, we, "o") || word_is(wb, we, "g") || word_is(wb, we, "usemtl")) ++c->tot_group;
        else if (word_is(wb, we, "f")) {
            size_t k = 0;
            while (next_word(&p, e, &wb, &we) && *wb != '#') ++k;
            if (k >= 3) {
                c->tot_corner += k;
                ++c->tot_face;
            }
        }
    }
    const size_t limit = AKP_IO_MAX_ELEMENTS;
    if (c->tot_v > limit || c->tot_vt > limit || c->tot_vn > limit || c->tot_corner > limit)
        return fail_at(c, c->name, 0, AK_ERR_UNSUPPORTED, "more than %zu vertices, UVs, normals or face corners", limit);
    return AK_OK;
}

static ak_result alloc_arrays(ob_ctx* c) {
    /* objects and meshes: at most one per o/g/usemtl line, plus "defaultobject" */
    size_t groups = c->tot_group + 1;
    struct {
        void** ptr;
        size_t n, size;
    } arrays[] = {
        {(void**)&c->pos, c->tot_v, sizeof(ak_vec3)},        {(void**)&c->tex, c->tot_vt, sizeof(ak_vec2)},
        {(void**)&c->nrm, c->tot_vn, sizeof(ak_vec3)},       {(void**)&c->corners, c->tot_corner, sizeof(ob_corner)},
        {(void**)&c->face_size, c->tot_face, sizeof(uint32_t)}, {(void**)&c->meshes, groups, sizeof(ob_mesh)},
        {(void**)&c->objects, groups, AK_NAME_SIZE},
    };
    for (size_t i = 0; i < sizeof arrays / sizeof arrays[0]; ++i) {
        if (!akp_budget_take(&c->budget, arrays[i].n ? arrays[i].n : 1, arrays[i].size))
            return fail_at(c, c->name, 0, AK_ERR_UNSUPPORTED,
                           "%zu x %zu bytes would exceed the memory budget of %zu bytes (%zu already used; "
                           "ak_io_desc.memory_budget)",
                           arrays[i].n, arrays[i].size, c->budget.limit, c->budget.used);
        *arrays[i].ptr = akp_alloc(c->alloc, (arrays[i].n ? arrays[i].n : 1) * arrays[i].size);
        if (!*arrays[i].ptr) return fail_at(c, c->name, 0, AK_ERR_NO_MEMORY, "out of memory");
    }
    return AK_OK;
}

static void new_mesh(ob_ctx* c, const char* name) {
    ob_mesh* m = &c->meshes[c->mesh_count++];
    memset(m, 0, sizeof *m);
    snprintf(m->name, sizeof m->name, "%s", name);
    if (c->has_material) snprintf(m->material, sizeof m->material, "%s", c->current_material);
    m->object = c->object_count - 1;
    m->first_face = c->n_face;
    m->first_corner = c->n_corner;
    m->all_vt = m->all_vn = true;
}

static void new_object(ob_ctx* c, const char* name) {
    snprintf(c->objects[c->object_count++], AK_NAME_SIZE, "%s", name);
    new_mesh(c, name);
}

/* One "a", "a/b", "a//c" or "a/b/c" corner; indices resolved against the final counts
 * (positive: Assimp also accepts forward references) or the counts so far (negative). */
static ak_result parse_corner(ob_ctx* c, long line, const char* b, const char* e, ob_corner* out) {
    int32_t idx[3] = {-1, -1, -1};
    const size_t so_far[3] = {c->n_v, c->n_vt, c->n_vn}, total_of[3] = {c->tot_v, c->tot_vt, c->tot_vn};
    static const char* const what[3] = {"position", "UV", "normal"};
    const char* p = b;
    for (int k = 0; k < 3; ++k) {
        if (k > 0) {
            if (p >= e) break;
            if (*p != '/') goto bad;
            ++p;
            if (k == 1 && p < e && *p == '/') continue; /* a//c */
        }
        bool neg = p < e && *p == '-';
        if (neg || (p < e && *p == '+')) ++p;
        if (p >= e || *p < '0' || *p > '9') goto bad;
        long long v = 0;
        while (p < e && *p >= '0' && *p <= '9') {
            v = v * 10 + (*p++ - '0');
            if (v > 1000000000000LL) v = 1000000000000LL;
        }
        if (v == 0) return fail_at(c, c->name, line, AK_ERR_BAD_INDEX, "a face %s index is 0 (indices start at 1)", what[k]);
        long long resolved = neg ? (long long)so_far[k] - v : v - 1;
        size_t range = neg ? so_far[k] : total_of[k];
        if (resolved < 0 || (unsigned long long)resolved >= range)
            return fail_at(c, c->name, line, AK_ERR_BAD_INDEX, "face %s index %s%lld is out of range (%zu %s%s)", what[k],
                           neg ? "-" : "", v, range, what[k], range == 1 ? "" : "s");
        idx[k] = (int32_t)resolved;
    }
    if (p != e) goto bad;
    out->v = idx[0], out->vt = idx[1], out->vn = idx[2];
    return AK_OK;
bad:
    return fail_at(c, c->name, line, AK_ERR_PARSE, "face corner '%.*s' is not v, v/vt, v//vn or v/vt/vn",
                   (int)(e - b < 40 ? e - b : 40), b);
}

/* Pass 2: the statements. */
static ak_result parse_pass(ob_ctx* c, const char* data, size_t size) {
    ob_text t = {data, data + size, 0};
    const char *b, *e;
    while (next_line(&t, &b, &e)) {
        const char *p = b, *wb, *we;
        if (memchr(b, 0, (size_t)(e - b))) return fail_at(c, c->name, t.line, AK_ERR_PARSE, "a NUL byte (not a text file)");
        if (!next_word(&p, e, &wb, &we) || *wb == '#') continue;
        if (word_is(wb, we, "v")) {
            float v[3];
            TRY(parse_floats(c, t.line, p, e, 3, 3, "v", v)); /* w or a vertex colour may follow: ignored */
            c->pos[c->n_v++] = ak_vec3_make(v[0], v[1], v[2]);
        } else if (word_is(wb, we, "vt")) {
            float v[2] = {0.0f, 0.0f};
            TRY(parse_floats(c, t.line, p, e, 1, 2, "vt", v));
            c->tex[c->n_vt++] = ak_vec2_make(v[0], v[1]);
        } else if (word_is(wb, we, "vn")) {
            float v[3];
            TRY(parse_floats(c, t.line, p, e, 3, 3, "vn", v));
            c->nrm[c->n_vn++] = ak_vec3_make(v[0], v[1], v[2]);
        } else if (word_is(wb, we, "f")) {
            const char* q = p;
            size_t k = 0;
            while (next_word(&q, e, &wb, &we) && *wb != '#') ++k;
            if (k < 3) continue; /* a point or a line: no surface */
            if (c->object_count == 0) new_object(c, OB_DEFAULT_OBJECT);
            ob_mesh* m = &c->meshes[c->mesh_count - 1];
            for (size_t i = 0; i < k; ++i) {
                next_word(&p, e, &wb, &we);
                ob_corner* cn = &c->corners[c->n_corner++];
                TRY(parse_corner(c, t.line, wb, we, cn));
                m->all_vt = m->all_vt && cn->vt >= 0;
                m->all_vn = m->all_vn && cn->vn >= 0;
            }
            c->face_size[c->n_face++] = (uint32_t)k;
            m->face_count++;
            m->corner_count += k;
            m->triangle_count += k - 2;
        } else if (word_is(wb, we, "o") || word_is(wb, we, "g")) {
            char name[AK_NAME_SIZE];
            TRY(rest_name(c, c->name, t.line, p, e, wb[0] == 'o' ? "object name" : "group name", name));
            if (c->object_count == 0 || strcmp(c->objects[c->object_count - 1], name) != 0) new_object(c, name);
        } else if (word_is(wb, we, "usemtl")) {
            char name[AK_NAME_SIZE];
            TRY(rest_name(c, c->name, t.line, p, e, "material name", name));
            if (c->has_material && strcmp(c->current_material, name) == 0) continue;
            snprintf(c->current_material, sizeof c->current_material, "%s", name);
            c->has_material = true;
            if (c->object_count == 0) continue; /* the first face's defaultobject takes it */
            ob_mesh* m = &c->meshes[c->mesh_count - 1];
            if (m->face_count) new_mesh(c, name);
            else snprintf(m->material, sizeof m->material, "%s", name);
        } else if (word_is(wb, we, "mtllib")) {
            char name[AK_NAME_SIZE];
            TRY(rest_name(c, c->name, t.line, p, e, "mtllib name", name));
            if (name[0]) read_mtllib(c, name);
        }
        /* s, l, p, vp, cstype, ...: tolerated, ignored */
    }
    return AK_OK;
}

static ak_result build_mesh(ob_ctx* c, const ob_mesh* om, ak_mesh** out) {
    ak_mesh_desc d = {
        .vertex_count = om->corner_count,
        .triangle_count = om->triangle_count,
        .has_normals = om->all_vn,
        .has_uvs = om->all_vt,
        .name = om->name,
    };
    size_t per_vertex = sizeof(ak_vec3) * (1 + (om->all_vn ? 1 : 0)) + (om->all_vt ? sizeof(ak_vec2) : 0);
    if (!akp_budget_take(&c->budget, om->corner_count, per_vertex) ||
        !akp_budget_take(&c->budget, om->triangle_count, 3 * sizeof(uint32_t)))
        return fail_at(c, c->name, 0, AK_ERR_UNSUPPORTED,
                       "mesh '%s' of %zu vertices would exceed the memory budget of %zu bytes", om->name,
                       om->corner_count, c->budget.limit);
    ak_mesh* m = NULL;
    ak_result r = ak_mesh_create(&d, c->alloc, &m);
    if (r != AK_OK) return fail_at(c, c->name, 0, r, "mesh '%s': cannot create a mesh of %zu vertices", om->name, om->corner_count);
    for (size_t i = 0; i < om->corner_count; ++i) {
        const ob_corner* cn = &c->corners[om->first_corner + i];
        m->positions[i] = c->pos[cn->v];
        if (m->normals) m->normals[i] = c->nrm[cn->vn];
        if (m->uvs) m->uvs[i] = c->tex[cn->vt];
    }
    size_t t = 0, base = 0;
    for (size_t f = 0; f < om->face_count; ++f) {
        uint32_t k = c->face_size[om->first_face + f];
        for (uint32_t i = 1; i + 1 < k; ++i, ++t) {
            m->indices[3 * t] = (uint32_t)base;
            m->indices[3 * t + 1] = (uint32_t)(base + i);
            m->indices[3 * t + 2] = (uint32_t)(base + i + 1);
        }
        base += k;
    }
    *out = m;
    return AK_OK;
}

static ak_result build_scene(ob_ctx* c, ak_scene** out_scene) {
    /* a file of vertices only: one point mesh, as ak_io_write_obj writes point clouds */
    if (c->n_face == 0 && c->n_v > 0 && c->object_count == 0) new_object(c, OB_DEFAULT_OBJECT);
    size_t mesh_total = 0;
    for (size_t i = 0; i < c->mesh_count; ++i) mesh_total += c->meshes[i].face_count > 0;
    bool points = c->n_face == 0 && c->n_v > 0;
    if (points) mesh_total = 1;
    ak_scene* s = NULL;
    ak_result r = ak_scene_alloc(mesh_total, 0, 0, c->alloc, &s);
    if (r != AK_OK) return fail_at(c, c->name, 0, r, "out of memory");
    const char* slash = strrchr(c->name, '/');
    akp_io_copy_name(s->name, slash ? slash + 1 : c->name);
    size_t node_count = 1 + c->object_count;
    akp_io_node* nodes = NULL;
    int32_t* joint_of_node = NULL;
    if (node_count > AKP_IO_MAX_NODES) {
        r = fail_at(c, c->name, 0, AK_ERR_UNSUPPORTED, "%zu objects and groups; at most %u nodes are supported",
                    c->object_count, AKP_IO_MAX_NODES);
        goto done;
    }
    nodes = (akp_io_node*)akp_calloc(c->alloc, node_count * sizeof(akp_io_node));
    joint_of_node = (int32_t*)akp_alloc(c->alloc, node_count * sizeof(int32_t));
    if (!nodes || !joint_of_node) {
        r = fail_at(c, c->name, 0, AK_ERR_NO_MEMORY, "out of memory");
        goto done;
    }
    nodes[0].name = s->name;
    nodes[0].parent = -1;
    nodes[0].rest = ak_transform_identity();
    for (size_t i = 0; i < c->object_count; ++i) {
        nodes[1 + i].name = c->objects[i];
        nodes[1 + i].parent = 0;
        nodes[1 + i].rest = ak_transform_identity();
    }
    r = akp_io_build_skeleton(s, nodes, node_count, joint_of_node, c->name, c->diag);
    if (r != AK_OK) goto done;
    s->is_joint = (bool*)akp_calloc(&s->alloc, node_count * sizeof(bool)); /* plain nodes, as Assimp's */
    if (!s->is_joint) {
        r = fail_at(c, c->name, 0, AK_ERR_NO_MEMORY, "out of memory");
        goto done;
    }
    if (c->material_count > 1) qsort(c->materials, c->material_count, sizeof(ob_material), material_cmp);
    /* textures: one per material whose map_Kd a mesh with UVs uses (tex_of[material] = index) */
    int32_t* tex_of = (int32_t*)akp_alloc(c->alloc, (c->material_count ? c->material_count : 1) * sizeof(int32_t));
    if (!tex_of) {
        r = fail_at(c, c->name, 0, AK_ERR_NO_MEMORY, "out of memory");
        goto done;
    }
    size_t tex_count = 0;
    for (size_t i = 0; i < c->material_count; ++i) tex_of[i] = -1;
    for (size_t i = 0; i < c->mesh_count && !points; ++i) {
        const ob_material* mat = c->meshes[i].material[0] ? find_material(c, c->meshes[i].material) : NULL;
        if (mat && mat->map_kd[0] && c->meshes[i].face_count && c->meshes[i].all_vt && tex_of[mat - c->materials] < 0)
            tex_of[mat - c->materials] = (int32_t)tex_count++;
    }
    if (tex_count && ak_scene_texture_alloc(s, tex_count) != AK_OK) {
        akp_free(c->alloc, tex_of);
        r = fail_at(c, c->name, 0, AK_ERR_NO_MEMORY, "out of memory");
        goto done;
    }
    for (size_t i = 0; i < c->material_count; ++i)
        if (tex_of[i] >= 0) load_map_kd(c, s, (size_t)tex_of[i], &c->materials[i]);
    size_t out = 0;
    for (size_t i = 0; i < c->mesh_count && r == AK_OK; ++i) {
        ob_mesh* om = &c->meshes[i];
        if (points && i == 0) {
            if (!akp_budget_take(&c->budget, c->n_v, sizeof(ak_vec3))) {
                r = fail_at(c, c->name, 0, AK_ERR_UNSUPPORTED, "%zu points exceed the memory budget", c->n_v);
                break;
            }
            ak_mesh_desc d = {.vertex_count = c->n_v, .name = om->name};
            r = ak_mesh_create(&d, c->alloc, &s->meshes[0].mesh);
            if (r != AK_OK) {
                fail_at(c, c->name, 0, r, "cannot create a mesh of %zu points", c->n_v);
                break;
            }
            memcpy(s->meshes[0].mesh->positions, c->pos, c->n_v * sizeof(ak_vec3));
        } else if (om->face_count == 0) {
            continue;
        } else {
            r = build_mesh(c, om, &s->meshes[out].mesh);
            if (r != AK_OK) break;
        }
        ak_scene_mesh* sm = &s->meshes[out++];
        sm->node = joint_of_node[1 + om->object];
        sm->skin = -1;
        const ob_material* mat = om->material[0] ? find_material(c, om->material) : NULL;
        sm->has_material = mat != NULL;
        if (mat) sm->base_color = mat->color;
        if (mat && !points && tex_of[mat - c->materials] >= 0 && s->textures[tex_of[mat - c->materials]].pixels &&
            sm->mesh->uvs)
            sm->texture = tex_of[mat - c->materials];
        if (points) break;
    }
    akp_free(c->alloc, tex_of);
done:
    akp_free(c->alloc, nodes);
    akp_free(c->alloc, joint_of_node);
    if (r != AK_OK) {
        ak_scene_destroy(s);
        return r;
    }
    *out_scene = s;
    return AK_OK;
}

/* ---- internal entry ------------------------------------------------------------------- */

ak_result akp_io_load_obj(const uint8_t* data, size_t size, const char* name, const char* base_dir,
                          const ak_io_desc* desc, const ak_allocator* alloc, ak_scene** out_scene, ak_diag* diag) {
    ob_ctx* c = (ob_ctx*)calloc(1, sizeof(ob_ctx));
    if (!c) {
        akp_diag_set(diag, name, "out of memory");
        return AK_ERR_NO_MEMORY;
    }
    c->alloc = alloc;
    c->desc = desc;
    c->name = name;
    c->base_dir = base_dir;
    c->diag = diag;
    c->budget = akp_io_budget(desc, size);
    akp_budget_take(&c->budget, 1, size); /* the text itself */
    const char* text = (const char*)data;
    if (size >= 3 && memcmp(text, "\xEF\xBB\xBF", 3) == 0) text += 3, size -= 3; /* UTF-8 byte order mark */
    ak_result r = count_pass(c, text, size);
    if (r == AK_OK) r = alloc_arrays(c);
    if (r == AK_OK) r = parse_pass(c, text, size);
    if (r == AK_OK) r = build_scene(c, out_scene);
    akp_free(alloc, c->pos);
    akp_free(alloc, c->tex);
    akp_free(alloc, c->nrm);
    akp_free(alloc, c->corners);
    akp_free(alloc, c->face_size);
    akp_free(alloc, c->meshes);
    akp_free(alloc, (void*)c->objects);
    akp_free(alloc, c->materials);
    free(c);
    return r;
}

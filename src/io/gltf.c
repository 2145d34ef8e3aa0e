/* glTF 2.0 reader (.gltf and .glb) on cJSON, following the specification's rules for
 * buffers, accessors (byteStride, sparse, normalized integers, matrix column padding),
 * nodes, meshes, skins and animations. Every failure names the file and the element. */
#ifndef _XOPEN_SOURCE
#define _XOPEN_SOURCE 700 /* realpath */
#endif
#include <cjson/cJSON.h> /* Debian libcjson-dev; see io.h for why glTF does not use Assimp */
#include <limits.h>
#include <stdarg.h>
#include <stdlib.h>

#include "io_internal.h"

/* ---- private types ------------------------------------------------------------------- */

enum {
    GL_BYTE = 5120,
    GL_UNSIGNED_BYTE = 5121,
    GL_SHORT = 5122,
    GL_UNSIGNED_SHORT = 5123,
    GL_UNSIGNED_INT = 5125,
    GL_FLOAT = 5126,
};

typedef struct gl_buffer {
    const uint8_t* data;
    size_t size;
    uint8_t* owned; /* decoded data: URI or external file */
} gl_buffer;

/* A resolved accessor: where element i component k lives. */
typedef struct gl_acc {
    size_t count;
    uint32_t comps;       /* components per element */
    uint32_t rows;        /* rows per matrix column (comps for non-matrices) */
    int ctype;            /* GL_* */
    size_t csize;         /* bytes per component */
    size_t col_stride;    /* bytes between matrix columns (padded to 4) */
    size_t elem_size;     /* bytes per element */
    bool normalized;
    const uint8_t* base;  /* NULL -> zeros */
    size_t stride;
    size_t sparse_count;
    const uint8_t* sparse_idx;
    int sparse_idx_type;
    const uint8_t* sparse_val;
} gl_acc;

/* cJSON_GetArrayItem walks a linked list; the big arrays are indexed through a table. */
typedef struct gl_table {
    const cJSON** items;
    size_t count;
} gl_table;

typedef struct gl_ctx {
    const ak_allocator* alloc;
    const ak_io_desc* desc;
    const char* name;
    const char* base_dir;
    ak_diag* diag;
    cJSON* root;
    cJSON *accessors, *views, *buffers, *nodes, *meshes, *skins, *animations;
    size_t n_acc, n_views, n_buffers, n_nodes, n_meshes, n_skins, n_anims;
    gl_table t_acc, t_views, t_buffers;
    gl_buffer* bufs;
    const uint8_t* glb_bin;
    size_t glb_bin_size;
    bool has_glb_bin;
    int32_t* joint_of_node;  /* [n_nodes] */
    int32_t* node_parent;    /* [n_nodes] */
    size_t* morph_base;      /* [scene mesh count] first morph weight index */
    ak_scene* scene;
    akp_budget budget;
} gl_ctx;

/* ---- static helpers: errors and JSON --------------------------------------------------- */

#if defined(__GNUC__)
__attribute__((format(printf, 3, 4)))
#endif
static ak_result fail(gl_ctx* c, ak_result r, const char* fmt, ...) {
    if (c->diag) {
        memset(c->diag, 0, sizeof *c->diag);
        c->diag->byte_offset = -1;
        snprintf(c->diag->path, sizeof c->diag->path, "%s", c->name);
        va_list ap;
        va_start(ap, fmt);
        vsnprintf(c->diag->message, sizeof c->diag->message, fmt, ap);
        va_end(ap);
        akp_io_sanitize(c->diag->path, sizeof c->diag->path);
        akp_io_sanitize(c->diag->message, sizeof c->diag->message);
    }
    return r;
}

static void warn(gl_ctx* c, const char* msg) {
    char buf[600];
    snprintf(buf, sizeof buf, "%s: %s", c->name, msg);
    akp_log(&c->desc->logger, AK_LOG_WARN, buf);
}

#define NO_LIMIT ((size_t)-1)

/* Charge n elements of size bytes to the load's memory budget before allocating them. */
static ak_result charge(gl_ctx* c, size_t n, size_t size, const char* what) {
    if (akp_budget_take(&c->budget, n, size)) return AK_OK;
    return fail(c, AK_ERR_UNSUPPORTED,
                "%s: %zu x %zu bytes would exceed the memory budget of %zu bytes (%zu already used; "
                "ak_io_desc.memory_budget)",
                what, n, size, c->budget.limit, c->budget.used);
}

#define TRY(expr)                                                                          \
    do {                                                                                   \
        ak_result tr_ = (expr);                                                            \
        if (tr_ != AK_OK) return tr_;                                                      \
    } while (0)

/* Optional array member: absent -> NULL/0; present but not an array -> AK_ERR_PARSE. */
static ak_result opt_array(gl_ctx* c, const cJSON* obj, const char* key, const char* where, cJSON** out,
                           size_t* out_count) {
    cJSON* a = cJSON_GetObjectItemCaseSensitive(obj, key);
    *out = NULL;
    if (out_count) *out_count = 0;
    if (!a) return AK_OK;
    if (!cJSON_IsArray(a)) return fail(c, AK_ERR_PARSE, "%s.%s is not an array", where, key);
    *out = a;
    if (out_count) *out_count = (size_t)cJSON_GetArraySize(a);
    return AK_OK;
}

/* A non-negative integer number. */
static bool as_uint(const cJSON* v, size_t* out) {
    if (!cJSON_IsNumber(v)) return false;
    double d = v->valuedouble;
    if (!(d >= 0.0) || d > 9007199254740992.0 || d != (double)(uint64_t)d) return false;
    *out = (size_t)d;
    return true;
}

/* Integer member: absent -> *out = dflt and AK_OK unless required (AK_ERR_PARSE); not a
 * non-negative integer -> AK_ERR_PARSE; >= limit -> AK_ERR_BAD_INDEX (NO_LIMIT: any value; a limit
 * of 0, an empty array, rejects every index). */
static ak_result get_uint(gl_ctx* c, const cJSON* obj, const char* key, const char* where, bool required,
                          size_t dflt, size_t limit, size_t* out) {
    const cJSON* v = cJSON_GetObjectItemCaseSensitive(obj, key);
    *out = dflt;
    if (!v) return required ? fail(c, AK_ERR_PARSE, "%s.%s is required", where, key) : AK_OK;
    if (!as_uint(v, out)) return fail(c, AK_ERR_PARSE, "%s.%s must be a non-negative integer", where, key);
    if (*out >= limit)
        return fail(c, AK_ERR_BAD_INDEX, "%s.%s = %zu is out of range (only %zu)", where, key, *out, limit);
    return AK_OK;
}

/* Index member that is optional: absent -> *out = -1. */
static ak_result get_opt_index(gl_ctx* c, const cJSON* obj, const char* key, const char* where, size_t limit,
                               int64_t* out) {
    size_t v = 0;
    *out = -1;
    if (!cJSON_GetObjectItemCaseSensitive(obj, key)) return AK_OK;
    if (limit == 0)
        return fail(c, AK_ERR_BAD_INDEX, "%s.%s refers to an element of an empty or missing array", where, key);
    TRY(get_uint(c, obj, key, where, true, 0, limit, &v));
    *out = (int64_t)v;
    return AK_OK;
}

/* Fixed-length number array member (translation, rotation, scale, matrix). */
static ak_result get_floats(gl_ctx* c, const cJSON* obj, const char* key, const char* where, size_t n, float* out,
                            bool* out_present) {
    const cJSON* a = cJSON_GetObjectItemCaseSensitive(obj, key);
    if (out_present) *out_present = a != NULL;
    if (!a) return AK_OK;
    if (!cJSON_IsArray(a) || (size_t)cJSON_GetArraySize(a) != n)
        return fail(c, AK_ERR_PARSE, "%s.%s must be an array of %zu numbers", where, key, n);
    size_t i = 0;
    for (const cJSON* e = a->child; e; e = e->next, ++i) {
        if (!cJSON_IsNumber(e)) return fail(c, AK_ERR_PARSE, "%s.%s[%zu] is not a number", where, key, i);
        float f = (float)e->valuedouble;
        if (!ak_finitef(f)) return fail(c, AK_ERR_BAD_DATA, "%s.%s[%zu] is not finite", where, key, i);
        out[i] = f;
    }
    return AK_OK;
}

static const char* get_string(const cJSON* obj, const char* key) {
    const cJSON* v = cJSON_GetObjectItemCaseSensitive(obj, key);
    return cJSON_IsString(v) ? v->valuestring : NULL;
}


/* A name that becomes a joint, mesh, skin, clip or morph target name must be valid UTF-8
 * without control bytes (cJSON passes both through: raw bytes, and \u escapes such as
 * \u001b): it reaches terminals, JSON reports and the glTF writer. */
static ak_result check_name(gl_ctx* c, const char* name, const char* what, size_t i, const char* field) {
    if (!name) return AK_OK;
    size_t n = strlen(name);
    if (!akp_io_utf8_valid(name, n))
        return fail(c, AK_ERR_PARSE, "%s[%zu].%s is not valid UTF-8", what, i, field);
    for (size_t k = 0; k < n; ++k)
        if ((unsigned char)name[k] < 0x20 || name[k] == 0x7F)
            return fail(c, AK_ERR_PARSE, "%s[%zu].%s holds a control character (byte %zu)", what, i, field, k);
    return AK_OK;
}

static ak_result check_names(gl_ctx* c, const cJSON* a, const char* what) {
    size_t i = 0;
    for (const cJSON* e = a ? a->child : NULL; e; e = e->next, ++i) {
        TRY(check_name(c, get_string(e, "name"), what, i, "name"));
        const cJSON* extras = cJSON_GetObjectItemCaseSensitive(e, "extras");
        const cJSON* names = cJSON_IsObject(extras) ? cJSON_GetObjectItemCaseSensitive(extras, "targetNames") : NULL;
        for (const cJSON* t = cJSON_IsArray(names) ? names->child : NULL; t; t = t->next)
            if (cJSON_IsString(t)) TRY(check_name(c, t->valuestring, what, i, "extras.targetNames"));
    }
    return AK_OK;
}

/* Elements of a top-level array must be objects. */
static ak_result check_objects(gl_ctx* c, const cJSON* a, const char* what) {
    size_t i = 0;
    for (const cJSON* e = a ? a->child : NULL; e; e = e->next, ++i)
        if (!cJSON_IsObject(e)) return fail(c, AK_ERR_PARSE, "%s[%zu] is not an object", what, i);
    return AK_OK;
}


static ak_result make_table(gl_ctx* c, const cJSON* a, size_t n, gl_table* t) {
    t->count = n;
    t->items = NULL;
    if (n == 0) return AK_OK;
    t->items = (const cJSON**)akp_alloc(c->alloc, n * sizeof(cJSON*));
    if (!t->items) return fail(c, AK_ERR_NO_MEMORY, "out of memory");
    size_t i = 0;
    for (const cJSON* e = a->child; e && i < n; e = e->next) t->items[i++] = e;
    return AK_OK;
}

/* ---- static helpers: buffers ---------------------------------------------------------- */

static int b64_value(uint8_t ch) {
    if (ch >= 'A' && ch <= 'Z') return ch - 'A';
    if (ch >= 'a' && ch <= 'z') return ch - 'a' + 26;
    if (ch >= '0' && ch <= '9') return ch - '0' + 52;
    if (ch == '+' || ch == '-') return 62; /* '-' and '_': the URL-safe alphabet */
    if (ch == '/' || ch == '_') return 63;
    return -1;
}

/* Strict base64 (padding optional at the very end). */
static ak_result b64_decode(gl_ctx* c, const char* s, size_t n, const char* what, uint8_t** out, size_t* out_size) {
    while (n > 0 && s[n - 1] == '=') --n;
    if (n % 4 == 1) return fail(c, AK_ERR_PARSE, "%s: base64 data has a bad length", what);
    size_t size = n / 4 * 3 + (n % 4 ? n % 4 - 1 : 0);
    TRY(charge(c, size + 1, 1, what));
    uint8_t* d = (uint8_t*)akp_alloc(c->alloc, size + 1);
    if (!d) return fail(c, AK_ERR_NO_MEMORY, "%s: out of memory decoding %zu bytes", what, size);
    uint32_t acc = 0;
    int bits = 0;
    size_t o = 0;
    for (size_t i = 0; i < n; ++i) {
        int v = b64_value((uint8_t)s[i]);
        if (v < 0) {
            akp_free(c->alloc, d);
            return fail(c, AK_ERR_PARSE, "%s: invalid base64 character at position %zu", what, i);
        }
        acc = (acc << 6) | (uint32_t)v;
        bits += 6;
        if (bits >= 8) {
            bits -= 8;
            d[o++] = (uint8_t)(acc >> bits);
        }
    }
    *out = d;
    *out_size = o;
    return AK_OK;
}

static int hex_value(char ch) {
    if (ch >= '0' && ch <= '9') return ch - '0';
    if (ch >= 'a' && ch <= 'f') return ch - 'a' + 10;
    if (ch >= 'A' && ch <= 'F') return ch - 'A' + 10;
    return -1;
}

/* An external URI -> a canonical path (percent-decoded, relative to base_dir, "..", "." and
 * symlinks resolved) that must lie inside base_dir or one of desc->extra_roots unless
 * desc->allow_any_path. A URI that leaves them gets one message, whatever exists there
 * (akp_io_resolve_inside looks at nothing outside), and never the resolved path. */
static ak_result resolve_uri(gl_ctx* c, const char* uri, const char* where, char out[PATH_MAX]) {
    char path[PATH_MAX];
    size_t o = 0;
    for (const char* p = uri; *p; ++p) {
        char ch = *p;
        if (*p == '%' && hex_value(p[1]) >= 0 && hex_value(p[2]) >= 0) {
            ch = (char)(hex_value(p[1]) * 16 + hex_value(p[2]));
            p += 2;
        }
        if (ch == 0) return fail(c, AK_ERR_IO, "%s: uri '%.200s' decodes to a NUL byte", where, uri);
        if (o + 1 >= sizeof path) return fail(c, AK_ERR_IO, "%s: uri '%.200s' is too long", where, uri);
        path[o++] = ch;
    }
    path[o] = 0;
    bool leaves = false;
    if (akp_io_resolve_inside(c->base_dir, path, c->desc, out, PATH_MAX, &leaves) == AK_OK) return AK_OK;
    if (leaves)
        return fail(c, AK_ERR_IO,
                    "%s: uri '%.200s' leaves the model's folder (allow it with ak_io_desc.extra_roots or "
                    "allow_any_path)",
                    where, uri);
    return fail(c, AK_ERR_IO, "%s: uri '%.200s': cannot open '%.200s' in the model's folder", where, uri, path);
}

static ak_result load_buffer(gl_ctx* c, size_t bi) {
    const cJSON* b = c->t_buffers.items[bi];
    char where[160];
    snprintf(where, sizeof where, "buffers[%zu]", bi);
    size_t len = 0;
    TRY(get_uint(c, b, "byteLength", where, true, 0, NO_LIMIT, &len));
    if (len == 0) return fail(c, AK_ERR_PARSE, "%s.byteLength must be at least 1", where);
    const cJSON* uri_item = cJSON_GetObjectItemCaseSensitive(b, "uri");
    gl_buffer* gb = &c->bufs[bi];
    if (!uri_item) {
        if (bi != 0 || !c->has_glb_bin)
            return fail(c, AK_ERR_PARSE, "%s has no uri and is not the GLB binary chunk", where);
        gb->data = c->glb_bin;
        gb->size = c->glb_bin_size;
    } else {
        if (!cJSON_IsString(uri_item)) return fail(c, AK_ERR_PARSE, "%s.uri is not a string", where);
        const char* uri = uri_item->valuestring;
        if (strncmp(uri, "data:", 5) == 0) {
            const char* comma = strchr(uri, ',');
            if (!comma || comma - uri < 12 || strncmp(comma - 7, ";base64", 7) != 0)
                return fail(c, AK_ERR_UNSUPPORTED, "%s: only base64 data: URIs are supported", where);
            TRY(b64_decode(c, comma + 1, strlen(comma + 1), where, &gb->owned, &gb->size));
        } else {
            if (!c->base_dir)
                return fail(c, AK_ERR_IO, "%s: external buffer '%.200s' needs a base directory", where, uri);
            char path[PATH_MAX];
            TRY(resolve_uri(c, uri, where, path));
            ak_diag sub;
            ak_result r = akp_io_read_file(path, c->alloc, len, &c->budget, &gb->owned, &gb->size, &sub);
            if (r != AK_OK) return fail(c, r, "%s: uri '%.200s': %s", where, uri, sub.message);
        }
        gb->data = gb->owned;
    }
    if (gb->size < len)
        return fail(c, AK_ERR_PARSE, "%s.byteLength is %zu but only %zu bytes of data are present", where, len,
                    gb->size);
    gb->size = len;
    return AK_OK;
}

/* ---- static helpers: accessors --------------------------------------------------------- */

static size_t ctype_size(int t) {
    switch (t) {
    case GL_BYTE:
    case GL_UNSIGNED_BYTE: return 1;
    case GL_SHORT:
    case GL_UNSIGNED_SHORT: return 2;
    case GL_UNSIGNED_INT:
    case GL_FLOAT: return 4;
    default: return 0;
    }
}

/* Bytes [offset, offset + length) of bufferView vi, checked against its buffer. */
static ak_result view_range(gl_ctx* c, size_t vi, const char* who, const uint8_t** out_ptr, size_t* out_len,
                            size_t* out_stride) {
    const cJSON* v = c->t_views.items[vi];
    char where[160];
    snprintf(where, sizeof where, "bufferViews[%zu]", vi);
    size_t bi = 0, off = 0, len = 0, stride = 0;
    TRY(get_uint(c, v, "buffer", where, true, 0, c->n_buffers, &bi));
    TRY(get_uint(c, v, "byteOffset", where, false, 0, NO_LIMIT, &off));
    TRY(get_uint(c, v, "byteLength", where, true, 0, NO_LIMIT, &len));
    TRY(get_uint(c, v, "byteStride", where, false, 0, NO_LIMIT, &stride));
    if (len == 0) return fail(c, AK_ERR_PARSE, "%s.byteLength must be at least 1", where);
    if (cJSON_GetObjectItemCaseSensitive(v, "byteStride") && (stride < 4 || stride > 252 || stride % 4))
        return fail(c, AK_ERR_PARSE, "%s.byteStride %zu must be a multiple of 4 in [4, 252]", where, stride);
    if (!c->bufs[bi].data) TRY(load_buffer(c, bi));
    if (off > c->bufs[bi].size || len > c->bufs[bi].size - off)
        return fail(c, AK_ERR_BAD_INDEX, "%s (used by %s): bytes [%zu, %zu) exceed buffers[%zu] of %zu bytes", where,
                    who, off, off + len, bi, c->bufs[bi].size);
    *out_ptr = c->bufs[bi].data + off;
    *out_len = len;
    if (out_stride) *out_stride = stride;
    return AK_OK;
}

static ak_result resolve_accessor(gl_ctx* c, size_t ai, gl_acc* a) {
    memset(a, 0, sizeof *a);
    const cJSON* j = c->t_acc.items[ai];
    char where[160];
    snprintf(where, sizeof where, "accessors[%zu]", ai);
    size_t ctype = 0, off = 0;
    TRY(get_uint(c, j, "componentType", where, true, 0, NO_LIMIT, &ctype));
    TRY(get_uint(c, j, "count", where, true, 0, NO_LIMIT, &a->count));
    TRY(get_uint(c, j, "byteOffset", where, false, 0, NO_LIMIT, &off));
    a->ctype = (int)ctype;
    a->csize = ctype_size(a->ctype);
    if (a->csize == 0) return fail(c, AK_ERR_PARSE, "%s.componentType %zu is not a glTF component type", where, ctype);
    if (a->count == 0) return fail(c, AK_ERR_PARSE, "%s.count must be at least 1", where);
    if (a->count > AKP_IO_MAX_ELEMENTS)
        return fail(c, AK_ERR_UNSUPPORTED, "%s.count %zu is above the supported %u", where, a->count,
                    AKP_IO_MAX_ELEMENTS);
    const cJSON* norm = cJSON_GetObjectItemCaseSensitive(j, "normalized");
    if (norm && !cJSON_IsBool(norm)) return fail(c, AK_ERR_PARSE, "%s.normalized is not a boolean", where);
    a->normalized = cJSON_IsTrue(norm);
    if (a->normalized && (a->ctype == GL_FLOAT || a->ctype == GL_UNSIGNED_INT))
        return fail(c, AK_ERR_PARSE, "%s: normalized is only allowed for byte and short components", where);
    const char* type = get_string(j, "type");
    if (!type) return fail(c, AK_ERR_PARSE, "%s.type is required", where);
    static const struct {
        const char* name;
        uint32_t comps, rows;
    } types[] = {{"SCALAR", 1, 1}, {"VEC2", 2, 2}, {"VEC3", 3, 3}, {"VEC4", 4, 4},
                 {"MAT2", 4, 2},   {"MAT3", 9, 3}, {"MAT4", 16, 4}};
    for (size_t t = 0; t < sizeof types / sizeof types[0]; ++t)
        if (strcmp(type, types[t].name) == 0) a->comps = types[t].comps, a->rows = types[t].rows;
    if (a->comps == 0) return fail(c, AK_ERR_PARSE, "%s.type '%.40s' is not a glTF accessor type", where, type);
    a->col_stride = a->rows * a->csize;
    if (a->comps > 4 || (a->comps == 4 && a->rows == 2)) /* matrix: columns start 4-byte aligned */
        a->col_stride = (a->col_stride + 3) & ~(size_t)3;
    a->elem_size = a->col_stride * (a->comps / a->rows);
    if (a->comps == a->rows) a->elem_size = a->comps * a->csize;

    int64_t vi = -1;
    TRY(get_opt_index(c, j, "bufferView", where, c->n_views, &vi));
    if (vi >= 0) {
        const uint8_t* p = NULL;
        size_t len = 0, stride = 0;
        TRY(view_range(c, (size_t)vi, where, &p, &len, &stride));
        a->stride = stride ? stride : a->elem_size;
        if (a->stride < a->elem_size)
            return fail(c, AK_ERR_PARSE, "%s: byteStride %zu is smaller than an element (%zu bytes)", where, a->stride,
                        a->elem_size);
        /* (count - 1) * stride + elem_size, checked for overflow (count < 2^26, stride <= 252) */
        size_t need = (a->count - 1) * a->stride + a->elem_size;
        if (off > len || need > len - off)
            return fail(c, AK_ERR_BAD_INDEX, "%s: %zu elements at byteOffset %zu need %zu bytes, bufferViews[%lld] has %zu",
                        where, a->count, off, need, (long long)vi, len);
        a->base = p + off;
    } else if (off) {
        return fail(c, AK_ERR_PARSE, "%s has byteOffset but no bufferView", where);
    }

    const cJSON* sp = cJSON_GetObjectItemCaseSensitive(j, "sparse");
    if (sp) {
        char sw[200];
        snprintf(sw, sizeof sw, "%s.sparse", where);
        if (!cJSON_IsObject(sp)) return fail(c, AK_ERR_PARSE, "%s is not an object", sw);
        TRY(get_uint(c, sp, "count", sw, true, 0, NO_LIMIT, &a->sparse_count));
        if (a->sparse_count == 0 || a->sparse_count > a->count)
            return fail(c, AK_ERR_PARSE, "%s.count %zu must be in [1, %zu]", sw, a->sparse_count, a->count);
        const cJSON* idx = cJSON_GetObjectItemCaseSensitive(sp, "indices");
        const cJSON* val = cJSON_GetObjectItemCaseSensitive(sp, "values");
        if (!cJSON_IsObject(idx) || !cJSON_IsObject(val))
            return fail(c, AK_ERR_PARSE, "%s needs indices and values objects", sw);
        char iw[256], vw[256];
        snprintf(iw, sizeof iw, "%s.indices", sw);
        snprintf(vw, sizeof vw, "%s.values", sw);
        size_t ivi = 0, ioff = 0, ict = 0, vvi = 0, voff = 0;
        TRY(get_uint(c, idx, "bufferView", iw, true, 0, c->n_views, &ivi));
        TRY(get_uint(c, idx, "byteOffset", iw, false, 0, NO_LIMIT, &ioff));
        TRY(get_uint(c, idx, "componentType", iw, true, 0, NO_LIMIT, &ict));
        TRY(get_uint(c, val, "bufferView", vw, true, 0, c->n_views, &vvi));
        TRY(get_uint(c, val, "byteOffset", vw, false, 0, NO_LIMIT, &voff));
        if (ict != GL_UNSIGNED_BYTE && ict != GL_UNSIGNED_SHORT && ict != GL_UNSIGNED_INT)
            return fail(c, AK_ERR_PARSE, "%s.componentType must be an unsigned integer type", iw);
        a->sparse_idx_type = (int)ict;
        const uint8_t* p = NULL;
        size_t len = 0;
        TRY(view_range(c, ivi, iw, &p, &len, NULL));
        size_t need = a->sparse_count * ctype_size((int)ict);
        if (ioff > len || need > len - ioff)
            return fail(c, AK_ERR_BAD_INDEX, "%s: %zu indices need %zu bytes past byteOffset %zu, the view has %zu", iw,
                        a->sparse_count, need, ioff, len);
        a->sparse_idx = p + ioff;
        TRY(view_range(c, vvi, vw, &p, &len, NULL));
        need = a->sparse_count * a->elem_size;
        if (voff > len || need > len - voff)
            return fail(c, AK_ERR_BAD_INDEX, "%s: %zu values need %zu bytes past byteOffset %zu, the view has %zu", vw,
                        a->sparse_count, need, voff, len);
        a->sparse_val = p + voff;
    }
    return AK_OK;
}

/* Little-endian loads through bytes: no alignment or host byte order assumed. */
static uint32_t load_u32(const uint8_t* p) {
    return (uint32_t)p[0] | (uint32_t)p[1] << 8 | (uint32_t)p[2] << 16 | (uint32_t)p[3] << 24;
}

static double load_component(const gl_acc* a, const uint8_t* p) {
    switch (a->ctype) {
    case GL_BYTE: {
        double v = (double)(int8_t)p[0];
        return a->normalized ? (v / 127.0 < -1.0 ? -1.0 : v / 127.0) : v;
    }
    case GL_UNSIGNED_BYTE: return a->normalized ? p[0] / 255.0 : (double)p[0];
    case GL_SHORT: {
        double v = (double)(int16_t)(uint16_t)(p[0] | p[1] << 8);
        return a->normalized ? (v / 32767.0 < -1.0 ? -1.0 : v / 32767.0) : v;
    }
    case GL_UNSIGNED_SHORT: {
        double v = (double)(uint16_t)(p[0] | p[1] << 8);
        return a->normalized ? v / 65535.0 : v;
    }
    case GL_UNSIGNED_INT: return (double)load_u32(p);
    default: {
        uint32_t u = load_u32(p);
        float f;
        memcpy(&f, &u, sizeof f);
        return (double)f;
    }
    }
}

static void load_element(const gl_acc* a, const uint8_t* elem, double* out) {
    for (uint32_t k = 0; k < a->comps; ++k)
        out[k] = load_component(a, elem + (k / a->rows) * a->col_stride + (k % a->rows) * a->csize);
}

/* Every element as doubles, sparse substitution applied: out[count * comps]. */
static ak_result read_accessor(gl_ctx* c, size_t ai, gl_acc* a, double** out) {
    *out = NULL;
    TRY(resolve_accessor(c, ai, a));
    char what[64];
    snprintf(what, sizeof what, "accessors[%zu]", ai);
    /* count * comps doubles now, then as many floats or u32 in the caller's copy */
    TRY(charge(c, a->count * a->comps, sizeof(double) + sizeof(float), what));
    double* d = (double*)akp_alloc(c->alloc, a->count * a->comps * sizeof(double));
    if (!d) return fail(c, AK_ERR_NO_MEMORY, "accessors[%zu]: out of memory for %zu elements", ai, a->count);
    for (size_t i = 0; i < a->count; ++i) {
        if (a->base) load_element(a, a->base + i * a->stride, d + i * a->comps);
        else
            for (uint32_t k = 0; k < a->comps; ++k) d[i * a->comps + k] = 0.0;
    }
    size_t isz = ctype_size(a->sparse_idx_type);
    size_t prev = 0;
    for (size_t s = 0; s < a->sparse_count; ++s) {
        const uint8_t* p = a->sparse_idx + s * isz;
        size_t idx = isz == 1 ? p[0] : isz == 2 ? (size_t)(p[0] | p[1] << 8) : (size_t)load_u32(p);
        if (idx >= a->count || (s > 0 && idx <= prev)) {
            akp_free(c->alloc, d);
            return fail(c, idx >= a->count ? AK_ERR_BAD_INDEX : AK_ERR_PARSE,
                        "accessors[%zu].sparse index %zu (entry %zu) is out of range or not increasing", ai, idx, s);
        }
        prev = idx;
        load_element(a, a->sparse_val + s * a->elem_size, d + idx * a->comps);
    }
    *out = d;
    return AK_OK;
}

/* Float data of an accessor whose component count must be one of allowed (0-terminated);
 * non-finite values -> AK_ERR_BAD_DATA. */
static ak_result read_floats(gl_ctx* c, size_t ai, const char* what, const uint32_t* allowed, float** out,
                             gl_acc* a) {
    double* d = NULL;
    *out = NULL;
    TRY(read_accessor(c, ai, a, &d));
    bool ok = false;
    for (const uint32_t* p = allowed; *p; ++p) ok = ok || *p == a->comps;
    if (!ok) {
        akp_free(c->alloc, d);
        return fail(c, AK_ERR_PARSE, "accessors[%zu] (%s) has %u components per element", ai, what, a->comps);
    }
    size_t n = a->count * a->comps;
    float* f = (float*)akp_alloc(c->alloc, n * sizeof(float));
    if (!f) {
        akp_free(c->alloc, d);
        return fail(c, AK_ERR_NO_MEMORY, "accessors[%zu]: out of memory", ai);
    }
    for (size_t i = 0; i < n; ++i) {
        f[i] = (float)d[i];
        if (!ak_finitef(f[i])) {
            akp_free(c->alloc, d);
            akp_free(c->alloc, f);
            return fail(c, AK_ERR_BAD_DATA, "accessors[%zu] (%s): element %zu component %zu is not finite", ai, what,
                        i / a->comps, i % a->comps);
        }
    }
    akp_free(c->alloc, d);
    *out = f;
    return AK_OK;
}

/* Unsigned integer data (indices, joints): component type must be an unsigned integer and
 * not normalized. */
static ak_result read_uints(gl_ctx* c, size_t ai, const char* what, uint32_t comps, uint32_t** out, gl_acc* a) {
    double* d = NULL;
    *out = NULL;
    TRY(read_accessor(c, ai, a, &d));
    if (a->comps != comps || a->normalized ||
        (a->ctype != GL_UNSIGNED_BYTE && a->ctype != GL_UNSIGNED_SHORT && a->ctype != GL_UNSIGNED_INT)) {
        akp_free(c->alloc, d);
        return fail(c, AK_ERR_PARSE, "accessors[%zu] (%s) must hold %u unsigned integer component(s)", ai, what, comps);
    }
    size_t n = a->count * a->comps;
    uint32_t* u = (uint32_t*)akp_alloc(c->alloc, n * sizeof(uint32_t));
    if (!u) {
        akp_free(c->alloc, d);
        return fail(c, AK_ERR_NO_MEMORY, "accessors[%zu]: out of memory", ai);
    }
    for (size_t i = 0; i < n; ++i) u[i] = (uint32_t)d[i];
    akp_free(c->alloc, d);
    *out = u;
    return AK_OK;
}

/* ---- static helpers: document ---------------------------------------------------------- */

static ak_result parse_glb(gl_ctx* c, const uint8_t* data, size_t size, const char** json, size_t* json_size) {
    if (size < 12) return fail(c, AK_ERR_PARSE, "GLB: truncated header (%zu bytes)", size);
    uint32_t version = load_u32(data + 4), length = load_u32(data + 8);
    if (version != 2) return fail(c, AK_ERR_UNSUPPORTED, "GLB: container version %u (only 2 is supported)", version);
    if (length != size)
        return fail(c, AK_ERR_PARSE, "GLB: header says %u bytes but the data has %zu (truncated?)", length, size);
    size_t pos = 12;
    bool have_json = false;
    for (int chunk = 0; pos < size; ++chunk) {
        if (size - pos < 8) return fail(c, AK_ERR_PARSE, "GLB: truncated chunk header at byte %zu", pos);
        uint32_t clen = load_u32(data + pos), ctype = load_u32(data + pos + 4);
        if (clen > size - pos - 8)
            return fail(c, AK_ERR_PARSE, "GLB: chunk %d of %u bytes at byte %zu runs past the end", chunk, clen, pos);
        const uint8_t* body = data + pos + 8;
        if (chunk == 0) {
            if (ctype != 0x4E4F534Au) return fail(c, AK_ERR_PARSE, "GLB: the first chunk is not JSON");
            *json = (const char*)body;
            *json_size = clen;
            have_json = true;
        } else if (chunk == 1 && ctype == 0x004E4942u) {
            c->glb_bin = body;
            c->glb_bin_size = clen;
            c->has_glb_bin = true;
        }
        pos += 8 + (size_t)clen;
    }
    if (!have_json) return fail(c, AK_ERR_PARSE, "GLB: no JSON chunk");
    return AK_OK;
}

static bool extension_harmless(const char* e) {
    static const char* const prefixes[] = {"KHR_materials_", "KHR_texture_", "KHR_mesh_quantization",
                                           "KHR_lights_punctual", "EXT_texture_"};
    for (size_t i = 0; i < sizeof prefixes / sizeof prefixes[0]; ++i)
        if (strncmp(e, prefixes[i], strlen(prefixes[i])) == 0) return true;
    return false;
}

static ak_result check_header(gl_ctx* c) {
    const cJSON* asset = cJSON_GetObjectItemCaseSensitive(c->root, "asset");
    if (!cJSON_IsObject(asset)) return fail(c, AK_ERR_PARSE, "asset is required");
    const char* version = get_string(asset, "version");
    if (!version) return fail(c, AK_ERR_PARSE, "asset.version is required");
    if (strncmp(version, "2.", 2) != 0)
        return fail(c, AK_ERR_UNSUPPORTED, "glTF version '%.20s' (only 2.x is supported)", version);
    cJSON* req = NULL;
    TRY(opt_array(c, c->root, "extensionsRequired", "", &req, NULL));
    for (const cJSON* e = req ? req->child : NULL; e; e = e->next) {
        if (!cJSON_IsString(e)) return fail(c, AK_ERR_PARSE, "extensionsRequired holds a non-string");
        if (!extension_harmless(e->valuestring))
            return fail(c, AK_ERR_UNSUPPORTED, "required extension %.100s is not supported", e->valuestring);
    }
    struct {
        const char* key;
        cJSON** arr;
        size_t* n;
    } tops[] = {{"accessors", &c->accessors, &c->n_acc}, {"bufferViews", &c->views, &c->n_views},
                {"buffers", &c->buffers, &c->n_buffers}, {"nodes", &c->nodes, &c->n_nodes},
                {"meshes", &c->meshes, &c->n_meshes},    {"skins", &c->skins, &c->n_skins},
                {"animations", &c->animations, &c->n_anims}};
    for (size_t i = 0; i < sizeof tops / sizeof tops[0]; ++i) {
        TRY(opt_array(c, c->root, tops[i].key, "", tops[i].arr, tops[i].n));
        TRY(check_objects(c, *tops[i].arr, tops[i].key));
        if (i >= 3) TRY(check_names(c, *tops[i].arr, tops[i].key));
    }
    /* scene / scenes: validated, not used to filter (every node is loaded). */
    cJSON* scenes = NULL;
    size_t n_scenes = 0, si = 0;
    TRY(opt_array(c, c->root, "scenes", "", &scenes, &n_scenes));
    TRY(check_objects(c, scenes, "scenes"));
    if (cJSON_GetObjectItemCaseSensitive(c->root, "scene")) {
        if (n_scenes == 0) return fail(c, AK_ERR_BAD_INDEX, "scene is set but there are no scenes");
        TRY(get_uint(c, c->root, "scene", "", true, 0, n_scenes, &si));
    }
    si = 0;
    for (const cJSON* s = scenes ? scenes->child : NULL; s; s = s->next, ++si) {
        cJSON* sn = NULL;
        char where[160];
        snprintf(where, sizeof where, "scenes[%zu]", si);
        TRY(opt_array(c, s, "nodes", where, &sn, NULL));
        size_t k = 0, v = 0;
        for (const cJSON* e = sn ? sn->child : NULL; e; e = e->next, ++k) {
            if (!as_uint(e, &v)) return fail(c, AK_ERR_PARSE, "%s.nodes[%zu] is not an index", where, k);
            if (v >= c->n_nodes) return fail(c, AK_ERR_BAD_INDEX, "%s.nodes[%zu] = %zu is out of range", where, k, v);
        }
    }
    TRY(make_table(c, c->accessors, c->n_acc, &c->t_acc));
    TRY(make_table(c, c->views, c->n_views, &c->t_views));
    TRY(make_table(c, c->buffers, c->n_buffers, &c->t_buffers));
    c->bufs = (gl_buffer*)akp_calloc(c->alloc, (c->n_buffers ? c->n_buffers : 1) * sizeof(gl_buffer));
    if (!c->bufs) return fail(c, AK_ERR_NO_MEMORY, "out of memory");
    return AK_OK;
}

/* ---- static helpers: nodes and skins ---------------------------------------------------- */

static ak_result read_node_transform(gl_ctx* c, const cJSON* n, const char* where, ak_transform* out) {
    float m[16], t[3] = {0, 0, 0}, r[4] = {0, 0, 0, 1}, s[3] = {1, 1, 1};
    bool has_m = false, has_t = false, has_r = false, has_s = false;
    TRY(get_floats(c, n, "matrix", where, 16, m, &has_m));
    TRY(get_floats(c, n, "translation", where, 3, t, &has_t));
    TRY(get_floats(c, n, "rotation", where, 4, r, &has_r));
    TRY(get_floats(c, n, "scale", where, 3, s, &has_s));
    if (has_m && (has_t || has_r || has_s))
        return fail(c, AK_ERR_PARSE, "%s has both matrix and translation/rotation/scale", where);
    if (has_m) {
        ak_mat4 mm;
        memcpy(mm.m, m, sizeof m);
        *out = akp_io_decompose(mm);
        return AK_OK;
    }
    ak_quat q = ak_quat_make(r[0], r[1], r[2], r[3]);
    float len = ak_quat_norm(q);
    if (!(len > 1e-6f)) return fail(c, AK_ERR_BAD_DATA, "%s.rotation is not a unit quaternion", where);
    *out = ak_transform_make(ak_vec3_make(t[0], t[1], t[2]), ak_quat_scale(q, 1.0f / len), ak_vec3_make(s[0], s[1], s[2]));
    return AK_OK;
}

static ak_result load_nodes_and_skins(gl_ctx* c, const gl_table* nodes) {
    ak_scene* scene = c->scene;
    const ak_allocator* a = c->alloc;
    size_t n = c->n_nodes;
    akp_io_node* desc = (akp_io_node*)akp_calloc(a, (n ? n : 1) * sizeof(akp_io_node));
    const ak_mat4** ibm_of_node = (const ak_mat4**)akp_calloc(a, (n ? n : 1) * sizeof(ak_mat4*));
    c->joint_of_node = (int32_t*)akp_alloc(a, (n ? n : 1) * sizeof(int32_t));
    c->node_parent = (int32_t*)akp_alloc(a, (n ? n : 1) * sizeof(int32_t));
    ak_result r = AK_OK;
    if (!desc || !ibm_of_node || !c->joint_of_node || !c->node_parent) {
        r = fail(c, AK_ERR_NO_MEMORY, "out of memory");
        goto done;
    }
    if (n > AKP_IO_MAX_NODES) {
        r = fail(c, AK_ERR_UNSUPPORTED, "%zu nodes; at most %u are supported", n, AKP_IO_MAX_NODES);
        goto done;
    }
    for (size_t i = 0; i < n; ++i) c->node_parent[i] = -1;
    for (size_t i = 0; i < n; ++i) {
        const cJSON* node = nodes->items[i];
        char where[160];
        snprintf(where, sizeof where, "nodes[%zu]", i);
        desc[i].name = get_string(node, "name");
        if ((r = read_node_transform(c, node, where, &desc[i].rest)) != AK_OK) goto done;
        cJSON* ch = NULL;
        if ((r = opt_array(c, node, "children", where, &ch, NULL)) != AK_OK) goto done;
        size_t k = 0, v = 0;
        for (const cJSON* e = ch ? ch->child : NULL; e; e = e->next, ++k) {
            if (!as_uint(e, &v)) {
                r = fail(c, AK_ERR_PARSE, "%s.children[%zu] is not an index", where, k);
                goto done;
            }
            if (v >= n) {
                r = fail(c, AK_ERR_BAD_INDEX, "%s.children[%zu] = %zu is out of range (%zu nodes)", where, k, v, n);
                goto done;
            }
            if (c->node_parent[v] >= 0 || v == i) {
                r = fail(c, AK_ERR_BAD_HIERARCHY, "nodes[%zu] is a child of nodes[%d] and of nodes[%zu]", v,
                         c->node_parent[v], i);
                goto done;
            }
            c->node_parent[v] = (int32_t)i;
        }
    }
    for (size_t i = 0; i < n; ++i) desc[i].parent = c->node_parent[i];

    /* Skins: slots, inverse binds; the first skin naming a node gives its skeleton inverse bind. */
    if (scene->skin_count) {
        size_t si = 0;
        for (const cJSON* s = c->skins->child; s; s = s->next, ++si) {
            char where[160];
            snprintf(where, sizeof where, "skins[%zu]", si);
            cJSON* joints = NULL;
            size_t jc = 0;
            if ((r = opt_array(c, s, "joints", where, &joints, &jc)) != AK_OK) goto done;
            if (jc == 0) {
                r = fail(c, AK_ERR_PARSE, "%s.joints is required and must not be empty", where);
                goto done;
            }
            if (jc > 65535) {
                r = fail(c, AK_ERR_UNSUPPORTED, "%s has %zu joints; at most 65535 are supported", where, jc);
                goto done;
            }
            if ((r = ak_scene_skin_alloc(scene, si, jc)) != AK_OK) {
                r = fail(c, r, "%s: out of memory", where);
                goto done;
            }
            ak_scene_skin* sk = &scene->skins[si];
            akp_io_copy_name(sk->name, get_string(s, "name"));
            size_t k = 0, v = 0;
            for (const cJSON* e = joints->child; e; e = e->next, ++k) {
                if (!as_uint(e, &v)) {
                    r = fail(c, AK_ERR_PARSE, "%s.joints[%zu] is not an index", where, k);
                    goto done;
                }
                if (v >= n) {
                    r = fail(c, AK_ERR_BAD_INDEX, "%s.joints[%zu] = %zu is out of range (%zu nodes)", where, k, v, n);
                    goto done;
                }
                sk->joints[k] = (int32_t)v; /* node index for now; mapped to joints below */
            }
            int64_t ibm = -1;
            if ((r = get_opt_index(c, s, "inverseBindMatrices", where, c->n_acc, &ibm)) != AK_OK) goto done;
            if (ibm >= 0) {
                float* f = NULL;
                gl_acc acc;
                static const uint32_t mat4[] = {16, 0};
                if ((r = read_floats(c, (size_t)ibm, "inverseBindMatrices", mat4, &f, &acc)) != AK_OK) goto done;
                if (acc.count < jc || acc.ctype != GL_FLOAT) {
                    akp_free(a, f);
                    r = fail(c, AK_ERR_PARSE, "%s.inverseBindMatrices: %zu float MAT4 needed, accessor has %zu", where,
                             jc, acc.count);
                    goto done;
                }
                for (size_t j = 0; j < jc; ++j) memcpy(sk->inverse_binds[j].m, f + 16 * j, 16 * sizeof(float));
                akp_free(a, f);
            }
            for (size_t j = 0; j < jc; ++j)
                if (!ibm_of_node[sk->joints[j]]) ibm_of_node[sk->joints[j]] = &sk->inverse_binds[j];
        }
    }
    for (size_t i = 0; i < n; ++i) desc[i].inverse_bind = ibm_of_node[i];
    if ((r = akp_io_build_skeleton(scene, desc, n, c->joint_of_node, c->name, c->diag)) != AK_OK) goto done;
    for (size_t si = 0; si < scene->skin_count; ++si)
        for (size_t j = 0; j < scene->skins[si].joint_count; ++j)
            scene->skins[si].joints[j] = c->joint_of_node[scene->skins[si].joints[j]];
    if (n) { /* without skins every node is a plain node */
        scene->is_joint = (bool*)akp_calloc(a, n * sizeof(bool));
        if (!scene->is_joint) {
            r = fail(c, AK_ERR_NO_MEMORY, "out of memory");
            goto done;
        }
        for (size_t si = 0; si < scene->skin_count; ++si)
            for (size_t j = 0; j < scene->skins[si].joint_count; ++j) scene->is_joint[scene->skins[si].joints[j]] = true;
    }
done:
    akp_free(a, desc);
    akp_free(a, ibm_of_node);
    return r;
}

/* ---- static helpers: meshes ------------------------------------------------------------- */

/* Attribute accessor index or -1. */
static ak_result attribute(gl_ctx* c, const cJSON* attrs, const char* key, const char* where, int64_t* out) {
    return get_opt_index(c, attrs, key, where, c->n_acc, out);
}

typedef struct prim_data {
    size_t vertex_count;
    float *pos, *nrm, *uv, *col, *tan; /* tan: [vertex_count * 4] */
    uint32_t col_comps;
    uint32_t* idx;
    size_t idx_count;
    uint16_t* joints; /* [vertex_count * infl] */
    float* weights;
    uint32_t infl;    /* 0, 4 or 8 */
    size_t targets;
    float *mpos, *mnrm, *mtan; /* [targets * vertex_count * 3] */
    bool has_mnrm, has_mtan;
} prim_data;

static void prim_free(gl_ctx* c, prim_data* p) {
    akp_free(c->alloc, p->pos);
    akp_free(c->alloc, p->nrm);
    akp_free(c->alloc, p->uv);
    akp_free(c->alloc, p->col);
    akp_free(c->alloc, p->idx);
    akp_free(c->alloc, p->joints);
    akp_free(c->alloc, p->weights);
    akp_free(c->alloc, p->mpos);
    akp_free(c->alloc, p->mnrm);
    akp_free(c->alloc, p->tan);
    akp_free(c->alloc, p->mtan);
    memset(p, 0, sizeof *p);
}

static ak_result read_vertex_floats(gl_ctx* c, const cJSON* attrs, const char* key, const char* where,
                                    const uint32_t* allowed, size_t vertex_count, float** out, uint32_t* out_comps) {
    int64_t ai = -1;
    TRY(attribute(c, attrs, key, where, &ai));
    if (ai < 0) return AK_OK;
    gl_acc acc;
    char what[256];
    snprintf(what, sizeof what, "%s %s", where, key);
    TRY(read_floats(c, (size_t)ai, what, allowed, out, &acc));
    if (acc.count != vertex_count) {
        akp_free(c->alloc, *out);
        *out = NULL;
        return fail(c, AK_ERR_PARSE, "%s: %s has %zu elements but POSITION has %zu", where, key, acc.count,
                    vertex_count);
    }
    if (out_comps) *out_comps = acc.comps;
    return AK_OK;
}

static ak_result read_primitive(gl_ctx* c, const cJSON* prim, const char* where, prim_data* p) {
    static const uint32_t v2[] = {2, 0}, v3[] = {3, 0}, v4[] = {4, 0}, v34[] = {3, 4, 0};
    const cJSON* attrs = cJSON_GetObjectItemCaseSensitive(prim, "attributes");
    if (!cJSON_IsObject(attrs)) return fail(c, AK_ERR_PARSE, "%s.attributes is required", where);
    int64_t pa = -1;
    TRY(attribute(c, attrs, "POSITION", where, &pa));
    if (pa < 0) return fail(c, AK_ERR_UNSUPPORTED, "%s has no POSITION attribute", where);
    gl_acc acc;
    char what[256];
    snprintf(what, sizeof what, "%s POSITION", where);
    TRY(read_floats(c, (size_t)pa, what, v3, &p->pos, &acc));
    p->vertex_count = acc.count;
    size_t nv = p->vertex_count;
    TRY(read_vertex_floats(c, attrs, "NORMAL", where, v3, nv, &p->nrm, NULL));
    TRY(read_vertex_floats(c, attrs, "TEXCOORD_0", where, v2, nv, &p->uv, NULL));
    TRY(read_vertex_floats(c, attrs, "COLOR_0", where, v34, nv, &p->col, &p->col_comps));
    /* TANGENT: VEC4 (xyz, handedness w), w must be +1 or -1 (glTF 2.0 section 3.7.2.1) */
    TRY(read_vertex_floats(c, attrs, "TANGENT", where, v4, nv, &p->tan, NULL));
    for (size_t v = 0; p->tan && v < nv; ++v)
        if (fabsf(fabsf(p->tan[4 * v + 3]) - 1.0f) > 1e-3f)
            return fail(c, AK_ERR_BAD_DATA, "%s TANGENT: vertex %zu has w = %g, not +1 or -1", where, v,
                        (double)p->tan[4 * v + 3]);

    /* Skin influences: JOINTS_0/WEIGHTS_0 and, when present, JOINTS_1/WEIGHTS_1 merged. */
    int64_t ja[2], wa[2];
    for (int s = 0; s < 2; ++s) {
        char jk[16], wk[16];
        snprintf(jk, sizeof jk, "JOINTS_%d", s);
        snprintf(wk, sizeof wk, "WEIGHTS_%d", s);
        TRY(attribute(c, attrs, jk, where, &ja[s]));
        TRY(attribute(c, attrs, wk, where, &wa[s]));
        if ((ja[s] < 0) != (wa[s] < 0)) return fail(c, AK_ERR_PARSE, "%s has %s without %s", where, ja[s] < 0 ? wk : jk, ja[s] < 0 ? jk : wk);
        if (s == 1 && ja[1] >= 0 && ja[0] < 0) return fail(c, AK_ERR_PARSE, "%s has JOINTS_1 without JOINTS_0", where);
    }
    if (ja[0] >= 0) {
        p->infl = ja[1] >= 0 ? 8 : 4;
        TRY(charge(c, nv * p->infl, sizeof(uint16_t) + sizeof(float), where));
        p->joints = (uint16_t*)akp_calloc(c->alloc, nv * p->infl * sizeof(uint16_t));
        p->weights = (float*)akp_calloc(c->alloc, nv * p->infl * sizeof(float));
        if (!p->joints || !p->weights) return fail(c, AK_ERR_NO_MEMORY, "%s: out of memory", where);
        for (int s = 0; s < 2 && ja[s] >= 0; ++s) {
            uint32_t* j = NULL;
            float* w = NULL;
            snprintf(what, sizeof what, "%s JOINTS_%d", where, s);
            TRY(read_uints(c, (size_t)ja[s], what, 4, &j, &acc));
            size_t jn = acc.count;
            bool wide = acc.ctype == GL_UNSIGNED_INT;
            snprintf(what, sizeof what, "%s WEIGHTS_%d", where, s);
            ak_result r = read_floats(c, (size_t)wa[s], what, v4, &w, &acc);
            if (r == AK_OK && (jn != nv || acc.count != nv))
                r = fail(c, AK_ERR_PARSE, "%s: JOINTS_%d/WEIGHTS_%d counts differ from POSITION's %zu", where, s, s, nv);
            if (r == AK_OK && wide) r = fail(c, AK_ERR_PARSE, "%s: JOINTS_%d must be unsigned byte or short", where, s);
            if (r == AK_OK && acc.ctype != GL_FLOAT && !acc.normalized)
                r = fail(c, AK_ERR_PARSE, "%s: WEIGHTS_%d must be float or normalized", where, s);
            for (size_t v = 0; r == AK_OK && v < nv; ++v) {
                for (int k = 0; k < 4; ++k) {
                    size_t o = v * p->infl + (size_t)s * 4 + (size_t)k;
                    float wk = w[v * 4 + (size_t)k];
                    if (wk < 0.0f) {
                        r = fail(c, AK_ERR_BAD_WEIGHTS, "%s: vertex %zu has a negative weight", where, v);
                        break;
                    }
                    p->joints[o] = (uint16_t)j[v * 4 + (size_t)k];
                    p->weights[o] = wk;
                }
            }
            akp_free(c->alloc, j);
            akp_free(c->alloc, w);
            if (r != AK_OK) return r;
        }
    }

    /* Indices, converted to a triangle list. */
    size_t mode = 4;
    TRY(get_uint(c, prim, "mode", where, false, 4, 7, &mode));
    int64_t ia = -1;
    TRY(get_opt_index(c, prim, "indices", where, c->n_acc, &ia));
    uint32_t* src = NULL;
    size_t sn = nv;
    if (ia >= 0) {
        snprintf(what, sizeof what, "%s indices", where);
        TRY(read_uints(c, (size_t)ia, what, 1, &src, &acc));
        sn = acc.count;
        for (size_t i = 0; i < sn; ++i)
            if (src[i] >= nv) {
                uint32_t bad = src[i];
                akp_free(c->alloc, src);
                return fail(c, AK_ERR_BAD_INDEX, "%s: index %zu is %u but there are %zu vertices", where, i, bad, nv);
            }
    }
    size_t tris = 0;
    if (mode == 4) {
        if (sn % 3) {
            akp_free(c->alloc, src);
            return fail(c, AK_ERR_PARSE, "%s: %zu indices is not a multiple of 3", where, sn);
        }
        tris = sn / 3;
    } else if (mode == 5 || mode == 6) {
        tris = sn >= 3 ? sn - 2 : 0;
    }
    p->idx_count = tris * 3;
    if (tris) {
        ak_result cr = charge(c, p->idx_count, sizeof(uint32_t), where);
        if (cr != AK_OK) {
            akp_free(c->alloc, src);
            return cr;
        }
        p->idx = (uint32_t*)akp_alloc(c->alloc, p->idx_count * sizeof(uint32_t));
        if (!p->idx) {
            akp_free(c->alloc, src);
            return fail(c, AK_ERR_NO_MEMORY, "%s: out of memory", where);
        }
        for (size_t t = 0; t < tris; ++t) {
            size_t a0 = 3 * t, a1 = 3 * t + 1, a2 = 3 * t + 2;
            if (mode == 5) { /* strip: odd triangles swap to keep the winding */
                a0 = t;
                a1 = t % 2 ? t + 2 : t + 1;
                a2 = t % 2 ? t + 1 : t + 2;
            } else if (mode == 6) { /* fan: (i+1, i+2, 0) */
                a0 = t + 1;
                a1 = t + 2;
                a2 = 0;
            }
            p->idx[3 * t] = src ? src[a0] : (uint32_t)a0;
            p->idx[3 * t + 1] = src ? src[a1] : (uint32_t)a1;
            p->idx[3 * t + 2] = src ? src[a2] : (uint32_t)a2;
        }
    }
    akp_free(c->alloc, src);

    /* Morph targets. */
    cJSON* targets = NULL;
    TRY(opt_array(c, prim, "targets", where, &targets, &p->targets));
    if (p->targets) {
        TRY(charge(c, p->targets * nv, 9 * sizeof(float), where));
        p->mpos = (float*)akp_calloc(c->alloc, p->targets * nv * 3 * sizeof(float));
        p->mnrm = (float*)akp_calloc(c->alloc, p->targets * nv * 3 * sizeof(float));
        p->mtan = (float*)akp_calloc(c->alloc, p->targets * nv * 3 * sizeof(float));
        if (!p->mpos || !p->mnrm || !p->mtan) return fail(c, AK_ERR_NO_MEMORY, "%s: out of memory for morph targets", where);
        size_t t = 0;
        for (const cJSON* tg = targets->child; tg; tg = tg->next, ++t) {
            char tw[256];
            snprintf(tw, sizeof tw, "%s.targets[%zu]", where, t);
            if (!cJSON_IsObject(tg)) return fail(c, AK_ERR_PARSE, "%s is not an object", tw);
            float* f = NULL;
            TRY(read_vertex_floats(c, tg, "POSITION", tw, v3, nv, &f, NULL));
            if (f) memcpy(p->mpos + t * nv * 3, f, nv * 3 * sizeof(float));
            akp_free(c->alloc, f);
            f = NULL;
            TRY(read_vertex_floats(c, tg, "NORMAL", tw, v3, nv, &f, NULL));
            if (f) {
                memcpy(p->mnrm + t * nv * 3, f, nv * 3 * sizeof(float));
                p->has_mnrm = true;
            }
            akp_free(c->alloc, f);
            f = NULL;
            TRY(read_vertex_floats(c, tg, "TANGENT", tw, v3, nv, &f, NULL));
            if (f) {
                memcpy(p->mtan + t * nv * 3, f, nv * 3 * sizeof(float));
                p->has_mtan = true;
            }
            akp_free(c->alloc, f);
        }
    }
    return AK_OK;
}

/* Make an ak_mesh from primitive data (skin slot checks are done per instance). */
static ak_result make_mesh(gl_ctx* c, prim_data* p, const char* name, const cJSON* mesh_json, const char* where,
                           ak_mesh** out) {
    ak_mesh_desc d = {
        .vertex_count = p->vertex_count,
        .triangle_count = p->idx_count / 3,
        .influence_count = p->infl ? (p->infl < c->desc->max_influences ? p->infl : c->desc->max_influences) : 0,
        .morph_target_count = p->targets,
        .has_normals = p->nrm != NULL,
        .has_uvs = p->uv != NULL,
        .has_colors = p->col != NULL,
        .has_morph_normals = p->has_mnrm,
        .name = name,
        .has_tangents = p->tan != NULL,
        .has_morph_tangents = p->has_mtan,
    };
    /* every instance is a full copy: charge what ak_mesh_create will allocate */
    size_t per_vertex = sizeof(ak_vec3) * (2 + 3 * p->targets) + sizeof(ak_vec2) + 2 * sizeof(ak_vec4) +
                        d.influence_count * (sizeof(uint16_t) + sizeof(float));
    TRY(charge(c, p->vertex_count, per_vertex, where));
    TRY(charge(c, p->idx_count, sizeof(uint32_t), where));
    ak_mesh* m = NULL;
    ak_result r = ak_mesh_create(&d, c->alloc, &m);
    if (r != AK_OK) return fail(c, r, "%s: cannot create a mesh of %zu vertices", where, p->vertex_count);
    size_t nv = p->vertex_count;
    for (size_t v = 0; v < nv; ++v) {
        m->positions[v] = ak_vec3_make(p->pos[3 * v], p->pos[3 * v + 1], p->pos[3 * v + 2]);
        if (p->nrm) m->normals[v] = ak_vec3_make(p->nrm[3 * v], p->nrm[3 * v + 1], p->nrm[3 * v + 2]);
        if (p->uv) m->uvs[v] = ak_vec2_make(p->uv[2 * v], p->uv[2 * v + 1]);
        if (p->tan) m->tangents[v] = ak_vec4_make(p->tan[4 * v], p->tan[4 * v + 1], p->tan[4 * v + 2], p->tan[4 * v + 3]);
        if (p->col) {
            const float* s = p->col + v * p->col_comps;
            m->colors[v] = ak_vec4_make(s[0], s[1], s[2], p->col_comps == 4 ? s[3] : 1.0f);
        }
    }
    if (p->idx_count) memcpy(m->indices, p->idx, p->idx_count * sizeof(uint32_t));
    for (size_t i = 0; i < p->targets * nv; ++i) {
        m->morph_positions[i] = ak_vec3_make(p->mpos[3 * i], p->mpos[3 * i + 1], p->mpos[3 * i + 2]);
        if (p->has_mnrm) m->morph_normals[i] = ak_vec3_make(p->mnrm[3 * i], p->mnrm[3 * i + 1], p->mnrm[3 * i + 2]);
        if (p->has_mtan) m->morph_tangents[i] = ak_vec3_make(p->mtan[3 * i], p->mtan[3 * i + 1], p->mtan[3 * i + 2]);
    }
    if (p->targets) {
        const cJSON* wt = cJSON_GetObjectItemCaseSensitive(mesh_json, "weights");
        if (wt) {
            r = get_floats(c, mesh_json, "weights", where, p->targets, m->morph_weights, NULL);
            if (r != AK_OK) {
                ak_mesh_destroy(m);
                return r;
            }
        }
        const cJSON* extras = cJSON_GetObjectItemCaseSensitive(mesh_json, "extras");
        const cJSON* names = cJSON_IsObject(extras) ? cJSON_GetObjectItemCaseSensitive(extras, "targetNames") : NULL;
        size_t t = 0;
        for (const cJSON* e = cJSON_IsArray(names) ? names->child : NULL; e && t < p->targets; e = e->next, ++t)
            if (cJSON_IsString(e)) akp_io_copy_name(m->morph_names[t], e->valuestring);
    }
    if (p->infl) akp_io_store_weights(m, p->joints, p->weights, p->infl, c->desc);
    *out = m;
    return AK_OK;
}

/* Check that every influence with a weight refers to a skin slot (after clean-up, so the
 * fallback weights are checked too). */
static ak_result check_slots(gl_ctx* c, const ak_mesh* m, size_t slots, const char* where, size_t skin) {
    size_t k = m->influence_count;
    for (size_t i = 0; i < m->vertex_count * k; ++i)
        if (m->weights[i] > 0.0f && m->joints[i] >= slots)
            return fail(c, AK_ERR_BAD_INDEX, "%s: vertex %zu weights joint slot %u but skins[%zu] has %zu joints",
                        where, i / k, m->joints[i], skin, slots);
    return AK_OK;
}

/* Scene meshes: meshes in file order x instancing nodes in node order x primitives. */
static ak_result count_scene_meshes(gl_ctx* c, const gl_table* nodes, const gl_table* meshes, size_t* out) {
    size_t* inst = (size_t*)akp_calloc(c->alloc, (c->n_meshes ? c->n_meshes : 1) * sizeof(size_t));
    if (!inst) return fail(c, AK_ERR_NO_MEMORY, "out of memory");
    ak_result r = AK_OK;
    for (size_t i = 0; i < c->n_nodes && r == AK_OK; ++i) {
        char where[160];
        snprintf(where, sizeof where, "nodes[%zu]", i);
        int64_t m = -1, s = -1;
        r = get_opt_index(c, nodes->items[i], "mesh", where, c->n_meshes, &m);
        if (r == AK_OK) r = get_opt_index(c, nodes->items[i], "skin", where, c->n_skins, &s);
        if (r == AK_OK && m >= 0) ++inst[m];
    }
    size_t total = 0;
    for (size_t m = 0; m < c->n_meshes && r == AK_OK; ++m) {
        char where[160];
        snprintf(where, sizeof where, "meshes[%zu]", m);
        cJSON* prims = NULL;
        size_t np = 0;
        r = opt_array(c, meshes->items[m], "primitives", where, &prims, &np);
        if (r == AK_OK && np == 0) r = fail(c, AK_ERR_PARSE, "%s.primitives is required and must not be empty", where);
        if (r == AK_OK) r = check_objects(c, prims, where);
        total += np * (inst[m] ? inst[m] : 1);
    }
    akp_free(c->alloc, inst);
    if (r == AK_OK && total > AKP_IO_MAX_ELEMENTS) r = fail(c, AK_ERR_UNSUPPORTED, "%zu mesh instances", total);
    *out = total;
    return r;
}

/* ---- static helpers: textures ------------------------------------------------------------- */

/* The bytes of image ii: a bufferView's range, a base64 data: URI or a file inside the
 * model's folder (owned: what to free afterwards). */
static ak_result image_bytes(gl_ctx* c, size_t ii, const uint8_t** out, size_t* out_size, uint8_t** owned) {
    const cJSON* im = cJSON_GetArrayItem(cJSON_GetObjectItemCaseSensitive(c->root, "images"), (int)ii);
    char where[64];
    snprintf(where, sizeof where, "images[%zu]", ii);
    if (!cJSON_IsObject(im)) return fail(c, AK_ERR_PARSE, "%s is not an object", where);
    const char* uri = get_string(im, "uri");
    if (cJSON_GetObjectItemCaseSensitive(im, "bufferView")) {
        size_t vi = 0;
        TRY(get_uint(c, im, "bufferView", where, true, 0, c->n_views, &vi));
        return view_range(c, vi, where, out, out_size, NULL);
    }
    if (!uri) return fail(c, AK_ERR_PARSE, "%s has neither a uri nor a bufferView", where);
    if (strncmp(uri, "data:", 5) == 0) {
        const char* comma = strchr(uri, ',');
        if (!comma || comma - uri < 12 || strncmp(comma - 7, ";base64", 7) != 0)
            return fail(c, AK_ERR_UNSUPPORTED, "%s: only base64 data: URIs are supported", where);
        TRY(b64_decode(c, comma + 1, strlen(comma + 1), where, owned, out_size));
        *out = *owned;
        return AK_OK;
    }
    if (!c->base_dir) return fail(c, AK_ERR_IO, "%s: external image '%.200s' needs a base directory", where, uri);
    char path[PATH_MAX];
    TRY(resolve_uri(c, uri, where, path));
    ak_diag sub;
    ak_result r = akp_io_read_file(path, c->alloc, 0, &c->budget, owned, out_size, &sub);
    if (r != AK_OK) return fail(c, r, "%s: uri '%.200s': %s", where, uri, sub.message);
    *out = *owned;
    return AK_OK;
}

static ak_result sampler_field(gl_ctx* c, const cJSON* s, const char* key, const char* where, size_t dflt,
                               size_t* out) {
    TRY(get_uint(c, s, key, where, false, dflt, NO_LIMIT, out));
    return AK_OK;
}

/* glTF texture ti -> scene texture ti: its sampler and its decoded source image. */
static ak_result load_texture(gl_ctx* c, size_t ti) {
    const cJSON* t = cJSON_GetArrayItem(cJSON_GetObjectItemCaseSensitive(c->root, "textures"), (int)ti);
    char where[64];
    snprintf(where, sizeof where, "textures[%zu]", ti);
    if (!cJSON_IsObject(t)) return fail(c, AK_ERR_PARSE, "%s is not an object", where);
    const cJSON* images = cJSON_GetObjectItemCaseSensitive(c->root, "images");
    const cJSON* samplers = cJSON_GetObjectItemCaseSensitive(c->root, "samplers");
    size_t n_images = cJSON_IsArray(images) ? (size_t)cJSON_GetArraySize(images) : 0;
    size_t n_samplers = cJSON_IsArray(samplers) ? (size_t)cJSON_GetArraySize(samplers) : 0;
    int64_t src = -1, smp = -1;
    TRY(get_opt_index(c, t, "source", where, n_images, &src));
    if (src < 0) return fail(c, AK_ERR_UNSUPPORTED, "%s has no source image (only PNG and JPEG are read)", where);
    TRY(get_opt_index(c, t, "sampler", where, n_samplers, &smp));
    ak_scene_texture* st = &c->scene->textures[ti];
    st->wrap_s = st->wrap_t = AK_TEXTURE_WRAP_REPEAT;
    st->mag_filter = st->min_filter = AK_TEXTURE_FILTER_LINEAR;
    if (smp >= 0) {
        const cJSON* s = cJSON_GetArrayItem(samplers, (int)smp);
        char sw[64];
        snprintf(sw, sizeof sw, "samplers[%lld]", (long long)smp);
        if (!cJSON_IsObject(s)) return fail(c, AK_ERR_PARSE, "%s is not an object", sw);
        size_t v[4];
        static const char* const keys[4] = {"wrapS", "wrapT", "magFilter", "minFilter"};
        for (int k = 0; k < 4; ++k) TRY(sampler_field(c, s, keys[k], sw, k < 2 ? 10497u : 9729u, &v[k]));
        for (int k = 0; k < 2; ++k) {
            ak_texture_wrap w = AK_TEXTURE_WRAP_REPEAT;
            if (v[k] == 33071) w = AK_TEXTURE_WRAP_CLAMP;
            else if (v[k] == 33648) w = AK_TEXTURE_WRAP_MIRROR;
            else if (v[k] != 10497) return fail(c, AK_ERR_PARSE, "%s.%s = %zu is not a wrap mode", sw, keys[k], v[k]);
            if (k == 0) st->wrap_s = w;
            else st->wrap_t = w;
        }
        if (v[2] != 9728 && v[2] != 9729) return fail(c, AK_ERR_PARSE, "%s.magFilter = %zu is not a filter", sw, v[2]);
        if (v[3] != 9728 && v[3] != 9729 && (v[3] < 9984 || v[3] > 9987))
            return fail(c, AK_ERR_PARSE, "%s.minFilter = %zu is not a filter", sw, v[3]);
        st->mag_filter = v[2] == 9728 ? AK_TEXTURE_FILTER_NEAREST : AK_TEXTURE_FILTER_LINEAR;
        /* mipmap filters (9984..9987) -> LINEAR: no mipmaps are built, and bilinear is closer to
         * the averaged look they give than the nearest texel of the full-size image */
        st->min_filter = v[3] == 9728 ? AK_TEXTURE_FILTER_NEAREST : AK_TEXTURE_FILTER_LINEAR;
    }
    const cJSON* im = cJSON_GetArrayItem(images, (int)src);
    const char* iname = get_string(im, "name");
    if (!iname) {
        const char* uri = get_string(im, "uri");
        if (uri && strncmp(uri, "data:", 5) != 0) iname = strrchr(uri, '/') ? strrchr(uri, '/') + 1 : uri;
    }
    if (iname && akp_io_utf8_valid(iname, strlen(iname))) {
        akp_io_copy_name(st->name, iname);
        akp_io_sanitize(st->name, sizeof st->name);
    }
    const uint8_t* bytes = NULL;
    size_t n = 0;
    uint8_t* owned = NULL;
    ak_result r = image_bytes(c, (size_t)src, &bytes, &n, &owned);
    if (r == AK_OK) {
        char msg[200];
        uint8_t* px = NULL;
        int w = 0, h = 0;
        r = akp_io_image_decode(c->desc, bytes, n, &c->budget, &c->scene->alloc, &px, &w, &h, msg,
                                sizeof msg);
        if (r != AK_OK) {
            r = fail(c, r, "images[%lld]: %s", (long long)src, msg);
        } else {
            st->pixels = px;
            st->width = w;
            st->height = h;
        }
    }
    akp_free(c->alloc, owned);
    return r;
}

/* Decode the textures that materials use as base colour (scene texture i = glTF texture i;
 * the others stay absent). A texture that cannot be read (a broken or missing image, a bad
 * sampler, over the memory budget) is a warning and stays absent: its meshes are drawn
 * without it. Only running out of memory fails the load. */
static ak_result load_textures(gl_ctx* c) {
    const cJSON* texs = cJSON_GetObjectItemCaseSensitive(c->root, "textures");
    size_t n = cJSON_IsArray(texs) ? (size_t)cJSON_GetArraySize(texs) : 0;
    if (n == 0) return AK_OK;
    TRY(charge(c, n, sizeof(ak_scene_texture) + 1, "textures"));
    if (ak_scene_texture_alloc(c->scene, n) != AK_OK) return fail(c, AK_ERR_NO_MEMORY, "out of memory");
    bool* used = (bool*)akp_calloc(c->alloc, n);
    if (!used) return fail(c, AK_ERR_NO_MEMORY, "out of memory");
    const cJSON* mats = cJSON_GetObjectItemCaseSensitive(c->root, "materials");
    for (const cJSON* m = cJSON_IsArray(mats) ? mats->child : NULL; m; m = m->next) {
        const cJSON* pbr = cJSON_GetObjectItemCaseSensitive(m, "pbrMetallicRoughness");
        const cJSON* bct = cJSON_IsObject(pbr) ? cJSON_GetObjectItemCaseSensitive(pbr, "baseColorTexture") : NULL;
        size_t ti = 0;
        if (cJSON_IsObject(bct) && as_uint(cJSON_GetObjectItemCaseSensitive(bct, "index"), &ti) && ti < n)
            used[ti] = true;
    }
    ak_result r = AK_OK;
    for (size_t ti = 0; ti < n && r == AK_OK; ++ti) {
        if (!used[ti]) continue;
        ak_diag sub;
        memset(&sub, 0, sizeof sub);
        ak_diag* keep = c->diag;
        c->diag = &sub;
        ak_result tr = load_texture(c, ti);
        c->diag = keep;
        if (tr == AK_ERR_NO_MEMORY) {
            r = fail(c, tr, "%s", sub.message);
        } else if (tr != AK_OK) {
            char msg[sizeof sub.message + 80];
            snprintf(msg, sizeof msg, "%s (%s); the meshes using it are drawn untextured", sub.message,
                     ak_result_string(tr));
            warn(c, msg);
        }
    }
    akp_free(c->alloc, used);
    return r;
}

/* The primitive's base colour texture (pbrMetallicRoughness.baseColorTexture), when it was
 * decoded and uses TEXCOORD_0; anything else is a warning and no texture. */
static void read_base_texture(gl_ctx* c, const cJSON* pbr, const char* mw, ak_scene_mesh* sm) {
    const cJSON* bct = cJSON_GetObjectItemCaseSensitive(pbr, "baseColorTexture");
    if (!bct) return;
    char msg[300];
    size_t ti = 0, tc = 0;
    const cJSON* tcj = cJSON_IsObject(bct) ? cJSON_GetObjectItemCaseSensitive(bct, "texCoord") : NULL;
    if (!cJSON_IsObject(bct) || !as_uint(cJSON_GetObjectItemCaseSensitive(bct, "index"), &ti) ||
        ti >= c->scene->texture_count) {
        snprintf(msg, sizeof msg, "%s.baseColorTexture does not name a texture; ignored", mw);
        warn(c, msg);
    } else if (tcj && (!as_uint(tcj, &tc) || tc != 0)) {
        snprintf(msg, sizeof msg, "%s.baseColorTexture uses a texCoord other than 0 (only TEXCOORD_0 is read); ignored",
                 mw);
        warn(c, msg);
    } else if (c->scene->textures[ti].pixels) {
        sm->texture = (int32_t)ti;
    }
}

/* The primitive's material: its base colour factor and texture (materials are otherwise not read). */
static ak_result read_material(gl_ctx* c, const cJSON* prim, const char* where, ak_scene_mesh* sm) {
    const cJSON* mats = cJSON_GetObjectItemCaseSensitive(c->root, "materials");
    size_t n = cJSON_IsArray(mats) ? (size_t)cJSON_GetArraySize(mats) : 0;
    int64_t mi = -1;
    TRY(get_opt_index(c, prim, "material", where, n, &mi));
    if (mi < 0) return AK_OK;
    const cJSON* m = cJSON_GetArrayItem(mats, (int)mi);
    const cJSON* pbr = cJSON_GetObjectItemCaseSensitive(m, "pbrMetallicRoughness");
    float col[4] = {1, 1, 1, 1};
    if (cJSON_IsObject(pbr)) {
        char mw[64];
        snprintf(mw, sizeof mw, "materials[%lld].pbrMetallicRoughness", (long long)mi);
        TRY(get_floats(c, pbr, "baseColorFactor", mw, 4, col, NULL));
        read_base_texture(c, pbr, mw, sm);
    }
    sm->has_material = true;
    sm->base_color = ak_vec4_make(col[0], col[1], col[2], col[3]);
    return AK_OK;
}

static ak_result load_meshes(gl_ctx* c, const gl_table* nodes, const gl_table* meshes) {
    ak_scene* scene = c->scene;
    size_t out = 0, base = 0;
    for (size_t mi = 0; mi < c->n_meshes; ++mi) {
        const cJSON* mj = meshes->items[mi];
        const cJSON* prims = cJSON_GetObjectItemCaseSensitive(mj, "primitives");
        size_t np = (size_t)cJSON_GetArraySize(prims);
        const char* mname = get_string(mj, "name");
        size_t pi = 0, targets0 = 0, instances = 0;
        /* Primitives are read one at a time, but scene mesh k of primitive pi goes to slot
         * out + k * np + pi: node-major, so each node's primitives stay together. */
        for (const cJSON* prim = prims->child; prim; prim = prim->next, ++pi) {
            char where[160], name[AK_NAME_SIZE];
            snprintf(where, sizeof where, "meshes[%zu].primitives[%zu]", mi, pi);
            if (mname && np == 1) akp_io_copy_name(name, mname);
            else if (mname) snprintf(name, sizeof name, "%.50s_%zu", mname, pi);
            else if (np == 1) snprintf(name, sizeof name, "mesh_%zu", mi);
            else snprintf(name, sizeof name, "mesh_%zu_%zu", mi, pi);
            prim_data p;
            memset(&p, 0, sizeof p);
            ak_result r = read_primitive(c, prim, where, &p);
            if (r == AK_OK && pi == 0) targets0 = p.targets;
            if (r == AK_OK && p.targets != targets0)
                r = fail(c, AK_ERR_PARSE, "%s has %zu morph targets, primitive 0 has %zu", where, p.targets, targets0);
            const cJSON* mw = cJSON_GetObjectItemCaseSensitive(mj, "weights");
            if (r == AK_OK && mw && (!cJSON_IsArray(mw) || (size_t)cJSON_GetArraySize(mw) != p.targets))
                r = fail(c, AK_ERR_PARSE, "meshes[%zu].weights must have one number per morph target (%zu)", mi,
                         p.targets);
            /* Instances in node order; one uninstanced entry when no node uses the mesh. */
            bool any = false;
            size_t k = 0;
            ak_mesh* plain = NULL; /* the instances' mesh with the default morph weights */
            for (size_t ni = 0; r == AK_OK && ni <= c->n_nodes; ++ni) {
                int64_t nm = -1, ns = -1;
                const cJSON* node = ni < c->n_nodes ? nodes->items[ni] : NULL;
                if (node) {
                    get_opt_index(c, node, "mesh", "", c->n_meshes, &nm); /* validated by count_scene_meshes */
                    get_opt_index(c, node, "skin", "", c->n_skins, &ns);
                    if (nm != (int64_t)mi) continue;
                } else if (any) {
                    break;
                }
                any = true;
                size_t slot = out + k * np + pi;
                ak_scene_mesh* sm = &scene->meshes[slot];
                sm->node = node ? c->joint_of_node[ni] : -1;
                sm->skin = -1;
                if (r == AK_OK) r = read_material(c, prim, where, sm);
                if (ns >= 0 && !p.infl)
                    r = fail(c, AK_ERR_PARSE, "%s: nodes[%zu] has a skin but the primitive has no JOINTS_0/WEIGHTS_0",
                             where, ni);
                /* later instances share the first one's mesh, unless their node sets its own
                 * morph weights (a mesh's default weights are the mesh's) */
                const bool own_weights = node && p.targets && cJSON_GetObjectItemCaseSensitive(node, "weights");
                if (r == AK_OK && plain && !own_weights) {
                    sm->mesh = plain;
                    sm->shares_mesh = true;
                } else if (r == AK_OK) {
                    r = make_mesh(c, &p, name, mj, where, &sm->mesh);
                    if (r == AK_OK && !own_weights) plain = sm->mesh;
                }
                if (r == AK_OK && sm->texture >= 0 && !sm->mesh->uvs) {
                    char msg[240];
                    snprintf(msg, sizeof msg, "%s has a base colour texture but no TEXCOORD_0; drawn untextured", where);
                    warn(c, msg);
                    sm->texture = -1;
                }
                if (r == AK_OK && ns >= 0) {
                    sm->skin = (int32_t)ns;
                    r = check_slots(c, sm->mesh, scene->skins[ns].joint_count, where, (size_t)ns);
                }
                if (r == AK_OK && node && p.targets && cJSON_GetObjectItemCaseSensitive(node, "weights")) {
                    char nw[160];
                    snprintf(nw, sizeof nw, "nodes[%zu]", ni);
                    r = get_floats(c, node, "weights", nw, p.targets, sm->mesh->morph_weights, NULL);
                }
                c->morph_base[slot] = base + (k * np + pi) * targets0;
                ++k;
            }
            instances = k;
            prim_free(c, &p);
            if (r != AK_OK) return r;
        }
        out += instances * np;
        base += instances * np * targets0;
    }
    return AK_OK;
}

/* ---- static helpers: animations --------------------------------------------------------- */

typedef struct sampler_data {
    float* times;
    float* values;
    size_t keys;
    size_t value_count; /* floats */
    ak_interp interp;
    bool read;
} sampler_data;

static ak_result read_sampler(gl_ctx* c, const cJSON* s, const char* where, sampler_data* sd) {
    static const uint32_t scalar[] = {1, 0}, any[] = {1, 2, 3, 4, 0};
    size_t in = 0, out = 0;
    TRY(get_uint(c, s, "input", where, true, 0, c->n_acc, &in));
    TRY(get_uint(c, s, "output", where, true, 0, c->n_acc, &out));
    const cJSON* ij = cJSON_GetObjectItemCaseSensitive(s, "interpolation");
    const char* interp = ij ? (cJSON_IsString(ij) ? ij->valuestring : "") : "LINEAR";
    if (strcmp(interp, "LINEAR") == 0) sd->interp = AK_INTERP_LINEAR;
    else if (strcmp(interp, "STEP") == 0) sd->interp = AK_INTERP_STEP;
    else if (strcmp(interp, "CUBICSPLINE") == 0) sd->interp = AK_INTERP_CUBICSPLINE;
    else return fail(c, AK_ERR_PARSE, "%s.interpolation '%.40s' is not STEP, LINEAR or CUBICSPLINE", where, interp);
    gl_acc acc;
    char what[256];
    snprintf(what, sizeof what, "%s input", where);
    TRY(read_floats(c, in, what, scalar, &sd->times, &acc));
    sd->keys = acc.count;
    if (sd->keys && sd->times[0] < 0.0f) /* glTF: times are >= 0; rejected like decreasing times */
        return fail(c, AK_ERR_UNSORTED, "%s: input time 0 (%g) is negative", where, (double)sd->times[0]);
    for (size_t k = 1; k < sd->keys; ++k)
        if (!(sd->times[k] > sd->times[k - 1]))
            return fail(c, AK_ERR_UNSORTED, "%s: input time %zu (%g) is not after time %zu (%g)", where, k,
                        (double)sd->times[k], k - 1, (double)sd->times[k - 1]);
    snprintf(what, sizeof what, "%s output", where);
    TRY(read_floats(c, out, what, any, &sd->values, &acc));
    sd->value_count = acc.count * acc.comps;
    sd->read = true;
    return AK_OK;
}

static ak_result load_animation(gl_ctx* c, const cJSON* an, size_t ai, ak_raw_channel** chans, size_t* chan_cap) {
    ak_scene* scene = c->scene;
    char where[160];
    snprintf(where, sizeof where, "animations[%zu]", ai);
    cJSON *channels = NULL, *samplers = NULL;
    size_t nc = 0, ns = 0;
    TRY(opt_array(c, an, "channels", where, &channels, &nc));
    TRY(opt_array(c, an, "samplers", where, &samplers, &ns));
    if (nc == 0 || ns == 0) return fail(c, AK_ERR_PARSE, "%s needs channels and samplers", where);
    TRY(check_objects(c, channels, where));
    TRY(check_objects(c, samplers, where));
    sampler_data* sd = (sampler_data*)akp_calloc(c->alloc, ns * sizeof(sampler_data));
    if (!sd) return fail(c, AK_ERR_NO_MEMORY, "out of memory");
    ak_result r = AK_OK;
    float duration = 0.0f;
    size_t si = 0;
    for (const cJSON* s = samplers->child; s && r == AK_OK; s = s->next, ++si) {
        char sw[200];
        snprintf(sw, sizeof sw, "%s.samplers[%zu]", where, si);
        r = read_sampler(c, s, sw, &sd[si]);
        if (r == AK_OK && sd[si].times[sd[si].keys - 1] > duration) duration = sd[si].times[sd[si].keys - 1];
    }
    size_t out = 0, ci = 0;
    for (const cJSON* ch = channels->child; ch && r == AK_OK; ch = ch->next, ++ci) {
        char cw[200];
        snprintf(cw, sizeof cw, "%s.channels[%zu]", where, ci);
        size_t smp = 0;
        if ((r = get_uint(c, ch, "sampler", cw, true, 0, ns, &smp)) != AK_OK) break;
        const cJSON* tg = cJSON_GetObjectItemCaseSensitive(ch, "target");
        if (!cJSON_IsObject(tg)) {
            r = fail(c, AK_ERR_PARSE, "%s.target is required", cw);
            break;
        }
        const char* path = get_string(tg, "path");
        if (!path) {
            r = fail(c, AK_ERR_PARSE, "%s.target.path is required", cw);
            break;
        }
        int64_t node = -1;
        if ((r = get_opt_index(c, tg, "node", cw, c->n_nodes, &node)) != AK_OK) break;
        ak_channel_target target;
        uint32_t comps;
        if (strcmp(path, "translation") == 0) target = AK_CHANNEL_TRANSLATION, comps = 3;
        else if (strcmp(path, "rotation") == 0) target = AK_CHANNEL_ROTATION, comps = 4;
        else if (strcmp(path, "scale") == 0) target = AK_CHANNEL_SCALE, comps = 3;
        else if (strcmp(path, "weights") == 0) target = AK_CHANNEL_MORPH_WEIGHTS, comps = 0;
        else {
            char msg[400];
            snprintf(msg, sizeof msg, "%s: target path '%.40s' ignored", cw, path);
            warn(c, msg);
            continue;
        }
        if (node < 0) { /* allowed by the spec when an extension supplies the target */
            char msg[400];
            snprintf(msg, sizeof msg, "%s has no target node; ignored", cw);
            warn(c, msg);
            continue;
        }
        const sampler_data* s = &sd[smp];
        size_t mul = s->interp == AK_INTERP_CUBICSPLINE ? 3 : 1;
        /* Scene meshes on this node (weights channels write each one's morph range). */
        size_t first = 0, count = 1;
        if (target == AK_CHANNEL_MORPH_WEIGHTS) {
            count = 0;
            for (size_t m = 0; m < scene->mesh_count; ++m)
                if (scene->meshes[m].node == c->joint_of_node[node] && scene->meshes[m].mesh->morph_target_count) {
                    if (count == 0) first = m;
                    ++count;
                    comps = (uint32_t)scene->meshes[m].mesh->morph_target_count;
                }
            if (count == 0) {
                r = fail(c, AK_ERR_PARSE, "%s animates weights of nodes[%lld], which has no morph targets", cw,
                         (long long)node);
                break;
            }
        }
        if (s->value_count != s->keys * comps * mul) {
            r = fail(c, AK_ERR_PARSE, "%s: sampler output has %zu values, %zu keys x %u components%s need %zu", cw,
                     s->value_count, s->keys, comps, mul == 3 ? " x 3 (CUBICSPLINE)" : "", s->keys * comps * mul);
            break;
        }
        for (size_t m = first, done = 0; done < count; ++m) {
            if (target == AK_CHANNEL_MORPH_WEIGHTS &&
                !(scene->meshes[m].node == c->joint_of_node[node] && scene->meshes[m].mesh->morph_target_count))
                continue;
            /* ak_clip_build copies the keys for every channel, also when many channels share
             * one sampler: charge each copy (times and values, twice for the build's work) */
            r = charge(c, s->keys, 2 * sizeof(float) * (1 + (size_t)comps * (s->interp == AK_INTERP_CUBICSPLINE ? 3 : 1)),
                       cw);
            if (r != AK_OK) break;
            if (out == *chan_cap) {
                size_t cap = *chan_cap ? *chan_cap * 2 : 16;
                ak_raw_channel* nc2 = (ak_raw_channel*)akp_alloc(c->alloc, cap * sizeof(ak_raw_channel));
                if (!nc2) {
                    r = fail(c, AK_ERR_NO_MEMORY, "out of memory");
                    break;
                }
                if (*chans) memcpy(nc2, *chans, out * sizeof(ak_raw_channel));
                akp_free(c->alloc, *chans);
                *chans = nc2;
                *chan_cap = cap;
            }
            ak_raw_channel* rc = &(*chans)[out++];
            memset(rc, 0, sizeof *rc);
            rc->target = target;
            rc->index = target == AK_CHANNEL_MORPH_WEIGHTS ? (uint32_t)c->morph_base[m] : (uint32_t)c->joint_of_node[node];
            rc->component_count = comps;
            rc->interp = s->interp;
            rc->key_count = s->keys;
            rc->times = s->times;
            rc->values = s->values;
            ++done;
        }
    }
    if (r == AK_OK && out == 0) r = fail(c, AK_ERR_UNSUPPORTED, "%s has no channel animkit can use", where);
    if (r == AK_OK) {
        char name[AK_NAME_SIZE];
        const char* an_name = get_string(an, "name");
        if (an_name && an_name[0]) akp_io_copy_name(name, an_name);
        else snprintf(name, sizeof name, "animation_%zu", ai);
        size_t morph_total = 0;
        for (size_t m = 0; m < scene->mesh_count; ++m) morph_total += scene->meshes[m].mesh->morph_target_count;
        ak_raw_clip raw = {
            .name = name,
            .duration = duration,
            .channels = *chans,
            .channel_count = out,
            .joint_count = ak_scene_joint_count(scene),
            .morph_weight_count = morph_total,
        };
        ak_diag sub;
        r = ak_clip_build(&raw, c->alloc, &scene->clips[ai], &sub);
        if (r != AK_OK) fail(c, r, "%s: %s", where, sub.message);
    }
    for (size_t i = 0; i < ns; ++i) {
        akp_free(c->alloc, sd[i].times);
        akp_free(c->alloc, sd[i].values);
    }
    akp_free(c->alloc, sd);
    return r;
}

/* ---- the reader ------------------------------------------------------------------------ */

static ak_result load_document(gl_ctx* c, const uint8_t* data, size_t size) {
    const char* json = (const char*)data;
    size_t json_size = size;
    if (size >= 4 && memcmp(data, "glTF", 4) == 0) {
        TRY(parse_glb(c, data, size, &json, &json_size));
    } else {
        /* A .glb that is not one (empty, random bytes): say so rather than "invalid JSON". A
         * .glb holding JSON text is still read as JSON. */
        size_t nl = strlen(c->name), i = 0;
        bool glb_name = nl >= 4 && (strcmp(c->name + nl - 4, ".glb") == 0 || strcmp(c->name + nl - 4, ".GLB") == 0);
        while (i < size && (data[i] == ' ' || data[i] == '\t' || data[i] == '\r' || data[i] == '\n')) ++i;
        bool json_like = i < size && data[i] == '{';
        if (size >= i + 3 && data[i] == 0xEF && data[i + 1] == 0xBB && data[i + 2] == 0xBF) json_like = true;
        if (glb_name && !json_like)
            return fail(c, AK_ERR_PARSE, "not a GLB (bad magic: the file does not start with \"glTF\"%s)",
                        size == 0 ? "; it is empty" : "");
    }
    if (json_size >= 3 && (uint8_t)json[0] == 0xEF && (uint8_t)json[1] == 0xBB && (uint8_t)json[2] == 0xBF) {
        json += 3; /* UTF-8 byte order mark */
        json_size -= 3;
    }
    /* cJSON makes one node per value: at most one per ',', '[', '{' plus one, each with its
     * own copy of strings and keys (bounded by the text) */
    size_t values = 1;
    for (size_t i = 0; i < json_size; ++i) values += json[i] == ',' || json[i] == '[' || json[i] == '{';
    TRY(charge(c, values, sizeof(cJSON), "the JSON tree"));
    TRY(charge(c, json_size, 1, "the JSON strings"));
    const char* end = NULL;
    c->root = cJSON_ParseWithLengthOpts(json, json_size, &end, 0);
    if (!c->root) {
        ak_result r = fail(c, AK_ERR_PARSE, "invalid JSON%s", json_size == 0 ? " (empty)" : "");
        if (c->diag && end && end >= json && end <= json + json_size) {
            long line = 1;
            for (const char* p = json; p < end; ++p) line += *p == '\n';
            c->diag->line = line;
            c->diag->byte_offset = (long)(end - (const char*)data);
            snprintf(c->diag->message, sizeof c->diag->message, "invalid JSON near byte %ld (line %ld)",
                     c->diag->byte_offset, line);
        }
        return r;
    }
    if (!cJSON_IsObject(c->root)) return fail(c, AK_ERR_PARSE, "the JSON document is not an object");
    TRY(check_header(c));

    gl_table nodes = {0}, meshes = {0};
    ak_result r = make_table(c, c->nodes, c->n_nodes, &nodes);
    if (r == AK_OK) r = make_table(c, c->meshes, c->n_meshes, &meshes);
    size_t mesh_count = 0;
    if (r == AK_OK) r = count_scene_meshes(c, &nodes, &meshes, &mesh_count);
    size_t clip_count = c->desc->skip_animations ? 0 : c->n_anims;
    if (r == AK_OK) {
        r = ak_scene_alloc(mesh_count, c->n_skins, clip_count, c->alloc, &c->scene);
        if (r != AK_OK) r = fail(c, r, "out of memory");
    }
    if (r == AK_OK) {
        akp_io_copy_name(c->scene->name, c->name);
        c->morph_base = (size_t*)akp_calloc(c->alloc, (mesh_count ? mesh_count : 1) * sizeof(size_t));
        if (!c->morph_base) r = fail(c, AK_ERR_NO_MEMORY, "out of memory");
    }
    if (r == AK_OK) r = load_nodes_and_skins(c, &nodes);
    if (r == AK_OK) r = load_textures(c);
    if (r == AK_OK) r = load_meshes(c, &nodes, &meshes);
    ak_raw_channel* chans = NULL;
    size_t cap = 0, ai = 0;
    for (const cJSON* an = c->animations ? c->animations->child : NULL; r == AK_OK && an && ai < clip_count;
         an = an->next, ++ai)
        r = load_animation(c, an, ai, &chans, &cap);
    akp_free(c->alloc, chans);
    akp_free(c->alloc, (void*)nodes.items);
    akp_free(c->alloc, (void*)meshes.items);
    return r;
}

ak_result akp_io_load_gltf(const uint8_t* data, size_t size, const char* name, const char* base_dir,
                           const ak_io_desc* desc, const ak_allocator* alloc, ak_scene** out_scene, ak_diag* diag) {
    gl_ctx c;
    memset(&c, 0, sizeof c);
    c.alloc = alloc;
    c.desc = desc;
    c.name = name;
    c.base_dir = base_dir;
    c.diag = diag;
    c.budget = akp_io_budget(desc, size);
    ak_result r = load_document(&c, data, size);
    for (size_t i = 0; c.bufs && i < c.n_buffers; ++i) akp_free(alloc, c.bufs[i].owned);
    akp_free(alloc, c.bufs);
    akp_free(alloc, c.joint_of_node);
    akp_free(alloc, c.node_parent);
    akp_free(alloc, c.morph_base);
    akp_free(alloc, (void*)c.t_acc.items);
    akp_free(alloc, (void*)c.t_views.items);
    akp_free(alloc, (void*)c.t_buffers.items);
    cJSON_Delete(c.root);
    if (r != AK_OK) {
        ak_scene_destroy(c.scene);
        return r;
    }
    *out_scene = c.scene;
    return AK_OK;
}

/* BVH (Biovision hierarchy) reader, animkit's own: safe on untrusted files.
 *
 * Streaming: a file is read through a 64 KiB window, never whole; the motion values go into
 * one float array that grows as frames arrive, so memory follows the data actually present,
 * not the declared "Frames:" count (which must match it exactly). The hierarchy is parsed
 * without recursion, nesting is bounded by AK_IO_BVH_MAX_DEPTH, every allocation is charged
 * to the load's memory budget first.
 *
 * The scene has the layout Assimp's BVH importer gave (so files load as before):
 *   - one skeleton joint per ROOT/JOINT in file order, named as in the file, rest transform =
 *     translation by OFFSET; one joint per End Site named "EndSite_<parent name>";
 *   - is_joint true for ROOT/JOINT, false for End Sites;
 *   - one clip "Motion"; per ROOT/JOINT in file order a translation channel (one key per
 *     frame when the joint has position channels: the OFFSET with the listed axes replaced by
 *     the channel values; otherwise one key holding the OFFSET), a rotation channel (one key
 *     per frame), a scale channel (one key of 1); key k at k x Frame Time, duration
 *     (Frames - 1) x Frame Time;
 *   - rotation channels apply in the order listed, intrinsically: "Zrotation Xrotation
 *     Yrotation" gives R = Rz * Rx * Ry acting on column vectors (angles in degrees).
 * "Frames: 0" gives the skeleton and no clip. */
#include <ctype.h>
#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdlib.h>

#include "io_internal.h"

/* ---- private types ------------------------------------------------------------------- */

#define BV_WINDOW 65536
#define BV_TOKEN 256

typedef enum bv_channel { BV_XPOS, BV_YPOS, BV_ZPOS, BV_XROT, BV_YROT, BV_ZROT } bv_channel;

typedef struct bv_node {
    char name[AK_NAME_SIZE];
    int32_t parent;
    bool end_site, has_offset, has_channels;
    double offset[3];
    uint8_t channel_count;
    uint8_t channels[6]; /* bv_channel */
    size_t first_value;  /* index of its first channel within a frame */
} bv_node;

typedef struct bv_ctx {
    const ak_allocator* alloc;
    const ak_io_desc* desc;
    const char* name; /* in diag: the path, or the memory block's name */
    const char* scene_name;
    ak_diag* diag;
    akp_budget budget;
    /* source: a FILE* through a window, or a memory block */
    FILE* file;
    const uint8_t* mem;
    size_t mem_size;
    uint8_t* window;
    size_t win_len, win_pos;
    size_t offset; /* bytes consumed */
    long line;
    long token_line;
    size_t token_offset;
    /* hierarchy */
    bv_node* nodes;
    size_t node_count, node_cap;
    size_t joint_count;   /* ROOT/JOINT entries */
    size_t channel_total; /* values per frame */
    /* motion */
    size_t frames;
    double frame_time;
    float* values;
    size_t value_count, value_cap;
    ak_scene* scene;
} bv_ctx;

/* ---- static helpers: errors and tokens ------------------------------------------------- */

#if defined(__GNUC__)
__attribute__((format(printf, 3, 4)))
#endif
static ak_result fail(bv_ctx* c, ak_result r, const char* fmt, ...) {
    if (c->diag) {
        memset(c->diag, 0, sizeof *c->diag);
        snprintf(c->diag->path, sizeof c->diag->path, "%s", c->name);
        c->diag->line = c->token_line;
        c->diag->byte_offset = (long)c->token_offset;
        va_list ap;
        va_start(ap, fmt);
        vsnprintf(c->diag->message, sizeof c->diag->message, fmt, ap);
        va_end(ap);
        akp_io_sanitize(c->diag->path, sizeof c->diag->path);
        akp_io_sanitize(c->diag->message, sizeof c->diag->message);
    }
    return r;
}

#define TRY(expr)                                                                          \
    do {                                                                                   \
        ak_result tr_ = (expr);                                                            \
        if (tr_ != AK_OK) return tr_;                                                      \
    } while (0)

static ak_result charge(bv_ctx* c, size_t n, size_t size, const char* what) {
    if (akp_budget_take(&c->budget, n, size)) return AK_OK;
    return fail(c, AK_ERR_UNSUPPORTED,
                "%s: %zu x %zu bytes would exceed the memory budget of %zu bytes (%zu already used; "
                "ak_io_desc.memory_budget)",
                what, n, size, c->budget.limit, c->budget.used);
}

/* Next byte, or -1 at the end. A read error is reported as the end (the caller then finds
 * the data short) after noting it in errno. */
static int next_byte(bv_ctx* c) {
    if (c->mem) {
        if (c->win_pos >= c->mem_size) return -1;
        ++c->offset;
        return c->mem[c->win_pos++];
    }
    if (c->win_pos >= c->win_len) {
        c->win_len = fread(c->window, 1, BV_WINDOW, c->file);
        c->win_pos = 0;
        if (c->win_len == 0) return -1;
    }
    ++c->offset;
    return c->window[c->win_pos++];
}

static void unread_byte(bv_ctx* c) {
    --c->win_pos;
    --c->offset;
}

/* The next whitespace-separated token into tok (NUL-terminated). Returns AK_OK with tok[0] 0
 * at the end of the data, AK_ERR_PARSE for a token longer than BV_TOKEN - 1 bytes or a NUL
 * byte. */
static ak_result next_token(bv_ctx* c, char tok[BV_TOKEN]) {
    int ch;
    do {
        ch = next_byte(c);
        if (ch == '\n') ++c->line;
    } while (ch == ' ' || ch == '\t' || ch == '\r' || ch == '\n' || ch == '\f' || ch == '\v');
    tok[0] = 0;
    c->token_line = c->line;
    c->token_offset = c->offset ? c->offset - 1 : 0;
    if (ch < 0) return AK_OK;
    size_t n = 0;
    while (ch >= 0 && !(ch == ' ' || ch == '\t' || ch == '\r' || ch == '\n' || ch == '\f' || ch == '\v')) {
        if (ch == 0) return fail(c, AK_ERR_PARSE, "line %ld: a NUL byte (not a text file)", c->line);
        if (n + 1 >= BV_TOKEN) return fail(c, AK_ERR_PARSE, "line %ld: a word longer than %d bytes", c->line, BV_TOKEN - 1);
        tok[n++] = (char)ch;
        ch = next_byte(c);
    }
    if (ch >= 0) unread_byte(c); /* the separator; a newline is counted on the next call */
    tok[n] = 0;
    return AK_OK;
}

static ak_result expect(bv_ctx* c, const char* want, const char* context) {
    char tok[BV_TOKEN];
    TRY(next_token(c, tok));
    if (strcmp(tok, want) != 0)
        return fail(c, AK_ERR_PARSE, "line %ld: expected '%s' %s, found '%.60s'", c->token_line, want, context,
                    tok[0] ? tok : "the end of the file");
    return AK_OK;
}

/* A finite decimal number filling the whole token. */
static ak_result number(bv_ctx* c, const char* tok, const char* what, double* out) {
    if (!tok[0]) return fail(c, AK_ERR_PARSE, "line %ld: the file ends where %s was expected", c->token_line, what);
    char* end = NULL;
    errno = 0;
    double v = strtod(tok, &end);
    if (end == tok || *end != 0) return fail(c, AK_ERR_PARSE, "line %ld: %s '%.60s' is not a number", c->token_line, what, tok);
    if (!isfinite(v))
        return fail(c, AK_ERR_BAD_DATA, "line %ld: %s '%.60s' is not finite", c->token_line, what, tok);
    *out = v;
    return AK_OK;
}

static ak_result next_number(bv_ctx* c, const char* what, double* out) {
    char tok[BV_TOKEN];
    TRY(next_token(c, tok));
    return number(c, tok, what, out);
}

/* ---- static helpers: hierarchy -------------------------------------------------------- */

static ak_result add_node(bv_ctx* c, const char* name, int32_t parent, bool end_site, size_t* out) {
    /* a joint name reaches terminals, JSON reports and glTF files: valid UTF-8, no control bytes */
    if (!end_site && !akp_io_utf8_valid(name, strlen(name)))
        return fail(c, AK_ERR_PARSE, "line %ld: the joint name is not valid UTF-8", c->token_line);
    for (const char* p = name; !end_site && *p; ++p)
        if ((unsigned char)*p < 0x20 || *p == 0x7F)
            return fail(c, AK_ERR_PARSE, "line %ld: the joint name holds a control byte", c->token_line);
    if (c->node_count >= AKP_IO_MAX_NODES)
        return fail(c, AK_ERR_UNSUPPORTED, "line %ld: more than %u nodes", c->token_line, AKP_IO_MAX_NODES);
    if (c->node_count == c->node_cap) {
        size_t cap = c->node_cap ? 2 * c->node_cap : 64;
        if (cap > AKP_IO_MAX_NODES) cap = AKP_IO_MAX_NODES;
        TRY(charge(c, cap, sizeof(bv_node), "BVH hierarchy"));
        bv_node* n = (bv_node*)akp_alloc(c->alloc, cap * sizeof(bv_node));
        if (!n) return fail(c, AK_ERR_NO_MEMORY, "out of memory for %zu nodes", cap);
        if (c->node_count) memcpy(n, c->nodes, c->node_count * sizeof(bv_node));
        akp_free(c->alloc, c->nodes);
        c->nodes = n;
        c->node_cap = cap;
    }
    bv_node* n = &c->nodes[c->node_count];
    memset(n, 0, sizeof *n);
    if (end_site) snprintf(n->name, sizeof n->name, "EndSite_%s", name);
    else akp_io_copy_name(n->name, name);
    n->parent = parent;
    n->end_site = end_site;
    *out = c->node_count++;
    if (!end_site) ++c->joint_count;
    return AK_OK;
}

static ak_result read_offset(bv_ctx* c, bv_node* n) {
    if (n->has_offset) return fail(c, AK_ERR_PARSE, "line %ld: '%.100s' has a second OFFSET", c->token_line, n->name);
    for (int k = 0; k < 3; ++k) TRY(next_number(c, "an OFFSET value", &n->offset[k]));
    n->has_offset = true;
    return AK_OK;
}

static ak_result read_channels(bv_ctx* c, bv_node* n) {
    static const char* const names[6] = {"Xposition", "Yposition", "Zposition", "Xrotation", "Yrotation", "Zrotation"};
    if (n->has_channels) return fail(c, AK_ERR_PARSE, "line %ld: '%.100s' has a second CHANNELS", c->token_line, n->name);
    double count = 0;
    TRY(next_number(c, "the CHANNELS count", &count));
    if (count < 0 || count > 6 || count != floor(count))
        return fail(c, AK_ERR_PARSE, "line %ld: CHANNELS %g (0 to 6 expected)", c->token_line, count);
    n->channel_count = (uint8_t)count;
    unsigned seen = 0;
    for (uint8_t i = 0; i < n->channel_count; ++i) {
        char tok[BV_TOKEN];
        TRY(next_token(c, tok));
        int k = 0;
        while (k < 6 && strcmp(tok, names[k]) != 0) ++k;
        if (k == 6)
            return fail(c, AK_ERR_PARSE, "line %ld: '%.60s' is not a BVH channel (Xposition ... Zrotation)",
                        c->token_line, tok[0] ? tok : "the end of the file");
        if (seen & (1u << k)) return fail(c, AK_ERR_PARSE, "line %ld: channel %s listed twice", c->token_line, tok);
        seen |= 1u << k;
        n->channels[i] = (uint8_t)k;
    }
    n->first_value = c->channel_total;
    c->channel_total += n->channel_count;
    n->has_channels = true;
    return AK_OK;
}

/* HIERARCHY ROOT name { ... } with JOINT and End Site children, iteratively with an explicit
 * stack of open nodes. */
static ak_result read_hierarchy(bv_ctx* c) {
    char tok[BV_TOKEN], name[BV_TOKEN];
    TRY(expect(c, "HIERARCHY", "at the start of a BVH file"));
    TRY(expect(c, "ROOT", "after HIERARCHY"));
    int32_t stack[AK_IO_BVH_MAX_DEPTH];
    size_t depth = 0, me = 0;
    TRY(next_token(c, name));
    if (!name[0] || strcmp(name, "{") == 0) return fail(c, AK_ERR_PARSE, "line %ld: ROOT has no name", c->token_line);
    TRY(add_node(c, name, -1, false, &me));
    TRY(expect(c, "{", "after the ROOT name"));
    stack[depth++] = (int32_t)me;
    while (depth > 0) {
        TRY(next_token(c, tok));
        bv_node* top = &c->nodes[stack[depth - 1]];
        if (!tok[0]) return fail(c, AK_ERR_PARSE, "the file ends inside '%.100s' (truncated?)", top->name);
        if (strcmp(tok, "}") == 0) {
            --depth;
        } else if (strcmp(tok, "OFFSET") == 0) {
            TRY(read_offset(c, top));
        } else if (strcmp(tok, "CHANNELS") == 0) {
            if (top->end_site) return fail(c, AK_ERR_PARSE, "line %ld: an End Site has no channels", c->token_line);
            TRY(read_channels(c, top));
        } else if (strcmp(tok, "JOINT") == 0 || strcmp(tok, "End") == 0) {
            bool end_site = tok[0] == 'E';
            if (top->end_site) return fail(c, AK_ERR_PARSE, "line %ld: an End Site has no children", c->token_line);
            if (depth >= AK_IO_BVH_MAX_DEPTH)
                return fail(c, AK_ERR_UNSUPPORTED, "line %ld: joints nested deeper than %u levels", c->token_line,
                            AK_IO_BVH_MAX_DEPTH);
            TRY(next_token(c, name));
            if (end_site && strcmp(name, "Site") != 0)
                return fail(c, AK_ERR_PARSE, "line %ld: expected 'End Site', found 'End %.60s'", c->token_line, name);
            if (!end_site && (!name[0] || strcmp(name, "{") == 0))
                return fail(c, AK_ERR_PARSE, "line %ld: JOINT has no name", c->token_line);
            int32_t parent = stack[depth - 1];
            /* add_node may move c->nodes: an End Site's name comes from a copy of its parent's */
            if (end_site) snprintf(name, sizeof name, "%s", c->nodes[parent].name);
            TRY(add_node(c, name, parent, end_site, &me));
            TRY(expect(c, "{", end_site ? "after End Site" : "after the JOINT name"));
            stack[depth++] = (int32_t)me;
        } else {
            return fail(c, AK_ERR_PARSE, "line %ld: unexpected '%.60s' in the hierarchy of '%.100s'", c->token_line, tok,
                        top->name);
        }
    }
    return AK_OK;
}

/* ---- static helpers: motion ------------------------------------------------------------ */

/* Bytes the clip will take per frame (the keys built here and ak_clip_build's copy). */
static size_t clip_bytes_per_frame(const bv_ctx* c) {
    size_t per = 0;
    for (size_t i = 0; i < c->node_count; ++i) {
        const bv_node* n = &c->nodes[i];
        if (n->end_site) continue;
        per += sizeof(float) * 5; /* rotation key: time + quaternion */
        for (uint8_t k = 0; k < n->channel_count; ++k)
            if (n->channels[k] <= BV_ZPOS) {
                per += sizeof(float) * 4; /* translation key: time + vec3 */
                break;
            }
    }
    return 2 * per;
}

static ak_result read_motion(bv_ctx* c) {
    char tok[BV_TOKEN];
    double v = 0.0;
    TRY(expect(c, "MOTION", "after the hierarchy"));
    TRY(expect(c, "Frames:", "after MOTION"));
    TRY(next_token(c, tok));
    char* end = NULL;
    errno = 0;
    unsigned long long frames = strtoull(tok, &end, 10);
    if (!tok[0] || !isdigit((unsigned char)tok[0]) || *end != 0 || errno == ERANGE)
        return fail(c, AK_ERR_PARSE, "line %ld: Frames: '%.60s' is not a frame count", c->token_line, tok);
    TRY(expect(c, "Frame", "after the frame count"));
    TRY(expect(c, "Time:", "after 'Frame'"));
    TRY(next_number(c, "Frame Time", &c->frame_time));
    if (!(c->frame_time > 0.0))
        return fail(c, AK_ERR_BAD_DATA, "line %ld: Frame Time %g must be positive", c->token_line, c->frame_time);
    if (frames > 0 && !ak_finitef((float)((double)(frames - 1) * c->frame_time)))
        return fail(c, AK_ERR_BAD_DATA, "line %ld: %llu frames of %g s overflow the clip's float time", c->token_line,
                    frames, c->frame_time);
    if (frames > 0 && c->channel_total == 0)
        return fail(c, AK_ERR_PARSE, "line %ld: %llu frames declared but no joint has CHANNELS", c->token_line, frames);
    /* The declared count must fit the budget before anything is read for it... */
    akp_budget trial = c->budget; /* a check only: the values are charged as they arrive */
    if (frames > SIZE_MAX / (c->channel_total ? c->channel_total : 1) / sizeof(float) ||
        !akp_budget_take(&trial, (size_t)frames, c->channel_total * sizeof(float) + clip_bytes_per_frame(c)))
        return fail(c, AK_ERR_UNSUPPORTED,
                    "line %ld: %llu frames of %zu channels would exceed the memory budget of %zu bytes "
                    "(ak_io_desc.memory_budget)",
                    c->token_line, frames, c->channel_total, c->budget.limit);
    c->frames = (size_t)frames;
    /* ...and memory grows only with the values actually present. */
    size_t want = c->frames * c->channel_total;
    while (c->value_count < want) {
        TRY(next_token(c, tok));
        if (!tok[0])
            return fail(c, AK_ERR_PARSE, "the motion data ends after %zu complete frames of the %zu declared (truncated?)",
                        c->value_count / c->channel_total, c->frames);
        TRY(number(c, tok, "a channel value", &v));
        if (c->value_count == c->value_cap) {
            size_t cap = c->value_cap ? 2 * c->value_cap : 4096;
            if (cap > want) cap = want;
            TRY(charge(c, cap, sizeof(float), "BVH motion"));
            float* nv = (float*)akp_alloc(c->alloc, cap * sizeof(float));
            if (!nv) return fail(c, AK_ERR_NO_MEMORY, "out of memory for %zu motion values", cap);
            if (c->value_count) memcpy(nv, c->values, c->value_count * sizeof(float));
            akp_free(c->alloc, c->values);
            c->values = nv;
            c->value_cap = cap;
        }
        float f = (float)v;
        if (!ak_finitef(f))
            return fail(c, AK_ERR_BAD_DATA, "line %ld: channel value '%.60s' overflows a float", c->token_line, tok);
        c->values[c->value_count++] = f;
    }
    /* A file cut inside its last number ("-19.3215" cut to "-19.3") would parse: the last
     * line of the motion must end with a newline (every exporter writes one). */
    const long last_line = c->line;
    TRY(next_token(c, tok));
    if (tok[0])
        return fail(c, AK_ERR_PARSE, "line %ld: '%.60s' after the %zu declared frames", c->token_line, tok, c->frames);
    if (c->line == last_line) {
        c->token_line = c->line;
        if (c->frames > 0)
            return fail(c, AK_ERR_PARSE, "line %ld: the file ends inside frame %zu (truncated?): the last line has no newline",
                        c->line, c->frames);
        return fail(c, AK_ERR_PARSE, "line %ld: the file ends inside the Frame Time line (truncated?): no newline",
                    c->line);
    }
    if (!c->mem && ferror(c->file)) return fail(c, AK_ERR_IO, "read error");
    return AK_OK;
}

/* ---- static helpers: scene --------------------------------------------------------------- */

static ak_result build_skeleton(bv_ctx* c) {
    size_t n = c->node_count;
    TRY(charge(c, n, sizeof(akp_io_node) + sizeof(int32_t) + 256, "BVH skeleton"));
    akp_io_node* desc = (akp_io_node*)akp_calloc(c->alloc, n * sizeof(akp_io_node));
    int32_t* joint_of_node = (int32_t*)akp_alloc(c->alloc, n * sizeof(int32_t));
    ak_result r = AK_ERR_NO_MEMORY;
    if (!desc || !joint_of_node) {
        fail(c, r, "out of memory");
        goto done;
    }
    for (size_t i = 0; i < n; ++i) {
        const bv_node* b = &c->nodes[i];
        desc[i].name = b->name;
        desc[i].parent = b->parent;
        desc[i].rest = ak_transform_identity();
        desc[i].rest.translation = ak_vec3_make((float)b->offset[0], (float)b->offset[1], (float)b->offset[2]);
        if (!ak_vec3_is_finite(desc[i].rest.translation)) {
            r = fail(c, AK_ERR_BAD_DATA, "'%.100s': OFFSET overflows a float", b->name);
            goto done;
        }
    }
    r = akp_io_build_skeleton(c->scene, desc, n, joint_of_node, c->name, c->diag);
    /* nodes are parents-first in file order already, so joint i is node i */
    for (size_t i = 0; r == AK_OK && i < n; ++i)
        if (joint_of_node[i] != (int32_t)i) r = fail(c, AK_ERR_BAD_HIERARCHY, "internal: node order changed");
    if (r == AK_OK) {
        c->scene->is_joint = (bool*)akp_calloc(&c->scene->alloc, n * sizeof(bool));
        if (!c->scene->is_joint) r = fail(c, AK_ERR_NO_MEMORY, "out of memory");
        for (size_t i = 0; r == AK_OK && i < n; ++i) c->scene->is_joint[i] = !c->nodes[i].end_site;
    }
done:
    akp_free(c->alloc, desc);
    akp_free(c->alloc, joint_of_node);
    return r;
}

/* Rotation of frame f of node n: the product of its rotation channels in the listed order. */
static ak_quat frame_rotation(const bv_ctx* c, const bv_node* n, size_t f) {
    double q[4] = {0, 0, 0, 1}; /* x y z w */
    const float* vals = c->values + f * c->channel_total + n->first_value;
    for (uint8_t k = 0; k < n->channel_count; ++k) {
        if (n->channels[k] < BV_XROT) continue;
        int axis = n->channels[k] - BV_XROT;
        double half = 0.5 * (double)vals[k] * 3.14159265358979323846 / 180.0;
        double r[4] = {0, 0, 0, cos(half)};
        r[axis] = sin(half);
        /* q = q * r (r applied first to column vectors: intrinsic order) */
        double x = q[3] * r[0] + q[0] * r[3] + q[1] * r[2] - q[2] * r[1];
        double y = q[3] * r[1] - q[0] * r[2] + q[1] * r[3] + q[2] * r[0];
        double z = q[3] * r[2] + q[0] * r[1] - q[1] * r[0] + q[2] * r[3];
        double w = q[3] * r[3] - q[0] * r[0] - q[1] * r[1] - q[2] * r[2];
        q[0] = x, q[1] = y, q[2] = z, q[3] = w;
    }
    return ak_quat_make((float)q[0], (float)q[1], (float)q[2], (float)q[3]);
}

static ak_result build_clip(bv_ctx* c) {
    size_t nf = c->frames, nj = c->joint_count;
    size_t key_floats = 0; /* all key arrays in one block: times, then values per channel */
    for (size_t i = 0; i < c->node_count; ++i) {
        const bv_node* n = &c->nodes[i];
        if (n->end_site) continue;
        bool pos = false;
        for (uint8_t k = 0; k < n->channel_count; ++k) pos = pos || n->channels[k] <= BV_ZPOS;
        key_floats += (pos ? nf * 3 : 3) + nf * 4 + 3;
    }
    TRY(charge(c, nf + key_floats, sizeof(float), "BVH clip keys"));
    TRY(charge(c, 3 * nj, sizeof(ak_raw_channel), "BVH clip channels"));
    float* times = (float*)akp_alloc(c->alloc, (nf + key_floats) * sizeof(float));
    ak_raw_channel* ch = (ak_raw_channel*)akp_calloc(c->alloc, 3 * nj * sizeof(ak_raw_channel));
    ak_result r = AK_OK;
    if (!times || !ch) {
        r = fail(c, AK_ERR_NO_MEMORY, "out of memory for the clip");
        goto done;
    }
    for (size_t f = 0; f < nf; ++f) {
        times[f] = (float)((double)f * c->frame_time);
        if (f > 0 && !(times[f] > times[f - 1])) {
            r = fail(c, AK_ERR_UNSUPPORTED, "frame %zu: its time %g s is not after the previous one in float precision",
                     f, (double)f * c->frame_time);
            goto done;
        }
    }
    static const float zero_time = 0.0f;
    float* vals = times + nf;
    size_t nch = 0;
    for (size_t i = 0; i < c->node_count; ++i) {
        const bv_node* n = &c->nodes[i];
        if (n->end_site) continue;
        bool pos = false;
        for (uint8_t k = 0; k < n->channel_count; ++k) pos = pos || n->channels[k] <= BV_ZPOS;
        /* translation: OFFSET with the listed position axes replaced */
        ak_raw_channel* t = &ch[nch++];
        t->target = AK_CHANNEL_TRANSLATION;
        t->index = (uint32_t)i;
        t->component_count = 3;
        t->interp = AK_INTERP_LINEAR;
        t->key_count = pos ? nf : 1;
        t->times = pos ? times : &zero_time;
        t->values = vals;
        for (size_t f = 0; f < t->key_count; ++f, vals += 3) {
            for (int e = 0; e < 3; ++e) vals[e] = (float)n->offset[e];
            const float* fv = c->values + f * c->channel_total + n->first_value;
            for (uint8_t k = 0; pos && k < n->channel_count; ++k)
                if (n->channels[k] <= BV_ZPOS) vals[n->channels[k]] = fv[k];
        }
        ak_raw_channel* rc = &ch[nch++];
        rc->target = AK_CHANNEL_ROTATION;
        rc->index = (uint32_t)i;
        rc->component_count = 4;
        rc->interp = AK_INTERP_LINEAR;
        rc->key_count = nf;
        rc->times = times;
        rc->values = vals;
        ak_quat prev = ak_quat_identity();
        for (size_t f = 0; f < nf; ++f, vals += 4) {
            ak_quat q = frame_rotation(c, n, f);
            if (f > 0 && ak_quat_dot(q, prev) < 0.0f) q = ak_quat_neg(q); /* the same rotation, no long way round */
            prev = q;
            vals[0] = q.x, vals[1] = q.y, vals[2] = q.z, vals[3] = q.w;
        }
        ak_raw_channel* sc = &ch[nch++];
        sc->target = AK_CHANNEL_SCALE;
        sc->index = (uint32_t)i;
        sc->component_count = 3;
        sc->interp = AK_INTERP_LINEAR;
        sc->key_count = 1;
        sc->times = &zero_time;
        vals[0] = vals[1] = vals[2] = 1.0f;
        sc->values = vals;
        vals += 3;
    }
    ak_raw_clip raw = {
        .name = "Motion",
        .duration = (float)((double)(nf - 1) * c->frame_time),
        .channels = ch,
        .channel_count = nch,
        .joint_count = c->node_count,
    };
    ak_diag sub;
    r = ak_clip_build(&raw, c->alloc, &c->scene->clips[0], &sub);
    if (r != AK_OK) fail(c, r, "clip: %s", sub.message);
done:
    akp_free(c->alloc, times);
    akp_free(c->alloc, ch);
    return r;
}

static ak_result load(bv_ctx* c) {
    TRY(read_hierarchy(c));
    TRY(read_motion(c));
    c->token_line = 0;
    c->token_offset = 0;
    size_t clips = c->frames > 0 && !c->desc->skip_animations ? 1 : 0;
    ak_result r = ak_scene_alloc(0, 0, clips, c->alloc, &c->scene);
    if (r != AK_OK) return fail(c, r, "out of memory");
    akp_io_copy_name(c->scene->name, c->scene_name);
    TRY(build_skeleton(c));
    if (clips) TRY(build_clip(c));
    return AK_OK;
}

/* ---- the reader ------------------------------------------------------------------------ */

ak_result akp_io_load_bvh(const char* path, const uint8_t* data, size_t size, const char* name,
                          const ak_io_desc* desc, const ak_allocator* alloc, ak_scene** out_scene, ak_diag* diag) {
    bv_ctx c;
    memset(&c, 0, sizeof c);
    c.alloc = alloc;
    c.desc = desc;
    c.name = path ? path : name;
    c.scene_name = name;
    c.diag = diag;
    c.line = 1;
    size_t input = size;
    if (path) {
        c.file = fopen(path, "rb");
        if (!c.file) return fail(&c, AK_ERR_IO, "cannot open file");
        long end = -1;
        if (fseek(c.file, 0, SEEK_END) == 0) end = ftell(c.file);
        if (end < 0 || fseek(c.file, 0, SEEK_SET) != 0) {
            fclose(c.file);
            return fail(&c, AK_ERR_IO, "cannot determine the file size (not a regular file?)");
        }
        input = (size_t)end;
    } else {
        c.mem = data;
        c.mem_size = size;
    }
    c.budget = akp_io_budget(desc, input);
    ak_result r = AK_OK;
    if (c.file) {
        r = charge(&c, BV_WINDOW, 1, "read window");
        if (r == AK_OK) {
            c.window = (uint8_t*)akp_alloc(alloc, BV_WINDOW);
            if (!c.window) r = fail(&c, AK_ERR_NO_MEMORY, "out of memory");
        }
    } else if (size >= 3 && data[0] == 0xEF && data[1] == 0xBB && data[2] == 0xBF) {
        c.win_pos = c.offset = 3; /* UTF-8 byte order mark */
    }
    if (r == AK_OK && c.file) { /* the same byte order mark in a file */
        int b0 = next_byte(&c), b1 = b0 == 0xEF ? next_byte(&c) : -1, b2 = b1 == 0xBB ? next_byte(&c) : -1;
        if (!(b0 == 0xEF && b1 == 0xBB && b2 == 0xBF)) {
            c.win_pos = 0;
            c.offset = 0;
        }
    }
    if (r == AK_OK) r = load(&c);
    if (c.file) fclose(c.file);
    akp_free(alloc, c.window);
    akp_free(alloc, c.nodes);
    akp_free(alloc, c.values);
    if (r != AK_OK) {
        ak_scene_destroy(c.scene);
        return r;
    }
    *out_scene = c.scene;
    return AK_OK;
}

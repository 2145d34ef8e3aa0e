/* Shared CLI glue: parsing, errors, loading, JSON, progress. */
#include "cli.h"

#include <ctype.h>
#include <dirent.h> /* opendir: a rig file beside an OBJ */
#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

int cli_parse(const char* cmd, int argc, char** argv, const cli_opt* opts, size_t opt_count, cli_args* out) {
    memset(out, 0, sizeof(*out));
    out->cmd = cmd;
    for (int i = 0; i < argc; ++i) {
        const char* a = argv[i];
        if (strcmp(a, "--help") == 0 || strcmp(a, "-h") == 0) {
            out->help = true;
            continue;
        }
        if (a[0] == '-' && a[1] != '\0' && !(isdigit((unsigned char)a[1]) || a[1] == '.')) {
            /* --name=value is accepted too */
            const char* eq = strchr(a, '=');
            size_t nlen = eq ? (size_t)(eq - a) : strlen(a);
            size_t k = 0;
            for (; k < opt_count; ++k) {
                if ((strlen(opts[k].name) == nlen && strncmp(opts[k].name, a, nlen) == 0) ||
                    (opts[k].alias && strlen(opts[k].alias) == nlen && strncmp(opts[k].alias, a, nlen) == 0))
                    break;
            }
            if (k == opt_count) return cli_usage(cmd, "unknown option '%s'", a);
            if (opts[k].has_value) {
                if (eq) out->values[k] = eq + 1;
                else if (i + 1 < argc) out->values[k] = argv[++i];
                else return cli_usage(cmd, "option '%.*s' needs a value", (int)nlen, a);
            } else {
                if (eq) return cli_usage(cmd, "option '%s' takes no value", opts[k].name);
                out->values[k] = "1";
            }
            if (out->all_count == CLI_MAX_ALL) return cli_usage(cmd, "too many options (at most %d)", CLI_MAX_ALL);
            out->all_opt[out->all_count] = (int)k;
            out->all_values[out->all_count++] = out->values[k];
            continue;
        }
        if (out->pos_count >= CLI_MAX_POS) return cli_usage(cmd, "too many arguments");
        out->pos[out->pos_count++] = a;
    }
    return CLI_OK;
}

const char* cli_get(const cli_args* a, const cli_opt* opts, size_t opt_count, const char* name) {
    for (size_t k = 0; k < opt_count && k < CLI_MAX_OPTS; ++k)
        if (strcmp(opts[k].name, name) == 0) return a->values[k];
    return NULL;
}

size_t cli_get_all(const cli_args* a, const cli_opt* opts, size_t opt_count, const char* name, const char** out,
                   size_t cap) {
    size_t n = 0;
    for (int i = 0; i < a->all_count; ++i)
        if ((size_t)a->all_opt[i] < opt_count && strcmp(opts[a->all_opt[i]].name, name) == 0 && n < cap)
            out[n++] = a->all_values[i];
    return n;
}

size_t cli_escape(char* out, size_t cap, const char* s) {
    size_t n = 0;
    if (!cap) return 0;
#define CLI_PUT_(c) (n + 1 < cap ? (void)(out[n++] = (c)) : (void)0)
    const unsigned char* p = (const unsigned char*)(s ? s : "");
    while (*p) {
        unsigned char c = *p;
        const size_t len = ak_utf8_char(p, SIZE_MAX);
        const bool ok = len > 0;
        const bool c1 = ok && len == 2 && c == 0xC2 && p[1] < 0xA0; /* U+0080..U+009F: C1 controls */
        if (!ok || c < 0x20 || c == 0x7f || c1) {
            char hex[8];
            snprintf(hex, sizeof hex, "\\x%02x", c1 ? p[1] : c);
            if (c1) snprintf(hex, sizeof hex, "\\u%04x", p[1]);
            if (n + strlen(hex) + 1 > cap) break;
            for (const char* h = hex; *h; ++h) CLI_PUT_(*h);
            p += c1 ? 2 : 1;
            continue;
        }
        if (n + len + 1 > cap) break;
        for (size_t k = 0; k < len; ++k) CLI_PUT_((char)p[k]);
        p += len;
    }
#undef CLI_PUT_
    out[n] = '\0';
    return n;
}

/* Format, escape control bytes and invalid UTF-8 (names and paths quoted from files must not
 * reach the terminal raw: an ESC sequence in a BVH joint name would retitle it or clear it),
 * print one line. */
static void print_escaped(const char* cmd, const char* fmt, va_list ap) {
    char raw[2048], safe[4096];
    vsnprintf(raw, sizeof raw, fmt, ap);
    cli_escape(safe, sizeof safe, raw);
    fprintf(stderr, "animkit %s: %s\n", cmd, safe);
}

int cli_fail(const char* cmd, const char* fmt, ...) {
    va_list ap;
    va_start(ap, fmt);
    print_escaped(cmd, fmt, ap);
    va_end(ap);
    return CLI_BAD_INPUT;
}

int cli_usage(const char* cmd, const char* fmt, ...) {
    va_list ap;
    va_start(ap, fmt);
    print_escaped(cmd, fmt, ap);
    fprintf(stderr, "try 'animkit %s --help'\n", cmd);
    va_end(ap);
    return CLI_BAD_USAGE;
}

bool cli_quiet = false;

void cli_wrote(const char* path, const char* fmt, ...) {
    if (cli_quiet) return;
    char safe[1024];
    cli_escape(safe, sizeof safe, path);
    fprintf(stderr, "wrote %s", safe);
    if (fmt && *fmt) {
        char raw[1024], detail[2048];
        va_list ap;
        va_start(ap, fmt);
        vsnprintf(raw, sizeof raw, fmt, ap);
        va_end(ap);
        cli_escape(detail, sizeof detail, raw);
        fprintf(stderr, ": %s", detail);
    }
    fputc('\n', stderr);
}

int cli_no_clip(const char* cmd, const char* file, const char* wanted, const ak_scene* s) {
    char names[1024] = "";
    size_t used = 0;
    for (size_t c = 0; c < s->clip_count && used + 8 < sizeof names; ++c) {
        const char* n = ak_clip_name(s->clips[c]);
        int w = snprintf(names + used, sizeof names - used, "%s#%zu '%s'", c ? ", " : "", c, n && n[0] ? n : "");
        if (w < 0) break;
        used += (size_t)w < sizeof names - used ? (size_t)w : sizeof names - used - 1;
    }
    if (s->clip_count == 0) return cli_fail(cmd, "%s: no clip '%s': the file has no clips", file, wanted);
    return cli_fail(cmd, "%s: no clip '%s'; its clip%s (by name or number): %s", file, wanted, cli_plural(s->clip_count),
                    names);
}

void cli_time_note(const char* cmd, float t, const ak_clip* clip) {
    if (!clip || cli_quiet) return;
    const float d = ak_clip_duration(clip);
    if (t >= 0.0f && t <= d) return;
    char name[256];
    cli_escape(name, sizeof name, ak_clip_name(clip));
    fprintf(stderr, "animkit %s: note: --time %g is %s clip '%s' (0 to %g s): its %s pose is used\n", cmd, (double)t,
            t < 0.0f ? "before" : "past the end of", name, (double)d, t < 0.0f ? "first" : "last");
}

int cli_work_check(const char* cmd, double work, const char* what, const char* lower) {
    double budget = CLI_WORK_BUDGET;
    const char* env = getenv("ANIMKIT_MAX_WORK");
    if (env && *env) {
        char* end = NULL;
        double v = strtod(env, &end);
        if (*end || !(v > 0.0) || !isfinite(v)) return cli_fail(cmd, "ANIMKIT_MAX_WORK='%.40s' is not a positive number", env);
        budget = v;
    }
    if (!(work <= budget))
        return cli_fail(cmd, "the run asks for %.3g %s, above the work budget of %.3g; lower %s (or raise the budget "
                        "with the environment variable ANIMKIT_MAX_WORK)", work, what, budget, lower);
    return CLI_OK;
}

bool cli_parse_float(const char* s, float* out) {
    if (!s || !*s) return false;
    char* end = NULL;
    errno = 0;
    double v = strtod(s, &end);
    /* ERANGE on underflow (a subnormal or a value rounding to 0) is still a number */
    if ((errno && !(errno == ERANGE && fabs(v) < 1.0)) || *end != '\0' || !isfinite(v) || fabs(v) > 3.0e38) return false;
    *out = (float)v;
    return true;
}

bool cli_parse_int(const char* s, long lo, long hi, long* out) {
    if (!s || !*s) return false;
    char* end = NULL;
    errno = 0;
    long v = strtol(s, &end, 10);
    if (errno || *end != '\0' || v < lo || v > hi) return false;
    *out = v;
    return true;
}

bool cli_parse_vec3(const char* s, ak_vec3* out) {
    if (!s) return false;
    char buf[128];
    if (strlen(s) >= sizeof buf) return false;
    strcpy(buf, s);
    float v[3];
    /* split by hand: strtok would read "1,,2,3" as 1,2,3 and ignore a trailing "," */
    char* tok = buf;
    for (int i = 0; i < 3; ++i) {
        char* comma = strchr(tok, ',');
        if ((i < 2) != (comma != NULL)) return false;
        if (comma) *comma = '\0';
        if (!cli_parse_float(tok, &v[i])) return false;
        if (comma) tok = comma + 1;
    }
    *out = ak_vec3_make(v[0], v[1], v[2]);
    return true;
}

bool cli_parse_size(const char* s, int* w, int* h) {
    if (!s) return false;
    const char* x = strchr(s, 'x');
    if (!x) return false;
    char a[32];
    size_t n = (size_t)(x - s);
    if (n == 0 || n >= sizeof a) return false;
    memcpy(a, s, n);
    a[n] = '\0';
    long lw, lh;
    if (!cli_parse_int(a, 8, 8192, &lw) || !cli_parse_int(x + 1, 8, 8192, &lh)) return false;
    *w = (int)lw;
    *h = (int)lh;
    return true;
}

bool cli_has_ext(const char* path, const char* ext) {
    size_t n = strlen(path), e = strlen(ext);
    return n >= e && strcasecmp(path + n - e, ext) == 0;
}

int cli_load_scene(const char* cmd, const char* spec, ak_scene** out) {
    *out = NULL;
    if (!spec || !*spec) return cli_usage(cmd, "missing FILE or builtin:NAME");
    if (strncmp(spec, "builtin:", 8) == 0) {
        ak_result r = ak_builtin_create(spec, NULL, NULL, out);
        if (r == AK_ERR_NOT_FOUND) return cli_fail(cmd, "%s: unknown built-in model (try builtin:humanoid or builtin:cylinder)", spec);
        if (r != AK_OK) return cli_fail(cmd, "%s: %s", spec, ak_result_string(r));
        return CLI_OK;
    }
    struct stat st;
    if (stat(spec, &st) != 0) return cli_fail(cmd, "%s: no such file", spec);
    if (S_ISDIR(st.st_mode)) return cli_fail(cmd, "%s: is a directory, not a model file", spec);
    ak_diag diag;
    memset(&diag, 0, sizeof diag);
    ak_result r = ak_io_load(spec, NULL, NULL, out, &diag);
    if (r != AK_OK) {
        return cli_fail(cmd, "%s: %s", spec, diag.message[0] ? diag.message : ak_result_string(r));
    }
    return CLI_OK;
}

/* Node of the scene mesh whose morph range starts at morph index idx, or -1. */
static int morph_node(const ak_scene* s, uint32_t idx) {
    for (size_t m = 0, off = 0; m < s->mesh_count; ++m) {
        size_t t = s->meshes[m].mesh ? s->meshes[m].mesh->morph_target_count : 0;
        if (t && off == idx) return s->meshes[m].node;
        off += t;
    }
    return -1;
}

bool cli_clip_channel_repeats(const ak_scene* s, const ak_clip* clip, size_t i) {
    if (ak_clip_channel_target(clip, i) != AK_CHANNEL_MORPH_WEIGHTS) return false;
    int node = morph_node(s, ak_clip_channel_index(clip, i));
    if (node < 0) return false;
    for (size_t k = 0; k < i; ++k)
        if (ak_clip_channel_target(clip, k) == AK_CHANNEL_MORPH_WEIGHTS &&
            morph_node(s, ak_clip_channel_index(clip, k)) == node)
            return true;
    return false;
}

size_t cli_clip_file_channel_count(const ak_scene* s, const ak_clip* clip) {
    size_t n = ak_clip_channel_count(clip), count = 0;
    for (size_t i = 0; i < n; ++i) count += !cli_clip_channel_repeats(s, clip, i);
    return count;
}

void cli_obj_rig_note(const char* cmd, const char* path) {
    /* look for a MakeHuman rig beside the file: FOLDER/x.mhskel */
    char dir[1024];
    const char* slash = strrchr(path, '/');
    size_t n = slash ? (size_t)(slash - path) : 1;
    if (n >= sizeof dir) return;
    if (slash) memcpy(dir, path, n);
    else dir[0] = '.';
    dir[n] = '\0';
    char rig[256] = "";
    DIR* d = opendir(dir);
    for (struct dirent* e = d ? readdir(d) : NULL; e; e = readdir(d))
        if (cli_has_ext(e->d_name, ".mhskel") && strlen(e->d_name) < sizeof rig) {
            strcpy(rig, e->d_name);
            break;
        }
    if (d) closedir(d);
    if (rig[0])
        fprintf(stderr, "note: %s: OBJ is geometry only; the MakeHuman rig beside it (%s) is not read, so the model "
                        "has no skeleton or skin and stays in its rest pose\n", path, rig);
    else
        fprintf(stderr, "note: %s: OBJ is geometry only (no skeleton, skin or animation)\n", path);
    (void)cmd;
}

void cli_json_string(FILE* f, const char* s) {
    fputc('"', f);
    for (const unsigned char* p = (const unsigned char*)(s ? s : ""); *p;) {
        const unsigned char c = *p;
        if (c >= 0x80) { /* copy a valid UTF-8 character; an invalid byte becomes U+FFFD */
            const size_t len = ak_utf8_char(p, SIZE_MAX);
            if (len) fwrite(p, 1, len, f), p += len;
            else fputs("\\ufffd", f), ++p;
            continue;
        }
        switch (c) {
        case '"': fputs("\\\"", f); break;
        case '\\': fputs("\\\\", f); break;
        case '\n': fputs("\\n", f); break;
        case '\r': fputs("\\r", f); break;
        case '\t': fputs("\\t", f); break;
        default:
            if (c < 0x20 || c == 0x7f) fprintf(f, "\\u%04x", c);
            else fputc(c, f);
        }
        ++p;
    }
    fputc('"', f);
}

void cli_json_write_number(FILE* f, double v) {
    if (isfinite(v)) fprintf(f, "%.9g", v);
    else fputs("null", f);
}

void cli_progress(const char* label, size_t done, size_t total) {
    if (cli_quiet || !isatty(STDERR_FILENO) || total == 0) return;
    const int width = 30;
    int filled = (int)((double)done / (double)total * width);
    if (filled > width) filled = width;
    fprintf(stderr, "\r%-12s [", label);
    for (int i = 0; i < width; ++i) fputc(i < filled ? '#' : '.', stderr);
    fprintf(stderr, "] %zu/%zu", done, total);
    if (done >= total) fputc('\n', stderr);
    fflush(stderr);
}

double cli_now(void) {
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

bool cli_mkdir_p(const char* path) {
    char buf[1024];
    if (!path || strlen(path) >= sizeof buf) return false;
    strcpy(buf, path);
    for (char* p = buf + 1; *p; ++p) {
        if (*p == '/') {
            *p = '\0';
            mkdir(buf, 0777);
            *p = '/';
        }
    }
    mkdir(buf, 0777);
    struct stat st;
    return stat(buf, &st) == 0 && S_ISDIR(st.st_mode);
}

int cli_usage_int(const char* cmd, const char* flag, const char* value, long lo, long hi) {
    const char* s = value ? value : "";
    size_t i = s[0] == '-' || s[0] == '+';
    bool digits = s[i] != '\0';
    for (; s[i]; ++i) digits = digits && s[i] >= '0' && s[i] <= '9';
    if (digits) return cli_usage(cmd, "%s %s is out of range: expected a whole number in %ld..%ld", flag, s, lo, hi);
    return cli_usage(cmd, "%s '%s' is not a whole number (expected %ld..%ld)", flag, s, lo, hi);
}

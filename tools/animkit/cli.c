/* Shared CLI glue: parsing, errors, loading, JSON, progress. */
#include "cli.h"

#include <ctype.h>
#include <errno.h>
#include <math.h>
#include <stdarg.h>
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
                else return cli_usage(cmd, "option '%s' needs a value", opts[k].name);
            } else {
                if (eq) return cli_usage(cmd, "option '%s' takes no value", opts[k].name);
                out->values[k] = "1";
            }
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

int cli_fail(const char* cmd, const char* fmt, ...) {
    va_list ap;
    va_start(ap, fmt);
    fprintf(stderr, "animkit %s: ", cmd);
    vfprintf(stderr, fmt, ap);
    fputc('\n', stderr);
    va_end(ap);
    return CLI_BAD_INPUT;
}

int cli_usage(const char* cmd, const char* fmt, ...) {
    va_list ap;
    va_start(ap, fmt);
    fprintf(stderr, "animkit %s: ", cmd);
    vfprintf(stderr, fmt, ap);
    fprintf(stderr, "\ntry 'animkit %s --help'\n", cmd);
    va_end(ap);
    return CLI_BAD_USAGE;
}

bool cli_parse_float(const char* s, float* out) {
    if (!s || !*s) return false;
    char* end = NULL;
    errno = 0;
    double v = strtod(s, &end);
    if (errno || *end != '\0' || !isfinite(v) || fabs(v) > 3.0e38) return false;
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
    char* save = NULL;
    char* tok = strtok_r(buf, ",", &save);
    for (int i = 0; i < 3; ++i) {
        if (!tok || !cli_parse_float(tok, &v[i])) return false;
        tok = strtok_r(NULL, ",", &save);
    }
    if (tok) return false;
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

void cli_json_string(FILE* f, const char* s) {
    fputc('"', f);
    for (const unsigned char* p = (const unsigned char*)(s ? s : ""); *p; ++p) {
        switch (*p) {
        case '"': fputs("\\\"", f); break;
        case '\\': fputs("\\\\", f); break;
        case '\n': fputs("\\n", f); break;
        case '\r': fputs("\\r", f); break;
        case '\t': fputs("\\t", f); break;
        default:
            if (*p < 0x20) fprintf(f, "\\u%04x", *p);
            else fputc(*p, f);
        }
    }
    fputc('"', f);
}

void cli_json_write_number(FILE* f, double v) {
    if (isfinite(v)) fprintf(f, "%.9g", v);
    else fputs("null", f);
}

void cli_progress(const char* label, size_t done, size_t total) {
    if (!isatty(STDERR_FILENO) || total == 0) return;
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

/* A streaming JSON writer with cJSON's exact output: see json_write.h. */
#include "json_write.h"

#include <errno.h>
#include <float.h>
#include <math.h>
#include <string.h>

static void put(akp_jw* w, const char* s, size_t len) {
    w->bytes += len;
    if (!w->f || w->failed) return;
    if (w->n + len > sizeof w->buf) {
        akp_jw_flush(w);
        if (w->failed) return;
        if (len > sizeof w->buf) {
            if (fwrite(s, 1, len, w->f) != len) w->failed = true, w->err = errno ? errno : EIO;
            return;
        }
    }
    memcpy(w->buf + w->n, s, len);
    w->n += len;
}

static void put_tabs(akp_jw* w, int count) {
    static const char tabs[16] = "\t\t\t\t\t\t\t\t\t\t\t\t\t\t\t\t";
    for (; count > 0; count -= 16) put(w, tabs, (size_t)(count < 16 ? count : 16));
}

/* A string literal as cJSON's print_string_ptr writes it. */
static void put_string(akp_jw* w, const char* s) {
    put(w, "\"", 1);
    const char* run = s ? s : "";
    const char* p = run;
    for (; *p; ++p) {
        unsigned char ch = (unsigned char)*p;
        if (ch >= 32 && ch != '"' && ch != '\\') continue;
        put(w, run, (size_t)(p - run));
        char esc[8];
        switch (ch) {
        case '"': put(w, "\\\"", 2); break;
        case '\\': put(w, "\\\\", 2); break;
        case '\b': put(w, "\\b", 2); break;
        case '\f': put(w, "\\f", 2); break;
        case '\n': put(w, "\\n", 2); break;
        case '\r': put(w, "\\r", 2); break;
        case '\t': put(w, "\\t", 2); break;
        default: snprintf(esc, sizeof esc, "\\u%04x", ch); put(w, esc, 6); break;
        }
        run = p + 1;
    }
    put(w, run, (size_t)(p - run));
    put(w, "\"", 1);
}

/* What comes before a value: the separator from the previous item, the indentation and the
 * key of an object member. */
static void begin_item(akp_jw* w, const char* key) {
    if (w->depth == 0) return;
    int d = w->depth - 1;
    if (w->is_object[d]) {
        if (w->has_items[d]) put(w, w->format ? ",\n" : ",", w->format ? 2 : 1);
        if (w->format) put_tabs(w, w->depth);
        put_string(w, key);
        put(w, w->format ? ":\t" : ":", w->format ? 2 : 1);
    } else if (w->has_items[d]) {
        put(w, w->format ? ", " : ",", w->format ? 2 : 1);
    }
    w->has_items[d] = true;
}

static void jw_open(akp_jw* w, const char* key, bool object) {
    begin_item(w, key);
    if (w->depth == AKP_JW_MAX_DEPTH) {
        w->failed = true, w->err = EOVERFLOW;
        return;
    }
    put(w, object ? (w->format ? "{\n" : "{") : "[", object && w->format ? 2 : 1);
    w->is_object[w->depth] = object;
    w->has_items[w->depth] = false;
    ++w->depth;
}

/* ---- public ---------------------------------------------------------------------------- */

void akp_jw_init(akp_jw* w, FILE* f, bool format) {
    memset(w, 0, offsetof(akp_jw, buf));
    w->f = f;
    w->format = format;
}

void akp_jw_object(akp_jw* w, const char* key) { jw_open(w, key, true); }

void akp_jw_array(akp_jw* w, const char* key) { jw_open(w, key, false); }

void akp_jw_end(akp_jw* w) {
    if (w->depth == 0) return;
    int d = --w->depth;
    if (!w->is_object[d]) {
        put(w, "]", 1);
        return;
    }
    if (w->format) {
        if (w->has_items[d]) put(w, "\n", 1);
        put_tabs(w, d);
    }
    put(w, "}", 1);
}

void akp_jw_number(akp_jw* w, const char* key, double v) {
    begin_item(w, key);
    char b[32];
    int len;
    /* cJSON 1.7.15's print_number (no integer case: -0.0 prints as "-0") */
    if (isnan(v) || isinf(v)) {
        len = snprintf(b, sizeof b, "null");
    } else {
        len = snprintf(b, sizeof b, "%1.15g", v);
        double test = 0.0;
        if (sscanf(b, "%lg", &test) != 1 ||
            !(fabs(test - v) <= (fabs(test) > fabs(v) ? fabs(test) : fabs(v)) * DBL_EPSILON))
            len = snprintf(b, sizeof b, "%1.17g", v);
    }
    for (int i = 0; i < len; ++i) /* cJSON writes '.' whatever the locale's decimal point */
        if (b[i] == ',') b[i] = '.';
    put(w, b, (size_t)len);
}

void akp_jw_string(akp_jw* w, const char* key, const char* s) {
    begin_item(w, key);
    put_string(w, s);
}

bool akp_jw_flush(akp_jw* w) {
    if (w->f && !w->failed && w->n && fwrite(w->buf, 1, w->n, w->f) != w->n) w->failed = true, w->err = errno ? errno : EIO;
    w->n = 0;
    return !w->failed;
}

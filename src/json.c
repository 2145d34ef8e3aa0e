/* Strict JSON reading of scene files (particles, cloth, fluid, boids): see json.h. */
#include "json.h"

#include <float.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static const char* type_name(const cJSON* v) {
    if (cJSON_IsNumber(v)) return "a number";
    if (cJSON_IsString(v)) return "a string";
    if (cJSON_IsBool(v)) return "a boolean";
    if (cJSON_IsNull(v)) return "null";
    if (cJSON_IsArray(v)) return "an array";
    if (cJSON_IsObject(v)) return "an object";
    return "an invalid value";
}

bool akp_json_fail(akp_json* j, const char* path, const char* key, const char* fmt, ...) {
    if (j->failed) return false;
    j->failed = true;
    char where[256];
    akp_json_key(where, sizeof where, path ? path : "", key ? key : "");
    char what[384];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(what, sizeof what, fmt, ap);
    va_end(ap);
    const char* file = j->file ? j->file : "(scene)";
    if (where[0])
        snprintf(j->message, sizeof j->message, "%.150s: %.120s: %.230s", file, where, what);
    else
        snprintf(j->message, sizeof j->message, "%.150s: %.350s", file, what);
    /* Keys and strings come from the file: a control character in one must not split the
     * one-line message (or reach a terminal). */
    for (char* c = j->message; *c; ++c)
        if ((unsigned char)*c < 0x20 || *c == 0x7f) *c = '?';
    return false;
}

ak_result akp_json_diag(const akp_json* j, ak_result code, ak_diag* out_diag) {
    if (!out_diag) return code;
    memset(out_diag, 0, sizeof *out_diag);
    snprintf(out_diag->path, sizeof out_diag->path, "%s", j->file ? j->file : "");
    out_diag->byte_offset = -1;
    snprintf(out_diag->message, sizeof out_diag->message, "%s", j->message);
    return code;
}

ak_result akp_diag_set(ak_diag* out_diag, ak_result code, const char* file, const char* fmt, ...) {
    if (!out_diag) return code;
    akp_json j = {.file = file};
    char what[400];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(what, sizeof what, fmt, ap);
    va_end(ap);
    akp_json_fail(&j, "", NULL, "%s", what);
    return akp_json_diag(&j, code, out_diag);
}

const char* akp_json_index(char* buf, size_t size, const char* base, size_t index) {
    if (size) snprintf(buf, size, "%s[%zu]", base ? base : "", index);
    return buf;
}

const char* akp_json_key(char* buf, size_t size, const char* base, const char* key) {
    if (!size) return buf;
    base = base ? base : "";
    key = key ? key : "";
    if (!base[0])
        snprintf(buf, size, "%s", key);
    else if (!key[0])
        snprintf(buf, size, "%s", base);
    else
        snprintf(buf, size, "%s.%s", base, key);
    return buf;
}

/* Where text[0, size) breaks strict JSON (RFC 8259) at the lexical level, or NULL; *what says how.
 * cJSON is lenient where a scene reader must not be: it skips a leading byte-order mark, reads
 * numbers with strtod ("01", "1.", "1e" pass), stops at a raw NUL (so `{"dt":0.1}\0junk` and
 * "rk4<NUL>junk" pass as "rk4"), and copies invalid UTF-8 and raw control bytes into strings.
 * This pass checks the bytes; cJSON then checks the structure. "\u0000" is refused too: cJSON
 * decodes it into a NUL that ends the C string early, so "dt\u0000" would read as "dt". */
static const char* strict_json_error(const char* text, size_t size, const char** what) {
    const unsigned char* s = (const unsigned char*)text;
    if (size >= 3 && s[0] == 0xEF && s[1] == 0xBB && s[2] == 0xBF) {
        *what = "the file starts with a byte-order mark (JSON text has none)";
        return text;
    }
    size_t i = 0;
    while (i < size) {
        unsigned char c = s[i];
        if (c == '\0') {
            *what = "a NUL byte";
            return text + i;
        }
        if (c == '"') { /* a string: escapes, no control bytes, valid UTF-8 */
            ++i;
            for (;;) {
                if (i >= size) { /* unterminated: cJSON says where */
                    *what = NULL;
                    return NULL;
                }
                c = s[i];
                if (c == '"') {
                    ++i;
                    break;
                }
                if (c == '\0') {
                    *what = "a NUL byte in a string";
                    return text + i;
                }
                if (c < 0x20) {
                    *what = "a control byte in a string (write it as an escape)";
                    return text + i;
                }
                if (c == '\\') {
                    if (i + 1 >= size) break; /* unterminated: cJSON says where */
                    unsigned char e = s[i + 1];
                    if (e == 'u') {
                        if (i + 5 >= size) break;
                        unsigned v = 0;
                        for (int k = 2; k < 6; ++k) {
                            unsigned char h = s[i + k];
                            unsigned d = h >= '0' && h <= '9'   ? (unsigned)(h - '0')
                                         : h >= 'a' && h <= 'f' ? (unsigned)(h - 'a' + 10)
                                         : h >= 'A' && h <= 'F' ? (unsigned)(h - 'A' + 10)
                                                                : 16u;
                            if (d == 16u) {
                                *what = "a \\u escape without four hex digits";
                                return text + i;
                            }
                            v = v * 16u + d;
                        }
                        if (v == 0) {
                            *what = "a string holds \\u0000 (NUL)";
                            return text + i;
                        }
                        i += 6;
                    } else if (strchr("\"\\/bfnrt", e) && e) {
                        i += 2;
                    } else {
                        *what = "an unknown escape in a string";
                        return text + i;
                    }
                    continue;
                }
                if (c < 0x80) {
                    ++i;
                    continue;
                }
                const size_t n = ak_utf8_char(s + i, size - i);
                if (!n) {
                    *what = "invalid UTF-8 in a string";
                    return text + i;
                }
                i += n;
            }
            continue;
        }
        if (c == '-' || (c >= '0' && c <= '9')) { /* a number: -?(0|[1-9]\d*)(\.\d+)?([eE][+-]?\d+)? */
            size_t at = i;
            if (c == '-') ++i;
            if (i < size && s[i] == '0') {
                ++i;
                if (i < size && s[i] >= '0' && s[i] <= '9') {
                    *what = "a number with a leading zero";
                    return text + at;
                }
            } else if (i < size && s[i] >= '1' && s[i] <= '9') {
                while (i < size && s[i] >= '0' && s[i] <= '9') ++i;
            } else {
                *what = "a malformed number";
                return text + at;
            }
            if (i < size && s[i] == '.') {
                ++i;
                if (!(i < size && s[i] >= '0' && s[i] <= '9')) {
                    *what = "a malformed number (a digit must follow the '.')";
                    return text + at;
                }
                while (i < size && s[i] >= '0' && s[i] <= '9') ++i;
            }
            if (i < size && (s[i] == 'e' || s[i] == 'E')) {
                ++i;
                if (i < size && (s[i] == '+' || s[i] == '-')) ++i;
                if (!(i < size && s[i] >= '0' && s[i] <= '9')) {
                    *what = "a malformed number (a digit must follow the exponent)";
                    return text + at;
                }
                while (i < size && s[i] >= '0' && s[i] <= '9') ++i;
            }
            continue;
        }
        ++i;
    }
    *what = NULL;
    return NULL;
}

cJSON* akp_json_parse(akp_json* j, const char* text, size_t size) {
    if (j->failed) return NULL;
    const char* what = NULL;
    const char* bad = strict_json_error(text, size, &what);
    if (bad) {
        size_t line = 1, col = 1;
        for (const char* p = text; p < bad; ++p) line += *p == '\n', col = *p == '\n' ? 1 : col + 1;
        akp_json_fail(j, "", NULL, "%s at line %zu, column %zu", what, line, col);
        return NULL;
    }
    const char* end = NULL;
    cJSON* root = cJSON_ParseWithLengthOpts(text, size, &end, false);
    if (!root) {
        /* cJSON reports where it stopped; turn the byte offset into a line and column. */
        size_t at = (end && end >= text && end <= text + size) ? (size_t)(end - text) : 0;
        size_t line = 1, col = 1;
        for (size_t i = 0; i < at; ++i) {
            if (text[i] == '\n') {
                ++line;
                col = 1;
            } else {
                ++col;
            }
        }
        akp_json_fail(j, "", NULL, "invalid JSON at line %zu, column %zu", line, col);
        return NULL;
    }
    /* Trailing content other than whitespace is an error, as in any strict reader. */
    if (end) {
        for (const char* p = end; p < text + size; ++p) {
            if (*p != ' ' && *p != '\t' && *p != '\n' && *p != '\r') {
                cJSON_Delete(root);
                akp_json_fail(j, "", NULL, "unexpected content after the JSON value");
                return NULL;
            }
        }
    }
    if (!cJSON_IsObject(root)) {
        akp_json_fail(j, "", NULL, "the top level is not an object (got %s)", type_name(root));
        cJSON_Delete(root);
        return NULL;
    }
    return root;
}

char* akp_json_read_file(akp_json* j, const char* path, size_t max_size, size_t* out_size) {
    *out_size = 0;
    if (!j->file) j->file = path;
    if (j->failed) return NULL;
    if (!max_size) max_size = AKP_JSON_MAX_SIZE;
    FILE* f = fopen(path, "rb");
    if (!f) {
        akp_json_fail(j, "", NULL, "cannot open the file");
        return NULL;
    }
    size_t cap = 4096, size = 0;
    char* text = malloc(cap);
    while (text) {
        if (size == cap) {
            if (cap >= max_size + 1) break;
            size_t next = cap * 2 > max_size + 1 ? max_size + 1 : cap * 2;
            char* grown = realloc(text, next);
            if (!grown) {
                free(text);
                text = NULL;
                break;
            }
            text = grown;
            cap = next;
        }
        size_t got = fread(text + size, 1, cap - size, f);
        size += got;
        if (got == 0) break;
    }
    bool read_error = ferror(f) != 0;
    fclose(f);
    if (!text) {
        akp_json_fail(j, "", NULL, "out of memory reading the file");
        return NULL;
    }
    if (read_error || size > max_size) {
        if (read_error)
            akp_json_fail(j, "", NULL, "read error");
        else
            akp_json_fail(j, "", NULL, "the file is larger than %zu bytes", max_size);
        free(text);
        return NULL;
    }
    text[size] = '\0'; /* size < cap here: the last read returned 0 with room left */
    *out_size = size;
    return text;
}

cJSON* akp_json_load(akp_json* j, const char* path, size_t max_size) {
    size_t size = 0;
    char* text = akp_json_read_file(j, path, max_size, &size);
    if (!text) return NULL;
    cJSON* root = akp_json_parse(j, text, size);
    free(text);
    return root;
}

bool akp_json_object(akp_json* j, const cJSON* obj, const char* path, const char* const* allowed) {
    if (j->failed) return false;
    if (!cJSON_IsObject(obj)) return akp_json_fail(j, path, NULL, "expected an object, got %s", type_name(obj));
    for (const cJSON* m = obj->child; m; m = m->next) {
        const char* name = m->string ? m->string : "";
        bool known = false;
        for (size_t i = 0; allowed && allowed[i]; ++i)
            if (strcmp(allowed[i], name) == 0) known = true;
        if (!known) {
            char list[256] = "";
            size_t used = 0;
            for (size_t i = 0; allowed && allowed[i] && used < sizeof list; ++i) {
                int w = snprintf(list + used, sizeof list - used, "%s%s", i ? ", " : "", allowed[i]);
                if (w < 0) break;
                used += (size_t)w;
            }
            return akp_json_fail(j, path, NULL, "unknown key \"%s\" (allowed: %s)", name, list);
        }
        for (const cJSON* o = obj->child; o != m; o = o->next)
            if (o->string && strcmp(o->string, name) == 0)
                return akp_json_fail(j, path, name, "the key appears twice");
    }
    return true;
}

/* The member key of obj, or NULL; fails when obj itself is not an object. */
static const cJSON* member(akp_json* j, const cJSON* obj, const char* path, const char* key, bool* ok) {
    *ok = !j->failed;
    if (!*ok) return NULL;
    if (!cJSON_IsObject(obj)) {
        *ok = akp_json_fail(j, path, NULL, "expected an object, got %s", type_name(obj));
        return NULL;
    }
    return cJSON_GetObjectItemCaseSensitive(obj, key);
}

/* A finite number in [lo, hi] from v, or an error at path.key. */
static bool number_value(akp_json* j, const cJSON* v, const char* path, const char* key, double lo, double hi,
                         double* out) {
    if (!cJSON_IsNumber(v)) return akp_json_fail(j, path, key, "expected a number, got %s", type_name(v));
    double x = v->valuedouble;
    if (!isfinite(x)) return akp_json_fail(j, path, key, "the number is not finite");
    if (x < lo || x > hi) return akp_json_fail(j, path, key, "%.9g is outside [%g, %g]", x, lo, hi);
    *out = x;
    return true;
}

bool akp_json_number(akp_json* j, const cJSON* obj, const char* path, const char* key, double lo, double hi,
                     double* inout) {
    bool ok;
    const cJSON* v = member(j, obj, path, key, &ok);
    if (!ok || !v) return ok;
    return number_value(j, v, path, key, lo, hi, inout);
}

/* The value is rounded to float before the bounds are compared, so a documented minimum such as
 * 1e-7 (which is not a float: 1e-7f is slightly above it) is accepted when written as 1e-7, and a
 * number beyond the float range fails here, naming its key, instead of turning into an infinity
 * that fails later without one. */
bool akp_json_float(akp_json* j, const cJSON* obj, const char* path, const char* key, float lo, float hi,
                    float* inout) {
    bool ok;
    const cJSON* v = member(j, obj, path, key, &ok);
    if (!ok || !v) return ok;
    double x = 0.0;
    if (!number_value(j, v, path, key, -HUGE_VAL, HUGE_VAL, &x)) return false;
    if (fabs(x) > (double)FLT_MAX)
        return akp_json_fail(j, path, key, "%.9g is beyond the range of a float (magnitude at most %.9g)", x,
                             (double)FLT_MAX);
    float f = (float)x;
    if (f < lo || f > hi) return akp_json_fail(j, path, key, "%.9g is outside [%g, %g]", x, (double)lo, (double)hi);
    *inout = f;
    return true;
}

bool akp_json_int(akp_json* j, const cJSON* obj, const char* path, const char* key, long lo, long hi,
                  long* inout) {
    bool ok;
    const cJSON* v = member(j, obj, path, key, &ok);
    if (!ok || !v) return ok;
    double x = 0.0;
    if (!number_value(j, v, path, key, (double)lo, (double)hi, &x)) return false;
    if (x != floor(x)) return akp_json_fail(j, path, key, "expected an integer, got %.9g", x);
    *inout = (long)x;
    return true;
}

bool akp_json_bool(akp_json* j, const cJSON* obj, const char* path, const char* key, bool* inout) {
    bool ok;
    const cJSON* v = member(j, obj, path, key, &ok);
    if (!ok || !v) return ok;
    if (!cJSON_IsBool(v)) return akp_json_fail(j, path, key, "expected true or false, got %s", type_name(v));
    *inout = cJSON_IsTrue(v);
    return true;
}

bool akp_json_str(akp_json* j, const cJSON* obj, const char* path, const char* key, const char** inout) {
    bool ok;
    const cJSON* v = member(j, obj, path, key, &ok);
    if (!ok || !v) return ok;
    if (!cJSON_IsString(v) || !v->valuestring)
        return akp_json_fail(j, path, key, "expected a string, got %s", type_name(v));
    *inout = v->valuestring;
    return true;
}

bool akp_json_enum(akp_json* j, const cJSON* obj, const char* path, const char* key, const char* const* names,
                   int* inout) {
    const char* s = NULL;
    if (!akp_json_str(j, obj, path, key, &s)) return false;
    if (!s) return true;
    char list[256] = "";
    size_t used = 0;
    for (int i = 0; names[i]; ++i) {
        if (strcmp(names[i], s) == 0) {
            *inout = i;
            return true;
        }
        if (used < sizeof list) {
            int w = snprintf(list + used, sizeof list - used, "%s%s", i ? ", " : "", names[i]);
            if (w > 0) used += (size_t)w;
        }
    }
    return akp_json_fail(j, path, key, "\"%s\" is not one of: %s", s, list);
}

bool akp_json_floats(akp_json* j, const cJSON* obj, const char* path, const char* key, size_t count, float lo,
                     float hi, float* inout) {
    bool ok;
    const cJSON* v = member(j, obj, path, key, &ok);
    if (!ok || !v) return ok;
    if (!cJSON_IsArray(v)) return akp_json_fail(j, path, key, "expected an array of %zu numbers, got %s", count, type_name(v));
    size_t n = 0;
    for (const cJSON* e = v->child; e; e = e->next) ++n;
    if (n != count) return akp_json_fail(j, path, key, "expected %zu numbers, got %zu", count, n);
    float tmp[16];
    float* dst = count <= 16 ? tmp : inout; /* small arrays are all-or-nothing */
    char at[256], el[280];
    akp_json_key(at, sizeof at, path, key);
    size_t i = 0;
    for (const cJSON* e = v->child; e; e = e->next, ++i) {
        double x = 0.0;
        if (!number_value(j, e, akp_json_index(el, sizeof el, at, i), NULL, lo, hi, &x)) return false;
        dst[i] = (float)x;
    }
    if (dst == tmp) memcpy(inout, tmp, count * sizeof(float));
    return true;
}

bool akp_json_vec3(akp_json* j, const cJSON* obj, const char* path, const char* key, ak_vec3* inout) {
    float v[3] = {inout->x, inout->y, inout->z};
    if (!akp_json_floats(j, obj, path, key, 3, -HUGE_VALF, HUGE_VALF, v)) return false;
    inout->x = v[0];
    inout->y = v[1];
    inout->z = v[2];
    return true;
}

const cJSON* akp_json_array(akp_json* j, const cJSON* obj, const char* path, const char* key, size_t max_count,
                            size_t* out_count) {
    *out_count = 0;
    bool ok;
    const cJSON* v = member(j, obj, path, key, &ok);
    if (!ok || !v) return NULL;
    if (!cJSON_IsArray(v)) {
        akp_json_fail(j, path, key, "expected an array, got %s", type_name(v));
        return NULL;
    }
    size_t n = 0;
    for (const cJSON* e = v->child; e; e = e->next) ++n;
    if (n > max_count) {
        akp_json_fail(j, path, key, "%zu elements, more than the limit of %zu", n, max_count);
        return NULL;
    }
    *out_count = n;
    return v->child;
}

const cJSON* akp_json_member(akp_json* j, const cJSON* obj, const char* path, const char* key) {
    bool ok;
    const cJSON* v = member(j, obj, path, key, &ok);
    if (!ok || !v) return NULL;
    if (!cJSON_IsObject(v)) {
        akp_json_fail(j, path, key, "expected an object, got %s", type_name(v));
        return NULL;
    }
    return v;
}

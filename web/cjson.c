/* The part of cJSON's API that animkit calls, for the WebAssembly build only (web/, docs/web.md).
 *
 * Natively animkit links Debian's libcjson; Debian ships no wasm32 build of it, and the page must
 * load nothing from the network, so this file implements the same functions over the same
 * struct (Debian's own <cjson/cJSON.h>, which scripts/build-web.sh puts on the include path):
 * parsing with a length and an end pointer (strict JSON, nesting at most CJSON_NESTING_LIMIT,
 * numbers through strtod as cJSON reads them, so scene files give the native build's floats),
 * look-ups, type tests, building trees, and printing (compact or tab-indented). Written for
 * animkit; tests/web checks it through the page (a cloth scene parsed here and natively must give
 * the same positions) and tests/fuzz/fuzz_web_cjson.c fuzzes the parser natively. */
#include <ctype.h>
#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cjson/cJSON.h>

/* ---- nodes ---- */

static cJSON* node_new(int type) {
    cJSON* n = calloc(1, sizeof *n);
    if (n) n->type = type;
    return n;
}

static char* str_dup(const char* s) {
    size_t len = strlen(s);
    char* d = malloc(len + 1);
    if (d) memcpy(d, s, len + 1);
    return d;
}

void cJSON_Delete(cJSON* item) {
    while (item) {
        cJSON* next = item->next;
        if (!(item->type & cJSON_IsReference) && item->child) cJSON_Delete(item->child);
        if (!(item->type & cJSON_IsReference)) free(item->valuestring);
        if (!(item->type & cJSON_StringIsConst)) free(item->string);
        free(item);
        item = next;
    }
}

void cJSON_free(void* object) { free(object); }
void* cJSON_malloc(size_t size) { return malloc(size); }

/* ---- parsing ---- */

typedef struct parser {
    const unsigned char* p;
    const unsigned char* end;
    int depth;
} parser;

static void skip_ws(parser* ps) {
    while (ps->p < ps->end && *ps->p <= 32 && *ps->p != 0) ++ps->p;
}

static int hex4(const unsigned char* s, unsigned* out) {
    unsigned v = 0;
    for (int i = 0; i < 4; ++i) {
        unsigned c = s[i], d;
        if (c >= '0' && c <= '9') d = c - '0';
        else if (c >= 'a' && c <= 'f') d = c - 'a' + 10;
        else if (c >= 'A' && c <= 'F') d = c - 'A' + 10;
        else return 0;
        v = v * 16 + d;
    }
    *out = v;
    return 1;
}

static size_t utf8_put(unsigned cp, char* out) {
    if (cp < 0x80) {
        out[0] = (char)cp;
        return 1;
    }
    if (cp < 0x800) {
        out[0] = (char)(0xC0 | (cp >> 6));
        out[1] = (char)(0x80 | (cp & 0x3F));
        return 2;
    }
    if (cp < 0x10000) {
        out[0] = (char)(0xE0 | (cp >> 12));
        out[1] = (char)(0x80 | ((cp >> 6) & 0x3F));
        out[2] = (char)(0x80 | (cp & 0x3F));
        return 3;
    }
    out[0] = (char)(0xF0 | (cp >> 18));
    out[1] = (char)(0x80 | ((cp >> 12) & 0x3F));
    out[2] = (char)(0x80 | ((cp >> 6) & 0x3F));
    out[3] = (char)(0x80 | (cp & 0x3F));
    return 4;
}

/* A JSON string at ps->p (the opening quote) -> a new NUL-terminated UTF-8 string, or NULL. */
static char* parse_string(parser* ps) {
    if (ps->p >= ps->end || *ps->p != '"') return NULL;
    const unsigned char* s = ps->p + 1;
    const unsigned char* q = s;
    while (q < ps->end && *q != '"') {
        if (*q == '\\') {
            if (q + 1 >= ps->end) return NULL;
            ++q;
        }
        ++q;
    }
    if (q >= ps->end) return NULL;
    /* every escape decodes to at most as many bytes as it takes (\uXXXX: 6 -> <= 3, a pair 12 -> 4) */
    char* out = malloc((size_t)(q - s) + 1);
    if (!out) return NULL;
    size_t n = 0;
    const unsigned char* r = s;
    while (r < q) {
        if (*r != '\\') {
            if (*r < 32) goto fail; /* control characters must be escaped */
            out[n++] = (char)*r++;
            continue;
        }
        ++r;
        switch (*r) {
        case '"': out[n++] = '"'; break;
        case '\\': out[n++] = '\\'; break;
        case '/': out[n++] = '/'; break;
        case 'b': out[n++] = '\b'; break;
        case 'f': out[n++] = '\f'; break;
        case 'n': out[n++] = '\n'; break;
        case 'r': out[n++] = '\r'; break;
        case 't': out[n++] = '\t'; break;
        case 'u': {
            unsigned cp;
            if (q - r < 5 || !hex4(r + 1, &cp)) goto fail;
            r += 4;
            if (cp >= 0xDC00 && cp <= 0xDFFF) goto fail; /* a lone low surrogate */
            if (cp >= 0xD800 && cp <= 0xDBFF) {
                unsigned lo;
                if (q - r < 7 || r[1] != '\\' || r[2] != 'u' || !hex4(r + 3, &lo) || lo < 0xDC00 || lo > 0xDFFF) goto fail;
                cp = 0x10000 + (((cp & 0x3FF) << 10) | (lo & 0x3FF));
                r += 6;
            }
            if (cp == 0) goto fail; /* would cut the C string */
            n += utf8_put(cp, out + n);
            break;
        }
        default: goto fail;
        }
        ++r;
    }
    out[n] = 0;
    ps->p = q + 1;
    return out;
fail:
    free(out);
    ps->p = r;
    return NULL;
}

static int parse_value(parser* ps, cJSON* item);

static int parse_number(parser* ps, cJSON* item) {
    char buf[64];
    size_t n = 0;
    const unsigned char* q = ps->p;
    while (q < ps->end && n + 1 < sizeof buf &&
           ((*q >= '0' && *q <= '9') || *q == '-' || *q == '+' || *q == '.' || *q == 'e' || *q == 'E'))
        buf[n++] = (char)*q++;
    buf[n] = 0;
    if (n == 0) return 0;
    char* stop = NULL;
    double d = strtod(buf, &stop);
    if (stop == buf) return 0;
    item->type = cJSON_Number;
    item->valuedouble = d;
    item->valueint = d >= (double)INT_MAX ? INT_MAX : d <= (double)INT_MIN ? INT_MIN : (int)d;
    ps->p += stop - buf;
    return 1;
}

static int literal(parser* ps, const char* word) {
    size_t len = strlen(word);
    if ((size_t)(ps->end - ps->p) < len || memcmp(ps->p, word, len) != 0) return 0;
    ps->p += len;
    return 1;
}

static int parse_container(parser* ps, cJSON* item, int object) {
    if (++ps->depth > CJSON_NESTING_LIMIT) return 0;
    item->type = object ? cJSON_Object : cJSON_Array;
    ++ps->p; /* [ or { */
    skip_ws(ps);
    cJSON* tail = NULL;
    const unsigned char close = object ? '}' : ']';
    if (ps->p < ps->end && *ps->p == close) {
        ++ps->p;
        --ps->depth;
        return 1;
    }
    for (;;) {
        cJSON* child = node_new(cJSON_Invalid);
        if (!child) return 0;
        if (tail) {
            tail->next = child;
            child->prev = tail;
        } else {
            item->child = child;
        }
        tail = child;
        item->child->prev = tail; /* cJSON keeps the last element in child->prev */
        skip_ws(ps);
        if (object) {
            if (!(child->string = parse_string(ps))) return 0;
            skip_ws(ps);
            if (ps->p >= ps->end || *ps->p != ':') return 0;
            ++ps->p;
            skip_ws(ps);
        }
        if (!parse_value(ps, child)) return 0;
        skip_ws(ps);
        if (ps->p >= ps->end) return 0;
        if (*ps->p == ',') {
            ++ps->p;
            continue;
        }
        if (*ps->p != close) return 0;
        ++ps->p;
        --ps->depth;
        return 1;
    }
}

static int parse_value(parser* ps, cJSON* item) {
    if (ps->p >= ps->end) return 0;
    switch (*ps->p) {
    case 'n':
        item->type = cJSON_NULL;
        return literal(ps, "null");
    case 't':
        item->type = cJSON_True;
        item->valueint = 1;
        return literal(ps, "true");
    case 'f':
        item->type = cJSON_False;
        return literal(ps, "false");
    case '"':
        item->type = cJSON_String;
        return (item->valuestring = parse_string(ps)) != NULL;
    case '[': return parse_container(ps, item, 0);
    case '{': return parse_container(ps, item, 1);
    default:
        if (*ps->p == '-' || (*ps->p >= '0' && *ps->p <= '9')) return parse_number(ps, item);
        return 0;
    }
}

cJSON* cJSON_ParseWithLengthOpts(const char* value, size_t buffer_length, const char** return_parse_end,
                                 cJSON_bool require_null_terminated) {
    if (return_parse_end) *return_parse_end = value;
    if (!value || buffer_length == 0) return NULL;
    parser ps = {(const unsigned char*)value, (const unsigned char*)value + buffer_length, 0};
    if (buffer_length >= 3 && memcmp(value, "\xEF\xBB\xBF", 3) == 0) ps.p += 3; /* a UTF-8 byte order mark */
    cJSON* root = node_new(cJSON_Invalid);
    if (!root) return NULL;
    skip_ws(&ps);
    int ok = parse_value(&ps, root);
    if (ok && require_null_terminated) {
        skip_ws(&ps);
        ok = ps.p < ps.end && *ps.p == 0;
    }
    if (return_parse_end) *return_parse_end = (const char*)ps.p;
    if (!ok) {
        cJSON_Delete(root);
        return NULL;
    }
    return root;
}

cJSON* cJSON_ParseWithLength(const char* value, size_t buffer_length) {
    return cJSON_ParseWithLengthOpts(value, buffer_length, NULL, 0);
}

cJSON* cJSON_Parse(const char* value) { return value ? cJSON_ParseWithLength(value, strlen(value) + 1) : NULL; }

/* ---- look-ups and type tests ---- */

int cJSON_GetArraySize(const cJSON* array) {
    int n = 0;
    for (const cJSON* c = array ? array->child : NULL; c; c = c->next) ++n;
    return n;
}

cJSON* cJSON_GetArrayItem(const cJSON* array, int index) {
    if (!array || index < 0) return NULL;
    cJSON* c = array->child;
    while (c && index-- > 0) c = c->next;
    return c;
}

cJSON* cJSON_GetObjectItemCaseSensitive(const cJSON* const object, const char* const string) {
    if (!object || !string) return NULL;
    for (cJSON* c = object->child; c; c = c->next)
        if (c->string && strcmp(c->string, string) == 0) return c;
    return NULL;
}

#define TYPE_IS(item, t) ((item) != NULL && ((item)->type & 0xFF) == (t))
cJSON_bool cJSON_IsInvalid(const cJSON* const item) { return TYPE_IS(item, cJSON_Invalid); }
cJSON_bool cJSON_IsFalse(const cJSON* const item) { return TYPE_IS(item, cJSON_False); }
cJSON_bool cJSON_IsTrue(const cJSON* const item) { return TYPE_IS(item, cJSON_True); }
cJSON_bool cJSON_IsBool(const cJSON* const item) { return item != NULL && (item->type & (cJSON_True | cJSON_False)) != 0; }
cJSON_bool cJSON_IsNull(const cJSON* const item) { return TYPE_IS(item, cJSON_NULL); }
cJSON_bool cJSON_IsNumber(const cJSON* const item) { return TYPE_IS(item, cJSON_Number); }
cJSON_bool cJSON_IsString(const cJSON* const item) { return TYPE_IS(item, cJSON_String); }
cJSON_bool cJSON_IsArray(const cJSON* const item) { return TYPE_IS(item, cJSON_Array); }
cJSON_bool cJSON_IsObject(const cJSON* const item) { return TYPE_IS(item, cJSON_Object); }
cJSON_bool cJSON_IsRaw(const cJSON* const item) { return TYPE_IS(item, cJSON_Raw); }
char* cJSON_GetStringValue(const cJSON* const item) { return cJSON_IsString(item) ? item->valuestring : NULL; }
double cJSON_GetNumberValue(const cJSON* const item) { return cJSON_IsNumber(item) ? item->valuedouble : NAN; }

/* ---- building ---- */

cJSON* cJSON_CreateNull(void) { return node_new(cJSON_NULL); }
cJSON* cJSON_CreateTrue(void) { return node_new(cJSON_True); }
cJSON* cJSON_CreateFalse(void) { return node_new(cJSON_False); }
cJSON* cJSON_CreateBool(cJSON_bool b) { return node_new(b ? cJSON_True : cJSON_False); }
cJSON* cJSON_CreateArray(void) { return node_new(cJSON_Array); }
cJSON* cJSON_CreateObject(void) { return node_new(cJSON_Object); }

cJSON* cJSON_CreateNumber(double num) {
    cJSON* n = node_new(cJSON_Number);
    if (n) {
        n->valuedouble = num;
        n->valueint = num != num ? 0 : num >= (double)INT_MAX ? INT_MAX : num <= (double)INT_MIN ? INT_MIN : (int)num;
    }
    return n;
}

cJSON* cJSON_CreateString(const char* string) {
    cJSON* n = node_new(cJSON_String);
    if (n && !(n->valuestring = str_dup(string ? string : ""))) {
        cJSON_Delete(n);
        return NULL;
    }
    return n;
}

cJSON_bool cJSON_AddItemToArray(cJSON* array, cJSON* item) {
    if (!array || !item || array == item) return 0;
    if (!array->child) {
        array->child = item;
        item->prev = item;
        item->next = NULL;
    } else {
        cJSON* last = array->child->prev;
        last->next = item;
        item->prev = last;
        item->next = NULL;
        array->child->prev = item;
    }
    return 1;
}

cJSON_bool cJSON_AddItemToObject(cJSON* object, const char* string, cJSON* item) {
    if (!object || !string || !item) return 0;
    char* key = str_dup(string);
    if (!key) return 0;
    if (!(item->type & cJSON_StringIsConst)) free(item->string);
    item->string = key;
    item->type &= ~cJSON_StringIsConst;
    return cJSON_AddItemToArray(object, item);
}

static cJSON* add_new(cJSON* object, const char* name, cJSON* item) {
    if (!item) return NULL;
    if (!cJSON_AddItemToObject(object, name, item)) {
        cJSON_Delete(item);
        return NULL;
    }
    return item;
}

cJSON* cJSON_AddNullToObject(cJSON* const object, const char* const name) { return add_new(object, name, cJSON_CreateNull()); }
cJSON* cJSON_AddTrueToObject(cJSON* const object, const char* const name) { return add_new(object, name, cJSON_CreateTrue()); }
cJSON* cJSON_AddFalseToObject(cJSON* const object, const char* const name) { return add_new(object, name, cJSON_CreateFalse()); }
cJSON* cJSON_AddBoolToObject(cJSON* const object, const char* const name, const cJSON_bool b) {
    return add_new(object, name, cJSON_CreateBool(b));
}
cJSON* cJSON_AddNumberToObject(cJSON* const object, const char* const name, const double number) {
    return add_new(object, name, cJSON_CreateNumber(number));
}
cJSON* cJSON_AddStringToObject(cJSON* const object, const char* const name, const char* const string) {
    return add_new(object, name, cJSON_CreateString(string));
}
cJSON* cJSON_AddObjectToObject(cJSON* const object, const char* const name) { return add_new(object, name, cJSON_CreateObject()); }
cJSON* cJSON_AddArrayToObject(cJSON* const object, const char* const name) { return add_new(object, name, cJSON_CreateArray()); }

/* ---- printing ---- */

typedef struct out_buf {
    char* data;
    size_t size, cap;
    int failed;
} out_buf;

static void put(out_buf* b, const char* s, size_t n) {
    if (b->failed) return;
    if (b->size + n + 1 > b->cap) {
        size_t cap = b->cap ? b->cap : 256;
        while (cap < b->size + n + 1) cap *= 2;
        char* d = realloc(b->data, cap);
        if (!d) {
            b->failed = 1;
            return;
        }
        b->data = d;
        b->cap = cap;
    }
    memcpy(b->data + b->size, s, n);
    b->size += n;
    b->data[b->size] = 0;
}

static void put_s(out_buf* b, const char* s) { put(b, s, strlen(s)); }

static void print_number(out_buf* b, double d) {
    char tmp[40];
    if (isnan(d) || isinf(d)) {
        put_s(b, "null");
        return;
    }
    if (d == 0.0 && signbit(d)) {
        snprintf(tmp, sizeof tmp, "-0"); /* (the integer path would drop the sign) */
    } else if (fabs(d) < 1e15 && d == (double)(long long)d) { /* (the cast only where it fits) */
        snprintf(tmp, sizeof tmp, "%lld", (long long)d);
    } else {
        /* the shortest of 15 or 17 significant digits that reads back as the same double */
        snprintf(tmp, sizeof tmp, "%1.15g", d);
        if (strtod(tmp, NULL) != d) snprintf(tmp, sizeof tmp, "%1.17g", d);
    }
    put_s(b, tmp);
}

static void print_string(out_buf* b, const char* s) {
    put(b, "\"", 1);
    for (const unsigned char* p = (const unsigned char*)(s ? s : ""); *p; ++p) {
        char esc[8];
        switch (*p) {
        case '"': put_s(b, "\\\""); break;
        case '\\': put_s(b, "\\\\"); break;
        case '\b': put_s(b, "\\b"); break;
        case '\f': put_s(b, "\\f"); break;
        case '\n': put_s(b, "\\n"); break;
        case '\r': put_s(b, "\\r"); break;
        case '\t': put_s(b, "\\t"); break;
        default:
            if (*p < 32) {
                snprintf(esc, sizeof esc, "\\u%04x", *p);
                put_s(b, esc);
            } else {
                put(b, (const char*)p, 1);
            }
        }
    }
    put(b, "\"", 1);
}

static void indent(out_buf* b, int depth) {
    for (int i = 0; i < depth; ++i) put(b, "\t", 1);
}

static void print_value(out_buf* b, const cJSON* item, int fmt, int depth) {
    if (depth > CJSON_NESTING_LIMIT) {
        b->failed = 1;
        return;
    }
    switch (item->type & 0xFF) {
    case cJSON_NULL: put_s(b, "null"); break;
    case cJSON_False: put_s(b, "false"); break;
    case cJSON_True: put_s(b, "true"); break;
    case cJSON_Number: print_number(b, item->valuedouble); break;
    case cJSON_String: print_string(b, item->valuestring); break;
    case cJSON_Raw: put_s(b, item->valuestring ? item->valuestring : ""); break;
    case cJSON_Array:
    case cJSON_Object: {
        int object = (item->type & 0xFF) == cJSON_Object;
        put(b, object ? "{" : "[", 1);
        if (fmt && object && item->child) put(b, "\n", 1);
        for (const cJSON* c = item->child; c; c = c->next) {
            if (object) {
                if (fmt) indent(b, depth + 1);
                print_string(b, c->string);
                put_s(b, fmt ? ":\t" : ":");
            }
            print_value(b, c, fmt, depth + 1);
            if (c->next) put_s(b, fmt && !object ? ", " : ",");
            if (fmt && object) put(b, "\n", 1);
        }
        if (fmt && object && item->child) indent(b, depth);
        put(b, object ? "}" : "]", 1);
        break;
    }
    default: b->failed = 1; break;
    }
}

static char* print(const cJSON* item, int fmt) {
    if (!item) return NULL;
    out_buf b = {0};
    print_value(&b, item, fmt, 0);
    if (b.failed) {
        free(b.data);
        return NULL;
    }
    return b.data;
}

char* cJSON_Print(const cJSON* item) { return print(item, 1); }
char* cJSON_PrintUnformatted(const cJSON* item) { return print(item, 0); }

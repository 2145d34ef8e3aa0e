/* animkit internal: a streaming JSON writer (never installed). It writes JSON text as it is
 * produced, to a FILE or to nothing (only counting the bytes), so a writer of large documents
 * (the glTF writer) holds no tree and no text. The bytes are exactly cJSON's (Debian
 * libcjson 1.7.15) for the same values in the same order:
 *   - cJSON_PrintUnformatted when format is false: no whitespace at all;
 *   - cJSON_Print when format is true: an object's members one a line, indented with tabs
 *     by depth, "key":<TAB>value; array elements on one line, separated by ", ";
 *   - numbers as cJSON 1.7.15 prints a cJSON_CreateNumber(v): "%1.15g", or "%1.17g" when
 *     that does not read back within DBL_EPSILON relative (so -0.0 is "-0"); NaN and
 *     infinities as null; '.' as the decimal point whatever the locale;
 *   - strings with ", \, \b, \f, \n, \r, \t escaped, other bytes below 0x20 as \u00XX, all
 *     other bytes (UTF-8 included) as they are; a NULL string as "".
 * Usage:
 *     akp_jw w;
 *     akp_jw_init(&w, f, false);              // f NULL: count only
 *     akp_jw_object(&w, NULL);                // the root
 *     akp_jw_string(&w, "version", "2.0");
 *     akp_jw_array(&w, "nodes"); akp_jw_number(&w, NULL, 3); akp_jw_end(&w);
 *     akp_jw_end(&w);
 *     akp_jw_flush(&w);                       // w.bytes: the size; w.failed/w.err: a write failed
 * Members of an object take their key; elements of an array and the root take NULL. */
#ifndef ANIMKIT_SRC_IO_JSON_WRITE_H
#define ANIMKIT_SRC_IO_JSON_WRITE_H

#include <stdbool.h>
#include <stddef.h>
#include <stdio.h>

#define AKP_JW_MAX_DEPTH 64

typedef struct akp_jw {
    FILE* f;           /* where the text goes; NULL: counted only */
    bool format;       /* cJSON_Print's layout instead of cJSON_PrintUnformatted's */
    bool failed;       /* a write to f failed (errno in err), or nesting passed AKP_JW_MAX_DEPTH */
    int err;
    size_t bytes;      /* bytes of text produced so far (written or counted) */
    int depth;         /* open objects and arrays */
    bool is_object[AKP_JW_MAX_DEPTH];
    bool has_items[AKP_JW_MAX_DEPTH];
    size_t n;          /* bytes waiting in buf */
    char buf[8192];
} akp_jw;

/* Start writing to f (NULL: count only), in cJSON_Print's layout when format is set. */
void akp_jw_init(akp_jw* w, FILE* f, bool format);
/* Open an object / an array (a member named key, or an element / the root when key is NULL). */
void akp_jw_object(akp_jw* w, const char* key);
void akp_jw_array(akp_jw* w, const char* key);
/* Close the innermost open object or array. */
void akp_jw_end(akp_jw* w);
/* A number / a string value. */
void akp_jw_number(akp_jw* w, const char* key, double v);
void akp_jw_string(akp_jw* w, const char* key, const char* s);
/* Write what is buffered to f; false when a write has failed (w->err holds errno). */
bool akp_jw_flush(akp_jw* w);

#endif

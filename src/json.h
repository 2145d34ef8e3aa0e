/* animkit internal: strict reading of JSON scene files (particles, boids, cloth, fluid), shared by
 * the scene loaders of those modules (never installed; the command reads scenes through them).
 *
 * Every error names the file, the key path and the problem, as one line:
 *     scene.json: particles[3].m: expected a number, got a string
 *     scene.json: springs[0]: unknown key "stiffness" (allowed: i, j, rest, k, damping)
 *     scene.json: invalid JSON at line 4, column 12
 *
 * Usage (a parser reads optional keys into fields that already hold their defaults):
 *     akp_json j = {.file = "scene.json"};
 *     cJSON* root = akp_json_parse(&j, text, size);
 *     static const char* const keys[] = {"dt", "gravity", "particles", NULL};
 *     float dt = 0.01f;                                 // the default, kept when "dt" is absent
 *     akp_json_object(&j, root, "", keys);
 *     akp_json_float(&j, root, "", "dt", 1e-6f, 1.0f, &dt);
 *     size_t n = 0;
 *     const cJSON* ps = akp_json_array(&j, root, "", "particles", 1000000, &n);
 *     for (size_t i = 0; i < n && !j.failed; ++i) { char path[64]; akp_json_index(path, sizeof path, "particles", i); ... }
 *     cJSON_Delete(root);
 *     if (j.failed) { copy j.message into the caller's ak_diag; return AK_ERR_PARSE; }
 *
 * Errors are sticky: after the first one every call returns false and keeps the first
 * message, so a parser can run its reads in a row and check j.failed once.
 * Rules: numbers must be finite and inside [lo, hi]; integers integral; a key may appear
 * once per object; objects reject keys they do not list. Nesting is bounded by cJSON
 * (CJSON_NESTING_LIMIT, 1000 in Debian's build), so a hostile file cannot exhaust the stack. */
#ifndef ANIMKIT_SRC_JSON_H
#define ANIMKIT_SRC_JSON_H

#include <stdbool.h>
#include <stddef.h>

#include <animkit/math.h>
#include <cjson/cJSON.h> /* Debian libcjson-dev, as the glTF reader */

/* Largest scene file akp_json_load reads when max_size is 0. */
#define AKP_JSON_MAX_SIZE ((size_t)64 << 20)

typedef struct akp_json {
    const char* file;  /* name used in messages (required) */
    bool failed;       /* set by the first error */
    char message[512]; /* "FILE: PATH: problem" once failed, "" before */
} akp_json;

/* Parse text[0, size) (need not be NUL-terminated). Returns the root, which must be a JSON
 * object (free with cJSON_Delete), or NULL with j->message "FILE: invalid JSON at line L,
 * column C" / "FILE: the top level is not an object". */
cJSON* akp_json_parse(akp_json* j, const char* text, size_t size);
/* Read the file at path (at most max_size bytes, 0 -> AKP_JSON_MAX_SIZE) and parse it; j->file
 * is set to path when NULL. NULL with a message when the file cannot be read or is too big. */
cJSON* akp_json_load(akp_json* j, const char* path, size_t max_size);
/* The bytes of the file at path (malloc, *out_size bytes and a NUL), at most max_size
 * (0 -> AKP_JSON_MAX_SIZE), with akp_json_load's messages; NULL when it fails. */
char* akp_json_read_file(akp_json* j, const char* path, size_t max_size, size_t* out_size);

/* Copy j's message into *out_diag (NULL: nothing): path = j->file, line 0, byte_offset -1.
 * Returns code, so a loader can end with `return akp_json_diag(&j, AK_ERR_PARSE, out_diag);`. */
ak_result akp_json_diag(const akp_json* j, ak_result code, ak_diag* out_diag);
/* Fill *out_diag (NULL: nothing) with file and the message "FILE: <fmt...>"; returns code. */
ak_result akp_diag_set(ak_diag* out_diag, ak_result code, const char* file, const char* fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 4, 5)))
#endif
    ;

/* Record an error at path.key (key may be NULL or "", path may be ""): always returns false. */
bool akp_json_fail(akp_json* j, const char* path, const char* key, const char* fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 4, 5)))
#endif
    ;

/* "base[index]" into buf (size bytes; truncated safely); returns buf. */
const char* akp_json_index(char* buf, size_t size, const char* base, size_t index);
/* "base.key" (or "key" when base is empty) into buf; returns buf. */
const char* akp_json_key(char* buf, size_t size, const char* base, const char* key);

/* obj (found at path) must be an object whose keys are all in allowed (NULL-terminated) and
 * appear once each. */
bool akp_json_object(akp_json* j, const cJSON* obj, const char* path, const char* const* allowed);

/* Optional scalar members of obj. Each returns true and leaves *inout alone when the key is
 * absent; stores the value when it is present and valid; fails naming path.key otherwise. */
bool akp_json_number(akp_json* j, const cJSON* obj, const char* path, const char* key, double lo,
                     double hi, double* inout);
bool akp_json_float(akp_json* j, const cJSON* obj, const char* path, const char* key, float lo, float hi,
                    float* inout);
/* An integral number in [lo, hi] (1.0 is accepted, 1.5 is not). */
bool akp_json_int(akp_json* j, const cJSON* obj, const char* path, const char* key, long lo, long hi,
                  long* inout);
bool akp_json_bool(akp_json* j, const cJSON* obj, const char* path, const char* key, bool* inout);
/* A string that is one of names (NULL-terminated); *inout becomes its index. */
bool akp_json_enum(akp_json* j, const cJSON* obj, const char* path, const char* key,
                   const char* const* names, int* inout);
/* A string; *inout points into obj (valid while the tree lives). */
bool akp_json_str(akp_json* j, const cJSON* obj, const char* path, const char* key, const char** inout);
/* An array of exactly count finite numbers, each in [lo, hi]. */
bool akp_json_floats(akp_json* j, const cJSON* obj, const char* path, const char* key, size_t count,
                     float lo, float hi, float* inout);
/* [x, y, z], finite. */
bool akp_json_vec3(akp_json* j, const cJSON* obj, const char* path, const char* key, ak_vec3* inout);

/* An optional array member: NULL with *out_count = 0 when absent; its first element (iterate
 * with ->next) and its length otherwise. Fails when it is not an array or has more than
 * max_count elements (the memory budget of the caller). */
const cJSON* akp_json_array(akp_json* j, const cJSON* obj, const char* path, const char* key,
                            size_t max_count, size_t* out_count);
/* An optional object member: NULL when absent; fails when present and not an object. The
 * caller then checks its keys with akp_json_object. */
const cJSON* akp_json_member(akp_json* j, const cJSON* obj, const char* path, const char* key);

#endif

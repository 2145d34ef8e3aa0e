/* The web build's JSON parser (web/cjson.c, compiled into the WebAssembly page instead of
 * Debian's libcjson; docs/web.md) against libcjson itself, natively: the web file is compiled
 * in here with every function renamed web_cJSON_* so both live in one program. Valid JSON must
 * give the same tree (types, keys, strings, numbers bit for bit, valueint) and the same end
 * pointer; invalid JSON must be refused by both; printing must give text that libcjson parses
 * back to the same tree. Inputs: every JSON and glTF file of the repository's examples and fuzz
 * seeds, ../shared/assets when present, and hand-written cases. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "ak_test.h"

#define cJSON_AddArrayToObject web_cJSON_AddArrayToObject
#define cJSON_AddBoolToObject web_cJSON_AddBoolToObject
#define cJSON_AddFalseToObject web_cJSON_AddFalseToObject
#define cJSON_AddItemToArray web_cJSON_AddItemToArray
#define cJSON_AddItemToObject web_cJSON_AddItemToObject
#define cJSON_AddNullToObject web_cJSON_AddNullToObject
#define cJSON_AddNumberToObject web_cJSON_AddNumberToObject
#define cJSON_AddObjectToObject web_cJSON_AddObjectToObject
#define cJSON_AddStringToObject web_cJSON_AddStringToObject
#define cJSON_AddTrueToObject web_cJSON_AddTrueToObject
#define cJSON_CreateArray web_cJSON_CreateArray
#define cJSON_CreateBool web_cJSON_CreateBool
#define cJSON_CreateFalse web_cJSON_CreateFalse
#define cJSON_CreateNull web_cJSON_CreateNull
#define cJSON_CreateNumber web_cJSON_CreateNumber
#define cJSON_CreateObject web_cJSON_CreateObject
#define cJSON_CreateString web_cJSON_CreateString
#define cJSON_CreateTrue web_cJSON_CreateTrue
#define cJSON_Delete web_cJSON_Delete
#define cJSON_GetArrayItem web_cJSON_GetArrayItem
#define cJSON_GetArraySize web_cJSON_GetArraySize
#define cJSON_GetNumberValue web_cJSON_GetNumberValue
#define cJSON_GetObjectItemCaseSensitive web_cJSON_GetObjectItemCaseSensitive
#define cJSON_GetStringValue web_cJSON_GetStringValue
#define cJSON_IsArray web_cJSON_IsArray
#define cJSON_IsBool web_cJSON_IsBool
#define cJSON_IsFalse web_cJSON_IsFalse
#define cJSON_IsInvalid web_cJSON_IsInvalid
#define cJSON_IsNull web_cJSON_IsNull
#define cJSON_IsNumber web_cJSON_IsNumber
#define cJSON_IsObject web_cJSON_IsObject
#define cJSON_IsRaw web_cJSON_IsRaw
#define cJSON_IsString web_cJSON_IsString
#define cJSON_IsTrue web_cJSON_IsTrue
#define cJSON_Parse web_cJSON_Parse
#define cJSON_ParseWithLength web_cJSON_ParseWithLength
#define cJSON_ParseWithLengthOpts web_cJSON_ParseWithLengthOpts
#define cJSON_Print web_cJSON_Print
#define cJSON_PrintUnformatted web_cJSON_PrintUnformatted
#define cJSON_free web_cJSON_free
#define cJSON_malloc web_cJSON_malloc
#include "../web/cjson.c"
#undef cJSON_AddArrayToObject
#undef cJSON_AddBoolToObject
#undef cJSON_AddFalseToObject
#undef cJSON_AddItemToArray
#undef cJSON_AddItemToObject
#undef cJSON_AddNullToObject
#undef cJSON_AddNumberToObject
#undef cJSON_AddObjectToObject
#undef cJSON_AddStringToObject
#undef cJSON_AddTrueToObject
#undef cJSON_CreateArray
#undef cJSON_CreateBool
#undef cJSON_CreateFalse
#undef cJSON_CreateNull
#undef cJSON_CreateNumber
#undef cJSON_CreateObject
#undef cJSON_CreateString
#undef cJSON_CreateTrue
#undef cJSON_Delete
#undef cJSON_GetArrayItem
#undef cJSON_GetArraySize
#undef cJSON_GetNumberValue
#undef cJSON_GetObjectItemCaseSensitive
#undef cJSON_GetStringValue
#undef cJSON_IsArray
#undef cJSON_IsBool
#undef cJSON_IsFalse
#undef cJSON_IsInvalid
#undef cJSON_IsNull
#undef cJSON_IsNumber
#undef cJSON_IsObject
#undef cJSON_IsRaw
#undef cJSON_IsString
#undef cJSON_IsTrue
#undef cJSON_Parse
#undef cJSON_ParseWithLength
#undef cJSON_ParseWithLengthOpts
#undef cJSON_Print
#undef cJSON_PrintUnformatted
#undef cJSON_free
#undef cJSON_malloc

/* (the same header again, now with libcjson's names) */
cJSON* cJSON_ParseWithLengthOpts(const char* value, size_t buffer_length, const char** return_parse_end,
                                 cJSON_bool require_null_terminated);
char* cJSON_PrintUnformatted(const cJSON* item);
void cJSON_Delete(cJSON* item);

/* inf_as_null: b is a's printed text read back, where JSON has no infinity: a's +-inf numbers
 * are printed as null (as libcjson prints them). */
static int same_tree_(const cJSON* a, const cJSON* b, int inf_as_null) {
    for (; a || b; a = a->next, b = b->next) {
        if (inf_as_null && a && b && (a->type & 0xFF) == cJSON_Number && isinf(a->valuedouble) &&
            (b->type & 0xFF) == cJSON_NULL)
            continue;
        if (!a || !b || (a->type & 0xFF) != (b->type & 0xFF)) return 0;
        if ((a->string || b->string) && (!a->string || !b->string || strcmp(a->string, b->string) != 0)) return 0;
        if ((a->type & 0xFF) == cJSON_Number &&
            (memcmp(&a->valuedouble, &b->valuedouble, sizeof(double)) != 0 || a->valueint != b->valueint))
            return 0;
        if ((a->type & 0xFF) == cJSON_String && strcmp(a->valuestring, b->valuestring) != 0) return 0;
        if (!same_tree_(a->child, b->child, inf_as_null)) return 0;
    }
    return 1;
}

static int same_tree(const cJSON* a, const cJSON* b) { return same_tree_(a, b, 0); }

/* Both parsers on text[0, size): 1 when they agree (and, for valid input, printing round-trips). */
static int agree(const char* text, size_t size, const char* what) {
    const char *end_lib = NULL, *end_web = NULL;
    cJSON* lib = cJSON_ParseWithLengthOpts(text, size, &end_lib, 0);
    cJSON* web = web_cJSON_ParseWithLengthOpts(text, size, &end_web, 0);
    int ok = (!lib && !web) || (lib && web && same_tree(lib, web) && end_lib == end_web);
    if (ok && web) {
        char* printed = web_cJSON_PrintUnformatted(web);
        cJSON* back = printed ? cJSON_ParseWithLengthOpts(printed, strlen(printed), NULL, 0) : NULL;
        ok = back && same_tree_(web, back, 1);
        if (!ok) printf("  %s: web printing does not read back: %.80s\n", what, printed ? printed : "(null)");
        cJSON_Delete(back);
        free(printed);
    } else if (!ok) {
        printf("  %s: libcjson %s, web %s\n", what, lib ? "accepts" : "refuses", web ? "accepts" : "refuses");
    }
    cJSON_Delete(lib);
    web_cJSON_Delete(web);
    return ok;
}

static int agree_file(const char* path) {
    FILE* f = fopen(path, "rb");
    if (!f) return -1;
    char* buf = NULL;
    size_t n = 0, cap = 0, got;
    char chunk[65536];
    while ((got = fread(chunk, 1, sizeof chunk, f)) > 0) {
        if (n + got > cap) {
            cap = (n + got) * 2;
            char* nb = realloc(buf, cap);
            if (!nb) break;
            buf = nb;
        }
        memcpy(buf + n, chunk, got);
        n += got;
    }
    fclose(f);
    int ok = buf ? agree(buf, n, path) : 0;
    free(buf);
    return ok;
}

AK_TEST(same_trees_as_libcjson_on_the_repository_files) {
    static const char* const files[] = {
        "examples/cloth_flag.json",
        "tests/fuzz/scene_cloth_seeds/b1.json",
        "tests/fuzz/scene_cloth_seeds/drape.json",
        "tests/fuzz/scene_cloth_seeds/springs.json",
        "../shared/assets/gltf/RiggedSimple/glTF-Embedded/RiggedSimple.gltf",
        "../shared/assets/gltf/RiggedFigure/glTF/RiggedFigure.gltf",
        "../shared/assets/gltf/Fox/glTF/Fox.gltf",
    };
    int read = 0;
    for (size_t i = 0; i < sizeof files / sizeof files[0]; ++i) {
        char path[1024];
        snprintf(path, sizeof path, "%s/%s", AK_SOURCE_DIR, files[i]);
        int r = agree_file(path);
        if (r < 0) continue; /* the shared assets are optional */
        ++read;
        AK_CHECK_MSG(r == 1, "%s: the parsers disagree", files[i]);
    }
    AK_CHECK(read >= 4);
}

AK_TEST(same_results_as_libcjson_on_written_cases) {
    static const char* const cases[] = {
        "{}", "[]", "0", "-0", "-0.0", "1e400", "-1e400", "1e-400", "123456789012345678901234567890",
        "2147483647", "2147483648", "-2147483649", "0.1", "3.141592653589793238462643", "1.5e+3", "1E2",
        "[1,2,3]", "{\"a\":{\"b\":[true,false,null]}}", "\"esc \\\" \\\\ \\/ \\b \\f \\n \\r \\t\"",
        "\"\\u00e9\\u4e2d\\ud83d\\ude00\"", "  \t\n {\"k\" : 1 }  ", "\xEF\xBB\xBF{\"bom\":1}", "[1,2,3] trailing",
        "{\"dup\":1,\"dup\":2}", "[", "]", "{", "{\"a\"}", "{\"a\":}", "[1,]", "{,}", "[1 2]", "tru", "nul", "\"open",
        "{\"a\":1,}", "-", "", " ",
    };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; ++i)
        AK_CHECK_MSG(agree(cases[i], strlen(cases[i]), cases[i]), "case %zu (%s): the parsers disagree", i, cases[i]);
}

AK_TEST(refuses_invalid_strings_that_libcjson_lets_through) {
    /* Documented differences (docs/web.md): raw control characters in a string, malformed \u
     * escapes and \u0000 (which libcjson truncates the string at) are refused by the web parser. */
    static const char* const cases[] = {"\"a\tb\"", "\"\\u12\"", "\"\\uZZZZ\"", "\"\\u0000\"", "\"\\udc00\""};
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; ++i) {
        const char* end = NULL;
        cJSON* web = web_cJSON_ParseWithLengthOpts(cases[i], strlen(cases[i]), &end, 0);
        AK_CHECK_MSG(web == NULL, "case %zu (%s) was accepted", i, cases[i]);
        web_cJSON_Delete(web);
    }
}

AK_TEST(nesting_is_bounded) {
    const size_t depth = CJSON_NESTING_LIMIT + 1;
    char* text = malloc(2 * depth);
    AK_CHECK(text != NULL);
    if (!text) return;
    memset(text, '[', depth);
    memset(text + depth, ']', depth);
    cJSON* deep = web_cJSON_ParseWithLengthOpts(text, 2 * depth, NULL, 0);
    AK_CHECK(deep == NULL);
    web_cJSON_Delete(deep);
    cJSON* ok = web_cJSON_ParseWithLengthOpts(text + 1, 2 * depth - 2, NULL, 0); /* exactly the limit */
    AK_CHECK(ok != NULL);
    web_cJSON_Delete(ok);
    free(text);
}

AK_TEST(built_trees_print_as_json) {
    cJSON* o = web_cJSON_CreateObject();
    cJSON* arr = web_cJSON_AddArrayToObject(o, "a");
    web_cJSON_AddItemToArray(arr, web_cJSON_CreateNumber(1.5));
    web_cJSON_AddItemToArray(arr, web_cJSON_CreateNumber(-2));
    web_cJSON_AddStringToObject(o, "s", "q\"\n");
    web_cJSON_AddBoolToObject(o, "t", 1);
    web_cJSON_AddNullToObject(o, "n");
    web_cJSON_AddNumberToObject(o, "big", 1e300);
    char* text = web_cJSON_PrintUnformatted(o);
    AK_CHECK_STREQ(text, "{\"a\":[1.5,-2],\"s\":\"q\\\"\\n\",\"t\":true,\"n\":null,\"big\":1e+300}");
    char* pretty = web_cJSON_Print(o);
    cJSON* back = pretty ? cJSON_ParseWithLengthOpts(pretty, strlen(pretty), NULL, 0) : NULL;
    AK_CHECK(back != NULL && same_tree(back, o));
    cJSON_Delete(back);
    free(pretty);
    free(text);
    web_cJSON_Delete(o);
}

int main(void) {
    AK_RUN(same_trees_as_libcjson_on_the_repository_files);
    AK_RUN(same_results_as_libcjson_on_written_cases);
    AK_RUN(refuses_invalid_strings_that_libcjson_lets_through);
    AK_RUN(nesting_is_bounded);
    AK_RUN(built_trees_print_as_json);
    return ak_test_finish();
}

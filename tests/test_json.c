/* The library's strict JSON scene reader (src/json.c, internal; the scene loaders of particles,
 * cloth, fluid and boids read through it): every error names the file, the key path and the
 * problem; absent keys keep their defaults. */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "json.h"
#include "ak_test.h"

static cJSON* parse(akp_json* j, const char* text) { return akp_json_parse(j, text, strlen(text)); }

AK_TEST(defaults_kept_and_values_read) {
    akp_json j = {.file = "s.json"};
    cJSON* root = parse(&j, "{\"dt\": 0.02, \"n\": 3, \"on\": true, \"g\": [0, -9.81, 0], \"mode\": \"b\"}");
    AK_CHECK(root != NULL);
    static const char* const keys[] = {"dt", "n", "on", "g", "mode", "absent", NULL};
    static const char* const modes[] = {"a", "b", NULL};
    float dt = 1.0f, missing = 7.0f;
    long n = 0;
    bool on = false;
    ak_vec3 g = {0, 0, 0};
    int mode = 0;
    AK_CHECK(akp_json_object(&j, root, "", keys));
    AK_CHECK(akp_json_float(&j, root, "", "dt", 0.0f, 1.0f, &dt));
    AK_CHECK(akp_json_float(&j, root, "", "absent", 0.0f, 10.0f, &missing));
    AK_CHECK(akp_json_int(&j, root, "", "n", 0, 10, &n));
    AK_CHECK(akp_json_bool(&j, root, "", "on", &on));
    AK_CHECK(akp_json_vec3(&j, root, "", "g", &g));
    AK_CHECK(akp_json_enum(&j, root, "", "mode", modes, &mode));
    AK_CHECK(!j.failed);
    AK_CHECK_NEAR(dt, 0.02, 1e-7);
    AK_CHECK_NEAR(missing, 7.0, 0.0);
    AK_CHECK_EQ(n, 3);
    AK_CHECK(on);
    AK_CHECK_NEAR(g.y, -9.81, 1e-6);
    AK_CHECK_EQ(mode, 1);
    cJSON_Delete(root);
}

/* One bad document, the message it must give. */
typedef struct bad_case {
    const char* text;
    const char* message;
} bad_case;

static void read_scene(akp_json* j, const cJSON* root) {
    static const char* const keys[] = {"dt", "particles", "mode", NULL};
    static const char* const pkeys[] = {"p", "m", "n", NULL};
    static const char* const modes[] = {"a", "b", NULL};
    float dt = 0.01f;
    int mode = 0;
    akp_json_object(j, root, "", keys);
    akp_json_float(j, root, "", "dt", 1e-6f, 1.0f, &dt);
    akp_json_enum(j, root, "", "mode", modes, &mode);
    size_t count = 0;
    const cJSON* e = akp_json_array(j, root, "", "particles", 4, &count);
    for (size_t i = 0; i < count && e; ++i, e = e->next) {
        char path[64];
        akp_json_index(path, sizeof path, "particles", i);
        ak_vec3 p = {0, 0, 0};
        float m = 1.0f;
        long n = 0;
        akp_json_object(j, e, path, pkeys);
        akp_json_vec3(j, e, path, "p", &p);
        akp_json_float(j, e, path, "m", 0.0f, 1e6f, &m);
        akp_json_int(j, e, path, "n", 0, 5, &n);
    }
}

AK_TEST(errors_name_file_path_and_problem) {
    const bad_case cases[] = {
        {"{\"dt\": \"x\"}", "s.json: dt: expected a number, got a string"},
        {"{\"dt\": 5}", "s.json: dt: 5 is outside [1e-06, 1]"},
        {"{\"dt\": 1e999}", "s.json: dt: the number is not finite"},
        {"{\"zz\": 1}", "s.json: unknown key \"zz\" (allowed: dt, particles, mode)"},
        {"{\"dt\": 0.1, \"dt\": 0.2}", "s.json: dt: the key appears twice"},
        {"{\"mode\": \"c\"}", "s.json: mode: \"c\" is not one of: a, b"},
        {"{\"particles\": {}}", "s.json: particles: expected an array, got an object"},
        {"{\"particles\": [1,2,3,4,5]}", "s.json: particles: 5 elements, more than the limit of 4"},
        {"{\"particles\": [{\"p\": [1, 2]}]}", "s.json: particles[0].p: expected 3 numbers, got 2"},
        {"{\"particles\": [{}, {\"p\": [1, null, 3]}]}", "s.json: particles[1].p[1]: expected a number, got null"},
        {"{\"particles\": [{}, {}, {\"m\": -1}]}", "s.json: particles[2].m: -1 is outside [0, 1e+06]"},
        {"{\"particles\": [{\"n\": 1.5}]}", "s.json: particles[0].n: expected an integer, got 1.5"},
        {"{\"particles\": [{\"q\": 1}]}", "s.json: particles[0]: unknown key \"q\" (allowed: p, m, n)"},
        {"{\"particles\": [7]}", "s.json: particles[0]: expected an object, got a number"},
        {"{\"dt\": 0.1,\n \"mode\": }", "s.json: invalid JSON at line 2, column 10"},
        {"[1]", "s.json: the top level is not an object (got an array)"},
        {"{} x", "s.json: unexpected content after the JSON value"},
        {"", "s.json: invalid JSON at line 1, column 1"},
        {"{\"a\\nb\\u001b\": 1}", "s.json: unknown key \"a?b?\" (allowed: dt, particles, mode)"},
        /* a NUL escape would cut the string short: "a\u0000x" read as "a", "dt\u0000" as "dt" */
        {"{\"mode\": \"a\\u0000x\"}", "s.json: a string holds \\u0000 (NUL) at line 1, column 12"},
        {"{\"dt\\u0000\": 0.1}", "s.json: a string holds \\u0000 (NUL) at line 1, column 5"},
    };
    for (size_t c = 0; c < sizeof cases / sizeof cases[0]; ++c) {
        akp_json j = {.file = "s.json"};
        cJSON* root = parse(&j, cases[c].text);
        if (root) read_scene(&j, root);
        cJSON_Delete(root);
        AK_CHECK_MSG(j.failed, "case %zu accepted: %s", c, cases[c].text);
        AK_CHECK_STREQ(j.message, cases[c].message);
    }
}

AK_TEST(first_error_is_kept) {
    akp_json j = {.file = "s.json"};
    cJSON* root = parse(&j, "{\"a\": \"x\", \"b\": \"y\"}");
    float a = 0, b = 0;
    AK_CHECK(!akp_json_float(&j, root, "", "a", 0, 1, &a));
    AK_CHECK(!akp_json_float(&j, root, "", "b", 0, 1, &b));
    AK_CHECK_STREQ(j.message, "s.json: a: expected a number, got a string");
    cJSON_Delete(root);
}

AK_TEST(load_checks_size_and_missing_files) {
    const char* path = "test_cli_json_tmp.json";
    FILE* f = fopen(path, "wb");
    AK_CHECK(f != NULL);
    if (!f) return;
    fputs("{\"dt\": 0.5}\n", f);
    fclose(f);
    akp_json j = {0};
    cJSON* root = akp_json_load(&j, path, 0);
    AK_CHECK(root != NULL && !j.failed);
    float dt = 0;
    AK_CHECK(akp_json_float(&j, root, "", "dt", 0, 1, &dt));
    AK_CHECK_NEAR(dt, 0.5, 0.0);
    cJSON_Delete(root);
    akp_json small = {0};
    AK_CHECK(akp_json_load(&small, path, 4) == NULL);
    AK_CHECK(strstr(small.message, "larger than 4 bytes") != NULL);
    akp_json none = {.file = "nope.json"};
    AK_CHECK(akp_json_load(&none, "does/not/exist.json", 0) == NULL);
    AK_CHECK_STREQ(none.message, "nope.json: cannot open the file");
    remove(path);
}

/* Deep nesting ends in an error from cJSON's nesting limit, not a stack overflow. */
/* An escaped backslash followed by "u0000" is text, not a NUL. */
AK_TEST(escaped_backslash_is_not_a_nul) {
    akp_json j = {.file = "s.json"};
    cJSON* root = parse(&j, "{\"mode\": \"\\\\u0000\"}");
    AK_CHECK(root != NULL && !j.failed);
    const cJSON* m = cJSON_GetObjectItemCaseSensitive(root, "mode");
    AK_CHECK(cJSON_IsString(m) && strcmp(m->valuestring, "\\u0000") == 0);
    cJSON_Delete(root);
}

AK_TEST(deep_nesting_is_an_error) {
    enum { DEPTH = 100000 };
    static char text[2 * DEPTH + 16];
    size_t n = 0;
    text[n++] = '{';
    memcpy(text + n, "\"a\":", 4);
    n += 4;
    for (int i = 0; i < DEPTH; ++i) text[n++] = '[';
    for (int i = 0; i < DEPTH; ++i) text[n++] = ']';
    text[n++] = '}';
    akp_json j = {.file = "deep.json"};
    cJSON* root = akp_json_parse(&j, text, n);
    AK_CHECK(root == NULL && j.failed);
    cJSON_Delete(root);
}

int main(void) {
    AK_RUN(defaults_kept_and_values_read);
    AK_RUN(errors_name_file_path_and_problem);
    AK_RUN(first_error_is_kept);
    AK_RUN(load_checks_size_and_missing_files);
    AK_RUN(escaped_backslash_is_not_a_nul);
    AK_RUN(deep_nesting_is_an_error);
    return ak_test_finish();
}

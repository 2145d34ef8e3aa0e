/* The animkit rigid command: exit codes, the --json contract (exact keys, scene order, world
 * space) and the output checked against closed forms (a thrown body's parabola, a sphere
 * resting on the ground, the incline preset's sliding box), and errors that name the key path. */
#include <animkit/animkit.h>
#include <cjson/cJSON.h>

#include "ak_test.h"
#include "cli_test.h"

static ak_vec3 vec_of(const cJSON* body, const char* key) {
    const cJSON* p = cJSON_GetObjectItemCaseSensitive(body, key);
    if (!cJSON_IsArray(p) || cJSON_GetArraySize(p) < 3) return ak_vec3_make(NAN, NAN, NAN);
    return ak_vec3_make((float)cJSON_GetArrayItem(p, 0)->valuedouble,
                        (float)cJSON_GetArrayItem(p, 1)->valuedouble,
                        (float)cJSON_GetArrayItem(p, 2)->valuedouble);
}

static int count_keys(const cJSON* o) {
    int n = 0;
    for (const cJSON* c = o ? o->child : NULL; c; c = c->next) ++n;
    return n;
}

AK_TEST(usage) {
    AK_CHECK_EQ(run("rigid --help", true), 0);
    AK_CHECK(strstr(out_buf, "usage: animkit rigid") != NULL);
    AK_CHECK_EQ(run("rigid", true), 2);
    AK_CHECK_EQ(run("rigid --preset nope", true), 2);
    AK_CHECK_EQ(run("rigid --preset stack --steps -3", true), 2);
    AK_CHECK_EQ(run("rigid --preset stack --substeps 0", true), 2);
    AK_CHECK_EQ(run("rigid --preset stack --dt 0", true), 2);
    AK_CHECK_EQ(run("rigid --preset stack -o out.txt", true), 2);
    AK_CHECK_EQ(run("rigid --preset stack x.json", true), 2);
    AK_CHECK_EQ(run("rigid --preset ragdoll --steps 3", true), 0);
    AK_CHECK(strstr(out_buf, "11 joints") != NULL);
}

/* Body 0 is a static ground plane, body 1 a sphere resting on it, body 2 a box thrown far
 * from everything: after 1 s the box is at x0 + v0 t + g t^2 / 2 (less semi-implicit Euler's
 * g h t / 2), the sphere still at y = radius. */
AK_TEST(json_contract_and_closed_forms) {
    AK_CHECK(write_file(
        "rigid_scene.json",
        "{\"gravity\": [0, -9.81, 0], \"steps\": 60, \"substeps\": 20, \"bodies\": ["
        "{\"shape\": {\"type\": \"plane\", \"normal\": [0, 1, 0]}, \"static\": true},"
        "{\"shape\": {\"type\": \"sphere\", \"radius\": 0.25}, \"position\": [0, 0.25, 0]},"
        "{\"shape\": {\"type\": \"box\", \"half_extents\": [0.1, 0.2, 0.3]}, \"position\": [100, "
        "50, 0],"
        " \"velocity\": [2, 5, -1], \"mass\": 3}]}"));
    AK_CHECK_EQ(run("rigid rigid_scene.json --json rigid_out.json", true), 0);
    cJSON* j = read_json("rigid_out.json");
    AK_CHECK(j != NULL);
    if (!j) return;
    AK_CHECK_EQ(count_keys(j), 4);
    AK_CHECK(cJSON_IsNumber(cJSON_GetObjectItemCaseSensitive(j, "time")));
    AK_CHECK(cJSON_IsNumber(cJSON_GetObjectItemCaseSensitive(j, "max_penetration")));
    AK_CHECK(cJSON_IsNumber(cJSON_GetObjectItemCaseSensitive(j, "energy")));
    AK_CHECK_NEAR(cJSON_GetObjectItemCaseSensitive(j, "time")->valuedouble, 1.0, 1e-6);
    const cJSON* bodies = cJSON_GetObjectItemCaseSensitive(j, "bodies");
    AK_CHECK_EQ(cJSON_GetArraySize(bodies), 3);
    for (int i = 0; i < cJSON_GetArraySize(bodies); ++i) {
        const cJSON* b = cJSON_GetArrayItem(bodies, i);
        AK_CHECK_EQ(count_keys(b), 4);
        AK_CHECK_EQ(cJSON_GetArraySize(cJSON_GetObjectItemCaseSensitive(b, "orientation")), 4);
        AK_CHECK_EQ(cJSON_GetArraySize(cJSON_GetObjectItemCaseSensitive(b, "angular_velocity")), 3);
    }
    ak_vec3 sphere = vec_of(cJSON_GetArrayItem(bodies, 1), "position");
    AK_CHECK_NEAR(sphere.y, 0.25, 1e-3);
    AK_CHECK_NEAR(sphere.x, 0.0, 1e-4);
    ak_vec3 box = vec_of(cJSON_GetArrayItem(bodies, 2), "position"),
            bv = vec_of(cJSON_GetArrayItem(bodies, 2), "velocity");
    const double t = 1.0, h = 1.0 / 1200.0;
    AK_CHECK_NEAR(box.x, 100.0 + 2.0 * t, 1e-3);
    AK_CHECK_NEAR(box.y, 50.0 + 5.0 * t - 0.5 * 9.81 * t * t - 9.81 * h * t / 2.0, 2e-3);
    AK_CHECK_NEAR(box.z, -t, 1e-3);
    AK_CHECK_NEAR(bv.y, 5.0 - 9.81 * t, 1e-3);
    /* energy: the sphere rests (potential m g r), the box's is conserved up to Euler's drift */
    double ms = 1000.0 * 4.0 / 3.0 * 3.14159265358979 * 0.015625;
    double e0 = ms * 9.81 * 0.25 + 3.0 * (9.81 * 50.0 + 0.5 * (4.0 + 25.0 + 1.0));
    AK_CHECK_NEAR(cJSON_GetObjectItemCaseSensitive(j, "energy")->valuedouble, e0, 2e-3 * e0);
    cJSON_Delete(j);
}

/* The incline preset: body 1 (friction sqrt(0.3 * 0.3) = 0.3 < tan 30) slides from rest with
 * a = g (sin 30 - 0.3 cos 30) for 2 s; body 2 (sqrt(0.3 * 1.6) = 0.69 > tan 30) stays. */
AK_TEST(incline_preset) {
    AK_CHECK_EQ(run("rigid --preset incline --json rigid_incline.json", true), 0);
    cJSON* j = read_json("rigid_incline.json");
    AK_CHECK(j != NULL);
    if (!j) return;
    const cJSON* bodies = cJSON_GetObjectItemCaseSensitive(j, "bodies");
    ak_vec3 v1 = vec_of(cJSON_GetArrayItem(bodies, 1), "velocity"),
            v2 = vec_of(cJSON_GetArrayItem(bodies, 2), "velocity");
    const double th = 0.5236, a = 9.81 * (sin(th) - 0.3 * cos(th));
    AK_CHECK_NEAR(ak_vec3_length(v1), a * 2.0, 0.01 * a * 2.0);
    AK_CHECK_NEAR(ak_vec3_length(v2), 0.0, 1e-3);
    cJSON_Delete(j);
}

/* Bad scenes exit 1 and name the file and the key path. */
AK_TEST(bad_scenes_name_the_key) {
    static const struct {
        const char* text;
        const char* want;
    } cases[] = {
        {"{\"bodies\": [{\"shape\": {\"type\": \"box\"}}]}", "bodies[0].shape.half_extents"},
        {"{\"bodies\": [{\"shape\": {\"type\": \"sphere\", \"radius\": 1}, \"densty\": 3}]}",
         "densty"},
        {"{\"bodies\": [{\"shape\": {\"type\": \"hull\", \"points\": []}}]}",
         "bodies[0].shape.points"},
        {"{\"bodies\": [{\"shape\": {\"type\": \"sphere\", \"radius\": 1}, \"mass\": 1, "
         "\"density\": 2}]}",
         "bodies[0].mass"},
        {"{\"bodies\": [{\"shape\": {\"type\": \"sphere\", \"radius\": 1}, \"restitution\": 2}]}",
         "bodies[0].restitution"},
        {"{\"bodies\": [{\"shape\": {\"type\": \"sphere\", \"radius\": 1, \"half_height\": 1}}]}",
         "bodies[0].shape.half_height"},
        {"{\"bodies\": []}", "bodies"},
        {"{\"bodies\": [{\"shape\": {\"type\": \"sphere\", \"radius\": 1}}], \"joints\": [{}]}",
         "joints[0].type"},
        {"{\"bodies\": [{\"shape\": {\"type\": \"sphere\", \"radius\": 1}}], \"joints\": "
         "[{\"type\": \"ball\", \"bodies\": [0, 1]}]}",
         "joints[0].bodies"},
        {"{\"bodies\": [{\"shape\": {\"type\": \"sphere\", \"radius\": 1}, \"position\": [0, "
         "\"a\", 0]}]}",
         "bodies[0].position"},
        {"{\"bodies\": [", "invalid JSON"},
    };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; ++i) {
        AK_CHECK(write_file("rigid_bad.json", cases[i].text));
        AK_CHECK_EQ(run("rigid rigid_bad.json", true), 1);
        AK_CHECK_MSG(strstr(out_buf, "rigid_bad.json") && strstr(out_buf, cases[i].want),
                     "case %zu: %s", i, out_buf);
    }
}

/* Contacts dropped over max_contacts are not silent: a column of five spheres on the ground with
 * "max_contacts": 2 runs (exit 0) and warns naming max_contacts; the same scene with the
 * default prints no warning. */
AK_TEST(dropped_contacts_warn) {
    static const char* const bodies =
        "\"bodies\": [{\"shape\": {\"type\": \"plane\", \"normal\": [0, 1, 0]}, \"static\": true},"
        "{\"shape\": {\"type\": \"sphere\", \"radius\": 0.1}, \"position\": [0, 0.1, 0]},"
        "{\"shape\": {\"type\": \"sphere\", \"radius\": 0.1}, \"position\": [0, 0.3, 0]},"
        "{\"shape\": {\"type\": \"sphere\", \"radius\": 0.1}, \"position\": [0, 0.5, 0]},"
        "{\"shape\": {\"type\": \"sphere\", \"radius\": 0.1}, \"position\": [0, 0.7, 0]},"
        "{\"shape\": {\"type\": \"sphere\", \"radius\": 0.1}, \"position\": [0, 0.9, 0]}]}";
    char text[1024];
    snprintf(text, sizeof text, "{\"steps\": 10, \"max_contacts\": 2, %s", bodies);
    AK_CHECK(write_file("rigid_small.json", text));
    AK_CHECK_EQ(run("rigid rigid_small.json", true), 0);
    AK_CHECK_MSG(strstr(out_buf, "warning") && strstr(out_buf, "max_contacts") &&
                     strstr(out_buf, "dropped"),
                 "%s", out_buf);
    snprintf(text, sizeof text, "{\"steps\": 10, %s", bodies);
    AK_CHECK(write_file("rigid_small.json", text));
    AK_CHECK_EQ(run("rigid rigid_small.json", true), 0);
    AK_CHECK_MSG(!strstr(out_buf, "max_contacts"), "%s", out_buf);
}

/* Dominoes fall in order: after 6 s every domino but the last two has tipped, and each is tipped
 * at least as far as the one after it (the wave runs from the first to the last), except the
 * last one, which may already lie flat. */
AK_TEST(dominoes_fall_in_order) {
    AK_CHECK_EQ(run("rigid --preset dominoes --json rigid_dominoes.json", true), 0);
    cJSON* j = read_json("rigid_dominoes.json");
    AK_CHECK(j != NULL);
    if (!j) return;
    const cJSON* bodies = cJSON_GetObjectItemCaseSensitive(j, "bodies");
    int n = cJSON_GetArraySize(bodies);
    AK_CHECK_EQ(n, 21);
    double prev = 180.0;
    for (int i = 1; i < n; ++i) {
        const cJSON* o =
            cJSON_GetObjectItemCaseSensitive(cJSON_GetArrayItem(bodies, i), "orientation");
        double w = fabs(cJSON_GetArrayItem(o, 3)->valuedouble);
        double tilt = 2.0 * acos(w < 1.0 ? w : 1.0) * 180.0 / 3.14159265358979;
        if (i <= n - 3) AK_CHECK_MSG(tilt > 30.0, "domino %d tilted only %g deg", i, tilt);
        /* the last domino has nothing ahead to lean on: once the wave reaches it, it lies flat
         * (90 degrees) and the one before leans on it */
        if (i == n - 1 && tilt > prev + 0.5)
            AK_CHECK_MSG(fabs(tilt - 90.0) < 2.0, "last domino at %g deg, neither leaning nor flat",
                         tilt);
        else
            AK_CHECK_MSG(tilt <= prev + 0.5, "domino %d (%g deg) is past domino %d (%g deg)", i,
                         tilt, i - 1, prev);
        prev = tilt;
    }
    cJSON_Delete(j);
}

int main(void) {
    AK_RUN(usage);
    AK_RUN(json_contract_and_closed_forms);
    AK_RUN(incline_preset);
    AK_RUN(bad_scenes_name_the_key);
    AK_RUN(dropped_contacts_warn);
    AK_RUN_SLOW(dominoes_fall_in_order);
    return ak_test_finish();
}

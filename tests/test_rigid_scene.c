/* The rigid-body scene format as library functions (ak_rigid_scene_load_bytes / _load_file /
 * _preset / _free and ak_rigid_scene_run_*): values read from bytes equal the numbers written in
 * the test's JSON, absent keys take the defaults docs/rigid.md lists, errors name the file and
 * the key path in one line, files that cannot be read are AK_ERR_IO, the presets hold the bodies
 * their documentation describes, and a run follows closed forms (a thrown body's parabola, its
 * energy). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <animkit/animkit.h>

#include "ak_test.h"

#define LOAD(text, scene, diag) ak_rigid_scene_load_bytes((text), strlen(text), "t.json", (scene), (diag))

AK_TEST(rigid_scene_from_bytes) {
    const char* text =
        "{\"gravity\": [0, -3, 1], \"dt\": 0.01, \"steps\": 7, \"substeps\": 5, \"threads\": 2,"
        " \"linear_damping\": 0.25, \"angular_damping\": 0.5, \"contact_offset\": 0.02, \"sleep\": false,"
        " \"contact_iterations\": 3, \"contacts_after_joints\": true, \"sleep_linear_speed\": 0.8,"
        " \"sleep_angular_speed\": 1.0, \"sleep_time\": 2, \"velocity_iterations\": 2,"
        " \"bodies\": ["
        "  {\"shape\": {\"type\": \"plane\", \"normal\": [0, 2, 0]}, \"static\": true, \"friction\": 0},"
        "  {\"shape\": {\"type\": \"box\", \"half_extents\": [0.1, 0.2, 0.3]}, \"position\": [1, 2, 3],"
        "   \"orientation\": [0, 0, 2, 0], \"velocity\": [4, 5, 6], \"angular_velocity\": [0, 1, 0],"
        "   \"mass\": 3, \"friction\": 0.7, \"restitution\": 0.4},"
        "  {\"shape\": {\"type\": \"capsule\", \"radius\": 0.1, \"half_height\": 0.5}, \"density\": 500}],"
        " \"joints\": [{\"type\": \"hinge\", \"bodies\": [1, 2], \"anchor\": [0, 1, 0], \"axis\": [1, 0, 0],"
        "   \"limits\": [-0.5, 0.5], \"compliance\": 0.001}]}";
    ak_rigid_scene s;
    ak_diag d;
    ak_rigid_scene_defaults(&s);
    AK_CHECK_EQ(LOAD(text, &s, &d), AK_OK);
    AK_CHECK_NEAR(s.gravity.y, -3.0f, 0.0f);
    AK_CHECK_NEAR(s.gravity.z, 1.0f, 0.0f);
    AK_CHECK_NEAR(s.dt, 0.01f, 0.0f);
    AK_CHECK_EQ(s.steps, 7);
    AK_CHECK_EQ(s.substeps, 5u);
    AK_CHECK_EQ(s.thread_count, 2u);
    AK_CHECK_NEAR(s.model.linear_damping, 0.25f, 0.0f);
    AK_CHECK_NEAR(s.model.angular_damping, 0.5f, 0.0f);
    AK_CHECK_NEAR(s.model.contact_offset, 0.02f, 0.0f);
    AK_CHECK(!s.sleep);
    AK_CHECK_EQ(s.model.contact_iterations, 3u);
    AK_CHECK_EQ(s.model.velocity_iterations, 2u);
    AK_CHECK(s.model.contacts_after_joints);
    AK_CHECK_NEAR(s.model.sleep_linear_speed, 0.8f, 0.0f);
    AK_CHECK_NEAR(s.model.sleep_angular_speed, 1.0f, 0.0f);
    AK_CHECK_NEAR(s.model.sleep_time, 2.0f, 0.0f);
    AK_CHECK_EQ(s.body_count, 3u);
    AK_CHECK_EQ(s.joint_count, 1u);
    if (s.body_count == 3 && s.joint_count == 1) {
        const ak_rigid_body_desc *g = &s.bodies[0], *b = &s.bodies[1], *c = &s.bodies[2];
        AK_CHECK_EQ(g->shape.type, AK_RIGID_PLANE);
        AK_CHECK(g->is_static);
        AK_CHECK_NEAR(g->shape.normal.y, 2.0f, 0.0f);
        AK_CHECK(g->friction == AK_RIGID_FRICTIONLESS); /* 0 in a file is a real zero */
        AK_CHECK_EQ(b->shape.type, AK_RIGID_BOX);
        AK_CHECK_NEAR(b->shape.half_extents.z, 0.3f, 0.0f);
        AK_CHECK_NEAR(b->position.x, 1.0f, 0.0f);
        AK_CHECK_NEAR(b->position.z, 3.0f, 0.0f);
        /* [0, 0, 2, 0] normalised: a half turn about z */
        AK_CHECK_NEAR(b->orientation.z, 1.0f, 1e-6f);
        AK_CHECK_NEAR(b->orientation.w, 0.0f, 1e-6f);
        AK_CHECK_NEAR(b->velocity.y, 5.0f, 0.0f);
        AK_CHECK_NEAR(b->angular_velocity.y, 1.0f, 0.0f);
        AK_CHECK_NEAR(b->mass, 3.0f, 0.0f);
        AK_CHECK_NEAR(b->friction, 0.7f, 0.0f);
        AK_CHECK_NEAR(b->restitution, 0.4f, 0.0f);
        AK_CHECK(!b->is_static);
        AK_CHECK_EQ(c->shape.type, AK_RIGID_CAPSULE);
        AK_CHECK_NEAR(c->shape.radius, 0.1f, 0.0f);
        AK_CHECK_NEAR(c->shape.half_height, 0.5f, 0.0f);
        AK_CHECK_NEAR(c->density, 500.0f, 0.0f);
        /* body defaults (docs/rigid.md): friction 0.5, restitution 0, at rest at the origin */
        AK_CHECK_NEAR(c->friction, 0.5f, 0.0f);
        AK_CHECK_NEAR(c->restitution, 0.0f, 0.0f);
        AK_CHECK_NEAR(c->orientation.w, 1.0f, 0.0f);
        AK_CHECK_NEAR(ak_vec3_length(c->position) + ak_vec3_length(c->velocity), 0.0f, 0.0f);
        const ak_rigid_joint_desc* jd = &s.joints[0];
        AK_CHECK_EQ(jd->type, AK_RIGID_JOINT_HINGE);
        AK_CHECK_EQ(jd->body_a, 1u);
        AK_CHECK_EQ(jd->body_b, 2u);
        AK_CHECK_NEAR(jd->anchor.y, 1.0f, 0.0f);
        AK_CHECK_NEAR(jd->axis.x, 1.0f, 0.0f);
        AK_CHECK(jd->limited);
        AK_CHECK_NEAR(jd->lower, -0.5f, 0.0f);
        AK_CHECK_NEAR(jd->upper, 0.5f, 0.0f);
        AK_CHECK_NEAR(jd->compliance, 0.001f, 0.0f);
    }
    ak_rigid_scene_free(&s);
    AK_CHECK(s.bodies == NULL && s.body_count == 0 && s.joints == NULL && s.joint_count == 0);
    ak_rigid_scene_free(&s); /* twice is fine */
    ak_rigid_scene_free(NULL);

    /* every top-level key absent: the defaults of docs/rigid.md */
    const char* one = "{\"bodies\": [{\"shape\": {\"type\": \"sphere\", \"radius\": 0.5}}]}";
    ak_rigid_scene_defaults(&s);
    AK_CHECK_EQ(LOAD(one, &s, NULL), AK_OK);
    AK_CHECK_NEAR(s.gravity.y, -9.81f, 0.0f);
    AK_CHECK_NEAR(s.gravity.x, 0.0f, 0.0f);
    AK_CHECK_NEAR(s.dt, 1.0f / 60.0f, 0.0f);
    AK_CHECK_EQ(s.steps, 240);
    AK_CHECK_EQ(s.substeps, 20u);
    AK_CHECK_EQ(s.thread_count, 1u);
    AK_CHECK(s.sleep);
    AK_CHECK_NEAR(s.model.contact_offset, 0.01f, 0.0f);
    AK_CHECK(s.model.contact_iterations <= 1u); /* one pass (0 and 1 both mean it) */
    AK_CHECK(!s.model.contacts_after_joints);
    /* 0: the model's defaults, 0.05 m/s, 0.05 rad/s, 0.5 s */
    AK_CHECK(s.model.sleep_linear_speed == 0.0f && s.model.sleep_angular_speed == 0.0f && s.model.sleep_time == 0.0f);
    AK_CHECK_EQ(s.body_count, 1u);
    AK_CHECK_EQ(s.joint_count, 0u);
    if (s.body_count == 1) AK_CHECK_NEAR(s.bodies[0].density, 1000.0f, 0.0f);
    ak_rigid_scene_free(&s);
}

AK_TEST(rigid_scene_errors_name_key_paths) {
    static const struct {
        const char* text;
        const char* message;
    } cases[] = {
        {"{\"bodies\": [{\"shape\": {\"type\": \"sphere\", \"radius\": 1}},"
         " {\"shape\": {\"type\": \"box\"}}]}",
         "t.json: bodies[1].shape.half_extents: is required for a box"},
        {"{\"bodies\": [{\"shape\": {\"type\": \"sphere\", \"radius\": 1}, \"densty\": 3}]}", "densty"},
        {"{\"bodies\": [{\"shape\": {\"type\": \"sphere\", \"radius\": 1}, \"mass\": 1, \"density\": 2}]}",
         "t.json: bodies[0].mass: give density or mass, not both"},
        {"{\"bodies\": [{\"shape\": {\"type\": \"sphere\", \"radius\": 1}, \"restitution\": 2}]}",
         "t.json: bodies[0].restitution"},
        {"{\"bodies\": [{\"shape\": {\"type\": \"hull\", \"points\": []}}]}", "t.json: bodies[0].shape.points: is required"},
        {"{\"bodies\": []}", "t.json: bodies: is required and must hold at least one body"},
        {"{\"dt\": 0.01}", "t.json: bodies: is required"},
        {"{\"bodies\": [{\"shape\": {\"type\": \"sphere\", \"radius\": 1}}], \"joints\": "
         "[{\"type\": \"ball\", \"bodies\": [0, 1]}]}",
         "t.json: joints[0].bodies: a body index is out of range (the scene has 1 bodies)"},
        {"{\"bodies\": [{\"shape\": {\"type\": \"sphere\", \"radius\": 1}}], \"steps\": 1.5}", "t.json: steps"},
        {"{\"bodies\": [{\"shape\": {\"type\": \"sphere\", \"radius\": 1}}], \"substeps\": 1001}", "t.json: substeps"},
        {"{\"bodies\": [{\"shape\": {\"type\": \"sphere\", \"radius\": 1}}], \"contact_iterations\": 65}",
         "t.json: contact_iterations"},
        {"{\"bodies\": [{\"shape\": {\"type\": \"sphere\", \"radius\": 1}}], \"velocity_iterations\": 0}",
         "t.json: velocity_iterations"},
        {"{\"bodies\": [{\"shape\": {\"type\": \"sphere\", \"radius\": 1}}], \"contacts_after_joints\": 1}",
         "t.json: contacts_after_joints"},
        {"{\"bodies\": [{\"shape\": {\"type\": \"sphere\", \"radius\": 1}}], \"sleep_time\": 0}", "t.json: sleep_time"},
        {"{\"bodies\": [", "t.json: invalid JSON"},
        {"[1]", "t.json: "},
        {"", "t.json: "},
    };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; ++i) {
        ak_rigid_scene s;
        ak_diag d;
        ak_rigid_scene_defaults(&s);
        AK_CHECK_EQ(LOAD(cases[i].text, &s, &d), AK_ERR_PARSE);
        AK_CHECK_MSG(strncmp(d.message, "t.json: ", 8) == 0 && strstr(d.message, cases[i].message) &&
                         !strchr(d.message, '\n'),
                     "case %zu: %s", i, d.message);
        AK_CHECK(s.bodies == NULL && s.body_count == 0 && s.joints == NULL && s.joint_count == 0);
        ak_rigid_scene_free(&s);
    }
    /* NULL arguments are errors, not crashes; name NULL -> "(scene)" */
    ak_diag d;
    AK_CHECK_EQ(ak_rigid_scene_load_bytes("{}", 2, NULL, NULL, &d), AK_ERR_NULL_ARG);
    ak_rigid_scene s;
    ak_rigid_scene_defaults(&s);
    AK_CHECK_EQ(ak_rigid_scene_load_bytes(NULL, 3, NULL, &s, &d), AK_ERR_NULL_ARG);
    AK_CHECK_EQ(ak_rigid_scene_load_bytes("{}", 2, NULL, &s, &d), AK_ERR_PARSE);
    AK_CHECK(strncmp(d.message, "(scene): bodies", 15) == 0);
    AK_CHECK_EQ(ak_rigid_scene_load_file(NULL, &s, &d), AK_ERR_NULL_ARG);
    ak_rigid_scene_free(&s);
}

AK_TEST(rigid_scene_files) {
    const char* path = "rigid_scene_lib.json";
    FILE* f = fopen(path, "wb");
    AK_CHECK(f != NULL);
    if (!f) return;
    fputs("{\"steps\": 3, \"bodies\": [{\"shape\": {\"type\": \"sphere\", \"radius\": 0.5}}]}", f);
    fclose(f);
    ak_rigid_scene s;
    ak_diag d;
    /* over a preset: keys the file leaves out keep the preset's values (ragdoll: 40 substeps),
     * its bodies and joints are replaced by the file's */
    AK_CHECK_EQ(ak_rigid_scene_preset("ragdoll", &s, &d), AK_OK);
    AK_CHECK(s.joint_count > 0);
    AK_CHECK_EQ(ak_rigid_scene_load_file(path, &s, &d), AK_OK);
    AK_CHECK_EQ(s.steps, 3);
    AK_CHECK_EQ(s.substeps, 40u);
    AK_CHECK_EQ(s.body_count, 1u);
    AK_CHECK_EQ(s.joint_count, 0u);
    ak_rigid_scene_free(&s);
    remove(path);
    ak_rigid_scene_defaults(&s);
    AK_CHECK_EQ(ak_rigid_scene_load_file("no/such/rigid.json", &s, &d), AK_ERR_IO);
    AK_CHECK(strncmp(d.message, "no/such/rigid.json: ", 20) == 0);
    AK_CHECK(s.body_count == 0);
    ak_rigid_scene_free(&s);
}

AK_TEST(rigid_scene_presets) {
    size_t count = 0;
    const char* const* names = ak_rigid_scene_preset_names(&count);
    AK_CHECK_EQ(count, 6u);
    AK_CHECK(names[count] == NULL);
    /* bodies each preset's documentation gives (the ground or slope plane included) */
    static const struct {
        const char* name;
        size_t bodies;
        long steps;
        uint32_t substeps;
    } want[] = {{"stack", 11, 240, 20},      {"pyramid", 211, 240, 40}, {"dominoes", 21, 360, 20},
                {"avalanche", 202, 300, 20}, {"ragdoll", 0, 180, 40},   {"incline", 3, 120, 20}};
    for (size_t i = 0; i < count && i < 6; ++i) {
        AK_CHECK_STREQ(names[i], want[i].name);
        AK_CHECK(strstr(AK_RIGID_SCENE_PRESETS, names[i]) != NULL);
        ak_rigid_scene s;
        ak_diag d;
        AK_CHECK_EQ(ak_rigid_scene_preset(names[i], &s, &d), AK_OK);
        if (want[i].bodies) AK_CHECK_EQ(s.body_count, want[i].bodies);
        AK_CHECK_EQ(s.steps, want[i].steps);
        AK_CHECK_EQ(s.substeps, want[i].substeps);
        for (size_t k = 0; k < s.joint_count; ++k)
            AK_CHECK(s.joints[k].body_a < s.body_count && s.joints[k].body_b < s.body_count &&
                     s.joints[k].body_a != s.joints[k].body_b);
        /* every preset has exactly one static ground (or slope) as body 0 */
        if (s.body_count) AK_CHECK(s.bodies[0].is_static && s.bodies[0].shape.type == AK_RIGID_PLANE);
        ak_rigid_scene_free(&s);
    }
    /* the ragdoll: builtin:humanoid's capsules and joints after the ground */
    ak_scene* hum = NULL;
    ak_builtin_desc bd = {.cell_size = 0.1f};
    AK_CHECK_EQ(ak_builtin_create("humanoid", &bd, NULL, &hum), AK_OK);
    if (hum) {
        ak_rigid_scene s;
        AK_CHECK_EQ(ak_rigid_scene_preset("ragdoll", &s, NULL), AK_OK);
        AK_CHECK_EQ(s.body_count, 1 + ak_rigid_ragdoll_body_count(hum->skeleton));
        AK_CHECK_EQ(s.joint_count, ak_rigid_ragdoll_joint_count(hum->skeleton));
        AK_CHECK(s.joint_count > 0);
        ak_rigid_scene_free(&s);
        ak_scene_destroy(hum);
    }
    ak_rigid_scene s;
    ak_diag d;
    AK_CHECK_EQ(ak_rigid_scene_preset("nope", &s, &d), AK_ERR_NOT_FOUND);
    AK_CHECK(strstr(d.message, "nope") && strstr(d.message, AK_RIGID_SCENE_PRESETS));
    AK_CHECK(s.body_count == 0 && s.bodies == NULL && s.steps == 240); /* the defaults */
    AK_CHECK_EQ(ak_rigid_scene_preset(NULL, &s, &d), AK_ERR_NULL_ARG);
    ak_rigid_scene_free(&s);
}

/* A box thrown far from everything: after 1 s (60 steps of 20 substeps, h = 1/1200 s) it is at
 * x0 + v0 t + g t^2 / 2 less semi-implicit Euler's g h t / 2, and its energy (potential +
 * kinetic, 3 kg) is what it started with up to that drift. */
AK_TEST(rigid_scene_run_parabola) {
    const char* text = "{\"steps\": 60, \"substeps\": 20, \"bodies\": ["
                       "{\"shape\": {\"type\": \"box\", \"half_extents\": [0.1, 0.2, 0.3]},"
                       " \"position\": [100, 50, 0], \"velocity\": [2, 5, -1], \"mass\": 3}]}";
    ak_rigid_scene s;
    ak_diag d;
    ak_rigid_scene_defaults(&s);
    AK_CHECK_EQ(LOAD(text, &s, &d), AK_OK);
    ak_rigid_scene_run run;
    AK_CHECK_EQ(ak_rigid_scene_run_init(&run, &s, "t.json", &d), AK_OK);
    const double e0 = 3.0 * (9.81 * 50.0 + 0.5 * (4.0 + 25.0 + 1.0));
    AK_CHECK_NEAR(ak_rigid_scene_run_energy(&run), e0, 1e-4 * e0);
    ak_rigid_scene_free(&s); /* the run does not need the scene any more */
    while (run.step_index < 60 && ak_rigid_scene_run_step(&run) == AK_OK) {}
    AK_CHECK_EQ(run.step_index, 60);
    AK_CHECK_NEAR(run.time, 1.0, 1e-6);
    const double t = 1.0, h = 1.0 / 1200.0;
    if (run.body_count == 1) {
        AK_CHECK_NEAR(run.positions[0].x, 100.0 + 2.0 * t, 1e-3);
        AK_CHECK_NEAR(run.positions[0].y, 50.0 + 5.0 * t - 0.5 * 9.81 * t * t - 9.81 * h * t / 2.0, 2e-3);
        AK_CHECK_NEAR(run.positions[0].z, -t, 1e-3);
        AK_CHECK_NEAR(run.velocities[0].y, 5.0 - 9.81 * t, 1e-3);
    }
    AK_CHECK_NEAR(ak_rigid_scene_run_energy(&run), e0, 2e-3 * e0);
    ak_rigid_scene_run_free(&run);
    ak_rigid_scene_run_free(&run); /* twice is fine */
    AK_CHECK_EQ(ak_rigid_scene_run_init(NULL, &s, NULL, &d), AK_ERR_NULL_ARG);
    AK_CHECK_EQ(ak_rigid_scene_run_init(&run, NULL, NULL, &d), AK_ERR_NULL_ARG);
    ak_rigid_scene_run_free(&run);
}

int main(void) {
    AK_RUN(rigid_scene_from_bytes);
    AK_RUN(rigid_scene_errors_name_key_paths);
    AK_RUN(rigid_scene_files);
    AK_RUN(rigid_scene_presets);
    AK_RUN(rigid_scene_run_parabola);
    return ak_test_finish();
}

/* The scene files and presets of particles, cloth, fluid and boids as library functions
 * (ak_<module>_scene_load_bytes / _load_file / _preset / _free): values read from bytes equal
 * the numbers written in the test's JSON, absent keys take the defaults docs/<module>.md lists,
 * errors name the file and the key path, files that cannot be read are AK_ERR_IO, and the
 * presets hold the values their documentation gives. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <animkit/animkit.h>

#include "ak_test.h"

#define LOAD(fn, text, scene, diag) fn((text), strlen(text), "t.json", (scene), (diag))

/* ---- particles ---------------------------------------------------------------------------- */

AK_TEST(particles_from_bytes) {
    const char* text = "{\"dt\": 0.005, \"integrator\": \"rk4\", \"gravity\": [0, -3, 0],"
                       " \"particles\": [{\"p\": [1, 2, 3], \"v\": [0.5, 0, 0], \"m\": 2}, {\"p\": [0, 1, 0]}],"
                       " \"springs\": [{\"i\": 0, \"j\": 1, \"rest\": 0.25, \"k\": 40}],"
                       " \"spheres\": [{\"c\": [0, 0, 0], \"r\": 0.5}]}";
    ak_particles_scene s;
    ak_diag d;
    AK_CHECK_EQ(LOAD(ak_particles_scene_load_bytes, text, &s, &d), AK_OK);
    AK_CHECK_NEAR(s.dt, 0.005f, 0.0f);
    AK_CHECK_EQ(s.integrator, AK_INTEGRATOR_RK4);
    AK_CHECK_NEAR(s.world.gravity.y, -3.0f, 0.0f);
    AK_CHECK_EQ(s.particle_count, 2u);
    if (s.particle_count == 2) {
        AK_CHECK_NEAR(s.particles[0].position.z, 3.0f, 0.0f);
        AK_CHECK_NEAR(s.particles[0].velocity.x, 0.5f, 0.0f);
        AK_CHECK_NEAR(s.particles[0].mass, 2.0f, 0.0f);
    }
    AK_CHECK_EQ(s.world.springs.count, 1u);
    if (s.world.springs.count == 1) AK_CHECK_NEAR(s.world.springs.ptr[0].rest, 0.25f, 0.0f);
    AK_CHECK_EQ(s.world.spheres.count, 1u);
    /* capacity: the listed particles when there is no emitter (docs/particles.md) */
    AK_CHECK_EQ(s.capacity, 2u);
    ak_particles_scene_free(&s);
    AK_CHECK(s.particles == NULL && s.particle_count == 0);
    ak_particles_scene_free(&s); /* twice is fine */

    /* the defaults: dt 0.01, symplectic; with an emitter the capacity is particles + 100000 */
    const char* em = "{\"emitters\": [{\"rate\": 10}]}";
    AK_CHECK_EQ(LOAD(ak_particles_scene_load_bytes, em, &s, NULL), AK_OK);
    AK_CHECK_NEAR(s.dt, 0.01f, 0.0f);
    AK_CHECK_EQ(s.integrator, AK_INTEGRATOR_SYMPLECTIC);
    AK_CHECK_EQ(s.emitter_count, 1u);
    AK_CHECK_EQ(s.capacity, 100000u);
    ak_particles_scene_free(&s);
}

AK_TEST(particles_errors_name_key_paths) {
    static const struct {
        const char* text;
        const char* message;
    } cases[] = {
        {"{\"particles\": [{\"p\": [0, 0, 0]}, {\"p\": [0, 0, 0], \"m\": \"x\"}]}",
         "t.json: particles[1].m: expected a number, got a string"},
        {"{\"dt\": 0.1, \"dt\": 0.2}", "t.json: dt: the key appears twice"},
        {"{\"dt\": 0.1,}", NULL}, /* a syntax error: line and column, checked below */
        {"[1]", "t.json: the top level is not an object (got an array)"},
    };
    for (size_t k = 0; k < sizeof cases / sizeof cases[0]; ++k) {
        ak_particles_scene s;
        ak_diag d;
        AK_CHECK_EQ(LOAD(ak_particles_scene_load_bytes, cases[k].text, &s, &d), AK_ERR_PARSE);
        AK_CHECK(s.particles == NULL && s.particle_count == 0);
        AK_CHECK_STREQ(d.path, "t.json");
        if (cases[k].message)
            AK_CHECK_STREQ(d.message, cases[k].message);
        else
            AK_CHECK_MSG(strstr(d.message, "t.json: ") == d.message && strstr(d.message, "line 1, column"),
                         "%s", d.message);
        AK_CHECK(strchr(d.message, '\n') == NULL);
    }
    /* a NULL diag is allowed; NULL bytes with a size are not */
    ak_particles_scene s;
    AK_CHECK_EQ(ak_particles_scene_load_bytes("{\"zz\": 1}", 9, NULL, &s, NULL), AK_ERR_PARSE);
    ak_diag d;
    AK_CHECK_EQ(ak_particles_scene_load_bytes(NULL, 4, "n.json", &s, &d), AK_ERR_NULL_ARG);
    AK_CHECK(strncmp(d.message, "n.json: ", 8) == 0);
}

AK_TEST(particles_presets) {
    ak_particles_scene s;
    ak_diag d;
    /* fireworks: four sphere emitters bursting every 1.8 s, quadratic drag (docs/particles.md) */
    AK_CHECK_EQ(ak_particles_scene_preset("fireworks", &s, &d), AK_OK);
    AK_CHECK_EQ(s.emitter_count, 4u);
    for (size_t e = 0; e < s.emitter_count && e < 4; ++e) {
        AK_CHECK_EQ(s.emitters[e].shape, AK_EMITTER_SPHERE);
        AK_CHECK_NEAR(s.bursts[e].interval, 1.8f, 0.0f);
        AK_CHECK(s.bursts[e].count > 0);
    }
    AK_CHECK(s.world.drag_quadratic > 0.0f);
    ak_particles_scene_free(&s);
    /* fountain: a floor and a ball; rain: a wind */
    AK_CHECK_EQ(ak_particles_scene_preset("fountain", &s, &d), AK_OK);
    AK_CHECK_EQ(s.world.planes.count, 1u);
    AK_CHECK_EQ(s.world.spheres.count, 1u);
    ak_particles_scene_free(&s);
    AK_CHECK_EQ(ak_particles_scene_preset("rain", &s, &d), AK_OK);
    AK_CHECK(s.world.wind.x != 0.0f);
    ak_particles_scene_free(&s);
    /* character: sparks from a mesh surface the caller supplies */
    AK_CHECK_EQ(ak_particles_scene_preset("character", &s, &d), AK_OK);
    bool mesh = false;
    for (size_t e = 0; e < s.emitter_count; ++e) mesh |= s.emitters[e].shape == AK_EMITTER_MESH;
    AK_CHECK(mesh);
    ak_particles_scene_free(&s);
    AK_CHECK_EQ(ak_particles_scene_preset("volcano", &s, &d), AK_ERR_NOT_FOUND);
    AK_CHECK(strstr(d.message, AK_PARTICLES_SCENE_PRESETS) != NULL);
}

/* A scene run as the command runs it: free fall against the closed form of symplectic Euler,
 * bursts counted against their schedule. */
AK_TEST(particles_scene_run) {
    ak_particles_scene s;
    ak_diag d;
    const char* fall = "{\"dt\": 0.01, \"gravity\": [0, -10, 0], \"particles\": [{\"p\": [0, 5, 0], \"m\": 1}]}";
    AK_CHECK_EQ(LOAD(ak_particles_scene_load_bytes, fall, &s, &d), AK_OK);
    ak_particles_scene_run run;
    AK_CHECK_EQ(ak_particles_scene_run_init(&run, &s, &(ak_particles_scene_run_desc){.seed = 1}, &d), AK_OK);
    for (int k = 0; k < 10; ++k) AK_CHECK_EQ(ak_particles_scene_run_step(&run, &d), AK_OK);
    AK_CHECK_EQ(run.step_index, 10);
    ak_particles_state st = ak_particles_get_state(run.system);
    AK_CHECK_EQ(st.count, 1u);
    /* v_k = k g dt, x_n = x_0 + g dt^2 n (n + 1) / 2 */
    if (st.count == 1) AK_CHECK_NEAR(st.position[0].y, 5.0f - 10.0f * 1e-4f * 55.0f, 2e-5f);
    ak_particles_scene_run_free(&run);
    ak_particles_scene_free(&s);

    const char* bursts = "{\"dt\": 0.1, \"gravity\": [0, 0, 0], \"emitters\": [{\"rate\": 0, \"burst\": 7,"
                         " \"burst_start\": 0.25, \"burst_interval\": 0.5, \"lifetime\": [100, 100]}]}";
    AK_CHECK_EQ(LOAD(ak_particles_scene_load_bytes, bursts, &s, &d), AK_OK);
    AK_CHECK_EQ(ak_particles_scene_run_init(&run, &s, NULL, &d), AK_OK);
    /* bursts at 0.25, 0.75, 1.25 ...: fired in the step that ends after them */
    const size_t want[10] = {0, 0, 7, 7, 7, 7, 7, 14, 14, 14};
    for (int k = 0; k < 10; ++k) {
        AK_CHECK_EQ(ak_particles_scene_run_step(&run, &d), AK_OK);
        AK_CHECK_MSG(ak_particles_count(run.system) == want[k], "step %d: %zu particles, want %zu", k,
                     ak_particles_count(run.system), want[k]);
    }
    ak_particles_scene_run_free(&run);
    ak_particles_scene_run_free(&run); /* twice is fine */
    ak_particles_scene_free(&s);
}

/* ---- files (every format): the example scenes load, a missing file is AK_ERR_IO ------------ */

AK_TEST(files_load_and_missing_files_fail) {
    ak_diag d;
    ak_particles_scene ps;
    AK_CHECK_MSG(ak_particles_scene_load_file(AK_SOURCE_DIR "/examples/particles_fountain.json", &ps, &d) == AK_OK,
                 "%s", d.message);
    /* the example lists 3 particles, 2 springs and 2 emitters, the second bursting 300 */
    AK_CHECK_EQ(ps.particle_count, 3u);
    AK_CHECK_EQ(ps.world.springs.count, 2u);
    AK_CHECK_EQ(ps.emitter_count, 2u);
    if (ps.emitter_count == 2) AK_CHECK_EQ(ps.bursts[1].count, 300u);
    AK_CHECK_EQ(ps.capacity, 20000u);
    ak_particles_scene_free(&ps);
    AK_CHECK_EQ(ak_particles_scene_load_file("nope.json", &ps, &d), AK_ERR_IO);
    AK_CHECK_STREQ(d.message, "nope.json: cannot open the file");

    ak_cloth_scene cs;
    AK_CHECK_MSG(ak_cloth_scene_load_file(AK_SOURCE_DIR "/examples/cloth_flag.json", &cs, &d) == AK_OK, "%s",
                 d.message);
    ak_cloth_scene_free(&cs);
    AK_CHECK_EQ(ak_cloth_scene_load_file("nope.json", &cs, &d), AK_ERR_IO);
    AK_CHECK_STREQ(d.message, "nope.json: cannot open the file");

    ak_fluid_scene* fs = malloc(sizeof *fs);
    AK_CHECK(fs != NULL);
    if (fs) {
        AK_CHECK_MSG(ak_fluid_scene_load_file(AK_SOURCE_DIR "/examples/fluid_dam.json", fs, &d) == AK_OK, "%s",
                     d.message);
        AK_CHECK(ak_fluid_scene_initial_count(fs) > 0);
        AK_CHECK_EQ(ak_fluid_scene_load_file("nope.json", fs, &d), AK_ERR_IO);
        ak_fluid_scene_free(fs);
        free(fs);
    }

    ak_boids_scene bs;
    ak_boids_scene_defaults(&bs);
    AK_CHECK_MSG(ak_boids_scene_load_file(AK_SOURCE_DIR "/examples/boids_flock.json", &bs, &d) == AK_OK, "%s",
                 d.message);
    ak_boids_scene_free(&bs);
    AK_CHECK_EQ(ak_boids_scene_load_file("nope.json", &bs, &d), AK_ERR_IO);
    ak_boids_scene_free(&bs);

    /* a file over the budget: the message says so (the budget is 64 MiB: write a sparse file) */
    const char* big = "test_scenes_big.json";
    FILE* f = fopen(big, "wb");
    AK_CHECK(f != NULL);
    if (f) {
        fputc('{', f);
        fseek(f, (long)AK_CLOTH_SCENE_MAX_FILE_SIZE + 16, SEEK_SET);
        fputc('}', f);
        fclose(f);
        AK_CHECK_EQ(ak_cloth_scene_load_file(big, &cs, &d), AK_ERR_IO);
        AK_CHECK_MSG(strstr(d.message, "larger than 67108864 bytes") != NULL, "%s", d.message);
        remove(big);
    }
}

/* ---- cloth ---------------------------------------------------------------------------------- */

AK_TEST(cloth_bytes_errors_and_presets) {
    ak_cloth_scene s;
    ak_diag d;
    const char* text = "{\"grid\": {\"width\": 5, \"height\": 4, \"spacing\": 0.1}, \"pins\": [0, 4],"
                       " \"wind\": [1, 0, 0], \"steps\": 7,"
                       " \"character\": {\"model\": \"builtin:humanoid\"}}";
    AK_CHECK_EQ(LOAD(ak_cloth_scene_load_bytes, text, &s, &d), AK_OK);
    AK_CHECK_EQ(s.desc.grid_width, 5u);
    AK_CHECK_EQ(s.desc.grid_height, 4u);
    AK_CHECK_NEAR(s.desc.spacing, 0.1f, 0.0f);
    AK_CHECK_EQ(s.pin_count, 2u);
    AK_CHECK(s.desc.pins.ptr == s.pins && s.desc.pins.count == 2);
    AK_CHECK_EQ(s.steps, 7);
    /* absent keys: dt 1/60, 10 substeps (docs/cloth.md) */
    AK_CHECK_NEAR(s.dt, 1.0f / 60.0f, 0.0f);
    AK_CHECK_EQ(s.substeps, 10u);
    /* the character is recorded by name only: loading it is the caller's */
    AK_CHECK_STREQ(s.model, "builtin:humanoid");
    ak_cloth_scene_free(&s);

    AK_CHECK_EQ(LOAD(ak_cloth_scene_load_bytes, "{\"grid\": {\"width\": 1}}", &s, &d), AK_ERR_PARSE);
    AK_CHECK_STREQ(d.message, "t.json: grid.width: 1 is outside [2, 4096]");
    AK_CHECK_EQ(LOAD(ak_cloth_scene_load_bytes, "{\"grid\": {\"width\": 4096, \"height\": 4096}}", &s, &d),
                AK_ERR_PARSE);
    AK_CHECK_MSG(strstr(d.message, "t.json: grid: ") == d.message && strstr(d.message, "budget"), "%s", d.message);
    AK_CHECK(s.pins == NULL);

    /* flag: 32 x 20 pinned along its pole edge (20 pins, column 0), wind (8, 0, 2) */
    AK_CHECK_EQ(ak_cloth_scene_preset("flag", &s, &d), AK_OK);
    AK_CHECK_EQ(s.desc.grid_width, 32u);
    AK_CHECK_EQ(s.desc.grid_height, 20u);
    AK_CHECK_EQ(s.pin_count, 20u);
    for (size_t k = 0; k < s.pin_count; ++k) AK_CHECK_EQ(s.pins[k] % 32u, 0u);
    AK_CHECK(s.wind.x == 8.0f && s.wind.y == 0.0f && s.wind.z == 2.0f);
    ak_cloth_scene_free(&s);
    /* curtain 40 x 30 on 14 rings; drape 32 x 32 on a sphere of radius 0.3 at y = 0.5 */
    AK_CHECK_EQ(ak_cloth_scene_preset("curtain", &s, &d), AK_OK);
    AK_CHECK(s.desc.grid_width == 40u && s.desc.grid_height == 30u && s.pin_count == 14u);
    ak_cloth_scene_free(&s);
    AK_CHECK_EQ(ak_cloth_scene_preset("drape", &s, &d), AK_OK);
    AK_CHECK(s.desc.grid_width == 32u && s.desc.grid_height == 32u && s.sphere_count == 1u);
    if (s.sphere_count == 1) {
        AK_CHECK_NEAR(s.spheres[0].radius, 0.3f, 0.0f);
        AK_CHECK_NEAR(s.spheres[0].center.y, 0.5f, 0.0f);
    }
    AK_CHECK(s.self_collision);
    ak_cloth_scene_free(&s);
    /* cape: 12 x 30 attached to builtin:humanoid's spine_02 */
    AK_CHECK_EQ(ak_cloth_scene_preset("cape", &s, &d), AK_OK);
    AK_CHECK(s.desc.grid_width == 12u && s.desc.grid_height == 30u);
    AK_CHECK_STREQ(s.model, "builtin:humanoid");
    AK_CHECK(s.attach_count > 0);
    if (s.attach_count) AK_CHECK_STREQ(s.attach[0].joint, "spine_02");
    ak_cloth_scene_free(&s);
    AK_CHECK_EQ(ak_cloth_scene_preset("sail", &s, &d), AK_ERR_NOT_FOUND);
}

/* A cloth scene run as the command runs it: the flag's pinned pole edge stays where it was built,
 * the free edge falls and streams, every position stays finite; the spring solver raises its
 * substeps to its stable bound and says so. */
AK_TEST(cloth_scene_run) {
    ak_cloth_scene s;
    ak_diag d;
    AK_CHECK_EQ(ak_cloth_scene_preset("flag", &s, &d), AK_OK);
    ak_cloth_scene_run run;
    AK_CHECK_EQ(ak_cloth_scene_run_init(&run, &s, NULL, &d), AK_OK);
    AK_CHECK_EQ(run.vertex_count, 640u);
    ak_vec3 pin0[20];
    for (size_t k = 0; k < s.pin_count && k < 20; ++k) pin0[k] = run.positions[s.pins[k]];
    const ak_vec3 corner0 = run.positions[31]; /* the free top corner */
    for (int k = 0; k < 10; ++k) AK_CHECK_EQ(ak_cloth_scene_run_step(&run, "flag", &d), AK_OK);
    AK_CHECK_EQ(run.step_index, 10);
    AK_CHECK_NEAR(run.time, 10.0f * s.dt, 1e-6f);
    for (size_t k = 0; k < s.pin_count && k < 20; ++k) {
        const ak_vec3 p = run.positions[s.pins[k]];
        AK_CHECK(p.x == pin0[k].x && p.y == pin0[k].y && p.z == pin0[k].z);
    }
    AK_CHECK(ak_vec3_distance(run.positions[31], corner0) > 1e-3f);
    bool finite = true;
    for (size_t i = 0; i < run.vertex_count; ++i) finite &= ak_vec3_is_finite(run.positions[i]);
    AK_CHECK(finite);
    ak_cloth_scene_run_free(&run);
    ak_cloth_scene_run_free(&run);
    /* springs: 153 substeps for the flag (docs/cloth.md), not the scene's 10 */
    s.desc.solver = AK_CLOTH_SPRINGS;
    s.desc.bending = AK_CLOTH_BEND_SPRINGS;
    AK_CHECK_EQ(ak_cloth_scene_run_init(&run, &s, NULL, &d), AK_OK);
    AK_CHECK(run.stable_substep > 0.0 && run.substeps_given == 10u);
    AK_CHECK_EQ(s.substeps, 153u);
    ak_cloth_scene_run_free(&run);
    ak_cloth_scene_free(&s);
}

/* ---- fluid ---------------------------------------------------------------------------------- */

AK_TEST(fluid_bytes_errors_and_presets) {
    ak_fluid_scene* s = malloc(sizeof *s);
    AK_CHECK(s != NULL);
    if (!s) return;
    ak_diag d;
    const char* text = "{\"solver\": \"sph\", \"box\": {\"min\": [0, 0, 0], \"max\": [1, 1, 1]},"
                       " \"blocks\": [{\"min\": [0, 0, 0], \"max\": [0.1, 0.1, 0.1]}], \"steps\": 3}";
    AK_CHECK_MSG(LOAD(ak_fluid_scene_load_bytes, text, s, &d) == AK_OK, "%s", d.message);
    AK_CHECK_EQ(s->desc.solver, AK_FLUID_SPH);
    AK_CHECK_EQ(s->block_count, 1u);
    AK_CHECK_EQ(ak_fluid_scene_steps(s), 3);
    /* SPH's default step is 1e-3 s (docs/fluid.md); h = 2 rest spacings */
    AK_CHECK_NEAR(s->dt, 1e-3f, 0.0f);
    AK_CHECK_NEAR(s->desc.h, 2.0f * ak_fluid_rest_spacing(&s->desc), 1e-7f);
    /* the lattice of a 0.1 m cube at the rest spacing of 1 g particles of water (1 cm) */
    const double sp = ak_fluid_rest_spacing(&s->desc);
    const size_t per_axis = (size_t)floor(0.1 / sp + 1e-4);
    AK_CHECK_EQ(ak_fluid_scene_initial_count(s), per_axis * per_axis * per_axis);

    AK_CHECK_EQ(LOAD(ak_fluid_scene_load_bytes, "{\"blocks\": [{\"min\": [0, 0, 0], \"max\": [1, 1]}]}", s, &d),
                AK_ERR_PARSE);
    AK_CHECK_STREQ(d.message, "t.json: blocks[0].max: expected 3 numbers, got 2");
    /* a block over the particle budget fails before anything is allocated */
    AK_CHECK_EQ(LOAD(ak_fluid_scene_load_bytes, "{\"blocks\": [{\"min\": [0, 0, 0], \"max\": [100, 100, 100]}]}", s,
                     &d),
                AK_ERR_PARSE);
    AK_CHECK_MSG(strstr(d.message, "t.json: blocks: ") == d.message, "%s", d.message);

    /* dam: a block 1:2:1 against one wall of a box four times as long */
    AK_CHECK_EQ(ak_fluid_scene_preset("dam", 2000, s, &d), AK_OK);
    AK_CHECK_EQ(s->block_count, 1u);
    if (s->block_count == 1) {
        const ak_fluid_block* b = &s->blocks[0];
        const float w = b->max.x - b->min.x;
        AK_CHECK_NEAR(b->max.y - b->min.y, 2.0f * w, 1e-6f);
        AK_CHECK_NEAR(b->max.z - b->min.z, w, 1e-6f);
        AK_CHECK_NEAR(s->desc.box_max.x - s->desc.box_min.x, 4.0f * w, 1e-6f);
    }
    /* pour: the count is the capacity; an emitter and a sphere */
    AK_CHECK_EQ(ak_fluid_scene_preset("pour", 5000, s, &d), AK_OK);
    AK_CHECK_EQ(ak_fluid_scene_capacity(s), 5000u);
    AK_CHECK(s->emitter_count == 1 && s->collider_count == 1 && s->colliders[0].shape == AK_FLUID_SPHERE);
    AK_CHECK_EQ(ak_fluid_scene_preset("splash", 0, s, &d), AK_OK);
    AK_CHECK(s->block_count == 2 && s->colliders[0].shape == AK_FLUID_CAPSULE);
    AK_CHECK_EQ(ak_fluid_scene_preset("lake", 0, s, &d), AK_ERR_NOT_FOUND);
    AK_CHECK(strstr(d.message, "dam, pour, splash") != NULL);
    free(s);
}

/* ---- boids ---------------------------------------------------------------------------------- */

AK_TEST(boids_bytes_errors_and_presets) {
    ak_boids_scene s;
    ak_diag d;
    ak_boids_scene_defaults(&s);
    /* the defaults (docs/boids.md): 500 birds, 2000 steps of 0.02 s, a 20 m box */
    AK_CHECK_EQ(s.count, 500u);
    AK_CHECK_EQ(s.steps, 2000);
    AK_CHECK_NEAR(s.dt, 0.02f, 0.0f);
    AK_CHECK(s.params.bounds_min.x == -10.0f && s.params.bounds_max.x == 10.0f);
    AK_CHECK_EQ(LOAD(ak_boids_scene_load_bytes, "{\"count\": 40, \"steps\": 9}", &s, &d), AK_OK);
    AK_CHECK_EQ(s.count, 40u);
    AK_CHECK_EQ(s.steps, 9);
    AK_CHECK_NEAR(s.dt, 0.02f, 0.0f); /* absent: kept */
    AK_CHECK_EQ(LOAD(ak_boids_scene_load_bytes, "{\"bounds\": {\"mode\": \"bounce\"}}", &s, &d), AK_ERR_PARSE);
    AK_CHECK_STREQ(d.message, "t.json: bounds.mode: \"bounce\" is not one of: steer, wrap, none");
    ak_boids_scene_free(&s);

    /* obstacles: a sphere of radius 2.5 at the centre and four 1.2 x 20 x 1.2 m pillars at ±5 */
    AK_CHECK_EQ(ak_boids_scene_preset("obstacles", &s, &d), AK_OK);
    AK_CHECK_EQ(s.params.obstacle_count, 5u);
    if (s.params.obstacle_count == 5) {
        AK_CHECK(s.params.obstacles[0].kind == AK_BOIDS_SPHERE && s.params.obstacles[0].radius == 2.5f);
        for (int k = 1; k < 5; ++k) {
            const ak_boids_obstacle* o = &s.params.obstacles[k];
            AK_CHECK(o->kind == AK_BOIDS_BOX && fabsf(o->center.x) == 5.0f && fabsf(o->center.z) == 5.0f);
            AK_CHECK(o->half_extents.x == 0.6f && o->half_extents.y == 10.0f && o->half_extents.z == 0.6f);
        }
    }
    /* a file over a preset keeps the preset's values it does not name */
    AK_CHECK_EQ(LOAD(ak_boids_scene_load_bytes, "{\"seed\": 5}", &s, &d), AK_OK);
    AK_CHECK(s.seed == 5 && s.params.obstacle_count == 5);
    ak_boids_scene_free(&s);
    /* predator: species 1 is 0.6% of the agents, max_speed 4.5, pursues species 0 within 10 m */
    AK_CHECK_EQ(ak_boids_scene_preset("predator", &s, &d), AK_OK);
    AK_CHECK_EQ(s.params.species_count, 2u);
    AK_CHECK_NEAR(s.fraction[1], 0.006f, 0.0f);
    AK_CHECK_NEAR(s.species[1].max_speed, 4.5f, 0.0f);
    AK_CHECK(s.species[1].pursue_mask == 1u && s.species[1].pursue_radius == 10.0f);
    AK_CHECK(s.species[0].flee_mask == 2u && s.species[0].flee_radius == 6.0f);
    ak_boids_scene_free(&s);
    AK_CHECK_EQ(ak_boids_scene_preset("swarm", &s, &d), AK_ERR_NOT_FOUND);
    ak_boids_scene_free(&s);
    /* the box grows as cbrt(count / 500) beyond 500 agents */
    ak_boids_scene_defaults(&s);
    ak_boids_scene_scale_bounds(&s, 4000);
    AK_CHECK_NEAR(s.params.bounds_max.x, 20.0f, 1e-5f);
}

/* A boids scene run as the command runs it: the predator preset places 3 predators among 500
 * agents inside the bounds (docs/boids.md), and a run is a function of the seed alone. */
AK_TEST(boids_scene_run) {
    ak_boids_scene s;
    ak_diag d;
    AK_CHECK_EQ(ak_boids_scene_preset("predator", &s, &d), AK_OK);
    ak_boids_scene_run a, b;
    AK_CHECK_EQ(ak_boids_scene_run_init(&a, &s, NULL, &d), AK_OK);
    AK_CHECK_EQ(ak_boids_scene_run_init(&b, &s, &(ak_boids_scene_run_desc){.thread_count = 2, .naive = true}, &d), AK_OK);
    AK_CHECK_EQ(a.agent_count, 500u);
    size_t predators = 0;
    for (size_t i = 0; i < a.agent_count; ++i) {
        predators += a.species[i] == 1;
        const ak_vec3 p = a.positions[i];
        AK_CHECK(p.x >= -10.0f && p.x <= 10.0f && p.y >= -10.0f && p.y <= 10.0f && p.z >= -10.0f && p.z <= 10.0f);
    }
    AK_CHECK_EQ(predators, 3u);
    for (int k = 0; k < 5; ++k) {
        AK_CHECK_EQ(ak_boids_scene_run_step(&a), AK_OK);
        AK_CHECK_EQ(ak_boids_scene_run_step(&b), AK_OK);
    }
    AK_CHECK_EQ(a.step_index, 5);
    /* grid on one thread and naive search on two: the same bits (boids.h) */
    AK_CHECK(memcmp(a.positions, b.positions, a.agent_count * sizeof(ak_vec3)) == 0);
    AK_CHECK(memcmp(a.velocities, b.velocities, a.agent_count * sizeof(ak_vec3)) == 0);
    ak_boids_scene_run_free(&a);
    ak_boids_scene_run_free(&b);
    ak_boids_scene_run_free(&b);
    /* a leader index past the agents is refused with its key path */
    ak_boids_scene_free(&s);
    ak_boids_scene_defaults(&s);
    AK_CHECK_EQ(LOAD(ak_boids_scene_load_bytes, "{\"count\": 4, \"leader\": {\"index\": 9}}", &s, &d), AK_OK);
    AK_CHECK(ak_boids_scene_run_init(&a, &s, &(ak_boids_scene_run_desc){.name = "t.json"}, &d) != AK_OK);
    AK_CHECK_STREQ(d.message, "t.json: leader.index: 9 is not below the 4 agents");
    ak_boids_scene_run_free(&a);
    ak_boids_scene_free(&s);
}

int main(void) {
    AK_RUN(particles_from_bytes);
    AK_RUN(particles_errors_name_key_paths);
    AK_RUN(particles_presets);
    AK_RUN(particles_scene_run);
    AK_RUN(files_load_and_missing_files_fail);
    AK_RUN(cloth_bytes_errors_and_presets);
    AK_RUN(cloth_scene_run);
    AK_RUN(fluid_bytes_errors_and_presets);
    AK_RUN(boids_bytes_errors_and_presets);
    AK_RUN(boids_scene_run);
    return ak_test_finish();
}

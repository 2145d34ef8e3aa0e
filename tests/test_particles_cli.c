/* animkit particles: the command's contract (exit codes, one-line errors naming file and key
 * path, the --json keys and order) with results checked against closed forms. */
#include <animkit/animkit.h>
#include <cjson/cJSON.h>
#include <unistd.h> /* rmdir */

#include "ak_test.h"
#include "cli_test.h"

static double num(const cJSON* arr, int i) { return cJSON_GetArrayItem(arr, i)->valuedouble; }

AK_TEST(bad_scenes_exit_1_with_path) {
    struct {
        const char* text;
        const char* expect; /* key path and problem in the one line */
    } cases[] = {
        {"{\"particles\": [{\"p\": [0,0,0]}], \"springs\": [{\"i\": 0, \"j\": 5}]}",
         "springs[0].j"},
        {"{\"spheres\": [{\"r\": -1}]}", "spheres[0].r"},
        {"{\"gravty\": [0, 1, 0]}", "unknown key \"gravty\""},
        {"{\"particles\": [{\"p\": [0, \"x\", 0]}]}", "particles[0].p"},
        {"{\"dt\": NaN}", "invalid JSON"},
        {"{\"dt\": 1e999}", "dt"},
        {"{\"drag\": {\"linear\": -1}}", "drag.linear"},
        {"{\"integrator\": \"leapfrog\"}", "integrator"},
        {"{\"emitters\": [{\"speed\": [3, 1]}]}", "emitters[0].speed"},
        {"{\"planes\": [{\"n\": [0, 0, 0]}]}", "planes[0].n"},
        {"{\"particles\": [{\"m\": 1, \"m\": 2}]}", "particles[0]"},
        {"[1, 2]", "top level"},
        {"{\"render\": {\"style\": \"blobs\"}}", "render.style"},
        {"{\"render\": {\"texture\": \"fire.jpg\"}}", "render.texture"},
        {"{\"render\": {\"sheet\": [2.5, 1]}}", "render.sheet"},
        {"{\"render\": {\"colour_over_life\": [[0.5, 1, 1, 1, 1], [0.2, 1, 1, 1, 1]]}}",
         "render.colour_over_life[1]"},
        {"{\"render\": {\"size_over_life\": [[0, 1, 2]]}}", "render.size_over_life[0]"},
    };
    for (size_t k = 0; k < sizeof cases / sizeof cases[0]; ++k) {
        write_file("particles_bad.json", cases[k].text);
        int rc = run("particles particles_bad.json --steps 2", true);
        AK_CHECK_MSG(rc == 1, "case %zu: exit %d (%s)", k, rc, out_buf);
        AK_CHECK_MSG(strstr(out_buf, "particles_bad.json") && strstr(out_buf, cases[k].expect),
                     "case %zu: %s", k, out_buf);
        int lines = 0;
        for (const char* p = out_buf; *p; ++p) lines += *p == '\n';
        AK_CHECK_MSG(lines == 1, "case %zu: %d lines", k, lines);
    }
    AK_CHECK_EQ(run("particles missing_file.json", true), 1);
    AK_CHECK_EQ(run("particles", true), 2);
    AK_CHECK_EQ(run("particles --preset nope", true), 2);
    AK_CHECK_EQ(run("particles --preset rain particles_bad.json", true), 2);
    AK_CHECK_EQ(run("particles --preset rain --integrator midpoint", true), 2);
    AK_CHECK_EQ(run("particles --preset rain --dt -1", true), 2);
    AK_CHECK_EQ(run("particles --preset rain -o out.bmp", true), 2);
    /* out-of-range flags name the allowed range */
    AK_CHECK(run("particles --preset rain --steps 100000001", true) == 2 && strstr(out_buf, "0..100000000"));
    AK_CHECK(run("particles --preset rain --size 100000x100000 -o big.png", true) == 2 && strstr(out_buf, "8..8192"));
    AK_CHECK_EQ(run("particles --help", true), 0);
    AK_CHECK(strstr(out_buf, "usage: animkit particles") != NULL);
}

AK_TEST(json_matches_closed_form) {
    /* A thrown particle (Verlet: exact for constant gravity) and a pinned one; the file's
     * dt is overridden on the command line. */
    write_file(
        "particles_throw.json",
        "{\"dt\": 0.5, \"integrator\": \"euler\", \"gravity\": [0, -10, 0],"
        " \"particles\": [{\"p\": [1, 2, 3], \"v\": [2, 5, 0]}, {\"p\": [0, 1, 0], \"m\": 0}]}");
    AK_CHECK_EQ(run("particles particles_throw.json --steps 40 --dt 0.025 --integrator verlet "
                    "--json throw.json", true),
                0);
    cJSON* j = read_json("throw.json");
    AK_CHECK(j != NULL);
    if (!j) return;
    AK_CHECK_NEAR(cJSON_GetObjectItem(j, "time")->valuedouble, 1.0, 1e-6);
    AK_CHECK_EQ(cJSON_GetObjectItem(j, "steps")->valueint, 40);
    const cJSON* ps = cJSON_GetObjectItem(j, "particles");
    AK_CHECK_EQ(cJSON_GetArraySize(ps), 2);
    const cJSON* p0 = cJSON_GetObjectItem(cJSON_GetArrayItem(ps, 0), "p");
    const cJSON* v0 = cJSON_GetObjectItem(cJSON_GetArrayItem(ps, 0), "v");
    const double t = 40 * (double)0.025f;
    AK_CHECK_NEAR(num(p0, 0), 1 + 2 * t, 1e-4);
    AK_CHECK_NEAR(num(p0, 1), 2 + 5 * t - 5 * t * t, 1e-4);
    AK_CHECK_NEAR(num(p0, 2), 3, 1e-6);
    AK_CHECK_NEAR(num(v0, 1), 5 - 10 * t, 1e-4);
    const cJSON* p1 = cJSON_GetObjectItem(cJSON_GetArrayItem(ps, 1), "p");
    AK_CHECK_NEAR(num(p1, 1), 1.0, 0.0);
    cJSON_Delete(j);

    /* Emitted particles come after the file's; 2.5/s for 2 s emits exactly 5. */
    write_file("particles_emit.json",
               "{\"gravity\": [0, 0, 0], \"particles\": [{\"p\": [9, 9, 9]}],"
               " \"emitters\": [{\"rate\": 2.5, \"speed\": [0, 0], \"lifetime\": [100, 100]}]}");
    AK_CHECK_EQ(
        run("particles particles_emit.json --steps 200 --dt 0.01 --json emit.json --threads 2", true), 0);
    j = read_json("emit.json");
    AK_CHECK(j != NULL);
    if (!j) return;
    ps = cJSON_GetObjectItem(j, "particles");
    AK_CHECK_EQ(cJSON_GetArraySize(ps), 6);
    AK_CHECK_NEAR(num(cJSON_GetObjectItem(cJSON_GetArrayItem(ps, 0), "p"), 0), 9.0, 0.0);
    cJSON_Delete(j);
}

/* A file particle that dies (its lifetime) before particles joined by a spring: the spring
 * follows the survivors to their new indices (two unit masses on a k = 100 spring released
 * 1 m stretched: L(t) = 1 + cos(sqrt(200) t)), and the springs to the dead particle go. The
 * step after the death used to fail with "an index is out of range". */
AK_TEST(springs_survive_a_death) {
    write_file("particles_die.json",
               "{\"dt\": 0.0005, \"gravity\": [0, 0, 0],"
               " \"particles\": [{\"p\": [1, 5, 0], \"lifetime\": 0.01}, {\"p\": [0, 0, 0]}, {\"p\": [2, 0, 0]}],"
               " \"springs\": [{\"i\": 1, \"j\": 2, \"rest\": 1, \"k\": 100}, {\"i\": 0, \"j\": 2, \"k\": 0}]}");
    AK_CHECK_EQ(run("particles particles_die.json --steps 400 --json die.json", true), 0);
    cJSON* j = read_json("die.json");
    AK_CHECK(j != NULL);
    if (!j) return;
    const cJSON* ps = cJSON_GetObjectItem(j, "particles");
    AK_CHECK_EQ(cJSON_GetArraySize(ps), 2);
    if (cJSON_GetArraySize(ps) == 2) {
        const cJSON* a = cJSON_GetObjectItem(cJSON_GetArrayItem(ps, 0), "p");
        const cJSON* b = cJSON_GetObjectItem(cJSON_GetArrayItem(ps, 1), "p");
        const double t = 400 * 0.0005, len = num(b, 0) - num(a, 0);
        AK_CHECK_NEAR(len, 1 + cos(sqrt(200.0) * t), 0.01);
        AK_CHECK_NEAR(num(a, 0) + num(b, 0), 2.0, 1e-4); /* the centre stays: no force from the dead one */
        AK_CHECK_NEAR(num(a, 1), 0.0, 1e-6);
    }
    cJSON_Delete(j);

    /* bursts every 1e-12 s into a full system of 10: the due bursts are dropped (the loop
     * used to call the emitter 10^7 times per step, and its 32-bit count wrapped and spun) */
    write_file("particles_bursts.json", "{\"capacity\": 10, \"emitters\": [{\"burst\": 4, \"burst_interval\": 1e-12,"
                                        " \"lifetime\": [0, 0]}]}");
    AK_CHECK_EQ(run("particles particles_bursts.json --steps 3 --json bursts.json", true), 0);
    j = read_json("bursts.json");
    AK_CHECK(j != NULL && cJSON_GetArraySize(cJSON_GetObjectItem(j, "particles")) == 10);
    cJSON_Delete(j);
    remove("particles_die.json"), remove("die.json"), remove("particles_bursts.json"), remove("bursts.json");
}

/* One red particle alone is framed with room around it (zero-size bounds put the camera on
 * it: the image showed only the ground); the title says "1 particle". */
AK_TEST(single_particle_is_framed) {
    write_file("particles_one.json", "{\"particles\": [{\"m\": 0, \"p\": [0, 5, 0], \"colour\": [1, 0, 0, 1]}]}");
    AK_CHECK_EQ(run("particles particles_one.json --steps 0 --size 160x120 -o one.png", true), 0);
    int w = 0, h = 0, red = 0;
    AK_CHECK(ak_png_info("one.png", &w, &h) == AK_OK && w == 160 && h == 120);
    static uint8_t px[160 * 120 * 4];
    const ak_image img = {.pixels = px, .width = 160, .height = 120};
    AK_CHECK(ak_png_read("one.png", &img) == AK_OK);
    for (int i = 0; i < 160 * 120; ++i) red += px[4 * i] > 150 && px[4 * i + 1] < 80 && px[4 * i + 2] < 80;
    AK_CHECK_MSG(red >= 4, "%d red pixels", red);
    remove("particles_one.json"), remove("one.png");
}

/* Count pixels of an image file near an sRGB colour (each channel within 40 levels). */
static int count_colour(const char* path, int w, int h, int r, int g, int b) {
    static uint8_t px[200 * 150 * 4];
    const ak_image img = {.pixels = px, .width = w, .height = h};
    if (w * h > 200 * 150 || ak_png_read(path, &img) != AK_OK) return -1;
    int n = 0;
    for (int i = 0; i < w * h; ++i)
        n += abs(px[4 * i] - r) < 40 && abs(px[4 * i + 1] - g) < 40 && abs(px[4 * i + 2] - b) < 40;
    return n;
}

AK_TEST(scene_sprites_colour_and_sheet_over_life) {
    /* A white pinned particle of lifetime 1 s drawn as a sprite: its colour comes from the
     * colour_over_life key (blue), and with a 2-frame PNG sheet (red | green, relative to the
     * scene file) the frame follows the age: frame 0 before t = 0.5, frame 1 after. */
    write_file("particles_sprite.json",
               "{\"particles\": [{\"m\": 0, \"p\": [0, 1, 0], \"size\": 0.15, \"lifetime\": 1}],"
               " \"render\": {\"style\": \"sprites\", \"colour_over_life\": [[0, 0, 0, 1, 1]]}}");
    AK_CHECK_EQ(run("particles particles_sprite.json --steps 10 --size 160x120 -o sprite_blue.png", true), 0);
    int blue = count_colour("sprite_blue.png", 160, 120, 0, 0, 255);
    AK_CHECK_MSG(blue >= 20, "%d blue pixels", blue);
    /* cut-outs: alpha-tested, so every drawn pixel has the full colour (none half blended) */
    write_file("particles_cutout.json",
               "{\"particles\": [{\"m\": 0, \"p\": [0, 1, 0], \"size\": 0.15}],"
               " \"render\": {\"style\": \"sprites\", \"blend\": \"cutout\", \"colour_over_life\": [[0, 0, 0, 1, 1]]}}");
    AK_CHECK_EQ(run("particles particles_cutout.json --steps 1 --size 160x120 -o sprite_cut.png", true), 0);
    static uint8_t cut_px[160 * 120 * 4];
    const ak_image cut = {.pixels = cut_px, .width = 160, .height = 120};
    AK_CHECK_EQ(ak_png_read("sprite_cut.png", &cut), AK_OK);
    int full = 0, partial = 0;
    for (int i = 0; i < 160 * 120; ++i) {
        const uint8_t* p = cut_px + 4 * i;
        if (p[2] > 2 * p[0] + 40 && p[2] > 2 * p[1] + 40) { /* clearly blue: sprite pixels */
            if (p[0] <= 2 && p[1] <= 2 && p[2] >= 253) ++full;
            else ++partial;
        }
    }
    AK_CHECK_MSG(full >= 20 && partial <= full / 4, "cut-out: %d full and %d partly blue pixels", full, partial);
    remove("particles_cutout.json"), remove("sprite_cut.png");
    uint8_t sheet_px[2 * 8 * 8 * 4];
    ak_image sheet = {.pixels = sheet_px, .width = 16, .height = 8};
    for (int y = 0; y < 8; ++y)
        for (int x = 0; x < 16; ++x) {
            uint8_t* p = ak_image_pixel(&sheet, x, y);
            p[0] = x < 8 ? 255 : 0, p[1] = x < 8 ? 0 : 255, p[2] = 0, p[3] = 255;
        }
    mkdir("sprite_dir", 0755);
    AK_CHECK_EQ(ak_png_write("sprite_dir/sheet.png", &sheet), AK_OK);
    write_file("sprite_dir/s.json",
               "{\"particles\": [{\"m\": 0, \"p\": [0, 1, 0], \"size\": 0.15, \"lifetime\": 1}],"
               " \"render\": {\"style\": \"sprites\", \"texture\": \"sheet.png\", \"sheet\": [2, 1]}}");
    AK_CHECK_EQ(run("particles sprite_dir/s.json --steps 20 --size 160x120 -o sprite_f0.png", true), 0);
    AK_CHECK_EQ(run("particles sprite_dir/s.json --steps 70 --size 160x120 -o sprite_f1.png", true), 0);
    int r0 = count_colour("sprite_f0.png", 160, 120, 255, 0, 0), g0 = count_colour("sprite_f0.png", 160, 120, 0, 255, 0);
    int r1 = count_colour("sprite_f1.png", 160, 120, 255, 0, 0), g1 = count_colour("sprite_f1.png", 160, 120, 0, 255, 0);
    AK_CHECK_MSG(r0 >= 20 && g0 == 0, "age 0.2 s: %d red, %d green pixels", r0, g0);
    AK_CHECK_MSG(g1 >= 20 && r1 == 0, "age 0.7 s: %d red, %d green pixels", r1, g1);
    /* a missing sheet is a one-line error naming the file */
    write_file("sprite_dir/m.json", "{\"render\": {\"style\": \"sprites\", \"texture\": \"nope.png\"}}");
    AK_CHECK_EQ(run("particles sprite_dir/m.json --steps 1 -o sprite_m.png", true), 1);
    AK_CHECK_MSG(strstr(out_buf, "sprite_dir/nope.png") != NULL, "%s", out_buf);
    remove("particles_sprite.json"), remove("sprite_blue.png"), remove("sprite_f0.png"), remove("sprite_f1.png");
    remove("sprite_dir/s.json"), remove("sprite_dir/m.json"), remove("sprite_dir/sheet.png"), rmdir("sprite_dir");
}

AK_TEST(presets_run_and_render) {
    const char* presets[] = {"fountain", "rain", "fireworks", "character", "fire", "smoke"};
    for (int k = 0; k < 6; ++k) {
        char args[256];
        snprintf(
            args, sizeof args,
            "particles --preset %s --steps 12 --size 96x72 -o preset_%s.png --json preset_%s.json",
            presets[k], presets[k], presets[k]);
        AK_CHECK_MSG(run(args, true) == 0, "%s: %s", presets[k], out_buf);
        char path[64];
        snprintf(path, sizeof path, "preset_%s.png", presets[k]);
        int w = 0, h = 0;
        AK_CHECK_EQ(ak_png_info(path, &w, &h), AK_OK);
        AK_CHECK(w == 96 && h == 72);
    }
    AK_CHECK_EQ(run("particles --preset rain --steps 0 --size 64x48 -o zero.gif --json zero.json", true), 0);
    int zw = 0, zh = 0, zf = 0;
    AK_CHECK_EQ(ak_gif_info("zero.gif", &zw, &zh, &zf), AK_OK);
    AK_CHECK_EQ(zf, 1);
    AK_CHECK_EQ(run("particles --preset fireworks --steps 6 --size 64x48 -o fw.gif", true), 0);
    int w = 0, h = 0, frames = 0;
    AK_CHECK_EQ(ak_gif_info("fw.gif", &w, &h, &frames), AK_OK);
    AK_CHECK_EQ(frames, 7);
    /* Same seed, 1 and 2 threads: identical files. */
    AK_CHECK_EQ(run("particles --preset rain --steps 30 --seed 5 --json r1.json", true), 0);
    AK_CHECK_EQ(run("particles --preset rain --steps 30 --seed 5 --threads 2 --json r2.json", true), 0);
    cJSON* a = read_json("r1.json");
    char* sa = a ? cJSON_PrintUnformatted(a) : NULL;
    cJSON* b = read_json("r2.json");
    char* sb = b ? cJSON_PrintUnformatted(b) : NULL;
    AK_CHECK(sa && sb && strcmp(sa, sb) == 0);
    free(sa), free(sb), cJSON_Delete(a), cJSON_Delete(b);
}

int main(void) {
    AK_RUN(bad_scenes_exit_1_with_path);
    AK_RUN(json_matches_closed_form);
    AK_RUN(springs_survive_a_death);
    AK_RUN(single_particle_is_framed);
    AK_RUN(scene_sprites_colour_and_sheet_over_life);
    AK_RUN(presets_run_and_render);
    return ak_test_finish();
}

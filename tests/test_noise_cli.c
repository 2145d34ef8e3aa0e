/* The animkit noise and terrain commands: the exact output contract (one line, 9 significant
 * digits, values equal to the library's), exit code 2 with the allowed range for bad
 * parameters, and the files terrain writes (16-bit PNG read back, OBJ counts, GIF frames). */
#include <animkit/animkit.h>

#include "ak_test.h"
#include "cli_test.h"

/* One line of space-separated numbers, each printed with %.9g (so it reads back exactly). */
static int parse_line(float* v, int cap) {
    const char* nl = strchr(out_buf, '\n');
    if (!nl || nl[1] != '\0') return -1;
    int n = 0;
    char* p = out_buf;
    while (*p && *p != '\n' && n < cap) {
        char* end;
        v[n++] = strtof(p, &end);
        if (end == p) return -1;
        p = end;
        while (*p == ' ') ++p;
    }
    return n;
}

AK_TEST(noise_values) {
    ak_noise n0 = ak_noise_make(0), n7 = ak_noise_make(7);
    float v[8], g[4];
    AK_CHECK_EQ(run("noise perlin 3.14,42,7", false), 0);
    AK_CHECK_EQ(parse_line(v, 8), 1);
    AK_CHECK(v[0] == ak_noise_perlin3(&n0, 3.14f, 42.0f, 7.0f, NULL));
    AK_CHECK_NEAR(v[0], 0.13691995878400012, 2e-6); /* Perlin's reference value */
    AK_CHECK(strlen(out_buf) <= 12);                 /* "0.13692005\n": 9 significant digits at most */
    AK_CHECK_EQ(run("noise perlin -4.2,10,6 --seed 7 --gradient", false), 0);
    AK_CHECK_EQ(parse_line(v, 8), 4);
    AK_CHECK(v[0] == ak_noise_perlin3(&n7, -4.2f, 10.0f, 6.0f, g) && v[1] == g[0] && v[2] == g[1] && v[3] == g[2]);
    AK_CHECK_EQ(run("noise simplex 1.5,2.25 --octaves 4 --lacunarity 2.5 --gain 0.4 --type ridged --gradient", false), 0);
    AK_CHECK_EQ(parse_line(v, 8), 3);
    const ak_fractal_desc fd = {.basis = AK_NOISE_BASIS_SIMPLEX, .type = AK_FRACTAL_RIDGED, .octaves = 4,
                                .lacunarity = 2.5f, .gain = 0.4f};
    const float p2[2] = {1.5f, 2.25f};
    AK_CHECK(v[0] == ak_fractal_eval(&n0, &fd, 2, p2, g) && v[1] == g[0] && v[2] == g[1]);
    AK_CHECK_EQ(run("noise value 0.3,0.2,0.1,0.7", false), 0);
    const float p4[4] = {0.3f, 0.2f, 0.1f, 0.7f};
    AK_CHECK(parse_line(v, 8) == 1 && v[0] == ak_noise_value(&n0, 4, p4, NULL));
    AK_CHECK_EQ(run("noise worley 0.3,0.7 --type turbulence", false), 0); /* fractal defaults: 6 octaves */
    const ak_fractal_desc fw = {.basis = AK_NOISE_BASIS_WORLEY, .type = AK_FRACTAL_TURBULENCE, .octaves = 6};
    const float pw[2] = {0.3f, 0.7f};
    AK_CHECK(parse_line(v, 8) == 1 && v[0] == ak_fractal_eval(&n0, &fw, 2, pw, NULL));
    AK_CHECK_EQ(run("noise perlin 2 --seed 18446744073709551615", false), 0);
}

AK_TEST(noise_bad_parameters) {
    const char* bad[] = {"noise", "noise perlin", "noise fractal 1,2", "noise perlin 1,2,3,4,5", "noise simplex 1,2,3,4",
                         "noise worley 1,2,3,4", "noise perlin 1,x", "noise perlin 1e30", "noise perlin 1 --octaves 0",
                         "noise perlin 1 --octaves 17", "noise perlin 1 --gain 2.5", "noise perlin 1 --lacunarity -1",
                         "noise perlin 1 --type fractal", "noise perlin 1 --seed -3", "noise perlin 1 --seed 1x",
                         "noise perlin 1 --bogus",
                         "noise perlin 1,,2", "noise perlin 1,", "noise perlin ,1"};
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; ++i) AK_CHECK_MSG(run(bad[i], true) == 2, "%s", bad[i]);
    AK_CHECK(run("noise perlin 1 --octaves 17", true) == 2 && strstr(out_buf, "allowed range 1 to 16"));
    AK_CHECK(run("noise perlin 1 --gain 3", true) == 2 && strstr(out_buf, "(0, 2]"));
    AK_CHECK(run("noise --help", false) == 0 && strstr(out_buf, "usage: animkit noise"));
}

AK_TEST(terrain_files) {
    AK_CHECK_EQ(run("terrain --size 40x30 --world 50 --height 5 --type ridged --erode 2000 -o cli_t.png", false), 0);
    int w = 0, h = 0;
    AK_CHECK(ak_png_info("cli_t.png", &w, &h) == AK_OK && w == 40 && h == 30);
    FILE* f = fopen("cli_t.png", "rb");
    unsigned char head[26] = {0};
    if (f) {
        AK_CHECK(fread(head, 1, 26, f) == 26);
        fclose(f);
    }
    AK_CHECK(head[24] == 16 && head[25] == 0); /* IHDR: bit depth 16, colour type 0 (grey) */
    AK_CHECK_EQ(run("terrain --size 9x5 --noise simplex --octaves 3 -o cli_t.obj", false), 0);
    f = fopen("cli_t.obj", "r");
    int v = 0, vt = 0, vn = 0, faces = 0;
    char line[256];
    while (f && fgets(line, sizeof line, f)) {
        v += strncmp(line, "v ", 2) == 0, vt += strncmp(line, "vt ", 3) == 0;
        vn += strncmp(line, "vn ", 3) == 0, faces += strncmp(line, "f ", 2) == 0;
    }
    if (f) fclose(f);
    AK_CHECK(v == 45 && vt == 45 && vn == 45 && faces == 64);
    AK_CHECK_EQ(run("terrain --size 17x17 -o cli_t.gif", false), 0);
    int frames = 0;
    AK_CHECK(ak_gif_info("cli_t.gif", &w, &h, &frames) == AK_OK && frames == 48);
    AK_CHECK_EQ(run("terrain --size 17x17 --render -o cli_r.png", false), 0);
    AK_CHECK(ak_png_info("cli_r.png", &w, &h) == AK_OK && w == 960);
    remove("cli_t.png"), remove("cli_t.obj"), remove("cli_t.gif"), remove("cli_r.png");
}

/* The shaded render frames the whole terrain: every pixel on the image's border is sky (bluish:
 * blue well above red, where the terrain's sand, grass, rock and shaded snow are not). The
 * near corner used to run off the bottom and left edges. */
AK_TEST(terrain_render_framed) {
    const char* cases[] = {"terrain --size 65x65 --render -o cli_f.png", "terrain --size 65x17 --render -o cli_f.png",
                           "terrain --size 17x65 --height 60 --render -o cli_f.png"};
    for (size_t c = 0; c < sizeof cases / sizeof cases[0]; ++c) {
        AK_CHECK_EQ(run(cases[c], false), 0);
        int w = 0, h = 0;
        AK_CHECK(ak_png_info("cli_f.png", &w, &h) == AK_OK && w > 0 && h > 0);
        uint8_t* px = malloc((size_t)w * (size_t)h * 4);
        const ak_image img = {.pixels = px, .width = w, .height = h};
        AK_CHECK(px && ak_png_read("cli_f.png", &img) == AK_OK);
        int ground = 0;
        for (int y = 0; px && y < h; ++y)
            for (int x = 0; x < w; ++x) {
                if (x != 0 && y != 0 && x != w - 1 && y != h - 1) continue;
                const uint8_t* p = px + ((size_t)y * (size_t)w + (size_t)x) * 4;
                ground += p[2] < p[0] + 15;
            }
        AK_CHECK_MSG(ground == 0, "%s: %d border pixels are terrain", cases[c], ground);
        free(px);
    }
    remove("cli_f.png");
}

AK_TEST(terrain_bad_parameters) {
    const char* bad[] = {"terrain", "terrain -o x.txt", "terrain --size 1x5 -o x.obj", "terrain --size 5000x5 -o x.obj",
                         "terrain --world 0 -o x.obj", "terrain --height -2 -o x.obj", "terrain --noise value -o x.obj",
                         "terrain --octaves 20 -o x.obj", "terrain --gain 0 -o x.obj", "terrain --lacunarity 17 -o x.obj",
                         "terrain --type wavy -o x.obj", "terrain --seed -1 -o x.obj", "terrain --erode 99999999 -o x.obj",
                         "terrain --render -o x.obj", "terrain extra -o x.obj"};
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; ++i) AK_CHECK_MSG(run(bad[i], true) == 2, "%s", bad[i]);
    AK_CHECK(run("terrain --size 1x5 -o x.obj", true) == 2 && strstr(out_buf, "from 2 to 2049"));
    AK_CHECK(run("terrain --erode -5 -o x.obj", true) == 2 && strstr(out_buf, "0 to 10000000"));
    AK_CHECK(run("terrain --size 9x9 -o /nonexistent-dir/x.obj", true) == 1);
}

int main(void) {
    AK_RUN(noise_values);
    AK_RUN(noise_bad_parameters);
    AK_RUN(terrain_files);
    AK_RUN(terrain_render_framed);
    AK_RUN(terrain_bad_parameters);
    return ak_test_finish();
}

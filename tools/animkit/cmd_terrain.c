/* animkit terrain: a fractal heightfield to OBJ, a 16-bit PNG heightmap, a shaded PNG render or
 * a GIF turntable flight. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "cli.h"

static const char* const usage =
    "usage: animkit terrain [--size WxH] [--world S] [--height H] [--noise perlin|simplex]\n"
    "                       [--octaves N] [--lacunarity L] [--gain G] [--type fbm|ridged|turbulence]\n"
    "                       [--seed K] [--erode N] [--render] -o OUT.obj|OUT.png|OUT.gif\n"
    "Generate a heightfield from a fractal sum of noise and write it:\n"
    "  OUT.obj  Wavefront OBJ with normals and UVs\n"
    "  OUT.png  16-bit greyscale heightmap (lowest height 0, highest 65535); with --render a\n"
    "           shaded render coloured by height and slope instead\n"
    "  OUT.gif  a turntable flight around the terrain (48 frames)\n"
    "  --size       samples along x and z, each 2 to 2049 (default 257x257)\n"
    "  --world      metres from the first to the last sample along x, in (0, 1000000] (default 100)\n"
    "  --height     metres of the fractal's top value, in (0, 1000000] (default 20)\n"
    "  --noise      basis (default perlin)\n"
    "  --octaves    1 to 16 (default 8); --lacunarity in (0, 16] (default 2); --gain in (0, 2]\n"
    "               (default 0.5); --type default fbm\n"
    "  --seed       0 to 18446744073709551615 (default 0)\n"
    "  --erode      hydraulic erosion droplets, 0 to 10000000 (default 0), followed by 20\n"
    "               thermal passes\n"
    "Prints one summary line. A progress bar shows on a terminal.\n";

typedef struct terrain_data {
    ak_terrain_desc desc;
    size_t count;
    float* heights;
    ak_vec3* normals;
} terrain_data;

static void erode_progress(size_t done, size_t total, void* user) {
    (void)user;
    cli_progress("erode", done, total);
}

static bool parse_dims(const char* s, uint32_t* w, uint32_t* h) {
    const char* x = s ? strchr(s, 'x') : NULL;
    if (!x || x == s || (size_t)(x - s) >= 16) return false;
    char a[16];
    memcpy(a, s, (size_t)(x - s));
    a[x - s] = '\0';
    long lw, lh;
    if (!cli_parse_int(a, 2, 2049, &lw) || !cli_parse_int(x + 1, 2, 2049, &lh)) return false;
    *w = (uint32_t)lw, *h = (uint32_t)lh;
    return true;
}

static bool parse_u64(const char* s, uint64_t* out) {
    if (!s || !*s || *s == '-' || *s == '+') return false;
    char* end = NULL;
    unsigned long long v = strtoull(s, &end, 10);
    if (*end != '\0' || (v == ~0ull && strcmp(s, "18446744073709551615") != 0)) return false;
    *out = (uint64_t)v;
    return true;
}

/* Whether the box lo..hi projects inside 95% of the view from eye towards target (vertical
 * field of view fovy, aspect w / h), every corner in front of the camera. */
static bool box_in_view(ak_vec3 eye, ak_vec3 target, ak_vec3 lo, ak_vec3 hi, float fovy, float aspect) {
    const ak_vec3 f = ak_vec3_normalize(ak_vec3_sub(target, eye));
    const ak_vec3 rt = ak_vec3_normalize(ak_vec3_cross(f, ak_vec3_make(0, 1, 0)));
    const ak_vec3 up = ak_vec3_cross(rt, f);
    const float ty = 0.95f * tanf(0.5f * fovy), tx = ty * aspect;
    for (int c = 0; c < 8; ++c) {
        const ak_vec3 p = ak_vec3_make(c & 1 ? hi.x : lo.x, c & 2 ? hi.y : lo.y, c & 4 ? hi.z : lo.z);
        const ak_vec3 d = ak_vec3_sub(p, eye);
        const float z = ak_vec3_dot(d, f);
        if (!(z > 0.0f) || fabsf(ak_vec3_dot(d, rt)) > tx * z || fabsf(ak_vec3_dot(d, up)) > ty * z) return false;
    }
    return true;
}

/* Render the coloured mesh from orbit angle a (radians) into img. */
static int render_frames(const terrain_data* t, const char* path, bool gif) {
    const ak_terrain_desc* d = &t->desc;
    const size_t n = t->count, ni = ak_terrain_index_count(d);
    ak_vec3* pos = malloc(n * sizeof *pos);
    ak_vec4* col = malloc(n * sizeof *col);
    uint32_t* idx = malloc(ni * sizeof *idx);
    const int w = gif ? 480 : 960, h = gif ? 360 : 720;
    uint8_t* px = malloc((size_t)w * h * 4);
    ak_raster* r = NULL;
    ak_gif_writer* gw = NULL;
    int rc = CLI_OK;
    if (!pos || !col || !idx || !px) {
        rc = cli_fail("terrain", "out of memory for a %ux%u render", d->width, d->height);
        goto done;
    }
    ak_terrain_mesh(d, (ak_f32_cspan){t->heights, n}, (ak_vec3_span){pos, n}, (ak_vec2_span){0}, (ak_u32_span){idx, ni});
    ak_terrain_colors(d, (ak_f32_cspan){t->heights, n}, (ak_vec3_cspan){t->normals, n}, (ak_vec4_span){col, n});
    ak_result res = ak_raster_create(&(ak_raster_desc){.width = w, .height = h, .supersample = 2, .thread_count = 2},
                                     NULL, &r);
    if (res != AK_OK) {
        rc = cli_fail("terrain", "renderer: %s", ak_result_string(res));
        goto done;
    }
    if (gif) {
        res = ak_gif_writer_create(path, &(ak_gif_desc){.width = w, .height = h, .delay_cs = 6}, NULL, &gw);
        if (res != AK_OK) {
            rc = cli_fail("terrain", "%s: %s", path, ak_result_string(res));
            goto done;
        }
    }
    double mean = 0;
    for (size_t i = 0; i < n; ++i) mean += t->heights[i];
    mean /= (double)n;
    const float S = d->world_size * fmaxf(1.0f, (float)(d->height - 1) / (float)(d->width - 1));
    const ak_vec3 target = ak_vec3_make(0.0f, (float)mean, 0.0f);
    const ak_raster_mesh mesh = {.positions = {pos, n}, .normals = {t->normals, n}, .colors = {col, n},
                                 .indices = {idx, ni}, .material = {.color = {1, 1, 1, 1}, .specular = 0.05f}};
    const int frames = gif ? 48 : 1;
    ak_image img = {.pixels = px, .width = w, .height = h};
    /* one distance for every frame, far enough that the whole terrain is in view in each (the
     * near corner used to leave the image) */
    ak_vec3 lo = pos[0], hi = pos[0];
    for (size_t i = 1; i < n; ++i) lo = ak_vec3_min(lo, pos[i]), hi = ak_vec3_max(hi, pos[i]);
    float zoom = 1.0f;
    for (int f = 0; f < frames; ++f) {
        const float a = 0.6f + AK_TWO_PI * (float)f / (float)frames;
        const float elev = 0.5f * S + (gif ? 0.12f * S * sinf(2.0f * a) : 0.0f);
        while (zoom < 20.0f && !box_in_view(ak_vec3_add(target, ak_vec3_scale(ak_vec3_make(1.1f * S * cosf(a), elev,
                                                                                                1.1f * S * sinf(a)),
                                                                                  zoom)),
                                            target, lo, hi, 0.75f, (float)w / (float)h))
            zoom *= 1.03f;
    }
    for (int f = 0; f < frames && rc == CLI_OK; ++f) {
        const float a = 0.6f + AK_TWO_PI * (float)f / (float)frames;
        const float elev = zoom * (0.5f * S + (gif ? 0.12f * S * sinf(2.0f * a) : 0.0f)); /* the flight bobs */
        const float rad = zoom * 1.1f * S;
        const ak_vec3 eye = ak_vec3_make(rad * cosf(a), (float)mean + elev, rad * sinf(a));
        const ak_raster_camera cam = ak_raster_camera_perspective(eye, target, 0.75f, (float)w / (float)h,
                                                                  0.01f * S, 10.0f * zoom * S);
        ak_raster_clear(r, ak_vec4_make(0.58f, 0.72f, 0.90f, 1), ak_vec4_make(0.86f, 0.90f, 0.95f, 1));
        res = ak_raster_draw_mesh(r, &cam, &mesh);
        if (res == AK_OK) res = ak_raster_resolve(r, &img);
        if (res == AK_OK) res = gif ? ak_gif_writer_add_frame(gw, &img) : ak_png_write(path, &img);
        if (res != AK_OK) rc = cli_fail("terrain", "%s: %s", path, ak_result_string(res));
        cli_progress(gif ? "render" : "render", (size_t)f + 1, (size_t)frames);
    }
done:
    if (gw && rc != CLI_OK) ak_gif_writer_discard(gw); /* a failed run leaves no partial GIF */
    else if (gw) {
        res = ak_gif_writer_finish(gw);
        if (res != AK_OK) rc = cli_fail("terrain", "%s: %s", path, ak_result_string(res));
    }
    ak_raster_destroy(r);
    free(pos), free(col), free(idx), free(px);
    return rc;
}

/* Images are at most 960 pixels wide: grids above 513 samples are rendered from every k-th
 * sample (the same world rectangle; heights and normals copied, not resampled). */
static int render_decimated(const terrain_data* t, const char* path, bool gif) {
    const ak_terrain_desc* d = &t->desc;
    const uint32_t side = d->width > d->height ? d->width : d->height;
    const uint32_t k = side > 513 ? (side - 1 + 511) / 512 : 1;
    if (k == 1) return render_frames(t, path, gif);
    terrain_data s = *t;
    s.desc.width = (d->width - 1) / k + 1;
    s.desc.height = (d->height - 1) / k + 1;
    s.desc.world_size = d->world_size / (float)(d->width - 1) * (float)(k * (s.desc.width - 1));
    s.count = (size_t)s.desc.width * s.desc.height;
    s.heights = malloc(s.count * sizeof *s.heights);
    s.normals = malloc(s.count * sizeof *s.normals);
    int rc;
    if (!s.heights || !s.normals) {
        rc = cli_fail("terrain", "out of memory for a %ux%u render", s.desc.width, s.desc.height);
    } else {
        for (uint32_t j = 0; j < s.desc.height; ++j)
            for (uint32_t i = 0; i < s.desc.width; ++i) {
                const size_t from = (size_t)j * k * d->width + (size_t)i * k;
                s.heights[(size_t)j * s.desc.width + i] = t->heights[from];
                s.normals[(size_t)j * s.desc.width + i] = t->normals[from];
            }
        rc = render_frames(&s, path, gif);
    }
    free(s.heights), free(s.normals);
    return rc;
}

int cmd_terrain(int argc, char** argv) {
    static const cli_opt opts[] = {
        {"--size", NULL, true},   {"--world", NULL, true},   {"--height", NULL, true},     {"--noise", NULL, true},
        {"--octaves", NULL, true}, {"--lacunarity", NULL, true}, {"--gain", NULL, true},   {"--type", NULL, true},
        {"--seed", NULL, true},   {"--erode", NULL, true},   {"--output", "-o", true},     {"--render", NULL, false},
    };
    cli_args a;
    int rc = cli_parse("terrain", argc, argv, opts, sizeof opts / sizeof opts[0], &a);
    if (rc) return rc;
    if (a.help) {
        fputs(usage, stdout);
        return CLI_OK;
    }
    if (a.pos_count) return cli_usage("terrain", "unexpected argument '%s'", a.pos[0]);
    const char* out = CLI_GET(&a, "--output");
    if (!out) return cli_usage("terrain", "missing -o OUT.obj|OUT.png|OUT.gif");
    const bool obj = cli_has_ext(out, ".obj"), png = cli_has_ext(out, ".png"), gif = cli_has_ext(out, ".gif");
    if (!obj && !png && !gif) return cli_usage("terrain", "-o '%s': the name must end in .obj, .png or .gif", out);
    const bool render = CLI_GET(&a, "--render") != NULL;
    if (render && obj) /* a .gif is always a rendered turntable: --render changes nothing there */
        return cli_usage("terrain", "--render makes an image: -o OUT.png for a still, OUT.gif for a turntable");

    terrain_data t = {.desc = {.width = 257, .height = 257, .world_size = 100, .height_scale = 20,
                               .fractal = {.type = AK_FRACTAL_FBM, .octaves = 8}, .thread_count = 2}};
    ak_terrain_desc* d = &t.desc;
    const char* s;
    if ((s = CLI_GET(&a, "--size")) && !parse_dims(s, &d->width, &d->height))
        return cli_usage("terrain", "--size '%s': allowed WxH with W and H from 2 to 2049", s);
    if ((s = CLI_GET(&a, "--world")) && (!cli_parse_float(s, &d->world_size) || !(d->world_size > 0) || d->world_size > 1e6f))
        return cli_usage("terrain", "--world '%s': allowed range (0, 1000000] metres", s);
    if ((s = CLI_GET(&a, "--height")) &&
        (!cli_parse_float(s, &d->height_scale) || !(d->height_scale > 0) || d->height_scale > 1e6f))
        return cli_usage("terrain", "--height '%s': allowed range (0, 1000000] metres", s);
    if ((s = CLI_GET(&a, "--noise"))) {
        if (strcmp(s, "perlin") == 0) d->fractal.basis = AK_NOISE_BASIS_PERLIN;
        else if (strcmp(s, "simplex") == 0) d->fractal.basis = AK_NOISE_BASIS_SIMPLEX;
        else return cli_usage("terrain", "--noise '%s': allowed perlin, simplex", s);
    }
    long v;
    if ((s = CLI_GET(&a, "--octaves"))) {
        if (!cli_parse_int(s, 1, 16, &v)) return cli_usage("terrain", "--octaves '%s': allowed range 1 to 16", s);
        d->fractal.octaves = (uint32_t)v;
    }
    if ((s = CLI_GET(&a, "--lacunarity")) &&
        (!cli_parse_float(s, &d->fractal.lacunarity) || !(d->fractal.lacunarity > 0) || d->fractal.lacunarity > 16))
        return cli_usage("terrain", "--lacunarity '%s': allowed range (0, 16]", s);
    if ((s = CLI_GET(&a, "--gain")) &&
        (!cli_parse_float(s, &d->fractal.gain) || !(d->fractal.gain > 0) || d->fractal.gain > 2))
        return cli_usage("terrain", "--gain '%s': allowed range (0, 2]", s);
    if ((s = CLI_GET(&a, "--type"))) {
        if (strcmp(s, "fbm") == 0) d->fractal.type = AK_FRACTAL_FBM;
        else if (strcmp(s, "ridged") == 0) d->fractal.type = AK_FRACTAL_RIDGED;
        else if (strcmp(s, "turbulence") == 0) d->fractal.type = AK_FRACTAL_TURBULENCE;
        else return cli_usage("terrain", "--type '%s': allowed fbm, ridged, turbulence", s);
    }
    uint64_t seed = 0;
    if ((s = CLI_GET(&a, "--seed")) && !parse_u64(s, &seed))
        return cli_usage("terrain", "--seed '%s': allowed range 0 to 18446744073709551615", s);
    long droplets = 0;
    if ((s = CLI_GET(&a, "--erode")) && !cli_parse_int(s, 0, 10000000, &droplets))
        return cli_usage("terrain", "--erode '%s': allowed range 0 to 10000000 droplets", s);

    const ak_noise n = ak_noise_make(seed);
    d->noise = &n;
    t.count = (size_t)d->width * d->height;
    t.heights = malloc(t.count * sizeof *t.heights);
    t.normals = malloc(t.count * sizeof *t.normals);
    if (!t.heights || !t.normals) {
        free(t.heights), free(t.normals);
        return cli_fail("terrain", "out of memory for %ux%u samples", d->width, d->height);
    }
    const double t0 = cli_now();
    cli_progress("terrain", 0, 1);
    ak_result res = ak_terrain_generate(d, (ak_f32_span){t.heights, t.count}, (ak_vec3_span){t.normals, t.count});
    cli_progress("terrain", 1, 1);
    if (res == AK_OK && droplets > 0) {
        const ak_terrain_erosion e = {.droplets = (uint32_t)droplets, .thermal_iterations = 20, .seed = seed};
        res = ak_terrain_erode(&e, d, (ak_f32_span){t.heights, t.count}, erode_progress, NULL);
        if (res == AK_OK) res = ak_terrain_normals(d, (ak_f32_cspan){t.heights, t.count}, (ak_vec3_span){t.normals, t.count});
    }
    if (res != AK_OK) {
        free(t.heights), free(t.normals);
        return cli_fail("terrain", "%s", ak_result_string(res));
    }
    float lo = INFINITY, hi = -INFINITY;
    for (size_t i = 0; i < t.count; ++i) lo = fminf(lo, t.heights[i]), hi = fmaxf(hi, t.heights[i]);
    const char* what = "";
    if (obj) {
        res = ak_terrain_write_obj(out, d, (ak_f32_cspan){t.heights, t.count}, (ak_vec3_cspan){t.normals, t.count});
        what = "OBJ mesh";
        rc = res == AK_OK ? CLI_OK : cli_fail("terrain", "%s: %s", out, ak_result_string(res));
    } else if (png && !render) {
        res = ak_terrain_write_png16(out, d, (ak_f32_cspan){t.heights, t.count}, lo, hi);
        what = "16-bit heightmap";
        rc = res == AK_OK ? CLI_OK : cli_fail("terrain", "%s: %s", out, ak_result_string(res));
    } else {
        what = gif ? "turntable GIF" : "shaded render";
        rc = render_decimated(&t, out, gif);
    }
    if (rc == CLI_OK) { /* the summary on stdout, the file announced as every command does */
        printf("terrain %ux%u, %g m wide, heights [%.3f, %.3f] m, %ld droplet%s, in %.2f s\n", d->width, d->height,
               (double)d->world_size, (double)lo, (double)hi, droplets, droplets == 1 ? "" : "s", cli_now() - t0);
        cli_wrote(out, "%s", what);
    }
    free(t.heights), free(t.normals);
    return rc;
}

/* Tests for animkit terrain: heights equal the fractal, analytic normals match the mesh's face
 * and vertex normals, results independent of threads, 16-bit PNG read back with libpng's
 * classic reader, OBJ structure, erosion properties, colours by height and slope. */
#include <png.h>
#include <stdlib.h>
#include <string.h>

#include <animkit/mesh.h>
#include <animkit/terrain.h>

#include "ak_test.h"

static const ak_noise* test_noise(void) {
    static ak_noise n;
    static int made = 0;
    if (!made) n = ak_noise_make(5), made = 1;
    return &n;
}

AK_TEST(desc_validity) {
    ak_terrain_desc d = {.noise = test_noise()};
    AK_CHECK_EQ(ak_terrain_desc_validate(&d), AK_OK);
    AK_CHECK_EQ(ak_terrain_desc_validate(&(ak_terrain_desc){0}), AK_ERR_NULL_ARG);
    AK_CHECK_EQ(ak_terrain_desc_validate(NULL), AK_ERR_NULL_ARG);
    ak_terrain_desc b = d;
    b.width = 1;
    AK_CHECK_EQ(ak_terrain_desc_validate(&b), AK_ERR_BAD_ARG);
    b = d, b.height = 16385;
    AK_CHECK_EQ(ak_terrain_desc_validate(&b), AK_ERR_BAD_ARG);
    b = d, b.world_size = -1;
    AK_CHECK_EQ(ak_terrain_desc_validate(&b), AK_ERR_BAD_ARG);
    b = d, b.height_scale = NAN;
    AK_CHECK_EQ(ak_terrain_desc_validate(&b), AK_ERR_BAD_ARG);
    b = d, b.feature_size = INFINITY;
    AK_CHECK_EQ(ak_terrain_desc_validate(&b), AK_ERR_BAD_ARG);
    b = d, b.thread_count = 65;
    AK_CHECK_EQ(ak_terrain_desc_validate(&b), AK_ERR_BAD_ARG);
    b = d, b.fractal.octaves = 40;
    AK_CHECK_EQ(ak_terrain_desc_validate(&b), AK_ERR_BAD_ARG);
    ak_terrain_desc r = ak_terrain_desc_resolved(&d);
    AK_CHECK(r.width == 257 && r.height == 257 && r.world_size == 100.0f && r.height_scale == 20.0f &&
             r.feature_size == 25.0f);
    float h[4];
    b = d, b.width = 2, b.height = 3;
    AK_CHECK_EQ(ak_terrain_generate(&b, (ak_f32_span){h, 4}, (ak_vec3_span){0}), AK_ERR_SPAN_SMALL);
    AK_CHECK_EQ(ak_terrain_generate(&b, (ak_f32_span){0}, (ak_vec3_span){0}), AK_ERR_NULL_ARG);
    AK_CHECK_EQ(ak_terrain_index_count(&b), 12);
}

/* The heights are height_scale * F(p / feature) / hi, F evaluated independently per point. */
AK_TEST(heights_equal_the_fractal) {
    ak_terrain_desc d = {.noise = test_noise(), .width = 33, .height = 17, .world_size = 40, .height_scale = 8,
                         .fractal = {.type = AK_FRACTAL_RIDGED, .octaves = 5}};
    float h[33 * 17];
    AK_CHECK_EQ(ak_terrain_generate(&d, (ak_f32_span){h, 33 * 17}, (ak_vec3_span){0}), AK_OK);
    float lo, hi;
    ak_fractal_range(&d.fractal, 2, &lo, &hi);
    const float feature = 10.0f, cell = 40.0f / 32.0f;
    for (uint32_t j = 0; j < 17; ++j)
        for (uint32_t i = 0; i < 33; ++i) {
            const float p[2] = {(-20.0f + (float)i * cell) / feature, (-8.0f * cell + (float)j * cell) / feature};
            const double want = 8.0 * ak_fractal_eval(test_noise(), &d.fractal, 2, p, NULL) / hi;
            AK_CHECK_NEAR(h[j * 33 + i], want, 1e-4);
            const ak_vec3 s = ak_terrain_sample_position(&d, i, j, 1.0f);
            AK_CHECK_NEAR(s.x, -20.0f + (float)i * cell, 1e-5);
            AK_CHECK_NEAR(s.z, -10.0f + (float)j * cell, 1e-5);
        }
}

/* Analytic normals against the mesh at a resolution: the worst angle (degrees) between each
 * triangle's face normal (cross product of its edges) and the mean analytic normal of its
 * corners, and between ak_normals_compute's area-weighted vertex normals and the analytic
 * ones at interior vertices. Faces must point up (+y): counter-clockwise winding. */
static void normal_errors(uint32_t w, uint32_t h, double* worst_face, double* worst_vertex, double* mean_tilt) {
    ak_terrain_desc d = {.noise = test_noise(), .width = w, .height = h, .world_size = 20, .height_scale = 3,
                         .feature_size = 8, .fractal = {.octaves = 3}, .thread_count = 2};
    const size_t n = (size_t)w * h, ni = ak_terrain_index_count(&d);
    float* hm = malloc(n * sizeof *hm);
    ak_vec3 *nrm = malloc(n * sizeof *nrm), *pos = malloc(n * sizeof *pos), *vn = malloc(n * sizeof *vn);
    ak_vec3* fdn = malloc(n * sizeof *fdn);
    uint32_t* idx = malloc(ni * sizeof *idx);
    AK_CHECK_EQ(ak_terrain_generate(&d, (ak_f32_span){hm, n}, (ak_vec3_span){nrm, n}), AK_OK);
    AK_CHECK_EQ(ak_terrain_mesh(&d, (ak_f32_cspan){hm, n}, (ak_vec3_span){pos, n}, (ak_vec2_span){0},
                                (ak_u32_span){idx, ni}),
                AK_OK);
    *worst_face = *worst_vertex = *mean_tilt = 0;
    for (size_t t = 0; t < ni / 3; ++t) {
        const uint32_t a = idx[3 * t], b = idx[3 * t + 1], c = idx[3 * t + 2];
        const ak_vec3 fn = ak_vec3_normalize(ak_vec3_cross(ak_vec3_sub(pos[b], pos[a]), ak_vec3_sub(pos[c], pos[a])));
        AK_CHECK(fn.y > 0.0f);
        const ak_vec3 an = ak_vec3_normalize(ak_vec3_add(ak_vec3_add(nrm[a], nrm[b]), nrm[c]));
        *worst_face = fmax(*worst_face, acos(fmin(1.0, (double)ak_vec3_dot(fn, an))) * 180.0 / 3.14159265358979);
    }
    AK_CHECK_EQ(ak_normals_compute((ak_vec3_cspan){pos, n}, (ak_u32_cspan){idx, ni}, (ak_vec3_span){vn, n}), AK_OK);
    for (uint32_t j = 1; j + 1 < h; ++j)
        for (uint32_t i = 1; i + 1 < w; ++i) {
            const size_t a = (size_t)j * w + i;
            *worst_vertex = fmax(*worst_vertex, acos(fmin(1.0, (double)ak_vec3_dot(vn[a], nrm[a]))) * 180.0 / 3.14159265358979);
            *mean_tilt += acos(fmin(1.0, (double)nrm[a].y)) * 180.0 / 3.14159265358979;
        }
    *mean_tilt /= (double)(w - 2) * (h - 2);
    /* ak_terrain_normals (finite differences of the heights) agree with the analytic ones */
    AK_CHECK_EQ(ak_terrain_normals(&d, (ak_f32_cspan){hm, n}, (ak_vec3_span){fdn, n}), AK_OK);
    double worst_fd = 0;
    for (uint32_t j = 1; j + 1 < h; ++j)
        for (uint32_t i = 1; i + 1 < w; ++i) {
            const size_t a = (size_t)j * w + i;
            worst_fd = fmax(worst_fd, acos(fmin(1.0, (double)ak_vec3_dot(fdn[a], nrm[a]))) * 180.0 / 3.14159265358979);
        }
    AK_CHECK(worst_fd < 2.0 * *worst_vertex + 0.05);
    free(hm), free(nrm), free(pos), free(vn), free(fdn), free(idx);
}

/* The mesh converges to the analytic surface: halving the cell size shrinks the face-normal
 * error about 2x (first order) and the vertex-normal error about 4x (second order). A wrong
 * derivative scale or sign would not converge. */
AK_TEST(normals_match_mesh) {
    double f[3], v[3], tilt;
    const uint32_t sizes[3] = {65, 129, 257};
    for (int r = 0; r < 3; ++r) {
        normal_errors(sizes[r], (sizes[r] - 1) * 3 / 4 + 1, &f[r], &v[r], &tilt);
        printf("  %3ux%-3u worst face-normal angle %.3f deg, vertex-normal angle %.4f deg (mean tilt %.1f deg)\n",
               sizes[r], (sizes[r] - 1) * 3 / 4 + 1, f[r], v[r], tilt);
        AK_CHECK(tilt > 5.0); /* a real slope, so the comparison means something */
    }
    AK_CHECK(f[2] < 2.0 && v[2] < 0.35);
    AK_CHECK(f[1] / f[2] > 1.6 && f[0] / f[1] > 1.6);
    AK_CHECK(v[1] / v[2] > 3.0 && v[0] / v[1] > 3.0);
}

AK_TEST(threads_and_simd_give_same_results) {
    enum { W = 150, H = 61 };
    static float h[3][W * H];
    static ak_vec3 n[3][W * H];
    for (int r = 0; r < 3; ++r) {
        ak_terrain_desc d = {.noise = test_noise(), .width = W, .height = H, .fractal = {.octaves = 7},
                             .thread_count = (uint32_t)(r == 1 ? 3 : 1), .skip_simd = r == 2};
        AK_CHECK_EQ(ak_terrain_generate(&d, (ak_f32_span){h[r], W * H}, (ak_vec3_span){n[r], W * H}), AK_OK);
    }
    AK_CHECK(memcmp(h[0], h[1], sizeof h[0]) == 0 && memcmp(n[0], n[1], sizeof n[0]) == 0);
    AK_CHECK(memcmp(h[0], h[2], sizeof h[0]) == 0 && memcmp(n[0], n[2], sizeof n[0]) == 0);
}

/* Read a 16-bit greyscale PNG with libpng's classic API (not the writer's code path). */
static int read_png16(const char* path, uint32_t* w, uint32_t* h, uint16_t* out, size_t cap) {
    FILE* f = fopen(path, "rb");
    if (!f) return 0;
    png_structp png = png_create_read_struct(PNG_LIBPNG_VER_STRING, NULL, NULL, NULL);
    png_infop info = png_create_info_struct(png);
    if (setjmp(png_jmpbuf(png))) {
        png_destroy_read_struct(&png, &info, NULL);
        fclose(f);
        return 0;
    }
    png_init_io(png, f);
    png_read_info(png, info);
    *w = png_get_image_width(png, info);
    *h = png_get_image_height(png, info);
    int ok = png_get_bit_depth(png, info) == 16 && png_get_color_type(png, info) == PNG_COLOR_TYPE_GRAY &&
             (size_t)*w * *h <= cap;
    if (ok) {
        uint8_t row[2 * 1024];
        for (uint32_t j = 0; j < *h; ++j) {
            png_read_row(png, row, NULL);
            for (uint32_t i = 0; i < *w; ++i) out[(size_t)j * *w + i] = (uint16_t)(row[2 * i] << 8 | row[2 * i + 1]);
        }
    }
    png_destroy_read_struct(&png, &info, NULL);
    fclose(f);
    return ok;
}

AK_TEST(png16_reads_back) {
    enum { W = 70, H = 45 };
    static float h[W * H];
    static uint16_t px[W * H];
    ak_terrain_desc d = {.noise = test_noise(), .width = W, .height = H, .fractal = {.octaves = 6}};
    AK_CHECK_EQ(ak_terrain_generate(&d, (ak_f32_span){h, W * H}, (ak_vec3_span){0}), AK_OK);
    const char* path = "test_terrain_height.png";
    AK_CHECK_EQ(ak_terrain_write_png16(path, &d, (ak_f32_cspan){h, W * H}, 0, 0), AK_OK);
    uint32_t w = 0, hh = 0;
    AK_CHECK(read_png16(path, &w, &hh, px, W * H));
    AK_CHECK(w == W && hh == H);
    double lo = INFINITY, hi = -INFINITY;
    for (int i = 0; i < W * H; ++i) lo = fmin(lo, h[i]), hi = fmax(hi, h[i]);
    int mismatches = 0;
    for (int i = 0; i < W * H; ++i) {
        const double back = lo + (hi - lo) * px[i] / 65535.0;
        AK_CHECK_NEAR(back, h[i], (hi - lo) / 65535.0 * 0.5 + 1e-5 * (hi - lo));
        mismatches += abs((int)px[i] - (int)lround((h[i] - lo) / (hi - lo) * 65535.0)) > 0;
    }
    AK_CHECK(mismatches <= W * H / 1000); /* float vs double rounding at a .5 boundary only */
    AK_CHECK(px[0] != px[1]);
    /* explicit range: clamped */
    AK_CHECK_EQ(ak_terrain_write_png16(path, &d, (ak_f32_cspan){h, W * H}, 0.0f, 0.001f), AK_OK);
    AK_CHECK(read_png16(path, &w, &hh, px, W * H));
    for (int i = 0; i < W * H; ++i) AK_CHECK(px[i] == (h[i] <= 0.0f ? 0 : h[i] >= 0.001f ? 65535 : px[i]));
    AK_CHECK_EQ(ak_terrain_write_png16(path, &d, (ak_f32_cspan){h, W * H}, 1.0f, 0.0f), AK_ERR_BAD_ARG);
    AK_CHECK_EQ(ak_terrain_write_png16("/nonexistent-dir/x.png", &d, (ak_f32_cspan){h, W * H}, 0, 0), AK_ERR_IO);
    remove(path);
}

AK_TEST(obj_structure) {
    enum { W = 9, H = 5 };
    float h[W * H];
    ak_vec3 n[W * H];
    ak_terrain_desc d = {.noise = test_noise(), .width = W, .height = H, .world_size = 8};
    AK_CHECK_EQ(ak_terrain_generate(&d, (ak_f32_span){h, W * H}, (ak_vec3_span){n, W * H}), AK_OK);
    const char* path = "test_terrain.obj";
    AK_CHECK_EQ(ak_terrain_write_obj(path, &d, (ak_f32_cspan){h, W * H}, (ak_vec3_cspan){n, W * H}), AK_OK);
    FILE* f = fopen(path, "r");
    AK_CHECK(f != NULL);
    if (!f) return;
    char line[256];
    int v = 0, vt = 0, vn = 0, faces = 0;
    float y4 = 0;
    while (fgets(line, sizeof line, f)) {
        if (strncmp(line, "v ", 2) == 0) {
            float x, y, z;
            if (sscanf(line + 2, "%f %f %f", &x, &y, &z) == 3 && v == 4) y4 = y;
            ++v;
        }
        vt += strncmp(line, "vt ", 3) == 0;
        vn += strncmp(line, "vn ", 3) == 0;
        if (strncmp(line, "f ", 2) == 0) {
            unsigned a[9];
            AK_CHECK(sscanf(line + 2, "%u/%u/%u %u/%u/%u %u/%u/%u", &a[0], &a[1], &a[2], &a[3], &a[4], &a[5], &a[6],
                            &a[7], &a[8]) == 9);
            for (int k = 0; k < 9; ++k) AK_CHECK(a[k] >= 1 && a[k] <= W * H);
            ++faces;
        }
    }
    fclose(f);
    remove(path);
    AK_CHECK(v == W * H && vt == W * H && vn == W * H && faces == (W - 1) * (H - 1) * 2);
    AK_CHECK_NEAR(y4, h[4], 1e-5);
}

static double sum_of(const float* h, size_t n) {
    double s = 0;
    for (size_t i = 0; i < n; ++i) s += h[i];
    return s;
}

static void count_progress(size_t done, size_t total, void* user) {
    size_t* calls = (size_t*)user;
    calls[0]++;
    calls[1] = done == total;
}

AK_TEST(erosion_properties) {
    enum { W = 96, H = 96 };
    static float h0[W * H], h1[W * H], h2[W * H];
    ak_terrain_desc d = {.noise = test_noise(), .width = W, .height = H, .world_size = 50,
                         .fractal = {.type = AK_FRACTAL_RIDGED, .octaves = 6}};
    AK_CHECK_EQ(ak_terrain_generate(&d, (ak_f32_span){h0, W * H}, (ak_vec3_span){0}), AK_OK);
    memcpy(h1, h0, sizeof h0);
    memcpy(h2, h0, sizeof h0);
    const ak_terrain_erosion e = {.droplets = 4000, .seed = 3};
    size_t calls[2] = {0, 0};
    AK_CHECK_EQ(ak_terrain_erode(&e, &d, (ak_f32_span){h1, W * H}, count_progress, calls), AK_OK);
    AK_CHECK(calls[0] >= 2 && calls[1] == 1);
    AK_CHECK_EQ(ak_terrain_erode(&e, &d, (ak_f32_span){h2, W * H}, NULL, NULL), AK_OK);
    AK_CHECK(memcmp(h1, h2, sizeof h1) == 0); /* deterministic from the seed */
    double changed = 0;
    for (int i = 0; i < W * H; ++i) {
        AK_CHECK(isfinite(h1[i]));
        changed += fabs(h1[i] - h0[i]);
    }
    AK_CHECK(changed > 1.0);
    /* droplets start with no sediment: they only carry material off, never create it */
    AK_CHECK(sum_of(h1, W * H) <= sum_of(h0, W * H) + 1e-3);

    /* thermal: conserves material, and the steepest neighbour difference does not grow */
    memcpy(h2, h0, sizeof h0);
    AK_CHECK_EQ(ak_terrain_erode(&(ak_terrain_erosion){.thermal_iterations = 50}, &d, (ak_f32_span){h2, W * H}, NULL,
                                 NULL),
                AK_OK);
    AK_CHECK_NEAR(sum_of(h2, W * H), sum_of(h0, W * H), 1e-2);
    float steep0 = 0, steep2 = 0;
    for (int j = 0; j < H; ++j)
        for (int i = 0; i + 1 < W; ++i) {
            steep0 = fmaxf(steep0, fabsf(h0[j * W + i + 1] - h0[j * W + i]));
            steep2 = fmaxf(steep2, fabsf(h2[j * W + i + 1] - h2[j * W + i]));
        }
    AK_CHECK(steep2 < steep0);

    h2[17] = NAN;
    memcpy(h1, h2, sizeof h2);
    AK_CHECK_EQ(ak_terrain_erode(&e, &d, (ak_f32_span){h2, W * H}, NULL, NULL), AK_ERR_BAD_DATA);
    AK_CHECK(memcmp(h1, h2, sizeof h1) == 0);
    AK_CHECK_EQ(ak_terrain_erode(&(ak_terrain_erosion){.inertia = 2}, &d, (ak_f32_span){h1, W * H}, NULL, NULL),
                AK_ERR_BAD_ARG);
    AK_CHECK_EQ(ak_terrain_erode(&(ak_terrain_erosion){.radius = 9}, &d, (ak_f32_span){h1, W * H}, NULL, NULL),
                AK_ERR_BAD_ARG);
    AK_CHECK_EQ(ak_terrain_erode(&e, &d, (ak_f32_span){h1, 10}, NULL, NULL), AK_ERR_SPAN_SMALL);
}

AK_TEST(colors_by_height_and_slope) {
    ak_terrain_desc d = {.noise = test_noise(), .width = 2, .height = 2, .height_scale = 10};
    /* fbm: heights span [-10, 10] */
    const float h[4] = {-10.0f, 9.5f, 9.5f, 0.0f};
    const ak_vec3 flat = ak_vec3_make(0, 1, 0), steep = ak_vec3_normalize(ak_vec3_make(1, 0.4f, 0));
    const ak_vec3 n[4] = {flat, flat, steep, steep};
    ak_vec4 c[4];
    AK_CHECK_EQ(ak_terrain_colors(&d, (ak_f32_cspan){h, 4}, (ak_vec3_cspan){n, 4}, (ak_vec4_span){c, 4}), AK_OK);
    AK_CHECK(c[0].x > c[0].z && c[0].x > 0.7f);                    /* sand: warm, bright */
    AK_CHECK(c[1].x > 0.9f && c[1].y > 0.9f && c[1].z > 0.9f);     /* snow */
    AK_CHECK(fabsf(c[2].x - c[2].y) < 0.06f && c[2].x < 0.6f);     /* rock: grey */
    AK_CHECK(fabsf(c[3].x - c[3].y) < 0.06f);
    for (int i = 0; i < 4; ++i) AK_CHECK(c[i].w == 1.0f && c[i].x >= 0 && c[i].x <= 1);
    AK_CHECK_EQ(ak_terrain_colors(&d, (ak_f32_cspan){h, 3}, (ak_vec3_cspan){n, 4}, (ak_vec4_span){c, 4}),
                AK_ERR_SPAN_SMALL);
}

int main(void) {
    AK_RUN(desc_validity);
    AK_RUN(heights_equal_the_fractal);
    AK_RUN(normals_match_mesh);
    AK_RUN(threads_and_simd_give_same_results);
    AK_RUN(png16_reads_back);
    AK_RUN(obj_structure);
    AK_RUN(erosion_properties);
    AK_RUN(colors_by_height_and_slope);
    return ak_test_finish();
}

/* Tests for the view helpers. Oracles: projection of the box corners computed here in double,
 * the documented heatmap endpoints and panel layout arithmetic, linearity of the plot mapping
 * and the colours found at mapped pixels, and decoding the GIF written. */
#include <animkit/view.h>

#include "ak_test.h"

/* Project a world point through a camera in double: pixel x, y and whether it is in front. */
static bool project_d(const ak_raster_camera* cam, int w, int h, ak_vec3 p, double* x, double* y) {
    double v[4], c[4];
    for (int r = 0; r < 4; ++r)
        v[r] = (double)cam->view.m[r] * p.x + (double)cam->view.m[4 + r] * p.y + (double)cam->view.m[8 + r] * p.z +
               cam->view.m[12 + r];
    for (int r = 0; r < 4; ++r)
        c[r] = (double)cam->projection.m[r] * v[0] + (double)cam->projection.m[4 + r] * v[1] +
               (double)cam->projection.m[8 + r] * v[2] + (double)cam->projection.m[12 + r] * v[3];
    if (!(c[3] > 0) || c[2] < -c[3] || c[2] > c[3]) return false;
    *x = (c[0] / c[3] * 0.5 + 0.5) * w;
    *y = (0.5 - c[1] / c[3] * 0.5) * h;
    return true;
}

AK_TEST(orbit_framing_keeps_box_inside) {
    ak_rng rng = ak_rng_make(11);
    for (int it = 0; it < 300; ++it) {
        ak_vec3 c = ak_vec3_make(ak_rng_range(&rng, -50, 50), ak_rng_range(&rng, -5, 5), ak_rng_range(&rng, -50, 50));
        ak_vec3 half = ak_vec3_make(ak_rng_range(&rng, 0.01f, 3), ak_rng_range(&rng, 0.01f, 3), ak_rng_range(&rng, 0.01f, 3));
        if (it % 2 == 0) half = ak_vec3_splat(half.x); /* cubes: also check the framing is tight */
        ak_vec3 lo = ak_vec3_sub(c, half), hi = ak_vec3_add(c, half);
        int W = 100 + (int)(ak_rng_float(&rng) * 600), H = 100 + (int)(ak_rng_float(&rng) * 400);
        ak_view_orbit o = {.azimuth = ak_rng_range(&rng, -7, 7), .elevation = ak_rng_range(&rng, -1.5f, 1.5f),
                           .aspect = (float)W / (float)H, .orthographic = it % 5 == 0,
                           .fovy = it % 3 == 0 ? 0.0f : ak_rng_range(&rng, 0.3f, 1.5f)};
        ak_raster_camera cam = ak_view_orbit_camera(lo, hi, &o);
        double minx = 1e9, maxx = -1e9, miny = 1e9, maxy = -1e9;
        for (int k = 0; k < 8; ++k) {
            ak_vec3 p = ak_vec3_make(k & 1 ? hi.x : lo.x, k & 2 ? hi.y : lo.y, k & 4 ? hi.z : lo.z);
            double x, y;
            bool ok = project_d(&cam, W, H, p, &x, &y);
            AK_CHECK_MSG(ok, "iteration %d corner %d behind the camera or clipped", it, k);
            if (!ok) continue;
            minx = fmin(minx, x), maxx = fmax(maxx, x), miny = fmin(miny, y), maxy = fmax(maxy, y);
        }
        AK_CHECK_MSG(minx >= 0 && maxx <= W && miny >= 0 && maxy <= H,
                     "iteration %d: box spans x %.1f..%.1f y %.1f..%.1f of %dx%d", it, minx, maxx, miny, maxy, W, H);
        /* and a cube is framed, not lost in the distance */
        if (it % 2 == 0) AK_CHECK(fmax((maxx - minx) / W, (maxy - miny) / H) > 0.3);
    }
    /* bad bounds fall back to a finite camera */
    ak_raster_camera bad = ak_view_orbit_camera(ak_vec3_make(NAN, 0, 0), ak_vec3_one(), NULL);
    AK_CHECK(ak_mat4_is_finite(&bad.view) && ak_mat4_is_finite(&bad.projection));
}

AK_TEST(heatmap_endpoints_and_mapping) {
    ak_vec4 lo = ak_view_heatmap_color(0.0f), hi = ak_view_heatmap_color(1.0f), mid = ak_view_heatmap_color(0.5f);
    AK_CHECK(lo.z > 0.8f && lo.x < 0.2f); /* blue */
    AK_CHECK(hi.x > 0.8f && hi.z < 0.2f); /* red */
    AK_CHECK(mid.y > mid.x && mid.y > mid.z); /* green in the middle */
    AK_CHECK_NEAR(lo.w, 1.0f, 0);
    ak_vec4 n = ak_view_heatmap_color(NAN), under = ak_view_heatmap_color(-3), over = ak_view_heatmap_color(7);
    AK_CHECK(memcmp(&n, &lo, sizeof lo) == 0 && memcmp(&under, &lo, sizeof lo) == 0);
    AK_CHECK(memcmp(&over, &hi, sizeof hi) == 0);
    float v[3] = {2.0f, 4.0f, 3.0f};
    ak_vec4 out[3];
    AK_CHECK_EQ(ak_view_heatmap_colors((ak_f32_cspan){v, 3}, 2.0f, 4.0f, (ak_vec4_span){out, 3}), AK_OK);
    AK_CHECK(memcmp(&out[0], &lo, sizeof lo) == 0 && memcmp(&out[1], &hi, sizeof hi) == 0);
    AK_CHECK(memcmp(&out[2], &mid, sizeof mid) == 0);
    AK_CHECK_EQ(ak_view_heatmap_colors((ak_f32_cspan){v, 3}, 0, 1, (ak_vec4_span){out, 2}), AK_ERR_SPAN_SMALL);
    AK_CHECK_EQ(ak_view_heatmap_colors((ak_f32_cspan){v, 3}, NAN, 1, (ak_vec4_span){out, 3}), AK_ERR_BAD_ARG);
    AK_CHECK_EQ(ak_view_heatmap_colors((ak_f32_cspan){NULL, 3}, 0, 1, (ak_vec4_span){out, 3}), AK_ERR_NULL_ARG);
}

AK_TEST(joint_weights_from_mesh) {
    uint16_t joints[6] = {0, 2, 1, 2, 2, 2};
    float weights[6] = {0.25f, 0.75f, 1.0f, 0.0f, 0.5f, 0.5f};
    ak_vec3 pos[3] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
    ak_mesh m;
    memset(&m, 0, sizeof m);
    m.vertex_count = 3;
    m.influence_count = 2;
    m.positions = pos;
    m.joints = joints;
    m.weights = weights;
    float w[3];
    AK_CHECK_EQ(ak_view_joint_weights(&m, 2, (ak_f32_span){w, 3}), AK_OK);
    AK_CHECK_NEAR(w[0], 0.75f, 0);
    AK_CHECK_NEAR(w[1], 0.0f, 0);
    AK_CHECK_NEAR(w[2], 1.0f, 0); /* duplicate slots add up */
    AK_CHECK_EQ(ak_view_joint_weights(&m, 2, (ak_f32_span){w, 2}), AK_ERR_SPAN_SMALL);
    AK_CHECK_EQ(ak_view_joint_weights(NULL, 2, (ak_f32_span){w, 3}), AK_ERR_NULL_ARG);
    ak_raster_mesh rm = ak_view_raster_mesh(&m);
    AK_CHECK(rm.positions.ptr == pos && rm.positions.count == 3 && rm.indices.count == 0);
}

AK_TEST(panels_sizes_and_placement) {
    enum { PW = 100, PH = 80 };
    static uint8_t px[3][PW * PH * 4];
    ak_image img[3];
    ak_view_panel panels[3];
    const char* labels[3] = {"LBS", "DQS", "CoR"};
    for (int i = 0; i < 3; ++i) {
        img[i] = (ak_image){.pixels = px[i], .width = PW, .height = PH};
        ak_image_fill(&img[i], ak_vec4_make(0.2f * (float)i, 0.5f, 1.0f - 0.3f * (float)i, 1));
        panels[i] = (ak_view_panel){.image = &img[i], .label = labels[i]};
    }
    int W, H;
    ak_view_panels_size(NULL, 3, PW, PH, &W, &H);
    const int gap = 6, label_h = 2 * AK_FONT_GLYPH_HEIGHT + 8;
    AK_CHECK_EQ(W, 3 * PW + 4 * gap);
    AK_CHECK_EQ(H, label_h + PH + 2 * gap);
    ak_view_panels_desc two = {.columns = 2, .title = "title"};
    int W2, H2;
    ak_view_panels_size(&two, 3, PW, PH, &W2, &H2);
    AK_CHECK_EQ(W2, 2 * PW + 3 * gap);
    AK_CHECK_EQ(H2, (3 * AK_FONT_GLYPH_HEIGHT + 12) + 2 * (label_h + PH) + 3 * gap);
    uint8_t* out = (uint8_t*)malloc((size_t)W * H * 4);
    ak_image o = {.pixels = out, .width = W, .height = H};
    AK_CHECK_EQ(ak_view_panels_compose(NULL, panels, 3, &o), AK_OK);
    /* panel i's pixels sit at x = gap + i*(PW+gap), y = gap + label_h */
    for (int i = 0; i < 3; ++i) {
        int x = gap + i * (PW + gap) + PW / 2, y = gap + label_h + PH / 2;
        AK_CHECK(memcmp(ak_image_pixel(&o, x, y), ak_image_pixel(&img[i], PW / 2, PH / 2), 4) == 0);
        /* the label strip above has some text ink (bright pixels on the dark background) */
        int ink = 0;
        for (int yy = gap; yy < gap + label_h; ++yy)
            for (int xx = gap + i * (PW + gap); xx < gap + i * (PW + gap) + PW; ++xx) ink += ak_image_pixel(&o, xx, yy)[0] > 200;
        AK_CHECK(ink > 10);
    }
    ak_image wrong = {.pixels = out, .width = W - 1, .height = H};
    AK_CHECK_EQ(ak_view_panels_compose(NULL, panels, 3, &wrong), AK_ERR_BAD_ARG);
    AK_CHECK_EQ(ak_view_panels_compose(NULL, panels, 0, &o), AK_ERR_EMPTY);
    ak_image other = {.pixels = px[2], .width = PW / 2, .height = PH};
    panels[2].image = &other;
    AK_CHECK_EQ(ak_view_panels_compose(NULL, panels, 3, &o), AK_ERR_BAD_ARG);
    free(out);
}

AK_TEST(plot_draws_at_mapped_pixels) {
    enum { W = 400, H = 260, N = 101 };
    static uint8_t px[W * H * 4];
    ak_image img = {.pixels = px, .width = W, .height = H};
    float x[N], y[N];
    for (int i = 0; i < N; ++i) {
        x[i] = 0.1f * (float)i;
        y[i] = 1.0f;
    }
    float kx[2] = {2.0f, 8.0f}, ky[2] = {0.5f, 1.5f}, ks[2] = {0.0f, 0.0f};
    ak_view_series s[2] = {
        {.x = {x, N}, .y = {y, N}, .color = {1, 0, 0, 1}, .label = "flat", .width = 3},
        {.key_x = {kx, 2}, .key_y = {ky, 2}, .key_in_slope = {ks, 2}, .key_out_slope = {ks, 2},
         .color = {0, 0.6f, 0, 1}, .label = "keys"},
    };
    ak_view_plot plot = {.series = s, .series_count = 2, .title = "plot", .x_label = "time (s)", .y_label = "value",
                         .x_min = 0, .x_max = 10, .y_min = 0, .y_max = 2};
    AK_CHECK_EQ(ak_view_plot_draw(&plot, &img), AK_OK);
    ak_vec2 p00, p11, pm, pk, pq;
    AK_CHECK(ak_view_plot_map(&plot, W, H, 0, 0, &p00));
    AK_CHECK(ak_view_plot_map(&plot, W, H, 10, 2, &p11));
    AK_CHECK(ak_view_plot_map(&plot, W, H, 5, 1, &pm));
    AK_CHECK(ak_view_plot_map(&plot, W, H, 2, 0.5f, &pk));
    AK_CHECK(ak_view_plot_map(&plot, W, H, 5, 1.5f, &pq));
    /* linear mapping, y up */
    AK_CHECK_NEAR(pm.x, 0.5f * (p00.x + p11.x), 1e-3);
    AK_CHECK_NEAR(pm.y, 0.5f * (p00.y + p11.y), 1e-3);
    AK_CHECK(p11.x > p00.x + 200 && p11.y < p00.y - 120);
    const uint8_t* c = ak_image_pixel(&img, (int)pm.x, (int)pm.y);
    AK_CHECK_MSG(c[0] > 200 && c[1] < 60 && c[2] < 60, "line pixel %d %d %d", c[0], c[1], c[2]);
    c = ak_image_pixel(&img, (int)pk.x, (int)pk.y);
    AK_CHECK_MSG(c[1] > 100 && c[0] < 60, "key pixel %d %d %d", c[0], c[1], c[2]);
    c = ak_image_pixel(&img, (int)pq.x, (int)pq.y);
    AK_CHECK(!(c[0] > 200 && c[1] < 60)); /* off the line: not red */
    /* a horizontal tangent handle to the right of the key (28 px long by default) */
    c = ak_image_pixel(&img, (int)pk.x + 18, (int)pk.y);
    AK_CHECK(c[0] < 120 && c[2] < 120);
    ak_image_pixel(&img, 0, 0);
    /* bad input */
    ak_view_series bad = {.x = {x, N}, .y = {y, N - 1}};
    ak_view_plot bp = {.series = &bad, .series_count = 1};
    AK_CHECK_EQ(ak_view_plot_draw(&bp, &img), AK_ERR_BAD_ARG);
    bp.series_count = 0;
    AK_CHECK_EQ(ak_view_plot_draw(&bp, &img), AK_ERR_EMPTY);
    ak_image tiny = {.pixels = px, .width = 50, .height = 40};
    AK_CHECK_EQ(ak_view_plot_draw(&plot, &tiny), AK_ERR_BAD_ARG);
    AK_CHECK_EQ(ak_view_plot_draw(NULL, &img), AK_ERR_NULL_ARG);
    float nanx[2] = {NAN, NAN};
    ak_view_series ns = {.x = {nanx, 2}, .y = {nanx, 2}};
    ak_view_plot np = {.series = &ns, .series_count = 1};
    AK_CHECK_EQ(ak_view_plot_draw(&np, &img), AK_ERR_EMPTY);
    float hugey[2] = {-3e38f, 3e38f}, hugex[2] = {0, 1};
    ak_view_series hs = {.x = {hugex, 2}, .y = {hugey, 2}};
    ak_view_plot hp = {.series = &hs, .series_count = 1};
    AK_CHECK_EQ(ak_view_plot_draw(&hp, &img), AK_ERR_BAD_ARG); /* and no endless tick loop */
    hugey[0] = 1e6f, hugey[1] = 1e6f + 0.5f;                   /* tiny range far from zero: fine */
    AK_CHECK_EQ(ak_view_plot_draw(&hp, &img), AK_OK);
    ak_view_plot inv = plot;
    inv.x_min = 5, inv.x_max = 1;
    AK_CHECK_EQ(ak_view_plot_draw(&inv, &img), AK_ERR_BAD_ARG);
}

AK_TEST(scene_render_skeleton_and_gif) {
    enum { W = 160, H = 120 };
    ak_raster* r = NULL;
    AK_CHECK_EQ(ak_raster_create(&(ak_raster_desc){.width = W, .height = H}, NULL, &r), AK_OK);
    if (!r) return;
    static uint8_t px[3][W * H * 4];
    ak_image frames[3];
    ak_vec3 tri[3] = {{-0.5f, 0, 0}, {0.5f, 0, 0}, {0, 1, 0}};
    ak_raster_mesh m = {.positions = {tri, 3}};
    ak_mat4 joints[2] = {ak_mat4_translation(ak_vec3_make(0, 0.2f, 0.3f)), ak_mat4_translation(ak_vec3_make(0, 0.9f, 0.3f))};
    int32_t parents[2] = {-1, 0};
    ak_view_skeleton sk = {.joint_model = {joints, 2}, .parents = {parents, 2}, .joint_color = {1, 0, 1, 1}};
    ak_view_scene scene = {.meshes = &m, .mesh_count = 1, .skeleton = &sk, .title = "t"};
    ak_vec3 lo, hi;
    ak_view_scene_bounds(&scene, &lo, &hi);
    AK_CHECK_NEAR(lo.y, 0, 0);
    AK_CHECK_NEAR(hi.y, 1, 0);
    AK_CHECK_NEAR(hi.z, 0.3f, 0);
    for (int f = 0; f < 3; ++f) {
        frames[f] = (ak_image){.pixels = px[f], .width = W, .height = H};
        ak_raster_camera cam = ak_view_orbit_camera(lo, hi, &(ak_view_orbit){.azimuth = 0.3f * (float)f,
                                                                              .elevation = 0.2f, .aspect = (float)W / H});
        AK_CHECK_EQ(ak_view_render(r, &cam, &scene, &frames[f]), AK_OK);
        /* the top joint is drawn on top in its colour (magenta) where the camera puts it */
        ak_vec3 jp;
        AK_CHECK(ak_raster_camera_project(&cam, W, H, ak_vec3_make(0, 0.9f, 0.3f), &jp));
        const uint8_t* c = ak_image_pixel(&frames[f], (int)jp.x, (int)jp.y);
        AK_CHECK_MSG(c[0] > 150 && c[2] > 150 && c[1] < 100, "joint pixel %d %d %d", c[0], c[1], c[2]);
    }
    AK_CHECK_EQ(ak_view_frames_write_gif("view_frames.gif", frames, 3, 5), AK_OK);
    int w, h, n;
    AK_CHECK_EQ(ak_gif_info("view_frames.gif", &w, &h, &n), AK_OK);
    AK_CHECK_EQ(w, W);
    AK_CHECK_EQ(h, H);
    AK_CHECK_EQ(n, 3);
    AK_CHECK_EQ(ak_view_frames_write_gif("view_frames.gif", frames, 0, 5), AK_ERR_EMPTY);
    int32_t bad_parents[2] = {-1, 5};
    sk.parents = (ak_i32_cspan){bad_parents, 2};
    ak_raster_camera cam = ak_view_orbit_camera(lo, hi, NULL);
    AK_CHECK_EQ(ak_view_draw_skeleton(r, &cam, &sk), AK_ERR_BAD_INDEX);
    sk.parents = (ak_i32_cspan){parents, 1};
    AK_CHECK_EQ(ak_view_draw_skeleton(r, &cam, &sk), AK_ERR_BAD_ARG);
    AK_CHECK_EQ(ak_view_render(r, &cam, NULL, &frames[0]), AK_ERR_NULL_ARG);
    ak_view_skeleton zero_sk = {0};
    AK_CHECK_EQ(ak_view_draw_skeleton(r, &cam, &zero_sk), AK_ERR_NULL_ARG);
    ak_view_scene empty = {0}; /* background only: every pixel is a background colour */
    AK_CHECK_EQ(ak_view_render(r, &cam, &empty, &frames[0]), AK_OK);
    AK_CHECK(memcmp(ak_image_pixel(&frames[0], 3, 5), ak_image_pixel(&frames[0], W - 3, 5), 4) == 0);
    AK_CHECK(ak_image_pixel(&frames[0], 3, 2)[2] > ak_image_pixel(&frames[0], 3, H - 2)[2]); /* light top */
    ak_raster_destroy(r);
}

/* Readable charts: dense keys draw no markers (the picture equals the line alone), float noise
 * on a constant stays flat, a title too long for the chart keeps both ends inside it. */
AK_TEST(plot_readable_dense_keys_noise_titles) {
    enum { W = 400, H = 260, N = 1000 };
    static uint8_t pa[W * H * 4], pb[W * H * 4];
    ak_image ia = {.pixels = pa, .width = W, .height = H}, ib = {.pixels = pb, .width = W, .height = H};
    static float x[N], y[N];
    for (int i = 0; i < N; ++i) x[i] = 0.01f * (float)i, y[i] = sinf(x[i]);
    ak_view_series line = {.x = {x, N}, .y = {y, N}, .color = {0.2f, 0.3f, 0.9f, 1}};
    ak_view_series keyed = line;
    keyed.key_x = (ak_f32_cspan){x, N};
    keyed.key_y = (ak_f32_cspan){y, N};
    ak_view_plot plot = {.series = &line, .series_count = 1, .title = "dense"};
    AK_CHECK_EQ(ak_view_plot_draw(&plot, &ia), AK_OK);
    plot.series = &keyed;
    AK_CHECK_EQ(ak_view_plot_draw(&plot, &ib), AK_OK);
    AK_CHECK_MSG(memcmp(pa, pb, sizeof pa) == 0, "1000 keys in 400 px drew markers");
    /* 10 keys, 30+ px apart: markers drawn */
    keyed.key_x.count = keyed.key_y.count = 10;
    float kx[10], ky[10];
    for (int i = 0; i < 10; ++i) kx[i] = (float)i, ky[i] = sinf(kx[i]);
    keyed.key_x.ptr = kx, keyed.key_y.ptr = ky;
    AK_CHECK_EQ(ak_view_plot_draw(&plot, &ib), AK_OK);
    AK_CHECK(memcmp(pa, pb, sizeof pa) != 0);
    /* 1 +- 1e-6: the y range spans at least 1% of 1, so the noise is under a pixel */
    for (int i = 0; i < N; ++i) y[i] = 1.0f + ((i & 1) ? 1e-6f : -1e-6f);
    ak_view_plot noise = {.series = &line, .series_count = 1};
    ak_vec2 lo, hi;
    AK_CHECK(ak_view_plot_map(&noise, W, H, 1.0f, 1.0f - 1e-6f, &lo));
    AK_CHECK(ak_view_plot_map(&noise, W, H, 1.0f, 1.0f + 1e-6f, &hi));
    AK_CHECK_MSG(fabsf(lo.y - hi.y) < 1.0f, "noise spans %.1f px", (double)fabsf(lo.y - hi.y));
    /* a real change larger than 1% still fills the chart */
    for (int i = 0; i < N; ++i) y[i] = 1.0f + 0.5f * (float)i / (float)N;
    AK_CHECK(ak_view_plot_map(&noise, W, H, 1.0f, 1.0f, &lo));
    AK_CHECK(ak_view_plot_map(&noise, W, H, 1.0f, 1.5f, &hi));
    AK_CHECK(lo.y - hi.y > 150.0f);
    /* a long title in a narrow chart: shrunk and cut in the middle, clear of both edges */
    enum { NW = 200, NH = 120 };
    static uint8_t pn[NW * NH * 4];
    ak_image in = {.pixels = pn, .width = NW, .height = NH};
    ak_view_plot longt = {.series = &line, .series_count = 1,
                          .title = "MMMMMMMMMMMMMMMMMMMMMMMMMMMMMMMMMMMMMMMMMMMMMMMMMMMMMMMMMMMM rotation (linear)"};
    AK_CHECK_EQ(ak_view_plot_draw(&longt, &in), AK_OK);
    int ink_edge = 0, ink = 0;
    for (int yy = 0; yy < 30; ++yy)
        for (int xx = 0; xx < NW; ++xx) {
            const uint8_t* c = ak_image_pixel(&in, xx, yy);
            if (c[0] > 100) continue;
            ++ink;
            ink_edge += xx < 5 || xx >= NW - 5;
        }
    AK_CHECK_MSG(ink > 50 && ink_edge == 0, "title ink %d, at the edges %d", ink, ink_edge);
}

/* CIE 1976 L*a*b* of an sRGB colour (D65), written out here from the standards. */
static void srgb_to_lab(ak_vec4 c, double out[3]) {
    double rgb[3] = {c.x, c.y, c.z};
    for (int k = 0; k < 3; ++k) rgb[k] = rgb[k] <= 0.04045 ? rgb[k] / 12.92 : pow((rgb[k] + 0.055) / 1.055, 2.4);
    double xyz[3] = {(0.4124 * rgb[0] + 0.3576 * rgb[1] + 0.1805 * rgb[2]) / 0.95047,
                     0.2126 * rgb[0] + 0.7152 * rgb[1] + 0.0722 * rgb[2],
                     (0.0193 * rgb[0] + 0.1192 * rgb[1] + 0.9505 * rgb[2]) / 1.08883};
    for (int k = 0; k < 3; ++k) xyz[k] = xyz[k] > 216.0 / 24389.0 ? cbrt(xyz[k]) : (24389.0 / 27.0 * xyz[k] + 16.0) / 116.0;
    out[0] = 116.0 * xyz[1] - 16.0, out[1] = 500.0 * (xyz[0] - xyz[1]), out[2] = 200.0 * (xyz[1] - xyz[2]);
}

static double delta_e(ak_vec4 a, ak_vec4 b) {
    double p[3], q[3];
    srgb_to_lab(a, p), srgb_to_lab(b, q);
    return sqrt((p[0] - q[0]) * (p[0] - q[0]) + (p[1] - q[1]) * (p[1] - q[1]) + (p[2] - q[2]) * (p[2] - q[2]));
}

/* The legend palette: for 24 colours (the humanoid and CesiumMan skins have 21 and 23 bones)
 * every pair differs by more than 15 CIE76 units (the golden-angle hues it replaces, at one
 * saturation and value, put slots 13 apart only 12 degrees of hue from each other);
 * consecutive colours by more than 20; none is grey; the first k do not depend on the count;
 * they repeat only after AK_VIEW_DISTINCT_COLOR_COUNT. */
AK_TEST(distinct_colors_for_legends) {
    static ak_vec4 c[AK_VIEW_DISTINCT_COLOR_COUNT + 2];
    AK_CHECK_EQ(ak_view_distinct_colors((ak_vec4_span){c, AK_VIEW_DISTINCT_COLOR_COUNT + 2}), AK_OK);
    double worst = 1e9, worst_next = 1e9;
    for (int i = 0; i < 24; ++i) {
        for (int j = 0; j < i; ++j) worst = fmin(worst, delta_e(c[i], c[j]));
        if (i) worst_next = fmin(worst_next, delta_e(c[i], c[i - 1]));
        double lab[3];
        srgb_to_lab(c[i], lab);
        AK_CHECK_MSG(hypot(lab[1], lab[2]) > 15.0, "colour %d is greyish (chroma %.1f)", i, hypot(lab[1], lab[2]));
    }
    AK_CHECK_MSG(worst > 15.0, "closest pair of 24: %.1f", worst);
    AK_CHECK_MSG(worst_next > 20.0, "closest consecutive pair: %.1f", worst_next);
    for (int i = 0; i < AK_VIEW_DISTINCT_COLOR_COUNT; ++i)
        for (int j = 0; j < i; ++j)
            AK_CHECK_MSG(delta_e(c[i], c[j]) > 1.0, "colours %d and %d are the same", i, j);
    AK_CHECK(c[AK_VIEW_DISTINCT_COLOR_COUNT].x == c[0].x && c[AK_VIEW_DISTINCT_COLOR_COUNT + 1].z == c[1].z);
    ak_vec4 few[5];
    AK_CHECK_EQ(ak_view_distinct_colors((ak_vec4_span){few, 5}), AK_OK);
    for (int i = 0; i < 5; ++i) AK_CHECK(few[i].x == c[i].x && few[i].y == c[i].y && few[i].z == c[i].z);
    AK_CHECK_EQ(ak_view_distinct_colors((ak_vec4_span){NULL, 3}), AK_ERR_NULL_ARG);
    AK_CHECK_EQ(ak_view_distinct_colors((ak_vec4_span){NULL, 0}), AK_OK);
}

int main(void) {
    AK_RUN(orbit_framing_keeps_box_inside);
    AK_RUN(heatmap_endpoints_and_mapping);
    AK_RUN(joint_weights_from_mesh);
    AK_RUN(panels_sizes_and_placement);
    AK_RUN(plot_draws_at_mapped_pixels);
    AK_RUN(scene_render_skeleton_and_gif);
    AK_RUN(plot_readable_dense_keys_noise_titles);
    AK_RUN(distinct_colors_for_legends);
    return ak_test_finish();
}

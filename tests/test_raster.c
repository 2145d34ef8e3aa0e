/* Tests for the software renderer. Oracles: point-in-triangle with the top-left rule written
 * here in double precision, the pinhole projection formula, Lambert's law and the sRGB curve
 * written out here, and libpng/giflib decoding of the files written. */
#include <animkit/raster.h>

#include "ak_test.h"
#include "ref/ref_gif.h" /* delays read back straight from the file */

#include <stdint.h>

/* ---- helpers -------------------------------------------------------------------------- */

/* Camera whose clip space equals world space: NDC = world (w = 1). */
static ak_raster_camera identity_camera(void) {
    ak_raster_camera c = {ak_mat4_identity(), ak_mat4_identity()};
    return c;
}

/* Pixel coordinates (y down) -> NDC world point for identity_camera. */
static ak_vec3 px_to_ndc(double x, double y, int w, int h, float z) {
    return ak_vec3_make((float)(x * 2.0 / w - 1.0), (float)(1.0 - y * 2.0 / h), z);
}

typedef struct target {
    ak_raster* r;
    uint8_t* px;
    ak_image img;
} target;

static bool target_make(target* t, int w, int h, int ss, int threads) {
    ak_raster_desc d = {.width = w, .height = h, .supersample = ss, .thread_count = threads};
    t->r = NULL;
    if (ak_raster_create(&d, NULL, &t->r) != AK_OK) return false;
    t->px = (uint8_t*)calloc((size_t)w * (size_t)h * 4, 1);
    t->img = (ak_image){.pixels = t->px, .width = w, .height = h};
    return t->px != NULL;
}

static void target_free(target* t) {
    ak_raster_destroy(t->r);
    free(t->px);
}

static const uint8_t* at(const target* t, int x, int y) { return ak_image_pixel(&t->img, x, y); }

/* Independent reference: is the pixel centre (px, py) covered by triangle a, b, c (image
 * coordinates, y down) under the top-left rule? Points on an edge count only on a top edge
 * (horizontal, interior below it) or a left edge (interior to its right). */
static bool ref_covered(const double a[2], const double b[2], const double c[2], double px, double py) {
    const double* v[3] = {a, b, c};
    double area = (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]);
    if (area == 0.0) return false;
    for (int i = 0; i < 3; ++i) {
        const double* p0 = v[i];
        const double* p1 = v[(i + 1) % 3];
        const double* o = v[(i + 2) % 3];
        double e = (p1[0] - p0[0]) * (py - p0[1]) - (p1[1] - p0[1]) * (px - p0[0]);
        double eo = (p1[0] - p0[0]) * (o[1] - p0[1]) - (p1[1] - p0[1]) * (o[0] - p0[0]);
        double s = eo > 0 ? 1.0 : -1.0;
        if (s * e > 0) continue;
        if (s * e < 0) return false;
        /* exactly on the edge line */
        bool top = p0[1] == p1[1] && o[1] > p0[1];
        /* moving +x from the edge increases s*e iff the interior is to the right */
        bool left = p0[1] != p1[1] && s * -(p1[1] - p0[1]) > 0;
        if (!top && !left) return false;
    }
    return true;
}

/* Draw one triangle as an unlit additive coverage counter (each write adds 1 to red). */
static ak_result draw_counter(target* t, const ak_raster_camera* cam, const ak_vec3* pos, size_t count,
                              const uint32_t* idx, size_t icount) {
    ak_raster_mesh m = {
        .positions = {pos, count},
        .indices = {idx, icount},
        .material = {.color = ak_vec4_make(1.0f / 255.0f, 0, 0, 0)},
        .shading = AK_SHADING_UNLIT,
        .blend = AK_BLEND_ADD,
        .no_depth_test = true,
    };
    return ak_raster_draw_mesh(t->r, cam, &m);
}

/* ---- coverage ---------------------------------------------------------------------------- */

AK_TEST(coverage_matches_point_in_triangle) {
    const int W = 64, H = 48;
    target t;
    AK_CHECK(target_make(&t, W, H, 1, 1));
    ak_raster_camera cam = identity_camera();
    ak_rng rng = ak_rng_make(7);
    int mismatches = 0, covered_total = 0;
    for (int tri = 0; tri < 400; ++tri) {
        double v[3][2];
        /* vertices on a 1/16-pixel grid (exact in float), some on pixel centres, some off-image;
           every fourth triangle has a horizontal edge to exercise the top rule */
        for (int k = 0; k < 3; ++k) {
            int grid = tri % 3 == 0 ? 2 : 16;
            v[k][0] = (double)(int)(ak_rng_range(&rng, -10.0f, (float)W + 10.0f) * (float)grid) / grid;
            v[k][1] = (double)(int)(ak_rng_range(&rng, -10.0f, (float)H + 10.0f) * (float)grid) / grid;
        }
        if (tri % 4 == 1) v[2][1] = v[1][1];
        ak_vec3 pos[3];
        for (int k = 0; k < 3; ++k) pos[k] = px_to_ndc(v[k][0], v[k][1], W, H, 0.0f);
        ak_raster_clear(t.r, ak_vec4_make(0, 0, 0, 1), ak_vec4_make(0, 0, 0, 1));
        AK_CHECK_EQ(draw_counter(&t, &cam, pos, 3, NULL, 0), AK_OK);
        AK_CHECK_EQ(ak_raster_resolve(t.r, &t.img), AK_OK);
        for (int y = 0; y < H; ++y)
            for (int x = 0; x < W; ++x) {
                int want = ref_covered(v[0], v[1], v[2], x + 0.5, y + 0.5) ? 1 : 0;
                int got = at(&t, x, y)[0];
                covered_total += want;
                if (got != want && mismatches++ < 5)
                    AK_FAIL_("triangle %d pixel (%d,%d): got %d want %d", tri, x, y, got, want);
            }
    }
    AK_CHECK_EQ(mismatches, 0);
    AK_CHECK(covered_total > 10000); /* the test really exercised coverage */
    target_free(&t);
}

AK_TEST(shared_edges_quad_and_fan_cover_once) {
    const int W = 96, H = 80;
    target t;
    AK_CHECK(target_make(&t, W, H, 1, 1));
    /* quad of two triangles with an oblique shared diagonal, identity camera */
    ak_raster_camera cam = identity_camera();
    ak_vec3 q[4] = {px_to_ndc(10.3, 7.7, W, H, 0), px_to_ndc(80.1, 12.4, W, H, 0), px_to_ndc(70.6, 70.2, W, H, 0),
                    px_to_ndc(5.5, 60.5, W, H, 0)};
    uint32_t qi[6] = {0, 1, 2, 0, 2, 3};
    ak_raster_clear(t.r, ak_vec4_make(0, 0, 0, 1), ak_vec4_make(0, 0, 0, 1));
    AK_CHECK_EQ(draw_counter(&t, &cam, q, 4, qi, 6), AK_OK);
    AK_CHECK_EQ(ak_raster_resolve(t.r, &t.img), AK_OK);
    int over = 0, ones = 0;
    for (int y = 0; y < H; ++y)
        for (int x = 0; x < W; ++x) {
            int c = at(&t, x, y)[0];
            if (c > 1) ++over;
            ones += c == 1;
        }
    AK_CHECK_EQ(over, 0);
    /* the quad's area (shoelace) approximates its pixel count */
    double qa[4][2] = {{10.3, 7.7}, {80.1, 12.4}, {70.6, 70.2}, {5.5, 60.5}}, area = 0;
    for (int i = 0; i < 4; ++i) area += qa[i][0] * qa[(i + 1) % 4][1] - qa[(i + 1) % 4][0] * qa[i][1];
    area = fabs(area) * 0.5;
    AK_CHECK_NEAR(ones, area, area * 0.03);

    /* fan of 48 triangles on a disc in 3D seen by a perspective camera: every pixel whose
       centre is clearly inside the (projected) polygon is drawn exactly once */
    enum { N = 48 };
    ak_vec3 fan[N + 1];
    uint32_t fi[N * 3];
    fan[0] = ak_vec3_make(0.05f, 0.0f, 0.02f);
    for (int i = 0; i < N; ++i) {
        float a = AK_TWO_PI * (float)i / N;
        fan[i + 1] = ak_vec3_make(1.3f * cosf(a), 0.0f, 1.1f * sinf(a));
        fi[i * 3] = 0;
        fi[i * 3 + 1] = (uint32_t)(i + 1);
        fi[i * 3 + 2] = (uint32_t)((i + 1) % N + 1);
    }
    ak_raster_camera pc = ak_raster_camera_perspective(ak_vec3_make(0.4f, 2.0f, 2.5f), ak_vec3_zero(), ak_radians(50),
                                                       (float)W / H, 0.1f, 20);
    ak_raster_clear(t.r, ak_vec4_make(0, 0, 0, 1), ak_vec4_make(0, 0, 0, 1));
    AK_CHECK_EQ(draw_counter(&t, &pc, fan, N + 1, fi, N * 3), AK_OK);
    AK_CHECK_EQ(ak_raster_resolve(t.r, &t.img), AK_OK);
    /* project the rim in double with the camera matrices */
    double rim[N][2];
    ak_mat4 vp = ak_mat4_mul(pc.projection, pc.view);
    for (int i = 0; i < N; ++i) {
        double c[4];
        for (int r = 0; r < 4; ++r)
            c[r] = (double)vp.m[r] * fan[i + 1].x + (double)vp.m[4 + r] * fan[i + 1].y +
                   (double)vp.m[8 + r] * fan[i + 1].z + vp.m[12 + r];
        rim[i][0] = (c[0] / c[3] * 0.5 + 0.5) * W;
        rim[i][1] = (0.5 - c[1] / c[3] * 0.5) * H;
    }
    over = 0;
    int holes = 0, outside_drawn = 0;
    for (int y = 0; y < H; ++y)
        for (int x = 0; x < W; ++x) {
            double px = x + 0.5, py = y + 0.5, mind = 1e9;
            int sgn = 0;
            bool inside = true;
            for (int i = 0; i < N; ++i) {
                const double* a = rim[i];
                const double* b = rim[(i + 1) % N];
                double ex = b[0] - a[0], ey = b[1] - a[1];
                double cr = ex * (py - a[1]) - ey * (px - a[0]);
                double d = cr / sqrt(ex * ex + ey * ey);
                int s = cr > 0 ? 1 : -1;
                if (sgn == 0) sgn = s;
                if (s != sgn) inside = false;
                if (fabs(d) < mind) mind = fabs(d);
            }
            int c = at(&t, x, y)[0];
            if (c > 1) ++over;
            if (mind < 0.01) continue; /* on the rim: either answer is fine */
            if (inside && c != 1) ++holes;
            if (!inside && c != 0) ++outside_drawn;
        }
    AK_CHECK_EQ(over, 0);
    AK_CHECK_EQ(holes, 0);
    AK_CHECK_EQ(outside_drawn, 0);
    target_free(&t);
}

/* ---- depth, clipping, projection -------------------------------------------------------------- */

static ak_raster_mesh unlit_tri(const ak_vec3* p, ak_vec4 color) {
    ak_raster_mesh m = {.positions = {p, 3}, .material = {.color = color}, .shading = AK_SHADING_UNLIT};
    return m;
}

/* ak_raster_read_samples: UNLIT per-vertex colours that are exact bytes come back exactly (an
 * id channel), and the depth, turned into the distance along the view axis by the header's
 * formula, matches the plane z = -x/2 hit by each sample's ray (closed form, double). */
AK_TEST(read_samples_ids_and_depth) {
    const int W = 16, H = 12, SS = 2, SW = W * SS, SH = H * SS;
    ak_raster* r = NULL;
    AK_CHECK_EQ(ak_raster_create(&(ak_raster_desc){.width = W, .height = H, .supersample = SS}, NULL, &r), AK_OK);
    const float n = 0.1f, f = 10.0f, fovy = ak_radians(60), aspect = (float)W / (float)H;
    ak_raster_camera cam = ak_raster_camera_perspective(ak_vec3_make(0, 0, 3), ak_vec3_zero(), fovy, aspect, n, f);
    ak_raster_clear(r, ak_vec4_make(0, 0, 0, 1), ak_vec4_make(0, 0, 0, 1));
    const ak_vec3 pos[6] = {{-1, -1, 0.5f}, {1, -1, -0.5f}, {1, 1, -0.5f}, {-1, -1, 0.5f}, {1, 1, -0.5f}, {-1, 1, 0.5f}};
    const uint8_t id[3] = {17, 200, 3};
    ak_vec4 col[6];
    for (int k = 0; k < 6; ++k) col[k] = ak_vec4_make(id[0] / 255.0f, id[1] / 255.0f, id[2] / 255.0f, 1);
    ak_raster_mesh m = {.positions = {pos, 6}, .colors = {col, 6}, .material = {.color = {1, 1, 1, 1}},
                        .shading = AK_SHADING_UNLIT};
    AK_CHECK_EQ(ak_raster_draw_mesh(r, &cam, &m), AK_OK);
    uint8_t* rgba = malloc((size_t)SW * SH * 4);
    float* depth = malloc((size_t)SW * SH * sizeof(float));
    AK_CHECK(rgba && depth);
    AK_CHECK_EQ(ak_raster_read_samples(NULL, (ak_u8_span){rgba, (size_t)SW * SH * 4}, (ak_f32_span){0}), AK_ERR_NULL_ARG);
    AK_CHECK_EQ(ak_raster_read_samples(r, (ak_u8_span){rgba, (size_t)SW * SH * 4 - 1}, (ak_f32_span){0}),
                AK_ERR_SPAN_SMALL);
    AK_CHECK_EQ(ak_raster_read_samples(r, (ak_u8_span){0}, (ak_f32_span){depth, (size_t)SW * SH - 1}), AK_ERR_SPAN_SMALL);
    AK_CHECK_EQ(ak_raster_read_samples(r, (ak_u8_span){NULL, 4}, (ak_f32_span){0}), AK_ERR_NULL_ARG);
    AK_CHECK_EQ(ak_raster_read_samples(r, (ak_u8_span){rgba, (size_t)SW * SH * 4}, (ak_f32_span){depth, (size_t)SW * SH}),
                AK_OK);
    const double ty = tan(0.5 * fovy), tx = ty * aspect;
    int covered = 0, background = 0;
    double worst = 0.0;
    for (int y = 0; y < SH; ++y)
        for (int x = 0; x < SW; ++x) {
            const uint8_t* c = rgba + 4 * ((size_t)y * SW + x);
            const float d = depth[(size_t)y * SW + x];
            const double xn = 2.0 * (x + 0.5) / SW - 1.0, yn = 1.0 - 2.0 * (y + 0.5) / SH;
            /* the sample's ray eye + s (xn tx, yn ty, -1) meets the plane z = -x / 2 at s */
            const double s = 3.0 / (1.0 - 0.5 * xn * tx), hx = s * xn * tx, hy = s * yn * ty;
            const bool inside = fabs(hx) < 0.99 && fabs(hy) < 0.99, outside = fabs(hx) > 1.01 || fabs(hy) > 1.01;
            if (c[0] == 0 && c[1] == 0 && c[2] == 0) {
                AK_CHECK_MSG(!inside, "sample %d %d inside the quad not drawn", x, y);
                AK_CHECK(d == 1.0f);
                ++background;
                continue;
            }
            AK_CHECK_MSG(!outside, "sample %d %d outside the quad drawn", x, y);
            AK_CHECK_MSG(c[0] == id[0] && c[1] == id[1] && c[2] == id[2] && c[3] == 255, "sample %d %d: %d %d %d %d", x, y,
                         c[0], c[1], c[2], c[3]);
            const double z = 2.0 * n * f / (f + n - (2.0 * d - 1.0) * (f - n));
            worst = fmax(worst, fabs(z - s) / s);
            ++covered;
        }
    printf("  %d samples covered (id bytes exact), %d background; depth -> distance worst relative error %.2g\n",
           covered, background, worst);
    AK_CHECK(covered > 100 && background > 10);
    AK_CHECK_MSG(worst < 1e-4, "worst %g", worst);
    free(rgba);
    free(depth);
    ak_raster_destroy(r);
}

AK_TEST(depth_test_orders_by_distance) {
    target t;
    AK_CHECK(target_make(&t, 32, 32, 1, 1));
    ak_raster_camera cam = ak_raster_camera_perspective(ak_vec3_make(0, 0, 3), ak_vec3_zero(), ak_radians(60), 1, 0.1f, 10);
    ak_vec3 nearp[3] = {{-1, -1, 0.5f}, {1, -1, 0.5f}, {0, 1, 0.5f}};
    ak_vec3 farp[3] = {{-1.5f, -1.5f, -0.5f}, {1.5f, -1.5f, -0.5f}, {0, 1.5f, -0.5f}};
    for (int order = 0; order < 2; ++order) {
        ak_raster_clear(t.r, ak_vec4_make(0, 0, 0, 1), ak_vec4_make(0, 0, 0, 1));
        ak_raster_mesh a = unlit_tri(nearp, ak_vec4_make(0, 0, 1, 1)), b = unlit_tri(farp, ak_vec4_make(1, 0, 0, 1));
        AK_CHECK_EQ(ak_raster_draw_mesh(t.r, &cam, order ? &a : &b), AK_OK);
        AK_CHECK_EQ(ak_raster_draw_mesh(t.r, &cam, order ? &b : &a), AK_OK);
        ak_raster_resolve(t.r, &t.img);
        AK_CHECK_EQ(at(&t, 16, 16)[2], 255); /* near (blue) wins in both orders */
        AK_CHECK_EQ(at(&t, 16, 16)[0], 0);
    }
    target_free(&t);
}

AK_TEST(near_plane_crossing_triangle_is_clipped_not_dropped) {
    target t;
    AK_CHECK(target_make(&t, 64, 64, 1, 1));
    /* camera at the origin looking down -Z; one vertex behind the camera */
    ak_raster_camera cam = ak_raster_camera_perspective(ak_vec3_zero(), ak_vec3_make(0, 0, -1), ak_radians(90), 1, 0.5f, 50);
    ak_vec3 p[3] = {{-1, -0.5f, -2}, {1, -0.5f, -2}, {0, -0.5f, 3}};
    ak_raster_clear(t.r, ak_vec4_make(0, 0, 0, 1), ak_vec4_make(0, 0, 0, 1));
    ak_raster_mesh m = unlit_tri(p, ak_vec4_make(0, 1, 0, 1));
    AK_CHECK_EQ(ak_raster_draw_mesh(t.r, &cam, &m), AK_OK);
    ak_raster_resolve(t.r, &t.img);
    /* the point (0, -0.5, -1) is on the triangle and in front: projects to x = 32,
       y = 32 + 0.5/1 * 32 = 48 (tan 45 = 1) */
    AK_CHECK_EQ(at(&t, 32, 48)[1], 255);
    AK_CHECK_EQ(at(&t, 32, 60)[1], 255); /* near the bottom edge: the clipped part reaches it */
    AK_CHECK_EQ(at(&t, 32, 20)[1], 0);   /* above the horizon of the plane: nothing */
    /* a triangle entirely behind the camera draws nothing */
    ak_vec3 q[3] = {{-1, -1, 2}, {1, -1, 2}, {0, 1, 2}};
    ak_raster_clear(t.r, ak_vec4_make(0, 0, 0, 1), ak_vec4_make(0, 0, 0, 1));
    m = unlit_tri(q, ak_vec4_make(0, 1, 0, 1));
    AK_CHECK_EQ(ak_raster_draw_mesh(t.r, &cam, &m), AK_OK);
    ak_raster_resolve(t.r, &t.img);
    int drawn = 0;
    for (int y = 0; y < 64; ++y)
        for (int x = 0; x < 64; ++x) drawn += at(&t, x, y)[1] != 0;
    AK_CHECK_EQ(drawn, 0);
    target_free(&t);
}

AK_TEST(cube_corners_where_projection_puts_them) {
    const int W = 160, H = 120;
    target t;
    AK_CHECK(target_make(&t, W, H, 1, 1));
    const double eye[3] = {2.5, 1.8, 3.1}, fov = 45.0 * 3.14159265358979323846 / 180.0;
    ak_raster_camera cam = ak_raster_camera_perspective(ak_vec3_make((float)eye[0], (float)eye[1], (float)eye[2]),
                                                        ak_vec3_zero(), (float)fov, (float)W / H, 0.1f, 100);
    ak_vec3 pos[8];
    for (int i = 0; i < 8; ++i)
        pos[i] = ak_vec3_make(i & 1 ? 0.5f : -0.5f, i & 2 ? 0.5f : -0.5f, i & 4 ? 0.5f : -0.5f);
    const uint32_t idx[36] = {0, 2, 1, 1, 2, 3, 4, 5, 6, 5, 7, 6, 0, 1, 4, 1, 5, 4,
                              2, 6, 3, 3, 6, 7, 0, 4, 2, 2, 4, 6, 1, 3, 5, 3, 7, 5};
    ak_raster_mesh m = {.positions = {pos, 8}, .indices = {idx, 36}, .shading = AK_SHADING_UNLIT,
                        .material = {.color = {1, 1, 1, 1}}};
    ak_raster_clear(t.r, ak_vec4_make(0, 0, 0, 1), ak_vec4_make(0, 0, 0, 1));
    AK_CHECK_EQ(ak_raster_draw_mesh(t.r, &cam, &m), AK_OK);
    ak_raster_resolve(t.r, &t.img);
    /* pinhole projection in double: camera basis from eye towards the origin, y up */
    double f[3] = {-eye[0], -eye[1], -eye[2]}, fl = sqrt(f[0] * f[0] + f[1] * f[1] + f[2] * f[2]);
    for (int k = 0; k < 3; ++k) f[k] /= fl;
    double r[3] = {-f[2], 0, f[0]}, rl = sqrt(r[0] * r[0] + r[2] * r[2]); /* f x (0,1,0) */
    for (int k = 0; k < 3; ++k) r[k] /= rl;
    double u[3] = {r[1] * f[2] - r[2] * f[1], r[2] * f[0] - r[0] * f[2], r[0] * f[1] - r[1] * f[0]};
    double th = tan(fov / 2), minx = 1e9, maxx = -1e9, miny = 1e9, maxy = -1e9;
    for (int i = 0; i < 8; ++i) {
        double d[3] = {pos[i].x - eye[0], pos[i].y - eye[1], pos[i].z - eye[2]};
        double xc = d[0] * r[0] + d[1] * r[1] + d[2] * r[2], yc = d[0] * u[0] + d[1] * u[1] + d[2] * u[2];
        double zc = d[0] * f[0] + d[1] * f[1] + d[2] * f[2];
        double sx = W / 2.0 + (xc / zc) / (th * W / H) * W / 2.0, sy = H / 2.0 - (yc / zc) / th * H / 2.0;
        minx = fmin(minx, sx), maxx = fmax(maxx, sx), miny = fmin(miny, sy), maxy = fmax(maxy, sy);
        /* some covered pixel centre within 1 pixel of the corner */
        bool near = false;
        for (int y = (int)sy - 2; y <= (int)sy + 2; ++y)
            for (int x = (int)sx - 2; x <= (int)sx + 2; ++x)
                if (x >= 0 && y >= 0 && x < W && y < H && at(&t, x, y)[0] == 255 &&
                    fabs(x + 0.5 - sx) <= 1.0 && fabs(y + 0.5 - sy) <= 1.0)
                    near = true;
        AK_CHECK_MSG(near, "corner %d at (%.2f, %.2f) has no drawn pixel within 1 px", i, sx, sy);
    }
    int bx0 = W, bx1 = -1, by0 = H, by1 = -1;
    for (int y = 0; y < H; ++y)
        for (int x = 0; x < W; ++x)
            if (at(&t, x, y)[0] == 255) {
                if (x < bx0) bx0 = x;
                if (x > bx1) bx1 = x;
                if (y < by0) by0 = y;
                if (y > by1) by1 = y;
            }
    AK_CHECK_NEAR(bx0 + 0.5, minx, 1.0);
    AK_CHECK_NEAR(bx1 + 0.5, maxx, 1.0);
    AK_CHECK_NEAR(by0 + 0.5, miny, 1.0);
    AK_CHECK_NEAR(by1 + 0.5, maxy, 1.0);
    /* ak_raster_camera_project agrees with the formula too */
    ak_vec3 pp;
    AK_CHECK(ak_raster_camera_project(&cam, W, H, pos[7], &pp));
    target_free(&t);
}

AK_TEST(perspective_correct_interpolation) {
    const int W = 64, H = 64;
    target t;
    AK_CHECK(target_make(&t, W, H, 1, 1));
    ak_raster_camera cam = ak_raster_camera_perspective(ak_vec3_make(0, 1, 0), ak_vec3_make(0, 1, -1), ak_radians(90),
                                                        1, 0.1f, 100);
    /* a floor strip from z = -1 (red) to z = -9 (blue) */
    ak_vec3 p[4] = {{-1, 0, -1}, {1, 0, -1}, {1, 0, -9}, {-1, 0, -9}};
    ak_vec4 c[4] = {{1, 0, 0, 1}, {1, 0, 0, 1}, {0, 0, 1, 1}, {0, 0, 1, 1}};
    uint32_t idx[6] = {0, 1, 2, 0, 2, 3};
    ak_raster_mesh m = {.positions = {p, 4}, .colors = {c, 4}, .indices = {idx, 6}, .shading = AK_SHADING_UNLIT,
                        .material = {.color = {1, 1, 1, 1}}};
    ak_raster_clear(t.r, ak_vec4_make(0, 0, 0, 1), ak_vec4_make(0, 0, 0, 1));
    AK_CHECK_EQ(ak_raster_draw_mesh(t.r, &cam, &m), AK_OK);
    ak_raster_resolve(t.r, &t.img);
    /* world point at z = -5 is half way: screen y = 32 + (1/5) * 32 = 38.4 */
    for (int y = 34; y < 62; ++y) {
        double yc = y + 0.5, zw = 32.0 / (yc - 32.0); /* depth of the floor seen at this row */
        double s = (zw - 1.0) / 8.0;                  /* 0 at the red end, 1 at the blue end */
        if (s < 0 || s > 1) continue;
        AK_CHECK_NEAR(at(&t, 32, y)[2], s * 255.0, 3.0);
        AK_CHECK_NEAR(at(&t, 32, y)[0], (1 - s) * 255.0, 3.0);
    }
    target_free(&t);
}

/* ---- shading ------------------------------------------------------------------------------- */

static double srgb_encode(double l) { return l <= 0.0031308 ? l * 12.92 : 1.055 * pow(l, 1 / 2.4) - 0.055; }
static double srgb_decode(double s) { return s <= 0.04045 ? s / 12.92 : pow((s + 0.055) / 1.055, 2.4); }

AK_TEST(lambert_diffuse_matches_formula) {
    target t;
    AK_CHECK(target_make(&t, 16, 16, 1, 1));
    ak_raster_camera cam = ak_raster_camera_orthographic(ak_vec3_make(0, 0, 5), ak_vec3_zero(), 1, 1, 0.1f, 10);
    ak_vec3 p[4] = {{-2, -2, 0}, {2, -2, 0}, {2, 2, 0}, {-2, 2, 0}};
    ak_vec3 n[4] = {{0, 0, 1}, {0, 0, 1}, {0, 0, 1}, {0, 0, 1}};
    uint32_t idx[6] = {0, 1, 2, 0, 2, 3};
    const ak_shading modes[3] = {AK_SHADING_PHONG, AK_SHADING_GOURAUD, AK_SHADING_FLAT};
    for (int a = 0; a < 4; ++a) {
        double ang = 0.2 + 0.35 * a;
        ak_raster_lighting light = {
            .key_direction = ak_vec3_make((float)sin(ang), 0, (float)-cos(ang)),
            .key_color = ak_vec3_make(0.9f, 0.9f, 0.9f),
            .fill_color = ak_vec3_splat(1e-9f),
            .ambient_color = ak_vec3_splat(1e-9f),
        };
        /* also through the per-vertex colour paths: colour (0.7, 0.5, 0.3) on a white material */
        const ak_vec4 vc[4] = {{0.7f, 0.5f, 0.3f, 1}, {0.7f, 0.5f, 0.3f, 1}, {0.7f, 0.5f, 0.3f, 1}, {0.7f, 0.5f, 0.3f, 1}};
        for (int s = 0; s < 6; ++s) {
            ak_raster_mesh m = {.positions = {p, 4}, .normals = {n, 4}, .indices = {idx, 6},
                                .material = {.color = ak_vec4_make(0.7f, 0.5f, 0.3f, 1), .specular = -1},
                                .lighting = &light, .shading = modes[s % 3]};
            if (s >= 3) {
                m.colors = (ak_vec4_cspan){vc, 4};
                m.material.color = ak_vec4_make(1, 1, 1, 1);
            }
            ak_raster_clear(t.r, ak_vec4_make(0, 0, 0, 1), ak_vec4_make(0, 0, 0, 1));
            AK_CHECK_EQ(ak_raster_draw_mesh(t.r, &cam, &m), AK_OK);
            ak_raster_resolve(t.r, &t.img);
            const double alb[3] = {0.7, 0.5, 0.3};
            for (int k = 0; k < 3; ++k) {
                double lin = srgb_decode(alb[k]) * 0.9 * cos(ang);
                AK_CHECK_NEAR(at(&t, 8, 8)[k], srgb_encode(lin) * 255.0, 1.5);
            }
        }
    }
    target_free(&t);
}

AK_TEST(model_matrix_moves_geometry) {
    target t;
    AK_CHECK(target_make(&t, 32, 32, 1, 1));
    ak_raster_camera cam = identity_camera();
    /* a small triangle around pixel (8, 16); translated by +1 NDC in x = +16 pixels */
    ak_vec3 p[3] = {px_to_ndc(6, 18, 32, 32, 0), px_to_ndc(10, 18, 32, 32, 0), px_to_ndc(8, 14, 32, 32, 0)};
    ak_mat4 move = ak_mat4_translation(ak_vec3_make(1, 0, 0));
    ak_raster_mesh m = unlit_tri(p, ak_vec4_make(1, 1, 1, 1));
    m.model = &move;
    for (int s = 0; s < 4; ++s) {
        m.shading = (ak_shading)(s + 1);
        ak_raster_clear(t.r, ak_vec4_make(0, 0, 0, 1), ak_vec4_make(0, 0, 0, 1));
        AK_CHECK_EQ(ak_raster_draw_mesh(t.r, &cam, &m), AK_OK);
        ak_raster_resolve(t.r, &t.img);
        AK_CHECK(at(&t, 24, 16)[0] > 0);
        AK_CHECK_EQ(at(&t, 8, 16)[0], 0);
    }
    target_free(&t);
}

AK_TEST(back_face_culling_and_two_sided) {
    target t;
    AK_CHECK(target_make(&t, 16, 16, 1, 1));
    ak_raster_camera cam = ak_raster_camera_perspective(ak_vec3_make(0, 0, 3), ak_vec3_zero(), ak_radians(60), 1, 0.1f, 10);
    ak_vec3 cw[3] = {{-1, -1, 0}, {0, 1, 0}, {1, -1, 0}}; /* clockwise seen from +Z: a back face */
    ak_raster_mesh m = unlit_tri(cw, ak_vec4_make(1, 1, 1, 1));
    ak_raster_clear(t.r, ak_vec4_make(0, 0, 0, 1), ak_vec4_make(0, 0, 0, 1));
    AK_CHECK_EQ(ak_raster_draw_mesh(t.r, &cam, &m), AK_OK);
    ak_raster_resolve(t.r, &t.img);
    AK_CHECK_EQ(at(&t, 8, 9)[0], 255);
    m.cull_back_faces = true;
    ak_raster_clear(t.r, ak_vec4_make(0, 0, 0, 1), ak_vec4_make(0, 0, 0, 1));
    AK_CHECK_EQ(ak_raster_draw_mesh(t.r, &cam, &m), AK_OK);
    ak_raster_resolve(t.r, &t.img);
    AK_CHECK_EQ(at(&t, 8, 9)[0], 0);
    target_free(&t);
}

/* ---- lines, points, threads, anti-aliasing, text -------------------------------------------------- */

AK_TEST(lines_and_points_respect_depth) {
    target t;
    AK_CHECK(target_make(&t, 32, 32, 1, 1));
    ak_raster_camera cam = ak_raster_camera_perspective(ak_vec3_make(0, 0, 3), ak_vec3_zero(), ak_radians(60), 1, 0.1f, 10);
    ak_vec3 wall[3] = {{-3, -3, 0}, {3, -3, 0}, {0, 3, 0}};
    ak_vec3 seg[2] = {{-1, 0, -1}, {1, 0, -1}}; /* behind the wall */
    for (int on_top = 0; on_top < 2; ++on_top) {
        ak_raster_clear(t.r, ak_vec4_make(0, 0, 0, 1), ak_vec4_make(0, 0, 0, 1));
        ak_raster_mesh m = unlit_tri(wall, ak_vec4_make(0, 0, 1, 1));
        AK_CHECK_EQ(ak_raster_draw_mesh(t.r, &cam, &m), AK_OK);
        ak_raster_lines l = {.positions = {seg, 2}, .color = {1, 0, 0, 1}, .width = 3, .on_top = on_top != 0};
        AK_CHECK_EQ(ak_raster_draw_lines(t.r, &cam, &l), AK_OK);
        ak_raster_points pt = {.positions = {seg, 1}, .color = {0, 1, 0, 1}, .radius = 3, .on_top = on_top != 0};
        AK_CHECK_EQ(ak_raster_draw_points(t.r, &cam, &pt), AK_OK);
        ak_raster_resolve(t.r, &t.img);
        AK_CHECK_EQ(at(&t, 16, 16)[0], on_top ? 255 : 0);
        /* the point at (-1,0,-1) projects to x = 16 - (1/4)/tan30 * 16 = 9.07 */
        const uint8_t* jp = at(&t, 9, 16); /* points are shaded like small spheres: mostly green */
        if (on_top) AK_CHECK(jp[1] > 150 && jp[0] < 60 && jp[2] < 60);
        else AK_CHECK(jp[1] == 0 && jp[2] == 255);
        AK_CHECK_EQ(at(&t, 16, 16)[2], on_top ? 0 : 255);
    }
    target_free(&t);
}

static void scene(target* t) {
    ak_raster_camera cam = ak_raster_camera_perspective(ak_vec3_make(1.5f, 1.2f, 2.5f), ak_vec3_make(0, 0.4f, 0),
                                                        ak_radians(45), 1.25f, 0.1f, 20);
    enum { SEG = 24, RING = 16 };
    static ak_vec3 pos[(SEG + 1) * (RING + 1)], nrm[(SEG + 1) * (RING + 1)];
    static uint32_t idx[SEG * RING * 6];
    size_t ni = 0;
    for (int i = 0; i <= SEG; ++i)
        for (int j = 0; j <= RING; ++j) {
            float th = AK_PI * (float)j / RING, ph = AK_TWO_PI * (float)i / SEG;
            ak_vec3 n = ak_vec3_make(sinf(th) * cosf(ph), cosf(th), sinf(th) * sinf(ph));
            pos[i * (RING + 1) + j] = ak_vec3_add(ak_vec3_scale(n, 0.4f), ak_vec3_make(0, 0.4f, 0));
            nrm[i * (RING + 1) + j] = n;
        }
    for (int i = 0; i < SEG; ++i)
        for (int j = 0; j < RING; ++j) {
            uint32_t a = (uint32_t)(i * (RING + 1) + j), b = a + RING + 1;
            uint32_t q[6] = {a, a + 1, b, b, a + 1, b + 1};
            for (int k = 0; k < 6; ++k) idx[ni++] = q[k];
        }
    ak_raster_clear(t->r, ak_vec4_make(0.8f, 0.85f, 0.9f, 1), ak_vec4_make(0.5f, 0.5f, 0.55f, 1));
    ak_raster_mesh m = {.positions = {pos, sizeof pos / sizeof pos[0]}, .normals = {nrm, sizeof nrm / sizeof nrm[0]},
                        .indices = {idx, ni}};
    ak_raster_ground g = {.half_extent = 2, .casters = &m, .caster_count = 1};
    ak_raster_draw_ground(t->r, &cam, &g);
    ak_raster_draw_mesh(t->r, &cam, &m);
    ak_raster_draw_text(t->r, 2, 2, "Hi", 1, ak_vec4_make(0, 0, 0, 1));
    ak_raster_resolve(t->r, &t->img);
}

AK_TEST(threads_give_identical_images) {
    target a, b;
    AK_CHECK(target_make(&a, 100, 80, 2, 1));
    AK_CHECK(target_make(&b, 100, 80, 2, 3));
    scene(&a);
    scene(&b);
    AK_CHECK(memcmp(a.px, b.px, 100 * 80 * 4) == 0);
    /* and the scene is not blank: the sphere is lit brighter on the key-light side */
    int distinct = 0;
    for (int i = 1; i < 100 * 80; ++i) distinct += memcmp(a.px + i * 4, a.px, 3) != 0;
    AK_CHECK(distinct > 1000);
    target_free(&a);
    target_free(&b);
}

AK_TEST(threads_keep_order_when_segments_overflow) {
    /* 5000 huge triangles that cross the near plane and the guard band: each is clipped into
       several pieces, so the per-thread segments fill up and rounds end early; alpha blending
       makes the result depend on the drawing order, which must match one thread exactly */
    enum { N = 5000 };
    ak_vec3* pos = (ak_vec3*)malloc(sizeof(ak_vec3) * N * 3);
    ak_vec4* col = (ak_vec4*)malloc(sizeof(ak_vec4) * N * 3);
    ak_rng rng = ak_rng_make(5);
    for (int i = 0; i < N; ++i) {
        /* a floor triangle far larger than the view, turned about the camera's vertical axis:
           near, far and the side guard planes all cut it */
        float a = ak_rng_range(&rng, 0, AK_TWO_PI), cs = cosf(a), sn = sinf(a);
        const float fx[3] = {-1000, 1000, 0}, fz[3] = {-1000, -1000, 1000};
        for (int k = 0; k < 3; ++k)
            pos[i * 3 + k] = ak_vec3_make(cs * fx[k] + sn * fz[k], -1.0f, -sn * fx[k] + cs * fz[k] + 3.0f);
        ak_vec4 c = ak_vec4_make(ak_rng_float(&rng), ak_rng_float(&rng), ak_rng_float(&rng), 0.5f);
        col[i * 3] = col[i * 3 + 1] = col[i * 3 + 2] = c;
    }
    ak_raster_camera cam = ak_raster_camera_perspective(ak_vec3_make(0, 0, 3), ak_vec3_zero(), ak_radians(60), 1.25f, 0.5f, 100);
    ak_raster_mesh m = {.positions = {pos, N * 3}, .colors = {col, N * 3}, .shading = AK_SHADING_UNLIT,
                        .blend = AK_BLEND_ALPHA, .material = {.color = {1, 1, 1, 1}}};
    target one, three;
    AK_CHECK(target_make(&one, 80, 64, 1, 1));
    AK_CHECK(target_make(&three, 80, 64, 1, 3));
    ak_raster_clear(one.r, ak_vec4_make(0, 0, 0, 1), ak_vec4_make(0, 0, 0, 1));
    ak_raster_clear(three.r, ak_vec4_make(0, 0, 0, 1), ak_vec4_make(0, 0, 0, 1));
    AK_CHECK_EQ(ak_raster_draw_mesh(one.r, &cam, &m), AK_OK);
    AK_CHECK_EQ(ak_raster_draw_mesh(three.r, &cam, &m), AK_OK);
    ak_raster_resolve(one.r, &one.img);
    ak_raster_resolve(three.r, &three.img);
    AK_CHECK(memcmp(one.px, three.px, 80 * 64 * 4) == 0);
    int lit = 0;
    for (int i = 0; i < 80 * 64; ++i) lit += one.px[i * 4] + one.px[i * 4 + 1] + one.px[i * 4 + 2] > 0;
    AK_CHECK(lit > 80 * 64 / 3); /* the clipped pieces really cover the floor half of the image */
    target_free(&one);
    target_free(&three);
    free(pos);
    free(col);
}

AK_TEST(supersampling_softens_edges) {
    for (int ss = 1; ss <= 4; ss += 3) {
        target t;
        AK_CHECK(target_make(&t, 32, 32, ss, 1));
        ak_raster_camera cam = identity_camera();
        /* a slanted edge: with 4x4 samples edge pixels take intermediate values */
        ak_vec3 p[3] = {px_to_ndc(2, 2, 32, 32, 0), px_to_ndc(30, 9, 32, 32, 0), px_to_ndc(4, 30, 32, 32, 0)};
        ak_raster_clear(t.r, ak_vec4_make(0, 0, 0, 1), ak_vec4_make(0, 0, 0, 1));
        ak_raster_mesh m = unlit_tri(p, ak_vec4_make(1, 1, 1, 1));
        AK_CHECK_EQ(ak_raster_draw_mesh(t.r, &cam, &m), AK_OK);
        ak_raster_resolve(t.r, &t.img);
        int mid = 0;
        for (int y = 0; y < 32; ++y)
            for (int x = 0; x < 32; ++x) mid += at(&t, x, y)[0] > 10 && at(&t, x, y)[0] < 245;
        if (ss == 1) AK_CHECK_EQ(mid, 0);
        else AK_CHECK(mid > 20);
        target_free(&t);
    }
}

AK_TEST(text_glyphs_and_size) {
    int w = 0, h = 0;
    ak_text_size("ab\nc", 1, &w, &h);
    AK_CHECK_EQ(w, 2 * AK_FONT_ADVANCE_X - 1);
    AK_CHECK_EQ(h, 2 * AK_FONT_ADVANCE_Y - 2);
    ak_text_size("", 3, &w, &h);
    AK_CHECK_EQ(w, 0);
    AK_CHECK_EQ(h, 0);
    /* every printable glyph except space has ink, and differs from every other glyph */
    uint8_t g[95][7];
    for (int c = 32; c < 127; ++c) ak_font_glyph((char)c, g[c - 32]);
    for (int c = 33; c < 127; ++c) {
        int ink = 0;
        for (int r = 0; r < 7; ++r) ink += g[c - 32][r] != 0;
        AK_CHECK_MSG(ink > 0, "glyph '%c' is empty", c);
        for (int d = 32; d < c; ++d) AK_CHECK_MSG(memcmp(g[c - 32], g[d - 32], 7) != 0, "'%c' == '%c'", c, d);
    }
    /* 'L' at scale 2: its vertical stroke is the leftmost column, its foot the last row */
    uint8_t px[20 * 20 * 4];
    ak_image img = {.pixels = px, .width = 20, .height = 20};
    ak_image_fill(&img, ak_vec4_make(0, 0, 0, 1));
    AK_CHECK_EQ(ak_image_draw_text(&img, 3, 2, "L", 2, ak_vec4_make(1, 1, 1, 1)), AK_OK);
    AK_CHECK_EQ(ak_image_pixel(&img, 3, 2)[0], 255);
    AK_CHECK_EQ(ak_image_pixel(&img, 4, 15)[0], 255);
    AK_CHECK_EQ(ak_image_pixel(&img, 12, 15)[0], 255);
    AK_CHECK_EQ(ak_image_pixel(&img, 12, 2)[0], 0);
    AK_CHECK_EQ(ak_image_pixel(&img, 2, 2)[0], 0);
    AK_CHECK_EQ(ak_image_draw_text(NULL, 0, 0, "x", 1, ak_vec4_make(1, 1, 1, 1)), AK_ERR_NULL_ARG);
}

/* ---- files ----------------------------------------------------------------------------------- */

AK_TEST(png_round_trip) {
    const int W = 37, H = 23;
    uint8_t* a = (uint8_t*)malloc(W * H * 4);
    uint8_t* b = (uint8_t*)calloc(W * H * 4, 1);
    ak_rng rng = ak_rng_make(3);
    for (int i = 0; i < W * H * 4; ++i) a[i] = (uint8_t)(ak_rng_u32(&rng) >> 24);
    ak_image ia = {.pixels = a, .width = W, .height = H}, ib = {.pixels = b, .width = W, .height = H};
    AK_CHECK_EQ(ak_png_write("raster_rt.png", &ia), AK_OK);
    int w = 0, h = 0;
    AK_CHECK_EQ(ak_png_info("raster_rt.png", &w, &h), AK_OK);
    AK_CHECK_EQ(w, W);
    AK_CHECK_EQ(h, H);
    AK_CHECK_EQ(ak_png_read("raster_rt.png", &ib), AK_OK);
    AK_CHECK(memcmp(a, b, W * H * 4) == 0);
    ak_image small = {.pixels = b, .width = W - 1, .height = H};
    AK_CHECK_EQ(ak_png_read("raster_rt.png", &small), AK_ERR_BAD_ARG);
    AK_CHECK_EQ(ak_png_read("does/not/exist.png", &ib), AK_ERR_IO);
    FILE* f = fopen("raster_bad.png", "wb");
    if (f) {
        fputs("not a png at all", f);
        fclose(f);
    }
    AK_CHECK_EQ(ak_png_info("raster_bad.png", &w, &h), AK_ERR_PARSE);
    AK_CHECK_EQ(ak_png_write("no_such_dir/x.png", &ia), AK_ERR_IO);
    AK_CHECK(ak_image_format_available(AK_IMAGE_FORMAT_PNG));
    AK_CHECK(ak_image_format_available(AK_IMAGE_FORMAT_GIF));
    AK_CHECK(!ak_image_format_available(AK_IMAGE_FORMAT_MP4));
    free(a);
    free(b);
}

AK_TEST(gif_round_trip) {
    const int W = 40, H = 30, F = 3;
    uint8_t* a = (uint8_t*)malloc(W * H * 4);
    uint8_t* b = (uint8_t*)malloc(W * H * 4);
    ak_image ia = {.pixels = a, .width = W, .height = H}, ib = {.pixels = b, .width = W, .height = H};
    ak_gif_writer* gw = NULL;
    AK_CHECK_EQ(ak_gif_writer_create("raster_rt.gif", &(ak_gif_desc){.width = W, .height = H, .no_dither = true}, NULL,
                                     &gw),
                AK_OK);
    /* frames with at most 200 distinct colours, each alone in its 5-bit cell: exact round trip */
    for (int f = 0; f < F; ++f) {
        for (int y = 0; y < H; ++y)
            for (int x = 0; x < W; ++x) {
                uint8_t* p = ak_image_pixel(&ia, x, y);
                int k = ((x / 4) + (y / 3) * 10 + f * 7) % 200;
                p[0] = (uint8_t)((k % 8) * 32 + 4);
                p[1] = (uint8_t)(((k / 8) % 5) * 48 + 12);
                p[2] = (uint8_t)((k / 40) * 40 + 20);
                p[3] = 255;
            }
        AK_CHECK_EQ(ak_gif_writer_add_frame(gw, &ia), AK_OK);
    }
    AK_CHECK_EQ(ak_gif_writer_finish(gw), AK_OK);
    int w = 0, h = 0, n = 0;
    AK_CHECK_EQ(ak_gif_info("raster_rt.gif", &w, &h, &n), AK_OK);
    AK_CHECK_EQ(w, W);
    AK_CHECK_EQ(h, H);
    AK_CHECK_EQ(n, F);
    AK_CHECK_EQ(ak_gif_read_frame("raster_rt.gif", F - 1, &ib), AK_OK);
    AK_CHECK(memcmp(a, b, W * H * 4) == 0); /* the last frame written is still in a */
    AK_CHECK_EQ(ak_gif_read_frame("raster_rt.gif", F, &ib), AK_ERR_BAD_INDEX);

    /* a smooth gradient (more colours than a palette holds) stays close on average */
    AK_CHECK_EQ(ak_gif_writer_create("raster_grad.gif", &(ak_gif_desc){.width = W, .height = H}, NULL, &gw), AK_OK);
    for (int y = 0; y < H; ++y)
        for (int x = 0; x < W; ++x) {
            uint8_t* p = ak_image_pixel(&ia, x, y);
            p[0] = (uint8_t)(x * 255 / (W - 1));
            p[1] = (uint8_t)(y * 255 / (H - 1));
            p[2] = (uint8_t)((x + y) * 3);
            p[3] = 255;
        }
    AK_CHECK_EQ(ak_gif_writer_add_frame(gw, &ia), AK_OK);
    AK_CHECK_EQ(ak_gif_writer_finish(gw), AK_OK);
    AK_CHECK_EQ(ak_gif_read_frame("raster_grad.gif", 0, &ib), AK_OK);
    double err = 0;
    for (int i = 0; i < W * H * 4; ++i) err += fabs((double)a[i] - b[i]);
    AK_CHECK(err / (W * H * 3) < 6.0);

    /* errors */
    AK_CHECK_EQ(ak_gif_writer_create("raster_x.gif", &(ak_gif_desc){.width = 0, .height = 5}, NULL, &gw), AK_ERR_BAD_ARG);
    AK_CHECK(gw == NULL);
    AK_CHECK_EQ(ak_gif_writer_create("no_such_dir/x.gif", &(ak_gif_desc){.width = 4, .height = 4}, NULL, &gw), AK_ERR_IO);
    AK_CHECK_EQ(ak_gif_info("raster_rt.png", &w, &h, &n), AK_ERR_PARSE);
    AK_CHECK_EQ(ak_gif_info("does/not/exist.gif", &w, &h, &n), AK_ERR_IO);
    AK_CHECK_EQ(ak_gif_writer_finish(NULL), AK_ERR_NULL_ARG);
    AK_CHECK_EQ(ak_gif_writer_create("raster_empty.gif", &(ak_gif_desc){.width = 4, .height = 4}, NULL, &gw), AK_OK);
    AK_CHECK_EQ(ak_gif_writer_finish(gw), AK_ERR_EMPTY);
    AK_CHECK_EQ(ak_gif_info("raster_empty.gif", &w, &h, &n), AK_OK);
    AK_CHECK_EQ(n, 1);
    free(a);
    free(b);
}

/* Copy the first len bytes of src to dst. */
static bool copy_prefix(const char* src, const char* dst, long len) {
    FILE* f = fopen(src, "rb");
    if (!f) return false;
    char* buf = (char*)malloc((size_t)len + 1);
    size_t got = fread(buf, 1, (size_t)len, f);
    fclose(f);
    FILE* g = fopen(dst, "wb");
    if (!g) {
        free(buf);
        return false;
    }
    fwrite(buf, 1, got, g);
    fclose(g);
    free(buf);
    return true;
}

static long file_size(const char* path) {
    FILE* f = fopen(path, "rb");
    if (!f) return -1;
    fseek(f, 0, SEEK_END);
    long n = ftell(f);
    fclose(f);
    return n;
}

static ak_result write_small_gif(const ak_image* img) {
    ak_gif_writer* w = NULL;
    ak_result r = ak_gif_writer_create("raster_trunc.gif", &(ak_gif_desc){.width = img->width, .height = img->height},
                                       NULL, &w);
    if (r != AK_OK) return r;
    r = ak_gif_writer_add_frame(w, img);
    ak_result f = ak_gif_writer_finish(w);
    return r != AK_OK ? r : f;
}

AK_TEST(truncated_files_give_errors_not_crashes) {
    /* small valid files, then every prefix: readers must fail cleanly (ASan/UBSan watch) */
    enum { W = 9, H = 7 };
    uint8_t px[W * H * 4], back[W * H * 4];
    for (int i = 0; i < W * H * 4; ++i) px[i] = (uint8_t)(i * 37);
    ak_image img = {.pixels = px, .width = W, .height = H}, out = {.pixels = back, .width = W, .height = H};
    AK_CHECK_EQ(ak_png_write("raster_trunc.png", &img), AK_OK);
    AK_CHECK_EQ(write_small_gif(&img), AK_OK);
    const char* files[2] = {"raster_trunc.png", "raster_trunc.gif"};
    for (int f = 0; f < 2; ++f) {
        long n = file_size(files[f]);
        AK_CHECK(n > 20);
        int ok_prefixes = 0;
        for (long len = 0; len < n; ++len) {
            AK_CHECK(copy_prefix(files[f], "raster_cut.bin", len));
            ak_result r;
            int w = 0, h = 0, c = 0;
            if (f == 0) {
                r = ak_png_info("raster_cut.bin", &w, &h);
                if (r == AK_OK) r = ak_png_read("raster_cut.bin", &out);
            } else {
                r = ak_gif_info("raster_cut.bin", &w, &h, &c);
                if (r == AK_OK) r = ak_gif_read_frame("raster_cut.bin", 0, &out);
            }
            AK_CHECK(r == AK_OK || r == AK_ERR_PARSE || r == AK_ERR_BAD_ARG);
            if (r == AK_OK) {
                /* only the end marker (PNG's 12-byte IEND chunk, GIF's 1-byte trailer) may be
                   missing, and then the pixels must be the real ones */
                ++ok_prefixes;
                AK_CHECK_MSG(len >= n - 12, "%s: prefix of %ld of %ld bytes decoded", files[f], len, n);
                if (f == 0) AK_CHECK(memcmp(back, px, sizeof px) == 0);
            }
        }
        AK_CHECK(ok_prefixes <= 12);
    }
}

/* ---- bad input --------------------------------------------------------------------------------- */

AK_TEST(bad_input_codes) {
    ak_raster* r = (ak_raster*)1;
    AK_CHECK_EQ(ak_raster_create(NULL, NULL, &r), AK_ERR_NULL_ARG);
    AK_CHECK(r == NULL);
    ak_raster_desc zero = {0};
    AK_CHECK_EQ(ak_raster_create(&zero, NULL, &r), AK_ERR_BAD_ARG);
    AK_CHECK_EQ(ak_raster_create(&(ak_raster_desc){.width = 8, .height = 8, .supersample = 5}, NULL, &r), AK_ERR_BAD_ARG);
    AK_CHECK_EQ(ak_raster_create(&(ak_raster_desc){.width = 8, .height = -1}, NULL, &r), AK_ERR_BAD_ARG);
    AK_CHECK_EQ(ak_raster_create(&(ak_raster_desc){.width = 8, .height = 8, .thread_count = 65}, NULL, &r),
                AK_ERR_BAD_ARG);
    ak_raster_desc res = ak_raster_desc_resolved(&(ak_raster_desc){.width = 8, .height = 8});
    AK_CHECK_EQ(res.supersample, 1);
    AK_CHECK_EQ(res.thread_count, 1);
    ak_raster_destroy(NULL);
    ak_raster_clear(NULL, ak_vec4_make(0, 0, 0, 1), ak_vec4_make(0, 0, 0, 1));

    target t;
    AK_CHECK(target_make(&t, 16, 16, 2, 2));
    ak_raster_camera cam = ak_raster_camera_perspective(ak_vec3_make(0, 0, 3), ak_vec3_zero(), ak_radians(60), 1, 0.1f, 10);
    ak_vec3 p[4] = {{-1, -1, 0}, {1, -1, 0}, {0, 1, 0}, {0, 0, 0}};
    uint32_t bad_idx[3] = {0, 1, 9}, four[4] = {0, 1, 2, 3};
    ak_raster_mesh m = {.positions = {p, 3}};
    AK_CHECK_EQ(ak_raster_draw_mesh(NULL, &cam, &m), AK_ERR_NULL_ARG);
    AK_CHECK_EQ(ak_raster_draw_mesh(t.r, NULL, &m), AK_ERR_NULL_ARG);
    AK_CHECK_EQ(ak_raster_draw_mesh(t.r, &cam, NULL), AK_ERR_NULL_ARG);
    ak_raster_mesh empty = {0};
    AK_CHECK_EQ(ak_raster_draw_mesh(t.r, &cam, &empty), AK_ERR_NULL_ARG);
    m.indices = (ak_u32_cspan){bad_idx, 3};
    AK_CHECK_EQ(ak_raster_draw_mesh(t.r, &cam, &m), AK_ERR_BAD_INDEX);
    m.indices = (ak_u32_cspan){four, 4};
    AK_CHECK_EQ(ak_raster_draw_mesh(t.r, &cam, &m), AK_ERR_BAD_ARG);
    m.indices = (ak_u32_cspan){NULL, 0};
    m.normals = (ak_vec3_cspan){p, 2};
    AK_CHECK_EQ(ak_raster_draw_mesh(t.r, &cam, &m), AK_ERR_BAD_ARG);
    m.normals = (ak_vec3_cspan){NULL, 0};
    m.shading = (ak_shading)42;
    AK_CHECK_EQ(ak_raster_draw_mesh(t.r, &cam, &m), AK_ERR_BAD_ARG);
    m.shading = AK_SHADING_DEFAULT;
    ak_raster_camera nan_cam = cam;
    nan_cam.view.m[0] = NAN;
    AK_CHECK_EQ(ak_raster_draw_mesh(t.r, &nan_cam, &m), AK_ERR_BAD_DATA);
    /* a NaN vertex skips its triangle only; the image stays finite and the other draws */
    ak_vec3 q[6] = {{NAN, 0, 0}, {1, 0, 0}, {0, 1, 0}, {-1, -1, 0}, {1, -1, 0}, {0, 1, 0}};
    ak_raster_mesh mq = {.positions = {q, 6}, .shading = AK_SHADING_UNLIT, .material = {.color = {1, 1, 1, 1}}};
    ak_raster_clear(t.r, ak_vec4_make(0, 0, 0, 1), ak_vec4_make(0, 0, 0, 1));
    AK_CHECK_EQ(ak_raster_draw_mesh(t.r, &cam, &mq), AK_OK);
    ak_raster_resolve(t.r, &t.img);
    AK_CHECK_EQ(at(&t, 8, 9)[0], 255);
    /* huge (but finite) coordinates: clipped by the guard band, no crash */
    ak_vec3 big[3] = {{-1e30f, -1, 0}, {1e30f, -1, 0}, {0, 1e30f, -1}};
    ak_raster_mesh mb = {.positions = {big, 3}};
    AK_CHECK_EQ(ak_raster_draw_mesh(t.r, &cam, &mb), AK_OK);
    ak_raster_lines l = {.positions = {p, 3}};
    AK_CHECK_EQ(ak_raster_draw_lines(t.r, &cam, &l), AK_OK); /* odd count: the last point is ignored */
    l.indices = (ak_u32_cspan){bad_idx, 3};
    AK_CHECK_EQ(ak_raster_draw_lines(t.r, &cam, &l), AK_ERR_BAD_ARG);
    l.indices = (ak_u32_cspan){bad_idx + 1, 2};
    AK_CHECK_EQ(ak_raster_draw_lines(t.r, &cam, &l), AK_ERR_BAD_INDEX);
    ak_raster_points pts = {0};
    AK_CHECK_EQ(ak_raster_draw_points(t.r, &cam, &pts), AK_ERR_NULL_ARG);
    ak_raster_lines zero_lines = {0};
    AK_CHECK_EQ(ak_raster_draw_lines(t.r, &cam, &zero_lines), AK_ERR_NULL_ARG);
    ak_raster_ground zero_ground = {0}; /* every field zero is a valid default ground */
    AK_CHECK_EQ(ak_raster_draw_ground(t.r, &cam, &zero_ground), AK_OK);
    ak_raster_ground g = {.half_extent = NAN};
    AK_CHECK_EQ(ak_raster_draw_ground(t.r, &cam, &g), AK_ERR_BAD_ARG);
    g = (ak_raster_ground){.caster_count = 1};
    AK_CHECK_EQ(ak_raster_draw_ground(t.r, &cam, &g), AK_ERR_NULL_ARG);
    ak_image wrong = {.pixels = t.px, .width = 8, .height = 16};
    AK_CHECK_EQ(ak_raster_resolve(t.r, &wrong), AK_ERR_BAD_ARG);
    AK_CHECK_EQ(ak_raster_resolve(t.r, NULL), AK_ERR_NULL_ARG);
    AK_CHECK_EQ(ak_raster_draw_text(t.r, 0, 0, NULL, 1, ak_vec4_make(1, 1, 1, 1)), AK_ERR_NULL_ARG);
    /* huge but finite 2D coordinates and sizes: clipped, no overflow (UBSan watches) */
    AK_CHECK_EQ(ak_image_fill_rect(&t.img, -1e30f, -1e30f, 3e30f, 3e30f, ak_vec4_make(1, 0, 0, 1)), AK_OK);
    AK_CHECK_EQ(ak_image_fill_rect(&t.img, 1e30f, 1e30f, 1, 1, ak_vec4_make(1, 0, 0, 1)), AK_OK);
    AK_CHECK_EQ(ak_image_draw_line(&t.img, ak_vec2_make(-1e30f, 0), ak_vec2_make(1e30f, 5), 1e30f, ak_vec4_make(1, 1, 1, 1)),
                AK_OK);
    AK_CHECK_EQ(ak_image_draw_disc(&t.img, ak_vec2_make(1e30f, -1e30f), 1e30f, ak_vec4_make(1, 1, 1, 1), 1e30f,
                                   ak_vec4_make(0, 0, 0, 1)),
                AK_OK);
    AK_CHECK_EQ(ak_image_draw_text(&t.img, 2147483000, -2147483000, "overflow?", 64, ak_vec4_make(1, 1, 1, 1)), AK_OK);
    AK_CHECK_EQ(ak_raster_draw_text(t.r, 2147483000, 0, "x", 3, ak_vec4_make(1, 1, 1, 1)), AK_OK);
    ak_raster_points huge_pt = {.positions = {p, 1}, .radius = 1e30f, .outline = 1e30f};
    AK_CHECK_EQ(ak_raster_draw_points(t.r, &cam, &huge_pt), AK_OK);
    ak_raster_lines huge_ln = {.positions = {p, 2}, .width = 1e30f};
    AK_CHECK_EQ(ak_raster_draw_lines(t.r, &cam, &huge_ln), AK_OK);
    ak_raster_ground soft = {.shadow_softness = 1e30f, .casters = &mq, .caster_count = 1};
    AK_CHECK_EQ(ak_raster_draw_ground(t.r, &cam, &soft), AK_OK);
    ak_vec3 far_tri[3] = {{1e30f, 0, 0}, {-1e30f, 0, 1e30f}, {0, 1e30f, 0}};
    ak_raster_mesh far_caster = {.positions = {far_tri, 3}};
    soft.casters = &far_caster;
    AK_CHECK_EQ(ak_raster_draw_ground(t.r, &cam, &soft), AK_OK);
    ak_image zero_img = {.pixels = t.px, .width = 0, .height = 4};
    AK_CHECK_EQ(ak_image_fill(&zero_img, ak_vec4_make(1, 1, 1, 1)), AK_ERR_BAD_ARG);
    AK_CHECK_EQ(ak_png_write("x.png", &zero_img), AK_ERR_BAD_ARG);
    ak_vec3 out;
    AK_CHECK(!ak_raster_camera_project(&cam, 16, 16, ak_vec3_make(0, 0, 5), &out)); /* behind */
    AK_CHECK(!ak_raster_camera_project(&cam, 16, 16, ak_vec3_make(NAN, 0, 0), &out));
    target_free(&t);
}

/* frame_rate: whole-centisecond delays whose running sum stays within half a centisecond of
 * k * 100 / rate (24 fps: 4 and 5 alternate; 24 frames last exactly 1 s). */
AK_TEST(gif_frame_rate_delays) {
    uint8_t px[8 * 8 * 4];
    memset(px, 128, sizeof px);
    ak_image img = {.pixels = px, .width = 8, .height = 8};
    const float rates[3] = {24.0f, 12.5f, 30.0f};
    for (int r = 0; r < 3; ++r) {
        ak_gif_writer* gw = NULL;
        AK_CHECK_EQ(ak_gif_writer_create("raster_rate.gif", &(ak_gif_desc){.width = 8, .height = 8, .frame_rate = rates[r]},
                                         NULL, &gw),
                    AK_OK);
        for (int f = 0; f < 48; ++f) {
            px[(f % 64) * 4] = (uint8_t)(f * 5); /* a change per frame */
            AK_CHECK_EQ(ak_gif_writer_add_frame(gw, &img), AK_OK);
        }
        AK_CHECK_EQ(ak_gif_writer_finish(gw), AK_OK);
        int d[64];
        AK_CHECK_EQ(ref_gif_delays("raster_rate.gif", d, 64), 48);
        long sum = 0;
        for (int k = 0; k < 48; ++k) {
            sum += d[k];
            double want = 100.0 * (k + 1) / rates[r];
            AK_CHECK_MSG(fabs((double)sum - want) <= 0.5 + 1e-9, "%g fps: frame %d ends at %ld cs, want %.2f", (double)rates[r],
                         k, sum, want);
            AK_CHECK(d[k] == (int)floor(100.0 / rates[r]) || d[k] == (int)ceil(100.0 / rates[r]));
        }
    }
    /* no rate: delay_cs as before */
    ak_gif_writer* gw = NULL;
    AK_CHECK_EQ(ak_gif_writer_create("raster_rate.gif", &(ak_gif_desc){.width = 8, .height = 8, .delay_cs = 7}, NULL, &gw), AK_OK);
    AK_CHECK_EQ(ak_gif_writer_add_frame(gw, &img), AK_OK);
    AK_CHECK_EQ(ak_gif_writer_add_frame(gw, &img), AK_OK);
    AK_CHECK_EQ(ak_gif_writer_finish(gw), AK_OK);
    int d[4];
    AK_CHECK_EQ(ref_gif_delays("raster_rate.gif", d, 4), 2);
    AK_CHECK(d[0] == 7 && d[1] == 7);
}

/* Delta frames: a still gradient with a small square moving over it. The file is a fraction
 * of the whole-frame one, every decoded frame stays close to its source, and where the square
 * has left the background is as close as in the first frame (no leftovers, no palette
 * patchwork). */
AK_TEST(gif_delta_frames) {
    enum { W = 96, H = 64, F = 24 };
    static uint8_t src[F][W * H * 4], dec[W * H * 4];
    for (int f = 0; f < F; ++f)
        for (int y = 0; y < H; ++y)
            for (int x = 0; x < W; ++x) {
                uint8_t* p = src[f] + ((size_t)y * W + (size_t)x) * 4;
                bool square = x >= 3 * f && x < 3 * f + 8 && y >= 20 && y < 28;
                p[0] = square ? 230 : (uint8_t)(60 + x);
                p[1] = square ? 40 : (uint8_t)(80 + y);
                p[2] = square ? 30 : (uint8_t)(200 - x / 2);
                p[3] = 255;
            }
    const char* names[2] = {"raster_delta.gif", "raster_whole.gif"};
    long size[2];
    for (int v = 0; v < 2; ++v) {
        ak_gif_writer* gw = NULL;
        AK_CHECK_EQ(ak_gif_writer_create(names[v], &(ak_gif_desc){.width = W, .height = H, .no_delta = v == 1}, NULL, &gw), AK_OK);
        for (int f = 0; f < F; ++f) AK_CHECK_EQ(ak_gif_writer_add_frame(gw, &(ak_image){.pixels = src[f], .width = W, .height = H}), AK_OK);
        AK_CHECK_EQ(ak_gif_writer_finish(gw), AK_OK);
        FILE* fp = fopen(names[v], "rb");
        AK_CHECK(fp != NULL);
        if (!fp) return;
        fseek(fp, 0, SEEK_END);
        size[v] = ftell(fp);
        fclose(fp);
    }
    AK_CHECK_MSG(size[0] * 3 < size[1], "delta %ld bytes, whole frames %ld", size[0], size[1]);
    ak_image out = {.pixels = dec, .width = W, .height = H};
    double first_bg = 0.0;
    for (int f = 0; f < F; ++f) {
        AK_CHECK_EQ(ak_gif_read_frame(names[0], f, &out), AK_OK);
        double err = 0.0, bg = 0.0;
        int nbg = 0;
        for (int y = 0; y < H; ++y)
            for (int x = 0; x < W; ++x) {
                const uint8_t* a = src[f] + ((size_t)y * W + (size_t)x) * 4;
                const uint8_t* b = dec + ((size_t)y * W + (size_t)x) * 4;
                double e = (fabs((double)a[0] - b[0]) + fabs((double)a[1] - b[1]) + fabs((double)a[2] - b[2])) / 3.0;
                err += e;
                if (y >= 20 && y < 28 && x < 3 * f) bg += e, ++nbg; /* where the square has been */
                if (f == 0 && y >= 20 && y < 28 && x >= 8) bg += e, ++nbg;
            }
        AK_CHECK_MSG(err / (W * H) < 6.0, "frame %d: mean error %.2f", f, err / (W * H));
        if (nbg) bg /= nbg;
        if (f == 0) first_bg = bg;
        else AK_CHECK_MSG(bg <= first_bg + 1.0, "frame %d: the square's trail differs by %.2f (first frame %.2f)", f, bg, first_bg);
        /* the square itself is exact enough to be seen */
        const uint8_t* c = dec + ((size_t)24 * W + (size_t)(3 * f + 4)) * 4;
        AK_CHECK(c[0] > 200 && c[1] < 80 && c[2] < 80);
    }
}

/* ---- sprites ------------------------------------------------------------------------------- */

/* A w x h texture of one opaque colour per sprite-sheet frame (cols x rows frames). */
static uint8_t* sheet_make(ak_image* img, int cols, int rows, int fw, int fh) {
    img->width = cols * fw, img->height = rows * fh, img->stride = 0;
    img->pixels = (uint8_t*)calloc((size_t)img->width * (size_t)img->height * 4, 1);
    if (!img->pixels) return NULL;
    for (int y = 0; y < img->height; ++y)
        for (int x = 0; x < img->width; ++x) {
            int f = (y / fh) * cols + x / fw;
            uint8_t* p = ak_image_pixel(img, x, y);
            p[0] = (uint8_t)(20 * f), p[1] = (uint8_t)(250 - 20 * f), p[2] = (uint8_t)(7 * f), p[3] = 255;
        }
    return img->pixels;
}

AK_TEST(sprite_billboard_faces_the_camera) {
    /* An oblique camera: the quad must still project to an axis-aligned square of side
     * size * (H / 2) / (d tan(fovy / 2)) pixels centred on the image centre (pinhole formula). */
    enum { W = 96, H = 96 };
    target t;
    AK_CHECK(target_make(&t, W, H, 1, 1));
    const ak_vec3 eye = ak_vec3_make(3, 2, 4);
    const double d = sqrt(9.0 + 4.0 + 16.0), fovy = 40.0 * 3.14159265358979323846 / 180.0, size = 0.6;
    ak_raster_camera cam = ak_raster_camera_perspective(eye, ak_vec3_zero(), (float)fovy, 1, 0.1f, 20);
    ak_raster_clear(t.r, ak_vec4_make(0, 0, 0, 1), ak_vec4_make(0, 0, 0, 1));
    uint8_t tex_px[4 * 4 * 4];
    ak_image tex = {.pixels = tex_px, .width = 4, .height = 4};
    AK_CHECK_EQ(ak_sprite_texture_generate(AK_SPRITE_TEXTURE_SOLID, 0, &tex), AK_OK);
    ak_vec3 p = ak_vec3_zero();
    ak_raster_sprites sp = {.positions = {&p, 1}, .size = (float)size, .texture = &tex, .blend = AK_BLEND_OPAQUE};
    AK_CHECK_EQ(ak_raster_draw_sprites(t.r, &cam, &sp), AK_OK);
    ak_raster_resolve(t.r, &t.img);
    int x0 = W, x1 = -1, y0 = H, y1 = -1, n = 0;
    for (int y = 0; y < H; ++y)
        for (int x = 0; x < W; ++x)
            if (at(&t, x, y)[0] > 128) {
                x0 = x < x0 ? x : x0, x1 = x > x1 ? x : x1, y0 = y < y0 ? y : y0, y1 = y > y1 ? y : y1;
                ++n;
            }
    const double side = size * (H / 2.0) / (d * tan(fovy / 2.0));
    AK_CHECK_NEAR((double)(x1 - x0 + 1), side, 1.0);
    AK_CHECK_NEAR((double)(y1 - y0 + 1), side, 1.0);
    AK_CHECK_EQ(n, (x1 - x0 + 1) * (y1 - y0 + 1)); /* a filled axis-aligned rectangle */
    AK_CHECK_NEAR(0.5 * (x0 + x1 + 1), W / 2.0, 0.75);
    AK_CHECK_NEAR(0.5 * (y0 + y1 + 1), H / 2.0, 0.75);
    target_free(&t);
}

AK_TEST(sprite_blending_back_to_front) {
    /* Three half-transparent sprites at one pixel, given front to back: sorted, the result is
     * the over-composite of the known colours far to near, computed here; unsorted it is not. */
    target t;
    AK_CHECK(target_make(&t, 32, 32, 1, 1));
    ak_raster_camera cam = ak_raster_camera_perspective(ak_vec3_make(0, 0, 5), ak_vec3_zero(), ak_radians(50), 1, 0.1f, 20);
    uint8_t tex_px[2 * 2 * 4];
    ak_image tex = {.pixels = tex_px, .width = 2, .height = 2};
    AK_CHECK_EQ(ak_sprite_texture_generate(AK_SPRITE_TEXTURE_SOLID, 0, &tex), AK_OK);
    ak_vec3 pos[3] = {{0, 0, 1}, {0, 0, 0}, {0, 0, -1}}; /* near, middle, far */
    ak_vec4 col[3] = {{1, 0, 0, 0.5f}, {0, 1, 0, 0.6f}, {0, 0, 1, 0.7f}};
    float depth[3];
    uint32_t order[3];
    AK_CHECK_EQ(ak_raster_sprites_sort(&cam, (ak_vec3_cspan){pos, 3}, (ak_f32_span){depth, 3}, (ak_u32_span){order, 3}), AK_OK);
    AK_CHECK_EQ(order[0], 2u);
    AK_CHECK_EQ(order[1], 1u);
    AK_CHECK_EQ(order[2], 0u);
    const double bg[3] = {40, 80, 120};
    double expect[3] = {bg[0], bg[1], bg[2]};
    for (int k = 2; k >= 0; --k) { /* far to near, in doubles on 0..255 */
        const double c[3] = {col[k].x * 255.0, col[k].y * 255.0, col[k].z * 255.0}, a = col[k].w;
        for (int ch = 0; ch < 3; ++ch) expect[ch] = c[ch] * a + expect[ch] * (1.0 - a);
    }
    for (int sorted = 0; sorted < 2; ++sorted) {
        ak_vec4 b = ak_vec4_make(40.0f / 255.0f, 80.0f / 255.0f, 120.0f / 255.0f, 1);
        ak_raster_clear(t.r, b, b);
        ak_raster_sprites sp = {.positions = {pos, 3}, .size = 1.0f, .colors = {col, 3}, .texture = &tex};
        if (sorted) sp.order = (ak_u32_cspan){order, 3};
        AK_CHECK_EQ(ak_raster_draw_sprites(t.r, &cam, &sp), AK_OK);
        ak_raster_resolve(t.r, &t.img);
        const uint8_t* px = at(&t, 16, 16);
        double err = 0;
        for (int ch = 0; ch < 3; ++ch) err = fmax(err, fabs(px[ch] - expect[ch]));
        if (sorted) AK_CHECK_MSG(err <= 2.0, "sorted composite off by %.1f levels", err);
        else AK_CHECK_MSG(err > 20.0, "the unsorted order should differ (off by only %.1f)", err);
    }
    /* depth tested against opaque geometry: a sprite behind an opaque triangle is hidden */
    ak_raster_clear(t.r, ak_vec4_make(0, 0, 0, 1), ak_vec4_make(0, 0, 0, 1));
    ak_vec3 tri[3] = {{-2, -2, 0}, {2, -2, 0}, {0, 2, 0}};
    ak_raster_mesh m = unlit_tri(tri, ak_vec4_make(0, 0, 1, 1));
    AK_CHECK_EQ(ak_raster_draw_mesh(t.r, &cam, &m), AK_OK);
    ak_vec3 behind = {0, 0, -1}, front = {0.3f, 0, 1};
    ak_vec4 red = {1, 0, 0, 1};
    ak_raster_sprites hidden = {.positions = {&behind, 1}, .size = 0.5f, .color = red, .texture = &tex};
    AK_CHECK_EQ(ak_raster_draw_sprites(t.r, &cam, &hidden), AK_OK);
    ak_raster_resolve(t.r, &t.img);
    AK_CHECK_EQ(at(&t, 16, 16)[0], 0);
    AK_CHECK_EQ(at(&t, 16, 16)[2], 255);
    ak_raster_sprites shown = {.positions = {&front, 1}, .size = 0.5f, .color = red, .texture = &tex};
    AK_CHECK_EQ(ak_raster_draw_sprites(t.r, &cam, &shown), AK_OK);
    ak_vec3 fp;
    AK_CHECK(ak_raster_camera_project(&cam, 32, 32, front, &fp));
    ak_raster_resolve(t.r, &t.img);
    AK_CHECK_EQ(at(&t, (int)fp.x, (int)fp.y)[0], 255);
    target_free(&t);
}

AK_TEST(sprite_sheet_frame_and_textures) {
    target t;
    AK_CHECK(target_make(&t, 32, 32, 1, 1));
    ak_raster_camera cam = ak_raster_camera_perspective(ak_vec3_make(0, 0, 3), ak_vec3_zero(), ak_radians(50), 1, 0.1f, 20);
    ak_image sheet;
    AK_CHECK(sheet_make(&sheet, 4, 2, 8, 8) != NULL);
    ak_vec3 p = ak_vec3_zero();
    for (uint32_t f = 0; f < 10; ++f) { /* 8 frames: 8 and 9 wrap to 0 and 1 */
        ak_raster_clear(t.r, ak_vec4_make(0, 0, 0, 1), ak_vec4_make(0, 0, 0, 1));
        ak_raster_sprites sp = {.positions = {&p, 1}, .size = 1.0f, .frames = {&f, 1}, .texture = &sheet,
                                .sheet_columns = 4, .sheet_rows = 2};
        AK_CHECK_EQ(ak_raster_draw_sprites(t.r, &cam, &sp), AK_OK);
        ak_raster_resolve(t.r, &t.img);
        const uint8_t* px = at(&t, 16, 16);
        const int k = (int)(f % 8);
        AK_CHECK_MSG(px[0] == 20 * k && px[1] == 250 - 20 * k && px[2] == 7 * k, "frame %u: got %d %d %d", f, px[0], px[1],
                     px[2]);
    }
    free(sheet.pixels);
    /* the soft disc: alpha (1 - r^2)^2, r from the texel centre */
    uint8_t dpx[16 * 16 * 4];
    ak_image disc = {.pixels = dpx, .width = 16, .height = 16};
    AK_CHECK_EQ(ak_sprite_texture_generate(AK_SPRITE_TEXTURE_DISC, 0, &disc), AK_OK);
    for (int y = 0; y < 16; y += 3)
        for (int x = 0; x < 16; x += 3) {
            double u = 2.0 * (x + 0.5) / 16.0 - 1.0, v = 2.0 * (y + 0.5) / 16.0 - 1.0, r2 = u * u + v * v;
            double a = r2 < 1.0 ? (1.0 - r2) * (1.0 - r2) : 0.0;
            AK_CHECK_NEAR((double)ak_image_pixel(&disc, x, y)[3], a * 255.0, 0.6);
        }
    uint8_t ppx[32 * 32 * 4];
    ak_image puff = {.pixels = ppx, .width = 32, .height = 32};
    AK_CHECK_EQ(ak_sprite_texture_generate(AK_SPRITE_TEXTURE_PUFF, 3, &puff), AK_OK);
    AK_CHECK(ak_image_pixel(&puff, 16, 16)[3] > 60);  /* dense middle */
    AK_CHECK_EQ(ak_image_pixel(&puff, 0, 0)[3], 0);   /* clear corners */
    /* bad input */
    AK_CHECK_EQ(ak_sprite_texture_generate(AK_SPRITE_TEXTURE_COUNT, 0, &puff), AK_ERR_BAD_ARG);
    uint32_t bad = 1;
    ak_raster_sprites sp = {.positions = {&p, 1}, .order = {&bad, 1}};
    AK_CHECK_EQ(ak_raster_draw_sprites(t.r, &cam, &sp), AK_ERR_BAD_INDEX);
    float nan_size = NAN;
    ak_raster_sprites nan_sp = {.positions = {&p, 1}, .sizes = {&nan_size, 1}};
    AK_CHECK_EQ(ak_raster_draw_sprites(t.r, &cam, &nan_sp), AK_OK); /* skipped, not drawn */
    target_free(&t);
}

/* A wide translucent rectangle (the viewer's HUD bars): every pixel against the blend's closed
 * form p + (c - p) * a (a = coverage x alpha; within 1 of it: float rounding), and bit for bit
 * against the same rectangle drawn as strips narrower than 64 pixels, which take the per-pixel
 * path (the wide one is served from per-byte tables, src/raster/raster_image.c). */
AK_TEST(fill_rect_translucent_matches_closed_form) {
    enum { W = 300, H = 9 };
    static uint8_t a_px[W * H * 4], b_px[W * H * 4], orig[W * H * 4];
    uint32_t seed = 12345u;
    for (size_t i = 0; i < sizeof orig; ++i) {
        seed = seed * 1664525u + 1013904223u;
        orig[i] = (uint8_t)(seed >> 24);
    }
    memcpy(a_px, orig, sizeof orig);
    memcpy(b_px, orig, sizeof orig);
    ak_image a = {.pixels = a_px, .width = W, .height = H},
             b = {.pixels = b_px, .width = W, .height = H};
    const ak_vec4 col =
        ak_vec4_make(40.0f / 255.0f, 200.0f / 255.0f, 1.0f, 153.0f / 255.0f); /* alpha 0.6 */
    const float x = 10.25f, y = 1.5f, w = 250.5f, h = 6.0f; /* rows 1..7, columns 10..260 */
    AK_CHECK_EQ(ak_image_fill_rect(&a, x, y, w, h, col), AK_OK);
    /* strips: [10.25, 60), [60, 110), ... [260, 260.75): the same coverage per pixel */
    AK_CHECK_EQ(ak_image_fill_rect(&b, x, y, 60.0f - x, h, col), AK_OK);
    for (float sx = 60.0f; sx < x + w; sx += 50.0f) {
        float ex = sx + 50.0f < x + w ? sx + 50.0f : x + w;
        AK_CHECK_EQ(ak_image_fill_rect(&b, sx, y, ex - sx, h, col), AK_OK);
    }
    AK_CHECK(memcmp(a_px, b_px, sizeof a_px) == 0);
    const double c[4] = {40, 200, 255, 255};
    int worst = 0, changed = 0;
    for (int py = 0; py < H; ++py)
        for (int px = 0; px < W; ++px) {
            double cx = fmin(px + 1.0, (double)x + w) - fmax((double)px, (double)x);
            double cy = fmin(py + 1.0, (double)y + h) - fmax((double)py, (double)y);
            cx = cx < 0 ? 0 : cx > 1 ? 1 : cx;
            cy = cy < 0 ? 0 : cy > 1 ? 1 : cy;
            double al = cx * cy * 153.0 / 255.0;
            for (int k = 0; k < 4; ++k) {
                size_t i = ((size_t)py * W + (size_t)px) * 4u + (size_t)k;
                double want = al > 0 ? orig[i] + (c[k] - orig[i]) * al : orig[i];
                int d = abs((int)a_px[i] - (int)floor(want + 0.5));
                if (d > worst) worst = d;
                if (a_px[i] != orig[i]) ++changed;
            }
        }
    AK_CHECK_MSG(worst <= 1 && changed > 4000, "worst %d, %d channel values changed", worst,
                 changed);
}

/* ak_raster_memory_size is the one allocation ak_raster_create asks for (an allocator that
 * records it), for several descs; a target made in a caller's block of that size draws as one
 * from the heap; out-of-range descs give 0. */
typedef struct one_block {
    unsigned char* mem;
    size_t cap, asked;
    int calls;
} one_block;

static void* one_block_alloc(size_t size, void* user) {
    one_block* b = (one_block*)user;
    b->asked = size;
    ++b->calls;
    return size <= b->cap ? b->mem : NULL;
}

static void one_block_free(void* ptr, void* user) { (void)ptr, (void)user; }

AK_TEST(memory_size_is_the_allocation) {
    const ak_raster_desc descs[3] = {{.width = 48, .height = 8}, {.width = 64, .height = 40, .supersample = 2},
                                     {.width = 300, .height = 200, .supersample = 3, .thread_count = 3}};
    for (int i = 0; i < 3; ++i) {
        const size_t need = ak_raster_memory_size(&descs[i]);
        one_block b = {malloc(need), need, 0, 0};
        const ak_allocator al = {.alloc = one_block_alloc, .free = one_block_free, .user = &b};
        ak_raster *r = NULL, *h = NULL;
        AK_CHECK_EQ(ak_raster_create(&descs[i], &al, &r), AK_OK);
        AK_CHECK_EQ(b.calls, 1);
        AK_CHECK_EQ(b.asked, need);
        AK_CHECK_EQ(ak_raster_create(&descs[i], NULL, &h), AK_OK);
        if (r && h) {
            const ak_raster_camera cam = ak_raster_camera_perspective(ak_vec3_make(0, 1, 4), ak_vec3_make(0, 0, 0),
                                                                      0.8f, (float)descs[i].width / (float)descs[i].height,
                                                                      0.1f, 50.0f);
            const ak_vec3 tri[3] = {{-1, 0, 0}, {1, 0, 0}, {0, 1.5f, 0}};
            const ak_raster_mesh m = {.positions = {tri, 3}};
            ak_raster_clear(r, ak_vec4_make(0, 0, 0, 1), ak_vec4_make(0, 0, 0, 1));
            ak_raster_clear(h, ak_vec4_make(0, 0, 0, 1), ak_vec4_make(0, 0, 0, 1));
            AK_CHECK_EQ(ak_raster_draw_mesh(r, &cam, &m), AK_OK);
            AK_CHECK_EQ(ak_raster_draw_mesh(h, &cam, &m), AK_OK);
            const size_t ss = descs[i].supersample ? (size_t)descs[i].supersample : 1u; /* samples */
            const size_t px = (size_t)descs[i].width * ss * (size_t)descs[i].height * ss;
            uint8_t* a = malloc(px * 4);
            uint8_t* c = malloc(px * 4);
            AK_CHECK_EQ(ak_raster_read_samples(r, (ak_u8_span){a, px * 4}, (ak_f32_span){0}), AK_OK);
            AK_CHECK_EQ(ak_raster_read_samples(h, (ak_u8_span){c, px * 4}, (ak_f32_span){0}), AK_OK);
            AK_CHECK(memcmp(a, c, px * 4) == 0);
            free(a);
            free(c);
        }
        ak_raster_destroy(r);
        ak_raster_destroy(h);
        free(b.mem);
    }
    const ak_raster_desc bad[3] = {{.width = 0, .height = 8}, {.width = 8, .height = 9000}, {.width = 8, .height = 8, .supersample = 5}};
    for (int i = 0; i < 3; ++i) AK_CHECK_EQ(ak_raster_memory_size(&bad[i]), 0u);
    AK_CHECK_EQ(ak_raster_memory_size(NULL), 0u);
}

int main(void) {
    AK_RUN(memory_size_is_the_allocation);
    AK_RUN(fill_rect_translucent_matches_closed_form);
    AK_RUN(coverage_matches_point_in_triangle);
    AK_RUN(shared_edges_quad_and_fan_cover_once);
    AK_RUN(depth_test_orders_by_distance);
    AK_RUN(read_samples_ids_and_depth);
    AK_RUN(near_plane_crossing_triangle_is_clipped_not_dropped);
    AK_RUN(cube_corners_where_projection_puts_them);
    AK_RUN(perspective_correct_interpolation);
    AK_RUN(lambert_diffuse_matches_formula);
    AK_RUN(model_matrix_moves_geometry);
    AK_RUN(back_face_culling_and_two_sided);
    AK_RUN(lines_and_points_respect_depth);
    AK_RUN(threads_give_identical_images);
    AK_RUN(threads_keep_order_when_segments_overflow);
    AK_RUN(supersampling_softens_edges);
    AK_RUN(text_glyphs_and_size);
    AK_RUN(png_round_trip);
    AK_RUN(gif_round_trip);
    AK_RUN(gif_frame_rate_delays);
    AK_RUN(gif_delta_frames);
    AK_RUN(truncated_files_give_errors_not_crashes);
    AK_RUN(bad_input_codes);
    AK_RUN(sprite_billboard_faces_the_camera);
    AK_RUN(sprite_blending_back_to_front);
    AK_RUN(sprite_sheet_frame_and_textures);
    return ak_test_finish();
}

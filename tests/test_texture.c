/* Base-colour textures across modules: PNG and JPEG decoding (images written here with libpng
 * and libjpeg, decoded, compared), broken images, glTF textures and samplers (warnings for
 * broken ones), the rasterizer's texturing against per-pixel references computed here
 * (ray-plane intersection for perspective, closed-form wrap modes), and textures surviving
 * glTF and OBJ export. */
#include <animkit/animkit.h>
#include <png.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#if __has_include(<jpeglib.h>)
#include <jpeglib.h>
#define HAVE_JPEG_WRITER 1
#endif

#include "ak_test.h"
#include "cli_test.h"

/* ---- helpers ------------------------------------------------------------------------------- */

static bool file_exists(const char* p) {
    FILE* f = fopen(p, "rb");
    if (f) fclose(f);
    return f != NULL;
}

static const char* asset(const char* rel) {
    static char buf[4][1200];
    static int k = 0;
    char* b = buf[k++ & 3];
    const char* dir = ak_test_assets_dir();
    snprintf(b, 1200, "%s/gltf/%.100s", dir ? dir : "(no assets)", rel);
    return b;
}

static uint8_t* png_encode(const uint8_t* px, int w, int h, uint32_t format, size_t* out_size) {
    png_image pi;
    memset(&pi, 0, sizeof pi);
    pi.version = PNG_IMAGE_VERSION;
    pi.width = (png_uint_32)w;
    pi.height = (png_uint_32)h;
    pi.format = format;
    png_alloc_size_t n = 0;
    if (!png_image_write_to_memory(&pi, NULL, &n, 0, px, 0, NULL)) return NULL;
    uint8_t* buf = malloc(n);
    if (!png_image_write_to_memory(&pi, buf, &n, 0, px, 0, NULL)) {
        free(buf);
        return NULL;
    }
    *out_size = n;
    return buf;
}

static uint32_t crc32_of(const uint8_t* p, size_t n) {
    uint32_t c = 0xFFFFFFFFu;
    for (size_t i = 0; i < n; ++i) {
        c ^= p[i];
        for (int k = 0; k < 8; ++k) c = (c >> 1) ^ (0xEDB88320u & (0u - (c & 1u)));
    }
    return c ^ 0xFFFFFFFFu;
}

static void put_be32(uint8_t* p, uint32_t v) {
    p[0] = (uint8_t)(v >> 24);
    p[1] = (uint8_t)(v >> 16);
    p[2] = (uint8_t)(v >> 8);
    p[3] = (uint8_t)v;
}

/* A PNG whose (valid, CRC-correct) header claims w x h pixels, followed by an empty IDAT. */
static size_t png_header_only(uint32_t w, uint32_t h, uint8_t out[64]) {
    static const uint8_t sig[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1A, '\n'};
    memcpy(out, sig, 8);
    uint8_t* c = out + 8;
    put_be32(c, 13);
    memcpy(c + 4, "IHDR", 4);
    put_be32(c + 8, w);
    put_be32(c + 12, h);
    c[16] = 8; /* depth */
    c[17] = 6; /* RGBA */
    c[18] = c[19] = c[20] = 0;
    put_be32(c + 21, crc32_of(c + 4, 17));
    uint8_t* e = c + 25;
    put_be32(e, 0);
    memcpy(e + 4, "IDAT", 4);
    put_be32(e + 8, crc32_of(e + 4, 4));
    return 8 + 25 + 12;
}

#ifdef HAVE_JPEG_WRITER
static uint8_t* jpeg_encode(const uint8_t* px, int w, int h, int comps, bool progressive,
                            size_t* out_size) {
    struct jpeg_compress_struct ci;
    struct jpeg_error_mgr err;
    ci.err = jpeg_std_error(&err);
    jpeg_create_compress(&ci);
    unsigned char* mem = NULL;
    unsigned long n = 0;
    jpeg_mem_dest(&ci, &mem, &n);
    ci.image_width = (JDIMENSION)w;
    ci.image_height = (JDIMENSION)h;
    ci.input_components = comps;
    ci.in_color_space = comps == 1 ? JCS_GRAYSCALE : JCS_RGB;
    jpeg_set_defaults(&ci);
    jpeg_set_quality(&ci, 100, TRUE);
    if (progressive) jpeg_simple_progression(&ci);
    jpeg_start_compress(&ci, TRUE);
    while (ci.next_scanline < ci.image_height) {
        JSAMPROW row = (JSAMPROW)(px + (size_t)ci.next_scanline * (size_t)w * (size_t)comps);
        jpeg_write_scanlines(&ci, &row, 1);
    }
    jpeg_finish_compress(&ci);
    jpeg_destroy_compress(&ci);
    uint8_t* copy = malloc(n);
    memcpy(copy, mem, n);
    free(mem);
    *out_size = n;
    return copy;
}
#endif

static char* b64(const uint8_t* d, size_t n) {
    static const char* a = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    char* o = malloc(4 * (n / 3 + 1) + 1);
    size_t k = 0;
    for (size_t i = 0; i < n; i += 3) {
        uint32_t v = (uint32_t)d[i] << 16 | (i + 1 < n ? (uint32_t)d[i + 1] << 8 : 0) |
                     (i + 2 < n ? d[i + 2] : 0);
        o[k++] = a[v >> 18 & 63];
        o[k++] = a[v >> 12 & 63];
        o[k++] = i + 1 < n ? a[v >> 6 & 63] : '=';
        o[k++] = i + 2 < n ? a[v & 63] : '=';
    }
    o[k] = 0;
    return o;
}

static int g_warnings = 0;
static char g_last_warning[1024];
static void count_warning(ak_log_level level, const char* msg, void* user) {
    (void)level;
    (void)user;
    ++g_warnings;
    snprintf(g_last_warning, sizeof g_last_warning, "%s", msg);
}

/* ---- decoders ------------------------------------------------------------------------------ */

AK_TEST(png_decode) {
    enum { W = 7, H = 5 };
    uint8_t px[W * H * 4];
    for (int i = 0; i < W * H * 4; ++i) px[i] = (uint8_t)(i * 37 + 11);
    size_t n = 0;
    uint8_t* png = png_encode(px, W, H, PNG_FORMAT_RGBA, &n);
    AK_CHECK(png != NULL);
    uint8_t* out = NULL;
    int w = 0, h = 0;
    AK_CHECK_EQ(ak_io_image_decode(png, n, 0, NULL, &out, &w, &h, NULL), AK_OK);
    AK_CHECK_EQ(w, W);
    AK_CHECK_EQ(h, H);
    AK_CHECK(out && memcmp(out, px, sizeof px) == 0);
    ak_io_image_free(NULL, out);
    free(png);
    /* 8-bit grey: expanded to r = g = b, opaque */
    uint8_t grey[W * H];
    for (int i = 0; i < W * H; ++i) grey[i] = (uint8_t)(i * 7);
    png = png_encode(grey, W, H, PNG_FORMAT_GRAY, &n);
    AK_CHECK_EQ(ak_io_image_decode(png, n, 0, NULL, &out, &w, &h, NULL), AK_OK);
    for (int i = 0; out && i < W * H; ++i) {
        AK_CHECK(out[4 * i] == grey[i] && out[4 * i + 1] == grey[i] && out[4 * i + 2] == grey[i]);
        AK_CHECK_EQ(out[4 * i + 3], 255);
    }
    ak_io_image_free(NULL, out);
    free(png);
}

AK_TEST(jpeg_decode) {
#ifdef HAVE_JPEG_WRITER
    enum { W = 24, H = 16 };
    uint8_t rgb[W * H * 3];
    for (int y = 0; y < H; ++y)
        for (int x = 0; x < W; ++x) {
            rgb[(y * W + x) * 3] = (uint8_t)(10 * x);
            rgb[(y * W + x) * 3 + 1] = (uint8_t)(15 * y);
            rgb[(y * W + x) * 3 + 2] = 128;
        }
    size_t n = 0;
    uint8_t* jpg = jpeg_encode(rgb, W, H, 3, false, &n);
    uint8_t* out = NULL;
    int w = 0, h = 0;
    ak_result r = ak_io_image_decode(jpg, n, 0, NULL, &out, &w, &h, NULL);
    if (r == AK_ERR_UNSUPPORTED) {
        free(jpg);
        AK_SKIP("this build has no JPEG decoder");
        return;
    }
    AK_CHECK_EQ(r, AK_OK);
    AK_CHECK_EQ(w, W);
    AK_CHECK_EQ(h, H);
    int worst = 0;
    for (int i = 0; out && i < W * H; ++i) {
        for (int k = 0; k < 3; ++k) {
            int d = abs((int)out[4 * i + k] - (int)rgb[3 * i + k]);
            worst = d > worst ? d : worst;
        }
        AK_CHECK_EQ(out[4 * i + 3], 255);
    }
    AK_CHECK_MSG(worst <= 8, "JPEG quality 100 differs by %d levels", worst); /* lossy, but close */
    ak_io_image_free(NULL, out);
    free(jpg);
    /* greyscale JPEG */
    uint8_t grey[W * H];
    for (int i = 0; i < W * H; ++i) grey[i] = (uint8_t)(i % W * 10);
    jpg = jpeg_encode(grey, W, H, 1, false, &n);
    AK_CHECK_EQ(ak_io_image_decode(jpg, n, 0, NULL, &out, &w, &h, NULL), AK_OK);
    worst = 0;
    for (int i = 0; out && i < W * H; ++i) {
        AK_CHECK(out[4 * i] == out[4 * i + 1] && out[4 * i] == out[4 * i + 2]);
        int d = abs((int)out[4 * i] - (int)grey[i]);
        worst = d > worst ? d : worst;
    }
    AK_CHECK(worst <= 4);
    ak_io_image_free(NULL, out);
    /* truncated: an error, not a crash or a partial image */
    ak_diag diag;
    AK_CHECK_EQ(ak_io_image_decode(jpg, n / 2, 0, NULL, &out, &w, &h, &diag), AK_ERR_PARSE);
    AK_CHECK(out == NULL && strstr(diag.message, "JPEG") != NULL);
    free(jpg);
    /* progressive: the same pixels; its coefficients count against the budget too */
    jpg = jpeg_encode(rgb, W, H, 3, true, &n);
    AK_CHECK_EQ(ak_io_image_decode(jpg, n, 0, NULL, &out, &w, &h, NULL), AK_OK);
    worst = 0;
    for (int i = 0; out && i < W * H; ++i)
        for (int k = 0; k < 3; ++k)
            worst = abs((int)out[4 * i + k] - (int)rgb[3 * i + k]) > worst
                        ? abs((int)out[4 * i + k] - (int)rgb[3 * i + k])
                        : worst;
    AK_CHECK(worst <= 8);
    ak_io_image_free(NULL, out);
    AK_CHECK_EQ(ak_io_image_decode(jpg, n, W * H * 4 + 16, NULL, &out, &w, &h, &diag),
                AK_ERR_UNSUPPORTED);
    AK_CHECK(strstr(diag.message, "progressive") != NULL);
    free(jpg);
#else
    AK_SKIP("jpeglib.h not found when building the test");
#endif
}

AK_TEST(broken_images) {
    uint8_t* out = (uint8_t*)1;
    int w = 0, h = 0;
    ak_diag diag;
    const uint8_t junk[] = "this is not an image at all";
    AK_CHECK_EQ(ak_io_image_decode(junk, sizeof junk, 0, NULL, &out, &w, &h, &diag), AK_ERR_PARSE);
    AK_CHECK(out == NULL);
    AK_CHECK_EQ(ak_io_image_decode(junk, 0, 0, NULL, &out, &w, &h, &diag), AK_ERR_PARSE);
    AK_CHECK_EQ(ak_io_image_decode(NULL, 0, 0, NULL, NULL, &w, &h, &diag), AK_ERR_NULL_ARG);
    /* a truncated PNG */
    uint8_t px[16 * 16 * 4];
    for (size_t i = 0; i < sizeof px; ++i) px[i] = (uint8_t)(i * 13);
    size_t n = 0;
    uint8_t* png = png_encode(px, 16, 16, PNG_FORMAT_RGBA, &n);
    AK_CHECK_EQ(ak_io_image_decode(png, n - 20, 0, NULL, &out, &w, &h, &diag), AK_ERR_PARSE);
    AK_CHECK(out == NULL && strstr(diag.message, "PNG") != NULL);
    /* one flipped byte in the data: libpng's CRC or zlib check catches it */
    png[n / 2] ^= 0x5A;
    AK_CHECK(ak_io_image_decode(png, n, 0, NULL, &out, &w, &h, &diag) != AK_OK);
    AK_CHECK(out == NULL);
    free(png);
    /* absurd sizes are refused from the header, before any allocation */
    uint8_t hdr[64];
    size_t hn = png_header_only(20000, 20000, hdr);
    AK_CHECK_EQ(ak_io_image_decode(hdr, hn, 0, NULL, &out, &w, &h, &diag), AK_ERR_UNSUPPORTED);
    AK_CHECK(strstr(diag.message, "20000 x 20000") != NULL);
    hn = png_header_only(4000, 4000, hdr); /* 64 MB of pixels against a 1 MB budget */
    AK_CHECK_EQ(ak_io_image_decode(hdr, hn, 1u << 20, NULL, &out, &w, &h, &diag),
                AK_ERR_UNSUPPORTED);
    AK_CHECK(strstr(diag.message, "budget") != NULL);
    /* within the budget the same header decodes as far as the missing data: a parse error */
    hn = png_header_only(8, 8, hdr);
    AK_CHECK_EQ(ak_io_image_decode(hdr, hn, 0, NULL, &out, &w, &h, &diag), AK_ERR_PARSE);
    AK_CHECK(out == NULL);
}

/* ---- rasterizer ---------------------------------------------------------------------------- */

/* Texel (i, j) of the reference texture: a unique colour per texel. */
static void texel_color(int i, int j, uint8_t out[4]) {
    out[0] = (uint8_t)(32 * i + 16);
    out[1] = (uint8_t)(32 * j + 16);
    out[2] = 200;
    out[3] = 255;
}

static double frac_dist(double x) { return fabs(x - floor(x + 0.5)); }

/* A textured quad on the ground plane seen in perspective: each pixel's colour must be the
 * texel that the ray through the pixel centre hits (ray-plane intersection, computed here),
 * which differs from what screen-space (affine) interpolation of the UVs would give. */
AK_TEST(raster_perspective_correct) {
    enum { W = 96, H = 72, T = 8 };
    uint8_t tex_px[T * T * 4];
    for (int j = 0; j < T; ++j)
        for (int i = 0; i < T; ++i) texel_color(i, j, &tex_px[(j * T + i) * 4]);
    ak_raster_texture tex = {.image = {.pixels = tex_px, .width = T, .height = T},
                             .mag_filter = AK_RASTER_FILTER_NEAREST,
                             .min_filter = AK_RASTER_FILTER_NEAREST};
    const ak_vec3 pos[4] = {{-1, 0, -1}, {1, 0, -1}, {1, 0, 1}, {-1, 0, 1}};
    const ak_vec2 uv[4] = {{0, 0}, {1, 0}, {1, 1}, {0, 1}}; /* u = (x + 1) / 2, v = (z + 1) / 2 */
    const uint32_t idx[6] = {0, 1, 2, 0, 2, 3};
    ak_raster* r = NULL;
    AK_CHECK_EQ(ak_raster_create(&(ak_raster_desc){.width = W, .height = H}, NULL, &r), AK_OK);
    ak_raster_camera cam =
        ak_raster_camera_perspective(ak_vec3_make(0.2f, 0.9f, 2.2f), ak_vec3_make(0, 0, -0.3f),
                                     ak_radians(60), (float)W / H, 0.1f, 20);
    ak_raster_clear(r, ak_vec4_make(0, 0, 0, 1), ak_vec4_make(0, 0, 0, 1));
    ak_raster_mesh m = {.positions = {pos, 4},
                        .indices = {idx, 6},
                        .uvs = {uv, 4},
                        .texture = &tex,
                        .material = {.color = {1, 1, 1, 1}},
                        .shading = AK_SHADING_UNLIT};
    AK_CHECK_EQ(ak_raster_draw_mesh(r, &cam, &m), AK_OK);
    uint8_t* img_px = calloc(W * H, 4);
    ak_image img = {.pixels = img_px, .width = W, .height = H};
    AK_CHECK_EQ(ak_raster_resolve(r, &img), AK_OK);
    ak_mat4 inv = ak_mat4_inverse(ak_mat4_mul(cam.projection, cam.view));
    /* projected corners, for the affine reference */
    ak_vec3 sp[4];
    for (int k = 0; k < 4; ++k) AK_CHECK(ak_raster_camera_project(&cam, W, H, pos[k], &sp[k]));
    int checked = 0, wrong = 0, affine_differs = 0;
    for (int y = 0; y < H; ++y)
        for (int x = 0; x < W; ++x) {
            float nx = (x + 0.5f) / W * 2 - 1, ny = 1 - (y + 0.5f) / H * 2;
            ak_vec4 a = ak_mat4_mul_vec4(inv, ak_vec4_make(nx, ny, -1, 1));
            ak_vec4 b = ak_mat4_mul_vec4(inv, ak_vec4_make(nx, ny, 1, 1));
            ak_vec3 p0 = ak_vec3_make(a.x / a.w, a.y / a.w, a.z / a.w),
                    p1 = ak_vec3_make(b.x / b.w, b.y / b.w, b.z / b.w);
            double t = p0.y / (double)(p0.y - p1.y);
            double hx = p0.x + t * (p1.x - p0.x), hz = p0.z + t * (p1.z - p0.z);
            double u = (hx + 1) / 2, v = (hz + 1) / 2;
            if (!(u > 0.01 && u < 0.99 && v > 0.01 && v < 0.99)) continue;
            if (frac_dist(u * T) < 0.03 || frac_dist(v * T) < 0.03) continue; /* on a texel edge */
            uint8_t want[4];
            texel_color((int)floor(u * T), (int)floor(v * T), want);
            const uint8_t* got = ak_image_pixel(&img, x, y);
            ++checked;
            if (got[0] != want[0] || got[1] != want[1] || got[2] != want[2]) ++wrong;
            /* affine: screen-space barycentrics of the triangle holding the pixel */
            double px = x + 0.5, py = y + 0.5;
            for (int tri = 0; tri < 2; ++tri) {
                const ak_vec3 *A = &sp[idx[3 * tri]], *B = &sp[idx[3 * tri + 1]],
                              *C = &sp[idx[3 * tri + 2]];
                double den = (B->y - C->y) * (A->x - C->x) + (C->x - B->x) * (A->y - C->y);
                double l0 = ((B->y - C->y) * (px - C->x) + (C->x - B->x) * (py - C->y)) / den;
                double l1 = ((C->y - A->y) * (px - C->x) + (A->x - C->x) * (py - C->y)) / den;
                double l2 = 1 - l0 - l1;
                if (l0 < 0 || l1 < 0 || l2 < 0) continue;
                const ak_vec2 *ua = &uv[idx[3 * tri]], *ub = &uv[idx[3 * tri + 1]],
                              *uc = &uv[idx[3 * tri + 2]];
                double au = l0 * ua->x + l1 * ub->x + l2 * uc->x,
                       av = l0 * ua->y + l1 * ub->y + l2 * uc->y;
                if ((int)floor(au * T) != (int)floor(u * T) ||
                    (int)floor(av * T) != (int)floor(v * T))
                    ++affine_differs;
                break;
            }
        }
    AK_CHECK_MSG(checked > 1000, "only %d pixels checked", checked);
    AK_CHECK_MSG(wrong == 0, "%d of %d pixels show the wrong texel", wrong, checked);
    /* the scene is chosen so that affine interpolation would be visibly wrong */
    AK_CHECK_MSG(affine_differs > checked / 10, "affine differs at only %d of %d", affine_differs,
                 checked);
    free(img_px);
    ak_raster_destroy(r);
}

/* Expected texel index along an axis of n texels for coordinate u. */
static int wrap_ref(double u, int n, ak_raster_wrap w) {
    if (w == AK_RASTER_WRAP_CLAMP) {
        double c = u < 0 ? 0 : (u > 1 ? 1 : u);
        int i = (int)floor(c * n);
        return i >= n ? n - 1 : i;
    }
    if (w == AK_RASTER_WRAP_MIRROR) {
        double f = u - 2 * floor(u / 2); /* [0, 2) */
        double m = f < 1 ? f : 2 - f;
        int i = (int)floor(m * n);
        return i >= n ? n - 1 : i;
    }
    double f = u - floor(u);
    return (int)floor(f * n);
}

/* A screen-filling quad with u from -1 to 2 across the image (orthographic, so UV is linear in
 * x): every pixel's texel follows the wrap mode's definition. Bilinear filtering between texel
 * centres is checked against the interpolated bytes (unlit filters sRGB bytes). */
AK_TEST(raster_wrap_modes) {
    enum { W = 150, H = 4, T = 4 };
    const uint8_t tex_px[T * 4] = {255, 0, 0,   255, 0,   255, 0,   255,
                                   0,   0, 255, 255, 250, 250, 250, 255};
    const ak_vec3 pos[4] = {{-1, -1, 0}, {1, -1, 0}, {1, 1, 0}, {-1, 1, 0}};
    const ak_vec2 uv[4] = {{-1, 0.5f}, {2, 0.5f}, {2, 0.5f}, {-1, 0.5f}};
    const uint32_t idx[6] = {0, 1, 2, 0, 2, 3};
    ak_raster* r = NULL;
    AK_CHECK_EQ(ak_raster_create(&(ak_raster_desc){.width = W, .height = H}, NULL, &r), AK_OK);
    ak_raster_camera cam =
        ak_raster_camera_orthographic(ak_vec3_make(0, 0, 5), ak_vec3_zero(), 1, 1, 0.1f, 10);
    uint8_t* img_px = calloc(W * H, 4);
    ak_image img = {.pixels = img_px, .width = W, .height = H};
    const ak_raster_wrap modes[3] = {AK_RASTER_WRAP_REPEAT, AK_RASTER_WRAP_CLAMP,
                                     AK_RASTER_WRAP_MIRROR};
    for (int mi = 0; mi < 3; ++mi) {
        for (int f = 0; f < 2; ++f) {
            ak_raster_filter filt = f ? AK_RASTER_FILTER_LINEAR : AK_RASTER_FILTER_NEAREST;
            ak_raster_texture tex = {.image = {.pixels = (uint8_t*)tex_px, .width = T, .height = 1},
                                     .wrap_u = modes[mi],
                                     .wrap_v = AK_RASTER_WRAP_CLAMP,
                                     .mag_filter = filt,
                                     .min_filter = filt};
            ak_raster_clear(r, ak_vec4_make(0, 0, 0, 1), ak_vec4_make(0, 0, 0, 1));
            ak_raster_mesh m = {.positions = {pos, 4},
                                .indices = {idx, 6},
                                .uvs = {uv, 4},
                                .texture = &tex,
                                .material = {.color = {1, 1, 1, 1}},
                                .shading = AK_SHADING_UNLIT};
            AK_CHECK_EQ(ak_raster_draw_mesh(r, &cam, &m), AK_OK);
            AK_CHECK_EQ(ak_raster_resolve(r, &img), AK_OK);
            int checked = 0, wrong = 0;
            for (int x = 0; x < W; ++x) {
                double u = -1 + 3.0 * (x + 0.5) / W;
                const uint8_t* got = ak_image_pixel(&img, x, 1);
                if (!f) {
                    if (frac_dist(u * T) < 0.02) continue;
                    const uint8_t* want = &tex_px[4 * wrap_ref(u, T, modes[mi])];
                    ++checked;
                    wrong += got[0] != want[0] || got[1] != want[1] || got[2] != want[2];
                } else {
                    /* bilinear: between the centres of texels i and i + 1 (wrapped) */
                    double s = u * T - 0.5, fl = floor(s), t = s - fl;
                    double c0 = (fl + 0.5) / T, c1 = (fl + 1.5) / T; /* the two centres' u */
                    const uint8_t* a = &tex_px[4 * wrap_ref(c0, T, modes[mi])];
                    const uint8_t* b = &tex_px[4 * wrap_ref(c1, T, modes[mi])];
                    ++checked;
                    for (int k = 0; k < 3; ++k) {
                        double want = a[k] + (b[k] - a[k]) * t;
                        if (fabs(got[k] - want) > 2.0) ++wrong;
                    }
                }
            }
            AK_CHECK_MSG(checked > 100 && wrong == 0, "mode %d filter %d: %d wrong of %d", mi, f,
                         wrong, checked);
        }
    }
    /* bad texture descriptions are refused */
    ak_raster_texture bad = {.image = {.pixels = NULL, .width = T, .height = 1}};
    ak_raster_mesh m = {
        .positions = {pos, 4}, .indices = {idx, 6}, .uvs = {uv, 4}, .texture = &bad};
    AK_CHECK_EQ(ak_raster_draw_mesh(r, &cam, &m), AK_ERR_BAD_ARG);
    ak_raster_texture bad_wrap = {.image = {.pixels = (uint8_t*)tex_px, .width = T, .height = 1},
                                  .wrap_u = 7};
    m.texture = &bad_wrap;
    AK_CHECK_EQ(ak_raster_draw_mesh(r, &cam, &m), AK_ERR_BAD_ARG);
    m.texture = NULL;
    m.uvs.count = 3;
    AK_CHECK_EQ(ak_raster_draw_mesh(r, &cam, &m), AK_ERR_BAD_ARG);
    free(img_px);
    ak_raster_destroy(r);
}

/* Lit: the texel multiplies the albedo in linear light, so a texel of half the linear value
 * gives half the linear lit colour of a white texel (Phong, no specular). */
AK_TEST(raster_lit_texture_scales_albedo) {
    enum { W = 16, H = 16 };
    uint8_t half = 0;
    for (int b = 0; b < 256; ++b)
        if (fabsf(ak_srgb_to_linear(b / 255.0f) - 0.5f * ak_srgb_to_linear(200 / 255.0f)) <
            fabsf(ak_srgb_to_linear(half / 255.0f) - 0.5f * ak_srgb_to_linear(200 / 255.0f)))
            half = (uint8_t)b;
    const ak_vec3 pos[4] = {{-1, -1, 0}, {1, -1, 0}, {1, 1, 0}, {-1, 1, 0}};
    const ak_vec3 nrm[4] = {{0, 0, 1}, {0, 0, 1}, {0, 0, 1}, {0, 0, 1}};
    const ak_vec2 uv[4] = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
    const uint32_t idx[6] = {0, 1, 2, 0, 2, 3};
    ak_raster* r = NULL;
    AK_CHECK_EQ(ak_raster_create(&(ak_raster_desc){.width = W, .height = H}, NULL, &r), AK_OK);
    ak_raster_camera cam =
        ak_raster_camera_orthographic(ak_vec3_make(0, 0, 5), ak_vec3_zero(), 1, 1, 0.1f, 10);
    uint8_t img_px[2][W * H * 4];
    const uint8_t texels[2] = {200, half};
    for (int k = 0; k < 2; ++k) {
        uint8_t t[4] = {texels[k], texels[k], texels[k], 255};
        ak_raster_texture tex = {.image = {.pixels = t, .width = 1, .height = 1}};
        ak_raster_clear(r, ak_vec4_make(0, 0, 0, 1), ak_vec4_make(0, 0, 0, 1));
        ak_raster_mesh m = {.positions = {pos, 4},
                            .normals = {nrm, 4},
                            .indices = {idx, 6},
                            .uvs = {uv, 4},
                            .texture = &tex,
                            .material = {.color = {0.5f, 0.5f, 0.5f, 1}, .specular = -1}};
        AK_CHECK_EQ(ak_raster_draw_mesh(r, &cam, &m), AK_OK);
        AK_CHECK_EQ(ak_raster_resolve(r, &(ak_image){.pixels = img_px[k], .width = W, .height = H}),
                    AK_OK);
    }
    float a = ak_srgb_to_linear(img_px[0][(8 * W + 8) * 4] / 255.0f);
    float b = ak_srgb_to_linear(img_px[1][(8 * W + 8) * 4] / 255.0f);
    AK_CHECK(a > 0.05f && a < 0.7f); /* below the tone curve's shoulder */
    AK_CHECK_NEAR(b / a, 0.5f, 0.03f);
    ak_raster_destroy(r);
}

/* ---- glTF ---------------------------------------------------------------------------------- */

/* One textured triangle as a .gltf text: positions and UVs in a data: URI buffer, the image
 * given by image_json (an "images" element). */
static char* gltf_triangle(const char* image_json, const char* sampler_json) {
    float data[15] = {0, 0, 0, 1, 0, 0, 0, 1, 0, /* uv */ 0, 0, 1, 0, 0, 1};
    char* b = b64((const uint8_t*)data, sizeof data);
    size_t cap = strlen(b) + strlen(image_json) + 2048;
    char* out = malloc(cap);
    snprintf(out, cap,
             "{\"asset\":{\"version\":\"2.0\"},\"buffers\":[{\"byteLength\":60,\"uri\":\"data:"
             "application/"
             "octet-stream;base64,%s\"}],\"bufferViews\":[{\"buffer\":0,\"byteLength\":36},{"
             "\"buffer\":0,"
             "\"byteOffset\":36,\"byteLength\":24}],\"accessors\":[{\"bufferView\":0,"
             "\"componentType\":5126,"
             "\"count\":3,\"type\":\"VEC3\",\"min\":[0,0,0],\"max\":[1,1,0]},{\"bufferView\":1,"
             "\"componentType\":"
             "5126,\"count\":3,\"type\":\"VEC2\"}],\"meshes\":[{\"primitives\":[{\"attributes\":{"
             "\"POSITION\":0,"
             "\"TEXCOORD_0\":1},\"material\":0}]}],\"nodes\":[{\"mesh\":0}],\"materials\":[{"
             "\"pbrMetallicRoughness\":{\"baseColorFactor\":[1,0.5,0.25,1],\"baseColorTexture\":{"
             "\"index\":0}}}],"
             "\"textures\":[{\"source\":0%s}],\"samplers\":[%s],\"images\":[%s]}",
             b, sampler_json[0] ? ",\"sampler\":0" : "", sampler_json, image_json);
    free(b);
    return out;
}

AK_TEST(gltf_texture_and_sampler) {
    uint8_t px[3 * 2 * 4];
    for (size_t i = 0; i < sizeof px; ++i) px[i] = (uint8_t)(i * 9 + 3);
    size_t n = 0;
    uint8_t* png = png_encode(px, 3, 2, PNG_FORMAT_RGBA, &n);
    char* pb = b64(png, n);
    char* image = malloc(strlen(pb) + 64);
    sprintf(image, "{\"uri\":\"data:image/png;base64,%s\"}", pb);
    char* doc = gltf_triangle(
        image, "{\"wrapS\":33648,\"wrapT\":33071,\"magFilter\":9728,\"minFilter\":9986}");
    ak_scene* s = NULL;
    ak_diag diag;
    AK_CHECK_EQ(ak_io_load_memory(doc, strlen(doc), "tri.gltf", NULL, NULL, NULL, &s, &diag),
                AK_OK);
    if (s) {
        AK_CHECK_EQ(s->texture_count, 1u);
        AK_CHECK_EQ(s->meshes[0].texture, 0);
        AK_CHECK_NEAR(s->meshes[0].base_color.y, 0.5f, 1e-6);
        const ak_scene_texture* t = &s->textures[0];
        AK_CHECK(t->width == 3 && t->height == 2 && t->pixels &&
                 memcmp(t->pixels, px, sizeof px) == 0);
        AK_CHECK_EQ(t->wrap_s, AK_TEXTURE_WRAP_MIRROR);
        AK_CHECK_EQ(t->wrap_t, AK_TEXTURE_WRAP_CLAMP);
        AK_CHECK_EQ(t->mag_filter, AK_TEXTURE_FILTER_NEAREST);
        AK_CHECK_EQ(t->min_filter, AK_TEXTURE_FILTER_LINEAR); /* a mipmap filter without mipmaps */
        AK_CHECK(s->meshes[0].mesh->uvs && s->meshes[0].mesh->uvs[1].x == 1.0f);
    }
    ak_scene_destroy(s);
    free(doc);
    /* no sampler: REPEAT and LINEAR */
    doc = gltf_triangle(image, "");
    s = NULL;
    AK_CHECK_EQ(ak_io_load_memory(doc, strlen(doc), "tri.gltf", NULL, NULL, NULL, &s, &diag),
                AK_OK);
    if (s) {
        AK_CHECK(s->textures[0].wrap_s == AK_TEXTURE_WRAP_REPEAT &&
                 s->textures[0].wrap_t == AK_TEXTURE_WRAP_REPEAT);
        AK_CHECK(s->textures[0].mag_filter == AK_TEXTURE_FILTER_LINEAR);
    }
    ak_scene_destroy(s);
    free(doc);
    free(image);
    free(pb);
    free(png);
}

/* ak_io_desc.image_decoder (the browser's decoder in the WebAssembly page): the decoder sees the
 * image's encoded bytes; its pixels become the texture (copied: the decoder's buffer is changed
 * after the load and the texture must not follow); AK_ERR_UNSUPPORTED falls back to libpng; a
 * refusal or an absurd size is a warning and no texture; an image over the memory budget too. */
typedef struct hook_state {
    const uint8_t* want; /* the encoded bytes the decoder must be handed */
    size_t want_size;
    uint8_t px[5 * 4 * 4];
    const uint8_t* big; /* w * h * 4 bytes when w * h > 20 */
    int w, h, calls, seen_right_bytes;
    ak_result answer;
} hook_state;
static ak_result hook_decoder(void* user, const void* data, size_t size, ak_io_image_view* out) {
    hook_state* st = (hook_state*)user;
    ++st->calls;
    if (size == st->want_size && memcmp(data, st->want, size) == 0) ++st->seen_right_bytes;
    if (st->answer != AK_OK) return st->answer;
    out->pixels = st->w * st->h > 20 ? st->big : st->px;
    out->width = st->w;
    out->height = st->h;
    return AK_OK;
}

AK_TEST(gltf_caller_image_decoder) {
    uint8_t png_px[3 * 2 * 4];
    for (size_t i = 0; i < sizeof png_px; ++i) png_px[i] = (uint8_t)(i * 9 + 3);
    size_t n = 0;
    uint8_t* png = png_encode(png_px, 3, 2, PNG_FORMAT_RGBA, &n);
    char* pb = b64(png, n);
    char* image = malloc(strlen(pb) + 64);
    sprintf(image, "{\"uri\":\"data:image/png;base64,%s\"}", pb);
    char* doc = gltf_triangle(image, "");
    hook_state st = {.want = png, .want_size = n, .w = 5, .h = 4, .answer = AK_OK};
    for (size_t i = 0; i < sizeof st.px; ++i) st.px[i] = (uint8_t)(250 - i);
    struct {
        ak_result answer;
        int w, h;
        size_t budget;
        int expect; /* 0: the decoder's pixels, 1: libpng's, 2: none and one warning */
        const char* warning;
    } cases[] = {
        {AK_OK, 5, 4, 0, 0, ""},
        {AK_ERR_UNSUPPORTED, 5, 4, 0, 1, ""},
        {AK_ERR_PARSE, 5, 4, 0, 2, "decoder refused it"},
        {AK_OK, 0, 4, 0, 2, "decoder gave 0 x 4"},
        {AK_OK, 5, 16385, 0, 2, "decoder gave 5 x 16385"},
        {AK_OK, 200, 200, 100000, 2, "memory budget"},
    };
    uint8_t* big = calloc(200 * 200, 4); /* 160 kB: over a budget of 100 kB, which the file fits */
    st.big = big;
    for (size_t k = 0; k < sizeof cases / sizeof cases[0]; ++k) {
        st.answer = cases[k].answer;
        st.w = cases[k].w;
        st.h = cases[k].h;
        st.calls = st.seen_right_bytes = 0;
        ak_io_desc d = {.logger = {.func = count_warning},
                        .image_decoder = hook_decoder,
                        .image_decoder_user = &st,
                        .memory_budget = cases[k].budget};
        g_warnings = 0;
        g_last_warning[0] = 0;
        ak_scene* s = NULL;
        ak_diag diag;
        ak_result r = ak_io_load_memory(doc, strlen(doc), "tri.gltf", NULL, &d, NULL, &s, &diag);
        AK_CHECK_MSG(r == AK_OK, "case %zu: %s (%s)", k, ak_result_string(r), diag.message);
        AK_CHECK_MSG(st.calls == 1 && st.seen_right_bytes == 1,
                     "case %zu: %d calls, %d with the PNG's bytes", k, st.calls,
                     st.seen_right_bytes);
        if (!s) continue;
        const ak_scene_texture* t = &s->textures[0];
        if (cases[k].expect == 0) {
            AK_CHECK(t->width == 5 && t->height == 4 && t->pixels && t->pixels != st.px);
            uint8_t ref[sizeof st.px];
            memcpy(ref, st.px, sizeof ref);
            memset(st.px, 0,
                   sizeof st.px); /* the decoder's buffer changes: the texture is a copy */
            AK_CHECK(t->pixels && memcmp(t->pixels, ref, sizeof ref) == 0);
            memcpy(st.px, ref, sizeof ref);
            AK_CHECK_EQ(g_warnings, 0);
        } else if (cases[k].expect == 1) {
            AK_CHECK(t->width == 3 && t->height == 2 && t->pixels &&
                     memcmp(t->pixels, png_px, sizeof png_px) == 0);
            AK_CHECK_EQ(g_warnings, 0);
        } else {
            AK_CHECK_MSG(t->pixels == NULL && s->meshes[0].texture == -1 && g_warnings == 1 &&
                             strstr(g_last_warning, cases[k].warning),
                         "case %zu: pixels %p, %d warnings '%s'", k, (void*)t->pixels, g_warnings,
                         g_last_warning);
        }
        ak_scene_destroy(s);
    }
    free(big);
    free(doc);
    free(image);
    free(pb);
    free(png);
}

/* A texture that cannot be read is a warning and no texture; the model still loads. */
AK_TEST(gltf_broken_texture_warns) {
    const char* images[] = {
        "{\"uri\":\"data:image/png;base64,iVBORw0KGgoAAAANSUhEUgAAAAEAAAAB\"}", /* a truncated PNG
                                                                                 */
        "{\"uri\":\"data:image/png;base64,aGVsbG8gd29ybGQ=\"}",                 /* not an image */
        "{\"uri\":\"../../../../etc/passwd\"}",           /* leaves the folder */
        "{\"uri\":\"missing.png\"}",                      /* not there */
        "{\"bufferView\":99,\"mimeType\":\"image/png\"}", /* bad view */
        "{\"name\":\"nothing\"}",                         /* no data */
    };
    const char* expect[] = {"PNG",         "not a PNG or JPEG", "leaves the model's folder",
                            "missing.png", "bufferView",        "neither"};
    for (size_t i = 0; i < sizeof images / sizeof images[0]; ++i) {
        char* doc = gltf_triangle(images[i], "");
        ak_io_desc d = {.logger = {.func = count_warning}};
        g_warnings = 0;
        g_last_warning[0] = 0;
        ak_scene* s = NULL;
        ak_diag diag;
        ak_result r =
            ak_io_load_memory(doc, strlen(doc), "tri.gltf", AK_BINARY_DIR, &d, NULL, &s, &diag);
        AK_CHECK_MSG(r == AK_OK, "image %zu: %s (%s)", i, ak_result_string(r), diag.message);
        AK_CHECK_MSG(g_warnings == 1 && strstr(g_last_warning, expect[i]) != NULL,
                     "image %zu: %d warnings, '%s'", i, g_warnings, g_last_warning);
        if (s) {
            AK_CHECK_EQ(s->meshes[0].texture, -1);
            AK_CHECK(s->textures[0].pixels == NULL);
        }
        ak_scene_destroy(s);
        free(doc);
    }
}

AK_TEST(gltf_assets_textured) {
    const char* fox_glb = asset("Fox/glTF-Binary/Fox.glb");
    const char* fox_gltf = asset("Fox/glTF/Fox.gltf");
    const char* fox_png = asset("Fox/glTF/Texture.png");
    const char* man = asset("CesiumMan/glTF-Binary/CesiumMan.glb");
    if (!file_exists(fox_glb) || !file_exists(fox_gltf) || !file_exists(man))
        { AK_SKIP("assets not found"); return; }
    /* the PNG file itself, read by libpng's file reader: the independent reference */
    int w = 0, h = 0;
    AK_CHECK_EQ(ak_png_info(fox_png, &w, &h), AK_OK);
    uint8_t* ref = malloc((size_t)w * (size_t)h * 4);
    AK_CHECK_EQ(ak_png_read(fox_png, &(ak_image){.pixels = ref, .width = w, .height = h}), AK_OK);
    const char* foxes[2] = {fox_glb, fox_gltf}; /* embedded (bufferView) and external file */
    for (int k = 0; k < 2; ++k) {
        ak_scene* s = NULL;
        ak_diag diag;
        AK_CHECK_EQ(ak_io_load(foxes[k], NULL, NULL, &s, &diag), AK_OK);
        if (!s) continue;
        AK_CHECK_EQ(s->texture_count, 1u);
        AK_CHECK(s->mesh_count >= 1 && s->meshes[0].texture == 0 && s->meshes[0].mesh->uvs);
        const ak_scene_texture* t = &s->textures[0];
        AK_CHECK(t->width == w && t->height == h && t->pixels &&
                 memcmp(t->pixels, ref, (size_t)w * (size_t)h * 4) == 0);
        ak_scene_destroy(s);
    }
    free(ref);
    ak_scene* s = NULL;
    ak_diag diag;
    AK_CHECK_EQ(ak_io_load(man, NULL, NULL, &s, &diag), AK_OK);
    if (s) {
        AK_CHECK_EQ(s->texture_count, 1u);
        const ak_scene_texture* t = &s->textures[0];
#if defined(HAVE_JPEG_WRITER)
        AK_CHECK(t->pixels != NULL && t->width > 0 && t->height > 0);
        AK_CHECK(s->meshes[0].texture == 0);
        /* a JPEG of a textured figure: many distinct colours, not one grey */
        int distinct = 0;
        static bool seen[4096];
        memset(seen, 0, sizeof seen);
        for (int i = 0; t->pixels && i < t->width * t->height; ++i) {
            int q = (t->pixels[4 * i] >> 4) << 8 | (t->pixels[4 * i + 1] >> 4) << 4 |
                    (t->pixels[4 * i + 2] >> 4);
            if (!seen[q]) ++distinct;
            seen[q] = true;
        }
        AK_CHECK_MSG(distinct > 50, "%d distinct colours", distinct);
#else
        (void)t;
#endif
        AK_CHECK_EQ(t->wrap_s, AK_TEXTURE_WRAP_REPEAT);
    }
    ak_scene_destroy(s);
}

/* ---- export -------------------------------------------------------------------------------- */

static bool same_texture(const ak_scene* a, const ak_scene* b, size_t mesh) {
    int32_t ta = a->meshes[mesh].texture, tb = b->meshes[mesh].texture;
    if (ta < 0 || tb < 0 || (size_t)tb >= b->texture_count) return false;
    const ak_scene_texture *x = &a->textures[ta], *y = &b->textures[tb];
    return x->width == y->width && x->height == y->height && y->pixels &&
           memcmp(x->pixels, y->pixels, (size_t)x->width * (size_t)x->height * 4u) == 0;
}

/* `animkit export Fox.glb -o x.glb` keeps the texture: the re-loaded file has the same texels. */
AK_TEST(cli_export_keeps_texture) {
    const char* fox = asset("Fox/glTF-Binary/Fox.glb");
    if (!file_exists(fox)) { AK_SKIP("assets not found"); return; }
    char args[2048];
    snprintf(args, sizeof args, "export '%s' -o tex_fox.glb", fox);
    AK_CHECK_EQ(run(args, true), 0);
    ak_scene *a = NULL, *b = NULL;
    ak_diag diag;
    AK_CHECK_EQ(ak_io_load(fox, NULL, NULL, &a, &diag), AK_OK);
    AK_CHECK_EQ(ak_io_load("tex_fox.glb", NULL, NULL, &b, &diag), AK_OK);
    if (a && b) {
        AK_CHECK_EQ(b->texture_count, 1u);
        AK_CHECK(b->mesh_count == a->mesh_count && same_texture(a, b, 0));
        AK_CHECK(b->meshes[0].mesh->uvs &&
                 memcmp(a->meshes[0].mesh->uvs, b->meshes[0].mesh->uvs,
                        a->meshes[0].mesh->vertex_count * sizeof(ak_vec2)) == 0);
    }
    ak_scene_destroy(a);
    ak_scene_destroy(b);
}

/* OBJ export: vt, an .mtl with map_Kd and the PNG it names (rows flipped for OBJ's bottom-left
 * origin); animkit's OBJ reader gives back the same texels for the same UVs. */
AK_TEST(obj_export_map_kd) {
    const char* fox = asset("Fox/glTF-Binary/Fox.glb");
    if (!file_exists(fox)) { AK_SKIP("assets not found"); return; }
    ak_scene *a = NULL, *b = NULL;
    ak_diag diag;
    AK_CHECK_EQ(ak_io_load(fox, NULL, NULL, &a, &diag), AK_OK);
    if (!a) return;
    AK_CHECK_EQ(ak_io_write_obj("tex_fox.obj", a, NULL, NULL, &diag), AK_OK);
    /* the files: mtllib/usemtl in the .obj, map_Kd in the .mtl, the PNG flipped */
    FILE* f = fopen("tex_fox.mtl", "rb");
    AK_CHECK(f != NULL);
    char text[4096] = "";
    if (f) {
        text[fread(text, 1, sizeof text - 1, f)] = 0;
        fclose(f);
    }
    AK_CHECK(strstr(text, "map_Kd tex_fox_0.png") != NULL);
    int w = 0, h = 0;
    AK_CHECK_EQ(ak_png_info("tex_fox_0.png", &w, &h), AK_OK);
    const ak_scene_texture* t = &a->textures[0];
    AK_CHECK(w == t->width && h == t->height);
    uint8_t* png = malloc((size_t)w * (size_t)h * 4);
    AK_CHECK_EQ(ak_png_read("tex_fox_0.png", &(ak_image){.pixels = png, .width = w, .height = h}),
                AK_OK);
    AK_CHECK(memcmp(png, t->pixels + (size_t)(h - 1) * (size_t)w * 4, (size_t)w * 4) ==
             0); /* first row = last */
    free(png);
    AK_CHECK_EQ(ak_io_load("tex_fox.obj", NULL, NULL, &b, &diag), AK_OK);
    if (b) {
        AK_CHECK_EQ(b->mesh_count, a->mesh_count);
        AK_CHECK(b->meshes[0].mesh->uvs != NULL);
        AK_CHECK_MSG(same_texture(a, b, 0), "the OBJ's texture differs");
        AK_CHECK(b->meshes[0].mesh->uvs[5].x == a->meshes[0].mesh->uvs[5].x &&
                 b->meshes[0].mesh->uvs[5].y == a->meshes[0].mesh->uvs[5].y);
    }
    ak_scene_destroy(a);
    ak_scene_destroy(b);
    /* a map_Kd that leaves the folder or is broken: a warning, no texture, the OBJ loads */
    f = fopen("tex_bad.obj", "wb");
    fputs("mtllib tex_bad.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 0 1\nusemtl a\nf 1/1 "
          "2/2 3/3\n",
          f);
    fclose(f);
    const char* maps[2] = {"../../../../etc/passwd", "tex_bad.obj"};
    for (int k = 0; k < 2; ++k) {
        f = fopen("tex_bad.mtl", "wb");
        fprintf(f, "newmtl a\nKd 1 1 1\nmap_Kd -s 1 1 1 %s\n", maps[k]);
        fclose(f);
        ak_io_desc d = {.logger = {.func = count_warning}};
        g_warnings = 0;
        b = NULL;
        AK_CHECK_EQ(ak_io_load("tex_bad.obj", &d, NULL, &b, &diag), AK_OK);
        AK_CHECK_MSG(g_warnings == 1 && strstr(g_last_warning, "map_Kd") != NULL, "%d: '%s'",
                     g_warnings, g_last_warning);
        if (b) AK_CHECK(b->meshes[0].texture == -1 && b->meshes[0].has_material);
        ak_scene_destroy(b);
    }
}

/* CesiumMan's head shows the texture's logo (blue, green and white), not a uniform grey or
 * clay disc. The head is the topmost part of the figure: the rows from the first that differs
 * from the background (a vertical gradient, so a figure pixel differs from its row's left end)
 * down 40 pixels, from row `from` (below the viewer's text bar). */
static void check_head(const ak_image* img, int from, const char* what) {
    int top = -1;
    for (int y = from; y < img->height && top < 0; ++y)
        for (int x = 0; x < img->width; ++x) {
            const uint8_t *p = ak_image_pixel(img, x, y), *bg = ak_image_pixel(img, 2, y);
            if (abs(p[0] - bg[0]) + abs(p[1] - bg[1]) + abs(p[2] - bg[2]) > 40) {
                top = y;
                break;
            }
        }
    AK_CHECK_MSG(top > 0, "%s: no figure", what);
    int blue = 0, green = 0, figure = 0;
    for (int y = top; top > 0 && y < top + 40 && y < img->height; ++y)
        for (int x = 0; x < img->width; ++x) {
            const uint8_t *p = ak_image_pixel(img, x, y), *bg = ak_image_pixel(img, 2, y);
            if (abs(p[0] - bg[0]) + abs(p[1] - bg[1]) + abs(p[2] - bg[2]) <= 40) continue;
            ++figure;
            blue += p[2] > p[0] + 60 && p[2] > p[1] + 10;  /* the logo's sky blue */
            green += p[1] > p[0] + 30 && p[1] > p[2] + 30; /* its green hills */
        }
    AK_CHECK_MSG(figure > 300 && blue > figure / 10 && green > figure / 50,
                 "%s: head of %d pixels, %d blue, %d green", what, figure, blue, green);
}

/* `render` to a PNG shows the texture on the head. */
AK_TEST(cesium_man_head_textured) {
    const char* man = asset("CesiumMan/glTF-Binary/CesiumMan.glb");
    if (!file_exists(man)) { AK_SKIP("assets not found"); return; }
    char args[2048];
    snprintf(args, sizeof args, "render '%s' -o tex_man.png", man);
    AK_CHECK_EQ(run(args, true), 0);
    int w = 0, h = 0;
    AK_CHECK_EQ(ak_png_info("tex_man.png", &w, &h), AK_OK);
    uint8_t* px = malloc((size_t)w * (size_t)h * 4);
    ak_image img = {.pixels = px, .width = w, .height = h};
    AK_CHECK_EQ(ak_png_read("tex_man.png", &img), AK_OK);
    check_head(&img, 30, "render PNG");
    free(px);
}

/* The GIF and the viewer draw through the same frame code: checked as slow cases. */
AK_TEST(cesium_man_head_gif_and_viewer) {
    const char* man = asset("CesiumMan/glTF-Binary/CesiumMan.glb");
    if (!file_exists(man)) { AK_SKIP("assets not found"); return; }
    char args[2048];
    int w = 0, h = 0;
    uint8_t* px = NULL;
    ak_image img;
    snprintf(args, sizeof args, "render '%s' --frames 0:0.1:0.1 -o tex_man.gif", man);
    AK_CHECK_EQ(run(args, true), 0);
    int frames = 0;
    AK_CHECK_EQ(ak_gif_info("tex_man.gif", &w, &h, &frames), AK_OK);
    px = malloc((size_t)w * (size_t)h * 4);
    img = (ak_image){.pixels = px, .width = w, .height = h};
    AK_CHECK_EQ(ak_gif_read_frame("tex_man.gif", 0, &img), AK_OK);
    check_head(&img, 30, "render GIF");
    free(px);
    FILE* f = fopen("tex_view.txt", "wb");
    fputs("wait 2\nscreenshot tex_view.png\nquit\n", f);
    fclose(f);
    snprintf(args, sizeof args, "view '%s' --headless --size 480x360 --script tex_view.txt", man);
    AK_CHECK_EQ(run(args, true), 0);
    AK_CHECK_EQ(ak_png_info("tex_view.png", &w, &h), AK_OK);
    px = malloc((size_t)w * (size_t)h * 4);
    img = (ak_image){.pixels = px, .width = w, .height = h};
    AK_CHECK_EQ(ak_png_read("tex_view.png", &img), AK_OK);
    check_head(&img, 40, "viewer");
    free(px);
}

int main(void) {
    AK_RUN(png_decode);
    AK_RUN(jpeg_decode);
    AK_RUN(broken_images);
    AK_RUN(raster_perspective_correct);
    AK_RUN(raster_wrap_modes);
    AK_RUN(raster_lit_texture_scales_albedo);
    AK_RUN(gltf_texture_and_sampler);
    AK_RUN(gltf_caller_image_decoder);
    AK_RUN(gltf_broken_texture_warns);
    AK_RUN(gltf_assets_textured);
    AK_RUN(cli_export_keeps_texture);
    AK_RUN(obj_export_map_kd);
    AK_RUN(cesium_man_head_textured);
    AK_RUN_SLOW(cesium_man_head_gif_and_viewer);
    return ak_test_finish();
}

/* Sprites: camera-facing textured squares blended in a given order, their back-to-front sort
 * and the built-in sprite textures.
 *
 * A billboard's corners are its centre plus or minus half its size along the camera's right
 * and up axes, so in view space the quad lies at one depth, parallel to the image plane: its
 * projection is an axis-aligned rectangle (a square for square pixels) with one depth, and a
 * sprite is drawn by walking that rectangle's samples, with no triangle set-up. */
#include <math.h>

#include <animkit/raster.h>

#include "../internal.h"
#include "raster_internal.h"

/* ---- helpers ----------------------------------------------------------------------------- */

static inline float clamp01f(float x) { return x < 0.0f ? 0.0f : (x > 1.0f ? 1.0f : x); }

static bool camera_finite(const ak_raster_camera* c) {
    return ak_mat4_is_finite(&c->view) && ak_mat4_is_finite(&c->projection);
}

static ak_vec4 mat_mul4(const ak_mat4* m, ak_vec4 p) {
    const float* e = m->m;
    return ak_vec4_make(e[0] * p.x + e[4] * p.y + e[8] * p.z + e[12] * p.w,
                        e[1] * p.x + e[5] * p.y + e[9] * p.z + e[13] * p.w,
                        e[2] * p.x + e[6] * p.y + e[10] * p.z + e[14] * p.w,
                        e[3] * p.x + e[7] * p.y + e[11] * p.z + e[15] * p.w);
}

/* The soft disc's alpha at (u, v) in [0, 1]^2. */
static inline float disc_alpha(float u, float v) {
    float x = 2.0f * u - 1.0f, y = 2.0f * v - 1.0f, r2 = x * x + y * y;
    if (r2 >= 1.0f) return 0.0f;
    float k = 1.0f - r2;
    return k * k;
}

/* A 32-bit integer hash (lowbias32) -> [0, 1). */
static float hash01(uint32_t x) {
    x ^= x >> 16;
    x *= 0x7feb352du;
    x ^= x >> 15;
    x *= 0x846ca68bu;
    x ^= x >> 16;
    return (float)(x >> 8) * (1.0f / 16777216.0f);
}

/* Smooth value noise on an integer lattice. */
static float value_noise(float x, float y, uint32_t seed) {
    float fx = floorf(x), fy = floorf(y);
    int ix = (int)fx, iy = (int)fy;
    float tx = x - fx, ty = y - fy;
    tx = tx * tx * (3.0f - 2.0f * tx);
    ty = ty * ty * (3.0f - 2.0f * ty);
    float v[4];
    for (int k = 0; k < 4; ++k) {
        uint32_t h = (uint32_t)(ix + (k & 1)) * 0x9e3779b1u ^ (uint32_t)(iy + (k >> 1)) * 0x85ebca77u ^
                     seed * 0xc2b2ae3du;
        v[k] = hash01(h);
    }
    return (v[0] + (v[1] - v[0]) * tx) + ((v[2] + (v[3] - v[2]) * tx) - (v[0] + (v[1] - v[0]) * tx)) * ty;
}

/* One row of bilinear taps: the two texel rows of the frame rectangle (taps clamped to the
 * frame, so no bleeding from the neighbours in a sheet) and the weight of the second. */
typedef struct tap_row {
    const uint8_t *r0, *r1;
    float w1;
} tap_row;

static tap_row tap_row_at(const ak_image* tex, int fx0, int fy0, int fh, float v) {
    const float y = v * (float)fh - 0.5f;
    int y0 = (int)floorf(y);
    const float ty = y - (float)y0;
    int y1 = y0 + 1;
    y0 = y0 < 0 ? 0 : (y0 >= fh ? fh - 1 : y0);
    y1 = y1 < 0 ? 0 : (y1 >= fh ? fh - 1 : y1);
    tap_row t = {ak_image_pixel(tex, fx0, fy0 + y0), ak_image_pixel(tex, fx0, fy0 + y1), ty};
    return t;
}

/* Bilinear sample at u in [0, 1] across the frame's fw texels on the row's taps, colour
 * weighted by alpha (no dark fringes); out rgb 0..255, alpha 0..1. */
static inline void sample_row(const tap_row* row, int fw, float u, float out[4]) {
    const float x = u * (float)fw - 0.5f;
    int x0 = (int)floorf(x);
    const float tx = x - (float)x0;
    int x1 = x0 + 1;
    x0 = x0 < 0 ? 0 : (x0 >= fw ? fw - 1 : x0);
    x1 = x1 < 0 ? 0 : (x1 >= fw ? fw - 1 : x1);
    const uint8_t* p[4] = {row->r0 + 4 * x0, row->r0 + 4 * x1, row->r1 + 4 * x0, row->r1 + 4 * x1};
    if ((p[0][3] | p[1][3] | p[2][3] | p[3][3]) == 0) {
        out[0] = out[1] = out[2] = out[3] = 0.0f;
        return;
    }
    const float w[4] = {(1.0f - tx) * (1.0f - row->w1), tx * (1.0f - row->w1), (1.0f - tx) * row->w1, tx * row->w1};
    float acc[4] = {0, 0, 0, 0};
    for (int k = 0; k < 4; ++k) {
        const float a = (float)p[k][3] * w[k];
        acc[0] += (float)p[k][0] * a;
        acc[1] += (float)p[k][1] * a;
        acc[2] += (float)p[k][2] * a;
        acc[3] += a;
    }
    const float inv = acc[3] > 1e-6f ? 1.0f / acc[3] : 0.0f;
    out[0] = acc[0] * inv, out[1] = acc[1] * inv, out[2] = acc[2] * inv, out[3] = acc[3] * (1.0f / 255.0f);
}

/* Heap sort of order[]: "before" = farther (smaller view z), ties by
 * index, so the order is the same on every platform. */
static bool before(const float* z, uint32_t a, uint32_t b) { return z[a] < z[b] || (z[a] == z[b] && a < b); }

static void sift_down(uint32_t* o, const float* z, size_t start, size_t end) {
    size_t root = start;
    while (2 * root + 1 < end) {
        size_t child = 2 * root + 1;
        if (child + 1 < end && before(z, o[child], o[child + 1])) ++child;
        if (!before(z, o[root], o[child])) return;
        uint32_t t = o[root];
        o[root] = o[child];
        o[child] = t;
        root = child;
    }
}

/* ---- public ------------------------------------------------------------------------------ */

ak_result ak_sprite_texture_generate(ak_sprite_texture kind, uint32_t seed, const ak_image* out) {
    if (!out || !out->pixels) return AK_ERR_NULL_ARG;
    if (out->width <= 0 || out->height <= 0 || (unsigned)kind >= AK_SPRITE_TEXTURE_COUNT) return AK_ERR_BAD_ARG;
    for (int y = 0; y < out->height; ++y)
        for (int x = 0; x < out->width; ++x) {
            float u = ((float)x + 0.5f) / (float)out->width, v = ((float)y + 0.5f) / (float)out->height;
            float a = 1.0f;
            if (kind == AK_SPRITE_TEXTURE_DISC) {
                a = disc_alpha(u, v);
            } else if (kind == AK_SPRITE_TEXTURE_PUFF) {
                /* lumps: two octaves of value noise, stronger towards the rim */
                float n = 0.65f * value_noise(u * 4.0f, v * 4.0f, seed) + 0.35f * value_noise(u * 9.0f, v * 9.0f, seed + 7u);
                float xx = 2.0f * u - 1.0f, yy = 2.0f * v - 1.0f;
                float r = sqrtf(xx * xx + yy * yy) / (0.75f + 0.35f * n);
                float k = r < 1.0f ? 1.0f - r * r : 0.0f;
                a = k * k * (0.55f + 0.45f * n);
            }
            uint8_t* p = ak_image_pixel(out, x, y);
            p[0] = p[1] = p[2] = 255;
            p[3] = (uint8_t)(clamp01f(a) * 255.0f + 0.5f);
        }
    return AK_OK;
}

ak_result ak_raster_sprites_sort(const ak_raster_camera* camera, ak_vec3_cspan positions, ak_f32_span scratch_depth,
                                 ak_u32_span out_order) {
    if (!camera || (positions.count && (!positions.ptr || !scratch_depth.ptr || !out_order.ptr)))
        return AK_ERR_NULL_ARG;
    if (scratch_depth.count < positions.count || out_order.count < positions.count || positions.count > UINT32_MAX)
        return AK_ERR_BAD_ARG;
    if (!camera_finite(camera)) return AK_ERR_BAD_DATA;
    const float* v = camera->view.m;
    for (size_t i = 0; i < positions.count; ++i) {
        ak_vec3 p = positions.ptr[i];
        float z = v[2] * p.x + v[6] * p.y + v[10] * p.z + v[14]; /* view-space z: -distance ahead */
        scratch_depth.ptr[i] = ak_finitef(z) ? z : -INFINITY;
        out_order.ptr[i] = (uint32_t)i;
    }
    const size_t n = positions.count;
    uint32_t* o = out_order.ptr;
    for (size_t s = n / 2; s-- > 0;) sift_down(o, scratch_depth.ptr, s, n);
    for (size_t end = n; end > 1; --end) {
        uint32_t t = o[0];
        o[0] = o[end - 1];
        o[end - 1] = t;
        sift_down(o, scratch_depth.ptr, 0, end - 1);
    }
    return AK_OK;
}

ak_result ak_raster_draw_sprites(ak_raster* raster, const ak_raster_camera* camera, const ak_raster_sprites* sprites) {
    if (!raster || !camera || !sprites || !sprites->positions.ptr || sprites->positions.count == 0)
        return AK_ERR_NULL_ARG;
    const ak_raster_sprites* s = sprites;
    const size_t n = s->positions.count;
    if ((s->sizes.count && (s->sizes.count != n || !s->sizes.ptr)) ||
        (s->colors.count && (s->colors.count != n || !s->colors.ptr)) ||
        (s->frames.count && (s->frames.count != n || !s->frames.ptr)) || (s->order.count && !s->order.ptr))
        return AK_ERR_BAD_ARG;
    const int cols = s->sheet_columns ? s->sheet_columns : 1, rows = s->sheet_rows ? s->sheet_rows : 1;
    if (cols < 1 || cols > 4096 || rows < 1 || rows > 4096) return AK_ERR_BAD_ARG;
    if (s->texture && (!s->texture->pixels || s->texture->width < cols || s->texture->height < rows))
        return AK_ERR_BAD_ARG;
    const ak_blend blend = s->blend == AK_BLEND_DEFAULT ? AK_BLEND_ALPHA : s->blend;
    if (blend != AK_BLEND_ALPHA && blend != AK_BLEND_ADD && blend != AK_BLEND_OPAQUE) return AK_ERR_BAD_ARG;
    for (size_t k = 0; k < s->order.count; ++k)
        if (s->order.ptr[k] >= n) return AK_ERR_BAD_INDEX;
    if (!camera_finite(camera)) return AK_ERR_BAD_DATA;

    const akp_raster_target t = akp_raster_target_of(raster);
    const int fw = s->texture ? s->texture->width / cols : 1, fh = s->texture ? s->texture->height / rows : 1;
    const uint32_t frame_count = (uint32_t)cols * (uint32_t)rows;
    const float default_size = s->size > 0.0f && ak_finitef(s->size) ? s->size : 0.1f;
    ak_vec4 default_color = s->color;
    if (default_color.x == 0.0f && default_color.y == 0.0f && default_color.z == 0.0f && default_color.w == 0.0f)
        default_color = ak_vec4_make(1, 1, 1, 1);
    const size_t count = s->order.count ? s->order.count : n;
    for (size_t k = 0; k < count; ++k) {
        const size_t i = s->order.count ? s->order.ptr[k] : k;
        const float size = s->sizes.count ? s->sizes.ptr[i] : default_size;
        const ak_vec4 col = s->colors.count ? s->colors.ptr[i] : default_color;
        const ak_vec3 p = s->positions.ptr[i];
        if (!ak_vec3_is_finite(p) || !(size > 0.0f) || !ak_finitef(size) || !ak_finitef(col.x) || !ak_finitef(col.y) ||
            !ak_finitef(col.z) || !ak_finitef(col.w))
            continue;
        /* the corners in view space share the centre's depth */
        ak_vec4 pv = mat_mul4(&camera->view, ak_vec4_make(p.x, p.y, p.z, 1.0f));
        const float h = 0.5f * size;
        ak_vec4 lo = mat_mul4(&camera->projection, ak_vec4_make(pv.x - h, pv.y - h, pv.z, 1.0f));
        ak_vec4 hi = mat_mul4(&camera->projection, ak_vec4_make(pv.x + h, pv.y + h, pv.z, 1.0f));
        if (!(lo.w > 0.0f) || !(hi.w > 0.0f) || !(lo.z >= -lo.w) || !(lo.z <= lo.w)) continue;
        const float X0 = (lo.x / lo.w * 0.5f + 0.5f) * (float)t.width, X1 = (hi.x / hi.w * 0.5f + 0.5f) * (float)t.width;
        const float Y0 = (0.5f - hi.y / hi.w * 0.5f) * (float)t.height, Y1 = (0.5f - lo.y / lo.w * 0.5f) * (float)t.height;
        const float z = lo.z / lo.w * 0.5f + 0.5f;
        if (!(X1 > X0) || !(Y1 > Y0) || !ak_finitef(X0) || !ak_finitef(X1) || !ak_finitef(Y0) || !ak_finitef(Y1))
            continue;
        /* samples whose centre lies in [X0, X1) x [Y0, Y1) */
        const float xa = ceilf(X0 - 0.5f), xb = ceilf(X1 - 0.5f) - 1.0f;
        const float ya = ceilf(Y0 - 0.5f), yb = ceilf(Y1 - 0.5f) - 1.0f;
        const int x0 = xa < 0.0f ? 0 : (xa > (float)t.width ? t.width : (int)xa);
        const int x1 = xb >= (float)t.width ? t.width - 1 : (xb < -1.0f ? -1 : (int)xb);
        const int y0 = ya < 0.0f ? 0 : (ya > (float)t.height ? t.height : (int)ya);
        const int y1 = yb >= (float)t.height ? t.height - 1 : (yb < -1.0f ? -1 : (int)yb);
        const uint32_t frame = (s->frames.count ? s->frames.ptr[i] : 0u) % frame_count;
        const int fx0 = (int)(frame % (uint32_t)cols) * fw, fy0 = (int)(frame / (uint32_t)cols) * fh;
        const float tint[4] = {clamp01f(col.x), clamp01f(col.y), clamp01f(col.z), clamp01f(col.w)};
        const float iw = 1.0f / (X1 - X0), ih = 1.0f / (Y1 - Y0);
        for (int y = y0; y <= y1; ++y) {
            const float v = ((float)y + 0.5f - Y0) * ih;
            const tap_row row = s->texture ? tap_row_at(s->texture, fx0, fy0, fh, v) : (tap_row){NULL, NULL, 0.0f};
            uint8_t* crow = t.color + (size_t)y * (size_t)t.width * 4u;
            float* zrow = t.depth + (size_t)y * (size_t)t.width;
            for (int x = x0; x <= x1; ++x) {
                if (!(z < zrow[x])) continue;
                const float u = ((float)x + 0.5f - X0) * iw;
                float tex[4];
                if (s->texture) {
                    sample_row(&row, fw, u, tex);
                    if (!(tex[3] > 0.0f) && blend != AK_BLEND_OPAQUE) continue;
                } else {
                    tex[0] = tex[1] = tex[2] = 255.0f;
                    tex[3] = disc_alpha(u, v);
                }
                const float a = tex[3] * tint[3];
                uint8_t* px = crow + (size_t)x * 4u;
                if (blend == AK_BLEND_OPAQUE) {
                    if (a < 0.5f) continue;
                    for (int c = 0; c < 3; ++c) px[c] = (uint8_t)(tex[c] * tint[c] + 0.5f);
                    zrow[x] = z;
                } else if (blend == AK_BLEND_ADD) {
                    for (int c = 0; c < 3; ++c) {
                        float sum = (float)px[c] + tex[c] * tint[c] * a;
                        px[c] = (uint8_t)(sum >= 255.0f ? 255.0f : sum + 0.5f);
                    }
                } else {
                    if (!(a > 0.0f)) continue;
                    for (int c = 0; c < 3; ++c) {
                        float out = tex[c] * tint[c] * a + (float)px[c] * (1.0f - a);
                        px[c] = (uint8_t)(out >= 255.0f ? 255.0f : out + 0.5f);
                    }
                }
            }
        }
    }
    return AK_OK;
}

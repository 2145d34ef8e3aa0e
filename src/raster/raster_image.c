/* sRGB conversion, 2D drawing on RGBA8 images and the built-in 5x7 bitmap font. */
#include <math.h>

#include <animkit/raster.h>

#include "../internal.h"

/* ---- the font --------------------------------------------------------------------------- */

/* Printable ASCII 32..126, 7 rows each, bit 4 = leftmost column. Drawn by hand for animkit. */
static const uint8_t k_font[95][7] = {
    {0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00}, /* space */
    {0x04, 0x04, 0x04, 0x04, 0x04, 0x00, 0x04}, /* ! */
    {0x0A, 0x0A, 0x00, 0x00, 0x00, 0x00, 0x00}, /* " */
    {0x0A, 0x0A, 0x1F, 0x0A, 0x1F, 0x0A, 0x0A}, /* # */
    {0x04, 0x0F, 0x14, 0x0E, 0x05, 0x1E, 0x04}, /* $ */
    {0x19, 0x19, 0x02, 0x04, 0x08, 0x13, 0x13}, /* % */
    {0x08, 0x14, 0x14, 0x08, 0x15, 0x12, 0x0D}, /* & */
    {0x04, 0x04, 0x00, 0x00, 0x00, 0x00, 0x00}, /* ' */
    {0x02, 0x04, 0x08, 0x08, 0x08, 0x04, 0x02}, /* ( */
    {0x08, 0x04, 0x02, 0x02, 0x02, 0x04, 0x08}, /* ) */
    {0x00, 0x04, 0x15, 0x0E, 0x15, 0x04, 0x00}, /* * */
    {0x00, 0x04, 0x04, 0x1F, 0x04, 0x04, 0x00}, /* + */
    {0x00, 0x00, 0x00, 0x00, 0x0C, 0x04, 0x08}, /* , */
    {0x00, 0x00, 0x00, 0x1F, 0x00, 0x00, 0x00}, /* - */
    {0x00, 0x00, 0x00, 0x00, 0x00, 0x0C, 0x0C}, /* . */
    {0x01, 0x01, 0x02, 0x04, 0x08, 0x10, 0x10}, /* / */
    {0x0E, 0x11, 0x13, 0x15, 0x19, 0x11, 0x0E}, /* 0 */
    {0x04, 0x0C, 0x04, 0x04, 0x04, 0x04, 0x0E}, /* 1 */
    {0x0E, 0x11, 0x01, 0x02, 0x04, 0x08, 0x1F}, /* 2 */
    {0x1F, 0x02, 0x04, 0x02, 0x01, 0x11, 0x0E}, /* 3 */
    {0x02, 0x06, 0x0A, 0x12, 0x1F, 0x02, 0x02}, /* 4 */
    {0x1F, 0x10, 0x1E, 0x01, 0x01, 0x11, 0x0E}, /* 5 */
    {0x06, 0x08, 0x10, 0x1E, 0x11, 0x11, 0x0E}, /* 6 */
    {0x1F, 0x01, 0x02, 0x04, 0x08, 0x08, 0x08}, /* 7 */
    {0x0E, 0x11, 0x11, 0x0E, 0x11, 0x11, 0x0E}, /* 8 */
    {0x0E, 0x11, 0x11, 0x0F, 0x01, 0x02, 0x0C}, /* 9 */
    {0x00, 0x0C, 0x0C, 0x00, 0x0C, 0x0C, 0x00}, /* : */
    {0x00, 0x0C, 0x0C, 0x00, 0x0C, 0x04, 0x08}, /* ; */
    {0x02, 0x04, 0x08, 0x10, 0x08, 0x04, 0x02}, /* < */
    {0x00, 0x00, 0x1F, 0x00, 0x1F, 0x00, 0x00}, /* = */
    {0x08, 0x04, 0x02, 0x01, 0x02, 0x04, 0x08}, /* > */
    {0x0E, 0x11, 0x01, 0x02, 0x04, 0x00, 0x04}, /* ? */
    {0x0E, 0x11, 0x17, 0x15, 0x17, 0x10, 0x0E}, /* @ */
    {0x0E, 0x11, 0x11, 0x1F, 0x11, 0x11, 0x11}, /* A */
    {0x1E, 0x11, 0x11, 0x1E, 0x11, 0x11, 0x1E}, /* B */
    {0x0E, 0x11, 0x10, 0x10, 0x10, 0x11, 0x0E}, /* C */
    {0x1C, 0x12, 0x11, 0x11, 0x11, 0x12, 0x1C}, /* D */
    {0x1F, 0x10, 0x10, 0x1E, 0x10, 0x10, 0x1F}, /* E */
    {0x1F, 0x10, 0x10, 0x1E, 0x10, 0x10, 0x10}, /* F */
    {0x0E, 0x11, 0x10, 0x17, 0x11, 0x11, 0x0F}, /* G */
    {0x11, 0x11, 0x11, 0x1F, 0x11, 0x11, 0x11}, /* H */
    {0x0E, 0x04, 0x04, 0x04, 0x04, 0x04, 0x0E}, /* I */
    {0x07, 0x02, 0x02, 0x02, 0x02, 0x12, 0x0C}, /* J */
    {0x11, 0x12, 0x14, 0x18, 0x14, 0x12, 0x11}, /* K */
    {0x10, 0x10, 0x10, 0x10, 0x10, 0x10, 0x1F}, /* L */
    {0x11, 0x1B, 0x15, 0x15, 0x11, 0x11, 0x11}, /* M */
    {0x11, 0x11, 0x19, 0x15, 0x13, 0x11, 0x11}, /* N */
    {0x0E, 0x11, 0x11, 0x11, 0x11, 0x11, 0x0E}, /* O */
    {0x1E, 0x11, 0x11, 0x1E, 0x10, 0x10, 0x10}, /* P */
    {0x0E, 0x11, 0x11, 0x11, 0x15, 0x12, 0x0D}, /* Q */
    {0x1E, 0x11, 0x11, 0x1E, 0x14, 0x12, 0x11}, /* R */
    {0x0F, 0x10, 0x10, 0x0E, 0x01, 0x01, 0x1E}, /* S */
    {0x1F, 0x04, 0x04, 0x04, 0x04, 0x04, 0x04}, /* T */
    {0x11, 0x11, 0x11, 0x11, 0x11, 0x11, 0x0E}, /* U */
    {0x11, 0x11, 0x11, 0x11, 0x11, 0x0A, 0x04}, /* V */
    {0x11, 0x11, 0x11, 0x15, 0x15, 0x15, 0x0A}, /* W */
    {0x11, 0x11, 0x0A, 0x04, 0x0A, 0x11, 0x11}, /* X */
    {0x11, 0x11, 0x11, 0x0A, 0x04, 0x04, 0x04}, /* Y */
    {0x1F, 0x01, 0x02, 0x04, 0x08, 0x10, 0x1F}, /* Z */
    {0x0E, 0x08, 0x08, 0x08, 0x08, 0x08, 0x0E}, /* [ */
    {0x10, 0x10, 0x08, 0x04, 0x02, 0x01, 0x01}, /* backslash */
    {0x0E, 0x02, 0x02, 0x02, 0x02, 0x02, 0x0E}, /* ] */
    {0x04, 0x0A, 0x11, 0x00, 0x00, 0x00, 0x00}, /* ^ */
    {0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x1F}, /* _ */
    {0x08, 0x04, 0x00, 0x00, 0x00, 0x00, 0x00}, /* ` */
    {0x00, 0x00, 0x0E, 0x01, 0x0F, 0x11, 0x0F}, /* a */
    {0x10, 0x10, 0x16, 0x19, 0x11, 0x11, 0x1E}, /* b */
    {0x00, 0x00, 0x0E, 0x10, 0x10, 0x11, 0x0E}, /* c */
    {0x01, 0x01, 0x0D, 0x13, 0x11, 0x11, 0x0F}, /* d */
    {0x00, 0x00, 0x0E, 0x11, 0x1F, 0x10, 0x0E}, /* e */
    {0x06, 0x09, 0x08, 0x1C, 0x08, 0x08, 0x08}, /* f */
    {0x00, 0x00, 0x0F, 0x11, 0x0F, 0x01, 0x0E}, /* g */
    {0x10, 0x10, 0x16, 0x19, 0x11, 0x11, 0x11}, /* h */
    {0x04, 0x00, 0x0C, 0x04, 0x04, 0x04, 0x0E}, /* i */
    {0x02, 0x00, 0x06, 0x02, 0x02, 0x12, 0x0C}, /* j */
    {0x10, 0x10, 0x12, 0x14, 0x18, 0x14, 0x12}, /* k */
    {0x0C, 0x04, 0x04, 0x04, 0x04, 0x04, 0x0E}, /* l */
    {0x00, 0x00, 0x1A, 0x15, 0x15, 0x11, 0x11}, /* m */
    {0x00, 0x00, 0x16, 0x19, 0x11, 0x11, 0x11}, /* n */
    {0x00, 0x00, 0x0E, 0x11, 0x11, 0x11, 0x0E}, /* o */
    {0x00, 0x00, 0x1E, 0x11, 0x1E, 0x10, 0x10}, /* p */
    {0x00, 0x00, 0x0D, 0x13, 0x0F, 0x01, 0x01}, /* q */
    {0x00, 0x00, 0x16, 0x19, 0x10, 0x10, 0x10}, /* r */
    {0x00, 0x00, 0x0E, 0x10, 0x0E, 0x01, 0x1E}, /* s */
    {0x08, 0x08, 0x1C, 0x08, 0x08, 0x09, 0x06}, /* t */
    {0x00, 0x00, 0x11, 0x11, 0x11, 0x13, 0x0D}, /* u */
    {0x00, 0x00, 0x11, 0x11, 0x11, 0x0A, 0x04}, /* v */
    {0x00, 0x00, 0x11, 0x11, 0x15, 0x15, 0x0A}, /* w */
    {0x00, 0x00, 0x11, 0x0A, 0x04, 0x0A, 0x11}, /* x */
    {0x00, 0x00, 0x11, 0x11, 0x0F, 0x01, 0x0E}, /* y */
    {0x00, 0x00, 0x1F, 0x02, 0x04, 0x08, 0x1F}, /* z */
    {0x02, 0x04, 0x04, 0x08, 0x04, 0x04, 0x02}, /* { */
    {0x04, 0x04, 0x04, 0x04, 0x04, 0x04, 0x04}, /* | */
    {0x08, 0x04, 0x04, 0x02, 0x04, 0x04, 0x08}, /* } */
    {0x00, 0x00, 0x08, 0x15, 0x02, 0x00, 0x00}, /* ~ */
};

/* ---- helpers -------------------------------------------------------------------------------- */

static inline float clamp01(float x) { return x < 0.0f ? 0.0f : (x > 1.0f ? 1.0f : x); }

/* float -> int clamped to [lo, hi] without undefined behaviour for huge values or NaN (-> lo). */
static inline int to_int_clamped(float v, int lo, int hi) {
    if (!(v >= (float)lo)) return lo;
    if (v >= (float)hi) return hi;
    return (int)v;
}

static bool image_ok(const ak_image* im) {
    return im && im->pixels && im->width > 0 && im->height > 0 &&
           (im->stride == 0 || im->stride >= (size_t)im->width * 4u);
}

static ak_result image_check(const ak_image* im) {
    if (!im || !im->pixels) return AK_ERR_NULL_ARG;
    return image_ok(im) ? AK_OK : AK_ERR_BAD_ARG;
}

/* Blend colour c (bytes) into pixel p with coverage cov in [0,1] times c's alpha. */
static inline void blend(uint8_t* p, const uint8_t c[4], float cov) {
    float a = cov * (float)c[3] * (1.0f / 255.0f);
    if (a <= 0.0f) return;
    if (a >= 1.0f) {
        p[0] = c[0];
        p[1] = c[1];
        p[2] = c[2];
        p[3] = 255;
        return;
    }
    for (int k = 0; k < 3; ++k) p[k] = (uint8_t)((float)p[k] + ((float)c[k] - (float)p[k]) * a + 0.5f);
    p[3] = (uint8_t)((float)p[3] + (255.0f - (float)p[3]) * a + 0.5f);
}

/* ---- public: colour -------------------------------------------------------------------------- */

void ak_color_to_rgba8(ak_vec4 color, uint8_t out_rgba[4]) {
    float c[4] = {color.x, color.y, color.z, color.w};
    for (int k = 0; k < 4; ++k) out_rgba[k] = (uint8_t)(clamp01(ak_finitef(c[k]) ? c[k] : 0.0f) * 255.0f + 0.5f);
}

float ak_srgb_to_linear(float s) {
    if (!(s > 0.0f)) return 0.0f;
    if (s <= 0.04045f) return s / 12.92f;
    return powf((s + 0.055f) / 1.055f, 2.4f);
}

float ak_linear_to_srgb(float l) {
    if (!(l > 0.0f)) return 0.0f;
    if (l <= 0.0031308f) return l * 12.92f;
    return 1.055f * powf(l, 1.0f / 2.4f) - 0.055f;
}

/* ---- public: 2D drawing ------------------------------------------------------------------------ */

ak_result ak_image_fill(const ak_image* image, ak_vec4 color) {
    ak_result r = image_check(image);
    if (r != AK_OK) return r;
    uint8_t c[4];
    ak_color_to_rgba8(color, c);
    for (int y = 0; y < image->height; ++y)
        for (int x = 0; x < image->width; ++x) memcpy(ak_image_pixel(image, x, y), c, 4);
    return AK_OK;
}

ak_result ak_image_fill_rect(const ak_image* image, float x, float y, float w, float h, ak_vec4 color) {
    ak_result r = image_check(image);
    if (r != AK_OK) return r;
    if (!ak_finitef(x) || !ak_finitef(y) || !ak_finitef(w) || !ak_finitef(h)) return AK_OK;
    uint8_t c[4];
    ak_color_to_rgba8(color, c);
    float x1 = x + w, y1 = y + h;
    int ix0 = to_int_clamped(floorf(x), 0, image->width), iy0 = to_int_clamped(floorf(y), 0, image->height);
    int ix1 = to_int_clamped(ceilf(x1), 0, image->width), iy1 = to_int_clamped(ceilf(y1), 0, image->height);
    /* blend() of a coverage seen before is a table lookup per channel: the tables hold blend()'s
     * own results for each byte value (the same float operations), built once per distinct
     * partial coverage (one for a translucent rectangle's inside) */
    uint8_t lut[4][256];
    float lut_cov = -1.0f;
    for (int py = iy0; py < iy1; ++py) {
        float cy = clamp01(ak_minf((float)py + 1.0f, y1) - ak_maxf((float)py, y));
        for (int px = ix0; px < ix1; ++px) {
            float cx = clamp01(ak_minf((float)px + 1.0f, x1) - ak_maxf((float)px, x));
            float cov = cx * cy;
            float a = cov * (float)c[3] * (1.0f / 255.0f);
            if (!(a > 0.0f && a < 1.0f) || cx != 1.0f ||
                ix1 - ix0 < 64) { /* edges, small or opaque */
                blend(ak_image_pixel(image, px, py), c, cov);
                continue;
            }
            if (cov != lut_cov) {
                for (int v = 0; v < 256; ++v) {
                    for (int k = 0; k < 3; ++k)
                        lut[k][v] = (uint8_t)((float)v + ((float)c[k] - (float)v) * a + 0.5f);
                    lut[3][v] = (uint8_t)((float)v + (255.0f - (float)v) * a + 0.5f);
                }
                lut_cov = cov;
            }
            uint8_t* p = ak_image_pixel(image, px, py);
            for (int k = 0; k < 4; ++k) p[k] = lut[k][p[k]];
        }
    }
    return AK_OK;
}

ak_result ak_image_draw_line(const ak_image* image, ak_vec2 a, ak_vec2 b, float width, ak_vec4 color) {
    ak_result r = image_check(image);
    if (r != AK_OK) return r;
    if (!ak_finitef(a.x) || !ak_finitef(a.y) || !ak_finitef(b.x) || !ak_finitef(b.y)) return AK_OK;
    if (!(width > 0.0f) || !ak_finitef(width)) width = 1.0f;
    uint8_t c[4];
    ak_color_to_rgba8(color, c);
    const float hw = 0.5f * width;
    float minx = ak_minf(a.x, b.x) - hw - 1.0f, maxx = ak_maxf(a.x, b.x) + hw + 1.0f;
    float miny = ak_minf(a.y, b.y) - hw - 1.0f, maxy = ak_maxf(a.y, b.y) + hw + 1.0f;
    int x0 = to_int_clamped(floorf(minx), 0, image->width), x1 = to_int_clamped(ceilf(maxx), -1, image->width - 1);
    int y0 = to_int_clamped(floorf(miny), 0, image->height), y1 = to_int_clamped(ceilf(maxy), -1, image->height - 1);
    float dx = b.x - a.x, dy = b.y - a.y, l2 = dx * dx + dy * dy;
    for (int py = y0; py <= y1; ++py)
        for (int px = x0; px <= x1; ++px) {
            float qx = (float)px + 0.5f - a.x, qy = (float)py + 0.5f - a.y;
            float t = l2 > 0.0f ? clamp01((qx * dx + qy * dy) / l2) : 0.0f;
            float ex = qx - t * dx, ey = qy - t * dy;
            float d = sqrtf(ex * ex + ey * ey);
            float cov = clamp01(hw + 0.5f - d);
            if (width < 1.0f) cov *= width; /* thin lines: fade instead of thinning below a pixel */
            if (cov > 0.0f) blend(ak_image_pixel(image, px, py), c, cov);
        }
    return AK_OK;
}

ak_result ak_image_draw_disc(const ak_image* image, ak_vec2 center, float radius, ak_vec4 color, float outline_width,
                             ak_vec4 outline_color) {
    ak_result r = image_check(image);
    if (r != AK_OK) return r;
    if (!ak_finitef(center.x) || !ak_finitef(center.y) || !(radius > 0.0f) || !ak_finitef(radius)) return AK_OK;
    if (!(outline_width > 0.0f) || !ak_finitef(outline_width)) outline_width = 0.0f;
    uint8_t c[4], oc[4];
    ak_color_to_rgba8(color, c);
    ak_color_to_rgba8(outline_color, oc);
    float R = radius + outline_width;
    int x0 = to_int_clamped(floorf(center.x - R - 1.0f), 0, image->width);
    int x1 = to_int_clamped(ceilf(center.x + R + 1.0f), -1, image->width - 1);
    int y0 = to_int_clamped(floorf(center.y - R - 1.0f), 0, image->height);
    int y1 = to_int_clamped(ceilf(center.y + R + 1.0f), -1, image->height - 1);
    for (int py = y0; py <= y1; ++py)
        for (int px = x0; px <= x1; ++px) {
            float qx = (float)px + 0.5f - center.x, qy = (float)py + 0.5f - center.y;
            float d = sqrtf(qx * qx + qy * qy);
            uint8_t* p = ak_image_pixel(image, px, py);
            if (outline_width > 0.0f) blend(p, oc, clamp01(R + 0.5f - d));
            blend(p, c, clamp01(radius + 0.5f - d));
        }
    return AK_OK;
}

ak_result ak_image_blit(const ak_image* dst, int x, int y, const ak_image* src) {
    if (!dst || !src || !dst->pixels || !src->pixels) return AK_ERR_NULL_ARG;
    if (!image_ok(dst) || !image_ok(src)) return AK_ERR_BAD_ARG;
    for (int sy = 0; sy < src->height; ++sy) {
        int dy = y + sy;
        if (dy < 0 || dy >= dst->height) continue;
        int sx0 = x < 0 ? -x : 0;
        int sx1 = src->width;
        if (x + sx1 > dst->width) sx1 = dst->width - x;
        if (sx0 >= sx1) continue;
        memcpy(ak_image_pixel(dst, x + sx0, dy), ak_image_pixel(src, sx0, sy), (size_t)(sx1 - sx0) * 4u);
    }
    return AK_OK;
}

/* ---- public: text ------------------------------------------------------------------------------- */

void ak_font_glyph(char c, uint8_t out_rows[7]) {
    int i = (unsigned char)c;
    if (i < 32 || i > 126) i = '?';
    memcpy(out_rows, k_font[i - 32], 7);
}

void ak_text_size(const char* text, int scale, int* out_width, int* out_height) {
    int s = scale > 0 ? (scale > 64 ? 64 : scale) : 1;
    int w = 0, lines = 0, cur = 0;
    if (text && *text) {
        lines = 1;
        for (const char* p = text; *p; ++p) {
            if (*p == '\n') {
                ++lines;
                cur = 0;
                continue;
            }
            ++cur;
            if (cur > w) w = cur;
        }
    }
    if (out_width) *out_width = w > 0 ? (w * AK_FONT_ADVANCE_X - (AK_FONT_ADVANCE_X - AK_FONT_GLYPH_WIDTH)) * s : 0;
    if (out_height)
        *out_height = lines > 0 ? (lines * AK_FONT_ADVANCE_Y - (AK_FONT_ADVANCE_Y - AK_FONT_GLYPH_HEIGHT)) * s : 0;
}

ak_result ak_image_draw_text(const ak_image* image, int x, int y, const char* text, int scale, ak_vec4 color) {
    if (!image || !text || !image->pixels) return AK_ERR_NULL_ARG;
    if (!image_ok(image)) return AK_ERR_BAD_ARG;
    int s = scale > 0 ? (scale > 64 ? 64 : scale) : 1;
    /* far outside any image: nothing to draw (and no int overflow further down) */
    if (x < -(1 << 24) || x > (1 << 24) || y < -(1 << 24) || y > (1 << 24)) return AK_OK;
    uint8_t c[4];
    ak_color_to_rgba8(color, c);
    int cx = x, cy = y;
    for (const char* p = text; *p; ++p) {
        if (*p == '\n') {
            cx = x;
            cy += AK_FONT_ADVANCE_Y * s;
            continue;
        }
        uint8_t rows[7];
        ak_font_glyph(*p, rows);
        for (int gy = 0; gy < 7; ++gy)
            for (int gx = 0; gx < 5; ++gx) {
                if (!(rows[gy] & (0x10 >> gx))) continue;
                for (int by = 0; by < s; ++by) {
                    int py = cy + gy * s + by;
                    if (py < 0 || py >= image->height) continue;
                    for (int bx = 0; bx < s; ++bx) {
                        int px = cx + gx * s + bx;
                        if (px < 0 || px >= image->width) continue;
                        blend(ak_image_pixel(image, px, py), c, 1.0f);
                    }
                }
            }
        cx += AK_FONT_ADVANCE_X * s;
    }
    return AK_OK;
}

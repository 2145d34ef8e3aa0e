/* Render target, camera, clipping, triangle setup and the threaded rasterizer.
 *
 * Pipeline of a draw call: each input (mesh triangle, line segment, point) is transformed to
 * clip space, culled, shaded at the vertices as the mode needs, clipped against the near/far
 * planes and a guard band, projected, snapped to 1/256 sample units and rasterized with
 * integer edge functions. With one thread every triangle is rasterized as soon as it is set
 * up. With several, the draw runs in rounds: the threads set up consecutive chunks of inputs
 * into their own segments, meet at a barrier, and then each rasterizes only the rows it owns
 * (32-row blocks of samples dealt out round-robin) of every segment in input order. No two
 * threads write the same pixel, and the per-pixel drawing order is the input order for any
 * thread count, so the image does not depend on it. */
#include <math.h>

#include <animkit/raster.h>

#include "../internal.h"
#include "raster_internal.h"
#include "../tasks.h"
#if defined(__wasm_simd128__)
#include <wasm_simd128.h> /* the WebAssembly build's SIMD128 paths (tex_sample, ground_row_simd) */
#endif

/* ---- private types ------------------------------------------------------------------ */

#define MAXA 12          /* attributes per vertex */
#define MAX_THREADS 64
#define SUBPIX 256       /* fixed-point sub-sample units */
#define GUARD 4.0f       /* guard band in NDC units: |x|, |y| <= GUARD * w */
#define SHADOW_RES 256
#define ROW_BLOCK_SHIFT 5
#define CHUNK 2048          /* inputs each thread sets up per round */
#define SEG_CAP (2 * CHUNK) /* set-up triangles a thread's segment holds */
#define OUT_PER_INPUT 7     /* worst case triangles from one clipped triangle */
#define TONE_LUT_SIZE 8192 /* covers linear [0, 2] */
#define POW_LUT_SIZE 1024

#if defined(__GNUC__)
#define FORCE_INLINE inline __attribute__((always_inline))
#else
#define FORCE_INLINE inline
#endif

typedef enum frag_mode {
    FRAG_UNLIT_CONST = 0, /* flat[] colour as bytes (unlit), no attributes */
    FRAG_UNLIT_VCOLOR,    /* attr 0..3 sRGB colour (unlit) */
    FRAG_FLAT,            /* flat[] linear colour computed at setup */
    FRAG_GOURAUD,         /* attr 0..3 linear lit colour */
    FRAG_PHONG,           /* attr 0..2 world pos, 3..5 normal */
    FRAG_PHONG_VC,        /* FRAG_PHONG plus 6..9 linear vertex colour */
    FRAG_POINT,           /* attr 0..1 disc coordinates in [-1,1], flat[] colour */
    FRAG_GROUND           /* attr 0..2 world position */
} frag_mode;

typedef struct cvert {
    float c[4];
    float a[MAXA];
} cvert;

typedef struct rtri {
    int64_t A[3], B[3], C[3];
    int64_t bias[3];
    float inv_area;
    float z0, dz1, dz2;
    float iw0, diw1, diw2;
    float a0[MAXA], da1[MAXA], da2[MAXA];
    float flat[4];
    int x0, x1, y0, y1;
    bool minify; /* textured: more texels than samples over the triangle */
} rtri;

typedef struct drawctx drawctx;
/* Where set-up triangles go: straight to the rasterizer of the thread that made them. */
/* Where set-up triangles go: appended to a thread's segment (buf != NULL), or straight to
 * the rasterizer (single thread). */
typedef struct sink {
    rtri t;
    rtri* buf;          /* segment, or NULL to rasterize at once */
    size_t count, cap;  /* triangles in buf, and its capacity */
} sink;
typedef void (*setup_fn)(const drawctx* dc, size_t input_index, sink* sk);

struct drawctx {
    ak_raster* r;
    frag_mode mode;
    int attr_count;
    ak_blend blend;
    bool depth_test, depth_write;
    bool cull;
    bool has_vcolor;
    float depth_bias;
    /* transforms */
    ak_mat4 model, vp, mvp; /* mvp = vp * model */
    bool model_identity;
    ak_mat3 normal_matrix;
    ak_vec3 eye, view_forward;
    bool ortho;
    /* shading */
    ak_vec3 base_lin;
    float base_alpha;
    float specular, shininess;
    float pow_lut[POW_LUT_SIZE + 1]; /* specular * x^shininess for x in [0, 1] */
    ak_vec3 key_l, fill_l; /* unit vectors towards the lights */
    ak_vec3 key_c, fill_c, amb_c;
    float const_rgba[4];   /* FRAG_UNLIT_CONST bytes / FRAG_POINT linear colour */
    float outline_rgba[4];
    float outline_frac;    /* FRAG_POINT: inner radius / outer radius */
    /* inputs */
    const ak_raster_mesh* mesh;
    const ak_raster_lines* lines;
    const ak_raster_points* points;
    const cvert* quad;     /* ground: 4 corners */
    const ak_raster_texture* tex; /* textured mesh: UVs are attributes uv_attr, uv_attr + 1 */
    int uv_attr;
    size_t tex_stride;
    float half_width_px;   /* lines: half width in samples; points: radius in samples */
    /* ground */
    ak_vec3 ground_lin, line_lin;
    float ground_h, ground_cx, ground_cz, ground_e, grid_spacing, pix_angle;
    bool shadow;
    setup_fn setup;
    size_t input_count;
};

struct ak_raster {
    ak_raster_desc desc;
    ak_allocator alloc;
    bool has_alloc;
    int sw, sh, ss;
    uint8_t* color;   /* sw * sh * 4 */
    float* depth;     /* sw * sh */
    float* shadow;    /* SHADOW_RES^2 */
    rtri* segs;       /* thread_count * SEG_CAP when thread_count > 1, else NULL */
    float* shadow_tmp;
    float to_srgb_lut[4097]; /* linear [0,1] -> sRGB byte (as float) */
    float to_lin_lut[256];   /* sRGB byte -> linear */
    float tone_lut[TONE_LUT_SIZE + 1]; /* shaded linear [0, 2] -> sRGB byte, soft shoulder */
};

/* ---- small helpers -------------------------------------------------------------------- */

static inline float clamp01(float x) { return x < 0.0f ? 0.0f : (x > 1.0f ? 1.0f : x); }

/* Shaded linear value -> sRGB byte through the tone curve (a soft shoulder above 0.8 keeps
 * highlights from clipping flat). */
static inline uint8_t enc(const ak_raster* r, float lin) {
    if (!(lin > 0.0f)) lin = 0.0f;
    if (lin > 2.0f) lin = 2.0f;
    return (uint8_t)r->tone_lut[(int)(lin * (TONE_LUT_SIZE / 2) + 0.5f)];
}

static float tone(float lin) {
    if (lin > 0.8f) lin = 0.8f + 0.2f * (1.0f - expf(-(lin - 0.8f) * 5.0f));
    return lin > 1.0f ? 1.0f : lin;
}

static ak_vec3 srgb3_to_lin(ak_vec4 c) {
    return ak_vec3_make(ak_srgb_to_linear(clamp01(c.x)), ak_srgb_to_linear(clamp01(c.y)),
                        ak_srgb_to_linear(clamp01(c.z)));
}

static bool vec4_is_zero(ak_vec4 v) { return v.x == 0.0f && v.y == 0.0f && v.z == 0.0f && v.w == 0.0f; }
static bool vec3_is_zero(ak_vec3 v) { return v.x == 0.0f && v.y == 0.0f && v.z == 0.0f; }
static bool vec4_finite(ak_vec4 v) { return ak_finitef(v.x) && ak_finitef(v.y) && ak_finitef(v.z) && ak_finitef(v.w); }

static ak_vec4 mul4(const ak_mat4* m, ak_vec3 p) {
    const float* a = m->m;
    return ak_vec4_make(a[0] * p.x + a[4] * p.y + a[8] * p.z + a[12], a[1] * p.x + a[5] * p.y + a[9] * p.z + a[13],
                        a[2] * p.x + a[6] * p.y + a[10] * p.z + a[14], a[3] * p.x + a[7] * p.y + a[11] * p.z + a[15]);
}

static ak_vec3 eye_of(const ak_raster_camera* cam) {
    ak_mat4 inv = ak_mat4_inverse_affine(cam->view);
    return ak_mat4_get_translation(inv);
}

/* ---- camera ----------------------------------------------------------------------------- */

ak_raster_camera ak_raster_camera_perspective(ak_vec3 eye, ak_vec3 target, float fovy, float aspect, float near_z,
                                              float far_z) {
    ak_raster_camera c;
    c.view = ak_mat4_look_at(eye, target, ak_vec3_make(0.0f, 1.0f, 0.0f));
    c.projection = ak_mat4_perspective(fovy, aspect, near_z, far_z);
    return c;
}

ak_raster_camera ak_raster_camera_orthographic(ak_vec3 eye, ak_vec3 target, float half_height, float aspect,
                                               float near_z, float far_z) {
    ak_raster_camera c;
    if (!(half_height > 0.0f) || !ak_finitef(half_height)) half_height = 1.0f;
    if (!(aspect > 0.0f) || !ak_finitef(aspect)) aspect = 1.0f;
    c.view = ak_mat4_look_at(eye, target, ak_vec3_make(0.0f, 1.0f, 0.0f));
    c.projection = ak_mat4_orthographic(-half_height * aspect, half_height * aspect, -half_height, half_height,
                                        near_z, far_z);
    return c;
}

bool ak_raster_camera_project(const ak_raster_camera* camera, int width, int height, ak_vec3 world,
                              ak_vec3* out_pixel) {
    if (!camera || !out_pixel || !ak_vec3_is_finite(world)) return false;
    ak_mat4 vp = ak_mat4_mul(camera->projection, camera->view);
    ak_vec4 c = mul4(&vp, world);
    if (!(c.z >= -c.w) || !(c.w > 0.0f)) return false;
    float iw = 1.0f / c.w;
    *out_pixel = ak_vec3_make((c.x * iw * 0.5f + 0.5f) * (float)width, (0.5f - c.y * iw * 0.5f) * (float)height,
                              c.z * iw * 0.5f + 0.5f);
    return ak_vec3_is_finite(*out_pixel);
}

/* ---- target lifecycle ----------------------------------------------------------------- */

ak_raster_desc ak_raster_desc_resolved(const ak_raster_desc* desc) {
    ak_raster_desc d;
    memset(&d, 0, sizeof d);
    if (desc) d = *desc;
    if (d.supersample == 0) d.supersample = 1;
    if (d.thread_count == 0) d.thread_count = 1;
    return d;
}

/* The one allocation of a target: its parts' offsets and the total (false: desc out of range). */
typedef struct raster_layout {
    size_t off_color, off_depth, off_shadow, off_tmp, off_segs, nseg, total;
} raster_layout;

static bool raster_layout_of(const ak_raster_desc* d, raster_layout* L) {
    if (d->width < 1 || d->width > 8192 || d->height < 1 || d->height > 8192) return false;
    if (d->supersample < 1 || d->supersample > 4 || d->thread_count < 1 || d->thread_count > MAX_THREADS) return false;
    size_t sw = (size_t)d->width * (size_t)d->supersample, sh = (size_t)d->height * (size_t)d->supersample;
    L->off_color = akp_align16(sizeof(ak_raster));
    L->off_depth = L->off_color + akp_align16(sw * sh * 4u);
    L->off_shadow = L->off_depth + akp_align16(sw * sh * sizeof(float));
    L->off_tmp = L->off_shadow + akp_align16((size_t)SHADOW_RES * SHADOW_RES * sizeof(float));
    L->off_segs = L->off_tmp + akp_align16((size_t)SHADOW_RES * SHADOW_RES * sizeof(float));
    L->nseg = d->thread_count > 1 ? (size_t)d->thread_count * SEG_CAP : 0;
    L->total = L->off_segs + L->nseg * sizeof(rtri);
    return true;
}

size_t ak_raster_memory_size(const ak_raster_desc* desc) {
    if (!desc) return 0;
    const ak_raster_desc d = ak_raster_desc_resolved(desc);
    raster_layout L;
    return raster_layout_of(&d, &L) ? L.total : 0;
}

ak_result ak_raster_create(const ak_raster_desc* desc, const ak_allocator* alloc, ak_raster** out_raster) {
    if (out_raster) *out_raster = NULL;
    if (!desc || !out_raster) return AK_ERR_NULL_ARG;
    if (alloc && (!alloc->alloc != !alloc->free)) return AK_ERR_BAD_ARG;
    ak_raster_desc d = ak_raster_desc_resolved(desc);
    raster_layout L;
    if (!raster_layout_of(&d, &L)) return AK_ERR_BAD_ARG;
    size_t sw = (size_t)d.width * (size_t)d.supersample, sh = (size_t)d.height * (size_t)d.supersample;
    const size_t off_color = L.off_color, off_depth = L.off_depth, off_shadow = L.off_shadow, off_tmp = L.off_tmp,
                 off_segs = L.off_segs, nseg = L.nseg, total = L.total;
    uint8_t* mem = (uint8_t*)akp_alloc(alloc, total);
    if (!mem) return AK_ERR_NO_MEMORY;
    ak_raster* r = (ak_raster*)mem;
    memset(r, 0, sizeof *r);
    r->desc = d;
    if (alloc && alloc->alloc) {
        r->alloc = *alloc;
        r->has_alloc = true;
    }
    r->ss = d.supersample;
    r->sw = (int)sw;
    r->sh = (int)sh;
    r->color = mem + off_color;
    r->depth = (float*)(void*)(mem + off_depth);
    r->shadow = (float*)(void*)(mem + off_shadow);
    r->shadow_tmp = (float*)(void*)(mem + off_tmp);
    r->segs = nseg ? (rtri*)(void*)(mem + off_segs) : NULL;
    for (int i = 0; i <= 4096; ++i) r->to_srgb_lut[i] = floorf(ak_linear_to_srgb((float)i / 4096.0f) * 255.0f + 0.5f);
    for (int i = 0; i < 256; ++i) r->to_lin_lut[i] = ak_srgb_to_linear((float)i / 255.0f);
    for (int i = 0; i <= TONE_LUT_SIZE; ++i)
        r->tone_lut[i] = floorf(ak_linear_to_srgb(tone(2.0f * (float)i / TONE_LUT_SIZE)) * 255.0f + 0.5f);
    memset(r->color, 0, sw * sh * 4u);
    for (size_t i = 0; i < sw * sh; ++i) {
        r->color[i * 4 + 3] = 255;
        r->depth[i] = 1.0f;
    }
    *out_raster = r;
    return AK_OK;
}

void ak_raster_destroy(ak_raster* raster) {
    if (!raster) return;
    ak_allocator a = raster->alloc;
    akp_free(raster->has_alloc ? &a : NULL, raster);
}

ak_raster_desc ak_raster_get_desc(const ak_raster* raster) {
    ak_raster_desc d;
    memset(&d, 0, sizeof d);
    return raster ? raster->desc : d;
}

void ak_raster_clear(ak_raster* raster, ak_vec4 top_color, ak_vec4 bottom_color) {
    if (!raster) return;
    ak_raster_clear_depth(raster);
    ak_vec3 t = srgb3_to_lin(top_color), b = srgb3_to_lin(bottom_color);
    float ta = ak_finitef(top_color.w) ? clamp01(top_color.w) : 1.0f;
    float ba = ak_finitef(bottom_color.w) ? clamp01(bottom_color.w) : 1.0f;
    for (int y = 0; y < raster->sh; ++y) {
        float s = raster->sh > 1 ? (float)y / (float)(raster->sh - 1) : 0.0f;
        ak_vec3 c = ak_vec3_lerp(t, b, s);
        uint8_t px[4] = {(uint8_t)raster->to_srgb_lut[(int)(clamp01(c.x) * 4096.0f + 0.5f)],
                         (uint8_t)raster->to_srgb_lut[(int)(clamp01(c.y) * 4096.0f + 0.5f)],
                         (uint8_t)raster->to_srgb_lut[(int)(clamp01(c.z) * 4096.0f + 0.5f)],
                         (uint8_t)(ak_lerpf(ta, ba, s) * 255.0f + 0.5f)};
        uint8_t* row = raster->color + (size_t)y * (size_t)raster->sw * 4u;
        /* one pixel, then the filled part copied onto the rest, doubling */
        const size_t bytes = (size_t)raster->sw * 4u;
        memcpy(row, px, 4);
        for (size_t done = 4; done < bytes; done *= 2)
            memcpy(row + done, row, done < bytes - done ? done : bytes - done);
    }
}

void ak_raster_clear_depth(ak_raster* raster) {
    if (!raster) return;
    size_t n = (size_t)raster->sw * (size_t)raster->sh;
    for (size_t i = 0; i < n; ++i) raster->depth[i] = 1.0f;
}

ak_result ak_raster_read_samples(const ak_raster* raster, ak_u8_span out_color, ak_f32_span out_depth) {
    if (!raster || (out_color.count && !out_color.ptr) || (out_depth.count && !out_depth.ptr)) return AK_ERR_NULL_ARG;
    const size_t n = (size_t)raster->sw * (size_t)raster->sh;
    if ((out_color.count && out_color.count < 4 * n) || (out_depth.count && out_depth.count < n))
        return AK_ERR_SPAN_SMALL;
    if (out_color.count) memcpy(out_color.ptr, raster->color, 4 * n);
    if (out_depth.count) memcpy(out_depth.ptr, raster->depth, n * sizeof(float));
    return AK_OK;
}

ak_result ak_raster_resolve(const ak_raster* raster, const ak_image* out) {
    if (!raster || !out || !out->pixels) return AK_ERR_NULL_ARG;
    if (out->width != raster->desc.width || out->height != raster->desc.height) return AK_ERR_BAD_ARG;
    const int ss = raster->ss;
    const float inv = 1.0f / (float)(ss * ss);
    if (ss == 1) {
        for (int y = 0; y < out->height; ++y)
            memcpy(ak_image_pixel(out, 0, y), raster->color + (size_t)y * (size_t)raster->sw * 4u,
                   (size_t)out->width * 4u);
        return AK_OK;
    }
    for (int y = 0; y < out->height; ++y) {
        for (int x = 0; x < out->width; ++x) {
            uint8_t* dst = ak_image_pixel(out, x, y);
            float acc[3] = {0, 0, 0};
            unsigned alpha = 0;
            for (int sy = 0; sy < ss; ++sy) {
                const uint8_t* src = raster->color + ((size_t)(y * ss + sy) * (size_t)raster->sw + (size_t)(x * ss)) * 4u;
                for (int sx = 0; sx < ss; ++sx, src += 4) {
                    acc[0] += raster->to_lin_lut[src[0]];
                    acc[1] += raster->to_lin_lut[src[1]];
                    acc[2] += raster->to_lin_lut[src[2]];
                    alpha += src[3];
                }
            }
            for (int k = 0; k < 3; ++k) dst[k] = (uint8_t)raster->to_srgb_lut[(int)(clamp01(acc[k] * inv) * 4096.0f + 0.5f)];
            dst[3] = (uint8_t)((alpha + (unsigned)(ss * ss) / 2u) / (unsigned)(ss * ss));
        }
    }
    return AK_OK;
}

/* ---- lighting ------------------------------------------------------------------------- */

ak_raster_lighting ak_raster_lighting_resolved(const ak_raster_lighting* lighting) {
    ak_raster_lighting l;
    memset(&l, 0, sizeof l);
    if (lighting) l = *lighting;
    if (vec3_is_zero(l.key_direction)) l.key_direction = ak_vec3_make(0.4f, -0.6f, -0.7f);
    if (vec3_is_zero(l.key_color)) l.key_color = ak_vec3_make(1.05f, 1.0f, 0.94f);
    if (vec3_is_zero(l.fill_direction)) l.fill_direction = ak_vec3_make(-0.7f, -0.25f, -0.3f);
    if (vec3_is_zero(l.fill_color)) l.fill_color = ak_vec3_make(0.30f, 0.34f, 0.44f);
    if (vec3_is_zero(l.ambient_color)) l.ambient_color = ak_vec3_make(0.20f, 0.22f, 0.26f);
    return l;
}

static void setup_lighting(drawctx* dc, const ak_raster_lighting* lighting, ak_raster_material mat, bool unlit) {
    ak_raster_lighting l = ak_raster_lighting_resolved(lighting);
    dc->key_l = ak_vec3_normalize(ak_vec3_neg(l.key_direction));
    dc->fill_l = ak_vec3_normalize(ak_vec3_neg(l.fill_direction));
    dc->key_c = l.key_color;
    dc->fill_c = l.fill_color;
    dc->amb_c = l.ambient_color;
    ak_vec4 base = vec4_is_zero(mat.color) ? ak_vec4_make(0.78f, 0.74f, 0.70f, 1.0f) : mat.color;
    if (!vec4_finite(base)) base = ak_vec4_make(0.78f, 0.74f, 0.70f, 1.0f);
    dc->base_lin = srgb3_to_lin(base);
    dc->base_alpha = clamp01(base.w);
    dc->specular = mat.specular == 0.0f ? 0.25f : (mat.specular < 0.0f ? 0.0f : mat.specular);
    dc->shininess = mat.shininess > 0.0f ? mat.shininess : 32.0f;
    if (!ak_finitef(dc->specular)) dc->specular = 0.25f;
    if (!ak_finitef(dc->shininess)) dc->shininess = 32.0f;
    if (unlit) return; /* no specular term: skip the table (1,025 powf, most of a small draw's set-up) */
    for (int i = 0; i <= POW_LUT_SIZE; ++i)
        dc->pow_lut[i] = dc->specular * powf((float)i / POW_LUT_SIZE, dc->shininess);
}

/* Unit vector, or zero for a zero/degenerate vector (NaN-free). */
static inline ak_vec3 fast_normalize(ak_vec3 a) {
    float l2 = a.x * a.x + a.y * a.y + a.z * a.z;
    float s = l2 > 1e-30f ? 1.0f / sqrtf(l2) : 0.0f;
    return ak_vec3_make(a.x * s, a.y * s, a.z * s);
}

/* Lit linear colour for unit normal n at world point p with linear albedo alb. */
static inline ak_vec3 shade(const drawctx* dc, ak_vec3 n, ak_vec3 p, ak_vec3 alb) {
    ak_vec3 v = dc->ortho ? ak_vec3_neg(dc->view_forward) : fast_normalize(ak_vec3_sub(dc->eye, p));
    /* two-sided lighting: light the side that faces the viewer, whatever the winding says */
    if (!dc->cull && ak_vec3_dot(n, v) < 0.0f) n = ak_vec3_neg(n);
    float kd = ak_vec3_dot(n, dc->key_l), fd = ak_vec3_dot(n, dc->fill_l);
    kd = kd > 0.0f ? kd : 0.0f;
    fd = fd > 0.0f ? fd : 0.0f;
    /* hemisphere ambient: a little brighter facing up */
    float hemi = 0.8f + 0.2f * n.y;
    ak_vec3 light = ak_vec3_make(dc->amb_c.x * hemi + dc->key_c.x * kd + dc->fill_c.x * fd,
                                 dc->amb_c.y * hemi + dc->key_c.y * kd + dc->fill_c.y * fd,
                                 dc->amb_c.z * hemi + dc->key_c.z * kd + dc->fill_c.z * fd);
    ak_vec3 c = ak_vec3_mul(alb, light);
    if (dc->specular > 0.0f && kd > 0.0f) {
        /* Phong: the light's mirror direction R = 2 (n.l) n - l against the view direction */
        ak_vec3 rl = ak_vec3_sub(ak_vec3_scale(n, 2.0f * kd), dc->key_l);
        float rv = ak_vec3_dot(rl, v);
        if (rv > 0.0f) {
            float s = dc->pow_lut[(int)(ak_minf(rv, 1.0f) * POW_LUT_SIZE + 0.5f)];
            c = ak_vec3_madd(c, dc->key_c, s);
        }
    }
    return c;
}

static void raster_tri(const drawctx* dc, const rtri* t, int ti, int tc);

/* ---- clipping and setup ------------------------------------------------------------------ */

static const float k_planes[6][4] = {
    {0, 0, 1, 1}, {0, 0, -1, 1}, {1, 0, 0, GUARD}, {-1, 0, 0, GUARD}, {0, 1, 0, GUARD}, {0, -1, 0, GUARD},
};

static inline float plane_dist(int p, const float c[4]) {
    return k_planes[p][0] * c[0] + k_planes[p][1] * c[1] + k_planes[p][2] * c[2] + k_planes[p][3] * c[3];
}

static inline unsigned outcode(const float c[4]) {
    unsigned code = 0;
    for (int p = 0; p < 6; ++p)
        if (plane_dist(p, c) < 0.0f) code |= 1u << p;
    return code;
}

static void lerp_vert(const cvert* a, const cvert* b, float t, int na, cvert* out) {
    for (int k = 0; k < 4; ++k) out->c[k] = a->c[k] + (b->c[k] - a->c[k]) * t;
    for (int k = 0; k < na; ++k) out->a[k] = a->a[k] + (b->a[k] - a->a[k]) * t;
}

/* Project, snap and set up one screen triangle; degenerate ones produce nothing. */
static void setup_screen_tri(const drawctx* dc, const cvert* v0, const cvert* v1, const cvert* v2,
                             const float flat[4], sink* sk) {
    const ak_raster* r = dc->r;
    const cvert* v[3] = {v0, v1, v2};
    double sx[3], sy[3];
    float z[3], iw[3];
    int64_t fx[3], fy[3];
    for (int i = 0; i < 3; ++i) {
        float w = v[i]->c[3];
        if (!(w > 0.0f)) return;
        iw[i] = 1.0f / w;
        sx[i] = ((double)v[i]->c[0] * iw[i] * 0.5 + 0.5) * r->sw;
        sy[i] = (0.5 - (double)v[i]->c[1] * iw[i] * 0.5) * r->sh;
        z[i] = v[i]->c[2] * iw[i] * 0.5f + 0.5f + dc->depth_bias;
        fx[i] = (int64_t)floor(sx[i] * SUBPIX + 0.5);
        fy[i] = (int64_t)floor(sy[i] * SUBPIX + 0.5);
    }
    int64_t area = (fx[1] - fx[0]) * (fy[2] - fy[0]) - (fy[1] - fy[0]) * (fx[2] - fx[0]);
    if (area == 0) return;
    int o[3] = {0, 1, 2};
    if (area < 0) {
        o[1] = 2;
        o[2] = 1;
        area = -area;
    }
    rtri* t = sk->buf ? &sk->buf[sk->count] : &sk->t;
    int64_t X[3] = {fx[o[0]], fx[o[1]], fx[o[2]]}, Y[3] = {fy[o[0]], fy[o[1]], fy[o[2]]};
    for (int i = 0; i < 3; ++i) {
        int a = (i + 1) % 3, b = (i + 2) % 3; /* edge opposite vertex i */
        int64_t A = Y[a] - Y[b], B = X[b] - X[a];
        t->A[i] = A;
        t->B[i] = B;
        t->C[i] = -A * X[a] - B * Y[a];
        t->bias[i] = (A > 0 || (A == 0 && B > 0)) ? 0 : -1;
    }
    int64_t minx = X[0], maxx = X[0], miny = Y[0], maxy = Y[0];
    for (int i = 1; i < 3; ++i) {
        if (X[i] < minx) minx = X[i];
        if (X[i] > maxx) maxx = X[i];
        if (Y[i] < miny) miny = Y[i];
        if (Y[i] > maxy) maxy = Y[i];
    }
    /* pixel X covered only if its centre X*256+128 lies in [min, max] */
    int64_t x0 = (minx - SUBPIX / 2 + SUBPIX - 1) / SUBPIX, x1 = (maxx - SUBPIX / 2) / SUBPIX;
    int64_t y0 = (miny - SUBPIX / 2 + SUBPIX - 1) / SUBPIX, y1 = (maxy - SUBPIX / 2) / SUBPIX;
    if (minx - SUBPIX / 2 < 0) x0 = 0;
    if (miny - SUBPIX / 2 < 0) y0 = 0;
    if (maxx - SUBPIX / 2 < 0 || maxy - SUBPIX / 2 < 0) return;
    if (x1 >= r->sw) x1 = r->sw - 1;
    if (y1 >= r->sh) y1 = r->sh - 1;
    if (x0 > x1 || y0 > y1) return;
    t->x0 = (int)x0;
    t->x1 = (int)x1;
    t->y0 = (int)y0;
    t->y1 = (int)y1;
    t->inv_area = (float)(1.0 / (double)area);
    const int i0 = o[0], i1 = o[1], i2 = o[2];
    t->z0 = z[i0];
    t->dz1 = z[i1] - z[i0];
    t->dz2 = z[i2] - z[i0];
    t->iw0 = iw[i0];
    t->diw1 = iw[i1] - iw[i0];
    t->diw2 = iw[i2] - iw[i0];
    for (int k = 0; k < dc->attr_count; ++k) {
        float a0 = v[i0]->a[k] * iw[i0];
        t->a0[k] = a0;
        t->da1[k] = v[i1]->a[k] * iw[i1] - a0;
        t->da2[k] = v[i2]->a[k] * iw[i2] - a0;
    }
#if defined(__wasm_simd128__)
    _Static_assert(MAXA % 4 == 0, "the SIMD128 interpolation reads attributes four at a time");
    for (int k = dc->attr_count; k < MAXA; ++k)
        t->a0[k] = t->da1[k] = t->da2[k] = 0.0f; /* defined lanes */
#endif
    if (flat) memcpy(t->flat, flat, sizeof t->flat);
    t->minify = false;
    if (dc->tex) {
        /* texels over the triangle (UV area x texture size) against the samples it covers */
        const int ua = dc->uv_attr;
        float du1 = v[1]->a[ua] - v[0]->a[ua], dv1 = v[1]->a[ua + 1] - v[0]->a[ua + 1];
        float du2 = v[2]->a[ua] - v[0]->a[ua], dv2 = v[2]->a[ua + 1] - v[0]->a[ua + 1];
        double texels = fabs((double)du1 * dv2 - (double)dv1 * du2) * dc->tex->image.width * dc->tex->image.height;
        t->minify = texels > (double)area / ((double)SUBPIX * SUBPIX);
    }
    if (sk->buf) ++sk->count;
    else raster_tri(dc, t, 0, 1);
}

/* Clip a clip-space triangle against near/far and the guard band, then set up the pieces. */
static void clip_and_setup(const drawctx* dc, const cvert* a, const cvert* b, const cvert* c,
                           const float flat[4], sink* sk) {
    unsigned oa = outcode(a->c), ob = outcode(b->c), oc = outcode(c->c);
    if (oa & ob & oc) return;
    if ((oa | ob | oc) == 0) {
        setup_screen_tri(dc, a, b, c, flat, sk);
        return;
    }
    cvert buf[2][12];
    int n = 3;
    buf[0][0] = *a;
    buf[0][1] = *b;
    buf[0][2] = *c;
    int cur = 0;
    unsigned any = oa | ob | oc;
    for (int p = 0; p < 6 && n >= 3; ++p) {
        if (!(any & (1u << p))) continue;
        const cvert* in = buf[cur];
        cvert* o = buf[cur ^ 1];
        int m = 0;
        for (int i = 0; i < n; ++i) {
            const cvert* s = &in[i];
            const cvert* e = &in[(i + 1) % n];
            float ds = plane_dist(p, s->c), de = plane_dist(p, e->c);
            if (ds >= 0.0f) o[m++] = *s;
            if ((ds >= 0.0f) != (de >= 0.0f) && m < 12) {
                float t = ds / (ds - de);
                lerp_vert(s, e, t, dc->attr_count, &o[m++]);
            }
        }
        n = m;
        cur ^= 1;
    }
    for (int i = 1; i + 1 < n; ++i) setup_screen_tri(dc, &buf[cur][0], &buf[cur][i], &buf[cur][i + 1], flat, sk);
}

/* ---- fragments ------------------------------------------------------------------------ */

static inline void write_px(const drawctx* dc, uint8_t* px, float* zb, float z, const uint8_t src[4]) {
    switch (dc->blend) {
    case AK_BLEND_ALPHA: {
        unsigned a = src[3];
        for (int k = 0; k < 3; ++k) px[k] = (uint8_t)((src[k] * a + px[k] * (255u - a) + 127u) / 255u);
        break;
    }
    case AK_BLEND_ADD:
        for (int k = 0; k < 4; ++k) {
            unsigned s = (unsigned)px[k] + src[k];
            px[k] = (uint8_t)(s > 255u ? 255u : s);
        }
        break;
    default:
        memcpy(px, src, 4);
        break;
    }
    if (dc->depth_write) *zb = z;
}

static float shadow_sample(const ak_raster* r, float u, float v) {
    /* u, v in texel units */
    u -= 0.5f;
    v -= 0.5f;
    if (!(u > -1.0f && v > -1.0f && u < (float)SHADOW_RES && v < (float)SHADOW_RES)) return 0.0f;
    int x0 = (int)floorf(u), y0 = (int)floorf(v);
    float fx = u - (float)x0, fy = v - (float)y0;
    float s = 0.0f;
    for (int j = 0; j < 2; ++j)
        for (int i = 0; i < 2; ++i) {
            int x = x0 + i, y = y0 + j;
            if (x < 0 || y < 0 || x >= SHADOW_RES || y >= SHADOW_RES) continue;
            float w = (i ? fx : 1.0f - fx) * (j ? fy : 1.0f - fy);
            s += w * r->shadow[y * SHADOW_RES + x];
        }
    return s;
}

static inline float smoothstep(float e0, float e1, float x) {
    float t = clamp01((x - e0) / (e1 - e0));
    return t * t * (3.0f - 2.0f * t);
}

/* Attributes each fragment mode interpolates (a constant once the mode is). */
static FORCE_INLINE int mode_attr_count(frag_mode mode) {
    switch (mode) {
    case FRAG_UNLIT_VCOLOR: return 4;
    case FRAG_GOURAUD: return 4;
    case FRAG_PHONG: return 6;
    case FRAG_PHONG_VC: return 10;
    case FRAG_POINT: return 2;
    case FRAG_GROUND: return 3;
    default: return 0;
    }
}

/* ---- textures ------------------------------------------------------------------------------ */

/* Reduce a texture coordinate to one period of its wrap mode, so that texel indices need no
 * division: REPEAT -> [0, 1), MIRROR -> [0, 2) (the second half mirrored), CLAMP -> [0, 1].
 * Non-finite -> 0; huge values keep their period only as far as float precision allows. */
static inline float tex_period(float u, ak_raster_wrap w) {
    if (!ak_finitef(u)) return 0.0f;
    if (w == AK_RASTER_WRAP_CLAMP) return u < 0.0f ? 0.0f : (u > 1.0f ? 1.0f : u);
    /* REPEAT: the lines below with p = 1 (u / 1 and 1 * x are exact) */
    if (w != AK_RASTER_WRAP_MIRROR) {
        float f = u - floorf(u);
        return f >= 0.0f && f < 1.0f ? f : 0.0f;
    }
    float p = 2.0f;
    float f = u - p * floorf(u / p);
    return f >= 0.0f && f < p ? f : 0.0f; /* rounding can give exactly p */
}

/* Texel index i (in [-1, 2n] after tex_period and the bilinear half-texel shift) of an axis of
 * n texels, wrapped. */
static inline int tex_index(int i, int n, ak_raster_wrap w) {
    if (w == AK_RASTER_WRAP_CLAMP) return i < 0 ? 0 : (i >= n ? n - 1 : i);
    if (w == AK_RASTER_WRAP_MIRROR) {
        int p = 2 * n;
        if (i < 0) i += p;
        if (i >= p) i -= p;
        return i < n ? i : p - 1 - i;
    }
    if (i < 0) return i + n;
    return i >= n ? i - n : i;
}

/* The texel colour at (u, v): linear light (lit modes) or sRGB (unlit) in [0, 1], alpha in
 * [0, 1]. Bilinear filtering weighs the 4 texels around the point. */
static void tex_sample(const drawctx* dc, float u, float v, bool minify, bool linear, float out[4]) {
    const ak_raster_texture* t = dc->tex;
    const int w = t->image.width, h = t->image.height;
    const uint8_t* px = t->image.pixels;
    const size_t stride = dc->tex_stride;
    ak_raster_filter f = minify ? t->min_filter : t->mag_filter;
    const float* lut = dc->r->to_lin_lut;
    const float x = tex_period(u, t->wrap_u) * (float)w, y = tex_period(v, t->wrap_v) * (float)h;
    if (f == AK_RASTER_FILTER_NEAREST) {
        int i = tex_index((int)x, w, t->wrap_u), j = tex_index((int)y, h, t->wrap_v);
        const uint8_t* p = px + (size_t)j * stride + (size_t)i * 4u;
        for (int k = 0; k < 3; ++k) out[k] = linear ? lut[p[k]] : (float)p[k] * (1.0f / 255.0f);
        out[3] = (float)p[3] * (1.0f / 255.0f);
        return;
    }
    const float xs = x - 0.5f, ys = y - 0.5f;
    const float fx0 = floorf(xs), fy0 = floorf(ys);
    const float fx = xs - fx0, fy = ys - fy0;
    const int x0 = (int)fx0, y0 = (int)fy0;
    const int i0 = tex_index(x0, w, t->wrap_u), i1 = tex_index(x0 + 1, w, t->wrap_u);
    const int j0 = tex_index(y0, h, t->wrap_v), j1 = tex_index(y0 + 1, h, t->wrap_v);
    const uint8_t* r0 = px + (size_t)j0 * stride;
    const uint8_t* r1 = px + (size_t)j1 * stride;
    const uint8_t* p[4] = {r0 + (size_t)i0 * 4u, r0 + (size_t)i1 * 4u, r1 + (size_t)i0 * 4u, r1 + (size_t)i1 * 4u};
    const float wt[4] = {(1.0f - fx) * (1.0f - fy), fx * (1.0f - fy), (1.0f - fx) * fy, fx * fy};
#if defined(__wasm_simd128__)
    /* the four channels at once: per channel the scalar loops' sums in the same order, each
     * term rounded as there (lit: wt * lut for colour, (wt * a) * (1/255) for alpha) */
    {
        const v128_t scale = linear ? wasm_f32x4_make(1.0f, 1.0f, 1.0f, 1.0f / 255.0f)
                                    : wasm_f32x4_splat(1.0f / 255.0f);
        v128_t acc = wasm_f32x4_splat(0.0f);
        for (int q = 0; q < 4; ++q) {
            const v128_t c =
                linear ? wasm_f32x4_make(lut[p[q][0]], lut[p[q][1]], lut[p[q][2]], (float)p[q][3])
                       : wasm_f32x4_make((float)p[q][0], (float)p[q][1], (float)p[q][2],
                                         (float)p[q][3]);
            acc = wasm_f32x4_add(acc,
                                 wasm_f32x4_mul(wasm_f32x4_mul(wasm_f32x4_splat(wt[q]), c), scale));
        }
        wasm_v128_store(out, acc);
        return;
    }
#endif
    for (int k = 0; k < 4; ++k) out[k] = 0.0f;
    if (linear) {
        for (int q = 0; q < 4; ++q)
            for (int k = 0; k < 3; ++k) out[k] += wt[q] * lut[p[q][k]];
    } else {
        for (int q = 0; q < 4; ++q)
            for (int k = 0; k < 3; ++k) out[k] += wt[q] * (float)p[q][k] * (1.0f / 255.0f);
    }
    for (int q = 0; q < 4; ++q) out[3] += wt[q] * (float)p[q][3] * (1.0f / 255.0f);
}

/* Compute the fragment colour; returns false to discard. */
static FORCE_INLINE bool fragment(const drawctx* dc, frag_mode mode, bool tex, const rtri* t, const float* a,
                                  uint8_t out[4], const uint8_t* dst) {
    const ak_raster* r = dc->r;
    float tx[4] = {1, 1, 1, 1};
    if (tex) {
        const int ua = mode_attr_count(mode);
        tex_sample(dc, a[ua], a[ua + 1], t->minify, mode != FRAG_UNLIT_CONST && mode != FRAG_UNLIT_VCOLOR, tx);
    }
    switch (mode) {
    case FRAG_UNLIT_CONST:
        if (tex) {
            for (int k = 0; k < 4; ++k) out[k] = (uint8_t)(dc->const_rgba[k] * tx[k] + 0.5f);
            return true;
        }
        for (int k = 0; k < 4; ++k) out[k] = (uint8_t)dc->const_rgba[k];
        return true;
    case FRAG_UNLIT_VCOLOR:
        for (int k = 0; k < 4; ++k) out[k] = (uint8_t)(clamp01(a[k] * tx[k]) * 255.0f + 0.5f);
        return true;
    case FRAG_FLAT:
        out[0] = enc(r, t->flat[0] * tx[0]);
        out[1] = enc(r, t->flat[1] * tx[1]);
        out[2] = enc(r, t->flat[2] * tx[2]);
        out[3] = (uint8_t)(clamp01(t->flat[3] * tx[3]) * 255.0f + 0.5f);
        return true;
    case FRAG_GOURAUD:
        out[0] = enc(r, a[0] * tx[0]);
        out[1] = enc(r, a[1] * tx[1]);
        out[2] = enc(r, a[2] * tx[2]);
        out[3] = (uint8_t)(clamp01(a[3] * tx[3]) * 255.0f + 0.5f);
        return true;
    case FRAG_PHONG:
    case FRAG_PHONG_VC: {
        ak_vec3 n = fast_normalize(ak_vec3_make(a[3], a[4], a[5]));
        ak_vec3 alb = dc->base_lin;
        float alpha = dc->base_alpha;
        if (mode == FRAG_PHONG_VC) {
            alb = ak_vec3_mul(alb, ak_vec3_make(a[6], a[7], a[8]));
            alpha *= a[9];
        }
        if (tex) {
            alb = ak_vec3_mul(alb, ak_vec3_make(tx[0], tx[1], tx[2]));
            alpha *= tx[3];
        }
        ak_vec3 c = shade(dc, n, ak_vec3_make(a[0], a[1], a[2]), alb);
        out[0] = enc(r, c.x);
        out[1] = enc(r, c.y);
        out[2] = enc(r, c.z);
        out[3] = (uint8_t)(clamp01(alpha) * 255.0f + 0.5f);
        return true;
    }
    case FRAG_POINT: {
        float d2 = a[0] * a[0] + a[1] * a[1];
        if (d2 > 1.0f) return false;
        float inner = dc->outline_frac;
        if (d2 > inner * inner) {
            for (int k = 0; k < 4; ++k) out[k] = (uint8_t)dc->outline_rgba[k];
            return true;
        }
        /* shade the disc as a small sphere lit from the upper left */
        float u = a[0] / inner, v = a[1] / inner;
        float nz = sqrtf(clamp01(1.0f - u * u - v * v));
        float lam = 0.55f + 0.45f * clamp01(-0.45f * u + 0.55f * v + 0.7f * nz);
        float hl = -0.35f * u + 0.45f * v + 0.82f * nz;
        float spec = hl > 0.0f ? 0.35f * powf(hl, 24.0f) : 0.0f;
        for (int k = 0; k < 3; ++k) out[k] = enc(r, t->flat[k] * lam + spec);
        out[3] = (uint8_t)(clamp01(t->flat[3]) * 255.0f + 0.5f);
        return true;
    }
    case FRAG_GROUND: {
        float px = a[0], pz = a[2];
        float dx = px - dc->ground_cx, dz = pz - dc->ground_cz;
        float rad = sqrtf(dx * dx + dz * dz) / dc->ground_e;
        float fade = 1.0f - smoothstep(0.45f, 1.0f, rad);
        if (fade <= 0.0f) return false;
        ak_vec3 c = dc->ground_lin;
        /* grid: pixel footprint in metres from distance and grazing angle */
        ak_vec3 to_eye = ak_vec3_sub(dc->eye, ak_vec3_make(a[0], a[1], a[2]));
        float dist = ak_vec3_length(to_eye);
        float cosv = dist > 0.0f ? fabsf(to_eye.y) / dist : 1.0f;
        if (dc->ortho) {
            dist = 1.0f;
            cosv = fabsf(dc->view_forward.y);
        }
        float foot = dist * dc->pix_angle / (cosv > 0.12f ? cosv : 0.12f);
        float sp = dc->grid_spacing;
        float gu = px / sp, gv = pz / sp;
        float du = fabsf(gu - floorf(gu + 0.5f)) * sp, dv = fabsf(gv - floorf(gv + 0.5f)) * sp;
        float d = du < dv ? du : dv;
        float hw = 0.5f * (float)r->ss * foot;
        float line = clamp01(1.0f - (d - hw) / foot);
        line *= clamp01(1.6f - 4.0f * foot * (float)r->ss / sp);
        c = ak_vec3_lerp(c, dc->line_lin, line * 0.8f);
        if (dc->shadow) {
            float texel = 2.0f * dc->ground_e / (float)SHADOW_RES;
            float s = shadow_sample(r, (px - (dc->ground_cx - dc->ground_e)) / texel,
                                    (pz - (dc->ground_cz - dc->ground_e)) / texel);
            c = ak_vec3_scale(c, 1.0f - s);
        }
        for (int k = 0; k < 3; ++k) {
            float bg = r->to_lin_lut[dst[k]];
            float v = (k == 0 ? c.x : (k == 1 ? c.y : c.z));
            out[k] = (uint8_t)r->to_srgb_lut[(int)(clamp01(bg + (v - bg) * fade) * 4096.0f + 0.5f)];
        }
        out[3] = 255;
        return true;
    }
    }
    return false;
}

#if defined(__wasm_simd128__)
/* The WebAssembly build (docs/web.md): the ground's pixels four at a time with SIMD128. The
 * ground is the frame's largest surface and its fragment (fade, grid, shadow) the heaviest per
 * pixel; every lane runs the scalar FRAG_GROUND code's float operations in the same order
 * (IEEE division, square root and floor per lane; -ffp-contract=off, no fused multiply-add), so
 * the pixels are bit-identical to the scalar path's, which every other build runs and the raster
 * tests check (tests/web/run.mjs compares the page's frame with the native viewer's). */
static FORCE_INLINE v128_t v_clamp01(v128_t x) {
    v128_t r =
        wasm_v128_bitselect(wasm_f32x4_splat(1.0f), x, wasm_f32x4_gt(x, wasm_f32x4_splat(1.0f)));
    return wasm_v128_bitselect(wasm_f32x4_splat(0.0f), r, wasm_f32x4_lt(x, wasm_f32x4_splat(0.0f)));
}

/* Row y of triangle t, pixels x0..x1, with the edge values e* at x0 and their steps s*. */
static void ground_row_simd(const drawctx* dc, const rtri* t, int x0, int x1, int64_t e0,
                            int64_t e1, int64_t e2, int64_t s0, int64_t s1, int64_t s2,
                            uint8_t* crow, float* zrow) {
    const ak_raster* r = dc->r;
    const v128_t one = wasm_f32x4_splat(1.0f), zero = wasm_f32x4_splat(0.0f);
    const v128_t gcx = wasm_f32x4_splat(dc->ground_cx), gcz = wasm_f32x4_splat(dc->ground_cz);
    const v128_t ge = wasm_f32x4_splat(dc->ground_e), sp = wasm_f32x4_splat(dc->grid_spacing);
    const v128_t ss = wasm_f32x4_splat((float)r->ss);
    const float texel = 2.0f * dc->ground_e / (float)SHADOW_RES;
    for (int x = x0; x <= x1; x += 4) {
        const int n = x1 - x + 1 < 4 ? x1 - x + 1 : 4;
        float l1s[4] = {0, 0, 0, 0}, l2s[4] = {0, 0, 0, 0}, zb[4] = {0, 0, 0, 0};
        int live[4] = {0, 0, 0, 0}, any = 0;
        for (int k = 0; k < n; ++k, e0 += s0, e1 += s1, e2 += s2) {
            if ((e0 | e1 | e2) < 0) continue;
            live[k] = -1;
            any = 1;
            l1s[k] = (float)(e1 - t->bias[1]) * t->inv_area;
            l2s[k] = (float)(e2 - t->bias[2]) * t->inv_area;
            zb[k] = zrow[x + k];
        }
        if (!any) continue;
        const v128_t l1 = wasm_v128_load(l1s), l2 = wasm_v128_load(l2s);
        v128_t alive = wasm_v128_load(live);
        const v128_t z = wasm_f32x4_add(
            wasm_f32x4_add(wasm_f32x4_splat(t->z0), wasm_f32x4_mul(l1, wasm_f32x4_splat(t->dz1))),
            wasm_f32x4_mul(l2, wasm_f32x4_splat(t->dz2)));
        if (dc->depth_test) alive = wasm_v128_and(alive, wasm_f32x4_lt(z, wasm_v128_load(zb)));
        alive = wasm_v128_and(alive, wasm_v128_and(wasm_f32x4_ge(z, zero), wasm_f32x4_le(z, one)));
        if (!wasm_v128_any_true(alive)) continue;
        const v128_t iw = wasm_f32x4_add(
            wasm_f32x4_add(wasm_f32x4_splat(t->iw0), wasm_f32x4_mul(l1, wasm_f32x4_splat(t->diw1))),
            wasm_f32x4_mul(l2, wasm_f32x4_splat(t->diw2)));
        const v128_t w = wasm_f32x4_div(one, iw);
        v128_t a[3];
        for (int k = 0; k < 3; ++k)
            a[k] = wasm_f32x4_mul(
                wasm_f32x4_add(wasm_f32x4_add(wasm_f32x4_splat(t->a0[k]),
                                              wasm_f32x4_mul(l1, wasm_f32x4_splat(t->da1[k]))),
                               wasm_f32x4_mul(l2, wasm_f32x4_splat(t->da2[k]))),
                w);
        /* fade towards the edge of the ground's disc */
        const v128_t px = a[0], pz = a[2];
        const v128_t dx = wasm_f32x4_sub(px, gcx), dz = wasm_f32x4_sub(pz, gcz);
        const v128_t rad = wasm_f32x4_div(
            wasm_f32x4_sqrt(wasm_f32x4_add(wasm_f32x4_mul(dx, dx), wasm_f32x4_mul(dz, dz))), ge);
        const v128_t st = v_clamp01(wasm_f32x4_div(wasm_f32x4_sub(rad, wasm_f32x4_splat(0.45f)),
                                                   wasm_f32x4_splat(1.0f - 0.45f)));
        const v128_t fade = wasm_f32x4_sub(
            one, wasm_f32x4_mul(wasm_f32x4_mul(st, st),
                                wasm_f32x4_sub(wasm_f32x4_splat(3.0f),
                                               wasm_f32x4_mul(wasm_f32x4_splat(2.0f), st))));
        alive = wasm_v128_andnot(alive, wasm_f32x4_le(fade, zero));
        if (!wasm_v128_any_true(alive)) continue;
        /* grid: pixel footprint in metres from distance and grazing angle */
        const v128_t tx = wasm_f32x4_sub(wasm_f32x4_splat(dc->eye.x), a[0]);
        const v128_t ty = wasm_f32x4_sub(wasm_f32x4_splat(dc->eye.y), a[1]);
        const v128_t tz = wasm_f32x4_sub(wasm_f32x4_splat(dc->eye.z), a[2]);
        v128_t dist = wasm_f32x4_sqrt(
            wasm_f32x4_add(wasm_f32x4_add(wasm_f32x4_mul(tx, tx), wasm_f32x4_mul(ty, ty)),
                           wasm_f32x4_mul(tz, tz)));
        v128_t cosv = wasm_v128_bitselect(wasm_f32x4_div(wasm_f32x4_abs(ty), dist), one,
                                          wasm_f32x4_gt(dist, zero));
        if (dc->ortho) {
            dist = one;
            cosv = wasm_f32x4_splat(fabsf(dc->view_forward.y));
        }
        const v128_t c012 = wasm_f32x4_splat(0.12f);
        const v128_t foot =
            wasm_f32x4_div(wasm_f32x4_mul(dist, wasm_f32x4_splat(dc->pix_angle)),
                           wasm_v128_bitselect(cosv, c012, wasm_f32x4_gt(cosv, c012)));
        const v128_t half = wasm_f32x4_splat(0.5f);
        const v128_t gu = wasm_f32x4_div(px, sp), gv = wasm_f32x4_div(pz, sp);
        const v128_t du = wasm_f32x4_mul(
            wasm_f32x4_abs(wasm_f32x4_sub(gu, wasm_f32x4_floor(wasm_f32x4_add(gu, half)))), sp);
        const v128_t dv = wasm_f32x4_mul(
            wasm_f32x4_abs(wasm_f32x4_sub(gv, wasm_f32x4_floor(wasm_f32x4_add(gv, half)))), sp);
        const v128_t d = wasm_v128_bitselect(du, dv, wasm_f32x4_lt(du, dv));
        const v128_t hw = wasm_f32x4_mul(wasm_f32x4_mul(half, ss), foot);
        v128_t line = v_clamp01(wasm_f32x4_sub(one, wasm_f32x4_div(wasm_f32x4_sub(d, hw), foot)));
        line = wasm_f32x4_mul(
            line, v_clamp01(wasm_f32x4_sub(
                      wasm_f32x4_splat(1.6f),
                      wasm_f32x4_div(
                          wasm_f32x4_mul(wasm_f32x4_mul(wasm_f32x4_splat(4.0f), foot), ss), sp))));
        const v128_t lt = wasm_f32x4_mul(line, wasm_f32x4_splat(0.8f));
        const float gl[3] = {dc->ground_lin.x, dc->ground_lin.y, dc->ground_lin.z};
        const float ll[3] = {dc->line_lin.x, dc->line_lin.y, dc->line_lin.z};
        v128_t c[3];
        for (int k = 0; k < 3; ++k) {
            const v128_t g = wasm_f32x4_splat(gl[k]);
            c[k] =
                wasm_f32x4_add(g, wasm_f32x4_mul(wasm_f32x4_sub(wasm_f32x4_splat(ll[k]), g), lt));
        }
        if (dc->shadow) {
            const v128_t tv = wasm_f32x4_splat(texel);
            /* shadow_sample, lane by lane in the same order: the 4 taps' weights, a tap outside
             * the map adds w * 0 (+0: the sum is the same), out of range -> 0 */
            const v128_t u = wasm_f32x4_sub(
                wasm_f32x4_div(wasm_f32x4_sub(px, wasm_f32x4_splat(dc->ground_cx - dc->ground_e)),
                               tv),
                half);
            const v128_t v = wasm_f32x4_sub(
                wasm_f32x4_div(wasm_f32x4_sub(pz, wasm_f32x4_splat(dc->ground_cz - dc->ground_e)),
                               tv),
                half);
            const v128_t m1 = wasm_f32x4_splat(-1.0f), sr = wasm_f32x4_splat((float)SHADOW_RES);
            const v128_t inr =
                wasm_v128_and(wasm_v128_and(wasm_f32x4_gt(u, m1), wasm_f32x4_gt(v, m1)),
                              wasm_v128_and(wasm_f32x4_lt(u, sr), wasm_f32x4_lt(v, sr)));
            const v128_t fu = wasm_f32x4_floor(u), fv = wasm_f32x4_floor(v);
            const v128_t fx = wasm_f32x4_sub(u, fu), fy = wasm_f32x4_sub(v, fv);
            int32_t ix[4], iy[4], in[4];
            wasm_v128_store(ix, wasm_i32x4_trunc_sat_f32x4(fu));
            wasm_v128_store(iy, wasm_i32x4_trunc_sat_f32x4(fv));
            wasm_v128_store(in, wasm_v128_and(inr, alive));
            float tap[4][4] = {{0}}; /* [j * 2 + i][lane] */
            for (int k = 0; k < n; ++k) {
                if (!in[k]) continue;
                for (int j = 0; j < 2; ++j)
                    for (int i = 0; i < 2; ++i) {
                        int sx = ix[k] + i, sy = iy[k] + j;
                        if (sx >= 0 && sy >= 0 && sx < SHADOW_RES && sy < SHADOW_RES)
                            tap[j * 2 + i][k] = r->shadow[sy * SHADOW_RES + sx];
                    }
            }
            const v128_t gx = wasm_f32x4_sub(one, fx), gy = wasm_f32x4_sub(one, fy);
            v128_t sh = wasm_f32x4_add(
                zero, wasm_f32x4_mul(wasm_f32x4_mul(gx, gy), wasm_v128_load(tap[0])));
            sh = wasm_f32x4_add(sh, wasm_f32x4_mul(wasm_f32x4_mul(fx, gy), wasm_v128_load(tap[1])));
            sh = wasm_f32x4_add(sh, wasm_f32x4_mul(wasm_f32x4_mul(gx, fy), wasm_v128_load(tap[2])));
            sh = wasm_f32x4_add(sh, wasm_f32x4_mul(wasm_f32x4_mul(fx, fy), wasm_v128_load(tap[3])));
            sh = wasm_v128_and(sh, inr); /* out of range: 0 */
            const v128_t f = wasm_f32x4_sub(one, sh);
            for (int k = 0; k < 3; ++k) c[k] = wasm_f32x4_mul(c[k], f);
        }
        /* over what is there (the background): clamp01(bg + (c - bg) * fade) through the sRGB
         * table, as the scalar code does per channel */
        uint8_t* dst = crow + (size_t)x * 4u;
        int32_t idx[3][4];
        for (int q = 0; q < 3; ++q) {
            float bgs[4] = {0, 0, 0, 0};
            for (int k = 0; k < n; ++k) bgs[k] = r->to_lin_lut[dst[4 * k + q]];
            const v128_t bg = wasm_v128_load(bgs);
            const v128_t m =
                v_clamp01(wasm_f32x4_add(bg, wasm_f32x4_mul(wasm_f32x4_sub(c[q], bg), fade)));
            wasm_v128_store(idx[q], wasm_i32x4_trunc_sat_f32x4(wasm_f32x4_add(
                                        wasm_f32x4_mul(m, wasm_f32x4_splat(4096.0f)), half)));
        }
        uint32_t am[4];
        float zk[4];
        wasm_v128_store(am, alive);
        wasm_v128_store(zk, z);
        for (int k = 0; k < n; ++k) {
            if (!am[k]) continue;
            uint8_t out[4] = {(uint8_t)r->to_srgb_lut[idx[0][k]],
                              (uint8_t)r->to_srgb_lut[idx[1][k]],
                              (uint8_t)r->to_srgb_lut[idx[2][k]], 255};
            write_px(dc, dst + 4 * k, &zrow[x + k], zk[k], out);
        }
    }
}
#endif

static FORCE_INLINE void raster_tri_mode(const drawctx* dc, frag_mode mode, bool tex, const rtri* t,
                                         int thread_index, int thread_count) {
    ak_raster* r = dc->r;
    const int na = mode_attr_count(mode) + (tex ? 2 : 0);
    for (int y = t->y0; y <= t->y1; ++y) {
        if (thread_count > 1) {
            int blk = y >> ROW_BLOCK_SHIFT;
            if (blk % thread_count != thread_index) {
                /* jump to the first row of this thread's next block */
                int skip = (thread_index - blk % thread_count + thread_count) % thread_count;
                y = ((blk + skip) << ROW_BLOCK_SHIFT) - 1;
                continue;
            }
        }
        const int64_t py = (int64_t)y * SUBPIX + SUBPIX / 2;
        const int64_t px0 = (int64_t)t->x0 * SUBPIX + SUBPIX / 2;
        int64_t e0 = t->A[0] * px0 + t->B[0] * py + t->C[0] + t->bias[0];
        int64_t e1 = t->A[1] * px0 + t->B[1] * py + t->C[1] + t->bias[1];
        int64_t e2 = t->A[2] * px0 + t->B[2] * py + t->C[2] + t->bias[2];
        const int64_t s0 = t->A[0] * SUBPIX, s1 = t->A[1] * SUBPIX, s2 = t->A[2] * SUBPIX;
        uint8_t* crow = r->color + (size_t)y * (size_t)r->sw * 4u;
        float* zrow = r->depth + (size_t)y * (size_t)r->sw;
#if defined(__wasm_simd128__)
        if (mode == FRAG_GROUND && !tex) {
            ground_row_simd(dc, t, t->x0, t->x1, e0, e1, e2, s0, s1, s2, crow, zrow);
            continue;
        }
#endif
        for (int x = t->x0; x <= t->x1; ++x, e0 += s0, e1 += s1, e2 += s2) {
            if ((e0 | e1 | e2) < 0) continue;
            /* remove the bias again so the barycentrics are exact */
            float l1 = (float)(e1 - t->bias[1]) * t->inv_area;
            float l2 = (float)(e2 - t->bias[2]) * t->inv_area;
            float z = t->z0 + l1 * t->dz1 + l2 * t->dz2;
            if (dc->depth_test && !(z < zrow[x])) continue;
            if (!(z >= 0.0f && z <= 1.0f)) continue;
            float a[MAXA];
            if (na) {
                float iw = t->iw0 + l1 * t->diw1 + l2 * t->diw2;
                float w = 1.0f / iw;
#if defined(__wasm_simd128__)
                if (na > 3) { /* four attributes at a time, each as the scalar line rounds it */
                    const v128_t vl1 = wasm_f32x4_splat(l1), vl2 = wasm_f32x4_splat(l2),
                                 vw = wasm_f32x4_splat(w);
                    for (int k = 0; k < na; k += 4) /* na <= MAXA = 12: lanes past na are unused */
                        wasm_v128_store(
                            &a[k],
                            wasm_f32x4_mul(
                                wasm_f32x4_add(
                                    wasm_f32x4_add(wasm_v128_load(&t->a0[k]),
                                                   wasm_f32x4_mul(vl1, wasm_v128_load(&t->da1[k]))),
                                    wasm_f32x4_mul(vl2, wasm_v128_load(&t->da2[k]))),
                                vw));
                } else
#endif
                    for (int k = 0; k < na; ++k)
                        a[k] = (t->a0[k] + l1 * t->da1[k] + l2 * t->da2[k]) * w;
            }
            uint8_t src[4];
            uint8_t* px = crow + (size_t)x * 4u;
            if (!fragment(dc, mode, tex, t, a, src, px)) continue;
            write_px(dc, px, &zrow[x], z, src);
        }
    }
}

static void raster_tri(const drawctx* dc, const rtri* t, int ti, int tc) {
    if (dc->tex) {
        switch (dc->mode) {
        case FRAG_UNLIT_CONST: raster_tri_mode(dc, FRAG_UNLIT_CONST, true, t, ti, tc); break;
        case FRAG_UNLIT_VCOLOR: raster_tri_mode(dc, FRAG_UNLIT_VCOLOR, true, t, ti, tc); break;
        case FRAG_FLAT: raster_tri_mode(dc, FRAG_FLAT, true, t, ti, tc); break;
        case FRAG_GOURAUD: raster_tri_mode(dc, FRAG_GOURAUD, true, t, ti, tc); break;
        case FRAG_PHONG: raster_tri_mode(dc, FRAG_PHONG, true, t, ti, tc); break;
        default: raster_tri_mode(dc, FRAG_PHONG_VC, true, t, ti, tc); break;
        }
        return;
    }
    switch (dc->mode) {
    case FRAG_UNLIT_CONST: raster_tri_mode(dc, FRAG_UNLIT_CONST, false, t, ti, tc); break;
    case FRAG_UNLIT_VCOLOR: raster_tri_mode(dc, FRAG_UNLIT_VCOLOR, false, t, ti, tc); break;
    case FRAG_FLAT: raster_tri_mode(dc, FRAG_FLAT, false, t, ti, tc); break;
    case FRAG_GOURAUD: raster_tri_mode(dc, FRAG_GOURAUD, false, t, ti, tc); break;
    case FRAG_PHONG: raster_tri_mode(dc, FRAG_PHONG, false, t, ti, tc); break;
    case FRAG_PHONG_VC: raster_tri_mode(dc, FRAG_PHONG_VC, false, t, ti, tc); break;
    case FRAG_POINT: raster_tri_mode(dc, FRAG_POINT, false, t, ti, tc); break;
    case FRAG_GROUND: raster_tri_mode(dc, FRAG_GROUND, false, t, ti, tc); break;
    }
}

/* ---- threading -------------------------------------------------------------------------- */

/* What each thread's setup produced in a round; written before the first barrier of the
 * round, read after it. */
typedef struct rounds {
    size_t count[MAX_THREADS]; /* triangles in the thread's segment */
    size_t next[MAX_THREADS];  /* first input the thread did not set up */
    bool full[MAX_THREADS];    /* the segment filled up before the thread's chunk ended */
} rounds;

typedef struct worker {
    const drawctx* dc;
    int index, count;
    akp_barrier* barrier;
    rounds* rounds;
} worker;

static void run_single(const drawctx* dc) {
    sink sk;
    memset(&sk, 0, sizeof sk);
    for (size_t i = 0; i < dc->input_count; ++i) dc->setup(dc, i, &sk);
}

/* One thread of a parallel draw. Each round the threads set up consecutive chunks of the
 * inputs into their own segments, wait, then each rasterizes its own rows of every segment in
 * input order, and wait again. A segment that fills up ends the round early: the segments after
 * it are dropped and redone, so the per-pixel order is always the input order. */
static void run_worker(const worker* w) {
    const drawctx* dc = w->dc;
    rounds* st = w->rounds;
    const size_t n = dc->input_count, T = (size_t)w->count;
    sink sk;
    memset(&sk, 0, sizeof sk);
    sk.buf = dc->r->segs + (size_t)w->index * SEG_CAP;
    sk.cap = SEG_CAP;
    size_t base = 0;
    while (base < n) {
        size_t b = base + (size_t)w->index * CHUNK, e = b + CHUNK, i;
        if (b > n) b = n;
        if (e > n) e = n;
        sk.count = 0;
        for (i = b; i < e && sk.cap - sk.count >= OUT_PER_INPUT; ++i) dc->setup(dc, i, &sk);
        st->count[w->index] = sk.count;
        st->next[w->index] = i;
        st->full[w->index] = i < e;
        akp_barrier_wait(w->barrier);
        size_t last = T - 1;
        for (size_t k = 0; k < T; ++k)
            if (st->full[k]) {
                last = k;
                break;
            }
        for (size_t k = 0; k <= last; ++k) {
            const rtri* seg = dc->r->segs + k * SEG_CAP;
            for (size_t t = 0; t < st->count[k]; ++t) raster_tri(dc, &seg[t], w->index, w->count);
        }
        size_t next_base = st->full[last] ? st->next[last] : base + T * CHUNK;
        akp_barrier_wait(w->barrier);
        base = next_base;
    }
}

static void* worker_main(void* p) {
    run_worker((worker*)p);
    return NULL;
}

/* Run a draw over desc.thread_count threads (see run_worker): the caller and thread_count - 1
 * of the library's workers (src/tasks.h); alone when they cannot all have a thread. */
static void run_draw(const drawctx* dc) {
    int tc = dc->r->desc.thread_count;
    if (dc->input_count < 256 || !dc->r->segs) tc = 1; /* threads would cost more than they save */
    if (tc == 1) {
        run_single(dc);
        return;
    }
    worker ws[MAX_THREADS];
    rounds st;
    akp_barrier barrier;
    akp_barrier_init(&barrier, (uint32_t)tc);
    for (int i = 0; i < tc; ++i) ws[i] = (worker){dc, i, tc, &barrier, &st};
    akp_team_run team;
    if (akp_team_begin(&team, worker_main, ws, sizeof(worker), (uint32_t)tc)) {
        run_worker(&ws[0]);
        akp_team_end(&team);
    } else {
        run_single(dc);
    }
    akp_barrier_destroy(&barrier);
}

/* ---- meshes ------------------------------------------------------------------------------- */

static void mesh_setup(const drawctx* dc, size_t ti, sink* sk) {
    const ak_raster_mesh* m = dc->mesh;
    uint32_t idx[3];
    if (m->indices.count) {
        idx[0] = m->indices.ptr[ti * 3];
        idx[1] = m->indices.ptr[ti * 3 + 1];
        idx[2] = m->indices.ptr[ti * 3 + 2];
    } else {
        idx[0] = (uint32_t)(ti * 3);
        idx[1] = (uint32_t)(ti * 3 + 1);
        idx[2] = (uint32_t)(ti * 3 + 2);
    }
    ak_vec3 wp[3];
    cvert v[3];
    for (int k = 0; k < 3; ++k) {
        ak_vec3 p = m->positions.ptr[idx[k]];
        if (!ak_vec3_is_finite(p)) return;
        wp[k] = p; /* model space until the cheap rejections are done */
        ak_vec4 c = mul4(&dc->mvp, p);
        v[k].c[0] = c.x;
        v[k].c[1] = c.y;
        v[k].c[2] = c.z;
        v[k].c[3] = c.w;
        if (!vec4_finite(c)) return;
    }
    /* orientation in homogeneous coordinates: det[x y w] > 0 <=> counter-clockwise in NDC */
    float det = v[0].c[0] * (v[1].c[1] * v[2].c[3] - v[2].c[1] * v[1].c[3]) -
                v[1].c[0] * (v[0].c[1] * v[2].c[3] - v[2].c[1] * v[0].c[3]) +
                v[2].c[0] * (v[0].c[1] * v[1].c[3] - v[1].c[1] * v[0].c[3]);
    int front = det > 0.0f;
    if (det == 0.0f) return;
    if (dc->cull && !front) return;
    if (!dc->model_identity)
        for (int k = 0; k < 3; ++k) wp[k] = ak_mat4_transform_point(dc->model, wp[k]);
    float flat[4] = {0, 0, 0, 1};
    ak_vec3 fn = ak_vec3_normalize(ak_vec3_cross(ak_vec3_sub(wp[1], wp[0]), ak_vec3_sub(wp[2], wp[0])));
    const bool has_n = m->normals.count > 0;
    ak_vec4 vc[3];
    for (int k = 0; k < 3; ++k) {
        if (dc->has_vcolor) {
            ak_vec4 c = m->colors.ptr[idx[k]];
            vc[k] = vec4_finite(c) ? c : ak_vec4_make(1, 1, 1, 1);
        } else {
            vc[k] = ak_vec4_make(1, 1, 1, 1);
        }
    }
    switch (dc->mode) {
    case FRAG_UNLIT_CONST:
        memcpy(flat, dc->const_rgba, sizeof flat);
        break;
    case FRAG_UNLIT_VCOLOR:
        for (int k = 0; k < 3; ++k) {
            v[k].a[0] = vc[k].x * (dc->const_rgba[0] / 255.0f);
            v[k].a[1] = vc[k].y * (dc->const_rgba[1] / 255.0f);
            v[k].a[2] = vc[k].z * (dc->const_rgba[2] / 255.0f);
            v[k].a[3] = vc[k].w * (dc->const_rgba[3] / 255.0f);
        }
        break;
    case FRAG_FLAT: {
        ak_vec3 n = fn;
        ak_vec3 cen = ak_vec3_scale(ak_vec3_add(ak_vec3_add(wp[0], wp[1]), wp[2]), 1.0f / 3.0f);
        ak_vec3 alb = dc->base_lin;
        float alpha = dc->base_alpha;
        if (dc->has_vcolor) {
            ak_vec4 avg = ak_vec4_scale(ak_vec4_add(ak_vec4_add(vc[0], vc[1]), vc[2]), 1.0f / 3.0f);
            alb = ak_vec3_mul(alb, srgb3_to_lin(avg));
            alpha *= clamp01(avg.w);
        }
        ak_vec3 c = shade(dc, n, cen, alb);
        flat[0] = c.x;
        flat[1] = c.y;
        flat[2] = c.z;
        flat[3] = alpha;
        break;
    }
    case FRAG_GOURAUD:
        for (int k = 0; k < 3; ++k) {
            ak_vec3 n = has_n ? ak_vec3_normalize(ak_mat3_mul_vec3(dc->normal_matrix, m->normals.ptr[idx[k]])) : fn;
            if (!ak_vec3_is_finite(n)) n = fn;
            ak_vec3 alb = dc->base_lin;
            if (dc->has_vcolor) alb = ak_vec3_mul(alb, srgb3_to_lin(vc[k]));
            ak_vec3 c = shade(dc, n, wp[k], alb);
            v[k].a[0] = c.x;
            v[k].a[1] = c.y;
            v[k].a[2] = c.z;
            v[k].a[3] = dc->base_alpha * clamp01(vc[k].w);
        }
        break;
    case FRAG_PHONG:
    case FRAG_PHONG_VC:
        for (int k = 0; k < 3; ++k) {
            ak_vec3 n = has_n ? ak_mat3_mul_vec3(dc->normal_matrix, m->normals.ptr[idx[k]]) : fn;
            if (!ak_vec3_is_finite(n)) n = fn;
            v[k].a[0] = wp[k].x;
            v[k].a[1] = wp[k].y;
            v[k].a[2] = wp[k].z;
            v[k].a[3] = n.x;
            v[k].a[4] = n.y;
            v[k].a[5] = n.z;
            if (dc->has_vcolor) {
                ak_vec3 lc = srgb3_to_lin(vc[k]);
                v[k].a[6] = lc.x;
                v[k].a[7] = lc.y;
                v[k].a[8] = lc.z;
                v[k].a[9] = clamp01(vc[k].w);
            }
        }
        break;
    default:
        break;
    }
    if (dc->tex)
        for (int k = 0; k < 3; ++k) {
            ak_vec2 uv = m->uvs.ptr[idx[k]];
            v[k].a[dc->uv_attr] = ak_finitef(uv.x) ? uv.x : 0.0f;
            v[k].a[dc->uv_attr + 1] = ak_finitef(uv.y) ? uv.y : 0.0f;
        }
    clip_and_setup(dc, &v[0], &v[1], &v[2], flat, sk);
}

static void base_ctx(drawctx* dc, ak_raster* r, const ak_raster_camera* cam, const ak_mat4* model) {
    memset(dc, 0, sizeof *dc);
    dc->r = r;
    dc->model = model ? *model : ak_mat4_identity();
    dc->vp = ak_mat4_mul(cam->projection, cam->view);
    dc->mvp = ak_mat4_mul(dc->vp, dc->model);
    dc->model_identity = model == NULL;
    dc->normal_matrix = ak_mat4_normal_matrix(dc->model);
    dc->eye = eye_of(cam);
    /* camera forward (-Z of the view) in world space: third row of the rotation, negated */
    dc->view_forward = ak_vec3_normalize(ak_vec3_make(-cam->view.m[2], -cam->view.m[6], -cam->view.m[10]));
    dc->ortho = cam->projection.m[15] != 0.0f;
    dc->depth_test = true;
    dc->depth_write = true;
}

static ak_result check_camera(const ak_raster_camera* cam) {
    if (!ak_mat4_is_finite(&cam->view) || !ak_mat4_is_finite(&cam->projection)) return AK_ERR_BAD_DATA;
    return AK_OK;
}

ak_result ak_raster_draw_mesh(ak_raster* raster, const ak_raster_camera* camera, const ak_raster_mesh* mesh) {
    if (!raster || !camera || !mesh || !mesh->positions.ptr || mesh->positions.count == 0) return AK_ERR_NULL_ARG;
    ak_result res = check_camera(camera);
    if (res != AK_OK) return res;
    if (mesh->indices.count % 3 != 0 || (mesh->indices.count && !mesh->indices.ptr)) return AK_ERR_BAD_ARG;
    if (mesh->normals.count && (mesh->normals.count != mesh->positions.count || !mesh->normals.ptr))
        return AK_ERR_BAD_ARG;
    if (mesh->colors.count && (mesh->colors.count != mesh->positions.count || !mesh->colors.ptr))
        return AK_ERR_BAD_ARG;
    if ((unsigned)mesh->shading > (unsigned)AK_SHADING_UNLIT || (unsigned)mesh->blend > (unsigned)AK_BLEND_ADD)
        return AK_ERR_BAD_ARG;
    if (mesh->uvs.count && (mesh->uvs.count != mesh->positions.count || !mesh->uvs.ptr)) return AK_ERR_BAD_ARG;
    const ak_raster_texture* tex = mesh->texture;
    if (tex) {
        const ak_image* ti = &tex->image;
        if (!ti->pixels || ti->width <= 0 || ti->height <= 0 || (ti->stride && ti->stride < (size_t)ti->width * 4u) ||
            (unsigned)tex->wrap_u > (unsigned)AK_RASTER_WRAP_MIRROR ||
            (unsigned)tex->wrap_v > (unsigned)AK_RASTER_WRAP_MIRROR ||
            (unsigned)tex->mag_filter > (unsigned)AK_RASTER_FILTER_NEAREST ||
            (unsigned)tex->min_filter > (unsigned)AK_RASTER_FILTER_NEAREST)
            return AK_ERR_BAD_ARG;
        if (!mesh->uvs.count) tex = NULL;
    }
    if (mesh->model && !ak_mat4_is_finite(mesh->model)) return AK_ERR_BAD_DATA;
    for (size_t i = 0; i < mesh->indices.count; ++i)
        if (mesh->indices.ptr[i] >= mesh->positions.count) return AK_ERR_BAD_INDEX;
    drawctx dc;
    base_ctx(&dc, raster, camera, mesh->model);
    dc.mesh = mesh;
    dc.cull = mesh->cull_back_faces;
    dc.has_vcolor = mesh->colors.count > 0;
    dc.blend = mesh->blend == AK_BLEND_DEFAULT ? AK_BLEND_OPAQUE : mesh->blend;
    dc.depth_test = !mesh->no_depth_test;
    dc.depth_write = dc.blend == AK_BLEND_OPAQUE;
    ak_shading sh = mesh->shading == AK_SHADING_DEFAULT ? AK_SHADING_PHONG : mesh->shading;
    setup_lighting(&dc, mesh->lighting, mesh->material, sh == AK_SHADING_UNLIT);
    switch (sh) {
    case AK_SHADING_UNLIT: {
        ak_vec4 c = vec4_is_zero(mesh->material.color) ? ak_vec4_make(0.78f, 0.74f, 0.70f, 1) : mesh->material.color;
        uint8_t b[4];
        ak_color_to_rgba8(c, b);
        for (int k = 0; k < 4; ++k) dc.const_rgba[k] = b[k];
        dc.mode = dc.has_vcolor ? FRAG_UNLIT_VCOLOR : FRAG_UNLIT_CONST;
        dc.attr_count = dc.has_vcolor ? 4 : 0;
        break;
    }
    case AK_SHADING_FLAT:
        dc.mode = FRAG_FLAT;
        break;
    case AK_SHADING_GOURAUD:
        dc.mode = FRAG_GOURAUD;
        dc.attr_count = 4;
        break;
    default:
        dc.mode = dc.has_vcolor ? FRAG_PHONG_VC : FRAG_PHONG;
        dc.attr_count = mode_attr_count(dc.mode);
        break;
    }
    if (tex) {
        dc.tex = tex;
        dc.tex_stride = tex->image.stride ? tex->image.stride : (size_t)tex->image.width * 4u;
        dc.uv_attr = mode_attr_count(dc.mode);
        dc.attr_count = dc.uv_attr + 2;
    }
    dc.setup = mesh_setup;
    dc.input_count = mesh->indices.count ? mesh->indices.count / 3 : mesh->positions.count / 3;
    run_draw(&dc);
    return AK_OK;
}

/* ---- lines and points ------------------------------------------------------------------- */

static void emit_quad(const drawctx* dc, const cvert q[4], const float flat[4], sink* sk) {
    setup_screen_tri(dc, &q[0], &q[1], &q[2], flat, sk);
    setup_screen_tri(dc, &q[0], &q[2], &q[3], flat, sk);
}

/* A screen-space vertex (NDC x, y, z; w = 1) as a cvert. */
static cvert ndc_vert(float x, float y, float z) {
    cvert v;
    memset(&v, 0, sizeof v);
    v.c[0] = x;
    v.c[1] = y;
    v.c[2] = z;
    v.c[3] = 1.0f;
    return v;
}

static void line_setup(const drawctx* dc, size_t si, sink* sk) {
    const ak_raster_lines* l = dc->lines;
    uint32_t ia = l->indices.count ? l->indices.ptr[si * 2] : (uint32_t)(si * 2);
    uint32_t ib = l->indices.count ? l->indices.ptr[si * 2 + 1] : (uint32_t)(si * 2 + 1);
    ak_vec3 pa = l->positions.ptr[ia], pb = l->positions.ptr[ib];
    if (!ak_vec3_is_finite(pa) || !ak_vec3_is_finite(pb)) return;
    ak_vec4 ca = mul4(&dc->vp, ak_mat4_transform_point(dc->model, pa));
    ak_vec4 cb = mul4(&dc->vp, ak_mat4_transform_point(dc->model, pb));
    ak_vec4 cola = l->colors.count ? l->colors.ptr[ia] : l->color, colb = l->colors.count ? l->colors.ptr[ib] : l->color;
    if (!l->colors.count && vec4_is_zero(cola)) cola = colb = ak_vec4_make(0, 0, 0, 1);
    /* parametric clip against the six planes */
    float t0 = 0.0f, t1 = 1.0f;
    float A[4] = {ca.x, ca.y, ca.z, ca.w}, B[4] = {cb.x, cb.y, cb.z, cb.w};
    for (int p = 0; p < 6; ++p) {
        float da = plane_dist(p, A), db = plane_dist(p, B);
        if (da < 0.0f && db < 0.0f) return;
        if (da < 0.0f) {
            float t = da / (da - db);
            if (t > t0) t0 = t;
        } else if (db < 0.0f) {
            float t = da / (da - db);
            if (t < t1) t1 = t;
        }
    }
    if (!(t0 < t1)) return;
    float P[2][4];
    ak_vec4 col[2];
    for (int k = 0; k < 4; ++k) {
        P[0][k] = A[k] + (B[k] - A[k]) * t0;
        P[1][k] = A[k] + (B[k] - A[k]) * t1;
    }
    col[0] = ak_vec4_add(cola, ak_vec4_scale(ak_vec4_add(colb, ak_vec4_scale(cola, -1.0f)), t0));
    col[1] = ak_vec4_add(cola, ak_vec4_scale(ak_vec4_add(colb, ak_vec4_scale(cola, -1.0f)), t1));
    float sx[2], sy[2], sz[2];
    for (int k = 0; k < 2; ++k) {
        if (!(P[k][3] > 0.0f)) return;
        sx[k] = P[k][0] / P[k][3];
        sy[k] = P[k][1] / P[k][3];
        sz[k] = P[k][2] / P[k][3];
    }
    /* direction in sample pixels */
    float hx = 0.5f * (float)dc->r->sw, hy = 0.5f * (float)dc->r->sh;
    float dx = (sx[1] - sx[0]) * hx, dy = (sy[1] - sy[0]) * hy;
    float len = sqrtf(dx * dx + dy * dy);
    float ux, uy;
    if (len < 1e-6f) {
        ux = 1.0f;
        uy = 0.0f;
    } else {
        ux = dx / len;
        uy = dy / len;
    }
    float w = dc->half_width_px;
    /* offsets in NDC: along (extension for square caps) and across */
    float ax = ux * w / hx, ay = uy * w / hy, nx = -uy * w / hx, ny = ux * w / hy;
    cvert q[4];
    q[0] = ndc_vert(sx[0] - ax + nx, sy[0] - ay + ny, sz[0]);
    q[1] = ndc_vert(sx[0] - ax - nx, sy[0] - ay - ny, sz[0]);
    q[2] = ndc_vert(sx[1] + ax - nx, sy[1] + ay - ny, sz[1]);
    q[3] = ndc_vert(sx[1] + ax + nx, sy[1] + ay + ny, sz[1]);
    for (int k = 0; k < 4; ++k) {
        ak_vec4 c = col[k < 2 ? 0 : 1];
        q[k].a[0] = c.x;
        q[k].a[1] = c.y;
        q[k].a[2] = c.z;
        q[k].a[3] = c.w;
    }
    emit_quad(dc, q, NULL, sk);
}

ak_result ak_raster_draw_lines(ak_raster* raster, const ak_raster_camera* camera, const ak_raster_lines* lines) {
    if (!raster || !camera || !lines || !lines->positions.ptr || lines->positions.count == 0) return AK_ERR_NULL_ARG;
    ak_result res = check_camera(camera);
    if (res != AK_OK) return res;
    if (lines->indices.count % 2 != 0 || (lines->indices.count && !lines->indices.ptr)) return AK_ERR_BAD_ARG;
    if (lines->colors.count && (lines->colors.count != lines->positions.count || !lines->colors.ptr))
        return AK_ERR_BAD_ARG;
    if (lines->model && !ak_mat4_is_finite(lines->model)) return AK_ERR_BAD_DATA;
    for (size_t i = 0; i < lines->indices.count; ++i)
        if (lines->indices.ptr[i] >= lines->positions.count) return AK_ERR_BAD_INDEX;
    drawctx dc;
    base_ctx(&dc, raster, camera, lines->model);
    dc.lines = lines;
    dc.mode = FRAG_UNLIT_VCOLOR;
    dc.attr_count = 4;
    dc.blend = AK_BLEND_ALPHA;
    dc.depth_test = !lines->on_top;
    dc.depth_write = false;
    dc.depth_bias = -2e-5f;
    float wpx = lines->width > 0.0f && ak_finitef(lines->width) ? ak_minf(lines->width, 256.0f) : 2.0f;
    dc.half_width_px = 0.5f * wpx * (float)raster->ss;
    dc.setup = line_setup;
    dc.input_count = lines->indices.count ? lines->indices.count / 2 : lines->positions.count / 2;
    run_draw(&dc);
    return AK_OK;
}

static void point_setup(const drawctx* dc, size_t pi, sink* sk) {
    const ak_raster_points* pt = dc->points;
    ak_vec3 p = pt->positions.ptr[pi];
    if (!ak_vec3_is_finite(p)) return;
    ak_vec4 c = mul4(&dc->vp, ak_mat4_transform_point(dc->model, p));
    if (!(c.z >= -c.w) || !(c.z <= c.w) || !(c.w > 0.0f)) return;
    float x = c.x / c.w, y = c.y / c.w, z = c.z / c.w;
    if (!(fabsf(x) < GUARD * 0.5f && fabsf(y) < GUARD * 0.5f)) return;
    ak_vec4 col = pt->colors.count ? pt->colors.ptr[pi] : pt->color;
    if (!pt->colors.count && vec4_is_zero(col)) col = ak_vec4_make(0, 0, 0, 1);
    if (!vec4_finite(col)) col = ak_vec4_make(0, 0, 0, 1);
    float flat[4] = {ak_srgb_to_linear(clamp01(col.x)), ak_srgb_to_linear(clamp01(col.y)),
                     ak_srgb_to_linear(clamp01(col.z)), clamp01(col.w)};
    float rx = dc->half_width_px / (0.5f * (float)dc->r->sw), ry = dc->half_width_px / (0.5f * (float)dc->r->sh);
    cvert q[4];
    q[0] = ndc_vert(x - rx, y - ry, z);
    q[1] = ndc_vert(x + rx, y - ry, z);
    q[2] = ndc_vert(x + rx, y + ry, z);
    q[3] = ndc_vert(x - rx, y + ry, z);
    const float uv[4][2] = {{-1, -1}, {1, -1}, {1, 1}, {-1, 1}};
    for (int k = 0; k < 4; ++k) {
        q[k].a[0] = uv[k][0];
        q[k].a[1] = uv[k][1];
    }
    emit_quad(dc, q, flat, sk);
}

ak_result ak_raster_draw_points(ak_raster* raster, const ak_raster_camera* camera, const ak_raster_points* points) {
    if (!raster || !camera || !points || !points->positions.ptr || points->positions.count == 0)
        return AK_ERR_NULL_ARG;
    ak_result res = check_camera(camera);
    if (res != AK_OK) return res;
    if (points->colors.count && (points->colors.count != points->positions.count || !points->colors.ptr))
        return AK_ERR_BAD_ARG;
    if (points->model && !ak_mat4_is_finite(points->model)) return AK_ERR_BAD_DATA;
    drawctx dc;
    base_ctx(&dc, raster, camera, points->model);
    dc.points = points;
    dc.mode = FRAG_POINT;
    dc.attr_count = 2;
    dc.blend = AK_BLEND_OPAQUE;
    dc.depth_test = !points->on_top;
    dc.depth_write = true;
    dc.depth_bias = -4e-5f;
    float rad = points->radius > 0.0f && ak_finitef(points->radius) ? ak_minf(points->radius, 256.0f) : 4.0f;
    float ol = points->outline > 0.0f && ak_finitef(points->outline) ? ak_minf(points->outline, 256.0f) : 0.0f;
    dc.half_width_px = (rad + ol) * (float)raster->ss;
    dc.outline_frac = rad / (rad + ol);
    /* outline: the point colour darkened */
    ak_vec4 oc = points->color;
    if (vec4_is_zero(oc)) oc = ak_vec4_make(0, 0, 0, 1);
    uint8_t ob[4];
    ak_color_to_rgba8(ak_vec4_make(oc.x * 0.3f, oc.y * 0.3f, oc.z * 0.3f, 1.0f), ob);
    for (int k = 0; k < 4; ++k) dc.outline_rgba[k] = ob[k];
    dc.setup = point_setup;
    dc.input_count = points->positions.count;
    run_draw(&dc);
    return AK_OK;
}

/* ---- ground ------------------------------------------------------------------------------- */

/* Rasterize the caster triangles, projected onto the plane along the light, into the shadow
 * map as an opacity that is strongest where the caster touches the plane. */
static void shadow_render(ak_raster* r, const ak_raster_ground* g, ak_vec3 ldir, float cx, float cz, float e,
                          float strength) {
    float* S = r->shadow;
    memset(S, 0, sizeof(float) * SHADOW_RES * SHADOW_RES);
    const float texel = 2.0f * e / (float)SHADOW_RES;
    const float falloff = e * 0.25f;
    for (size_t ci = 0; ci < g->caster_count; ++ci) {
        const ak_raster_mesh* m = &g->casters[ci];
        ak_mat4 model = m->model ? *m->model : ak_mat4_identity();
        size_t tcount = m->indices.count ? m->indices.count / 3 : m->positions.count / 3;
        for (size_t t = 0; t < tcount; ++t) {
            float u[3], v[3], h[3];
            bool ok = true;
            for (int k = 0; k < 3; ++k) {
                size_t idx = m->indices.count ? m->indices.ptr[t * 3 + (size_t)k] : t * 3 + (size_t)k;
                ak_vec3 p = ak_mat4_transform_point(model, m->positions.ptr[idx]);
                if (!ak_vec3_is_finite(p)) {
                    ok = false;
                    break;
                }
                float hh = p.y - g->height;
                if (hh < 0.0f) hh = 0.0f;
                float s = hh / -ldir.y;
                u[k] = (p.x + ldir.x * s - (cx - e)) / texel;
                v[k] = (p.z + ldir.z * s - (cz - e)) / texel;
                h[k] = hh;
            }
            if (!ok) continue;
            float area = (u[1] - u[0]) * (v[2] - v[0]) - (v[1] - v[0]) * (u[2] - u[0]);
            if (!(fabsf(area) > 1e-12f)) continue;
            float minu = ak_minf(u[0], ak_minf(u[1], u[2])), maxu = ak_maxf(u[0], ak_maxf(u[1], u[2]));
            float minv = ak_minf(v[0], ak_minf(v[1], v[2])), maxv = ak_maxf(v[0], ak_maxf(v[1], v[2]));
            if (!(maxu >= 0.0f && maxv >= 0.0f && minu <= (float)SHADOW_RES && minv <= (float)SHADOW_RES)) continue;
            int x0 = (int)floorf(ak_maxf(minu, 0.0f)), x1 = (int)ceilf(ak_minf(maxu, (float)SHADOW_RES - 1.0f));
            int y0 = (int)floorf(ak_maxf(minv, 0.0f)), y1 = (int)ceilf(ak_minf(maxv, (float)SHADOW_RES - 1.0f));
            float ia = 1.0f / area;
            for (int y = y0; y <= y1; ++y)
                for (int x = x0; x <= x1; ++x) {
                    float px = (float)x + 0.5f, py = (float)y + 0.5f;
                    float l0 = ((u[1] - px) * (v[2] - py) - (v[1] - py) * (u[2] - px)) * ia;
                    float l1 = ((u[2] - px) * (v[0] - py) - (v[2] - py) * (u[0] - px)) * ia;
                    float l2 = 1.0f - l0 - l1;
                    if (l0 < 0.0f || l1 < 0.0f || l2 < 0.0f) continue;
                    float hh = l0 * h[0] + l1 * h[1] + l2 * h[2];
                    float o = strength * (0.45f + 0.55f * expf(-hh / falloff));
                    if (o > S[y * SHADOW_RES + x]) S[y * SHADOW_RES + x] = o;
                }
        }
    }
}

static void box_blur(float* s, float* tmp, int radius) {
    if (radius < 1) return;
    const float inv = 1.0f / (float)(2 * radius + 1);
    for (int pass = 0; pass < 2; ++pass) {
        /* horizontal into tmp, vertical back into s */
        for (int y = 0; y < SHADOW_RES; ++y) {
            float acc = 0.0f;
            for (int x = -radius; x <= radius; ++x) acc += (x >= 0 && x < SHADOW_RES) ? s[y * SHADOW_RES + x] : 0.0f;
            for (int x = 0; x < SHADOW_RES; ++x) {
                tmp[y * SHADOW_RES + x] = acc * inv;
                int xa = x + radius + 1, xr = x - radius;
                acc += (xa < SHADOW_RES ? s[y * SHADOW_RES + xa] : 0.0f) - (xr >= 0 ? s[y * SHADOW_RES + xr] : 0.0f);
            }
        }
        /* vertical: every column's running sum at once, row by row (each column sees the same
         * additions in the same order as a column-by-column pass; rows are contiguous) */
        float acc[SHADOW_RES];
        for (int x = 0; x < SHADOW_RES; ++x) acc[x] = 0.0f;
        for (int y = -radius; y <= radius; ++y)
            for (int x = 0; x < SHADOW_RES; ++x)
                acc[x] += (y >= 0 && y < SHADOW_RES) ? tmp[y * SHADOW_RES + x] : 0.0f;
        for (int y = 0; y < SHADOW_RES; ++y) {
            const int ya = y + radius + 1, yr = y - radius;
            for (int x = 0; x < SHADOW_RES; ++x) {
                s[y * SHADOW_RES + x] = acc[x] * inv;
                acc[x] += (ya < SHADOW_RES ? tmp[ya * SHADOW_RES + x] : 0.0f) -
                          (yr >= 0 ? tmp[yr * SHADOW_RES + x] : 0.0f);
            }
        }
    }
}

static void ground_setup(const drawctx* dc, size_t ti, sink* sk) {
    const cvert* q = dc->quad;
    if (ti == 0) clip_and_setup(dc, &q[0], &q[1], &q[2], NULL, sk);
    else clip_and_setup(dc, &q[0], &q[2], &q[3], NULL, sk);
}

ak_result ak_raster_draw_ground(ak_raster* raster, const ak_raster_camera* camera, const ak_raster_ground* ground) {
    if (!raster || !camera || !ground) return AK_ERR_NULL_ARG;
    ak_result res = check_camera(camera);
    if (res != AK_OK) return res;
    if (!ak_finitef(ground->height) || !ak_vec3_is_finite(ground->center) || !ak_finitef(ground->half_extent) ||
        !ak_finitef(ground->grid_spacing) || ground->half_extent < 0.0f || ground->grid_spacing < 0.0f ||
        !ak_finitef(ground->shadow_softness) || !ak_finitef(ground->shadow_strength))
        return AK_ERR_BAD_ARG;
    if (ground->caster_count && !ground->casters) return AK_ERR_NULL_ARG;
    for (size_t i = 0; i < ground->caster_count; ++i) {
        const ak_raster_mesh* m = &ground->casters[i];
        if (!m->positions.ptr || m->positions.count == 0) return AK_ERR_NULL_ARG;
        if (m->indices.count % 3 != 0 || (m->indices.count && !m->indices.ptr)) return AK_ERR_BAD_ARG;
        for (size_t k = 0; k < m->indices.count; ++k)
            if (m->indices.ptr[k] >= m->positions.count) return AK_ERR_BAD_INDEX;
        if (m->model && !ak_mat4_is_finite(m->model)) return AK_ERR_BAD_DATA;
    }
    drawctx dc;
    base_ctx(&dc, raster, camera, NULL);
    float e = ground->half_extent > 0.0f ? ground->half_extent : 4.0f;
    dc.ground_e = e;
    dc.ground_h = ground->height;
    dc.ground_cx = ground->center.x;
    dc.ground_cz = ground->center.z;
    dc.grid_spacing = ground->grid_spacing > 0.0f ? ground->grid_spacing : e / 8.0f;
    dc.ground_lin = srgb3_to_lin(vec4_is_zero(ground->color) ? ak_vec4_make(0.80f, 0.80f, 0.78f, 1) : ground->color);
    dc.line_lin =
        srgb3_to_lin(vec4_is_zero(ground->line_color) ? ak_vec4_make(0.55f, 0.56f, 0.58f, 1) : ground->line_color);
    /* angle of one sample pixel: from the projection's vertical scale */
    float py = camera->projection.m[5];
    if (dc.ortho) dc.pix_angle = 2.0f / (py * (float)raster->sh);
    else dc.pix_angle = 2.0f / ((py > 1e-6f ? py : 1.0f) * (float)raster->sh);
    if (ground->caster_count) {
        ak_raster_lighting l = ak_raster_lighting_resolved(ground->lighting);
        ak_vec3 d = ak_vec3_normalize(l.key_direction);
        /* contact shadows read best from a mostly vertical light */
        d = ak_vec3_normalize(ak_vec3_lerp(d, ak_vec3_make(0, -1, 0), 0.5f));
        if (d.y > -0.3f) d = ak_vec3_normalize(ak_vec3_make(d.x, -0.3f, d.z));
        float strength = ground->shadow_strength > 0.0f ? clamp01(ground->shadow_strength) : 0.55f;
        shadow_render(raster, ground, d, dc.ground_cx, dc.ground_cz, e, strength);
        float soft = ground->shadow_softness > 0.0f ? ground->shadow_softness : e / 40.0f;
        float frad = soft / (2.0f * e / (float)SHADOW_RES) * 0.6f + 0.5f;
        int rad = frad < 32.0f ? (int)frad : 32;
        box_blur(raster->shadow, raster->shadow_tmp, rad);
        dc.shadow = true;
    }
    cvert q[4];
    const float sx[4] = {-1, 1, 1, -1}, sz[4] = {1, 1, -1, -1};
    for (int k = 0; k < 4; ++k) {
        ak_vec3 p = ak_vec3_make(dc.ground_cx + sx[k] * e, ground->height, dc.ground_cz + sz[k] * e);
        ak_vec4 c = mul4(&dc.vp, p);
        memset(&q[k], 0, sizeof q[k]);
        q[k].c[0] = c.x;
        q[k].c[1] = c.y;
        q[k].c[2] = c.z;
        q[k].c[3] = c.w;
        q[k].a[0] = p.x;
        q[k].a[1] = p.y;
        q[k].a[2] = p.z;
    }
    dc.quad = q;
    dc.mode = FRAG_GROUND;
    dc.attr_count = 3;
    dc.blend = AK_BLEND_OPAQUE;
    dc.setup = ground_setup;
    dc.input_count = 2;
    run_draw(&dc);
    return AK_OK;
}

/* ---- text ------------------------------------------------------------------------------- */

ak_result ak_raster_draw_text(ak_raster* raster, int x, int y, const char* text, int scale, ak_vec4 color) {
    if (!raster || !text) return AK_ERR_NULL_ARG;
    if (x < -(1 << 24) || x > (1 << 24) || y < -(1 << 24) || y > (1 << 24)) return AK_OK; /* off any image */
    ak_image img = {raster->color, raster->sw, raster->sh, 0};
    int s = scale > 0 ? (scale > 64 ? 64 : scale) : 1;
    return ak_image_draw_text(&img, x * raster->ss, y * raster->ss, text, s * raster->ss, color);
}

/* ---- internal access for the other raster files ----------------------------------------- */

akp_raster_target akp_raster_target_of(ak_raster* raster) {
    akp_raster_target t = {raster->color, raster->depth, raster->sw, raster->sh, raster->ss};
    return t;
}

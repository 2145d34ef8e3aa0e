/* View helpers: framing, heatmaps, scene render, skeleton overlay, panels, plots, GIF. */
#include <math.h>
#include <stdio.h>

#include <animkit/view.h>

#include "internal.h"

/* ---- private types and helpers ---------------------------------------------------------------- */

typedef struct plot_layout {
    float ax0, ax1, ay0, ay1;         /* plot area in pixels (x0 left, y0 top) */
    double xmin, xmax, ymin, ymax;    /* data range */
    double xstep, ystep;              /* tick spacing */
    int xdec, ydec;                   /* decimals in tick labels */
} plot_layout;

static bool vec4_zero(ak_vec4 v) { return v.x == 0.0f && v.y == 0.0f && v.z == 0.0f && v.w == 0.0f; }
static ak_vec4 or_default(ak_vec4 v, ak_vec4 d) { return vec4_zero(v) ? d : v; }
static ak_vec4 rgba(float r, float g, float b, float a) { return ak_vec4_make(r, g, b, a); }

#define MIN_KEY_GAP 8.0 /* pixels: average key spacing below which key markers are left out */

static bool span_ok_f32(ak_f32_cspan s) { return s.count == 0 || s.ptr != NULL; }

/* Tick step from {1, 2, 5} x 10^k close to range / target_count. */
static double nice_step(double range, double target_count, int* out_decimals) {
    if (!(range > 0.0) || !isfinite(range)) range = 1.0;
    double raw = range / (target_count > 1.0 ? target_count : 1.0);
    double mag = pow(10.0, floor(log10(raw)));
    double norm = raw / mag;
    double step = (norm < 1.5 ? 1.0 : norm < 3.0 ? 2.0 : norm < 7.0 ? 5.0 : 10.0) * mag;
    int dec = (int)-floor(log10(step) + 1e-9);
    *out_decimals = dec > 0 ? (dec > 6 ? 6 : dec) : 0;
    return step;
}

static void format_tick(char* buf, size_t size, double v, double step, int dec) {
    if (fabs(v) < step * 1e-6) v = 0.0;
    snprintf(buf, size, "%.*f", dec, v);
}

/* ---- framing ------------------------------------------------------------------------------------ */

ak_raster_camera ak_view_orbit_camera(ak_vec3 lo, ak_vec3 hi, const ak_view_orbit* orbit) {
    ak_view_orbit o;
    memset(&o, 0, sizeof o);
    if (orbit) o = *orbit;
    float fovy = (o.fovy > 0.0f && o.fovy < 3.0f) ? o.fovy : ak_radians(40.0f);
    float margin = (o.margin > 0.0f && ak_finitef(o.margin)) ? o.margin : 1.1f;
    float aspect = (o.aspect > 0.0f && ak_finitef(o.aspect)) ? o.aspect : 1.0f;
    float az = ak_finitef(o.azimuth) ? o.azimuth : 0.0f;
    float el = ak_finitef(o.elevation) ? ak_clampf(o.elevation, -1.45f, 1.45f) : 0.0f;
    if (!ak_vec3_is_finite(lo) || !ak_vec3_is_finite(hi) || lo.x > hi.x || lo.y > hi.y || lo.z > hi.z) {
        lo = ak_vec3_splat(-0.5f);
        hi = ak_vec3_splat(0.5f);
    }
    ak_vec3 c = ak_vec3_scale(ak_vec3_add(lo, hi), 0.5f);
    float R = 0.5f * ak_vec3_length(ak_vec3_sub(hi, lo));
    if (!(R > 1e-4f)) R = 1e-4f;
    ak_vec3 dir = ak_vec3_make(cosf(el) * sinf(az), sinf(el), cosf(el) * cosf(az)); /* towards the eye */
    ak_vec3 right = ak_vec3_normalize(ak_vec3_cross(ak_vec3_neg(dir), ak_vec3_make(0, 1, 0)));
    ak_vec3 up = ak_vec3_cross(right, ak_vec3_neg(dir));
    /* fit the eight corners themselves (tighter than the bounding sphere for long boxes) */
    float half_v = 0.5f * fovy, half_h = atanf(tanf(half_v) * aspect);
    float tx = tanf(half_h) / margin, ty = tanf(half_v) / margin;
    float d = 0.0f, zmax = -INFINITY, xy_max = 0.0f;
    for (int k = 0; k < 8; ++k) {
        ak_vec3 q = ak_vec3_sub(ak_vec3_make(k & 1 ? hi.x : lo.x, k & 2 ? hi.y : lo.y, k & 4 ? hi.z : lo.z), c);
        float x = fabsf(ak_vec3_dot(q, right)), y = fabsf(ak_vec3_dot(q, up)), z = ak_vec3_dot(q, dir);
        d = ak_maxf(d, ak_maxf(z + x / tx, z + y / ty));
        zmax = ak_maxf(zmax, z);
        xy_max = ak_maxf(xy_max, ak_maxf(x / aspect, y));
    }
    if (o.orthographic) {
        float hh = ak_maxf(xy_max * margin, 1e-4f);
        ak_vec3 eye = ak_vec3_madd(c, dir, zmax + R);
        return ak_raster_camera_orthographic(eye, c, hh, aspect, 0.1f * R, zmax + 6.0f * R);
    }
    d = ak_maxf(d, zmax + 0.05f * R);
    ak_vec3 eye = ak_vec3_madd(c, dir, d);
    float near_z = ak_maxf(0.5f * (d - zmax), 0.001f * d);
    return ak_raster_camera_perspective(eye, c, fovy, aspect, near_z, d + 6.0f * R);
}

/* ---- colours ---------------------------------------------------------------------------------- */

ak_vec4 ak_view_heatmap_color(float t) {
    static const float stops[5][3] = {
        {0.10f, 0.22f, 0.90f}, /* blue */
        {0.08f, 0.72f, 0.92f}, /* cyan */
        {0.20f, 0.80f, 0.25f}, /* green */
        {0.98f, 0.84f, 0.12f}, /* yellow */
        {0.90f, 0.12f, 0.08f}, /* red */
    };
    if (!(t > 0.0f)) t = 0.0f;
    if (t > 1.0f) t = 1.0f;
    float f = t * 4.0f;
    int i = (int)f;
    if (i > 3) i = 3;
    float u = f - (float)i;
    return rgba(ak_lerpf(stops[i][0], stops[i + 1][0], u), ak_lerpf(stops[i][1], stops[i + 1][1], u),
                ak_lerpf(stops[i][2], stops[i + 1][2], u), 1.0f);
}

ak_result ak_view_heatmap_colors(ak_f32_cspan values, float lo, float hi, ak_vec4_span out_colors) {
    if ((values.count && !values.ptr) || (out_colors.count && !out_colors.ptr)) return AK_ERR_NULL_ARG;
    if (out_colors.count < values.count) return AK_ERR_SPAN_SMALL;
    if (!ak_finitef(lo) || !ak_finitef(hi)) return AK_ERR_BAD_ARG;
    for (size_t i = 0; i < values.count; ++i) {
        float t = hi != lo ? (values.ptr[i] - lo) / (hi - lo) : 0.5f;
        out_colors.ptr[i] = ak_view_heatmap_color(t);
    }
    return AK_OK;
}

ak_result ak_view_joint_weights(const ak_mesh* mesh, uint32_t joint_index, ak_f32_span out_weights) {
    if (!mesh || (out_weights.count && !out_weights.ptr)) return AK_ERR_NULL_ARG;
    if (out_weights.count < mesh->vertex_count) return AK_ERR_SPAN_SMALL;
    const uint32_t ic = mesh->influence_count;
    for (size_t v = 0; v < mesh->vertex_count; ++v) {
        float w = 0.0f;
        if (ic && mesh->joints && mesh->weights)
            for (uint32_t k = 0; k < ic; ++k)
                if (mesh->joints[v * ic + k] == joint_index && ak_finitef(mesh->weights[v * ic + k]))
                    w += mesh->weights[v * ic + k];
        out_weights.ptr[v] = w;
    }
    return AK_OK;
}

ak_vec4 ak_view_palette_color(size_t index) {
    static const float pal[8][3] = {
        {0.20f, 0.45f, 0.80f}, {0.90f, 0.40f, 0.15f}, {0.20f, 0.65f, 0.30f}, {0.80f, 0.20f, 0.30f},
        {0.55f, 0.35f, 0.75f}, {0.55f, 0.40f, 0.25f}, {0.90f, 0.45f, 0.70f}, {0.40f, 0.40f, 0.40f},
    };
    const float* c = pal[index % 8];
    return rgba(c[0], c[1], c[2], 1.0f);
}

/* OKLab (Ottosson 2020) -> linear sRGB. */
static void oklab_to_linear(double L, double a, double b, double out[3]) {
    double l_ = L + 0.3963377774 * a + 0.2158037573 * b;
    double m_ = L - 0.1055613458 * a - 0.0638541728 * b;
    double s_ = L - 0.0894841775 * a - 1.2914855480 * b;
    double l = l_ * l_ * l_, m = m_ * m_ * m_, s = s_ * s_ * s_;
    out[0] = 4.0767416621 * l - 3.3077115913 * m + 0.2309699292 * s;
    out[1] = -1.2684380046 * l + 2.6097574011 * m - 0.3413193965 * s;
    out[2] = -0.0041960863 * l - 0.7034186147 * m + 1.7076147010 * s;
}

/* The candidates (OKLab and sRGB) in a fixed order: lightness x chroma x hue, in gamut. */
#define DISTINCT_GRID (5 * 3 * 24) /* lightness x chroma x hue; AK_VIEW_DISTINCT_COLOR_COUNT are in gamut */
typedef struct distinct_candidates {
    double lab[DISTINCT_GRID][3];
    float rgb[DISTINCT_GRID][3];
    double dmin[DISTINCT_GRID]; /* squared distance to the nearest chosen one */
    int count;
} distinct_candidates;

static void distinct_fill(distinct_candidates* c) {
    static const double Ls[5] = {0.50, 0.58, 0.66, 0.74, 0.82}, Cs[3] = {0.09, 0.14, 0.19};
    c->count = 0;
    for (int li = 0; li < 5; ++li)
        for (int ci = 0; ci < 3; ++ci)
            for (int hi = 0; hi < 24; ++hi) {
                const double h = (double)hi * (2.0 * 3.14159265358979323846 / 24.0);
                const double L = Ls[li], a = Cs[ci] * cos(h), b = Cs[ci] * sin(h);
                double lin[3];
                oklab_to_linear(L, a, b, lin);
                if (lin[0] < 0.0 || lin[0] > 1.0 || lin[1] < 0.0 || lin[1] > 1.0 || lin[2] < 0.0 || lin[2] > 1.0) continue;
                c->lab[c->count][0] = L, c->lab[c->count][1] = a, c->lab[c->count][2] = b;
                for (int k = 0; k < 3; ++k) c->rgb[c->count][k] = ak_linear_to_srgb((float)lin[k]);
                c->dmin[c->count] = INFINITY;
                ++c->count;
            }
}

ak_result ak_view_distinct_colors(ak_vec4_span out_colors) {
    if (out_colors.count && !out_colors.ptr) return AK_ERR_NULL_ARG;
    if (!out_colors.count) return AK_OK;
    distinct_candidates c;
    distinct_fill(&c);
    /* start from the candidate nearest a mid blue (L 0.58, hue 255 degrees, chroma 0.14) */
    const double b0[3] = {0.58, 0.14 * cos(4.45), 0.14 * sin(4.45)};
    int pick = 0;
    double best = INFINITY;
    for (int i = 0; i < c.count; ++i) {
        double d = 0;
        for (int k = 0; k < 3; ++k) d += (c.lab[i][k] - b0[k]) * (c.lab[i][k] - b0[k]);
        if (d < best) best = d, pick = i;
    }
    const size_t distinct = (size_t)c.count;
    for (size_t n = 0; n < out_colors.count; ++n) {
        if (n >= distinct) { /* every candidate used: repeat */
            out_colors.ptr[n] = out_colors.ptr[n % distinct];
            continue;
        }
        out_colors.ptr[n] = rgba(c.rgb[pick][0], c.rgb[pick][1], c.rgb[pick][2], 1.0f);
        c.dmin[pick] = -1.0; /* taken */
        int next = -1;
        double far = -1.0;
        for (int i = 0; i < c.count; ++i) {
            if (c.dmin[i] < 0.0) continue;
            double d = 0;
            for (int k = 0; k < 3; ++k) d += (c.lab[i][k] - c.lab[pick][k]) * (c.lab[i][k] - c.lab[pick][k]);
            if (d < c.dmin[i]) c.dmin[i] = d;
            if (c.dmin[i] > far) far = c.dmin[i], next = i;
        }
        if (next >= 0) pick = next;
    }
    return AK_OK;
}

/* ---- scenes ----------------------------------------------------------------------------------- */

ak_raster_mesh ak_view_raster_mesh(const ak_mesh* mesh) {
    ak_raster_mesh m;
    memset(&m, 0, sizeof m);
    if (!mesh) return m;
    m.positions = (ak_vec3_cspan){mesh->positions, mesh->positions ? mesh->vertex_count : 0};
    if (mesh->normals) m.normals = (ak_vec3_cspan){mesh->normals, mesh->vertex_count};
    if (mesh->indices) m.indices = (ak_u32_cspan){mesh->indices, mesh->triangle_count * 3};
    return m;
}

static ak_vec3 joint_world(const ak_view_skeleton* s, size_t i) {
    ak_vec3 p = ak_mat4_get_translation(s->joint_model.ptr[i]);
    return s->model ? ak_mat4_transform_point(*s->model, p) : p;
}

ak_result ak_view_draw_skeleton(ak_raster* raster, const ak_raster_camera* camera, const ak_view_skeleton* s) {
    if (!raster || !camera || !s || !s->joint_model.ptr || !s->parents.ptr || s->joint_model.count == 0)
        return AK_ERR_NULL_ARG;
    if (s->parents.count != s->joint_model.count) return AK_ERR_BAD_ARG;
    const size_t n = s->joint_model.count;
    for (size_t i = 0; i < n; ++i)
        if (s->parents.ptr[i] < -1 || (size_t)(s->parents.ptr[i] + 1) > n) return AK_ERR_BAD_INDEX;
    ak_vec4 bone = or_default(s->bone_color, rgba(0.97f, 0.97f, 1.0f, 1));
    ak_vec4 joint = or_default(s->joint_color, rgba(1.0f, 0.78f, 0.18f, 1));
    float bw = s->bone_width > 0.0f ? s->bone_width : 2.5f;
    float jr = s->joint_radius > 0.0f ? s->joint_radius : 3.5f;
    enum { CHUNK = 128 };
    ak_vec3 seg[2 * CHUNK];
    size_t ns = 0;
    ak_result r = AK_OK;
    for (size_t i = 0; i < n && r == AK_OK; ++i) {
        int p = s->parents.ptr[i];
        if (p >= 0) {
            ak_vec3 a = joint_world(s, (size_t)p), b = joint_world(s, i);
            if (ak_vec3_is_finite(a) && ak_vec3_is_finite(b)) {
                seg[2 * ns] = a;
                seg[2 * ns + 1] = b;
                ++ns;
            }
        }
        if (ns == CHUNK || (i + 1 == n && ns > 0)) {
            /* a dark halo under the bone keeps it readable on any background */
            ak_raster_lines halo = {.positions = {seg, 2 * ns}, .color = rgba(0.05f, 0.05f, 0.08f, 0.55f),
                                    .width = bw + 2.0f, .on_top = !s->depth_tested};
            ak_raster_lines lines = {.positions = {seg, 2 * ns}, .color = bone, .width = bw,
                                     .on_top = !s->depth_tested};
            r = ak_raster_draw_lines(raster, camera, &halo);
            if (r == AK_OK) r = ak_raster_draw_lines(raster, camera, &lines);
            ns = 0;
        }
    }
    ak_vec3 pts[CHUNK];
    size_t np = 0;
    for (size_t i = 0; i < n && r == AK_OK; ++i) {
        ak_vec3 a = joint_world(s, i);
        if (ak_vec3_is_finite(a)) pts[np++] = a;
        if (np == CHUNK || (i + 1 == n && np > 0)) {
            ak_raster_points pt = {.positions = {pts, np}, .color = joint, .radius = jr, .outline = 1.2f,
                                   .on_top = !s->depth_tested};
            r = ak_raster_draw_points(raster, camera, &pt);
            np = 0;
        }
    }
    return r;
}

void ak_view_scene_bounds(const ak_view_scene* scene, ak_vec3* out_min, ak_vec3* out_max) {
    ak_vec3 lo = ak_vec3_splat(INFINITY), hi = ak_vec3_splat(-INFINITY);
    bool any = false;
    if (scene) {
        for (size_t m = 0; scene->meshes && m < scene->mesh_count; ++m) {
            const ak_raster_mesh* me = &scene->meshes[m];
            for (size_t i = 0; me->positions.ptr && i < me->positions.count; ++i) {
                ak_vec3 p = me->positions.ptr[i];
                if (me->model) p = ak_mat4_transform_point(*me->model, p);
                if (!ak_vec3_is_finite(p)) continue;
                lo = ak_vec3_min(lo, p);
                hi = ak_vec3_max(hi, p);
                any = true;
            }
        }
        const ak_view_skeleton* s = scene->skeleton;
        for (size_t i = 0; s && s->joint_model.ptr && i < s->joint_model.count; ++i) {
            ak_vec3 p = joint_world(s, i);
            if (!ak_vec3_is_finite(p)) continue;
            lo = ak_vec3_min(lo, p);
            hi = ak_vec3_max(hi, p);
            any = true;
        }
    }
    if (!any) lo = hi = ak_vec3_zero();
    if (out_min) *out_min = lo;
    if (out_max) *out_max = hi;
}

ak_result ak_view_render(ak_raster* raster, const ak_raster_camera* camera, const ak_view_scene* scene,
                         const ak_image* out) {
    if (!raster || !camera || !scene || !out) return AK_ERR_NULL_ARG;
    if (scene->mesh_count && !scene->meshes) return AK_ERR_NULL_ARG;
    ak_raster_clear(raster, or_default(scene->background_top, rgba(0.82f, 0.86f, 0.92f, 1)),
                    or_default(scene->background_bottom, rgba(0.50f, 0.53f, 0.60f, 1)));
    ak_result r = AK_OK;
    if (!scene->no_ground && (scene->mesh_count || scene->skeleton)) {
        ak_vec3 lo, hi;
        ak_view_scene_bounds(scene, &lo, &hi);
        ak_vec3 size = ak_vec3_sub(hi, lo);
        float horiz = ak_maxf(size.x, size.z);
        float e = ak_maxf(ak_maxf(1.4f * horiz, 0.9f * size.y), 1e-3f);
        int dec;
        float spacing = (float)nice_step(e, 7.0, &dec);
        ak_raster_ground g = {
            .height = lo.y,
            .center = ak_vec3_scale(ak_vec3_add(lo, hi), 0.5f),
            .half_extent = e,
            .grid_spacing = spacing,
            .casters = scene->meshes,
            .caster_count = scene->mesh_count,
        };
        r = ak_raster_draw_ground(raster, camera, &g);
    }
    for (size_t m = 0; r == AK_OK && m < scene->mesh_count; ++m) r = ak_raster_draw_mesh(raster, camera, &scene->meshes[m]);
    if (r == AK_OK && scene->skeleton) r = ak_view_draw_skeleton(raster, camera, scene->skeleton);
    if (r == AK_OK && scene->title) r = ak_raster_draw_text(raster, 10, 10, scene->title, 2, rgba(0.08f, 0.09f, 0.12f, 1));
    if (r == AK_OK) r = ak_raster_resolve(raster, out);
    return r;
}

/* ---- panels ----------------------------------------------------------------------------------- */

typedef struct panels_geom {
    int cols, rows, gap, label_h, title_h, label_scale;
} panels_geom;

static panels_geom panels_layout(const ak_view_panels_desc* d, size_t count) {
    panels_geom g;
    g.cols = (d && d->columns > 0) ? d->columns : (int)count;
    if (g.cols > (int)count) g.cols = (int)count;
    if (g.cols < 1) g.cols = 1;
    g.rows = (int)((count + (size_t)g.cols - 1) / (size_t)g.cols);
    g.gap = (d && d->gap > 0) ? d->gap : 6;
    g.label_scale = (d && d->label_scale > 0) ? d->label_scale : 2;
    g.label_h = g.label_scale * AK_FONT_GLYPH_HEIGHT + 8;
    g.title_h = (d && d->title) ? (g.label_scale + 1) * AK_FONT_GLYPH_HEIGHT + 12 : 0;
    return g;
}

void ak_view_panels_size(const ak_view_panels_desc* desc, size_t panel_count, int panel_width, int panel_height,
                         int* out_width, int* out_height) {
    int w = 0, h = 0;
    if (panel_count > 0 && panel_width > 0 && panel_height > 0) {
        panels_geom g = panels_layout(desc, panel_count);
        w = g.cols * panel_width + (g.cols + 1) * g.gap;
        h = g.title_h + g.rows * (g.label_h + panel_height) + (g.rows + 1) * g.gap;
    }
    if (out_width) *out_width = w;
    if (out_height) *out_height = h;
}

ak_result ak_view_panels_compose(const ak_view_panels_desc* desc, const ak_view_panel* panels, size_t panel_count,
                                 const ak_image* out) {
    if (!out || !out->pixels || (panel_count && !panels)) return AK_ERR_NULL_ARG;
    if (panel_count == 0) return AK_ERR_EMPTY;
    for (size_t i = 0; i < panel_count; ++i)
        if (!panels[i].image || !panels[i].image->pixels) return AK_ERR_NULL_ARG;
    const int pw = panels[0].image->width, ph = panels[0].image->height;
    for (size_t i = 0; i < panel_count; ++i)
        if (panels[i].image->width != pw || panels[i].image->height != ph) return AK_ERR_BAD_ARG;
    int W, H;
    ak_view_panels_size(desc, panel_count, pw, ph, &W, &H);
    if (out->width != W || out->height != H || W == 0) return AK_ERR_BAD_ARG;
    panels_geom g = panels_layout(desc, panel_count);
    ak_vec4 bg = or_default(desc ? desc->background : rgba(0, 0, 0, 0), rgba(0.14f, 0.15f, 0.18f, 1));
    ak_vec4 fg = or_default(desc ? desc->text_color : rgba(0, 0, 0, 0), rgba(0.95f, 0.95f, 0.95f, 1));
    ak_result r = ak_image_fill(out, bg);
    if (r != AK_OK) return r;
    if (desc && desc->title) {
        /* one scale above the labels; smaller when that is wider than the image (one narrow
         * panel), centred in the strip sized for the larger scale */
        int scale = g.label_scale + 1, tw, th;
        ak_text_size(desc->title, scale, &tw, &th);
        while (tw > W - 2 * g.gap && scale > 1) ak_text_size(desc->title, --scale, &tw, &th);
        int dy = (g.label_scale + 1 - scale) * AK_FONT_GLYPH_HEIGHT / 2;
        ak_image_draw_text(out, (W - tw) / 2, 6 + g.gap / 2 + dy, desc->title, scale, fg);
    }
    for (size_t i = 0; i < panel_count; ++i) {
        int c = (int)(i % (size_t)g.cols), row = (int)(i / (size_t)g.cols);
        int x = g.gap + c * (pw + g.gap);
        int y = g.title_h + g.gap + row * (g.label_h + ph + g.gap);
        if (panels[i].label) {
            int tw, th;
            ak_text_size(panels[i].label, g.label_scale, &tw, &th);
            ak_image_draw_text(out, x + (pw - tw) / 2, y + 4, panels[i].label, g.label_scale, fg);
        }
        r = ak_image_blit(out, x, y + g.label_h, panels[i].image);
        if (r != AK_OK) return r;
    }
    return AK_OK;
}

/* ---- plots ------------------------------------------------------------------------------------ */

static ak_result plot_check(const ak_view_plot* p) {
    if (!p || !p->series) return AK_ERR_NULL_ARG;
    if (p->series_count == 0) return AK_ERR_EMPTY;
    for (size_t i = 0; i < p->series_count; ++i) {
        const ak_view_series* s = &p->series[i];
        if (!span_ok_f32(s->x) || !span_ok_f32(s->y) || !span_ok_f32(s->key_x) || !span_ok_f32(s->key_y) ||
            !span_ok_f32(s->key_in_slope) || !span_ok_f32(s->key_out_slope))
            return AK_ERR_NULL_ARG;
        if (s->x.count != s->y.count || s->key_x.count != s->key_y.count) return AK_ERR_BAD_ARG;
        if ((s->key_in_slope.count && s->key_in_slope.count != s->key_x.count) ||
            (s->key_out_slope.count && s->key_out_slope.count != s->key_x.count))
            return AK_ERR_BAD_ARG;
    }
    if (!ak_finitef(p->x_min) || !ak_finitef(p->x_max) || !ak_finitef(p->y_min) || !ak_finitef(p->y_max) ||
        p->x_min > p->x_max || p->y_min > p->y_max)
        return AK_ERR_BAD_ARG;
    return AK_OK;
}

static ak_result plot_layout_make(const ak_view_plot* p, int w, int h, plot_layout* L) {
    ak_result r = plot_check(p);
    if (r != AK_OK) return r;
    if (w < 120 || h < 80) return AK_ERR_BAD_ARG;
    double xmin = INFINITY, xmax = -INFINITY, ymin = INFINITY, ymax = -INFINITY;
    for (size_t i = 0; i < p->series_count; ++i) {
        const ak_view_series* s = &p->series[i];
        for (size_t k = 0; k < s->x.count; ++k) {
            if (!ak_finitef(s->x.ptr[k]) || !ak_finitef(s->y.ptr[k])) continue;
            xmin = fmin(xmin, s->x.ptr[k]), xmax = fmax(xmax, s->x.ptr[k]);
            ymin = fmin(ymin, s->y.ptr[k]), ymax = fmax(ymax, s->y.ptr[k]);
        }
        for (size_t k = 0; k < s->key_x.count; ++k) {
            if (!ak_finitef(s->key_x.ptr[k]) || !ak_finitef(s->key_y.ptr[k])) continue;
            xmin = fmin(xmin, s->key_x.ptr[k]), xmax = fmax(xmax, s->key_x.ptr[k]);
            ymin = fmin(ymin, s->key_y.ptr[k]), ymax = fmax(ymax, s->key_y.ptr[k]);
        }
    }
    if (!(xmin <= xmax)) return AK_ERR_EMPTY;
    if (p->x_min != p->x_max) xmin = p->x_min, xmax = p->x_max;
    else if (xmax - xmin <= 1e-12 * fmax(1.0, fabs(xmin))) xmin -= 1.0, xmax += 1.0;
    if (p->y_min != p->y_max) {
        ymin = p->y_min, ymax = p->y_max;
    } else {
        if (ymax - ymin <= 1e-12 * fmax(1.0, fabs(ymin))) {
            ymin -= 1.0, ymax += 1.0;
        } else {
            /* at least 1% of the magnitude: a scale of 1 +- 1e-6 float noise stays a flat line */
            double least = 0.01 * fmax(fabs(ymin), fabs(ymax)), mid = 0.5 * (ymin + ymax);
            if (ymax - ymin < least) ymin = mid - 0.5 * least, ymax = mid + 0.5 * least;
        }
        double pad = 0.08 * (ymax - ymin);
        ymin -= pad, ymax += pad;
    }
    /* spans beyond float range cannot be mapped to pixels */
    if (!isfinite(xmax - xmin) || !isfinite(ymax - ymin) || fabs(xmin) > 1e30 || fabs(xmax) > 1e30 ||
        fabs(ymin) > 1e30 || fabs(ymax) > 1e30)
        return AK_ERR_BAD_ARG;
    L->xmin = xmin, L->xmax = xmax, L->ymin = ymin, L->ymax = ymax;
    L->ystep = nice_step(ymax - ymin, h > 300 ? 6.0 : 4.0, &L->ydec);
    L->xstep = nice_step(xmax - xmin, fmax(2.0, (double)w / 90.0), &L->xdec);
    /* widest y tick label sets the left margin */
    int maxlen = 1;
    char buf[64];
    int guard = 0;
    for (double v = ceil(ymin / L->ystep) * L->ystep; v <= ymax + L->ystep * 1e-6 && guard < 64; v += L->ystep, ++guard) {
        format_tick(buf, sizeof buf, v, L->ystep, L->ydec);
        int len = (int)strlen(buf);
        if (len > maxlen) maxlen = len;
    }
    L->ax0 = (float)(10 + maxlen * AK_FONT_ADVANCE_X + 6);
    L->ax1 = (float)(w - 14);
    bool legend = false;
    for (size_t i = 0; !p->no_legend && i < p->series_count; ++i) legend = legend || p->series[i].label != NULL;
    L->ay0 = (float)(p->title ? 34 : 14) + (p->y_label || legend ? 14.0f : 0.0f);
    L->ay1 = (float)(h - 24 - (p->x_label ? 14 : 0));
    if (L->ax1 - L->ax0 < 20.0f || L->ay1 - L->ay0 < 20.0f) return AK_ERR_BAD_ARG;
    return AK_OK;
}

static ak_vec2 map_pt(const plot_layout* L, double x, double y) {
    return ak_vec2_make((float)(L->ax0 + (x - L->xmin) / (L->xmax - L->xmin) * (L->ax1 - L->ax0)),
                        (float)(L->ay1 - (y - L->ymin) / (L->ymax - L->ymin) * (L->ay1 - L->ay0)));
}

bool ak_view_plot_map(const ak_view_plot* plot, int width, int height, float x, float y, ak_vec2* out_pixel) {
    plot_layout L;
    if (!out_pixel || plot_layout_make(plot, width, height, &L) != AK_OK) return false;
    *out_pixel = map_pt(&L, x, y);
    return true;
}

/* Clip segment a-b to the rectangle (Liang-Barsky); false when nothing is left. */
static bool clip_seg(const plot_layout* L, ak_vec2* a, ak_vec2* b) {
    float t0 = 0.0f, t1 = 1.0f, dx = b->x - a->x, dy = b->y - a->y;
    const float p[4] = {-dx, dx, -dy, dy};
    const float q[4] = {a->x - L->ax0, L->ax1 - a->x, a->y - L->ay0, L->ay1 - a->y};
    for (int i = 0; i < 4; ++i) {
        if (p[i] == 0.0f) {
            if (q[i] < 0.0f) return false;
            continue;
        }
        float t = q[i] / p[i];
        if (p[i] < 0.0f) t0 = t > t0 ? t : t0;
        else t1 = t < t1 ? t : t1;
    }
    if (t0 > t1) return false;
    ak_vec2 na = ak_vec2_make(a->x + t0 * dx, a->y + t0 * dy), nb = ak_vec2_make(a->x + t1 * dx, a->y + t1 * dy);
    *a = na;
    *b = nb;
    return true;
}

static void handle(const ak_image* img, const plot_layout* L, ak_vec2 k, float slope, float dir, float len,
                   ak_vec4 color) {
    if (!ak_finitef(slope)) return;
    double sx = (L->ax1 - L->ax0) / (L->xmax - L->xmin), sy = (L->ay1 - L->ay0) / (L->ymax - L->ymin);
    double hx = sx, hy = -slope * sy, hl = sqrt(hx * hx + hy * hy);
    if (!(hl > 0.0)) return;
    ak_vec2 e = ak_vec2_make(k.x + dir * len * (float)(hx / hl), k.y + dir * len * (float)(hy / hl));
    ak_vec2 a = k, b = e;
    if (!clip_seg(L, &a, &b)) return;
    ak_image_draw_line(img, a, b, 1.5f, color);
    if (b.x == e.x && b.y == e.y) ak_image_draw_disc(img, e, 2.5f, rgba(1, 1, 1, 1), 1.2f, color);
}

/* Title centred at the top: font scale 2, else 1 when that does not fit, else cut in the
 * middle ("LeftHandIndex...Rotation") so both ends stay readable. */
static void draw_title(const ak_image* out, const char* title, ak_vec4 ink) {
    int room = out->width - 16, tw, th;
    ak_text_size(title, 2, &tw, &th);
    if (tw <= room) {
        ak_image_draw_text(out, (out->width - tw) / 2, 8, title, 2, ink);
        return;
    }
    ak_text_size(title, 1, &tw, &th);
    char buf[256];
    size_t len = strlen(title);
    int max_chars = room / AK_FONT_ADVANCE_X;
    if (tw > room && max_chars >= 5 && len < sizeof buf) {
        size_t keep = (size_t)max_chars - 3, head = (keep + 1) / 2, tail = keep - head;
        memcpy(buf, title, head);
        memcpy(buf + head, "...", 3);
        memcpy(buf + head + 3, title + len - tail, tail + 1);
        title = buf;
        ak_text_size(title, 1, &tw, &th);
    }
    ak_image_draw_text(out, (out->width - tw) / 2, 12, title, 1, ink);
}

ak_result ak_view_plot_draw(const ak_view_plot* p, const ak_image* out) {
    if (!out || !out->pixels) return AK_ERR_NULL_ARG;
    plot_layout L;
    ak_result r = plot_layout_make(p, out->width, out->height, &L);
    if (r != AK_OK) return r;
    const ak_vec4 ink = rgba(0.15f, 0.16f, 0.2f, 1), grid = rgba(0.86f, 0.87f, 0.89f, 1);
    ak_image_fill(out, or_default(p->background, rgba(0.98f, 0.98f, 0.97f, 1)));
    ak_image_fill_rect(out, L.ax0, L.ay0, L.ax1 - L.ax0, L.ay1 - L.ay0, rgba(1, 1, 1, 1));
    char buf[64];
    /* grid and ticks */
    int guard = 0;
    for (double v = ceil(L.ymin / L.ystep) * L.ystep; v <= L.ymax + L.ystep * 1e-6 && guard < 64; v += L.ystep, ++guard) {
        float y = map_pt(&L, L.xmin, v).y;
        ak_image_draw_line(out, ak_vec2_make(L.ax0, y), ak_vec2_make(L.ax1, y), 1.0f, grid);
        format_tick(buf, sizeof buf, v, L.ystep, L.ydec);
        int tw, th;
        ak_text_size(buf, 1, &tw, &th);
        ak_image_draw_text(out, (int)L.ax0 - 6 - tw, (int)(y - 3.5f), buf, 1, ink);
    }
    guard = 0;
    for (double v = ceil(L.xmin / L.xstep) * L.xstep; v <= L.xmax + L.xstep * 1e-6 && guard < 64; v += L.xstep, ++guard) {
        float x = map_pt(&L, v, L.ymin).x;
        ak_image_draw_line(out, ak_vec2_make(x, L.ay0), ak_vec2_make(x, L.ay1), 1.0f, grid);
        ak_image_draw_line(out, ak_vec2_make(x, L.ay1), ak_vec2_make(x, L.ay1 + 4.0f), 1.0f, ink);
        format_tick(buf, sizeof buf, v, L.xstep, L.xdec);
        int tw, th;
        ak_text_size(buf, 1, &tw, &th);
        ak_image_draw_text(out, (int)(x - 0.5f * (float)tw), (int)L.ay1 + 7, buf, 1, ink);
    }
    if (L.ymin < 0.0 && L.ymax > 0.0) {
        float y0 = map_pt(&L, L.xmin, 0.0).y;
        ak_image_draw_line(out, ak_vec2_make(L.ax0, y0), ak_vec2_make(L.ax1, y0), 1.0f, rgba(0.6f, 0.62f, 0.66f, 1));
    }
    ak_image_draw_line(out, ak_vec2_make(L.ax0, L.ay0), ak_vec2_make(L.ax0, L.ay1), 1.5f, ink);
    ak_image_draw_line(out, ak_vec2_make(L.ax0, L.ay1), ak_vec2_make(L.ax1, L.ay1), 1.5f, ink);
    /* labels */
    if (p->title) draw_title(out, p->title, ink);
    if (p->x_label) {
        int tw, th;
        ak_text_size(p->x_label, 1, &tw, &th);
        ak_image_draw_text(out, (int)(0.5f * (L.ax0 + L.ax1)) - tw / 2, out->height - 12, p->x_label, 1, ink);
    }
    if (p->y_label) ak_image_draw_text(out, (int)L.ax0 - 4, (int)L.ay0 - 12, p->y_label, 1, ink);
    /* series */
    const float hlen = p->handle_length > 0.0f && ak_finitef(p->handle_length) ? p->handle_length : 28.0f;
    for (size_t i = 0; i < p->series_count; ++i) {
        const ak_view_series* s = &p->series[i];
        ak_vec4 c = or_default(s->color, ak_view_palette_color(i));
        float w = s->width > 0.0f && ak_finitef(s->width) ? s->width : 2.0f;
        for (size_t k = 0; k + 1 < s->x.count; ++k) {
            float x0 = s->x.ptr[k], y0 = s->y.ptr[k], x1 = s->x.ptr[k + 1], y1 = s->y.ptr[k + 1];
            if (!ak_finitef(x0) || !ak_finitef(y0) || !ak_finitef(x1) || !ak_finitef(y1)) continue;
            ak_vec2 a = map_pt(&L, x0, y0), b = map_pt(&L, x1, y1);
            if (clip_seg(&L, &a, &b)) ak_image_draw_line(out, a, b, w, c);
        }
        ak_vec4 hc = rgba(c.x * 0.6f, c.y * 0.6f, c.z * 0.6f, 1);
        /* markers only when the keys in view are on average MIN_KEY_GAP pixels apart or more:
         * denser keys (motion capture) would merge into a band over their own line */
        size_t in_view = 0;
        for (size_t k = 0; k < s->key_x.count; ++k)
            in_view += ak_finitef(s->key_x.ptr[k]) && s->key_x.ptr[k] >= L.xmin && s->key_x.ptr[k] <= L.xmax;
        bool markers = in_view <= 1 || (double)(L.ax1 - L.ax0) / (double)(in_view - 1) >= MIN_KEY_GAP;
        for (size_t k = 0; markers && k < s->key_x.count; ++k) {
            float kx = s->key_x.ptr[k], ky = s->key_y.ptr[k];
            if (!ak_finitef(kx) || !ak_finitef(ky)) continue;
            ak_vec2 kp = map_pt(&L, kx, ky);
            if (kp.x < L.ax0 - 0.5f || kp.x > L.ax1 + 0.5f || kp.y < L.ay0 - 0.5f || kp.y > L.ay1 + 0.5f) continue;
            if (s->key_in_slope.count) handle(out, &L, kp, s->key_in_slope.ptr[k], -1.0f, hlen, hc);
            if (s->key_out_slope.count) handle(out, &L, kp, s->key_out_slope.ptr[k], 1.0f, hlen, hc);
            ak_image_draw_disc(out, kp, 4.0f, c, 1.5f, rgba(0.1f, 0.1f, 0.12f, 1));
        }
    }
    /* legend: one row in the top margin, right-aligned */
    if (!p->no_legend) {
        float x = L.ax1;
        for (size_t i = p->series_count; i-- > 0;) {
            if (!p->series[i].label) continue;
            int tw, th;
            ak_text_size(p->series[i].label, 1, &tw, &th);
            x -= (float)tw + 26.0f;
            ak_vec4 c = or_default(p->series[i].color, ak_view_palette_color(i));
            float y = L.ay0 - 8.0f;
            ak_image_draw_line(out, ak_vec2_make(x, y), ak_vec2_make(x + 14, y), 3.0f, c);
            ak_image_draw_text(out, (int)(x + 18), (int)(y - 3.5f), p->series[i].label, 1, ink);
            x -= 8.0f;
        }
    }
    return AK_OK;
}

/* ---- animation -------------------------------------------------------------------------------- */

ak_result ak_view_frames_write_gif(const char* path, const ak_image* frames, size_t frame_count, int delay_cs) {
    if (!path || (frame_count && !frames)) return AK_ERR_NULL_ARG;
    if (frame_count == 0) return AK_ERR_EMPTY;
    for (size_t i = 0; i < frame_count; ++i) {
        if (!frames[i].pixels) return AK_ERR_NULL_ARG;
        if (frames[i].width != frames[0].width || frames[i].height != frames[0].height) return AK_ERR_BAD_ARG;
    }
    ak_gif_writer* w = NULL;
    ak_gif_desc d = {.width = frames[0].width, .height = frames[0].height, .delay_cs = delay_cs > 0 ? delay_cs : 4};
    ak_result r = ak_gif_writer_create(path, &d, NULL, &w);
    if (r != AK_OK) return r;
    for (size_t i = 0; i < frame_count && r == AK_OK; ++i) r = ak_gif_writer_add_frame(w, &frames[i]);
    ak_result f = ak_gif_writer_finish(w);
    return r != AK_OK ? r : f;
}

/* animkit view: ready-made pictures on top of raster.h, so a tool draws each view in a few calls.
 *
 * What it does: an orbit camera that frames a bounding box; a one-call scene render (background
 * gradient, ground grid with a soft shadow, meshes, skeleton overlay, title); skeleton
 * overlays from model-space joint matrices and parent indices; a blue-to-red heatmap for
 * per-vertex scalars (skin weights of one bone); side-by-side panels with labels; 2D line
 * charts with axes, ticks, labels, legend, key markers and tangent handles (curve editor and
 * easing views); and writing a frame sequence as an animated GIF.
 *
 * What it does NOT do: animate, skin or sample anything (the caller poses and deforms, then
 * passes arrays in), read files, or keep state between calls.
 *
 * Usage:
 *     ak_raster_mesh body = ak_view_raster_mesh(mesh);      // spans over an ak_mesh
 *     body.positions = (ak_vec3_cspan){skinned, mesh->vertex_count};
 *     ak_view_skeleton sk = { .joint_model = {model, n}, .parents = parents };
 *     ak_view_scene scene = { .meshes = &body, .mesh_count = 1, .skeleton = &sk, .title = "walk" };
 *     ak_vec3 lo, hi;
 *     ak_view_scene_bounds(&scene, &lo, &hi);
 *     ak_raster_camera cam = ak_view_orbit_camera(lo, hi, &(ak_view_orbit){
 *         .azimuth = 0.6f, .elevation = 0.25f, .aspect = 640.0f / 480.0f });
 *     ak_view_render(r, &cam, &scene, &image);             // r: an ak_raster of 640x480
 *     ak_png_write("walk.png", &image);
 *
 *     ak_view_series s = { .x = {t, n}, .y = {v, n}, .label = "hip.y" };
 *     ak_view_plot_draw(&(ak_view_plot){ .series = &s, .series_count = 1, .title = "hip" }, &image);
 *
 * Ownership and threading: every function works on caller-owned arrays and images and keeps
 * no pointer after it returns. Functions drawing into one ak_raster or ak_image must not run
 * concurrently on that target; anything else is reentrant.
 */
#ifndef ANIMKIT_VIEW_H
#define ANIMKIT_VIEW_H

#include "mesh.h"
#include "raster.h"

#ifdef __cplusplus
extern "C" {
#endif

/* ---- framing ---------------------------------------------------------------------------- */

typedef struct ak_view_orbit {
    float azimuth;     /* radians about +Y; 0 -> camera on the +Z side looking towards -Z */
    float elevation;   /* radians above the horizon, clamped to +-1.45; 0 is a level view */
    float fovy;        /* vertical field of view, radians; 0 -> 40 degrees */
    float margin;      /* framing slack; 0 -> 1.1 (values below 1 may crop the box) */
    float aspect;      /* image width / height; 0 -> 1 */
    bool orthographic; /* false -> perspective */
} ak_view_orbit;

/* Camera looking at the box centre from the given angles, just far enough that all eight
 * corners fit in the view with the margin (the box touches the image edge when margin = 1).
 * orbit NULL -> all defaults.
 * Non-finite or inverted bounds fall back to the unit cube around the origin. */
AK_API ak_raster_camera ak_view_orbit_camera(ak_vec3 bbox_min, ak_vec3 bbox_max, const ak_view_orbit* orbit);

/* ---- colours ----------------------------------------------------------------------------- */

/* Heatmap colour (sRGB, opaque) for t in [0, 1]: blue -> cyan -> green -> yellow -> red.
 * t is clamped; NaN gives the t = 0 colour. */
AK_API ak_vec4 ak_view_heatmap_color(float t);
/* Heatmap colours for values mapped linearly from [lo, hi] to [0, 1]; lo == hi maps every value
 * to 0.5. out_colors.count >= values.count. AK_ERR_NULL_ARG, AK_ERR_SPAN_SMALL, AK_ERR_BAD_ARG
 * (lo or hi not finite). */
AK_API ak_result ak_view_heatmap_colors(ak_f32_cspan values, float lo, float hi, ak_vec4_span out_colors);
/* Per-vertex weight of one joint from a skinned mesh's joints/weights arrays (0 where the
 * vertex has no influence from it). out_weights.count >= mesh->vertex_count. AK_ERR_NULL_ARG,
 * AK_ERR_SPAN_SMALL. An unskinned mesh gives all zeros. */
AK_API ak_result ak_view_joint_weights(const ak_mesh* mesh, uint32_t joint_index, ak_f32_span out_weights);
/* Distinct colour number index of a small qualitative palette (plots, several meshes). */
AK_API ak_vec4 ak_view_palette_color(size_t index);
#define AK_VIEW_DISTINCT_COLOR_COUNT 222
/* Colours for many categories (a legend of bones): out_colors.count sRGB colours, each as far
 * as possible from all the ones before it in OKLab (a perceptually uniform space): greedy
 * farthest-point picks among AK_VIEW_DISTINCT_COLOR_COUNT candidates of medium lightness
 * (L 0.50..0.82) and clear chroma (0.09..0.19) inside the sRGB gamut, starting from a blue. So
 * consecutive entries differ most, the first k colours are the same for any count >= k, none
 * is grey, and entries repeat (cyclically) only beyond AK_VIEW_DISTINCT_COLOR_COUNT. The closest
 * pair of the first 24 colours is 18.8 CIE76 units apart (13.3 for 32, 9.3 for 64; about 2.3 is
 * just noticeable). AK_ERR_NULL_ARG when count > 0 and ptr is NULL. */
AK_API ak_result ak_view_distinct_colors(ak_vec4_span out_colors);

/* ---- scenes ------------------------------------------------------------------------------ */

/* An ak_raster_mesh over an ak_mesh's own positions, normals and indices (no colours,
 * default material). NULL -> a zeroed struct (which draw calls reject with AK_ERR_NULL_ARG). */
AK_API ak_raster_mesh ak_view_raster_mesh(const ak_mesh* mesh);

typedef struct ak_view_skeleton {
    ak_mat4_cspan joint_model; /* required; model-space joint matrices (translation = position) */
    ak_i32_cspan parents;      /* required; parent per joint, -1 for roots; count == joint_model.count */
    const ak_mat4* model;      /* model -> world; NULL -> identity */
    ak_vec4 bone_color;        /* sRGB; zero -> near white (0.97, 0.97, 1.0), with a dark halo */
    ak_vec4 joint_color;       /* sRGB; zero -> (1.0, 0.78, 0.18, 1) */
    float bone_width;          /* output pixels; 0 -> 2.5 */
    float joint_radius;        /* output pixels; 0 -> 3.5 */
    bool depth_tested;         /* false -> drawn over the meshes (the usual overlay) */
} ak_view_skeleton;

/* Draw bones (joint to parent) as lines and joints as points. AK_ERR_NULL_ARG, AK_ERR_BAD_ARG
 * (parents.count != joint_model.count), AK_ERR_BAD_INDEX (a parent >= the joint count).
 * Joints with non-finite matrices are skipped. */
AK_API ak_result ak_view_draw_skeleton(ak_raster* raster, const ak_raster_camera* camera,
                                       const ak_view_skeleton* skeleton);

typedef struct ak_view_scene {
    const ak_raster_mesh* meshes;     /* NULL with mesh_count 0 -> no meshes */
    size_t mesh_count;
    const ak_view_skeleton* skeleton; /* NULL -> no overlay */
    const char* title;                /* drawn top-left; NULL -> none */
    ak_vec4 background_top;           /* sRGB; zero -> (0.82, 0.86, 0.92) */
    ak_vec4 background_bottom;        /* sRGB; zero -> (0.50, 0.53, 0.60) */
    bool no_ground;                   /* false -> grid at the scene's lowest point, with shadow */
} ak_view_scene;

/* World-space bounds of the scene's meshes (through their model matrices) and skeleton
 * joints, skipping non-finite points. An empty scene gives min = max = 0. */
AK_API void ak_view_scene_bounds(const ak_view_scene* scene, ak_vec3* out_min, ak_vec3* out_max);

/* Clear, draw ground, meshes, skeleton and title, and resolve into out (out's size must
 * equal the raster's). Returns the first failing code of the raster calls, AK_ERR_NULL_ARG. */
AK_API ak_result ak_view_render(ak_raster* raster, const ak_raster_camera* camera, const ak_view_scene* scene,
                                const ak_image* out);

/* ---- panels --------------------------------------------------------------------------------- */

typedef struct ak_view_panel {
    const ak_image* image; /* required; every panel has the same size */
    const char* label;     /* centred above the panel; NULL -> no label (the strip stays) */
} ak_view_panel;

typedef struct ak_view_panels_desc {
    int columns;          /* panels per row; 0 -> all in one row */
    int gap;              /* pixels between and around panels; 0 -> 6 */
    int label_scale;      /* font scale of labels; 0 -> 2 */
    const char* title;    /* drawn in a strip across the top at label_scale + 1 (smaller
                             when too wide for the image); NULL -> no strip */
    ak_vec4 background;   /* sRGB; zero -> (0.14, 0.15, 0.18) */
    ak_vec4 text_color;   /* sRGB; zero -> (0.95, 0.95, 0.95) */
} ak_view_panels_desc;

/* Size of the composed image for panel_count panels of panel_width x panel_height
 * (desc NULL -> defaults). Zero count or size gives 0 x 0. */
AK_API void ak_view_panels_size(const ak_view_panels_desc* desc, size_t panel_count, int panel_width,
                                int panel_height, int* out_width, int* out_height);
/* Compose panels row by row with labels into out, whose size must equal ak_view_panels_size.
 * AK_ERR_NULL_ARG, AK_ERR_EMPTY (no panels), AK_ERR_BAD_ARG (panel sizes differ, out size wrong). */
AK_API ak_result ak_view_panels_compose(const ak_view_panels_desc* desc, const ak_view_panel* panels,
                                        size_t panel_count, const ak_image* out);

/* ---- plots ---------------------------------------------------------------------------------- */

typedef struct ak_view_series {
    ak_f32_cspan x;             /* sample positions (time), any order is drawn as given */
    ak_f32_cspan y;             /* values; count == x.count (may be 0 for keys-only series) */
    ak_vec4 color;              /* sRGB; zero -> ak_view_palette_color(series index) */
    const char* label;          /* legend entry; NULL -> not listed */
    float width;                /* line width in pixels; 0 -> 2 */
    ak_f32_cspan key_x;         /* key markers; empty -> none. Markers and handles are drawn only
                                   when the keys in view are on average 8 pixels apart or more
                                   (denser keys, e.g. motion capture, are their line already) */
    ak_f32_cspan key_y;         /* count == key_x.count */
    ak_f32_cspan key_in_slope;  /* incoming tangent dy/dx per key; empty -> no handles */
    ak_f32_cspan key_out_slope; /* outgoing tangent dy/dx per key; empty -> no handles */
} ak_view_series;

typedef struct ak_view_plot {
    const ak_view_series* series; /* required */
    size_t series_count;          /* required, > 0 */
    const char* title;            /* NULL -> none; font scale 2, or 1 when too wide, then cut in
                                     the middle with "..." so both ends show */
    const char* x_label;          /* NULL -> none */
    const char* y_label;          /* NULL -> none */
    float x_min, x_max;           /* equal (e.g. both 0) -> fitted to the data */
    float y_min, y_max;           /* equal -> fitted to the data with a margin, spanning at least
                                     1% of the largest |y| (float noise on a constant stays flat) */
    float handle_length;          /* tangent handle length in pixels; 0 -> 28 */
    ak_vec4 background;           /* sRGB; zero -> (0.98, 0.98, 0.97) */
    bool no_legend;               /* false -> legend row above the plot area when labels exist */
} ak_view_plot;

/* Data-to-pixel mapping of a plot drawn into a width x height image: writes the pixel of the
 * data point (x, y) (centre coordinates, may be outside the plot area). Returns false when the
 * plot is invalid (see ak_view_plot_draw) or the image is too small for the axes. */
AK_API bool ak_view_plot_map(const ak_view_plot* plot, int width, int height, float x, float y,
                             ak_vec2* out_pixel);
/* Draw the chart into out (whole image). AK_ERR_NULL_ARG, AK_ERR_EMPTY (no series or no
 * points at all), AK_ERR_BAD_ARG (count mismatches, image smaller than 120 x 80, non-finite
 * or inverted range, data beyond +-1e30). Non-finite samples break the line (a gap), non-finite keys are skipped. */
AK_API ak_result ak_view_plot_draw(const ak_view_plot* plot, const ak_image* out);

/* ---- animation -------------------------------------------------------------------------------- */

/* Write frames (all the same size) as a looping animated GIF with delay_cs hundredths of a
 * second between frames (0 -> 4). AK_ERR_NULL_ARG, AK_ERR_EMPTY, AK_ERR_BAD_ARG (sizes
 * differ), AK_ERR_IO, AK_ERR_NO_MEMORY. */
AK_API ak_result ak_view_frames_write_gif(const char* path, const ak_image* frames, size_t frame_count,
                                          int delay_cs);

#ifdef __cplusplus
}
#endif
#endif /* ANIMKIT_VIEW_H */

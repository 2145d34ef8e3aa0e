/* Rendering glue shared by render, demo, weights and ik. */
#ifndef ANIMKIT_CLI_RENDER_H
#define ANIMKIT_CLI_RENDER_H

#include <animkit/view.h>

#include "cli.h"

/* A camera, ground and skeleton overlay fixed for a whole animation. */
typedef struct cli_frame {
    int width, height;
    ak_raster* raster;
    ak_raster_camera camera;
    ak_vec3 bmin, bmax;
    int* joint_list;      /* skeleton joints drawn in the overlay */
    int32_t* joint_parent;
    ak_mat4* joint_model;
    size_t joint_count;
    ak_raster_mesh* draw;  /* draw list: every scene mesh plus CLI_MAX_EXTRA extras */
    ak_raster_texture* tex; /* [draw_capacity] the base colour texture of draw[i] */
    size_t draw_capacity;
} cli_frame;

/* Extra meshes (props) one frame may draw besides the scene's. */
#define CLI_MAX_EXTRA 8

typedef struct cli_draw_opts {
    bool skeleton;         /* overlay the skeleton */
    ak_vec4** colors;      /* per scene mesh: per-vertex colours or NULL */
    const char* title;
    ak_vec4 tint;          /* material colour; w = 0 -> clay */
    const ak_raster_mesh* extra; /* more meshes (props, the demo's tail and ball) */
    size_t extra_count;
    const bool* hidden;    /* per scene mesh: true -> not drawn; NULL -> every mesh drawn */
    /* drawn after the meshes and the skeleton, before the title and the resolve (the viewer's
     * simulations draw their particles and agents here); NULL -> nothing */
    ak_result (*draw)(void* user, ak_raster* raster, const ak_raster_camera* camera, int width, int height);
    void* draw_user;
    ak_vec4 sky_top, sky_bottom; /* background gradient; both all zero -> the light default sky */
} cli_draw_opts;

/* Where the camera looks from. Zero -> the orbit framing cli_frame_init uses (yaw 31.5, pitch
 * 12.6 degrees, far enough to frame the bounds, 40 degree field of view) except for yaw and
 * pitch, which are taken as given when has_angles is true. */
typedef struct cli_camera {
    bool has_angles;
    float yaw;      /* degrees about +Y; 0 -> on the +Z side looking towards -Z, 90 -> on +X */
    float pitch;    /* degrees above the horizon, clamped to [-85, 85] */
    float distance; /* from the framed box's centre, scene units; 0 -> just far enough to frame it */
    float fov;      /* vertical field of view, degrees in (0, 170); 0 -> 40 */
} cli_camera;

/* Grow [lo, hi] by the posed meshes (or the joints when there is no mesh). */
void cli_bounds_add_pose(const cli_poser* p, ak_vec3* lo, ak_vec3* hi);
/* The same over the meshes not hidden (hidden: per scene mesh, NULL -> none hidden); the
 * joints when no visible mesh has vertices. */
void cli_bounds_add_visible(const cli_poser* p, const bool* hidden, ak_vec3* lo, ak_vec3* hi);
int cli_frame_init(cli_frame* f, const ak_scene* s, int width, int height, ak_vec3 lo, ak_vec3 hi, float azimuth);
/* cli_frame_init with a camera (cam NULL -> as cli_frame_init with azimuth 0.55 rad). */
int cli_frame_init_camera(cli_frame* f, const ak_scene* s, int width, int height, ak_vec3 lo, ak_vec3 hi,
                          const cli_camera* cam);
/* Aim f's camera at the box [lo, hi] (the ground stays where cli_frame_init put it): render
 * --follow calls it per frame with a box that moves with the root. */
void cli_frame_aim(cli_frame* f, ak_vec3 lo, ak_vec3 hi, const cli_camera* cam);
void cli_frame_free(cli_frame* f);
/* Draw the posed scene (p may be NULL: extras only) into out. */
ak_result cli_frame_draw(cli_frame* f, const cli_poser* p, const cli_draw_opts* o, const ak_image* out);
int cli_image_alloc(ak_image* img, int w, int h);
/* Heat colours of bone's weights for every mesh its skin reaches (colors[m] NULL elsewhere;
 * colors has scene->mesh_count entries; the caller frees them). *out_found says whether any
 * mesh has the bone. */
int cli_weights_colors(const ak_scene* s, const char* bone, ak_vec4** colors, int* out_found);

int cli_render_weights_png(const char* path, const ak_scene* s, size_t mesh_index, const uint16_t* joints,
                           const float* weights, uint32_t k, int slot, const char* bone_name);
/* Every bone's region: each vertex in the colour of the bone that weighs it most, with a legend
 * naming each bone that dominates some vertex (slot_names[slot_count]); the legend's bones take
 * the colours of ak_view_distinct_colors in order (distinct for up to 222 bones, the most
 * distinct first), undominated vertices are grey. */
int cli_render_bones_png(const char* path, const ak_scene* s, size_t mesh_index, const uint16_t* joints,
                         const float* weights, uint32_t k, size_t slot_count, const char* const* slot_names);
int cli_render_ik_png(const char* path, cli_poser* p, const int16_t* chain, size_t n, ak_vec3 target);

#endif

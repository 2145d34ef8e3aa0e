/* animkit command line: the flock shared by `animkit boids` and `animkit view`: placing the
 * agents from a scene, stepping them, and their shapes (birds or fish with a wing beat, and
 * the obstacles) as triangle meshes. */
#ifndef ANIMKIT_CLI_BOIDS_RUN_H
#define ANIMKIT_CLI_BOIDS_RUN_H

#include "cli.h"
#include <animkit/boids.h>

/* The library's run of a scene (ak_boids_scene_run, animkit/boids.h). */
typedef ak_boids_scene_run boids_run;

/* Place the scene's agents ("agents", or count at random in the bounds from the seed) and
 * validate the step job (naive: the O(N^2) neighbour search instead of the grid; the same
 * results, bit for bit). Returns an exit code with the message printed as `animkit CMD:`
 * naming file; free with boids_run_free in every case. */
int boids_run_init(boids_run* r, const ak_boids_scene* sc, const char* cmd, const char* file, uint32_t threads,
                   bool naive);
/* Step number `step` (0-based; the wander noise depends on it). */
ak_result boids_run_step(boids_run* r, long step);
/* What a failed step's result means for a user (AK_ERR_BUDGET says what to lower). */
const char* boids_run_error(ak_result res);
void boids_run_free(boids_run* r);

/* Triangles of the agents (5 vertices, 4 triangles each) and obstacles. */
typedef struct boids_shapes {
    ak_vec3* pos;
    ak_vec4* col;
    uint32_t* idx;
    ak_vec3* opos;
    uint32_t* oidx;
    size_t overt, otri;
    ak_clip* beat; /* the wing-beat (or tail-sway) clip: one scalar channel, looped */
} boids_shapes;

/* A plane facing up (drawn as the ground, not as a slab). */
bool boids_is_floor(const ak_boids_obstacle* o);
/* Allocate for n agents and build the obstacles (planes as slabs plane_size across); false
 * when out of memory (free it anyway). */
bool boids_shapes_init(boids_shapes* r, const ak_boids_scene* sc, size_t n, float plane_size);
/* Rebuild the obstacle triangles (after an obstacle moved); false when out of memory. */
bool boids_shapes_obstacles(boids_shapes* r, const ak_boids_params* prm, float plane_size);
/* Pose every agent at `time` (each at its own beat phase) and give the two meshes. */
void boids_shapes_update(boids_shapes* r, const ak_boids_scene* sc, const boids_run* st, float time, ak_raster_mesh* out_birds,
                         ak_raster_mesh* out_obstacles);
void boids_shapes_free(boids_shapes* r);

#endif

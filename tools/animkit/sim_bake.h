/* Recording a simulation's frames for `-o OUT.glb|OUT.gltf` (animkit cloth, animkit particles):
 * the frames go to scene.h's ak_scene_bake_mesh_frames / ak_scene_bake_point_frames and the
 * scene to io.h's ak_io_save. Every step is a frame unless that would exceed
 * AK_SCENE_BAKE_MAX_FRAMES frames or SIM_BAKE_BUDGET bytes of recorded data: then every k-th
 * step (the smallest k that fits), frame time k * dt, the clip ending at the last recorded step. */
#ifndef ANIMKIT_TOOLS_SIM_BAKE_H
#define ANIMKIT_TOOLS_SIM_BAKE_H

#include "animkit/animkit.h"

/* Most bytes of recorded frames (positions, normals, ids) a run keeps for the glTF output. */
#define SIM_BAKE_BUDGET ((size_t)256 << 20)
/* Radius of the octahedron each particle node carries in the glTF output. */
#define SIM_BAKE_MARKER_SIZE 0.025f

typedef struct sim_bake {
    const char* cmd;   /* for messages */
    const char* out;   /* the output path */
    long every;        /* record steps that are multiples of every */
    size_t n;          /* mesh: vertices per frame */
    size_t frames, cap;
    ak_vec3 *pos, *nrm;            /* mesh frames, frame-major */
    ak_scene_bake_points* pts;     /* particle frames (each owns its arrays) */
    size_t entries;                /* particle positions recorded */
} sim_bake;

/* True when path ends in .glb or .gltf (any case). */
bool sim_bake_wanted(const char* path);
/* Prepare recording of a mesh of n vertices over steps steps; CLI_OK or a cli_fail code. */
int sim_bake_mesh_init(sim_bake* b, const char* cmd, const char* out, size_t n, long steps);
/* Record the state after `step` steps when it is a frame step. */
int sim_bake_mesh_add(sim_bake* b, long step, const ak_vec3* x, const ak_vec3* nrm);
/* Bake and write; dt is the step. */
int sim_bake_mesh_write(sim_bake* b, const char* name, float dt, ak_u32_cspan indices, ak_vec4 colour);
/* Same for particles (ids unique per particle). */
int sim_bake_points_init(sim_bake* b, const char* cmd, const char* out, long steps);
int sim_bake_points_add(sim_bake* b, long step, const ak_vec3* p, const uint32_t* ids, size_t count);
int sim_bake_points_write(sim_bake* b, const char* name, float dt);
void sim_bake_free(sim_bake* b);

#endif

/* animkit fluid: scene files and presets (see docs/fluid.md for every key and its default). */
#ifndef ANIMKIT_CLI_SCENE_FLUID_H
#define ANIMKIT_CLI_SCENE_FLUID_H

#include <stdbool.h>
#include <stddef.h>

#include <animkit/fluid.h>

#include "cli_json.h"

/* Limits that bound a hostile scene's memory. */
#define FLUID_SCENE_MAX_PARTICLES 2000000u
#define FLUID_SCENE_MAX_ITEMS 256u
#define FLUID_SCENE_MAX_STEPS 10000000L

/* An initial block of liquid: the rest lattice filling [min, max]. */
typedef struct fluid_block {
    ak_vec3 min, max, velocity;
} fluid_block;

typedef struct fluid_scene {
    ak_fluid_desc desc;    /* h = h_ratio * rest spacing */
    float h_ratio;         /* default 2 */
    float dt;              /* default 1/400 (PBF), 1e-3 (SPH) or 2e-4 (WCSPH) */
    float duration;        /* simulated seconds when steps is not given; default 1 */
    long steps;            /* default (-1): ceil(duration / dt), see fluid_scene_steps */
    long max_particles;    /* capacity; default: initial particles + 20000 when emitters exist */
    size_t block_count, collider_count, emitter_count, sink_count;
    fluid_block blocks[FLUID_SCENE_MAX_ITEMS];
    ak_fluid_collider colliders[FLUID_SCENE_MAX_ITEMS];
    ak_fluid_emitter emitters[FLUID_SCENE_MAX_ITEMS];
    ak_fluid_sink sinks[FLUID_SCENE_MAX_ITEMS];
    bool dt_set;           /* "dt" was given */
} fluid_scene;

/* The defaults (PBF, 1 cm particles of water, gravity -9.81 Y, no box, nothing else). */
void fluid_scene_defaults(fluid_scene* s);
/* Parse a scene from text[0, size); file names the source in messages. Returns true, or false
 * with j->message "FILE: KEY.PATH: problem". Counts and sizes are checked against the limits
 * above (the initial particle count included) before anything is allocated. */
bool fluid_scene_parse(cli_json* j, const char* text, size_t size, fluid_scene* out);
/* Build a preset ("dam", "pour", "splash") of about count particles (0 -> 4000). False for an
 * unknown name. */
bool fluid_scene_preset(const char* name, long count, fluid_scene* out);
/* The default step of a solver: 1/400 s (PBF), 1e-3 s (SPH), 2e-4 s (WCSPH). */
float fluid_scene_default_dt(ak_fluid_solver solver);
/* The steps to run: s->steps when given, else ceil(duration / dt) (at least 1). */
long fluid_scene_steps(const fluid_scene* s);
/* Particles the blocks hold (lattice count) and the capacity to allocate. */
size_t fluid_scene_initial_count(const fluid_scene* s);
size_t fluid_scene_capacity(const fluid_scene* s);
/* Fill positions/velocities with the blocks' particles (cap entries at most); returns the count. */
size_t fluid_scene_fill(const fluid_scene* s, ak_vec3* positions, ak_vec3* velocities, size_t cap);

#endif

/* animkit command line: particle scene files (docs/particles.md describes every key). */
#ifndef ANIMKIT_SCENE_PARTICLES_H
#define ANIMKIT_SCENE_PARTICLES_H

#include <stdbool.h>
#include <stddef.h>

#include <animkit/particles.h>
#include <animkit/raster.h>

/* Bursts the CLI fires from an emitter: count particles at time start, then every interval. */
typedef struct particles_burst {
    uint32_t count;
    float start;    /* seconds */
    float interval; /* seconds; 0 = once */
} particles_burst;

/* How the particles are drawn: round points (the default) or camera-facing sprites with a
 * texture, a sprite sheet, blending and colour/size over life ("render" in a scene file). */
typedef struct particles_sprites {
    bool enabled;              /* false -> points */
    ak_sprite_texture texture; /* built-in texture when sheet_path is NULL: DISC or PUFF */
    char* sheet_path;          /* a PNG sprite sheet (owned), or NULL */
    int sheet_columns;         /* frames across; 0 -> 1 (built-in PUFF with frames: that many puffs) */
    int sheet_rows;            /* frames down; 0 -> 1 */
    ak_blend blend;            /* AK_BLEND_ALPHA (sorted back to front), AK_BLEND_ADD, or
                                  AK_BLEND_OPAQUE (alpha-tested cut-outs: leaves, grass) */
    ak_particle_look look;     /* colour, size and frame over life */
} particles_sprites;

/* A parsed scene: the world and everything to add, owning its arrays (particles_scene_free). */
typedef struct particles_scene {
    float dt;                           /* default 0.01 */
    ak_particles_integrator integrator; /* default SYMPLECTIC */
    uint32_t capacity;                  /* default: particles + 100000 when there are emitters */
    ak_particles_world world;
    ak_particle_init* particles;
    size_t particle_count;
    ak_particle_spring* springs;
    ak_particle_plane* planes;
    ak_particle_sphere* spheres;
    ak_particle_box* boxes;
    ak_particle_attractor* attractors;
    ak_particle_vortex* vortices;
    ak_particle_emitter* emitters;
    particles_burst* bursts; /* [emitter_count] */
    size_t emitter_count;
    particles_sprites sprites;
} particles_scene;

/* Limits a scene file may ask for (memory budget before allocating). */
#define PARTICLES_SCENE_MAX_ITEMS 1000000u
#define PARTICLES_SCENE_MAX_CAPACITY 2000000u /* about 0.5 GB of system state */

/* Parse text[0, size) from file (the name used in messages). Emitter shapes "mesh" are not
 * allowed in files. Returns true and fills *out, or false with one line "FILE: PATH: problem"
 * in err (err_size bytes) and *out empty. */
bool particles_scene_parse(const char* file, const char* text, size_t size, particles_scene* out,
                           char* err, size_t err_size);
/* Free the arrays (safe on an empty or failed scene). */
void particles_scene_free(particles_scene* s);

#endif

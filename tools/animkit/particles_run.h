/* animkit command line: a particle run shared by `animkit particles` and `animkit view`
 * (presets, the character preset's posed humanoid, stepping with emitters and bursts, the
 * collider shapes as triangles, and drawing the particles as points). */
#ifndef ANIMKIT_CLI_PARTICLES_RUN_H
#define ANIMKIT_CLI_PARTICLES_RUN_H

#include "cli.h"
#include <animkit/particles.h>

/* Whether name is a preset of ak_particles_scene_preset (AK_PARTICLES_SCENE_PRESETS). */
bool particles_preset_known(const char* name);

/* The character preset: builtin:humanoid walking (clip 0), its posed meshes concatenated as
 * one collider and one emitter surface. */
typedef struct particles_character {
    ak_scene* scene;
    cli_poser poser;
    bool posed;
    ak_vec3* positions; /* all meshes concatenated */
    uint32_t* indices;
    size_t vertex_count, index_count;
    ak_particle_mesh* collider;
    float* cdf;
} particles_character;

/* Load and pose the humanoid at time 0; returns (and stores in *rc) an exit code. */
int particles_character_init(particles_character* c, int* rc);
/* Pose at time t; the collider gets the pose with the elapsed time since the last one. */
ak_result particles_character_pose(particles_character* c, float t, float elapsed);
void particles_character_free(particles_character* c);

/* A system built from a scene (which it points to and whose emitters it updates). */
typedef struct particles_run {
    ak_particles_scene_run lib; /* the library's run (its world may be edited: the viewer's wind) */
    ak_particles* ps;           /* lib.system */
    particles_character* ch;    /* NULL unless the character preset */
} particles_run;

/* Create the system, add the scene's particles; ch NULL unless the character preset.
 * Returns an exit code (message printed). */
int particles_run_init(particles_run* r, ak_particles_scene* s, particles_character* ch, uint64_t seed, uint32_t threads);
/* Step number `step` (0-based): pose the character for its end, emit, fire bursts, step. */
int particles_run_step(particles_run* r, int step);
/* Free the system (safe on a zeroed run). */
void particles_run_free(particles_run* r);

/* UV spheres and boxes of the scene's colliders as one triangle mesh. */
typedef struct particles_shapes {
    ak_vec3* pos;
    ak_vec3* nrm;
    uint32_t* idx;
    size_t vcount, icount;
} particles_shapes;

/* Build sh from the world's spheres and boxes; false when out of memory (free it anyway). */
bool particles_shapes_build(particles_shapes* sh, const ak_particles_scene* s);
void particles_shapes_free(particles_shapes* sh);

/* Grow [lo, hi] by p (points beyond 1e6 in some axis are skipped). */
void particles_bounds_add(ak_vec3* lo, ak_vec3* hi, ak_vec3 p);

/* Draw the live particles as points: colours fade with age, the radius is the mean size seen
 * at `centre` (1..12 pixels), outlined above 3 pixels. colours has room for the capacity. */
ak_result particles_draw_points(ak_raster* ras, const ak_raster_camera* camera, int width, int height, ak_vec3 centre,
                                ak_particles* ps, ak_vec4* colours);

/* Sprite drawing of a scene whose "render" asks for sprites: per-particle arrays for the
 * capacity, the texture (the scene's PNG sheet, or built-in puffs/discs, one per frame). */
typedef struct particles_sprite_renderer {
    bool ready; /* false: the scene draws points */
    float* sizes;
    ak_vec4* colours;
    uint32_t* frames;
    uint32_t* order;
    float* depth;
    ak_image texture;
    int columns, rows;
} particles_sprite_renderer;

/* Prepare sr for s (nothing when s draws points); an exit code, with the message printed. */
int particles_sprites_init(particles_sprite_renderer* sr, const ak_particles_scene* s, const char* command);
/* Draw the live particles as sprites: colour and size over life, the frame from the age, sorted
 * back to front for alpha blending. */
ak_result particles_draw_sprites(ak_raster* ras, const ak_raster_camera* camera, const ak_particles_scene* s,
                                 particles_sprite_renderer* sr, ak_particles* ps);
/* Free (safe on a zeroed renderer). */
void particles_sprites_free(particles_sprite_renderer* sr);
/* Whether s draws glowing (additive) sprites, which `particles -o` and the viewer show on a
 * dark sky; then *top and *bottom get its colours. */
bool particles_dark_sky(const ak_particles_scene* s, ak_vec4* top, ak_vec4* bottom);

#endif

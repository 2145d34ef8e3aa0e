/* animkit command line: a cloth run shared by `animkit cloth` and `animkit view`: the cloth
 * built from a scene, the character that carries or meets it, one step at a time, the box a
 * camera frames, and sphere/capsule meshes for drawing the colliders. */
#ifndef ANIMKIT_CLI_CLOTH_RUN_H
#define ANIMKIT_CLI_CLOTH_RUN_H

#include "cli.h"
#include "render.h"
#include <animkit/cloth.h>

/* The character: pose, attachments, colliders. */
typedef struct cloth_character {
    ak_scene* scene;
    cli_poser poser;
    int clip;
    float duration;
    int* attach_joint;      /* [attach_count] joint index or -1 */
    ak_vec3* attach_offset; /* joint-local offset, or offset from the mesh vertex */
    ak_vec3* mesh_pos;      /* all meshes' posed positions, concatenated */
    uint32_t* mesh_idx;
    size_t mesh_vertices, mesh_tris;
    int* bone_parent;       /* limb capsules: joint pairs and radii */
    int* bone_child;
    float* bone_radius;
    size_t bone_count;
    ak_cloth_capsule* capsules; /* scene capsules then limb capsules */
} cloth_character;

void cloth_character_free(cloth_character* c);

/* A cloth built from a scene (which it points to) by the library's run, with the character. */
typedef struct cloth_run {
    ak_cloth_scene_run lib;           /* the cloth, its state and its step job */
    ak_cloth_scene* sc;
    cloth_character ch;
    /* lib's, under the command's names (refreshed by init and step) */
    ak_cloth* cloth;
    ak_vec3 *x, *vel, *nrm, *targets; /* [n], [n], [n], [attach_count] */
    ak_cloth_capsule* caps;           /* the scene's capsules, then the limb capsules */
    size_t n;
    long step;                        /* steps run */
    float time;                       /* simulated seconds */
} cloth_run;

/* Build the cloth, load and pose the character (attachments keep their offsets at t = 0),
 * and the step job. Returns an exit code with the message printed as `animkit CMD:` naming
 * name; free with cloth_run_free in every case. */
int cloth_run_init(cloth_run* run, ak_cloth_scene* sc, const char* cmd, const char* name);
/* One step: pose the character and the attachment targets at its end, gusty wind, step.
 * Returns an exit code (a blow-up names its step). */
int cloth_run_step(cloth_run* run, const char* cmd, const char* name);
/* The box `animkit cloth -o` frames: the cloth at rest, spheres, upward planes, the character,
 * and room downwind. */
void cloth_run_bounds(const cloth_run* run, ak_vec3* lo, ak_vec3* hi);
void cloth_run_free(cloth_run* run);

/* A sphere (a == b) or capsule mesh for drawing: rings x segments of a unit sphere whose halves
 * are centred on a and b. */
enum { PROP_RINGS = 12, PROP_SEGS = 20, PROP_VERTS = (PROP_RINGS + 1) * PROP_SEGS, PROP_TRIS = PROP_RINGS * PROP_SEGS * 2 };
typedef struct cloth_prop {
    ak_vec3 pos[PROP_VERTS], nrm[PROP_VERTS];
    uint32_t idx[PROP_TRIS * 3];
} cloth_prop;

void cloth_prop_build(cloth_prop* p, ak_vec3 a, ak_vec3 b, float r);

#endif

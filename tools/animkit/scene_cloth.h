/* animkit cloth: the scene file (JSON) and the built-in presets, parsed into one struct.
 * Every key, its unit and its default: docs/cloth.md. */
#ifndef ANIMKIT_CLI_SCENE_CLOTH_H
#define ANIMKIT_CLI_SCENE_CLOTH_H

#include <stdbool.h>
#include <stddef.h>

#include <animkit/cloth.h>

/* Budgets: a scene file cannot ask for more than this. */
#define CLOTH_SCENE_MAX_PARTICLES ((size_t)1 << 20)
#define CLOTH_SCENE_MAX_LIST 4096 /* pins, attachments, colliders of each kind */
#define CLOTH_SCENE_MAX_STEPS 1000000L

typedef struct cloth_attach_spec {
    uint32_t vertex;     /* cloth vertex */
    char joint[64];      /* follow this joint rigidly ("" -> mesh_vertex) */
    long mesh_vertex;    /* or follow this skinned vertex of the character's mesh 0 (-1: joint) */
    bool has_position;   /* position given: the vertex starts there (else at its rest position) */
    ak_vec3 position;    /* world, at t = 0: where the attachment holds it (gathers a collar) */
} cloth_attach_spec;

typedef struct cloth_scene {
    ak_cloth_desc desc;        /* grid, material, solver (spans point into the arrays below) */
    uint32_t* pins;            /* [pin_count] */
    size_t pin_count;
    ak_vec3* pin_positions;    /* [pin_position_count]: 0 (rest positions) or pin_count */
    size_t pin_position_count;
    cloth_attach_spec* attach; /* [attach_count] */
    size_t attach_count;
    /* stepping */
    float dt;                  /* seconds per step */
    long steps;
    uint32_t substeps, iterations;
    bool iterations_given;     /* the scene says "iterations" (else implicit uses its own cap) */
    bool substeps_forced;      /* --substeps given: the spring solver keeps it even below its
                                  stable count (otherwise it runs at least that count) */
    ak_vec3 gravity, wind;
    float gust;                /* wind *= 1 + gust * sin(2 pi gust_frequency t) */
    float gust_frequency;
    float drag, lift, air_density, damping, thickness, friction, self_distance;
    bool self_collision;
    ak_cloth_plane* planes;
    size_t plane_count;
    ak_cloth_sphere* spheres;
    size_t sphere_count;
    ak_cloth_capsule* capsules;
    size_t capsule_count;
    /* character */
    char model[256];           /* "" -> none; else FILE or builtin:NAME */
    char clip[64];             /* clip name or index; "" -> the first */
    bool mesh_collider;        /* the posed character mesh collides */
    bool limb_capsules;        /* capsules along the character's bones collide */
    float capsule_scale;       /* limb capsule radius / mean skin distance to the bone */
    int thread_count;
} cloth_scene;

/* Defaults (every key absent). */
void cloth_scene_defaults(cloth_scene* s);
/* Parse a scene from text[0, size). file names the input in messages. Returns true, or false
 * with "FILE: KEY.PATH: problem" in message. The scene owns its arrays: cloth_scene_free. */
bool cloth_scene_parse(const char* file, const char* text, size_t size, cloth_scene* out, char* message,
                       size_t message_size);
/* A preset: "flag", "curtain", "drape" or "cape"; false for another name. */
bool cloth_scene_preset(const char* name, cloth_scene* out);
void cloth_scene_free(cloth_scene* s);

#endif

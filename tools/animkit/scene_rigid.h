/* animkit rigid: the scene file (JSON) and the built-in presets, parsed into one struct.
 * Every key, its unit and its default: docs/rigid.md. */
#ifndef ANIMKIT_CLI_SCENE_RIGID_H
#define ANIMKIT_CLI_SCENE_RIGID_H

#include <stdbool.h>
#include <stddef.h>

#include <animkit/rigid.h>

/* Budgets: a scene file cannot ask for more than this. */
#define RIGID_SCENE_MAX_BODIES 100000
#define RIGID_SCENE_MAX_STEPS 1000000L
#define RIGID_SCENE_MAX_JOINTS 100000

typedef struct rigid_scene {
    ak_rigid_body_desc* bodies; /* [body_count], scene order */
    size_t body_count;
    ak_rigid_joint_desc* joints; /* [joint_count] */
    size_t joint_count;
    ak_rigid_model_desc model; /* damping, contact offset (bodies filled by the caller) */
    ak_vec3 gravity;           /* m/s^2 */
    float dt;                  /* seconds per step */
    long steps;
    uint32_t substeps;
    int thread_count;
    bool sleep; /* bodies may fall asleep */
} rigid_scene;

/* Defaults (every key absent, no bodies). */
void rigid_scene_defaults(rigid_scene* s);
/* Free the arrays (the struct stays valid and empty). */
void rigid_scene_free(rigid_scene* s);
/* Parse text[0, size) of file `file`. On failure returns false with "FILE: KEY.PATH: problem"
 * in msg (cap bytes) and s freed. */
bool rigid_scene_parse(const char* file, const char* text, size_t size, rigid_scene* s, char* msg,
                       size_t cap);
/* A built-in preset: stack, pyramid, dominoes, avalanche, ragdoll, incline. False (s empty)
 * for an unknown name (or when the ragdoll's character cannot be built). */
bool rigid_scene_preset(const char* name, rigid_scene* s);

#endif

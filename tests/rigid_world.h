/* A small rigid world for the rigid tests: up to RIGID_WORLD_MAX bodies with their state arrays
 * and a step job (dt 1/60 s, gravity -9.81 m/s^2 along Y), the model and scratch owned here. */
#ifndef ANIMKIT_TEST_RIGID_WORLD_H
#define ANIMKIT_TEST_RIGID_WORLD_H

#include <stdlib.h>
#include <string.h>

#include <animkit/rigid.h>

#define RIGID_WORLD_MAX 32

typedef struct world {
    ak_rigid_model* model;
    size_t n;
    ak_vec3 x[RIGID_WORLD_MAX], v[RIGID_WORLD_MAX], w[RIGID_WORLD_MAX];
    ak_quat q[RIGID_WORLD_MAX];
    ak_rigid_step_job job;
    float pen; /* the last step's deepest penetration */
} world;

/* false when the model cannot be built, n is above RIGID_WORLD_MAX or memory runs out. */
static inline bool world_init(world* wd, const ak_rigid_body_desc* bodies, size_t n, uint32_t substeps) {
    memset(wd, 0, sizeof *wd);
    if (n > RIGID_WORLD_MAX) return false;
    ak_rigid_model_desc md = {.bodies = {bodies, n}};
    if (ak_rigid_model_create(&md, NULL, &wd->model) != AK_OK) return false;
    wd->n = n;
    ak_rigid_initial_state(wd->model, (ak_vec3_span){wd->x, n}, (ak_quat_span){wd->q, n},
                           (ak_vec3_span){wd->v, n}, (ak_vec3_span){wd->w, n});
    wd->job = (ak_rigid_step_job){.model = wd->model,
                                  .dt = 1.0f / 60.0f,
                                  .substeps = substeps,
                                  .gravity = {0.0f, -9.81f, 0.0f},
                                  .positions = {wd->x, n},
                                  .orientations = {wd->q, n},
                                  .velocities = {wd->v, n},
                                  .angular_velocities = {wd->w, n},
                                  .out_max_penetration = &wd->pen};
    size_t size = ak_rigid_step_scratch_size(&wd->job);
    wd->job.scratch = (ak_u8_span){malloc(size), size};
    return wd->job.scratch.ptr != NULL;
}

static inline void world_free(world* wd) {
    free(wd->job.scratch.ptr);
    ak_rigid_model_destroy(wd->model);
}

#endif

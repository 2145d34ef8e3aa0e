/* Liquid poured on rigid bodies, one-way (ak_rigid_fluid_colliders): a static tilted hull (a
 * wedge) in a tank and a box that slides along the tank's floor and pushes the liquid. Each
 * step: the rigid step, the bodies written as the fluid's colliders, the fluid step. Prints how
 * deep the deepest particle ever got inside a body (0: none entered) and where the liquid is. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include <animkit/animkit.h>

int main(void) {
    /* bodies: a wedge (a hull of 6 points), a box sliding at 0.5 m/s with no gravity on it */
    const ak_vec3 wedge[6] = {{-0.15f, 0, -0.15f}, {0.15f, 0, -0.15f}, {-0.15f, 0.15f, -0.15f},
                              {-0.15f, 0, 0.15f},  {0.15f, 0, 0.15f},  {-0.15f, 0.15f, 0.15f}};
    ak_rigid_body_desc bodies[2] = {
        {.shape = {.type = AK_RIGID_HULL, .points = {wedge, 6}},
         .position = {0.3f, 0.0f, 0.2f},
         .is_static = true},
        {.shape = {.type = AK_RIGID_BOX, .half_extents = {0.04f, 0.1f, 0.15f}},
         .position = {0.7f, 0.1f, 0.2f},
         .velocity = {-0.5f, 0, 0}}};
    ak_rigid_model* model = NULL;
    if (ak_rigid_model_create(&(ak_rigid_model_desc){.bodies = {bodies, 2}}, NULL, &model) != AK_OK)
        return 1;
    ak_vec3 x[2], v[2], w[2];
    ak_quat q[2];
    ak_rigid_initial_state(model, (ak_vec3_span){x, 2}, (ak_quat_span){q, 2}, (ak_vec3_span){v, 2},
                           (ak_vec3_span){w, 2});
    const float dt = 1.0f / 200.0f;
    ak_rigid_step_job rj = {.model = model,
                            .dt = dt,
                            .substeps = 4,
                            .positions = {x, 2},
                            .orientations = {q, 2},
                            .velocities = {v, 2},
                            .angular_velocities = {w, 2}}; /* no gravity: the box keeps sliding */
    size_t rbytes = ak_rigid_step_scratch_size(&rj);
    rj.scratch = (ak_u8_span){malloc(rbytes), rbytes};

    /* liquid: 4 cm particles, a 0.24 x 0.16 x 0.24 m block over the wedge; a 0.8 x 1 x 0.4 tank */
    ak_fluid_desc fd = {.h = 0.08f,
                        .particle_mass = 0.064f,
                        .gravity = {0, -9.81f, 0},
                        .box_min = {0, 0, 0},
                        .box_max = {0.8f, 1.0f, 0.4f}};
    const ak_vec3 lo = {0.12f, 0.3f, 0.08f}, hi = {0.36f, 0.46f, 0.32f};
    size_t cap = ak_fluid_fill_box(&fd, lo, hi, (ak_vec3_span){NULL, 0}), n;
    ak_vec3* pos = malloc(cap * sizeof *pos);
    ak_vec3* vel = calloc(cap, sizeof *vel);
    size_t fbytes = ak_fluid_scratch_size(cap, &fd);
    void* fscratch = malloc(fbytes);
    if (!rj.scratch.ptr || !pos || !vel || !fscratch) return 1;
    n = ak_fluid_fill_box(&fd, lo, hi, (ak_vec3_span){pos, cap});
    ak_fluid_step_job fj = {.desc = &fd,
                            .dt = dt,
                            .positions = {pos, cap},
                            .velocities = {vel, cap},
                            .particle_count = &n,
                            .scratch = {fscratch, fbytes}};

    size_t nc, np;
    ak_rigid_fluid_colliders_size(model, &nc, &np); /* 2 colliders, the wedge's 5 planes */
    ak_fluid_collider cols[2];
    ak_vec4 planes[8];
    float deepest = 0.0f;
    for (int step = 0; step < 120; ++step) {
        if (ak_rigid_step_run(&rj) != AK_OK) return 1;
        ak_rigid_fluid_colliders(model, (ak_vec3_cspan){x, 2}, (ak_quat_cspan){q, 2},
                                 (ak_vec3_cspan){v, 2}, (ak_vec3_cspan){w, 2},
                                 (ak_fluid_collider_span){cols, 2}, (ak_vec4_span){planes, 8}, &nc);
        fj.colliders = (ak_fluid_collider_cspan){cols, nc};
        if (ak_fluid_step_run(&fj) != AK_OK) return 1;
        /* how deep inside the wedge's planes (the body frame) or the box any particle is */
        for (size_t i = 0; i < n; ++i)
            for (size_t c = 0; c < nc; ++c) {
                ak_vec3 l = ak_quat_rotate(ak_quat_conjugate(cols[c].orientation),
                                           ak_vec3_sub(pos[i], cols[c].a));
                float depth;
                if (cols[c].shape == AK_FLUID_BOX) {
                    ak_vec3 h = cols[c].half_extents;
                    depth = fminf(fminf(h.x - fabsf(l.x), h.y - fabsf(l.y)), h.z - fabsf(l.z));
                } else {
                    depth = INFINITY;
                    for (uint32_t k = 0; k < cols[c].plane_count; ++k) {
                        ak_vec4 p = cols[c].planes[k];
                        depth = fminf(depth, p.w - (p.x * l.x + p.y * l.y + p.z * l.z));
                    }
                }
                deepest = fmaxf(deepest, depth);
            }
    }
    double mx = 0.0, my = 0.0, vx = 0.0;
    for (size_t i = 0; i < n; ++i) mx += pos[i].x, my += pos[i].y, vx += vel[i].x;
    printf("%zu particles, %zu colliders (%zu hull planes), 0.6 s: deepest inside a body %.2g m; "
           "liquid centre x %.3f y %.3f m, mean x velocity %.3f m/s; box at x %.3f m\n",
           n, nc, np, (double)deepest, mx / (double)n, my / (double)n, vx / (double)n,
           (double)x[1].x);
    free(fscratch), free(vel), free(pos), free(rj.scratch.ptr);
    ak_rigid_model_destroy(model);
    return deepest <= 1e-4f ? 0 : 1;
}

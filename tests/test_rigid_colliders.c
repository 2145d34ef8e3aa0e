/* Rigid bodies as one-way colliders of other simulations, through ak_rigid_world_mesh (the
 * bodies as one world-space triangle mesh at the current state, which cloth and particles
 * already take as a collider): a cloth dropped on a box body that itself rests on the ground
 * (both simulations stepped together, the cloth reading the box's pose every step) settles on
 * the box's top face at the analytic height top + thickness; particles dropped on it come to
 * rest on the top face; the mesh's vertices lie on the shapes at their poses. */
#include <math.h>
#include <stdlib.h>

#include <animkit/animkit.h>

#include "ak_test.h"

AK_TEST(world_mesh_on_the_shapes) {
    ak_rigid_body_desc b[3] = {
        {.shape = {.type = AK_RIGID_PLANE}, .is_static = true},
        {.shape = {.type = AK_RIGID_BOX, .half_extents = {0.5f, 0.25f, 0.4f}},
         .position = {1, 2, 3}},
        {.shape = {.type = AK_RIGID_CAPSULE, .radius = 0.2f, .half_height = 0.3f},
         .position = {-1, 1, 0}},
    };
    b[1].orientation = ak_quat_from_axis_angle(ak_vec3_normalize(ak_vec3_make(1, 1, 0)), 0.7f);
    b[2].orientation = ak_quat_from_axis_angle(ak_vec3_make(0, 0, 1), 1.2f);
    ak_rigid_model* m = NULL;
    ak_rigid_model_desc md = {.bodies = {b, 3}};
    AK_CHECK_EQ(ak_rigid_model_create(&md, NULL, &m), AK_OK);
    if (!m) return;
    ak_vec3 x[3], v[3], w[3];
    ak_quat q[3];
    ak_rigid_initial_state(m, (ak_vec3_span){x, 3}, (ak_quat_span){q, 3}, (ak_vec3_span){v, 3},
                           (ak_vec3_span){w, 3});
    size_t nv, ni;
    ak_rigid_world_mesh_size(m, &nv, &ni);
    AK_CHECK_EQ(nv, (size_t)(24 + 10 * 17)); /* the plane is left out */
    ak_vec3* p = malloc(nv * sizeof *p);
    ak_vec3* n = malloc(nv * sizeof *n);
    uint32_t* idx = malloc(ni * sizeof *idx);
    AK_CHECK(p && n && idx);
    if (p && n && idx) {
        AK_CHECK_EQ(ak_rigid_world_mesh(m, (ak_vec3_cspan){x, 3}, (ak_quat_cspan){q, 3},
                                        (ak_vec3_span){p, nv}, (ak_vec3_span){n, nv},
                                        (ak_u32_span){idx, ni}),
                    AK_OK);
        float worst = 0.0f;
        for (size_t k = 0; k < nv; ++k) {
            /* back into the body's frame: on the box's faces, at the capsule's radius */
            size_t body = k < 24 ? 1 : 2;
            ak_vec3 l = ak_quat_rotate(ak_quat_conjugate(q[body]), ak_vec3_sub(p[k], x[body]));
            float e;
            if (body == 1) {
                e = fabsf(fabsf(l.x) - 0.5f) + fabsf(fabsf(l.y) - 0.25f) + fabsf(fabsf(l.z) - 0.4f);
            } else {
                ak_vec3 c = ak_vec3_make(0, ak_clampf(l.y, -0.3f, 0.3f), 0);
                e = fabsf(ak_vec3_distance(l, c) - 0.2f);
            }
            worst = ak_maxf(worst, e);
        }
        AK_CHECK_MSG(worst < 1e-5f, "a mesh vertex is %g m off its body's shape", worst);
        for (size_t k = 0; k < ni; ++k) AK_CHECK(idx[k] < nv);
        x[2].y = NAN;
        AK_CHECK_EQ(ak_rigid_world_mesh(m, (ak_vec3_cspan){x, 3}, (ak_quat_cspan){q, 3},
                                        (ak_vec3_span){p, nv}, (ak_vec3_span){n, nv},
                                        (ak_u32_span){idx, ni}),
                    AK_ERR_BAD_DATA);
        AK_CHECK_EQ(ak_rigid_world_mesh(m, (ak_vec3_cspan){x, 3}, (ak_quat_cspan){q, 3},
                                        (ak_vec3_span){p, nv - 1}, (ak_vec3_span){n, nv},
                                        (ak_u32_span){idx, ni}),
                    AK_ERR_SPAN_SMALL);
    }
    free(p), free(n), free(idx);
    ak_rigid_model_destroy(m);
}

/* A 0.5 m cloth (11 x 11 particles) dropped from 0.3 m above a 1 m x 0.5 m x 1 m box resting on
 * the ground; 2 s of both simulations at 1/60 s. The box's top is at 0.5 m; the cloth keeps
 * `thickness` (1 cm) from the collider mesh, so it must lie flat at 0.51 m. */
AK_TEST(cloth_rests_on_a_box_body) {
    ak_rigid_body_desc b[2] = {
        {.shape = {.type = AK_RIGID_PLANE}, .is_static = true},
        {.shape = {.type = AK_RIGID_BOX, .half_extents = {0.5f, 0.25f, 0.5f}},
         .position = {0, 0.25f, 0}},
    };
    ak_rigid_model* m = NULL;
    ak_rigid_model_desc md = {.bodies = {b, 2}};
    AK_CHECK_EQ(ak_rigid_model_create(&md, NULL, &m), AK_OK);
    ak_cloth* cloth = NULL;
    ak_cloth_desc cd = {.grid_width = 11,
                        .grid_height = 11,
                        .spacing = 0.05f,
                        .grid_origin = {-0.25f, 0.8f, 0.25f},
                        .bending = AK_CLOTH_BEND_SPRINGS};
    AK_CHECK_EQ(ak_cloth_create(&cd, NULL, &cloth), AK_OK);
    if (!m || !cloth) {
        ak_rigid_model_destroy(m);
        ak_cloth_destroy(cloth);
        return;
    }
    ak_vec3 x[2], v[2], w[2];
    ak_quat q[2];
    ak_rigid_initial_state(m, (ak_vec3_span){x, 2}, (ak_quat_span){q, 2}, (ak_vec3_span){v, 2},
                           (ak_vec3_span){w, 2});
    ak_rigid_step_job rj = {.model = m,
                            .dt = 1.0f / 60.0f,
                            .substeps = 10,
                            .gravity = {0, -9.81f, 0},
                            .positions = {x, 2},
                            .orientations = {q, 2},
                            .velocities = {v, 2},
                            .angular_velocities = {w, 2}};
    size_t rsize = ak_rigid_step_scratch_size(&rj);
    rj.scratch = (ak_u8_span){malloc(rsize), rsize};
    size_t nv, ni;
    ak_rigid_world_mesh_size(m, &nv, &ni);
    ak_vec3* mp = malloc(nv * sizeof *mp);
    ak_vec3* mn = malloc(nv * sizeof *mn);
    uint32_t* mi = malloc(ni * sizeof *mi);
    const size_t n = ak_cloth_vertex_count(cloth);
    ak_vec3* cx = malloc(n * sizeof *cx);
    ak_vec3* cv = calloc(n, sizeof *cv);
    ak_cloth_step_job cj = {.cloth = cloth,
                            .dt = 1.0f / 60.0f,
                            .substeps = 10,
                            .iterations = 2,
                            .gravity = {0, -9.81f, 0},
                            .damping = 1.0f,
                            .friction = 0.5f,
                            .mesh = {{mp, nv}, {mi, ni}},
                            .positions = {cx, n},
                            .velocities = {cv, n}};
    size_t csize = ak_cloth_step_scratch_size(&cj);
    cj.scratch = (ak_u8_span){malloc(csize), csize};
    bool ok = rj.scratch.ptr && mp && mn && mi && cx && cv && cj.scratch.ptr &&
              ak_cloth_rest_positions(cloth, (ak_vec3_span){cx, n}) == AK_OK;
    AK_CHECK(ok);
    for (int f = 0; ok && f < 120; ++f) {
        /* the colliders at the bodies' current poses, then both simulations step */
        ok = ak_rigid_world_mesh(m, (ak_vec3_cspan){x, 2}, (ak_quat_cspan){q, 2},
                                 (ak_vec3_span){mp, nv}, (ak_vec3_span){mn, nv},
                                 (ak_u32_span){mi, ni}) == AK_OK &&
             ak_cloth_step_run(&cj) == AK_OK && ak_rigid_step_run(&rj) == AK_OK;
    }
    AK_CHECK(ok);
    if (ok) {
        float lo = INFINITY, hi = -INFINITY;
        for (size_t k = 0; k < n; ++k) lo = ak_minf(lo, cx[k].y), hi = ak_maxf(hi, cx[k].y);
        const float top = x[1].y + 0.25f, expect = 0.5f + 0.01f;
        printf("  box top %.5f m; cloth from %.5f to %.5f m (analytic %.3f)\n", (double)top,
               (double)lo, (double)hi, (double)expect);
        AK_CHECK_MSG(fabsf(top - 0.5f) < 1e-3f, "the box's top moved to %g m", top);
        AK_CHECK_MSG(fabsf(lo - expect) < 2e-3f && fabsf(hi - expect) < 2e-3f,
                     "the cloth lies between %g and %g m, not at %g m", lo, hi, expect);
    }
    free(rj.scratch.ptr), free(cj.scratch.ptr), free(mp), free(mn), free(mi), free(cx), free(cv);
    ak_cloth_destroy(cloth);
    ak_rigid_model_destroy(m);
}

/* 25 particles dropped on the same box body (resting on the ground, stepped together with
 * them) through an ak_particle_mesh updated to the box's pose each step: with restitution 0
 * and friction 1 they come to rest on its top face, at 0.5 m (contacts leave them 1e-5 m off
 * the surface), and none falls through. */
AK_TEST(particles_rest_on_a_box_body) {
    ak_rigid_body_desc b[2] = {
        {.shape = {.type = AK_RIGID_PLANE}, .is_static = true},
        {.shape = {.type = AK_RIGID_BOX, .half_extents = {0.5f, 0.25f, 0.5f}},
         .position = {0, 0.25f, 0}},
    };
    ak_rigid_model* m = NULL;
    ak_rigid_model_desc md = {.bodies = {b, 2}};
    AK_CHECK_EQ(ak_rigid_model_create(&md, NULL, &m), AK_OK);
    ak_particles* ps = NULL;
    AK_CHECK_EQ(ak_particles_create(&(ak_particles_desc){.capacity = 25, .seed = 1}, NULL, &ps),
                AK_OK);
    if (!m || !ps) {
        ak_rigid_model_destroy(m);
        ak_particles_destroy(ps);
        return;
    }
    for (int k = 0; k < 25; ++k) {
        ak_particle_init pi = {
            .position = {-0.3f + 0.15f * (float)(k % 5), 1.0f, -0.3f + 0.15f * (float)(k / 5)},
            .mass = 0.01f};
        AK_CHECK_EQ(ak_particles_add(ps, &pi, NULL), AK_OK);
    }
    ak_vec3 x[2], v[2], w[2];
    ak_quat q[2];
    ak_rigid_initial_state(m, (ak_vec3_span){x, 2}, (ak_quat_span){q, 2}, (ak_vec3_span){v, 2},
                           (ak_vec3_span){w, 2});
    const float dt = 1.0f / 60.0f;
    ak_rigid_step_job rj = {.model = m,
                            .dt = dt,
                            .substeps = 10,
                            .gravity = {0, -9.81f, 0},
                            .positions = {x, 2},
                            .orientations = {q, 2},
                            .velocities = {v, 2},
                            .angular_velocities = {w, 2}};
    size_t rsize = ak_rigid_step_scratch_size(&rj);
    rj.scratch = (ak_u8_span){malloc(rsize), rsize};
    size_t nv, ni;
    ak_rigid_world_mesh_size(m, &nv, &ni);
    ak_vec3* mp = malloc(nv * sizeof *mp);
    ak_vec3* mn = malloc(nv * sizeof *mn);
    uint32_t* mi = malloc(ni * sizeof *mi);
    ak_particle_mesh* pm = NULL;
    bool ok =
        rj.scratch.ptr && mp && mn && mi &&
        ak_rigid_world_mesh(m, (ak_vec3_cspan){x, 2}, (ak_quat_cspan){q, 2}, (ak_vec3_span){mp, nv},
                            (ak_vec3_span){mn, nv}, (ak_u32_span){mi, ni}) == AK_OK &&
        ak_particle_mesh_create(
            &(ak_particle_mesh_desc){.positions = {mp, nv}, .indices = {mi, ni}, .friction = 1.0f},
            NULL, &pm) == AK_OK;
    AK_CHECK(ok);
    const ak_particle_mesh* meshes[1] = {pm};
    ak_particles_world world = {.gravity = {0, -9.81f, 0}, .meshes = {meshes, 1}};
    float lowest = INFINITY;
    for (int f = 0; ok && f < 90; ++f) {
        /* the bodies step, the mesh follows them (elapsed dt: its velocity), then the particles */
        ok = ak_rigid_step_run(&rj) == AK_OK &&
             ak_rigid_world_mesh(m, (ak_vec3_cspan){x, 2}, (ak_quat_cspan){q, 2},
                                 (ak_vec3_span){mp, nv}, (ak_vec3_span){mn, nv},
                                 (ak_u32_span){mi, ni}) == AK_OK &&
             ak_particle_mesh_update(pm, (ak_vec3_cspan){mp, nv}, dt) == AK_OK &&
             ak_particles_step(ps, &world, dt) == AK_OK;
        ak_particles_state st = ak_particles_get_state(ps);
        for (size_t k = 0; k < st.count; ++k) lowest = ak_minf(lowest, st.position[k].y);
    }
    AK_CHECK(ok);
    ak_particles_state st = ak_particles_get_state(ps);
    AK_CHECK_EQ(st.count, (size_t)25);
    float lo = INFINITY, hi = -INFINITY;
    for (size_t k = 0; k < st.count; ++k)
        lo = ak_minf(lo, st.position[k].y), hi = ak_maxf(hi, st.position[k].y);
    const float top = x[1].y + 0.25f;
    printf("  particles on the box: %.5f to %.5f m (top %.5f m), lowest ever %.5f m\n", (double)lo,
           (double)hi, (double)top, (double)lowest);
    AK_CHECK_MSG(fabsf(lo - top) < 1e-3f && fabsf(hi - top) < 1e-3f,
                 "particles at %g..%g m, top at %g m", lo, hi, top);
    AK_CHECK_MSG(lowest > top - 1e-3f, "a particle went to %g m, through the top at %g m", lowest,
                 top);
    ak_particle_mesh_destroy(pm);
    free(rj.scratch.ptr), free(mp), free(mn), free(mi);
    ak_particles_destroy(ps);
    ak_rigid_model_destroy(m);
}

int main(void) {
    AK_RUN(world_mesh_on_the_shapes);
    AK_RUN(cloth_rests_on_a_box_body);
    AK_RUN(particles_rest_on_a_box_body);
    return ak_test_finish();
}

/* softskin_bend: volumetric skinning of builtin:cylinder through its "bend" clip (120 degrees
 * over 1 s), at 60 Hz, then held 1/2 s. Prints every 10 frames the enclosed volume relative to
 * rest (soft beside LBS) and the flesh's kinetic energy. */
#include <stdio.h>
#include <stdlib.h>

#include <animkit/animkit.h>

int main(void) {
    ak_builtin_desc bd = {.rings = 24, .segments = 16};
    ak_scene* s = NULL;
    if (ak_builtin_create("builtin:cylinder", &bd, NULL, &s) != AK_OK) return 1;
    const ak_mesh* m = s->meshes[0].mesh;
    const ak_scene_skin* sk = &s->skins[0];
    size_t nv = m->vertex_count, nj = ak_scene_joint_count(s), ns = sk->joint_count;
    int clip = ak_scene_find_clip(s, "bend");
    if (clip < 0 || ns > 8 || nj > 8) return 1;

    /* bones from the skin's bind joint positions (slot order is parent first here) */
    ak_vec3 jp[8];
    int32_t parent[8];
    ak_i32_cspan sp = ak_skeleton_parents(s->skeleton);
    for (size_t k = 0; k < ns; ++k) {
        jp[k] = ak_mat4_get_translation(ak_mat4_inverse_affine(sk->inverse_binds[k]));
        parent[k] = -1;
        for (size_t q = 0; q < ns; ++q)
            if (sk->joints[q] == sp.ptr[sk->joints[k]]) parent[k] = (int32_t)q;
    }
    ak_skin_bone bones[16];
    size_t nb = 0;
    if (ak_skin_bones_from_joints((ak_vec3_cspan){jp, ns}, (ak_i32_cspan){parent, ns}, false,
                                  (ak_skin_bone_span){bones, 16}, &nb) != AK_OK)
        return 1;

    size_t wn = nv * m->influence_count;
    ak_skin_soft_desc d = {.positions = {m->positions, nv},
                           .indices = {m->indices, 3 * m->triangle_count},
                           .joints = {m->joints, wn},
                           .weights = {m->weights, wn},
                           .influence_count = m->influence_count,
                           .bones = {bones, nb},
                           .resolution = 12};
    ak_skin_soft* soft = NULL;
    if (ak_skin_soft_create(&d, NULL, &soft) != AK_OK) return 1;
    size_t nn = ak_skin_soft_node_count(soft), ss = ak_skin_soft_step_scratch_size(soft);
    printf("lattice: %zu nodes (%zu kinematic), %zu tetrahedra\n", nn, ak_skin_soft_kinematic_count(soft),
           ak_skin_soft_tet_count(soft));
    ak_vec3 *x = malloc(nn * sizeof *x), *v = malloc(nn * sizeof *v), *out = malloc(nv * sizeof *out);
    ak_vec3* lbs = malloc(nv * sizeof *lbs);
    uint8_t* scratch = malloc(ss);
    if (!x || !v || !out || !lbs || !scratch) return 1;
    ak_transform local[8];
    ak_mat4 world[8], palette[8], previous[8];
    ak_u32_cspan tris = {m->indices, 3 * m->triangle_count};
    double v0 = ak_volume_compute((ak_vec3_cspan){m->positions, nv}, tris);
    for (int f = 0; f <= 90; ++f) {
        float t = ak_minf((float)f / 60.0f, 1.0f);
        ak_scene_rest_pose(s, (ak_transform_span){local, nj});
        ak_clip_sample(s->clips[clip], t, NULL, (ak_transform_span){local, nj}, (ak_f32_span){0}, (ak_f32_span){0});
        ak_scene_world_matrices(s, (ak_transform_cspan){local, nj}, (ak_mat4_span){world, nj});
        ak_scene_skin_palette(s, 0, (ak_mat4_cspan){world, nj}, (ak_mat4_span){palette, ns});
        if (f == 0) {
            ak_skin_soft_state_init(soft, (ak_mat4_cspan){palette, ns}, (ak_vec3_span){x, nn}, (ak_vec3_span){v, nn});
        } else {
            float ke = 0.0f;
            ak_skin_soft_step_job job = {.soft = soft,
                                         .palette = {palette, ns},
                                         .previous_palette = {previous, ns},
                                         .dt = 1.0f / 60.0f,
                                         .node_positions = {x, nn},
                                         .node_velocities = {v, nn},
                                         .scratch = {scratch, ss},
                                         .out_positions = {out, nv},
                                         .out_kinetic_energy = &ke};
            if (ak_skin_soft_step_run(&job) != AK_OK) return 1;
            if (f % 10 == 0) {
                ak_skin_job lj = {.influence_count = m->influence_count,
                                  .palette = {palette, ns},
                                  .positions = {m->positions, nv, 0},
                                  .joints = {m->joints, nv, 0},
                                  .weights = {m->weights, nv, 0},
                                  .out_positions = {lbs, nv, 0}};
                if (ak_skin_job_run(&lj) != AK_OK) return 1;
                printf("frame %2d  t %.2f s  volume/rest soft %.4f  LBS %.4f  kinetic energy %.4f J\n", f, (double)t,
                       ak_volume_compute((ak_vec3_cspan){out, nv}, tris) / v0,
                       ak_volume_compute((ak_vec3_cspan){lbs, nv}, tris) / v0, (double)ke);
            }
        }
        for (size_t k = 0; k < ns; ++k) previous[k] = palette[k];
    }
    free(x);
    free(v);
    free(out);
    free(lbs);
    free(scratch);
    ak_skin_soft_destroy(soft);
    ak_scene_destroy(s);
    return 0;
}

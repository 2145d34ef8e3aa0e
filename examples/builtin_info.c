/* builtin_info: build the procedural humanoid and print what it holds.
 * Shows ak_builtin_create, the joint tree with types and limits, the mesh checks, the clips,
 * and the right wrist's world position over the "wave" clip (forward kinematics). */
#include <stdio.h>

#include <animkit/builtin.h>

static const char* type_name(ak_joint_type t) {
    switch (t) {
    case AK_JOINT_BALL:
        return "ball";
    case AK_JOINT_HINGE:
        return "hinge";
    case AK_JOINT_PRISM:
        return "prism";
    default:
        return "free";
    }
}

int main(void) {
    ak_scene* scene = NULL;
    ak_result r = ak_builtin_create("builtin:humanoid", NULL, NULL, &scene);
    if (r != AK_OK) {
        fprintf(stderr, "builtin_info: %s\n", ak_result_string(r));
        return 1;
    }
    const ak_skeleton* sk = scene->skeleton;
    const size_t n = ak_skeleton_joint_count(sk);
    ak_i32_cspan parents = ak_skeleton_parents(sk);
    printf("%s: %zu joints\n", scene->name, n);
    for (size_t j = 0; j < n; ++j) {
        ak_joint_type t = ak_skeleton_joint_type(sk, j);
        ak_joint_limits l = ak_skeleton_joint_limits(sk, j);
        printf("  %2zu %-15s parent %-15s %-5s", j, ak_skeleton_joint_name(sk, j),
               parents.ptr[j] < 0 ? "-" : ak_skeleton_joint_name(sk, (size_t)parents.ptr[j]),
               type_name(t));
        if (t == AK_JOINT_HINGE)
            printf("  axis (%.2f %.2f %.2f) %.0f..%.0f deg", (double)l.axis.x, (double)l.axis.y,
                   (double)l.axis.z, (double)ak_degrees(l.min), (double)ak_degrees(l.max));
        if (t == AK_JOINT_BALL)
            printf("  cone %.0f deg, twist %.0f..%.0f deg", (double)ak_degrees(l.cone_angle),
                   (double)ak_degrees(l.twist_min), (double)ak_degrees(l.twist_max));
        printf("\n");
    }

    const ak_mesh* mesh = scene->meshes[0].mesh;
    ak_vec3 lo, hi;
    ak_mesh_bounds(mesh, &lo, &hi);
    double volume = ak_volume_compute((ak_vec3_cspan){mesh->positions, mesh->vertex_count},
                                      (ak_u32_cspan){mesh->indices, 3 * mesh->triangle_count});
    printf("mesh '%s': %zu vertices, %zu triangles, %u influences, closed and oriented: %s\n",
           mesh->name, mesh->vertex_count, mesh->triangle_count, (unsigned)mesh->influence_count,
           ak_mesh_is_closed_oriented(mesh) ? "yes" : "no");
    printf("  height %.3f m, width %.3f m, volume %.4f m^3, weights: %s\n", (double)(hi.y - lo.y),
           (double)(hi.x - lo.x), volume,
           ak_result_name(ak_mesh_validate_weights(mesh, n, 0.0f, NULL)));

    for (size_t c = 0; c < scene->clip_count; ++c)
        printf("clip %zu '%s': %.2f s, %zu channels\n", c, ak_clip_name(scene->clips[c]),
               (double)ak_clip_duration(scene->clips[c]), ak_clip_channel_count(scene->clips[c]));

    /* Right wrist height during the wave. */
    int wave = ak_scene_find_clip(scene, "wave");
    int wrist = ak_skeleton_find_joint(sk, "right_wrist");
    ak_transform local[32];
    ak_mat4 world[32];
    if (wave >= 0 && wrist >= 0 && n <= 32) {
        printf("right_wrist during 'wave' (t, x, y, z):\n");
        for (int i = 0; i <= 8; ++i) {
            float t = 0.25f * (float)i;
            ak_scene_rest_pose(scene, (ak_transform_span){local, n});
            ak_clip_sample(scene->clips[wave], t, NULL, (ak_transform_span){local, n},
                           (ak_f32_span){NULL, 0}, (ak_f32_span){NULL, 0});
            ak_scene_world_matrices(scene, (ak_transform_cspan){local, n},
                                    (ak_mat4_span){world, n});
            ak_vec3 p = ak_mat4_get_translation(world[wrist]);
            printf("  %.2f  %+.3f %+.3f %+.3f\n", (double)t, (double)p.x, (double)p.y, (double)p.z);
        }
    }
    ak_scene_destroy(scene);
    return 0;
}

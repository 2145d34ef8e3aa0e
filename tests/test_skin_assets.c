/* Skinning on the real skinned glTF assets (a whole-library test: it needs io, clip and scene).
 * For every skinned mesh, at several times of its first clip: LBS from ak_skin_job_run equals
 * a straightforward double-precision reference written here, within 1e-5 of the model's
 * bounding-box diagonal; DQS and CoR (with centers from ak_skin_cor_centers_compute) run on
 * the same data and give finite results that stay near LBS. Assets missing -> SKIP. */
#include <animkit/io.h>
#include <animkit/skin.h>

#include "ak_test.h"

static const char* const k_assets[] = {
    "gltf/CesiumMan/glTF-Binary/CesiumMan.glb", "gltf/Fox/glTF-Binary/Fox.glb",
    "gltf/RiggedFigure/glTF-Binary/RiggedFigure.glb", "gltf/RiggedSimple/glTF-Binary/RiggedSimple.glb",
    "gltf/RecursiveSkeletons/glTF-Binary/RecursiveSkeletons.glb", "gltf/SimpleSkin/glTF/SimpleSkin.gltf",
};

static void check_mesh(const char* file, const ak_scene* scene, const ak_mesh* mesh, size_t skin_index,
                       const ak_mat4* palette, size_t palette_count, const ak_vec3* centers, int* checked) {
    const size_t n = mesh->vertex_count;
    const uint32_t k = mesh->influence_count;
    (void)scene;
    ak_vec3* out = (ak_vec3*)malloc(n * sizeof(ak_vec3));
    ak_vec3* out2 = (ak_vec3*)malloc(n * sizeof(ak_vec3));
    ak_skin_job probe = {.method = AK_SKIN_COR, .palette = {palette, palette_count}};
    const size_t scratch_size = ak_skin_job_scratch_size(&probe); /* the largest: CoR */
    unsigned char* scratch = (unsigned char*)malloc(scratch_size);
    ak_skin_job job = {
        .influence_count = k,
        .palette = {palette, palette_count},
        .positions = {mesh->positions, n, 0},
        .joints = {mesh->joints, n, 0},
        .weights = {mesh->weights, n, 0},
        .cor_centers = {centers, n, 0},
        .scratch = {scratch, scratch_size},
        .out_positions = {out, n, 0},
    };
    ak_result r = ak_skin_job_run(&job);
    AK_CHECK_MSG(r == AK_OK, "%s skin %zu: LBS %s", file, skin_index, ak_result_name(r));
    if (r == AK_OK) {
        /* reference in double; the tolerance is relative to the posed bounding box */
        ak_vec3 lo = out[0], hi = out[0];
        double worst = 0.0;
        for (size_t v = 0; v < n; ++v) {
            double p[3] = {0, 0, 0};
            const ak_vec3 x = mesh->positions[v];
            for (uint32_t e = 0; e < k; ++e) {
                const float* m = palette[mesh->joints[v * k + e]].m;
                const double w = mesh->weights[v * k + e];
                for (int row = 0; row < 3; ++row)
                    p[row] += w * ((double)m[row] * x.x + (double)m[4 + row] * x.y + (double)m[8 + row] * x.z +
                                   (double)m[12 + row]);
            }
            worst = fmax(worst, fabs(p[0] - out[v].x) + fabs(p[1] - out[v].y) + fabs(p[2] - out[v].z));
            lo = ak_vec3_min(lo, out[v]);
            hi = ak_vec3_max(hi, out[v]);
        }
        double diag = ak_vec3_length(ak_vec3_sub(hi, lo));
        AK_CHECK_MSG(worst <= 1e-5 * diag, "%s: LBS vs double reference %g (diagonal %g)", file, worst, diag);
        /* DQS and CoR: finite, and close to LBS for these (mostly rigid) rigs: within 10% of
         * the diagonal; candy-wrapper differences are a few percent at most here */
        for (int m = AK_SKIN_DQS; m <= AK_SKIN_COR; ++m) {
            job.method = (ak_skin_method)m;
            job.out_positions.ptr = out2;
            r = ak_skin_job_run(&job);
            AK_CHECK_MSG(r == AK_OK, "%s: method %d %s", file, m, ak_result_name(r));
            double far = 0.0;
            bool finite = true;
            for (size_t v = 0; v < n; ++v) {
                finite = finite && ak_vec3_is_finite(out2[v]);
                far = fmax(far, ak_vec3_distance(out[v], out2[v]));
            }
            AK_CHECK_MSG(finite, "%s: method %d gave non-finite positions", file, m);
            AK_CHECK_MSG(far <= 0.1 * diag, "%s: method %d moved %g from LBS (diagonal %g)", file, m, far, diag);
        }
        ++*checked;
    }
    free(out);
    free(out2);
    free(scratch);
}

AK_TEST(lbs_on_skinned_gltf_matches_double_reference) {
    int checked = 0;
    for (size_t a = 0; a < sizeof k_assets / sizeof k_assets[0]; ++a) {
        char path[4096];
        if (!ak_test_asset(path, sizeof path, k_assets[a])) {
            AK_SKIP("%s not found", k_assets[a]);
            continue;
        }
        ak_scene* scene = NULL;
        ak_diag diag;
        ak_result r = ak_io_load(path, NULL, NULL, &scene, &diag);
        AK_CHECK_MSG(r == AK_OK, "%s: %s (%s)", k_assets[a], ak_result_name(r), diag.message);
        if (r != AK_OK) continue;
        const size_t jc = ak_scene_joint_count(scene);
        ak_transform* pose = (ak_transform*)malloc((jc ? jc : 1) * sizeof(ak_transform));
        ak_mat4* world = (ak_mat4*)malloc((jc ? jc : 1) * sizeof(ak_mat4));
        for (size_t mi = 0; mi < scene->mesh_count; ++mi) {
            const ak_mesh* mesh = scene->meshes[mi].mesh;
            const int32_t skin = scene->meshes[mi].skin;
            if (skin < 0 || !mesh->influence_count || !mesh->weights) continue;
            const ak_scene_skin* sk = &scene->skins[skin];
            ak_mat4* palette = (ak_mat4*)malloc(sk->joint_count * sizeof(ak_mat4));
            ak_vec3* centers = (ak_vec3*)malloc(mesh->vertex_count * sizeof(ak_vec3));
            ak_skin_cor_desc cd = {
                .positions = {mesh->positions, mesh->vertex_count},
                .indices = {mesh->indices, 3 * mesh->triangle_count},
                .joints = {mesh->joints, mesh->vertex_count * mesh->influence_count},
                .weights = {mesh->weights, mesh->vertex_count * mesh->influence_count},
                .influence_count = mesh->influence_count,
            };
            if (mesh->triangle_count == 0 ||
                ak_skin_cor_centers_compute(&cd, NULL, (ak_vec3_span){centers, mesh->vertex_count}) != AK_OK)
                memcpy(centers, mesh->positions, mesh->vertex_count * sizeof(ak_vec3));
            const ak_clip* clip = scene->clip_count ? scene->clips[0] : NULL;
            const float duration = clip ? ak_clip_duration(clip) : 0.0f;
            for (int s = 0; s < 4; ++s) {
                AK_CHECK_EQ(ak_scene_rest_pose(scene, (ak_transform_span){pose, jc}), AK_OK);
                if (clip)
                    AK_CHECK_EQ(ak_clip_sample(clip, duration * (float)s / 3.0f, NULL, (ak_transform_span){pose, jc},
                                               (ak_f32_span){NULL, 0}, (ak_f32_span){NULL, 0}),
                                AK_OK);
                AK_CHECK_EQ(ak_scene_world_matrices(scene, (ak_transform_cspan){pose, jc}, (ak_mat4_span){world, jc}),
                            AK_OK);
                AK_CHECK_EQ(ak_scene_skin_palette(scene, (size_t)skin, (ak_mat4_cspan){world, jc},
                                                  (ak_mat4_span){palette, sk->joint_count}),
                            AK_OK);
                check_mesh(k_assets[a], scene, mesh, (size_t)skin, palette, sk->joint_count, centers, &checked);
            }
            free(palette);
            free(centers);
        }
        free(pose);
        free(world);
        ak_scene_destroy(scene);
    }
    printf("  %d skinned mesh poses checked\n", checked);
}

int main(void) {
    AK_RUN(lbs_on_skinned_gltf_matches_double_reference);
    return ak_test_finish();
}

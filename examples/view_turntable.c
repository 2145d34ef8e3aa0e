/* view_turntable: the view helpers on a model. The built-in humanoid at its rest pose, shaded
 * with its skeleton drawn over it, is filmed from an orbit camera that turns once around it
 * (turntable.gif); the second half of the turn shows the skin weights of the left elbow as a
 * heatmap instead. Two of the frames are also written as PNGs. Prints what it wrote. Runs headless: everything is drawn by the software
 * rasterizer into caller-owned images. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include <animkit/animkit.h>

enum { W = 320, H = 240, FRAMES = 24 };

int main(void) {
    ak_scene* s = NULL;
    if (ak_builtin_create("builtin:humanoid", NULL, NULL, &s) != AK_OK) return 1;
    const ak_mesh* mesh = s->meshes[0].mesh;
    const size_t nj = ak_scene_joint_count(s), nv = mesh->vertex_count;

    /* the rest pose: joint matrices for the skeleton overlay (the mesh is stored at rest) */
    ak_transform* local = malloc(nj * sizeof *local);
    ak_mat4* world = malloc(nj * sizeof *world);
    float* weights = malloc(nv * sizeof *weights);
    ak_vec4* heat = malloc(nv * sizeof *heat);
    uint8_t* pixels = malloc((size_t)FRAMES * W * H * 4);
    ak_image* frames = calloc(FRAMES, sizeof *frames);
    ak_raster* r = NULL;
    int rc = 1;
    if (!local || !world || !weights || !heat || !pixels || !frames) goto done;
    if (ak_scene_rest_pose(s, (ak_transform_span){local, nj}) != AK_OK ||
        ak_scene_world_matrices(s, (ak_transform_cspan){local, nj}, (ak_mat4_span){world, nj}) != AK_OK)
        goto done;

    /* the heatmap: per-vertex weight of one bone, blue (0) to red (1). The mesh's joint
     * indices are skin slots: find the slot of the elbow in the mesh's skin. */
    const int elbow = ak_skeleton_find_joint(s->skeleton, "left_elbow");
    const ak_scene_skin* skin = s->meshes[0].skin >= 0 ? &s->skins[s->meshes[0].skin] : NULL;
    uint32_t slot = UINT32_MAX;
    for (size_t k = 0; skin && k < skin->joint_count; ++k)
        if (skin->joints[k] == elbow) slot = (uint32_t)k;
    if (slot == UINT32_MAX || ak_view_joint_weights(mesh, slot, (ak_f32_span){weights, nv}) != AK_OK ||
        ak_view_heatmap_colors((ak_f32_cspan){weights, nv}, 0.0f, 1.0f, (ak_vec4_span){heat, nv}) != AK_OK)
        goto done;
    size_t touched = 0;
    for (size_t v = 0; v < nv; ++v) touched += weights[v] > 0.0f;

    ak_raster_mesh shaded = ak_view_raster_mesh(mesh);
    ak_raster_mesh weighted = shaded;
    weighted.colors = (ak_vec4_cspan){heat, nv};
    weighted.material.color = ak_vec4_make(1, 1, 1, 1); /* the colours as they are */
    ak_view_skeleton sk = {.joint_model = {world, nj}, .parents = ak_skeleton_parents(s->skeleton)};
    if (ak_raster_create(&(ak_raster_desc){.width = W, .height = H, .supersample = 2, .thread_count = 2}, NULL, &r) !=
        AK_OK)
        goto done;

    /* one box for the whole turn, so the model stays the same size on screen */
    ak_view_scene scene = {.meshes = &shaded, .mesh_count = 1, .skeleton = &sk};
    ak_vec3 lo, hi;
    ak_view_scene_bounds(&scene, &lo, &hi);
    for (int f = 0; f < FRAMES; ++f) {
        const bool heatmap = f >= FRAMES / 2;
        scene.meshes = heatmap ? &weighted : &shaded;
        scene.skeleton = heatmap ? NULL : &sk;
        scene.title = heatmap ? "weights: left_elbow" : "rest pose + skeleton";
        ak_view_orbit orbit = {.azimuth = AK_TWO_PI * (float)f / FRAMES, .elevation = 0.25f, .aspect = (float)W / H};
        ak_raster_camera cam = ak_view_orbit_camera(lo, hi, &orbit);
        frames[f] = (ak_image){.pixels = pixels + (size_t)f * W * H * 4, .width = W, .height = H};
        if (ak_view_render(r, &cam, &scene, &frames[f]) != AK_OK) goto done;
    }
    if (ak_view_frames_write_gif("turntable.gif", frames, FRAMES, 8) != AK_OK) goto done;
    if (ak_png_write("turntable_first.png", &frames[0]) != AK_OK ||
        ak_png_write("turntable_weights.png", &frames[FRAMES * 7 / 12]) != AK_OK)
        goto done;
    printf("humanoid: %zu joints, %zu vertices, %zu weighted to left_elbow\n", nj, nv, touched);
    printf("framed box [%.2f %.2f %.2f]..[%.2f %.2f %.2f]\n", (double)lo.x, (double)lo.y, (double)lo.z, (double)hi.x,
           (double)hi.y, (double)hi.z);
    printf("wrote turntable.gif (%d frames of %dx%d), turntable_first.png, turntable_weights.png\n", FRAMES, W, H);
    rc = 0;
done:
    if (rc) fprintf(stderr, "view_turntable: failed\n");
    ak_raster_destroy(r);
    free(local), free(world), free(weights), free(heat), free(pixels), free(frames);
    ak_scene_destroy(s);
    return rc;
}

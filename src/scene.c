/* Scene container: allocation, destruction, posing helpers. */
#include <animkit/scene.h>

#include <ctype.h>

#include "internal.h"

/* Declared in clip.h by the keyframe module; repeated here so this file builds on its own. */
void ak_clip_destroy(ak_clip* clip);
const char* ak_clip_name(const ak_clip* clip);

ak_result ak_scene_alloc(size_t mesh_count, size_t skin_count, size_t clip_count, const ak_allocator* alloc,
                         ak_scene** out_scene) {
    if (!out_scene) return AK_ERR_NULL_ARG;
    *out_scene = NULL;
    ak_scene* s = (ak_scene*)akp_calloc(alloc, sizeof(ak_scene));
    if (!s) return AK_ERR_NO_MEMORY;
    if (alloc) s->alloc = *alloc;
    const ak_allocator* a = &s->alloc;
    if (mesh_count && !(s->meshes = (ak_scene_mesh*)akp_calloc(a, mesh_count * sizeof(ak_scene_mesh)))) goto oom;
    s->mesh_count = mesh_count;
    for (size_t i = 0; i < mesh_count; ++i) s->meshes[i].node = s->meshes[i].skin = s->meshes[i].texture = -1;
    if (skin_count && !(s->skins = (ak_scene_skin*)akp_calloc(a, skin_count * sizeof(ak_scene_skin)))) goto oom;
    s->skin_count = skin_count;
    if (clip_count && !(s->clips = (ak_clip**)akp_calloc(a, clip_count * sizeof(ak_clip*)))) goto oom;
    s->clip_count = clip_count;
    *out_scene = s;
    return AK_OK;
oom:
    ak_scene_destroy(s);
    return AK_ERR_NO_MEMORY;
}

ak_result ak_scene_skin_alloc(ak_scene* scene, size_t skin_index, size_t joint_count) {
    if (!scene) return AK_ERR_NULL_ARG;
    if (skin_index >= scene->skin_count) return AK_ERR_BAD_INDEX;
    ak_scene_skin* sk = &scene->skins[skin_index];
    akp_free(&scene->alloc, sk->joints);
    akp_free(&scene->alloc, sk->inverse_binds);
    sk->joints = NULL;
    sk->inverse_binds = NULL;
    sk->joint_count = 0;
    if (joint_count == 0) return AK_OK;
    sk->joints = (int32_t*)akp_calloc(&scene->alloc, joint_count * sizeof(int32_t));
    sk->inverse_binds = (ak_mat4*)akp_alloc(&scene->alloc, joint_count * sizeof(ak_mat4));
    if (!sk->joints || !sk->inverse_binds) return AK_ERR_NO_MEMORY;
    for (size_t i = 0; i < joint_count; ++i) sk->inverse_binds[i] = ak_mat4_identity();
    sk->joint_count = joint_count;
    return AK_OK;
}

static void free_textures(ak_scene* scene) {
    for (size_t i = 0; i < scene->texture_count; ++i) akp_free(&scene->alloc, scene->textures[i].pixels);
    akp_free(&scene->alloc, scene->textures);
    scene->textures = NULL;
    scene->texture_count = 0;
}

ak_result ak_scene_texture_alloc(ak_scene* scene, size_t texture_count) {
    if (!scene) return AK_ERR_NULL_ARG;
    free_textures(scene);
    if (texture_count == 0) return AK_OK;
    if (texture_count > SIZE_MAX / sizeof(ak_scene_texture)) return AK_ERR_NO_MEMORY;
    scene->textures = (ak_scene_texture*)akp_calloc(&scene->alloc, texture_count * sizeof(ak_scene_texture));
    if (!scene->textures) return AK_ERR_NO_MEMORY;
    scene->texture_count = texture_count;
    return AK_OK;
}

ak_result ak_scene_texture_alloc_pixels(ak_scene* scene, size_t texture_index, int width, int height) {
    if (!scene) return AK_ERR_NULL_ARG;
    if (texture_index >= scene->texture_count) return AK_ERR_BAD_INDEX;
    if (width <= 0 || height <= 0 || width > 32768 || height > 32768) return AK_ERR_BAD_ARG;
    ak_scene_texture* t = &scene->textures[texture_index];
    akp_free(&scene->alloc, t->pixels);
    t->pixels = NULL;
    t->width = t->height = 0;
    t->pixels = (uint8_t*)akp_calloc(&scene->alloc, (size_t)width * (size_t)height * 4u);
    if (!t->pixels) return AK_ERR_NO_MEMORY;
    t->width = width;
    t->height = height;
    return AK_OK;
}

void ak_scene_destroy(ak_scene* scene) {
    if (!scene) return;
    ak_allocator a = scene->alloc;
    ak_skeleton_destroy(scene->skeleton);
    for (size_t i = 0; i < scene->mesh_count; ++i)
        if (!scene->meshes[i].shares_mesh) ak_mesh_destroy(scene->meshes[i].mesh);
    for (size_t i = 0; i < scene->skin_count; ++i) {
        akp_free(&a, scene->skins[i].joints);
        akp_free(&a, scene->skins[i].inverse_binds);
    }
    for (size_t i = 0; i < scene->clip_count; ++i) ak_clip_destroy(scene->clips[i]);
    free_textures(scene);
    akp_free(&a, scene->meshes);
    akp_free(&a, scene->skins);
    akp_free(&a, scene->clips);
    akp_free(&a, scene->is_joint);
    akp_free(&a, scene);
}

size_t ak_scene_joint_count(const ak_scene* scene) {
    return (scene && scene->skeleton) ? ak_skeleton_joint_count(scene->skeleton) : 0;
}

int ak_scene_find_clip(const ak_scene* scene, const char* name_or_index) {
    if (!scene || scene->clip_count == 0) return -1;
    if (!name_or_index || !*name_or_index) return 0;
    for (size_t i = 0; i < scene->clip_count; ++i)
        if (scene->clips[i] && strcmp(ak_clip_name(scene->clips[i]), name_or_index) == 0) return (int)i;
    bool digits = true;
    for (const char* p = name_or_index; *p; ++p) digits = digits && isdigit((unsigned char)*p);
    if (digits && strlen(name_or_index) < 9) {
        long v = strtol(name_or_index, NULL, 10);
        if (v >= 0 && (size_t)v < scene->clip_count) return (int)v;
    }
    return -1;
}

ak_result ak_scene_rest_pose(const ak_scene* scene, ak_transform_span out_local) {
    if (!scene || !scene->skeleton || !out_local.ptr) return AK_ERR_NULL_ARG;
    ak_transform_cspan rest = ak_skeleton_rest_pose(scene->skeleton);
    if (out_local.count < rest.count) return AK_ERR_SPAN_SMALL;
    memcpy(out_local.ptr, rest.ptr, rest.count * sizeof(ak_transform));
    return AK_OK;
}

ak_result ak_scene_world_matrices(const ak_scene* scene, ak_transform_cspan local, ak_mat4_span out_world) {
    if (!scene || !scene->skeleton) return AK_ERR_NULL_ARG;
    return ak_skeleton_local_to_model(scene->skeleton, local, out_world);
}

ak_result ak_scene_skin_palette(const ak_scene* scene, size_t skin_index, ak_mat4_cspan world,
                                ak_mat4_span out_palette) {
    if (!scene || !world.ptr || !out_palette.ptr) return AK_ERR_NULL_ARG;
    if (skin_index >= scene->skin_count) return AK_ERR_BAD_INDEX;
    const ak_scene_skin* sk = &scene->skins[skin_index];
    if (out_palette.count < sk->joint_count) return AK_ERR_SPAN_SMALL;
    for (size_t k = 0; k < sk->joint_count; ++k) {
        int32_t j = sk->joints[k];
        if (j < 0 || (size_t)j >= world.count) return AK_ERR_BAD_INDEX;
        out_palette.ptr[k] = ak_mat4_mul(world.ptr[j], sk->inverse_binds[k]);
    }
    return AK_OK;
}

void ak_scene_bounds(const ak_scene* scene, ak_vec3* out_min, ak_vec3* out_max) {
    ak_vec3 lo = ak_vec3_splat(INFINITY), hi = ak_vec3_splat(-INFINITY);
    size_t n = ak_scene_joint_count(scene);
    ak_mat4* world = NULL;
    if (n) {
        ak_transform_cspan rest = ak_skeleton_rest_pose(scene->skeleton);
        world = (ak_mat4*)akp_alloc(&scene->alloc, n * sizeof(ak_mat4));
        if (world) ak_skeleton_local_to_model(scene->skeleton, rest, (ak_mat4_span){world, n});
    }
    bool any = false;
    for (size_t m = 0; scene && m < scene->mesh_count; ++m) {
        const ak_scene_mesh* sm = &scene->meshes[m];
        if (!sm->mesh) continue;
        ak_mat4 place = ak_mat4_identity();
        if (sm->skin < 0 && sm->node >= 0 && world && (size_t)sm->node < n) place = world[sm->node];
        for (size_t v = 0; v < sm->mesh->vertex_count; ++v) {
            ak_vec3 p = ak_mat4_transform_point(place, sm->mesh->positions[v]);
            if (!ak_vec3_is_finite(p)) continue;
            lo = ak_vec3_min(lo, p);
            hi = ak_vec3_max(hi, p);
            any = true;
        }
    }
    if (!any && world) {
        for (size_t j = 0; j < n; ++j) {
            ak_vec3 p = ak_mat4_get_translation(world[j]);
            if (!ak_vec3_is_finite(p)) continue;
            lo = ak_vec3_min(lo, p);
            hi = ak_vec3_max(hi, p);
            any = true;
        }
    }
    if (world) akp_free(&scene->alloc, world);
    if (!any) lo = hi = ak_vec3_zero();
    if (out_min) *out_min = lo;
    if (out_max) *out_max = hi;
}

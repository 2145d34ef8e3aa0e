/* animkit scene: a skeleton, the meshes it carries, their skins, and clips, as one value.
 *
 * What it does: the common shape of everything a file or a built-in model provides, so
 * tools handle "FILE or builtin:NAME" the same way. The model follows glTF 2.0: every node
 * of the scene (joints and the nodes between them, mesh nodes) is a joint of one skeleton,
 * stored parents before children; a skin lists which skeleton joints drive a mesh and their
 * inverse bind matrices; a mesh's per-vertex joint indices refer to slots of its skin.
 * Posing, exactly as glTF defines it:
 *     world = FK(local pose)                              (ak_scene_world_matrices)
 *     palette[k] = world[skin.joints[k]] * skin.inverse_binds[k]   (ak_scene_skin_palette)
 *     skinned vertex = sum_k w_k palette[joint_k] p       (the mesh node's own transform ignored)
 *     unskinned mesh vertex = world[mesh.node] p          (mesh.node -1 -> identity)
 * Morph targets come before skinning: clips address one flat array of morph weights, in which
 * target t of scene mesh m has index sum_{k<m} meshes[k].mesh->morph_target_count + t; its
 * default is meshes[m].mesh->morph_weights[t].
 *
 * What it does NOT do: read files (io.h), make models (builtin.h), deform (skin.h, blendshape.h).
 *
 * Usage:
 *     ak_scene* scene = ...;                        // from ak_io_load or ak_builtin_create
 *     size_t n = ak_skeleton_joint_count(scene->skeleton);
 *     ak_transform* local = malloc(n * sizeof *local);
 *     ak_mat4* world = malloc(n * sizeof *world);
 *     ak_scene_rest_pose(scene, (ak_transform_span){local, n});
 *     ak_clip_sample(scene->clips[0], 0.5f, NULL, (ak_transform_span){local, n}, ...);
 *     ak_scene_world_matrices(scene, (ak_transform_cspan){local, n}, (ak_mat4_span){world, n});
 *     ak_mat4 palette[64];
 *     ak_scene_skin_palette(scene, 0, (ak_mat4_cspan){world, n}, (ak_mat4_span)AK_SPAN(palette));
 *     // then skin.h's job with .palette = {palette, scene->skins[0].joint_count}
 *     // (the whole path as a program: examples/skin_gltf_minimal.c)
 *     ak_scene_destroy(scene);
 *
 * Ownership: a scene owns its skeleton, meshes, skins and clips and frees them all in
 * ak_scene_destroy, through the allocator it was made with. Read-only after it is returned;
 * safe to share between threads.
 */
#ifndef ANIMKIT_SCENE_H
#define ANIMKIT_SCENE_H

#include "clip.h"
#include "mesh.h"
#include "skeleton.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Which skeleton joints drive a skinned mesh (a glTF skin). */
typedef struct ak_scene_skin {
    char name[AK_NAME_SIZE];
    size_t joint_count;     /* slots */
    int32_t* joints;        /* [joint_count] skeleton joint index per slot */
    ak_mat4* inverse_binds; /* [joint_count] model-space inverse bind matrices */
} ak_scene_skin;

/* One mesh (one glTF primitive) placed in the scene. */
typedef struct ak_scene_mesh {
    ak_mesh* mesh; /* owned; mesh->joints index skin slots */
    int32_t node;  /* skeleton joint carrying the mesh, -1 -> identity */
    int32_t skin;  /* index into scene->skins, -1 -> unskinned */
    bool has_material;  /* glTF: the primitive names a material; false -> none */
    ak_vec4 base_color; /* that material's pbrMetallicRoughness.baseColorFactor (linear RGBA,
                           (1,1,1,1) when it gives none); unused when has_material is false */
} ak_scene_mesh;

typedef struct ak_scene {
    char name[AK_NAME_SIZE];  /* file name or "builtin:NAME" */
    ak_skeleton* skeleton;    /* every node; NULL only when the scene has no nodes */
    ak_scene_mesh* meshes;    /* [mesh_count], file order */
    size_t mesh_count;
    ak_scene_skin* skins;     /* [skin_count] */
    size_t skin_count;
    ak_clip** clips;          /* [clip_count], file order */
    size_t clip_count;
    bool* is_joint;           /* [joint count of skeleton]: true for joints used by a skin
                                 (false for plain nodes); NULL -> all are joints */
    ak_allocator alloc;       /* the allocator everything above was made with */
} ak_scene;

/* Allocate an empty scene with zeroed arrays of the given sizes (meshes, skins, clips).
 * The producer (importer, builtin) then fills them. Returns AK_ERR_NULL_ARG, AK_ERR_NO_MEMORY. */
AK_API ak_result ak_scene_alloc(size_t mesh_count, size_t skin_count, size_t clip_count,
                                const ak_allocator* alloc, ak_scene** out_scene);
/* Allocate the arrays of one skin (joints, inverse_binds) for joint_count slots. */
AK_API ak_result ak_scene_skin_alloc(ak_scene* scene, size_t skin_index, size_t joint_count);
/* Free the scene and everything it owns; NULL is a no-op. */
AK_API void ak_scene_destroy(ak_scene* scene);

/* Number of skeleton joints (0 when there is no skeleton). */
AK_API size_t ak_scene_joint_count(const ak_scene* scene);

/* Clip by name, or by decimal index when name_or_index is all digits; -1 when absent.
 * NULL or "" -> 0 when the scene has clips, else -1. */
AK_API int ak_scene_find_clip(const ak_scene* scene, const char* name_or_index);

/* Copy the skeleton's rest (bind) pose into out_local (count >= joint count).
 * Returns AK_ERR_NULL_ARG, AK_ERR_SPAN_SMALL. */
AK_API ak_result ak_scene_rest_pose(const ak_scene* scene, ak_transform_span out_local);

/* World (model-space) matrix of every node from local transforms (FK).
 * Returns AK_ERR_NULL_ARG, AK_ERR_SPAN_SMALL. */
AK_API ak_result ak_scene_world_matrices(const ak_scene* scene, ak_transform_cspan local, ak_mat4_span out_world);

/* Skinning palette of skin skin_index: out_palette[k] = world[joints[k]] * inverse_binds[k].
 * out_palette.count >= skin joint_count. This is the palette a scene mesh's joint indices
 * (skin slots) address: pass it to the skin job (skin.h) as {palette, skin joint_count}.
 * ak_skeleton_skinning_matrices, indexed by skeleton joint, does not fit loaded scenes and
 * refuses them (AK_ERR_UNSUPPORTED). Returns AK_ERR_NULL_ARG, AK_ERR_BAD_INDEX,
 * AK_ERR_SPAN_SMALL. */
AK_API ak_result ak_scene_skin_palette(const ak_scene* scene, size_t skin_index, ak_mat4_cspan world,
                                       ak_mat4_span out_palette);

/* Model-space bounding box of every mesh in its bind/rest placement (skinned meshes as given,
 * unskinned moved by their node's rest world matrix). No meshes: the joints' positions.
 * Temporary memory comes from the scene's allocator; NULL scene or no data -> zeros. */
AK_API void ak_scene_bounds(const ak_scene* scene, ak_vec3* out_min, ak_vec3* out_max);

#ifdef __cplusplus
}
#endif
#endif /* ANIMKIT_SCENE_H */

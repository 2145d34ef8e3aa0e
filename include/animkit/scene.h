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
 * Also bakes per-frame results (a cloth's vertices, particles) into an animated scene that io.h
 * writes (ak_scene_bake_mesh_frames, ak_scene_bake_point_frames).
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

/* How texture coordinates outside [0, 1] are mapped (glTF sampler wrapS / wrapT). */
typedef enum ak_texture_wrap {
    AK_TEXTURE_WRAP_REPEAT = 0, /* glTF 10497, the default: the fractional part */
    AK_TEXTURE_WRAP_CLAMP,      /* glTF 33071 CLAMP_TO_EDGE */
    AK_TEXTURE_WRAP_MIRROR      /* glTF 33648 MIRRORED_REPEAT */
} ak_texture_wrap;

/* How a texture is sampled between texels (glTF magFilter / minFilter; a mipmap minFilter,
 * 9984..9987, reads as LINEAR: mipmaps are not built, and bilinear comes closer to their
 * averaged look than the nearest texel). */
typedef enum ak_texture_filter {
    AK_TEXTURE_FILTER_LINEAR = 0, /* bilinear, the default when the sampler names none */
    AK_TEXTURE_FILTER_NEAREST     /* the texel under the point */
} ak_texture_filter;

/* A decoded base-colour texture (a glTF texture: its image and sampler; an OBJ map_Kd). */
typedef struct ak_scene_texture {
    char name[AK_NAME_SIZE]; /* the image's name or file name, "" when it has none */
    int width, height;       /* texels; 0 when the texture is absent (pixels NULL) */
    uint8_t* pixels;         /* [width * height * 4] RGBA8, sRGB colour, straight alpha, rows
                                top to bottom (texture coordinate (0, 0) is the top-left
                                corner, glTF's rule), owned by the scene; NULL -> absent (a
                                texture no material uses, or an image that failed to decode:
                                the loader warned) */
    ak_texture_wrap wrap_s, wrap_t;
    ak_texture_filter mag_filter, min_filter;
} ak_scene_texture;

/* One mesh (one glTF primitive) placed in the scene. Several entries may place one mesh
 * (instances: each with its own node, skin and material): the first entry with that pointer
 * owns it, the later ones set shares_mesh. ak_io_save writes an instanced mesh's data once. */
typedef struct ak_scene_mesh {
    ak_mesh* mesh; /* owned (unless shares_mesh); mesh->joints index skin slots */
    int32_t node;  /* skeleton joint carrying the mesh, -1 -> identity */
    int32_t skin;  /* index into scene->skins, -1 -> unskinned */
    bool has_material;  /* glTF: the primitive names a material; false -> none */
    ak_vec4 base_color; /* that material's pbrMetallicRoughness.baseColorFactor (linear RGBA,
                           (1,1,1,1) when it gives none); unused when has_material is false */
    int32_t texture;    /* base colour texture: index into scene->textures (its texels are
                           multiplied by base_color; texture coordinates are the mesh's uvs),
                           -1 -> none (ak_scene_alloc sets -1) */
    bool shares_mesh;   /* true: mesh is an earlier entry's (the same pointer), which owns it;
                           ak_scene_destroy frees only the owner's. false: this entry owns it */
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
    ak_scene_texture* textures; /* [texture_count] (ak_scene_texture_alloc); NULL when none */
    size_t texture_count;
    ak_allocator alloc;       /* the allocator everything above was made with */
} ak_scene;

/* Allocate an empty scene with zeroed arrays of the given sizes (meshes, skins, clips).
 * The producer (importer, builtin) then fills them. Returns AK_ERR_NULL_ARG, AK_ERR_NO_MEMORY. */
AK_API ak_result ak_scene_alloc(size_t mesh_count, size_t skin_count, size_t clip_count,
                                const ak_allocator* alloc, ak_scene** out_scene);
/* Allocate the arrays of one skin (joints, inverse_binds) for joint_count slots. */
AK_API ak_result ak_scene_skin_alloc(ak_scene* scene, size_t skin_index, size_t joint_count);
/* Give the scene texture_count empty textures (pixels NULL, REPEAT, LINEAR), replacing any it
 * had. Returns AK_ERR_NULL_ARG, AK_ERR_NO_MEMORY. */
AK_API ak_result ak_scene_texture_alloc(ak_scene* scene, size_t texture_count);
/* Allocate texture texture_index's pixels (width * height * 4 bytes, zeroed) through the
 * scene's allocator, replacing any it had. Returns AK_ERR_NULL_ARG, AK_ERR_BAD_INDEX,
 * AK_ERR_BAD_ARG (a size <= 0, or above 32768), AK_ERR_NO_MEMORY. */
AK_API ak_result ak_scene_texture_alloc_pixels(ak_scene* scene, size_t texture_index, int width, int height);
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

/* ---- baking computed motion (simulations) into a scene -------------------------------------
 * Two ways to turn per-frame results into an animated scene that io.h's ak_io_save writes as
 * glTF (docs/io.md "Baking simulations"); neither knows a file format, and the simulation
 * modules know neither:
 *   - ak_scene_bake_mesh_frames, for a deforming mesh (cloth): MORPH-TARGET animation. The
 *     frames are cut into blocks of up to AK_SCENE_BAKE_TARGETS_PER_MESH frames (the most
 *     components a clip channel holds): block b is one scene mesh on its own node, its base
 *     positions are frame s = 64 b and its targets t = 0..63 hold frames s+1+t as deltas from
 *     frame s; a weights channel keys frame s at weights 0 and frame s+1+t at weight 1 on target
 *     t (0 elsewhere), so frame k shows exactly frame k, and between frames LINEAR weights give
 *     the linear blend of the two frames (STEP holds the earlier one). Block b's node has a STEP
 *     scale channel: 1 from time s to the time of its last frame (exclusive, except for the
 *     last block), 0 elsewhere, so exactly one block is visible at any time. One block (65
 *     frames or fewer) has no scale channel. Nodes: a root named desc->name with one child
 *     "<name>_<b>" per block, all with identity rest transforms.
 *   - ak_scene_bake_point_frames, for particles: PER-NODE animation. One root node named
 *     desc->name and one child node "<name>_<id>" per distinct particle id (ascending id), with
 *     a translation channel keyed at the frames where the particle exists (LINEAR or STEP) and,
 *     when it is missing from some frame, a STEP scale channel that is 0 while it is missing
 *     (before its birth, after its death) and 1 while it exists. Rest translation = its first
 *     position. With marker_size > 0 every particle node carries a small octahedron mesh
 *     (6 vertices, radius marker_size) so engines draw it; 0 -> bare nodes.
 * Frame k is at time k * frame_time; the clip (named desc->name) lasts
 * (frame_count - 1) * frame_time. One frame gives the scene without a clip.
 * Bounds: at most max_frames frames (0 -> AK_SCENE_BAKE_MAX_FRAMES) and, for points, at most
 * max_points distinct ids (0 -> AK_SCENE_BAKE_MAX_POINTS, never above 32000); the bytes the
 * scene and its temporaries need are estimated before anything is allocated and must fit
 * memory_budget (0 -> AK_SCENE_BAKE_DEFAULT_BUDGET). Over any bound: AK_ERR_UNSUPPORTED
 * with the numbers in diag; nothing is allocated. */
#define AK_SCENE_BAKE_TARGETS_PER_MESH 64u
#define AK_SCENE_BAKE_MAX_FRAMES 4096u
#define AK_SCENE_BAKE_MAX_POINTS 16384u
#define AK_SCENE_BAKE_DEFAULT_BUDGET ((size_t)512 << 20)

/* A deforming mesh over frames (frame-major arrays). */
typedef struct ak_scene_bake_mesh_desc {
    const char* name;            /* scene, root node, mesh and clip name; NULL -> "bake" */
    size_t vertex_count;         /* required, > 0 */
    size_t frame_count;          /* required, 1 .. max_frames */
    const ak_vec3* positions;    /* required, [frame_count * vertex_count], frame k first */
    const ak_vec3* normals;      /* optional, same layout: base NORMAL + morph NORMAL deltas */
    ak_u32_cspan indices;        /* triangle list (count a multiple of 3, each < vertex_count);
                                    empty -> a point cloud */
    float frame_time;            /* required, > 0 seconds between frames */
    ak_interp interp;            /* weights: 0 or LINEAR (blend between frames) or STEP */
    ak_vec4 base_color;          /* material base colour; all zero -> no material */
    size_t max_frames;           /* 0 -> AK_SCENE_BAKE_MAX_FRAMES */
    size_t memory_budget;        /* 0 -> AK_SCENE_BAKE_DEFAULT_BUDGET */
} ak_scene_bake_mesh_desc;

/* Build a scene (*out_scene, freed with ak_scene_destroy) as described above. The inputs are
 * read only during the call. Returns AK_ERR_NULL_ARG (desc, out_scene or positions NULL, or
 * indices.ptr NULL with a count), AK_ERR_EMPTY (vertex_count or frame_count 0), AK_ERR_BAD_ARG
 * (frame_time not > 0 or not finite, interp other than LINEAR/STEP, an index count not a
 * multiple of 3, (frame_count - 1) * frame_time not finite), AK_ERR_BAD_INDEX (an index out of
 * range), AK_ERR_BAD_DATA (a non-finite position or normal: diag names frame and vertex),
 * AK_ERR_UNSUPPORTED (over a bound), AK_ERR_NO_MEMORY. */
AK_API ak_result ak_scene_bake_mesh_frames(const ak_scene_bake_mesh_desc* desc, const ak_allocator* alloc,
                                           ak_scene** out_scene, ak_diag* diag);

/* One frame of a point set: count points with their ids (unique within the frame). */
typedef struct ak_scene_bake_points {
    const ak_vec3* positions; /* [count] */
    const uint32_t* ids;      /* [count]: the same id in two frames is the same point */
    size_t count;             /* 0 -> no point in this frame (pointers may be NULL) */
} ak_scene_bake_points;

typedef struct ak_scene_bake_points_desc {
    const char* name;                    /* NULL -> "particles" */
    const ak_scene_bake_points* frames;  /* required, [frame_count] */
    size_t frame_count;                  /* required, 1 .. max_frames */
    float frame_time;                    /* required, > 0 */
    ak_interp interp;                    /* translations: 0 or LINEAR, or STEP */
    float marker_size;                   /* >= 0: octahedron radius per node, 0 -> no mesh */
    size_t max_frames;                   /* 0 -> AK_SCENE_BAKE_MAX_FRAMES */
    size_t max_points;                   /* 0 -> AK_SCENE_BAKE_MAX_POINTS; at most 32000 */
    size_t memory_budget;                /* 0 -> AK_SCENE_BAKE_DEFAULT_BUDGET */
} ak_scene_bake_points_desc;

/* Build a scene of per-particle nodes as described above. No point in any frame gives the
 * root node alone and no clip. Returns the codes of ak_scene_bake_mesh_frames, plus
 * AK_ERR_NULL_ARG (frames NULL, or a frame with a count and a NULL array), AK_ERR_DUPLICATE
 * (an id twice in one frame), AK_ERR_BAD_ARG (marker_size negative or not finite, max_points
 * above 32000). */
AK_API ak_result ak_scene_bake_point_frames(const ak_scene_bake_points_desc* desc, const ak_allocator* alloc,
                                            ak_scene** out_scene, ak_diag* diag);

#ifdef __cplusplus
}
#endif
#endif /* ANIMKIT_SCENE_H */

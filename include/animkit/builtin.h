/* animkit builtin: procedurally generated test characters, no files needed.
 *
 * What it does: builds an ak_scene (scene.h) shaped exactly like an imported file: one
 * skeleton, one skinned mesh (node -1, skin 0, every vertex limited to 4 influences and
 * normalised), one skin whose slots are the skeleton's joints in order (slot k = joint k)
 * with inverse binds = inverse of the rest model matrices, and clips built with
 * ak_clip_build from keyframes written in code. Units are metres and seconds, +Y up, the
 * humanoid faces +Z (so its left is +X, as in glTF).
 *
 *   "builtin:cylinder" (or "cylinder"): a closed, capped tube of radius `radius` from y = 0
 *     to y = `length` along +Y, `rings` x `segments` quads on the side and a triangle fan on
 *     each cap. A chain of `bone_count` bones runs up the axis: joints "root" (y = 0),
 *     "joint1", ... and a leaf "tip" (y = length) that drives no vertex. Weights blend
 *     between consecutive bones with a smoothstep over a band of `blend` x bone length
 *     centred on each interior joint (at most 2 non-zero influences per vertex). Interior
 *     joints are AK_JOINT_BALL (twist axis +Y, cone 150 degrees, twist unlimited).
 *     Clips (1 s each, 5 keys, SLERP): "bend" rotates the interior joints about +Z so the
 *     chain bends 0 -> 120 degrees in total (split equally between interior joints),
 *     "twist" rotates them about +Y by 0 -> 180 degrees in total, "bend_twist" does both.
 *     These are the classic tests of the candy-wrapper and elbow-collapse artifacts.
 *
 *   "builtin:humanoid" (or "humanoid"): 1.8 m figure in an A-pose (arms 45 degrees down),
 *     17 joints: pelvis (root, free), spine_01, spine_02, neck, head (balls), left_/right_
 *     shoulder (balls, 137-degree cone), elbow (hinges, 0..145 degrees of flexion), wrist
 *     (balls), hip (balls, 90-degree cone), knee (hinges about +X, 0..140 degrees), ankle
 *     (hinges about +X, -25..35 degrees, positive tips the toes down). Rest rotations are
 *     the identity, so limit axes are model axes at rest. The mesh is one closed, consistently
 * oriented surface: the zero set of a smooth union of (tapered) capsules, polygonised with marching
 * tetrahedra on a grid of `cell_size`, then relaxed (Laplacian steps projected back onto the
 * surface); normals are the field's gradient. Weights fall off as 1 / d^4, d the distance to each
 * joint's bone segment less 3/4 of the limb's radius there (clamped at 0, softened by 2 cm); limb
 * joints of one side never influence the other side (a smoothstep band 4 cm wide around x = 0
 * separates them). Clips: "walk" (1 s loop, in place: legs and arms swing in opposition, knees bend
 * within their hinge range, the pelvis bobs and yaws) and "wave" (2 s: the right arm rises, waves
 *     three times, and comes back). Every keyed pose respects the joint limits.
 *
 * What it does NOT do: read files (io.h) or deform (skin.h).
 *
 * Usage:
 *     ak_scene* scene = NULL;
 *     ak_builtin_desc desc = { .rings = 64 };                  // zero fields -> defaults
 *     if (ak_builtin_create("builtin:cylinder", &desc, NULL, &scene) != AK_OK) return 1;
 *     const ak_mesh* mesh = scene->meshes[0].mesh;             // skinned, skin 0
 *     int bend = ak_scene_find_clip(scene, "bend");
 *     size_t n = ak_scene_joint_count(scene);
 *     ak_transform local[8];
 *     ak_mat4 world[8], palette[8];
 *     ak_scene_rest_pose(scene, (ak_transform_span){local, n});
 *     ak_clip_sample(scene->clips[bend], 1.0f, NULL, (ak_transform_span){local, n},
 *                    (ak_f32_span){0}, (ak_f32_span){0});
 *     ak_scene_world_matrices(scene, (ak_transform_cspan){local, n}, (ak_mat4_span){world, n});
 *     ak_scene_skin_palette(scene, 0, (ak_mat4_cspan){world, n}, (ak_mat4_span){palette, n});
 *     // ... skin mesh->positions with palette (skin.h) ...
 *     ak_scene_destroy(scene);
 *
 * Ownership and threading: the returned scene is owned by the caller (ak_scene_destroy);
 * creation allocates through the given allocator only (scratch included) and is reentrant.
 */
#ifndef ANIMKIT_BUILTIN_H
#define ANIMKIT_BUILTIN_H

#include "scene.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Options; every zero field takes its default. Fields a model does not use are ignored. */
typedef struct ak_builtin_desc {
    float length;        /* cylinder: metres along +Y; 0 -> 2.0 */
    float radius;        /* cylinder: metres; 0 -> 0.25 */
    uint32_t rings;      /* cylinder: quads along the axis, 1..4096; 0 -> 48 */
    uint32_t segments;   /* cylinder: quads around the axis, 3..4096; 0 -> 32 */
    uint32_t bone_count; /* cylinder: 2 or 3; 0 -> 2 */
    float blend;         /* cylinder: weight blend band across a joint, as a fraction of a
                            bone's length, in (0, 1]; 0 -> 0.5 */
    float cell_size;     /* humanoid: polygonisation grid spacing in metres, 0.008..0.1;
                            0 -> 0.03 (about 17k triangles) */
} ak_builtin_desc;

/* The desc with every zero field replaced by its default (desc NULL -> all defaults). */
AK_API ak_builtin_desc ak_builtin_desc_resolved(const ak_builtin_desc* desc);

/* Build a built-in model. name: "cylinder" or "humanoid", with or without the "builtin:"
 * prefix. desc NULL -> defaults. Returns AK_ERR_NULL_ARG (name or out_scene NULL),
 * AK_ERR_NOT_FOUND (unknown name), AK_ERR_BAD_ARG (a desc field outside its range, e.g.
 * bone_count 4, negative length, NaN), AK_ERR_NO_MEMORY. *out_scene is NULL on failure. */
AK_API ak_result ak_builtin_create(const char* name, const ak_builtin_desc* desc,
                                   const ak_allocator* alloc, ak_scene** out_scene);

/* Names of the built-in models ("cylinder", "humanoid"), without the prefix; a static
 * table. out_count (optional) receives its length. */
AK_API const char* const* ak_builtin_names(size_t* out_count);

#ifdef __cplusplus
}
#endif
#endif /* ANIMKIT_BUILTIN_H */

/* animkit retarget: put a clip made for one skeleton onto another (mocap onto a character).
 *
 * What it does:
 *   - maps target joints to source joints automatically: both skeletons fitted to a humanoid
 *     template by topology, rest-pose geometry and name hints (ak_humanoid_roles_find), then
 *     paired bone by bone (ak_retarget_map_by_roles), with a report that is a map file
 *     (ak_retarget_map_write); a skeleton that is not a humanoid (a quadruped) is reported so;
 *   - or maps target joints to source joints by name: the same name (case and "prefix:" such as
 *     "mixamorig:" ignored, and never two joints the rules below give different humanoid
 *     bones: builtin:humanoid's left_shoulder is an upper arm, a CMU LeftShoulder a collarbone)
 *     first, then humanoid bones recognised in CMU/BVH, Mixamo, Unreal
 *     mannequin, VRM humanoid and animkit's builtin humanoid names (ak_humanoid_bone_of_name),
 *     left/right written as Left/Right/L/R prefixes or _l/_r/.L/.R suffixes; or a caller's map;
 *   - transfers rotations as deltas from each skeleton's rest pose in the common model
 *     ("world") frame: for a mapped pair (source j, target k) at time t,
 *         W_t[k](t) = D_j(t) * C_k * W_t[k](rest),   D_j(t) = W_s[j](t) * W_s[j](rest)^-1,
 *     where W are model-space rotations and C_k turns the target's rest bone direction (k to
 *     its first mapped child) onto the source's (j to that child's source joint), so a T-pose
 *     source drives an A-pose target with the same bone directions (C = identity for the
 *     root-motion joint and for joints without a mapped child they take their parent's C);
 *     the target's local rotation follows from its parent's model rotation;
 *   - keeps the target's own bone lengths (local translations of every joint but the root
 *     joint stay at its rest pose); moves the root joint (the hips, else the first mapped
 *     joint) by the source's displacement from its rest position scaled by the ratio of leg
 *     lengths (target / source, hip to knee to ankle; the root's rest height when legs are
 *     not mapped), or unscaled; when both feet are mapped, the clip is then grounded: moved up or down by the one offset that brings the target's
 *     lowest ankle over the clip to its lowest ankle at rest (a BVH's rest pose has the hips at
 *     the origin while its motion carries them at hip height: the rest displacement alone
 *     counted that height twice);
 *   - optionally cleans up foot contacts: a source foot is in contact at a frame when its
 *     height above its lowest point in the clip is below contact_height and its horizontal
 *     speed below contact_speed; during each run of contact frames the target foot is pinned
 *     at its mean position over the run with the two-bone IK (upper leg, lower leg, foot; the
 *     foot keeps its model-space rotation); a pin out of the leg's reach stretches the leg
 *     towards it (ak_retarget_stats.unreached_frames);
 *   - bakes the result at frame_rate into a clip for the target (ak_clip_bake).
 * Both skeletons are assumed to share the up axis and facing direction of their model space.
 *
 *   - parses map files ("TARGET_JOINT = SOURCE_JOINT" lines, ak_retarget_map_parse) from
 *     memory, with the line of the first problem in an ak_diag.
 * What it does NOT do: read files (the CLI reads map files, refusing FIFOs), morph weights,
 * translation animation of non-root joints (target bone lengths are kept), joint limits.
 *
 * Usage:
 *     int32_t map[128];                                   // >= target joint count
 *     ak_retarget_map_by_name(src->skeleton, dst->skeleton, (ak_i32_span)AK_SPAN(map));
 *     ak_retarget_desc d = {
 *         .source = src->skeleton, .clip = src->clips[0], .target = dst->skeleton,
 *         .source_of_target = {map, ak_skeleton_joint_count(dst->skeleton)},
 *     };
 *     ak_clip* clip = NULL;
 *     ak_diag diag;
 *     if (ak_retarget_clip(&d, NULL, &clip, NULL, &diag) != AK_OK) puts(diag.message);
 *     // sample clip on dst's skeleton, or put it in dst->clips and ak_io_save(...)
 *     ak_clip_destroy(clip);
 *
 * Ownership and threading: nothing is kept after a call; reentrant.
 */
#ifndef ANIMKIT_RETARGET_H
#define ANIMKIT_RETARGET_H

#include "clip.h"
#include "skeleton.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Humanoid bones recognised by name (each names the joint that rotates that bone). */
typedef enum ak_humanoid_bone {
    AK_BONE_NONE = 0,
    AK_BONE_HIPS,
    AK_BONE_SPINE, AK_BONE_CHEST, AK_BONE_UPPER_CHEST, AK_BONE_NECK, AK_BONE_HEAD,
    AK_BONE_LEFT_SHOULDER, AK_BONE_LEFT_UPPER_ARM, AK_BONE_LEFT_LOWER_ARM, AK_BONE_LEFT_HAND,
    AK_BONE_RIGHT_SHOULDER, AK_BONE_RIGHT_UPPER_ARM, AK_BONE_RIGHT_LOWER_ARM, AK_BONE_RIGHT_HAND,
    AK_BONE_LEFT_UPPER_LEG, AK_BONE_LEFT_LOWER_LEG, AK_BONE_LEFT_FOOT, AK_BONE_LEFT_TOES,
    AK_BONE_RIGHT_UPPER_LEG, AK_BONE_RIGHT_LOWER_LEG, AK_BONE_RIGHT_FOOT, AK_BONE_RIGHT_TOES,
    AK_BONE_COUNT
} ak_humanoid_bone;

/* VRM-style name of a bone ("hips", "leftUpperArm", ...); "none" out of range; never NULL. */
AK_API const char* ak_humanoid_bone_name(ak_humanoid_bone bone);

/* Bone a joint name stands for, from the name alone (AK_BONE_NONE when not recognised).
 * Spine joints give AK_BONE_SPINE; ak_humanoid_bones_of_skeleton numbers them by hierarchy. */
AK_API ak_humanoid_bone ak_humanoid_bone_of_name(const char* name);

/* Bone of every joint of a skeleton: names (ak_humanoid_bone_of_name), then the hierarchy:
 * spine joints between the hips and the neck become SPINE, CHEST, UPPER_CHEST in order (the
 * rest NONE); a SHOULDER whose child is the LOWER_ARM is the UPPER_ARM (animkit's builtin
 * "left_shoulder" is the shoulder joint of the arm); each bone goes to the first joint (by
 * index) that claims it. out_bones.count >= joint count.
 * Returns AK_ERR_NULL_ARG, AK_ERR_SPAN_SMALL. */
AK_API ak_result ak_humanoid_bones_of_skeleton(const ak_skeleton* skeleton, ak_i32_span out_bones);

/* Source joint for every target joint (-1: unmapped, keeps its rest pose): the same joint name
 * (case-insensitive, anything up to the last ':' dropped) first, then the same humanoid bone
 * (ak_humanoid_bones_of_skeleton on both); a source joint is used once.
 * out_source_of_target.count >= target joint count. Temporary memory (one bone array per
 * skeleton) comes from malloc. Returns AK_ERR_NULL_ARG, AK_ERR_SPAN_SMALL, AK_ERR_NO_MEMORY;
 * *out_mapped_count (optional) = target joints mapped. */
AK_API ak_result ak_retarget_map_by_name(const ak_skeleton* source, const ak_skeleton* target,
                                         ak_i32_span out_source_of_target, size_t* out_mapped_count);

/* Parse a map file's text into out_source_of_target (every entry -1 first, then
 * out[target joint] = source joint for each line). Format: one "TARGET_JOINT = SOURCE_JOINT" a
 * line; '#' starts a comment; blank lines are skipped; spaces and tabs around the names and a
 * CR before the newline are dropped; names are matched exactly (ak_skeleton_find_joint). The
 * text need not end in a newline. out_source_of_target.count >= target joint count.
 * Returns AK_ERR_NULL_ARG (a skeleton or the span NULL, or text NULL with text_size > 0),
 * AK_ERR_SPAN_SMALL, AK_ERR_PARSE (a line holds a NUL byte, has no '=', an empty name or a name
 * of AK_NAME_SIZE bytes or more), AK_ERR_NOT_FOUND (a name is not a joint of its skeleton),
 * AK_ERR_DUPLICATE (a target joint mapped twice), AK_ERR_EMPTY (no line maps a joint). diag
 * (optional; its path is left empty) gets "line N: problem" ("line N holds a NUL byte") with
 * diag->line = N (0 for AK_ERR_EMPTY). *out_mapped_count (optional) = lines mapped, 0 on error.
 * Allocates nothing; reentrant. */
AK_API ak_result ak_retarget_map_parse(const char* text, size_t text_size, const ak_skeleton* source,
                                       const ak_skeleton* target, ak_i32_span out_source_of_target,
                                       size_t* out_mapped_count, ak_diag* diag);

/* How a skeleton's joints fill the humanoid template (ak_humanoid_roles_find). */
typedef enum ak_humanoid_sides {
    AK_SIDES_NONE = 0,   /* no limbs found: sides not decided */
    AK_SIDES_TOES,       /* from the rest pose: toes point forward, left = up x forward */
    AK_SIDES_NAMES,      /* from the names (Left/L/_l ...): the rig has no toes */
    AK_SIDES_CONVENTION  /* neither: glTF's convention, the model faces +Z (left = up x +Z) */
} ak_humanoid_sides;

typedef struct ak_humanoid_roles {
    int32_t joint[AK_BONE_COUNT];     /* joint playing each bone, -1 none ([AK_BONE_NONE] = -1) */
    float confidence[AK_BONE_COUNT];  /* 0 (none) .. 1: 1 = topology, geometry and the name
                                         agree; 0.8 = the name says nothing (or only the limb
                                         or the side); 0.5 = the name says another bone or
                                         the other side */
    int32_t name_bone[AK_BONE_COUNT]; /* what the joint's name alone says (ak_humanoid_bone) */
    float score;             /* mean confidence over the 15 required bones (0 .. 1) */
    bool is_humanoid;        /* every required bone found and the rest pose stands upright */
    ak_vec3 up;              /* model-space up: from the feet towards the head (unit) */
    ak_vec3 forward;         /* model-space facing direction (unit, perpendicular to up) */
    ak_humanoid_sides sides; /* what decided left from right */
    float spine_angle;       /* degrees between hips->head and the legs' upward direction */
    float hand_height;       /* lowest hand's height above the hips, in leg lengths */
} ak_humanoid_roles;

/* Find the humanoid template in a skeleton's rest pose, the way engines auto-map avatars:
 *   - topology: the hips are the shallowest joint with two leg chains (subtrees of >= 3
 *     joints, the pair of most similar length) and a spine subtree holding a chest: the
 *     shallowest joint with two arm chains (the most similar pair of >= 3-joint subtrees) and a
 *     neck/head chain (the remaining child pointing most along hips -> chest); each chain
 *     follows, from joint to joint, the child with the longest path below it;
 *   - geometry (rest pose, joints at one position merged into the first): along a limb the
 *     upper and lower bone are the two consecutive bones of largest total length whose lengths
 *     are within a factor 2.5 of each other and after which comes a bone shorter than 0.6 of
 *     the lower one (the hand or foot) or nothing; the joint before the upper arm is the
 *     shoulder (clavicle), the one after the foot the toes; spine joints between the hips and the
 *     chest become SPINE (first), CHEST (next to last) and UPPER_CHEST (last, the one the arms
 *     hang from) when there are three or more, SPINE, CHEST for two, SPINE for one; the
 *     neck is the first joint of the head chain, the head its last (its parent when the last
 *     is an "end"/"top" leaf, or the joint named head);
 *   - up = feet towards head; left vs right: the toes give the facing direction (left = up x
 *     forward), else the names (Left/Right/L/R/_l/_r ...), else glTF's +Z facing;
 *   - names (ak_humanoid_bones_of_skeleton, plus "arm"/"leg"/"spine"... words and L/R tokens
 *     for rigs such as CesiumMan's "leg_joint_L_1") only grade each role's confidence.
 * A humanoid also stands: hips -> head within 45 degrees of the legs' upward direction and
 * the hands no lower than 0.8 leg lengths below the hips (a quadruped's spine is horizontal
 * and its front paws stand on the floor).
 * Returns AK_OK for a humanoid; AK_ERR_NOT_FOUND when the template does not fit (out holds
 * what was found, is_humanoid false; diag says what is missing or why it is not a humanoid);
 * AK_ERR_NULL_ARG, AK_ERR_BAD_DATA (a rest position not finite), AK_ERR_NO_MEMORY. Temporary
 * memory (about 110 bytes a joint) from alloc (NULL: malloc/free). Reentrant. */
AK_API ak_result ak_humanoid_roles_find(const ak_skeleton* skeleton, const ak_allocator* alloc, ak_humanoid_roles* out,
                                        ak_diag* diag);

/* Source joint for every target joint by humanoid role: out[target_roles->joint[b]] =
 * source_roles->joint[b] for every bone b both have, except the torso: the spine joints
 * (SPINE, CHEST, UPPER_CHEST present) are paired bottom to bottom and top to top (the joint
 * the arms hang from drives the joint the arms hang from), the middle ones in proportion.
 * Every other target joint gets -1. out_source_of_target.count >= target joint count.
 * Returns AK_ERR_NULL_ARG, AK_ERR_SPAN_SMALL, AK_ERR_BAD_INDEX (a role's joint out of its
 * skeleton); *out_mapped_count (optional) = target joints mapped. Allocates nothing. */
AK_API ak_result ak_retarget_map_by_roles(const ak_skeleton* source, const ak_humanoid_roles* source_roles,
                                          const ak_skeleton* target, const ak_humanoid_roles* target_roles,
                                          ak_i32_span out_source_of_target, size_t* out_mapped_count);

/* Write a map as text in the map-file format (ak_retarget_map_parse reads it back to the same
 * map): a comment header (the roles' score, up, facing and side evidence when given), then one
 * "TARGET_JOINT = SOURCE_JOINT  # bone  confidence target/source" line per mapped target joint
 * in template order (roles given) or joint order, then comment lines for the template bones
 * one side lacks ("# leftToes: no target joint (source LeftToeBase)"). source_roles and
 * target_roles may be NULL (no bone column). Writes at most buffer_size bytes, NUL-terminated
 * (buffer may be NULL when buffer_size is 0); *out_size (optional) = the text's length without
 * the NUL, as snprintf (a larger buffer is needed when >= buffer_size).
 * Returns AK_ERR_NULL_ARG, AK_ERR_SPAN_SMALL (map shorter than the target), AK_ERR_BAD_INDEX (a
 * map entry or a role's joint out of its skeleton). Allocates nothing; reentrant. */
AK_API ak_result ak_retarget_map_write(const ak_skeleton* source, const ak_humanoid_roles* source_roles,
                                       const ak_skeleton* target, const ak_humanoid_roles* target_roles,
                                       ak_i32_cspan source_of_target, char* buffer, size_t buffer_size,
                                       size_t* out_size);

typedef struct ak_retarget_desc {
    const ak_skeleton* source;     /* required: the skeleton the clip animates */
    const ak_clip* clip;           /* required: a clip of source (joint count <= source's) */
    const ak_skeleton* target;     /* required */
    ak_i32_cspan source_of_target; /* [target joint count] source joint per target joint, -1
                                      unmapped; empty -> ak_retarget_map_by_name */
    float frame_rate;              /* frames per second of the baked result; 0 -> 30 */
    bool unscaled_root_motion;     /* true -> the root moves by the source's displacement as is;
                                      false (default) -> scaled by the leg-length ratio */
    bool skip_foot_contacts;       /* true -> no foot clean-up; false (default) -> pin feet */
    float contact_height;          /* contact: foot height above its lowest point, in source leg
                                      lengths; 0 -> 0.08 */
    float contact_speed;           /* contact: horizontal foot speed, source leg lengths per
                                      second; 0 -> 0.6 */
    const char* name;              /* clip name; NULL -> the source clip's name */
} ak_retarget_desc;

/* What a retarget did. */
typedef struct ak_retarget_stats {
    size_t frame_count;     /* frames baked */
    size_t mapped_count;    /* target joints driven by a source joint */
    int32_t root_joint;     /* target root-motion joint (-1 none) */
    float root_scale;       /* factor applied to the root displacement */
    size_t contact_frames;  /* source foot-frames in contact (both feet counted) */
    size_t pinned_frames;   /* target foot-frames the IK pinned */
    size_t unreached_frames; /* of those, frames the pin was out of the leg's reach (the leg is
                                stretched towards it and the foot slides) */
} ak_retarget_stats;

/* The desc with zero fields replaced by their defaults (NULL -> all defaults). */
AK_API ak_retarget_desc ak_retarget_desc_resolved(const ak_retarget_desc* desc);

/* Retarget desc->clip onto desc->target and bake it (frames at 0, 1/rate, ... up to the clip's
 * duration; the last frame samples the source at its duration). alloc NULL -> malloc/free (temporary arrays and
 * the clip). Returns AK_ERR_NULL_ARG (desc, source, clip, target or out_clip NULL),
 * AK_ERR_SPAN_SMALL (source_of_target shorter than the target's joint count),
 * AK_ERR_BAD_INDEX (a map entry >= the source's joint count or < -1, or the clip addresses
 * more joints than the source has), AK_ERR_NOT_FOUND (no target joint mapped),
 * AK_ERR_BAD_ARG (frame_rate, contact_height or contact_speed negative or not finite),
 * AK_ERR_BAD_DATA (a non-finite pose), AK_ERR_NO_MEMORY. diag (optional) says which.
 * *out_clip is NULL on failure; out_stats optional. */
AK_API ak_result ak_retarget_clip(const ak_retarget_desc* desc, const ak_allocator* alloc, ak_clip** out_clip,
                                  ak_retarget_stats* out_stats, ak_diag* diag);

#ifdef __cplusplus
}
#endif
#endif /* ANIMKIT_RETARGET_H */

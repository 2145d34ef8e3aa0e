/* animkit clip: animation clips, poses, sampling and blending.
 *
 * What it does: a clip is a named set of channels, each a track (curve.h) bound to a joint's
 * local translation, rotation or scale, to a range of morph-target weights, or to a range of
 * free scalar channels, with a duration. ak_clip_build checks an editable ak_raw_clip and
 * builds the immutable runtime clip; ak_clip_sample writes the clip's values at a time into
 * a pose. A pose is an array of local joint transforms (ak_transform) plus morph weights and
 * scalars, all caller-owned. Sampling through a caller-owned cursor makes forward playback
 * O(1) amortised per channel and stays correct for any jump. The module also blends poses
 * (weighted N-way blend, per-joint masks, additive layers, cross-fade) and extracts root
 * motion (a clip walking in place plus the root's horizontal trajectory), bakes a
 * sequence of computed poses into a clip (ak_clip_bake) and removes keys within a model-space
 * tolerance (ak_clip_reduce).
 *
 * glTF: STEP, LINEAR (SLERP for rotations, shortest path) and CUBICSPLINE (tangents scaled by
 * the key interval, rotations renormalised) follow the glTF 2.0 specification, Appendix C.
 * Times before a channel's first key give the first key, after its last key the last key.
 *
 * What it does NOT do: skeletons or model-space matrices (skeleton.h), file formats (io.h),
 * retargeting, or time wrapping inside ak_clip_sample (wrap with ak_time_wrap first).
 *
 * Usage:
 *     ak_clip* clip = NULL;
 *     if (ak_clip_build(&raw, NULL, &clip, &diag) != AK_OK) fprintf(stderr, "%s\n", diag.message);
 *     size_t cn = ak_clip_cursor_storage_count(clip);      // segments + key cache
 *     uint32_t* keys = calloc(cn, sizeof *keys);
 *     ak_clip_cursor cursor;
 *     ak_clip_cursor_init(&cursor, clip, (ak_u32_span){keys, cn});
 *     ak_transform local[32];                              // start from the rest pose
 *     for (int j = 0; j < 32; ++j) local[j] = rest[j];
 *     for (float t = 0.0f; t < 10.0f; t += 1.0f / 60.0f) {
 *         float ct = ak_time_wrap(t, ak_clip_duration(clip), AK_WRAP_LOOP);
 *         ak_clip_sample(clip, ct, &cursor, (ak_transform_span)AK_SPAN(local),
 *                        (ak_f32_span){0}, (ak_f32_span){0});
 *         // ... skeleton local-to-model, skinning ...
 *     }
 *     free(keys);
 *     ak_clip_destroy(clip);
 *
 * Ownership and threading: a built clip is one allocation, immutable, and may be sampled
 * from any number of threads at once, each thread with its own cursor. The raw clip is copied
 * (the caller may free it after the build). Nothing keeps a caller pointer except a cursor,
 * which keeps its clip and storage pointers until re-initialised.
 */
#ifndef ANIMKIT_CLIP_H
#define ANIMKIT_CLIP_H

#include "curve.h"

#ifdef __cplusplus
extern "C" {
#endif

/* What a channel animates. */
typedef enum ak_channel_target {
    AK_CHANNEL_TRANSLATION = 0, /* joint local translation, 3 components */
    AK_CHANNEL_ROTATION,        /* joint local rotation quaternion (x,y,z,w), 4 components */
    AK_CHANNEL_SCALE,           /* joint local scale, 3 components */
    AK_CHANNEL_MORPH_WEIGHTS,   /* morph target weights [index, index + component_count) */
    AK_CHANNEL_SCALAR,          /* free scalar channels [index, index + component_count) */
    AK_CHANNEL_TARGET_COUNT
} ak_channel_target;

/* Editable channel: keys in any order (sorted and checked by ak_clip_build). */
typedef struct ak_raw_channel {
    ak_channel_target target;
    uint32_t index;           /* joint index (T/R/S) or first morph weight / scalar index */
    uint32_t component_count; /* values per key: 3 (T, S), 4 (R), N for weights/scalars;
                                 0 -> 3 for T/S, 4 for R, 1 otherwise */
    ak_interp interp;         /* 0 -> LINEAR (SLERP for rotations) */
    float tension;            /* CARDINAL only: mu, 0 -> 1 (Catmull-Rom) */
    size_t key_count;         /* required, >= 1 */
    const float* times;       /* [key_count] seconds */
    const float* values;      /* [key_count * component_count]; CUBICSPLINE and HERMITE:
                                 [key_count * 3 * component_count] as (in-tangent, value,
                                 out-tangent) per key, glTF order; BEZIER: (value, out-control,
                                 in-control) per key */
} ak_raw_channel;

/* Editable clip. */
typedef struct ak_raw_clip {
    const char* name;               /* NULL -> "" */
    float duration;                 /* seconds; 0 -> last key time over all channels */
    const ak_raw_channel* channels; /* [channel_count] */
    size_t channel_count;
    size_t joint_count;             /* joints the clip may address (index < joint_count) */
    size_t morph_weight_count;      /* morph weights it may address */
    size_t scalar_count;            /* scalar channels it may address */
} ak_raw_clip;

typedef struct ak_clip ak_clip;

/* ---- build and query ---------------------------------------------------------------- */

/* Check a raw clip and build the runtime clip (one allocation through alloc; NULL ->
 * malloc/free). Keys are sorted by time. Rules, first failure returned, with the channel
 * and key in diag (optional):
 *   raw or out_clip NULL, or a channel's times/values NULL        -> AK_ERR_NULL_ARG
 *   channel_count 0, or a channel with key_count 0                 -> AK_ERR_EMPTY
 *   duration negative, target/interp out of range, component_count not 3 for T/S or 4 for
 *   R, above AK_TRACK_MAX_COMPONENTS, a rotation-only mode (NLERP, SQUAD) on a non-rotation
 *   channel, tension negative or not finite                        -> AK_ERR_BAD_ARG
 *   CARDINAL, BEZIER, NATURAL or LAGRANGE on a rotation channel    -> AK_ERR_UNSUPPORTED
 *   joint index >= joint_count, or index + component_count above morph_weight_count /
 *   scalar_count                                                   -> AK_ERR_BAD_INDEX
 *   duration, a time or a value NaN or infinite, a zero quaternion -> AK_ERR_BAD_DATA
 *   two keys of a channel at one time, or two channels animating the same joint property
 *   or overlapping weight/scalar ranges                            -> AK_ERR_DUPLICATE
 *   allocation failed                                              -> AK_ERR_NO_MEMORY
 * *out_clip is NULL on failure. */
AK_API ak_result ak_clip_build(const ak_raw_clip* raw, const ak_allocator* alloc,
                               ak_clip** out_clip, ak_diag* diag);

/* Free a clip (with the allocator it was built with); NULL is a no-op. */
AK_API void ak_clip_destroy(ak_clip* clip);

/* Name given at build (truncated to AK_NAME_SIZE - 1 bytes); never NULL ("" for NULL clip). */
AK_API const char* ak_clip_name(const ak_clip* clip);
/* Duration in seconds (raw duration, or the last key time when that was 0). NULL -> 0. */
AK_API float ak_clip_duration(const ak_clip* clip);
/* Sizes the clip was built for (raw joint_count, morph_weight_count, scalar_count). */
AK_API size_t ak_clip_joint_count(const ak_clip* clip);
AK_API size_t ak_clip_morph_weight_count(const ak_clip* clip);
AK_API size_t ak_clip_scalar_count(const ak_clip* clip);
/* Number of channels, in the order of the raw clip. NULL -> 0. */
AK_API size_t ak_clip_channel_count(const ak_clip* clip);

/* Per-channel queries; channel_index < ak_clip_channel_count. An out-of-range index or a
 * NULL clip gives 0 / AK_CHANNEL_TARGET_COUNT / AK_INTERP_DEFAULT / NULL. */
AK_API ak_channel_target ak_clip_channel_target(const ak_clip* clip, size_t channel_index);
/* Joint index (T/R/S) or first morph weight / scalar index. */
AK_API uint32_t ak_clip_channel_index(const ak_clip* clip, size_t channel_index);
AK_API ak_interp ak_clip_channel_interp(const ak_clip* clip, size_t channel_index);
AK_API size_t ak_clip_channel_key_count(const ak_clip* clip, size_t channel_index);
/* The channel's runtime track, owned by the clip (valid until ak_clip_destroy; never destroy
 * it): use the ak_track_* queries for key times, values, tangents and plots. */
AK_API const ak_track* ak_clip_channel_track(const ak_clip* clip, size_t channel_index);

/* ---- sampling ----------------------------------------------------------------------- */

/* Playback state: the last key segment of every channel, so the next sample near the last
 * one finds its keys without a search, and (with the full storage) a key cache: the keys
 * around the current time of every LINEAR translation/scale and LINEAR/NLERP rotation channel
 * with two or more keys, laid out four channels per SIMD vector (structure of arrays). A
 * sample then checks four channels' key intervals in one operation, interpolates four
 * channels per operation, and reloads only the channels whose interval the time has left
 * (once per group when the four channels share their key times, as baked clips do; one key
 * search and one interval for the whole clip when every group has the same key times).
 * Caller-owned; initialise with ak_clip_cursor_init. One cursor per playing instance (and per
 * thread). */
typedef struct ak_clip_cursor {
    const ak_clip* clip;   /* the clip the cursor was initialised for */
    uint32_t* segments;    /* caller storage: [channel count] segments, then the key cache */
    size_t segment_count;  /* storage elements */
} ak_clip_cursor;

/* Elements of uint32_t storage for a cursor with its key cache: the channel count, plus 3 +
 * 84 per group of four cached channels in SIMD builds (about 66 per joint with T, R and S
 * channels: 264 bytes, 16 KB for 60 joints). NULL -> 0. The minimum a cursor accepts is
 * ak_clip_channel_count (segments only, no key cache: slower, same results). */
AK_API size_t ak_clip_cursor_storage_count(const ak_clip* clip);

/* Bind a cursor to a clip and storage (any uint32_t alignment), positioned at the start. The
 * cursor keeps both pointers. storage.count >= ak_clip_cursor_storage_count enables the key
 * cache; between ak_clip_channel_count and that, the cursor keeps segments only.
 * Returns AK_ERR_NULL_ARG (cursor or clip NULL, storage.ptr NULL with a non-zero
 * requirement) or AK_ERR_SPAN_SMALL (storage.count < ak_clip_channel_count). */
AK_API ak_result ak_clip_cursor_init(ak_clip_cursor* cursor, const ak_clip* clip,
                                     ak_u32_span storage);

/* Sampling kernels, for ak_clip_set_simd_limit. */
typedef enum ak_clip_simd {
    AK_CLIP_SIMD_DEFAULT = 0, /* the widest kernel this CPU has */
    AK_CLIP_SIMD_SCALAR,      /* no SIMD lanes: a cursor keeps segments only (its key cache idle) */
    AK_CLIP_SIMD_SSE2,        /* the key cache's lanes in SSE2 (the x86-64 baseline) */
    AK_CLIP_SIMD_AVX2,        /* at most the same lanes with the AVX2 (VEX) encoding */
    AK_CLIP_SIMD_AVX512,      /* at most the AVX-512 VL (EVEX) encoding, 32 registers */
    AK_CLIP_SIMD_COUNT
} ak_clip_simd;

/* Cap the kernel ak_clip_sample uses with a cursor's key cache (the widest the CPU has, checked
 * at run time, at or below limit; build picks the DEFAULT). Every kernel gives the same floats.
 * For comparisons and tests: call it before sharing the clip between threads. Returns
 * AK_ERR_NULL_ARG, AK_ERR_BAD_ARG (out of range). */
AK_API ak_result ak_clip_set_simd_limit(ak_clip* clip, ak_clip_simd limit);
/* The sampling kernel in use: "scalar", "sse2", "avx2" or "avx512" ("" for NULL). */
AK_API const char* ak_clip_simd_name(const ak_clip* clip);

/* Write the clip's values at time into a pose. Channels write only what they animate:
 * joints, weights and scalars the clip does not animate are left untouched, so callers
 * initialise inout_local with the rest pose (and weights with their defaults).
 * time is used as given (wrap it first with ak_time_wrap); each channel clamps it to its
 * own keys. A NaN time samples the first keys.
 * cursor: NULL -> binary search per channel (fine for one-off samples); else a cursor from
 * ak_clip_cursor_init for this clip (O(1) amortised per channel when time moves forward by
 * less than a key interval; any jump is still exact). Results are bit-identical either way
 * (the key cache's SIMD lanes run the scalar evaluator's operations in its order).
 * inout_local.count >= ak_clip_joint_count when the clip has joint channels (may be empty
 * otherwise); inout_morph_weights / inout_scalars: empty -> those channels are skipped, else
 * count >= ak_clip_morph_weight_count / ak_clip_scalar_count.
 * Returns AK_ERR_NULL_ARG (clip NULL, or inout_local empty while the clip animates joints),
 * AK_ERR_BAD_ARG (cursor initialised for another clip), AK_ERR_SPAN_SMALL. Nothing is
 * written on failure. */
AK_API ak_result ak_clip_sample(const ak_clip* clip, float time, ak_clip_cursor* cursor,
                                ak_transform_span inout_local, ak_f32_span inout_morph_weights,
                                ak_f32_span inout_scalars);

/* ---- blending ----------------------------------------------------------------------- */

/* One input pose of a blend. */
typedef struct ak_blend_layer {
    ak_transform_cspan pose;    /* required: local transforms, count >= the job's joint count;
                                   for additive layers a delta from ak_pose_additive_delta */
    float weight;               /* >= 0; 0 -> the layer contributes nothing */
    ak_f32_cspan joint_weights; /* optional per-joint mask in [0, 1] multiplying weight (count
                                   >= joint count); empty -> 1 for every joint */
} ak_blend_layer;

/* Weighted blend of N poses, then additive layers on top.
 * Per joint j with w_i = layer i's weight * mask_i[j] and W = sum w_i:
 *   translation, scale: sum w_i x_i / W;
 *   rotation: normalise(sum w_i s_i q_i), s_i = +-1 puts every q_i in the hemisphere of the
 *   first contributing rotation (q and -q are the same rotation);
 *   when W < threshold the rest pose joins with weight threshold - W, so joints no layer
 *   covers fade smoothly to the rest pose instead of dividing by zero.
 * Then each additive layer with weight a = weight * mask[j] and delta (t, r, s) gives
 *   translation += a t, rotation = rotation * slerp(identity, r, a), scale *= lerp(1, s, a).
 * A joint covered by a single layer of non-zero weight gets that layer's transform unchanged
 * (bit-exact), so masks leave the joints they exclude exactly as the other layer has them. */
typedef struct ak_blend_job {
    const ak_blend_layer* layers;          /* [layer_count]; may be NULL when layer_count is 0 */
    size_t layer_count;                    /* 0 -> the output is the rest pose plus additive layers */
    const ak_blend_layer* additive_layers; /* [additive_count]; may be NULL when the count is 0 */
    size_t additive_count;
    ak_transform_cspan rest_pose;          /* required: local rest pose; its count is the joint count */
    float threshold;                       /* total weight under which the rest pose fills in; 0 -> 0.1 */
    ak_transform_span out_local;           /* required: count >= rest_pose.count; must not overlap
                                              any input */
} ak_blend_job;

/* First rule the job breaks, in order: rest_pose.ptr or out_local.ptr NULL, layers NULL with
 * layer_count > 0 (same for additive), a layer's pose.ptr NULL -> AK_ERR_NULL_ARG;
 * rest_pose empty -> AK_ERR_EMPTY; out_local, a pose or a non-empty mask shorter than the
 * joint count -> AK_ERR_SPAN_SMALL; a weight or the threshold negative -> AK_ERR_BAD_ARG;
 * a weight, the threshold or a mask entry NaN/infinite, or a mask entry outside [0, 1] ->
 * AK_ERR_BAD_DATA; out_local overlapping an input -> AK_ERR_BAD_ARG. AK_OK otherwise.
 * A zero-initialised job gives AK_ERR_NULL_ARG. */
AK_API ak_result ak_blend_validate(const ak_blend_job* job);

/* Validate, then write the blended pose (nothing written on failure). Never allocates. */
AK_API ak_result ak_blend_run(const ak_blend_job* job);

/* Additive delta of pose against reference, per joint: translation pose - ref, rotation
 * conj(ref) * pose (so ref * delta = pose), scale pose / ref (a zero reference scale
 * component gives 1). Applying the delta of the reference itself changes nothing.
 * All spans count >= pose.count; out_delta may not overlap the inputs.
 * Returns AK_ERR_NULL_ARG, AK_ERR_EMPTY (pose empty) or AK_ERR_SPAN_SMALL. */
AK_API ak_result ak_pose_additive_delta(ak_transform_cspan pose, ak_transform_cspan reference,
                                        ak_transform_span out_delta);

/* Cross-fade: out = blend of from (weight 1 - alpha) and to (weight alpha), alpha clamped to
 * [0, 1] (NaN -> 0); translations and scales lerp, rotations nlerp on the shorter arc, the
 * same as ak_blend_run with two layers. Drive alpha with ak_ease(kind, elapsed / fade_time)
 * for a slow-in, slow-out transition. out may alias from or to.
 * Spans: from.count and to.count >= out.count. Returns AK_ERR_NULL_ARG, AK_ERR_EMPTY,
 * AK_ERR_SPAN_SMALL. */
AK_API ak_result ak_pose_crossfade(ak_transform_cspan from, ak_transform_cspan to, float alpha,
                                   ak_transform_span out);

/* ---- root motion -------------------------------------------------------------------- */

typedef struct ak_root_motion_desc {
    uint32_t root_joint; /* joint whose translation carries the travel; 0 -> joint 0 */
} ak_root_motion_desc;

/* Split the root's horizontal (XZ) travel out of a clip, so a character can walk in place
 * and be moved by the game. With p(t) the root joint's translation channel and p0 its first
 * key's value:
 *   *out_in_place: a copy of the clip whose root translation is (p0.x, p(t).y, p0.z);
 *   *out_trajectory: a 3-component track with (p(t).x - p0.x, 0, p(t).z - p0.z) in the
 *   root's parent space, same keys and curve shape (the cubic modes become HERMITE with
 *   their tangents), so in_place + trajectory = original exactly up to
 *   float rounding. Rotation (turning) is not extracted.
 * A clip without a translation channel on the root gives an unchanged copy and a one-key
 * zero trajectory. desc NULL -> defaults. alloc (NULL -> malloc/free) allocates both; free
 * them with ak_clip_destroy and ak_track_destroy.
 * Returns AK_ERR_NULL_ARG, AK_ERR_BAD_INDEX (root_joint >= ak_clip_joint_count),
 * AK_ERR_NO_MEMORY; on failure both outputs are NULL. */
AK_API ak_result ak_clip_extract_root_motion(const ak_clip* clip, const ak_root_motion_desc* desc,
                                             const ak_allocator* alloc, ak_clip** out_in_place,
                                             ak_track** out_trajectory);

/* ---- baking ------------------------------------------------------------------------- */

/* A sequence of poses sampled at a fixed rate (IK-solved, blended, simulated, retargeted)
 * to turn into a clip, e.g. to write it with ak_io_save. */
typedef struct ak_clip_bake_desc {
    const ak_transform* poses;    /* required: [frame_count * joint_count] local transforms,
                                     frame-major (frame f, joint j at f * joint_count + j) */
    size_t frame_count;           /* required, >= 1 */
    size_t joint_count;           /* required, >= 1 */
    float frame_rate;             /* frames per second; 0 -> 30 */
    float start_time;             /* seconds of frame 0; 0 -> 0 */
    const float* morph_weights;   /* optional: [frame_count * morph_weight_count], frame-major */
    size_t morph_weight_count;    /* 0 -> no morph-weight channel */
    ak_transform_cspan rest_pose; /* optional (count >= joint_count): a joint property equal to
                                     the rest pose's at every frame (bit for bit; a rotation or
                                     its negation) gets no channel; empty -> every joint gets
                                     translation, rotation and scale channels */
    const char* name;             /* NULL -> "" */
    bool step;                    /* true -> STEP keys; false (default) -> LINEAR (rotations SLERP) */
} ak_clip_bake_desc;

/* Build a clip with one key per frame at start_time + f / frame_rate: a translation, rotation
 * and scale channel per joint (those equal to rest_pose left out), and one morph-weight
 * channel over [0, morph_weight_count) when weights are given. Sampling the clip at a frame
 * time gives that frame's pose exactly (rotations up to sign); between frames it
 * interpolates (lerp / slerp, or holds with step). Neighbouring rotation keys are put in one
 * hemisphere. When nothing moves, the clip holds joint 0's rotation (a clip needs a channel).
 * alloc NULL -> malloc/free (temporary arrays and the clip).
 * Returns AK_ERR_NULL_ARG (desc, poses or out_clip NULL; morph_weights NULL with a count),
 * AK_ERR_EMPTY (frame_count or joint_count 0), AK_ERR_BAD_ARG (frame_rate negative or not
 * finite, start_time not finite), AK_ERR_SPAN_SMALL (rest_pose shorter than joint_count),
 * AK_ERR_BAD_DATA (a non-finite pose or weight, a zero rotation), AK_ERR_NO_MEMORY; diag
 * (optional) names the frame and joint. *out_clip is NULL on failure. */
AK_API ak_result ak_clip_bake(const ak_clip_bake_desc* desc, const ak_allocator* alloc, ak_clip** out_clip,
                              ak_diag* diag);

/* ---- keyframe reduction ------------------------------------------------------------- */

/* What ak_clip_reduce measures the error against. */
typedef struct ak_clip_reduce_desc {
    const int32_t* parents;       /* required: [ak_clip_joint_count] parent of each joint, -1 for
                                     a root, parents before children (ak_skeleton_parents) */
    ak_transform_cspan rest_pose; /* required: count >= ak_clip_joint_count; the local transform
                                     of joints and properties the clip does not animate */
    float tolerance;              /* largest model-space error, in model units; 0 -> 1e-3 */
    float distance;               /* the error is measured at each joint's origin and at points
                                     this far along its axes (a skin vertex near the joint);
                                     model units, 0 -> 0.1 */
} ak_clip_reduce_desc;

/* Offline: a copy of clip with keys removed where the interpolation of the remaining keys
 * stays within the tolerance in model space. Reduced: translation, rotation and scale
 * channels with LINEAR (rotations: slerp) or NLERP keys and at least three keys; every other
 * channel is copied unchanged. Each channel is simplified by Douglas-Peucker with a local
 * error (translation distance; rotation angle and scale change times the joint's radius:
 * distance plus its farthest descendant in the rest pose); then the result is checked in
 * model space (forward kinematics of both clips over parents and rest_pose, error = the
 * largest distance between the two clips' positions of every joint's origin and its three
 * axis points at distance) at every key time of the clip and the midpoint of every key
 * interval; the local tolerance starts at the tolerance and shrinks by 0.7 until the check
 * passes (the last of 25 tries keeps every key off its neighbours' interpolation).
 * out_error (optional) gets that checked error (infinite when the model-space positions
 * overflow float, e.g. for scales near 1e30: the result is then the last try's). Cost: one clip build and check per try
 * (60 joints x 301 keys: about 50 ms). alloc (NULL -> malloc/free) allocates scratch and the
 * clip. Removing keys can make playback slower when the channels then no longer share their
 * key times (the cursor's key cache refreshes such channels one by one).
 * Returns AK_ERR_NULL_ARG, AK_ERR_BAD_ARG (tolerance or distance negative or not finite),
 * AK_ERR_SPAN_SMALL (rest_pose shorter than the joint count), AK_ERR_BAD_DATA (a rest_pose
 * transform not finite), AK_ERR_BAD_INDEX (a parent not before its child), AK_ERR_UNSUPPORTED (a channel with CARDINAL, BEZIER, NATURAL, LAGRANGE or
 * SQUAD keys), AK_ERR_NO_MEMORY. *out_clip is NULL on failure. */
AK_API ak_result ak_clip_reduce(const ak_clip* clip, const ak_clip_reduce_desc* desc, const ak_allocator* alloc,
                                ak_clip** out_clip, double* out_error, ak_diag* diag);

#ifdef __cplusplus
}
#endif
#endif /* ANIMKIT_CLIP_H */

/* animkit clip: animation clips, poses, sampling and blending.
 * (Header being completed by the keyframe module; the raw clip structs below are a contract
 * shared with io.h and builtin.h and must keep their fields.) */
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

#ifdef __cplusplus
}
#endif
#endif

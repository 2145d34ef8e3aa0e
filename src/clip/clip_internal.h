/* Runtime clip layout shared by src/clip.c and src/clip/blend.c (never installed). */
#ifndef ANIMKIT_CLIP_INTERNAL_H
#define ANIMKIT_CLIP_INTERNAL_H

#include <animkit/clip.h>

#include "curve/track.h"

/* Channels ak_clip_sample evaluates inline (set at build; everything else goes through
 * akp_track_eval): at least two keys and one of these shapes. */
typedef enum akp_clip_fast {
    AKP_CLIP_FAST_NONE = 0,
    AKP_CLIP_FAST_VEC3,  /* translation or scale, LINEAR */
    AKP_CLIP_FAST_SLERP, /* rotation, LINEAR (slerp with the per-segment constants) */
    AKP_CLIP_FAST_NLERP  /* rotation, NLERP */
} akp_clip_fast;

typedef struct akp_clip_channel {
    ak_track track; /* data points into the clip's block */
    ak_channel_target target;
    uint32_t index;
    akp_clip_fast fast;
    uint32_t dst; /* FAST_*: float offset of the value in the pose (index * transform + field) */
} akp_clip_channel;

/* Four FAST channels of one kind, sampled together in SIMD lanes through a cursor's key cache
 * (src/clip.c, "key cache"). A group with fewer channels repeats its first lane's channel. */
typedef struct akp_clip_group {
    akp_clip_fast kind; /* VEC3, SLERP or NLERP */
    uint32_t ch[4];     /* channel indices */
    uint32_t dst[4];    /* their akp_clip_channel.dst */
    bool shared;        /* the four tracks have the same key times (bit for bit) */
} akp_clip_group;

/* One allocation: this header, the channel array, the groups and the slow channel list, then
 * every track's data. */
struct ak_clip {
    ak_allocator alloc;
    akp_clip_channel* channels; /* [channel_count] */
    size_t channel_count;
    akp_clip_group* groups; /* [group_count]: FAST channels four by four (SIMD builds; else 0) */
    size_t group_count;
    uint32_t* slow;         /* [slow_count]: channels in no group, in channel order */
    size_t slow_count;
    size_t size; /* bytes of the whole block (for copies) */
    size_t joint_count;
    size_t morph_weight_count;
    size_t scalar_count;
    float duration;
    bool has_joint_channels;
    bool uniform; /* groups exist, every one shared, all with the same key times (src/clip.c) */
    uint8_t sample_kernel; /* AKP_CLIP_K_*: how a cursor's key cache is sampled (src/clip.c) */
    char name[AK_NAME_SIZE];
};

/* Key-cache sampling kernels (ak_clip_set_simd_limit). */
enum { AKP_CLIP_K_SCALAR = 0, AKP_CLIP_K_SSE2, AKP_CLIP_K_AVX2, AKP_CLIP_K_AVX512 };

#endif

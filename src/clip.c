/* Clips: build from raw channels, queries, cursors and sampling into a pose.
 * Blending and root motion are in src/clip/blend.c. */
#include <animkit/clip.h>

#include "clip/clip_internal.h"
#include "internal.h"

/* ---- static helpers ------------------------------------------------------------------ */

static uint32_t resolved_components(const ak_raw_channel* ch) {
    if (ch->component_count) return ch->component_count;
    if (ch->target == AK_CHANNEL_TRANSLATION || ch->target == AK_CHANNEL_SCALE) return 3u;
    if (ch->target == AK_CHANNEL_ROTATION) return 4u;
    return 1u;
}

static bool is_joint_target(ak_channel_target t) {
    return t == AK_CHANNEL_TRANSLATION || t == AK_CHANNEL_ROTATION || t == AK_CHANNEL_SCALE;
}

static const char* target_name(ak_channel_target t) {
    static const char* const names[] = {"translation", "rotation", "scale", "weights", "scalar"};
    return (unsigned)t < (unsigned)AK_CHANNEL_TARGET_COUNT ? names[t] : "unknown";
}

/* Check one channel's binding (target, components, index range). */
static ak_result check_binding(const ak_raw_clip* raw, size_t i, ak_diag* diag) {
    const ak_raw_channel* ch = &raw->channels[i];
    if ((unsigned)ch->target >= (unsigned)AK_CHANNEL_TARGET_COUNT) {
        akp_diag_set(diag, NULL, "channel %zu has an unknown target %d", i, (int)ch->target);
        return AK_ERR_BAD_ARG;
    }
    uint32_t cc = resolved_components(ch);
    bool bad_cc = (ch->target == AK_CHANNEL_ROTATION && cc != 4) ||
                  ((ch->target == AK_CHANNEL_TRANSLATION || ch->target == AK_CHANNEL_SCALE) && cc != 3) ||
                  cc > AK_TRACK_MAX_COMPONENTS;
    if (bad_cc) {
        akp_diag_set(diag, NULL, "channel %zu (%s) has %u components", i, target_name(ch->target), (unsigned)cc);
        return AK_ERR_BAD_ARG;
    }
    if (is_joint_target(ch->target)) {
        if (ch->index >= raw->joint_count) {
            akp_diag_set(diag, NULL, "channel %zu (%s) addresses joint %u of %zu", i, target_name(ch->target),
                         (unsigned)ch->index, raw->joint_count);
            return AK_ERR_BAD_INDEX;
        }
    } else {
        size_t limit = ch->target == AK_CHANNEL_MORPH_WEIGHTS ? raw->morph_weight_count : raw->scalar_count;
        if ((size_t)ch->index + cc > limit) {
            akp_diag_set(diag, NULL, "channel %zu (%s) addresses [%u, %u) of %zu", i, target_name(ch->target),
                         (unsigned)ch->index, (unsigned)(ch->index + cc), limit);
            return AK_ERR_BAD_INDEX;
        }
    }
    return AK_OK;
}

/* Two channels writing the same value. */
static bool channels_overlap(const ak_raw_channel* a, const ak_raw_channel* b) {
    if (a->target != b->target) return false;
    if (is_joint_target(a->target)) return a->index == b->index;
    uint32_t ea = a->index + resolved_components(a), eb = b->index + resolved_components(b);
    return a->index < eb && b->index < ea;
}

static ak_raw_track channel_as_track(const ak_raw_channel* ch) {
    ak_raw_track t;
    memset(&t, 0, sizeof t);
    t.component_count = resolved_components(ch);
    t.is_rotation = ch->target == AK_CHANNEL_ROTATION;
    t.interp = ch->interp;
    t.tension = ch->tension;
    t.key_count = ch->key_count;
    t.times = ch->times;
    t.values = ch->values;
    return t;
}

/* Sample channel c on segment seg into the pose (spans already checked). */
static void write_channel(const akp_clip_channel* ch, size_t seg, float t, ak_transform* local, float* weights,
                          float* scalars) {
    float v[AK_TRACK_MAX_COMPONENTS];
    switch (ch->target) {
    case AK_CHANNEL_TRANSLATION:
        akp_track_eval(&ch->track, seg, t, v);
        local[ch->index].translation = ak_vec3_make(v[0], v[1], v[2]);
        break;
    case AK_CHANNEL_ROTATION:
        akp_track_eval(&ch->track, seg, t, v);
        local[ch->index].rotation = ak_quat_make(v[0], v[1], v[2], v[3]);
        break;
    case AK_CHANNEL_SCALE:
        akp_track_eval(&ch->track, seg, t, v);
        local[ch->index].scale = ak_vec3_make(v[0], v[1], v[2]);
        break;
    case AK_CHANNEL_MORPH_WEIGHTS:
        if (weights) akp_track_eval(&ch->track, seg, t, weights + ch->index);
        break;
    case AK_CHANNEL_SCALAR:
        if (scalars) akp_track_eval(&ch->track, seg, t, scalars + ch->index);
        break;
    case AK_CHANNEL_TARGET_COUNT:
        break;
    }
}

/* ---- build and query ---------------------------------------------------------------- */

ak_result ak_clip_build(const ak_raw_clip* raw, const ak_allocator* alloc, ak_clip** out_clip, ak_diag* diag) {
    if (out_clip) *out_clip = NULL;
    if (!raw || !out_clip) {
        akp_diag_set(diag, NULL, "raw clip or output pointer is NULL");
        return AK_ERR_NULL_ARG;
    }
    if (raw->channel_count == 0) {
        akp_diag_set(diag, NULL, "clip has no channels");
        return AK_ERR_EMPTY;
    }
    if (!raw->channels) {
        akp_diag_set(diag, NULL, "clip channels pointer is NULL");
        return AK_ERR_NULL_ARG;
    }
    if (!ak_finitef(raw->duration)) {
        akp_diag_set(diag, NULL, "clip duration is not finite");
        return AK_ERR_BAD_DATA;
    }
    if (raw->duration < 0.0f) {
        akp_diag_set(diag, NULL, "clip duration %g is negative", (double)raw->duration);
        return AK_ERR_BAD_ARG;
    }
    size_t nch = raw->channel_count;
    size_t size = akp_align16(sizeof(ak_clip)) + akp_align16(nch * sizeof(akp_clip_channel));
    bool joints = false;
    for (size_t i = 0; i < nch; ++i) {
        char prefix[64];
        snprintf(prefix, sizeof prefix, "channel %zu: ", i);
        ak_raw_track rt = channel_as_track(&raw->channels[i]), resolved;
        ak_result r = akp_track_check(&rt, &resolved, diag, prefix);
        if (r != AK_OK) return r;
        r = check_binding(raw, i, diag);
        if (r != AK_OK) return r;
        size += akp_track_data_size(&resolved);
        joints = joints || is_joint_target(raw->channels[i].target);
    }
    for (size_t i = 0; i < nch; ++i) {
        for (size_t j = i + 1; j < nch; ++j) {
            if (channels_overlap(&raw->channels[i], &raw->channels[j])) {
                akp_diag_set(diag, NULL, "channels %zu and %zu both animate %s %u", i, j,
                             target_name(raw->channels[i].target), (unsigned)raw->channels[j].index);
                return AK_ERR_DUPLICATE;
            }
        }
    }

    char* mem = (char*)akp_calloc(alloc, size);
    if (!mem) return AK_ERR_NO_MEMORY;
    ak_clip* clip = (ak_clip*)mem;
    clip->channels = (akp_clip_channel*)(mem + akp_align16(sizeof(ak_clip)));
    clip->channel_count = nch;
    clip->size = size;
    if (alloc) clip->alloc = *alloc;
    clip->joint_count = raw->joint_count;
    clip->morph_weight_count = raw->morph_weight_count;
    clip->scalar_count = raw->scalar_count;
    clip->has_joint_channels = joints;
    snprintf(clip->name, sizeof clip->name, "%s", raw->name ? raw->name : "");
    char* data = mem + akp_align16(sizeof(ak_clip)) + akp_align16(nch * sizeof(akp_clip_channel));
    float last = 0.0f;
    for (size_t i = 0; i < nch; ++i) {
        char prefix[64];
        snprintf(prefix, sizeof prefix, "channel %zu: ", i);
        ak_raw_track rt = channel_as_track(&raw->channels[i]), resolved;
        (void)akp_track_check(&rt, &resolved, NULL, prefix);
        akp_clip_channel* ch = &clip->channels[i];
        ch->target = raw->channels[i].target;
        ch->index = raw->channels[i].index;
        ak_result r = akp_track_build_into(&resolved, &ch->track, data, alloc, diag, prefix);
        if (r != AK_OK) {
            akp_free(alloc, mem);
            return r;
        }
        data += akp_track_data_size(&resolved);
        float end = ch->track.times[ch->track.key_count - 1];
        if (end > last) last = end;
    }
    clip->duration = raw->duration > 0.0f ? raw->duration : last;
    *out_clip = clip;
    return AK_OK;
}

void ak_clip_destroy(ak_clip* clip) {
    if (!clip) return;
    ak_allocator a = clip->alloc;
    akp_free(&a, clip);
}

const char* ak_clip_name(const ak_clip* clip) { return clip ? clip->name : ""; }
float ak_clip_duration(const ak_clip* clip) { return clip ? clip->duration : 0.0f; }
size_t ak_clip_joint_count(const ak_clip* clip) { return clip ? clip->joint_count : 0u; }
size_t ak_clip_morph_weight_count(const ak_clip* clip) { return clip ? clip->morph_weight_count : 0u; }
size_t ak_clip_scalar_count(const ak_clip* clip) { return clip ? clip->scalar_count : 0u; }
size_t ak_clip_channel_count(const ak_clip* clip) { return clip ? clip->channel_count : 0u; }

ak_channel_target ak_clip_channel_target(const ak_clip* clip, size_t i) {
    return clip && i < clip->channel_count ? clip->channels[i].target : AK_CHANNEL_TARGET_COUNT;
}
uint32_t ak_clip_channel_index(const ak_clip* clip, size_t i) {
    return clip && i < clip->channel_count ? clip->channels[i].index : 0u;
}
ak_interp ak_clip_channel_interp(const ak_clip* clip, size_t i) {
    return clip && i < clip->channel_count ? clip->channels[i].track.interp : AK_INTERP_DEFAULT;
}
size_t ak_clip_channel_key_count(const ak_clip* clip, size_t i) {
    return clip && i < clip->channel_count ? clip->channels[i].track.key_count : 0u;
}
const ak_track* ak_clip_channel_track(const ak_clip* clip, size_t i) {
    return clip && i < clip->channel_count ? &clip->channels[i].track : NULL;
}

/* ---- sampling ----------------------------------------------------------------------- */

size_t ak_clip_cursor_storage_count(const ak_clip* clip) { return clip ? clip->channel_count : 0u; }

ak_result ak_clip_cursor_init(ak_clip_cursor* cursor, const ak_clip* clip, ak_u32_span storage) {
    if (!cursor || !clip) return AK_ERR_NULL_ARG;
    size_t need = clip->channel_count;
    if (need && !storage.ptr) return AK_ERR_NULL_ARG;
    if (storage.count < need) return AK_ERR_SPAN_SMALL;
    for (size_t i = 0; i < need; ++i) storage.ptr[i] = 0u;
    cursor->clip = clip;
    cursor->segments = storage.ptr;
    cursor->segment_count = storage.count;
    return AK_OK;
}

ak_result ak_clip_sample(const ak_clip* clip, float time, ak_clip_cursor* cursor, ak_transform_span local,
                         ak_f32_span weights, ak_f32_span scalars) {
    if (!clip) return AK_ERR_NULL_ARG;
    if (clip->has_joint_channels && (!local.ptr || local.count == 0)) return AK_ERR_NULL_ARG;
    if (cursor && (cursor->clip != clip || !cursor->segments || cursor->segment_count < clip->channel_count))
        return AK_ERR_BAD_ARG;
    if (clip->has_joint_channels && local.count < clip->joint_count) return AK_ERR_SPAN_SMALL;
    float* w = weights.ptr && weights.count ? weights.ptr : NULL;
    float* s = scalars.ptr && scalars.count ? scalars.ptr : NULL;
    if (w && weights.count < clip->morph_weight_count) return AK_ERR_SPAN_SMALL;
    if (s && scalars.count < clip->scalar_count) return AK_ERR_SPAN_SMALL;
    const akp_clip_channel* ch = clip->channels;
    if (cursor) {
        uint32_t* segs = cursor->segments;
        for (size_t i = 0; i < clip->channel_count; ++i) {
            size_t seg = akp_track_find_from(&ch[i].track, time, segs[i]);
            segs[i] = (uint32_t)seg;
            write_channel(&ch[i], seg, time, local.ptr, w, s);
        }
    } else {
        for (size_t i = 0; i < clip->channel_count; ++i)
            write_channel(&ch[i], akp_track_find(&ch[i].track, time), time, local.ptr, w, s);
    }
    return AK_OK;
}

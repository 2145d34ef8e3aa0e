/* Pose blending (weighted layers, masks, additive layers, cross-fade) and root motion. */
#include <animkit/clip.h>

#include "clip/clip_internal.h"
#include "internal.h"

/* ---- static helpers ------------------------------------------------------------------ */

static bool ranges_overlap(const void* a, size_t a_bytes, const void* b, size_t b_bytes) {
    uintptr_t a0 = (uintptr_t)a, b0 = (uintptr_t)b;
    return a_bytes && b_bytes && a0 < b0 + b_bytes && b0 < a0 + a_bytes;
}

static ak_result check_layer(const ak_blend_layer* l, size_t joints, const ak_transform_span* out) {
    if (!l->pose.ptr) return AK_ERR_NULL_ARG;
    if (l->pose.count < joints) return AK_ERR_SPAN_SMALL;
    if (l->joint_weights.count && (!l->joint_weights.ptr || l->joint_weights.count < joints))
        return l->joint_weights.ptr ? AK_ERR_SPAN_SMALL : AK_ERR_NULL_ARG;
    if (!ak_finitef(l->weight)) return AK_ERR_BAD_DATA;
    if (l->weight < 0.0f) return AK_ERR_BAD_ARG;
    for (size_t j = 0; j < l->joint_weights.count && j < joints; ++j) {
        float m = l->joint_weights.ptr[j];
        if (!(m >= 0.0f && m <= 1.0f)) return AK_ERR_BAD_DATA;
    }
    size_t ob = out->count * sizeof(ak_transform);
    if (ranges_overlap(out->ptr, ob, l->pose.ptr, l->pose.count * sizeof(ak_transform)) ||
        ranges_overlap(out->ptr, ob, l->joint_weights.ptr, l->joint_weights.count * sizeof(float)))
        return AK_ERR_BAD_ARG;
    return AK_OK;
}

/* Relocate a copied clip block's internal pointers from old_base to new_base. */
static void relocate_clip(ak_clip* c, const char* old_base) {
    char* base = (char*)c;
#define AKP_RELOC(ptr, type) ((ptr) = (type)(void*)(base + ((const char*)(ptr) - old_base)))
    AKP_RELOC(c->channels, akp_clip_channel*);
    AKP_RELOC(c->groups, akp_clip_group*);
    AKP_RELOC(c->slow, uint32_t*);
    for (size_t i = 0; i < c->channel_count; ++i) {
        ak_track* t = &c->channels[i].track;
        AKP_RELOC(t->times, const float*);
        AKP_RELOC(t->values, const float*);
        if (t->newton) AKP_RELOC(t->newton, const double*);
    }
#undef AKP_RELOC
}

/* ---- blending ----------------------------------------------------------------------- */

ak_result ak_blend_validate(const ak_blend_job* job) {
    if (!job || !job->rest_pose.ptr || !job->out_local.ptr) return AK_ERR_NULL_ARG;
    if ((job->layer_count && !job->layers) || (job->additive_count && !job->additive_layers)) return AK_ERR_NULL_ARG;
    size_t joints = job->rest_pose.count;
    if (joints == 0) return AK_ERR_EMPTY;
    if (job->out_local.count < joints) return AK_ERR_SPAN_SMALL;
    if (!ak_finitef(job->threshold)) return AK_ERR_BAD_DATA;
    if (job->threshold < 0.0f) return AK_ERR_BAD_ARG;
    for (size_t i = 0; i < job->layer_count; ++i) {
        ak_result r = check_layer(&job->layers[i], joints, &job->out_local);
        if (r != AK_OK) return r;
    }
    for (size_t i = 0; i < job->additive_count; ++i) {
        ak_result r = check_layer(&job->additive_layers[i], joints, &job->out_local);
        if (r != AK_OK) return r;
    }
    if (ranges_overlap(job->out_local.ptr, job->out_local.count * sizeof(ak_transform), job->rest_pose.ptr,
                       joints * sizeof(ak_transform)))
        return AK_ERR_BAD_ARG;
    return AK_OK;
}

ak_result ak_blend_run(const ak_blend_job* job) {
    ak_result r = ak_blend_validate(job);
    if (r != AK_OK) return r;
    size_t joints = job->rest_pose.count;
    float threshold = job->threshold > 0.0f ? job->threshold : 0.1f;
    /* Where a weighted sum overflows float (weights or values near FLT_MAX), the joint is
     * redone with every weight (and the threshold) divided by the sum of the layer weights:
     * the same average, and sums of weights <= 1 times finite values stay finite. */
    double weight_sum = 0.0;
    for (size_t i = 0; i < job->layer_count; ++i) weight_sum += (double)job->layers[i].weight;
    for (size_t j = 0; j < joints; ++j) {
        ak_vec3 t = ak_vec3_zero(), s = ak_vec3_zero();
        ak_quat q = ak_quat_make(0, 0, 0, 0), ref = ak_quat_identity();
        float total = 0.0f;
        bool have_ref = false;
        int contributors = 0;
        const ak_transform* only = NULL;
        for (float ws = 1.0f;;) {
            float thr = threshold * ws;
            for (size_t i = 0; i <= job->layer_count; ++i) {
                const ak_transform* x;
                float w;
                if (i < job->layer_count) {
                    const ak_blend_layer* l = &job->layers[i];
                    w = l->weight * ws * (l->joint_weights.count ? l->joint_weights.ptr[j] : 1.0f);
                    x = &l->pose.ptr[j];
                } else {
                    /* The rest pose fills in where the layers carry too little weight. */
                    w = total < thr ? thr - total : 0.0f;
                    x = &job->rest_pose.ptr[j];
                }
                if (!(w > 0.0f)) continue;
                if (!have_ref) {
                    ref = x->rotation;
                    have_ref = true;
                }
                ++contributors;
                only = x;
                float sign = ak_quat_dot(ref, x->rotation) < 0.0f ? -w : w;
                t = ak_vec3_madd(t, x->translation, w);
                s = ak_vec3_madd(s, x->scale, w);
                q = ak_quat_add(q, ak_quat_scale(x->rotation, sign));
                total += w;
            }
            bool finite = ak_finitef(total) && ak_vec3_is_finite(t) && ak_vec3_is_finite(s) && ak_quat_is_finite(q);
            if (finite || ws != 1.0f || !(weight_sum > 1.0)) break;
            ws = (float)(1.0 / weight_sum); /* rare path: start over with scaled weights */
            t = s = ak_vec3_zero();
            q = ak_quat_make(0, 0, 0, 0);
            total = 0.0f;
            have_ref = false;
            contributors = 0;
        }
        ak_transform out;
        out.translation = ak_vec3_scale(t, 1.0f / total);
        out.scale = ak_vec3_scale(s, 1.0f / total);
        out.rotation = ak_quat_normalize(q);
        /* A single contributor passes through bit-exact (masked-out layers change nothing). */
        if (contributors == 1) out = *only;
        for (size_t i = 0; i < job->additive_count; ++i) {
            const ak_blend_layer* l = &job->additive_layers[i];
            float a = l->weight * (l->joint_weights.count ? l->joint_weights.ptr[j] : 1.0f);
            if (!(a > 0.0f)) continue;
            const ak_transform* d = &l->pose.ptr[j];
            out.translation = ak_vec3_madd(out.translation, d->translation, a);
            out.rotation = ak_quat_normalize(ak_quat_mul(out.rotation, ak_quat_slerp(ak_quat_identity(), d->rotation, a)));
            out.scale = ak_vec3_mul(out.scale, ak_vec3_make(1.0f + (d->scale.x - 1.0f) * a, 1.0f + (d->scale.y - 1.0f) * a,
                                                            1.0f + (d->scale.z - 1.0f) * a));
        }
        job->out_local.ptr[j] = out;
    }
    return AK_OK;
}

ak_result ak_pose_additive_delta(ak_transform_cspan pose, ak_transform_cspan ref, ak_transform_span out) {
    if (!pose.ptr || !ref.ptr || !out.ptr) return AK_ERR_NULL_ARG;
    if (pose.count == 0) return AK_ERR_EMPTY;
    if (ref.count < pose.count || out.count < pose.count) return AK_ERR_SPAN_SMALL;
    for (size_t j = 0; j < pose.count; ++j) {
        ak_transform p = pose.ptr[j], r = ref.ptr[j], d;
        d.translation = ak_vec3_sub(p.translation, r.translation);
        ak_quat rq = ak_quat_normalize(r.rotation), pq = ak_quat_normalize(p.rotation);
        d.rotation = ak_quat_normalize(ak_quat_mul(ak_quat_conjugate(rq), pq));
        if (d.rotation.w < 0.0f) d.rotation = ak_quat_neg(d.rotation);
        d.scale = ak_vec3_make(r.scale.x != 0.0f ? p.scale.x / r.scale.x : 1.0f,
                               r.scale.y != 0.0f ? p.scale.y / r.scale.y : 1.0f,
                               r.scale.z != 0.0f ? p.scale.z / r.scale.z : 1.0f);
        out.ptr[j] = d;
    }
    return AK_OK;
}

ak_result ak_pose_crossfade(ak_transform_cspan from, ak_transform_cspan to, float alpha, ak_transform_span out) {
    if (!from.ptr || !to.ptr || !out.ptr) return AK_ERR_NULL_ARG;
    if (out.count == 0) return AK_ERR_EMPTY;
    if (from.count < out.count || to.count < out.count) return AK_ERR_SPAN_SMALL;
    float a = alpha > 0.0f ? (alpha < 1.0f ? alpha : 1.0f) : 0.0f;
    for (size_t j = 0; j < out.count; ++j) {
        ak_transform f = from.ptr[j], t = to.ptr[j], o;
        o.translation = ak_vec3_lerp(f.translation, t.translation, a);
        o.scale = ak_vec3_lerp(f.scale, t.scale, a);
        o.rotation = ak_quat_nlerp(f.rotation, t.rotation, a);
        out.ptr[j] = o;
    }
    return AK_OK;
}

/* ---- root motion -------------------------------------------------------------------- */

ak_result ak_clip_extract_root_motion(const ak_clip* clip, const ak_root_motion_desc* desc, const ak_allocator* alloc,
                                      ak_clip** out_in_place, ak_track** out_trajectory) {
    if (out_in_place) *out_in_place = NULL;
    if (out_trajectory) *out_trajectory = NULL;
    if (!clip || !out_in_place || !out_trajectory) return AK_ERR_NULL_ARG;
    uint32_t root = desc ? desc->root_joint : 0u;
    if (root >= clip->joint_count) return AK_ERR_BAD_INDEX;

    char* mem = (char*)akp_alloc(alloc, clip->size);
    if (!mem) return AK_ERR_NO_MEMORY;
    memcpy(mem, clip, clip->size);
    ak_clip* copy = (ak_clip*)mem;
    relocate_clip(copy, (const char*)clip);
    memset(&copy->alloc, 0, sizeof copy->alloc);
    if (alloc) copy->alloc = *alloc;

    akp_clip_channel* ch = NULL;
    for (size_t i = 0; i < copy->channel_count; ++i)
        if (copy->channels[i].target == AK_CHANNEL_TRANSLATION && copy->channels[i].index == root) ch = &copy->channels[i];

    ak_result r;
    if (!ch) {
        static const float zero_time = 0.0f, zero_value[3] = {0.0f, 0.0f, 0.0f};
        ak_raw_track raw = {.component_count = 3, .key_count = 1, .times = &zero_time, .values = zero_value};
        r = ak_track_build(&raw, alloc, out_trajectory, NULL);
    } else {
        ak_track* tr = &ch->track;
        size_t n = tr->key_count, stride = tr->stride;
        /* The copy's arrays, reached through mem (the runtime track only holds const views). */
        float* vals = (float*)(void*)(mem + ((const char*)tr->values - mem));
        float* traj = (float*)akp_alloc(alloc, n * stride * sizeof(float));
        if (!traj) {
            akp_free(alloc, mem);
            return AK_ERR_NO_MEMORY;
        }
        uint32_t off = tr->value_offset;
        float x0 = vals[off + 0], z0 = vals[off + 2];
        for (size_t k = 0; k < n; ++k) {
            float* key = vals + k * stride;
            float* out = traj + k * stride;
            for (uint32_t part = 0; part < stride / 3; ++part) {
                bool is_value = part * 3 == off;
                float* in3 = key + part * 3;
                float* out3 = out + part * 3;
                out3[0] = is_value ? in3[0] - x0 : in3[0];
                out3[1] = 0.0f;
                out3[2] = is_value ? in3[2] - z0 : in3[2];
                in3[0] = is_value ? x0 : 0.0f;
                in3[2] = is_value ? z0 : 0.0f;
            }
        }
        if (tr->newton) {
            double* nw = (double*)(void*)(mem + ((const char*)tr->newton - mem));
            for (size_t k = 0; k < n; ++k) {
                nw[k * 3 + 0] = k == 0 ? (double)x0 : 0.0;
                nw[k * 3 + 2] = k == 0 ? (double)z0 : 0.0;
            }
        }
        ak_interp interp = tr->interp;
        if (tr->eval == AKP_EVAL_HERMITE) interp = AK_INTERP_HERMITE;
        ak_raw_track raw = {.component_count = 3, .interp = interp, .key_count = n, .times = tr->times, .values = traj};
        r = ak_track_build(&raw, alloc, out_trajectory, NULL);
        akp_free(alloc, traj);
    }
    if (r != AK_OK) {
        akp_free(alloc, mem);
        return r;
    }
    *out_in_place = copy;
    return AK_OK;
}

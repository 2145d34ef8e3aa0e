/* Baking: a sequence of poses at a frame rate into a clip (clip.h, ak_clip_bake). */
#include <animkit/clip.h>

#include "internal.h"

/* ---- static helpers ------------------------------------------------------------------ */

/* Component p (0 translation, 1 rotation, 2 scale) of a transform as floats. */
static uint32_t part_values(const ak_transform* t, int p, float* out) {
    if (p == 0) {
        out[0] = t->translation.x, out[1] = t->translation.y, out[2] = t->translation.z;
        return 3;
    }
    if (p == 1) {
        out[0] = t->rotation.x, out[1] = t->rotation.y, out[2] = t->rotation.z, out[3] = t->rotation.w;
        return 4;
    }
    out[0] = t->scale.x, out[1] = t->scale.y, out[2] = t->scale.z;
    return 3;
}

/* ---- public ---------------------------------------------------------------------------- */

ak_result ak_clip_bake(const ak_clip_bake_desc* desc, const ak_allocator* alloc, ak_clip** out_clip, ak_diag* diag) {
    if (out_clip) *out_clip = NULL;
    if (!desc || !out_clip || !desc->poses) {
        akp_diag_set(diag, NULL, "desc, desc->poses and out_clip are required");
        return AK_ERR_NULL_ARG;
    }
    if (desc->frame_count == 0 || desc->joint_count == 0) {
        akp_diag_set(diag, NULL, "frame_count and joint_count must be > 0");
        return AK_ERR_EMPTY;
    }
    float rate = desc->frame_rate == 0.0f ? 30.0f : desc->frame_rate;
    if (!(rate > 0.0f) || !ak_finitef(rate) || !ak_finitef(desc->start_time)) {
        akp_diag_set(diag, NULL, "frame_rate %g / start_time %g: a positive finite rate is required", (double)rate,
                     (double)desc->start_time);
        return AK_ERR_BAD_ARG;
    }
    if (desc->morph_weight_count && !desc->morph_weights) {
        akp_diag_set(diag, NULL, "morph_weights is required when morph_weight_count > 0");
        return AK_ERR_NULL_ARG;
    }
    if (desc->rest_pose.ptr && desc->rest_pose.count < desc->joint_count) {
        akp_diag_set(diag, NULL, "rest_pose has %zu joints, %zu needed", desc->rest_pose.count, desc->joint_count);
        return AK_ERR_SPAN_SMALL;
    }
    size_t nf = desc->frame_count, nj = desc->joint_count, nw = desc->morph_weight_count;
    if (nf > SIZE_MAX / 16 / (nj + 1) || (nw && nf > SIZE_MAX / 4 / nw)) return AK_ERR_NO_MEMORY;
    ak_interp interp = desc->step ? AK_INTERP_STEP : AK_INTERP_LINEAR;
    /* one float block: times, then per joint and part the values of the channels kept */
    /* (each part is gathered 4 floats per frame, then packed: room for one more frame block) */
    size_t floats = nf + nf * nj * 10 + nf * nw + 4 * nf;
    float* buf = (float*)akp_alloc(alloc, floats * sizeof(float));
    ak_raw_channel* ch = (ak_raw_channel*)akp_alloc(alloc, (3 * nj + 1) * sizeof(ak_raw_channel));
    if (!buf || !ch) {
        akp_free(alloc, buf);
        akp_free(alloc, ch);
        akp_diag_set(diag, NULL, "out of memory");
        return AK_ERR_NO_MEMORY;
    }
    float* times = buf;
    for (size_t f = 0; f < nf; ++f) times[f] = desc->start_time + (float)((double)f / (double)rate);
    float* next = buf + nf;
    size_t nc = 0;
    ak_result r = AK_OK;
    for (size_t j = 0; j < nj && r == AK_OK; ++j) {
        for (int p = 0; p < 3; ++p) {
            float* vals = next;
            bool moves = false;
            uint32_t cc = 0;
            float rest[4] = {0, 0, 0, 0};
            if (desc->rest_pose.ptr) part_values(&desc->rest_pose.ptr[j], p, rest);
            for (size_t f = 0; f < nf; ++f) {
                ak_transform t = desc->poses[f * nj + j];
                if (!ak_transform_is_finite(t)) {
                    akp_diag_set(diag, NULL, "frame %zu joint %zu: the pose is not finite", f, j);
                    r = AK_ERR_BAD_DATA;
                    break;
                }
                cc = part_values(&t, p, vals + f * 4);
                float* v = vals + f * 4;
                /* keep neighbouring rotations in one hemisphere (the same rotations; slerp
                 * takes the short arc either way, but curves read better) */
                if (p == 1 && f > 0) {
                    const float* u = vals + (f - 1) * 4;
                    if (u[0] * v[0] + u[1] * v[1] + u[2] * v[2] + u[3] * v[3] < 0.0f)
                        for (int k = 0; k < 4; ++k) v[k] = -v[k];
                }
                if (!desc->rest_pose.ptr) {
                    moves = true;
                } else { /* a rotation equal to the rest's or to its negation is the same */
                    bool same = true, negated = p == 1;
                    for (uint32_t k = 0; k < cc; ++k) {
                        same = same && v[k] == rest[k];
                        negated = negated && v[k] == -rest[k];
                    }
                    moves = moves || !(same || negated);
                }
            }
            if (r != AK_OK) break;
            if (!moves) continue;
            /* pack to cc floats per key */
            for (size_t f = 0; f < nf; ++f)
                for (uint32_t k = 0; k < cc; ++k) vals[f * cc + k] = vals[f * 4 + k];
            next += nf * cc;
            ch[nc++] = (ak_raw_channel){.target = p == 0 ? AK_CHANNEL_TRANSLATION : p == 1 ? AK_CHANNEL_ROTATION : AK_CHANNEL_SCALE,
                                        .index = (uint32_t)j, .interp = interp, .key_count = nf, .times = times, .values = vals};
        }
    }
    if (r == AK_OK && nw) {
        memcpy(next, desc->morph_weights, nf * nw * sizeof(float));
        ch[nc++] = (ak_raw_channel){.target = AK_CHANNEL_MORPH_WEIGHTS, .index = 0, .component_count = (uint32_t)nw,
                                    .interp = interp, .key_count = nf, .times = times, .values = next};
    }
    if (r == AK_OK && nc == 0) { /* a clip needs a channel: the root's rotation, held */
        float* v = next;
        part_values(&desc->poses[0], 1, v);
        for (size_t f = 1; f < nf; ++f) memcpy(v + 4 * f, v, 4 * sizeof(float));
        ch[nc++] = (ak_raw_channel){.target = AK_CHANNEL_ROTATION, .index = 0, .interp = interp, .key_count = nf,
                                    .times = times, .values = v};
    }
    if (r == AK_OK) {
        ak_raw_clip raw = {.name = desc->name, .channels = ch, .channel_count = nc, .joint_count = nj,
                           .morph_weight_count = nw};
        r = ak_clip_build(&raw, alloc, out_clip, diag);
    }
    akp_free(alloc, buf);
    akp_free(alloc, ch);
    return r;
}

/* Reference checks for the clip sampler, shared by test_clip.c (synthetic clips) and
 * test_io.c (real glTF clips): a double-precision glTF slerp computed from a track's keys, and
 * a check of ak_clip_sample's output against the per-track evaluator and that slerp.
 * Header-only. */
#ifndef ANIMKIT_REF_CLIP_H
#define ANIMKIT_REF_CLIP_H

#include <animkit/clip.h>
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

/* Double-precision glTF slerp (shortest arc) of a LINEAR rotation track at t: the spec's
 * formula computed from the keys, independent of the runtime's per-segment constants. */
static inline void ref_clip_slerp_d(const ak_track* tr, float t, double out[4]) {
    ak_f32_cspan kt = ak_track_times(tr);
    size_t n = kt.count, k = 0;
    float a[4], b[4];
    if (n == 1 || !(t > kt.ptr[0]) || t >= kt.ptr[n - 1]) {
        ak_track_key(tr, (n == 1 || !(t > kt.ptr[0])) ? 0 : n - 1, (ak_f32_span)AK_SPAN(a), (ak_f32_span){0},
                     (ak_f32_span){0});
        for (int c = 0; c < 4; ++c) out[c] = a[c];
        return;
    }
    while (k + 2 < n && kt.ptr[k + 1] <= t) ++k;
    ak_track_key(tr, k, (ak_f32_span)AK_SPAN(a), (ak_f32_span){0}, (ak_f32_span){0});
    ak_track_key(tr, k + 1, (ak_f32_span)AK_SPAN(b), (ak_f32_span){0}, (ak_f32_span){0});
    double u = ((double)t - kt.ptr[k]) / ((double)kt.ptr[k + 1] - kt.ptr[k]);
    double dot = (double)a[0] * b[0] + (double)a[1] * b[1] + (double)a[2] * b[2] + (double)a[3] * b[3];
    double sgn = dot < 0 ? -1.0 : 1.0, ang = acos(fmin(1.0, fabs(dot))), n2 = 0.0;
    double wa = ang < 1e-9 ? 1.0 - u : sin(ang * (1 - u)) / sin(ang);
    double wb = sgn * (ang < 1e-9 ? u : sin(ang * u) / sin(ang));
    for (int c = 0; c < 4; ++c) out[c] = wa * a[c] + wb * b[c], n2 += out[c] * out[c];
    for (int c = 0; c < 4; ++c) out[c] /= sqrt(n2);
}

/* Sample c at times[0..count) through a cursor; every joint channel must equal ak_track_sample
 * on the channel's own track bit for bit (the generic per-track evaluator), and LINEAR
 * rotations must match the double-precision slerp. Returns mismatches; *worst gets the
 * largest |component| difference from the double slerp. */
static inline int ref_clip_check_against_tracks(const ak_clip* c, ak_clip_cursor* cur, const float* times,
                                               size_t count, size_t joints, double* worst) {
    int bad = 0;
    ak_transform* pose = (ak_transform*)malloc(joints * sizeof *pose);
    float* w = (float*)calloc(ak_clip_morph_weight_count(c) + 1, sizeof *w);
    float* s = (float*)calloc(ak_clip_scalar_count(c) + 1, sizeof *s);
    for (size_t i = 0; i < count; ++i) {
        for (size_t j = 0; j < joints; ++j) pose[j] = ak_transform_identity();
        if (ak_clip_sample(c, times[i], cur, (ak_transform_span){pose, joints},
                           (ak_f32_span){w, ak_clip_morph_weight_count(c)},
                           (ak_f32_span){s, ak_clip_scalar_count(c)}) != AK_OK) {
            ++bad;
            continue;
        }
        for (size_t ci = 0; ci < ak_clip_channel_count(c); ++ci) {
            ak_channel_target tg = ak_clip_channel_target(c, ci);
            if (tg > AK_CHANNEL_SCALE) continue;
            const ak_track* tr = ak_clip_channel_track(c, ci);
            ak_transform* x = &pose[ak_clip_channel_index(c, ci)];
            float ref[4], got[4];
            ak_track_sample(tr, times[i], (ak_f32_span)AK_SPAN(ref));
            const float* g = tg == AK_CHANNEL_TRANSLATION ? &x->translation.x
                             : tg == AK_CHANNEL_ROTATION  ? &x->rotation.x
                                                          : &x->scale.x;
            uint32_t cc = tg == AK_CHANNEL_ROTATION ? 4u : 3u;
            memcpy(got, g, cc * sizeof(float));
            if (memcmp(got, ref, cc * sizeof(float))) ++bad;
            if (tg == AK_CHANNEL_ROTATION && ak_clip_channel_interp(c, ci) == AK_INTERP_LINEAR) {
                double d[4];
                ref_clip_slerp_d(tr, times[i], d);
                for (int k = 0; k < 4; ++k) *worst = fmax(*worst, fabs(got[k] - d[k]));
            }
        }
    }
    free(pose);
    free(w);
    free(s);
    return bad;
}

#endif

/* Clips: build from raw channels, queries, cursors and sampling into a pose.
 * Blending and root motion are in src/clip/blend.c. */
#include <animkit/clip.h>

#include "clip/clip_internal.h"
#include "internal.h"
#include <float.h>

#include "simd.h" /* SSE2: four slerp channels at a time */

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

/* A channel's target range, to find overlapping channels by sorting (a baked crowd has
 * hundreds of thousands of channels: the pairwise check was quadratic). */
typedef struct channel_span {
    uint32_t target, begin, end;
} channel_span;

static int channel_span_cmp(const void* a, const void* b) {
    const channel_span *x = (const channel_span*)a, *y = (const channel_span*)b;
    if (x->target != y->target) return x->target < y->target ? -1 : 1;
    return x->begin < y->begin ? -1 : x->begin > y->begin;
}

/* Whether two channels overlap (channels_overlap), in O(n log n); AK_ERR_NO_MEMORY as -1. */
static int any_overlap(const ak_raw_channel* ch, size_t n, const ak_allocator* alloc) {
    channel_span* s = (channel_span*)akp_alloc(alloc, (n ? n : 1) * sizeof *s);
    if (!s) return -1;
    for (size_t i = 0; i < n; ++i) {
        const uint32_t end = is_joint_target(ch[i].target) ? ch[i].index + 1u : ch[i].index + resolved_components(&ch[i]);
        s[i] = (channel_span){(uint32_t)ch[i].target, ch[i].index, end};
    }
    qsort(s, n, sizeof *s, channel_span_cmp);
    /* within a target, sorted by begin: an overlap is a begin below the largest end before it
     * (joint targets: the same index twice) */
    int found = 0;
    uint32_t max_end = 0;
    for (size_t i = 0; i < n && !found; ++i) {
        if (i == 0 || s[i].target != s[i - 1].target) max_end = s[i].end;
        else if (s[i].begin < max_end) found = 1;
        else if (s[i].end > max_end) max_end = s[i].end;
    }
    akp_free(alloc, s);
    return found;
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

/* ---- fast path ------------------------------------------------------------------------ */

/* Which inline evaluator channel ch can use, and where its value lands in a pose. */
static void set_fast(akp_clip_channel* ch) {
    const ak_track* tr = &ch->track;
    ch->fast = AKP_CLIP_FAST_NONE;
    ch->dst = 0;
    if (tr->key_count < 2) return;
    const size_t per = sizeof(ak_transform) / sizeof(float);
    size_t field;
    if (ch->target == AK_CHANNEL_TRANSLATION && tr->eval == AKP_EVAL_LINEAR) {
        ch->fast = AKP_CLIP_FAST_VEC3;
        field = offsetof(ak_transform, translation);
    } else if (ch->target == AK_CHANNEL_SCALE && tr->eval == AKP_EVAL_LINEAR) {
        ch->fast = AKP_CLIP_FAST_VEC3;
        field = offsetof(ak_transform, scale);
    } else if (ch->target == AK_CHANNEL_ROTATION && tr->eval == AKP_EVAL_SLERP) {
        ch->fast = AKP_CLIP_FAST_SLERP;
        field = offsetof(ak_transform, rotation);
    } else if (ch->target == AK_CHANNEL_ROTATION && tr->eval == AKP_EVAL_NLERP) {
        ch->fast = AKP_CLIP_FAST_NLERP;
        field = offsetof(ak_transform, rotation);
    } else {
        return;
    }
    ch->dst = (uint32_t)(ch->index * per + field / sizeof(float));
}

/* akp_track_eval for a FAST channel, inlined: the same operations in the same order, so the
 * same floats (tests/test_clip.c compares it with ak_track_sample on the channel's track). */
static inline void eval_fast(const akp_clip_channel* ch, size_t seg, float t, float* pose) {
    const ak_track* tr = &ch->track;
    const float* times = tr->times;
    size_t n = tr->key_count, stride = tr->stride;
    float* out = pose + ch->dst;
    const float* a;
    if (!(t > times[0])) {
        a = tr->values;
    } else if (t >= times[n - 1]) {
        a = tr->values + (n - 1) * stride;
    } else {
        a = tr->values + seg * stride;
        const float* b = a + stride;
        float t0 = times[seg], t1 = times[seg + 1];
        float u = (t - t0) / (t1 - t0);
        u = u < 0.0f ? 0.0f : (u > 1.0f ? 1.0f : u);
        if (ch->fast == AKP_CLIP_FAST_VEC3) {
            out[0] = a[0] + (b[0] - a[0]) * u;
            out[1] = a[1] + (b[1] - a[1]) * u;
            out[2] = a[2] + (b[2] - a[2]) * u;
            return;
        }
        ak_quat q;
        if (ch->fast == AKP_CLIP_FAST_NLERP || a[5] == 0.0f) {
            q = ak_quat_nlerp(ak_quat_make(a[0], a[1], a[2], a[3]), ak_quat_make(b[0], b[1], b[2], b[3]), u);
        } else {
            float wa = akp_sin_half_pi((1.0f - u) * a[4]) * a[5], wb = akp_sin_half_pi(u * a[4]) * a[5] * a[6];
            q = ak_quat_normalize(ak_quat_make(wa * a[0] + wb * b[0], wa * a[1] + wb * b[1], wa * a[2] + wb * b[2],
                                               wa * a[3] + wb * b[3]));
        }
        out[0] = q.x;
        out[1] = q.y;
        out[2] = q.z;
        out[3] = q.w;
        return;
    }
    out[0] = a[0];
    out[1] = a[1];
    out[2] = a[2];
    if (ch->fast != AKP_CLIP_FAST_VEC3) out[3] = a[3];
}

#if AK_SIMD_SSE2
/* akp_sin_half_pi on four lanes: the same operations in the same order. */
static inline __m128 sin4_half_pi(__m128 x) {
    __m128 x2 = _mm_mul_ps(x, x);
    __m128 p = _mm_set1_ps(1.0f / 6227020800.0f);
    p = _mm_sub_ps(_mm_mul_ps(p, x2), _mm_set1_ps(1.0f / 39916800.0f));
    p = _mm_add_ps(_mm_mul_ps(p, x2), _mm_set1_ps(1.0f / 362880.0f));
    p = _mm_sub_ps(_mm_mul_ps(p, x2), _mm_set1_ps(1.0f / 5040.0f));
    p = _mm_add_ps(_mm_mul_ps(p, x2), _mm_set1_ps(1.0f / 120.0f));
    p = _mm_sub_ps(_mm_mul_ps(p, x2), _mm_set1_ps(1.0f / 6.0f));
    return _mm_add_ps(x, _mm_mul_ps(x, _mm_mul_ps(x2, p)));
}

/* A SLERP channel strictly inside its keys with a non-degenerate segment (a[5] != 0). */
typedef struct slerp_lane {
    const akp_clip_channel* ch;
    size_t seg;
} slerp_lane;

/* eval_fast of four such channels in SSE2 lanes, float for float: the keys and their slerp
 * constants are transposed to lanes, the weights, the blend and the normalisation run in the
 * scalar code's order; a lane whose squared norm needs ak_quat_normalize's rescue path (tiny,
 * infinite or NaN) is redone by eval_fast. */
static void slerp4(const slerp_lane* L, float t, float* pose) {
    const float* a[4];
    float u[4];
    for (int l = 0; l < 4; ++l) {
        const ak_track* tr = &L[l].ch->track;
        a[l] = tr->values + L[l].seg * tr->stride;
        float t0 = tr->times[L[l].seg], t1 = tr->times[L[l].seg + 1];
        float v = (t - t0) / (t1 - t0);
        u[l] = v < 0.0f ? 0.0f : (v > 1.0f ? 1.0f : v);
    }
    __m128 ax = _mm_loadu_ps(a[0]), ay = _mm_loadu_ps(a[1]), az = _mm_loadu_ps(a[2]), aw = _mm_loadu_ps(a[3]);
    __m128 th = _mm_loadu_ps(a[0] + 4), is = _mm_loadu_ps(a[1] + 4), sg = _mm_loadu_ps(a[2] + 4),
           z3 = _mm_loadu_ps(a[3] + 4);
    __m128 bx = _mm_loadu_ps(a[0] + 8), by = _mm_loadu_ps(a[1] + 8), bz = _mm_loadu_ps(a[2] + 8),
           bw = _mm_loadu_ps(a[3] + 8);
    AKP_SIMD_TRANSPOSE4(ax, ay, az, aw);
    AKP_SIMD_TRANSPOSE4(th, is, sg, z3);
    AKP_SIMD_TRANSPOSE4(bx, by, bz, bw);
    (void)z3;
    __m128 U = _mm_loadu_ps(u), one = _mm_set1_ps(1.0f);
    __m128 wa = _mm_mul_ps(sin4_half_pi(_mm_mul_ps(_mm_sub_ps(one, U), th)), is);
    __m128 wb = _mm_mul_ps(_mm_mul_ps(sin4_half_pi(_mm_mul_ps(U, th)), is), sg);
    __m128 qx = _mm_add_ps(_mm_mul_ps(wa, ax), _mm_mul_ps(wb, bx));
    __m128 qy = _mm_add_ps(_mm_mul_ps(wa, ay), _mm_mul_ps(wb, by));
    __m128 qz = _mm_add_ps(_mm_mul_ps(wa, az), _mm_mul_ps(wb, bz));
    __m128 qw = _mm_add_ps(_mm_mul_ps(wa, aw), _mm_mul_ps(wb, bw));
    __m128 n2 = _mm_add_ps(_mm_add_ps(_mm_add_ps(_mm_mul_ps(qx, qx), _mm_mul_ps(qy, qy)), _mm_mul_ps(qz, qz)),
                           _mm_mul_ps(qw, qw));
    __m128 ok = _mm_and_ps(_mm_cmpgt_ps(n2, _mm_set1_ps(1e-30f)), _mm_cmple_ps(n2, _mm_set1_ps(FLT_MAX)));
    __m128 sc = _mm_div_ps(one, _mm_sqrt_ps(n2));
    qx = _mm_mul_ps(qx, sc);
    qy = _mm_mul_ps(qy, sc);
    qz = _mm_mul_ps(qz, sc);
    qw = _mm_mul_ps(qw, sc);
    AKP_SIMD_TRANSPOSE4(qx, qy, qz, qw);
    int good = _mm_movemask_ps(ok);
    __m128 q[4] = {qx, qy, qz, qw};
    for (int l = 0; l < 4; ++l) {
        if (good >> l & 1) _mm_storeu_ps(pose + L[l].ch->dst, q[l]);
        else eval_fast(L[l].ch, L[l].seg, t, pose);
    }
}
#endif

/* Sample channels (list: [count] channel indices; NULL: every channel) at segments segs (NULL:
 * binary search; else the cursor's, updated). */
static void sample_channels(const ak_clip* clip, const uint32_t* list, size_t count, float time, uint32_t* segs,
                            ak_transform* local, float* w, float* s) {
    const akp_clip_channel* ch = clip->channels;
    float* pose = local ? &local[0].translation.x : NULL;
#if AK_SIMD_SSE2
    slerp_lane batch[4];
    int nb = 0;
#endif
    for (size_t li = 0; li < count; ++li) {
        const size_t i = list ? list[li] : li;
        const ak_track* tr = &ch[i].track;
        size_t seg;
        if (segs) {
            /* The cached segment still holds time: no search (forward playback within a key). */
            seg = segs[i];
            size_t last = tr->key_count >= 2 ? tr->key_count - 2 : 0;
            if (!(seg <= last && tr->times[seg] <= time && (seg == last || time < tr->times[seg + 1]))) {
                seg = akp_track_find_from(tr, time, seg);
                segs[i] = (uint32_t)seg;
            }
        } else {
            seg = akp_track_find(tr, time);
        }
        if (ch[i].fast == AKP_CLIP_FAST_NONE) {
            write_channel(&ch[i], seg, time, local, w, s);
            continue;
        }
        if (ch[i].fast == AKP_CLIP_FAST_VEC3 && time > tr->times[0] && time < tr->times[tr->key_count - 1]) {
            /* eval_fast's interior lerp, written here so the common case makes no call. */
            const float* a = tr->values + seg * 3;
            float t0 = tr->times[seg], t1 = tr->times[seg + 1];
            float u = (time - t0) / (t1 - t0);
            u = u < 0.0f ? 0.0f : (u > 1.0f ? 1.0f : u);
            float* out = pose + ch[i].dst;
            out[0] = a[0] + (a[3] - a[0]) * u;
            out[1] = a[1] + (a[4] - a[1]) * u;
            out[2] = a[2] + (a[5] - a[2]) * u;
            continue;
        }
#if AK_SIMD_SSE2
        if (ch[i].fast == AKP_CLIP_FAST_SLERP && time > tr->times[0] && time < tr->times[tr->key_count - 1] &&
            tr->values[seg * tr->stride + 5] != 0.0f) {
            batch[nb].ch = &ch[i];
            batch[nb].seg = seg;
            if (++nb == 4) {
                slerp4(batch, time, pose);
                nb = 0;
            }
            continue;
        }
#endif
        eval_fast(&ch[i], seg, time, pose);
    }
#if AK_SIMD_SSE2
    for (int l = 0; l < nb; ++l) eval_fast(batch[l].ch, batch[l].seg, time, pose);
#endif
}


/* ---- key cache ------------------------------------------------------------------------- */

/* A cursor with the full storage (ak_clip_cursor_storage_count) keeps, after its segment
 * indices, a key cache: for every group of four FAST channels (akp_clip_group) the keys of the
 * segment each lane is in, already transposed to lanes (structure of arrays), and the time
 * interval [lo, hi) over which they stay valid. A sample compares the time with the four
 * intervals in one SIMD operation and interpolates the four channels in lanes; only lanes whose
 * interval the time has left are refreshed, one scalar lane at a time, from the channel's
 * track. The lanes compute the scalar evaluator's operations in its order (division for u,
 * no fused multiply-add), so the values are the same floats as eval_fast / akp_track_eval.
 * Per group, CACHE_FIELDS x 4 floats, field f of lane l at f * 4 + l: */
enum {
    F_LO = 0,   /* the lane is valid for lo <= t < hi */
    F_HI = 1,
    F_T0 = 2,   /* u = (t - t0) / dt, clamped to [0, 1] */
    F_DT = 3,
    F_HOLD = 4, /* all ones: t is outside the keys, the value is a */
    F_FIX = 5,  /* all ones: recompute the lane with eval_fast (slerp of a degenerate segment) */
    F_A = 6,    /* a.x .. a.w */
    F_B = 10,   /* VEC3, NLERP: b - a (b on a's hemisphere for NLERP); SLERP: b */
    F_TH = 14,  /* SLERP: the segment's angle, 1 / sin, sign of b */
    F_IS = 15,
    F_SG = 16,
    F_BR = 17,  /* VEC3, NLERP: b as stored (SLERP: F_B), the next segment's a */
    CACHE_FIELDS = 21
};
#define CACHE_GROUP_U32 ((size_t)CACHE_FIELDS * 4u)

/* Elements of storage for the segment indices plus the cache (with room to align it to 16). */
static size_t cursor_full_count(const ak_clip* clip) {
    return clip->channel_count + (clip->group_count ? 3u + clip->group_count * CACHE_GROUP_U32 : 0u);
}

static uint32_t* cursor_cache(const ak_clip_cursor* cur) {
    const ak_clip* clip = cur->clip;
    if (!clip->group_count || cur->segment_count < cursor_full_count(clip)) return NULL;
    uint32_t* base = cur->segments + clip->channel_count;
    return base + ((16u - ((uintptr_t)base & 15u)) & 15u) / 4u;
}

static inline void put_f(uint32_t* c, size_t field, int lane, float v) { memcpy(&c[field * 4 + (size_t)lane], &v, 4); }

/* Empty intervals: every lane refreshes at its first sample. */
static void cache_reset(const ak_clip* clip, uint32_t* cache) {
    for (size_t g = 0; g < clip->group_count; ++g)
        for (int l = 0; l < 4; ++l) {
            put_f(cache + g * CACHE_GROUP_U32, F_LO, l, INFINITY);
            put_f(cache + g * CACHE_GROUP_U32, F_HI, l, -INFINITY);
        }
}

#if AK_SIMD_SSE2
/* The smallest float above x (x finite or -inf). */
static float next_up(float x) {
    if (x == 0.0f) return FLT_TRUE_MIN;
    uint32_t b;
    memcpy(&b, &x, 4);
    b = x > 0.0f ? b + 1u : b - 1u;
    memcpy(&x, &b, 4);
    return x;
}

/* Three floats at p into lanes 0..2 (lane 3 zero), reading nothing past p[2]. */
static inline __m128 load3(const float* p) {
    return _mm_movelh_ps(_mm_loadl_pi(_mm_setzero_ps(), (const __m64*)(const void*)p), _mm_load_ss(p + 2));
}

#if defined(__GNUC__)
#define AKP_ALWAYS_INLINE __attribute__((always_inline)) inline
#else
#define AKP_ALWAYS_INLINE inline
#endif

/* One lane's refreshed state. */
typedef struct lane_keys {
    float lo, hi, t0, dt;
    int hold; /* -1 or 0 */
    const float* pa;
    const float* pb;
    uint32_t ka, kb; /* the key indices of pa and pb */
} lane_keys;

/* Lane l's new interval and key pointers (refresh true), or harmless fillers. */
static AKP_ALWAYS_INLINE lane_keys lane_refresh(const ak_clip* clip, const akp_clip_group* G, uint32_t* segs, int l, bool refresh,
                                     float t) {
    const ak_track* tr = &clip->channels[G->ch[l]].track;
    const float* times = tr->times;
    const size_t n = tr->key_count, stride = tr->stride;
    lane_keys r = {0.0f, 0.0f, 0.0f, 1.0f, -1, tr->values, tr->values, 0u, 0u};
    if (!refresh) return r;
    if (!(t > times[0])) {
        r.lo = -INFINITY, r.hi = next_up(times[0]);
    } else if (t >= times[n - 1]) {
        r.lo = times[n - 1], r.hi = INFINITY;
        r.pa = r.pb = tr->values + (n - 1) * stride;
        r.ka = r.kb = (uint32_t)(n - 1);
    } else {
        uint32_t* slot = &segs[G->ch[l]];
        size_t k = *slot;
        if (k + 2 < n && times[k + 1] <= t && t < times[k + 2]) ++k; /* the next segment */
        else k = akp_track_find_from(tr, t, k);
        *slot = (uint32_t)k;
        r.lo = k == 0 ? next_up(times[0]) : times[k], r.hi = times[k + 1];
        r.t0 = times[k], r.dt = times[k + 1] - times[k], r.hold = 0;
        r.pa = tr->values + k * stride, r.pb = r.pa + stride;
        r.ka = (uint32_t)k, r.kb = (uint32_t)k + 1u;
    }
    return r;
}

/* Write the keys k0..k3 of the lanes in mask into the cache (full: all four, no blend). */
static AKP_ALWAYS_INLINE void cache_write(const akp_clip_group* G, float* f, int mask, bool full, lane_keys k0,
                                          lane_keys k1, lane_keys k2, lane_keys k3) {
    const float* pa[4] = {k0.pa, k1.pa, k2.pa, k3.pa};
    const float* pb[4] = {k0.pb, k1.pb, k2.pb, k3.pb};
    /* Forward playback reads each track's keys in order, but a clip has more tracks than the
     * hardware prefetcher follows streams: fetch the cache line after the new keys now, so
     * the refreshes a few keys later find it. */
    for (int l = 0; l < 4; ++l)
        if (mask >> l & 1) _mm_prefetch((const char*)(uintptr_t)((uintptr_t)pb[l] + 64u), _MM_HINT_T0); /* may pass the end: a hint */
    const __m128i bits = _mm_setr_epi32(1, 2, 4, 8);
    const __m128 m = _mm_castsi128_ps(_mm_cmpeq_epi32(_mm_and_si128(_mm_set1_epi32(mask), bits), bits));
#define AKP_PUT(field, v)                                                                                        \
    _mm_store_ps(f + 4 * (field), full ? (v) : akp_simd_select(m, (v), _mm_load_ps(f + 4 * (field))))
    AKP_PUT(F_LO, _mm_setr_ps(k0.lo, k1.lo, k2.lo, k3.lo));
    AKP_PUT(F_HI, _mm_setr_ps(k0.hi, k1.hi, k2.hi, k3.hi));
    AKP_PUT(F_T0, _mm_setr_ps(k0.t0, k1.t0, k2.t0, k3.t0));
    AKP_PUT(F_DT, _mm_setr_ps(k0.dt, k1.dt, k2.dt, k3.dt));
    const __m128 hm = _mm_castsi128_ps(_mm_setr_epi32(k0.hold, k1.hold, k2.hold, k3.hold));
    AKP_PUT(F_HOLD, hm);
    if (G->kind == AKP_CLIP_FAST_VEC3) {
        __m128 ax = load3(pa[0]), ay = load3(pa[1]), az = load3(pa[2]), aw = load3(pa[3]);
        __m128 bx = load3(pb[0]), by = load3(pb[1]), bz = load3(pb[2]), bw = load3(pb[3]);
        AKP_SIMD_TRANSPOSE4(ax, ay, az, aw);
        AKP_SIMD_TRANSPOSE4(bx, by, bz, bw);
        (void)aw, (void)bw;
        /* hold lanes: b = a, so b - a = 0 */
        AKP_PUT(F_A, ax), AKP_PUT(F_A + 1, ay), AKP_PUT(F_A + 2, az);
        AKP_PUT(F_B, _mm_sub_ps(bx, ax)), AKP_PUT(F_B + 1, _mm_sub_ps(by, ay)), AKP_PUT(F_B + 2, _mm_sub_ps(bz, az));
        AKP_PUT(F_BR, bx), AKP_PUT(F_BR + 1, by), AKP_PUT(F_BR + 2, bz);
        return;
    }
    __m128 ax = _mm_loadu_ps(pa[0]), ay = _mm_loadu_ps(pa[1]), az = _mm_loadu_ps(pa[2]), aw = _mm_loadu_ps(pa[3]);
    __m128 bx = _mm_loadu_ps(pb[0]), by = _mm_loadu_ps(pb[1]), bz = _mm_loadu_ps(pb[2]), bw = _mm_loadu_ps(pb[3]);
    AKP_SIMD_TRANSPOSE4(ax, ay, az, aw);
    AKP_SIMD_TRANSPOSE4(bx, by, bz, bw);
    AKP_PUT(F_A, ax), AKP_PUT(F_A + 1, ay), AKP_PUT(F_A + 2, az), AKP_PUT(F_A + 3, aw);
    if (G->kind == AKP_CLIP_FAST_NLERP) {
        /* ak_quat_nlerp: b on a's hemisphere (dot summed in ak_quat_dot's order), then b - a */
        __m128 dot = _mm_add_ps(_mm_add_ps(_mm_add_ps(_mm_mul_ps(ax, bx), _mm_mul_ps(ay, by)), _mm_mul_ps(az, bz)),
                                _mm_mul_ps(aw, bw));
        __m128 flip = _mm_and_ps(_mm_cmplt_ps(dot, _mm_setzero_ps()), _mm_set1_ps(-0.0f));
        AKP_PUT(F_B, _mm_sub_ps(_mm_xor_ps(bx, flip), ax));
        AKP_PUT(F_B + 1, _mm_sub_ps(_mm_xor_ps(by, flip), ay));
        AKP_PUT(F_B + 2, _mm_sub_ps(_mm_xor_ps(bz, flip), az));
        AKP_PUT(F_B + 3, _mm_sub_ps(_mm_xor_ps(bw, flip), aw));
        AKP_PUT(F_BR, bx), AKP_PUT(F_BR + 1, by), AKP_PUT(F_BR + 2, bz), AKP_PUT(F_BR + 3, bw);
        AKP_PUT(F_FIX, _mm_setzero_ps());
        return;
    }
    __m128 th = _mm_loadu_ps(pa[0] + 4), is = _mm_loadu_ps(pa[1] + 4), sg = _mm_loadu_ps(pa[2] + 4),
           z3 = _mm_loadu_ps(pa[3] + 4);
    AKP_SIMD_TRANSPOSE4(th, is, sg, z3);
    (void)z3;
    AKP_PUT(F_B, bx), AKP_PUT(F_B + 1, by), AKP_PUT(F_B + 2, bz), AKP_PUT(F_B + 3, bw);
    AKP_PUT(F_TH, th), AKP_PUT(F_IS, is), AKP_PUT(F_SG, sg);
    AKP_PUT(F_FIX, _mm_andnot_ps(hm, _mm_cmpeq_ps(is, _mm_setzero_ps())));
#undef AKP_PUT
}

/* cache_write of a shared group whose four lanes moved from segment k - 1 to k (k: the new
 * interval in k0, pa the new a keys): the new a keys are the old b keys, still in the cache
 * (F_BR; F_B for SLERP) as the same floats, so only the b keys (and SLERP's constants) are
 * loaded and transposed; the stored fields are those cache_write would store. */
static AKP_ALWAYS_INLINE void cache_write_step(const akp_clip_group* G, float* f, lane_keys k0, const float* const* pa,
                                               const float* const* pb, bool intervals) {
    /* No prefetch here (cache_write has one): in forward playback the tracks' keys are read in
     * ascending order, and on the vs_ozz clip (180 tracks, 60 fps playback of 30 fps keys) the
     * four prefetches per group and step made sampling about 10% slower (EPYC Zen 5). */
    if (intervals) {
        _mm_store_ps(f + 4 * F_LO, _mm_set1_ps(k0.lo));
        _mm_store_ps(f + 4 * F_HI, _mm_set1_ps(k0.hi));
        _mm_store_ps(f + 4 * F_T0, _mm_set1_ps(k0.t0));
        _mm_store_ps(f + 4 * F_DT, _mm_set1_ps(k0.dt));
        _mm_store_ps(f + 4 * F_HOLD, _mm_setzero_ps());
    }
    if (G->kind == AKP_CLIP_FAST_VEC3) {
        const __m128 ax = _mm_load_ps(f + 4 * F_BR), ay = _mm_load_ps(f + 4 * (F_BR + 1)),
                     az = _mm_load_ps(f + 4 * (F_BR + 2));
        __m128 bx = load3(pb[0]), by = load3(pb[1]), bz = load3(pb[2]), bw = load3(pb[3]);
        AKP_SIMD_TRANSPOSE4(bx, by, bz, bw);
        (void)bw;
        _mm_store_ps(f + 4 * F_A, ax), _mm_store_ps(f + 4 * (F_A + 1), ay), _mm_store_ps(f + 4 * (F_A + 2), az);
        _mm_store_ps(f + 4 * F_B, _mm_sub_ps(bx, ax)), _mm_store_ps(f + 4 * (F_B + 1), _mm_sub_ps(by, ay));
        _mm_store_ps(f + 4 * (F_B + 2), _mm_sub_ps(bz, az));
        _mm_store_ps(f + 4 * F_BR, bx), _mm_store_ps(f + 4 * (F_BR + 1), by), _mm_store_ps(f + 4 * (F_BR + 2), bz);
        return;
    }
    const int src = G->kind == AKP_CLIP_FAST_NLERP ? F_BR : F_B;
    const __m128 ax = _mm_load_ps(f + 4 * src), ay = _mm_load_ps(f + 4 * (src + 1)), az = _mm_load_ps(f + 4 * (src + 2)),
                 aw = _mm_load_ps(f + 4 * (src + 3));
    __m128 bx = _mm_loadu_ps(pb[0]), by = _mm_loadu_ps(pb[1]), bz = _mm_loadu_ps(pb[2]), bw = _mm_loadu_ps(pb[3]);
    AKP_SIMD_TRANSPOSE4(bx, by, bz, bw);
    _mm_store_ps(f + 4 * F_A, ax), _mm_store_ps(f + 4 * (F_A + 1), ay), _mm_store_ps(f + 4 * (F_A + 2), az);
    _mm_store_ps(f + 4 * (F_A + 3), aw);
    if (G->kind == AKP_CLIP_FAST_NLERP) {
        __m128 dot = _mm_add_ps(_mm_add_ps(_mm_add_ps(_mm_mul_ps(ax, bx), _mm_mul_ps(ay, by)), _mm_mul_ps(az, bz)),
                                _mm_mul_ps(aw, bw));
        __m128 flip = _mm_and_ps(_mm_cmplt_ps(dot, _mm_setzero_ps()), _mm_set1_ps(-0.0f));
        _mm_store_ps(f + 4 * F_B, _mm_sub_ps(_mm_xor_ps(bx, flip), ax));
        _mm_store_ps(f + 4 * (F_B + 1), _mm_sub_ps(_mm_xor_ps(by, flip), ay));
        _mm_store_ps(f + 4 * (F_B + 2), _mm_sub_ps(_mm_xor_ps(bz, flip), az));
        _mm_store_ps(f + 4 * (F_B + 3), _mm_sub_ps(_mm_xor_ps(bw, flip), aw));
        _mm_store_ps(f + 4 * F_BR, bx), _mm_store_ps(f + 4 * (F_BR + 1), by), _mm_store_ps(f + 4 * (F_BR + 2), bz);
        _mm_store_ps(f + 4 * (F_BR + 3), bw);
        _mm_store_ps(f + 4 * F_FIX, _mm_setzero_ps());
        return;
    }
    __m128 th = _mm_loadu_ps(pa[0] + 4), is = _mm_loadu_ps(pa[1] + 4), sg = _mm_loadu_ps(pa[2] + 4),
           z3 = _mm_loadu_ps(pa[3] + 4);
    AKP_SIMD_TRANSPOSE4(th, is, sg, z3);
    (void)z3;
    _mm_store_ps(f + 4 * F_B, bx), _mm_store_ps(f + 4 * (F_B + 1), by), _mm_store_ps(f + 4 * (F_B + 2), bz);
    _mm_store_ps(f + 4 * (F_B + 3), bw);
    _mm_store_ps(f + 4 * F_TH, th), _mm_store_ps(f + 4 * F_IS, is), _mm_store_ps(f + 4 * F_SG, sg);
    _mm_store_ps(f + 4 * F_FIX, _mm_cmpeq_ps(is, _mm_setzero_ps()));
}

/* Write the cache of shared group G for the interval and key indices in k0 (lane_refresh of
 * lane 0, or of a track with the same key times), and the lanes' segments. step: the cache
 * holds segment k - 1 of every lane and the new interval is segment k (the forward playback
 * step, k0.hold == 0; the caller tells it from the segment, interval end and hold flag the
 * cache had): only the b keys are loaded (cache_write_step), the interval fields written when
 * intervals. Otherwise the whole cache is written (cache_write). */
static AKP_ALWAYS_INLINE void refresh_shared(const ak_clip* clip, const akp_clip_group* G, uint32_t* segs, float* f,
                                             lane_keys k0, bool step, bool intervals) {
    const float* pa[4];
    const float* pb[4];
    const size_t stride = clip->channels[G->ch[0]].track.stride; /* the same for the four (shared) */
    const size_t oa = k0.ka * stride, ob = k0.kb * stride;
    for (int l = 0; l < 4; ++l) {
        const float* v = clip->channels[G->ch[l]].track.values;
        pa[l] = v + oa, pb[l] = v + ob;
    }
    if (k0.hold == 0) {
        for (int l = 0; l < 4; ++l) segs[G->ch[l]] = k0.ka;
        if (step) {
            cache_write_step(G, f, k0, pa, pb, intervals);
            return;
        }
    } else {
        for (int l = 1; l < 4; ++l) segs[G->ch[l]] = segs[G->ch[0]];
    }
    lane_keys k[4];
    for (int l = 0; l < 4; ++l) k[l] = k0, k[l].pa = pa[l], k[l].pb = pb[l];
    cache_write(G, f, 15, true, k[0], k[1], k[2], k[3]);
}

/* Refresh the lanes of group G set in mask for time t (not NaN): per lane, in scalar code, the
 * segment (usually the next one) or the key it holds outside the keys; then the keys of the
 * four lanes are transposed in SIMD registers and the refreshed lanes written into the cache.
 * A group whose channels share their key times (G->shared) refreshes all four lanes together,
 * so lane 0's segment serves all four. */
static AKP_ALWAYS_INLINE void refresh_group(const ak_clip* clip, const akp_clip_group* G, uint32_t* segs, float* f, int mask, float t) {
    if (mask == 15 && G->shared) {
        const uint32_t old = segs[G->ch[0]];
        const float old_hi = f[4 * F_HI];
        const bool old_inside = ((const uint32_t*)(const void*)f)[4 * F_HOLD] == 0u;
        const lane_keys k0 = lane_refresh(clip, G, segs, 0, true, t);
        refresh_shared(clip, G, segs, f, k0,
                       k0.hold == 0 && old_inside && k0.ka == old + 1u &&
                           old_hi == clip->channels[G->ch[0]].track.times[k0.ka],
                       true);
        return;
    }
    const lane_keys k0 = lane_refresh(clip, G, segs, 0, mask & 1, t), k1 = lane_refresh(clip, G, segs, 1, mask & 2, t),
                    k2 = lane_refresh(clip, G, segs, 2, mask & 4, t), k3 = lane_refresh(clip, G, segs, 3, mask & 8, t);
    if (mask == 15) cache_write(G, f, 15, true, k0, k1, k2, k3);
    else cache_write(G, f, mask, false, k0, k1, k2, k3);
}

/* Make group g's cached lanes valid for time: refresh the lanes whose interval it has left. */
static AKP_ALWAYS_INLINE void group_validate(const ak_clip* clip, size_t g, float time, uint32_t* segs,
                                             uint32_t* cache) {
    const __m128 T = _mm_set1_ps(time);
    uint32_t* c = cache + g * CACHE_GROUP_U32;
    const float* f = (const float*)(const void*)c;
    int in = _mm_movemask_ps(_mm_and_ps(_mm_cmpge_ps(T, _mm_load_ps(f + 4 * F_LO)),
                                        _mm_cmplt_ps(T, _mm_load_ps(f + 4 * F_HI))));
    if (in != 15) refresh_group(clip, &clip->groups[g], segs, (float*)(void*)c, ~in & 15, time);
}

/* The lanes' interpolation parameter at time T from cache fields f: u = (t - t0) / dt clamped. */
static AKP_ALWAYS_INLINE __m128 lanes_u(const float* f, __m128 T) {
    __m128 u = _mm_div_ps(_mm_sub_ps(T, _mm_load_ps(f + 4 * F_T0)), _mm_load_ps(f + 4 * F_DT));
    return _mm_min_ps(_mm_set1_ps(1.0f), _mm_max_ps(_mm_setzero_ps(), u)); /* u < 0 ? 0 : (u > 1 ? 1 : u), NaN kept */
}

/* Sample group g through its valid cache with the lanes' u (lanes_u) and hold mask. */
static AKP_ALWAYS_INLINE void sample_group_at(const ak_clip* clip, size_t g, __m128 u, __m128 hold, float time,
                                              uint32_t* segs, uint32_t* cache, float* pose) {
    const __m128 one = _mm_set1_ps(1.0f), ones = _mm_castsi128_ps(_mm_set1_epi32(-1));
    {
        const akp_clip_group* G = &clip->groups[g];
        uint32_t* c = cache + g * CACHE_GROUP_U32;
        const float* f = (const float*)(const void*)c;
        __m128 ax = _mm_load_ps(f + 4 * F_A), ay = _mm_load_ps(f + 4 * (F_A + 1)), az = _mm_load_ps(f + 4 * (F_A + 2));
        if (G->kind == AKP_CLIP_FAST_VEC3) {
            __m128 x = _mm_add_ps(ax, _mm_mul_ps(_mm_load_ps(f + 4 * F_B), u));
            __m128 y = _mm_add_ps(ay, _mm_mul_ps(_mm_load_ps(f + 4 * (F_B + 1)), u));
            __m128 z = _mm_add_ps(az, _mm_mul_ps(_mm_load_ps(f + 4 * (F_B + 2)), u));
            if (_mm_movemask_ps(hold)) {
                x = akp_simd_select(hold, ax, x);
                y = akp_simd_select(hold, ay, y);
                z = akp_simd_select(hold, az, z);
            }
            __m128 w = _mm_setzero_ps();
            AKP_SIMD_TRANSPOSE4(x, y, z, w);
            const __m128 r[4] = {x, y, z, w};
            for (int l = 0; l < 4; ++l) {
                float* o = pose + G->dst[l];
                _mm_storel_pi((__m64*)(void*)o, r[l]);
                _mm_store_ss(o + 2, _mm_movehl_ps(r[l], r[l]));
            }
            return;
        }
        __m128 aw = _mm_load_ps(f + 4 * (F_A + 3));
        __m128 qx, qy, qz, qw;
        const __m128 bx = _mm_load_ps(f + 4 * F_B), by = _mm_load_ps(f + 4 * (F_B + 1)),
                     bz = _mm_load_ps(f + 4 * (F_B + 2)), bw = _mm_load_ps(f + 4 * (F_B + 3));
        if (G->kind == AKP_CLIP_FAST_NLERP) {
            qx = _mm_add_ps(ax, _mm_mul_ps(bx, u));
            qy = _mm_add_ps(ay, _mm_mul_ps(by, u));
            qz = _mm_add_ps(az, _mm_mul_ps(bz, u));
            qw = _mm_add_ps(aw, _mm_mul_ps(bw, u));
        } else {
            const __m128 th = _mm_load_ps(f + 4 * F_TH), is = _mm_load_ps(f + 4 * F_IS);
            __m128 wa = _mm_mul_ps(sin4_half_pi(_mm_mul_ps(_mm_sub_ps(one, u), th)), is);
            __m128 wb = _mm_mul_ps(_mm_mul_ps(sin4_half_pi(_mm_mul_ps(u, th)), is), _mm_load_ps(f + 4 * F_SG));
            qx = _mm_add_ps(_mm_mul_ps(wa, ax), _mm_mul_ps(wb, bx));
            qy = _mm_add_ps(_mm_mul_ps(wa, ay), _mm_mul_ps(wb, by));
            qz = _mm_add_ps(_mm_mul_ps(wa, az), _mm_mul_ps(wb, bz));
            qw = _mm_add_ps(_mm_mul_ps(wa, aw), _mm_mul_ps(wb, bw));
        }
        __m128 n2 = _mm_add_ps(_mm_add_ps(_mm_add_ps(_mm_mul_ps(qx, qx), _mm_mul_ps(qy, qy)), _mm_mul_ps(qz, qz)),
                               _mm_mul_ps(qw, qw));
        __m128 ok = _mm_and_ps(_mm_cmpgt_ps(n2, _mm_set1_ps(1e-30f)), _mm_cmple_ps(n2, _mm_set1_ps(FLT_MAX)));
        __m128 sc = _mm_div_ps(one, _mm_sqrt_ps(n2));
        qx = akp_simd_select(hold, ax, _mm_mul_ps(qx, sc));
        qy = akp_simd_select(hold, ay, _mm_mul_ps(qy, sc));
        qz = akp_simd_select(hold, az, _mm_mul_ps(qz, sc));
        qw = akp_simd_select(hold, aw, _mm_mul_ps(qw, sc));
        AKP_SIMD_TRANSPOSE4(qx, qy, qz, qw);
        const __m128 r[4] = {qx, qy, qz, qw};
        /* lanes to redo in scalar code: rescue normalisations and degenerate slerp segments */
        int redo = _mm_movemask_ps(_mm_andnot_ps(hold, _mm_or_ps(_mm_andnot_ps(ok, ones), _mm_load_ps(f + 4 * F_FIX))));
        for (int l = 0; l < 4; ++l) _mm_storeu_ps(pose + G->dst[l], r[l]);
        if (redo)
            for (int l = 0; l < 4; ++l)
                if (redo >> l & 1) eval_fast(&clip->channels[G->ch[l]], segs[G->ch[l]], time, pose);
    }
}

/* Sample group g through the cache (time not NaN). */
static AKP_ALWAYS_INLINE void sample_group(const ak_clip* clip, size_t g, float time, uint32_t* segs, uint32_t* cache,
                                           float* pose) {
    group_validate(clip, g, time, segs, cache);
    const float* f = (const float*)(const void*)(cache + g * CACHE_GROUP_U32);
    sample_group_at(clip, g, lanes_u(f, _mm_set1_ps(time)), _mm_load_ps(f + 4 * F_HOLD), time, segs, cache, pose);
}

/* A uniform clip (clip->uniform: every group shared, all with the same key times) keeps one
 * interval for the whole cache, in group 0's fields: every sample validates or refreshes all
 * groups together (the groups' caches hold the same segment), and the other groups' interval
 * fields (lo, hi, t0, dt, hold) are written only by full refreshes and never read. Make the
 * cache valid for time (not NaN): when group 0's interval does not hold it, one key search
 * (lane_refresh of group 0's lane 0) and every group refreshed with its result; the forward
 * step (cache_write_step) when group 0's cache holds the segment before the new one and the
 * group's lane 0 segment is group 0's (the scalar kernel moves the segments, not the cache). */
static AKP_ALWAYS_INLINE void uniform_validate(const ak_clip* clip, float time, uint32_t* segs, uint32_t* cache) {
    const __m128 T = _mm_set1_ps(time);
    float* f0 = (float*)(void*)cache;
    if (_mm_movemask_ps(_mm_and_ps(_mm_cmpge_ps(T, _mm_load_ps(f0 + 4 * F_LO)), _mm_cmplt_ps(T, _mm_load_ps(f0 + 4 * F_HI)))) ==
        15)
        return;
    const akp_clip_group* G0 = &clip->groups[0];
    const uint32_t old = segs[G0->ch[0]];
    const float old_hi = f0[4 * F_HI];
    const bool old_inside = ((const uint32_t*)(const void*)f0)[4 * F_HOLD] == 0u;
    const lane_keys k0 = lane_refresh(clip, G0, segs, 0, true, time);
    segs[G0->ch[0]] = old;
    const bool step = k0.hold == 0 && old_inside && k0.ka == old + 1u &&
                      old_hi == clip->channels[G0->ch[0]].track.times[k0.ka];
    for (size_t g = 0; g < clip->group_count; ++g) {
        const akp_clip_group* G = &clip->groups[g];
        float* f = (float*)(void*)(cache + g * CACHE_GROUP_U32);
        /* the step needs this group's cache to hold segment old too */
        refresh_shared(clip, G, segs, f, k0, step && segs[G->ch[0]] == old, g == 0);
    }
}

/* Sample every group through the cache (time not NaN): the SSE2 kernel. */
static AKP_ALWAYS_INLINE void sample_groups(const ak_clip* clip, float time, uint32_t* segs, uint32_t* cache,
                                            float* pose) {
    if (clip->uniform) {
        uniform_validate(clip, time, segs, cache);
        const float* f0 = (const float*)(const void*)cache;
        const __m128 u = lanes_u(f0, _mm_set1_ps(time)), hold = _mm_load_ps(f0 + 4 * F_HOLD);
        for (size_t g = 0; g < clip->group_count; ++g) sample_group_at(clip, g, u, hold, time, segs, cache, pose);
        return;
    }
    for (size_t g = 0; g < clip->group_count; ++g) sample_group(clip, g, time, segs, cache, pose);
}

#if defined(__GNUC__) && defined(__x86_64__)
#include <immintrin.h>
/* sin4_half_pi on eight lanes. */
__attribute__((target("avx2"), always_inline)) static inline __m256 sin8_half_pi(__m256 x) {
    __m256 x2 = _mm256_mul_ps(x, x);
    __m256 p = _mm256_set1_ps(1.0f / 6227020800.0f);
    p = _mm256_sub_ps(_mm256_mul_ps(p, x2), _mm256_set1_ps(1.0f / 39916800.0f));
    p = _mm256_add_ps(_mm256_mul_ps(p, x2), _mm256_set1_ps(1.0f / 362880.0f));
    p = _mm256_sub_ps(_mm256_mul_ps(p, x2), _mm256_set1_ps(1.0f / 5040.0f));
    p = _mm256_add_ps(_mm256_mul_ps(p, x2), _mm256_set1_ps(1.0f / 120.0f));
    p = _mm256_sub_ps(_mm256_mul_ps(p, x2), _mm256_set1_ps(1.0f / 6.0f));
    return _mm256_add_ps(x, _mm256_mul_ps(x, _mm256_mul_ps(x2, p)));
}

/* Two SLERP groups g and g + 1 at once, group g in the low and g + 1 in the high half of AVX
 * registers: sample_group's SLERP operations lane for lane (the same floats), half the
 * instructions for the interpolation and the transposes. */
__attribute__((target("avx2"), always_inline)) static inline void slerp_pair8_at(const ak_clip* clip, size_t g, __m256 u,
                                                                                 __m256 hold, float time, uint32_t* segs,
                                                                                 uint32_t* cache, float* pose) {
    const akp_clip_group* G[2] = {&clip->groups[g], &clip->groups[g + 1]};
    const float* f0 = (const float*)(const void*)(cache + g * CACHE_GROUP_U32);
    const float* f1 = f0 + CACHE_GROUP_U32;
#define AKP_LD8(field) _mm256_insertf128_ps(_mm256_castps128_ps256(_mm_load_ps(f0 + 4 * (field))), _mm_load_ps(f1 + 4 * (field)), 1)
    const __m256 one = _mm256_set1_ps(1.0f), ones = _mm256_castsi256_ps(_mm256_set1_epi32(-1));
    const __m256 ax = AKP_LD8(F_A), ay = AKP_LD8(F_A + 1), az = AKP_LD8(F_A + 2), aw = AKP_LD8(F_A + 3);
    const __m256 bx = AKP_LD8(F_B), by = AKP_LD8(F_B + 1), bz = AKP_LD8(F_B + 2), bw = AKP_LD8(F_B + 3);
    const __m256 th = AKP_LD8(F_TH), is = AKP_LD8(F_IS);
    __m256 wa = _mm256_mul_ps(sin8_half_pi(_mm256_mul_ps(_mm256_sub_ps(one, u), th)), is);
    __m256 wb = _mm256_mul_ps(_mm256_mul_ps(sin8_half_pi(_mm256_mul_ps(u, th)), is), AKP_LD8(F_SG));
    __m256 qx = _mm256_add_ps(_mm256_mul_ps(wa, ax), _mm256_mul_ps(wb, bx));
    __m256 qy = _mm256_add_ps(_mm256_mul_ps(wa, ay), _mm256_mul_ps(wb, by));
    __m256 qz = _mm256_add_ps(_mm256_mul_ps(wa, az), _mm256_mul_ps(wb, bz));
    __m256 qw = _mm256_add_ps(_mm256_mul_ps(wa, aw), _mm256_mul_ps(wb, bw));
    __m256 n2 = _mm256_add_ps(
        _mm256_add_ps(_mm256_add_ps(_mm256_mul_ps(qx, qx), _mm256_mul_ps(qy, qy)), _mm256_mul_ps(qz, qz)),
        _mm256_mul_ps(qw, qw));
    __m256 ok = _mm256_and_ps(_mm256_cmp_ps(n2, _mm256_set1_ps(1e-30f), _CMP_GT_OQ),
                              _mm256_cmp_ps(n2, _mm256_set1_ps(FLT_MAX), _CMP_LE_OQ));
    __m256 sc = _mm256_div_ps(one, _mm256_sqrt_ps(n2));
    qx = _mm256_blendv_ps(_mm256_mul_ps(qx, sc), ax, hold);
    qy = _mm256_blendv_ps(_mm256_mul_ps(qy, sc), ay, hold);
    qz = _mm256_blendv_ps(_mm256_mul_ps(qz, sc), az, hold);
    qw = _mm256_blendv_ps(_mm256_mul_ps(qw, sc), aw, hold);
    /* _MM_TRANSPOSE4_PS in both halves */
    const __m256 t0 = _mm256_unpacklo_ps(qx, qy), t1 = _mm256_unpackhi_ps(qx, qy);
    const __m256 t2 = _mm256_unpacklo_ps(qz, qw), t3 = _mm256_unpackhi_ps(qz, qw);
    const __m256 r[4] = {_mm256_shuffle_ps(t0, t2, 0x44), _mm256_shuffle_ps(t0, t2, 0xEE),
                         _mm256_shuffle_ps(t1, t3, 0x44), _mm256_shuffle_ps(t1, t3, 0xEE)};
    const int redo = _mm256_movemask_ps(
        _mm256_andnot_ps(hold, _mm256_or_ps(_mm256_andnot_ps(ok, ones), AKP_LD8(F_FIX))));
#undef AKP_LD8
    for (int l = 0; l < 4; ++l) {
        _mm_storeu_ps(pose + G[0]->dst[l], _mm256_castps256_ps128(r[l]));
        _mm_storeu_ps(pose + G[1]->dst[l], _mm256_extractf128_ps(r[l], 1));
    }
    if (redo)
        for (int h = 0; h < 2; ++h)
            for (int l = 0; l < 4; ++l)
                if (redo >> (4 * h + l) & 1) eval_fast(&clip->channels[G[h]->ch[l]], segs[G[h]->ch[l]], time, pose);
}

/* Two SLERP groups g and g + 1 through the cache (time not NaN), each with its own interval. */
__attribute__((target("avx2"), always_inline)) static inline void slerp_pair8(const ak_clip* clip, size_t g, float time,
                                                                              uint32_t* segs, uint32_t* cache,
                                                                              float* pose) {
    group_validate(clip, g, time, segs, cache);
    group_validate(clip, g + 1, time, segs, cache);
    const float* f0 = (const float*)(const void*)(cache + g * CACHE_GROUP_U32);
    const float* f1 = f0 + CACHE_GROUP_U32;
    const __m128 T = _mm_set1_ps(time);
    const __m256 u = _mm256_insertf128_ps(_mm256_castps128_ps256(lanes_u(f0, T)), lanes_u(f1, T), 1);
    const __m256 hold =
        _mm256_insertf128_ps(_mm256_castps128_ps256(_mm_load_ps(f0 + 4 * F_HOLD)), _mm_load_ps(f1 + 4 * F_HOLD), 1);
    slerp_pair8_at(clip, g, u, hold, time, segs, cache, pose);
}

/* The AVX kernels' loop: consecutive SLERP groups two by two, the rest as sample_groups. */
__attribute__((target("avx2"), always_inline)) static inline void sample_groups_pairs(const ak_clip* clip, float time,
                                                                                      uint32_t* segs, uint32_t* cache,
                                                                                      float* pose) {
    if (clip->uniform) {
        uniform_validate(clip, time, segs, cache);
        const float* f0 = (const float*)(const void*)cache;
        const __m128 u = lanes_u(f0, _mm_set1_ps(time)), hold = _mm_load_ps(f0 + 4 * F_HOLD);
        const __m256 u8 = _mm256_insertf128_ps(_mm256_castps128_ps256(u), u, 1),
                     hold8 = _mm256_insertf128_ps(_mm256_castps128_ps256(hold), hold, 1);
        for (size_t g = 0; g < clip->group_count; ++g) {
            if (g + 1 < clip->group_count && clip->groups[g].kind == AKP_CLIP_FAST_SLERP &&
                clip->groups[g + 1].kind == AKP_CLIP_FAST_SLERP) {
                slerp_pair8_at(clip, g, u8, hold8, time, segs, cache, pose);
                ++g;
                continue;
            }
            sample_group_at(clip, g, u, hold, time, segs, cache, pose);
        }
        return;
    }
    for (size_t g = 0; g < clip->group_count; ++g) {
        if (g + 1 < clip->group_count && clip->groups[g].kind == AKP_CLIP_FAST_SLERP &&
            clip->groups[g + 1].kind == AKP_CLIP_FAST_SLERP) {
            slerp_pair8(clip, g, time, segs, cache, pose);
            ++g;
            continue;
        }
        sample_group(clip, g, time, segs, cache, pose);
    }
}
#endif

/* sample_groups compiled three times: SSE2 (the x86-64 baseline), and with the VEX (AVX2) and
 * EVEX (AVX-512 VL: 32 registers) encodings for CPUs that have them, chosen at run time
 * (clip->sample_kernel). The same SSE-width operations in the same order, no FMA (the build
 * disables contraction), so every kernel gives the same floats. */
static void sample_groups_sse2(const ak_clip* clip, float time, uint32_t* segs, uint32_t* cache, float* pose) {
    sample_groups(clip, time, segs, cache, pose);
}
#if defined(__GNUC__) && defined(__x86_64__)
#define AKP_CLIP_VEX 1
__attribute__((target("avx2"))) static void sample_groups_avx2(const ak_clip* clip, float time, uint32_t* segs,
                                                               uint32_t* cache, float* pose) {
    sample_groups_pairs(clip, time, segs, cache, pose);
}
__attribute__((target("avx512f,avx512vl,avx2"))) static void sample_groups_avx512(const ak_clip* clip, float time,
                                                                                  uint32_t* segs, uint32_t* cache,
                                                                                  float* pose) {
    sample_groups_pairs(clip, time, segs, cache, pose);
}
#else
#define AKP_CLIP_VEX 0
#endif
#endif

/* The sampling kernel for a limit on this CPU (AKP_CLIP_K_*). */
static uint8_t clip_kernel_pick(ak_clip_simd limit) {
    const ak_clip_simd lim = limit == AK_CLIP_SIMD_DEFAULT ? AK_CLIP_SIMD_AVX512 : limit;
    if (lim == AK_CLIP_SIMD_SCALAR) return AKP_CLIP_K_SCALAR;
#if AK_SIMD_SSE2 && AKP_CLIP_VEX
    if (lim >= AK_CLIP_SIMD_AVX512 && __builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512vl") &&
        __builtin_cpu_supports("avx2"))
        return AKP_CLIP_K_AVX512;
    if (lim >= AK_CLIP_SIMD_AVX2 && __builtin_cpu_supports("avx2")) return AKP_CLIP_K_AVX2;
#endif
#if AK_SIMD_SSE2
    return AKP_CLIP_K_SSE2;
#else
    return AKP_CLIP_K_SCALAR;
#endif
}

ak_result ak_clip_set_simd_limit(ak_clip* clip, ak_clip_simd limit) {
    if (!clip) return AK_ERR_NULL_ARG;
    if ((unsigned)limit >= (unsigned)AK_CLIP_SIMD_COUNT) return AK_ERR_BAD_ARG;
    clip->sample_kernel = clip_kernel_pick(limit);
    return AK_OK;
}

const char* ak_clip_simd_name(const ak_clip* clip) {
    static const char* const names[] = {"scalar", "sse2", "avx2", "avx512"};
    return clip ? names[clip->sample_kernel] : "";
}

/* Group the FAST channels four by four per kind (SIMD builds); the rest go to the slow list. */
static void make_groups(ak_clip* clip) {
    clip->group_count = 0;
    clip->slow_count = 0;
#if AK_SIMD_SSE2
    static const akp_clip_fast kinds[3] = {AKP_CLIP_FAST_VEC3, AKP_CLIP_FAST_SLERP, AKP_CLIP_FAST_NLERP};
    for (int k = 0; k < 3; ++k) {
        int lane = 4;
        for (size_t i = 0; i < clip->channel_count; ++i) {
            if (clip->channels[i].fast != kinds[k]) continue;
            if (lane == 4) {
                akp_clip_group* g = &clip->groups[clip->group_count++];
                g->kind = kinds[k];
                for (int l = 0; l < 4; ++l) g->ch[l] = (uint32_t)i, g->dst[l] = clip->channels[i].dst;
                lane = 0;
            }
            akp_clip_group* g = &clip->groups[clip->group_count - 1];
            g->ch[lane] = (uint32_t)i;
            g->dst[lane] = clip->channels[i].dst;
            ++lane;
        }
    }
    for (size_t g = 0; g < clip->group_count; ++g) {
        akp_clip_group* G = &clip->groups[g];
        const ak_track* t0 = &clip->channels[G->ch[0]].track;
        G->shared = true;
        for (int l = 1; l < 4; ++l) {
            const ak_track* tl = &clip->channels[G->ch[l]].track;
            G->shared = G->shared && tl->key_count == t0->key_count && tl->stride == t0->stride &&
                        (tl->times == t0->times || !memcmp(tl->times, t0->times, t0->key_count * sizeof(float)));
        }
    }
    clip->uniform = clip->group_count > 0;
    for (size_t g = 0; g < clip->group_count && clip->uniform; ++g) {
        const ak_track* t0 = &clip->channels[clip->groups[0].ch[0]].track;
        const ak_track* tg = &clip->channels[clip->groups[g].ch[0]].track;
        clip->uniform = clip->groups[g].shared && tg->key_count == t0->key_count &&
                        (tg->times == t0->times || !memcmp(tg->times, t0->times, t0->key_count * sizeof(float)));
    }
    for (size_t i = 0; i < clip->channel_count; ++i)
        if (clip->channels[i].fast == AKP_CLIP_FAST_NONE) clip->slow[clip->slow_count++] = (uint32_t)i;
#else
    for (size_t i = 0; i < clip->channel_count; ++i) clip->slow[clip->slow_count++] = (uint32_t)i;
#endif
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
    const size_t max_groups = nch / 4u + 3u; /* four per group, one partial group per kind */
    const size_t head = akp_align16(sizeof(ak_clip)) + akp_align16(nch * sizeof(akp_clip_channel)) +
                        akp_align16(max_groups * sizeof(akp_clip_group)) + akp_align16(nch * sizeof(uint32_t));
    size_t size = head;
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
    const int overlap = any_overlap(raw->channels, nch, alloc);
    if (overlap < 0) return AK_ERR_NO_MEMORY;
    for (size_t i = 0; overlap && i < nch; ++i) { /* name the first pair, as the pairwise check did */
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
    clip->groups = (akp_clip_group*)(void*)(mem + akp_align16(sizeof(ak_clip)) + akp_align16(nch * sizeof(akp_clip_channel)));
    clip->slow = (uint32_t*)(void*)((char*)clip->groups + akp_align16(max_groups * sizeof(akp_clip_group)));
    char* data = mem + head;
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
        set_fast(ch);
        data += akp_track_data_size(&resolved);
        float end = ch->track.times[ch->track.key_count - 1];
        if (end > last) last = end;
    }
    clip->duration = raw->duration > 0.0f ? raw->duration : last;
    make_groups(clip);
    clip->sample_kernel = clip_kernel_pick(AK_CLIP_SIMD_DEFAULT);
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

size_t ak_clip_cursor_storage_count(const ak_clip* clip) { return clip ? cursor_full_count(clip) : 0u; }

ak_result ak_clip_cursor_init(ak_clip_cursor* cursor, const ak_clip* clip, ak_u32_span storage) {
    if (!cursor || !clip) return AK_ERR_NULL_ARG;
    size_t need = clip->channel_count;
    if (need && !storage.ptr) return AK_ERR_NULL_ARG;
    if (storage.count < need) return AK_ERR_SPAN_SMALL;
    for (size_t i = 0; i < need; ++i) storage.ptr[i] = 0u;
    cursor->clip = clip;
    cursor->segments = storage.ptr;
    cursor->segment_count = storage.count;
    uint32_t* cache = cursor_cache(cursor);
    if (cache) cache_reset(clip, cache);
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
    uint32_t* cache = cursor && time == time ? cursor_cache(cursor) : NULL; /* NaN: the plain path */
#if AK_SIMD_SSE2
    if (cache && clip->sample_kernel != AKP_CLIP_K_SCALAR) {
        if (clip->has_joint_channels) {
            float* pose = &local.ptr[0].translation.x;
            switch (clip->sample_kernel) {
#if AKP_CLIP_VEX
            case AKP_CLIP_K_AVX512: sample_groups_avx512(clip, time, cursor->segments, cache, pose); break;
            case AKP_CLIP_K_AVX2: sample_groups_avx2(clip, time, cursor->segments, cache, pose); break;
#endif
            default: sample_groups_sse2(clip, time, cursor->segments, cache, pose); break;
            }
        }
        sample_channels(clip, clip->slow, clip->slow_count, time, cursor->segments, local.ptr, w, s);
        return AK_OK;
    }
#endif
    (void)cache;
    /* A NaN time with a key cache: binary search, leaving the cursor's segments alone. The
     * cache's lanes keep their keys through the NaN sample and redo degenerate slerp segments
     * (equal keys) from those segments, so they must still match the cache. */
    uint32_t* segs = cursor && !(time != time && cursor_cache(cursor)) ? cursor->segments : NULL;
    sample_channels(clip, NULL, clip->channel_count, time, segs, local.ptr, w, s);
    return AK_OK;
}

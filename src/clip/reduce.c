/* Keyframe reduction (clip.h, ak_clip_reduce): Douglas-Peucker per channel with a local error
 * metric, checked and tightened until the model-space error meets the tolerance. */
#include <animkit/clip.h>

#include "clip/clip_internal.h"
#include "internal.h"

/* ---- static helpers ------------------------------------------------------------------ */

/* Modes whose runtime keys hold the raw values unchanged (so they can be rebuilt). */
static bool copyable(const ak_track* tr) {
    switch (tr->interp) {
    case AK_INTERP_STEP:
    case AK_INTERP_LINEAR:
    case AK_INTERP_NLERP:
    case AK_INTERP_CUBICSPLINE:
    case AK_INTERP_HERMITE:
        return true;
    default:
        return false;
    }
}

static bool reducible(const akp_clip_channel* ch) {
    const ak_track* tr = &ch->track;
    bool joint = ch->target == AK_CHANNEL_TRANSLATION || ch->target == AK_CHANNEL_ROTATION ||
                 ch->target == AK_CHANNEL_SCALE;
    return joint && tr->key_count >= 3 &&
           (tr->eval == AKP_EVAL_LINEAR || tr->eval == AKP_EVAL_SLERP || tr->eval == AKP_EVAL_NLERP);
}

static uint32_t raw_stride_of(const ak_track* tr) {
    return tr->stride == 8u && tr->eval == AKP_EVAL_SLERP ? 4u : tr->stride;
}

/* Local error of key k against the interpolation of keys i and j (i < k < j): translation in
 * model units, rotation as angle x radius, scale as the largest component change x radius. */
static double key_error(const akp_clip_channel* ch, size_t i, size_t k, size_t j, double radius) {
    const ak_track* tr = &ch->track;
    const float* a = tr->values + i * tr->stride;
    const float* b = tr->values + j * tr->stride;
    const float* v = tr->values + k * tr->stride;
    float u = (tr->times[k] - tr->times[i]) / (tr->times[j] - tr->times[i]);
    if (ch->target == AK_CHANNEL_ROTATION) {
        ak_quat qa = ak_quat_make(a[0], a[1], a[2], a[3]), qb = ak_quat_make(b[0], b[1], b[2], b[3]);
        ak_quat q = tr->eval == AKP_EVAL_NLERP ? ak_quat_nlerp(qa, qb, u) : ak_quat_slerp(qa, qb, u);
        /* rotation angle between q and v from the chord (well conditioned for small angles,
         * unlike acos of the dot product): 4 asin(|q -+ v| / 2) for unit quaternions */
        double qd[4] = {q.x, q.y, q.z, q.w}, vd[4] = {v[0], v[1], v[2], v[3]}, nq = 0.0, nv = 0.0, dot = 0.0;
        for (int c = 0; c < 4; ++c) nq += qd[c] * qd[c], nv += vd[c] * vd[c], dot += qd[c] * vd[c];
        double s = dot < 0.0 ? -1.0 : 1.0, chord = 0.0;
        for (int c = 0; c < 4; ++c) {
            double e = qd[c] / sqrt(nq) - s * vd[c] / sqrt(nv);
            chord += e * e;
        }
        double h = 0.5 * sqrt(chord);
        return 4.0 * asin(h < 1.0 ? h : 1.0) * radius;
    }
    double e = 0.0;
    for (int c = 0; c < 3; ++c) {
        double x = (double)a[c] + ((double)b[c] - a[c]) * u - v[c];
        e = ch->target == AK_CHANNEL_TRANSLATION ? e + x * x : fmax(e, fabs(x));
    }
    return ch->target == AK_CHANNEL_TRANSLATION ? sqrt(e) : e * radius;
}

/* Douglas-Peucker over keys [0, n): keep[k] = 1 for the keys needed within tol. stack holds
 * 2 n indices (explicit, so no recursion depth). */
static void simplify(const akp_clip_channel* ch, double tol, double radius, uint8_t* keep, size_t* stack) {
    size_t n = ch->track.key_count, top = 0;
    memset(keep, 0, n);
    keep[0] = keep[n - 1] = 1;
    stack[top++] = 0, stack[top++] = n - 1;
    while (top) {
        size_t j = stack[--top], i = stack[--top];
        double worst = -1.0;
        size_t wk = 0;
        for (size_t k = i + 1; k < j; ++k) {
            double e = key_error(ch, i, k, j, radius);
            if (e > worst) worst = e, wk = k;
        }
        if (j > i + 1 && worst > tol) {
            keep[wk] = 1;
            stack[top++] = i, stack[top++] = wk;
            stack[top++] = wk, stack[top++] = j;
        }
    }
}

/* Model matrices of pose by parents (parents before children). */
static void pose_fk(const int32_t* parents, const ak_transform* pose, size_t n, ak_mat4* out) {
    for (size_t i = 0; i < n; ++i) {
        ak_mat4 m = ak_transform_to_mat4(pose[i]);
        out[i] = parents[i] >= 0 ? ak_mat4_mul(out[parents[i]], m) : m;
    }
}

/* Largest distance between the two clips' model positions of each joint's origin and of the
 * points at distance r along its axes, at time t. */
static double model_error(const ak_clip* a, const ak_clip* b, float t, const ak_clip_reduce_desc* d, size_t n,
                          ak_transform* pa, ak_transform* pb, ak_mat4* ma, ak_mat4* mb) {
    memcpy(pa, d->rest_pose.ptr, n * sizeof *pa);
    memcpy(pb, d->rest_pose.ptr, n * sizeof *pb);
    ak_clip_sample(a, t, NULL, (ak_transform_span){pa, n}, (ak_f32_span){0}, (ak_f32_span){0});
    ak_clip_sample(b, t, NULL, (ak_transform_span){pb, n}, (ak_f32_span){0}, (ak_f32_span){0});
    pose_fk(d->parents, pa, n, ma);
    pose_fk(d->parents, pb, n, mb);
    double worst = 0.0;
    float r = d->distance;
    const ak_vec3 pts[4] = {{0, 0, 0}, {r, 0, 0}, {0, r, 0}, {0, 0, r}};
    for (size_t j = 0; j < n; ++j)
        for (int p = 0; p < 4; ++p) {
            ak_vec3 x = ak_mat4_transform_point(ma[j], pts[p]), y = ak_mat4_transform_point(mb[j], pts[p]);
            double e = (double)ak_vec3_length(ak_vec3_sub(x, y));
            worst = e <= worst ? worst : (e == e ? e : INFINITY); /* overflow (NaN) never passes */
        }
    return worst;
}

static int cmp_float(const void* a, const void* b) {
    float x = *(const float*)a, y = *(const float*)b;
    return (x > y) - (x < y);
}

/* The next 16-aligned piece of scratch. */
static void* take(char** p, size_t bytes) {
    void* r = *p;
    *p += akp_align16(bytes);
    return r;
}

/* ---- public ---------------------------------------------------------------------------- */

ak_result ak_clip_reduce(const ak_clip* clip, const ak_clip_reduce_desc* desc, const ak_allocator* alloc,
                         ak_clip** out_clip, double* out_error, ak_diag* diag) {
    if (out_clip) *out_clip = NULL;
    if (!clip || !desc || !out_clip || !desc->parents || !desc->rest_pose.ptr) {
        akp_diag_set(diag, NULL, "clip, desc, desc->parents, desc->rest_pose and out_clip are required");
        return AK_ERR_NULL_ARG;
    }
    ak_clip_reduce_desc d = *desc;
    if (d.tolerance == 0.0f) d.tolerance = 1e-3f;
    if (d.distance == 0.0f) d.distance = 0.1f;
    if (!(d.tolerance > 0.0f) || !(d.distance > 0.0f) || !ak_finitef(d.tolerance) || !ak_finitef(d.distance)) {
        akp_diag_set(diag, NULL, "tolerance %g and distance %g must be positive and finite", (double)d.tolerance,
                     (double)d.distance);
        return AK_ERR_BAD_ARG;
    }
    const size_t n = clip->joint_count, nch = clip->channel_count;
    if (d.rest_pose.count < n) {
        akp_diag_set(diag, NULL, "rest_pose has %zu transforms, the clip addresses %zu joints", d.rest_pose.count, n);
        return AK_ERR_SPAN_SMALL;
    }
    for (size_t j = 0; j < n; ++j) {
        const ak_transform* t = &d.rest_pose.ptr[j];
        if (!ak_vec3_is_finite(t->translation) || !ak_vec3_is_finite(t->scale) || !ak_finitef(t->rotation.x) ||
            !ak_finitef(t->rotation.y) || !ak_finitef(t->rotation.z) || !ak_finitef(t->rotation.w)) {
            akp_diag_set(diag, NULL, "rest_pose[%zu] is not finite", j);
            return AK_ERR_BAD_DATA;
        }
    }
    for (size_t j = 0; j < n; ++j) {
        if (d.parents[j] >= (int32_t)j || d.parents[j] < -1) {
            akp_diag_set(diag, NULL, "joint %zu has parent %d (parents must come first)", j, (int)d.parents[j]);
            return AK_ERR_BAD_INDEX;
        }
    }
    size_t max_keys = 0, all_keys = 0;
    for (size_t c = 0; c < nch; ++c) {
        const ak_track* tr = &clip->channels[c].track;
        if (!copyable(tr)) {
            akp_diag_set(diag, NULL, "channel %zu uses %s keys (reduce supports STEP, LINEAR, NLERP, CUBICSPLINE, "
                         "HERMITE)", c, ak_interp_name(tr->interp));
            return AK_ERR_UNSUPPORTED;
        }
        max_keys = tr->key_count > max_keys ? tr->key_count : max_keys;
        all_keys += tr->key_count;
    }

    /* Scratch: per-joint radius, poses and matrices for checks, keep flags, DP stack, the
     * reduced key arrays and the check times (every key time and segment midpoint). */
    size_t value_floats = 0;
    for (size_t c = 0; c < nch; ++c)
        value_floats += clip->channels[c].track.key_count * raw_stride_of(&clip->channels[c].track);
    size_t bytes = akp_align16(n * sizeof(double)) + 2 * akp_align16(n * sizeof(ak_transform)) +
                   2 * akp_align16(n * sizeof(ak_mat4)) + akp_align16(all_keys) +
                   akp_align16(2 * max_keys * sizeof(size_t)) + akp_align16(all_keys * sizeof(float)) +
                   akp_align16(value_floats * sizeof(float)) + akp_align16(nch * sizeof(ak_raw_channel)) +
                   akp_align16(2 * all_keys * sizeof(float));
    char* mem = (char*)akp_calloc(alloc, bytes);
    if (!mem) return AK_ERR_NO_MEMORY;
    char* p = mem;
    double* radius = (double*)take(&p, (n) * sizeof(double));
    ak_transform* pa = (ak_transform*)take(&p, (n) * sizeof(ak_transform));
    ak_transform* pb = (ak_transform*)take(&p, (n) * sizeof(ak_transform));
    ak_mat4* ma = (ak_mat4*)take(&p, (n) * sizeof(ak_mat4));
    ak_mat4* mb = (ak_mat4*)take(&p, (n) * sizeof(ak_mat4));
    uint8_t* keep = (uint8_t*)take(&p, (all_keys) * sizeof(uint8_t));
    size_t* stack = (size_t*)take(&p, (2 * max_keys) * sizeof(size_t));
    float* times = (float*)take(&p, (all_keys) * sizeof(float));
    float* values = (float*)take(&p, (value_floats) * sizeof(float));
    ak_raw_channel* raw = (ak_raw_channel*)take(&p, (nch) * sizeof(ak_raw_channel));
    float* checks = (float*)take(&p, (2 * all_keys) * sizeof(float));

    /* Radius of each joint: distance plus the farthest descendant in the rest pose, so a
     * rotation error of angle a moves no point of the subtree by more than a x radius. */
    memcpy(pa, d.rest_pose.ptr, n * sizeof *pa);
    pose_fk(d.parents, pa, n, ma);
    for (size_t j = 0; j < n; ++j) radius[j] = d.distance;
    for (size_t j = 0; j < n; ++j) {
        ak_vec3 pj = ak_mat4_transform_point(ma[j], ak_vec3_make(0, 0, 0));
        for (int a = d.parents[j]; a >= 0; a = d.parents[a]) {
            ak_vec3 pa3 = ak_mat4_transform_point(ma[a], ak_vec3_make(0, 0, 0));
            radius[a] = fmax(radius[a], d.distance + (double)ak_vec3_length(ak_vec3_sub(pj, pa3)));
        }
    }
    size_t nchecks = 0;
    for (size_t c = 0; c < nch; ++c) {
        const ak_track* tr = &clip->channels[c].track;
        for (size_t k = 0; k < tr->key_count; ++k) {
            checks[nchecks++] = tr->times[k];
            if (k + 1 < tr->key_count) checks[nchecks++] = 0.5f * (tr->times[k] + tr->times[k + 1]);
        }
    }
    qsort(checks, nchecks, sizeof *checks, cmp_float); /* channels usually share their times */
    size_t unique = 0;
    for (size_t i = 0; i < nchecks; ++i)
        if (unique == 0 || checks[i] != checks[unique - 1]) checks[unique++] = checks[i];
    nchecks = unique;

    /* Reduce with a local tolerance (the model tolerance, then 0.7x smaller each try), check in
     * model space, until the check passes (the 25th and last try keeps every key that is not
     * exactly on the interpolation of its neighbours). */
    ak_result r = AK_OK;
    ak_clip* best = NULL;
    double err = 0.0;
    double scale = 1.0;
    for (int attempt = 0; attempt < 25 && !best; ++attempt, scale *= 0.7) {
        double tol = attempt == 24 ? 0.0 : scale * d.tolerance;
        size_t tk = 0, tv = 0;
        for (size_t c = 0; c < nch; ++c) {
            const akp_clip_channel* ch = &clip->channels[c];
            const ak_track* tr = &ch->track;
            size_t kn = tr->key_count;
            uint32_t rs = raw_stride_of(tr);
            uint8_t* kp = keep + tk;
            if (reducible(ch)) {
                simplify(ch, tol, ch->target == AK_CHANNEL_TRANSLATION ? 1.0 : radius[ch->index], kp, stack);
            } else {
                memset(kp, 1, kn);
            }
            ak_raw_channel* rc = &raw[c];
            memset(rc, 0, sizeof *rc);
            rc->target = ch->target;
            rc->index = ch->index;
            rc->component_count = tr->component_count;
            rc->interp = tr->interp;
            rc->tension = tr->tension;
            rc->times = times + tk;
            rc->values = values + tv;
            for (size_t k = 0; k < kn; ++k) {
                if (!kp[k]) continue;
                times[tk + rc->key_count] = tr->times[k];
                memcpy(values + tv + rc->key_count * rs, tr->values + k * tr->stride, rs * sizeof(float));
                ++rc->key_count;
            }
            tk += kn;
            tv += kn * rs;
        }
        ak_raw_clip rclip = {.name = clip->name, .duration = clip->duration, .channels = raw, .channel_count = nch,
                             .joint_count = n, .morph_weight_count = clip->morph_weight_count,
                             .scalar_count = clip->scalar_count};
        ak_clip* cand = NULL;
        r = ak_clip_build(&rclip, alloc, &cand, diag);
        if (r != AK_OK) break;
        err = 0.0;
        for (size_t i = 0; i < nchecks; ++i) err = fmax(err, model_error(clip, cand, checks[i], &d, n, pa, pb, ma, mb));
        if (err <= d.tolerance || attempt == 24) best = cand;
        else ak_clip_destroy(cand);
    }
    akp_free(alloc, mem);
    if (r != AK_OK) return r;
    if (out_error) *out_error = err;
    *out_clip = best;
    return AK_OK;
}

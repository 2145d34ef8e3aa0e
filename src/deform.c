/* Expressive deformers: squash & stretch, bend, twist, the bouncing ball, and jiggle joints. */
#include <animkit/deform.h>

#include "internal.h"

/* ---- static helpers ------------------------------------------------------------------------ */

static bool vec3_finite(ak_vec3 v) { return ak_vec3_is_finite(v); }

/* sin(x)/x and (1 - cos x)/x, accurate near 0 (series below 1e-3: error ~x^4/120 < 1e-13). */
static float sinc_f(float x) {
    if (fabsf(x) < 1e-3f) return 1.0f - x * x * (1.0f / 6.0f);
    return sinf(x) / x;
}
static float cosc_f(float x) {
    if (fabsf(x) < 1e-3f) return x * 0.5f - x * x * x * (1.0f / 24.0f);
    return (1.0f - cosf(x)) / x;
}

static bool deformer_ok(const ak_deformer* d) {
    if ((unsigned)d->type >= (unsigned)AK_DEFORMER_TYPE_COUNT) return false;
    if (!vec3_finite(d->origin) || !vec3_finite(d->axis) || !vec3_finite(d->bend_direction)) return false;
    if (!ak_finitef(d->amount) || !ak_finitef(d->length)) return false;
    if (d->type == AK_DEFORMER_SQUASH && d->amount < 0.0f) return false;
    if (d->type != AK_DEFORMER_SQUASH && d->length < 0.0f) return false;
    return true;
}

/* Rotate v about unit axis a by angle (Rodrigues). */
static ak_vec3 rotate_about(ak_vec3 v, ak_vec3 a, float c, float s) {
    ak_vec3 axv = ak_vec3_cross(a, v);
    float ad = ak_vec3_dot(a, v) * (1.0f - c);
    return ak_vec3_make(v.x * c + axv.x * s + a.x * ad, v.y * c + axv.y * s + a.y * ad,
                        v.z * c + axv.z * s + a.z * ad);
}

/* One point (and optionally one normal) through one resolved, valid deformer. */
static void deform_one(const ak_deformer* d, ak_vec3* p, ak_vec3* n) {
    const ak_vec3 a = d->axis;
    const ak_vec3 r = ak_vec3_sub(*p, d->origin);
    const float u = ak_vec3_dot(r, a);
    switch (d->type) {
    case AK_DEFORMER_SQUASH: {
        const float s = d->amount, across = 1.0f / sqrtf(s);
        ak_vec3 perp = ak_vec3_madd(r, a, -u);
        *p = ak_vec3_add(d->origin, ak_vec3_add(ak_vec3_scale(a, s * u), ak_vec3_scale(perp, across)));
        if (n) {
            float na = ak_vec3_dot(*n, a);
            ak_vec3 nperp = ak_vec3_madd(*n, a, -na);
            *n = ak_vec3_add(ak_vec3_scale(a, na / s), ak_vec3_scale(nperp, 1.0f / across));
        }
        break;
    }
    case AK_DEFORMER_BEND: {
        if (u <= 0.0f) break;
        const ak_vec3 b = d->bend_direction;
        const float L = d->length, theta = d->amount, kappa = theta / L;
        const float w = ak_vec3_dot(r, b);
        const ak_vec3 rest = ak_vec3_sub(r, ak_vec3_add(ak_vec3_scale(a, u), ak_vec3_scale(b, w)));
        const float uc = u < L ? u : L;
        const float phi = kappa * uc, c = cosf(phi), s = sinf(phi);
        float ca = uc * sinc_f(phi) - w * s;
        float cb = uc * cosc_f(phi) + w * c;
        if (u > L) {
            ca += (u - L) * c;
            cb += (u - L) * s;
        }
        *p = ak_vec3_add(d->origin, ak_vec3_add(rest, ak_vec3_add(ak_vec3_scale(a, ca), ak_vec3_scale(b, cb))));
        if (n) {
            float na = ak_vec3_dot(*n, a), nb = ak_vec3_dot(*n, b);
            ak_vec3 nrest = ak_vec3_sub(*n, ak_vec3_add(ak_vec3_scale(a, na), ak_vec3_scale(b, nb)));
            if (u < L) {
                /* Inside the arc the Jacobian is R(phi) diag(1 - kappa w, 1, 1) in (a, b, a x b). */
                float stretch = 1.0f - kappa * w;
                if (stretch < 1e-4f) stretch = 1e-4f;
                na /= stretch;
            }
            ak_vec3 ta = ak_vec3_add(ak_vec3_scale(a, c), ak_vec3_scale(b, s));
            ak_vec3 tb = ak_vec3_sub(ak_vec3_scale(b, c), ak_vec3_scale(a, s));
            *n = ak_vec3_add(nrest, ak_vec3_add(ak_vec3_scale(ta, na), ak_vec3_scale(tb, nb)));
        }
        break;
    }
    case AK_DEFORMER_TWIST: {
        const float L = d->length;
        const float f = u <= 0.0f ? 0.0f : (u >= L ? 1.0f : u / L);
        const float psi = d->amount * f, c = cosf(psi), s = sinf(psi);
        const ak_vec3 q = ak_vec3_madd(r, a, -u);
        *p = ak_vec3_add(d->origin, ak_vec3_add(ak_vec3_scale(a, u), rotate_about(q, a, c, s)));
        if (n) {
            ak_vec3 m = *n;
            if (u > 0.0f && u < L) {
                /* F = R (I + v a^T), v = (amount / L) (a x q); F^-T n = R (n - a (v . n)). */
                ak_vec3 v = ak_vec3_scale(ak_vec3_cross(a, q), d->amount / L);
                m = ak_vec3_madd(m, a, -ak_vec3_dot(v, m));
            }
            *n = rotate_about(m, a, c, s);
        }
        break;
    }
    default:
        break;
    }
    if (n) {
        ak_vec3 u1 = ak_vec3_normalize(*n);
        *n = ak_vec3_length_sq(u1) > 0.0f ? u1 : ak_vec3_make(0.0f, 1.0f, 0.0f);
    }
}

/* ---- squash & stretch, bend, twist ------------------------------------------------------- */

ak_deformer ak_deformer_resolved(ak_deformer d) {
    ak_vec3 a = ak_vec3_normalize(d.axis);
    if (ak_vec3_length_sq(a) == 0.0f) a = ak_vec3_make(0.0f, 1.0f, 0.0f);
    d.axis = a;
    ak_vec3 b = ak_vec3_madd(d.bend_direction, a, -ak_vec3_dot(d.bend_direction, a));
    b = ak_vec3_normalize(b);
    if (ak_vec3_length_sq(b) == 0.0f) b = ak_vec3_any_perpendicular(a);
    d.bend_direction = b;
    if (d.type == AK_DEFORMER_SQUASH && d.amount == 0.0f) d.amount = 1.0f;
    if (d.length == 0.0f) d.length = 1.0f;
    return d;
}

ak_mat4 ak_squash_matrix(ak_vec3 center, ak_vec3 axis, float stretch) {
    if (!(stretch > 0.0f) || !ak_finitef(stretch) || !vec3_finite(center) || !vec3_finite(axis))
        return ak_mat4_identity();
    ak_vec3 a = ak_vec3_normalize(axis);
    if (ak_vec3_length_sq(a) == 0.0f) a = ak_vec3_make(0.0f, 1.0f, 0.0f);
    const float across = 1.0f / sqrtf(stretch), k = stretch - across;
    const float av[3] = {a.x, a.y, a.z};
    ak_mat3 l;
    for (int c = 0; c < 3; ++c)
        for (int r = 0; r < 3; ++r) l.m[c * 3 + r] = (r == c ? across : 0.0f) + k * av[r] * av[c];
    /* T(c) L T(-c): translation c - L c. */
    ak_vec3 t = ak_vec3_sub(center, ak_mat3_mul_vec3(l, center));
    return ak_mat4_from_mat3(l, t);
}

ak_vec3 ak_deformer_apply_point(const ak_deformer* deformer, ak_vec3 p) {
    if (!deformer || !deformer_ok(deformer)) return p;
    ak_deformer d = ak_deformer_resolved(*deformer);
    deform_one(&d, &p, NULL);
    return p;
}

ak_result ak_deform_validate(const ak_deform_job* job) {
    if (!job || !job->deformers || job->deformer_count == 0) return AK_ERR_NULL_ARG;
    if (!job->positions.ptr || job->positions.count == 0 || !job->out_positions.ptr) return AK_ERR_NULL_ARG;
    if (job->out_normals.ptr && !job->normals.ptr) return AK_ERR_NULL_ARG;
    if (job->normals.ptr && job->normals.count != job->positions.count) return AK_ERR_BAD_ARG;
    for (size_t i = 0; i < job->deformer_count; ++i)
        if (!deformer_ok(&job->deformers[i])) return AK_ERR_BAD_ARG;
    if (job->out_positions.count < job->positions.count) return AK_ERR_SPAN_SMALL;
    if (job->out_normals.ptr && job->out_normals.count < job->positions.count) return AK_ERR_SPAN_SMALL;
    return AK_OK;
}

ak_result ak_deform_run(const ak_deform_job* job) {
    ak_result r = ak_deform_validate(job);
    if (r != AK_OK) return r;
    const bool with_n = job->out_normals.ptr != NULL;
    for (size_t i = 0; i < job->positions.count; ++i) {
        ak_vec3 p = job->positions.ptr[i];
        ak_vec3 n = with_n ? job->normals.ptr[i] : ak_vec3_zero();
        for (size_t k = 0; k < job->deformer_count; ++k) {
            /* Resolving per point keeps the job free of scratch; it is a few flops. */
            ak_deformer d = ak_deformer_resolved(job->deformers[k]);
            deform_one(&d, &p, with_n ? &n : NULL);
        }
        job->out_positions.ptr[i] = p;
        if (with_n) job->out_normals.ptr[i] = n;
    }
    return AK_OK;
}

/* ---- automatic squash & stretch --------------------------------------------------------------- */

ak_squash_tracker_desc ak_squash_tracker_desc_resolved(const ak_squash_tracker_desc* desc) {
    ak_squash_tracker_desc d;
    memset(&d, 0, sizeof(d));
    if (desc) d = *desc;
    if (d.min_stretch == 0.0f) d.min_stretch = 0.5f;
    if (d.max_stretch == 0.0f) d.max_stretch = 2.0f;
    return d;
}

ak_result ak_squash_tracker_update(ak_squash_tracker* tr, const ak_squash_tracker_desc* desc, ak_vec3 position,
                                   float dt, ak_deformer* out_deformer) {
    if (!tr || !desc || !out_deformer) return AK_ERR_NULL_ARG;
    if (!(dt > 0.0f) || !ak_finitef(dt)) return AK_ERR_BAD_ARG;
    if (!(desc->speed_gain >= 0.0f) || !(desc->accel_gain >= 0.0f) || !(desc->response_time >= 0.0f) ||
        !(desc->accel_dead_zone >= 0.0f) || !ak_finitef(desc->accel_dead_zone) ||
        !(desc->min_stretch >= 0.0f) || !(desc->max_stretch >= 0.0f) || !ak_finitef(desc->speed_gain) ||
        !ak_finitef(desc->accel_gain) || !ak_finitef(desc->response_time) || !ak_finitef(desc->max_stretch) ||
        !vec3_finite(desc->gravity))
        return AK_ERR_BAD_ARG;
    const ak_squash_tracker_desc rd = ak_squash_tracker_desc_resolved(desc);
    const float lo = rd.min_stretch, hi = rd.max_stretch;
    if (lo > hi) return AK_ERR_BAD_ARG;
    if (!vec3_finite(position)) return AK_ERR_BAD_DATA;

    ak_vec3 v = ak_vec3_zero(), acc = ak_vec3_zero();
    if (tr->sample_count >= 1) v = ak_vec3_scale(ak_vec3_sub(position, tr->prev_position), 1.0f / dt);
    if (tr->sample_count >= 2) acc = ak_vec3_sub(ak_vec3_scale(ak_vec3_sub(v, tr->prev_velocity), 1.0f / dt), desc->gravity);
    if (!vec3_finite(v) || !vec3_finite(acc)) return AK_ERR_BAD_DATA;

    ak_vec3 axis = ak_vec3_length_sq(tr->axis) > 0.0f ? tr->axis : ak_vec3_make(0.0f, 1.0f, 0.0f);
    float target = 0.0f;
    const float speed = ak_vec3_length(v), am = ak_vec3_length(acc);
    const float ls = logf(1.0f + desc->speed_gain * speed);                    /* >= 0 */
    const float la = -logf(1.0f + desc->accel_gain * ak_maxf(am - desc->accel_dead_zone, 0.0f)); /* <= 0 */
    ak_vec3 new_axis = axis;
    if (-la > ls && am > 0.0f) {
        target = la;
        new_axis = ak_vec3_scale(acc, 1.0f / am);
    } else if (speed > 0.0f && ls > 0.0f) {
        target = ls;
        new_axis = ak_vec3_scale(v, 1.0f / speed);
    }
    target = ak_clampf(target, logf(lo), logf(hi));
    const float alpha = desc->response_time > 0.0f ? 1.0f - expf(-dt / desc->response_time) : 1.0f;
    /* A squash along a and along -a is the same deformation: keep the axis on one side. */
    if (ak_vec3_dot(new_axis, axis) < 0.0f) new_axis = ak_vec3_neg(new_axis);
    ak_vec3 blended = ak_vec3_normalize(ak_vec3_lerp(axis, new_axis, alpha));
    if (ak_vec3_length_sq(blended) == 0.0f) blended = new_axis;

    tr->log_stretch += alpha * (target - tr->log_stretch);
    tr->axis = blended;
    tr->prev_velocity = v;
    tr->prev_position = position;
    if (tr->sample_count < 1000000u) ++tr->sample_count;

    memset(out_deformer, 0, sizeof(*out_deformer));
    out_deformer->type = AK_DEFORMER_SQUASH;
    out_deformer->origin = position;
    out_deformer->axis = blended;
    out_deformer->amount = expf(tr->log_stretch);
    out_deformer->length = 1.0f;
    return AK_OK;
}

/* ---- the bouncing ball ------------------------------------------------------------------------ */

typedef struct bounce_params {
    float h, r, g, tc, sq, k, vx, v0, tf;
    ak_vec3 start;
} bounce_params;

static float pos_or(float x, float def) { return (x > 0.0f && ak_finitef(x)) ? x : def; }

ak_bounce_desc ak_bounce_desc_resolved(const ak_bounce_desc* desc) {
    ak_bounce_desc d;
    memset(&d, 0, sizeof(d));
    if (desc) d = *desc;
    d.height = pos_or(d.height, 1.0f);
    d.radius = pos_or(d.radius, 0.25f);
    d.gravity = pos_or(d.gravity, 9.81f);
    d.contact_time = pos_or(d.contact_time, 0.1f);
    d.squash = ak_clampf(pos_or(d.squash, 0.6f), 0.05f, 1.0f);
    d.stretch_per_speed = pos_or(d.stretch_per_speed, 0.04f);
    if (!ak_finitef(d.forward_speed)) d.forward_speed = 0.0f;
    if (!vec3_finite(d.start)) d.start = ak_vec3_zero();
    return d;
}

static bounce_params bounce_resolve(const ak_bounce_desc* desc) {
    const ak_bounce_desc d = ak_bounce_desc_resolved(desc);
    bounce_params p;
    p.h = d.height;
    p.r = d.radius;
    p.g = d.gravity;
    p.tc = d.contact_time;
    p.sq = d.squash;
    p.k = d.stretch_per_speed;
    p.vx = d.forward_speed;
    p.start = d.start;
    p.v0 = sqrtf(2.0f * p.g * p.h);
    p.tf = 2.0f * p.v0 / p.g;
    return p;
}

float ak_bounce_period(const ak_bounce_desc* desc) {
    bounce_params p = bounce_resolve(desc);
    return p.tf + p.tc;
}

ak_bounce_state ak_bounce_sample(const ak_bounce_desc* desc, float t) {
    bounce_params p = bounce_resolve(desc);
    if (!ak_finitef(t)) t = 0.0f;
    const float period = p.tf + p.tc;
    float tau = fmodf(t, period);
    if (tau < 0.0f) tau += period;
    ak_bounce_state s;
    memset(&s, 0, sizeof(s));
    const float x = p.start.x + p.vx * t;
    if (tau < p.tf) {
        /* Flight: the bottom follows a parabola; stretch along the velocity. */
        const float vy = p.v0 - p.g * tau;
        const float bottom = p.v0 * tau - 0.5f * p.g * tau * tau;
        s.velocity = ak_vec3_make(p.vx, vy, 0.0f);
        const float speed = ak_vec3_length(s.velocity);
        s.axis = speed > 0.0f ? ak_vec3_scale(s.velocity, 1.0f / speed) : ak_vec3_make(0.0f, 1.0f, 0.0f);
        s.stretch = 1.0f + p.k * speed;
        /* Half-height of the ellipsoid (semi-axes r s along axis, r / sqrt(s) across) along Y. */
        const float ay = s.axis.y;
        const float half = p.r * sqrtf(s.stretch * s.stretch * ay * ay + (1.0f - ay * ay) / s.stretch);
        s.center = ak_vec3_make(x, p.start.y + bottom + half, p.start.z);
        s.in_contact = false;
    } else {
        /* Contact: squash along Y, deepest halfway, bottom pinned to the floor. */
        const float u = (tau - p.tf) / p.tc;
        s.stretch = 1.0f - (1.0f - p.sq) * sinf(AK_PI * u);
        s.axis = ak_vec3_make(0.0f, 1.0f, 0.0f);
        s.velocity = ak_vec3_make(p.vx, 0.0f, 0.0f);
        s.center = ak_vec3_make(x, p.start.y + p.r * s.stretch, p.start.z);
        s.in_contact = true;
    }
    ak_mat4 sq = ak_squash_matrix(ak_vec3_zero(), s.axis, s.stretch);
    ak_mat4 model = ak_mat4_mul(sq, ak_mat4_scaling(ak_vec3_splat(p.r)));
    model.m[12] = s.center.x;
    model.m[13] = s.center.y;
    model.m[14] = s.center.z;
    s.model = model;
    return s;
}

/* ---- jiggle ------------------------------------------------------------------------------------ */

ak_jiggle_params ak_jiggle_params_resolved(ak_jiggle_params p) {
    if (!(p.substep > 0.0f) || !ak_finitef(p.substep)) p.substep = 1.0f / 240.0f;
    const float w = p.stiffness > 0.0f && ak_finitef(p.stiffness) ? sqrtf(p.stiffness) : 0.0f;
    if (p.substep * w > 0.25f) p.substep = 0.25f / w;
    if (p.damping > 0.0f && ak_finitef(p.damping) && p.substep * p.damping > 0.25f) p.substep = 0.25f / p.damping;
    if (p.max_substeps == 0) p.max_substeps = 64u;
    return p;
}

typedef struct jiggle_resolved {
    float k, c, h;
    ak_vec3 g;
    uint32_t max_steps;
} jiggle_resolved;

static jiggle_resolved jiggle_resolve(const ak_jiggle_params* params) {
    const ak_jiggle_params p = ak_jiggle_params_resolved(*params);
    jiggle_resolved r;
    r.k = p.stiffness;
    r.c = p.damping;
    r.g = p.gravity;
    r.h = p.substep;
    r.max_steps = p.max_substeps;
    return r;
}

ak_result ak_jiggle_validate(const ak_jiggle_job* job) {
    if (!job || !job->parents.ptr || !job->joints || job->joint_count == 0 || !job->states.ptr || !job->model.ptr ||
        !job->out_model.ptr)
        return AK_ERR_NULL_ARG;
    const ak_jiggle_params* p = &job->params;
    if (!(p->stiffness >= 0.0f) || !(p->damping >= 0.0f) || !(p->substep >= 0.0f) || !ak_finitef(p->stiffness) ||
        !ak_finitef(p->damping) || !ak_finitef(p->substep) || !vec3_finite(p->gravity))
        return AK_ERR_BAD_ARG;
    const size_t n = job->parents.count;
    if (job->model.count != n) return AK_ERR_BAD_ARG;
    for (size_t i = 0; i < job->joint_count; ++i) {
        const ak_jiggle_joint* j = &job->joints[i];
        if (j->joint < 0 || (size_t)j->joint >= n) return AK_ERR_BAD_INDEX;
        if (i > 0 && j->joint <= job->joints[i - 1].joint) return AK_ERR_BAD_ARG;
        if (!vec3_finite(j->tip)) return AK_ERR_BAD_ARG;
    }
    for (size_t i = 0; i < n; ++i)
        if (job->parents.ptr[i] < -1 || job->parents.ptr[i] >= (int)i) return AK_ERR_BAD_HIERARCHY;
    if (job->states.count < job->joint_count || job->out_model.count < n) return AK_ERR_SPAN_SMALL;
    if (!(job->dt >= 0.0f) || !ak_finitef(job->dt)) return AK_ERR_BAD_DATA;
    for (size_t i = 0; i < n; ++i)
        if (!ak_mat4_is_finite(&job->model.ptr[i])) return AK_ERR_BAD_DATA;
    return AK_OK;
}

static bool mat4_same(const ak_mat4* a, const ak_mat4* b) { return memcmp(a, b, sizeof(ak_mat4)) == 0; }

/* Slot of joint in the sorted jiggle list, or -1. */
static int32_t jiggle_slot(const ak_jiggle_job* job, int joint) {
    size_t lo = 0, hi = job->joint_count;
    while (lo < hi) {
        size_t mid = (lo + hi) / 2;
        if (job->joints[mid].joint < joint) lo = mid + 1;
        else hi = mid;
    }
    return (lo < job->joint_count && job->joints[lo].joint == joint) ? (int32_t)lo : -1;
}

/* One substep for every jiggle joint, parents first. Each joint's animated head and target are
 * interpolated to the substep's time and carried by its nearest jiggling ancestor's correction
 * at that same substep, so a chain is integrated together rather than frame by frame. */
static void jiggle_substep(const ak_jiggle_job* job, const jiggle_resolved* p, float f) {
    for (size_t k = 0; k < job->joint_count; ++k) {
        ak_jiggle_state* st = &job->states.ptr[k];
        const bool rotate = ak_vec3_length_sq(job->joints[k].tip) > 0.0f;
        ak_vec3 hd = ak_vec3_lerp(st->prev_head, st->head, f);
        ak_vec3 tg = ak_vec3_lerp(st->prev_target, st->target, f);
        ak_quat cq = ak_quat_identity();
        ak_vec3 ct = ak_vec3_zero();
        if (st->ancestor >= 0) {
            const ak_jiggle_state* an = &job->states.ptr[st->ancestor];
            cq = an->corr_rotation;
            ct = an->corr_translation;
            hd = ak_vec3_add(ak_quat_rotate(cq, hd), ct);
            tg = ak_vec3_add(ak_quat_rotate(cq, tg), ct);
        }
        ak_vec3 x = st->position, v = st->velocity;
        ak_vec3 a = ak_vec3_scale(ak_vec3_sub(tg, x), p->k);
        a = ak_vec3_add(ak_vec3_madd(a, v, -p->c), p->g);
        v = ak_vec3_madd(v, a, p->h);
        x = ak_vec3_madd(x, v, p->h);
        if (rotate) {
            const float radius = ak_vec3_distance(st->target, st->head);
            const ak_vec3 dir = ak_vec3_sub(x, hd);
            const float len = ak_vec3_length(dir);
            if (len > 1e-12f) {
                const ak_vec3 nrm = ak_vec3_scale(dir, 1.0f / len);
                x = ak_vec3_madd(hd, nrm, radius);
                v = ak_vec3_madd(v, nrm, -ak_vec3_dot(v, nrm));
            } else {
                x = tg;
            }
            /* C_k(p) = R (C_a(p) - hd) + hd, R turning the carried tip onto the particle. */
            const ak_quat r = ak_quat_from_to(ak_vec3_sub(tg, hd), ak_vec3_sub(x, hd));
            st->corr_rotation = ak_quat_normalize(ak_quat_mul(r, cq));
            st->corr_translation = ak_vec3_add(ak_quat_rotate(r, ak_vec3_sub(ct, hd)), hd);
        } else {
            st->corr_rotation = cq;
            st->corr_translation = ak_vec3_add(ct, ak_vec3_sub(x, tg));
        }
        st->position = x;
        st->velocity = v;
    }
}

ak_result ak_jiggle_run(const ak_jiggle_job* job) {
    ak_result res = ak_jiggle_validate(job);
    if (res != AK_OK) return res;
    const jiggle_resolved p = jiggle_resolve(&job->params);
    const size_t n = job->parents.count, jc = job->joint_count;
    const ak_mat4* in = job->model.ptr;
    ak_mat4* out = job->out_model.ptr;
    ak_jiggle_state* states = job->states.ptr;

    /* The animated (un-jiggled) head and target of every jiggle joint, and its nearest jiggling
     * ancestor. A zero state anywhere restarts the whole job at rest. */
    bool restart = false;
    for (size_t k = 0; k < jc; ++k) {
        ak_jiggle_state* st = &states[k];
        const ak_jiggle_joint* jj = &job->joints[k];
        const ak_mat4 m = in[jj->joint];
        st->head = ak_mat4_get_translation(m);
        st->target = ak_vec3_length_sq(jj->tip) > 0.0f ? ak_mat4_transform_point(m, jj->tip) : st->head;
        int32_t anc = -1;
        for (int q = job->parents.ptr[jj->joint]; q >= 0 && anc < 0; q = job->parents.ptr[q]) anc = jiggle_slot(job, q);
        st->ancestor = anc;
        st->corr_rotation = ak_quat_identity();
        st->corr_translation = ak_vec3_zero();
        restart |= !st->initialized;
    }
    if (restart) {
        for (size_t k = 0; k < jc; ++k) {
            ak_jiggle_state* st = &states[k];
            st->position = st->target;
            st->velocity = ak_vec3_zero();
            st->prev_head = st->head;
            st->prev_target = st->target;
            st->time_left = 0.0f;
            st->initialized = 1u;
        }
    } else if (job->dt > 0.0f) {
        const float dt = job->dt;
        const float left0 = states[0].time_left > 0.0f ? states[0].time_left : 0.0f;
        float total = left0 + dt;
        /* The small bias absorbs float round-off in summed frame times (24 x 1/144 = 1/6). */
        uint32_t steps = (uint32_t)(total / p.h + 1e-3f);
        if (steps > p.max_steps) {
            steps = p.max_steps;
            total = (float)steps * p.h;
        }
        for (uint32_t s = 0; s < steps; ++s)
            jiggle_substep(job, &p, ak_clampf(((float)(s + 1) * p.h - left0) / dt, 0.0f, 1.0f));
        float left = total - (float)steps * p.h;
        if (left < 0.0f) left = 0.0f;
        for (size_t k = 0; k < jc; ++k) states[k].time_left = left;
    }
    for (size_t k = 0; k < jc; ++k) {
        states[k].prev_head = states[k].head;
        states[k].prev_target = states[k].target;
    }

    /* Output: every joint carried by its (possibly jiggled) parent, jiggle joints corrected. */
    size_t next = 0;
    for (size_t i = 0; i < n; ++i) {
        const int par = job->parents.ptr[i];
        ak_mat4 m = in[i];
        if (par >= 0 && !mat4_same(&out[par], &in[par]))
            m = ak_mat4_mul(ak_mat4_mul(out[par], ak_mat4_inverse_affine(in[par])), in[i]);
        if (next < jc && (size_t)job->joints[next].joint == i) {
            const ak_jiggle_joint* jj = &job->joints[next];
            const ak_jiggle_state* st = &states[next];
            ++next;
            const ak_vec3 head = ak_mat4_get_translation(m);
            const bool rotate = ak_vec3_length_sq(jj->tip) > 0.0f;
            const ak_vec3 target = rotate ? ak_mat4_transform_point(m, jj->tip) : head;
            /* The simulation trails the frame by time_left (< one substep): extrapolate. */
            const ak_vec3 x = ak_vec3_madd(st->position, st->velocity, st->time_left);
            if (rotate) {
                ak_quat q = ak_quat_from_to(ak_vec3_sub(target, head), ak_vec3_sub(x, head));
                ak_mat4 rot = ak_mat4_from_quat(q);
                ak_mat4 lin = m;
                lin.m[12] = lin.m[13] = lin.m[14] = 0.0f;
                m = ak_mat4_mul(rot, lin);
                m.m[12] = head.x;
                m.m[13] = head.y;
                m.m[14] = head.z;
            } else {
                ak_vec3 off = ak_vec3_sub(x, target);
                m.m[12] += off.x;
                m.m[13] += off.y;
                m.m[14] += off.z;
            }
        }
        out[i] = m;
    }
    return AK_OK;
}

/* Boids: validation, the per-agent rules, integration, obstacles, threads, measures.
 * The neighbour search (naive loop or grid) lives in boids_internal.h / search.c; both visit
 * candidates in different orders and this file's sums do not depend on that order (64-bit
 * fixed point), so both paths give bit-identical steps. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "tasks.h"
#include "../simd.h"
#include "boids_internal.h"

/* ---- species ------------------------------------------------------------------------- */

void ak_boids_species_resolved(const ak_boids_species* in, ak_boids_species* out) {
    if (!out) return;
    ak_boids_species s;
    if (in) s = *in;
    else memset(&s, 0, sizeof s);
    if (s.max_speed == 0.0f) s.max_speed = 2.0f;
    if (s.max_force == 0.0f) s.max_force = 8.0f;
    if (s.separation_radius == 0.0f) s.separation_radius = 1.0f;
    if (s.alignment_radius == 0.0f) s.alignment_radius = 2.0f;
    if (s.cohesion_radius == 0.0f) s.cohesion_radius = 2.0f;
    if (s.wander_jitter == 0.0f) s.wander_jitter = 2.0f;
    if (s.avoid_distance == 0.0f) s.avoid_distance = 1.0f;
    if (s.bounds_weight == 0.0f) s.bounds_weight = 4.0f;
    if (s.flee_radius == 0.0f) s.flee_radius = 4.0f;
    if (s.pursue_radius == 0.0f) s.pursue_radius = 4.0f;
    *out = s;
}

static bool species_ok(const ak_boids_species* s) {
    const float f[] = {s->max_speed,        s->min_speed,        s->max_force,       s->separation_weight,
                       s->separation_radius, s->alignment_weight, s->alignment_radius, s->cohesion_weight,
                       s->cohesion_radius,   s->view_angle,       s->goal_weight,      s->leader_weight,
                       s->wander_weight,     s->wander_jitter,    s->avoid_weight,     s->avoid_distance,
                       s->bounds_weight,     s->flee_weight,      s->flee_radius,      s->pursue_weight,
                       s->pursue_radius};
    for (size_t i = 0; i < sizeof f / sizeof f[0]; ++i)
        if (!(f[i] >= 0.0f) || !ak_finitef(f[i]) || f[i] > 1e15f) return false;
    const float max_speed = s->max_speed > 0.0f ? s->max_speed : 2.0f; /* the resolved default */
    return s->k_nearest <= AK_BOIDS_MAX_K && s->min_speed <= max_speed;
}

/* The runtime form of a species: squared radii, the view cone, fixed-point scales. */
static void species_runtime(const ak_boids_species* in, akp_boids_sp* o) {
    ak_boids_species s;
    ak_boids_species_resolved(in, &s);
    memset(o, 0, sizeof *o);
    o->s = s;
    o->rs2 = s.separation_weight > 0.0f ? s.separation_radius * s.separation_radius : 0.0f;
    o->ra2 = s.alignment_weight > 0.0f ? s.alignment_radius * s.alignment_radius : 0.0f;
    o->rc2 = s.cohesion_weight > 0.0f ? s.cohesion_radius * s.cohesion_radius : 0.0f;
    o->rn2 = ak_maxf(o->rs2, ak_maxf(o->ra2, o->rc2));
    o->fr2 = (s.flee_mask && s.flee_weight > 0.0f) ? s.flee_radius * s.flee_radius : 0.0f;
    o->pr2 = (s.pursue_mask && s.pursue_weight > 0.0f) ? s.pursue_radius * s.pursue_radius : 0.0f;
    o->query_radius = sqrtf(ak_maxf(o->rn2, ak_maxf(o->fr2, o->pr2)));
    if (s.view_angle > 0.0f && s.view_angle < 360.0f) {
        const double c = cos(0.5 * (double)s.view_angle * 3.14159265358979323846 / 180.0);
        o->fov = c >= 0.0 ? 1 : 2;
        o->cos2 = (float)(c * c);
    }
    /* Fixed point: the separation term is in units of 1/separation_radius (at most 1e3 of
     * them, the distance being clamped to 1e-3 radius), velocities in units of max_speed,
     * offsets in units of the cohesion radius. */
    o->dmin2 = 1e-6f * o->rs2;
    o->sep_scale = AKP_BOIDS_FIX_SEP * s.separation_radius;
    o->ali_scale = AKP_BOIDS_FIX / s.max_speed;
    o->coh_scale = AKP_BOIDS_FIX / s.cohesion_radius;
}

/* ---- validation ---------------------------------------------------------------------- */

static bool vec_ok(ak_vec3 v) {
    return ak_vec3_is_finite(v) && fabsf(v.x) <= 1e15f && fabsf(v.y) <= 1e15f && fabsf(v.z) <= 1e15f;
}

_Static_assert(sizeof(ak_vec3) == 3 * sizeof(float), "ak_vec3 is three packed floats");

/* vec_ok over count floats (a span of ak_vec3 as 3 count floats): |x| <= 1e15 on the bits,
 * which also rejects NaN and infinities (their magnitude bits are larger). */
static bool floats_ok(const float* f, size_t count) {
    const float lf = 1e15f;
    uint32_t lim;
    memcpy(&lim, &lf, sizeof lim);
    size_t i = 0;
#if AK_SIMD_SSE2
    const __m128i mag = _mm_set1_epi32(0x7fffffff), vl = _mm_set1_epi32((int)lim);
    __m128i bad = _mm_setzero_si128();
    for (; i + 16 <= count; i += 16)
        for (size_t k = 0; k < 16; k += 4) {
            const __m128i w = _mm_loadu_si128((const __m128i*)(const void*)(f + i + k));
            bad = _mm_or_si128(bad, _mm_cmpgt_epi32(_mm_and_si128(w, mag), vl));
        }
    if (_mm_movemask_epi8(bad)) return false;
#endif
    for (; i < count; ++i) {
        uint32_t w;
        memcpy(&w, f + i, sizeof w);
        if ((w & 0x7fffffffu) > lim) return false;
    }
    return true;
}

static bool overlaps(const void* a, size_t an, const void* b, size_t bn) {
    const char *pa = (const char*)a, *pb = (const char*)b;
    if (!pa || !pb || an == 0 || bn == 0) return false;
    return pa < pb + bn && pb < pa + an;
}

static bool any_wander(const ak_boids_params* p) {
    for (uint32_t s = 0; s < p->species_count; ++s)
        if (p->species[s].wander_weight > 0.0f) return true;
    return false;
}

static bool has_box(const ak_boids_params* p) {
    return p->bounds_min.x != 0.0f || p->bounds_min.y != 0.0f || p->bounds_min.z != 0.0f ||
           p->bounds_max.x != 0.0f || p->bounds_max.y != 0.0f || p->bounds_max.z != 0.0f;
}

ak_boids_bounds akp_boids_bounds_mode(const ak_boids_params* p) {
    if (!has_box(p) || p->bounds == AK_BOIDS_BOUNDS_NONE) return AK_BOIDS_BOUNDS_NONE;
    return p->bounds == AK_BOIDS_BOUNDS_DEFAULT ? AK_BOIDS_BOUNDS_STEER : p->bounds;
}

/* The agents' data of [b, e): species indices, positions and velocities (and the wander
 * offsets when need_wander): the O(n) part of validation, which ak_boids_step_run splits over
 * its threads. AK_ERR_BAD_INDEX before AK_ERR_BAD_DATA, as validate_inputs checks them. */
static ak_result scan_agents(const ak_boids_step_job* job, bool need_wander, size_t b, size_t e) {
    const ak_boids_params* p = job->params;
    if (job->species.ptr)
        for (size_t i = b; i < e; ++i)
            if (job->species.ptr[i] >= p->species_count) return AK_ERR_BAD_INDEX;
    if (!floats_ok((const float*)(const void*)(job->positions.ptr + b), 3 * (e - b)) ||
        !floats_ok((const float*)(const void*)(job->velocities.ptr + b), 3 * (e - b)))
        return AK_ERR_BAD_DATA;
    if (need_wander && job->wander.ptr)
        for (size_t i = b; i < e; ++i)
            if (!vec_ok(job->wander.ptr[i])) return AK_ERR_BAD_DATA;
    return AK_OK;
}

/* Everything but dt, the wander span and the outputs (shared with the neighbours job); scan
 * false leaves out the agents' data (scan_agents). */
static ak_result validate_inputs(const ak_boids_step_job* job, bool need_wander, bool scan) {
    if (!job || !job->params || !job->params->species || !job->positions.ptr || !job->velocities.ptr)
        return AK_ERR_NULL_ARG;
    const ak_boids_params* p = job->params;
    if (p->obstacle_count > 0 && !p->obstacles) return AK_ERR_NULL_ARG;
    if (need_wander && any_wander(p) && !job->wander.ptr) return AK_ERR_NULL_ARG;
    const size_t n = job->positions.count;
    if (p->species_count == 0 || p->species_count > AK_BOIDS_MAX_SPECIES || job->thread_count > 64 ||
        n > AK_BOIDS_MAX_AGENTS || p->obstacle_count > 1024 || (unsigned)p->bounds >= AK_BOIDS_BOUNDS_COUNT)
        return AK_ERR_BAD_ARG;
    if (has_box(p)) {
        if (!vec_ok(p->bounds_min) || !vec_ok(p->bounds_max) || !(p->bounds_max.x > p->bounds_min.x) ||
            !(p->bounds_max.z > p->bounds_min.z) || (!p->planar && !(p->bounds_max.y > p->bounds_min.y)))
            return AK_ERR_BAD_ARG;
    }
    if (!(p->bounds_margin >= 0.0f) || !ak_finitef(p->bounds_margin) || !(p->leader_distance >= 0.0f) ||
        !ak_finitef(p->leader_distance) || !vec_ok(p->goal))
        return AK_ERR_BAD_ARG;
    if (p->has_leader && p->leader_index >= n && n > 0) return AK_ERR_BAD_ARG;
    for (uint32_t s = 0; s < p->species_count; ++s)
        if (!species_ok(&p->species[s])) return AK_ERR_BAD_ARG;
    for (uint32_t o = 0; o < p->obstacle_count; ++o) {
        const ak_boids_obstacle* ob = &p->obstacles[o];
        if ((unsigned)ob->kind >= AK_BOIDS_OBSTACLE_KIND_COUNT || !vec_ok(ob->center)) return AK_ERR_BAD_ARG;
        if (ob->kind == AK_BOIDS_SPHERE && !(ob->radius > 0.0f && ob->radius <= 1e15f)) return AK_ERR_BAD_ARG;
        if (ob->kind == AK_BOIDS_PLANE && (!vec_ok(ob->normal) || !(ak_vec3_length_sq(ak_vec3_normalize(ob->normal)) > 0.5f)))
            return AK_ERR_BAD_ARG;
        if (ob->kind == AK_BOIDS_BOX &&
            !(ob->half_extents.x > 0.0f && ob->half_extents.y > 0.0f && ob->half_extents.z > 0.0f &&
              vec_ok(ob->half_extents)))
            return AK_ERR_BAD_ARG;
    }
    if (n == 0) return AK_ERR_EMPTY;
    if (job->velocities.count < n || (job->species.ptr && job->species.count < n) ||
        (need_wander && job->wander.ptr && job->wander.count < n))
        return AK_ERR_SPAN_SMALL;
    return scan ? scan_agents(job, need_wander, 0, n) : AK_OK;
}

ak_result akp_boids_validate_inputs(const ak_boids_step_job* job, bool need_wander) {
    return validate_inputs(job, need_wander, true);
}

size_t ak_boids_step_scratch_size(const ak_boids_step_job* job) {
    if (!job || !job->params || !job->params->species || job->params->species_count == 0 ||
        job->params->species_count > AK_BOIDS_MAX_SPECIES || job->positions.count == 0 ||
        job->positions.count > AK_BOIDS_MAX_AGENTS)
        return 0;
    if (job->use_naive) return 0;
    return akp_boids_search_scratch_size(job);
}

/* ak_boids_step_validate; scan false leaves out the agents' data (scan_agents). */
static ak_result step_validate(const ak_boids_step_job* job, bool scan) {
    ak_result r = validate_inputs(job, true, scan);
    if (r != AK_OK && r != AK_ERR_EMPTY && r != AK_ERR_SPAN_SMALL && r != AK_ERR_BAD_INDEX && r != AK_ERR_BAD_DATA)
        return r;
    if (job && (!job->out_positions.ptr || !job->out_velocities.ptr)) return AK_ERR_NULL_ARG;
    if (!(job->dt > 0.0f) || !ak_finitef(job->dt)) return AK_ERR_BAD_ARG;
    const size_t n = job->positions.count, b = n * sizeof(ak_vec3);
    if (overlaps(job->out_positions.ptr, job->out_positions.count * sizeof(ak_vec3), job->positions.ptr, b) ||
        overlaps(job->out_positions.ptr, job->out_positions.count * sizeof(ak_vec3), job->velocities.ptr, b) ||
        overlaps(job->out_velocities.ptr, job->out_velocities.count * sizeof(ak_vec3), job->positions.ptr, b) ||
        overlaps(job->out_velocities.ptr, job->out_velocities.count * sizeof(ak_vec3), job->velocities.ptr, b) ||
        overlaps(job->out_velocities.ptr, job->out_velocities.count * sizeof(ak_vec3), job->out_positions.ptr,
                 job->out_positions.count * sizeof(ak_vec3)) ||
        overlaps(job->wander.ptr, job->wander.count * sizeof(ak_vec3), job->out_positions.ptr,
                 job->out_positions.count * sizeof(ak_vec3)) ||
        overlaps(job->wander.ptr, job->wander.count * sizeof(ak_vec3), job->out_velocities.ptr,
                 job->out_velocities.count * sizeof(ak_vec3)))
        return AK_ERR_BAD_ARG;
    if (r != AK_OK) return r;
    if (job->out_positions.count < n || job->out_velocities.count < n) return AK_ERR_SPAN_SMALL;
    if (!job->use_naive) {
        const size_t need = akp_boids_search_scratch_size(job);
        if (job->scratch.count < need || (need > 0 && !job->scratch.ptr)) return AK_ERR_SPAN_SMALL;
    }
    return AK_OK;
}

ak_result ak_boids_step_validate(const ak_boids_step_job* job) { return step_validate(job, true); }

/* ---- obstacles ----------------------------------------------------------------------- */

/* Signed distance from p to an obstacle (negative inside) and the outward normal there. In 2D
 * the obstacle is cut at p's height. Returns false when the obstacle does not exist in 2D (a
 * horizontal plane). */
static bool obstacle_sdf(const ak_boids_obstacle* o, bool planar, ak_vec3 p, float* out_s, ak_vec3* out_n) {
    ak_vec3 c = o->center;
    if (planar) c.y = p.y;
    const ak_vec3 d = ak_vec3_sub(p, c);
    switch (o->kind) {
    case AK_BOIDS_SPHERE: {
        const float l = ak_vec3_length(d);
        *out_s = l - o->radius;
        *out_n = l > 0.0f ? ak_vec3_scale(d, 1.0f / l) : ak_vec3_make(planar ? 1.0f : 0.0f, planar ? 0.0f : 1.0f, 0.0f);
        return true;
    }
    case AK_BOIDS_PLANE: {
        ak_vec3 n = o->normal;
        if (planar) n.y = 0.0f;
        n = ak_vec3_normalize(n);
        if (ak_vec3_length_sq(n) < 0.5f) return false;
        *out_s = ak_vec3_dot(n, d);
        *out_n = n;
        return true;
    }
    default: {
        const ak_vec3 h = o->half_extents;
        float q[3] = {fabsf(d.x) - h.x, planar ? -INFINITY : fabsf(d.y) - h.y, fabsf(d.z) - h.z};
        const float sg[3] = {d.x < 0.0f ? -1.0f : 1.0f, d.y < 0.0f ? -1.0f : 1.0f, d.z < 0.0f ? -1.0f : 1.0f};
        if (q[0] > 0.0f || q[1] > 0.0f || q[2] > 0.0f) {
            const ak_vec3 e = ak_vec3_make(q[0] > 0.0f ? q[0] * sg[0] : 0.0f, q[1] > 0.0f ? q[1] * sg[1] : 0.0f,
                                           q[2] > 0.0f ? q[2] * sg[2] : 0.0f);
            *out_s = ak_vec3_length(e);
            *out_n = ak_vec3_normalize(e);
            return true;
        }
        int a = q[1] > q[0] ? 1 : 0;
        if (q[2] > q[a]) a = 2;
        *out_s = q[a];
        *out_n = ak_vec3_make(a == 0 ? sg[0] : 0.0f, a == 1 ? sg[1] : 0.0f, a == 2 ? sg[2] : 0.0f);
        return true;
    }
    }
}

/* First parameter t in [0, 1] where the segment a -> b enters the obstacle, or -1. */
static float obstacle_entry(const ak_boids_obstacle* o, bool planar, ak_vec3 a, ak_vec3 b) {
    ak_vec3 c = o->center;
    if (planar) c.y = a.y;
    const ak_vec3 oa = ak_vec3_sub(a, c), d = ak_vec3_sub(b, a);
    if (o->kind == AK_BOIDS_SPHERE) {
        const double dd = (double)d.x * d.x + (double)d.y * d.y + (double)d.z * d.z;
        const double od = (double)oa.x * d.x + (double)oa.y * d.y + (double)oa.z * d.z;
        const double oo = (double)oa.x * oa.x + (double)oa.y * oa.y + (double)oa.z * oa.z -
                          (double)o->radius * o->radius;
        if (dd <= 0.0) return -1.0f;
        const double disc = od * od - dd * oo;
        if (disc < 0.0) return -1.0f;
        const double t = (-od - sqrt(disc)) / dd;
        return (t >= 0.0 && t <= 1.0) ? (float)t : -1.0f;
    }
    if (o->kind == AK_BOIDS_BOX) {
        const float ov[3] = {oa.x, oa.y, oa.z}, dv[3] = {d.x, d.y, d.z};
        const float h[3] = {o->half_extents.x, o->half_extents.y, o->half_extents.z};
        double t0 = 0.0, t1 = 1.0;
        for (int k = 0; k < 3; ++k) {
            if (k == 1 && planar) continue;
            if (dv[k] == 0.0f) {
                if (fabsf(ov[k]) > h[k]) return -1.0f;
                continue;
            }
            double ta = (-(double)h[k] - ov[k]) / dv[k], tb = ((double)h[k] - ov[k]) / dv[k];
            if (ta > tb) {
                const double t = ta;
                ta = tb;
                tb = t;
            }
            if (ta > t0) t0 = ta;
            if (tb < t1) t1 = tb;
            if (t0 > t1) return -1.0f;
        }
        return (float)t0;
    }
    float s0, s1;
    ak_vec3 n;
    if (!obstacle_sdf(o, planar, a, &s0, &n) || !obstacle_sdf(o, planar, b, &s1, &n)) return -1.0f;
    if (s0 >= 0.0f && s1 < 0.0f) return s0 / (s0 - s1);
    return -1.0f;
}

/* Push p out to distance >= a small margin along the obstacle's normal; remove the inward
 * part of v. */
static void push_out(const ak_boids_obstacle* o, bool planar, ak_vec3* p, ak_vec3* v) {
    for (int pass = 0; pass < 4; ++pass) {
        float s;
        ak_vec3 n;
        if (!obstacle_sdf(o, planar, *p, &s, &n)) return;
        const float scale = fmaxf(fabsf(p->x), fmaxf(fabsf(p->y), fabsf(p->z)));
        const float margin = 1e-5f + 4e-7f * scale * (float)(1 << pass);
        if (s >= margin * 0.5f) break;
        *p = ak_vec3_madd(*p, n, margin - s);
        if (planar) n.y = 0.0f;
        const float vn = ak_vec3_dot(*v, n);
        if (vn < 0.0f) *v = ak_vec3_madd(*v, n, -vn);
    }
}

/* The hard constraint: an agent that would end inside an obstacle (or cross one during the
 * step) stops at the entry point, just outside, and keeps only its tangential velocity.
 * Returns true when it had to act. */
static bool resolve_obstacles(const ak_boids_params* prm, ak_vec3 p0, ak_vec3* p, ak_vec3* v) {
    bool hit = false;
    for (uint32_t k = 0; k < prm->obstacle_count; ++k) {
        const ak_boids_obstacle* o = &prm->obstacles[k];
        float s;
        ak_vec3 n;
        if (!obstacle_sdf(o, prm->planar, p0, &s, &n)) continue;
        if (s < 0.0f) {
            /* Started inside (placed there by the caller): leave by the nearest face. */
            push_out(o, prm->planar, p, v);
            hit = true;
            continue;
        }
        const float t = obstacle_entry(o, prm->planar, p0, *p);
        if (t >= 0.0f) {
            *p = ak_vec3_lerp(p0, *p, t);
            push_out(o, prm->planar, p, v);
            hit = true;
        }
    }
    /* Overlapping obstacles: a push out of one may enter another. */
    for (int pass = 0; pass < 4; ++pass) {
        bool inside = false;
        for (uint32_t k = 0; k < prm->obstacle_count; ++k) {
            float s;
            ak_vec3 n;
            if (obstacle_sdf(&prm->obstacles[k], prm->planar, *p, &s, &n) && s < 0.0f) {
                push_out(&prm->obstacles[k], prm->planar, p, v);
                inside = hit = true;
            }
        }
        if (!inside) break;
    }
    return hit;
}

/* ---- one agent ------------------------------------------------------------------------ */

static ak_vec3 seek(ak_vec3 from, ak_vec3 to, ak_vec3 v, float speed) {
    return ak_vec3_sub(ak_vec3_scale(ak_vec3_normalize(ak_vec3_sub(to, from)), speed), v);
}

static ak_vec3 random_unit(ak_rng* r, bool planar) {
    for (int tries = 0; tries < 16; ++tries) {
        ak_vec3 u = ak_vec3_make(ak_rng_range(r, -1.0f, 1.0f), planar ? 0.0f : ak_rng_range(r, -1.0f, 1.0f),
                                 ak_rng_range(r, -1.0f, 1.0f));
        const float l2 = ak_vec3_length_sq(u);
        if (l2 > 1e-4f && l2 <= 1.0f) return ak_vec3_scale(u, 1.0f / sqrtf(l2));
    }
    return ak_vec3_make(1.0f, 0.0f, 0.0f);
}

static ak_vec3 dequant(const int64_t q[3], double div) {
    return ak_vec3_make((float)((double)q[0] / div), (float)((double)q[1] / div), (float)((double)q[2] / div));
}

/* Turn the gathered neighbour sums into the new velocity and position of agent i. */
static bool integrate(const akp_boids_ctx* c, const akp_boids_gather* g, size_t i, ak_vec3* out_p,
                      ak_vec3* out_v) {
    const ak_boids_step_job* job = c->job;
    const ak_boids_params* prm = c->params;
    const akp_boids_sp* S = g->sp;
    const ak_boids_species* s = &S->s;
    const ak_vec3 p = g->p, v = g->v;
    ak_vec3 f = ak_vec3_zero();
    if (g->ns) f = ak_vec3_madd(f, dequant(g->sep, (double)S->sep_scale), s->separation_weight);
    if (g->na)
        f = ak_vec3_madd(f, ak_vec3_sub(dequant(g->ali, (double)S->ali_scale * g->na), v), s->alignment_weight);
    if (g->nc) f = ak_vec3_madd(f, dequant(g->coh, (double)S->coh_scale * g->nc), s->cohesion_weight);
    if (g->flee_j != UINT32_MAX)
        f = ak_vec3_madd(f, seek(job->positions.ptr[g->flee_j], p, v, s->max_speed), s->flee_weight);
    if (g->prey_j != UINT32_MAX) {
        const ak_vec3 q = job->positions.ptr[g->prey_j], qv = job->velocities.ptr[g->prey_j];
        const float t = ak_vec3_distance(p, q) / s->max_speed;
        f = ak_vec3_madd(f, seek(p, ak_vec3_madd(q, qv, t), v, s->max_speed), s->pursue_weight);
    }
    if (s->goal_weight > 0.0f) f = ak_vec3_madd(f, seek(p, prm->goal, v, s->max_speed), s->goal_weight);
    if (s->leader_weight > 0.0f && prm->has_leader && i != prm->leader_index) {
        const ak_vec3 lp = job->positions.ptr[prm->leader_index], lv = job->velocities.ptr[prm->leader_index];
        const float back = prm->leader_distance > 0.0f ? prm->leader_distance : 1.0f;
        const ak_vec3 target = ak_vec3_madd(lp, ak_vec3_normalize(lv), -back);
        /* Arrive: slow down inside one leader_distance of the target instead of overshooting. */
        const float dist = ak_vec3_distance(p, target);
        const float speed = s->max_speed * ak_minf(1.0f, dist / back);
        f = ak_vec3_madd(f, seek(p, target, v, speed), s->leader_weight);
    }
    if (s->wander_weight > 0.0f && job->wander.ptr) {
        ak_rng r = ak_rng_make(job->seed ^ (0x9E3779B97F4A7C15ull * (job->step_index + 1)) ^
                               ((uint64_t)i * 0xD1B54A32D192ED03ull));
        ak_vec3 w = job->wander.ptr[i];
        if (prm->planar) w.y = 0.0f;
        if (ak_vec3_length_sq(w) < 1e-12f) w = random_unit(&r, prm->planar);
        w = ak_vec3_normalize(ak_vec3_madd(w, random_unit(&r, prm->planar), s->wander_jitter * sqrtf(job->dt)));
        if (ak_vec3_length_sq(w) < 0.5f) w = random_unit(&r, prm->planar);
        job->wander.ptr[i] = w;
        f = ak_vec3_madd(f, w, s->wander_weight);
    }
    if (s->avoid_weight > 0.0f) {
        const float L = s->avoid_distance;
        for (uint32_t k = 0; k < prm->obstacle_count; ++k) {
            float d;
            ak_vec3 n;
            if (!obstacle_sdf(&prm->obstacles[k], prm->planar, p, &d, &n) || d >= L) continue;
            f = ak_vec3_madd(f, n, s->avoid_weight * (L - d) / ak_maxf(d, 1e-3f * L));
        }
    }
    const ak_boids_bounds mode = c->bounds;
    if (mode == AK_BOIDS_BOUNDS_STEER) {
        const float m = prm->bounds_margin > 0.0f ? prm->bounds_margin : 1.0f;
        const float pv[3] = {p.x, p.y, p.z};
        const float lo[3] = {prm->bounds_min.x, prm->bounds_min.y, prm->bounds_min.z};
        const float hi[3] = {prm->bounds_max.x, prm->bounds_max.y, prm->bounds_max.z};
        float fb[3] = {0.0f, 0.0f, 0.0f};
        for (int a = 0; a < 3; ++a) {
            if (a == 1 && prm->planar) continue;
            if (pv[a] < lo[a] + m) fb[a] = lo[a] + m - pv[a];
            else if (pv[a] > hi[a] - m) fb[a] = hi[a] - m - pv[a];
        }
        f = ak_vec3_madd(f, ak_vec3_make(fb[0], fb[1], fb[2]), s->bounds_weight);
    }
    if (prm->planar) f.y = 0.0f;
    const float fl = ak_vec3_length(f);
    if (fl > s->max_force) f = ak_vec3_scale(f, s->max_force / fl);
    if (!ak_vec3_is_finite(f)) f = ak_vec3_zero();

    ak_vec3 nv = ak_vec3_madd(v, f, job->dt);
    if (prm->planar) nv.y = 0.0f;
    const float sp = ak_vec3_length(nv);
    if (sp > s->max_speed) nv = ak_vec3_scale(nv, s->max_speed / sp);
    else if (sp < s->min_speed) {
        /* Keep flying: an agent that stopped goes on along its old heading. */
        const ak_vec3 dir = sp > 1e-20f ? ak_vec3_scale(nv, 1.0f / sp) : ak_vec3_normalize(v);
        nv = ak_vec3_scale(dir, s->min_speed);
    }
    ak_vec3 np = ak_vec3_madd(p, nv, job->dt);
    bool wrapped = false;
    if (mode == AK_BOIDS_BOUNDS_WRAP) {
        float pv[3] = {np.x, np.y, np.z};
        const float lo[3] = {prm->bounds_min.x, prm->bounds_min.y, prm->bounds_min.z};
        const float hi[3] = {prm->bounds_max.x, prm->bounds_max.y, prm->bounds_max.z};
        for (int a = 0; a < 3; ++a) {
            if (a == 1 && prm->planar) continue;
            if (pv[a] >= lo[a] && pv[a] < hi[a]) continue;
            wrapped = true;
            const double ext = (double)hi[a] - lo[a];
            double x = fmod((double)pv[a] - lo[a], ext);
            if (x < 0.0) x += ext;
            float r = (float)(lo[a] + x);
            if (!(r < hi[a])) r = lo[a];
            if (r < lo[a]) r = lo[a];
            pv[a] = r;
        }
        np = ak_vec3_make(pv[0], pv[1], pv[2]);
    }
    bool contact = false;
    /* A wrapped agent starts its obstacle check from where it re-entered. */
    if (prm->obstacle_count > 0) {
        const ak_vec3 from = wrapped ? np : p;
        contact = resolve_obstacles(prm, from, &np, &nv);
    }
    *out_p = np;
    *out_v = nv;
    return contact;
}

/* ---- threads ------------------------------------------------------------------------- */

typedef struct step_task {
    _Alignas(64) const akp_boids_ctx* c; /* one cache line per task: each thread counts in its own */
    size_t part, parts;
    uint64_t interactions;
    uint32_t contacts;
    akp_boids_batch* batch; /* the thread's batch when integrating 8 at a time, else NULL */
} step_task;

static void step_agent(const akp_boids_ctx* c, size_t i, const akp_boids_gather* g, void* user) {
    step_task* t = (step_task*)user;
    t->interactions += g->nflock;
    ak_vec3 np, nv;
    t->contacts += integrate(c, g, i, &np, &nv) ? 1u : 0u;
    c->job->out_positions.ptr[i] = np;
    c->job->out_velocities.ptr[i] = nv;
}

/* Whether the step integrates 8 agents at a time (akp_boids_integrate_avx512 / _avx2): the common
 * case only, where integrate() reduces to the three flock rules, the limits and wrapping. */
static bool batch_ok(const akp_boids_ctx* c) {
    const ak_boids_params* prm = c->params;
    if (!c->sym || !(c->avx512 || c->avx2) || prm->planar || prm->obstacle_count > 0 || c->bounds == AK_BOIDS_BOUNDS_STEER)
        return false;
    const ak_boids_species* s = &c->sp[0].s;
    return !(s->goal_weight > 0.0f) && !(s->leader_weight > 0.0f && prm->has_leader) &&
           !(s->wander_weight > 0.0f && c->job->wander.ptr) && !(s->avoid_weight > 0.0f && prm->obstacle_count > 0);
}

/* Integrate the batch; the lanes it leaves go through integrate() (agents already copied). */
static void batch_flush(const akp_boids_ctx* c, step_task* t) {
    akp_boids_batch* b = t->batch;
    if (!b->n) return;
    for (uint32_t l = b->n; l < AKP_BOIDS_BATCH; ++l) { /* defined values in the unused lanes */
        b->idx[l] = 0;
        for (int a = 0; a < 9; ++a) b->q[a][l] = 0;
        b->ns[l] = b->na[l] = b->nc[l] = 0;
        for (int a = 0; a < 3; ++a) b->p[a][l] = b->v[a][l] = 0.0f;
    }
    uint32_t redo = c->avx512 ? akp_boids_integrate_avx512(c, &c->sp[0], b) : akp_boids_integrate_avx2(c, &c->sp[0], b);
    for (; redo; redo &= redo - 1u) {
        const unsigned l = (unsigned)__builtin_ctz(redo);
        akp_boids_gather g;
        g.sp = &c->sp[0];
        g.p = ak_vec3_make(b->p[0][l], b->p[1][l], b->p[2][l]);
        g.v = ak_vec3_make(b->v[0][l], b->v[1][l], b->v[2][l]);
        for (int a = 0; a < 3; ++a) {
            g.sep[a] = b->q[a][l];
            g.ali[a] = b->q[3 + a][l];
            g.coh[a] = b->q[6 + a][l];
        }
        g.ns = b->ns[l];
        g.na = b->na[l];
        g.nc = b->nc[l];
        g.flee_j = g.prey_j = UINT32_MAX;
        ak_vec3 np, nv;
        t->contacts += integrate(c, &g, b->idx[l], &np, &nv) ? 1u : 0u;
        c->job->out_positions.ptr[b->idx[l]] = np;
        c->job->out_velocities.ptr[b->idx[l]] = nv;
    }
    b->n = 0;
}

static void batch_agent(const akp_boids_ctx* c, size_t i, const akp_boids_gather* g, void* user) {
    step_task* t = (step_task*)user;
    t->interactions += g->nflock;
    akp_boids_batch* b = t->batch;
    const uint32_t l = b->n++;
    b->idx[l] = (uint32_t)i;
    for (int a = 0; a < 3; ++a) {
        b->q[a][l] = g->sep[a];
        b->q[3 + a][l] = g->ali[a];
        b->q[6 + a][l] = g->coh[a];
    }
    b->ns[l] = g->ns;
    b->na[l] = g->na;
    b->nc[l] = g->nc;
    b->p[0][l] = g->p.x, b->p[1][l] = g->p.y, b->p[2][l] = g->p.z;
    b->v[0][l] = g->v.x, b->v[1][l] = g->v.y, b->v[2][l] = g->v.z;
    if (b->n == AKP_BOIDS_BATCH) batch_flush(c, t);
}

static void* step_thread(void* arg) {
    step_task* t = (step_task*)arg;
    akp_boids_batch batch;
    if (t->c->sym) {
        batch.n = 0;
        t->batch = batch_ok(t->c) ? &batch : NULL;
        akp_boids_sym_range(t->c, t->part, t->parts, t->batch ? batch_agent : step_agent, t);
        if (t->batch) batch_flush(t->c, t);
        t->batch = NULL;
    } else {
        akp_boids_gather_range(t->c, t->part, t->parts, step_agent, t);
    }
    return NULL;
}

static void* step_finish_thread(void* arg) {
    step_task* t = (step_task*)arg;
    akp_boids_batch batch;
    batch.n = 0;
    t->batch = batch_ok(t->c) ? &batch : NULL;
    akp_boids_sym_finish(t->c, t->part, t->parts, t->batch ? batch_agent : step_agent, t);
    if (t->batch) batch_flush(t->c, t);
    t->batch = NULL;
    return NULL;
}

void akp_boids_run_tasks(void* (*fn)(void*), void* tasks, size_t size, uint32_t count) {
    akp_run_tasks(fn, tasks, size, count);
}

uint32_t akp_boids_threads(uint32_t requested, size_t n) {
    uint32_t t = requested == 0 ? 1u : requested;
    if (t > 64) t = 64;
    /* A thread start costs about as much as a few hundred agents. */
    if ((size_t)t * 512u > n) t = (uint32_t)(n / 512u) > 0 ? (uint32_t)(n / 512u) : 1u;
    return t;
}

void akp_boids_ctx_init(akp_boids_ctx* c, const ak_boids_step_job* job) {
    memset(c, 0, sizeof *c);
    c->job = job;
    c->params = job->params;
    c->n = job->positions.count;
    c->bounds = akp_boids_bounds_mode(job->params);
    for (uint32_t s = 0; s < job->params->species_count; ++s) species_runtime(&job->params->species[s], &c->sp[s]);
}

/* akp_check_split's check: scan_agents over agents [b, e) of the job at ctx. */
static int scan_part(const void* ctx, size_t b, size_t e) {
    return (int)scan_agents((const ak_boids_step_job*)ctx, true, b, e);
}

/* ak_boids_step_validate with the agents' data checked on the step's threads (one read of the
 * positions and velocities: 0.8 ms of a 1M-agent step on one core, all of it serial before).
 * Same result: when a rule other than the data fails, the serial check answers (its order of
 * rules); else AK_ERR_BAD_INDEX if any part has a bad species, else AK_ERR_BAD_DATA if any has
 * bad data, as scan_agents over all agents would say. */
static ak_result step_validate_split(const ak_boids_step_job* job) {
    ak_result r = step_validate(job, false);
    if (r != AK_OK) return ak_boids_step_validate(job);
    const size_t n = job->positions.count;
    int res[AKP_TASKS_MAX];
    const uint32_t parts = akp_check_split(n, akp_boids_threads(job->thread_count, n), scan_part, job, res);
    for (uint32_t t = 0; t < parts; ++t)
        if (res[t] == (int)AK_ERR_BAD_INDEX) return AK_ERR_BAD_INDEX;
    for (uint32_t t = 0; t < parts; ++t)
        if (res[t] != (int)AK_OK) return (ak_result)res[t];
    return AK_OK;
}

ak_result ak_boids_step_run(const ak_boids_step_job* job) {
    ak_result r = step_validate_split(job);
    if (r != AK_OK) return r;
    akp_boids_ctx c;
    akp_boids_ctx_init(&c, job);
    r = akp_boids_search_prepare(&c, job->scratch);
    if (r != AK_OK) return r;
    const uint32_t threads = akp_boids_threads(job->thread_count, c.n);
    step_task tasks[64];
    for (uint32_t t = 0; t < threads; ++t) tasks[t] = (step_task){&c, t, threads, 0, 0, NULL};
    akp_boids_partition(&c, threads);
    if (c.sym) akp_boids_sym_clear(&c, threads);
    akp_boids_run_tasks(step_thread, tasks, sizeof tasks[0], threads);
    if (c.sym && threads > 1) akp_boids_run_tasks(step_finish_thread, tasks, sizeof tasks[0], threads);
    uint64_t inter = 0;
    uint32_t contacts = 0;
    for (uint32_t t = 0; t < threads; ++t) {
        inter += tasks[t].interactions;
        contacts += tasks[t].contacts;
    }
    if (job->out_interaction_count) *job->out_interaction_count = inter;
    if (job->out_contact_count) *job->out_contact_count = contacts;
    return AK_OK;
}

/* ---- neighbour lists ------------------------------------------------------------------ */

typedef struct nb_task {
    const akp_boids_ctx* c;
    const ak_boids_neighbors_job* job;
    size_t begin, end;
    bool write; /* second pass: write the indices */
} nb_task;

static void* nb_thread(void* arg) {
    nb_task* t = (nb_task*)arg;
    akp_boids_gather g;
    uint32_t* off = t->job->out_offsets.ptr;
    for (size_t i = t->begin; i < t->end; ++i) {
        if (!t->write) {
            akp_boids_gather_agent(t->c, i, &g);
            off[i + 1] = g.nflock;
        } else {
            akp_boids_list_agent(t->c, i, t->job->out_indices.ptr + off[i], off[i + 1] - off[i]);
        }
    }
    return NULL;
}

ak_result ak_boids_neighbors_run(const ak_boids_neighbors_job* job) {
    if (!job || !job->step || !job->out_total || !job->out_offsets.ptr) return AK_ERR_NULL_ARG;
    const ak_boids_step_job* sj = job->step;
    ak_result r = akp_boids_validate_inputs(sj, false);
    if (r != AK_OK) return r;
    const size_t n = sj->positions.count;
    if (job->out_offsets.count < n + 1) return AK_ERR_SPAN_SMALL;
    if (!sj->use_naive) {
        const size_t need = akp_boids_search_scratch_size(sj);
        if (sj->scratch.count < need || (need > 0 && !sj->scratch.ptr)) return AK_ERR_SPAN_SMALL;
    }
    akp_boids_ctx c;
    akp_boids_ctx_init(&c, sj);
    r = akp_boids_search_prepare(&c, sj->scratch);
    if (r != AK_OK) return r;
    const uint32_t threads = akp_boids_threads(sj->thread_count, n);
    nb_task tasks[64];
    const size_t chunk = (n + threads - 1) / threads;
    for (uint32_t t = 0; t < threads; ++t) {
        const size_t b = (size_t)t * chunk, e = b + chunk;
        tasks[t] = (nb_task){&c, job, b < n ? b : n, e < n ? e : n, false};
    }
    akp_boids_run_tasks(nb_thread, tasks, sizeof tasks[0], threads);
    uint64_t total = 0;
    job->out_offsets.ptr[0] = 0;
    for (size_t i = 0; i < n; ++i) {
        total += job->out_offsets.ptr[i + 1];
        job->out_offsets.ptr[i + 1] = total > UINT32_MAX ? UINT32_MAX : (uint32_t)total;
    }
    *job->out_total = (size_t)total;
    if (total > UINT32_MAX || job->out_indices.count < total || (total > 0 && !job->out_indices.ptr))
        return AK_ERR_SPAN_SMALL;
    for (uint32_t t = 0; t < threads; ++t) tasks[t].write = true;
    akp_boids_run_tasks(nb_thread, tasks, sizeof tasks[0], threads);
    return AK_OK;
}

/* ---- measures ------------------------------------------------------------------------- */

float ak_boids_order(ak_vec3_cspan velocities) {
    if (!velocities.ptr || velocities.count == 0) return 0.0f;
    double sx = 0.0, sy = 0.0, sz = 0.0;
    for (size_t i = 0; i < velocities.count; ++i) {
        const ak_vec3 v = velocities.ptr[i];
        const double l = sqrt((double)v.x * v.x + (double)v.y * v.y + (double)v.z * v.z);
        if (!(l > 0.0) || !isfinite(l)) continue;
        sx += v.x / l;
        sy += v.y / l;
        sz += v.z / l;
    }
    const double n = (double)velocities.count;
    const double o = sqrt(sx * sx + sy * sy + sz * sz) / n;
    return (float)(o > 1.0 ? 1.0 : o);
}

typedef struct xkey {
    float x;
    uint32_t i;
} xkey;

static int xkey_cmp(const void* a, const void* b) {
    const xkey *ka = (const xkey*)a, *kb = (const xkey*)b;
    if (ka->x != kb->x) return ka->x < kb->x ? -1 : 1;
    return ka->i < kb->i ? -1 : (ka->i > kb->i ? 1 : 0);
}

size_t ak_boids_min_distance_scratch_size(size_t count) { return count * sizeof(xkey); }

ak_result ak_boids_min_distance(ak_vec3_cspan positions, ak_u8_span scratch, float* out_distance) {
    if (!out_distance || !positions.ptr) return AK_ERR_NULL_ARG;
    const size_t n = positions.count;
    if (n < 2) return AK_ERR_EMPTY;
    if (n > UINT32_MAX) return AK_ERR_BAD_ARG;
    if (!scratch.ptr || scratch.count < ak_boids_min_distance_scratch_size(n)) return AK_ERR_SPAN_SMALL;
    xkey* k = (xkey*)(void*)scratch.ptr;
    for (size_t i = 0; i < n; ++i) {
        if (!ak_vec3_is_finite(positions.ptr[i])) return AK_ERR_BAD_DATA;
        k[i] = (xkey){positions.ptr[i].x, (uint32_t)i};
    }
    qsort(k, n, sizeof *k, xkey_cmp);
    double best2 = INFINITY;
    for (size_t a = 0; a < n; ++a) {
        const ak_vec3 p = positions.ptr[k[a].i];
        for (size_t b = a + 1; b < n; ++b) {
            const double dx = (double)k[b].x - p.x;
            if (dx * dx >= best2) break;
            const ak_vec3 q = positions.ptr[k[b].i];
            const double dy = (double)q.y - p.y, dz = (double)q.z - p.z;
            const double d2 = dx * dx + dy * dy + dz * dz;
            if (d2 < best2) best2 = d2;
        }
    }
    *out_distance = (float)sqrt(best2);
    return AK_OK;
}

/* Crowd characters: a walk cycle per agent whose clip time follows the distance walked. */
#include <math.h>

#include <animkit/crowd.h>
#include <animkit/ik.h>

#include "internal.h"

/* ---- helpers ------------------------------------------------------------------------------ */

/* Model-space positions of both feet at clip time t (local and world: [joint_count]). */
static ak_result feet_at(const ak_crowd_gait_desc* d, int left, int right, float t, ak_transform_span local,
                         ak_mat4_span world, ak_vec3 out[2]) {
    ak_result r = ak_scene_rest_pose(d->scene, local);
    if (r == AK_OK)
        r = ak_clip_sample(d->scene->clips[d->clip_index], t, NULL, local, (ak_f32_span){0}, (ak_f32_span){0});
    if (r == AK_OK) r = ak_scene_world_matrices(d->scene, (ak_transform_cspan){local.ptr, local.count}, world);
    if (r != AK_OK) return r;
    out[0] = ak_mat4_get_translation(world.ptr[left]);
    out[1] = ak_mat4_get_translation(world.ptr[right]);
    return AK_OK;
}

static float smoothstep01(float x) {
    x = ak_clampf(x, 0.0f, 1.0f);
    return x * x * (3.0f - 2.0f * x);
}

/* Model transform of joint j: its ancestors' locals composed (at most joint-count levels). */
static ak_transform model_of(ak_i32_cspan parents, const ak_transform* local, int j) {
    ak_transform m = local[j];
    size_t guard = parents.count;
    for (int p = parents.ptr[j]; p >= 0 && (size_t)p < parents.count && guard-- > 0; p = parents.ptr[p])
        m = ak_transform_mul(local[p], m);
    return m;
}

/* The rotation about +y that turns the gait's forward onto the character's heading. */
static ak_quat root_rotation(const ak_crowd_gait* g, const ak_crowd_character* c) {
    const float af = atan2f(g->forward.x, g->forward.z);
    const float ah = atan2f(c->heading.x, c->heading.y);
    return ak_quat_from_axis_angle(ak_vec3_make(0.0f, 1.0f, 0.0f), ah - af);
}

/* The leg of foot f: hip, knee, ankle joints; false when the foot has no grandparent. */
static bool leg_of(const ak_crowd_gait* g, ak_i32_cspan parents, int f, int leg[3]) {
    const int a = g->feet[f];
    if (a < 0 || (size_t)a >= parents.count) return false;
    const int k = parents.ptr[a];
    if (k < 0 || (size_t)k >= parents.count) return false;
    const int h = parents.ptr[k];
    if (h < 0 || (size_t)h >= parents.count) return false;
    leg[0] = h, leg[1] = k, leg[2] = a;
    return true;
}

/* How far the hip must come down for the leg (hip, knee, ankle model positions) to reach the
 * target at 99.9% of its length; INFINITY when no drop makes it (horizontally too far). */
static float leg_drop(ak_vec3 hip, ak_vec3 knee, ak_vec3 ankle, ak_vec3 target) {
    const float reach = 0.999f * (ak_vec3_length(ak_vec3_sub(knee, hip)) + ak_vec3_length(ak_vec3_sub(ankle, knee)));
    const float dx = target.x - hip.x, dz = target.z - hip.z, h2 = dx * dx + dz * dz;
    if (h2 >= reach * reach) return INFINITY;
    const float need = sqrtf(reach * reach - h2); /* the largest vertical hip-target distance */
    return fmaxf(0.0f, (hip.y - target.y) - need);
}

/* World (x, z) of a model point for a character standing at p. */
static ak_vec2 to_world(ak_quat q, ak_vec2 p, ak_vec3 m) {
    const ak_vec3 w = ak_quat_rotate(q, m);
    return ak_vec2_make(w.x + p.x, w.z + p.y);
}

/* Model point of world ground point w at height y, for a character standing at p. */
static ak_vec3 to_model(ak_quat q, ak_vec2 p, ak_vec2 w, float y) {
    return ak_quat_rotate(ak_quat_conjugate(q), ak_vec3_make(w.x - p.x, y, w.y - p.y));
}

/* ---- public -------------------------------------------------------------------------------- */

ak_result ak_crowd_gait_measure(const ak_crowd_gait_desc* desc, const ak_allocator* alloc, ak_crowd_gait* out_gait,
                                ak_diag* out_diag) {
    if (!desc || !out_gait || !desc->scene || !desc->scene->skeleton) {
        akp_diag_set(out_diag, "gait", "no desc, scene, skeleton or output");
        return AK_ERR_NULL_ARG;
    }
    const ak_scene* sc = desc->scene;
    if (desc->clip_index < 0 || (size_t)desc->clip_index >= sc->clip_count) {
        akp_diag_set(out_diag, sc->name, "clip %d out of range (%zu clips)", desc->clip_index, sc->clip_count);
        return AK_ERR_BAD_INDEX;
    }
    const size_t n = ak_scene_joint_count(sc);
    const ak_transform_cspan rest = ak_skeleton_rest_pose(sc->skeleton);
    int feet[2] = {desc->left_foot, desc->right_foot};
    ak_transform* local = akp_alloc(alloc, n * sizeof *local);
    ak_mat4* world = akp_alloc(alloc, n * sizeof *world);
    ak_result res = AK_OK;
    if (!local || !world) {
        akp_diag_set(out_diag, sc->name, "out of memory");
        res = AK_ERR_NO_MEMORY;
        goto done;
    }
    const ak_transform_span ls = {local, n};
    const ak_mat4_span ws = {world, n};
    if (feet[0] == 0 && feet[1] == 0) {
        /* automatic: the lowest joint of the rest pose on each side */
        for (size_t j = 0; j < n; ++j) local[j] = rest.ptr[j];
        res = ak_scene_world_matrices(sc, (ak_transform_cspan){local, n}, ws);
        if (res != AK_OK) goto done;
        float low[2] = {INFINITY, INFINITY};
        feet[0] = feet[1] = -1;
        for (size_t j = 0; j < n; ++j) {
            if (sc->is_joint && !sc->is_joint[j]) continue;
            const ak_vec3 p = ak_mat4_get_translation(world[j]);
            const int side = p.x > 0.0f ? 0 : (p.x < 0.0f ? 1 : -1);
            if (side >= 0 && p.y < low[side]) {
                low[side] = p.y;
                feet[side] = (int)j;
            }
        }
        if (feet[0] < 0 || feet[1] < 0) {
            akp_diag_set(out_diag, sc->name, "no joint on the %s side (x %s 0) to take for a foot",
                         feet[0] < 0 ? "left" : "right", feet[0] < 0 ? ">" : "<");
            res = AK_ERR_NOT_FOUND;
            goto done;
        }
    } else if (feet[0] < 0 || feet[1] < 0 || (size_t)feet[0] >= n || (size_t)feet[1] >= n || feet[0] == feet[1]) {
        akp_diag_set(out_diag, sc->name, "feet %d, %d: not two distinct joints of %zu", feet[0], feet[1], n);
        res = AK_ERR_BAD_INDEX;
        goto done;
    }
    const ak_clip* clip = sc->clips[desc->clip_index];
    const float T = ak_clip_duration(clip);
    if (!(T >= 1e-3f) || !ak_finitef(T)) {
        akp_diag_set(out_diag, sc->name, "clip '%s' lasts %g s: too short for a walk cycle", ak_clip_name(clip),
                     (double)T);
        res = AK_ERR_BAD_DATA;
        goto done;
    }
    /* Pass 1: the lower foot's positions; the sum of its horizontal motion gives forward. */
    enum { S = AK_CROWD_GAIT_SAMPLES };
    ak_vec3 prev[2], cur[2];
    res = feet_at(desc, feet[0], feet[1], 0.0f, ls, ws, prev);
    if (res != AK_OK) goto done;
    float lo[2] = {prev[0].y, prev[1].y};
    double sx = 0.0, sz = 0.0;
    /* Keep the per-interval motion of the lower foot for pass 2 (stack: S small). */
    float mx[S], mz[S];
    for (unsigned k = 1; k <= S; ++k) {
        res = feet_at(desc, feet[0], feet[1], T * (float)k / (float)S, ls, ws, cur);
        if (res != AK_OK) goto done;
        /* the lower foot over the interval: by the mean height of its two ends */
        const int f = (prev[0].y + cur[0].y) <= (prev[1].y + cur[1].y) ? 0 : 1;
        mx[k - 1] = cur[f].x - prev[f].x;
        mz[k - 1] = cur[f].z - prev[f].z;
        sx += mx[k - 1];
        sz += mz[k - 1];
        for (int s = 0; s < 2; ++s) lo[s] = fminf(lo[s], cur[s].y);
        prev[0] = cur[0];
        prev[1] = cur[1];
    }
    const double len = sqrt(sx * sx + sz * sz);
    if (!(len >= 0.01)) {
        akp_diag_set(out_diag, sc->name,
                     "clip '%s': the stance foot travels %.3g m per cycle: not a walk in place (at least 0.01 m)",
                     ak_clip_name(clip), len);
        res = AK_ERR_BAD_DATA;
        goto done;
    }
    const float fx = (float)(-sx / len), fz = (float)(-sz / len);
    memset(out_gait, 0, sizeof *out_gait);
    double acc = 0.0;
    out_gait->distance[0] = 0.0f;
    for (unsigned k = 0; k < S; ++k) {
        const double back = -((double)mx[k] * fx + (double)mz[k] * fz);
        if (back > 0.0) acc += back;
        out_gait->distance[k + 1] = (float)acc;
    }
    out_gait->scene = sc;
    out_gait->clip_index = desc->clip_index;
    out_gait->feet[0] = feet[0];
    out_gait->feet[1] = feet[1];
    out_gait->duration = T;
    out_gait->stride_length = (float)acc;
    out_gait->stride_speed = (float)acc / T;
    out_gait->forward = ak_vec3_make(fx, 0.0f, fz);
    out_gait->foot_min_y[0] = lo[0];
    out_gait->foot_min_y[1] = lo[1];
done:
    akp_free(alloc, local);
    akp_free(alloc, world);
    return res;
}

float ak_crowd_gait_clip_time(const ak_crowd_gait* gait, float distance) {
    if (!gait || !(gait->stride_length > 0.0f) || !ak_finitef(distance) || distance < 0.0f) return 0.0f;
    const float L = gait->stride_length;
    float d = fmodf(distance, L);
    if (d >= L) d = 0.0f;
    /* the first interval k with distance[k + 1] > d (distance[0] = 0 <= d) */
    unsigned a = 0, b = AK_CROWD_GAIT_SAMPLES - 1;
    while (a < b) {
        const unsigned m = (a + b) / 2;
        if (gait->distance[m + 1] > d) b = m;
        else a = m + 1;
    }
    const float d0 = gait->distance[a], d1 = gait->distance[a + 1];
    const float u = d1 > d0 ? ak_clampf((d - d0) / (d1 - d0), 0.0f, 1.0f) : 0.0f;
    const float t = gait->duration * ((float)a + u) / (float)AK_CROWD_GAIT_SAMPLES;
    return t < gait->duration ? t : 0.0f;
}

ak_crowd_character ak_crowd_character_init(const ak_crowd_gait* gait, ak_vec2 heading, float phase) {
    ak_crowd_character c = {0};
    const float h = ak_vec2_length(heading);
    c.heading = (ak_finitef(h) && h > 1e-6f) ? ak_vec2_scale(heading, 1.0f / h) : ak_vec2_make(0.0f, 1.0f);
    if (gait && gait->stride_length > 0.0f && ak_finitef(phase)) {
        const float p = phase - floorf(phase);
        c.distance = p * gait->stride_length;
        if (!(c.distance < gait->stride_length)) c.distance = 0.0f;
        c.clip_time = ak_crowd_gait_clip_time(gait, c.distance);
    }
    return c;
}

size_t ak_crowd_characters_scratch_size(const ak_crowd_gait* gait) {
    if (!gait || !gait->scene) return 0;
    return ak_scene_joint_count(gait->scene) * sizeof(ak_transform) + 16u;
}

/* One character's feet after its update, standing at p (local: a pose's room). The clip's
 * foot (the unplanted pose) decides: down while within AK_CROWD_PLANT_BAND of its lowest (the
 * clip's lowest blended toward the rest pose's height by 1 - walk_weight, as the pose is). */
static void plant_feet(const ak_crowd_gait* g, ak_crowd_character* c, ak_vec2 p, float dt, ak_transform* local) {
    const ak_skeleton* sk = g->scene->skeleton;
    const size_t J = ak_skeleton_joint_count(sk);
    const ak_i32_cspan parents = ak_skeleton_parents(sk);
    if (ak_crowd_character_pose(g, c, (ak_transform_span){local, J}) != AK_OK) return;
    const ak_quat q = root_rotation(g, c);
    for (int f = 0; f < 2; ++f) {
        int leg[3];
        if (!leg_of(g, parents, f, leg)) return;
        const ak_vec3 hip = model_of(parents, local, leg[0]).translation;
        const ak_vec3 knee = model_of(parents, local, leg[1]).translation;
        const ak_vec3 a = model_of(parents, local, leg[2]).translation;
        const ak_vec2 aw = to_world(q, p, a);
        /* the lowest the clip's foot goes, blended toward the rest pose's as the pose is */
        const float rest_y = model_of(parents, ak_skeleton_rest_pose(sk).ptr, leg[2]).translation.y;
        const float low = rest_y + (g->foot_min_y[f] - rest_y) * ak_clampf(c->walk_weight, 0.0f, 1.0f);
        const bool down = a.y <= low + AK_CROWD_PLANT_BAND;
        uint8_t* st = &c->foot_state[f];
        float* w = &c->foot_weight[f];
        if (*st == AK_CROWD_FOOT_RELEASING && down) {
            /* put down again before the pin faded out (the clip stopped mid-swing: the idle
             * blend lowers the foot): step from where the foot is now */
            c->foot_pin[f] = ak_vec2_add(aw, ak_vec2_scale(ak_vec2_sub(c->foot_pin[f], aw), *w));
            *st = AK_CROWD_FOOT_STEPPING, *w = 1.0f;
        } else if (*st == AK_CROWD_FOOT_RELEASING || *st == AK_CROWD_FOOT_STEPPING) {
            *w -= dt / (*st == AK_CROWD_FOOT_RELEASING ? AK_CROWD_PLANT_RELEASE_TIME : AK_CROWD_PLANT_STEP_TIME);
            if (!(*w > 1e-3f)) *st = AK_CROWD_FOOT_FREE, *w = 0.0f; /* ended (float steps leave ~1e-8) */
        } else if (*st == AK_CROWD_FOOT_PINNED) {
            if (!down) {
                *st = AK_CROWD_FOOT_RELEASING, *w = 1.0f;
            } else {
                const float off = ak_vec2_length(ak_vec2_sub(c->foot_pin[f], aw));
                const float drop = leg_drop(hip, knee, a, to_model(q, p, c->foot_pin[f], a.y));
                /* one foot steps at a time, unless the leg can no longer hold this one */
                if ((off > AK_CROWD_PLANT_MAX_OFFSET && c->foot_state[1 - f] != AK_CROWD_FOOT_STEPPING) ||
                    drop > AK_CROWD_PLANT_MAX_DROP || !ak_finitef(off))
                    *st = AK_CROWD_FOOT_STEPPING, *w = 1.0f;
            }
        } else if (*st != AK_CROWD_FOOT_FREE) {
            *st = AK_CROWD_FOOT_FREE, *w = 0.0f;
        }
        if (*st == AK_CROWD_FOOT_FREE && down) {
            *st = AK_CROWD_FOOT_PINNED, *w = 1.0f;
            c->foot_pin[f] = aw;
        }
    }
}

ak_result ak_crowd_characters_update(const ak_crowd_characters_job* job) {
    if (!job || !job->gait || !job->characters.ptr || (job->characters.count && !job->velocities.ptr))
        return AK_ERR_NULL_ARG;
    if (!(job->dt > 0.0f) || !ak_finitef(job->dt) || !(job->turn_time >= 0.0f) || !ak_finitef(job->turn_time) ||
        !(job->max_turn_rate >= 0.0f) || !ak_finitef(job->max_turn_rate) || !(job->idle_speed >= 0.0f) ||
        !ak_finitef(job->idle_speed))
        return AK_ERR_BAD_ARG;
    const size_t n = job->characters.count;
    if (job->velocities.count < n) return AK_ERR_SPAN_SMALL;
    for (size_t i = 0; i < n; ++i)
        if (!ak_finitef(job->velocities.ptr[i].x) || !ak_finitef(job->velocities.ptr[i].y) ||
            fabsf(job->velocities.ptr[i].x) > 1e7f || fabsf(job->velocities.ptr[i].y) > 1e7f)
            return AK_ERR_BAD_DATA;
    const bool plant = job->positions.count > 0 || job->positions.ptr;
    ak_transform* local = NULL;
    if (plant) {
        if (n && !job->positions.ptr) return AK_ERR_NULL_ARG;
        if (job->positions.count < n) return AK_ERR_SPAN_SMALL;
        if (!job->gait->scene || !job->gait->scene->skeleton) return AK_ERR_NULL_ARG;
        const size_t need = ak_crowd_characters_scratch_size(job->gait);
        if (!job->scratch.ptr || job->scratch.count < need) return AK_ERR_SPAN_SMALL;
        const uintptr_t a = ((uintptr_t)job->scratch.ptr + 15u) & ~(uintptr_t)15u;
        local = (ak_transform*)a;
        for (size_t i = 0; i < n; ++i)
            if (!ak_finitef(job->positions.ptr[i].x) || !ak_finitef(job->positions.ptr[i].y) ||
                fabsf(job->positions.ptr[i].x) > 1e7f || fabsf(job->positions.ptr[i].y) > 1e7f)
                return AK_ERR_BAD_DATA;
    }
    const ak_crowd_gait* g = job->gait;
    const float turn_time = job->turn_time > 0.0f ? job->turn_time : 0.1f;
    const float max_turn = (job->max_turn_rate > 0.0f ? job->max_turn_rate : 6.0f) * job->dt;
    const float idle = job->idle_speed > 0.0f ? job->idle_speed : 0.15f;
    const float follow = 1.0f - expf(-job->dt / turn_time);
    const float L = g->stride_length;
    for (size_t i = 0; i < n; ++i) {
        ak_crowd_character* c = &job->characters.ptr[i];
        const ak_vec2 v = job->velocities.ptr[i];
        const float speed = ak_vec2_length(v);
        if (L > 0.0f) {
            double d = (double)c->distance + (double)speed * (double)job->dt;
            if (!(d >= 0.0) || !isfinite(d)) d = 0.0;
            d = fmod(d, (double)L);
            c->distance = (float)d < L ? (float)d : 0.0f;
            c->clip_time = ak_crowd_gait_clip_time(g, c->distance);
        }
        if (speed > 0.5f * idle) {
            /* turn toward v by the smoothed angle, at most max_turn */
            const ak_vec2 h = c->heading, u = ak_vec2_scale(v, 1.0f / speed);
            float a = atan2f(ak_vec2_cross(h, u), ak_vec2_dot(h, u)) * follow;
            a = ak_clampf(a, -max_turn, max_turn);
            const float ca = cosf(a), sa = sinf(a);
            ak_vec2 nh = ak_vec2_make(h.x * ca - h.y * sa, h.x * sa + h.y * ca);
            const float l = ak_vec2_length(nh);
            c->heading = l > 1e-6f && ak_finitef(l) ? ak_vec2_scale(nh, 1.0f / l) : u;
        }
        c->walk_weight = smoothstep01(speed / idle);
        if (plant) plant_feet(g, c, job->positions.ptr[i], job->dt, local);
    }
    return AK_OK;
}

size_t ak_crowd_character_bucket_count(uint32_t phase_buckets, uint32_t weight_levels) {
    if (phase_buckets == 0 || weight_levels < 2) return 0;
    return 1u + (size_t)(weight_levels - 1u) * phase_buckets;
}

size_t ak_crowd_character_bucket(const ak_crowd_gait* gait, const ak_crowd_character* character,
                                 uint32_t phase_buckets, uint32_t weight_levels, ak_crowd_character* out) {
    if (!gait || !character || !(gait->duration > 0.0f) || phase_buckets == 0 || weight_levels < 2) return SIZE_MAX;
    const float w = ak_clampf(ak_finitef(character->walk_weight) ? character->walk_weight : 0.0f, 0.0f, 1.0f);
    const uint32_t top = weight_levels - 1u;
    uint32_t level = (uint32_t)lrintf(w * (float)top);
    if (level > top) level = top;
    const float t = ak_finitef(character->clip_time) ? ak_clampf(character->clip_time, 0.0f, gait->duration) : 0.0f;
    uint32_t ph = (uint32_t)lrint((double)t / (double)gait->duration * (double)phase_buckets);
    if (ph >= phase_buckets) ph = 0; /* the end of the cycle is its start */
    if (out) {
        *out = *character;
        out->walk_weight = (float)level / (float)top;
        out->clip_time = level ? (float)((double)ph * (double)gait->duration / (double)phase_buckets) : 0.0f;
    }
    return level ? 1u + (size_t)(level - 1u) * phase_buckets + ph : 0u;
}

ak_result ak_crowd_character_pose(const ak_crowd_gait* gait, const ak_crowd_character* character,
                                  ak_transform_span out_local) {
    if (!gait || !character || !gait->scene || !gait->scene->skeleton || !out_local.ptr) return AK_ERR_NULL_ARG;
    const ak_transform_cspan rest = ak_skeleton_rest_pose(gait->scene->skeleton);
    if (out_local.count < rest.count) return AK_ERR_SPAN_SMALL;
    for (size_t j = 0; j < rest.count; ++j) out_local.ptr[j] = rest.ptr[j];
    const float w = ak_clampf(ak_finitef(character->walk_weight) ? character->walk_weight : 0.0f, 0.0f, 1.0f);
    if (w <= 0.0f) return AK_OK;
    const float t = ak_finitef(character->clip_time) ? ak_clampf(character->clip_time, 0.0f, gait->duration) : 0.0f;
    const ak_result r = ak_clip_sample(gait->scene->clips[gait->clip_index], t, NULL, out_local, (ak_f32_span){0},
                                       (ak_f32_span){0});
    if (r != AK_OK || w >= 1.0f) return r;
    for (size_t j = 0; j < rest.count; ++j) {
        ak_transform* o = &out_local.ptr[j];
        o->translation = ak_vec3_lerp(rest.ptr[j].translation, o->translation, w);
        o->scale = ak_vec3_lerp(rest.ptr[j].scale, o->scale, w);
        o->rotation = ak_quat_slerp(rest.ptr[j].rotation, o->rotation, w);
    }
    return AK_OK;
}

ak_result ak_crowd_character_pose_planted(const ak_crowd_gait* gait, const ak_crowd_character* character,
                                          ak_vec2 p, ak_transform_span out_local) {
    ak_result r = ak_crowd_character_pose(gait, character, out_local);
    if (r != AK_OK) return r;
    bool any = false;
    for (int f = 0; f < 2; ++f)
        any |= character->foot_state[f] != AK_CROWD_FOOT_FREE && character->foot_weight[f] > 0.0f;
    if (!any || !ak_finitef(p.x) || !ak_finitef(p.y)) return AK_OK;
    const ak_skeleton* sk = gait->scene->skeleton;
    const ak_i32_cspan parents = ak_skeleton_parents(sk);
    ak_transform* local = out_local.ptr;
    const ak_quat q = root_rotation(gait, character);
    int legs[2][3];
    ak_vec3 target[2];
    ak_quat foot_rot[2];
    float drop = 0.0f;
    for (int f = 0; f < 2; ++f) {
        if (!leg_of(gait, parents, f, legs[f])) return AK_OK;
        const ak_transform am = model_of(parents, local, legs[f][2]);
        const ak_vec3 a = am.translation;
        foot_rot[f] = am.rotation;
        const float w = ak_clampf(ak_finitef(character->foot_weight[f]) ? character->foot_weight[f] : 0.0f, 0.0f, 1.0f);
        const ak_vec3 pin = to_model(q, p, character->foot_pin[f], a.y);
        switch (character->foot_state[f]) {
        case AK_CROWD_FOOT_PINNED:
        case AK_CROWD_FOOT_RELEASING: target[f] = ak_vec3_lerp(a, pin, w); break;
        case AK_CROWD_FOOT_STEPPING: {
            const float s = 1.0f - w;
            target[f] = ak_vec3_lerp(pin, a, smoothstep01(s));
            target[f].y = a.y + AK_CROWD_PLANT_STEP_HEIGHT * sinf(3.14159265f * s);
            break;
        }
        default: target[f] = a; break;
        }
        const ak_vec3 hip = model_of(parents, local, legs[f][0]).translation;
        const ak_vec3 knee = model_of(parents, local, legs[f][1]).translation;
        drop = fmaxf(drop, leg_drop(hip, knee, a, target[f]));
    }
    /* the pelvis: the common root of the legs, lowered where a leg cannot reach */
    drop = fminf(drop, AK_CROWD_PLANT_MAX_DROP);
    if (drop > 0.0f) {
        int root = legs[0][0];
        for (size_t guard = parents.count; parents.ptr[root] >= 0 && guard-- > 0;) root = parents.ptr[root];
        local[root].translation.y -= drop;
    }
    for (int f = 0; f < 2; ++f) {
        const int* L = legs[f];
        const ak_transform h = model_of(parents, local, L[0]), k = model_of(parents, local, L[1]),
                           a = model_of(parents, local, L[2]);
        if (drop <= 0.0f && ak_vec3_length_sq(ak_vec3_sub(a.translation, target[f])) < 1e-12f) continue;
        ak_quat cs, cm;
        ak_ik_two_bone_job job = {.start = ak_transform_to_mat4(h), .mid = ak_transform_to_mat4(k),
                                  .end = ak_transform_to_mat4(a), .target = target[f], .pole = gait->forward,
                                  .out_start_rot = &cs, .out_mid_rot = &cm};
        if (ak_ik_two_bone_run(&job) != AK_OK) continue;
        local[L[0]].rotation = ak_quat_normalize(ak_quat_mul(local[L[0]].rotation, cs));
        local[L[1]].rotation = ak_quat_normalize(ak_quat_mul(local[L[1]].rotation, cm));
        /* the foot keeps its model orientation (the clip's) */
        const ak_quat kr = model_of(parents, local, L[1]).rotation;
        local[L[2]].rotation = ak_quat_normalize(ak_quat_mul(ak_quat_conjugate(kr), foot_rot[f]));
    }
    return AK_OK;
}

ak_mat4 ak_crowd_character_root(const ak_crowd_gait* gait, const ak_crowd_character* character, ak_vec2 p) {
    if (!gait || !character) return ak_mat4_identity();
    /* yaw about +y maps (x, z) by x' = x cos + z sin, z' = -x sin + z cos; turn forward onto heading */
    const float af = atan2f(gait->forward.x, gait->forward.z);
    const float ah = atan2f(character->heading.x, character->heading.y);
    const ak_quat q = ak_quat_from_axis_angle(ak_vec3_make(0.0f, 1.0f, 0.0f), ah - af);
    ak_mat4 m = ak_mat4_from_quat(q);
    m.m[12] = p.x;
    m.m[13] = 0.0f;
    m.m[14] = p.y;
    return m;
}

/* ---- baking the crowd into a scene -------------------------------------------------------- */

/* The walk clip's joint channels (translation, rotation, scale of the character's joints):
 * each becomes one channel per agent. */
static size_t bake_clip_channels(const ak_crowd_gait* g) {
    const ak_clip* clip = g->scene->clips[g->clip_index];
    const size_t J = ak_scene_joint_count(g->scene);
    size_t cc = 0;
    for (size_t c = 0; c < ak_clip_channel_count(clip); ++c) {
        const ak_channel_target t = ak_clip_channel_target(clip, c);
        if ((t == AK_CHANNEL_TRANSLATION || t == AK_CHANNEL_ROTATION || t == AK_CHANNEL_SCALE) &&
            ak_clip_channel_index(clip, c) < J)
            ++cc;
    }
    return cc;
}

/* Bytes a bake takes, estimated before allocating: the character's meshes (once: the agents
 * share them), per agent its nodes (the joint descs and the skeleton: 256 bytes a node) and
 * skin, and per agent, channel and frame a raw key and a built one (16 bytes each). */
static void bake_bytes(const ak_crowd_gait* g, size_t N, double* out_fixed, double* out_per_frame) {
    const ak_scene* cs = g->scene;
    const size_t J = ak_scene_joint_count(cs);
    double mesh = 0.0, skin = 0.0;
    for (size_t m = 0; m < cs->mesh_count; ++m) {
        const ak_mesh* me = cs->meshes[m].mesh;
        if (!me) continue;
        mesh += (double)me->vertex_count * (80.0 + 6.0 * me->influence_count) + 12.0 * (double)me->triangle_count +
                40.0 * (double)me->vertex_count * (double)me->morph_target_count;
    }
    for (size_t s = 0; s < cs->skin_count; ++s) skin += 68.0 * (double)cs->skins[s].joint_count;
    *out_fixed = mesh + (double)N * ((double)(J + 1) * 256.0 + skin + 128.0 * (double)cs->mesh_count);
    *out_per_frame = 2.0 * (double)N * (double)(2 + bake_clip_channels(g)) * 16.0;
}

size_t ak_crowd_bake_max_frames(const ak_crowd_gait* gait, size_t agent_count, size_t memory_budget) {
    if (!gait || !gait->scene || !gait->scene->skeleton || agent_count == 0) return 0;
    const size_t J = ak_scene_joint_count(gait->scene);
    if ((double)agent_count * (double)(J + 1) > (double)AK_SKELETON_MAX_JOINTS) return 0;
    double fixed, per_frame;
    bake_bytes(gait, agent_count, &fixed, &per_frame);
    const double budget = (double)(memory_budget ? memory_budget : AK_SCENE_BAKE_DEFAULT_BUDGET);
    if (fixed + per_frame > budget) return 0;
    const double f = floor((budget - fixed) / per_frame);
    return f >= (double)AK_SCENE_BAKE_MAX_FRAMES ? AK_SCENE_BAKE_MAX_FRAMES : (size_t)f;
}

ak_result ak_crowd_bake_scene(const ak_crowd_bake_desc* desc, const ak_allocator* alloc, ak_scene** out_scene,
                              ak_diag* out_diag) {
    if (out_scene) *out_scene = NULL;
    if (!desc || !out_scene || !desc->gait || !desc->gait->scene || !desc->gait->scene->skeleton ||
        !desc->positions || !desc->characters) {
        akp_diag_set(out_diag, "crowd", "no desc, gait, scene, positions, characters or output");
        return AK_ERR_NULL_ARG;
    }
    const char* name = desc->name ? desc->name : "crowd";
    const size_t N = desc->agent_count, F = desc->frame_count;
    if (N == 0 || F == 0) {
        akp_diag_set(out_diag, name, "no %s", N == 0 ? "agent" : "frame");
        return AK_ERR_EMPTY;
    }
    if (!(desc->frame_time > 0.0f) || !ak_finitef(desc->frame_time) ||
        !ak_finitef(desc->frame_time * (float)(F - 1))) {
        akp_diag_set(out_diag, name, "frame time %g s: not > 0 and finite", (double)desc->frame_time);
        return AK_ERR_BAD_ARG;
    }
    if (F > AK_SCENE_BAKE_MAX_FRAMES) {
        akp_diag_set(out_diag, name, "%zu frames: more than %u", F, AK_SCENE_BAKE_MAX_FRAMES);
        return AK_ERR_UNSUPPORTED;
    }
    const ak_crowd_gait* g = desc->gait;
    const ak_scene* cs = g->scene;
    const size_t J = ak_scene_joint_count(cs);
    if ((double)N * (double)(J + 1) > (double)AK_SKELETON_MAX_JOINTS) {
        akp_diag_set(out_diag, name, "%zu agents x %zu nodes: more than %u nodes", N, J + 1, AK_SKELETON_MAX_JOINTS);
        return AK_ERR_UNSUPPORTED;
    }
    for (size_t k = 0; k < N * F; ++k)
        if (!ak_finitef(desc->positions[k].x) || !ak_finitef(desc->positions[k].y) ||
            fabsf(desc->positions[k].x) > 1e7f || fabsf(desc->positions[k].y) > 1e7f) {
            akp_diag_set(out_diag, name, "frame %zu, agent %zu: position not finite or beyond 1e7 m", k / N, k % N);
            return AK_ERR_BAD_DATA;
        }
    /* The walk clip's joint channels: each becomes one channel per agent. */
    const ak_clip* clip = cs->clips[g->clip_index];
    const size_t per_agent = 2 + bake_clip_channels(g); /* root translation and rotation, then the clip's */
    /* Bytes, estimated before allocating: the meshes, the nodes, the raw keys and the built clip. */
    double fixed, per_frame;
    bake_bytes(g, N, &fixed, &per_frame);
    const double bytes = fixed + per_frame * (double)F;
    const size_t budget = desc->memory_budget ? desc->memory_budget : AK_SCENE_BAKE_DEFAULT_BUDGET;
    if (bytes > (double)budget) {
        akp_diag_set(out_diag, name, "%zu agents x %zu frames need about %.0f MB, more than the budget of %.0f MB", N,
                     F, bytes / 1048576.0, (double)budget / 1048576.0);
        return AK_ERR_UNSUPPORTED;
    }

    ak_scene* sc = NULL;
    ak_result res = ak_scene_alloc(N * cs->mesh_count, N * cs->skin_count, 1, alloc, &sc);
    if (res != AK_OK) return res;
    snprintf(sc->name, sizeof sc->name, "%s", name);
    const size_t nodes = N * (J + 1);
    ak_joint_desc* jd = akp_alloc(alloc, nodes * sizeof *jd);
    char(*names)[AK_NAME_SIZE] = akp_alloc(alloc, nodes * sizeof *names);
    ak_raw_channel* ch = akp_alloc(alloc, N * per_agent * sizeof *ch);
    float* times = akp_alloc(alloc, F * sizeof *times);
    float* keys = akp_alloc(alloc, N * per_agent * F * 4 * sizeof *keys);
    ak_transform* pose = akp_alloc(alloc, J * sizeof *pose);
    sc->is_joint = akp_alloc(&sc->alloc, nodes * sizeof *sc->is_joint);
    if (!jd || !names || !ch || !times || !keys || !pose || !sc->is_joint) {
        res = AK_ERR_NO_MEMORY;
        goto done;
    }
    /* nodes: per agent its root, then the character's nodes */
    const ak_i32_cspan parents = ak_skeleton_parents(cs->skeleton);
    for (size_t a = 0; a < N; ++a) {
        const size_t base = a * (J + 1);
        const ak_crowd_character* c0 = &desc->characters[a];
        const ak_vec2 p0 = desc->positions[a];
        snprintf(names[base], AK_NAME_SIZE, "%.40s_%zu", name, a);
        jd[base] = (ak_joint_desc){.name = names[base], .parent = -1,
                                   .rest = ak_transform_make(ak_vec3_make(p0.x, 0.0f, p0.y), root_rotation(g, c0),
                                                             ak_vec3_make(1.0f, 1.0f, 1.0f))};
        sc->is_joint[base] = false;
        /* the nodes rest in the first frame's pose (a one-frame scene is that frame) */
        res = ak_crowd_character_pose_planted(g, c0, p0, (ak_transform_span){pose, J});
        if (res != AK_OK) goto done;
        for (size_t j = 0; j < J; ++j) {
            snprintf(names[base + 1 + j], AK_NAME_SIZE, "%zu/%.40s", a, ak_skeleton_joint_name(cs->skeleton, j));
            jd[base + 1 + j] = (ak_joint_desc){.name = names[base + 1 + j],
                                               .parent = parents.ptr[j] < 0 ? (int)base : (int)(base + 1) + parents.ptr[j],
                                               .rest = pose[j]};
            sc->is_joint[base + 1 + j] = cs->is_joint ? cs->is_joint[j] : true;
        }
    }
    ak_skeleton_desc sd = {.joints = jd, .joint_count = nodes, .name = name, .palette_from_skins = true};
    res = ak_skeleton_create(&sd, &sc->alloc, &sc->skeleton, out_diag);
    if (res != AK_OK) goto done;
    /* skins and meshes: copies, their joints and nodes moved to the agent's */
    for (size_t a = 0; a < N && res == AK_OK; ++a) {
        const size_t base = a * (J + 1) + 1;
        for (size_t s = 0; s < cs->skin_count && res == AK_OK; ++s) {
            const ak_scene_skin* from = &cs->skins[s];
            ak_scene_skin* to = &sc->skins[a * cs->skin_count + s];
            res = ak_scene_skin_alloc(sc, a * cs->skin_count + s, from->joint_count);
            if (res != AK_OK) break;
            snprintf(to->name, sizeof to->name, "%zu/%.40s", a, from->name);
            for (size_t k = 0; k < from->joint_count; ++k) {
                to->joints[k] = (int32_t)base + from->joints[k];
                to->inverse_binds[k] = from->inverse_binds[k];
            }
        }
        for (size_t m = 0; m < cs->mesh_count && res == AK_OK; ++m) {
            const ak_scene_mesh* from = &cs->meshes[m];
            ak_scene_mesh* to = &sc->meshes[a * cs->mesh_count + m];
            *to = *from;
            to->mesh = NULL;
            to->texture = -1; /* textures are not copied */
            /* skinned: no node (ak_io_save gives it its own root: glTF ignores a skinned mesh's
             * node transform and warns when that node is animated); rigid: the agent's node */
            to->node = from->skin >= 0 ? -1 : (from->node < 0 ? (int32_t)(base - 1) : (int32_t)base + from->node);
            to->skin = from->skin < 0 ? -1 : (int32_t)(a * cs->skin_count) + from->skin;
            if (desc->colors) {
                to->has_material = true;
                to->base_color = desc->colors[a];
            }
            if (from->mesh && a == 0) { /* agent 0 owns the copy, the others place it */
                res = ak_mesh_clone(from->mesh, &sc->alloc, &to->mesh);
                if (res == AK_OK) snprintf(to->mesh->name, sizeof to->mesh->name, "%.40s", from->mesh->name);
            } else if (from->mesh) {
                to->mesh = sc->meshes[m].mesh;
                to->shares_mesh = true;
            }
        }
    }
    if (res != AK_OK) goto done;
    /* the clip: every frame's root and pose */
    for (size_t f = 0; f < F; ++f) times[f] = desc->frame_time * (float)f;
    for (size_t a = 0; a < N; ++a) {
        const size_t base = a * (J + 1);
        ak_raw_channel* c = ch + a * per_agent;
        float* kv = keys + a * per_agent * F * 4;
        c[0] = (ak_raw_channel){.target = AK_CHANNEL_TRANSLATION, .index = (uint32_t)base, .component_count = 3,
                                .interp = AK_INTERP_LINEAR, .key_count = F, .times = times, .values = kv};
        c[1] = (ak_raw_channel){.target = AK_CHANNEL_ROTATION, .index = (uint32_t)base, .component_count = 4,
                                .interp = AK_INTERP_LINEAR, .key_count = F, .times = times, .values = kv + F * 4};
        size_t k = 2;
        for (size_t q = 0; q < ak_clip_channel_count(clip); ++q) {
            const ak_channel_target t = ak_clip_channel_target(clip, q);
            const uint32_t j = ak_clip_channel_index(clip, q);
            if ((t != AK_CHANNEL_TRANSLATION && t != AK_CHANNEL_ROTATION && t != AK_CHANNEL_SCALE) || j >= J) continue;
            c[k] = (ak_raw_channel){.target = t, .index = (uint32_t)(base + 1 + j),
                                    .component_count = t == AK_CHANNEL_ROTATION ? 4u : 3u,
                                    .interp = AK_INTERP_LINEAR, .key_count = F, .times = times,
                                    .values = kv + k * F * 4};
            ++k;
        }
        for (size_t f = 0; f < F; ++f) {
            const ak_crowd_character* chr = &desc->characters[f * N + a];
            const ak_vec2 p = desc->positions[f * N + a];
            float* tr = kv + 3 * f;
            tr[0] = p.x, tr[1] = 0.0f, tr[2] = p.y;
            ak_quat r = root_rotation(g, chr);
            float* rq = kv + F * 4 + 4 * f;
            if (f > 0 && rq[-4] * r.x + rq[-3] * r.y + rq[-2] * r.z + rq[-1] * r.w < 0.0f) r = ak_quat_neg(r);
            rq[0] = r.x, rq[1] = r.y, rq[2] = r.z, rq[3] = r.w;
            res = ak_crowd_character_pose_planted(g, chr, p, (ak_transform_span){pose, J});
            if (res != AK_OK) goto done;
            for (size_t q = 2; q < per_agent; ++q) {
                const size_t j = c[q].index - base - 1;
                float* v = (float*)c[q].values + c[q].component_count * f;
                if (c[q].target == AK_CHANNEL_ROTATION) {
                    ak_quat o = pose[j].rotation;
                    if (f > 0 && v[-4] * o.x + v[-3] * o.y + v[-2] * o.z + v[-1] * o.w < 0.0f) o = ak_quat_neg(o);
                    v[0] = o.x, v[1] = o.y, v[2] = o.z, v[3] = o.w;
                } else {
                    const ak_vec3 o = c[q].target == AK_CHANNEL_TRANSLATION ? pose[j].translation : pose[j].scale;
                    v[0] = o.x, v[1] = o.y, v[2] = o.z;
                }
            }
        }
    }
    if (F > 1) {
        ak_raw_clip raw = {.name = name, .channels = ch, .channel_count = N * per_agent, .joint_count = nodes};
        res = ak_clip_build(&raw, &sc->alloc, &sc->clips[0], out_diag);
    } else {
        sc->clip_count = 0; /* one frame: the rest pose is the frame */
    }
done:
    akp_free(alloc, jd);
    akp_free(alloc, names);
    akp_free(alloc, ch);
    akp_free(alloc, times);
    akp_free(alloc, keys);
    akp_free(alloc, pose);
    if (res != AK_OK) {
        if (res == AK_ERR_NO_MEMORY) akp_diag_set(out_diag, name, "out of memory");
        ak_scene_destroy(sc);
        return res;
    }
    *out_scene = sc;
    return AK_OK;
}

/* animkit boids: a loaded scene stepped as `animkit boids` does (agents from the file or placed
 * at random from the seed, double-buffered steps); see ak_boids_scene_run in animkit/boids.h. */
#include <animkit/boids.h>

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "json.h" /* akp_diag_set */

ak_result ak_boids_scene_run_init(ak_boids_scene_run* st, const ak_boids_scene* sc, const ak_boids_scene_run_desc* desc,
                                  ak_diag* out_diag) {
    static const ak_boids_scene_run_desc none = {0};
    if (!st) return akp_diag_set(out_diag, AK_ERR_NULL_ARG, "boids", "no run");
    memset(st, 0, sizeof *st);
    if (!sc) return akp_diag_set(out_diag, AK_ERR_NULL_ARG, "boids", "no scene");
    if (!desc) desc = &none;
    const char* file = desc->name ? desc->name : "scene";
    st->n = sc->agent_count > 0 ? sc->agent_count : sc->count;
    if (sc->params.has_leader && sc->params.leader_index >= st->n)
        return akp_diag_set(out_diag, AK_ERR_BAD_INDEX, file, "leader.index: %u is not below the %zu agents",
                            sc->params.leader_index, st->n);
    st->p = malloc(st->n * sizeof(ak_vec3));
    st->v = malloc(st->n * sizeof(ak_vec3));
    st->p2 = malloc(st->n * sizeof(ak_vec3));
    st->v2 = malloc(st->n * sizeof(ak_vec3));
    st->w = calloc(st->n, sizeof(ak_vec3));
    st->s = calloc(st->n, 1);
    if (!st->p || !st->v || !st->p2 || !st->v2 || !st->w || !st->s)
        return akp_diag_set(out_diag, AK_ERR_NO_MEMORY, file, "out of memory for %zu agents", st->n);
    const ak_boids_params* prm = &sc->params;
    if (sc->agent_count > 0) {
        memcpy(st->p, sc->positions, st->n * sizeof(ak_vec3));
        memcpy(st->v, sc->velocities, st->n * sizeof(ak_vec3));
        memcpy(st->s, sc->agent_species, st->n);
    } else {
        ak_rng r = ak_rng_make((uint64_t)sc->seed);
        const ak_vec3 lo = prm->bounds_min, hi = prm->bounds_max;
        size_t used = 0;
        for (uint32_t k = 1; k < prm->species_count; ++k) {
            size_t c = (size_t)((double)sc->fraction[k] * (double)st->n + 0.5);
            if (c > st->n - used) c = st->n - used;
            for (size_t i = st->n - used - c; i < st->n - used; ++i) st->s[i] = (uint8_t)k;
            used += c;
        }
        for (size_t i = 0; i < st->n; ++i) {
            st->p[i] = ak_vec3_make(ak_rng_range(&r, lo.x, hi.x), prm->planar ? 0.0f : ak_rng_range(&r, lo.y, hi.y),
                                    ak_rng_range(&r, lo.z, hi.z));
            ak_vec3 d = ak_vec3_make(ak_rng_range(&r, -1, 1), prm->planar ? 0.0f : ak_rng_range(&r, -1, 1),
                                     ak_rng_range(&r, -1, 1));
            const float sp = sc->species[st->s[i]].max_speed;
            st->v[i] = ak_vec3_scale(ak_vec3_normalize(d), 0.5f * sp);
        }
    }
    if (prm->planar)
        for (size_t i = 0; i < st->n; ++i) st->v[i].y = 0.0f;
    st->agent_count = st->n, st->positions = st->p, st->velocities = st->v, st->species = st->s;

    st->job = (ak_boids_step_job){.params = prm, .positions = {st->p, st->n}, .velocities = {st->v, st->n},
                                  .species = {st->s, st->n}, .wander = {st->w, st->n}, .dt = sc->dt,
                                  .seed = (uint64_t)sc->seed, .thread_count = desc->thread_count ? desc->thread_count : 1,
                                  .use_naive = desc->naive,
                                  .out_positions = {st->p2, st->n}, .out_velocities = {st->v2, st->n}};
    st->scratch_size = ak_boids_step_scratch_size(&st->job);
    st->scratch = st->scratch_size ? malloc(st->scratch_size) : NULL;
    st->job.scratch = (ak_u8_span){st->scratch, st->scratch_size};
    if (st->scratch_size && !st->scratch) return akp_diag_set(out_diag, AK_ERR_NO_MEMORY, file, "out of memory");
    ak_result res = ak_boids_step_validate(&st->job);
    if (res != AK_OK) return akp_diag_set(out_diag, res, file, "%s", ak_result_string(res));
    if (out_diag) memset(out_diag, 0, sizeof *out_diag);
    return AK_OK;
}

ak_result ak_boids_scene_run_step(ak_boids_scene_run* st) {
    if (!st || !st->p) return AK_ERR_NULL_ARG;
    ak_boids_step_job* job = &st->job;
    job->step_index = (uint64_t)st->step_index;
    job->positions.ptr = st->p;
    job->velocities.ptr = st->v;
    job->out_positions.ptr = st->p2;
    job->out_velocities.ptr = st->v2;
    ak_result res = ak_boids_step_run(job);
    ak_vec3* t = st->p;
    st->p = st->p2;
    st->p2 = t;
    t = st->v;
    st->v = st->v2;
    st->v2 = t;
    st->positions = st->p, st->velocities = st->v;
    if (res == AK_OK) ++st->step_index;
    return res;
}

const char* ak_boids_scene_run_error(ak_result res) {
    if (res == AK_ERR_BUDGET)
        return "the agents are packed too densely: the grid's cell load (sum over cells of agents^2) is above the "
               "work budget of 2e7 (a quadratic step); spread them out (a larger bounds box, fewer agents) or "
               "lower the rule radii";
    return ak_result_string(res);
}

void ak_boids_scene_run_free(ak_boids_scene_run* r) {
    if (!r) return;
    free(r->p);
    free(r->v);
    free(r->p2);
    free(r->v2);
    free(r->w);
    free(r->s);
    free(r->scratch);
    memset(r, 0, sizeof *r);
}

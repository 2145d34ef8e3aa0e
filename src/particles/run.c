/* animkit particles: stepping a loaded scene as `animkit particles` does (emitters, the burst
 * schedule, springs re-indexed as file particles die); see ak_particles_scene_run in
 * animkit/particles.h. */
#include <animkit/particles.h>

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "json.h" /* akp_diag_set */

ak_result ak_particles_scene_run_init(ak_particles_scene_run* r, ak_particles_scene* s,
                                      const ak_particles_scene_run_desc* desc, ak_diag* out_diag) {
    static const ak_particles_scene_run_desc none = {0};
    if (!r) return akp_diag_set(out_diag, AK_ERR_NULL_ARG, "particles", "no run");
    memset(r, 0, sizeof *r);
    if (!s) return akp_diag_set(out_diag, AK_ERR_NULL_ARG, "particles", "no scene");
    if (!desc) desc = &none;
    r->scene = s;
    ak_particles_desc d = {.capacity = s->capacity,
                           .integrator = s->integrator,
                           .seed = desc->seed,
                           .thread_count = desc->thread_count};
    ak_result res = ak_particles_create(&d, NULL, &r->system);
    if (res != AK_OK)
        return akp_diag_set(out_diag, res, "particles", "cannot create the system: %s", ak_result_string(res));
    for (size_t i = 0; i < s->particle_count; ++i) {
        res = ak_particles_add(r->system, &s->particles[i], NULL);
        if (res != AK_OK) return akp_diag_set(out_diag, res, "particles", "particle %zu: %s", i, ak_result_string(res));
    }
    r->fired = calloc(s->emitter_count + 1, sizeof(uint64_t));
    r->springs = calloc(s->world.springs.count + 1, sizeof(ak_particle_spring));
    if (!r->fired || !r->springs) return akp_diag_set(out_diag, AK_ERR_NO_MEMORY, "particles", "out of memory");
    for (size_t e = 0; e < s->emitter_count; ++e) s->emitters[e].carry = 0.0;
    r->world = s->world;
    if (s->world.springs.count)
        memcpy(r->springs, s->world.springs.ptr, s->world.springs.count * sizeof *r->springs);
    r->world.springs.ptr = r->springs;
    r->file_alive = s->particle_count;
    if (desc->mesh_collider) {
        r->meshes[0] = desc->mesh_collider;
        r->world.meshes = (ak_particle_mesh_cspan){r->meshes, 1};
    }
    if (desc->mesh_positions.count)
        for (size_t e = 0; e < s->emitter_count; ++e)
            if (s->emitters[e].shape == AK_EMITTER_MESH) {
                s->emitters[e].mesh_positions = desc->mesh_positions;
                s->emitters[e].mesh_indices = desc->mesh_indices;
                s->emitters[e].mesh_area_cdf = desc->mesh_area_cdf;
            }
    if (out_diag) memset(out_diag, 0, sizeof *out_diag);
    return AK_OK;
}

/* How many bursts (start + k interval, k = 0, 1, ...) are due before t1: the smallest k >= fired
 * with start + k interval >= t1, saturating at 2^53 (where a double stops counting by one).
 * A bounded number of operations whatever the interval. */
static uint64_t bursts_due(float start, float interval, double t1, uint64_t fired) {
    const double limit = 9007199254740992.0; /* 2^53 */
    double k = ceil((t1 - (double)start) / (double)interval);
    if (!(k < limit)) k = limit;
    if (k < (double)fired) k = (double)fired;
    for (int i = 0; i < 4 && k > (double)fired && (double)start + (k - 1.0) * (double)interval >= t1; ++i) k -= 1.0;
    for (int i = 0; i < 4 && k < limit && (double)start + k * (double)interval < t1; ++i) k += 1.0;
    return (uint64_t)k;
}

ak_result ak_particles_scene_run_step(ak_particles_scene_run* r, ak_diag* out_diag) {
    if (!r || !r->system) return akp_diag_set(out_diag, AK_ERR_NULL_ARG, "particles", "no run");
    ak_particles_scene* s = r->scene;
    const float dt = s->dt;
    const long step = r->step_index;
    const double t1 = (double)(step + 1) * dt;
    ak_result res = AK_OK;
    for (size_t e = 0; e < s->emitter_count && res == AK_OK; ++e) {
        res = ak_particles_emit(r->system, &s->emitters[e], dt, NULL);
        /* Bursts due before the end of this step (start, start + interval, ...). The loop is
         * bounded by integers: at most capacity + 1 calls per emitter and step (each call adds
         * a particle until the system is full); the bursts still due after that are counted,
         * not fired, in a bounded number of operations. A 1e-30 s interval used to hang here:
         * the count was stepped with k -= 1.0 on a double near 1e28, which no longer changes. */
        const ak_particles_scene_burst* b = &s->bursts[e];
        const uint64_t max_calls = (uint64_t)ak_particles_capacity(r->system) + 1u;
        uint64_t calls = 0;
        while (res == AK_OK && b->count > 0 && (b->interval > 0.0f || r->fired[e] == 0)) {
            if ((double)b->start + (double)r->fired[e] * (double)b->interval >= t1) break;
            if (b->interval > 0.0f && (ak_particles_count(r->system) >= ak_particles_capacity(r->system) || calls >= max_calls)) {
                /* full: every burst still due this step would be dropped (a full system emits
                 * nothing and draws no random numbers), so count them without calling */
                r->fired[e] = bursts_due(b->start, b->interval, t1, r->fired[e]);
                break;
            }
            res = ak_particles_burst(r->system, &s->emitters[e], b->count, NULL);
            ++r->fired[e];
            ++calls;
        }
    }
    if (res == AK_OK) res = ak_particles_step(r->system, &r->world, dt);
    if (res == AK_ERR_BUDGET)
        return akp_diag_set(out_diag, res, "particles",
                        "step %ld: Lennard-Jones needs more than %.3g distance tests per force evaluation (particles "
                        "packed into few cells of the %g m cut-off); lower lennard_jones.cutoff or sigma, or spread "
                        "the particles out",
                        step, (double)AK_PARTICLES_LJ_DEFAULT_PAIR_TESTS,
                        (double)(r->world.lennard_jones.cutoff > 0.0f ? r->world.lennard_jones.cutoff
                                                                       : 2.5f * r->world.lennard_jones.sigma));
    if (res != AK_OK) return akp_diag_set(out_diag, res, "particles", "step %ld: %s", step, ak_result_string(res));
    /* File particles come first and keep their order (ids 0.. in file order); when some die
     * (a lifetime, or a state that stopped being finite) the springs follow the survivors'
     * new indices and springs to a dead particle go (they used to point past the end: the
     * next step failed with "an index is out of range") */
    const ak_particles_state st = ak_particles_get_state(r->system);
    size_t alive = 0;
    while (alive < st.count && st.id[alive] < s->particle_count) ++alive;
    if (alive != r->file_alive && s->world.springs.count) {
        uint32_t* where = malloc(s->particle_count * sizeof *where);
        if (!where) return akp_diag_set(out_diag, AK_ERR_NO_MEMORY, "particles", "out of memory");
        for (size_t i = 0; i < s->particle_count; ++i) where[i] = UINT32_MAX;
        for (size_t i = 0; i < alive; ++i) where[st.id[i]] = (uint32_t)i;
        size_t n = 0;
        for (size_t k = 0; k < s->world.springs.count; ++k) {
            ak_particle_spring sp = s->world.springs.ptr[k];
            if (where[sp.i] == UINT32_MAX || where[sp.j] == UINT32_MAX) continue;
            sp.i = where[sp.i], sp.j = where[sp.j];
            r->springs[n++] = sp;
        }
        r->world.springs.count = n;
        free(where);
    }
    r->file_alive = alive;
    ++r->step_index;
    if (out_diag) memset(out_diag, 0, sizeof *out_diag);
    return AK_OK;
}

void ak_particles_scene_run_free(ak_particles_scene_run* r) {
    if (!r) return;
    ak_particles_destroy(r->system);
    free(r->fired);
    free(r->springs);
    memset(r, 0, sizeof *r);
}

/* animkit cloth: a loaded scene stepped as `animkit cloth` does (the spring solver's stable
 * substeps, gusty wind, colliders, attachment targets); see ak_cloth_scene_run in
 * animkit/cloth.h. A character is the caller's: it poses its mesh and sets the attachment
 * targets and extra capsules before each step. */
#include <animkit/cloth.h>

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "json.h" /* akp_diag_set */

ak_result ak_cloth_scene_run_init(ak_cloth_scene_run* run, ak_cloth_scene* sc, const ak_cloth_scene_run_desc* desc,
                                  ak_diag* out_diag) {
    static const ak_cloth_scene_run_desc none = {0};
    if (!run) return akp_diag_set(out_diag, AK_ERR_NULL_ARG, "cloth", "no run");
    memset(run, 0, sizeof *run);
    if (!sc) return akp_diag_set(out_diag, AK_ERR_NULL_ARG, "cloth", "no scene");
    if (!desc) desc = &none;
    const char* name = desc->name ? desc->name : "scene";
    run->scene = sc;
    ak_result r = AK_OK;
    if (sc->attach_count) {
        run->attach_idx = calloc(sc->attach_count, sizeof(uint32_t));
        if (!run->attach_idx) return akp_diag_set(out_diag, AK_ERR_NO_MEMORY, name, "out of memory");
        for (size_t k = 0; k < sc->attach_count; ++k) run->attach_idx[k] = sc->attach[k].vertex;
        sc->desc.attachments = (ak_u32_cspan){run->attach_idx, sc->attach_count};
    }
    r = ak_cloth_create(&sc->desc, NULL, &run->cloth);
    if (r != AK_OK) return akp_diag_set(out_diag, r, name, "the cloth cannot be built: %s", ak_result_string(r));
    /* the spring solver is stable only below a substep it computes (ak_cloth_stable_substep):
     * run at least dt / (0.9 h) substeps unless the caller forced its count */
    if (sc->desc.solver == AK_CLOTH_SPRINGS) {
        const double h = ak_cloth_stable_substep(run->cloth);
        const double need = ceil((double)sc->dt / (0.9 * h));
        if (isfinite(need) && need > (double)sc->substeps && !sc->substeps_forced) {
            run->stable_substep = h;
            run->substeps_given = sc->substeps;
            run->substeps_needed = need;
            if (need > 10000.0)
                return akp_diag_set(out_diag, AK_ERR_BUDGET, name,
                                    "the spring solver needs %.0f substeps per step (over 10000): lower dt or the "
                                    "stiffness, or use --solver implicit or xpbd",
                                    need);
            sc->substeps = (uint32_t)need;
        }
    }
    const size_t n = ak_cloth_vertex_count(run->cloth);
    run->vertex_count = n;
    run->positions = malloc(n * sizeof(ak_vec3));
    run->velocities = calloc(n, sizeof(ak_vec3));
    run->normals = malloc(n * sizeof(ak_vec3));
    run->residuals = calloc(n, sizeof(ak_vec3));
    run->targets = calloc(sc->attach_count + 1, sizeof(ak_vec3));
    run->capsules = calloc(sc->capsule_count + desc->extra_capsule_count + 1, sizeof(ak_cloth_capsule));
    if (!run->positions || !run->velocities || !run->normals || !run->targets || !run->residuals || !run->capsules)
        return akp_diag_set(out_diag, AK_ERR_NO_MEMORY, name, "out of memory");
    ak_cloth_rest_positions(run->cloth, (ak_vec3_span){run->positions, n});
    /* attachments with a given position start there (a collar gathered on the neck) */
    for (size_t k = 0; k < sc->attach_count; ++k)
        if (sc->attach[k].has_position && sc->attach[k].vertex < n) run->positions[sc->attach[k].vertex] = sc->attach[k].position;
    if (sc->capsule_count) memcpy(run->capsules, sc->capsules, sc->capsule_count * sizeof(ak_cloth_capsule));
    run->job = (ak_cloth_step_job){
        .cloth = run->cloth, .dt = sc->dt, .substeps = sc->substeps,
        /* implicit: the scene's iterations cap CG only when given (else the library's 200) */
        .iterations = sc->desc.solver == AK_CLOTH_IMPLICIT && !sc->iterations_given ? 0 : sc->iterations,
        .gravity = sc->gravity,
        .drag = sc->drag, .lift = sc->lift, .air_density = sc->air_density, .damping = sc->damping,
        .planes = sc->planes, .plane_count = sc->plane_count, .spheres = sc->spheres, .sphere_count = sc->sphere_count,
        .capsules = run->capsules, .capsule_count = sc->capsule_count + desc->extra_capsule_count,
        .thickness = sc->thickness, .friction = sc->friction, .self_collision = sc->self_collision,
        .self_distance = sc->self_distance,
        .attachment_targets = {run->targets, sc->attach_count}, .thread_count = (uint32_t)sc->thread_count,
        .positions = {run->positions, n}, .velocities = {run->velocities, n}, .position_residuals = {run->residuals, n},
        .out_normals = {run->normals, n},
    };
    if (desc->mesh.positions.count && desc->mesh.indices.count) run->job.mesh = desc->mesh;
    const size_t scratch_size = ak_cloth_step_scratch_size(&run->job);
    run->scratch = malloc(scratch_size ? scratch_size : 1);
    if (!run->scratch) return akp_diag_set(out_diag, AK_ERR_NO_MEMORY, name, "out of memory");
    run->job.scratch = (ak_u8_span){run->scratch, scratch_size};
    ak_cloth_normals(run->cloth, (ak_vec3_cspan){run->positions, n}, (ak_vec3_span){run->normals, n});
    if (out_diag) memset(out_diag, 0, sizeof *out_diag);
    return AK_OK;
}

ak_result ak_cloth_scene_run_step(ak_cloth_scene_run* run, const char* name, ak_diag* out_diag) {
    if (!run || !run->cloth) return akp_diag_set(out_diag, AK_ERR_NULL_ARG, "cloth", "no run");
    if (!name) name = "scene";
    const ak_cloth_scene* sc = run->scene;
    const long step = run->step_index;
    const float t_end = (float)(step + 1) * sc->dt;
    const float gust = 1.0f + sc->gust * sinf(2.0f * AK_PI * sc->gust_frequency * run->time);
    run->job.wind = ak_vec3_scale(sc->wind, gust);
    const ak_result r = ak_cloth_step_run(&run->job);
    if (r == AK_ERR_NO_CONVERGENCE)
        return akp_diag_set(out_diag, r, name,
                            "blow-up: the state became non-finite at step %ld (t = %.4g s); try a smaller --dt "
                            "or more --substeps",
                            step + 1, (double)t_end);
    if (r != AK_OK) return akp_diag_set(out_diag, r, name, "step %ld: %s", step + 1, ak_result_string(r));
    run->time = t_end;
    run->step_index = step + 1;
    if (out_diag) memset(out_diag, 0, sizeof *out_diag);
    return AK_OK;
}

void ak_cloth_scene_run_free(ak_cloth_scene_run* run) {
    if (!run) return;
    free(run->positions), free(run->residuals), free(run->velocities), free(run->normals), free(run->targets);
    free(run->scratch), free(run->attach_idx), free(run->capsules);
    ak_cloth_destroy(run->cloth);
    memset(run, 0, sizeof *run);
}

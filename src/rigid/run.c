/* animkit rigid: a loaded scene stepped as `animkit rigid` does (the model from the scene, its
 * initial state, sleep timers when the scene lets bodies sleep); see ak_rigid_scene_run in
 * animkit/rigid.h. */
#include <animkit/rigid.h>

#include <stdlib.h>
#include <string.h>

#include "json.h" /* akp_diag_set */

ak_result ak_rigid_scene_run_init(ak_rigid_scene_run* run, const ak_rigid_scene* sc, const char* name,
                                  ak_diag* out_diag) {
    if (!run) return akp_diag_set(out_diag, AK_ERR_NULL_ARG, "rigid", "no run");
    memset(run, 0, sizeof *run);
    if (!sc) return akp_diag_set(out_diag, AK_ERR_NULL_ARG, "rigid", "no scene");
    const char* file = name ? name : "scene";
    const size_t n = sc->body_count;
    ak_rigid_model_desc md = sc->model;
    md.bodies = (ak_rigid_body_desc_cspan){sc->bodies, n};
    md.joints = (ak_rigid_joint_desc_cspan){sc->joints, sc->joint_count};
    ak_result r = ak_rigid_model_create(&md, NULL, &run->model);
    if (r != AK_OK)
        return akp_diag_set(out_diag, r, file, "the bodies cannot be built: %s", ak_result_string(r));
    run->positions = malloc((n ? n : 1) * sizeof *run->positions);
    run->orientations = malloc((n ? n : 1) * sizeof *run->orientations);
    run->velocities = malloc((n ? n : 1) * sizeof *run->velocities);
    run->angular_velocities = malloc((n ? n : 1) * sizeof *run->angular_velocities);
    run->sleep_timers = calloc(n ? n : 1, sizeof *run->sleep_timers);
    run->anchors = malloc((4 * n + 4) * sizeof *run->anchors);
    if (!run->positions || !run->orientations || !run->velocities || !run->angular_velocities ||
        !run->sleep_timers || !run->anchors)
        return akp_diag_set(out_diag, AK_ERR_NO_MEMORY, file, "out of memory for %zu bodies", n);
    run->body_count = n;
    run->gravity = sc->gravity;
    ak_rigid_initial_state(run->model, (ak_vec3_span){run->positions, n}, (ak_quat_span){run->orientations, n},
                           (ak_vec3_span){run->velocities, n}, (ak_vec3_span){run->angular_velocities, n});
    run->job = (ak_rigid_step_job){.model = run->model,
                                   .dt = sc->dt,
                                   .substeps = sc->substeps,
                                   .gravity = sc->gravity,
                                   .thread_count = sc->thread_count,
                                   .positions = {run->positions, n},
                                   .orientations = {run->orientations, n},
                                   .velocities = {run->velocities, n},
                                   .angular_velocities = {run->angular_velocities, n},
                                   .contact_anchors = {run->anchors, 4 * n + 4},
                                   .contact_anchor_count = &run->anchor_count,
                                   .out_max_penetration = &run->max_penetration,
                                   .out_dropped_contacts = &run->dropped_last};
    if (sc->sleep) run->job.sleep_timers = (ak_f32_span){run->sleep_timers, n};
    const size_t bytes = ak_rigid_step_scratch_size(&run->job);
    run->job.scratch = (ak_u8_span){malloc(bytes ? bytes : 1), bytes};
    if (!run->job.scratch.ptr)
        return akp_diag_set(out_diag, AK_ERR_NO_MEMORY, file, "out of memory for the step's %zu bytes", bytes);
    r = ak_rigid_step_validate(&run->job);
    if (r != AK_OK) return akp_diag_set(out_diag, r, file, "the step cannot run: %s", ak_result_string(r));
    if (out_diag) memset(out_diag, 0, sizeof *out_diag);
    return AK_OK;
}

ak_result ak_rigid_scene_run_step(ak_rigid_scene_run* run) {
    if (!run || !run->model) return AK_ERR_NULL_ARG;
    /* the job points at max_penetration inside *run: re-aim it in case the struct was copied */
    run->job.out_max_penetration = &run->max_penetration;
    run->job.out_dropped_contacts = &run->dropped_last;
    run->job.contact_anchor_count = &run->anchor_count;
    const ak_result r = ak_rigid_step_run(&run->job);
    if (r != AK_OK) return r;
    ++run->step_index;
    run->dropped_contacts += run->dropped_last;
    if (run->dropped_last && !run->dropped_first_step) run->dropped_first_step = run->step_index;
    run->time = (double)run->step_index * (double)run->job.dt;
    return AK_OK;
}

double ak_rigid_scene_run_energy(const ak_rigid_scene_run* run) {
    if (!run || !run->model) return 0.0;
    const size_t n = run->body_count;
    return ak_rigid_energy(run->model, run->gravity, (ak_vec3_cspan){run->positions, n},
                           (ak_quat_cspan){run->orientations, n}, (ak_vec3_cspan){run->velocities, n},
                           (ak_vec3_cspan){run->angular_velocities, n});
}

void ak_rigid_scene_run_free(ak_rigid_scene_run* run) {
    if (!run) return;
    ak_rigid_model_destroy(run->model);
    free(run->positions);
    free(run->orientations);
    free(run->velocities);
    free(run->angular_velocities);
    free(run->sleep_timers);
    free(run->anchors);
    free(run->job.scratch.ptr);
    memset(run, 0, sizeof *run);
}

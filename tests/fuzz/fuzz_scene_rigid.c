/* libFuzzer harness for the rigid-body scene reader (ak_rigid_scene_load_bytes, src/rigid/scene.c)
 * and the rigid module behind it; built and run by scripts/fuzz.sh.
 *
 * Each input is parsed as a scene file. A parsed scene must hold its documented invariants
 * (at least one body, positive step, joints between two different bodies of the scene); when it
 * has few bodies it is built and
 * stepped three times, and the state must stay finite or the step must say it blew up (and
 * then leave the state as it was). Any crash, leak or sanitizer report is a bug. */
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include <animkit/rigid.h>

int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    ak_rigid_scene s;
    ak_diag diag;
    ak_rigid_scene_defaults(&s);
    if (ak_rigid_scene_load_bytes(data, size, "fuzz.json", &s, &diag) != AK_OK) {
        /* a failure always says why, in one line that names the file, and leaves no bodies */
        if (strncmp(diag.message, "fuzz.json", 9) != 0 || strchr(diag.message, '\n') ||
            s.bodies || s.joints || s.body_count || s.joint_count || s.points || s.point_count)
            abort();
        ak_rigid_scene_free(&s);
        return 0;
    }
    if (s.body_count == 0 || !(s.dt > 0.0f) || s.substeps == 0) abort();
    for (size_t k = 0; k < s.joint_count; ++k)
        if (s.joints[k].body_a >= s.body_count || s.joints[k].body_b >= s.body_count ||
            s.joints[k].body_a == s.joints[k].body_b)
            abort();
    ak_rigid_model_desc md = s.model;
    md.bodies = (ak_rigid_body_desc_cspan){s.bodies, s.body_count};
    md.joints = (ak_rigid_joint_desc_cspan){s.joints, s.joint_count};
    ak_rigid_model* m = NULL;
    if (s.body_count <= 64 && ak_rigid_model_create(&md, NULL, &m) == AK_OK) {
        size_t n = s.body_count;
        ak_vec3 x[64], v[64], w[64], x0[64];
        ak_quat q[64];
        float timers[64] = {0};
        ak_rigid_initial_state(m, (ak_vec3_span){x, n}, (ak_quat_span){q, n}, (ak_vec3_span){v, n},
                               (ak_vec3_span){w, n});
        ak_rigid_step_job job = {.model = m,
                                 .dt = s.dt,
                                 .substeps = s.substeps > 10 ? 10 : s.substeps,
                                 .gravity = s.gravity,
                                 .positions = {x, n},
                                 .orientations = {q, n},
                                 .velocities = {v, n},
                                 .angular_velocities = {w, n},
                                 .sleep_timers = {timers, s.sleep ? n : 0}};
        size_t bytes = ak_rigid_step_scratch_size(&job);
        job.scratch = (ak_u8_span){malloc(bytes), bytes};
        for (int k = 0; k < 3; ++k) {
            memcpy(x0, x, n * sizeof *x);
            ak_result r = ak_rigid_step_run(&job);
            if (r == AK_ERR_BAD_DATA) {
                if (memcmp(x0, x, n * sizeof *x) != 0) abort(); /* a blow-up leaves the state */
                break;
            }
            if (r != AK_OK) abort();
            for (size_t i = 0; i < n; ++i)
                if (!ak_vec3_is_finite(x[i]) || !ak_quat_is_finite(q[i])) abort();
        }
        free(job.scratch.ptr);
    }
    ak_rigid_model_destroy(m);
    ak_rigid_scene_free(&s);
    return 0;
}

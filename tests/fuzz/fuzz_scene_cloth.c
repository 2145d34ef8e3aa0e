/* libFuzzer harness for the cloth scene reader (ak_cloth_scene_load_bytes, src/cloth/scene.c) and
 * the cloth module behind it (built by scripts/fuzz.sh with the library).
 *
 * Each input is parsed as a scene file. A parsed scene must hold its documented invariants
 * (pins inside the grid, positive step); when its grid is small it is built into a cloth and
 * stepped twice with its colliders and wind (attachments get their rest positions as targets,
 * no character is loaded), and the state must stay finite or the step must say it blew up.
 * Any crash, leak or sanitizer report is a bug. */
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include <animkit/cloth.h>

int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    ak_cloth_scene s;
    ak_diag diag;
    if (ak_cloth_scene_load_bytes(data, size, "fuzz.json", &s, &diag) != AK_OK) {
        if (strncmp(diag.message, "fuzz.json", 9) != 0 || strchr(diag.message, '\n')) abort(); /* says why */
        return 0;
    }
    const size_t n = (size_t)s.desc.grid_width * s.desc.grid_height;
    for (size_t k = 0; k < s.pin_count; ++k)
        if (s.pins[k] >= n) abort();
    if (!(s.dt > 0.0f)) abort();
    uint32_t* att = calloc(s.attach_count + 1, sizeof(uint32_t));
    for (size_t k = 0; k < s.attach_count; ++k) att[k] = s.attach[k].vertex;
    s.desc.attachments = (ak_u32_cspan){att, s.attach_count};
    ak_cloth* cloth = NULL;
    if (n <= 4096 && ak_cloth_create(&s.desc, NULL, &cloth) == AK_OK) {
        ak_vec3* x = malloc(n * sizeof(ak_vec3));
        ak_vec3* v = calloc(n, sizeof(ak_vec3));
        ak_vec3* t = calloc(s.attach_count + 1, sizeof(ak_vec3));
        ak_cloth_rest_positions(cloth, (ak_vec3_span){x, n});
        for (size_t k = 0; k < s.attach_count; ++k) t[k] = x[att[k]];
        ak_cloth_step_job job = {
            .cloth = cloth, .dt = s.dt, .substeps = s.substeps > 20 ? 20 : s.substeps, .iterations = 1,
            .gravity = s.gravity, .wind = s.wind, .drag = s.drag, .lift = s.lift, .air_density = s.air_density,
            .damping = s.damping, .planes = s.planes, .plane_count = s.plane_count, .spheres = s.spheres,
            .sphere_count = s.sphere_count, .capsules = s.capsules, .capsule_count = s.capsule_count,
            .thickness = s.thickness, .friction = s.friction, .self_collision = s.self_collision,
            .self_distance = s.self_distance, .attachment_targets = {t, s.attach_count}, .thread_count = 2,
            .positions = {x, n}, .velocities = {v, n},
        };
        size_t bytes = ak_cloth_step_scratch_size(&job);
        job.scratch = (ak_u8_span){malloc(bytes), bytes};
        for (int k = 0; k < 2; ++k) {
            ak_result r = ak_cloth_step_run(&job);
            if (r == AK_ERR_NO_CONVERGENCE) break;
            if (r != AK_OK) break; /* a rule the parser lets through but the step rejects */
            for (size_t i = 0; i < n; ++i)
                if (!ak_vec3_is_finite(x[i])) abort();
        }
        free(job.scratch.ptr);
        free(x), free(v), free(t);
    }
    ak_cloth_destroy(cloth);
    free(att);
    ak_cloth_scene_free(&s);
    return 0;
}

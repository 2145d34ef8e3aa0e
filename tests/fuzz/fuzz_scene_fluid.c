/* libFuzzer target for fluid scene files: ak_ak_fluid_scene_load_bytes (src/fluid/scene.c) on
 * the input as JSON text, then, for a scene that parses and stays small (at most 300
 * particles of capacity), three steps of the solver it names, so every parsed value reaches
 * the library's validation and step. scripts/fuzz.sh builds it with the whole library:
 *     scripts/fuzz.sh 60 scene_fluid   (seeds: tests/fuzz/scene_fluid.seeds, scene_fluid.dict)
 * Any crash, leak or sanitizer report is a bug; a rejected scene is fine. */
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include <animkit/fluid.h>

int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    if (size > 1u << 16) return 0;
    ak_fluid_scene* s = malloc(sizeof *s);
    if (!s) return 0;
    ak_diag diag;
    if (ak_fluid_scene_load_bytes(data, size, "fuzz.json", s, &diag) == AK_OK) {
        const size_t cap = ak_fluid_scene_capacity(s);
        const size_t bytes = ak_fluid_scratch_size(cap, &s->desc);
        if (cap <= 300 && bytes > 0 && bytes < ((size_t)64 << 20)) {
            ak_vec3* pos = calloc(cap ? cap : 1, sizeof *pos);
            ak_vec3* vel = calloc(cap ? cap : 1, sizeof *vel);
            void* scratch = malloc(bytes);
            if (pos && vel && scratch) {
                size_t n = ak_fluid_scene_fill(s, pos, vel, cap);
                ak_fluid_step_job job = {.desc = &s->desc, .dt = s->dt, .positions = {pos, cap},
                                         .velocities = {vel, cap}, .particle_count = &n,
                                         .colliders = {s->colliders, s->collider_count},
                                         .emitters = {s->emitters, s->emitter_count},
                                         .sinks = {s->sinks, s->sink_count}, .scratch = {scratch, bytes}};
                for (int k = 0; k < 3; ++k) {
                    job.time = (float)k * s->dt;
                    if (ak_fluid_step_run(&job) != AK_OK) break;
                }
            }
            free(pos), free(vel), free(scratch);
        }
    }
    else if (strncmp(diag.message, "fuzz.json", 9) != 0 || strchr(diag.message, '\n'))
        abort();
    free(s);
    return 0;
}

/* libFuzzer target for fluid scene files: fluid_scene_parse (tools/animkit/scene_fluid.c) on
 * the input as JSON text, then, for a scene that parses and stays small (at most 300
 * particles of capacity), three steps of the solver it names, so every parsed value reaches
 * the library's validation and step. scripts/fuzz.sh builds it with the whole library and
 * the CLI's sources except main.c:
 *     scripts/fuzz.sh 60 scene_fluid   (seeds: tests/fuzz/scene_fluid.seeds, scene_fluid.dict)
 * Any crash, leak or sanitizer report is a bug; a rejected scene is fine. */
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "scene_fluid.h"

int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    if (size > 1u << 16) return 0;
    fluid_scene* s = malloc(sizeof *s);
    if (!s) return 0;
    cli_json j = {.file = "fuzz.json"};
    if (fluid_scene_parse(&j, (const char*)data, size, s)) {
        const size_t cap = fluid_scene_capacity(s);
        const size_t bytes = ak_fluid_scratch_size(cap, &s->desc);
        if (cap <= 300 && bytes > 0 && bytes < ((size_t)64 << 20)) {
            ak_vec3* pos = calloc(cap ? cap : 1, sizeof *pos);
            ak_vec3* vel = calloc(cap ? cap : 1, sizeof *vel);
            void* scratch = malloc(bytes);
            if (pos && vel && scratch) {
                size_t n = fluid_scene_fill(s, pos, vel, cap);
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
    free(s);
    return 0;
}

/* libFuzzer harness for particle scene files (ak_particles_scene_load_bytes, src/particles/scene.c).
 *
 * scripts/fuzz.sh builds it with the library, then runs e.g.
 *     ./fuzz_scene_particles -dict=tests/fuzz/scene_particles.dict examples/particles_fountain.json
 *
 * Each input is parsed from memory; an accepted scene (capacity cut to 2000) is stepped three
 * times by the command's runner, now the library's (ak_particles_scene_run_step: emitters, the
 * burst schedule, springs re-indexed as particles die), so the fuzzer reaches the per-step loops whose counts come from
 * the file (a 1e-30 s burst_interval once hung there). Every particle left must be finite. A
 * rejected scene must come with a one-line message. Any crash, hang, leak or sanitizer report
 * is a bug. */
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include <animkit/particles.h>

int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    ak_particles_scene s;
    ak_diag diag;
    if (ak_particles_scene_load_bytes(data, size, "fuzz.json", &s, &diag) != AK_OK) {
        if (strncmp(diag.message, "fuzz.json", 9) != 0 || strchr(diag.message, '\n')) abort();
        return 0;
    }
    if (s.capacity > 2000) s.capacity = s.particle_count > 2000 ? (uint32_t)s.particle_count : 2000;
    ak_particles_scene_run run;
    if (ak_particles_scene_run_init(&run, &s, &(ak_particles_scene_run_desc){.seed = 1, .thread_count = 1}, NULL) ==
        AK_OK) {
        for (int step = 0; step < 3; ++step)
            if (ak_particles_scene_run_step(&run, NULL) != AK_OK) break;
        ak_particles_state st = ak_particles_get_state(run.system);
        for (size_t i = 0; i < st.count; ++i)
            if (!ak_finitef(st.position[i].x) || !ak_finitef(st.position[i].y) ||
                !ak_finitef(st.position[i].z) || !ak_finitef(st.velocity[i].x) ||
                !ak_finitef(st.velocity[i].y) || !ak_finitef(st.velocity[i].z))
                abort();
    }
    ak_particles_scene_run_free(&run);
    ak_particles_scene_free(&s);
    return 0;
}

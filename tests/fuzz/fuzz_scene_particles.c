/* libFuzzer harness for particle scene files (tools/animkit/scene_particles.c).
 *
 * scripts/fuzz.sh builds it with the library and the CLI sources except main.c. By hand:
 *     clang -g -O1 -fsanitize=fuzzer,address,undefined -std=c11 -D_POSIX_C_SOURCE=200809L \
 *         -Iinclude -Isrc -Itools/animkit tests/fuzz/fuzz_scene_particles.c \
 *         tools/animkit/scene_particles.c tools/animkit/cli_json.c src/core.c src/math.c \
 *         src/math/[a-z]*.c src/grid.c src/particles.c -lcjson -lm -lpthread -o
 * fuzz_scene_particles
 *     ./fuzz_scene_particles -dict=tests/fuzz/scene_particles.dict examples/particles_fountain.json
 *
 * Each input is parsed from memory; an accepted scene (capacity cut to 2000) is stepped three
 * times with every emitter firing, and every particle left must be finite. A rejected one must
 * come with a one-line message. Any crash, leak or sanitizer report is a bug. */
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "scene_particles.h"

int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    particles_scene s;
    char err[600];
    if (!particles_scene_parse("fuzz.json", (const char*)data, size, &s, err, sizeof err)) {
        if (err[0] == '\0' || strchr(err, '\n')) abort();
        return 0;
    }
    ak_particles_desc d = {
        .capacity = s.capacity < 2000 ? s.capacity : 2000, .integrator = s.integrator, .seed = 1};
    ak_particles* ps = NULL;
    if (ak_particles_create(&d, NULL, &ps) == AK_OK) {
        for (size_t i = 0; i < s.particle_count; ++i) ak_particles_add(ps, &s.particles[i], NULL);
        for (int step = 0; step < 3; ++step) {
            for (size_t e = 0; e < s.emitter_count; ++e) {
                ak_particles_emit(ps, &s.emitters[e], s.dt, NULL);
                ak_particles_burst(ps, &s.emitters[e],
                                   s.bursts[e].count < 500 ? s.bursts[e].count : 500, NULL);
            }
            ak_particles_step(ps, &s.world, s.dt);
        }
        ak_particles_state st = ak_particles_get_state(ps);
        for (size_t i = 0; i < st.count; ++i)
            if (!ak_finitef(st.position[i].x) || !ak_finitef(st.position[i].y) ||
                !ak_finitef(st.position[i].z) || !ak_finitef(st.velocity[i].x) ||
                !ak_finitef(st.velocity[i].y) || !ak_finitef(st.velocity[i].z))
                abort();
    }
    ak_particles_destroy(ps);
    particles_scene_free(&s);
    return 0;
}

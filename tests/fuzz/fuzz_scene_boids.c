/* libFuzzer target for the boids scene reader (ak_boids_scene_load_bytes, src/boids/scene.c);
 * built and run by scripts/fuzz.sh.
 *
 * Each input is parsed from memory. A parse error must come with a message naming the file.
 * A parsed scene with at most 256 agents (or, without agents, up to 64 placed at random) is
 * validated and stepped twice on the grid path and once on the naive path: both must give the
 * same finite positions and velocities, and no agent may end inside an obstacle. */
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include <animkit/boids.h>

int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size);

static void run(const ak_boids_scene* sc) {
    size_t n = sc->agent_count ? sc->agent_count : (sc->count < 64 ? sc->count : 64);
    if (n == 0 || n > 256) return;
    ak_vec3* buf = calloc(7 * n, sizeof(ak_vec3));
    uint8_t* sp = calloc(n, 1);
    if (!buf || !sp) abort();
    ak_vec3 *p = buf, *v = buf + n, *w = buf + 2 * n, *pa = buf + 3 * n, *va = buf + 4 * n, *pb = buf + 5 * n,
            *vb = buf + 6 * n;
    ak_rng r = ak_rng_make(1);
    for (size_t i = 0; i < n; ++i) {
        if (sc->agent_count) {
            p[i] = sc->positions[i];
            v[i] = sc->velocities[i];
            sp[i] = sc->agent_species[i];
        } else {
            p[i] = ak_vec3_make(ak_rng_range(&r, -5, 5), ak_rng_range(&r, -5, 5), ak_rng_range(&r, -5, 5));
            v[i] = ak_vec3_make(ak_rng_range(&r, -1, 1), 0, ak_rng_range(&r, -1, 1));
        }
    }
    ak_boids_params prm = sc->params;
    if (prm.has_leader && prm.leader_index >= n) prm.has_leader = false;
    ak_boids_step_job job = {.params = &prm, .positions = {p, n}, .velocities = {v, n}, .species = {sp, n},
                             .wander = {w, n}, .dt = sc->dt, .out_positions = {pa, n}, .out_velocities = {va, n},
                             .thread_count = 2};
    const size_t bytes = ak_boids_step_scratch_size(&job);
    uint8_t* scratch = malloc(bytes ? bytes : 1);
    if (!scratch) abort();
    job.scratch = (ak_u8_span){scratch, bytes};
    if (ak_boids_step_run(&job) == AK_OK) {
        memset(w, 0, n * sizeof(ak_vec3)); /* the same wander draw for the naive run */
        ak_boids_step_job naive = job;
        naive.use_naive = true;
        naive.out_positions.ptr = pb;
        naive.out_velocities.ptr = vb;
        if (ak_boids_step_run(&naive) != AK_OK) abort();
        if (memcmp(pa, pb, n * sizeof(ak_vec3)) != 0 || memcmp(va, vb, n * sizeof(ak_vec3)) != 0) abort();
        for (size_t i = 0; i < n; ++i)
            if (!ak_vec3_is_finite(pa[i]) || !ak_vec3_is_finite(va[i])) abort();
    }
    free(scratch);
    free(sp);
    free(buf);
}

int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    ak_boids_scene sc;
    ak_boids_scene_defaults(&sc);
    ak_diag diag;
    if (ak_boids_scene_load_bytes(data, size, "fuzz.json", &sc, &diag) == AK_OK) run(&sc);
    else if (strncmp(diag.message, "fuzz.json", 9) != 0 || strchr(diag.message, '\n')) abort();
    ak_boids_scene_free(&sc);
    return 0;
}

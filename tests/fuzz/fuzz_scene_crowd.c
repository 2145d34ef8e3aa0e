/* libFuzzer target for the crowd scene reader (ak_crowd_scene_load_bytes, src/crowd/scene.c);
 * built and run by scripts/fuzz.sh.
 *
 * Each input is parsed from memory. A parse error must come with a message naming the file; a
 * loaded scene must hold agents.
 * A parsed scene with at most 256 agents and 256 obstacle vertices is built into a crowd (ORCA
 * or vision, as the scene says) and stepped three times on 1 and on 2 threads (with contact
 * passes): both must give the same finite positions and velocities. */
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include <animkit/crowd.h>

int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size);

static void steps(const ak_crowd_scene* sc, ak_crowd* c, uint32_t threads, ak_vec2* p, ak_vec2* v) {
    const size_t n = sc->agent_count;
    ak_vec2* p2 = calloc(n, sizeof *p2);
    ak_vec2* v2 = calloc(n, sizeof *v2);
    uint32_t* wp = calloc(n, sizeof *wp);
    if (!p2 || !v2 || !wp) abort();
    memcpy(p, sc->positions, n * sizeof *p);
    memcpy(v, sc->velocities, n * sizeof *v);
    ak_crowd_step_job job = {.crowd = c, .dt = sc->dt, .thread_count = threads, .contact_iterations = 2};
    const size_t bytes = ak_crowd_step_scratch_size(&job);
    uint8_t* scratch = malloc(bytes ? bytes : 1);
    if (!scratch) abort();
    job.scratch = (ak_u8_span){scratch, bytes};
    for (int s = 0; s < 3; ++s) {
        job.positions = (ak_vec2_cspan){p, n};
        job.velocities = (ak_vec2_cspan){v, n};
        job.waypoints = (ak_u32_span){wp, n};
        job.out_positions = (ak_vec2_span){p2, n};
        job.out_velocities = (ak_vec2_span){v2, n};
        job.step_index = (uint64_t)s;
        const ak_result r = ak_crowd_step_run(&job);
        if (r != AK_OK && r != AK_ERR_BUDGET && r != AK_ERR_BAD_DATA) abort();
        if (r != AK_OK) break;
        for (size_t i = 0; i < n; ++i)
            if (!ak_finitef(p2[i].x) || !ak_finitef(p2[i].y) || !ak_finitef(v2[i].x) || !ak_finitef(v2[i].y)) abort();
        memcpy(p, p2, n * sizeof *p);
        memcpy(v, v2, n * sizeof *v);
    }
    free(scratch);
    free(p2);
    free(v2);
    free(wp);
}

int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    ak_crowd_scene sc;
    ak_crowd_scene_defaults(&sc);
    ak_diag diag;
    if (ak_crowd_scene_load_bytes(data, size, "fuzz.json", &sc, &diag) == AK_OK) {
        if (sc.agent_count == 0) abort(); /* a loaded scene has agents */
        if (sc.agent_count > 0 && sc.agent_count <= 256 && sc.vertex_count <= 256) {
            ak_crowd_desc d = {.agents = {sc.agents, sc.agent_count}, .obstacles = sc.obstacles,
                               .obstacle_count = (uint32_t)sc.obstacle_count,
                               .method = sc.method};
            ak_crowd* c = NULL;
            if (ak_crowd_create(&d, NULL, &c) == AK_OK) {
                const size_t n = sc.agent_count;
                ak_vec2* buf = calloc(4 * n, sizeof *buf);
                if (!buf) abort();
                steps(&sc, c, 1, buf, buf + n);
                steps(&sc, c, 2, buf + 2 * n, buf + 3 * n);
                if (memcmp(buf, buf + 2 * n, 2 * n * sizeof *buf) != 0) abort();
                free(buf);
                ak_crowd_destroy(c);
            }
        }
    } else if (strncmp(diag.message, "fuzz.json: ", 11) != 0 || strcmp(diag.path, "fuzz.json") != 0) {
        abort();
    }
    ak_crowd_scene_free(&sc);
    return 0;
}

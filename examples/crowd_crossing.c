/* crowd: four people cross a square from its four sides with ORCA; prints where each one
 * is every two seconds and the closest two ever came (centre distance minus radii).
 * Shows: ak_crowd_create, the step job with its scratch, ak_crowd_goal_reached. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <animkit/crowd.h>

int main(void) {
    enum { N = 4 };
    const ak_vec2 start[N] = {{-6, 0}, {6, 0}, {0, -6}, {0, 6}};
    ak_vec2 goal[N];
    ak_crowd_agent agents[N];
    for (int i = 0; i < N; ++i) {
        goal[i] = (ak_vec2){-start[i].x, -start[i].y};
        agents[i] = (ak_crowd_agent){.radius = 0.3f, .pref_speed = 1.3f, .goals = {&goal[i], 1}};
    }
    ak_crowd* crowd = NULL;
    if (ak_crowd_create(&(ak_crowd_desc){.agents = {agents, N}}, NULL, &crowd) != AK_OK) return 1;

    ak_vec2 p[N], v[N] = {{0, 0}}, p2[N], v2[N];
    uint32_t wp[N] = {0};
    memcpy(p, start, sizeof p);
    ak_crowd_step_job job = {.crowd = crowd, .dt = 0.1f, .positions = {p, N}, .velocities = {v, N},
                             .waypoints = {wp, N}, .out_positions = {p2, N}, .out_velocities = {v2, N}};
    const size_t bytes = ak_crowd_step_scratch_size(&job);
    job.scratch = (ak_u8_span){malloc(bytes), bytes};
    if (!job.scratch.ptr) return 1;

    float closest = INFINITY;
    int arrived = 0, step = 0;
    for (; step < 300 && arrived < N; ++step) {
        job.step_index = (uint64_t)step;
        if (ak_crowd_step_run(&job) != AK_OK) return 1;
        memcpy(p, p2, sizeof p);
        memcpy(v, v2, sizeof v);
        for (int i = 0; i < N; ++i)
            for (int j = i + 1; j < N; ++j)
                closest = fminf(closest, hypotf(p[i].x - p[j].x, p[i].y - p[j].y) - 0.6f);
        arrived = 0;
        for (int i = 0; i < N; ++i) arrived += ak_crowd_goal_reached(crowd, (size_t)i, p[i], wp[i]);
        if (step % 20 == 19) {
            printf("t = %4.1f s:", 0.1 * (step + 1));
            for (int i = 0; i < N; ++i) printf("  (%5.2f, %5.2f)", p[i].x, p[i].y);
            printf("\n");
        }
    }
    printf("%d of %d at their goal after %.1f s; closest approach %.4f m\n", arrived, N, 0.1 * step, closest);
    free(job.scratch.ptr);
    ak_crowd_destroy(crowd);
    return arrived == N ? 0 : 1;
}

/* crowd: two people walk head-on past each other (ORCA), each a builtin:humanoid whose walk
 * cycle follows the distance it walks; prints the gait measured from the clip and each one's
 * clip time and heading every second, and writes the run as crowd_characters.glb.
 * Shows: ak_crowd_gait_measure, ak_crowd_character_init, ak_crowd_characters_update,
 * ak_crowd_bake_scene and io.h's ak_io_save. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <animkit/animkit.h>

int main(void) {
    enum { N = 2, STEPS = 80 };
    const float dt = 0.1f;
    ak_scene* humanoid = NULL;
    ak_builtin_desc bd = {.cell_size = 0.1f}; /* a coarse mesh: about 1,200 triangles */
    if (ak_builtin_create("builtin:humanoid", &bd, NULL, &humanoid) != AK_OK) return 1;
    ak_crowd_gait gait;
    ak_diag diag;
    ak_crowd_gait_desc gd = {.scene = humanoid, .clip_index = ak_scene_find_clip(humanoid, "walk")};
    if (ak_crowd_gait_measure(&gd, NULL, &gait, &diag) != AK_OK) {
        fprintf(stderr, "%s\n", diag.message);
        return 1;
    }
    printf("walk: stride %.3f m per %.2f s cycle (%.3f m/s at rate 1), forward (%.2f, %.2f)\n",
           (double)gait.stride_length, (double)gait.duration, (double)gait.stride_speed, (double)gait.forward.x,
           (double)gait.forward.z);

    const ak_vec2 start[N] = {{-5, 0}, {5, 0}};
    ak_vec2 goal[N] = {{5, 0}, {-5, 0}};
    ak_crowd_agent agents[N] = {{.goals = {&goal[0], 1}}, {.goals = {&goal[1], 1}}};
    ak_crowd* crowd = NULL;
    if (ak_crowd_create(&(ak_crowd_desc){.agents = {agents, N}}, NULL, &crowd) != AK_OK) return 1;
    ak_vec2 p[N], v[N] = {{0, 0}}, p2[N], v2[N];
    uint32_t wp[N] = {0};
    memcpy(p, start, sizeof p);
    ak_crowd_step_job job = {.crowd = crowd, .dt = dt, .positions = {p, N}, .velocities = {v, N},
                             .waypoints = {wp, N}, .out_positions = {p2, N}, .out_velocities = {v2, N}};
    const size_t bytes = ak_crowd_step_scratch_size(&job);
    job.scratch = (ak_u8_span){malloc(bytes), bytes};

    ak_crowd_character ch[N];
    for (int i = 0; i < N; ++i) ch[i] = ak_crowd_character_init(&gait, ak_vec2_sub(goal[i], start[i]), 0.5f * (float)i);
    /* every step recorded for the glTF file */
    static ak_vec2 rec_p[(STEPS + 1) * N];
    static ak_crowd_character rec_c[(STEPS + 1) * N];
    memcpy(rec_p, p, sizeof p);
    memcpy(rec_c, ch, sizeof ch);
    for (int s = 0; s < STEPS && job.scratch.ptr; ++s) {
        job.step_index = (uint64_t)s;
        if (ak_crowd_step_run(&job) != AK_OK) return 1;
        memcpy(p, p2, sizeof p);
        memcpy(v, v2, sizeof v);
        ak_crowd_characters_job cj = {.gait = &gait, .dt = dt, .velocities = {v, N}, .characters = {ch, N}};
        if (ak_crowd_characters_update(&cj) != AK_OK) return 1;
        memcpy(rec_p + (size_t)(s + 1) * N, p, sizeof p);
        memcpy(rec_c + (size_t)(s + 1) * N, ch, sizeof ch);
        if ((s + 1) % 10 == 0)
            for (int i = 0; i < N; ++i)
                printf("t %.1f s  agent %d at (%5.2f, %5.2f) speed %.2f m/s: clip time %.3f s, heading (%.2f, %.2f), "
                       "walking %.2f\n",
                       (double)((float)(s + 1) * dt), i, (double)p[i].x, (double)p[i].y,
                       (double)ak_vec2_length(v[i]), (double)ch[i].clip_time, (double)ch[i].heading.x,
                       (double)ch[i].heading.y, (double)ch[i].walk_weight);
    }
    ak_crowd_bake_desc bake = {.gait = &gait, .agent_count = N, .frame_count = STEPS + 1, .positions = rec_p,
                               .characters = rec_c, .frame_time = dt};
    ak_scene* out = NULL;
    int rc = 0;
    if (ak_crowd_bake_scene(&bake, NULL, &out, &diag) != AK_OK || ak_io_save("crowd_characters.glb", out, NULL, &diag) != AK_OK) {
        fprintf(stderr, "%s\n", diag.message);
        rc = 1;
    } else {
        printf("wrote crowd_characters.glb: %d skinned characters, %d frames\n", N, STEPS + 1);
    }
    ak_scene_destroy(out);
    free(job.scratch.ptr);
    ak_crowd_destroy(crowd);
    ak_scene_destroy(humanoid);
    return rc;
}

/* rigid_bounce_and_stack: a sphere dropped from 1 m with restitution 0.6 bounces to e^2 h,
 * e^4 h, ... (printed beside the closed form), then a stack of five boxes settles and sleeps
 * (printed: how far the top box moved, and the deepest contact). */
#include <stdio.h>
#include <stdlib.h>

#include <animkit/rigid.h>

/* The initial state into x, q, v, w and a step job over it (timers NULL: no sleeping). */
static ak_rigid_step_job make_job(const ak_rigid_model* m, ak_vec3* x, ak_quat* q, ak_vec3* v,
                                  ak_vec3* w, float* timers, size_t n) {
    ak_rigid_initial_state(m, (ak_vec3_span){x, n}, (ak_quat_span){q, n}, (ak_vec3_span){v, n},
                           (ak_vec3_span){w, n});
    ak_rigid_step_job job = {.model = m,
                             .dt = 1.0f / 60.0f,
                             .substeps = 20,
                             .gravity = {0, -9.81f, 0},
                             .positions = {x, n},
                             .orientations = {q, n},
                             .velocities = {v, n},
                             .angular_velocities = {w, n},
                             .sleep_timers = {timers, timers ? n : 0}};
    size_t size = ak_rigid_step_scratch_size(&job);
    job.scratch = (ak_u8_span){malloc(size), size};
    return job;
}

int main(void) {
    /* 1. the bounce */
    ak_rigid_body_desc ball[2] = {
        {.shape = {.type = AK_RIGID_PLANE}},
        {.shape = {.type = AK_RIGID_SPHERE, .radius = 0.1f},
         .position = {0, 1.1f, 0},
         .restitution = 0.6f},
    };
    ak_rigid_model* m = NULL;
    if (ak_rigid_model_create(&(ak_rigid_model_desc){.bodies = {ball, 2}}, NULL, &m) != AK_OK)
        return 1;
    ak_vec3 x[8], v[8], w[8];
    ak_quat q[8];
    float timers[8] = {0};
    ak_rigid_step_job job = make_job(m, x, q, v, w, NULL, 2);
    if (!job.scratch.ptr) return 1;
    float peak = 0.0f, expect = 1.0f;
    int bounces = 0;
    for (int f = 0; f < 600 && bounces < 3; ++f) {
        float vy = v[1].y;
        ak_rigid_step_run(&job);
        if (v[1].y > 0.0f) peak = x[1].y - 0.1f > peak ? x[1].y - 0.1f : peak;
        if (vy > 0.0f && v[1].y <= 0.0f) { /* the top of a bounce */
            expect *= 0.36f;
            ++bounces;
            printf("bounce %d: height %.4f m (e^%d h = %.4f m)\n", bounces, (double)peak,
                   2 * bounces, (double)expect);
            peak = 0.0f;
        }
    }
    free(job.scratch.ptr);
    ak_rigid_model_destroy(m);

    /* 2. the stack */
    ak_rigid_body_desc boxes[6] = {{.shape = {.type = AK_RIGID_PLANE}}};
    for (int i = 1; i < 6; ++i)
        boxes[i] = (ak_rigid_body_desc){
            .shape = {.type = AK_RIGID_BOX, .half_extents = {0.5f, 0.25f, 0.5f}},
            .position = {0, 0.25f + 0.5f * (float)(i - 1), 0}};
    if (ak_rigid_model_create(&(ak_rigid_model_desc){.bodies = {boxes, 6}}, NULL, &m) != AK_OK)
        return 1;
    job = make_job(m, x, q, v, w, timers, 6);
    if (!job.scratch.ptr) return 1;
    float pen = 0.0f, worst = 0.0f;
    job.out_max_penetration = &pen;
    for (int f = 0; f < 180; ++f) {
        ak_rigid_step_run(&job);
        worst = pen > worst ? pen : worst;
    }
    ak_vec3 top = x[5];
    printf("stack of 5 after 3 s: top box moved %.2e m, deepest contact %.2e m, asleep: %s\n",
           (double)ak_vec3_distance(top, boxes[5].position), (double)worst,
           timers[5] >= 0.5f ? "yes" : "no");
    free(job.scratch.ptr);
    ak_rigid_model_destroy(m);
    return 0;
}

/* deform_bouncing_ball: the squash-and-stretch bouncing ball, plus the automatic squash tracker
 * fed with the same ball's centre. Prints per frame the centre, stretch, contact flag, the
 * tracker's stretch, and the deformed ball's volume ratio (always 1: det of the squash = 1). */
#include <stdio.h>

#include <animkit/deform.h>

int main(void) {
    ak_bounce_desc ball = {.height = 1.0f, .radius = 0.25f, .forward_speed = 0.8f};
    const float period = ak_bounce_period(&ball), fps = 30.0f;
    ak_squash_tracker tracker = {0};
    ak_squash_tracker_desc td = {.speed_gain = 0.05f, .accel_gain = 0.002f, .gravity = {0, -9.81f, 0},
                                 .accel_dead_zone = 12.0f, .response_time = 0.03f};
    printf("period %.3f s\n%6s %8s %8s %8s %8s %7s %9s %8s\n", period, "t", "x", "y", "axis.x", "stretch", "contact",
           "tracker", "vol");
    const int frames = (int)(2.0f * period * fps);
    for (int f = 0; f <= frames; ++f) {
        float t = (float)f / fps;
        ak_bounce_state s = ak_bounce_sample(&ball, t);
        ak_deformer auto_squash;
        if (ak_squash_tracker_update(&tracker, &td, s.center, 1.0f / fps, &auto_squash) != AK_OK) return 1;
        /* Volume ratio of the deformed unit sphere: det(model) / r^3. */
        float vol = ak_mat4_determinant(s.model) / (ball.radius * ball.radius * ball.radius);
        printf("%6.3f %8.4f %8.4f %8.4f %8.4f %7s %9.4f %8.5f\n", t, s.center.x, s.center.y, s.axis.x, s.stretch,
               s.in_contact ? "yes" : "no", auto_squash.amount, vol);
    }
    /* The same squash as a deformer over points (e.g. a prop mesh): points on the unit sphere. */
    ak_vec3 pts[3] = {{0, 1, 0}, {1, 0, 0}, {0, 0, 1}}, out[3];
    ak_deformer d = {.type = AK_DEFORMER_SQUASH, .axis = {0, 1, 0}, .amount = 0.5f};
    ak_deform_job job = {.deformers = &d, .deformer_count = 1, .positions = AK_SPAN(pts), .out_positions = AK_SPAN(out)};
    if (ak_deform_run(&job) != AK_OK) return 1;
    printf("squash 0.5 along Y: top (%.3f %.3f %.3f), side (%.3f %.3f %.3f)\n", out[0].x, out[0].y, out[0].z, out[1].x,
           out[1].y, out[1].z);
    return 0;
}

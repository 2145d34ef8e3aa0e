/* noise_fbm_gain: 1D fBm of Perlin noise for three gains, plotted to noise_fbm_gain.png, and
 * the roughness each gain gives (mean |slope|); then a sway layer and noise wind sampled over
 * time, the procedural-animation uses of the same noise. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include <animkit/animkit.h>

enum { W = 800, H = 420, SAMPLES = 800 };

int main(void) {
    const ak_noise n = ak_noise_make(0);
    printf("Perlin's reference point: noise(3.14, 42, 7) = %.9g (published 0.136919959)\n",
           (double)ak_noise_perlin3(&n, 3.14f, 42.0f, 7.0f, NULL));

    uint8_t* px = malloc((size_t)W * H * 4);
    if (!px) return 1;
    ak_image img = {.pixels = px, .width = W, .height = H};
    ak_image_fill(&img, ak_vec4_make(0.97f, 0.97f, 0.95f, 1));
    const float gains[3] = {0.3f, 0.5f, 0.7f};
    const ak_vec4 colors[3] = {{0.15f, 0.35f, 0.75f, 1}, {0.15f, 0.6f, 0.3f, 1}, {0.8f, 0.25f, 0.2f, 1}};
    printf("\n8-octave fBm, lacunarity 2: gain -> roughness\n");
    for (int c = 0; c < 3; ++c) {
        const ak_fractal_desc fd = {.type = AK_FRACTAL_FBM, .octaves = 8, .gain = gains[c]};
        float lo, hi;
        ak_fractal_range(&fd, 1, &lo, &hi);
        double slope = 0;
        ak_vec2 prev = {0, 0};
        for (int i = 0; i < SAMPLES; ++i) {
            const float x = 8.0f * (float)i / SAMPLES, p[1] = {x};
            float g[1];
            const float v = ak_fractal_eval(&n, &fd, 1, p, g) / hi; /* in [-1, 1] */
            slope += fabsf(g[0] / hi) / SAMPLES;
            const ak_vec2 q = ak_vec2_make((float)i * W / SAMPLES, (float)(c + 0.5f) * H / 3.0f - v * 110.0f);
            if (i) ak_image_draw_line(&img, prev, q, 2.0f, colors[c]);
            prev = q;
        }
        char label[64];
        snprintf(label, sizeof label, "gain %.1f", (double)gains[c]);
        ak_image_draw_text(&img, 10, (int)((float)c * H / 3.0f) + 8, label, 2, colors[c]);
        printf("  gain %.1f: mean |dh/dx| %.2f (of the normalised curve)\n", (double)gains[c], slope);
    }
    ak_result r = ak_png_write("noise_fbm_gain.png", &img);
    free(px);
    if (r != AK_OK) {
        fprintf(stderr, "noise_fbm_gain.png: %s\n", ak_result_string(r));
        return 1;
    }
    printf("wrote noise_fbm_gain.png\n");

    /* a three-joint chain swaying at idle */
    ak_transform pose[3], out[3];
    for (int j = 0; j < 3; ++j)
        pose[j] = (ak_transform){ak_vec3_make(0, 0.3f * (float)j, 0), ak_quat_identity(), ak_vec3_make(1, 1, 1)};
    const float amp[3] = {0.02f, 0.03f, 0.05f}, freq[3] = {0.3f, 0.4f, 0.6f};
    printf("\nsway: angle of the head joint's delta (degrees) over 2 s\n ");
    for (int f = 0; f <= 8; ++f) {
        ak_noise_sway_job job = {.noise = &n, .time = 0.25f * (float)f, .pose = {pose, 3}, .amplitudes = {amp, 3},
                                 .frequencies = {freq, 3}, .out_pose = {out, 3}};
        if (ak_noise_sway_run(&job) != AK_OK) return 1;
        printf(" %.2f", 2.0 * acos(fmin(1.0, fabs((double)out[2].rotation.w))) * 57.29578);
    }
    const ak_noise_wind_desc wind = {.direction = {1, 0, 0.3f}, .speed = 4, .gust = 0.5f, .turbulence = 1};
    printf("\nwind at (0, 1, 0): speed over 4 s\n ");
    for (int f = 0; f <= 8; ++f)
        printf(" %.2f", (double)ak_vec3_length(ak_noise_wind(&n, &wind, ak_vec3_make(0, 1, 0), 0.5f * (float)f)));
    printf("\n");
    return 0;
}

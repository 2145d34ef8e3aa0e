/* terrain_types: which parameters make which terrain. fBm, turbulence and ridged sums of the
 * same Perlin noise, each with two gains, rendered side by side to terrain_types.png, with
 * their relief and mean slope printed. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include <animkit/animkit.h>

enum { N = 97, PW = 320, PH = 240 };

int main(void) {
    const ak_noise noise = ak_noise_make(11);
    const ak_fractal_type types[3] = {AK_FRACTAL_FBM, AK_FRACTAL_TURBULENCE, AK_FRACTAL_RIDGED};
    const char* names[3] = {"fbm", "turbulence", "ridged"};
    const float gains[2] = {0.35f, 0.6f};
    static float h[N * N];
    static ak_vec3 nrm[N * N], pos[N * N];
    static ak_vec4 col[N * N];
    static uint32_t idx[(N - 1) * (N - 1) * 6];
    uint8_t* px = malloc((size_t)PW * 3 * PH * 2 * 4);
    uint8_t* panel = malloc((size_t)PW * PH * 4);
    ak_raster* r = NULL;
    if (!px || !panel || ak_raster_create(&(ak_raster_desc){.width = PW, .height = PH, .supersample = 2}, NULL, &r))
        return 1;
    ak_image sheet = {.pixels = px, .width = PW * 3, .height = PH * 2}, pimg = {.pixels = panel, .width = PW, .height = PH};
    printf("%-11s %5s %10s %12s\n", "type", "gain", "relief m", "mean slope");
    for (int g = 0; g < 2; ++g)
        for (int t = 0; t < 3; ++t) {
            const ak_terrain_desc d = {.noise = &noise, .width = N, .height = N, .world_size = 100, .height_scale = 18,
                                       .fractal = {.type = types[t], .octaves = 5, .gain = gains[g]}};
            if (ak_terrain_generate(&d, (ak_f32_span){h, N * N}, (ak_vec3_span){nrm, N * N}) != AK_OK) return 1;
            ak_terrain_mesh(&d, (ak_f32_cspan){h, N * N}, (ak_vec3_span){pos, N * N}, (ak_vec2_span){0},
                            (ak_u32_span){idx, sizeof idx / sizeof idx[0]});
            ak_terrain_colors(&d, (ak_f32_cspan){h, N * N}, (ak_vec3_cspan){nrm, N * N}, (ak_vec4_span){col, N * N});
            float lo = 1e9f, hi = -1e9f;
            double slope = 0;
            for (int i = 0; i < N * N; ++i) {
                lo = fminf(lo, h[i]), hi = fmaxf(hi, h[i]);
                slope += acos((double)nrm[i].y) * 57.29578 / (N * N);
            }
            printf("%-11s %5.2f %10.1f %10.1f deg\n", names[t], (double)gains[g], (double)(hi - lo), slope);
            const ak_raster_camera cam = ak_raster_camera_perspective(ak_vec3_make(95, 70, 95), ak_vec3_make(0, 0, 0),
                                                                      0.7f, (float)PW / PH, 1, 1000);
            ak_raster_clear(r, ak_vec4_make(0.6f, 0.74f, 0.9f, 1), ak_vec4_make(0.88f, 0.91f, 0.95f, 1));
            const ak_raster_mesh m = {.positions = {pos, N * N}, .normals = {nrm, N * N}, .colors = {col, N * N},
                                      .indices = {idx, sizeof idx / sizeof idx[0]},
                                      .material = {.color = {1, 1, 1, 1}, .specular = 0.05f}};
            if (ak_raster_draw_mesh(r, &cam, &m) != AK_OK || ak_raster_resolve(r, &pimg) != AK_OK) return 1;
            char label[48];
            snprintf(label, sizeof label, "%s gain %.2f", names[t], (double)gains[g]);
            ak_image_draw_text(&pimg, 8, 8, label, 2, ak_vec4_make(0.1f, 0.1f, 0.12f, 1));
            ak_image_blit(&sheet, t * PW, g * PH, &pimg);
        }
    const ak_result res = ak_png_write("terrain_types.png", &sheet);
    ak_raster_destroy(r);
    free(px), free(panel);
    if (res != AK_OK) return 1;
    printf("wrote terrain_types.png (higher gain: rougher; turbulence: billowy; ridged: sharp crests)\n");
    return 0;
}

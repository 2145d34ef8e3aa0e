/* raster_views: the view helpers. A bent tube with a two-bone skeleton shown shaded and as a
 * weight heatmap in two labelled panels (views.png), and a curve-editor style plot of easing
 * curves with keys and tangent handles (curves.png). Prints the files it wrote. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include <animkit/view.h>

enum { SEG = 48, RING = 24, NV = (SEG + 1) * RING, NT = SEG * RING * 2 };

/* A tube along +Y of height 2 bent by `bend` radians around its middle; w = weight of the upper bone. */
static void make_tube(float bend, ak_vec3* pos, ak_vec3* nrm, float* w, uint32_t* idx) {
    for (int i = 0; i <= SEG; ++i) {
        float v = (float)i / SEG, y = 2.0f * v;
        float t = 1.0f / (1.0f + expf(-(y - 1.0f) * 8.0f)); /* smooth weight across the joint */
        float a = bend * t;
        for (int j = 0; j < RING; ++j) {
            float th = AK_TWO_PI * (float)j / RING;
            ak_vec3 n = ak_vec3_make(cosf(th), 0, sinf(th));
            ak_vec3 p = ak_vec3_make(0.25f * n.x, y - 1.0f, 0.25f * n.z);
            /* rotate about Z around the joint at the origin by the blended angle */
            float c = cosf(a), s = sinf(a);
            pos[i * RING + j] = ak_vec3_make(c * p.x - s * p.y, s * p.x + c * p.y + 1.0f, p.z);
            nrm[i * RING + j] = ak_vec3_make(c * n.x, s * n.x, n.z);
            w[i * RING + j] = t;
        }
    }
    int k = 0;
    for (int i = 0; i < SEG; ++i)
        for (int j = 0; j < RING; ++j) {
            uint32_t a = (uint32_t)(i * RING + j), b = (uint32_t)(i * RING + (j + 1) % RING);
            uint32_t q[6] = {a, a + RING, b, b, a + RING, b + RING}; /* counter-clockwise from outside */
            for (int m = 0; m < 6; ++m) idx[k++] = q[m];
        }
}

int main(void) {
    static ak_vec3 pos[NV], nrm[NV];
    static float w[NV];
    static ak_vec4 heat[NV];
    static uint32_t idx[NT * 3];
    const float bend = 0.9f;
    make_tube(bend, pos, nrm, w, idx);
    ak_view_heatmap_colors((ak_f32_cspan){w, NV}, 0.0f, 1.0f, (ak_vec4_span){heat, NV});

    ak_mat4 joints[3] = {ak_mat4_identity(), ak_mat4_translation(ak_vec3_make(0, 1, 0)),
                         ak_mat4_translation(ak_vec3_make(-sinf(bend), 1 + cosf(bend), 0))};
    int32_t parents[3] = {-1, 0, 1};
    ak_view_skeleton sk = {.joint_model = {joints, 3}, .parents = {parents, 3}};

    enum { PW = 360, PH = 300 };
    ak_raster* r = NULL;
    if (ak_raster_create(&(ak_raster_desc){.width = PW, .height = PH, .supersample = 3, .thread_count = 2}, NULL,
                         &r) != AK_OK)
        return 1;
    static uint8_t px[2][PW * PH * 4];
    ak_image img[2] = {{.pixels = px[0], .width = PW, .height = PH}, {.pixels = px[1], .width = PW, .height = PH}};
    ak_raster_mesh shaded = {.positions = {pos, NV}, .normals = {nrm, NV}, .indices = {idx, NT * 3},
                             .material = {.color = {0.30f, 0.55f, 0.80f, 1}, .specular = 0.5f}};
    ak_raster_mesh heatmap = shaded;
    heatmap.colors = (ak_vec4_cspan){heat, NV};
    heatmap.material.color = ak_vec4_make(1, 1, 1, 1);
    for (int p = 0; p < 2; ++p) {
        ak_view_scene scene = {.meshes = p ? &heatmap : &shaded, .mesh_count = 1, .skeleton = &sk};
        ak_vec3 lo, hi;
        ak_view_scene_bounds(&scene, &lo, &hi);
        ak_raster_camera cam = ak_view_orbit_camera(lo, hi, &(ak_view_orbit){.azimuth = 0.5f, .elevation = 0.3f,
                                                                              .aspect = (float)PW / PH});
        if (ak_view_render(r, &cam, &scene, &img[p]) != AK_OK) return 1;
    }
    ak_raster_destroy(r);
    ak_view_panel panels[2] = {{&img[0], "shaded + skeleton"}, {&img[1], "weights of bone 1"}};
    ak_view_panels_desc pd = {.title = "animkit view helpers"};
    int W, H;
    ak_view_panels_size(&pd, 2, PW, PH, &W, &H);
    uint8_t* out = malloc((size_t)W * H * 4);
    ak_image comp = {.pixels = out, .width = W, .height = H};
    if (!out || ak_view_panels_compose(&pd, panels, 2, &comp) != AK_OK || ak_png_write("views.png", &comp) != AK_OK)
        return 1;
    printf("wrote views.png (%dx%d)\n", W, H);
    free(out);

    /* easing curves sampled on [0, 1], keys at both ends with their tangents */
    enum { N = 101 };
    static float t[N], lin[N], smooth[N], back[N];
    for (int i = 0; i < N; ++i) {
        float x = (float)i / (N - 1);
        t[i] = x;
        lin[i] = x;
        smooth[i] = x * x * (3 - 2 * x);
        back[i] = x * x * (2.70158f * x - 1.70158f);
    }
    float kx[2] = {0, 1}, ky[2] = {0, 1}, in_s[2] = {0, 0}, out_s[2] = {0, 0}, bin[2] = {0, 4.70158f}, bout[2] = {0, 0};
    ak_view_series s[3] = {
        {.x = {t, N}, .y = {lin, N}, .label = "linear"},
        {.x = {t, N}, .y = {smooth, N}, .label = "smoothstep", .key_x = {kx, 2}, .key_y = {ky, 2},
         .key_in_slope = {in_s, 2}, .key_out_slope = {out_s, 2}},
        {.x = {t, N}, .y = {back, N}, .label = "ease-in back", .key_x = {kx, 2}, .key_y = {ky, 2},
         .key_in_slope = {bin, 2}, .key_out_slope = {bout, 2}},
    };
    static uint8_t ppx[560 * 360 * 4];
    ak_image plot_img = {.pixels = ppx, .width = 560, .height = 360};
    ak_view_plot plot = {.series = s, .series_count = 3, .title = "easing curves", .x_label = "time (normalised)",
                         .y_label = "value"};
    if (ak_view_plot_draw(&plot, &plot_img) != AK_OK || ak_png_write("curves.png", &plot_img) != AK_OK) return 1;
    printf("wrote curves.png (560x360)\n");
    return 0;
}

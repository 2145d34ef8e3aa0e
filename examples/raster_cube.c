/* raster_cube: the software renderer on its own. Renders a lit cube and sphere on a ground grid
 * with soft shadows, a "bone" as a line with two joint points, and a title, to cube.png; then a
 * 24-frame turntable to cube.gif. Prints what it wrote and the formats this build can write. */
#include <stdio.h>
#include <stdlib.h>

#include <animkit/raster.h>

/* A unit cube (side 1) resting on y = 0: 6 faces x 4 corners with face normals. */
static void make_cube(ak_vec3 pos[24], ak_vec3 nrm[24], uint32_t idx[36]) {
    static const float n[6][3] = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
    for (int f = 0; f < 6; ++f) {
        ak_vec3 N = ak_vec3_make(n[f][0], n[f][1], n[f][2]);
        ak_vec3 U = ak_vec3_any_perpendicular(N);
        ak_vec3 V = ak_vec3_cross(N, U);
        const float s[4][2] = {{-1, -1}, {1, -1}, {1, 1}, {-1, 1}};
        for (int k = 0; k < 4; ++k) {
            ak_vec3 p = ak_vec3_add(ak_vec3_scale(N, 0.5f),
                                    ak_vec3_add(ak_vec3_scale(U, 0.5f * s[k][0]), ak_vec3_scale(V, 0.5f * s[k][1])));
            pos[f * 4 + k] = ak_vec3_add(p, ak_vec3_make(0, 0.5f, 0));
            nrm[f * 4 + k] = N;
        }
        const uint32_t q[6] = {0, 1, 2, 0, 2, 3};
        for (int k = 0; k < 6; ++k) idx[f * 6 + k] = (uint32_t)(f * 4) + q[k];
    }
}

/* A UV sphere of radius 0.35 standing on the floor at x = 1.1. */
enum { SLICES = 32, STACKS = 16, SPHERE_V = (SLICES + 1) * (STACKS + 1), SPHERE_I = SLICES * STACKS * 6 };
static void make_sphere(ak_vec3* pos, ak_vec3* nrm, uint32_t* idx) {
    for (int i = 0; i <= SLICES; ++i)
        for (int j = 0; j <= STACKS; ++j) {
            float ph = AK_TWO_PI * (float)i / SLICES, th = AK_PI * (float)j / STACKS;
            ak_vec3 n = ak_vec3_make(sinf(th) * cosf(ph), cosf(th), sinf(th) * sinf(ph));
            pos[i * (STACKS + 1) + j] = ak_vec3_add(ak_vec3_scale(n, 0.35f), ak_vec3_make(1.1f, 0.35f, 0.2f));
            nrm[i * (STACKS + 1) + j] = n;
        }
    int k = 0;
    for (int i = 0; i < SLICES; ++i)
        for (int j = 0; j < STACKS; ++j) {
            uint32_t a = (uint32_t)(i * (STACKS + 1) + j), b = a + STACKS + 1;
            const uint32_t q[6] = {a, b, a + 1, b, b + 1, a + 1};
            for (int m = 0; m < 6; ++m) idx[k++] = q[m];
        }
}

static int render(ak_raster* r, float azimuth, const ak_image* img, int w, int h, bool labels) {
    ak_vec3 pos[24], nrm[24];
    uint32_t idx[36];
    static ak_vec3 spos[SPHERE_V], snrm[SPHERE_V];
    static uint32_t sidx[SPHERE_I];
    make_cube(pos, nrm, idx);
    make_sphere(spos, snrm, sidx);
    ak_vec3 eye = ak_vec3_make(4.2f * sinf(azimuth), 2.6f, 4.2f * cosf(azimuth));
    ak_raster_camera cam = ak_raster_camera_perspective(eye, ak_vec3_make(0, 0.4f, 0), ak_radians(38.0f),
                                                        (float)w / (float)h, 0.1f, 50.0f);
    ak_raster_clear(r, ak_vec4_make(0.80f, 0.85f, 0.92f, 1), ak_vec4_make(0.52f, 0.55f, 0.62f, 1));
    ak_raster_mesh cube = {
        .positions = {pos, 24}, .normals = {nrm, 24}, .indices = {idx, 36},
        .material = {.color = ak_vec4_make(0.85f, 0.45f, 0.25f, 1), .specular = 0.4f, .shininess = 48},
        .cull_back_faces = true,
    };
    ak_raster_mesh things[2] = {cube, {.positions = {spos, SPHERE_V}, .normals = {snrm, SPHERE_V},
                                       .indices = {sidx, SPHERE_I}, .cull_back_faces = true,
                                       .material = {.color = {0.2f, 0.6f, 0.65f, 1}, .specular = 0.6f}}};
    ak_raster_ground ground = {.half_extent = 3.0f, .grid_spacing = 0.25f, .casters = things, .caster_count = 2};
    if (ak_raster_draw_ground(r, &cam, &ground) != AK_OK) return 1;
    for (int i = 0; i < 2; ++i)
        if (ak_raster_draw_mesh(r, &cam, &things[i]) != AK_OK) return 1;
    /* the 12 edges of the top face and a vertical "bone" with joints */
    ak_vec3 bone[2] = {{0, 1.0f, 0}, {0, 1.6f, 0}};
    ak_raster_lines lines = {.positions = {bone, 2}, .color = {0.1f, 0.2f, 0.5f, 1}, .width = 3};
    ak_raster_points pts = {.positions = {bone, 2}, .color = {0.95f, 0.8f, 0.2f, 1}, .radius = 5, .outline = 1.5f};
    if (ak_raster_draw_lines(r, &cam, &lines) != AK_OK || ak_raster_draw_points(r, &cam, &pts) != AK_OK) return 1;
    if (labels) ak_raster_draw_text(r, 10, 10, "animkit raster: Phong, grid, soft shadow", 2, ak_vec4_make(0.1f, 0.1f, 0.15f, 1));
    return ak_raster_resolve(r, img) == AK_OK ? 0 : 1;
}

int main(void) {
    const int W = 640, H = 480;
    ak_raster* r = NULL;
    ak_raster_desc d = {.width = W, .height = H, .supersample = 3, .thread_count = 2};
    if (ak_raster_create(&d, NULL, &r) != AK_OK) return 1;
    uint8_t* px = malloc((size_t)W * H * 4);
    ak_image img = {.pixels = px, .width = W, .height = H};
    if (!px || render(r, 0.6f, &img, W, H, true) != 0 || ak_png_write("cube.png", &img) != AK_OK) return 1;
    printf("wrote cube.png (%dx%d)\n", W, H);
    ak_raster_destroy(r);

    /* turntable: smaller frames */
    const int GW = 320, GH = 240, FRAMES = 24;
    ak_raster_desc gd = {.width = GW, .height = GH, .supersample = 2};
    ak_gif_writer* gif = NULL;
    if (ak_raster_create(&gd, NULL, &r) != AK_OK) return 1;
    if (ak_gif_writer_create("cube.gif", &(ak_gif_desc){.width = GW, .height = GH, .delay_cs = 6}, NULL, &gif) != AK_OK)
        return 1;
    ak_image frame = {.pixels = px, .width = GW, .height = GH};
    for (int i = 0; i < FRAMES; ++i) {
        if (render(r, 0.6f + AK_TWO_PI * (float)i / (float)FRAMES, &frame, GW, GH, false) != 0) return 1;
        if (ak_gif_writer_add_frame(gif, &frame) != AK_OK) return 1;
    }
    if (ak_gif_writer_finish(gif) != AK_OK) return 1;
    printf("wrote cube.gif (%dx%d, %d frames)\nformats: %s\n", GW, GH, FRAMES, ak_image_formats_string());
    ak_raster_destroy(r);
    free(px);
    return 0;
}

/* particles_fountain: a fountain of 600 particles/s falling on a floor and a ball, stepped with
 * semi-implicit Euler, then drawn as shaded points with the software rasterizer. Prints the
 * particle count each half second and writes particles_fountain.png. */
#include <stdio.h>
#include <stdlib.h>

#include <animkit/particles.h>
#include <animkit/raster.h>

int main(void) {
    ak_particles* ps = NULL;
    ak_particles_desc desc = {.capacity = 5000, .seed = 7};
    if (ak_particles_create(&desc, NULL, &ps) != AK_OK) return 1;
    ak_particle_emitter jet = {.shape = AK_EMITTER_DISC,
                               .radius = 0.04f,
                               .direction = {0, 1, 0},
                               .cone_angle = 0.15f,
                               .speed_min = 4.5f,
                               .speed_max = 5.0f,
                               .lifetime_min = 2.5f,
                               .lifetime_max = 3.0f,
                               .rate = 600.0f,
                               .colour = {0.3f, 0.55f, 1.0f, 1.0f}};
    ak_particle_plane floor = {.normal = {0, 1, 0}, .restitution = 0.4f, .friction = 0.3f};
    ak_particle_sphere ball = {.center = {0.35f, 0.3f, 0}, .radius = 0.3f, .restitution = 0.3f};
    ak_particles_world world = {.gravity = {0, -9.81f, 0},
                                .drag_linear = 0.02f,
                                .planes = {&floor, 1},
                                .spheres = {&ball, 1}};
    const float dt = 0.01f;
    for (int s = 1; s <= 300; ++s) {
        if (ak_particles_emit(ps, &jet, dt, NULL) != AK_OK ||
            ak_particles_step(ps, &world, dt) != AK_OK)
            return 1;
        if (s % 50 == 0)
            printf("t = %.1f s: %zu particles\n", ak_particles_time(ps), ak_particles_count(ps));
    }

    enum { W = 320, H = 240 };
    ak_raster* r = NULL;
    ak_raster_desc rd = {.width = W, .height = H, .supersample = 2};
    uint8_t* px = malloc((size_t)W * H * 4);
    if (!px || ak_raster_create(&rd, NULL, &r) != AK_OK) return 1;
    ak_raster_camera cam = ak_raster_camera_perspective(
        ak_vec3_make(0.8f, 1.6f, 3.4f), ak_vec3_make(0, 0.7f, 0), 0.8f, (float)W / H, 0.1f, 50.0f);
    ak_raster_clear(r, ak_vec4_make(0.85f, 0.88f, 0.93f, 1), ak_vec4_make(0.55f, 0.58f, 0.64f, 1));
    ak_raster_draw_ground(r, &cam, &(ak_raster_ground){.half_extent = 2.0f});
    ak_particles_state st = ak_particles_get_state(ps);
    ak_raster_points pts = {
        .positions = {st.position, st.count}, .colors = {st.colour, st.count}, .radius = 2.0f};
    ak_image img = {.pixels = px, .width = W, .height = H};
    if (ak_raster_draw_points(r, &cam, &pts) != AK_OK || ak_raster_resolve(r, &img) != AK_OK)
        return 1;
    ak_result res = ak_png_write("particles_fountain.png", &img);
    printf("wrote particles_fountain.png (%s)\n", ak_result_string(res));
    ak_raster_destroy(r);
    free(px);
    ak_particles_destroy(ps);
    return res == AK_OK ? 0 : 1;
}

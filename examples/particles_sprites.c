/* particles_sprites: a campfire as billboards. Flames rise from a disc (buoyant: gravity points
 * up), and each particle is drawn as a camera-facing puff whose colour and size follow keys over
 * its life (ak_particle_look) and whose sprite-sheet frame comes from its age; additive blending
 * needs no sort. A column of smoke above it is alpha-blended, sorted back to front with
 * ak_raster_sprites_sort. Writes particles_sprites.png and prints the live counts. */
#include <stdio.h>
#include <stdlib.h>

#include <animkit/particles.h>
#include <animkit/raster.h>

enum { W = 480, H = 360, FW = 64, COLS = 4, ROWS = 2 };

/* Draw one system's particles as sprites with a look. */
static ak_result draw(ak_raster* r, const ak_raster_camera* cam, ak_particles* ps, const ak_particle_look* look,
                      const ak_image* sheet, ak_blend blend, float* sizes, ak_vec4* colours, uint32_t* frames,
                      float* depth, uint32_t* order) {
    ak_particles_state st = ak_particles_get_state(ps);
    if (!st.count) return AK_OK;
    for (size_t i = 0; i < st.count; ++i) {
        ak_vec4 k = ak_particle_look_colour(look, st.age[i], st.lifetime[i]), c = st.colour[i];
        colours[i] = ak_vec4_make(c.x * k.x, c.y * k.y, c.z * k.z, c.w * k.w);
        sizes[i] = 2.0f * st.size[i] * ak_particle_look_size(look, st.age[i], st.lifetime[i]);
        frames[i] = ak_particle_look_frame(look, st.age[i], st.lifetime[i]);
    }
    ak_raster_sprites s = {.positions = {st.position, st.count}, .sizes = {sizes, st.count},
                           .colors = {colours, st.count}, .frames = {frames, st.count}, .texture = sheet,
                           .sheet_columns = COLS, .sheet_rows = ROWS, .blend = blend};
    if (blend == AK_BLEND_ALPHA) {
        ak_result res = ak_raster_sprites_sort(cam, (ak_vec3_cspan){st.position, st.count},
                                               (ak_f32_span){depth, st.count}, (ak_u32_span){order, st.count});
        if (res != AK_OK) return res;
        s.order = (ak_u32_cspan){order, st.count};
    }
    return ak_raster_draw_sprites(r, cam, &s);
}

int main(void) {
    enum { CAP = 4000 };
    ak_particles *fire = NULL, *smoke = NULL;
    if (ak_particles_create(&(ak_particles_desc){.capacity = CAP, .seed = 3}, NULL, &fire) != AK_OK ||
        ak_particles_create(&(ak_particles_desc){.capacity = CAP, .seed = 4}, NULL, &smoke) != AK_OK)
        return 1;
    ak_particle_emitter flames = {.shape = AK_EMITTER_DISC, .radius = 0.2f, .direction = {0, 1, 0}, .cone_angle = 0.2f,
                                  .speed_min = 0.8f, .speed_max = 1.4f, .lifetime_min = 0.6f, .lifetime_max = 1.1f,
                                  .size_min = 0.08f, .size_max = 0.12f, .mass = 1, .rate = 350,
                                  .colour = {1.0f, 0.62f, 0.22f, 1}};
    ak_particle_emitter fumes = flames;
    fumes.center = ak_vec3_make(0, 0.8f, 0), fumes.radius = 0.1f, fumes.speed_min = 0.4f, fumes.speed_max = 0.6f;
    fumes.lifetime_min = 2.5f, fumes.lifetime_max = 3.5f, fumes.size_min = 0.12f, fumes.size_max = 0.16f;
    fumes.rate = 30, fumes.colour = ak_vec4_make(0.35f, 0.35f, 0.38f, 1);
    ak_particles_world hot = {.gravity = {0, 2.0f, 0}, .drag_linear = 0.8f};
    ak_particles_world air = {.gravity = {0, 0.3f, 0}, .drag_linear = 0.6f, .wind = {0.4f, 0, 0}};
    /* hot yellow -> red -> nothing while shrinking; smoke fades in and out while it grows */
    ak_particle_look fire_look = {.colour_keys = {{0.0f, {1, 1, 0.75f, 0.3f}}, {0.3f, {1, 0.75f, 0.45f, 0.3f}},
                                                  {0.7f, {0.9f, 0.35f, 0.25f, 0.2f}}, {1.0f, {0.5f, 0.2f, 0.2f, 0}}},
                                  .colour_key_count = 4,
                                  .size_keys = {{0.0f, 0.7f}, {0.35f, 1.0f}, {1.0f, 0.35f}},
                                  .size_key_count = 3,
                                  .frame_count = COLS * ROWS};
    ak_particle_look smoke_look = {.colour_keys = {{0.0f, {1, 1, 1, 0}}, {0.15f, {1, 1, 1, 0.6f}}, {1.0f, {1.8f, 1.8f, 1.8f, 0}}},
                                   .colour_key_count = 3,
                                   .size_keys = {{0.0f, 0.8f}, {1.0f, 3.0f}},
                                   .size_key_count = 2,
                                   .frame_count = COLS * ROWS,
                                   .frame_rate = 2.0f};
    if (ak_particle_look_validate(&fire_look) != AK_OK || ak_particle_look_validate(&smoke_look) != AK_OK) return 1;
    /* a sheet of differently seeded puffs, one per frame */
    uint8_t* sheet_px = malloc((size_t)COLS * FW * ROWS * FW * 4);
    float* sizes = malloc(CAP * sizeof *sizes);
    ak_vec4* colours = malloc(CAP * sizeof *colours);
    uint32_t* frames = malloc(CAP * sizeof *frames);
    float* depth = malloc(CAP * sizeof *depth);
    uint32_t* order = malloc(CAP * sizeof *order);
    uint8_t* px = malloc((size_t)W * H * 4);
    ak_raster* r = NULL;
    int rc = 1;
    if (!sheet_px || !sizes || !colours || !frames || !depth || !order || !px ||
        ak_raster_create(&(ak_raster_desc){.width = W, .height = H, .supersample = 2}, NULL, &r) != AK_OK)
        goto done;
    ak_image sheet = {.pixels = sheet_px, .width = COLS * FW, .height = ROWS * FW};
    for (int f = 0; f < COLS * ROWS; ++f) {
        ak_image cell = {.pixels = ak_image_pixel(&sheet, (f % COLS) * FW, (f / COLS) * FW), .width = FW, .height = FW,
                         .stride = (size_t)sheet.width * 4};
        ak_sprite_texture_generate(AK_SPRITE_TEXTURE_PUFF, (uint32_t)f + 1, &cell);
    }
    const float dt = 0.01f;
    for (int step = 1; step <= 300; ++step) {
        ak_particles_emit(fire, &flames, dt, NULL);
        ak_particles_emit(smoke, &fumes, dt, NULL);
        ak_particles_step(fire, &hot, dt);
        ak_particles_step(smoke, &air, dt);
        if (step % 100 == 0)
            printf("t = %.1f s: %zu flame and %zu smoke particles\n", step * dt, ak_particles_count(fire),
                   ak_particles_count(smoke));
    }
    ak_raster_camera cam = ak_raster_camera_perspective(ak_vec3_make(0, 1.2f, 3.2f), ak_vec3_make(0, 1.0f, 0),
                                                        ak_radians(45), (float)W / H, 0.1f, 30);
    ak_raster_clear(r, ak_vec4_make(0.05f, 0.06f, 0.10f, 1), ak_vec4_make(0.16f, 0.16f, 0.20f, 1));
    ak_raster_draw_ground(r, &cam, &(ak_raster_ground){.color = {0.26f, 0.25f, 0.25f, 1}, .line_color = {0.33f, 0.32f, 0.32f, 1}});
    /* smoke first (it is behind and above the flames), then the flames' light on top */
    if (draw(r, &cam, smoke, &smoke_look, &sheet, AK_BLEND_ALPHA, sizes, colours, frames, depth, order) != AK_OK ||
        draw(r, &cam, fire, &fire_look, &sheet, AK_BLEND_ADD, sizes, colours, frames, depth, order) != AK_OK)
        goto done;
    ak_image img = {.pixels = px, .width = W, .height = H};
    if (ak_raster_resolve(r, &img) != AK_OK || ak_png_write("particles_sprites.png", &img) != AK_OK) goto done;
    printf("wrote particles_sprites.png\n");
    rc = 0;
done:
    ak_raster_destroy(r);
    free(sheet_px), free(sizes), free(colours), free(frames), free(depth), free(order), free(px);
    ak_particles_destroy(fire);
    ak_particles_destroy(smoke);
    return rc;
}

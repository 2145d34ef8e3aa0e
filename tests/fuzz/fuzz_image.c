/* libFuzzer target for the texture image path: the PNG (libpng) and JPEG (libjpeg-turbo)
 * decoders behind ak_io_image_decode, and the glTF reader's image handling around them; built
 * and run by scripts/fuzz.sh (see docs/io.md).
 *
 * Each input is (1) decoded directly, with the default budget and with a 256 KiB one, and
 * (2) embedded as the image of a one-triangle GLB (a bufferView over the whole input, the
 * texture with a sampler), loaded from memory. A decoded image must have a size within the
 * limits and pixels; a loaded scene's texture must be absent or complete, and the mesh that
 * uses it must have UVs. The textured triangle is then drawn (the rasterizer samples the
 * texture). Any crash, leak or sanitizer report is a bug. */
#include <animkit/io.h>
#include <animkit/raster.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size);

static void put_u32(uint8_t* p, uint32_t v) {
    p[0] = (uint8_t)v;
    p[1] = (uint8_t)(v >> 8);
    p[2] = (uint8_t)(v >> 16);
    p[3] = (uint8_t)(v >> 24);
}

static void draw(const ak_scene* s) {
    const ak_scene_mesh* sm = &s->meshes[0];
    if (sm->texture < 0) return;
    if ((size_t)sm->texture >= s->texture_count || !sm->mesh->uvs) abort();
    const ak_scene_texture* t = &s->textures[sm->texture];
    if (!t->pixels || t->width <= 0 || t->height <= 0) abort();
    ak_raster* r = NULL;
    if (ak_raster_create(&(ak_raster_desc){.width = 16, .height = 16}, NULL, &r) != AK_OK) return;
    ak_raster_texture tex = {.image = {.pixels = t->pixels, .width = t->width, .height = t->height},
                             .wrap_u = (ak_raster_wrap)t->wrap_s,
                             .wrap_v = (ak_raster_wrap)t->wrap_t,
                             .mag_filter = (ak_raster_filter)t->mag_filter,
                             .min_filter = (ak_raster_filter)t->min_filter};
    ak_raster_camera cam = ak_raster_camera_orthographic(
        ak_vec3_make(0.5f, 0.5f, 3), ak_vec3_make(0.5f, 0.5f, 0), 0.6f, 1, 0.1f, 10);
    ak_raster_mesh m = {.positions = {sm->mesh->positions, sm->mesh->vertex_count},
                        .uvs = {sm->mesh->uvs, sm->mesh->vertex_count},
                        .indices = {sm->mesh->indices, sm->mesh->triangle_count * 3},
                        .texture = &tex};
    if (ak_raster_draw_mesh(r, &cam, &m) != AK_OK) abort();
    ak_raster_destroy(r);
}

int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    for (int i = 0; i < 2; ++i) {
        uint8_t* px = NULL;
        int w = 0, h = 0;
        ak_diag diag;
        if (ak_io_image_decode(data, size, i ? 256u << 10 : 0, NULL, &px, &w, &h, &diag) == AK_OK) {
            if (!px || w <= 0 || h <= 0 || w > 16384 || h > 16384) abort();
            volatile uint8_t sink = px[(size_t)w * (size_t)h * 4 - 1];
            (void)sink;
        } else if (px) {
            abort();
        }
        ak_io_image_free(NULL, px);
    }
    /* the GLB: positions (36 bytes) and UVs (24 bytes), then the image bytes */
    static const float geo[15] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 2, 0, 0, -1};
    if (size > (1u << 24)) return 0;
    size_t img_off = sizeof geo, bin = (img_off + size + 3) & ~(size_t)3;
    char json[1600];
    int jn = snprintf(
        json, sizeof json,
        "{\"asset\":{\"version\":\"2.0\"},\"buffers\":[{\"byteLength\":%zu}],\"bufferViews\":[{"
        "\"buffer\":0,"
        "\"byteLength\":36},{\"buffer\":0,\"byteOffset\":36,\"byteLength\":24},{\"buffer\":0,"
        "\"byteOffset\":%zu,\"byteLength\":%zu}],\"accessors\":[{\"bufferView\":0,"
        "\"componentType\":5126,"
        "\"count\":3,\"type\":\"VEC3\",\"min\":[0,0,0],\"max\":[1,1,0]},{\"bufferView\":1,"
        "\"componentType\":5126,\"count\":3,\"type\":\"VEC2\"}],\"meshes\":[{\"primitives\":[{"
        "\"attributes\":{\"POSITION\":0,\"TEXCOORD_0\":1},\"material\":0}]}],\"nodes\":[{\"mesh\":"
        "0}],"
        "\"materials\":[{\"pbrMetallicRoughness\":{\"baseColorTexture\":{\"index\":0}}}],"
        "\"textures\":[{"
        "\"source\":0,\"sampler\":0}],\"samplers\":[{\"wrapS\":%d,\"wrapT\":33648,\"magFilter\":%d}"
        "],"
        "\"images\":[{\"bufferView\":2,\"mimeType\":\"image/png\"}]}",
        bin, img_off, size ? size : 1, size && (data[0] & 1) ? 33071 : 10497,
        size && (data[0] & 2) ? 9728 : 9729);
    size_t jlen = ((size_t)jn + 3) & ~(size_t)3;
    size_t total = 12 + 8 + jlen + 8 + bin;
    uint8_t* glb = calloc(1, total);
    if (!glb) return 0;
    memcpy(glb, "glTF", 4);
    put_u32(glb + 4, 2);
    put_u32(glb + 8, (uint32_t)total);
    put_u32(glb + 12, (uint32_t)jlen);
    memcpy(glb + 16, "JSON", 4);
    memset(glb + 20, ' ', jlen);
    memcpy(glb + 20, json, (size_t)jn);
    uint8_t* b = glb + 20 + jlen;
    put_u32(b, (uint32_t)bin);
    memcpy(b + 4, "BIN\0", 4);
    memcpy(b + 8, geo, sizeof geo);
    if (size) memcpy(b + 8 + img_off, data, size);
    ak_scene* scene = NULL;
    ak_diag diag;
    ak_io_desc desc = {.format = AK_IO_FORMAT_GLTF, .memory_budget = 8u << 20};
    if (ak_io_load_memory(glb, total, "fuzz.glb", NULL, &desc, NULL, &scene, &diag) == AK_OK) {
        if (scene->mesh_count != 1) abort();
        draw(scene);
    }
    ak_scene_destroy(scene);
    free(glb);
    return 0;
}

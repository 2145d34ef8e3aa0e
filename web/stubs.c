/* The WebAssembly build's stand-ins for the four library files that need a Debian library
 * Debian does not build for wasm32 (docs/web.md): src/raster/raster_file.c (libpng, giflib),
 * src/io/image.c (libpng, libjpeg), src/io/assimp.c (Assimp) and src/skin/weights_heat.c
 * (CHOLMOD). scripts/build-web.sh compiles this file instead of those four. Each function
 * keeps its native contract and fails the way the native build fails when the format is
 * missing: ak_image_format_available says false, PNG/GIF files are AK_ERR_UNSUPPORTED, the
 * built-in image decoder knows no format (the page's textures come from the browser through
 * ak_io_desc.image_decoder, web/animkit_web.c; an image it did not decode is a warning and the
 * mesh is drawn untextured, as a JPEG is without libjpeg), FBX/Collada/OBJ-through-Assimp and
 * bone heat weights are AK_ERR_UNSUPPORTED. The page never
 * writes files: frames go to the canvas. */
#include <stdio.h>
#include <string.h>

#include "internal.h"
#include "io/io_internal.h"
#include "skin/weights_internal.h"

#include <animkit/raster.h>

/* ---- src/raster/raster_file.c ---- */

bool ak_image_format_available(ak_image_format format) {
    (void)format;
    return false;
}

const char* ak_image_formats_string(void) { return ""; }

ak_result ak_png_write(const char* path, const ak_image* image) {
    if (!path || !image || !image->pixels) return AK_ERR_NULL_ARG;
    return AK_ERR_UNSUPPORTED;
}

ak_result ak_png_info(const char* path, int* out_width, int* out_height) {
    (void)path;
    if (out_width) *out_width = 0;
    if (out_height) *out_height = 0;
    return AK_ERR_UNSUPPORTED;
}

ak_result ak_png_read(const char* path, const ak_image* out) {
    (void)path, (void)out;
    return AK_ERR_UNSUPPORTED;
}

ak_result ak_gif_writer_create(const char* path, const ak_gif_desc* desc, const ak_allocator* alloc,
                               ak_gif_writer** out_writer) {
    (void)path, (void)desc, (void)alloc;
    if (out_writer) *out_writer = NULL;
    return AK_ERR_UNSUPPORTED;
}

ak_result ak_gif_writer_add_frame(ak_gif_writer* w, const ak_image* frame) {
    (void)w, (void)frame;
    return AK_ERR_UNSUPPORTED;
}

ak_result ak_gif_writer_finish(ak_gif_writer* w) {
    (void)w;
    return AK_ERR_UNSUPPORTED;
}

void ak_gif_writer_discard(ak_gif_writer* w) { (void)w; }

ak_result ak_gif_info(const char* path, int* out_width, int* out_height, int* out_frame_count) {
    (void)path;
    if (out_width) *out_width = 0;
    if (out_height) *out_height = 0;
    if (out_frame_count) *out_frame_count = 0;
    return AK_ERR_UNSUPPORTED;
}

ak_result ak_gif_read_frame(const char* path, int frame_index, const ak_image* out) {
    (void)path, (void)frame_index, (void)out;
    return AK_ERR_UNSUPPORTED;
}

/* ---- src/io/image.c ---- */

ak_result akp_image_decode(const uint8_t* data, size_t size, akp_budget* budget, const ak_allocator* alloc,
                           uint8_t** out_pixels, int* out_width, int* out_height, char* msg, size_t msg_size) {
    (void)data, (void)size, (void)budget, (void)alloc;
    *out_pixels = NULL;
    *out_width = *out_height = 0;
    snprintf(msg, msg_size, "this build (WebAssembly) has no PNG or JPEG decoder");
    return AK_ERR_UNSUPPORTED;
}

ak_result akp_image_encode_png(const uint8_t* rgba, int width, int height, uint8_t** out_data, size_t* out_size) {
    (void)rgba, (void)width, (void)height;
    *out_data = NULL;
    *out_size = 0;
    return AK_ERR_UNSUPPORTED;
}

ak_result ak_io_image_decode(const void* data, size_t size, size_t memory_budget, const ak_allocator* alloc,
                             uint8_t** out_pixels, int* out_width, int* out_height, ak_diag* diag) {
    (void)data, (void)size, (void)memory_budget, (void)alloc;
    if (out_pixels) *out_pixels = NULL;
    if (out_width) *out_width = 0;
    if (out_height) *out_height = 0;
    if (diag) {
        memset(diag, 0, sizeof *diag);
        diag->byte_offset = -1;
        snprintf(diag->path, sizeof diag->path, "memory");
        snprintf(diag->message, sizeof diag->message, "this build (WebAssembly) has no PNG or JPEG decoder");
    }
    return AK_ERR_UNSUPPORTED;
}

void ak_io_image_free(const ak_allocator* alloc, uint8_t* pixels) { akp_free(alloc, pixels); }

/* ---- src/io/assimp.c ---- */

ak_result akp_io_load_assimp(const char* path, const ak_io_desc* desc, const ak_allocator* alloc, ak_scene** out_scene,
                             ak_diag* diag) {
    (void)desc, (void)alloc;
    if (out_scene) *out_scene = NULL;
    if (diag) {
        memset(diag, 0, sizeof *diag);
        diag->byte_offset = -1;
        snprintf(diag->path, sizeof diag->path, "%s", path ? path : "");
        snprintf(diag->message, sizeof diag->message,
                 "this build (WebAssembly) has no Assimp: only glTF (.glb/.gltf) and BVH files load");
    }
    return AK_ERR_UNSUPPORTED;
}

/* ---- src/skin/weights_heat.c ---- */

ak_result akp_weights_heat(const ak_weights_desc* d, const ak_allocator* alloc, uint16_t* out_joints, float* out_weights) {
    (void)d, (void)alloc, (void)out_joints, (void)out_weights;
    return AK_ERR_UNSUPPORTED;
}

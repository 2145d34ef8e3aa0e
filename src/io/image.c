/* Texture images: PNG (libpng's simplified API) and JPEG (libjpeg-turbo) decoded from memory
 * into RGBA8, with the image's size read from its header and charged to the load's memory
 * budget before the pixels are allocated; PNG encoded to memory for the writers. */
#include <png.h> /* libpng 1.6 simplified API: png_image */
#include <setjmp.h>
#include <stdio.h>
#include <stdlib.h>

#ifdef AK_HAVE_JPEG
#include <jpeglib.h> /* Debian libjpeg62-turbo-dev; after stdio.h, which it needs */
#endif

#include "io_internal.h"

/* ---- static helpers ------------------------------------------------------------------------ */

static ak_result too_big(int w, int h, akp_budget* budget, char* msg, size_t msg_size) {
    if (w <= 0 || h <= 0 || w > AKP_IO_MAX_IMAGE_SIDE || h > AKP_IO_MAX_IMAGE_SIDE) {
        snprintf(msg, msg_size, "image of %d x %d pixels (at most %d per side)", w, h,
                 AKP_IO_MAX_IMAGE_SIDE);
        return AK_ERR_UNSUPPORTED;
    }
    if (budget && !akp_budget_take(budget, (size_t)w * (size_t)h, 4)) {
        snprintf(msg, msg_size,
                 "image of %d x %d pixels would exceed the memory budget of %zu bytes", w, h,
                 budget->limit);
        return AK_ERR_UNSUPPORTED;
    }
    return AK_OK;
}

static ak_result decode_png(const uint8_t* data, size_t size, akp_budget* budget,
                            const ak_allocator* alloc, uint8_t** out, int* out_w, int* out_h,
                            char* msg, size_t msg_size) {
    png_image pi;
    memset(&pi, 0, sizeof pi);
    pi.version = PNG_IMAGE_VERSION;
    if (!png_image_begin_read_from_memory(&pi, data, size)) {
        snprintf(msg, msg_size, "broken PNG: %s", pi.message);
        png_image_free(&pi);
        return AK_ERR_PARSE;
    }
    int w = pi.width > (png_uint_32)INT32_MAX ? -1 : (int)pi.width;
    int h = pi.height > (png_uint_32)INT32_MAX ? -1 : (int)pi.height;
    ak_result r = too_big(w, h, budget, msg, msg_size);
    if (r != AK_OK) {
        png_image_free(&pi);
        return r;
    }
    uint8_t* px = (uint8_t*)akp_alloc(alloc, (size_t)w * (size_t)h * 4u);
    if (!px) {
        png_image_free(&pi);
        snprintf(msg, msg_size, "out of memory");
        return AK_ERR_NO_MEMORY;
    }
    pi.format =
        PNG_FORMAT_RGBA; /* any colour type, 16-bit reduced, tRNS as alpha; no gamma change */
    if (!png_image_finish_read(&pi, NULL, px, (png_int_32)(w * 4), NULL)) {
        snprintf(msg, msg_size, "broken PNG: %s", pi.message);
        png_image_free(&pi);
        akp_free(alloc, px);
        return AK_ERR_PARSE;
    }
    png_image_free(&pi);
    *out = px;
    *out_w = w;
    *out_h = h;
    return AK_OK;
}

#ifdef AK_HAVE_JPEG
typedef struct jpeg_fail {
    struct jpeg_error_mgr mgr;
    jmp_buf jump;
    char text[JMSG_LENGTH_MAX];
} jpeg_fail;

static void jpeg_on_error(j_common_ptr cinfo) {
    jpeg_fail* f = (jpeg_fail*)cinfo->err;
    f->mgr.format_message(cinfo, f->text);
    longjmp(f->jump, 1);
}

static void jpeg_on_message(j_common_ptr cinfo) {
    (void)cinfo; /* warnings: silent, never printed */
}

static ak_result decode_jpeg(const uint8_t* data, size_t size, akp_budget* budget,
                             const ak_allocator* alloc, uint8_t** out, int* out_w, int* out_h,
                             char* msg, size_t msg_size) {
    struct jpeg_decompress_struct cinfo;
    jpeg_fail fail;
    memset(&cinfo, 0, sizeof cinfo);
    memset(&fail, 0, sizeof fail);
    cinfo.err = jpeg_std_error(&fail.mgr);
    fail.mgr.error_exit = jpeg_on_error;
    fail.mgr.output_message = jpeg_on_message;
    uint8_t* volatile px = NULL;
    volatile ak_result vr = AK_ERR_PARSE;
    if (setjmp(fail.jump)) {
        snprintf(msg, msg_size, "broken JPEG: %s", fail.text);
        jpeg_destroy_decompress(&cinfo);
        akp_free(alloc, px);
        return vr;
    }
    jpeg_create_decompress(&cinfo);
    if (size > (size_t)(unsigned long)-1) size = (size_t)(unsigned long)-1;
    jpeg_mem_src(&cinfo, data, (unsigned long)size);
    jpeg_read_header(&cinfo, TRUE);
    int w = cinfo.image_width > (JDIMENSION)INT32_MAX ? -1 : (int)cinfo.image_width;
    int h = cinfo.image_height > (JDIMENSION)INT32_MAX ? -1 : (int)cinfo.image_height;
    ak_result r = too_big(w, h, budget, msg, msg_size);
    if (r == AK_OK && cinfo.jpeg_color_space != JCS_GRAYSCALE &&
        cinfo.jpeg_color_space != JCS_YCbCr && cinfo.jpeg_color_space != JCS_RGB) {
        snprintf(msg, msg_size, "JPEG colour space %d (CMYK/YCCK) is not supported",
                 (int)cinfo.jpeg_color_space);
        r = AK_ERR_UNSUPPORTED;
    }
    /* a progressive (multi-scan) JPEG keeps every DCT coefficient (2 bytes per sample) in
     * libjpeg's own memory until the last scan: charged too */
    if (r == AK_OK && budget && jpeg_has_multiple_scans(&cinfo) &&
        !akp_budget_take(budget, (size_t)w * (size_t)h, (size_t)cinfo.num_components * 2u)) {
        snprintf(msg, msg_size,
                 "progressive JPEG of %d x %d pixels would exceed the memory budget of %zu bytes",
                 w, h, budget->limit);
        r = AK_ERR_UNSUPPORTED;
    }
    if (r != AK_OK) {
        jpeg_destroy_decompress(&cinfo);
        return r;
    }
    px = (uint8_t*)akp_alloc(alloc, (size_t)w * (size_t)h * 4u);
    if (!px) {
        jpeg_destroy_decompress(&cinfo);
        snprintf(msg, msg_size, "out of memory");
        return AK_ERR_NO_MEMORY;
    }
    cinfo.out_color_space = JCS_EXT_RGBA; /* libjpeg-turbo: grey and YCbCr to RGBA, alpha 255 */
    jpeg_start_decompress(&cinfo);
    if (cinfo.output_components != 4 || cinfo.output_width != (JDIMENSION)w ||
        cinfo.output_height != (JDIMENSION)h) {
        snprintf(fail.text, sizeof fail.text, "unexpected output layout");
        longjmp(fail.jump, 1);
    }
    while (cinfo.output_scanline < cinfo.output_height) {
        JSAMPROW row = px + (size_t)cinfo.output_scanline * (size_t)w * 4u;
        jpeg_read_scanlines(&cinfo, &row, 1);
    }
    jpeg_finish_decompress(&cinfo);
    jpeg_destroy_decompress(&cinfo);
    *out = px;
    *out_w = w;
    *out_h = h;
    return AK_OK;
}
#endif

/* ---- internal ------------------------------------------------------------------------------ */

ak_result akp_image_decode(const uint8_t* data, size_t size, akp_budget* budget,
                           const ak_allocator* alloc, uint8_t** out_pixels, int* out_width,
                           int* out_height, char* msg, size_t msg_size) {
    static const uint8_t png_sig[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1A, '\n'};
    *out_pixels = NULL;
    *out_width = *out_height = 0;
    msg[0] = 0;
    if (data && size >= 8 && memcmp(data, png_sig, 8) == 0)
        return decode_png(data, size, budget, alloc, out_pixels, out_width, out_height, msg,
                          msg_size);
    if (data && size >= 3 && data[0] == 0xFF && data[1] == 0xD8 && data[2] == 0xFF) {
#ifdef AK_HAVE_JPEG
        return decode_jpeg(data, size, budget, alloc, out_pixels, out_width, out_height, msg,
                           msg_size);
#else
        snprintf(msg, msg_size,
                 "JPEG image, but this build has no JPEG decoder (libjpeg62-turbo-dev)");
        return AK_ERR_UNSUPPORTED;
#endif
    }
    snprintf(msg, msg_size, "%s", size == 0 ? "empty image" : "not a PNG or JPEG image");
    return AK_ERR_PARSE;
}

ak_result akp_image_encode_png(const uint8_t* rgba, int width, int height, uint8_t** out_data,
                               size_t* out_size) {
    *out_data = NULL;
    *out_size = 0;
    png_image pi;
    memset(&pi, 0, sizeof pi);
    pi.version = PNG_IMAGE_VERSION;
    pi.width = (png_uint_32)width;
    pi.height = (png_uint_32)height;
    pi.format = PNG_FORMAT_RGBA;
    png_alloc_size_t n = 0;
    if (!png_image_write_to_memory(&pi, NULL, &n, 0, rgba, (png_int_32)(width * 4), NULL) ||
        n == 0) {
        png_image_free(&pi);
        return AK_ERR_BAD_ARG;
    }
    uint8_t* buf = (uint8_t*)malloc(n);
    if (!buf) return AK_ERR_NO_MEMORY;
    if (!png_image_write_to_memory(&pi, buf, &n, 0, rgba, (png_int_32)(width * 4), NULL)) {
        png_image_free(&pi);
        free(buf);
        return AK_ERR_BAD_ARG;
    }
    png_image_free(&pi);
    *out_data = buf;
    *out_size = (size_t)n;
    return AK_OK;
}

/* ---- public -------------------------------------------------------------------------------- */

ak_result ak_io_image_decode(const void* data, size_t size, size_t memory_budget,
                             const ak_allocator* alloc, uint8_t** out_pixels, int* out_width,
                             int* out_height, ak_diag* diag) {
    if (out_pixels) *out_pixels = NULL;
    if (out_width) *out_width = 0;
    if (out_height) *out_height = 0;
    if ((!data && size) || !out_pixels || !out_width || !out_height) return AK_ERR_NULL_ARG;
    akp_budget b = {.limit = memory_budget ? memory_budget : AK_IO_DEFAULT_BUDGET, .used = 0};
    char msg[256];
    ak_result r = akp_image_decode((const uint8_t*)data, size, &b, alloc, out_pixels, out_width,
                                   out_height, msg, sizeof msg);
    if (r != AK_OK && diag) {
        memset(diag, 0, sizeof *diag);
        diag->byte_offset = -1;
        snprintf(diag->path, sizeof diag->path, "memory");
        snprintf(diag->message, sizeof diag->message, "%s", msg);
        akp_io_sanitize(diag->message, sizeof diag->message);
    }
    return r;
}

void ak_io_image_free(const ak_allocator* alloc, uint8_t* pixels) { akp_free(alloc, pixels); }

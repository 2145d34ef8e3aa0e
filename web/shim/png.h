/* Stand-in for libpng's <png.h> in the WebAssembly build: the browser page writes no PNG
 * files (the canvas shows the frames; screenshots come from the browser). It declares only
 * what src/terrain.c's 16-bit heightmap writer names, and png_create_write_struct fails, so
 * ak_terrain_write_png16 reports an I/O error as it does when libpng runs out of memory.
 * Never installed, never used natively. */
#ifndef ANIMKIT_WEB_PNG_H
#define ANIMKIT_WEB_PNG_H

#include <stdio.h>

typedef struct png_struct_web* png_structp;
typedef struct png_info_web* png_infop;
typedef const char* png_const_charp;
typedef unsigned char* png_bytep;
typedef void (*png_error_ptr)(png_structp, png_const_charp);

#define PNG_LIBPNG_VER_STRING "web-stub"
#define PNG_COLOR_TYPE_GRAY 0
#define PNG_INTERLACE_NONE 0
#define PNG_COMPRESSION_TYPE_DEFAULT 0
#define PNG_FILTER_TYPE_DEFAULT 0

static inline png_structp png_create_write_struct(const char* ver, void* err_ptr, png_error_ptr err_fn,
                                                  png_error_ptr warn_fn) {
    (void)ver, (void)err_ptr, (void)err_fn, (void)warn_fn;
    return NULL;
}
static inline png_infop png_create_info_struct(png_structp p) { (void)p; return NULL; }
static inline void png_destroy_write_struct(png_structp* p, png_infop* i) { (void)p, (void)i; }
static inline void* png_get_error_ptr(png_structp p) { (void)p; return NULL; }
static inline void png_init_io(png_structp p, FILE* f) { (void)p, (void)f; }
static inline void png_set_IHDR(png_structp p, png_infop i, unsigned w, unsigned h, int depth, int color, int interlace,
                                int compression, int filter) {
    (void)p, (void)i, (void)w, (void)h, (void)depth, (void)color, (void)interlace, (void)compression, (void)filter;
}
static inline void png_write_info(png_structp p, png_infop i) { (void)p, (void)i; }
static inline void png_write_row(png_structp p, const unsigned char* row) { (void)p, (void)row; }
static inline void png_write_end(png_structp p, png_infop i) { (void)p, (void)i; }

#endif

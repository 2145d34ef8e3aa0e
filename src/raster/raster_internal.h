/* Shared between the files of src/raster (never installed). */
#ifndef ANIMKIT_RASTER_INTERNAL_H
#define ANIMKIT_RASTER_INTERNAL_H

#include <animkit/raster.h>

/* The sample buffers of a target: colour RGBA8 (sRGB) and depth in [0, 1], both
 * width * height samples (the output size times the supersampling factor ss). */
typedef struct akp_raster_target {
    uint8_t* color;
    float* depth;
    int width, height, ss;
} akp_raster_target;

akp_raster_target akp_raster_target_of(ak_raster* raster);

#endif

/* Entry points of the two weight methods (desc already resolved and checked). */
#ifndef ANIMKIT_SKIN_WEIGHTS_INTERNAL_H
#define ANIMKIT_SKIN_WEIGHTS_INTERNAL_H

#include "skin_internal.h"

ak_result akp_weights_distance(const ak_weights_desc* d, const ak_allocator* alloc, uint16_t* out_joints,
                               float* out_weights);
ak_result akp_weights_heat(const ak_weights_desc* d, const ak_allocator* alloc, uint16_t* out_joints,
                           float* out_weights);
/* Whole file into a malloc'd buffer (caller frees). AK_ERR_IO, AK_ERR_NO_MEMORY. */
ak_result akp_read_file(const char* path, unsigned char** out, size_t* out_size);
/* Write size bytes to a new file at path: AK_OK or AK_ERR_IO. */
ak_result akp_write_file(const char* path, const unsigned char* buf, size_t size);

/* Number of palette entries the bones reference (max joint_index + 1). */
static inline size_t akp_bones_joint_count(ak_skin_bone_cspan bones) {
    size_t n = 0;
    for (size_t b = 0; b < bones.count; ++b)
        if ((size_t)bones.ptr[b].joint_index + 1 > n) n = (size_t)bones.ptr[b].joint_index + 1;
    return n;
}

/* Length scale of the bones: the largest bone length or bone coordinate magnitude. Distance
 * thresholds ("on the bone") are relative to it, never to the mesh's bounding box, which one
 * stray far vertex can blow up. 0 when every bone is a point at the origin. */
static inline double akp_bones_scale(ak_skin_bone_cspan bones) {
    double scale = 0.0;
    for (size_t b = 0; b < bones.count; ++b) {
        const ak_skin_bone* bone = &bones.ptr[b];
        const float c[6] = {bone->head.x, bone->head.y, bone->head.z, bone->tail.x, bone->tail.y, bone->tail.z};
        for (int i = 0; i < 6; ++i) scale = fmax(scale, fabs((double)c[i]));
        scale = fmax(scale, (double)ak_vec3_length(ak_vec3_sub(bone->tail, bone->head)));
    }
    return scale;
}

#endif

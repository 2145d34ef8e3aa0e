/* Inverse-distance weights: w_ij = (1 / d_ij)^n normalised over joints, d_ij the distance from
 * vertex i to the nearest segment owned by joint j. Computed as (d_min / d_ij)^n so that the
 * largest term is exactly 1: no overflow near a bone and no underflow to 0/0 far away. */
#include "weights_internal.h"

ak_result akp_weights_distance(const ak_weights_desc* d, const ak_allocator* alloc, uint16_t* out_joints,
                               float* out_weights) {
    const size_t n = d->positions.count, jc = akp_bones_joint_count(d->bones);
    const uint32_t k = d->max_influences;
    double* dist2 = (double*)akp_alloc(alloc, 2 * jc * sizeof(double));
    if (!dist2) return AK_ERR_NO_MEMORY;
    double* dense = dist2 + jc;

    /* Distances below this count as "on the bone" (relative to the bones, see akp_bones_scale). */
    double scale = akp_bones_scale(d->bones);
    double eps2 = (scale > 0.0 ? scale * 1e-7 : 1e-12);
    eps2 *= eps2;
    const double half_power = 0.5 * (double)d->distance_power;

    for (size_t i = 0; i < n; ++i) {
        for (size_t j = 0; j < jc; ++j) dist2[j] = HUGE_VAL;
        for (size_t b = 0; b < d->bones.count; ++b) {
            const ak_skin_bone* bone = &d->bones.ptr[b];
            double d2 = akp_segment_dist_sq(d->positions.ptr[i], bone->head, bone->tail, NULL);
            if (d2 < dist2[bone->joint_index]) dist2[bone->joint_index] = d2;
        }
        double dmin2 = HUGE_VAL;
        uint16_t nearest = 0;
        for (size_t j = 0; j < jc; ++j)
            if (dist2[j] < dmin2) {
                dmin2 = dist2[j];
                nearest = (uint16_t)j;
            }
        for (size_t j = 0; j < jc; ++j) {
            if (dist2[j] == HUGE_VAL) dense[j] = 0.0; /* joint owns no bone */
            else if (dmin2 <= eps2) dense[j] = dist2[j] <= eps2 ? 1.0 : 0.0;
            else dense[j] = pow(dmin2 / dist2[j], half_power);
        }
        akp_weights_finish(dense, jc, k, d->min_weight, nearest, out_joints + i * k, out_weights + i * k);
    }
    akp_free(alloc, dist2);
    return AK_OK;
}

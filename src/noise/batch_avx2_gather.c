/* The AVX2 fractal kernels with vpgatherdd permutation lookups: batch_avx2.c compiled again
 * with AKP_NOISE_AVX2_GATHER; chosen where akp_noise_avx2_gather_preferred says so. */
#define AKP_NOISE_AVX2_GATHER
#include "batch_avx2.c"

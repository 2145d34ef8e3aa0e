/* The AVX-512 fractal kernels with byte-permute permutation lookups (AVX-512 BW and VBMI):
 * batch_avx512.c compiled again with AKP_NOISE_VBMI; see there. */
#define AKP_NOISE_VBMI
#include "batch_avx512.c"

/* FastNoiseLite side (bench/vs_noise): plain per-point loop. kind 0 Perlin, 1 OpenSimplex2,
 * 3 Value, 4 Cellular distance (Euclidean, F1), 5 Cellular cell value. */
#define FNL_IMPL
#include "FastNoiseLite.h"
void fnl_run(int kind, int octaves, int dims, int n, const float* x, const float* y, const float* z, float* out) {
    fnl_state s = fnlCreateState();
    s.seed = 1337;
    s.frequency = 1.0f;
    s.noise_type = kind == 0 ? FNL_NOISE_PERLIN : kind == 1 ? FNL_NOISE_OPENSIMPLEX2 : kind == 3 ? FNL_NOISE_VALUE : FNL_NOISE_CELLULAR;
    s.cellular_distance_func = FNL_CELLULAR_DISTANCE_EUCLIDEAN;
    s.cellular_return_type = kind == 5 ? FNL_CELLULAR_RETURN_TYPE_CELLVALUE : FNL_CELLULAR_RETURN_TYPE_DISTANCE;
    s.fractal_type = octaves > 1 ? FNL_FRACTAL_FBM : FNL_FRACTAL_NONE;
    s.octaves = octaves; s.lacunarity = 2.0f; s.gain = 0.5f; s.weighted_strength = 0.0f;
    if (dims == 2) for (int i = 0; i < n; ++i) out[i] = fnlGetNoise2D(&s, x[i], y[i]);
    else for (int i = 0; i < n; ++i) out[i] = fnlGetNoise3D(&s, x[i], y[i], z[i]);
}

/* FastNoise2 side of bench/vs_noise: Perlin, Simplex, Value, CellularDistance (Euclidean, F1
 * only) and CellularValue (the nearest cell's value), GenPositionArray2D/3D over SoA arrays. */
#include <FastNoise/FastNoise.h>
extern "C" {
/* kind 0 Perlin, 1 Simplex, 3 Value, 4 CellularDistance F1 Euclidean, 5 CellularValue; simd 0 Max, 1 AVX2 */
static FastNoise::SmartNode<> nodes[6][2][2];
static FastNoise::SmartNode<> get(int kind, int octaves, int simd) {
    int o = octaves > 1;
    if (nodes[kind][o][simd]) return nodes[kind][o][simd];
    FastSIMD::FeatureSet fs = simd == 0 ? FastSIMD::FeatureSet::Max : FastSIMD::FeatureSet::AVX2;
    FastNoise::SmartNode<> src;
    if (kind == 0) { auto p = FastNoise::New<FastNoise::Perlin>(fs); p->SetScale(1.0f); src = p; }
    else if (kind == 1) { auto p = FastNoise::New<FastNoise::Simplex>(fs); p->SetScale(1.0f); src = p; }
    else if (kind == 3) { auto p = FastNoise::New<FastNoise::Value>(fs); p->SetScale(1.0f); src = p; }
    else if (kind == 4) {
        auto p = FastNoise::New<FastNoise::CellularDistance>(fs); p->SetScale(1.0f);
        p->SetDistanceFunction(FastNoise::DistanceFunction::Euclidean);
        p->SetDistanceIndex0(0); p->SetDistanceIndex1(0);
        p->SetReturnType(FastNoise::CellularDistance::ReturnType::Index0);
        src = p;
    } else {
        auto p = FastNoise::New<FastNoise::CellularValue>(fs); p->SetScale(1.0f);
        p->SetDistanceFunction(FastNoise::DistanceFunction::Euclidean);
        src = p;
    }
    if (o) {
        auto f = FastNoise::New<FastNoise::FractalFBm>(fs);
        f->SetSource(src); f->SetOctaveCount(octaves); f->SetGain(0.5f); f->SetLacunarity(2.0f);
        src = f;
    }
    return nodes[kind][o][simd] = src;
}
const char* fn2_simd_name(int kind, int simd) {
    switch (get(kind, 1, simd)->GetActiveFeatureSet()) {
    case FastSIMD::FeatureSet::AVX512: return "AVX512";
    case FastSIMD::FeatureSet::AVX2: return "AVX2";
    default: return "other";
    }
}
void fn2_run(int kind, int octaves, int simd, int dims, int n, const float* x, const float* y, const float* z, float* out) {
    if (dims == 2) get(kind, octaves, simd)->GenPositionArray2D(out, n, x, y, 0, 0, 1337);
    else get(kind, octaves, simd)->GenPositionArray3D(out, n, x, y, z, 0, 0, 0, 1337);
}
}

#!/usr/bin/env bash
# bench/vs_noise/run.sh: ../shared/peers/noise/run.sh with this directory's noise_bench.c (the
# batch job on each SIMD path, scalar, AVX2 and AVX-512, chosen with job.simd_limit). Same
# arguments, from the project root after a Release build with -DBUILD_SHARED_LIBS=OFF:
#   bench/vs_noise/run.sh [BUILD_DIR=build] [ROUNDS=5] [FILTER]
# FastNoise2 is built once into BUILD_DIR/vs_noise (5-9 minutes on 2 cores).
set -euo pipefail
MINE=$(cd "$(dirname "$0")" && pwd)
HERE=$(cd "$MINE/../../../shared/peers/noise" && pwd)
INC=$PWD/include
BUILD=$(cd "${1:-build}" && pwd); ROUNDS=${2:-5}; FILTER=${3:-}
LIB=$(find "$BUILD" -name 'libanimkit.a' | head -1)
[[ -n $LIB ]] || { echo "no libanimkit.a under $BUILD (build with -DBUILD_SHARED_LIBS=OFF)" >&2; exit 2; }
OUT=${VS_NOISE_DIR:-$BUILD/vs_noise}; mkdir -p "$OUT"; cd "$OUT"
if [[ ! -f fn2/Release/lib/libFastNoise.a && ! -f fn2/lib/libFastNoise.a ]]; then
  cmake -S "$HERE/FastNoise2" -B fn2 -DCMAKE_BUILD_TYPE=Release -DFASTNOISE2_TOOLS=OFF -DFASTNOISE2_TESTS=OFF \
        -DFASTNOISE2_UTILITY=OFF -DCPM_FastSIMD_SOURCE="$HERE/FastSIMD" -DCMAKE_CXX_FLAGS=-w >fn2-configure.log
  cmake --build fn2 -j "$(nproc)" >fn2-build.log
fi
FN2LIB=$(find fn2 -name 'libFastNoise.a' | head -1)
FSI=$(find fn2 -type d -path '*FastSIMD_FastNoise/include' | head -1)
gcc -O3 -march=native -fwrapv -DNDEBUG -I"$HERE" -c "$HERE/fnl_part.c" -o fnl_part.o
gcc -O3 -fwrapv -DNDEBUG -I"$HERE" -c "$HERE/fnl_generic.c" -o fnl_generic.o
g++ -O3 -march=native -DNDEBUG -std=c++17 -I"$HERE/FastNoise2/include" -I"$HERE/FastSIMD/include" -I"$FSI" -c "$HERE/fn2_part.cpp" -o fn2_part.o
gcc -O3 -march=native -std=gnu11 -I"$INC" -DHAVE_FN2 -c "$MINE/noise_bench.c" -o noise_bench_ak.o
g++ -o vs_noise_ak noise_bench_ak.o fnl_part.o fnl_generic.o fn2_part.o "$FN2LIB" "$LIB" -lm -lpthread
./vs_noise_ak "$ROUNDS" "$FILTER"

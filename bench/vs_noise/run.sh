#!/bin/bash
# Every noise basis of animkit (Perlin, simplex, value, Worley; per-point call, scalar job, AVX2
# and AVX-512 jobs) beside FastNoiseLite (per point) and FastNoise2 (AVX2, AVX-512) on the same
# 1M points, 1 thread, thread CPU time, interleaved rounds; prints the median ns per point and
# the median per-round ratios against the peer, and checks every SIMD job against the scalar job.
# Needs ../shared/peers/noise (FastNoiseLite.h, FastNoise2, FastSIMD; or NOISE_PEERS) and a
# Release build with a static libanimkit.a. FastNoise2 is built once (5-9 min) into
# BUILD/vs_noise/fn2, where the peers' own run.sh puts it too. Usage, from the project root:
#   bench/vs_noise/run.sh [BUILD_DIR] [ROUNDS] [GROUP]   (GROUP: a substring such as worley3)
# A/B against another build: AB_BASE=DIR, DIR holding that build's src/noise objects (*.o, e.g.
# a copy of BUILD/CMakeFiles/ak_noise.dir/src/noise); its jobs are timed in the same rounds.
set -euo pipefail
HERE=$(cd "$(dirname "$0")" && pwd)
ROOT=$(cd "$HERE/../.." && pwd)
P=${NOISE_PEERS:-$ROOT/../shared/peers/noise}
[[ -f $P/FastNoiseLite.h ]] || { echo "no FastNoiseLite.h under $P (set NOISE_PEERS)"; exit 1; }
BUILD=$(cd "${1:-build}" && pwd); ROUNDS=${2:-5}; ONLY=${3:-}
LIB=$(find "$BUILD" -maxdepth 2 -name 'libanimkit.a' | head -1); [[ -n $LIB ]] || { echo "no libanimkit.a under $BUILD"; exit 1; }
OUT=${VS_NOISE_DIR:-$BUILD/vs_noise}; mkdir -p "$OUT"; cd "$OUT"
if [[ -z $(find fn2 -name 'libFastNoise.a' 2>/dev/null | head -1) ]]; then
  cmake -S "$P/FastNoise2" -B fn2 -DCMAKE_BUILD_TYPE=Release -DFASTNOISE2_TOOLS=OFF -DFASTNOISE2_TESTS=OFF \
        -DFASTNOISE2_UTILITY=OFF -DCPM_FastSIMD_SOURCE="$P/FastSIMD" -DCMAKE_CXX_FLAGS=-w >fn2-configure.log
  cmake --build fn2 -j "$(nproc)" >fn2-build.log
fi
FN2LIB=$(find fn2 -name 'libFastNoise.a' | head -1)
FSI=$(find fn2 -type d -path '*FastSIMD_FastNoise/include' | head -1)
gcc -O3 -march=native -fwrapv -DNDEBUG -I"$P" -c "$HERE/fnl_part.c" -o fnl_all.o
g++ -O3 -march=native -DNDEBUG -std=c++17 -I"$P/FastNoise2/include" -I"$P/FastSIMD/include" -I"$FSI" -c "$HERE/fn2_part.cpp" -o fn2_all.o
OLD=(); AB=()
if [[ -n ${AB_BASE:-} ]]; then
  ld -r -o old_noise.o "$AB_BASE"/*.o
  nm -g --defined-only old_noise.o | awk '{print $3, "old_" $3}' > old_noise.map
  objcopy --redefine-syms=old_noise.map old_noise.o
  OLD=(old_noise.o); AB=(-DAK_AB_OLD)
fi
gcc -O3 -march=native -std=gnu11 "${AB[@]}" -I"$ROOT/include" -c "$HERE/noise_bench.c" -o noise_bench_all.o
g++ -o vs_noise_all noise_bench_all.o fnl_all.o fn2_all.o "${OLD[@]}" "$FN2LIB" "$LIB" -lm -lpthread
./vs_noise_all "$ROUNDS" "$ONLY"

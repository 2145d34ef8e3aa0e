#!/usr/bin/env bash
# bench/vs_ozz/run.sh: ../shared/peers/vs_ozz/run.sh with this directory's ak_part.c, driver.cpp
# and harness.h (copies of the shared ones): the skinning jobs, FK and clip sampling take their
# SIMD limit from AK_VS_OZZ_SIMD=scalar|avx2|avx512, and the skinning rounds are long (each side
# runs >= AK_VS_OZZ_ROUND_MS per round, default 150) with the per-round spread of the ratios
# printed. Same arguments as the shared run.sh:
#   AK_VS_OZZ_SIMD=avx2 bench/vs_ozz/run.sh build 1000000 11 s
# AK_VS_OZZ_ROWS=P+N keeps only the skinning rows with normals; AK_VS_OZZ_ACCESS=seq only the
# sequential animation rows (see driver.cpp).
# Side-by-side benchmark: animkit (public API, C) against ozz-animation (C++), in one process,
# alternating the two libraries every round. Run from the project root after a Release build:
#   ../shared/peers/vs_ozz/run.sh [BUILD_DIR=build] [VERTICES=1000000] [ROUNDS=11] [WHAT=sai]
# WHAT: s skinning (LBS K=1,2,4,8 P and P+N, DQS, CoR, 2 threads), a animation (sample+FK of 60
# joints, sequential and random, with and without ozz iframes), i two-bone IK.
# ozz is built once into BUILD_DIR/peers/ozz (about a minute on 2 cores).
set -euo pipefail
MINE=$(cd "$(dirname "$0")" && pwd)
HERE=$(cd "${VS_OZZ_PEER:-$MINE/../../../shared/peers/vs_ozz}" && pwd) # VS_OZZ_PEER: the peers' vs_ozz/
ROOT=$PWD
B=$(cd "${1:-build}" && pwd)
N=${2:-1000000}; R=${3:-11}; W=${4:-sai}
O=$B/peers/ozz
[[ -f $B/libanimkit.a ]] || { echo "no $B/libanimkit.a: build the project (Release) first" >&2; exit 2; }
mkdir -p "$B/peers"
if [[ ! -f $O/src/geometry/runtime/libozz_geometry_r.a ]]; then
  cmake -S "$HERE/../ozz-animation" -B "$O" -DCMAKE_BUILD_TYPE=Release -Dozz_build_samples=OFF -Dozz_build_tests=OFF \
    -Dozz_build_fbx=OFF -Dozz_build_gltf=OFF -Dozz_build_howtos=OFF -Dozz_build_tools=OFF \
    -DCMAKE_CXX_FLAGS="-O3 -march=native" >"$B/peers/ozz-configure.log" 2>&1
  cmake --build "$O" -j"$(nproc)" --target ozz_base ozz_animation ozz_animation_offline ozz_geometry >"$B/peers/ozz-build.log" 2>&1
fi
mkdir -p "$B/peers/vs_ozz_simd"; cd "$B/peers/vs_ozz_simd"
cc -O2 -std=c11 -I"$ROOT/include" -I"$MINE" -c "$MINE/ak_part.c" -o ak_part.o
c++ -O3 -march=native -DNDEBUG -std=c++17 -I"$HERE/../ozz-animation/include" -I"$MINE" -c "$MINE/driver.cpp" -o driver.o
c++ -o vs_ozz driver.o ak_part.o "$B/libanimkit.a" "$O/src/geometry/runtime/libozz_geometry_r.a" \
  "$O/src/animation/offline/libozz_animation_offline_r.a" "$O/src/animation/runtime/libozz_animation_r.a" \
  "$O/src/base/libozz_base_r.a" ${AK_LIBS:--lcholmod -lpng -lgif -lassimp -lcjson} -lm -lpthread
exec ./vs_ozz "$N" "$R" "$W"

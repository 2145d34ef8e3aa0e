#!/bin/bash
# animkit's neighbour grid (pairs and CSR lists) beside CompactNSearch; see main.cpp.
# Needs the CompactNSearch sources of ../shared/peers/nsearch (or CNS_DIR) and a Release build.
# Usage, from the project root:
#   bench/vs_nsearch/run.sh [BUILD_DIR] [SIDE] [ROUNDS] [z]   (SIDE 38: 55k points, 80: 512k, 160: 4.1M)
set -euo pipefail
HERE=$(cd "$(dirname "$0")" && pwd)
ROOT=$(cd "$HERE/../.." && pwd)
CNS=${CNS_DIR:-$ROOT/../shared/peers/nsearch/CompactNSearch}
[[ -d $CNS ]] || { echo "no CompactNSearch at $CNS (set CNS_DIR)"; exit 1; }
BUILD=$(cd "${1:-build}" && pwd); SIDE=${2:-38}; ROUNDS=${3:-5}; Z=${4:-}
LIB=$(find "$BUILD" -maxdepth 2 -name 'libanimkit.a' | head -1); [[ -n $LIB ]] || { echo "no libanimkit.a under $BUILD"; exit 1; }
OUT=${VS_NSEARCH_DIR:-$BUILD/vs_nsearch2}; mkdir -p "$OUT"; cd "$OUT"
[[ cns.o -nt "$CNS/src/CompactNSearch.cpp" ]] || g++ -O3 -march=native -DNDEBUG -fopenmp -ffp-contract=off -std=c++17 -I"$CNS/include" -c "$CNS/src/CompactNSearch.cpp" -o cns.o
gcc -O2 -std=c11 -D_POSIX_C_SOURCE=200809L -Wall -Wextra -I"$ROOT/include" -c "$HERE/ak_side.c" -o ak_side.o
g++ -O2 -march=native -DNDEBUG -fopenmp -std=c++17 -I"$CNS/include" -c "$HERE/main.cpp" -o main.o
g++ -fopenmp -o vs_nsearch main.o ak_side.o cns.o "$LIB" -lm -lpthread
OMP_WAIT_POLICY=passive ./vs_nsearch "$SIDE" "$ROUNDS" $Z

#!/bin/bash
# animkit's per-point noise functions (src/noise/perlin.c, bases.c, fractal.c) from a git
# revision (default main) beside the working tree's, compiled with the same flags into one
# process (the revision's symbols renamed old_*, the tree's new_*): checks every output and
# gradient bit over many points (random, lattice-aligned, signed zeros, integers and their
# neighbours, near the 2^24 limit, NaN and infinities) and times the per-point calls,
# interleaved rounds, thread CPU time. Usage, from the project root after a Release build:
#   bench/vs_noise/vs_rev.sh [REV] [ROUNDS] [CHECK_POINTS] [BUILD_DIR]   (EXTRA_CFLAGS=-march=native ...)
set -euo pipefail
HERE=$(cd "$(dirname "$0")" && pwd)
ROOT=$(cd "$HERE/../.." && pwd)
REV=${1:-main}; ROUNDS=${2:-7}; CHECK=${3:-2000000}; BUILD=$(cd "${4:-$ROOT/build}" && pwd)
LIB=$(find "$BUILD" -maxdepth 2 -name 'libanimkit.a' | head -1); [[ -n $LIB ]] || { echo "no libanimkit.a under $BUILD"; exit 1; }
OUT=$(mktemp -d); trap 'rm -rf "$OUT"' EXIT
mkdir -p "$OUT/old"
git -C "$ROOT" archive "$REV" src/noise include | tar -x -C "$OUT/old"
CFLAGS="-O3 -DNDEBUG -std=c11 -Wall -Wextra -Wpedantic -fno-math-errno -ffp-contract=off -D_POSIX_C_SOURCE=200809L ${EXTRA_CFLAGS:-}"
for side in old new; do
  src=$([[ $side == old ]] && echo "$OUT/old" || echo "$ROOT")
  objs=()
  for f in perlin bases fractal; do
    gcc $CFLAGS -I"$src/include" -I"$src/src/noise" -c "$src/src/noise/$f.c" -o "$OUT/${side}_$f.o"
    objs+=("$OUT/${side}_$f.o")
  done
  ld -r -o "$OUT/$side.o" "${objs[@]}"
  nm -g --defined-only "$OUT/$side.o" | awk -v p="${side}_" '{print $3, p $3}' > "$OUT/$side.map"
  objcopy --redefine-syms="$OUT/$side.map" "$OUT/$side.o"
done
gcc -O2 -std=gnu11 ${EXTRA_CFLAGS:-} -I"$ROOT/include" -c "$HERE/vs_rev.c" -o "$OUT/vs_rev.o"
gcc -o "$OUT/vs_rev" "$OUT/vs_rev.o" "$OUT/old.o" "$OUT/new.o" "$LIB" -lm -lpthread
echo "old: $REV ($(git -C "$ROOT" rev-parse --short "$REV")), new: working tree of $(git -C "$ROOT" rev-parse --short HEAD)$(git -C "$ROOT" diff --quiet HEAD -- src/noise include || echo ' + uncommitted changes'); flags: $CFLAGS"
"$OUT/vs_rev" "$ROUNDS" "$CHECK"

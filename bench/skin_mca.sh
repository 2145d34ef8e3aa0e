#!/bin/sh
# Static model of the AVX2 skinning kernels: compiles bench/skin_mca.c (one 8-vertex block of
# LBS positions, LBS positions+normals, DQS and CoR, 4 influences) to assembly with the
# library's Release flags and runs llvm-mca on it for one CPU model (default znver3, the Zen 3
# core of docs/BENCHMARKS.md). Prints per block: the resource-bound throughput (the fewest
# cycles the block's instructions can take on that core's pipes, however well scheduled), the
# cycles of llvm-mca's simulation, and the load of the four FP pipes.
# Usage: bench/skin_mca.sh [cpu] [GHz]    e.g. bench/skin_mca.sh znver3 2.85
set -eu
root=$(cd "$(dirname "$0")/.." && pwd)
cpu=${1:-znver3}
ghz=${2:-2.85}
mca=$(command -v llvm-mca || command -v llvm-mca-14 || true)
if [ -z "$mca" ]; then
    echo "SKIP: llvm-mca not found (Debian package llvm)"
    exit 0
fi
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
${CC:-cc} -O3 -DNDEBUG -fno-math-errno -std=c11 -DAK_BUILDING -D_POSIX_C_SOURCE=200809L \
    -I"$root/include" -I"$root/src" -S -o "$tmp/k.s" "$root/bench/skin_mca.c"
"$mca" -mcpu="$cpu" -iterations=200 "$tmp/k.s" >"$tmp/mca.txt" 2>&1
# llvm-mca models a region as straight-line code: a loop the compiler kept inside one is
# counted for a single pass, so such a region's figures understate it
loops=$(awk '/LLVM-MCA-BEGIN/ { r = $NF; split("", seen) } /LLVM-MCA-END/ { r = "" }
    r != "" && /^\.L[0-9A-Za-z_]+:/ { seen[substr($1, 1, length($1) - 1)] = 1 }
    r != "" && $1 ~ /^j/ && ($2 in seen) && !(r in out) { out[r] = 1; printf "%s ", r }' "$tmp/k.s")
echo "llvm-mca ($("$mca" --version | sed -n 's/.*LLVM version \([0-9.]*\).*/\1/p')) -mcpu=$cpu, one block = 8 vertices, 4 influences; M vertices/s at $ghz GHz"
awk -v ghz="$ghz" '
    /Code Region - / { name = $NF }
    /^Iterations:/ { it = $2 }
    /^Total Cycles:/ { cyc = $3 }
    /^Total uOps:/ { uops = $3 }
    /^Block RThroughput:/ { rt = $3 }
    /^\[[0-9.]+\] +- / { res[$1] = $3 }
    /^Resource pressure per iteration:/ { getline hdr; getline val; nh = split(hdr, h, " "); split(val, v, " ");
        fp = ""; for (i = 1; i <= nh; ++i) if (res[h[i]] ~ /FPP[0-3]$/) fp = fp sprintf(" %6.1f", v[i]);
        if (!printed++) printf "%-15s %9s %9s %9s %9s %9s  %s\n", "block", "uops", "bound", "M vert/s", "simulated", "M vert/s", "FP pipes 0-3 (cycles)";
        printf "%-15s %9.0f %9.1f %9.0f %9.1f %9.0f  %s\n", name, uops / it, rt, 8 * ghz * 1000 / rt, cyc / it, 8 * ghz * 1000 / (cyc / it), fp }
' "$tmp/mca.txt"
[ -z "$loops" ] || echo "warning: the compiler kept a loop inside: $loops(llvm-mca counts one pass of it: figures too low)"

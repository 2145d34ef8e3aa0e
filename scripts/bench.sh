#!/usr/bin/env bash
# Runs every benchmark built under BUILD/bench and the side-by-side harnesses of ../shared/peers,
# saves each program's full output under BUILD/bench-results/NAME.txt and writes the summary
# table BUILD/bench-results/SUMMARY.md (scripts/bench_summary.py). From the project root, after
# a Release build:
#   scripts/bench.sh [BUILD_DIR=build]                  (`make bench`)
#   AK_BENCH_QUICK=1 scripts/bench.sh [BUILD_DIR]       (`make bench-quick`)
# Quick mode runs each program with the smallest sizes and fewest rounds it accepts, and exports
# AK_BENCH_QUICK=1 to it (bench_clock.h's bench_quick(): fewer rounds or a slow fixed-size part
# left out): it checks the pipeline in about two minutes; its numbers are not measurements. It runs a peer harness only
# when the peer library is already built (the full run builds ozz once, ~1 min, and FastNoise2
# once, 5-9 min, under BUILD). AK_BENCH_PEERS=0 leaves the peers out; AK_BENCH_PEERS_DIR sets
# where the peers are (default ../shared/peers; a git worktree elsewhere points it at the main
# checkout's); AK_BENCH_ONLY='bench_ik vs_ozz' runs only the named programs;
# AK_BENCH_NSEARCH_SIDES (default "38 80": 55k and 512k points) sets the neighbour-search sizes.
# Also run when built: bench_rigid_vs_bullet (needs libbullet-dev) and vs_rvo2 (needs the RVO2
# peer at configure time, -DAK_RVO2_DIR); the Python benches when `make python` put the module
# in python/animkit (bench_batch_dask.py also needs dask.distributed). Each one missing is
# skipped with a line saying why; a skip never fails the run, a failed program does.
set -uo pipefail
B=${1:-build}
QUICK=${AK_BENCH_QUICK:-0}
[[ $QUICK == 0 ]] && QUICK=
[[ -n $QUICK ]] && export AK_BENCH_QUICK=1
PEERS_ON=${AK_BENCH_PEERS:-1}
ONLY=${AK_BENCH_ONLY:-}
ROOT=$PWD
# The shared assets (CesiumMan, the CMU BVH files): benches without them skip those parts, and
# bench_retarget, which needs them, is skipped.
ASSETS=${ANIMKIT_ASSETS:-$ROOT/../shared/assets}
PEERS=${AK_BENCH_PEERS_DIR:-$ROOT/../shared/peers}
[[ -d $PEERS ]] && PEERS=$(cd "$PEERS" && pwd)
[[ -d $B/bench ]] || { echo "bench.sh: no $B/bench: build the project first (make build, Release)" >&2; exit 2; }
B=$(cd "$B" && pwd)
OUT=$B/bench-results
rm -rf "$OUT"
mkdir -p "$OUT"
LOG=$OUT/run.log
: >"$LOG"

wanted() { [[ -z $ONLY || " $ONLY " == *" $1 "* ]]; }

# Quick arguments: the smallest sizes / fewest rounds each bench accepts (its usage line).
# A bench not listed runs with its defaults in both modes.
quick_args() {
    case $1 in
        bench_batch) echo "3" ;;               # repeats
        bench_blendshape) echo "3000 5 10" ;;  # vertices, targets, moved %
        bench_boids) echo "--quick" ;;         # 5 steps instead of 21, no 1M-agent run
        bench_cloth) echo "5" ;;               # frames
        bench_fluid) echo "2000 2 1 all" ;;    # particles, timed steps, rounds, solvers
        bench_ik) echo "200" ;;                # targets per chain
        bench_particles) echo "10000" ;;       # particles of the step (the grid part is fixed)
        bench_retarget) echo "1" ;;            # repetitions
        bench_rigid_vs_bullet) echo "--layers 6 --spheres 300 --ragdolls 3 --steps 20 --substeps 10" ;;
        bench_scaling) echo "--quick" ;;       # small sizes, few steps (1 and 2 threads)
        bench_skin) echo "20000" ;;            # vertices (the triad and in-cache parts are fixed)
        *) echo "" ;;
    esac
}

# run NAME COMMAND...: runs the command, output (stdout and stderr) to OUT/NAME.txt, one line in run.log.
run() {
    local name=$1
    shift
    local t0 t1 rc
    echo "== $name: $*"
    t0=$(date +%s.%N)
    "$@" >"$OUT/$name.txt" 2>&1
    rc=$?
    t1=$(date +%s.%N)
    local secs
    secs=$(awk -v a="$t0" -v b="$t1" 'BEGIN { printf "%.1f", b - a }')
    printf '%s\t%s\t%s\t%s\n' "$name" "$rc" "$secs" "$*" >>"$LOG"
    if [[ $rc -ne 0 ]]; then
        echo "   FAILED (exit $rc, ${secs} s): last lines of $OUT/$name.txt:"
        tail -5 "$OUT/$name.txt" | sed 's/^/   | /'
    else
        echo "   ok (${secs} s) -> $OUT/$name.txt"
    fi
}

# skip NAME WHY: one clear line on the terminal and in run.log.
skip() {
    echo "== $1: SKIP: $2"
    printf '%s\tskip\t-\t%s\n' "$1" "$2" >>"$LOG"
}

{
    echo "date: $(date -u '+%Y-%m-%d %H:%M UTC')"
    if [[ -n $QUICK ]]; then echo "mode: quick (smallest sizes: checks the pipeline, not a measurement)"; else echo "mode: full"; fi
    echo "commit: $(git -C "$ROOT" rev-parse --short HEAD 2>/dev/null || echo unknown)$(git -C "$ROOT" diff --quiet HEAD 2>/dev/null || echo ' (with local changes)')"
    echo "cpu: $(grep -m1 'model name' /proc/cpuinfo 2>/dev/null | sed 's/.*: //')"
    echo "cores: $(nproc 2>/dev/null)"
    echo "simd: $(grep -m1 '^flags' /proc/cpuinfo 2>/dev/null | tr ' ' '\n' | grep -E '^(sse4_2|avx|avx2|fma|avx512f|avx512bw|avx512dq|avx512vl)$' | tr '\n' ' ')"
    echo "compiler: $(grep -m1 'CMAKE_C_COMPILER:' "$B/CMakeCache.txt" 2>/dev/null | sed 's/.*=//') $(grep -m1 'CMAKE_BUILD_TYPE:' "$B/CMakeCache.txt" 2>/dev/null | sed 's/.*=//')"
    echo "load at start: $(cut -d' ' -f1-3 /proc/loadavg 2>/dev/null)"
} >"$OUT/machine.txt"
cat "$OUT/machine.txt"

# 1. The benchmarks of bench/ (whatever bench_* the build has).
found=0
for exe in "$B"/bench/bench_*; do
    [[ -x $exe && -f $exe ]] || continue
    found=1
    name=$(basename "$exe")
    wanted "$name" || continue
    if [[ $name == bench_retarget && ! -f $ASSETS/bvh/01_01.bvh ]]; then
        skip "$name" "no $ASSETS/bvh/01_01.bvh (set ANIMKIT_ASSETS to the shared assets)"
        continue
    fi
    args=
    [[ -n $QUICK ]] && args=$(quick_args "$name")
    # bench_batch writes its jobs' outputs under the current folder: keep them out of the tree.
    cwd=()
    [[ $name == bench_batch ]] && cwd=(env -C "$OUT")
    # shellcheck disable=SC2086
    run "$name" "${cwd[@]}" "$exe" $args
done
[[ $found == 1 ]] || echo "bench.sh: no benchmark programs in $B/bench (configure with -DAK_BUILD_BENCH=ON)"
if [[ $found == 1 && ! -x $B/bench/bench_rigid_vs_bullet ]] && wanted bench_rigid_vs_bullet; then
    skip bench_rigid_vs_bullet "not built: Bullet 3 not found by pkg-config at configure time (apt-get install libbullet-dev)"
fi

# 1b. animkit crowd beside RVO2 (bench/vs_rvo2, built when the RVO2 peer was there at configure time).
if [[ -x $B/bench/vs_rvo2 ]]; then
    if [[ -n $QUICK ]]; then
        wanted vs_rvo2_agree && run vs_rvo2_agree "$B/bench/vs_rvo2" agree 50
        wanted vs_rvo2_time && run vs_rvo2_time "$B/bench/vs_rvo2" time 1000
        wanted vs_rvo2_work && run vs_rvo2_work "$B/bench/vs_rvo2" work 1000
    else
        wanted vs_rvo2_agree && run vs_rvo2_agree "$B/bench/vs_rvo2" agree
        wanted vs_rvo2_time && run vs_rvo2_time "$B/bench/vs_rvo2" time 1000 10000 100000
        wanted vs_rvo2_work && run vs_rvo2_work "$B/bench/vs_rvo2" work 10000
    fi
elif wanted vs_rvo2_time; then
    skip vs_rvo2 "not built: no RVO2 peer at configure time (-DAK_RVO2_DIR=.../peers/rvo2, now $PEERS/rvo2)"
fi

# 1c. The Python benches (bench/*.py), with the module `make python` puts in python/animkit
# (or the build's own copy under BUILD/python).
if wanted bench_python || wanted bench_batch_dask; then
    PY=/usr/bin/python3
    PYDIR=
    for d in "$ROOT/python" "$B/python"; do
        if [[ -x $PY ]] && PYTHONPATH=$d $PY -c 'import animkit._core' >/dev/null 2>&1; then PYDIR=$d; break; fi
    done
    if [[ ! -x $PY ]]; then
        skip bench_python "no /usr/bin/python3"
    elif [[ -z $PYDIR ]]; then
        skip bench_python "no importable Python module in python/animkit or $B/python (make python; needs numpy)"
    else
        wanted bench_python && run bench_python env PYTHONPATH="$PYDIR" $PY "$ROOT/bench/bench_python.py"
        if ! wanted bench_batch_dask; then
            :
        elif ! PYTHONPATH=$PYDIR $PY -c 'import dask.distributed' >/dev/null 2>&1; then
            skip bench_batch_dask "no dask.distributed for /usr/bin/python3"
        elif [[ -n $QUICK ]]; then
            run bench_batch_dask env PYTHONPATH="$PYDIR" $PY "$ROOT/bench/bench_batch_dask.py" 8 80x60
        else
            run bench_batch_dask env PYTHONPATH="$PYDIR" $PY "$ROOT/bench/bench_batch_dask.py" 48 640x480
        fi
    fi
fi

# 2. The side-by-side harnesses (../shared/peers/*/run.sh, arguments from each run.sh's usage line).
peer_lib_missing() { # prints why the harness cannot run, or nothing
    [[ -f $B/libanimkit.a ]] || { echo "no $B/libanimkit.a (build the animkit_static target)"; return; }
    [[ -d $PEERS ]] || { echo "no $PEERS"; return; }
}
if [[ $PEERS_ON == 0 ]]; then
    skip peers "AK_BENCH_PEERS=0"
elif [[ -n $(peer_lib_missing) ]]; then
    skip peers "$(peer_lib_missing)"
else
    # vs_ozz: skinning, sample+FK, two-bone IK against ozz-animation.
    if wanted vs_ozz || wanted vs_ozz_avx2; then
        if [[ ! -x $PEERS/vs_ozz/run.sh || ! -d $PEERS/ozz-animation ]]; then
            skip vs_ozz "peer absent ($PEERS/vs_ozz/run.sh or $PEERS/ozz-animation)"
        elif [[ -n $QUICK && ! -f $B/peers/ozz/src/geometry/runtime/libozz_geometry_r.a ]]; then
            skip vs_ozz "quick mode: ozz not built yet under $B/peers/ozz (make bench builds it, ~1 min)"
        else
            if [[ -n $QUICK ]]; then set -- 10000 3 sai; else set -- 1000000 11 sai; fi
            # this repository's copy of the driver (long rounds, per-round spread) when present
            if [[ -x $ROOT/bench/vs_ozz/run.sh ]]; then
                wanted vs_ozz && run vs_ozz env VS_OZZ_PEER="$PEERS/vs_ozz" "$ROOT/bench/vs_ozz/run.sh" "$B" "$@"
            else
                wanted vs_ozz && run vs_ozz "$PEERS/vs_ozz/run.sh" "$B" "$@"
            fi
            # The skinning rows again with animkit capped to its AVX2 kernel (bench/vs_ozz), on a CPU
            # that also has AVX-512: the targets hold on every CPU path.
            if wanted vs_ozz_avx2 && [[ -x $ROOT/bench/vs_ozz/run.sh ]] && grep -q avx512f /proc/cpuinfo; then
                run vs_ozz_avx2 env AK_VS_OZZ_SIMD=avx2 VS_OZZ_PEER="$PEERS/vs_ozz" "$ROOT/bench/vs_ozz/run.sh" "$B" "$1" "$2" s
            fi
        fi
    fi
    # vs_noise: FastNoiseLite and FastNoise2, every basis (this repository's harness,
    # bench/vs_noise/run.sh; the peers' own run.sh when it is gone).
    if wanted vs_noise; then
        if [[ ! -d $PEERS/noise/FastNoise2 ]]; then
            skip vs_noise "peer absent ($PEERS/noise)"
        elif [[ -n $QUICK && ! -f $B/vs_noise/fn2/lib/libFastNoise.a && ! -f $B/vs_noise/fn2/Release/lib/libFastNoise.a ]]; then
            skip vs_noise "quick mode: FastNoise2 not built yet under $B/vs_noise (make bench builds it, 5-9 min)"
        else
            if [[ -n $QUICK ]]; then rounds=1; else rounds=5; fi
            if [[ -x $ROOT/bench/vs_noise/run.sh ]]; then
                run vs_noise env NOISE_PEERS="$PEERS/noise" "$ROOT/bench/vs_noise/run.sh" "$B" "$rounds"
            else
                run vs_noise "$PEERS/noise/run.sh" "$B" "$rounds"
            fi
        fi
    fi
    # vs_nsearch: CompactNSearch (pairs and CSR lists, bench/vs_nsearch/run.sh), at each size.
    nsearch=("$PEERS/nsearch/run.sh")
    [[ -x $ROOT/bench/vs_nsearch/run.sh ]] && nsearch=(env CNS_DIR="$PEERS/nsearch/CompactNSearch" "$ROOT/bench/vs_nsearch/run.sh")
    if [[ ! -d $PEERS/nsearch/CompactNSearch ]]; then
        skip vs_nsearch "peer absent ($PEERS/nsearch)"
    elif [[ -n $QUICK ]]; then
        wanted vs_nsearch_12 && run vs_nsearch_12 "${nsearch[@]}" "$B" 12 1
    else
        for side in ${AK_BENCH_NSEARCH_SIDES:-38 80}; do
            wanted "vs_nsearch_$side" && run "vs_nsearch_$side" "${nsearch[@]}" "$B" "$side" 5
        done
    fi
    # Peers with no harness here, said once so that nobody wonders.
    [[ -z $ONLY ]] && for d in "$PEERS"/*/; do
        p=$(basename "$d")
        case $p in vs_ozz | ozz-animation | noise | nsearch) continue ;; esac
        [[ $p == rvo2 ]] && continue # bench/vs_rvo2, above
        if [[ -x $d/run.sh ]]; then
            skip "peer_$p" "$d/run.sh: no arguments known to scripts/bench.sh"
        else
            skip "peer_$p" "no side-by-side harness in $d (see its README/PEER.md)"
        fi
    done
fi

echo "load at end: $(cut -d' ' -f1-3 /proc/loadavg 2>/dev/null)" >>"$OUT/machine.txt"
if [[ -x /usr/bin/python3 ]]; then
    /usr/bin/python3 "$ROOT/scripts/bench_summary.py" "$OUT" && echo "summary: $OUT/SUMMARY.md"
else
    echo "bench.sh: no /usr/bin/python3: no SUMMARY.md (the outputs are in $OUT)"
fi
# A failed program fails the whole run (after the others ran).
! awk -F'\t' '$2 != "0" && $2 != "skip" { bad = 1 } END { exit !bad }' "$LOG"

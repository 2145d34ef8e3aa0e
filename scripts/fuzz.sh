#!/usr/bin/env bash
# Build every tests/fuzz/fuzz_<name>.c as a clang libFuzzer binary with ASan + UBSan and run
# each for SECONDS (default 60) on its seed corpus. Fails if any target finds a crash, a leak
# or a sanitizer report (the reproducer is left in build-fuzz/artifacts/).
#
#   scripts/fuzz.sh [SECONDS] [NAME...]     e.g. scripts/fuzz.sh 3600 bvh
#
# A target links the whole library (build-fuzz/lib, built by CMake with the same
# instrumentation) plus tools/animkit/*.c except main.c (as an archive, so a target pulls in
# only the CLI objects it uses, e.g. a scene-file parser). Per target <name>:
#   tests/fuzz/<name>.seeds  seed files, one per line: "$ASSETS/..." (ANIMKIT_ASSETS, else
#                            ../shared/assets), otherwise relative to the repository root;
#                            globs allowed; '#' starts a comment; missing files are skipped
#   tests/fuzz/<name>.dict   libFuzzer dictionary (optional)
#   tests/fuzz/<name>.options extra libFuzzer flags on one line (optional)
# The corpus grows in build-fuzz/corpus/<name> and is kept between runs. Environment:
# FUZZ_LIB (a build folder configured with AK_SANITIZE=ON and either AK_FUZZ_COVERAGE=ON (coverage
# on the parsers only, as .ci/run's build-asan) or -fsanitize=fuzzer-no-link in CMAKE_C_FLAGS
# (everywhere), whose libanimkit.a the targets link instead of building build-fuzz/lib),
# FUZZ_JOBS (parallel targets, default 1), FUZZ_MAX_LEN (default 65536), CC (default clang),
# FUZZ_SEED (libFuzzer's -seed, default 1, so that a run from the seed corpus is reproducible and
# CI's short run repeats the sequence that was checked before committing; 0 = a random seed per
# run, for long exploratory runs).
set -euo pipefail
cd "$(dirname "$0")/.."
ROOT=$PWD
SECS=${1:-60}
shift || true
ONLY=("$@")
OUT=$ROOT/build-fuzz
ASSETS=${ANIMKIT_ASSETS:-$ROOT/../shared/assets}
ASSETS=$(cd "$ASSETS" 2>/dev/null && pwd || echo "$ASSETS")
CC=${FUZZ_CC:-clang}
MAX_LEN=${FUZZ_MAX_LEN:-65536}
JOBS=$(nproc 2>/dev/null || echo 2)
SAN="-fsanitize=address,undefined -fno-sanitize-recover=undefined -fno-omit-frame-pointer"

command -v "$CC" >/dev/null || { echo "fuzz.sh: $CC not found (scripts/install-deps.sh installs clang)" >&2; exit 1; }

mkdir -p "$OUT"
if [ -n "${FUZZ_LIB:-}" ]; then
  # A library already built with the instrumentation: CI's ASan stage configures build-asan with
  # AK_FUZZ_COVERAGE=ON (libFuzzer coverage on the parsers, CMakeLists.txt), so the fuzz stage
  # does not compile the whole library a second time. Refuse a build without coverage: libFuzzer
  # would fuzz blind.
  LIBDIR=$(cd "$FUZZ_LIB" && pwd)
  grep -q '^AK_SANITIZE:BOOL=ON' "$LIBDIR/CMakeCache.txt" 2>/dev/null &&
    { grep -q '^AK_FUZZ_COVERAGE:BOOL=ON' "$LIBDIR/CMakeCache.txt" || grep -q 'fuzzer-no-link' "$LIBDIR/CMakeCache.txt"; } ||
    { echo "fuzz.sh: FUZZ_LIB=$FUZZ_LIB was not configured with AK_SANITIZE=ON and AK_FUZZ_COVERAGE=ON (or -fsanitize=fuzzer-no-link)" >&2; exit 1; }
  echo "== fuzz: the library of $FUZZ_LIB (ASan + UBSan + libFuzzer coverage)"
  cmake --build "$LIBDIR" -j "$JOBS" --target animkit_static > "$OUT/lib.log" 2>&1 || { tail -30 "$OUT/lib.log"; exit 1; }
else
  LIBDIR=$OUT/lib
  echo "== fuzz: building the library with $CC, libFuzzer + ASan + UBSan"
  cmake -S . -B "$LIBDIR" -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCMAKE_C_COMPILER="$CC" \
    -DCMAKE_C_FLAGS_RELWITHDEBINFO="-O1 -g" -DCMAKE_C_FLAGS="-fsanitize=fuzzer-no-link $SAN" \
    -DAK_BUILD_TESTS=OFF -DAK_BUILD_EXAMPLES=OFF -DAK_BUILD_BENCH=OFF -DAK_BUILD_TOOLS=OFF \
    > "$OUT/lib.log" 2>&1 || { tail -30 "$OUT/lib.log"; exit 1; }
  cmake --build "$LIBDIR" -j "$JOBS" --target animkit_static >> "$OUT/lib.log" 2>&1 || { tail -30 "$OUT/lib.log"; exit 1; }
fi
LIBS=$(sed -n 's/^Libs.private: //p' "$LIBDIR/animkit.pc")

CFLAGS=(-std=c11 -D_POSIX_C_SOURCE=200809L -O1 -g $SAN -Wall -Wextra -Werror
        -Iinclude -Isrc -Itools/animkit -DAK_FUZZ_ASSETS="\"$ASSETS\"")
mkdir -p "$OUT/cli" "$OUT/bin" "$OUT/corpus" "$OUT/artifacts" "$OUT/logs"
rm -f "$OUT/cli/"*.o "$OUT/libanimkit_cli.a"

# Compiles run JOBS at a time (background jobs); wait_all fails if any failed.
pids=()
spawn() {
  while [ "$(jobs -rp | wc -l)" -ge "$JOBS" ]; do wait -n || true; done
  "$@" &
  pids+=($!)
}
wait_all() {
  local bad=0 pid
  for pid in "${pids[@]}"; do wait "$pid" || bad=1; done
  pids=()
  [ "$bad" = 0 ] || { echo "fuzz.sh: a compile failed" >&2; exit 1; }
}

cli_objs=()
for src in tools/animkit/*.c; do
  [ "$(basename "$src")" = main.c ] && continue
  obj=$OUT/cli/$(basename "${src%.c}").o
  spawn "$CC" "${CFLAGS[@]}" -fsanitize=fuzzer-no-link -c "$src" -o "$obj"
  cli_objs+=("$obj")
done
wait_all
[ ${#cli_objs[@]} -gt 0 ] && ar rcs "$OUT/libanimkit_cli.a" "${cli_objs[@]}"

targets=()
for src in tests/fuzz/fuzz_*.c; do
  name=$(basename "${src%.c}"); name=${name#fuzz_}
  if [ ${#ONLY[@]} -gt 0 ] && [[ ! " ${ONLY[*]} " == *" $name "* ]]; then continue; fi
  echo "== fuzz: building fuzz_$name"
  spawn "$CC" "${CFLAGS[@]}" -fsanitize=fuzzer "$src" -o "$OUT/bin/fuzz_$name" \
    ${cli_objs:+"$OUT/libanimkit_cli.a"} "$LIBDIR/libanimkit.a" $LIBS
  targets+=("$name")
done
wait_all
[ ${#targets[@]} -gt 0 ] || { echo "fuzz.sh: no targets" >&2; exit 1; }

# Seeds: each line of tests/fuzz/<name>.seeds, $ASSETS expanded, globs allowed.
seed_corpus() {
  local name=$1 dir=$OUT/corpus/$1 line path
  mkdir -p "$dir"
  [ -f "tests/fuzz/$name.seeds" ] || return 0
  while IFS= read -r line || [ -n "$line" ]; do
    line=${line%%#*}; line=$(echo "$line" | xargs)
    [ -n "$line" ] || continue
    line=${line//\$ASSETS/$ASSETS}
    for path in $line; do
      if [ -f "$path" ]; then cp "$path" "$dir/seed_$(echo "$path" | tr '/ ' '__' | tail -c 100)"
      else echo "   (seed $path absent, skipped)"; fi
    done
  done < "tests/fuzz/$name.seeds"
}

export ASAN_OPTIONS=detect_leaks=1:abort_on_error=1:allocator_may_return_null=1
export UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1
export LSAN_OPTIONS=suppressions=$ROOT/tests/fuzz/lsan.supp:print_suppressions=0

run_one() {
  local name=$1 log=$OUT/logs/$1.log
  local args=(-max_total_time="$SECS" -max_len="$MAX_LEN" -timeout=20 -rss_limit_mb=2560
              -seed="${FUZZ_SEED:-1}"
              -print_final_stats=1 -artifact_prefix="$OUT/artifacts/$name-")
  [ -f "tests/fuzz/$name.dict" ] && args+=(-dict="tests/fuzz/$name.dict")
  [ -f "tests/fuzz/$name.options" ] && read -r -a extra < "tests/fuzz/$name.options" && args+=("${extra[@]}")
  if "$OUT/bin/fuzz_$name" "${args[@]}" "$OUT/corpus/$name" > "$log" 2>&1; then
    local runs rate
    runs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$log" | tail -1)
    rate=$(sed -n 's/^stat::average_exec_per_sec: *//p' "$log" | tail -1)
    echo "fuzz_$name: ok, ${runs:-?} runs in ${SECS} s (${rate:-?} exec/s), corpus $(ls "$OUT/corpus/$name" | wc -l) files"
    return 0
  fi
  echo "fuzz_$name: FAILED (log $log, reproducer in $OUT/artifacts/)"
  grep -E "ERROR|SUMMARY|runtime error|Test unit written" "$log" | head -20
  # The grep misses the cause of a bare abort() or an uncaught C++ exception (the harness's
  # own message, "terminate called ...") and the stack of a deadly signal: show the end of
  # the log without libFuzzer's progress lines, and the input itself, since CI keeps no files.
  echo "---- fuzz_$name: last 60 lines of the log, progress lines left out:"
  grep -vE '^#[0-9]+[[:space:]]+(INITED|NEW|REDUCE|pulse|RELOAD)' "$log" | tail -60 | cut -c1-300
  local art
  art=$(sed -n 's/.*Test unit written to \(.*\)$/\1/p' "$log" | tail -1)
  if [ -n "$art" ] && [ -f "$art" ]; then
    echo "---- the input, $(wc -c < "$art") bytes (first 4096), base64 (decode with base64 -d > x):"
    head -c 4096 "$art" | base64 -w 100
    echo "---- reproduce with: $OUT/bin/fuzz_$name $art"
  fi
  return 1
}

for t in "${targets[@]}"; do seed_corpus "$t"; done
echo "== fuzz: ${#targets[@]} targets, $SECS s each"
failed=0
PAR=${FUZZ_JOBS:-1}
pids=()
for t in "${targets[@]}"; do
  run_one "$t" & pids+=($!)
  if [ ${#pids[@]} -ge "$PAR" ]; then wait "${pids[0]}" || failed=1; pids=("${pids[@]:1}"); fi
done
for p in "${pids[@]}"; do wait "$p" || failed=1; done
[ "$failed" = 0 ] && echo "== fuzz: all targets clean" || echo "== fuzz: FAILURES"
exit "$failed"

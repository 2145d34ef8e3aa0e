#!/usr/bin/env bash
# `make web`: animkit compiled to WebAssembly (clang --target=wasm32-wasi, Debian's wasi-libc,
# wasm-ld) plus the page, into build/web/ (docs/web.md says why this toolchain and how it works).
# Usage: scripts/build-web.sh [OUT_DIR]   (default build/web). Needs the Debian packages clang,
# lld, wasi-libc and libclang-rt-14-dev-wasm32 (scripts/install-deps.sh --web installs them);
# without them it says what is missing and exits 1, and nothing else in the build depends on it.
set -euo pipefail
cd "$(dirname "$0")/.."
OUT=${1:-build/web}
CC=${AK_WEB_CC:-clang}
SYSROOT=/usr/include/wasm32-wasi

missing=()
command -v "$CC" >/dev/null 2>&1 || missing+=("clang")
command -v wasm-ld >/dev/null 2>&1 || missing+=("lld (wasm-ld)")
[[ -f $SYSROOT/stdio.h && -f /usr/lib/wasm32-wasi/libc.a ]] || missing+=("wasi-libc")
if command -v "$CC" >/dev/null 2>&1; then
  rt=$("$CC" --target=wasm32-wasi -print-libgcc-file-name 2>/dev/null || true)
  [[ -n $rt && -f $rt ]] || missing+=("libclang-rt-$("$CC" -dumpversion | cut -d. -f1)-dev-wasm32")
fi
[[ -f /usr/include/cjson/cJSON.h ]] || missing+=("libcjson-dev (its header)")
if ((${#missing[@]})); then
  echo "make web: the WebAssembly toolchain is not installed: missing ${missing[*]}." >&2
  echo "make web: install it with: sudo scripts/install-deps.sh --web   (Debian: clang lld wasi-libc libclang-rt-14-dev-wasm32)" >&2
  exit 1
fi

mkdir -p "$OUT/obj" "$OUT/inc/cjson"
ln -sf /usr/include/cjson/cJSON.h "$OUT/inc/cjson/cJSON.h"

# The library: every module, except the four files that need a library Debian has no wasm32
# build of (libpng/giflib, libpng/libjpeg, Assimp, CHOLMOD); web/stubs.c stands in for them.
mapfile -t LIB < <(ls src/*.c src/*/*.c | grep -v -E '^src/(raster/raster_file|io/image|io/assimp|skin/weights_heat)\.c$')
# The viewer's platform-independent state machine and simulations (tools/animkit/view_app.h).
# Every file there but main.c, the commands (cmd_*.c) and the SDL window (view_sdl.c).
mapfile -t TOOLS < <(ls tools/animkit/*.c | grep -v -E '/(main|view_sdl|cmd_[a-z_]*)\.c$')
WEB=(web/animkit_web.c web/fluid_sim.c web/cjson.c web/stubs.c)

CFLAGS=(--target=wasm32-wasi -std=c11 -O2 -msimd128 -mnontrapping-fptoint -msign-ext -Wall -Wextra -Wpedantic -Werror
        -fno-math-errno -ffp-contract=off -D_POSIX_C_SOURCE=200809L -D_WASI_EMULATED_GETPID -DAK_BUILDING -include web/shim/wasi_compat.h
        -Iweb/shim -I"$OUT/inc" -Iinclude -Isrc -Itools/animkit)
LAUNCHER=""
command -v ccache >/dev/null 2>&1 && LAUNCHER=ccache
export OUT CC LAUNCHER CFLAGS_STR="${CFLAGS[*]}"
compile() { # src -> obj (named after the path, so src/io.c and src/io/io.c stay apart)
  local obj="$OUT/obj/$(echo "$1" | tr / _ | sed 's/\.c$/.o/')"
  # shellcheck disable=SC2086 # the flags are words
  $LAUNCHER "$CC" $CFLAGS_STR -c "$1" -o "$obj" || { echo "make web: $1 failed to compile" >&2; return 1; }
}
export -f compile
printf '%s\n' "${LIB[@]}" "${TOOLS[@]}" "${WEB[@]}" | xargs -P "${JOBS:-2}" -n 1 bash -c 'compile "$1"' _

# AK_WEB_STRIP=0 keeps the function names (for profiling: tests/web/profile.mjs)
STRIP=-Wl,--strip-all
[[ ${AK_WEB_STRIP:-1} == 0 ]] && STRIP=""
OBJS=()
for s in "${LIB[@]}" "${TOOLS[@]}" "${WEB[@]}"; do OBJS+=("$OUT/obj/$(echo "$s" | tr / _ | sed 's/\.c$/.o/')"); done
# A reactor module (no main): the page calls the exports of web/animkit_web.c. 4 MiB of stack
# for the recursive-descent parsers' bounded depth; memory grows on demand.
"$CC" --target=wasm32-wasi -mexec-model=reactor -O2 "${OBJS[@]}" -o "$OUT/animkit.wasm" \
  $STRIP -Wl,-z,stack-size=4194304 -Wl,--export=malloc -Wl,--export=free -lwasi-emulated-getpid -lm
cp web/index.html web/animkit.js "$OUT/"
# The one bundled asset: a small rigged glTF (RiggedFigure.glb, 50 KB, CC-BY-4.0 (c) 2017 Cesium,
# from ../shared/assets when present), as a script so the page needs no fetch for it.
asset=${AK_WEB_ASSET:-../shared/assets/gltf/RiggedFigure/glTF-Binary/RiggedFigure.glb}
[[ -f $asset ]] || asset=/work/shared/assets/gltf/RiggedFigure/glTF-Binary/RiggedFigure.glb
if [[ -f $asset ]]; then
  { printf 'window.ANIMKIT_ASSETS = {"RiggedFigure.glb": "'; base64 -w0 "$asset"; printf '"};\n'; } > "$OUT/assets.js"
else
  echo "make web: no RiggedFigure.glb found (../shared/assets): the page bundles the built-in models only" >&2
  printf 'window.ANIMKIT_ASSETS = {};\n' > "$OUT/assets.js"
fi
size=$(stat -c %s "$OUT/animkit.wasm")
echo "make web: wrote $OUT/index.html and $OUT/animkit.wasm ($size bytes)"

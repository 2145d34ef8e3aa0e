#!/bin/sh
# ctest's test_web (label slow): builds the page (scripts/build-web.sh) and runs the browser
# tests (tests/web/run.mjs) in Debian's headless Chromium. Exit 77 (SKIP) with one line saying
# what is missing: Chromium, node, puppeteer-core (cd tests/web && npm ci) or the wasm toolchain
# (scripts/install-deps.sh --web installs all of them).
# Usage: run.sh SOURCE_DIR WEB_BUILD_DIR ANIMKIT_CLI OUT_DIR
set -u
src=$1 web=$2 cli=$3 out=$4
skip() { echo "SKIP: $*"; exit 77; }
[ -x /usr/bin/chromium ] || [ -n "${CHROMIUM:-}" ] || skip "no Chromium (Debian chromium; scripts/install-deps.sh --web)"
command -v node >/dev/null 2>&1 || skip "no node (Debian nodejs)"
[ -d "$src/tests/web/node_modules/puppeteer-core" ] || skip "puppeteer-core is not installed (cd tests/web && npm ci)"
[ -f /usr/include/wasm32-wasi/stdio.h ] || skip "no wasi-libc (scripts/install-deps.sh --web)"
clang --target=wasm32-wasi -print-libgcc-file-name 2>/dev/null | xargs test -f 2>/dev/null ||
  skip "no clang wasm32 runtime (Debian libclang-rt-14-dev-wasm32; scripts/install-deps.sh --web)"
command -v wasm-ld >/dev/null 2>&1 || skip "no wasm-ld (Debian lld)"
bash "$src/scripts/build-web.sh" "$web" || exit 1
cesium="$src/../shared/assets/gltf/CesiumMan/glTF-Binary/CesiumMan.glb"
[ -f "$cesium" ] || cesium=""
exec node "$src/tests/web/run.mjs" "$web" "$cli" "$out" $cesium

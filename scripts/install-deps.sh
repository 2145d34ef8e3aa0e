#!/usr/bin/env bash
# Installs the Debian packages animkit needs to build and test, only those missing.
# Works as root on a fresh Debian 12; as another user it uses sudo when available, and
# otherwise prints the exact command to run.
# --web also installs the optional WebAssembly group (`make web` and the browser test
# test_web, docs/web.md): without it those say what is missing and skip.
set -euo pipefail
WEB=0
[ "${1:-}" = "--web" ] && WEB=1

PACKAGES=(
  build-essential   # gcc, make
  cmake             # >= 3.25 (Debian 12 ships 3.25)
  ninja-build       # CMake's generator when present (the Makefile and .ci/run pick it)
  pkg-config
  libpng-dev        # PNG output (raster)
  libgif-dev        # animated GIF output (raster)
  libassimp-dev     # FBX, Collada, BVH, OBJ import (io)
  libcjson-dev      # JSON for the glTF 2.0 reader (io)
  libjpeg62-turbo-dev # JPEG base-colour textures of glTF/OBJ models (io; optional: without it JPEG textures are skipped)
  libsuitesparse-dev # CHOLMOD sparse Cholesky for bone-heat weights (skin)
  libsdl2-dev       # the window of `animkit view` (optional: without it, --headless only)
  xvfb              # virtual display: tests run the viewer's window under xvfb-run
  xauth             # xvfb-run needs it
  libx11-dev        # the X11 client that resizes and closes the viewer's window in test_view_window
  clang             # the ASan+UBSan CI stage and scripts/fuzz.sh
  libclang-rt-14-dev # clang's sanitizer and libFuzzer runtimes (-fsanitize=fuzzer), Debian 12
  libbullet-dev     # Bullet 3, the peer of bench/vs_bullet (optional: the benchmark is skipped without it)
  python3-dev       # the Python package's C extension (python/; optional: AK_PYTHON skips it without)
  python3-numpy     # its arrays (and the NumPy C API it builds against)
  python3-pytest    # the Python tests (test_python SKIPs without)
  python3-setuptools # pip install --no-build-isolation . (setup.py drives CMake)
  python3-matplotlib # examples/python (its smoke test SKIPs without)
  python3-distributed # animkit.batch on Dask (optional: its test SKIPs without)
)

# Optional group (--web): animkit compiled to WebAssembly and tested in a real browser.
WEB_PACKAGES=(
  lld               # wasm-ld, the WebAssembly linker (scripts/build-web.sh)
  wasi-libc         # the C library for clang --target=wasm32-wasi
  libclang-rt-14-dev-wasm32 # clang's wasm32 builtins (compiler-rt)
  chromium          # the headless browser test_web drives (tests/web/run.mjs)
  nodejs            # runs tests/web/run.mjs (puppeteer-core from npm, tests/web/package-lock.json)
)
if [ "$WEB" = 1 ]; then PACKAGES+=("${WEB_PACKAGES[@]}"); fi

missing=()
for p in "${PACKAGES[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done

# Optional: the Khronos glTF validator (npm gltf-validator) into build-tools/ (git-ignored),
# which tests/test_io_write.c runs on the files ak_io_save writes. Never fails the script.
if command -v npm >/dev/null 2>&1; then
  ak_root="$(cd "$(dirname "$0")/.." && pwd)"
  if [ ! -d "$ak_root/build-tools/node_modules/gltf-validator" ]; then
    (mkdir -p "$ak_root/build-tools" && cd "$ak_root/build-tools" &&
      npm install --no-audit --no-fund --silent gltf-validator >/dev/null 2>&1) ||
      echo "animkit: optional npm install of gltf-validator failed; its test will SKIP" >&2
  fi
else
  echo "animkit: npm not found; the glTF validator test will SKIP (optional)" >&2
fi

# --web: puppeteer-core for the browser test into tests/web/node_modules (git-ignored), at the
# versions tests/web/package-lock.json records. Never fails the script (offline: test_web SKIPs).
web_npm() {
  if [ "$WEB" = 1 ] && command -v npm >/dev/null 2>&1; then
    (cd "$(dirname "$0")/../tests/web" && npm ci --no-audit --no-fund --silent >/dev/null 2>&1) ||
      echo "animkit: optional npm ci in tests/web failed (offline?); test_web will SKIP" >&2
  fi
}

if [ ${#missing[@]} -eq 0 ]; then
  web_npm
  exit 0
fi

echo "animkit: installing missing Debian packages: ${missing[*]}"
if [ "$(id -u)" -eq 0 ]; then
  SUDO=""
elif command -v sudo >/dev/null 2>&1 && sudo -n true 2>/dev/null; then
  SUDO="sudo"
else
  echo "animkit: not root and no password-less sudo. Run this once, then try again:" >&2
  echo "    sudo apt-get update && sudo apt-get install -y ${missing[*]}" >&2
  exit 1
fi
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -qq
$SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
web_npm

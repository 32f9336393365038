#!/usr/bin/env bash
# Installs everything casual3d needs on Debian 12 (bookworm) and builds it.
# Idempotent: when every package is present and the build is current it only
# re-runs the (incremental) build. Works as root, or through sudo otherwise.
#
#   bash scripts/setup.sh            # install + build into build/
#   CASUAL3D_BUILD_DIR=dir bash scripts/setup.sh
set -euo pipefail

here="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build_dir="${CASUAL3D_BUILD_DIR:-$here/build}"

# Every Debian package the project uses, by what needs it.
packages=(
  # toolchain
  build-essential cmake ninja-build pkg-config ccache dpkg-dev time
  # format/ and encoder/
  libwebp-dev libopenexr-dev libdraco-dev libtinygltf-dev nlohmann-json3-dev
  # reconstruct/
  colmap libsqlite3-dev libopencv-dev libeigen3-dev libmaxflow-dev libjpeg-dev libpng-dev libexif-dev
  # reconstruct/: HEIC photos (libheif; heif-enc for tests) and video (ffmpeg for tests)
  libheif-dev libheif-examples ffmpeg
  # cli/, tests and benchmarks
  libcli11-dev libgtest-dev libgmock-dev libbenchmark-dev
  # python/: the module (import casual3d) and its tests
  pybind11-dev python3-dev python3-numpy python3-pytest
  # wasm-viewer/ and its browser test
  emscripten chromium
  # scale/: the distributed workflow and its test (Dask scheduler and workers)
  python3-distributed
)

missing=()
for p in "${packages[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done

if ((${#missing[@]})); then
  echo "setup: installing ${#missing[@]} Debian packages: ${missing[*]}"
  if [ "$(id -u)" -eq 0 ]; then
    sudo_cmd=()
  elif command -v sudo >/dev/null 2>&1; then
    sudo_cmd=(sudo)
  else
    echo "setup: error: not root and sudo is missing; install as root: apt-get install ${missing[*]}" >&2
    exit 1
  fi
  export DEBIAN_FRONTEND=noninteractive
  "${sudo_cmd[@]}" apt-get update -q >/dev/null
  "${sudo_cmd[@]}" apt-get install -y -q --no-install-recommends "${missing[@]}" >/dev/null
fi

if ! command -v node >/dev/null 2>&1 || ! command -v npm >/dev/null 2>&1; then
  echo "setup: installing Node.js and npm from Debian"
  if [ "$(id -u)" -eq 0 ]; then apt-get install -y -q nodejs npm >/dev/null;
  else sudo apt-get install -y -q nodejs npm >/dev/null; fi
fi

# npm packages for the viewer's tooling and tests (package-lock.json pins them).
if [ -f "$here/wasm-viewer/package.json" ]; then
  if [ ! -d "$here/wasm-viewer/node_modules" ] || \
     [ "$here/wasm-viewer/package-lock.json" -nt "$here/wasm-viewer/node_modules/.package-lock.json" ]; then
    echo "setup: installing npm packages for wasm-viewer/"
    (cd "$here/wasm-viewer" && npm ci --no-audit --no-fund --loglevel=error >/dev/null)
  fi
fi

launcher=()
command -v ccache >/dev/null 2>&1 && launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache -DCMAKE_C_COMPILER_LAUNCHER=ccache)
if [ ! -f "$build_dir/build.ninja" ]; then
  cmake -S "$here" -B "$build_dir" -G Ninja -DCMAKE_BUILD_TYPE=Release "${launcher[@]}" >/dev/null
fi
jobs="$(nproc 2>/dev/null || echo 2)"
if [ -t 1 ]; then
  cmake --build "$build_dir" -j "$jobs"
else
  # Quiet in CI logs: print the build output only when it fails.
  log="$(mktemp)"
  if ! cmake --build "$build_dir" -j "$jobs" >"$log" 2>&1; then
    cat "$log"; rm -f "$log"; echo "setup: error: the build failed (output above)" >&2; exit 1
  fi
  rm -f "$log"
fi
echo "setup: built $build_dir"

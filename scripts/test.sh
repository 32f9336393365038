#!/usr/bin/env bash
# Sets up (scripts/setup.sh) and runs the whole test suite: unit tests and
# end-to-end tests under ctest, including the Node and browser tests of the
# WebAssembly viewer. Tests that need ../shared/datasets skip when it is absent.
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build_dir="${CASUAL3D_BUILD_DIR:-$here/build}"
bash "$here/scripts/setup.sh"
cd "$build_dir"
ctest --output-on-failure -j "$(nproc 2>/dev/null || echo 2)" "$@"

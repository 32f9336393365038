#!/usr/bin/env bash
# Sets up (scripts/setup.sh), then runs the main job on the built-in default
# capture: a synthetic phone-style capture that casual3d generates itself.
#
#   bash scripts/demo.sh [OUTPUT_DIR]     (default: out/)
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build_dir="${CASUAL3D_BUILD_DIR:-$here/build}"
out="${1:-$here/out}"
bash "$here/scripts/setup.sh"
casual3d="$build_dir/cli/casual3d"

"$casual3d" synth --rig partial -o "$out/default-capture"
echo "demo: wrote the default capture to $out/default-capture"

#!/usr/bin/env bash
# Sets up (scripts/setup.sh), then runs the main job on the built-in default
# capture: renders the synthetic phone-style capture (16 photos) and turns its
# photos into a web-ready 3D photo with `casual3d reconstruct`.
#
#   bash scripts/demo.sh [OUTPUT_DIR]     (default: out/)
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build_dir="${CASUAL3D_BUILD_DIR:-$here/build}"
out="${1:-$here/out}"
bash "$here/scripts/setup.sh"
casual3d="$build_dir/cli/casual3d"

"$casual3d" synth --rig partial -o "$out/default-capture"
# Only the photos go in: calibration comes from COLMAP and the photos' EXIF,
# as for a real capture (the capture's ground truth stays for evaluation).
"$casual3d" reconstruct "$out/default-capture/images" -o "$out/default-3d-photo"
echo "demo: the 3D photo is in $out/default-3d-photo/web (open it with: $casual3d view $out/default-3d-photo/web)"

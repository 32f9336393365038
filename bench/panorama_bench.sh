#!/usr/bin/env bash
# Benchmark of the panorama stages (warp + stitch + fuse + normals) on the
# default synthetic captures with their ground-truth depth maps, so that the
# numbers do not depend on the dense stage. Prints one table: wall time of each
# step, whole-process wall and CPU (user + system) time and peak memory.
#
#   bash bench/panorama_bench.sh [BUILD_DIR] [PANO_WIDTH]
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build="${1:-$here/build}"
width="${2:-4096}"
casual3d="$build/cli/casual3d"
[ -x "$casual3d" ] || { echo "panorama_bench: $casual3d not found: build first (bash scripts/setup.sh)" >&2; exit 1; }
[ -x /usr/bin/time ] || { echo "panorama_bench: /usr/bin/time missing: apt-get install time" >&2; exit 1; }
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT

printf "%-8s %6s %7s %7s %7s %7s %7s %7s %7s %8s %8s %9s\n" rig photos load warp st.front st.back fuse normals write wall_s cpu_s peak_MiB
for rig in partial sphere; do
  "$casual3d" synth --rig "$rig" -o "$work/$rig" --panorama-width 256 >/dev/null
  /usr/bin/time -v -o "$work/time.txt" "$casual3d" panorama "$work/$rig" -o "$work/$rig-out" \
    --pano-width "$width" >/dev/null
  python3 - "$work/$rig-out/panorama.json" "$work/time.txt" "$rig" <<'PY'
import json, re, sys
p = json.load(open(sys.argv[1])); s = p["seconds"]
t = open(sys.argv[2]).read()
rss = int(re.search(r"Maximum resident set size \(kbytes\): (\d+)", t).group(1)) / 1024
wall = re.search(r"Elapsed \(wall clock\) time \(h:mm:ss or m:ss\): ([\d:.]+)", t).group(1).split(":")
secs = sum(float(x) * 60 ** i for i, x in enumerate(reversed(wall)))
cpu = float(re.search(r"User time \(seconds\): ([\d.]+)", t).group(1)) + \
      float(re.search(r"System time \(seconds\): ([\d.]+)", t).group(1))
print("%-8s %6d %7.2f %7.2f %7.2f %7.2f %7.2f %7.2f %7.2f %8.2f %8.2f %9.0f" % (
    sys.argv[3], p["photos"], s["load"], s["warp"], s["stitch_front"], s["stitch_back"],
    s["fuse"], s["normals"], s["write"], secs, cpu, rss))
PY
done

#!/usr/bin/env bash
# Benchmark of the whole pipeline (`casual3d reconstruct`) on the default
# synthetic capture and on the LLFF fern capture, followed by virtual
# rephotography (`casual3d evaluate`). Each stage runs as its own process
# (--from S --to S, resuming from the stage cache) under /usr/bin/time, so the
# table gives wall time, CPU time (user + system) and peak memory per stage.
# Then: package size and the rephotography figures (error, completeness, PSNR,
# SSIM; the synthetic capture also gives depth against its ground truth).
#
#   bash bench/pipeline_bench.sh [BUILD_DIR] [WORK_DIR]
#
# WORK_DIR keeps the runs (default: a temporary folder, removed at the end);
# runs already there resume from their caches: a cached stage takes no time,
# and the "recorded_s" column gives the time report.json recorded when it ran
# (marked "(c)").
# Environment:
#   CASUAL3D_DATASETS  folder holding fern/ (default: ../shared/datasets beside
#                      the checkout); fern is skipped when it is absent.
#   BENCH_THREADS      worker threads (default 2)
#   BENCH_PANO_WIDTH   panorama width (default 4096)
#   BENCH_CAPTURES     which captures: "synthetic fern" (default), or one of them
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build="${1:-$here/build}"
casual3d="$build/cli/casual3d"
threads="${BENCH_THREADS:-2}"
width="${BENCH_PANO_WIDTH:-4096}"
captures="${BENCH_CAPTURES:-synthetic fern}"
datasets="${CASUAL3D_DATASETS:-$here/../shared/datasets}"
[ -x "$casual3d" ] || { echo "pipeline_bench: $casual3d not found: build first (bash scripts/setup.sh)" >&2; exit 1; }
[ -x /usr/bin/time ] || { echo "pipeline_bench: /usr/bin/time missing: apt-get install time" >&2; exit 1; }
command -v python3 >/dev/null || { echo "pipeline_bench: python3 missing" >&2; exit 1; }
if [ -n "${2:-}" ]; then
  work="$2"
  mkdir -p "$work"
else
  work="$(mktemp -d)"
  trap 'rm -rf "$work"' EXIT
fi
rows="$work/rows.txt"
: > "$rows"

# timed NAME LOG -- command...: runs the command under /usr/bin/time -v and
# appends "capture stage wall cpu rss_kb" to the rows.
timed() {
  local capture="$1" stage="$2"
  shift 2
  if ! /usr/bin/time -v -o "$work/time.txt" "$@" > "$work/$capture-$stage.log" 2>&1; then
    echo "pipeline_bench: $capture $stage failed; see $work/$capture-$stage.log" >&2
    tail -n 5 "$work/$capture-$stage.log" >&2
    exit 1
  fi
  python3 - "$work/time.txt" "$capture" "$stage" >> "$rows" <<'PY'
import re, sys
t = open(sys.argv[1]).read()
wall = re.search(r"Elapsed \(wall clock\) time \(h:mm:ss or m:ss\): ([\d:.]+)", t).group(1).split(":")
secs = sum(float(x) * 60 ** i for i, x in enumerate(reversed(wall)))
cpu = float(re.search(r"User time \(seconds\): ([\d.]+)", t).group(1)) + \
      float(re.search(r"System time \(seconds\): ([\d.]+)", t).group(1))
rss = int(re.search(r"Maximum resident set size \(kbytes\): (\d+)", t).group(1))
print(sys.argv[2], sys.argv[3], "%.2f" % secs, "%.2f" % cpu, rss)
PY
}

# pipeline CAPTURE INPUT RUN EVAL_CAPTURE [reconstruct options...]
pipeline() {
  local capture="$1" input="$2" run="$3" eval_capture="$4"
  shift 4
  for stage in sparse dense panorama encode; do
    timed "$capture" "$stage" "$casual3d" reconstruct "$input" -o "$run" --from "$stage" \
      --to "$stage" --threads "$threads" --pano-width "$width" "$@"
  done
}

for capture in $captures; do
  case "$capture" in
    synthetic)
      if [ ! -d "$work/synthetic-capture/images" ]; then
        timed synthetic synth "$casual3d" synth -o "$work/synthetic-capture" --threads "$threads"
      fi
      pipeline synthetic "$work/synthetic-capture/images" "$work/synthetic" "$work/synthetic-capture"
      # Every photo (all were used): on a synthetic capture the depth is also
      # compared with the ground truth.
      timed synthetic evaluate "$casual3d" evaluate "$work/synthetic-capture" "$work/synthetic" \
        -o "$work/synthetic-report.html" --json "$work/synthetic-eval.json" --threads "$threads"
      ;;
    fern)
      if [ ! -d "$datasets/fern/images" ]; then
        echo "pipeline_bench: $datasets/fern/images not found: fern skipped" >&2
        continue
      fi
      # The LLFF protocol: photos 0, 8, 16 held out, compared at 1008x756.
      pipeline fern "$datasets/fern/images" "$work/fern" "$datasets/fern" --holdout-every 8
      timed fern evaluate "$casual3d" evaluate "$datasets/fern" "$work/fern" --width 1008 \
        -o "$work/fern-report.html" --json "$work/fern-eval.json" --threads "$threads"
      ;;
    *)
      echo "pipeline_bench: unknown capture '$capture' (synthetic, fern)" >&2
      exit 1
      ;;
  esac
done

python3 - "$rows" "$work" <<'PY'
import json, os, sys
rows = [l.split() for l in open(sys.argv[1]) if l.strip()]
work = sys.argv[2]
# "recorded_s": the stage's time in report.json, which a cached stage keeps
# from the run that computed it.
recorded = {}
for c in set(r[0] for r in rows):
    rep = os.path.join(work, c, "report.json")
    if os.path.exists(rep):
        for st in json.load(open(rep)).get("stages", []):
            recorded[(c, st["stage"])] = (st.get("seconds", 0.0), st.get("cached", False))
print("%-10s %-9s %9s %9s %9s %11s" % ("capture", "stage", "wall_s", "cpu_s", "peak_MiB",
                                       "recorded_s"))
captures = []
for c, stage, wall, cpu, rss in rows:
    if c not in captures:
        captures.append(c)
    rec = recorded.get((c, stage))
    print("%-10s %-9s %9.1f %9.1f %9.0f %11s" % (c, stage, float(wall), float(cpu), int(rss) / 1024,
          "" if rec is None else "%.1f%s" % (rec[0], " (c)" if rec[1] else "")))
for c in captures:
    r = [x for x in rows if x[0] == c and x[1] in ("sparse", "dense", "panorama", "encode")]
    print("%-10s %-9s %9.1f %9.1f %9.0f" % (c, "reconstr.", sum(float(x[2]) for x in r),
          sum(float(x[3]) for x in r), max(int(x[4]) for x in r) / 1024))
print()
# PSNR/SSIM over covered pixels, then over the whole frame (holes filled).
print("%-10s %8s %6s %6s %8s %7s %6s %7s %6s %8s %6s %9s" % ("capture", "pkg_MiB", "photos",
      "error", "complete", "PSNR_dB", "SSIM", "PSNR_wf", "SSIM_wf", "d_medrel", "d_3%",
      "holes_max"))
for c in captures:
    rep = os.path.join(work, c, "report.json")
    ev = os.path.join(work, c + "-eval.json")
    if not (os.path.exists(rep) and os.path.exists(ev)):
        continue
    r = json.load(open(rep))["results"]
    e = json.load(open(ev))["photo3d"][0]
    m = e["mean"]
    pano = r.get("panorama", {})
    print("%-10s %8.2f %6d %6.4f %8.3f %7.2f %6.3f %7.2f %6.3f %8s %6s %9s" % (
        c, r.get("encode", {}).get("package_bytes", 0) / 1048576.0, len(e["photos"]), m["error"],
        m["completeness"], m["psnr_db"], m["ssim"], m.get("psnr_filled_db", 0),
        m.get("ssim_filled", 0),
        "%.4f" % m["depth_median_relative_error"] if "depth_median_relative_error" in m else "-",
        "%.3f" % m["depth_within_tolerance"] if "depth_within_tolerance" in m else "-",
        "%.5f" % pano["fov_largest_hole_fraction"] if "fov_largest_hole_fraction" in pano else "-"))
PY

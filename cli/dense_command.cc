// `casual3d dense <workspace> -o <out>`: the dense stage (Sec. 4.3), a depth
// map, confidence and near envelope per photo. See reconstruct/depth/dense_stage.h;
// with --pass, one unit of it (reconstruct/depth/dense_units.h).

#include <cstdio>
#include <stdexcept>
#include <string>

#include "cli/command.h"
#include "reconstruct/depth/dense_stage.h"
#include "reconstruct/depth/dense_units.h"
#include "reconstruct/util/log.h"

namespace casual3d::cli {
namespace {

struct DenseCommandOptions {
  std::string workspace;
  std::string out;
  bool no_near_envelope = false;
  bool no_gc_filter = false;
  bool refine = false;
  bool no_flat_regions = false;
  bool no_relabel = false;
  bool no_fullres_refine = false;
  bool no_free_space_check = false;
  std::string pass;    // Empty: the whole stage.
  std::string photos;  // With --pass sweep or depth; empty: all.
  depth::DenseOptions dense;
};

void PrintReport(const depth::DenseReport& report, const std::string& out);

// One unit of the stage (--pass).
void RunUnit(const DenseCommandOptions& o, const depth::DenseOptions& opt) {
  depth::DensePass pass;
  if (!depth::DensePassFromName(o.pass, &pass))
    throw std::invalid_argument("--pass " + o.pass + ": not a pass (plan, sweep, depth, finish)");
  if (!o.photos.empty() && pass != depth::DensePass::kSweep && pass != depth::DensePass::kDepth)
    throw std::invalid_argument("--photos applies to --pass sweep and --pass depth only");
  const std::vector<int> photos = o.photos.empty() ? std::vector<int>() : depth::ParsePhotoList(o.photos);
  const depth::DenseUnitResult r = depth::RunDenseUnit(o.workspace, o.out, opt, pass, photos);
  switch (pass) {
    case depth::DensePass::kPlan:
      for (size_t i = 0; i < r.photos.size(); ++i) std::printf("%zu\t%s\n", i, r.photos[i].c_str());
      break;
    case depth::DensePass::kSweep:
    case depth::DensePass::kDepth:
      std::printf("dense: %s pass: %d photos done, %d already done\n", o.pass.c_str(), r.ran, r.skipped);
      break;
    case depth::DensePass::kFinish:
      PrintReport(r.report, o.out);
      break;
  }
}

void RunDense(const DenseCommandOptions& o) {
  depth::DenseOptions opt = o.dense;
  opt.use_near_envelope = !o.no_near_envelope;
  opt.use_gc_filter = !o.no_gc_filter;
  opt.refine.enabled = o.refine;
  opt.flat.enabled = !o.no_flat_regions;
  opt.relabel.enabled = !o.no_relabel;
  opt.fullres.enabled = !o.no_fullres_refine;
  opt.visibility.enabled = !o.no_free_space_check;
  const Status st = opt.Check();
  if (!st.ok()) throw std::invalid_argument("dense: " + st.message());
  if (!o.pass.empty()) {
    RunUnit(o, opt);
    return;
  }
  PrintReport(depth::RunDenseStage(o.workspace, o.out, opt), o.out);
}

void PrintReport(const depth::DenseReport& report, const std::string& out) {
  std::printf("dense: %zu depth maps in %s (%.1f s, peak memory %.0f MB)\n", report.photos.size(),
              out.c_str(), report.seconds_total, report.peak_rss_bytes / 1048576.0);
  std::printf("dense: cross-view consistency (depth within 2%% of >= 2 other views): %.1f%%\n",
              100 * report.cross_view_consistency);
  if (report.evaluated) {
    std::printf(
        "dense: against ground truth: median relative error %.2f%%, within 3%%: %.1f%%, near "
        "floaters: %.2f%%\n",
        100 * report.median_rel_error, 100 * report.within_3pct, 100 * report.near_floaters);
    if (report.observed_fraction > 0) {
      std::printf(
          "dense: on the %.1f%% of pixels whose surface >= 2 swept neighbours see: median %.2f%%, "
          "within 3%%: %.1f%%, near floaters: %.2f%%\n",
          100 * report.observed_fraction, 100 * report.median_rel_error_observed,
          100 * report.within_3pct_observed, 100 * report.near_floaters_observed);
    }
  }
}

}  // namespace

void AddDenseCommand(CLI::App& app) {
  auto opts = std::make_shared<DenseCommandOptions>();
  CLI::App* cmd = app.add_subcommand(
      "dense", "Depth map per photo: plane-sweep MVS with the near envelope prior and an MRF");
  cmd->add_option("workspace", opts->workspace,
                  "Workspace with images/ (undistorted photos) and sparse/ (COLMAP model)")
      ->required();
  cmd->add_option("-o,--out", opts->out, "Output folder (depth/, confidence/, envelope/, dense.json)")
      ->required();
  cmd->add_flag("--debug", opts->dense.debug, "Also write colour-mapped PNGs of every step to OUT/debug/");
  cmd->add_flag("--no-near-envelope", opts->no_near_envelope,
                "Ablation: MRF without the near envelope term (Eq. 4)");
  cmd->add_flag("--no-gc-filter", opts->no_gc_filter, "Ablation: build anchors without the GC filter");
  cmd->add_flag("--no-flat-regions", opts->no_flat_regions,
                "Ablation: no depth priors for textureless regions from their silhouettes");
  cmd->add_flag("--no-relabel", opts->no_relabel,
                "Ablation: keep fattened depth edges (no full-resolution boundary relabelling)");
  cmd->add_flag("--no-fullres-refine", opts->no_fullres_refine,
                "Ablation: no full-resolution depth search after upsampling");
  cmd->add_flag("--no-free-space-check", opts->no_free_space_check,
                "Ablation: keep depths that other photos' depth maps see through");
  cmd->add_option("--free-space-tolerance", opts->dense.visibility.tolerance,
                  "Relative depth band within which another photo's depth agrees (free-space check)")
      ->capture_default_str();
  cmd->add_option("--free-space-labels", opts->dense.visibility.tolerance_labels,
                  "... or this many label steps of inverse depth, whichever is larger")
      ->capture_default_str();
  cmd->add_option("--free-space-views", opts->dense.visibility.max_views,
                  "Other photos each depth map is checked against (best neighbours first)")
      ->capture_default_str();
  cmd->add_option("--free-space-rounds", opts->dense.visibility.rounds,
                  "Rounds of the free-space check over all photos")
      ->capture_default_str();
  cmd->add_option("--lambda-flat", opts->dense.mrf.lambda_flat,
                  "Weight of the textureless-region prior in the MRF data term")
      ->capture_default_str();
  cmd->add_option("--relabel-neighbors", opts->dense.relabel.max_neighbors,
                  "Neighbours the boundary relabelling tests (the sweep's first ones)")
      ->capture_default_str();
  cmd->add_flag("--refine", opts->refine,
                "Continuous depth search within one label of the MRF's (slower; helps wide baselines)");
  cmd->add_option("--threads", opts->dense.num_threads, "Worker threads (0 = all cores)")
      ->check(CLI::Range(0, 1024));
  cmd->add_option("--scale", opts->dense.working_scale,
                  "Sweep/MRF resolution relative to the photos, in (0, 1]")
      ->capture_default_str();
  cmd->add_option("--depths", opts->dense.sweep.num_depths, "Depth hypotheses (Sec. 4.3.1: 220)")
      ->capture_default_str();
  cmd->add_option("--neighbors", opts->dense.num_neighbors, "Neighbour photos per sweep")
      ->capture_default_str();
  cmd->add_option("--lambda-smooth", opts->dense.mrf.lambda_smooth, "Smoothness weight (Eq. 1)")
      ->capture_default_str();
  cmd->add_option("--lambda-near", opts->dense.mrf.lambda_near, "Near envelope penalty (Eq. 4)")
      ->capture_default_str();
  cmd->add_option("--mrf-passes", opts->dense.mrf.max_iterations,
                  "Most TRW-S passes (each forward and backward); fewer is faster, at a higher energy")
      ->capture_default_str();
  cmd->add_option("--window-radius", opts->dense.sweep.window_radius,
                  "ZNCC window radius at working resolution (2: 5x5)")
      ->capture_default_str();
  cmd->add_option("--texture-color-sigma", opts->dense.sweep.texture_color_sigma,
                  "Colour sigma of the texture measure w_photo; 0 = plain window variance")
      ->capture_default_str();
  cmd->add_option("--min-far-over-near", opts->dense.min_far_over_near,
                  "The sweep's far plane is at least this many times farther than its near plane")
      ->capture_default_str();
  cmd->add_option("--far-bias", opts->dense.mrf.far_bias,
                  "Cost leaning textureless pixels away from the camera (MRF data term)")
      ->capture_default_str();
  cmd->add_option("--occlusion-truncation", opts->dense.sweep.occlusion_truncation,
                  "Each of the best neighbours' matching costs is capped at the best one's plus "
                  "this (1: plain mean)")
      ->capture_default_str();
  cmd->add_option("--neighbor-coverage", opts->dense.neighbors.coverage_k,
                  "Neighbours are picked so that each part of the photo has this many partners "
                  "(0: by score alone)")
      ->capture_default_str();
  cmd->add_option("--pass", opts->pass,
                  "Run one unit of the stage over a shared OUT, for several processes or machines: "
                  "plan (list the photos), sweep, depth (per photo, see --photos), finish (all "
                  "photos); all units give the same files as one run without --pass");
  cmd->add_option("--photos", opts->photos,
                  "With --pass sweep or depth: the photos, by index in the plan, e.g. 0,3,5-9 (default: all)");
  cmd->add_option("--ground-truth", opts->dense.ground_truth_dir,
                  "Folder of ground-truth depth <stem>.exr (e.g. a synthetic capture's depth/) "
                  "to evaluate against; results go to dense.json");
  cmd->callback([opts]() { RunDense(*opts); });
}

}  // namespace casual3d::cli

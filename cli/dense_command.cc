// `casual3d dense <workspace> -o <out>`: the dense stage (Sec. 4.3), a depth
// map, confidence and near envelope per photo. See reconstruct/depth/dense_stage.h;
// with --pass, one unit of it (reconstruct/depth/dense_units.h).

#include <cstdio>
#include <stdexcept>
#include <string>

#include "cli/command.h"
#include "cli/described_option.h"
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
      // One line per photo, in the order to sweep them: its index, its name
      // and the sweeps its depth unit reads.
      for (int i : r.sweep_order) {
        std::string needs;
        for (int j : r.needs[i]) needs += (needs.empty() ? "" : ",") + std::to_string(j);
        std::printf("%d\t%s\t%s\n", i, r.photos[i].c_str(), needs.c_str());
      }
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
  AddDescribedOption(cmd, "--free-space-tolerance", opts->dense, opts->dense.visibility.tolerance);
  AddDescribedOption(cmd, "--free-space-labels", opts->dense, opts->dense.visibility.tolerance_labels);
  AddDescribedOption(cmd, "--free-space-views", opts->dense, opts->dense.visibility.max_views);
  AddDescribedOption(cmd, "--free-space-rounds", opts->dense, opts->dense.visibility.rounds);
  AddDescribedOption(cmd, "--lambda-flat", opts->dense, opts->dense.mrf.lambda_flat);
  AddDescribedOption(cmd, "--relabel-neighbors", opts->dense, opts->dense.relabel.max_neighbors);
  AddDescribedOption(cmd, "--threads", opts->dense, opts->dense.num_threads);
  AddDescribedOption(cmd, "--scale", opts->dense, opts->dense.working_scale);
  AddDescribedOption(cmd, "--depths", opts->dense, opts->dense.sweep.num_depths);
  AddDescribedOption(cmd, "--neighbors", opts->dense, opts->dense.num_neighbors);
  AddDescribedOption(cmd, "--lambda-smooth", opts->dense, opts->dense.mrf.lambda_smooth);
  AddDescribedOption(cmd, "--lambda-near", opts->dense, opts->dense.mrf.lambda_near);
  AddDescribedOption(cmd, "--mrf-passes", opts->dense, opts->dense.mrf.max_iterations);
  AddDescribedOption(cmd, "--window-radius", opts->dense, opts->dense.sweep.window_radius);
  AddDescribedOption(cmd, "--texture-color-sigma", opts->dense, opts->dense.sweep.texture_color_sigma);
  AddDescribedOption(cmd, "--min-far-over-near", opts->dense, opts->dense.min_far_over_near);
  AddDescribedOption(cmd, "--far-bias", opts->dense, opts->dense.mrf.far_bias);
  AddDescribedOption(cmd, "--occlusion-truncation", opts->dense, opts->dense.sweep.occlusion_truncation);
  AddDescribedOption(cmd, "--neighbor-coverage", opts->dense, opts->dense.neighbors.coverage_k);
  cmd->add_option("--pass", opts->pass,
                  "Run one unit of the stage over a shared OUT, for several processes or machines: "
                  "plan (list the photos), sweep, depth (per photo, see --photos), finish (all "
                  "photos); all units give the same files as one run without --pass");
  cmd->add_option("--photos", opts->photos,
                  "With --pass sweep or depth: the photos, by index in the plan, e.g. 0,3,5-9 (default: all)");
  AddDescribedOption(cmd, "--ground-truth", opts->dense, opts->dense.ground_truth_dir);
  cmd->callback([opts]() { RunDense(*opts); });
}

}  // namespace casual3d::cli

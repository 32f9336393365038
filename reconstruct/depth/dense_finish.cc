#include "reconstruct/depth/dense_finish.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <stdexcept>

#include <opencv2/imgproc.hpp>

#include "reconstruct/depth/dense_free_space.h"
#include "reconstruct/depth/dense_report.h"
#include "reconstruct/depth/depth_metrics.h"
#include "reconstruct/io/color_map.h"
#include "reconstruct/io/cv_bridge.h"
#include "reconstruct/io/exr_io.h"
#include "reconstruct/io/image_io.h"

namespace casual3d::depth {
namespace fs = std::filesystem;
namespace {

using Clock = std::chrono::steady_clock;

size_t PeakRssBytes() {
  std::ifstream f("/proc/self/status");
  std::string line;
  while (std::getline(f, line))
    if (line.rfind("VmHWM:", 0) == 0) return std::stoull(line.substr(6)) * 1024;
  return 0;
}

// Per-pixel verdict against ground truth: red = near floater (d < 0.85 g),
// yellow = nearer than 3%, green = within 3%, blue = farther than 3%,
// grey = sky (non-finite ground truth) estimated nearer than the far half of
// the range, black = sky otherwise.
Image8 ErrorMap(const ImageF& depth, const ImageF& gt) {
  const int w = depth.width(), h = depth.height();
  Image8 rgb(w, h, 3, 0);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const int gx = std::min(gt.width() - 1, static_cast<int>((x + 0.5) * gt.width() / w));
      const int gy = std::min(gt.height() - 1, static_cast<int>((y + 0.5) * gt.height() / h));
      const float g = gt.at(gx, gy), d = depth.at(x, y);
      uint8_t c[3] = {0, 0, 0};
      if (!(std::isfinite(g) && g > 0)) {
        if (std::isfinite(d)) c[0] = c[1] = c[2] = 96;
      } else if (!(d >= 0.85f * g)) {
        c[0] = 255;
      } else if (d < 0.97f * g) {
        c[0] = 255, c[1] = 200;
      } else if (d <= 1.03f * g) {
        c[1] = 200;
      } else {
        c[2] = 255;
      }
      for (int k = 0; k < 3; ++k) rgb.at(x, y, k) = c[k];
    }
  return rgb;
}

// `image` sampled at the pixel nearest each centre of a width x height grid.
ImageF ResizeNearest(const ImageF& image, int width, int height) {
  ImageF out(width, height, image.channels());
  cv::Mat dst = io::ToMat(out);
  cv::resize(io::ToMat(image), dst, cv::Size(width, height), 0, 0, cv::INTER_NEAREST_EXACT);
  return out;
}

// An image held elsewhere, as a pointer that owns nothing.
std::shared_ptr<const ImageF> Lend(const ImageF& image) {
  return std::shared_ptr<const ImageF>(std::shared_ptr<const ImageF>(), &image);
}

// Photo i's final map against its ground truth `gt`, over all pixels and
// over those whose true surface >= 2 swept neighbours see (`swept_gt`: the
// ground truth of plan.swept[i], in its order; empty ones skipped).
void EvaluateFinalDepth(const DensePlan& plan, int i, const ImageF& depth, const ImageF& gt,
                        const std::vector<std::shared_ptr<const ImageF>>& swept_gt, const CostVolume& shell,
                        const std::string& debug_dir, bool debug, PhotoReport* pr) {
  const DenseView& v = plan.ws.views[i];
  pr->evaluated = true;
  const LabelGrid grid{shell.inv_near, shell.inv_far, shell.num_labels};
  if (debug) {
    const std::string base = (fs::path(debug_dir) / OutputStem(v.name)).string();
    const Image8 gt_rgb = io::ColorizeDepth(gt, v.range.near_m, v.range.far_m), err_rgb = ErrorMap(depth, gt);
    io::WritePng(base + "_gt.png", gt_rgb.view());
    io::WritePng(base + "_error.png", err_rgb.view());
  }
  // Which swept neighbours see each pixel's true surface.
  std::vector<PinholeCamera> nb_cam;
  std::vector<const ImageF*> gt_ptrs;
  for (size_t k = 0; k < plan.swept[i].size(); ++k) {
    const ImageF& g = *swept_gt[k];
    if (g.empty()) continue;
    nb_cam.push_back(plan.ws.views[plan.swept[i][k]].camera.Resized(g.width(), g.height()));
    gt_ptrs.push_back(&g);
  }
  std::vector<const PinholeCamera*> cam_ptrs;
  for (const PinholeCamera& c : nb_cam) cam_ptrs.push_back(&c);
  const std::vector<uint8_t> observers =
      AgreeingViews(v.camera.Resized(gt.width(), gt.height()), gt, cam_ptrs, gt_ptrs, 0.02);
  const DepthAccuracy acc = EvaluateDepth(depth, gt, 0.5 * v.range.far_m, grid.InvStep(), &observers, 2);
  pr->pixels = acc.pixels;
  pr->observed_pixels = acc.observed_pixels;
  pr->median_rel_error_observed = acc.median_rel_error_observed;
  pr->within_3pct_observed = acc.within_3pct_observed;
  pr->near_floaters_observed = acc.near_floaters_observed;
  pr->median_rel_error = acc.median_rel_error;
  pr->within_3pct = acc.within_3pct;
  pr->near_floaters = acc.near_floaters;
  pr->sky_near = acc.sky_near;
  pr->within_half_label = acc.within_half_label;
  pr->within_two_labels = acc.within_two_labels;
}

}  // namespace

FinishInputs LendFinishInputs(const DensePlan& plan, const std::vector<ImageF>& depth,
                              const std::vector<ImageF>& ground_truth) {
  FinishInputs inputs;
  inputs.depth = [&depth](int i) { return Lend(depth.at(i)); };
  inputs.gray_full = [&plan](int i) {
    if (!HasViewPixels(plan.ws, i))
      throw std::logic_error("dense: photo " + plan.ws.views[i].name + " was not loaded before the finish pass");
    return Lend(plan.ws.views[i].gray_full);
  };
  inputs.ground_truth = [&ground_truth](int i) { return Lend(ground_truth.at(i)); };
  return inputs;
}

DenseReport FinishDense(const DensePlan& plan, const DenseOptions& options, const FinishInputs& inputs,
                        std::vector<PhotoReport> photos, const std::vector<CostVolume>& shells,
                        const std::string& out_dir, std::chrono::steady_clock::time_point start,
                        double seconds_load) {
  const int n = plan.size();
  const int threads = base::ResolveThreads(options.num_threads);
  FreeSpaceResult checked;
  if (options.visibility.enabled) {
    checked = CheckFreeSpaceRounds(plan, shells, options.visibility, threads, inputs.depth, inputs.gray_full);
    for (int i = 0; i < n; ++i) {
      photos[i].seen_through += checked.stats[i].flagged;
      photos[i].moved_back += checked.stats[i].replaced;
      photos[i].t_visibility += checked.seconds[i];
    }
  }
  const int rounds = static_cast<int>(checked.rounds.size());

  // Outputs and evaluation of the final maps, one map at a time: read, its
  // replacements applied, written, evaluated, and kept only at working
  // resolution for the cross-view consistency (the pixel nearest each
  // working pixel's centre).
  const std::string debug_dir = (fs::path(out_dir) / "debug").string();
  const bool evaluate = !options.ground_truth_dir.empty();
  // The evaluation of a photo reads its swept neighbours' ground truth too.
  ImageCache ground_truth(2 * (1 + options.num_neighbors), inputs.ground_truth);
  std::vector<ImageF> final_low(n);
  ForEachPhoto(plan, AllPhotos(n), threads, [&](int i) {
    const DenseView& v = plan.ws.views[i];
    PhotoReport& pr = photos[i];
    const std::string stem = OutputStem(v.name);
    const std::shared_ptr<const ImageF> depth = AfterMoves(inputs.depth(i), checked.rounds, i, rounds);
    const auto t0 = Clock::now();
    // ZIP compression: a third smaller.
    io::WriteExr((fs::path(out_dir) / "depth" / (stem + ".exr")).string(), *depth, {"Z"});
    if (options.debug) {
      const Image8 rgb = io::ColorizeDepth(*depth, v.range.near_m, v.range.far_m);
      io::WritePng((fs::path(debug_dir) / (stem + "_depth.png")).string(), rgb.view());
    }
    pr.t_upsample += SecondsSince(t0);
    if (evaluate) {
      const std::shared_ptr<const ImageF> gt = ground_truth.Get(i);
      if (!gt->empty()) {
        std::vector<std::shared_ptr<const ImageF>> swept_gt;
        for (int j : plan.swept[i]) swept_gt.push_back(ground_truth.Get(j));
        EvaluateFinalDepth(plan, i, *depth, *gt, swept_gt, shells[i], debug_dir, options.debug, &pr);
      }
    }
    final_low[i] = ResizeNearest(*depth, v.camera.width, v.camera.height);
  });

  // Cross-view consistency of the final depth maps at working resolution.
  std::vector<const DenseView*> view_ptrs;
  std::vector<const ImageF*> low_ptrs(n);
  for (const DenseView& v : plan.ws.views) view_ptrs.push_back(&v);
  for (int i = 0; i < n; ++i) low_ptrs[i] = &final_low[i];
  base::ParallelFor(0, n, threads, [&](int64_t i) {
    photos[i].cross_view_consistency =
        CrossViewConsistency(static_cast<int>(i), view_ptrs, low_ptrs, plan.ws.ranked_neighbors[i]);
  });

  DenseReport report;
  report.photos = std::move(photos);
  report.seconds_load = seconds_load;
  SummariseDenseReport(&report);
  report.seconds_total = SecondsSince(start);
  report.peak_rss_bytes = PeakRssBytes();
  WriteDenseJson((fs::path(out_dir) / "dense.json").string(), report, options);
  return report;
}

}  // namespace casual3d::depth

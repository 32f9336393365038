#include "reconstruct/depth/dense_passes.h"

#include <algorithm>
#include <cmath>
#include <filesystem>

#include <opencv2/imgproc.hpp>

#include "reconstruct/depth/cost_cache.h"
#include "reconstruct/depth/dense_mrf.h"
#include "reconstruct/depth/depth_metrics.h"
#include "reconstruct/depth/mrf_trws.h"
#include "reconstruct/io/color_map.h"
#include "reconstruct/io/cv_bridge.h"
#include "reconstruct/io/exr_io.h"
#include "reconstruct/io/file_util.h"
#include "reconstruct/io/image_io.h"

namespace casual3d::depth {
namespace fs = std::filesystem;
namespace {

using Clock = std::chrono::steady_clock;

int ScaledRadius(int radius_at_reference, double ratio) {
  return std::max(1, static_cast<int>(std::lround(radius_at_reference * ratio)));
}

// Inverse depth over the photo's range (near = warm); invalid pixels black.
Image8 Colorize(const ImageF& depth, const DepthRange& range) {
  return io::ColorizeDepth(depth, range.near_m, range.far_m);
}

ImageF ResizeLinear(const ImageF& image, int width, int height) {
  ImageF out(width, height, image.channels());
  cv::Mat dst = io::ToMat(out);
  cv::resize(io::ToMat(image), dst, cv::Size(width, height), 0, 0, cv::INTER_LINEAR);
  return out;
}

int CountValid(const ImageF& depth) {
  int n = 0;
  for (float v : depth.vector()) n += v > 0;
  return n;
}

std::string StemPath(const std::string& dir, const std::string& sub, const std::string& stem,
                     const std::string& suffix) {
  return (fs::path(dir) / sub / (stem + suffix)).string();
}

// Anchors (Fig. 4a-d) and near envelope (Fig. 4e-f) of photo i.
struct EnvelopeResult {
  ImageF gc, med, bil, propagated, envelope;  // envelope and propagated may be empty.
};
EnvelopeResult BuildEnvelope(const DensePlan& plan, int i, const DenseOptions& options, int threads,
                             const std::vector<const ImageF*>& wta, const LabelGrid& grid, PhotoReport* pr) {
  const DenseView& v = plan.ws.views[i];
  std::vector<const DenseView*> view_ptrs;
  for (const DenseView& view : plan.ws.views) view_ptrs.push_back(&view);
  EnvelopeResult r;
  r.gc = options.use_gc_filter ? GeometricConsistencyFilter(i, view_ptrs, wta, plan.ws.ranked_neighbors[i],
                                                            grid.InvStep(), options.gc, threads)
                               : *wta[i];
  MedianPruneOptions prune = options.prune;
  prune.small_radius = ScaledRadius(options.prune.small_radius, plan.diag_ratio);
  prune.large_radius = ScaledRadius(options.prune.large_radius, plan.diag_ratio);
  r.med = MedianPrune(r.gc, grid, prune, threads);
  r.bil = BilateralMedianPrune(r.med, v.color, grid, prune, threads);
  pr->anchors = {CountValid(*wta[i]), CountValid(r.gc), CountValid(r.med), CountValid(r.bil)};

  EnvelopeOptions env_opt = options.envelope;
  env_opt.variance_radius = ScaledRadius(options.envelope.variance_radius, plan.diag_ratio);
  PropagationStats ps;
  r.propagated = PropagateAnchors(r.bil, v.color, env_opt, &ps);
  pr->cg_iterations = ps.iterations;
  if (!r.propagated.empty()) r.envelope = FinalizeEnvelope(r.propagated, env_opt);
  return r;
}

// The MRF (Eq. 1-4) and its labels' sub-label depth at working resolution.
struct MrfResult {
  ImageF low_depth, low_conf;
  ImageF trws_depth;               // With debug only.
  std::vector<float> flat_prior;   // Fractional labels, NaN = none; empty when off.
  ImageF photo_weight;
  CostVolume grid;                 // Sizes and depth grid (no costs).
};
MrfResult SolveDepthMrf(const DensePlan& plan, int i, const DenseOptions& options, int threads,
                        const ImageF& wta, const ImageF& envelope, const CostVolume& shell,
                        const std::string& cost_path, BufferPool* pool, PhotoReport* pr) {
  const DenseView& v = plan.ws.views[i];
  const std::vector<const DenseView*> swept = plan.SweptViews(i);
  const LabelGrid grid{shell.inv_near, shell.inv_far, shell.num_labels};
  auto t0 = Clock::now();
  CostVolume vol = shell;
  const int w = vol.width, h = vol.height, L = vol.num_labels;
  const size_t np = static_cast<size_t>(w) * h;
  pool->TakeForOverwrite(&vol.cost, np * L);
  vol.photo_weight = ImageF(w, h, 1);
  ReadCostCache(cost_path, np * L, &vol.cost, &vol.photo_weight);
  GridMrf mrf;
  mrf.width = w;
  mrf.height = h;
  mrf.num_labels = L;
  MrfResult r;
  // Priors for textureless regions from their silhouettes (flat_regions.h).
  if (options.flat.enabled) {
    const auto tf = Clock::now();
    std::vector<FlatRegionNeighbor> fn;
    for (const DenseView* nb : swept) fn.push_back({&nb->color, nb->camera});
    FlatRegionStats flat_stats;
    r.flat_prior = FlatRegionPriors(v.color, vol.photo_weight, v.camera, wta, fn, vol, options.flat, &flat_stats);
    pr->t_flat = SecondsSince(tf);
    pr->flat_groups = flat_stats.groups;
    pr->flat_fitted = flat_stats.fitted;
    pr->flat_pixels = flat_stats.pixels;
  }
  const bool near_term = options.use_near_envelope && !envelope.empty() && options.mrf.lambda_near > 0;
  // The unary takes the costs' buffer (one buffer of 220 MB less per photo
  // in flight, so the pool can keep them all and no page is zeroed
  // afresh); the costs are read back from the cache after the solve.
  mrf.unary.swap(vol.cost);
  AssembleDenseMrf(vol.photo_weight, v.color, r.flat_prior, near_term ? envelope : ImageF(), grid, options.mrf,
                   &mrf);
  TrwsOptions trws;
  trws.max_iterations = options.mrf.max_iterations;
  const TrwsResult res = SolveTrws(mrf, trws, pool);
  vol.cost.swap(mrf.unary);
  ReadCostCache(cost_path, np * L, &vol.cost, nullptr);
  pr->mrf_energy = res.energy;
  pr->mrf_iterations = res.iterations;

  // Edge-aware median (window fattening), sub-label refinement, depth and confidence.
  const std::vector<int> labels = EdgeAwareMedian(std::vector<int>(res.labels.begin(), res.labels.end()), L,
                                                  v.color, options.edge_median, threads);
  std::vector<float> fl = FitSubLabel(vol, labels, options.sublabel, threads);
  pr->t_mrf = SecondsSince(t0);
  if (options.debug) {
    r.trws_depth = ImageF(w, h, 1);
    for (size_t p = 0; p < np; ++p) r.trws_depth.data()[p] = static_cast<float>(vol.DepthOfLabel(res.labels[p]));
  }
  t0 = Clock::now();
  fl = SmoothSubLabel(vol, std::move(fl), v.color, options.sublabel, threads);
  // Within a fitted flat region the plane is the estimate: the photos carry
  // no evidence there to refine it by.
  if (!r.flat_prior.empty())
    for (size_t p = 0; p < np; ++p)
      if (!std::isnan(r.flat_prior[p])) fl[p] = r.flat_prior[p];
  r.low_depth = ImageF(w, h, 1);
  r.low_conf = ImageF(w, h, 1);
  for (size_t p = 0; p < np; ++p) {
    const float* c = vol.cost.data() + p * L;
    r.low_depth.data()[p] = static_cast<float>(vol.DepthOfLabel(fl[p]));
    r.low_conf.data()[p] = vol.photo_weight.data()[p] * std::max(0.0f, 1.0f - c[labels[p]]);
  }
  pool->Give(&vol.cost);
  r.photo_weight = std::move(vol.photo_weight);
  r.grid = std::move(vol);
  pr->t_refine = SecondsSince(t0);
  return r;
}

// Full resolution (Sec. 4.3.1: joint bilateral weighted median), then the
// farther side's depth back onto fattened edge bands and a search within a
// label around every textured pixel (fullres_refine.h).
ImageF UpsampleDepth(const DensePlan& plan, int i, const DenseOptions& options, int threads, const ImageF& low_depth,
                     const LabelGrid& grid, const ImageF& full_color, PhotoReport* pr) {
  const DenseView& v = plan.ws.views[i];
  UpsampleOptions up = options.upsample;
  up.num_threads = threads;
  ImageF depth = JointBilateralMedianUpsample(low_depth, v.color, full_color, up);
  if (options.relabel.enabled || options.fullres.enabled) {
    const auto tf = Clock::now();
    std::vector<RefineNeighbor> rn;
    for (const DenseView* nb : plan.SweptViews(i)) rn.push_back({&nb->gray_full, nb->camera_full});
    if (options.relabel.enabled)
      depth = RelabelBoundaries(full_color, v.gray_full, v.camera_full, depth, rn, grid.InvStep(), options.relabel,
                                threads, &pr->relabelled);
    if (options.fullres.enabled) {
      FullResRefineStats rs;
      depth = RefineFullResolution(v.gray_full, v.camera_full, depth, rn, grid.InvStep(), options.fullres, threads,
                                   &rs);
      pr->refined = rs.refined;
    }
    pr->t_fullres = SecondsSince(tf);
  }
  return depth;
}

void WriteDepthDebug(const std::string& debug_dir, const std::string& stem, const DepthRange& range,
                     const ImageF& wta, const EnvelopeResult& env, const MrfResult& mrf, const ImageF& upsampled) {
  auto png = [&](const char* what, const ImageF& img) {
    const Image8 rgb = Colorize(img, range);
    io::WritePng((fs::path(debug_dir) / (stem + "_" + what + ".png")).string(), rgb.view());
  };
  const CostVolume& vol = mrf.grid;
  const int w = vol.width, h = vol.height;
  const size_t np = static_cast<size_t>(w) * h;
  png("wta", wta);
  png("gc", env.gc);
  png("median", env.med);
  png("bilateral", env.bil);
  if (!env.propagated.empty()) png("propagated", env.propagated);
  if (!env.envelope.empty()) png("envelope", env.envelope);
  png("trws", mrf.trws_depth);
  if (!mrf.flat_prior.empty()) {
    ImageF fp(w, h, 1, 0.0f);
    for (size_t p = 0; p < np; ++p)
      if (!std::isnan(mrf.flat_prior[p])) fp.data()[p] = static_cast<float>(vol.DepthOfLabel(mrf.flat_prior[p]));
    png("flat", fp);
  }
  png("mrf", mrf.low_depth);
  Image8 texture(w, h, 1);
  for (size_t p = 0; p < np; ++p)
    texture.data()[p] = static_cast<uint8_t>(std::lround(255.0f * mrf.photo_weight.data()[p]));
  io::WritePng((fs::path(debug_dir) / (stem + "_texture.png")).string(), texture);
  png("upsampled", upsampled);
}

}  // namespace

std::vector<const DenseView*> DensePlan::SweptViews(int i) const {
  std::vector<const DenseView*> out;
  for (int j : swept[i]) out.push_back(&ws.views[j]);
  return out;
}

std::vector<int> PhotosRead(const DensePlan& plan, const std::vector<int>& photos) {
  std::vector<int> read;
  for (int i : photos) {
    read.push_back(i);
    read.insert(read.end(), plan.swept[i].begin(), plan.swept[i].end());
  }
  std::sort(read.begin(), read.end());
  read.erase(std::unique(read.begin(), read.end()), read.end());
  return read;
}

namespace {

// Photo i and its swept neighbours must have their pixels (PhotosRead).
void CheckPixelsLoaded(const DensePlan& plan, int i) {
  for (int j : PhotosRead(plan, {i}))
    if (!HasViewPixels(plan.ws, j))
      throw std::logic_error("dense: photo " + plan.ws.views[j].name + " was not loaded before " +
                             plan.ws.views[i].name + "'s pass");
}

}  // namespace

std::vector<int> SweepsNeeded(const DensePlan& plan, const DenseOptions& options, int i) {
  std::vector<int> needed = {i};
  if (options.use_gc_filter)
    for (int j : plan.ws.ranked_neighbors[i])
      if (j != i && static_cast<int>(needed.size()) <= options.gc.max_views) needed.push_back(j);
  return needed;
}

double SecondsSince(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

std::vector<int> AllPhotos(int n) {
  std::vector<int> all(n);
  for (int i = 0; i < n; ++i) all[i] = i;
  return all;
}

DensePlan PlanDense(const std::string& workspace_dir, const DenseOptions& options, bool load_pixels) {
  DensePlan plan;
  plan.ws = LoadWorkspace(workspace_dir, options.working_scale, options.neighbors, load_pixels);
  const int n = plan.size();
  // Far-plane extension (dense_stage.h): labels are added beyond the sparse
  // range at the sparse range's spacing, so near content keeps its precision.
  plan.num_labels.assign(n, options.sweep.num_depths);
  plan.swept.resize(n);
  for (int i = 0; i < n; ++i) {
    DepthRange& r = plan.ws.views[i].range;
    const double far = std::max(r.far_m, options.min_far_over_near * r.near_m);
    const double grow = (1.0 / r.near_m - 1.0 / far) / (1.0 / r.near_m - 1.0 / r.far_m);
    plan.num_labels[i] = std::min(4 * options.sweep.num_depths,
                                  static_cast<int>(std::ceil(options.sweep.num_depths * grow - 1e-9)));
    r.far_m = far;
    for (int j : plan.ws.ranked_neighbors[i]) {
      if (static_cast<int>(plan.swept[i].size()) >= options.num_neighbors) break;
      plan.swept[i].push_back(j);
    }
  }
  plan.diag_ratio =
      std::hypot(plan.ws.views[0].camera.width, plan.ws.views[0].camera.height) / options.reference_diagonal;
  return plan;
}

PhotoReport PhotoHeader(const DensePlan& plan, int i) {
  const DenseView& v = plan.ws.views[i];
  PhotoReport pr;
  pr.name = v.name;
  pr.near_m = v.range.near_m;
  pr.far_m = v.range.far_m;
  pr.work_width = v.camera.width;
  pr.work_height = v.camera.height;
  pr.num_labels = plan.num_labels[i];
  pr.width = v.full_width;
  pr.height = v.full_height;
  for (int j : plan.swept[i]) pr.neighbors.push_back(plan.ws.views[j].name);
  return pr;
}

void CreateDenseOutputFolders(const std::string& out_dir, const DenseOptions& options) {
  io::CreateDirectories(out_dir);
  for (const char* sub : {"depth", "confidence", "envelope"}) io::CreateDirectories((fs::path(out_dir) / sub).string());
  if (options.debug) io::CreateDirectories((fs::path(out_dir) / "debug").string());
}

CostVolume SweepPhoto(const DensePlan& plan, int i, const DenseOptions& options, int threads,
                      const std::string& cost_path, BufferPool* pool, ImageF* wta) {
  CheckPixelsLoaded(plan, i);
  SweepOptions sweep = options.sweep;
  sweep.num_threads = threads;
  sweep.num_depths = plan.num_labels[i];
  CostVolume vol = ComputeCostVolume(plan.ws.views[i], plan.SweptViews(i), sweep, pool);
  *wta = WinnerTakesAll(vol, sweep.num_threads);
  WriteCostCache(cost_path, vol);
  pool->Give(&vol.cost);
  CostVolume shell;
  shell.width = vol.width;
  shell.height = vol.height;
  shell.num_labels = vol.num_labels;
  shell.inv_near = vol.inv_near;
  shell.inv_far = vol.inv_far;
  return shell;
}

ImageF ReadDepthMap(const std::string& dir, const std::string& stem) {
  const std::string path = (fs::path(dir) / (stem + ".exr")).string();
  if (!fs::exists(path)) return ImageF();
  io::ExrImage exr = io::ReadExr(path);
  int channel = 0;
  for (size_t c = 0; c < exr.channels.size(); ++c)
    if (exr.channels[c] == "Z" || exr.channels[c] == "depth") channel = static_cast<int>(c);
  ImageF gt(exr.pixels.width(), exr.pixels.height(), 1);
  for (int y = 0; y < gt.height(); ++y)
    for (int x = 0; x < gt.width(); ++x) gt.at(x, y) = exr.pixels.at(x, y, channel);
  return gt;
}

ImageF DepthPhoto(const DensePlan& plan, int i, const DenseOptions& options, int threads,
                  const std::vector<const ImageF*>& wta, const CostVolume& shell, const std::string& cost_path,
                  const ImageF& ground_truth, const std::string& out_dir, BufferPool* pool, PhotoReport* pr) {
  CheckPixelsLoaded(plan, i);
  const DenseView& v = plan.ws.views[i];
  const std::string stem = OutputStem(v.name);
  const LabelGrid grid{shell.inv_near, shell.inv_far, shell.num_labels};
  auto t0 = Clock::now();
  const EnvelopeResult env = BuildEnvelope(plan, i, options, threads, wta, grid, pr);
  pr->t_envelope = SecondsSince(t0);
  const MrfResult mrf =
      SolveDepthMrf(plan, i, options, threads, *wta[i], env.envelope, shell, cost_path, pool, pr);

  t0 = Clock::now();
  const ImageF full_color = ReadPhotoFloat((fs::path(plan.ws.images_dir) / v.name).string());
  ImageF depth = UpsampleDepth(plan, i, options, threads, mrf.low_depth, grid, full_color, pr);
  const ImageF conf = ResizeLinear(mrf.low_conf, v.full_width, v.full_height);
  const ImageF env_full = !env.envelope.empty()
                              ? ResizeLinear(env.envelope, v.full_width, v.full_height)
                              : ImageF(v.full_width, v.full_height, 1, static_cast<float>(v.range.near_m));
  // The confidence and the envelope without ZIP (docs/DECISIONS.md, "Dense:
  // confidence and envelope maps written without compression"). The depth
  // map is written after pass 3.
  io::ExrWriteOptions plain;
  plain.compression = io::ExrCompression::kNone;
  io::WriteExr(StemPath(out_dir, "confidence", stem, ".exr"), conf.view(), {"Y"}, plain);
  io::WriteExr(StemPath(out_dir, "envelope", stem, ".exr"), env_full.view(), {"Z"}, plain);
  if (options.debug)
    WriteDepthDebug((fs::path(out_dir) / "debug").string(), stem, v.range, *wta[i], env, mrf, depth);
  pr->t_upsample = SecondsSince(t0);

  // Ground truth: the anchors and the envelope (Fig. 6); the final depth
  // is evaluated after pass 3.
  if (!options.ground_truth_dir.empty() && !ground_truth.empty()) {
    const double tol = 2.0 * grid.InvStep();
    const char* names[] = {"wta", "gc", "median", "bilateral"};
    const ImageF* maps[] = {wta[i], &env.gc, &env.med, &env.bil};
    for (int s = 0; s < 4; ++s) {
      const AnchorQuality q = EvaluateAnchors(*maps[s], ground_truth, tol);
      pr->stages.push_back({names[s], q.completeness, q.precision});
    }
    if (!env.envelope.empty()) {
      const EnvelopeQuality eq = EvaluateEnvelope(env.envelope, ground_truth);
      pr->envelope_error = eq.error;
      pr->envelope_tightness = eq.tightness;
    }
  }
  return depth;
}

}  // namespace casual3d::depth

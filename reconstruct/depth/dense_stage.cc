#include "reconstruct/depth/dense_stage.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <limits>
#include <mutex>
#include <stdexcept>

#include <nlohmann/json.hpp>
#include <opencv2/imgproc.hpp>

#include "reconstruct/depth/depth_metrics.h"
#include "reconstruct/depth/huge_pages.h"
#include "reconstruct/depth/mrf_trws.h"
#include "reconstruct/depth/parallel.h"
#include "reconstruct/depth/workspace.h"
#include "reconstruct/io/colour_map.h"
#include "reconstruct/io/cv_bridge.h"
#include "reconstruct/io/exr_io.h"
#include "reconstruct/io/file_util.h"
#include "reconstruct/io/image_io.h"
#include "reconstruct/util/log.h"

namespace casual3d::depth {
namespace fs = std::filesystem;
namespace {

using Clock = std::chrono::steady_clock;
double Since(Clock::time_point t0) {
  return std::chrono::duration<double>(Clock::now() - t0).count();
}

size_t PeakRssBytes() {
  std::ifstream f("/proc/self/status");
  std::string line;
  while (std::getline(f, line))
    if (line.rfind("VmHWM:", 0) == 0) return std::stoull(line.substr(6)) * 1024;
  return 0;
}

int ScaledRadius(int radius_at_reference, double ratio) {
  return std::max(1, static_cast<int>(std::lround(radius_at_reference * ratio)));
}

// Inverse depth over the photo's range (near = warm); invalid pixels black.
Image8 Colorize(const ImageF& depth, const DepthRange& range) {
  return io::ColouriseDepth(depth, range.near_m, range.far_m);
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

ImageF ResizeLinear(const ImageF& image, int width, int height) {
  ImageF out(width, height, image.channels());
  cv::Mat dst = io::ToMat(out);
  cv::resize(io::ToMat(image), dst, cv::Size(width, height), 0, 0, cv::INTER_LINEAR);
  return out;
}

// `image` sampled at the pixel nearest each centre of a width x height grid.
ImageF ResizeNearest(const ImageF& image, int width, int height) {
  ImageF out(width, height, image.channels());
  cv::Mat dst = io::ToMat(out);
  cv::resize(io::ToMat(image), dst, cv::Size(width, height), 0, 0, cv::INTER_NEAREST_EXACT);
  return out;
}

int CountValid(const ImageF& depth) {
  int n = 0;
  for (float v : depth.vector()) n += v > 0;
  return n;
}

// The cost volume between the two passes, on disk as 16-bit fixed point
// (E_photo in [0, 1]; 1/65535 resolution is far below the costs' noise),
// converted in chunks (no second copy of the volume in memory).
constexpr size_t kCacheChunk = size_t{1} << 20;  // Costs per chunk.

void WriteCostCache(const std::string& path, const CostVolume& vol) {
  const std::string tmp = io::TemporaryPathFor(path);
  {
    std::ofstream f(tmp, std::ios::binary);
    std::vector<uint16_t> q(std::min(kCacheChunk, vol.cost.size()));
    for (size_t begin = 0; begin < vol.cost.size(); begin += kCacheChunk) {
      const size_t count = std::min(kCacheChunk, vol.cost.size() - begin);
      // Rounded half away from zero as std::lround, in a loop that vectorises
      // (the fraction of a float below 2^23 is exact).
      const float* c = vol.cost.data() + begin;
      for (size_t i = 0; i < count; ++i) {
        const float x = std::min(1.0f, std::max(0.0f, c[i])) * 65535.0f;
        const int t = static_cast<int>(x);
        q[i] = static_cast<uint16_t>(t + (x - static_cast<float>(t) >= 0.5f ? 1 : 0));
      }
      f.write(reinterpret_cast<const char*>(q.data()), static_cast<std::streamsize>(count * 2));
    }
    f.write(reinterpret_cast<const char*>(vol.photo_weight.data()),
            static_cast<std::streamsize>(vol.photo_weight.size() * sizeof(float)));
    if (!f) throw io::IoError(path + ": cannot write the cost cache (disk full?)");
  }
  io::CommitTemporary(tmp, path);
}

// Reads a cache's costs into `*cost` (resized to `total` floats, its old
// contents overwritten) and, when `photo_weight` is given (allocated to the
// volume's size), its photo weights.
void ReadCostCache(const std::string& path, size_t total, std::vector<float>* cost, ImageF* photo_weight) {
  cost->resize(total);
  std::ifstream f(path, std::ios::binary);
  std::vector<uint16_t> q(std::min(kCacheChunk, total));
  for (size_t begin = 0; begin < total && f; begin += kCacheChunk) {
    const size_t count = std::min(kCacheChunk, total - begin);
    f.read(reinterpret_cast<char*>(q.data()), static_cast<std::streamsize>(count * 2));
    float* c = cost->data() + begin;
    for (size_t i = 0; i < count; ++i) c[i] = q[i] * (1.0f / 65535.0f);
  }
  if (photo_weight)
    f.read(reinterpret_cast<char*>(photo_weight->data()),
           static_cast<std::streamsize>(photo_weight->width() * photo_weight->height() * sizeof(float)));
  if (!f) throw io::IoError(path + ": cost cache truncated");
}

ImageF ReadGroundTruth(const std::string& dir, const std::string& stem) {
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

// Runs body(i) for every photo of `views`, `outer` photos at a time. A
// photo's failure does not stop the others; the first one, named by its
// photo, is thrown once all have run.
template <typename Body>
void ForEachPhoto(const std::vector<DenseView>& views, int outer, Body&& body) {
  std::mutex mutex;
  std::string first_error;
  ParallelFor(0, static_cast<int64_t>(views.size()), outer, [&](int64_t i) {
    try {
      body(static_cast<int>(i));
    } catch (const std::exception& e) {
      std::lock_guard<std::mutex> lock(mutex);
      if (first_error.empty()) first_error = views[i].name + ": " + e.what();
    }
  });
  if (!first_error.empty()) throw std::runtime_error(first_error);
}

}  // namespace

Status MrfTermOptions::Check() const {
  if (!(lambda_smooth >= 0 && lambda_smooth <= 100)) return InvalidArgument("lambda_smooth outside [0, 100]");
  if (!(lambda_near >= 0 && lambda_near <= 100)) return InvalidArgument("lambda_near outside [0, 100]");
  if (!(sigma_color > 0 && sigma_color <= 10)) return InvalidArgument("mrf sigma_color outside (0, 10]");
  if (!(color_floor >= 0 && color_floor <= 1)) return InvalidArgument("mrf color_floor outside [0, 1]");
  if (!(far_bias >= 0 && far_bias <= 1)) return InvalidArgument("mrf far_bias outside [0, 1]");
  if (truncation_labels < 1 || truncation_labels > 4096)
    return InvalidArgument("truncation_labels outside [1, 4096]");
  if (max_iterations < 1 || max_iterations > 1000) return InvalidArgument("mrf max_iterations outside [1, 1000]");
  if (!(lambda_flat >= 0 && lambda_flat <= 100)) return InvalidArgument("lambda_flat outside [0, 100]");
  if (!(flat_truncation_labels >= 1 && flat_truncation_labels <= 100))
    return InvalidArgument("flat_truncation_labels outside [1, 100]");
  return Status::Ok();
}

Status DenseOptions::Check() const {
  if (!(working_scale > 0 && working_scale <= 1)) return InvalidArgument("working_scale outside (0, 1]");
  if (num_neighbors < 1 || num_neighbors > 16)
    return InvalidArgument("num_neighbors " + std::to_string(num_neighbors) + " outside [1, 16]");
  if (!(reference_diagonal > 0)) return InvalidArgument("reference_diagonal must be > 0");
  if (!(min_far_over_near >= 1 && min_far_over_near <= 1e6))
    return InvalidArgument("min_far_over_near outside [1, 1e6]");
  if (num_threads < 0) return InvalidArgument("num_threads must be >= 0");
  for (const Status& s : {neighbors.Check(), sweep.Check(), gc.Check(), prune.Check(), envelope.Check(),
                          mrf.Check(), edge_median.Check(), sublabel.Check(), refine.Check(), upsample.Check(),
                          fullres.Check(), relabel.Check(), flat.Check(), visibility.Check()})
    if (!s.ok()) return s;
  return Status::Ok();
}

DenseReport RunDenseStage(const std::string& workspace_dir, const std::string& out_dir,
                          const DenseOptions& options) {
  const Status st = options.Check();
  if (!st.ok()) throw std::invalid_argument(st.message());
  const auto t_start = Clock::now();
  const int threads = ResolveThreads(options.num_threads);
  if (!options.ground_truth_dir.empty() && !fs::is_directory(options.ground_truth_dir))
    throw std::runtime_error(options.ground_truth_dir + ": ground-truth folder does not exist");

  LoadedWorkspace ws = LoadWorkspace(workspace_dir, options.working_scale, options.neighbors);
  const int n = static_cast<int>(ws.views.size());
  // Far-plane extension (dense_stage.h): labels are added beyond the sparse
  // range at the sparse range's spacing, so near content keeps its precision.
  std::vector<int> num_labels(n, options.sweep.num_depths);
  for (int i = 0; i < n; ++i) {
    DepthRange& r = ws.views[i].range;
    const double far = std::max(r.far_m, options.min_far_over_near * r.near_m);
    const double grow = (1.0 / r.near_m - 1.0 / far) / (1.0 / r.near_m - 1.0 / r.far_m);
    num_labels[i] = std::min(4 * options.sweep.num_depths,
                             static_cast<int>(std::ceil(options.sweep.num_depths * grow - 1e-9)));
    r.far_m = far;
  }
  DenseReport report;
  report.seconds_load = Since(t_start);

  io::CreateDirectories(out_dir);
  for (const char* sub : {"depth", "confidence", "envelope"}) io::CreateDirectories((fs::path(out_dir) / sub).string());
  const std::string debug_dir = (fs::path(out_dir) / "debug").string();
  if (options.debug) io::CreateDirectories(debug_dir);
  const std::string cache_dir = (fs::path(out_dir) / ".dense-cache").string();
  io::CreateDirectories(cache_dir);
  struct CacheGuard {
    std::string dir;
    ~CacheGuard() {
      std::error_code ec;
      fs::remove_all(dir, ec);
    }
  } cache_guard{cache_dir};

  report.photos.resize(n);
  std::vector<ImageF> wta(n);
  std::vector<CostVolume> shells(n);  // Sizes and depth grid; costs live in the cache.
  std::vector<std::vector<const DenseView*>> swept(n);  // Each photo's swept neighbours.
  auto cache_path = [&](int i) {
    return (fs::path(cache_dir) / (OutputStem(ws.views[i].name) + ".cost")).string();
  };

  // Photos run `outer` at a time in both passes, `inner` threads each.
  const int outer = std::min(threads, n);
  const int inner = std::max(1, threads / outer);
  // The big buffers (the cost volume, which the MRF's unary then takes
  // over, and TRW-S's two message arrays: 220 MB each at the default
  // resolution) pass from one photo to the next (huge_pages.h). Three idle
  // buffers at most, one photo's set: on the synthetic capture at 4
  // neighbours, 2 / 3 / 4 kept took 54.3 / 52.2 / 53.1 s with peaks of 1.56
  // / 1.62 / 2.04 GB (docs/PERFORMANCE.md).
  BufferPool pool(3);

  // Pass 1: cost volumes and WTA depth maps of every photo (the GC filter
  // needs all WTA maps before any envelope can be built). Photos run
  // concurrently, one thread each: a sweep splits its planes over threads
  // with about 1.6x on 2 cores, whole photos in parallel with about 2x
  // (docs/PERFORMANCE.md, "Dense"). Results do not depend on the split.
  {
    util::Progress progress("dense: plane sweep", n);
    SweepOptions sweep = options.sweep;
    sweep.num_threads = inner;
    for (int i = 0; i < n; ++i) {
      const DenseView& v = ws.views[i];
      PhotoReport& pr = report.photos[i];
      pr.name = v.name;
      pr.near_m = v.range.near_m;
      pr.far_m = v.range.far_m;
      pr.work_width = v.camera.width;
      pr.work_height = v.camera.height;
      pr.num_labels = num_labels[i];
      pr.width = v.full_width;
      pr.height = v.full_height;
      std::vector<const DenseView*>& nbs = swept[i];
      for (int j : ws.ranked_neighbors[i]) {
        if (static_cast<int>(nbs.size()) >= options.num_neighbors) break;
        nbs.push_back(&ws.views[j]);
        pr.neighbors.push_back(ws.views[j].name);
      }
    }
    ForEachPhoto(ws.views, outer, [&](int i) {
      const auto t0 = Clock::now();
      SweepOptions photo_sweep = sweep;
      photo_sweep.num_depths = num_labels[i];
      CostVolume vol = ComputeCostVolume(ws.views[i], swept[i], photo_sweep, &pool);
      wta[i] = WinnerTakesAll(vol, photo_sweep.num_threads);
      WriteCostCache(cache_path(i), vol);
      pool.Give(&vol.cost);
      shells[i].width = vol.width;
      shells[i].height = vol.height;
      shells[i].num_labels = vol.num_labels;
      shells[i].inv_near = vol.inv_near;
      shells[i].inv_far = vol.inv_far;
      report.photos[i].t_sweep = Since(t0);
      progress.Advance();
    });
  }

  // Pass 2: envelope, MRF, upsampling and outputs. Photos run concurrently,
  // one thread each (TRW-S is sequential).
  std::vector<const DenseView*> view_ptrs;
  std::vector<const ImageF*> wta_ptrs;
  // Final full-resolution depth maps: the free-space check (pass 3) compares
  // them with each other before any is written.
  std::vector<ImageF> final_full(n);
  for (int i = 0; i < n; ++i) {
    view_ptrs.push_back(&ws.views[i]);
    wta_ptrs.push_back(&wta[i]);
  }
  const double diag_ratio =
      std::hypot(ws.views[0].camera.width, ws.views[0].camera.height) / options.reference_diagonal;
  // Ground truth (evaluation only), read once: each photo's is also needed by
  // the photos that sweep it (which of them see its surface). Empty where missing.
  std::vector<ImageF> ground_truth(n);
  if (!options.ground_truth_dir.empty())
    for (int i = 0; i < n; ++i)
      ground_truth[i] = ReadGroundTruth(options.ground_truth_dir, OutputStem(ws.views[i].name));
  util::Progress progress("dense: envelope + MRF", n);
  ForEachPhoto(ws.views, outer, [&](int i) {
    const DenseView& v = ws.views[i];
    PhotoReport& pr = report.photos[i];
    const std::string stem = OutputStem(v.name);
    const LabelGrid grid{shells[i].inv_near, shells[i].inv_far, shells[i].num_labels};
    auto t0 = Clock::now();

    // Anchors (Fig. 4a-d).
    const ImageF gc = options.use_gc_filter
                          ? GeometricConsistencyFilter(i, view_ptrs, wta_ptrs, ws.ranked_neighbors[i],
                                                       grid.InvStep(), options.gc, inner)
                          : wta[i];
    MedianPruneOptions prune = options.prune;
    prune.small_radius = ScaledRadius(options.prune.small_radius, diag_ratio);
    prune.large_radius = ScaledRadius(options.prune.large_radius, diag_ratio);
    const ImageF med = MedianPrune(gc, grid, prune, inner);
    const ImageF bil = BilateralMedianPrune(med, v.color, grid, prune, inner);
    pr.anchors = {CountValid(wta[i]), CountValid(gc), CountValid(med), CountValid(bil)};

    // Propagation and envelope (Fig. 4e-f).
    EnvelopeOptions env_opt = options.envelope;
    env_opt.variance_radius = ScaledRadius(options.envelope.variance_radius, diag_ratio);
    PropagationStats ps;
    const ImageF propagated = PropagateAnchors(bil, v.color, env_opt, &ps);
    pr.cg_iterations = ps.iterations;
    ImageF envelope;
    if (!propagated.empty()) envelope = FinalizeEnvelope(propagated, env_opt);
    pr.t_envelope = Since(t0);

    // MRF (Eq. 1-4).
    t0 = Clock::now();
    CostVolume vol = shells[i];
    const int w = vol.width, h = vol.height, L = vol.num_labels;
    const size_t np = static_cast<size_t>(w) * h;
    pool.TakeForOverwrite(&vol.cost, np * L);
    vol.photo_weight = ImageF(w, h, 1);
    ReadCostCache(cache_path(i), np * L, &vol.cost, &vol.photo_weight);
    GridMrf mrf;
    mrf.width = w;
    mrf.height = h;
    mrf.num_labels = L;
    mrf.truncation = options.mrf.truncation_labels;
    // Priors for textureless regions from their silhouettes (flat_regions.h).
    std::vector<float> flat_prior;
    FlatRegionStats flat_stats;
    if (options.flat.enabled) {
      const auto tf = Clock::now();
      std::vector<FlatRegionNeighbor> fn;
      for (const DenseView* nb : swept[i]) fn.push_back({&nb->color, nb->camera});
      flat_prior = FlatRegionPriors(v.color, vol.photo_weight, v.camera, wta[i], fn, vol, options.flat, &flat_stats);
      pr.t_flat = Since(tf);
      pr.flat_groups = flat_stats.groups;
      pr.flat_fitted = flat_stats.fitted;
      pr.flat_pixels = flat_stats.pixels;
    }
    const bool near_term = options.use_near_envelope && !envelope.empty() && options.mrf.lambda_near > 0;
    // The unary takes the costs' buffer (one buffer of 220 MB less per photo
    // in flight, so the pool can keep them all and no page is zeroed
    // afresh); the costs are read back from the cache after the solve.
    mrf.unary.swap(vol.cost);
    for (size_t p = 0; p < np; ++p) {
      const float wp = vol.photo_weight.data()[p];
      float* u = mrf.unary.data() + p * L;
      const bool has_prior = !flat_prior.empty() && !std::isnan(flat_prior[p]);
      const float bias = has_prior ? 0.0f : static_cast<float>(options.mrf.far_bias) * (1.0f - wp) / (L - 1);
      for (int k = 0; k < L; ++k) u[k] = wp * u[k] + bias * static_cast<float>(L - 1 - k);
      if (has_prior) {
        // Linear in the label distance up to flat_truncation labels.
        const float tf = static_cast<float>(options.mrf.flat_truncation_labels);
        const float lp = static_cast<float>(options.mrf.lambda_flat) * (1.0f - wp) / tf;
        for (int k = 0; k < L; ++k) u[k] += lp * std::min(tf, std::abs(k - flat_prior[p]));
      }
      if (near_term) {
        // Eq. 4: labels nearer than the envelope (k < label of n_i) pay lambda_near.
        const double kn = grid.LabelOf(envelope.data()[p]);
        const int kmax = std::min(L, static_cast<int>(std::ceil(kn)));
        for (int k = 0; k < kmax; ++k) u[k] += static_cast<float>(options.mrf.lambda_near);
      }
    }
    mrf.weight_right.assign(np, 0.0f);
    mrf.weight_down.assign(np, 0.0f);
    const double inv2s2 = 1.0 / (2.0 * options.mrf.sigma_color * options.mrf.sigma_color);
    const double scale = options.mrf.lambda_smooth / options.mrf.truncation_labels;
    auto wcolor = [&](int x0, int y0, int x1, int y1) {
      double d2 = 0;
      for (int c = 0; c < 3; ++c) {
        const double e = v.color.at(x0, y0, c) - v.color.at(x1, y1, c);
        d2 += e * e;
      }
      return static_cast<float>(scale * std::max(options.mrf.color_floor, std::exp(-d2 * inv2s2)));
    };
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x) {
        const size_t p = static_cast<size_t>(y) * w + x;
        if (x + 1 < w) mrf.weight_right[p] = wcolor(x, y, x + 1, y);
        if (y + 1 < h) mrf.weight_down[p] = wcolor(x, y, x, y + 1);
      }
    TrwsOptions trws;
    trws.max_iterations = options.mrf.max_iterations;
    const TrwsResult res = SolveTrws(mrf, trws, &pool);
    vol.cost.swap(mrf.unary);
    ReadCostCache(cache_path(i), np * L, &vol.cost, nullptr);
    pr.mrf_energy = res.energy;
    pr.mrf_iterations = res.iterations;

    // Edge-aware median (window fattening), sub-label refinement, depth and confidence.
    const std::vector<int> labels = EdgeAwareMedian(std::vector<int>(res.labels.begin(), res.labels.end()),
                                                    L, v.color, options.edge_median, inner);
    std::vector<float> fl = FitSubLabel(vol, labels, options.sublabel, inner);
    pr.t_mrf = Since(t0);
    ImageF trws_depth;
    if (options.debug) {
      trws_depth = ImageF(w, h, 1);
      for (size_t p = 0; p < np; ++p) trws_depth.data()[p] = static_cast<float>(vol.DepthOfLabel(res.labels[p]));
    }
    t0 = Clock::now();
    if (options.refine.enabled)
      fl = RefineContinuous(v, swept[i], vol, labels, fl, options.sweep, options.refine, inner);
    fl = SmoothSubLabel(vol, std::move(fl), v.color, options.sublabel, inner);
    // Within a fitted flat region the plane is the estimate: the photos carry
    // no evidence there to refine it by.
    if (!flat_prior.empty())
      for (size_t p = 0; p < np; ++p)
        if (!std::isnan(flat_prior[p])) fl[p] = flat_prior[p];
    ImageF low_depth(w, h, 1), low_conf(w, h, 1);
    for (size_t p = 0; p < np; ++p) {
      const float* c = vol.cost.data() + p * L;
      low_depth.data()[p] = static_cast<float>(vol.DepthOfLabel(fl[p]));
      low_conf.data()[p] = vol.photo_weight.data()[p] * std::max(0.0f, 1.0f - c[labels[p]]);
    }
    pool.Give(&vol.cost);
    pr.t_refine = Since(t0);

    // Full resolution (Sec. 4.3.1: joint bilateral weighted median).
    t0 = Clock::now();
    const ImageF full_color = ReadPhotoFloat((fs::path(ws.images_dir) / v.name).string());
    UpsampleOptions up = options.upsample;
    up.num_threads = inner;
    ImageF depth = JointBilateralMedianUpsample(low_depth, v.color, full_color, up);
    // At full resolution: the farther side's depth back onto fattened edge
    // bands, then a search within a label around every textured pixel
    // (fullres_refine.h).
    if (options.relabel.enabled || options.fullres.enabled) {
      const auto tf = Clock::now();
      std::vector<RefineNeighbor> rn;
      for (const DenseView* nb : swept[i]) rn.push_back({&nb->gray_full, nb->camera_full});
      if (options.relabel.enabled)
        depth = RelabelBoundaries(full_color, v.gray_full, v.camera_full, depth, rn, grid.InvStep(),
                                  options.relabel, inner, &pr.relabelled);
      if (options.fullres.enabled) {
        FullResRefineStats rs;
        depth = RefineFullResolution(v.gray_full, v.camera_full, depth, rn, grid.InvStep(), options.fullres,
                                     inner, &rs);
        pr.refined = rs.refined;
      }
      pr.t_fullres = Since(tf);
    }
    const ImageF conf = ResizeLinear(low_conf, v.full_width, v.full_height);
    ImageF env_full;
    if (!envelope.empty()) {
      env_full = ResizeLinear(envelope, v.full_width, v.full_height);
    } else {
      env_full = ImageF(v.full_width, v.full_height, 1, static_cast<float>(v.range.near_m));
    }
    // The confidence and the envelope without ZIP: it took 60-120 ms per map
    // and saved a quarter (confidence) to a half (envelope) of 4 MB
    // (docs/PERFORMANCE.md). The depth map is written after pass 3.
    io::ExrWriteOptions plain;
    plain.compression = io::ExrCompression::kNone;
    io::WriteExr((fs::path(out_dir) / "confidence" / (stem + ".exr")).string(), conf.view(), {"Y"}, plain);
    io::WriteExr((fs::path(out_dir) / "envelope" / (stem + ".exr")).string(),
                 static_cast<const ImageF&>(env_full).view(), {"Z"}, plain);
    if (options.debug) {
      auto png = [&](const char* what, const ImageF& img) {
        const Image8 rgb = Colorize(img, v.range);
        io::WritePng((fs::path(debug_dir) / (stem + "_" + what + ".png")).string(), rgb.view());
      };
      png("wta", wta[i]);
      png("gc", gc);
      png("median", med);
      png("bilateral", bil);
      if (!propagated.empty()) png("propagated", propagated);
      if (!envelope.empty()) png("envelope", envelope);
      png("trws", trws_depth);
      if (!flat_prior.empty()) {
        ImageF fp(w, h, 1, 0.0f);
        for (size_t p = 0; p < np; ++p)
          if (!std::isnan(flat_prior[p])) fp.data()[p] = static_cast<float>(vol.DepthOfLabel(flat_prior[p]));
        png("flat", fp);
      }
      png("mrf", low_depth);
      Image8 texture(w, h, 1);
      for (size_t p = 0; p < np; ++p)
        texture.data()[p] = static_cast<uint8_t>(std::lround(255.0f * vol.photo_weight.data()[p]));
      io::WritePng((fs::path(debug_dir) / (stem + "_texture.png")).string(), texture);
      png("upsampled", depth);
    }
    final_full[i] = std::move(depth);
    pr.t_upsample = Since(t0);

    // Ground truth: the anchors and the envelope (Fig. 6); the final depth
    // is evaluated after pass 3.
    if (!options.ground_truth_dir.empty() && !ground_truth[i].empty()) {
      const ImageF& gt = ground_truth[i];
      const double tol = 2.0 * grid.InvStep();
      const char* names[] = {"wta", "gc", "median", "bilateral"};
      const ImageF* maps[] = {&wta[i], &gc, &med, &bil};
      for (int s = 0; s < 4; ++s) {
        const AnchorQuality q = EvaluateAnchors(*maps[s], gt, tol);
        pr.stages.push_back({names[s], q.completeness, q.precision});
      }
      if (!envelope.empty()) {
        const EnvelopeQuality eq = EvaluateEnvelope(envelope, gt);
        pr.envelope_error = eq.error;
        pr.envelope_tightness = eq.tightness;
      }
    }
    progress.Advance();
  });
  progress.Finish();

  // Pass 3: the free-space check of the final maps against each other
  // (visibility_filter.h), at full resolution. Every round reads the maps as
  // the previous one left them, so the result does not depend on the order
  // of the photos.
  std::vector<PinholeCamera> full_cameras(n);
  std::vector<const PinholeCamera*> full_camera_ptrs(n);
  std::vector<const ImageF*> final_ptrs(n), gray_ptrs(n);
  for (int i = 0; i < n; ++i) {
    gray_ptrs[i] = &ws.views[i].gray_full;
    full_cameras[i] = ws.views[i].camera_full.Resized(final_full[i].width(), final_full[i].height());
    full_camera_ptrs[i] = &full_cameras[i];
    final_ptrs[i] = &final_full[i];
  }
  if (options.visibility.enabled) {
    util::Progress check_progress("dense: free-space check", n * options.visibility.rounds);
    for (int round = 0; round < options.visibility.rounds; ++round) {
      std::vector<std::vector<DepthReplacement>> moves(n);
      ForEachPhoto(ws.views, threads, [&](int i) {
        const auto t0 = Clock::now();
        VisibilityStats vs;
        const LabelGrid grid{shells[i].inv_near, shells[i].inv_far, shells[i].num_labels};
        moves[i] = CheckFreeSpace(i, full_camera_ptrs, final_ptrs, gray_ptrs, ws.ranked_neighbors[i], grid.InvStep(),
                                  options.visibility, &vs);
        PhotoReport& pr = report.photos[i];
        pr.seen_through += vs.flagged;
        pr.moved_back += vs.replaced;
        pr.t_visibility += Since(t0);
        check_progress.Advance();
      });
      for (int i = 0; i < n; ++i)
        for (const DepthReplacement& m : moves[i]) final_full[i].data()[m.index] = m.depth;
    }
    check_progress.Finish();
  }

  // Outputs and evaluation of the final maps.
  ForEachPhoto(ws.views, threads, [&](int i) {
    const DenseView& v = ws.views[i];
    PhotoReport& pr = report.photos[i];
    const std::string stem = OutputStem(v.name);
    const ImageF& depth = final_full[i];
    const auto t0 = Clock::now();
    // ZIP compression: a third smaller.
    io::WriteExr((fs::path(out_dir) / "depth" / (stem + ".exr")).string(), depth.view(), {"Z"});
    if (options.debug) {
      const Image8 rgb = Colorize(depth, v.range);
      io::WritePng((fs::path(debug_dir) / (stem + "_depth.png")).string(), rgb.view());
    }
    pr.t_upsample += Since(t0);
    if (!options.ground_truth_dir.empty()) {
      const ImageF& gt = ground_truth[i];
      if (!gt.empty()) {
        pr.evaluated = true;
        const LabelGrid grid{shells[i].inv_near, shells[i].inv_far, shells[i].num_labels};
        if (options.debug) {
          const std::string base = (fs::path(debug_dir) / stem).string();
          const Image8 gt_rgb = Colorize(gt, v.range), err_rgb = ErrorMap(depth, gt);
          io::WritePng(base + "_gt.png", gt_rgb.view());
          io::WritePng(base + "_error.png", err_rgb.view());
        }
        // Which swept neighbours see each pixel's true surface.
        std::vector<PinholeCamera> nb_cam;
        std::vector<const ImageF*> gt_ptrs;
        for (const DenseView* nb : swept[i]) {
          const ImageF& g = ground_truth[nb - ws.views.data()];
          if (g.empty()) continue;
          nb_cam.push_back(nb->camera.Resized(g.width(), g.height()));
          gt_ptrs.push_back(&g);
        }
        std::vector<const PinholeCamera*> cam_ptrs;
        for (const PinholeCamera& c : nb_cam) cam_ptrs.push_back(&c);
        const std::vector<uint8_t> observers =
            AgreeingViews(v.camera.Resized(gt.width(), gt.height()), gt, cam_ptrs, gt_ptrs, 0.02);
        const DepthAccuracy acc =
            EvaluateDepth(depth, gt, 0.5 * v.range.far_m, grid.InvStep(), &observers, 2);
        pr.pixels = acc.pixels;
        pr.observed_pixels = acc.observed_pixels;
        pr.median_rel_error_observed = acc.median_rel_error_observed;
        pr.within_3pct_observed = acc.within_3pct_observed;
        pr.near_floaters_observed = acc.near_floaters_observed;
        pr.median_rel_error = acc.median_rel_error;
        pr.within_3pct = acc.within_3pct;
        pr.near_floaters = acc.near_floaters;
        pr.sky_near = acc.sky_near;
        pr.within_half_label = acc.within_half_label;
        pr.within_two_labels = acc.within_two_labels;
      }
    }
  });

  // Cross-view consistency of the final depth maps, sampled at working
  // resolution (the pixel nearest each working pixel's centre).
  {
    std::vector<ImageF> final_low(n);
    std::vector<const ImageF*> low_ptrs(n);
    for (int i = 0; i < n; ++i) {
      final_low[i] = ResizeNearest(final_full[i], ws.views[i].camera.width, ws.views[i].camera.height);
      low_ptrs[i] = &final_low[i];
    }
    ParallelFor(0, n, threads, [&](int64_t i) {
      report.photos[i].cross_view_consistency =
          CrossViewConsistency(static_cast<int>(i), view_ptrs, low_ptrs, ws.ranked_neighbors[i]);
    });
    for (const PhotoReport& pr : report.photos) report.cross_view_consistency += pr.cross_view_consistency / n;
  }

  // Summary.
  long long weight = 0, pixels = 0, observed = 0;
  for (const PhotoReport& pr : report.photos) {
    if (!pr.evaluated) continue;
    pixels += pr.pixels;
    observed += pr.observed_pixels;
    report.median_rel_error_observed += pr.median_rel_error_observed * pr.observed_pixels;
    report.within_3pct_observed += pr.within_3pct_observed * pr.observed_pixels;
    report.near_floaters_observed += pr.near_floaters_observed * pr.observed_pixels;
    const long long px = static_cast<long long>(pr.width) * pr.height;
    report.evaluated = true;
    report.median_rel_error += pr.median_rel_error * px;
    report.within_3pct += pr.within_3pct * px;
    report.near_floaters += pr.near_floaters * px;
    report.within_half_label += pr.within_half_label * px;
    report.within_two_labels += pr.within_two_labels * px;
    weight += px;
  }
  if (weight > 0) {
    report.median_rel_error /= weight;
    report.within_3pct /= weight;
    report.near_floaters /= weight;
    report.within_half_label /= weight;
    report.within_two_labels /= weight;
  }
  if (observed > 0) {
    report.observed_fraction = static_cast<double>(observed) / pixels;
    report.median_rel_error_observed /= observed;
    report.within_3pct_observed /= observed;
    report.near_floaters_observed /= observed;
  }
  report.seconds_total = Since(t_start);
  report.peak_rss_bytes = PeakRssBytes();

  nlohmann::json j;
  j["format"] = "casual3d-dense-report";
  j["version"] = "1.0";
  j["seconds_total"] = report.seconds_total;
  j["seconds_load"] = report.seconds_load;
  j["peak_rss_bytes"] = report.peak_rss_bytes;
  j["use_near_envelope"] = options.use_near_envelope;
  j["use_gc_filter"] = options.use_gc_filter;
  j["num_depths"] = options.sweep.num_depths;
  j["working_scale"] = options.working_scale;
  j["continuous_refine"] = options.refine.enabled;
  j["cross_view_consistency"] = report.cross_view_consistency;
  if (report.evaluated) {
    j["accuracy"] = {{"median_rel_error", report.median_rel_error},
                     {"within_3pct", report.within_3pct},
                     {"near_floaters", report.near_floaters},
                     {"within_half_label", report.within_half_label},
                     {"within_two_labels", report.within_two_labels},
                     {"observed_fraction", report.observed_fraction},
                     {"median_rel_error_observed", report.median_rel_error_observed},
                     {"within_3pct_observed", report.within_3pct_observed},
                     {"near_floaters_observed", report.near_floaters_observed}};
  }
  for (const PhotoReport& pr : report.photos) {
    nlohmann::json p;
    p["name"] = pr.name;
    p["neighbors"] = pr.neighbors;
    p["near_m"] = pr.near_m;
    p["far_m"] = pr.far_m;
    p["size"] = {pr.width, pr.height};
    p["work_size"] = {pr.work_width, pr.work_height};
    p["num_labels"] = pr.num_labels;
    p["anchors"] = {{"wta", pr.anchors[0]}, {"gc", pr.anchors[1]}, {"median", pr.anchors[2]},
                    {"bilateral", pr.anchors[3]}};
    p["cg_iterations"] = pr.cg_iterations;
    p["mrf_energy"] = pr.mrf_energy;
    p["mrf_iterations"] = pr.mrf_iterations;
    p["cross_view_consistency"] = pr.cross_view_consistency;
    // "flat" is part of "mrf", "fullres" of "upsample_write".
    p["seconds"] = {{"sweep", pr.t_sweep},     {"envelope", pr.t_envelope}, {"mrf", pr.t_mrf},
                    {"flat", pr.t_flat},       {"refine", pr.t_refine},     {"upsample_write", pr.t_upsample},
                    {"fullres", pr.t_fullres}};
    p["flat_regions"] = {{"groups", pr.flat_groups}, {"fitted", pr.flat_fitted}, {"pixels", pr.flat_pixels}};
    p["relabelled_pixels"] = pr.relabelled;
    p["free_space"] = {{"seen_through", pr.seen_through}, {"moved_back", pr.moved_back}, {"seconds", pr.t_visibility}};
    p["refined_pixels"] = pr.refined;
    if (pr.evaluated) {
      p["accuracy"] = {{"median_rel_error", pr.median_rel_error}, {"within_3pct", pr.within_3pct},
                       {"near_floaters", pr.near_floaters}, {"sky_near", pr.sky_near},
                       {"within_half_label", pr.within_half_label}, {"within_two_labels", pr.within_two_labels},
                       {"observed_fraction", pr.pixels > 0 ? static_cast<double>(pr.observed_pixels) / pr.pixels : 0.0},
                       {"median_rel_error_observed", pr.median_rel_error_observed},
                       {"within_3pct_observed", pr.within_3pct_observed},
                       {"near_floaters_observed", pr.near_floaters_observed}};
      for (const StageQuality& s : pr.stages)
        p["anchor_quality"][s.stage] = {{"completeness", s.completeness}, {"precision", s.precision}};
      p["envelope_quality"] = {{"error", pr.envelope_error}, {"tightness", pr.envelope_tightness}};
    }
    j["photos"].push_back(p);
  }
  io::WriteFileAtomic((fs::path(out_dir) / "dense.json").string(), j.dump(2) + "\n");
  return report;
}

}  // namespace casual3d::depth

#include "reconstruct/depth/dense_stage.h"

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <stdexcept>

#include "reconstruct/depth/dense_finish.h"
#include "reconstruct/depth/dense_passes.h"
#include "reconstruct/depth/dense_schedule.h"
#include "reconstruct/io/file_util.h"
#include "reconstruct/util/log.h"

namespace casual3d::depth {
namespace fs = std::filesystem;

DenseReport RunDenseStage(const std::string& workspace_dir, const std::string& out_dir,
                          const DenseOptions& options) {
  const Status st = options.Check();
  if (!st.ok()) throw std::invalid_argument(st.message());
  const auto t_start = std::chrono::steady_clock::now();
  const int threads = base::ResolveThreads(options.num_threads);
  if (!options.ground_truth_dir.empty() && !fs::is_directory(options.ground_truth_dir))
    throw std::runtime_error(options.ground_truth_dir + ": ground-truth folder does not exist");

  const DensePlan plan = PlanDense(workspace_dir, options);
  const int n = plan.size();
  const double seconds_load = SecondsSince(t_start);

  CreateDenseOutputFolders(out_dir, options);
  const std::string cache_dir = (fs::path(out_dir) / ".dense-cache").string();
  io::CreateDirectories(cache_dir);
  struct CacheGuard {
    std::string dir;
    ~CacheGuard() {
      std::error_code ec;
      fs::remove_all(dir, ec);
    }
  } cache_guard{cache_dir};
  auto cache_path = [&](int i) {
    return (fs::path(cache_dir) / (OutputStem(plan.ws.views[i].name) + ".cost")).string();
  };

  std::vector<PhotoReport> photos(n);
  for (int i = 0; i < n; ++i) photos[i] = PhotoHeader(plan, i);
  std::vector<ImageF> wta(n);
  std::vector<const ImageF*> wta_ptrs(n);
  for (int i = 0; i < n; ++i) wta_ptrs[i] = &wta[i];
  std::vector<CostVolume> shells(n);  // Sizes and depth grid; costs live in the cache.

  // Photos run `outer` at a time in the per-photo passes, `inner` threads
  // each: whole photos in parallel scale better than a sweep's planes split
  // over threads, and TRW-S is sequential (docs/DECISIONS.md, "Dense: photos
  // swept in parallel"). Results do not depend on the split.
  const int outer = std::min(threads, n);
  const int inner = std::max(1, threads / outer);
  // The big buffers (the cost volume, which the MRF's unary then takes
  // over, and TRW-S's two message arrays: 220 MB each at the default
  // resolution) pass from one photo to the next (huge_pages.h). Three idle
  // buffers at most, one photo's set (docs/DECISIONS.md, "Dense: huge pages
  // and reused buffers").
  BufferPool pool(3);

  // Ground truth (evaluation only) is read once: each photo's is also
  // needed by the photos that sweep it. Empty where missing.
  std::vector<ImageF> ground_truth(n);
  if (!options.ground_truth_dir.empty())
    for (int i = 0; i < n; ++i) ground_truth[i] = ReadDepthMap(options.ground_truth_dir, OutputStem(plan.ws.views[i].name));

  // Passes 1 and 2 interleaved (dense_schedule.h): each photo's sweep (cost
  // volume and WTA map), and its depth pass (envelope, MRF, upsampling) as
  // soon as the photos whose WTA maps it reads are swept, its cost cache
  // deleted after it. The final maps stay in memory for the free-space
  // check (pass 3) before any is written.
  const DenseSchedule schedule = ScheduleDense(plan, options);
  const CacheNeed need = CheckCacheSpace(plan, schedule, outer, cache_dir);
  util::LogInfo("dense: at most " + std::to_string(need.count) + " of " + std::to_string(n) +
                " cost caches on disk at once (" + std::to_string(need.bytes >> 20) + " MB)");
  std::vector<ImageF> depth(n);
  util::Progress progress("dense: sweep, envelope + MRF", 2 * n);
  RunScheduled(
      plan, schedule, outer,
      [&](int i) {
        const auto t0 = std::chrono::steady_clock::now();
        shells[i] = SweepPhoto(plan, i, options, inner, cache_path(i), &pool, &wta[i]);
        photos[i].t_sweep = SecondsSince(t0);
        progress.Advance();
      },
      [&](int i) {
        depth[i] = DepthPhoto(plan, i, options, inner, wta_ptrs, shells[i], cache_path(i), ground_truth[i],
                              out_dir, &pool, &photos[i]);
        std::error_code ec;
        fs::remove(cache_path(i), ec);
        progress.Advance();
      });
  progress.Finish();

  // Pass 3, on the maps and images held here.
  return FinishDense(plan, options, LendFinishInputs(plan, depth, ground_truth), std::move(photos), shells, out_dir,
                     t_start, seconds_load);
}

}  // namespace casual3d::depth

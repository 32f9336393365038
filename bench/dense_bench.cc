// Dense stage benchmarks (docs/PERFORMANCE.md, "Dense"): the plane sweep
// (220 hypotheses, 4 neighbours), the WTA, the near-envelope filters and
// solver, TRW-S and the upsampling, on a ray-cast toy scene at the working
// resolution of a 1152x864 photo (576x432 at the default working scale 0.5).
// Counters: seconds per megapixel of the photo (4x the working pixels).
//
//   build/bench/dense_bench --benchmark_filter=Sweep/576

#include <cmath>
#include <map>

#include <benchmark/benchmark.h>

#include "reconstruct/depth/gc_filter.h"
#include "reconstruct/depth/median_prune.h"
#include "reconstruct/depth/mrf_trws.h"
#include "reconstruct/depth/near_envelope.h"
#include "reconstruct/depth/plane_sweep.h"
#include "reconstruct/depth/testing/toy_scene.h"
#include "reconstruct/depth/upsample.h"

namespace casual3d::depth {
namespace {

struct Rig {
  std::vector<DenseView> views;  // 0 = reference.
  std::vector<ImageF> depth;
};

const Rig& GetRig(int width) {
  static std::map<int, Rig> rigs;
  auto it = rigs.find(width);
  if (it != rigs.end()) return it->second;
  Rig rig;
  const int height = width * 3 / 4;
  const double f = 0.785 * width;  // 65 degrees horizontal field of view.
  const testing::ToyScene scene = testing::ToyScene::Default();
  const Eigen::Vector3d centres[5] = {{0, 0, 0}, {0.15, 0, 0}, {-0.15, 0, 0}, {0, 0.15, 0}, {0, -0.15, 0}};
  for (const auto& c : centres) {
    ImageF d;
    rig.views.push_back(testing::MakeView(scene, testing::ToyCamera(c, width, height, f), {0.5, 50.0}, 1.0,
                                          0.0, &d));
    rig.depth.push_back(std::move(d));
  }
  return rigs.emplace(width, std::move(rig)).first->second;
}

void SetPerMegapixel(benchmark::State& state, int width) {
  const double photo_mp = 4.0 * width * (width * 3 / 4) / 1e6;  // Working scale 0.5.
  state.counters["s_per_photo_MP"] =
      benchmark::Counter(1.0 / photo_mp, benchmark::Counter::kIsIterationInvariantRate |
                                             benchmark::Counter::kInvert);
}

void BM_Sweep(benchmark::State& state) {
  const int width = static_cast<int>(state.range(0));
  const Rig& rig = GetRig(width);
  SweepOptions opt;
  opt.num_threads = static_cast<int>(state.range(1));
  std::vector<const DenseView*> nbs = {&rig.views[1], &rig.views[2], &rig.views[3], &rig.views[4]};
  for (auto _ : state) {
    CostVolume vol = ComputeCostVolume(rig.views[0], nbs, opt);
    benchmark::DoNotOptimize(vol.cost.data());
  }
  SetPerMegapixel(state, width);
}
BENCHMARK(BM_Sweep)->Args({288, 2})->Args({576, 1})->Args({576, 2})->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_Trws(benchmark::State& state) {
  const int width = static_cast<int>(state.range(0));
  const Rig& rig = GetRig(width);
  static std::map<int, CostVolume> vols;
  if (!vols.count(width)) {
    SweepOptions opt;
    vols[width] = ComputeCostVolume(rig.views[0], {&rig.views[1], &rig.views[2], &rig.views[3], &rig.views[4]}, opt);
  }
  const CostVolume& vol = vols[width];
  GridMrf m;
  m.width = vol.width;
  m.height = vol.height;
  m.num_labels = vol.num_labels;
  m.truncation = 8;
  m.unary = vol.cost;
  m.weight_right.assign(static_cast<size_t>(vol.width) * vol.height, 0.25f / 8);
  m.weight_down = m.weight_right;
  for (auto _ : state) {
    TrwsResult r = SolveTrws(m);
    benchmark::DoNotOptimize(r.energy);
    state.counters["iterations"] = r.iterations;
  }
  SetPerMegapixel(state, width);
}
BENCHMARK(BM_Trws)->Arg(288)->Arg(576)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_EnvelopeFilters(benchmark::State& state) {
  const int width = static_cast<int>(state.range(0));
  const Rig& rig = GetRig(width);
  std::vector<const DenseView*> vp;
  std::vector<const ImageF*> dp;
  for (size_t i = 0; i < rig.views.size(); ++i) {
    vp.push_back(&rig.views[i]);
    dp.push_back(&rig.depth[i]);
  }
  const LabelGrid grid{2.0, 0.02, 220};
  const double ratio = std::hypot(width, width * 3 / 4) / 1622.5;
  MedianPruneOptions prune;
  prune.small_radius = std::max(1, static_cast<int>(std::lround(2 * ratio)));
  prune.large_radius = std::max(1, static_cast<int>(std::lround(25 * ratio)));
  EnvelopeOptions env;
  env.variance_radius = std::max(1, static_cast<int>(std::lround(9 * ratio)));
  for (auto _ : state) {
    const ImageF gc = GeometricConsistencyFilter(0, vp, dp, {1, 2, 3, 4}, grid.InvStep(), GcFilterOptions(), 1);
    const ImageF med = MedianPrune(gc, grid, prune, 1);
    const ImageF bil = BilateralMedianPrune(med, rig.views[0].color, grid, prune, 1);
    const ImageF prop = PropagateAnchors(bil, rig.views[0].color, env);
    benchmark::DoNotOptimize(FinalizeEnvelope(prop, env).data());
  }
  SetPerMegapixel(state, width);
}
BENCHMARK(BM_EnvelopeFilters)->Arg(576)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_Upsample(benchmark::State& state) {
  const int width = static_cast<int>(state.range(0));
  const Rig& low = GetRig(width);
  const Rig& high = GetRig(2 * width);
  UpsampleOptions opt;
  opt.num_threads = 1;
  for (auto _ : state) {
    ImageF up = JointBilateralMedianUpsample(low.depth[0], low.views[0].color, high.views[0].color, opt);
    benchmark::DoNotOptimize(up.data());
  }
  SetPerMegapixel(state, width);
}
BENCHMARK(BM_Upsample)->Arg(576)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace
}  // namespace casual3d::depth

BENCHMARK_MAIN();

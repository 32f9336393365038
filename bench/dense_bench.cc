// Dense stage benchmarks (docs/PERFORMANCE.md, "Dense"): the plane sweep
// (220 hypotheses, 4 neighbours), the WTA, the near-envelope filters and
// solver, TRW-S and the upsampling, on a ray-cast toy scene at the working
// resolution of a 1152x864 photo (576x432 at the default working scale 0.5);
// the boundary relabelling, the full-resolution search and the free-space
// check at the photo's resolution.
// Counters: seconds per megapixel of the photo (4x the working pixels); for
// the sweep and TRW-S, CPU time of the whole process (all threads) per unit
// of work: per pixel x label x neighbour (sweep) and per pixel x label x pass
// (TRW-S), and TRW-S's message memory.
//
//   build/bench/dense_bench --benchmark_filter='Sweep|Trws'
//   build/bench/dense_bench --benchmark_filter=Sweep/576

#include <benchmark/benchmark.h>

#include <algorithm>
#include <cmath>
#include <map>

#include "reconstruct/depth/edge_median.h"
#include "reconstruct/depth/fullres_refine.h"
#include "reconstruct/depth/gc_filter.h"
#include "reconstruct/depth/median_prune.h"
#include "reconstruct/depth/mrf_trws.h"
#include "reconstruct/depth/near_envelope.h"
#include "reconstruct/depth/plane_sweep.h"
#include "reconstruct/depth/testing/toy_scene.h"
#include "reconstruct/depth/upsample.h"
#include "reconstruct/depth/visibility_filter.h"

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
  const Eigen::Vector3d centres[5] = {
      {0, 0, 0}, {0.15, 0, 0}, {-0.15, 0, 0}, {0, 0.15, 0}, {0, -0.15, 0}};
  for (const auto& c : centres) {
    ImageF d;
    rig.views.push_back(testing::MakeView(scene, testing::ToyCamera(c, width, height, f),
                                          {0.5, 50.0}, 1.0, 0.0, &d));
    rig.depth.push_back(std::move(d));
  }
  return rigs.emplace(width, std::move(rig)).first->second;
}

void SetPerMegapixel(benchmark::State& state, int width) {
  const double photo_mp = 4.0 * width * (width * 3 / 4) / 1e6;  // Working scale 0.5.
  state.counters["s_per_photo_MP"] = benchmark::Counter(
      1.0 / photo_mp, benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
}

// The sweep's and TRW-S's counters are CPU rates: these benchmarks measure
// the process's CPU time (all threads), so the rates are CPU seconds per unit.
void SetCpuPerUnit(benchmark::State& state, const char* name, double units_per_iteration) {
  state.counters[name] =
      benchmark::Counter(units_per_iteration, benchmark::Counter::kIsIterationInvariantRate |
                                                  benchmark::Counter::kInvert);
}

// Args: working width, threads.
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
  const double pixels = static_cast<double>(width) * (width * 3 / 4);
  SetCpuPerUnit(state, "cpu_s_per_px_label_nb", pixels * opt.num_depths * nbs.size());
  SetCpuPerUnit(state, "cpu_s_per_photo_MP", 4.0 * pixels / 1e6);
}
BENCHMARK(BM_Sweep)
    ->Args({288, 2})
    ->Args({576, 1})
    ->Args({576, 2})
    ->Unit(benchmark::kMillisecond)
    ->MeasureProcessCPUTime();

// The MRF of the dense stage on the toy scene: unaries from the sweep, edge
// weights lambda_smooth / T * max(floor, w_color) as in dense_stage.cc.
const GridMrf& GetMrf(int width) {
  static std::map<int, GridMrf> mrfs;
  auto it = mrfs.find(width);
  if (it != mrfs.end()) return it->second;
  const Rig& rig = GetRig(width);
  SweepOptions opt;
  const CostVolume vol = ComputeCostVolume(
      rig.views[0], {&rig.views[1], &rig.views[2], &rig.views[3], &rig.views[4]}, opt);
  GridMrf m;
  m.width = vol.width;
  m.height = vol.height;
  m.num_labels = vol.num_labels;
  m.truncation = 8;
  m.unary = vol.cost;
  const size_t n = static_cast<size_t>(vol.width) * vol.height;
  m.weight_right.assign(n, 0.0f);
  m.weight_down.assign(n, 0.0f);
  const ImageF& c = rig.views[0].color;
  auto weight = [&](int x0, int y0, int x1, int y1) {
    double d2 = 0;
    for (int k = 0; k < 3; ++k) d2 += std::pow(c.at(x0, y0, k) - c.at(x1, y1, k), 2);
    return static_cast<float>(0.25 / 8 * std::max(0.02, std::exp(-d2 / (2 * 0.04 * 0.04))));
  };
  for (int y = 0; y < m.height; ++y)
    for (int x = 0; x < m.width; ++x) {
      const size_t p = static_cast<size_t>(y) * m.width + x;
      if (x + 1 < m.width) m.weight_right[p] = weight(x, y, x + 1, y);
      if (y + 1 < m.height) m.weight_down[p] = weight(x, y, x, y + 1);
    }
  return mrfs.emplace(width, std::move(m)).first->second;
}

// Args: working width, passes (0: the default stopping rule), AVX2
// messages where the CPU has them (1) or SSE2 (0), messages stored as half
// floats where the CPU has F16C (1) or as floats (0).
void BM_Trws(benchmark::State& state) {
  const int width = static_cast<int>(state.range(0));
  const GridMrf& m = GetMrf(width);
  TrwsOptions opt;
  opt.avx2_messages = state.range(2) != 0;
  opt.half_messages = state.range(3) != 0;
  if (state.range(1) > 0) {
    opt.max_iterations = static_cast<int>(state.range(1));
    opt.relative_tolerance = 0.0;
    opt.patience = opt.max_iterations;  // Exactly max_iterations passes.
  }
  TrwsResult r;
  for (auto _ : state) {
    r = SolveTrws(m, opt);
    benchmark::DoNotOptimize(r.energy);
  }
  state.counters["passes"] = r.iterations;
  state.counters["energy"] = r.energy;
  state.counters["best_pass"] =
      static_cast<double>(std::min_element(r.pass_energies.begin(), r.pass_energies.end()) -
                          r.pass_energies.begin() + 1);
  state.counters["message_MB"] = TrwsMessageBytes(m.width, m.height, m.num_labels,
                                                    opt.half_messages && TrwsHalfMessagesAvailable()) / 1e6;
  const double pixels = static_cast<double>(m.width) * m.height;
  SetCpuPerUnit(state, "cpu_s_per_px_label_pass", pixels * m.num_labels * r.iterations);
  SetCpuPerUnit(state, "cpu_s_per_photo_MP", 4.0 * pixels / 1e6);
}
BENCHMARK(BM_Trws)
    ->Args({288, 8, 1, 1})
    ->Args({576, 8, 1, 1})
    ->Args({576, 8, 1, 0})
    ->Args({576, 0, 1, 1})
    ->Args({576, 0, 1, 0})
    ->Args({576, 0, 0, 0})
    ->Unit(benchmark::kMillisecond)
    ->MeasureProcessCPUTime();

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
    const ImageF gc =
        GeometricConsistencyFilter(0, vp, dp, {1, 2, 3, 4}, grid.InvStep(), GcFilterOptions(), 1);
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
    ImageF up =
        JointBilateralMedianUpsample(low.depth[0], low.views[0].color, high.views[0].color, opt);
    benchmark::DoNotOptimize(up.data());
  }
  SetPerMegapixel(state, width);
}
BENCHMARK(BM_Upsample)->Arg(576)->Unit(benchmark::kMillisecond)->UseRealTime();

// The edge-aware median of a working-resolution labelling: the toy scene's
// true depth in 220 labels with every depth edge's near side spread 3 pixels
// outwards (the sweep's fattening, which the filter undoes). Counter:
// labels changed.
void BM_EdgeMedian(benchmark::State& state) {
  const int width = static_cast<int>(state.range(0));
  const Rig& rig = GetRig(width);
  const ImageF& truth = rig.depth[0];
  const LabelGrid grid{2.0, 0.02, 220};
  const ImageF fat = MinFilter(truth, 2 * 3 + 1);
  std::vector<int> labels(fat.vector().size());
  for (size_t p = 0; p < labels.size(); ++p) {
    const float d = fat.data()[p];
    const double k = std::isfinite(d) ? grid.LabelOf(d) : grid.num_labels - 1;
    labels[p] = std::clamp(static_cast<int>(std::lround(k)), 0, grid.num_labels - 1);
  }
  std::vector<int> out;
  for (auto _ : state) {
    out = EdgeAwareMedian(labels, grid.num_labels, rig.views[0].color, EdgeMedianOptions(), 1);
    benchmark::DoNotOptimize(out.data());
  }
  long long changed = 0;
  for (size_t i = 0; i < labels.size(); ++i) changed += out[i] != labels[i];
  state.counters["changed"] = static_cast<double>(changed);
  SetPerMegapixel(state, width);
}
BENCHMARK(BM_EdgeMedian)->Arg(576)->Unit(benchmark::kMillisecond)->UseRealTime();

// The full-resolution steps on the photo-sized rig, 4 neighbours, starting
// from the true depth with the near side of every depth edge spread 6 pixels
// outwards (the fattening the relabelling removes).
struct FullResInput {
  ImageF depth;
  std::vector<RefineNeighbor> neighbors;
};

const FullResInput& GetFullResInput(int width) {
  static std::map<int, FullResInput> inputs;
  auto it = inputs.find(width);
  if (it != inputs.end()) return it->second;
  const Rig& rig = GetRig(width);
  FullResInput in;
  const ImageF& truth = rig.depth[0];
  in.depth = MinFilter(truth, 2 * 6 + 1);
  for (float& d : in.depth.vector())
    if (!std::isfinite(d)) d = 50.0f;
  for (size_t i = 1; i < rig.views.size(); ++i) in.neighbors.push_back({&rig.views[i].gray, rig.views[i].camera});
  return inputs.emplace(width, std::move(in)).first->second;
}

void BM_Relabel(benchmark::State& state) {
  const int width = static_cast<int>(state.range(0));
  const Rig& rig = GetRig(2 * width);
  const FullResInput& in = GetFullResInput(2 * width);
  const LabelGrid grid{2.0, 0.02, 220};
  long long changed = 0;
  for (auto _ : state) {
    changed = 0;
    ImageF out = RelabelBoundaries(rig.views[0].color, rig.views[0].gray, rig.views[0].camera, in.depth,
                                   in.neighbors, grid.InvStep(), BoundaryRelabelOptions(), 1, &changed);
    benchmark::DoNotOptimize(out.data());
  }
  state.counters["changed"] = static_cast<double>(changed);
  SetPerMegapixel(state, width);
}
BENCHMARK(BM_Relabel)->Arg(576)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_FullResRefine(benchmark::State& state) {
  const int width = static_cast<int>(state.range(0));
  const Rig& rig = GetRig(2 * width);
  const FullResInput& in = GetFullResInput(2 * width);
  const LabelGrid grid{2.0, 0.02, 220};
  for (auto _ : state) {
    ImageF out = RefineFullResolution(rig.views[0].gray, rig.views[0].camera, in.depth, in.neighbors,
                                      grid.InvStep(), FullResRefineOptions(), 1);
    benchmark::DoNotOptimize(out.data());
  }
  SetPerMegapixel(state, width);
}
BENCHMARK(BM_FullResRefine)->Arg(576)->Unit(benchmark::kMillisecond)->UseRealTime();

// The free-space check of one photo-sized map against 12 others (its default
// number of views): a reference ring of 13 cameras, the reference's map
// fattened as above (its edge bands are what the check flags), the others
// exact. Counters: pixels flagged and moved back.
void BM_FreeSpace(benchmark::State& state) {
  const int width = 2 * static_cast<int>(state.range(0)), height = width * 3 / 4;
  static std::map<int, std::pair<std::vector<DenseView>, std::vector<ImageF>>> rings;
  auto& ring = rings[width];
  if (ring.first.empty()) {
    const testing::ToyScene scene = testing::ToyScene::Default();
    for (int k = 0; k < 13; ++k) {
      const double a = 2 * M_PI * k / 12;
      const Eigen::Vector3d c = k == 0 ? Eigen::Vector3d::Zero() : Eigen::Vector3d(0.15 * std::cos(a), 0.15 * std::sin(a), 0);
      ImageF d;
      ring.first.push_back(testing::MakeView(scene, testing::ToyCamera(c, width, height, 0.785 * width), {0.5, 50.0},
                                             1.0, 0.0, &d));
      for (float& z : d.vector())
        if (!std::isfinite(z)) z = 50.0f;
      ring.second.push_back(std::move(d));
    }
    ring.second[0] = GetFullResInput(width).depth;
  }
  std::vector<const PinholeCamera*> cameras;
  std::vector<const ImageF*> depths, grays;
  std::vector<int> others;
  for (int k = 0; k < 13; ++k) {
    cameras.push_back(&ring.first[k].camera);
    depths.push_back(&ring.second[k]);
    grays.push_back(&ring.first[k].gray);
    if (k > 0) others.push_back(k);
  }
  const LabelGrid grid{2.0, 0.02, 220};
  VisibilityStats stats;
  for (auto _ : state) {
    stats = VisibilityStats();
    auto moves = CheckFreeSpace(0, cameras, depths, grays, others, grid.InvStep(), VisibilityFilterOptions(), &stats);
    benchmark::DoNotOptimize(moves.data());
  }
  state.counters["flagged"] = static_cast<double>(stats.flagged);
  state.counters["moved"] = static_cast<double>(stats.replaced);
  SetPerMegapixel(state, static_cast<int>(state.range(0)));
}
BENCHMARK(BM_FreeSpace)->Arg(576)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace
}  // namespace casual3d::depth

BENCHMARK_MAIN();

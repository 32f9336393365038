// Timings of the stitch's seam blend solver (reconstruct/stitch/
// screened_poisson.h): one channel of a panorama-sized window, every pixel
// labelled, with jumps along the borders of 300x200-pixel patches to even
// out, screened over 1/32 of the width and solved to the seam blend's 1%
// residual. Arguments: the window's width (height half of it) and threads.

#include <benchmark/benchmark.h>

#include <vector>

#include "reconstruct/stitch/screened_poisson.h"

namespace casual3d::stitch {
namespace {

void BM_ScreenedPoissonSolve(benchmark::State& state) {
  const int w = static_cast<int>(state.range(0)), h = w / 2;
  PoissonGrid grid(w, h, true);
  std::vector<float> b(grid.screen.size(), 0.0f);
  const float length = w / 32.0f;
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      const size_t p = grid.index(x, y);
      grid.screen[p] = 1.0f / (length * length);
      grid.right[p] = 1.0f;
      grid.down[p] = y + 1 < h ? 1.0f : 0.0f;
      if (x + 1 < w && (x + 1) / 300 != x / 300) AddEdgeTarget(p, p + 1, 1.0f, 12.0f, &b);
      if (y + 1 < h && (y + 1) / 200 != y / 200) AddEdgeTarget(p, p + w, 1.0f, -8.0f, &b);
    }
  }
  PoissonSolveOptions options;
  options.relative_tolerance = 1e-2;
  options.max_iterations = 40;
  options.threads = static_cast<int>(state.range(1));
  PoissonSolveReport report;
  for (auto _ : state) {
    ScreenedPoissonSolver solver(grid, options);
    const std::vector<float> d = solver.Solve(b, &report);
    benchmark::DoNotOptimize(d.data());
  }
  state.counters["iterations"] = report.iterations;
  state.counters["pixels_per_s"] =
      benchmark::Counter(static_cast<double>(w) * h, benchmark::Counter::kIsIterationInvariantRate);
}
BENCHMARK(BM_ScreenedPoissonSolve)
    ->Args({1024, 2})
    ->Args({2048, 1})
    ->Args({2048, 2})
    ->Args({4096, 2})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

}  // namespace
}  // namespace casual3d::stitch

BENCHMARK_MAIN();

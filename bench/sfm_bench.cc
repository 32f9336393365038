// Descriptor matching of the sparse stage (reconstruct/sfm/descriptor_matcher.h):
// one pair of photos with N SIFT-like descriptors each, half of them shared
// with noise. docs/PERFORMANCE.md, "Sparse stage".

#include <benchmark/benchmark.h>

#include <algorithm>
#include <cmath>
#include <random>

#include "reconstruct/sfm/descriptor_matcher.h"
#include "reconstruct/sfm/testing/sift_like.h"

namespace {

using casual3d::sfm::SiftDescriptors;

void MakePair(int n, SiftDescriptors* a, SiftDescriptors* b) {
  using casual3d::sfm::testing::RandomSiftValues;
  using casual3d::sfm::testing::SiftLikeBytes;
  std::mt19937 rng(17);
  std::normal_distribution<double> noise(0.0, 5.0);
  a->rows = b->rows = n;
  for (int i = 0; i < n; ++i) {
    const std::vector<double> v = RandomSiftValues(&rng);
    std::vector<double> w = RandomSiftValues(&rng);
    if (i % 2 == 0)  // Every other descriptor of b is a's with noise.
      for (size_t k = 0; k < v.size(); ++k) w[k] = std::max(0.0, v[k] * 40 + noise(rng));
    const auto av = SiftLikeBytes(v), bw = SiftLikeBytes(w);
    a->data.insert(a->data.end(), av.begin(), av.end());
    b->data.insert(b->data.end(), bw.begin(), bw.end());
  }
}

void BM_MatchDescriptors(benchmark::State& state) {
  SiftDescriptors a, b;
  MakePair(static_cast<int>(state.range(0)), &a, &b);
  size_t matches = 0;
  for (auto _ : state) {
    matches = casual3d::sfm::MatchDescriptors(a, b).size();
    benchmark::DoNotOptimize(matches);
  }
  state.counters["matches"] = static_cast<double>(matches);
  const double n = static_cast<double>(state.range(0));
  state.counters["GFLOP/s"] = benchmark::Counter(2.0 * n * n * casual3d::sfm::kSiftDimensions / 1e9,
                                                  benchmark::Counter::kIsIterationInvariantRate);
}
BENCHMARK(BM_MatchDescriptors)->Arg(1024)->Arg(2048)->Arg(4096)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();

#include "reconstruct/stitch/alpha_expansion.h"

#include <cmath>
#include <random>

#include <gtest/gtest.h>

namespace casual3d::stitch {
namespace {

// Exhaustive minimum over all labellings of a tiny grid.
double BruteForceMinimum(const GridMrf& mrf, const GridMrf::Pairwise& pairwise) {
  const int n = mrf.width() * mrf.height();
  std::vector<int> labels(n, 0);
  double best = 1e300;
  while (true) {
    best = std::min(best, mrf.Energy(labels, pairwise));
    int i = 0;
    while (i < n && ++labels[i] == mrf.num_labels()) labels[i++] = 0;
    if (i == n) break;
  }
  return best;
}

TEST(AlphaExpansionTest, PottsEnergyCloseToExhaustiveOptimum) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> unit(0.0f, 1.0f);
  double ratio_sum = 0;
  const int trials = 30;
  for (int trial = 0; trial < trials; ++trial) {
    GridMrf mrf(3, 3, 3, /*wrap_x=*/false);
    for (int p = 0; p < 9; ++p)
      for (int l = 0; l < 3; ++l) mrf.data_cost(p, l) = unit(rng);
    const float lambda = 0.4f * unit(rng);
    GridMrf::Pairwise potts = [&](int, int, int a, int b) { return a == b ? 0.0f : lambda; };
    const std::vector<int> labels = mrf.Solve(potts, AlphaExpansionOptions());
    const double e = mrf.Energy(labels, potts);
    const double opt = BruteForceMinimum(mrf, potts);
    ASSERT_GE(e, opt - 1e-6);
    // Alpha expansion is within a factor 2 of the optimum for Potts models.
    ASSERT_LE(e, 2.0 * opt + 1e-6);
    ratio_sum += e / opt;
  }
  EXPECT_LT(ratio_sum / trials, 1.02);
}

TEST(AlphaExpansionTest, NonMetricSeamCostsNeverIncreaseEnergy) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> unit(0.0f, 1.0f);
  for (int trial = 0; trial < 20; ++trial) {
    GridMrf mrf(4, 3, 4, /*wrap_x=*/true);
    for (int p = 0; p < 12; ++p)
      for (int l = 0; l < 4; ++l)
        mrf.data_cost(p, l) = unit(rng) < 0.2f ? kInfiniteCost : unit(rng);
    std::vector<float> table(12 * 12 * 16);
    for (float& v : table) v = 0.5f * unit(rng);
    GridMrf::Pairwise seam = [&](int p, int q, int a, int b) {
      return a == b ? 0.0f : table[((p * 12 + q) % 144) * 16 + a * 4 + b];
    };
    std::vector<int> start(12, -1);
    const std::vector<int> first = mrf.Solve(start, seam, AlphaExpansionOptions{1, 0});
    const std::vector<int> more = mrf.Solve(first, seam, AlphaExpansionOptions{5, 0});
    EXPECT_LE(mrf.Energy(more, seam), mrf.Energy(first, seam) + 1e-6);
    for (int p = 0; p < 12; ++p) {
      if (more[p] >= 0) EXPECT_LT(mrf.data_cost(p, more[p]), kInfiniteCost);
    }
  }
}

TEST(AlphaExpansionTest, SmoothsANoisyTwoRegionImage) {
  // Left half prefers label 0, right half label 1, with 20% flipped noise.
  const int w = 40, h = 20;
  GridMrf mrf(w, h, 2, false);
  std::mt19937 rng(1);
  std::uniform_real_distribution<float> unit(0.0f, 1.0f);
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      int truth = x < w / 2 ? 0 : 1;
      if (unit(rng) < 0.2f) truth = 1 - truth;
      mrf.data_cost(y * w + x, truth) = 0.0f;
      mrf.data_cost(y * w + x, 1 - truth) = 1.0f;
    }
  }
  GridMrf::Pairwise potts = [](int, int, int a, int b) { return a == b ? 0.0f : 0.6f; };
  const std::vector<int> labels = mrf.Solve(potts, AlphaExpansionOptions());
  int wrong = 0;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) wrong += labels[y * w + x] != (x < w / 2 ? 0 : 1);
  EXPECT_LT(wrong, w * h / 50);
}

}  // namespace
}  // namespace casual3d::stitch

#include "reconstruct/depth/mrf_trws.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>

namespace casual3d::depth {
namespace {

GridMrf RandomMrf(int w, int h, int labels, int truncation, unsigned seed, float smooth) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u01(0.0f, 1.0f);
  GridMrf m;
  m.width = w;
  m.height = h;
  m.num_labels = labels;
  m.truncation = truncation;
  m.unary.resize(static_cast<size_t>(w) * h * labels);
  for (float& v : m.unary) v = u01(rng);
  m.weight_right.resize(static_cast<size_t>(w) * h);
  m.weight_down.resize(static_cast<size_t>(w) * h);
  for (float& v : m.weight_right) v = smooth * u01(rng);
  for (float& v : m.weight_down) v = smooth * u01(rng);
  return m;
}

// Exhaustive minimum over all labellings (small problems only).
double BruteForce(const GridMrf& m) {
  const size_t n = static_cast<size_t>(m.width) * m.height;
  std::vector<uint16_t> lab(n, 0);
  double best = std::numeric_limits<double>::infinity();
  for (;;) {
    best = std::min(best, MrfEnergy(m, lab));
    size_t i = 0;
    while (i < n && ++lab[i] == m.num_labels) lab[i++] = 0;
    if (i == n) break;
  }
  return best;
}

// Iterated conditional modes from the unary minimum: a weak reference solver.
double Icm(const GridMrf& m) {
  const int w = m.width, h = m.height, L = m.num_labels;
  std::vector<uint16_t> lab(static_cast<size_t>(w) * h);
  for (size_t p = 0; p < lab.size(); ++p)
    lab[p] = static_cast<uint16_t>(std::min_element(&m.unary[p * L], &m.unary[p * L] + L) -
                                   &m.unary[p * L]);
  for (int it = 0; it < 20; ++it)
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x) {
        const size_t p = static_cast<size_t>(y) * w + x;
        int best = lab[p];
        double best_c = std::numeric_limits<double>::infinity();
        for (int l = 0; l < L; ++l) {
          double c = m.unary[p * L + l];
          auto pw = [&](float wt, int o) { c += wt * std::min(std::abs(l - o), m.truncation); };
          if (x > 0) pw(m.weight_right[p - 1], lab[p - 1]);
          if (x + 1 < w) pw(m.weight_right[p], lab[p + 1]);
          if (y > 0) pw(m.weight_down[p - w], lab[p - w]);
          if (y + 1 < h) pw(m.weight_down[p], lab[p + w]);
          if (c < best_c) {
            best_c = c;
            best = l;
          }
        }
        lab[p] = static_cast<uint16_t>(best);
      }
  return MrfEnergy(m, lab);
}

TEST(Trws, MatchesExhaustiveSearchOnSmallGrids) {
  double worst_gap = 0.0, total_gap = 0.0;
  int optimal = 0;
  const int kProblems = 24;
  for (int s = 0; s < kProblems; ++s) {
    // 3x3 grid, 4 labels: 262,144 labellings. Strong smoothness makes it non-trivial.
    const GridMrf m = RandomMrf(3, 3, 4, 2, 100 + s, 0.6f);
    const double ref = BruteForce(m);
    const TrwsResult r = SolveTrws(m);  // Default options, as the dense stage uses them.
    EXPECT_NEAR(r.energy, MrfEnergy(m, r.labels), 1e-5);
    EXPECT_GE(r.energy, ref - 1e-6);
    const double gap = (r.energy - ref) / ref;
    worst_gap = std::max(worst_gap, gap);
    total_gap += gap;
    optimal += gap < 1e-6;
  }
  EXPECT_LE(worst_gap, 0.01);
  EXPECT_LE(total_gap / kProblems, 0.001);
  EXPECT_GE(optimal, kProblems - 2);
}

TEST(Trws, BeatsIcmOnLargerProblems) {
  for (int s = 0; s < 3; ++s) {
    const GridMrf m = RandomMrf(40, 30, 32, 6, 7 + s, 0.3f);
    const TrwsResult r = SolveTrws(m);
    EXPECT_LT(r.energy, Icm(m) * 0.99);
  }
}

TEST(Trws, DenoisesAPiecewiseConstantLabelImage) {
  // Two regions (labels 5 and 20 of 32); unaries favour the truth with noise.
  const int w = 48, h = 32, L = 32;
  GridMrf m;
  m.width = w;
  m.height = h;
  m.num_labels = L;
  m.truncation = 4;
  m.unary.resize(static_cast<size_t>(w) * h * L);
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> noise(0.0f, 1.0f);
  std::vector<int> truth(static_cast<size_t>(w) * h);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const size_t p = static_cast<size_t>(y) * w + x;
      truth[p] = x < w / 2 ? 5 : 20;
      for (int l = 0; l < L; ++l)
        m.unary[p * L + l] = 0.6f * noise(rng) + (l == truth[p] ? 0.0f : 0.35f);
    }
  m.weight_right.assign(static_cast<size_t>(w) * h, 0.15f);
  m.weight_down.assign(static_cast<size_t>(w) * h, 0.15f);
  const TrwsResult r = SolveTrws(m);
  int correct = 0;
  for (size_t p = 0; p < truth.size(); ++p) correct += r.labels[p] == truth[p];
  EXPECT_GE(correct, static_cast<int>(0.98 * truth.size()));
}

// Exact minimum of a chain MRF (a 1 x n or n x 1 grid) by dynamic programming.
double ChainMinimum(const GridMrf& m) {
  const int n = m.width * m.height, L = m.num_labels;
  const std::vector<float>& wt = m.height == 1 ? m.weight_right : m.weight_down;
  std::vector<double> cost(m.unary.begin(), m.unary.begin() + L), next(L);
  for (int i = 1; i < n; ++i) {
    for (int l = 0; l < L; ++l) {
      double best = std::numeric_limits<double>::infinity();
      for (int k = 0; k < L; ++k)
        best = std::min(best, cost[k] + static_cast<double>(wt[i - 1]) *
                                            std::min(std::abs(l - k), m.truncation));
      next[l] = m.unary[static_cast<size_t>(i) * L + l] + best;
    }
    cost.swap(next);
  }
  return *std::min_element(cost.begin(), cost.end());
}

TEST(Trws, ExactOnChains) {
  // Chains are trees, on which TRW-S is exact. Label counts around the SIMD
  // block sizes (multiples of 4 and 8 and not) exercise the padded labels;
  // truncations from 1 to beyond the label range exercise the cap.
  int cases = 0;
  for (int labels : {1, 2, 3, 7, 8, 9, 21, 64}) {
    for (int truncation : {1, 3, 100}) {
      for (int vertical = 0; vertical < 2; ++vertical) {
        const int len = 17;
        GridMrf m = RandomMrf(vertical ? 1 : len, vertical ? len : 1, labels, truncation,
                              1000 + labels * 7 + truncation + vertical, 0.4f);
        const double exact = ChainMinimum(m);
        // Float messages, and half ones where the CPU has them.
        for (bool half : {false, true}) {
          TrwsOptions opt;
          opt.half_messages = half;
          const TrwsResult r = SolveTrws(m, opt);
          EXPECT_NEAR(r.energy, exact, 1e-5 * std::max(1.0, exact))
              << labels << " labels, truncation " << truncation
              << (vertical ? ", vertical" : ", horizontal") << (half ? ", half messages" : "");
          EXPECT_NEAR(r.energy, MrfEnergy(m, r.labels), 1e-5);
        }
        ++cases;
      }
    }
  }
  EXPECT_EQ(cases, 48);
}

// The AVX2 messages (where the CPU has them) and the SSE2 ones are the same
// to the bit: labellings and every pass's energy agree exactly.
TEST(Trws, Avx2AndSse2MessagesAgreeExactly) {
#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__)
  if (!__builtin_cpu_supports("avx2")) GTEST_SKIP() << "this CPU has no AVX2";
#else
  GTEST_SKIP() << "the AVX2 path is built with GCC on x86-64 only";
#endif
  TrwsOptions opt;
  opt.max_iterations = 5;
  opt.relative_tolerance = 0.0;
  opt.patience = 1000;
  opt.half_messages = false;
  int cases = 0;
  for (int labels : {1, 3, 8, 9, 21, 64, 220})
    for (int truncation : {1, 3, 8, 100}) {
      const GridMrf m = RandomMrf(23, 17, labels, truncation, 77 + labels * 13 + truncation, 0.3f);
      const TrwsResult avx2 = SolveTrws(m, opt);
      TrwsOptions sse2_opt = opt;
      sse2_opt.avx2_messages = false;
      const TrwsResult sse2 = SolveTrws(m, sse2_opt);
      EXPECT_EQ(avx2.labels, sse2.labels) << labels << " labels, truncation " << truncation;
      EXPECT_EQ(avx2.pass_energies, sse2.pass_energies) << labels << " labels, truncation " << truncation;
      ++cases;
    }
  EXPECT_EQ(cases, 28);
}

// Half messages round every stored message to 11 significant bits: on a
// denoising problem of the dense stage's kind (220 labels, truncation 8,
// unary in [0, 1]) the solution stays that of float messages.
TEST(Trws, HalfMessagesMatchFloatOnes) {
  if (!TrwsHalfMessagesAvailable()) GTEST_SKIP() << "this CPU has no AVX2 and F16C";
  const int w = 96, h = 72, L = 220;
  GridMrf m = RandomMrf(w, h, L, 8, 5, 0.0f);
  // A smooth label surface with a step; unary: distance to it, plus noise.
  std::mt19937 rng(9);
  std::uniform_real_distribution<float> noise(0.0f, 0.3f);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const size_t p = static_cast<size_t>(y) * w + x;
      const float truth = (x < w / 2 ? 40.0f : 150.0f) + 0.3f * y;
      for (int l = 0; l < L; ++l)
        m.unary[p * L + l] = std::min(1.0f, std::abs(l - truth) / 20.0f) + noise(rng);
      m.weight_right[p] = x == w / 2 - 1 ? 0.002f : 0.03f;
      m.weight_down[p] = 0.03f;
    }
  TrwsOptions opt;
  opt.half_messages = false;
  const TrwsResult full = SolveTrws(m, opt);
  opt.half_messages = true;
  const TrwsResult half = SolveTrws(m, opt);
  EXPECT_NEAR(half.energy, full.energy, 1e-3 * full.energy);
  size_t same = 0;
  for (size_t p = 0; p < full.labels.size(); ++p) same += std::abs(full.labels[p] - half.labels[p]) <= 1;
  EXPECT_GE(static_cast<double>(same) / full.labels.size(), 0.99);
  EXPECT_EQ(TrwsMessageBytes(w, h, L, true) * 2, TrwsMessageBytes(w, h, L, false));
}

TEST(Trws, ReportsTheEnergyOfEveryPass) {
  const GridMrf m = RandomMrf(20, 15, 30, 5, 11, 0.5f);
  TrwsOptions opt;
  opt.max_iterations = 6;
  opt.relative_tolerance = 0.0;
  opt.patience = 1000;  // Run every pass.
  const TrwsResult r = SolveTrws(m, opt);
  ASSERT_EQ(r.iterations, 6);
  ASSERT_EQ(r.pass_energies.size(), 6u);
  EXPECT_DOUBLE_EQ(r.energy, *std::min_element(r.pass_energies.begin(), r.pass_energies.end()));
  // Stopping early: with a tolerance no pass can meet, patience 1 stops after two passes.
  opt.relative_tolerance = 1.0;
  opt.patience = 1;
  EXPECT_EQ(SolveTrws(m, opt).iterations, 2);
}

TEST(Trws, RejectsNegativeWeights) {
  GridMrf m = RandomMrf(4, 4, 3, 1, 1, 0.1f);
  m.weight_down[5] = -0.1f;
  EXPECT_THROW(SolveTrws(m), std::invalid_argument);
}

TEST(Trws, RejectsInconsistentSizes) {
  GridMrf m = RandomMrf(4, 4, 3, 1, 1, 0.1f);
  m.unary.pop_back();
  EXPECT_THROW(SolveTrws(m), std::invalid_argument);
}

}  // namespace
}  // namespace casual3d::depth

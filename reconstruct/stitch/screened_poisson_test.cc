#include "reconstruct/stitch/screened_poisson.h"

#include <algorithm>
#include <cmath>
#include <random>
#include <stdexcept>
#include <tuple>
#include <vector>

#include <gtest/gtest.h>

namespace casual3d::stitch {
namespace {

// The system's matrix in band storage: entry (i, j), |i - j| <= band, at
// i * (2 band + 1) + j - i + band. The band is the grid's width (1 for an
// unwrapped row).
struct BandMatrix {
  size_t n, band;
  std::vector<double> v;
  BandMatrix(size_t n_, size_t band_) : n(n_), band(band_), v(n_ * (2 * band_ + 1), 0.0) {}
  double& at(size_t i, size_t j) { return v[i * (2 * band + 1) + j + band - i]; }
};

BandMatrix SystemMatrix(const PoissonGrid& g) {
  BandMatrix a(static_cast<size_t>(g.width) * g.height, g.height > 1 || g.wrap_x ? g.width : 1);
  auto edge = [&](size_t p, size_t q, double w) {
    if (p == q || !(w > 0)) return;
    a.at(p, p) += w;
    a.at(q, q) += w;
    a.at(p, q) -= w;
    a.at(q, p) -= w;
  };
  for (int y = 0; y < g.height; ++y) {
    for (int x = 0; x < g.width; ++x) {
      const size_t p = g.index(x, y);
      a.at(p, p) += g.screen[p];
      if (x + 1 < g.width) edge(p, g.index(x + 1, y), g.right[p]);
      else if (g.wrap_x) edge(p, g.index(0, y), g.right[p]);
      if (y + 1 < g.height) edge(p, g.index(x, y + 1), g.down[p]);
    }
  }
  return a;
}

// Gaussian elimination without pivoting (the matrix is definite on the
// pixels that take part); rows of the others (all zero) give 0.
std::vector<double> DirectSolve(BandMatrix a, std::vector<double> b) {
  const size_t n = a.n, band = a.band;
  for (size_t k = 0; k < n; ++k) {
    if (a.at(k, k) == 0.0) continue;
    for (size_t i = k + 1; i < std::min(n, k + band + 1); ++i) {
      const double f = a.at(i, k) / a.at(k, k);
      if (f == 0.0) continue;
      for (size_t j = k; j < std::min(n, k + band + 1); ++j) a.at(i, j) -= f * a.at(k, j);
      b[i] -= f * b[k];
    }
  }
  std::vector<double> x(n, 0.0);
  for (size_t k = n; k-- > 0;) {
    if (a.at(k, k) == 0.0) continue;
    double s = b[k];
    for (size_t j = k + 1; j < std::min(n, k + band + 1); ++j) s -= a.at(k, j) * x[j];
    x[k] = s / a.at(k, k);
  }
  return x;
}

// Random weights, cut edges, a hole and wrapped columns: the multigrid
// conjugate gradients agree with a direct solution. 128x72 gives three
// levels (the coarsest at most 2048 pixels), 101x67 two, with blocks of one
// row or column at the ends and, wrapped, a coarser level that does not
// wrap; 5000x1 coarsens in blocks of 2x1; the narrow wrapped grids join a
// pixel to itself (width 1) or twice to its neighbour (width 2).
TEST(ScreenedPoissonTest, MatchesADirectSolution) {
  for (const auto& [W, H, wrap] :
       {std::tuple{128, 72, true}, std::tuple{101, 67, true}, std::tuple{101, 67, false},
        std::tuple{5000, 1, false}, std::tuple{1, 9, true}, std::tuple{2, 9, true}, std::tuple{3, 8, true}}) {
    PoissonGrid g(W, H, wrap);
    std::mt19937 rng(W + wrap);
    std::uniform_real_distribution<float> u(0.0f, 1.0f);
    std::vector<float> b(g.screen.size());
    for (size_t p = 0; p < b.size(); ++p) {
      g.screen[p] = 0.01f;
      g.right[p] = u(rng) < 0.15f ? 0.0f : 0.5f + u(rng);
      g.down[p] = u(rng) < 0.15f ? 0.0f : 0.5f + u(rng);
      b[p] = u(rng) - 0.5f;
    }
    for (int x = 0; x < W; ++x) g.down[g.index(x, H - 1)] = 0.0f;
    if (!wrap) {
      for (int y = 0; y < H; ++y) g.right[g.index(W - 1, y)] = 0.0f;
    }
    // A pixel outside the problem: no screen, no edges.
    const int hx = W > 5 ? 5 : W - 1, hy = H > 6 ? 6 : 0;
    const size_t hole = g.index(hx, hy);
    g.screen[hole] = 0.0f;
    g.right[hole] = g.down[hole] = 0.0f;
    if (hx > 0) g.right[g.index(hx - 1, hy)] = 0.0f;
    else if (wrap) g.right[g.index(W - 1, hy)] = 0.0f;
    if (hy > 0) g.down[g.index(hx, hy - 1)] = 0.0f;
    b[hole] = 1.0f;  // Ignored.

    PoissonSolveOptions options;
    options.relative_tolerance = 1e-6;
    options.max_iterations = 200;
    PoissonSolveReport report;
    const std::vector<float> d = ScreenedPoissonSolver(g, options).Solve(b, &report);
    std::vector<double> bd(b.begin(), b.end());
    bd[hole] = 0.0;
    const std::vector<double> want = DirectSolve(SystemMatrix(g), bd);
    double max_want = 0.0;
    for (double v : want) max_want = std::max(max_want, std::abs(v));
    ASSERT_GT(max_want, 0.5);
    for (size_t p = 0; p < d.size(); ++p)
      ASSERT_NEAR(d[p], want[p], 1e-4 * max_want) << W << "x" << H << " " << p;
    EXPECT_EQ(d[hole], 0.0f);
    EXPECT_LE(report.relative_residual, 1e-6) << W << "x" << H;
    EXPECT_LT(report.iterations, 60) << "the preconditioner does not act";
  }
}

// A jump of 20 between two halves stated as an edge target across their
// border: the correction spreads it over the screening length on both sides,
// and the jump it cancels is gone from f + d.
TEST(ScreenedPoissonTest, AnEdgeTargetSpreadsAJump) {
  const int W = 512, H = 64;
  PoissonGrid g(W, H, false);
  std::vector<float> f(static_cast<size_t>(W) * H), b(f.size(), 0.0f);
  const float length = 40.0f;  // Pixels.
  for (int y = 0; y < H; ++y) {
    for (int x = 0; x < W; ++x) {
      const size_t p = g.index(x, y);
      f[p] = x < W / 2 ? 100.0f : 120.0f;
      g.screen[p] = 1.0f / (length * length);
      g.right[p] = x + 1 < W ? 1.0f : 0.0f;
      g.down[p] = y + 1 < H ? 1.0f : 0.0f;
    }
    // Across the border the target is no step: r = 0 - (f_q - f_p).
    const size_t p = g.index(W / 2 - 1, y);
    AddEdgeTarget(p, p + 1, 1.0f, -20.0f, &b);
  }
  PoissonSolveOptions options;
  PoissonSolveReport report;
  const std::vector<float> d = ScreenedPoissonSolver(g, options).Solve(b, &report);
  EXPECT_LE(report.relative_residual, options.relative_tolerance);
  for (int y = 0; y < H; ++y) {
    float largest_step = 0.0f;
    for (int x = 0; x + 1 < W; ++x) {
      const size_t p = g.index(x, y);
      largest_step = std::max(largest_step, std::abs((f[p + 1] + d[p + 1]) - (f[p] + d[p])));
    }
    EXPECT_LT(largest_step, 1.0f) << "row " << y;
    // Both sides move half the way at the border and keep their level far away.
    EXPECT_NEAR(f[g.index(W / 2, y)] + d[g.index(W / 2, y)], 110.0f, 1.0f);
    EXPECT_NEAR(d[g.index(0, y)], 0.0f, 0.5f);
    EXPECT_NEAR(d[g.index(W - 1, y)], 0.0f, 0.5f);
  }
}

TEST(ScreenedPoissonTest, RefusesSizesThatDoNotMatch) {
  PoissonGrid g(4, 2, true);
  ScreenedPoissonSolver solver(g, PoissonSolveOptions());
  EXPECT_THROW(solver.Solve(std::vector<float>(7)), std::invalid_argument);
  EXPECT_EQ(solver.Solve(std::vector<float>(8, 0.0f)), std::vector<float>(8, 0.0f));
  g.down.pop_back();
  EXPECT_THROW(ScreenedPoissonSolver(g, PoissonSolveOptions()), std::invalid_argument);
}

}  // namespace
}  // namespace casual3d::stitch

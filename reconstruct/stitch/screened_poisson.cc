#include "reconstruct/stitch/screened_poisson.h"

#include <cmath>
#include <algorithm>
#include <stdexcept>

#include "base/parallel_for.h"

namespace casual3d::stitch {
namespace {

// Damped Jacobi: the same sweeps before and after the coarse correction keep
// the V-cycle a symmetric preconditioner, as conjugate gradients need.
constexpr float kJacobiWeight = 0.7f;
constexpr int kSmoothingSweeps = 2;
constexpr int kCoarsestSweeps = 40;
// Coarsening stops at this many pixels (or a height of 1).
constexpr size_t kCoarsestPixels = 2048;

// One level of the hierarchy: its grid (level 0 reads the caller's) and
// each pixel's diagonal.
struct Level {
  const PoissonGrid* grid = nullptr;
  PoissonGrid own;          // The coarser levels' grids.
  std::vector<float> diag;  // s_p plus the weights of p's edges; 0: not solved.
  std::vector<float> x, b, r;  // Scratch of the V-cycle.
};

// Column x's neighbour to the left or right, or -1 (none, or itself).
int Left(const PoissonGrid& g, int x) {
  const int l = x > 0 ? x - 1 : (g.wrap_x ? g.width - 1 : -1);
  return l == x ? -1 : l;
}
int Right(const PoissonGrid& g, int x) {
  const int r = x + 1 < g.width ? x + 1 : (g.wrap_x ? 0 : -1);
  return r == x ? -1 : r;
}

// Calls body(y) for every row of g.
template <typename Body>
void ForRows(const PoissonGrid& g, int threads, Body&& body) {
  base::ParallelFor(0, g.height, threads, [&](int64_t y) { body(static_cast<int>(y)); }, 8);
}

void ComputeDiag(Level* level, int threads) {
  const PoissonGrid& g = *level->grid;
  level->diag.resize(g.screen.size());
  ForRows(g, threads, [&](int y) {
    for (int x = 0; x < g.width; ++x) {
      const size_t p = g.index(x, y);
      float d = g.screen[p];
      if (Right(g, x) >= 0) d += g.right[p];
      if (const int l = Left(g, x); l >= 0) d += g.right[g.index(l, y)];
      if (y + 1 < g.height) d += g.down[p];
      if (y > 0) d += g.down[g.index(x, y - 1)];
      level->diag[p] = d;
    }
  });
}

// out = A v on one level.
void Apply(const Level& level, const std::vector<float>& v, std::vector<float>* out, int threads) {
  const PoissonGrid& g = *level.grid;
  ForRows(g, threads, [&](int y) {
    for (int x = 0; x < g.width; ++x) {
      const size_t p = g.index(x, y);
      if (!(level.diag[p] > 0)) {
        (*out)[p] = 0.0f;
        continue;
      }
      float sum = level.diag[p] * v[p];
      if (const int r = Right(g, x); r >= 0) sum -= g.right[p] * v[g.index(r, y)];
      if (const int l = Left(g, x); l >= 0) sum -= g.right[g.index(l, y)] * v[g.index(l, y)];
      if (y + 1 < g.height) sum -= g.down[p] * v[p + g.width];
      if (y > 0) sum -= g.down[p - g.width] * v[p - g.width];
      (*out)[p] = sum;
    }
  });
}

// The next coarser level: 2x2 blocks, their screens and the weights between
// them summed (the Galerkin operator of piecewise-constant interpolation).
// An odd wrapped width would join the last block to itself: the coarser
// level is then not wrapped (the fine wrap edges are left out of it).
void Coarsen(const Level& fine, Level* coarse, int threads) {
  const PoissonGrid& f = *fine.grid;
  const int cw = (f.width + 1) / 2, ch = (f.height + 1) / 2;
  coarse->own = PoissonGrid(cw, ch, f.wrap_x && f.width % 2 == 0 && cw > 1);
  coarse->grid = &coarse->own;
  PoissonGrid& c = coarse->own;
  ForRows(c, threads, [&](int Y) {
    for (int X = 0; X < cw; ++X) {
      const size_t P = c.index(X, Y);
      for (int y = 2 * Y; y < std::min(2 * Y + 2, f.height); ++y) {
        for (int x = 2 * X; x < std::min(2 * X + 2, f.width); ++x) c.screen[P] += f.screen[f.index(x, y)];
        // The edge leaving the block's right column to the next block.
        const int xr = std::min(2 * X + 1, f.width - 1);
        if (Right(f, xr) >= 0 && (Right(c, X) >= 0) && Right(f, xr) / 2 == Right(c, X))
          c.right[P] += f.right[f.index(xr, y)];
      }
      // The edges leaving the block's bottom row to the next block.
      const int yb = 2 * Y + 1;
      if (yb + 1 < f.height) {
        for (int x = 2 * X; x < std::min(2 * X + 2, f.width); ++x) c.down[P] += f.down[f.index(x, yb)];
      }
    }
  });
  ComputeDiag(coarse, threads);
}

void Jacobi(Level* level, int sweeps, int threads) {
  const PoissonGrid& g = *level->grid;
  for (int s = 0; s < sweeps; ++s) {
    Apply(*level, level->x, &level->r, threads);
    ForRows(g, threads, [&](int y) {
      const size_t end = g.index(0, y) + g.width;
      for (size_t p = g.index(0, y); p < end; ++p) {
        if (level->diag[p] > 0) level->x[p] += kJacobiWeight * (level->b[p] - level->r[p]) / level->diag[p];
      }
    });
  }
}

// levels[k].x = the V-cycle applied to levels[k].b.
void VCycle(std::vector<Level>& levels, size_t k, int threads) {
  Level& L = levels[k];
  std::fill(L.x.begin(), L.x.end(), 0.0f);
  if (k + 1 == levels.size()) {
    Jacobi(&L, kCoarsestSweeps, threads);
    return;
  }
  Jacobi(&L, kSmoothingSweeps, threads);
  Apply(L, L.x, &L.r, threads);
  Level& C = levels[k + 1];
  const PoissonGrid& g = *L.grid;
  const PoissonGrid& c = *C.grid;
  ForRows(c, threads, [&](int Y) {  // The residual, summed over each block.
    for (int X = 0; X < c.width; ++X) {
      float sum = 0.0f;
      for (int y = 2 * Y; y < std::min(2 * Y + 2, g.height); ++y)
        for (int x = 2 * X; x < std::min(2 * X + 2, g.width); ++x) sum += L.b[g.index(x, y)] - L.r[g.index(x, y)];
      C.b[c.index(X, Y)] = sum;
    }
  });
  VCycle(levels, k + 1, threads);
  ForRows(g, threads, [&](int y) {
    for (int x = 0; x < g.width; ++x) {
      const size_t p = g.index(x, y);
      if (L.diag[p] > 0) L.x[p] += C.x[c.index(x / 2, y / 2)];
    }
  });
  Jacobi(&L, kSmoothingSweeps, threads);
}

// The sum of a[i] * b[i], by rows, in a fixed order.
double Dot(const PoissonGrid& g, const std::vector<float>& a, const std::vector<float>& b, int threads) {
  std::vector<double> rows(g.height, 0.0);
  ForRows(g, threads, [&](int y) {
    double s = 0.0;
    const size_t end = g.index(0, y) + g.width;
    for (size_t i = g.index(0, y); i < end; ++i) s += static_cast<double>(a[i]) * b[i];
    rows[y] = s;
  });
  double s = 0.0;
  for (double v : rows) s += v;
  return s;
}

}  // namespace

struct ScreenedPoissonSolver::Hierarchy {
  std::vector<Level> levels;
};

ScreenedPoissonSolver::ScreenedPoissonSolver(const PoissonGrid& grid, const PoissonSolveOptions& options)
    : grid_(grid), options_(options), threads_(base::ResolveThreads(options.threads)),
      levels_(std::make_unique<Hierarchy>()) {
  const size_t n = static_cast<size_t>(grid.width) * grid.height;
  if (grid.width < 1 || grid.height < 1 || grid.right.size() != n || grid.down.size() != n ||
      grid.screen.size() != n) {
    throw std::invalid_argument("screened Poisson: the grid's vectors do not match its size");
  }
  std::vector<Level>& levels = levels_->levels;
  levels.reserve(64);  // Never reallocated: the levels' grids point into them.
  levels.emplace_back();
  levels[0].grid = &grid;
  ComputeDiag(&levels[0], threads_);
  for (;;) {
    const PoissonGrid& last = *levels.back().grid;
    if (last.height <= 1 || static_cast<size_t>(last.width) * last.height <= kCoarsestPixels) break;
    levels.emplace_back();
    Coarsen(levels[levels.size() - 2], &levels.back(), threads_);
  }
  for (Level& L : levels) {
    const size_t m = L.diag.size();
    L.x.assign(m, 0.0f);
    L.b.assign(m, 0.0f);
    L.r.assign(m, 0.0f);
  }
}

ScreenedPoissonSolver::~ScreenedPoissonSolver() = default;

std::vector<float> ScreenedPoissonSolver::Solve(const std::vector<float>& b, PoissonSolveReport* report) {
  const PoissonGrid& grid = grid_;
  const int threads = threads_;
  const size_t n = static_cast<size_t>(grid.width) * grid.height;
  if (b.size() != n) throw std::invalid_argument("screened Poisson: b's size does not match the grid");
  std::vector<Level>& levels = levels_->levels;

  // Preconditioned conjugate gradients from d = 0.
  std::vector<float> d(n, 0.0f), r(b), p(n), ap(n);
  for (size_t i = 0; i < n; ++i) {
    if (!(levels[0].diag[i] > 0)) r[i] = 0.0f;
  }
  const double b_norm = std::sqrt(Dot(grid, r, r, threads));
  PoissonSolveReport local;
  if (b_norm == 0.0) {
    if (report) *report = local;
    return d;
  }
  Level& top = levels[0];
  top.b = r;
  VCycle(levels, 0, threads);
  p = top.x;
  double rz = Dot(grid, r, top.x, threads);
  double r_norm = b_norm;
  int it = 0;
  while (it < options_.max_iterations && r_norm > options_.relative_tolerance * b_norm) {
    Apply(top, p, &ap, threads);
    const double pap = Dot(grid, p, ap, threads);
    if (!(pap > 0)) break;
    const double alpha = rz / pap;
    ForRows(grid, threads, [&](int y) {
      const size_t end = grid.index(0, y) + grid.width;
      for (size_t i = grid.index(0, y); i < end; ++i) {
        d[i] += static_cast<float>(alpha * p[i]);
        r[i] -= static_cast<float>(alpha * ap[i]);
      }
    });
    ++it;
    r_norm = std::sqrt(Dot(grid, r, r, threads));
    top.b = r;
    VCycle(levels, 0, threads);
    const double rz_next = Dot(grid, r, top.x, threads);
    const double beta = rz_next / rz;
    rz = rz_next;
    ForRows(grid, threads, [&](int y) {
      const size_t end = grid.index(0, y) + grid.width;
      for (size_t i = grid.index(0, y); i < end; ++i) p[i] = static_cast<float>(top.x[i] + beta * p[i]);
    });
  }
  local.iterations = it;
  local.relative_residual = r_norm / b_norm;
  if (report) *report = local;
  return d;
}

}  // namespace casual3d::stitch

#include "reconstruct/stitch/screened_poisson.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "base/parallel_for.h"

namespace casual3d::stitch {
namespace {

// Damped Jacobi: the same sweeps before and after the coarse correction keep
// the V-cycle a symmetric preconditioner, as conjugate gradients need.
constexpr float kJacobiWeight = 0.7f;
constexpr int kSmoothingSweeps = 2;
constexpr int kCoarsestSweeps = 40;
// Coarsening stops at this many pixels (a grid one pixel high coarsens in
// blocks of 2x1).
constexpr size_t kCoarsestPixels = 2048;

// One level of the hierarchy: its grid (level 0 reads the caller's) and
// each pixel's diagonal.
struct Level {
  const PoissonGrid* grid = nullptr;
  PoissonGrid own;          // The coarser levels' grids.
  std::vector<float> diag;  // s_p plus the weights of p's edges; 0: not solved.
  std::vector<float> inv_diag;  // 1 / diag, 0 where diag is 0.
  std::vector<float> x, b, r;  // Scratch of the V-cycle.
};

// Calls body(y) for every row of g.
template <typename Body>
void ForRows(const PoissonGrid& g, int threads, Body&& body) {
  base::ParallelFor(0, g.height, threads, [&](int64_t y) { body(static_cast<int>(y)); }, 8);
}

void ComputeDiag(Level* level, int threads) {
  const PoissonGrid& g = *level->grid;
  level->diag.resize(g.screen.size());
  level->inv_diag.resize(g.screen.size());
  ForRows(g, threads, [&](int y) {
    for (int x = 0; x < g.width; ++x) {
      const size_t p = g.index(x, y);
      float d = g.screen[p];
      if (g.Right(x) >= 0) d += g.right[p];
      if (const int l = g.Left(x); l >= 0) d += g.right[g.index(l, y)];
      if (y + 1 < g.height) d += g.down[p];
      if (y > 0) d += g.down[g.index(x, y - 1)];
      level->diag[p] = d;
      level->inv_diag[p] = d > 0 ? 1.0f / d : 0.0f;
    }
  });
}

// Row y of A v on one level, into out[0 .. width). A pixel that takes no
// part (diag 0, hence no edge) gets 0. Loops without branches, so that they
// vectorise.
void ApplyRow(const Level& level, const std::vector<float>& v, int y, float* out) {
  const PoissonGrid& g = *level.grid;
  const int w = g.width;
  const size_t row = g.index(0, y);
  const float* vp = v.data() + row;
  const float* rt = g.right.data() + row;
  const float* dg = level.diag.data() + row;
  for (int x = 0; x < w; ++x) out[x] = dg[x] * vp[x];
  for (int x = 0; x + 1 < w; ++x) out[x] -= rt[x] * vp[x + 1];
  for (int x = 1; x < w; ++x) out[x] -= rt[x - 1] * vp[x - 1];
  if (g.wrap_x && w > 1) {
    out[w - 1] -= rt[w - 1] * vp[0];
    out[0] -= rt[w - 1] * vp[w - 1];
  }
  if (y + 1 < g.height) {
    const float* dn = g.down.data() + row;
    const float* vn = vp + w;
    for (int x = 0; x < w; ++x) out[x] -= dn[x] * vn[x];
  }
  if (y > 0) {
    const float* up = g.down.data() + row - w;
    const float* vu = vp - w;
    for (int x = 0; x < w; ++x) out[x] -= up[x] * vu[x];
  }
}

// out = A v on one level.
void Apply(const Level& level, const std::vector<float>& v, std::vector<float>* out, int threads) {
  const PoissonGrid& g = *level.grid;
  ForRows(g, threads, [&](int y) { ApplyRow(level, v, y, out->data() + g.index(0, y)); });
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
        if (f.Right(xr) >= 0 && (c.Right(X) >= 0) && f.Right(xr) / 2 == c.Right(X))
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

// `sweeps` damped Jacobi sweeps on level.x, each in one pass (into level.r,
// then swapped); `from_zero`: x is 0, and the first sweep is x = w b / diag.
void Jacobi(Level* level, int sweeps, bool from_zero, int threads) {
  const PoissonGrid& g = *level->grid;
  const int w = g.width;
  for (int s = 0; s < sweeps; ++s) {
    const bool zero = from_zero && s == 0;
    ForRows(g, threads, [&](int y) {
      const size_t row = g.index(0, y);
      float* next = level->r.data() + row;
      const float* b = level->b.data() + row;
      const float* inv = level->inv_diag.data() + row;
      if (zero) {
        for (int x = 0; x < w; ++x) next[x] = kJacobiWeight * inv[x] * b[x];
        return;
      }
      ApplyRow(*level, level->x, y, next);
      const float* x0 = level->x.data() + row;
      for (int x = 0; x < w; ++x) next[x] = x0[x] + kJacobiWeight * inv[x] * (b[x] - next[x]);
    });
    level->x.swap(level->r);
  }
}

// levels[k].x = the V-cycle applied to levels[k].b.
void VCycle(std::vector<Level>& levels, size_t k, int threads) {
  Level& L = levels[k];
  if (k + 1 == levels.size()) {
    Jacobi(&L, kCoarsestSweeps, /*from_zero=*/true, threads);
    return;
  }
  Jacobi(&L, kSmoothingSweeps, /*from_zero=*/true, threads);
  Level& C = levels[k + 1];
  const PoissonGrid& g = *L.grid;
  const PoissonGrid& c = *C.grid;
  // The residual b - A x (into L.r), summed over each block.
  ForRows(c, threads, [&](int Y) {
    float* cb = C.b.data() + c.index(0, Y);
    std::fill(cb, cb + c.width, 0.0f);
    for (int y = 2 * Y; y < std::min(2 * Y + 2, g.height); ++y) {
      const size_t row = g.index(0, y);
      float* res = L.r.data() + row;
      ApplyRow(L, L.x, y, res);
      const float* b = L.b.data() + row;
      for (int x = 0; x < g.width; ++x) cb[x / 2] += b[x] - res[x];
    }
  });
  VCycle(levels, k + 1, threads);
  ForRows(g, threads, [&](int y) {
    for (int x = 0; x < g.width; ++x) {
      const size_t p = g.index(x, y);
      if (L.diag[p] > 0) L.x[p] += C.x[c.index(x / 2, y / 2)];
    }
  });
  Jacobi(&L, kSmoothingSweeps, /*from_zero=*/false, threads);
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
    if (static_cast<size_t>(last.width) * last.height <= kCoarsestPixels) break;
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
  // The top level's V-cycle reads r as its b (swapped in and out, not copied).
  Level& top = levels[0];
  auto precondition = [&]() {
    top.b.swap(r);
    VCycle(levels, 0, threads);
    top.b.swap(r);
  };
  precondition();
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
    if (r_norm <= options_.relative_tolerance * b_norm) break;  // No V-cycle for a direction not taken.
    precondition();
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

#pragma once

// A screened Poisson problem on a panorama grid, solved by conjugate
// gradients preconditioned with an aggregation multigrid V-cycle.
//
// Unknowns d (one per pixel) minimise
//   sum over edges e = (p, q) of w_e (d_q - d_p - r_e)^2 + sum over p of s_p d_p^2,
// whose normal equations (diag(s) + L_w) d = b the caller states through b
// (AddEdgeTarget builds b from the edge targets r_e). Edges join 4-neighbours;
// columns wrap when wrap_x is set. A pixel with s_p = 0 and no edge of
// positive weight takes no part (its d stays 0); every other pixel needs
// s_p > 0 somewhere in its connected part for the system to be definite
// (the stitch gives every present pixel the same s > 0).

#include <cstddef>
#include <cstdint>
#include <memory>
#include <vector>

namespace casual3d::stitch {

struct PoissonGrid {
  int width = 0, height = 0;
  bool wrap_x = false;
  std::vector<float> right;   // Weight of edge (x, y)-(x + 1, y); the last column's wraps (or is 0).
  std::vector<float> down;    // Weight of edge (x, y)-(x, y + 1); the last row's are 0.
  std::vector<float> screen;  // s_p >= 0.

  PoissonGrid() = default;
  PoissonGrid(int w, int h, bool wrap)
      : width(w), height(h), wrap_x(wrap),
        right(static_cast<size_t>(w) * h, 0.0f),
        down(static_cast<size_t>(w) * h, 0.0f),
        screen(static_cast<size_t>(w) * h, 0.0f) {}
  size_t index(int x, int y) const { return static_cast<size_t>(y) * width + x; }
  // Column x's neighbour to the left or right, or -1 (none, or x itself).
  int Left(int x) const {
    const int l = x > 0 ? x - 1 : (wrap_x ? width - 1 : -1);
    return l == x ? -1 : l;
  }
  int Right(int x) const {
    const int r = x + 1 < width ? x + 1 : (wrap_x ? 0 : -1);
    return r == x ? -1 : r;
  }
};

// Adds the target r of edge (p, q), oriented from p to q, to the right-hand
// side b: b_p -= w r, b_q += w r.
inline void AddEdgeTarget(size_t p, size_t q, float w, float r, std::vector<float>* b) {
  (*b)[p] -= w * r;
  (*b)[q] += w * r;
}

struct PoissonSolveOptions {
  int max_iterations = 60;
  // Stop once the residual's norm is this fraction of b's.
  double relative_tolerance = 1e-3;
  int threads = 0;  // 0: every hardware thread.
};

struct PoissonSolveReport {
  int iterations = 0;
  double relative_residual = 0.0;
};

// Solves (diag(screen) + L_w) d = b for one grid and any number of b (the
// multigrid hierarchy is built once). The grid must outlive the solver.
class ScreenedPoissonSolver {
 public:
  // Throws std::invalid_argument when the grid's vectors do not match its
  // width and height.
  ScreenedPoissonSolver(const PoissonGrid& grid, const PoissonSolveOptions& options);
  ~ScreenedPoissonSolver();
  ScreenedPoissonSolver(const ScreenedPoissonSolver&) = delete;
  ScreenedPoissonSolver& operator=(const ScreenedPoissonSolver&) = delete;

  // d for b (one value per pixel; throws std::invalid_argument on another size).
  std::vector<float> Solve(const std::vector<float>& b, PoissonSolveReport* report = nullptr);

 private:
  struct Hierarchy;
  const PoissonGrid& grid_;
  PoissonSolveOptions options_;
  int threads_;
  std::unique_ptr<Hierarchy> levels_;
};

}  // namespace casual3d::stitch

#include "reconstruct/depth/near_envelope.h"

#include <algorithm>
#include <cmath>
#include <deque>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

#include <Eigen/IterativeLinearSolvers>
#include <Eigen/Sparse>

namespace casual3d::depth {
namespace {

// Colour variance (mean over channels) in a (2r+1)^2 window, via integral images.
std::vector<double> PatchVariance(const ImageF& color, int r) {
  const int w = color.width(), h = color.height();
  std::vector<double> s((w + 1) * static_cast<size_t>(h + 1), 0.0), s2(s.size(), 0.0);
  auto at = [w](int x, int y) { return static_cast<size_t>(y) * (w + 1) + x; };
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      double a = 0, a2 = 0;
      for (int c = 0; c < 3; ++c) {
        const double v = color.at(x, y, c);
        a += v;
        a2 += v * v;
      }
      s[at(x + 1, y + 1)] = a + s[at(x, y + 1)] + s[at(x + 1, y)] - s[at(x, y)];
      s2[at(x + 1, y + 1)] = a2 + s2[at(x, y + 1)] + s2[at(x + 1, y)] - s2[at(x, y)];
    }
  std::vector<double> var(static_cast<size_t>(w) * h);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const int x0 = std::max(0, x - r), x1 = std::min(w, x + r + 1);
      const int y0 = std::max(0, y - r), y1 = std::min(h, y + r + 1);
      const double n = 3.0 * (x1 - x0) * (y1 - y0);
      const double sum = s[at(x1, y1)] - s[at(x0, y1)] - s[at(x1, y0)] + s[at(x0, y0)];
      const double sum2 = s2[at(x1, y1)] - s2[at(x0, y1)] - s2[at(x1, y0)] + s2[at(x0, y0)];
      const double mean = sum / n;
      var[static_cast<size_t>(y) * w + x] = std::max(0.0, sum2 / n - mean * mean);
    }
  return var;
}

// 1D sliding-window minimum (monotonic deque), window [i - r, i + r] clipped.
void SlidingMin(const float* in, float* out, int n, std::ptrdiff_t step, int r) {
  std::deque<int> q;
  int next = 0;
  for (int i = 0; i < n; ++i) {
    const int hi = std::min(n - 1, i + r);
    for (; next <= hi; ++next) {
      while (!q.empty() && in[q.back() * step] >= in[next * step]) q.pop_back();
      q.push_back(next);
    }
    while (q.front() < i - r) q.pop_front();
    out[i * step] = in[q.front() * step];
  }
}

// One level of the propagation problem: colour (RGB interleaved), anchor
// weight w_i (0 = no anchor) and anchor inverse depth x'_i per pixel.
struct Level {
  int width = 0, height = 0;
  std::vector<float> color;
  std::vector<double> weight, target;
};

// Half-resolution version of `fine`: colour is box-averaged over 2x2 blocks;
// anchor weights are summed and anchor targets weight-averaged, so the
// coarse data term approximates the fine one over the same area (the
// smoothness sum of a 2D grid keeps its scale under coarsening).
Level Coarsen(const Level& fine) {
  Level c;
  c.width = (fine.width + 1) / 2;
  c.height = (fine.height + 1) / 2;
  const size_t nc = static_cast<size_t>(c.width) * c.height;
  c.color.assign(3 * nc, 0.0f);
  c.weight.assign(nc, 0.0);
  c.target.assign(nc, 0.0);
  for (int y = 0; y < c.height; ++y)
    for (int x = 0; x < c.width; ++x) {
      const size_t ci = static_cast<size_t>(y) * c.width + x;
      float rgb[3] = {0, 0, 0};
      int count = 0;
      double wsum = 0, tsum = 0;
      for (int v = 2 * y; v < std::min(fine.height, 2 * y + 2); ++v)
        for (int u = 2 * x; u < std::min(fine.width, 2 * x + 2); ++u) {
          const size_t fi = static_cast<size_t>(v) * fine.width + u;
          for (int k = 0; k < 3; ++k) rgb[k] += fine.color[3 * fi + k];
          ++count;
          wsum += fine.weight[fi];
          tsum += fine.weight[fi] * fine.target[fi];
        }
      for (int k = 0; k < 3; ++k) c.color[3 * ci + k] = rgb[k] / static_cast<float>(count);
      c.weight[ci] = wsum;
      if (wsum > 0) c.target[ci] = tsum / wsum;
    }
  return c;
}

// Bilinear upsampling of a coarse solution (pixel centres aligned as in
// Coarsen) to fine_width x fine_height.
Eigen::VectorXd Upsample(const Eigen::VectorXd& coarse, int cw, int ch, int fine_width, int fine_height) {
  Eigen::VectorXd out(static_cast<Eigen::Index>(fine_width) * fine_height);
  for (int y = 0; y < fine_height; ++y) {
    const double fy = std::clamp((y + 0.5) / 2.0 - 0.5, 0.0, ch - 1.0);
    const int y0 = std::min(static_cast<int>(fy), ch - 1), y1 = std::min(y0 + 1, ch - 1);
    const double ty = fy - y0;
    for (int x = 0; x < fine_width; ++x) {
      const double fx = std::clamp((x + 0.5) / 2.0 - 0.5, 0.0, cw - 1.0);
      const int x0 = std::min(static_cast<int>(fx), cw - 1), x1 = std::min(x0 + 1, cw - 1);
      const double tx = fx - x0;
      auto c = [&](int u, int v) { return coarse[static_cast<Eigen::Index>(v) * cw + u]; };
      out[static_cast<Eigen::Index>(y) * fine_width + x] =
          (1 - ty) * ((1 - tx) * c(x0, y0) + tx * c(x1, y0)) + ty * ((1 - tx) * c(x0, y1) + tx * c(x1, y1));
    }
  }
  return out;
}

// Runs conjugate gradient with a Jacobi (diagonal) preconditioner from x0.
// On these grid Laplacians plus a diagonal it needs more iterations than an
// incomplete Cholesky factor, but each costs a fraction of the two
// triangular solves, and the coarse-to-fine guess keeps the count low.
Eigen::VectorXd RunCg(const Eigen::SparseMatrix<double>& a, const Eigen::VectorXd& rhs, const Eigen::VectorXd& x0,
                      const EnvelopeOptions& options, PropagationStats* stats) {
  Eigen::ConjugateGradient<Eigen::SparseMatrix<double>, Eigen::Lower | Eigen::Upper,
                           Eigen::DiagonalPreconditioner<double>>
      cg;
  cg.setTolerance(options.cg_tolerance);
  cg.setMaxIterations(options.cg_max_iterations);
  cg.compute(a);
  if (cg.info() != Eigen::Success) throw std::runtime_error("propagation: preconditioner failed");
  Eigen::VectorXd x = cg.solveWithGuess(rhs, x0);
  if (stats) {
    stats->iterations = static_cast<int>(cg.iterations());
    stats->residual = cg.error();
  }
  return x;
}

// Solves the normal equations (W + L) x = W x' of one level (Eq. 5) by
// preconditioned conjugate gradient, starting from the upsampled solution of
// the next coarser level when `coarse_levels` > 0 and the level is large
// enough, else from the anchors where known and their mean elsewhere.
// Requires at least one anchor. Fills `stats` (iterations, residual) if set.
Eigen::VectorXd SolveLevel(const Level& lv, const EnvelopeOptions& options, int coarse_levels,
                           PropagationStats* stats) {
  const int w = lv.width, h = lv.height;
  const Eigen::Index n = static_cast<Eigen::Index>(w) * h;
  const double inv2s2 = 1.0 / (2.0 * options.sigma_env * options.sigma_env);
  std::vector<Eigen::Triplet<double>> triplets;
  triplets.reserve(static_cast<size_t>(n) * 5);
  Eigen::VectorXd diag = Eigen::VectorXd::Zero(n), rhs = Eigen::VectorXd::Zero(n);
  double mean_anchor = 0.0;
  int anchors = 0;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const int i = y * w + x;
      if (lv.weight[i] > 0) {
        diag[i] += lv.weight[i];
        rhs[i] = lv.weight[i] * lv.target[i];
        mean_anchor += lv.target[i];
        ++anchors;
      }
      auto link = [&](int j) {
        double d2 = 0;
        for (int c = 0; c < 3; ++c) {
          const double e = static_cast<double>(lv.color[3 * i + c]) - lv.color[3 * j + c];
          d2 += e * e;
        }
        // A small floor keeps the graph connected across strong edges.
        const double wij = std::max(1e-6, std::exp(-d2 * inv2s2));
        diag[i] += wij;
        diag[j] += wij;
        triplets.emplace_back(i, j, -wij);
        triplets.emplace_back(j, i, -wij);
      };
      if (x + 1 < w) link(i + 1);
      if (y + 1 < h) link(i + w);
    }
  for (Eigen::Index i = 0; i < n; ++i) triplets.emplace_back(i, i, diag[i]);
  Eigen::SparseMatrix<double> a(n, n);
  a.setFromTriplets(triplets.begin(), triplets.end());
  triplets.clear();
  triplets.shrink_to_fit();

  Eigen::VectorXd x0;
  constexpr int kMinCoarseSide = 16;
  if (coarse_levels > 0 && (w + 1) / 2 >= kMinCoarseSide && (h + 1) / 2 >= kMinCoarseSide) {
    const Level coarse = Coarsen(lv);
    x0 = Upsample(SolveLevel(coarse, options, coarse_levels - 1, nullptr), coarse.width, coarse.height, w, h);
  } else {
    x0 = Eigen::VectorXd::Constant(n, mean_anchor / std::max(1, anchors));
    for (Eigen::Index i = 0; i < n; ++i)
      if (lv.weight[i] > 0) x0[i] = lv.target[i];
  }
  return RunCg(a, rhs, x0, options, stats);
}

}  // namespace

ImageF PropagateAnchors(const ImageF& anchors_depth, const ImageF& color,
                        const EnvelopeOptions& options, PropagationStats* stats) {
  const Status st = options.Check();
  if (!st.ok()) throw std::invalid_argument(st.message());
  const int w = anchors_depth.width(), h = anchors_depth.height();
  if (color.width() != w || color.height() != h || color.channels() != 3)
    throw std::invalid_argument("propagation: colour image size does not match the anchors");
  const size_t n = static_cast<size_t>(w) * h;
  const std::vector<double> var = PatchVariance(color, options.variance_radius);

  Level fine;
  fine.width = w;
  fine.height = h;
  fine.color.assign(color.data(), color.data() + 3 * n);
  fine.weight.assign(n, 0.0);
  fine.target.assign(n, 0.0);
  int anchors = 0;
  double lo = std::numeric_limits<double>::infinity(), hi = 0;
  for (size_t i = 0; i < n; ++i) {
    const float d = anchors_depth.data()[i];
    if (d > 0) {
      fine.weight[i] = options.unary_scale * var[i] + options.unary_floor;
      fine.target[i] = 1.0 / d;
      lo = std::min(lo, fine.target[i]);
      hi = std::max(hi, fine.target[i]);
      ++anchors;
    }
  }
  if (stats) *stats = PropagationStats{anchors, 0, 0.0};
  if (anchors == 0) return ImageF();
  const Eigen::VectorXd x = SolveLevel(fine, options, options.coarse_levels, stats);
  // Inverse depth is a convex combination of anchor inverse depths; clamp for
  // safety against an unconverged solve.
  ImageF out(w, h, 1);
  for (size_t i = 0; i < n; ++i)
    out.data()[i] = static_cast<float>(1.0 / std::min(hi, std::max(lo, x[static_cast<Eigen::Index>(i)])));
  return out;
}

ImageF MinFilter(const ImageF& image, int diameter) {
  const int w = image.width(), h = image.height(), r = std::max(0, diameter / 2);
  if (r == 0) return image;
  ImageF tmp(w, h, 1), out(w, h, 1);
  for (int y = 0; y < h; ++y) SlidingMin(image.row(y), tmp.row(y), w, 1, r);
  for (int x = 0; x < w; ++x) SlidingMin(tmp.data() + x, out.data() + x, h, w, r);
  return out;
}

ImageF FinalizeEnvelope(const ImageF& propagated, const EnvelopeOptions& options) {
  const Status st = options.Check();
  if (!st.ok()) throw std::invalid_argument(st.message());
  ImageF scaled = propagated;
  for (float& v : scaled.vector()) v *= static_cast<float>(options.scale);
  const double diag = std::hypot(propagated.width(), propagated.height());
  int diameter = static_cast<int>(std::lround(options.min_filter_fraction * diag));
  if (diameter % 2 == 0) diameter += 1;
  return MinFilter(scaled, diameter);
}

}  // namespace casual3d::depth

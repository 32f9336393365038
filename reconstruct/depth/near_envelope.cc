#include "reconstruct/depth/near_envelope.h"

#include <algorithm>
#include <cmath>
#include <deque>
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

}  // namespace

Status EnvelopeOptions::Check() const {
  if (!(sigma_env > 0 && sigma_env <= 10)) return InvalidArgument("sigma_env outside (0, 10]");
  if (!(unary_scale > 0 && unary_scale <= 1e6)) return InvalidArgument("unary_scale outside (0, 1e6]");
  if (!(unary_floor >= 0 && unary_floor <= 1e3)) return InvalidArgument("unary_floor outside [0, 1e3]");
  if (variance_radius < 1 || variance_radius > 256)
    return InvalidArgument("variance_radius " + std::to_string(variance_radius) + " outside [1, 256]");
  if (!(scale > 0 && scale <= 1)) return InvalidArgument("envelope scale outside (0, 1]");
  if (!(min_filter_fraction >= 0 && min_filter_fraction <= 0.5))
    return InvalidArgument("min_filter_fraction outside [0, 0.5]");
  if (!(cg_tolerance > 0 && cg_tolerance <= 0.1)) return InvalidArgument("cg_tolerance outside (0, 0.1]");
  if (cg_max_iterations < 1 || cg_max_iterations > 100000)
    return InvalidArgument("cg_max_iterations outside [1, 100000]");
  return Status::Ok();
}

ImageF PropagateAnchors(const ImageF& anchors_depth, const ImageF& color,
                        const EnvelopeOptions& options, PropagationStats* stats) {
  const Status st = options.Check();
  if (!st.ok()) throw std::invalid_argument(st.message());
  const int w = anchors_depth.width(), h = anchors_depth.height();
  if (color.width() != w || color.height() != h || color.channels() != 3)
    throw std::invalid_argument("propagation: colour image size does not match the anchors");
  const int n = w * h;
  const std::vector<double> var = PatchVariance(color, options.variance_radius);
  const double inv2s2 = 1.0 / (2.0 * options.sigma_env * options.sigma_env);

  std::vector<Eigen::Triplet<double>> triplets;
  triplets.reserve(static_cast<size_t>(n) * 5);
  Eigen::VectorXd diag = Eigen::VectorXd::Zero(n), rhs = Eigen::VectorXd::Zero(n);
  int anchors = 0;
  double mean_anchor = 0.0;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const int i = y * w + x;
      const float d = anchors_depth.at(x, y);
      if (d > 0) {
        const double wi = options.unary_scale * var[i] + options.unary_floor;
        diag[i] += wi;
        rhs[i] = wi / d;
        ++anchors;
        mean_anchor += 1.0 / d;
      }
      auto link = [&](int x2, int y2) {
        const int j = y2 * w + x2;
        double d2 = 0;
        for (int c = 0; c < 3; ++c) {
          const double e = color.at(x, y, c) - color.at(x2, y2, c);
          d2 += e * e;
        }
        // A small floor keeps the graph connected across strong edges.
        const double wij = std::max(1e-6, std::exp(-d2 * inv2s2));
        diag[i] += wij;
        diag[j] += wij;
        triplets.emplace_back(i, j, -wij);
        triplets.emplace_back(j, i, -wij);
      };
      if (x + 1 < w) link(x + 1, y);
      if (y + 1 < h) link(x, y + 1);
    }
  if (stats) stats->anchors = anchors;
  if (anchors == 0) return ImageF();
  mean_anchor /= anchors;
  for (int i = 0; i < n; ++i) triplets.emplace_back(i, i, diag[i]);
  Eigen::SparseMatrix<double> a(n, n);
  a.setFromTriplets(triplets.begin(), triplets.end());
  triplets.clear();
  triplets.shrink_to_fit();

  Eigen::ConjugateGradient<Eigen::SparseMatrix<double>, Eigen::Lower | Eigen::Upper,
                           Eigen::IncompleteCholesky<double>>
      cg;
  cg.setTolerance(options.cg_tolerance);
  cg.setMaxIterations(options.cg_max_iterations);
  cg.compute(a);
  if (cg.info() != Eigen::Success) throw std::runtime_error("propagation: preconditioner failed");
  // Start from the anchors where known and their mean elsewhere.
  Eigen::VectorXd x0 = Eigen::VectorXd::Constant(n, mean_anchor);
  for (int i = 0; i < n; ++i) {
    const float d = anchors_depth.data()[i];
    if (d > 0) x0[i] = 1.0 / d;
  }
  const Eigen::VectorXd x = cg.solveWithGuess(rhs, x0);
  if (stats) {
    stats->iterations = static_cast<int>(cg.iterations());
    stats->residual = cg.error();
  }
  // Inverse depth is a convex combination of anchor inverse depths; clamp for
  // safety against an unconverged solve.
  double lo = 1e300, hi = 0;
  for (int i = 0; i < n; ++i) {
    const float d = anchors_depth.data()[i];
    if (d > 0) {
      lo = std::min(lo, 1.0 / d);
      hi = std::max(hi, 1.0 / d);
    }
  }
  ImageF out(w, h, 1);
  for (int i = 0; i < n; ++i)
    out.data()[i] = static_cast<float>(1.0 / std::min(hi, std::max(lo, x[i])));
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

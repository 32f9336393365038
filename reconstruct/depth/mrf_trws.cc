#include "reconstruct/depth/mrf_trws.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace casual3d::depth {
namespace {

// out(l') = min_l h(l) + w * min(|l - l'|, T), normalised to min 0.
void DistanceTransform(const float* h, float* out, int num_labels, float w, int truncation) {
  float hmin = h[0];
  out[0] = h[0];
  for (int l = 1; l < num_labels; ++l) {
    out[l] = std::min(h[l], out[l - 1] + w);
    hmin = std::min(hmin, h[l]);
  }
  for (int l = num_labels - 2; l >= 0; --l) out[l] = std::min(out[l], out[l + 1] + w);
  const float cap = hmin + w * static_cast<float>(truncation);
  for (int l = 0; l < num_labels; ++l) out[l] = std::min(out[l], cap) - hmin;
}

inline float Pairwise(float w, int a, int b, int truncation) {
  return w * static_cast<float>(std::min(std::abs(a - b), truncation));
}

}  // namespace

double MrfEnergy(const GridMrf& mrf, const std::vector<uint16_t>& labels) {
  const int w = mrf.width, h = mrf.height, L = mrf.num_labels;
  double e = 0.0;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const size_t p = static_cast<size_t>(y) * w + x;
      e += mrf.unary[p * L + labels[p]];
      if (x + 1 < w) e += Pairwise(mrf.weight_right[p], labels[p], labels[p + 1], mrf.truncation);
      if (y + 1 < h) e += Pairwise(mrf.weight_down[p], labels[p], labels[p + w], mrf.truncation);
    }
  return e;
}

TrwsResult SolveTrws(const GridMrf& mrf, const TrwsOptions& options) {
  const int w = mrf.width, h = mrf.height, L = mrf.num_labels;
  const size_t n = static_cast<size_t>(w) * h;
  if (w <= 0 || h <= 0 || L < 1 || L > 65535 || mrf.unary.size() != n * L ||
      mrf.weight_right.size() != n || mrf.weight_down.size() != n || mrf.truncation < 1)
    throw std::invalid_argument("TRW-S: inconsistent MRF sizes");
  if (options.max_iterations < 1) throw std::invalid_argument("TRW-S: max_iterations < 1");

  // Incoming messages of every node, by the side they come from.
  std::vector<float> from_left(n * L, 0.0f), from_right(n * L, 0.0f), from_up(n * L, 0.0f),
      from_down(n * L, 0.0f);
  std::vector<float> belief(L), tmp(L);
  std::vector<uint16_t> labels(n, 0);
  TrwsResult result;
  result.energy = std::numeric_limits<double>::infinity();
  const int T = mrf.truncation;
  double prev_best = result.energy;
  int stale = 0;

  for (int iter = 0; iter < options.max_iterations; ++iter) {
    // Forward pass (raster order): messages to the right and down neighbours,
    // and the labelling conditioned on the already labelled left/up nodes.
    for (int y = 0; y < h; ++y) {
      for (int x = 0; x < w; ++x) {
        const size_t p = static_cast<size_t>(y) * w + x;
        const float* u = &mrf.unary[p * L];
        const float* ml = &from_left[p * L];
        const float* mr = &from_right[p * L];
        const float* mu = &from_up[p * L];
        const float* md = &from_down[p * L];
        for (int l = 0; l < L; ++l) belief[l] = u[l] + ml[l] + mr[l] + mu[l] + md[l];
        // Labelling (Kolmogorov 2006, Sec. 5).
        {
          int best = 0;
          float best_cost = std::numeric_limits<float>::infinity();
          const int ll = x > 0 ? labels[p - 1] : -1;
          const int lu = y > 0 ? labels[p - w] : -1;
          const float wl = x > 0 ? mrf.weight_right[p - 1] : 0.0f;
          const float wu = y > 0 ? mrf.weight_down[p - w] : 0.0f;
          for (int l = 0; l < L; ++l) {
            float c = u[l] + mr[l] + md[l];
            if (ll >= 0) c += Pairwise(wl, l, ll, T);
            if (lu >= 0) c += Pairwise(wu, l, lu, T);
            if (c < best_cost) {
              best_cost = c;
              best = l;
            }
          }
          labels[p] = static_cast<uint16_t>(best);
        }
        const int before = (x > 0) + (y > 0), after = (x + 1 < w) + (y + 1 < h);
        const float gamma = 1.0f / static_cast<float>(std::max(1, std::max(before, after)));
        if (x + 1 < w) {
          for (int l = 0; l < L; ++l) tmp[l] = gamma * belief[l] - mr[l];
          DistanceTransform(tmp.data(), &from_left[(p + 1) * L], L, mrf.weight_right[p], T);
        }
        if (y + 1 < h) {
          for (int l = 0; l < L; ++l) tmp[l] = gamma * belief[l] - md[l];
          DistanceTransform(tmp.data(), &from_up[(p + w) * L], L, mrf.weight_down[p], T);
        }
      }
    }
    const double e = MrfEnergy(mrf, labels);
    if (e < result.energy) {
      result.energy = e;
      result.labels = labels;
    }
    result.iterations = iter + 1;
    // Backward pass (reverse raster order): messages to the left and up neighbours.
    for (int y = h - 1; y >= 0; --y) {
      for (int x = w - 1; x >= 0; --x) {
        const size_t p = static_cast<size_t>(y) * w + x;
        const float* u = &mrf.unary[p * L];
        const float* ml = &from_left[p * L];
        const float* mr = &from_right[p * L];
        const float* mu = &from_up[p * L];
        const float* md = &from_down[p * L];
        for (int l = 0; l < L; ++l) belief[l] = u[l] + ml[l] + mr[l] + mu[l] + md[l];
        const int before = (x > 0) + (y > 0), after = (x + 1 < w) + (y + 1 < h);
        const float gamma = 1.0f / static_cast<float>(std::max(1, std::max(before, after)));
        if (x > 0) {
          for (int l = 0; l < L; ++l) tmp[l] = gamma * belief[l] - ml[l];
          DistanceTransform(tmp.data(), &from_right[(p - 1) * L], L, mrf.weight_right[p - 1], T);
        }
        if (y > 0) {
          for (int l = 0; l < L; ++l) tmp[l] = gamma * belief[l] - mu[l];
          DistanceTransform(tmp.data(), &from_down[(p - w) * L], L, mrf.weight_down[p - w], T);
        }
      }
    }
    // Stop after `patience` passes without a significant improvement.
    if (prev_best - result.energy <= options.relative_tolerance * std::abs(result.energy)) {
      if (++stale >= options.patience) break;
    } else {
      stale = 0;
      prev_best = result.energy;
    }
  }
  return result;
}

}  // namespace casual3d::depth

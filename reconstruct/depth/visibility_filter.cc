#include "reconstruct/depth/visibility_filter.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include "reconstruct/depth/fast_exp.h"
#include "reconstruct/depth/plane_sweep.h"
#include "reconstruct/depth/sweep_kernels.h"

namespace casual3d::depth {

namespace {

constexpr float kInf = std::numeric_limits<float>::infinity();

bool HasDepth(float d) { return d > 0 && std::isfinite(d); }

// Another view seen from the reference. A reference pixel (x, y) at depth d
// lands at `to`'s homogeneous coordinates h = Homogeneous(c, x, y, 1 / d)
// in it, at depth d * h[2]; `from` maps the view's pixels into the
// reference the same way.
struct Other {
  PlaneHomography to, from;
  const ImageF* depth;
  const ImageF* gray;
};

// Where reference pixel (x, y) at depth d lands in a view through `hom`:
// pixel-index coordinates (u, v) (centres at integers) and its depth there.
// False behind the view.
bool Land(const PlaneHomography& hom, int x, int y, double d, float* u, float* v, double* depth) {
  const float inv_d = static_cast<float>(1.0 / d);
  const float qz = hom.Homogeneous(2, x, y, inv_d);
  if (!(qz > 0)) return false;
  *u = hom.Homogeneous(0, x, y, inv_d) / qz - 0.5f;
  *v = hom.Homogeneous(1, x, y, inv_d) / qz - 0.5f;
  *depth = d * qz;
  return true;
}

// True when pixel-index coordinates (u, v) fall on a pixel of a w x h image.
bool OnImage(float u, float v, int w, int h) { return u >= -0.5f && v >= -0.5f && u < w - 0.5f && v < h - 0.5f; }

// The nearest valid depth among the 3x3 pixels around (u, v); +inf if none.
float NearestAround(const float* data, int width, int height, int u, int v) {
  float nearest = kInf;
  for (int y = std::max(0, v - 1); y <= std::min(height - 1, v + 1); ++y)
    for (int x = std::max(0, u - 1); x <= std::min(width - 1, u + 1); ++x) {
      const float d = data[static_cast<size_t>(y) * width + x];
      if (HasDepth(d)) nearest = std::min(nearest, d);
    }
  return nearest;
}

// Bilinear sample of a 1-channel image at pixel-index coordinates (u, v);
// NaN outside the pixel centres' hull.
float SampleInside(const ImageF& image, float u, float v) {
  if (!(u >= 0 && v >= 0 && u <= image.width() - 1 && v <= image.height() - 1))
    return std::numeric_limits<float>::quiet_NaN();
  return sweep::Bilinear(image.data(), image.width(), image.height(), u, v);
}

// A reference pixel's comparison window: half-size r, every stride-th
// pixel, each with an adaptive support weight (Yoon and Kweon 2006: window
// pixels of another grey level than the centre's, which may lie on another
// surface, count less).
struct Window {
  struct Tap {
    int dx, dy;
    float gray, weight;
  };
  std::vector<Tap> taps;
  double total_weight = 0;

  void Reset(const ImageF& gray_ref, int x, int y, int r, int stride) {
    constexpr float kSigma = 0.06f;
    constexpr float kInv2s2 = 1.0f / (2 * kSigma * kSigma);
    const float centre = gray_ref.at(x, y);
    taps.clear();
    total_weight = 0;
    for (int dy = -r; dy <= r; dy += stride)
      for (int dx = -r; dx <= r; dx += stride) {
        const int xs = x + dx, ys = y + dy;
        if (xs < 0 || ys < 0 || xs >= gray_ref.width() || ys >= gray_ref.height()) continue;
        const float g = gray_ref.at(xs, ys), e = g - centre;
        taps.push_back({dx, dy, g, ExpNonPositive(-e * e * kInv2s2)});
        total_weight += taps.back().weight;
      }
  }
};

// How well each view agrees with reference pixel (x, y) at depth z: the
// weighted mean absolute grey difference between the pixel's window and its
// projections at that depth (a fronto-parallel patch: the plane of inverse
// depth 1 / z). NaN for a view that does not see the whole window.
void PhotoCosts(const Window& window, int x, int y, double z, const std::vector<Other>& list,
                std::vector<float>* costs) {
  const float inv_z = static_cast<float>(1.0 / z);
  costs->assign(list.size(), std::numeric_limits<float>::quiet_NaN());
  for (size_t k = 0; k < list.size(); ++k) {
    const Other& o = list[k];
    double sum = 0;
    bool inside = true;
    for (const Window::Tap& tap : window.taps) {
      float u, v;
      const float g = o.to.Project(static_cast<float>(x + tap.dx), static_cast<float>(y + tap.dy), inv_z, &u, &v)
                          ? SampleInside(*o.gray, u, v)
                          : std::numeric_limits<float>::quiet_NaN();
      if (std::isnan(g)) {
        inside = false;
        break;
      }
      sum += tap.weight * std::abs(g - tap.gray);
    }
    if (inside && window.total_weight > 0)
      (*costs)[k] = static_cast<float>(sum / window.total_weight);
  }
}

}  // namespace

std::vector<DepthReplacement> CheckFreeSpace(int ref,
                                             const std::vector<const PinholeCamera*>& cameras,
                                             const std::vector<const ImageF*>& depths,
                                             const std::vector<const ImageF*>& grays,
                                             const std::vector<int>& others, double inv_step,
                                             const VisibilityFilterOptions& options,
                                             VisibilityStats* stats) {
  const PinholeCamera& cr = *cameras[ref];
  const ImageF& dr = *depths[ref];
  const int width = dr.width(), height = dr.height();
  for (size_t k = 0; k < depths.size(); ++k)
    if (depths[k]->width() != cameras[k]->width || depths[k]->height() != cameras[k]->height ||
        grays[k]->width() != depths[k]->width() || grays[k]->height() != depths[k]->height())
      throw std::invalid_argument("CheckFreeSpace: view " + std::to_string(k) +
                                  ": camera, depth and grey image sizes differ");
  std::vector<Other> list;
  for (int j : others) {
    if (j == ref) continue;
    if (static_cast<int>(list.size()) >= options.max_views) break;
    list.push_back({ComputePlaneHomography(cr, *cameras[j]), ComputePlaneHomography(*cameras[j], cr), depths[j],
                    grays[j]});
  }
  const double band_floor = options.tolerance_labels * inv_step;
  // The band of agreement around depth z, in inverse depth.
  auto band = [&](double z) { return std::max(options.tolerance / z, band_floor); };

  // 1. Pixels that other views see through.
  std::vector<int> flagged;
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      const float d = dr.at(x, y);
      if (!HasDepth(d)) continue;
      int through = 0, agree = 0;
      const int num_views = static_cast<int>(list.size());
      for (int k = 0; k < num_views; ++k) {
        // Settled once the views left cannot outvote the agreeing ones.
        if (agree >= through + (num_views - k)) break;
        const Other& o = list[k];
        float fu, fv;
        double zq;
        const int ow = o.depth->width(), oh = o.depth->height();
        if (!Land(o.to, x, y, d, &fu, &fv, &zq) || !OnImage(fu, fv, ow, oh)) continue;
        const int u = static_cast<int>(fu + 0.5f), v = static_cast<int>(fv + 0.5f);
        const double inv_q = 1.0 / zq, b = band(zq);
        const float dj = o.depth->at(u, v);
        if (HasDepth(dj) && std::abs(inv_q - 1.0 / dj) <= b) {
          ++agree;
        } else {
          const float nearest = NearestAround(o.depth->data(), ow, oh, u, v);
          if (std::isfinite(nearest) && 1.0 / nearest < inv_q - b) ++through;
        }
      }
      if (through >= options.min_violations && through > agree) flagged.push_back(y * width + x);
    }
  }
  if (stats) stats->flagged += static_cast<long long>(flagged.size());
  if (flagged.empty()) return {};

  // 2. What each view renders along the flagged pixels' rays.
  const size_t np = static_cast<size_t>(width) * height;
  const size_t k_views = list.size();
  std::vector<float> candidates(flagged.size() * k_views, kInf);
  std::vector<float> zbuf(np);
  for (size_t k = 0; k < k_views; ++k) {
    const Other& o = list[k];
    std::fill(zbuf.begin(), zbuf.end(), kInf);
    for (int y = 0; y < o.depth->height(); ++y) {
      const float* drow = o.depth->data() + static_cast<size_t>(y) * o.depth->width();
      for (int x = 0; x < o.depth->width(); ++x) {
        const float dj = drow[x];
        float fu, fv;
        double zr;
        if (!HasDepth(dj) || !Land(o.from, x, y, dj, &fu, &fv, &zr) || !OnImage(fu, fv, width, height)) continue;
        float& z = zbuf[static_cast<size_t>(static_cast<int>(fv + 0.5f)) * width + static_cast<int>(fu + 0.5f)];
        z = std::min(z, static_cast<float>(zr));
      }
    }
    // A pixel no splat reached (the view magnifies there) takes the nearest
    // of its 3x3 neighbourhood's.
    for (size_t s = 0; s < flagged.size(); ++s) {
      const int idx = flagged[s];
      float z = zbuf[idx];
      if (!std::isfinite(z))
        z = NearestAround(zbuf.data(), width, height, idx % width, idx / width);
      candidates[s * k_views + k] = z;
    }
  }

  // 3. The lower median of the candidates beyond the flagged depth, where
  // the photos agree with it about as well.
  const ImageF& gray_ref = *grays[ref];
  std::vector<DepthReplacement> out;
  std::vector<float> beyond, diffs, cost_far, cost_now;
  Window window;
  beyond.reserve(k_views);
  for (size_t s = 0; s < flagged.size(); ++s) {
    const double d = dr.data()[flagged[s]];
    const double limit = 1.0 / d - band(d);  // Inverse depths below this lie beyond.
    beyond.clear();
    for (size_t k = 0; k < k_views; ++k) {
      const float z = candidates[s * k_views + k];
      if (std::isfinite(z) && 1.0 / z < limit) beyond.push_back(z);
    }
    if (beyond.empty()) continue;
    const auto mid = beyond.begin() + (beyond.size() - 1) / 2;
    std::nth_element(beyond.begin(), mid, beyond.end());
    if (options.photo_gate) {
      // Per view, how much worse the farther depth explains the photo; the
      // move is refused when even the better half of the views (those that
      // may see past an occluder) find it worse by more than the margin.
      const int x = flagged[s] % width, y = flagged[s] / width;
      window.Reset(gray_ref, x, y, options.photo_radius, options.photo_stride);
      PhotoCosts(window, x, y, *mid, list, &cost_far);
      PhotoCosts(window, x, y, d, list, &cost_now);
      diffs.clear();
      for (size_t k = 0; k < k_views; ++k)
        if (!std::isnan(cost_far[k]) && !std::isnan(cost_now[k]))
          diffs.push_back(cost_far[k] - cost_now[k]);
      if (!diffs.empty()) {
        const size_t half = (diffs.size() + 1) / 2;
        std::partial_sort(diffs.begin(), diffs.begin() + half, diffs.end());
        double worse = 0;
        for (size_t k = 0; k < half; ++k) worse += diffs[k];
        if (worse / half > options.photo_margin) continue;
      }
    }
    out.push_back({flagged[s], *mid});
  }
  if (stats) stats->replaced += static_cast<long long>(out.size());
  return out;
}

}  // namespace casual3d::depth

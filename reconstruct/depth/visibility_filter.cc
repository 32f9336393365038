#include "reconstruct/depth/visibility_filter.h"

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include "reconstruct/depth/fast_exp.h"
#include "reconstruct/depth/sweep_kernels.h"

namespace casual3d::depth {

namespace {

constexpr float kInf = std::numeric_limits<float>::infinity();

bool HasDepth(float d) { return d > 0 && std::isfinite(d); }

// Another view seen from the reference: the rigid motion from the reference
// camera's frame to its frame.
struct Other {
  Eigen::Matrix3d r;
  Eigen::Vector3d t;
  // The same motion followed by the view's intrinsics: a point p of the
  // reference frame lands at pixel (h.x / h.z, h.y / h.z) for h = kr * p + kt,
  // with h.z its depth in the view.
  Eigen::Matrix3d kr;
  Eigen::Vector3d kt;
  const PinholeCamera* camera;
  const ImageF* depth;
  const ImageF* gray;
};

// The ray of pixel x = 0 of row y in the camera frame (unit Z); the next
// pixel's adds (1 / fx, 0, 0).
Eigen::Vector3d RowRay(const PinholeCamera& c, int y) {
  return {(0.5 - c.cx) / c.fx, ((y + 0.5) - c.cy) / c.fy, 1.0};
}

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

// Bilinear sample of a 1-channel image at continuous coordinates (u, v)
// (COLMAP's: pixel centres at +0.5); NaN outside the pixel centres' hull.
float SampleInside(const ImageF& image, double u, double v) {
  const double x = u - 0.5, y = v - 0.5;
  if (!(x >= 0 && y >= 0 && x <= image.width() - 1 && y <= image.height() - 1))
    return std::numeric_limits<float>::quiet_NaN();
  return sweep::Bilinear(image.data(), image.width(), image.height(), static_cast<float>(x),
                         static_cast<float>(y));
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
// projections at that depth (a fronto-parallel patch). NaN for a view that
// does not see the whole window.
void PhotoCosts(const PinholeCamera& cr, const Window& window, int x, int y, double z,
                const std::vector<Other>& list, std::vector<float>* costs) {
  const Eigen::Vector3d ray(((x + 0.5) - cr.cx) / cr.fx, ((y + 0.5) - cr.cy) / cr.fy, 1.0);
  costs->assign(list.size(), std::numeric_limits<float>::quiet_NaN());
  for (size_t k = 0; k < list.size(); ++k) {
    const Other& o = list[k];
    // h(dx, dy) = z * kr * ray(x + dx, y + dy) + kt, affine in (dx, dy).
    const Eigen::Vector3d h0 = z * (o.kr * ray) + o.kt;
    const Eigen::Vector3d hx = (z / cr.fx) * o.kr.col(0), hy = (z / cr.fy) * o.kr.col(1);
    double sum = 0;
    bool inside = true;
    for (const Window::Tap& tap : window.taps) {
      const Eigen::Vector3d h = h0 + tap.dx * hx + tap.dy * hy;
      const float g = h.z() > 0 ? SampleInside(*o.gray, h.x() / h.z(), h.y() / h.z())
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

Status VisibilityFilterOptions::Check() const {
  if (!(tolerance > 0 && tolerance <= 1))
    return InvalidArgument("visibility tolerance outside (0, 1]");
  if (!(tolerance_labels >= 0 && tolerance_labels <= 100))
    return InvalidArgument("visibility tolerance_labels outside [0, 100]");
  if (min_violations < 1 || min_violations > 255)
    return InvalidArgument("visibility min_violations outside [1, 255]");
  if (max_views < 1 || max_views > 255)
    return InvalidArgument("visibility max_views outside [1, 255]");
  if (rounds < 1 || rounds > 10) return InvalidArgument("visibility rounds outside [1, 10]");
  if (!(photo_margin >= 0 && photo_margin <= 1))
    return InvalidArgument("visibility photo_margin outside [0, 1]");
  if (photo_radius < 0 || photo_radius > 10)
    return InvalidArgument("visibility photo_radius outside [0, 10]");
  if (photo_stride < 1 || photo_stride > 10)
    return InvalidArgument("visibility photo_stride outside [1, 10]");
  return Status::Ok();
}

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
    Other o;
    o.camera = cameras[j];
    o.depth = depths[j];
    o.gray = grays[j];
    o.r = o.camera->R * cr.R.transpose();
    o.t = o.camera->t - o.r * cr.t;
    o.kr = o.camera->K() * o.r;
    o.kt = o.camera->K() * o.t;
    list.push_back(o);
  }
  const double band_floor = options.tolerance_labels * inv_step;
  // The band of agreement around depth z, in inverse depth.
  auto band = [&](double z) { return std::max(options.tolerance / z, band_floor); };

  // 1. Pixels that other views see through.
  std::vector<int> flagged;
  // h = kr * (d * ray(x, y)) + kt, with kr * ray(x, y) = row[k] + x * step[k].
  std::vector<Eigen::Vector3d> row(list.size()), step(list.size());
  for (size_t k = 0; k < list.size(); ++k) step[k] = list[k].kr.col(0) / cr.fx;
  for (int y = 0; y < height; ++y) {
    for (size_t k = 0; k < list.size(); ++k) row[k] = list[k].kr * RowRay(cr, y);
    for (int x = 0; x < width; ++x) {
      const float d = dr.at(x, y);
      if (!HasDepth(d)) continue;
      int through = 0, agree = 0;
      const int num_views = static_cast<int>(list.size());
      for (int k = 0; k < num_views; ++k) {
        // Settled once the views left cannot outvote the agreeing ones.
        if (agree >= through + (num_views - k)) break;
        const Other& o = list[k];
        const Eigen::Vector3d h = d * (row[k] + x * step[k]) + o.kt;
        if (h.z() <= 0) continue;
        const double fu = h.x() / h.z(), fv = h.y() / h.z();
        const int ow = o.depth->width(), oh = o.depth->height();
        if (!(fu >= 0 && fv >= 0 && fu < ow && fv < oh)) continue;
        const int u = static_cast<int>(fu), v = static_cast<int>(fv);
        const double inv_q = 1.0 / h.z(), b = band(h.z());
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
    const PinholeCamera& co = *o.camera;
    // The other view's frame to the reference's pixels: h = kr * q + kt.
    const Eigen::Matrix3d kr = cr.K() * o.r.transpose();
    const Eigen::Vector3d kt = -(kr * o.t);
    const Eigen::Vector3d step = kr.col(0) / co.fx;
    std::fill(zbuf.begin(), zbuf.end(), kInf);
    for (int y = 0; y < o.depth->height(); ++y) {
      const Eigen::Vector3d row = kr * RowRay(co, y);
      const float* drow = o.depth->data() + static_cast<size_t>(y) * o.depth->width();
      for (int x = 0; x < o.depth->width(); ++x) {
        const float dj = drow[x];
        if (!HasDepth(dj)) continue;
        const Eigen::Vector3d h = dj * (row + x * step) + kt;
        if (h.z() <= 0) continue;
        const double fu = h.x() / h.z(), fv = h.y() / h.z();
        if (!(fu >= 0 && fv >= 0 && fu < width && fv < height)) continue;
        float& z = zbuf[static_cast<size_t>(static_cast<int>(fv)) * width + static_cast<int>(fu)];
        z = std::min(z, static_cast<float>(h.z()));
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
      PhotoCosts(cr, window, x, y, *mid, list, &cost_far);
      PhotoCosts(cr, window, x, y, d, list, &cost_now);
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

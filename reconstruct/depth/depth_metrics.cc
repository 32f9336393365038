#include "reconstruct/depth/depth_metrics.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <vector>

namespace casual3d::depth {
namespace {

// Index of the ground-truth pixel at the centre of estimate pixel (x, y) of a w x h map.
inline size_t GtIndex(const ImageF& gt, int x, int y, int w, int h) {
  const int gx = std::min(gt.width() - 1, static_cast<int>((x + 0.5) * gt.width() / w));
  const int gy = std::min(gt.height() - 1, static_cast<int>((y + 0.5) * gt.height() / h));
  return static_cast<size_t>(gy) * gt.width() + gx;
}
inline float SampleGt(const ImageF& gt, int x, int y, int w, int h) {
  return gt.data()[GtIndex(gt, x, y, w, h) * gt.channels()];
}

}  // namespace

DepthAccuracy EvaluateDepth(const ImageF& depth, const ImageF& gt, double sky_near_m, double inv_step,
                            const std::vector<uint8_t>* observers, int min_observers) {
  if (observers && observers->size() != static_cast<size_t>(gt.width()) * gt.height())
    throw std::invalid_argument("EvaluateDepth: observer counts not of the ground truth's size");
  DepthAccuracy a;
  std::vector<float> rel, rel_observed;
  long long within = 0, floaters = 0, sky_near = 0, half_label = 0, two_labels = 0;
  long long within_observed = 0, floaters_observed = 0;
  const int w = depth.width(), h = depth.height();
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const float g = SampleGt(gt, x, y, w, h);
      const float d = depth.at(x, y);
      if (!std::isfinite(g) || g <= 0) {
        ++a.sky_pixels;
        if (!(d >= sky_near_m)) ++sky_near;
        continue;
      }
      ++a.pixels;
      const float e = d > 0 ? std::abs(d - g) / g : 1.0f;
      rel.push_back(e);
      const bool close = e <= 0.03f, floater = !(d >= 0.85f * g);
      within += close;
      floaters += floater;
      if (inv_step > 0 && d > 0) {
        const double e_inv = std::abs(1.0 / d - 1.0 / g);
        half_label += e_inv <= 0.5 * inv_step;
        two_labels += e_inv <= 2.0 * inv_step;
      }
      if (observers) {
        const uint8_t c = (*observers)[GtIndex(gt, x, y, w, h)];
        if (c != kNoDepth && c >= min_observers) {
          rel_observed.push_back(e);
          within_observed += close;
          floaters_observed += floater;
        }
      }
    }
  if (a.pixels > 0) {
    std::nth_element(rel.begin(), rel.begin() + rel.size() / 2, rel.end());
    a.median_rel_error = rel[rel.size() / 2];
    a.within_3pct = static_cast<double>(within) / a.pixels;
    a.near_floaters = static_cast<double>(floaters) / a.pixels;
    a.within_half_label = static_cast<double>(half_label) / a.pixels;
    a.within_two_labels = static_cast<double>(two_labels) / a.pixels;
  }
  if (a.sky_pixels > 0) a.sky_near = static_cast<double>(sky_near) / a.sky_pixels;
  a.observed_pixels = static_cast<long long>(rel_observed.size());
  if (a.observed_pixels > 0) {
    std::nth_element(rel_observed.begin(), rel_observed.begin() + rel_observed.size() / 2, rel_observed.end());
    a.median_rel_error_observed = rel_observed[rel_observed.size() / 2];
    a.within_3pct_observed = static_cast<double>(within_observed) / a.observed_pixels;
    a.near_floaters_observed = static_cast<double>(floaters_observed) / a.observed_pixels;
  }
  return a;
}

AnchorQuality EvaluateAnchors(const ImageF& anchors, const ImageF& gt, double inv_tolerance) {
  AnchorQuality q;
  long long kept = 0, inliers = 0;
  const int w = anchors.width(), h = anchors.height();
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const float d = anchors.at(x, y);
      if (!(d > 0)) continue;
      ++kept;
      const float g = SampleGt(gt, x, y, w, h);
      const double inv_g = std::isfinite(g) && g > 0 ? 1.0 / g : 0.0;
      if (std::abs(1.0 / d - inv_g) <= inv_tolerance) ++inliers;
    }
  const long long total = static_cast<long long>(w) * h;
  if (total > 0) q.completeness = static_cast<double>(kept) / total;
  if (kept > 0) q.precision = static_cast<double>(inliers) / kept;
  return q;
}

EnvelopeQuality EvaluateEnvelope(const ImageF& envelope, const ImageF& gt) {
  EnvelopeQuality q;
  long long cut = 0, total = 0, finite = 0;
  double tight = 0.0;
  const int w = envelope.width(), h = envelope.height();
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const float n = envelope.at(x, y);
      const float g = SampleGt(gt, x, y, w, h);
      ++total;
      if (!(n > 0)) continue;
      if (std::isfinite(g) && g > 0) {
        ++finite;
        if (n > g) ++cut;
        tight += 1.0 / n - 1.0 / g;
      }
    }
  if (total > 0) q.error = static_cast<double>(cut) / total;
  if (finite > 0) q.tightness = tight / finite;
  return q;
}

std::vector<uint8_t> AgreeingViews(const PinholeCamera& ref_camera, const ImageF& ref_depth,
                                   const std::vector<const PinholeCamera*>& cameras,
                                   const std::vector<const ImageF*>& depths, double rel_tolerance) {
  const PinholeCamera& cr = ref_camera;
  struct Other {
    Eigen::Matrix3d r;
    Eigen::Vector3d t;
    const PinholeCamera* cam;
    const ImageF* depth;
  };
  std::vector<Other> list;
  for (size_t k = 0; k < cameras.size() && list.size() < kNoDepth - 1; ++k) {
    Other o;
    o.cam = cameras[k];
    o.r = o.cam->R * cr.R.transpose();
    o.t = o.cam->t - o.r * cr.t;
    o.depth = depths[k];
    list.push_back(o);
  }
  std::vector<uint8_t> counts(static_cast<size_t>(ref_depth.width()) * ref_depth.height(), kNoDepth);
  for (int y = 0; y < ref_depth.height(); ++y)
    for (int x = 0; x < ref_depth.width(); ++x) {
      const double d = ref_depth.at(x, y);
      if (!(d > 0 && std::isfinite(d))) continue;
      const Eigen::Vector3d p(((x + 0.5) - cr.cx) / cr.fx * d, ((y + 0.5) - cr.cy) / cr.fy * d, d);
      int agree = 0;
      for (const Other& o : list) {
        const Eigen::Vector3d q = o.r * p + o.t;
        if (q.z() <= 0) continue;
        const int u = static_cast<int>(std::floor(o.cam->fx * q.x() / q.z() + o.cam->cx));
        const int v = static_cast<int>(std::floor(o.cam->fy * q.y() / q.z() + o.cam->cy));
        if (u < 0 || v < 0 || u >= o.depth->width() || v >= o.depth->height()) continue;
        const double dj = o.depth->at(u, v);
        if (dj > 0 && std::isfinite(dj) && std::abs(q.z() - dj) <= rel_tolerance * dj) ++agree;
      }
      counts[static_cast<size_t>(y) * ref_depth.width() + x] = static_cast<uint8_t>(agree);
    }
  return counts;
}

double CrossViewConsistency(int ref, const std::vector<const DenseView*>& views,
                            const std::vector<const ImageF*>& depths, const std::vector<int>& others,
                            double rel_tolerance, int min_views, int max_views) {
  std::vector<const PinholeCamera*> cameras;
  std::vector<const ImageF*> other_depths;
  for (int j : others) {
    if (j == ref || static_cast<int>(cameras.size()) >= max_views) continue;
    cameras.push_back(&views[j]->camera);
    other_depths.push_back(depths[j]);
  }
  const std::vector<uint8_t> counts =
      AgreeingViews(views[ref]->camera, *depths[ref], cameras, other_depths, rel_tolerance);
  long long valid = 0, consistent = 0;
  for (uint8_t c : counts) {
    if (c == kNoDepth) continue;
    ++valid;
    consistent += c >= min_views;
  }
  return valid > 0 ? static_cast<double>(consistent) / valid : 0.0;
}

}  // namespace casual3d::depth

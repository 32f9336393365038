#include "reconstruct/depth/depth_metrics.h"

#include <algorithm>
#include <cmath>
#include <vector>

namespace casual3d::depth {
namespace {

// Ground truth at the centre of estimate pixel (x, y) of a w x h map.
inline float SampleGt(const ImageF& gt, int x, int y, int w, int h) {
  const int gx = std::min(gt.width() - 1, static_cast<int>((x + 0.5) * gt.width() / w));
  const int gy = std::min(gt.height() - 1, static_cast<int>((y + 0.5) * gt.height() / h));
  return gt.at(gx, gy);
}

}  // namespace

DepthAccuracy EvaluateDepth(const ImageF& depth, const ImageF& gt, double sky_near_m) {
  DepthAccuracy a;
  std::vector<float> rel;
  long long within = 0, floaters = 0, sky_near = 0;
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
      if (e <= 0.03f) ++within;
      if (!(d >= 0.85f * g)) ++floaters;
    }
  if (a.pixels > 0) {
    std::nth_element(rel.begin(), rel.begin() + rel.size() / 2, rel.end());
    a.median_rel_error = rel[rel.size() / 2];
    a.within_3pct = static_cast<double>(within) / a.pixels;
    a.near_floaters = static_cast<double>(floaters) / a.pixels;
  }
  if (a.sky_pixels > 0) a.sky_near = static_cast<double>(sky_near) / a.sky_pixels;
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

}  // namespace casual3d::depth

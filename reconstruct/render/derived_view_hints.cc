#include "reconstruct/render/derived_view_hints.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

namespace casual3d::render {
namespace {

constexpr double kDeg = 180.0 / kPi;
// A 4:3 view is what the field of view is fitted to.
constexpr double kFitAspect = 4.0 / 3.0;

}  // namespace

bool YawExtentOfColumns(const std::vector<uint8_t>& column_has, double* yaw_min_deg,
                        double* yaw_max_deg) {
  const int w = static_cast<int>(column_has.size());
  int content_columns = 0;
  for (uint8_t c : column_has) content_columns += c != 0;
  if (content_columns == 0) return false;
  if (content_columns == w) {
    *yaw_min_deg = -180.0;
    *yaw_max_deg = 180.0;
    return true;
  }
  int best_start = 0, best_length = 0;
  for (int x = 0; x < w; ++x) {
    // Runs starting right after a content column, scanned around the seam.
    if (column_has[x] || !column_has[(x + w - 1) % w]) continue;
    int length = 0;
    while (length < w && !column_has[(x + length) % w]) ++length;
    if (length > best_length) best_length = length, best_start = x;
  }
  const int first = (best_start + best_length) % w;  // First content column after the gap.
  const double extent = 360.0 * (w - best_length) / w;
  double middle = (double(first) / w - 0.5) * 360.0 + extent / 2;
  if (middle >= 180) middle -= 360;
  *yaw_min_deg = middle - extent / 2;
  *yaw_max_deg = middle + extent / 2;
  return true;
}

double FrontDepthQuantile(const TwoLayerPanorama& pano, double q, const Image8* mask) {
  const LayerData& front = pano.layer(kFront);
  const size_t n = front.present.size();
  const size_t step = std::max<size_t>(1, n / (1 << 20));
  const uint8_t* inside = mask != nullptr ? mask->data() : nullptr;
  std::vector<float> depths;
  for (size_t i = 0; i < n; i += step)
    if (front.present[i] && (inside == nullptr || inside[i]) && std::isfinite(front.depth_m[i]) &&
        front.depth_m[i] > 0)
      depths.push_back(front.depth_m[i]);
  if (depths.empty()) return 0.0;
  const size_t k = static_cast<size_t>(std::clamp(q, 0.0, 1.0) * (depths.size() - 1));
  std::nth_element(depths.begin(), depths.begin() + k, depths.end());
  return depths[k];
}

ViewHints DeriveViewHints(const TwoLayerPanorama& pano) {
  ViewHints hints;
  const int w = pano.width(), h = pano.height();
  const LayerData& front = pano.layer(kFront);
  std::vector<int> column_count(w, 0), row_count(h, 0);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) column_count[x] += front.present[pano.index(x, y)] != 0;
  const int column_min = std::max(1, h / 200);
  std::vector<uint8_t> column(w);
  int content_columns = 0;
  for (int x = 0; x < w; ++x) content_columns += column[x] = column_count[x] >= column_min;

  const double low_depth = FrontDepthQuantile(pano, 0.05);
  if (low_depth > 0) {
    hints.volume_radius = kDerivedVolumeFraction * low_depth;
  } else {
    double near_m = 0, far_m = 0;
    hints.volume_radius =
        pano.NodeDepthRange(&near_m, &far_m) && near_m > 0 ? kDerivedVolumeFraction * near_m : 0.1;
  }
  if (content_columns == 0) return hints;

  // Longitudes: the complement of the largest circular run of empty columns.
  double yaw_min = -180, yaw_max = 180;
  YawExtentOfColumns(column, &yaw_min, &yaw_max);
  if (content_columns < w) hints.yaw_deg = 0.5 * (yaw_min + yaw_max);
  hints.content_yaw_min_deg = yaw_min;
  hints.content_yaw_max_deg = yaw_max;

  // Latitudes: first and last rows with enough front nodes in content columns.
  const int row_min = std::max(1, content_columns / 200);
  int top = -1, bottom = -1;
  for (int y = 0; y < h; ++y) {
    int count = 0;
    for (int x = 0; x < w; ++x) count += column[x] && front.present[pano.index(x, y)];
    if (count >= row_min) {
      if (top < 0) top = y;
      bottom = y;
    }
  }
  if (top < 0) top = 0, bottom = h - 1;
  hints.content_pitch_max_deg = (0.5 - double(top) / h) * 180.0;
  hints.content_pitch_min_deg = (0.5 - double(bottom + 1) / h) * 180.0;
  hints.pitch_deg = 0.5 * (hints.content_pitch_min_deg + hints.content_pitch_max_deg);

  const double lat_extent = hints.content_pitch_max_deg - hints.content_pitch_min_deg;
  const double lon_half = std::min(89.9, 0.5 * (yaw_max - yaw_min)) / kDeg;
  const double fov_from_lon = 2.0 * std::atan(std::tan(lon_half) / kFitAspect) * kDeg;
  hints.fov_deg = std::clamp(std::min(lat_extent, fov_from_lon), 10.0, 120.0);
  return hints;
}

ViewHints ResolveViewHints(const TwoLayerPanorama& pano, const std::optional<ViewHints>& hints,
                           bool* derived) {
  const bool use_given = hints.has_value() && hints->Validate().ok();
  if (derived != nullptr) *derived = !use_given;
  return use_given ? *hints : DeriveViewHints(pano);
}

}  // namespace casual3d::render

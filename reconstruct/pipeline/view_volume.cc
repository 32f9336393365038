#include "reconstruct/pipeline/view_volume.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "format/equirect.h"
#include "reconstruct/pipeline/capture_shape.h"
#include "reconstruct/render/derived_view_hints.h"

namespace casual3d::pipeline {
namespace {

constexpr double kDeg = 180.0 / kPi;

// The angle t (degrees) moved into [lo, hi] modulo 360, or to the nearer end.
double IntoInterval(double t, double lo, double hi) {
  if (hi - lo >= 360.0) return t;
  double best = lo, best_distance = 1e30;
  for (double k : {-720.0, -360.0, 0.0, 360.0, 720.0}) {
    const double u = t + k;
    if (u >= lo && u <= hi) return u;
    for (double end : {lo, hi}) {
      if (std::abs(u - end) < best_distance) {
        best_distance = std::abs(u - end);
        best = end;
      }
    }
  }
  return best;
}

double WrapDeg(double t) {
  t = std::fmod(t + 180.0, 360.0);
  if (t < 0) t += 360.0;
  return t - 180.0;
}

// Vertical field of view (degrees) of a view `aspect` wide whose horizontal
// field of view is `horizontal_deg`.
double VerticalFromHorizontal(double horizontal_deg, double aspect) {
  const double h = std::min(horizontal_deg, 179.0) / 2.0 / kDeg;
  return 2.0 * std::atan(std::tan(h) / aspect) * kDeg;
}

}  // namespace

// Largest share of the content box (solid angle) left without content.
constexpr double kMaxEmptyFraction = 0.005;

bool ContentExtent(const Image8& fov_mask, ViewHints* hints) {
  const int W = fov_mask.width(), H = fov_mask.height();
  std::vector<uint8_t> column(W, 0);
  int top = H, bottom = -1;
  for (int y = 0; y < H; ++y) {
    const uint8_t* row = &fov_mask.at(0, y);
    bool any = false;
    for (int x = 0; x < W; ++x) {
      if (row[x]) {
        column[x] = 1;
        any = true;
      }
    }
    if (any) {
      top = std::min(top, y);
      bottom = y;
    }
  }
  if (!render::YawExtentOfColumns(column, &hints->content_yaw_min_deg, &hints->content_yaw_max_deg))
    return false;
  hints->content_pitch_max_deg = 90.0 - 180.0 * top / H;
  hints->content_pitch_min_deg = 90.0 - 180.0 * (bottom + 1) / H;
  FitContentBox(fov_mask, kMaxEmptyFraction, hints);
  return true;
}

void FitContentBox(const Image8& fov_mask, double max_empty_fraction, ViewHints* hints) {
  const double yaw_span = hints->content_yaw_max_deg - hints->content_yaw_min_deg;
  if (yaw_span >= 360.0) return;  // Content all around: no side to move.
  const int W = fov_mask.width(), H = fov_mask.height();
  // Cells of about 1/256 of the circle; each holds its solid angle (cos of
  // the latitude) and the part of it outside the mask.
  const int cell = std::max(1, W / 256);
  const int gw = (W + cell - 1) / cell, gh = (H + cell - 1) / cell;
  std::vector<double> full(size_t(gw) * gh, 0.0), empty(full.size(), 0.0);
  for (int y = 0; y < H; ++y) {
    const double weight = std::cos((0.5 - (y + 0.5) / H) * kPi);
    const uint8_t* row = &fov_mask.at(0, y);
    for (int x = 0; x < W; ++x) {
      const size_t c = size_t(y / cell) * gw + x / cell;
      full[c] += weight;
      if (!row[x]) empty[c] += weight;
    }
  }
  // Summed-area tables over two copies side by side, so that a box across
  // the seam is one rectangle.
  const int tw = 2 * gw + 1;
  std::vector<double> sum_full(size_t(tw) * (gh + 1), 0.0), sum_empty(sum_full.size(), 0.0);
  for (int y = 0; y < gh; ++y)
    for (int x = 0; x < 2 * gw; ++x) {
      const size_t c = size_t(y) * gw + x % gw;
      const size_t t = size_t(y + 1) * tw + x + 1;
      sum_full[t] = full[c] + sum_full[t - 1] + sum_full[t - tw] - sum_full[t - tw - 1];
      sum_empty[t] = empty[c] + sum_empty[t - 1] + sum_empty[t - tw] - sum_empty[t - tw - 1];
    }
  const auto box = [&](const std::vector<double>& t, int x0, int x1, int y0, int y1) {
    // Columns x0..x1 (x0 in [0, gw), x1 < x0 + gw), rows y0..y1, inclusive.
    return t[size_t(y1 + 1) * tw + x1 + 1] - t[size_t(y0) * tw + x1 + 1] -
           t[size_t(y1 + 1) * tw + x0] + t[size_t(y0) * tw + x0];
  };
  // Cell columns of the extent, unwrapped (content across the seam starts
  // below 0), then moved into [0, gw) by `shift` whole turns.
  const int u0 = static_cast<int>(std::floor((hints->content_yaw_min_deg / 360.0 + 0.5) * gw));
  const int u1 = static_cast<int>(std::ceil((hints->content_yaw_max_deg / 360.0 + 0.5) * gw)) - 1;
  const int shift = u0 >= 0 ? -(u0 / gw) * gw : ((-u0 + gw - 1) / gw) * gw;
  const int a0 = u0 + shift, a1 = std::min(u1, u0 + gw - 1) + shift;
  const int b0 = std::clamp(static_cast<int>(std::floor((0.5 - hints->content_pitch_max_deg / 180.0) * gh)), 0, gh - 1);
  const int b1 = std::clamp(static_cast<int>(std::ceil((0.5 - hints->content_pitch_min_deg / 180.0) * gh)) - 1, b0, gh - 1);
  if (box(sum_empty, a0, a1, b0, b1) <= max_empty_fraction * box(sum_full, a0, a1, b0, b1)) return;
  // Every box inside the extent: the one holding the most content with at
  // most max_empty_fraction of it empty (ties: the earlier one).
  double best = -1.0;
  int bx0 = a0, bx1 = a1, by0 = b0, by1 = b1;
  for (int y0 = b0; y0 <= b1; ++y0)
    for (int y1 = y0; y1 <= b1; ++y1)
      for (int x0 = a0; x0 <= a1; ++x0)
        for (int x1 = x0; x1 <= a1; ++x1) {
          const double f = box(sum_full, x0, x1, y0, y1), e = box(sum_empty, x0, x1, y0, y1);
          if (e > max_empty_fraction * f) continue;
          if (f - e > best) best = f - e, bx0 = x0, bx1 = x1, by0 = y0, by1 = y1;
        }
  if (best <= 0) return;  // Nothing fits: keep the extent.
  hints->content_yaw_min_deg = (double(bx0 - shift) / gw - 0.5) * 360.0;
  hints->content_yaw_max_deg = (double(bx1 + 1 - shift) / gw - 0.5) * 360.0;
  hints->content_pitch_max_deg = (0.5 - double(by0) / gh) * 180.0;
  hints->content_pitch_min_deg = (0.5 - double(by1 + 1) / gh) * 180.0;
}

ViewHints ComputeViewHints(const TwoLayerPanorama& pano, const Image8& fov_mask,
                           const std::vector<CoverageView>& views, const PanoramaFrame& frame,
                           bool metric, const ViewVolumeOptions& options) {
  if (const Status st = options.Check(); !st.ok())
    throw std::invalid_argument("view volume options: " + st.message());
  if (fov_mask.width() != pano.width() || fov_mask.height() != pano.height())
    throw std::invalid_argument("view volume: the field-of-view mask is not the panorama's size");
  ViewHints hints;
  hints.metric = metric;
  ContentExtent(fov_mask, &hints);

  // Frame rotation.
  Eigen::Matrix3d R;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) R(r, c) = frame.rotation[3 * r + c];

  // Mean optical axis, median short-side field of view, camera spread
  // (capture_shape.h, where the capture's advice measures it too).
  Eigen::Vector3d axis_sum = Eigen::Vector3d::Zero();
  std::vector<double> fovs;
  const double spread = CameraSpread(views, frame);
  for (const CoverageView& v : views) {
    const Eigen::Matrix3d Rwc = v.pose.R();  // World to camera.
    axis_sum += R * Rwc.row(2).transpose();
    const double short_fov = std::min(v.camera.FovXDeg(), v.camera.FovYDeg());
    if (std::isfinite(short_fov) && short_fov > 0) fovs.push_back(short_fov);
  }
  double yaw = 0.5 * (hints.content_yaw_min_deg + hints.content_yaw_max_deg);
  double pitch = 0.5 * (hints.content_pitch_min_deg + hints.content_pitch_max_deg);
  if (axis_sum.norm() > 1e-9) {
    double lon, lat;
    DirectionToLonLat({axis_sum.x(), axis_sum.y(), axis_sum.z()}, &lon, &lat);
    yaw = lon * kDeg;
    pitch = lat * kDeg;
  }
  double fov = 60.0;
  if (!fovs.empty()) {
    std::nth_element(fovs.begin(), fovs.begin() + fovs.size() / 2, fovs.end());
    fov = fovs[fovs.size() / 2];
  }
  // Narrow the opening view to the content: vertically within its
  // latitudes, horizontally (at the frame's aspect) within its longitudes.
  const double yaw_span = hints.content_yaw_max_deg - hints.content_yaw_min_deg;
  const double pitch_span = hints.content_pitch_max_deg - hints.content_pitch_min_deg;
  fov = std::min(fov, 0.95 * pitch_span);
  if (yaw_span < 360.0) fov = std::min(fov, VerticalFromHorizontal(0.95 * yaw_span, options.frame_aspect));
  fov = std::clamp(fov, 10.0, 120.0);
  // Keep the view's edges inside the content where it is wide enough.
  const double half_v = 0.5 * fov;
  const double half_h = 0.5 * 2.0 * std::atan(std::tan(half_v / kDeg) * options.frame_aspect) * kDeg;
  if (pitch_span > fov)
    pitch = std::clamp(pitch, hints.content_pitch_min_deg + half_v, hints.content_pitch_max_deg - half_v);
  else
    pitch = 0.5 * (hints.content_pitch_min_deg + hints.content_pitch_max_deg);
  if (yaw_span < 360.0) {
    if (yaw_span > 2.0 * half_h)
      yaw = IntoInterval(yaw, hints.content_yaw_min_deg + half_h, hints.content_yaw_max_deg - half_h);
    else
      yaw = 0.5 * (hints.content_yaw_min_deg + hints.content_yaw_max_deg);
  }
  hints.yaw_deg = WrapDeg(yaw);
  hints.pitch_deg = std::clamp(pitch, -90.0, 90.0);
  hints.fov_deg = fov;

  // Near depth: a low percentile of the front depths inside the field of
  // view (of all front depths if none is inside; 1 without any).
  double near = render::FrontDepthQuantile(pano, options.near_percentile, &fov_mask);
  if (!(near > 0)) near = render::FrontDepthQuantile(pano, options.near_percentile);
  if (!(near > 0)) near = 1.0;
  hints.volume_radius = std::clamp(spread, options.min_radius_over_near * near,
                                   options.max_radius_over_near * near);
  return hints;
}

}  // namespace casual3d::pipeline

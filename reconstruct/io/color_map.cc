#include "reconstruct/io/color_map.h"

#include <algorithm>
#include <cmath>

namespace casual3d::io {
namespace {

// Piecewise-linear interpolation between N evenly spaced colour stops.
template <int N>
void Interpolate(const double (&stops)[N][3], double t, uint8_t rgb[3]) {
  const double s = (std::isfinite(t) ? std::clamp(t, 0.0, 1.0) : 0.0) * (N - 1);
  const int k = std::min(N - 2, static_cast<int>(s));
  const double f = s - k;
  for (int c = 0; c < 3; ++c)
    rgb[c] = static_cast<uint8_t>(std::lround(stops[k][c] * (1 - f) + stops[k + 1][c] * f));
}

}  // namespace

void DepthRampColor(double t, uint8_t rgb[3]) {
  static const double kStops[5][3] = {
      {20, 20, 110}, {20, 120, 170}, {60, 190, 120}, {240, 210, 40}, {215, 40, 30}};
  Interpolate(kStops, t, rgb);
}

void HeatColor(double t, uint8_t rgb[3]) {
  static const double kStops[5][3] = {
      {10, 10, 40}, {90, 30, 120}, {200, 60, 80}, {250, 160, 40}, {255, 250, 200}};
  Interpolate(kStops, t, rgb);
}

Image8 ColorizeDepth(const ImageF& depth_m, double near_m, double far_m) {
  const int w = depth_m.width(), h = depth_m.height();
  Image8 rgb(w, h, 3, 0);
  const double inv_near = 1.0 / near_m, inv_far = 1.0 / far_m;
  const double span = inv_near - inv_far;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const float d = depth_m.at(x, y);
      if (!(d > 0) || !std::isfinite(d)) continue;
      const double t = span != 0 ? (1.0 / d - inv_far) / span : 1.0;
      DepthRampColor(t, &rgb.at(x, y, 0));
    }
  return rgb;
}

}  // namespace casual3d::io

#pragma once

// Colour maps for previews, debug pictures and reports: one place, so that
// every picture the project writes reads the same way.

#include <cstdint>

#include "format/image.h"

namespace casual3d::io {

// Depth ramp for t in [0, 1] (values outside are clamped): dark blue (far,
// t = 0) through teal and yellow to red (near, t = 1). Callers pass
// normalised inverse depth so that near content gets the warm colours.
void DepthRampColor(double t, uint8_t rgb[3]);

// Error heat map for t in [0, 1] (clamped): dark blue (no error) through
// purple and orange to pale yellow (t >= 1); monotonic in lightness.
void HeatColor(double t, uint8_t rgb[3]);

// An RGB picture of a depth map (metres): inverse depth normalised between
// 1 / far_m (t = 0) and 1 / near_m (t = 1) through DepthRampColor. Pixels
// with a depth that is not finite and positive are black.
Image8 ColorizeDepth(const ImageF& depth_m, double near_m, double far_m);

}  // namespace casual3d::io

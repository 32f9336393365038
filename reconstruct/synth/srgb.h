#pragma once

// The sRGB transfer function (IEC 61966-2-1) between linear light and 8-bit
// sRGB code values.

#include <algorithm>
#include <cmath>
#include <cstdint>

namespace casual3d::synth {

// Linear [0, 1] (clamped) to an sRGB value in [0, 1].
inline double LinearToSrgb(double linear) {
  const double v = std::min(1.0, std::max(0.0, linear));
  return v <= 0.0031308 ? 12.92 * v : 1.055 * std::pow(v, 1.0 / 2.4) - 0.055;
}

// sRGB value in [0, 1] to linear.
inline double SrgbToLinear(double srgb) {
  return srgb <= 0.04045 ? srgb / 12.92 : std::pow((srgb + 0.055) / 1.055, 2.4);
}

// Linear [0, 1] to an 8-bit sRGB code value, rounded to nearest.
inline uint8_t LinearToSrgb8(double linear) {
  return static_cast<uint8_t>(std::lround(255.0 * LinearToSrgb(linear)));
}

}  // namespace casual3d::synth

#pragma once

// SIFT-like descriptors for the matcher's tests and benchmark: non-negative
// bytes scaled to length 512, as COLMAP stores them.

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include "reconstruct/sfm/descriptor_matcher.h"

namespace casual3d::sfm::testing {

// v (non-negative, not all zero) scaled to length 512 and rounded to bytes.
inline std::vector<uint8_t> SiftLikeBytes(const std::vector<double>& v) {
  double n = 0;
  for (double x : v) n += x * x;
  n = std::sqrt(n);
  std::vector<uint8_t> out(v.size());
  for (size_t k = 0; k < v.size(); ++k)
    out[k] = static_cast<uint8_t>(std::min(255.0, std::round(512.0 * v[k] / n)));
  return out;
}

// One random SIFT-like descriptor's values before scaling.
inline std::vector<double> RandomSiftValues(std::mt19937* rng) {
  std::exponential_distribution<double> e(1.0);
  std::vector<double> v(kSiftDimensions);
  for (double& x : v) x = e(*rng);
  return v;
}

// `rows` random SIFT-like descriptors.
inline SiftDescriptors RandomSiftDescriptors(int rows, std::mt19937* rng) {
  SiftDescriptors d;
  d.rows = rows;
  for (int i = 0; i < rows; ++i) {
    const std::vector<uint8_t> b = SiftLikeBytes(RandomSiftValues(rng));
    d.data.insert(d.data.end(), b.begin(), b.end());
  }
  return d;
}

}  // namespace casual3d::sfm::testing

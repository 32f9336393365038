#include "reconstruct/depth/sublabel_refine.h"

#include <gtest/gtest.h>

#include <cmath>

namespace casual3d::depth {
namespace {

CostVolume MakeVolume(int w, int h, int labels) {
  CostVolume v;
  v.width = w;
  v.height = h;
  v.num_labels = labels;
  v.inv_near = 1.0;
  v.inv_far = 0.1;
  v.cost.assign(static_cast<size_t>(w) * h * labels, 1.0f);
  v.photo_weight = ImageF(w, h, 1, 1.0f);
  return v;
}

// Quadratic costs with their minimum at `m` (fractional label).
void SetQuadratic(CostVolume* v, int x, int y, double m) {
  float* c = v->cost.data() + (static_cast<size_t>(y) * v->width + x) * v->num_labels;
  for (int k = 0; k < v->num_labels; ++k)
    c[k] = static_cast<float>(std::min(1.0, 0.05 * (k - m) * (k - m)));
}

TEST(RefineSubLabel, ParabolaRecoversFractionalMinima) {
  CostVolume v = MakeVolume(4, 1, 32);
  const double minima[] = {10.3, 10.7, 20.5, 5.0};
  std::vector<int> labels;
  for (int x = 0; x < 4; ++x) {
    SetQuadratic(&v, x, 0, minima[x]);
    labels.push_back(static_cast<int>(std::lround(minima[x])));
  }
  labels[1] = 10;  // The MRF chose a neighbour of the cost minimum.
  SubLabelOptions o;
  o.smooth_radius = 0;
  const std::vector<float> f = RefineSubLabel(v, labels, ImageF(4, 1, 3, 0.5f), o);
  for (int x = 0; x < 4; ++x) EXPECT_NEAR(f[x], minima[x], 1e-3) << x;
}

TEST(RefineSubLabel, SmoothsALabelStaircaseButKeepsDepthEdges) {
  // A ramp of true labels 10 + 0.1 x on the left half, quantised, and a
  // constant label 40 on the right half (a different colour); flat costs so
  // the parabola leaves integers.
  const int w = 40, h = 10;
  CostVolume v = MakeVolume(w, h, 64);
  ImageF color(w, h, 3);
  std::vector<int> labels(static_cast<size_t>(w) * h);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      for (int c = 0; c < 3; ++c) color.at(x, y, c) = x < 20 ? 0.3f : 0.7f;
      labels[static_cast<size_t>(y) * w + x] =
          x < 20 ? static_cast<int>(std::lround(10 + 0.1 * x)) : 40;
    }
  SubLabelOptions o;
  o.parabola = false;
  const std::vector<float> f = RefineSubLabel(v, labels, color, o);
  double err_quantised = 0, err_refined = 0;
  int n = 0;
  for (int y = 0; y < h; ++y)
    for (int x = 3; x < 17; ++x) {  // Away from the ramp's ends (one-sided windows).
      const double truth = 10 + 0.1 * x;
      err_quantised += std::abs(labels[static_cast<size_t>(y) * w + x] - truth);
      err_refined += std::abs(f[static_cast<size_t>(y) * w + x] - truth);
      ++n;
    }
  EXPECT_LT(err_refined / n, 0.5 * err_quantised / n);
  for (int y = 0; y < h; ++y) {
    EXPECT_FLOAT_EQ(f[static_cast<size_t>(y) * w + 25], 40.0f);
    EXPECT_LT(f[static_cast<size_t>(y) * w + 19], 13.0f);
  }
}

TEST(RefineSubLabel, RejectsMismatchedSizes) {
  CostVolume v = MakeVolume(4, 3, 8);
  EXPECT_THROW(RefineSubLabel(v, std::vector<int>(5, 0), ImageF(4, 3, 3), SubLabelOptions()),
               std::invalid_argument);
  SubLabelOptions bad;
  bad.max_label_gap = 0;
  EXPECT_THROW(RefineSubLabel(v, std::vector<int>(12, 0), ImageF(4, 3, 3), bad),
               std::invalid_argument);
}

}  // namespace
}  // namespace casual3d::depth

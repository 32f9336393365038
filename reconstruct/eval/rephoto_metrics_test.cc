#include "reconstruct/eval/rephoto_metrics.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <stdexcept>
#include <utility>

namespace casual3d::eval {
namespace {

// A textured RGB image with strong pixel-to-pixel variation.
Image8 Texture(int w, int h, uint32_t seed) {
  std::mt19937 rng(seed);
  Image8 image(w, h, 3);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      for (int c = 0; c < 3; ++c) image.at(x, y, c) = static_cast<uint8_t>(rng() % 256);
  return image;
}

TEST(RephotoMetricsTest, IdenticalImagesHaveZeroErrorAndPerfectScores) {
  const Image8 photo = Texture(64, 48, 1);
  const Image8 mask(64, 48, 1, 255);
  ImageF error_map;
  const RephotoMetrics m =
      ComputeRephotoMetrics(std::as_const(photo).view(), std::as_const(photo).view(),
                            std::as_const(mask).view(), {}, &error_map);
  EXPECT_EQ(m.covered_pixels, 64 * 48);
  EXPECT_DOUBLE_EQ(m.completeness, 1.0);
  EXPECT_DOUBLE_EQ(m.error, 0.0);
  EXPECT_DOUBLE_EQ(m.error_plain, 0.0);
  EXPECT_DOUBLE_EQ(m.psnr_db, 100.0);  // The cap.
  EXPECT_NEAR(m.ssim, 1.0, 1e-6);
  EXPECT_EQ(m.error_histogram[0], 64 * 48);
  EXPECT_FLOAT_EQ(error_map.at(10, 10), 0.0f);
}

TEST(RephotoMetricsTest, OnePixelShiftIsForgivenByTheShiftableWindow) {
  const int w = 64, h = 48;
  const Image8 photo = Texture(w, h, 2);
  // render(x, y) = photo(x - 1, y): the rendering is shifted one pixel right.
  Image8 render(w, h, 3);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      for (int c = 0; c < 3; ++c) render.at(x, y, c) = photo.at(std::max(0, x - 1), y, c);
  const Image8 mask(w, h, 1, 255);
  const RephotoMetrics m = ComputeRephotoMetrics(
      std::as_const(photo).view(), std::as_const(render).view(), std::as_const(mask).view());
  // photo(x, y) = render(x + 1, y) for x < w - 1; the last column has its match
  // outside the image.
  EXPECT_LT(m.error, 0.2 / w);
  // Random texture: the mean |a - b| of independent uniform bytes is 85/255.
  EXPECT_NEAR(m.error_plain, 1.0 / 3.0, 0.03);
  EXPECT_LT(m.psnr_db, 10.0);
  EXPECT_LT(m.ssim, 0.2);

  RephotoMetricOptions no_shift;
  no_shift.shift_radius_px = 0;
  const RephotoMetrics plain =
      ComputeRephotoMetrics(std::as_const(photo).view(), std::as_const(render).view(),
                            std::as_const(mask).view(), no_shift);
  EXPECT_DOUBLE_EQ(plain.error, m.error_plain);

  // A 3-pixel shift is beyond the +-2 pixel window.
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      for (int c = 0; c < 3; ++c) render.at(x, y, c) = photo.at(std::max(0, x - 3), y, c);
  const RephotoMetrics far = ComputeRephotoMetrics(
      std::as_const(photo).view(), std::as_const(render).view(), std::as_const(mask).view());
  EXPECT_GT(far.error, 0.05);
}

TEST(RephotoMetricsTest, CompletenessAndPsnrCountOnlyCoveredPixels) {
  const int w = 40, h = 20;
  Image8 photo(w, h, 3, 100), render(w, h, 3, 0), mask(w, h, 1, 0);
  // Left half covered with a constant offset of 10 code values.
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w / 2; ++x) {
      mask.at(x, y) = 255;
      for (int c = 0; c < 3; ++c) render.at(x, y, c) = 110;
    }
  ImageF error_map;
  Image8 filled;
  const RephotoMetrics m =
      ComputeRephotoMetrics(std::as_const(photo).view(), std::as_const(render).view(),
                            std::as_const(mask).view(), {}, &error_map, &filled);
  EXPECT_EQ(m.covered_pixels, w * h / 2);
  // The whole-frame figures see the right half filled from the left one
  // (110 everywhere), so the same 10-code offset over every pixel.
  ASSERT_EQ(filled.width(), w);
  EXPECT_EQ(filled.at(w - 1, h - 1, 0), 110);
  EXPECT_EQ(filled.at(w - 1, 0, 2), 110);
  EXPECT_NEAR(m.psnr_filled_db, 10 * std::log10(255.0 * 255.0 / 100.0), 1e-6);
  // SSIM of two constant images 100 and 110: luminance term only.
  const double c1 = (0.01 * 255) * (0.01 * 255);
  EXPECT_NEAR(m.ssim_filled, (2 * 100 * 110 + c1) / (100 * 100 + 110 * 110 + c1), 1e-4);
  EXPECT_DOUBLE_EQ(m.completeness, 0.5);
  EXPECT_NEAR(m.error, 30.0 / 765.0, 1e-12);
  EXPECT_NEAR(m.psnr_db, 10 * std::log10(255.0 * 255.0 / 100.0), 1e-9);  // 28.13 dB.
  EXPECT_FLOAT_EQ(error_map.at(w - 1, 0), -1.0f);
  EXPECT_NEAR(error_map.at(0, 0), 30.0 / 765.0, 1e-6);
}

TEST(RephotoMetricsTest, NothingCoveredGivesZeroCompleteness) {
  const Image8 photo = Texture(16, 16, 3);
  const Image8 mask(16, 16, 1, 0);
  const RephotoMetrics m = ComputeRephotoMetrics(
      std::as_const(photo).view(), std::as_const(photo).view(), std::as_const(mask).view());
  EXPECT_EQ(m.covered_pixels, 0);
  EXPECT_EQ(m.completeness, 0.0);
  EXPECT_EQ(m.psnr_db, 0.0);
}

TEST(RephotoMetricsTest, RejectsMismatchedInputsAndBadOptions) {
  const Image8 a(16, 16, 3), b(15, 16, 3), mask(16, 16, 1);
  EXPECT_THROW(ComputeRephotoMetrics(a.view(), b.view(), std::as_const(mask).view()),
               std::invalid_argument);
  RephotoMetricOptions bad;
  bad.shift_radius_px = 9;
  EXPECT_NE(bad.Check().message().find("shift_radius_px"), std::string::npos);
  EXPECT_THROW(ComputeRephotoMetrics(a.view(), a.view(), std::as_const(mask).view(), bad),
               std::invalid_argument);
}

TEST(RephotoMetricsTest, CurveEndsAtCompletenessAndMeanError) {
  std::vector<int64_t> histogram(10, 0);
  histogram[0] = 30;  // error ~0.05
  histogram[5] = 10;  // error ~0.55
  const auto curve = ErrorCompletenessCurve(histogram, 100);
  ASSERT_EQ(curve.size(), 2u);
  EXPECT_DOUBLE_EQ(curve[0].completeness, 0.3);
  EXPECT_DOUBLE_EQ(curve[0].error, 0.05);
  EXPECT_DOUBLE_EQ(curve[1].completeness, 0.4);
  EXPECT_NEAR(curve[1].error, (30 * 0.05 + 10 * 0.55) / 40, 1e-12);
}

}  // namespace
}  // namespace casual3d::eval

#include "reconstruct/eval/rephoto_metrics.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <opencv2/imgproc.hpp>
#include <stdexcept>

#include "reconstruct/io/cv_bridge.h"

namespace casual3d::eval {

namespace {

// Mean SSIM map of one channel (Wang et al. 2004) with a Gaussian window.
cv::Mat SsimMap(const cv::Mat& a8, const cv::Mat& b8) {
  constexpr double kC1 = (0.01 * 255) * (0.01 * 255);
  constexpr double kC2 = (0.03 * 255) * (0.03 * 255);
  cv::Mat a, b;
  a8.convertTo(a, CV_32F);
  b8.convertTo(b, CV_32F);
  const cv::Size window(11, 11);
  const double sigma = 1.5;
  cv::Mat mu_a, mu_b, aa, bb, ab;
  cv::GaussianBlur(a, mu_a, window, sigma, sigma, cv::BORDER_REFLECT);
  cv::GaussianBlur(b, mu_b, window, sigma, sigma, cv::BORDER_REFLECT);
  cv::GaussianBlur(a.mul(a), aa, window, sigma, sigma, cv::BORDER_REFLECT);
  cv::GaussianBlur(b.mul(b), bb, window, sigma, sigma, cv::BORDER_REFLECT);
  cv::GaussianBlur(a.mul(b), ab, window, sigma, sigma, cv::BORDER_REFLECT);
  const cv::Mat mu_aa = mu_a.mul(mu_a), mu_bb = mu_b.mul(mu_b), mu_ab = mu_a.mul(mu_b);
  const cv::Mat var_a = aa - mu_aa, var_b = bb - mu_bb, cov = ab - mu_ab;
  cv::Mat num = (2 * mu_ab + kC1).mul(2 * cov + kC2);
  cv::Mat den = (mu_aa + mu_bb + kC1).mul(var_a + var_b + kC2);
  cv::Mat ssim;
  cv::divide(num, den, ssim);
  return ssim;
}

}  // namespace

RephotoMetrics ComputeRephotoMetrics(ImageView<const uint8_t> photo,
                                     ImageView<const uint8_t> render, ImageView<const uint8_t> mask,
                                     const RephotoMetricOptions& options, ImageF* error_map,
                                     Image8* filled_out) {
  if (const Status st = options.Check(); !st.ok())
    throw std::invalid_argument("rephotography metrics: " + st.message());
  if (photo.channels() != 3 || render.channels() != 3 || mask.channels() != 1)
    throw std::invalid_argument(
        "rephotography metrics: photo and render must be RGB, mask 1 channel");
  const int w = photo.width(), h = photo.height();
  if (render.width() != w || render.height() != h || mask.width() != w || mask.height() != h)
    throw std::invalid_argument("rephotography metrics: photo " + std::to_string(w) + "x" +
                                std::to_string(h) + ", render " + std::to_string(render.width()) +
                                "x" + std::to_string(render.height()) + " and mask sizes differ");
  RephotoMetrics m;
  m.width = w;
  m.height = h;
  m.error_histogram.assign(options.histogram_bins, 0);
  if (error_map) *error_map = ImageF(w, h, 1, -1.0f);
  const int r = options.shift_radius_px;
  constexpr double kNorm = 1.0 / (3 * 255.0);
  double sum_error = 0, sum_plain = 0, sum_sq = 0;
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      if (!mask.at(x, y)) continue;
      ++m.covered_pixels;
      const uint8_t* p = &photo.at(x, y);
      const uint8_t* q0 = &render.at(x, y);
      int plain = 0;
      for (int c = 0; c < 3; ++c) {
        const int d = int(p[c]) - int(q0[c]);
        plain += std::abs(d);
        sum_sq += double(d) * d;
      }
      int best = plain;
      for (int dy = -r; dy <= r && best > 0; ++dy) {
        const int yy = y + dy;
        if (yy < 0 || yy >= h) continue;
        for (int dx = -r; dx <= r; ++dx) {
          const int xx = x + dx;
          if (xx < 0 || xx >= w || !mask.at(xx, yy)) continue;
          const uint8_t* q = &render.at(xx, yy);
          const int sad =
              std::abs(int(p[0]) - q[0]) + std::abs(int(p[1]) - q[1]) + std::abs(int(p[2]) - q[2]);
          best = std::min(best, sad);
        }
      }
      const double e = best * kNorm;
      sum_error += e;
      sum_plain += plain * kNorm;
      const int bin = std::min(options.histogram_bins - 1, int(e * options.histogram_bins));
      ++m.error_histogram[bin];
      if (error_map) error_map->at(x, y) = static_cast<float>(e);
    }
  }
  const int64_t total = int64_t{w} * h;
  m.completeness = total ? double(m.covered_pixels) / total : 0.0;
  if (m.covered_pixels == 0) return m;
  m.error = sum_error / m.covered_pixels;
  m.error_plain = sum_plain / m.covered_pixels;
  const double mse = sum_sq / (3.0 * m.covered_pixels);
  m.psnr_db = mse > 0 ? std::min(options.psnr_cap_db, 10.0 * std::log10(255.0 * 255.0 / mse))
                      : options.psnr_cap_db;

  const cv::Mat photo_mat = io::ToMat(photo), render_mat = io::ToMat(render);
  std::vector<cv::Mat> pc, rc;
  cv::split(photo_mat, pc);
  cv::split(render_mat, rc);
  cv::Mat ssim_sum = cv::Mat::zeros(h, w, CV_32F);
  for (int c = 0; c < 3; ++c) ssim_sum += SsimMap(pc[c], rc[c]);
  double sum_ssim = 0;
  for (int y = 0; y < h; ++y) {
    const float* row = ssim_sum.ptr<float>(y);
    for (int x = 0; x < w; ++x)
      if (mask.at(x, y)) sum_ssim += row[x] / 3.0;
  }
  m.ssim = sum_ssim / m.covered_pixels;

  // Whole frame with the holes inpainted.
  cv::Mat holes(h, w, CV_8U);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) holes.at<uint8_t>(y, x) = mask.at(x, y) ? 0 : 255;
  cv::Mat filled = render_mat.clone();
  if (m.covered_pixels < total) {
    // Each hole pixel takes the colour of the nearest covered pixel; labels
    // number the covered (zero) pixels 1, 2, ... in row-major order.
    cv::Mat distance, labels;
    cv::distanceTransform(holes, distance, labels, cv::DIST_L2, cv::DIST_MASK_5,
                          cv::DIST_LABEL_PIXEL);
    std::vector<cv::Vec3b> color_of(1);
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x)
        if (!holes.at<uint8_t>(y, x)) color_of.push_back(render_mat.at<cv::Vec3b>(y, x));
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x) {
        const int label = labels.at<int>(y, x);
        if (holes.at<uint8_t>(y, x) && label > 0 && label < static_cast<int>(color_of.size()))
          filled.at<cv::Vec3b>(y, x) = color_of[label];
      }
  }
  double sum_sq_filled = 0;
  for (int y = 0; y < h; ++y) {
    const uint8_t* a = photo_mat.ptr<uint8_t>(y);
    const uint8_t* b = filled.ptr<uint8_t>(y);
    for (int i = 0; i < 3 * w; ++i)
      sum_sq_filled += double(int(a[i]) - int(b[i])) * (int(a[i]) - int(b[i]));
  }
  const double mse_filled = sum_sq_filled / (3.0 * total);
  m.psnr_filled_db =
      mse_filled > 0 ? std::min(options.psnr_cap_db, 10.0 * std::log10(255.0 * 255.0 / mse_filled))
                     : options.psnr_cap_db;
  std::vector<cv::Mat> fc;
  cv::split(filled, fc);
  cv::Mat ssim_filled = cv::Mat::zeros(h, w, CV_32F);
  for (int c = 0; c < 3; ++c) ssim_filled += SsimMap(pc[c], fc[c]);
  m.ssim_filled = cv::mean(ssim_filled)[0] / 3.0;
  if (filled_out) {
    *filled_out = Image8(w, h, 3);
    filled.copyTo(io::ToMat(*filled_out));
  }
  return m;
}

std::vector<CurvePoint> ErrorCompletenessCurve(const std::vector<int64_t>& histogram,
                                               int64_t total_pixels) {
  std::vector<CurvePoint> curve;
  if (total_pixels <= 0 || histogram.empty()) return curve;
  const int bins = static_cast<int>(histogram.size());
  int64_t count = 0;
  double sum = 0;
  for (int b = 0; b < bins; ++b) {
    if (histogram[b] == 0) continue;
    count += histogram[b];
    sum += histogram[b] * ((b + 0.5) / bins);  // Bin centre.
    curve.push_back({double(count) / total_pixels, sum / count});
  }
  return curve;
}

}  // namespace casual3d::eval

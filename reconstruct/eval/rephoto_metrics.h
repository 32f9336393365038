#pragma once

// Image metrics of virtual rephotography (paper Sec. 6.3, after Waechter et
// al. 2017, "Virtual Rephotography"): a rendering of the 3D photo from the
// exact pose of a photo is compared with the photo itself.
//
//  * Completeness: the fraction of the photo's pixels that the rendering
//    covers.
//  * Shiftable-window error (the paper's measure): for every covered pixel p,
//      e(p) = min over |dx|, |dy| <= shift_radius_px of
//             sum_c |photo(p, c) - render(p + (dx, dy), c)| / (3 * 255),
//    where only covered rendered pixels are candidates. It forgives
//    misalignments of up to shift_radius_px pixels (calibration, resampling),
//    so that it measures missing or wrong content rather than sub-pixel shifts.
//    Range [0, 1]; the photo's error is the mean over covered pixels.
//  * Plain error: the same with no shift (dx = dy = 0), for comparison.
//  * PSNR over covered pixels: 10 log10(255^2 / MSE), MSE over the three
//    channels; capped at psnr_cap_db (identical images).
//  * SSIM (Wang et al. 2004; Gaussian window sigma 1.5 px, 11 x 11, constants
//    K1 = 0.01, K2 = 0.03 on 8-bit values), per channel, averaged over the
//    channels and over the covered pixels. Windows straddling the coverage
//    border see the render's background colour there.
//  * Whole-frame PSNR and SSIM: the same over every pixel of the photo, with
//    each uncovered pixel of the rendering filled with the colour of the
//    nearest covered one, for a comparison with methods that render every
//    pixel (LLFF, NeRF) that does not depend on a viewer's hole filling.

#include <cstdint>
#include <string>
#include <vector>

#include "format/status.h"
#include "format/image.h"
#include "reconstruct/util/options_fields.h"

namespace casual3d::eval {

struct RephotoMetricOptions {
  // Half-size of the shiftable window, pixels; [0, 8]. Sec. 6.3: +-2 pixels.
  int shift_radius_px = 2;
  // PSNR reported for a covered area without any difference, dB; (0, 1000].
  double psnr_cap_db = 100.0;
  // Bins of the per-pixel error histogram over [0, 1]; [8, 4096].
  int histogram_bins = 256;

  template <typename Self, typename Visitor>
  static void DescribeFields(Self& o, Visitor& v) {
    using R = util::Rule;
    v.Field("shift_radius_px", o.shift_radius_px, R::Closed(0, 8),
            "Half-size of the shiftable window, pixels");
    v.Field("psnr_cap_db", o.psnr_cap_db, R::OpenClosed(0, 1000),
            "PSNR reported for a covered area without any difference, dB");
    v.Field("histogram_bins", o.histogram_bins, R::Closed(8, 4096),
            "Bins of the per-pixel error histogram over [0, 1]");
  }
  Status Check() const { return util::CheckFields(*this); }  // Names the field and its range.
};

struct RephotoMetrics {
  int width = 0, height = 0;   // Compared image size, pixels.
  int64_t covered_pixels = 0;  // Pixels the rendering covers.
  double completeness = 0.0;   // covered_pixels / (width * height).
  double error = 0.0;          // Mean shiftable-window error over covered pixels, [0, 1].
  double error_plain = 0.0;    // Mean unshifted error over covered pixels, [0, 1].
  double psnr_db = 0.0;        // Over covered pixels; 0 when nothing is covered.
  double ssim = 0.0;           // Over covered pixels; 0 when nothing is covered.
  double psnr_filled_db = 0.0; // Whole frame, holes filled; 0 when nothing is covered.
  double ssim_filled = 0.0;    // Whole frame, holes filled; 0 when nothing is covered.
  // Histogram of the shiftable-window error of the covered pixels over [0, 1]
  // (histogram_bins bins): the error-versus-completeness curve (Fig. 13) is
  // built from it.
  std::vector<int64_t> error_histogram;
};

// Compares `photo` (RGB, 3 channels) with `render` (RGB, same size) where
// `mask` (1 channel, same size, non-zero = covered) says the rendering covers
// the pixel. If `error_map` is not null it receives the per-pixel
// shiftable-window error (width x height x 1; -1 where not covered); if
// `filled` is not null it receives the rendering with its holes filled. Throws
// std::invalid_argument for mismatched sizes or channel counts, or invalid
// options.
RephotoMetrics ComputeRephotoMetrics(ImageView<const uint8_t> photo,
                                     ImageView<const uint8_t> render, ImageView<const uint8_t> mask,
                                     const RephotoMetricOptions& options = {},
                                     ImageF* error_map = nullptr, Image8* filled = nullptr);

// The error-versus-completeness curve of one or more photos (paper Fig. 13):
// keeping only pixels whose error is at most a threshold t, completeness(t) is
// their fraction of all `total_pixels` and error(t) their mean error; one point
// per histogram bin with any pixel, t increasing. The last point is the
// photo's (completeness, error).
struct CurvePoint {
  double completeness = 0.0;
  double error = 0.0;
};
std::vector<CurvePoint> ErrorCompletenessCurve(const std::vector<int64_t>& histogram,
                                               int64_t total_pixels);

}  // namespace casual3d::eval

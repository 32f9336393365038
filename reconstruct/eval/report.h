#pragma once

// Reports of `casual3d evaluate`: one self-contained HTML file (inline CSS,
// inline SVG plots, PNG images as base64 data URIs; nothing is fetched from
// the network) and a JSON document with the same numbers for machines.
//
// The HTML report holds, for each 3D photo evaluated: a summary, the table of
// per-photo figures (error, plain error, completeness, PSNR, SSIM and, on
// synthetic captures, depth error against the ground truth), the error
// versus completeness plot (paper Fig. 13: one curve per 3D photo), per-photo
// thumbnails of photo, rendering and error heatmap, the timings per stage and,
// when measured, what a viewer sees (viewer_views_report.h);
// with several 3D photos (ablations) or reference results, a comparison table
// of their means and stage timings side by side.

#include <string>
#include <vector>

#include "format/status.h"
#include "reconstruct/eval/evaluate.h"
#include "reconstruct/util/options_fields.h"

namespace casual3d::eval {

// Published figures of another method on the same protocol, shown in the
// comparison table (for example LLFF on fern: 23.22 dB, 0.753).
struct ReferenceResult {
  std::string label;
  double psnr_db = 0.0;  // Whole-frame PSNR, dB.
  double ssim = 0.0;
};

struct ReportOptions {
  // Width of the thumbnails embedded per photo, pixels; [32, 2048].
  int thumbnail_width = 300;
  // Error mapped to the hottest heatmap colour, [0, 1] units of the metric;
  // (0, 1].
  double heatmap_max_error = 0.25;
  std::string title = "casual3d rephotography report";
  // Shown under the 3D photos' rows; each needs a label, a PSNR in
  // (0, 1000) dB and an SSIM in [-1, 1].
  std::vector<ReferenceResult> references;

  // `references`, a list, is not described (options_fields.h describes single
  // values); its entries are checked by one requirement.
  template <typename Self, typename Visitor>
  static void DescribeFields(Self& o, Visitor& v) {
    using R = util::Rule;
    v.Field("thumbnail_width", o.thumbnail_width, R::Closed(32, 2048),
            "Width of the thumbnails embedded per photo, pixels");
    v.Field("heatmap_max_error", o.heatmap_max_error, R::OpenClosed(0, 1),
            "Error mapped to the hottest heatmap colour, units of the metric");
    v.Field("title", o.title, R::Any(), "Title of the HTML report");
    const std::string invalid = InvalidReference(o.references);
    v.Require(invalid.empty(), "references", invalid);
  }
  Status Check() const { return util::CheckFields(*this); }  // Names the field and its range.

  // What is wrong with the first invalid reference ("'NeRF' needs a name, ..."),
  // or "" if all are valid.
  static std::string InvalidReference(const std::vector<ReferenceResult>& references);
};

// The HTML document for `capture` and the evaluations of one or more 3D photos.
// Throws std::invalid_argument for invalid options.
std::string RenderHtmlReport(const std::string& capture,
                             const std::vector<PhotoModelEvaluation>& evaluations,
                             const ReportOptions& options = {});

// The JSON document (pretty-printed): {"capture", "options", "photo3d": [{label,
// source, means, viewer_views? (viewer_views_report.h), stages, photos: [{name,
// index, held_out, error, error_plain, completeness, psnr_db, ssim,
// covered_pixels, width, height, depth?}]}]}.
std::string RenderJsonReport(const std::string& capture,
                             const std::vector<PhotoModelEvaluation>& evaluations,
                             const EvaluateOptions& options);

// The colour of the error heatmap for `error` (dark blue = 0 to yellow-white at
// `max_error`), RGB. Uncovered pixels (error < 0) are drawn mid grey.
void HeatmapColor(float error, double max_error, uint8_t rgb[3]);

// Base64 (RFC 4648, with padding) of `bytes`.
std::string Base64(const std::string& bytes);

// A PNG data URI of an RGB image scaled down to at most `width` pixels wide
// (area averaging); empty for an empty image.
std::string PngDataUri(const Image8& rgb, int width);

}  // namespace casual3d::eval

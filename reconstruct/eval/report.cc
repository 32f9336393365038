#include "reconstruct/eval/report.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <sstream>
#include <stdexcept>

#include "reconstruct/eval/viewer_views_report.h"
#include "reconstruct/io/color_map.h"
#include "reconstruct/io/cv_bridge.h"
#include "reconstruct/util/html.h"

namespace casual3d::eval {

std::string ReportOptions::InvalidReference(const std::vector<ReferenceResult>& references) {
  for (const ReferenceResult& r : references)
    if (r.label.empty() || !(r.psnr_db > 0 && r.psnr_db < 1000) || !(r.ssim >= -1 && r.ssim <= 1))
      return "'" + r.label + "' needs a name, a PSNR in (0, 1000) dB and an SSIM in [-1, 1]";
  return "";
}

std::string Base64(const std::string& bytes) {
  static const char kAlphabet[] =
      "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  out.reserve((bytes.size() + 2) / 3 * 4);
  size_t i = 0;
  for (; i + 2 < bytes.size(); i += 3) {
    const uint32_t v =
        (uint8_t(bytes[i]) << 16) | (uint8_t(bytes[i + 1]) << 8) | uint8_t(bytes[i + 2]);
    out += kAlphabet[v >> 18];
    out += kAlphabet[(v >> 12) & 63];
    out += kAlphabet[(v >> 6) & 63];
    out += kAlphabet[v & 63];
  }
  if (i < bytes.size()) {
    const bool two = i + 1 < bytes.size();
    const uint32_t v = (uint8_t(bytes[i]) << 16) | (two ? uint8_t(bytes[i + 1]) << 8 : 0);
    out += kAlphabet[v >> 18];
    out += kAlphabet[(v >> 12) & 63];
    out += two ? kAlphabet[(v >> 6) & 63] : '=';
    out += '=';
  }
  return out;
}

std::string PngDataUri(const Image8& rgb, int width) {
  if (rgb.empty()) return {};
  cv::Mat src = io::ToMat(rgb), scaled, bgr;
  const int w = std::min(width, rgb.width());
  const int h = std::max(1, static_cast<int>(std::lround(double(rgb.height()) * w / rgb.width())));
  cv::resize(src, scaled, cv::Size(w, h), 0, 0, cv::INTER_AREA);
  cv::cvtColor(scaled, bgr, cv::COLOR_RGB2BGR);
  std::vector<uint8_t> png;
  cv::imencode(".png", bgr, png);
  return "data:image/png;base64," + Base64(std::string(png.begin(), png.end()));
}

void HeatmapColor(float error, double max_error, uint8_t rgb[3]) {
  if (!(error >= 0)) {
    rgb[0] = rgb[1] = rgb[2] = 128;
    return;
  }
  io::HeatColor(error / max_error, rgb);
}

namespace {

std::string Fmt(const char* format, double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, format, v);
  return buf;
}

Image8 Heatmap(const ImageF& error, double max_error) {
  Image8 out(error.width(), error.height(), 3);
  for (int y = 0; y < error.height(); ++y)
    for (int x = 0; x < error.width(); ++x) HeatmapColor(error.at(x, y), max_error, &out.at(x, y));
  return out;
}

const char* kCurveColors[] = {"#d62728", "#1f77b4", "#2ca02c", "#9467bd", "#ff7f0e", "#8c564b"};

// Fig. 13: mean error against completeness, one curve per 3D photo and one
// dot per evaluated photo.
std::string ErrorCompletenessSvg(const std::vector<PhotoModelEvaluation>& evals) {
  const double w = 560, h = 340, left = 60, right = 20, top = 20, bottom = 45;
  double y_max = 0.05;
  for (const auto& e : evals) {
    for (const auto& p : e.photos) y_max = std::max(y_max, p.metrics.error * 1.15);
    for (const auto& c : ErrorCompletenessCurve(e.error_histogram, e.total_pixels))
      y_max = std::max(y_max, c.error * 1.15);
  }
  y_max = std::min(1.0, y_max);
  const auto px = [&](double c) { return left + c * (w - left - right); };
  const auto py = [&](double e) { return top + (1 - e / y_max) * (h - top - bottom); };
  std::ostringstream s;
  s << "<svg width=\"" << w << "\" height=\"" << h << "\" viewBox=\"0 0 " << w << " " << h
    << "\" role=\"img\" aria-label=\"error versus completeness\">";
  s << "<rect x=\"" << left << "\" y=\"" << top << "\" width=\"" << w - left - right
    << "\" height=\"" << h - top - bottom << "\" fill=\"#fafafa\" stroke=\"#999\"/>";
  for (int i = 0; i <= 5; ++i) {
    const double c = i / 5.0, e = y_max * i / 5.0;
    s << "<line x1=\"" << px(c) << "\" y1=\"" << top << "\" x2=\"" << px(c) << "\" y2=\""
      << h - bottom << "\" stroke=\"#e3e3e3\"/>";
    s << "<text x=\"" << px(c) << "\" y=\"" << h - bottom + 16 << "\" text-anchor=\"middle\">"
      << Fmt("%.1f", c) << "</text>";
    s << "<text x=\"" << left - 6 << "\" y=\"" << py(e) + 4 << "\" text-anchor=\"end\">"
      << Fmt("%.3f", e) << "</text>";
  }
  s << "<text x=\"" << (left + w - right) / 2 << "\" y=\"" << h - 6
    << "\" text-anchor=\"middle\">completeness</text>";
  s << "<text transform=\"translate(14," << (top + h - bottom) / 2
    << ") rotate(-90)\" text-anchor=\"middle\">mean error (shiftable window)</text>";
  for (size_t k = 0; k < evals.size(); ++k) {
    const char* color = kCurveColors[k % 6];
    const auto curve = ErrorCompletenessCurve(evals[k].error_histogram, evals[k].total_pixels);
    s << "<polyline fill=\"none\" stroke=\"" << color << "\" stroke-width=\"2\" points=\"";
    for (const auto& c : curve)
      s << Fmt("%.1f", px(c.completeness)) << "," << Fmt("%.1f", py(c.error)) << " ";
    s << "\"/>";
    for (const auto& p : evals[k].photos)
      s << "<circle cx=\"" << Fmt("%.1f", px(p.metrics.completeness)) << "\" cy=\""
        << Fmt("%.1f", py(p.metrics.error)) << "\" r=\"3.5\" fill=\"" << color << "\"><title>"
        << util::HtmlEscape(p.name) << "</title></circle>";
    s << "<text x=\"" << left + 10 << "\" y=\"" << top + 16 + 16 * k << "\" fill=\"" << color
      << "\">" << util::HtmlEscape(evals[k].label) << "</text>";
  }
  s << "</svg>";
  return s.str();
}

}  // namespace

std::string RenderHtmlReport(const std::string& capture,
                             const std::vector<PhotoModelEvaluation>& evals,
                             const ReportOptions& options) {
  if (const Status st = options.Check(); !st.ok())
    throw std::invalid_argument("report: " + st.message());
  std::ostringstream s;
  s << "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\"><title>"
    << util::HtmlEscape(options.title)
    << "</title>\n<style>\n"
       "body{font-family:system-ui,sans-serif;margin:24px;color:#222;max-width:1400px}\n"
       "table{border-collapse:collapse;margin:8px 0 20px}\n"
       "th,td{border:1px solid #ccc;padding:3px 8px;text-align:right}\n"
       "th{background:#f0f0f0}td.l,th.l{text-align:left}\n"
       "figure{display:inline-block;margin:4px}figcaption{font-size:12px;color:#555}\n"
       "svg text{font-size:12px;font-family:system-ui,sans-serif}\n"
       ".photo{border-top:1px solid #ddd;padding-top:6px}\n"
       "</style></head><body>\n";
  s << "<h1>" << util::HtmlEscape(options.title) << "</h1>\n<p>Capture: <code>"
    << util::HtmlEscape(capture)
    << "</code>. Virtual rephotography (Hedman et al. 2017, Sec. 6.3; Waechter et al. 2017): each "
       "photo is re-rendered from the 3D photo at its exact pose and compared with it. Error: per "
       "pixel, the minimum sum of absolute RGB differences within a shiftable window of &plusmn;2 "
       "pixels, divided by 3&times;255, averaged over covered pixels. Completeness: fraction of "
       "the "
       "photo covered. PSNR and SSIM over covered pixels; &ldquo;whole frame&rdquo;: over every "
       "pixel, each uncovered one filled with the colour of the nearest covered one (comparable "
       "with methods that render every pixel).</p>\n";

  if (evals.size() > 1 || !options.references.empty()) {
    // Stages recorded by any of the 3D photos, in order of first appearance.
    std::vector<std::string> stages;
    for (const auto& e : evals)
      for (const auto& [stage, sec] : e.stage_seconds)
        if (std::find(stages.begin(), stages.end(), stage) == stages.end()) stages.push_back(stage);
    s << "<h2>" << (evals.size() > 1 ? "Ablation comparison" : "Comparison with published results")
      << "</h2>\n<table><tr><th class=\"l\">3D photo</th><th>photos</th>"
         "<th>error</th><th>completeness</th><th>PSNR (dB)</th><th>SSIM</th><th>PSNR whole "
         "frame</th><th>SSIM whole frame</th><th>depth median rel. err.</th>"
         "<th>depth within 3%</th><th>triangles</th><th>package (MiB)</th>";
    for (const std::string& stage : stages) s << "<th>" << util::HtmlEscape(stage) << " (s)</th>";
    s << "</tr>\n";
    for (const auto& e : evals) {
      s << "<tr><td class=\"l\">" << util::HtmlEscape(e.label) << "</td><td>" << e.photos.size()
        << "</td><td>" << Fmt("%.4f", e.mean_error) << "</td><td>"
        << Fmt("%.3f", e.mean_completeness) << "</td><td>" << Fmt("%.2f", e.mean_psnr_db)
        << "</td><td>" << Fmt("%.3f", e.mean_ssim) << "</td><td>"
        << Fmt("%.2f", e.mean_psnr_filled_db) << "</td><td>" << Fmt("%.3f", e.mean_ssim_filled)
        << "</td><td>" << (e.has_depth ? Fmt("%.4f", e.mean_depth_median_rel) : "&ndash;")
        << "</td><td>" << (e.has_depth ? Fmt("%.3f", e.mean_depth_within) : "&ndash;")
        << "</td><td>" << e.mesh_triangles << "</td><td>"
        << (e.package_bytes ? Fmt("%.2f", e.package_bytes / 1048576.0) : "&ndash;") << "</td>";
      for (const std::string& stage : stages) {
        const auto it = std::find_if(e.stage_seconds.begin(), e.stage_seconds.end(),
                                     [&](const auto& p) { return p.first == stage; });
        s << "<td>" << (it == e.stage_seconds.end() ? "&ndash;" : Fmt("%.1f", it->second))
          << "</td>";
      }
      s << "</tr>\n";
    }
    for (const ReferenceResult& r : options.references) {
      s << "<tr><td class=\"l\"><i>" << util::HtmlEscape(r.label)
        << "</i> (published)</td><td>&ndash;</td><td>&ndash;</td><td>&ndash;</td><td>&ndash;</td>"
           "<td>&ndash;</td><td>"
        << Fmt("%.2f", r.psnr_db) << "</td><td>" << Fmt("%.3f", r.ssim) << "</td>";
      for (size_t k = 0; k < 4 + stages.size(); ++k) s << "<td>&ndash;</td>";
      s << "</tr>\n";
    }
    s << "</table>\n";
  }

  s << "<h2>Error versus completeness</h2>\n<p>Curves: keeping only pixels whose error is below a "
       "threshold, their share of all photo pixels against their mean error (as the paper's "
       "Fig. 13); dots: single photos.</p>\n"
    << ErrorCompletenessSvg(evals) << "\n";

  for (const auto& e : evals) {
    s << "<h2>" << util::HtmlEscape(e.label) << "</h2>\n<p>Read from <code>"
      << util::HtmlEscape(e.source) << "</code>; poses from <code>"
      << util::HtmlEscape(e.poses_from) << "</code>. Panorama " << e.pano_width << "&times;"
      << e.pano_height << ", mesh of " << e.mesh_triangles << " triangles";
    if (e.package_bytes) s << ", package " << Fmt("%.2f", e.package_bytes / 1048576.0) << " MiB";
    s << ". Mean over " << e.photos.size() << " photos: error " << Fmt("%.4f", e.mean_error)
      << ", completeness " << Fmt("%.3f", e.mean_completeness) << ", PSNR "
      << Fmt("%.2f", e.mean_psnr_db) << " dB, SSIM " << Fmt("%.3f", e.mean_ssim)
      << "; whole frame PSNR " << Fmt("%.2f", e.mean_psnr_filled_db) << " dB, SSIM "
      << Fmt("%.3f", e.mean_ssim_filled) << ".</p>\n";
    s << "<table><tr><th class=\"l\">photo</th><th>index</th><th>held "
         "out</th><th>size</th><th>error</th>"
         "<th>plain error</th><th>completeness</th><th>PSNR (dB)</th><th>SSIM</th>"
         "<th>PSNR whole frame</th><th>SSIM whole frame</th>";
    if (e.has_depth) s << "<th>depth median rel. err.</th><th>depth within 3%</th>";
    s << "<th>render (s)</th></tr>\n";
    for (const auto& p : e.photos) {
      const RephotoMetrics& m = p.metrics;
      s << "<tr><td class=\"l\">" << util::HtmlEscape(p.name) << "</td><td>" << p.index
        << "</td><td>" << (p.held_out ? "yes" : "no") << "</td><td>" << m.width << "&times;"
        << m.height << "</td><td>" << Fmt("%.4f", m.error) << "</td><td>"
        << Fmt("%.4f", m.error_plain) << "</td><td>" << Fmt("%.3f", m.completeness) << "</td><td>"
        << Fmt("%.2f", m.psnr_db) << "</td><td>" << Fmt("%.3f", m.ssim) << "</td><td>"
        << Fmt("%.2f", m.psnr_filled_db) << "</td><td>" << Fmt("%.3f", m.ssim_filled) << "</td>";
      if (e.has_depth)
        s << "<td>" << (p.depth.pixels ? Fmt("%.4f", p.depth.median_relative_error) : "&ndash;")
          << "</td><td>" << (p.depth.pixels ? Fmt("%.3f", p.depth.within_tolerance) : "&ndash;")
          << "</td>";
      s << "<td>" << Fmt("%.2f", p.seconds_render) << "</td></tr>\n";
    }
    s << "</table>\n";
    if (!e.stage_seconds.empty()) {
      s << "<h3>Timings per stage</h3>\n<table><tr><th "
           "class=\"l\">stage</th><th>seconds</th></tr>\n";
      for (const auto& [stage, sec] : e.stage_seconds)
        s << "<tr><td class=\"l\">" << util::HtmlEscape(stage) << "</td><td>" << Fmt("%.2f", sec)
          << "</td></tr>\n";
      s << "</table>\n";
    }
    if (e.viewer) s << ViewerViewsHtml(*e.viewer, options.thumbnail_width / 2);
    s << "<h3>Photos, rephotographs and error heatmaps</h3>\n<p>Heatmap: dark = low error, pale "
         "yellow = "
      << Fmt("%.2f", options.heatmap_max_error) << " or more, grey = not covered.</p>\n";
    for (const auto& p : e.photos) {
      if (p.photo.empty()) continue;
      s << "<div class=\"photo\"><b>" << util::HtmlEscape(p.name) << "</b><br>";
      s << "<figure><img alt=\"photo\" src=\"" << PngDataUri(p.photo, options.thumbnail_width)
        << "\"><figcaption>photo</figcaption></figure>";
      s << "<figure><img alt=\"rephotograph\" src=\""
        << PngDataUri(p.render, options.thumbnail_width)
        << "\"><figcaption>rephotograph</figcaption></figure>";
      s << "<figure><img alt=\"error\" src=\""
        << PngDataUri(Heatmap(p.error_map, options.heatmap_max_error), options.thumbnail_width)
        << "\"><figcaption>error " << Fmt("%.4f", p.metrics.error)
        << "</figcaption></figure></div>\n";
    }
  }
  s << "</body></html>\n";
  return s.str();
}

std::string RenderJsonReport(const std::string& capture,
                             const std::vector<PhotoModelEvaluation>& evals,
                             const EvaluateOptions& options) {
  nlohmann::json j;
  j["capture"] = capture;
  j["options"] = {{"width", options.width},
                  {"shift_radius_px", options.metrics.shift_radius_px},
                  {"psnr_cap_db", options.metrics.psnr_cap_db},
                  {"depth_tolerance", options.depth_tolerance},
                  {"viewer_views", options.viewer_views},
                  {"viewer_width", options.viewer.width},
                  {"viewer_height", options.viewer.height},
                  {"viewer_stretch_factor", options.viewer.stretch_factor},
                  {"viewer_sheet_stretch", options.backdrop ? options.viewer.sheet_stretch : 0.0}};
  j["photo3d"] = nlohmann::json::array();
  for (const auto& e : evals) {
    nlohmann::json m;
    m["label"] = e.label;
    m["source"] = e.source;
    m["poses_from"] = e.poses_from;
    if (e.reference_alignment) {
      const ReferenceAlignment& a = *e.reference_alignment;
      m["reference_alignment"] = {{"common_photos", a.num_common},
                                  {"scale", a.model_to_reference.scale},
                                  {"mean_rotation_error_deg", a.mean_rotation_error_deg},
                                  {"max_rotation_error_deg", a.max_rotation_error_deg},
                                  {"mean_centre_error", a.mean_centre_error},
                                  {"max_centre_error", a.max_centre_error}};
    }
    m["pano_width"] = e.pano_width;
    m["pano_height"] = e.pano_height;
    m["mesh_triangles"] = e.mesh_triangles;
    m["package_bytes"] = e.package_bytes;
    m["holdout"] = e.holdout;
    m["mean"] = {{"error", e.mean_error},
                 {"completeness", e.mean_completeness},
                 {"psnr_db", e.mean_psnr_db},
                 {"ssim", e.mean_ssim},
                 {"psnr_filled_db", e.mean_psnr_filled_db},
                 {"ssim_filled", e.mean_ssim_filled}};
    if (e.has_depth) {
      m["depth_scale"] = e.depth_scale;
      m["mean"]["depth_median_relative_error"] = e.mean_depth_median_rel;
      m["mean"]["depth_within_tolerance"] = e.mean_depth_within;
    }
    if (e.viewer) m["viewer_views"] = nlohmann::json::parse(ViewerViewsJson(*e.viewer));
    m["stages"] = nlohmann::json::array();
    for (const auto& [stage, sec] : e.stage_seconds)
      m["stages"].push_back({{"stage", stage}, {"seconds", sec}});
    m["photos"] = nlohmann::json::array();
    for (const auto& p : e.photos) {
      nlohmann::json q = {{"name", p.name},
                          {"index", p.index},
                          {"held_out", p.held_out},
                          {"width", p.metrics.width},
                          {"height", p.metrics.height},
                          {"covered_pixels", p.metrics.covered_pixels},
                          {"completeness", p.metrics.completeness},
                          {"error", p.metrics.error},
                          {"error_plain", p.metrics.error_plain},
                          {"psnr_db", p.metrics.psnr_db},
                          {"ssim", p.metrics.ssim},
                          {"psnr_filled_db", p.metrics.psnr_filled_db},
                          {"ssim_filled", p.metrics.ssim_filled},
                          {"seconds_render", p.seconds_render}};
      if (p.depth.available)
        q["depth"] = {{"pixels", p.depth.pixels},
                      {"median_relative_error", p.depth.median_relative_error},
                      {"median_ratio", p.depth.median_ratio},
                      {"within_tolerance", p.depth.within_tolerance}};
      m["photos"].push_back(q);
    }
    j["photo3d"].push_back(m);
  }
  return j.dump(2) + "\n";
}

}  // namespace casual3d::eval

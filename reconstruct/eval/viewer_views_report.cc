#include "reconstruct/eval/viewer_views_report.h"

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <sstream>
#include <stdexcept>

#include "reconstruct/eval/report.h"
#include "reconstruct/io/image_io.h"
#include "reconstruct/util/html.h"

namespace casual3d::eval {
namespace {

constexpr int kColumns = 8, kRows = 3;

std::string Percent(double fraction) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.3f%%", 100.0 * fraction);
  return buf;
}

std::string Fmt(const char* format, double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, format, v);
  return buf;
}

// File-name form of a view's name: "level az 45" -> "level_az_45".
std::string FileName(std::string name) {
  std::replace(name.begin(), name.end(), ' ', '_');
  return name;
}

}  // namespace

void ViewerGridCell(int index, int* column, int* row) {
  if (index == 0) {
    *column = 0, *row = 0;
  } else if (index <= 8) {
    *column = index - 1, *row = 1;
  } else {
    const int k = (index - 9) % 4;  // Azimuths 45, 135, 225, 315.
    *column = 2 * k + 1;
    *row = index <= 12 ? 0 : 2;
  }
}

Image8 ViewerHeatmapThumbnail(const ViewerViewResult& view, int factor) {
  const Image8 full = ViewerHeatmap(view);
  factor = std::max(1, factor);
  const int w = std::max(1, full.width() / factor), h = std::max(1, full.height() / factor);
  Image8 out(w, h, 3, 0);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      bool tear = false, stretched = false;
      int sum[3] = {0, 0, 0}, n = 0;
      for (int dy = 0; dy < factor; ++dy)
        for (int dx = 0; dx < factor; ++dx) {
          const int fx = x * factor + dx, fy = y * factor + dy;
          if (fx >= full.width() || fy >= full.height()) continue;
          const auto c = static_cast<ViewerPixel>(view.classes.at(fx, fy));
          tear |= c == ViewerPixel::kTear;
          stretched |= c == ViewerPixel::kStretched;
          for (int ch = 0; ch < 3; ++ch) sum[ch] += full.at(fx, fy, ch);
          ++n;
        }
      uint8_t* o = &out.at(x, y);
      if (tear) {
        o[0] = 255, o[1] = 0, o[2] = 0;
      } else if (stretched) {
        o[0] = 255, o[1] = 150, o[2] = 0;
      } else {
        for (int ch = 0; ch < 3; ++ch) o[ch] = static_cast<uint8_t>(sum[ch] / std::max(1, n));
      }
    }
  return out;
}

Image8 ViewerHeatmapGrid(const ViewerViewsEvaluation& eval, int factor) {
  if (eval.views.empty() || eval.views[0].classes.empty()) return {};
  const Image8 first = ViewerHeatmapThumbnail(eval.views[0], factor);
  const int tw = first.width(), th = first.height(), gap = 1;
  Image8 grid(kColumns * (tw + gap) + gap, kRows * (th + gap) + gap, 3, 40);
  for (size_t k = 0; k < eval.views.size(); ++k) {
    const Image8 t = k == 0 ? first : ViewerHeatmapThumbnail(eval.views[k], factor);
    int column, row;
    ViewerGridCell(static_cast<int>(k), &column, &row);
    for (int y = 0; y < std::min(th, t.height()); ++y)
      for (int x = 0; x < std::min(tw, t.width()); ++x)
        for (int ch = 0; ch < 3; ++ch)
          grid.at(gap + column * (tw + gap) + x, gap + row * (th + gap) + y, ch) = t.at(x, y, ch);
  }
  return grid;
}

std::string ViewerViewsSummary(const ViewerViewsEvaluation& e) {
  std::ostringstream s;
  s << "viewer views (" << e.views.size() << " at " << e.width << "x" << e.height
    << ", volume radius " << Fmt("%.4g", e.hints.volume_radius)
    << (e.hints_derived ? ", hints derived" : ", hints of the 3D photo") << "): tears centre "
    << Percent(e.centre_tears) << ", boundary mean " << Percent(e.boundary_tears_mean) << " max "
    << Percent(e.boundary_tears_max) << "; stretched fill centre " << Percent(e.centre_stretched)
    << ", boundary mean " << Percent(e.boundary_stretched_mean) << " max "
    << Percent(e.boundary_stretched_max);
  return s.str();
}

std::string ViewerViewsJson(const ViewerViewsEvaluation& e) {
  const ViewHints& h = e.hints;
  nlohmann::json j = {{"width", e.width},
                      {"height", e.height},
                      {"stretch_factor", e.stretch_factor},
                      {"sheet_stretch", e.sheet_stretch},
                      {"hints_derived", e.hints_derived},
                      {"hints",
                       {{"yaw_deg", h.yaw_deg},
                        {"pitch_deg", h.pitch_deg},
                        {"fov_deg", h.fov_deg},
                        {"content_yaw_deg", {h.content_yaw_min_deg, h.content_yaw_max_deg}},
                        {"content_pitch_deg", {h.content_pitch_min_deg, h.content_pitch_max_deg}},
                        {"volume_radius", h.volume_radius},
                        {"metric", h.metric}}},
                      {"centre_tears", e.centre_tears},
                      {"boundary_tears_mean", e.boundary_tears_mean},
                      {"boundary_tears_max", e.boundary_tears_max},
                      {"centre_stretched", e.centre_stretched},
                      {"boundary_stretched_mean", e.boundary_stretched_mean},
                      {"boundary_stretched_max", e.boundary_stretched_max},
                      {"views", nlohmann::json::array()}};
  for (const ViewerViewResult& v : e.views)
    j["views"].push_back(
        {{"name", v.name},
         {"position", {v.camera.position[0], v.camera.position[1], v.camera.position[2]}},
         {"captured_pixels", v.captured_pixels},
         {"tear_pixels", v.tear_pixels},
         {"stretched_pixels", v.stretched_pixels},
         {"tear_fraction", v.tear_fraction},
         {"stretched_fraction", v.stretched_fraction},
         {"median_triangle_px", v.median_triangle_px}});
  return j.dump();
}

std::string ViewerViewsHtml(const ViewerViewsEvaluation& e, int thumbnail_width) {
  const ViewHints& h = e.hints;
  std::ostringstream s;
  s << "<h3>What a viewer sees</h3>\n<p>The mesh rendered at " << e.width << "&times;" << e.height
    << " from 17 eyes: the centre and 16 on the viewing volume's surface (radius "
    << Fmt("%.4g", h.volume_radius) << (h.metric ? " m" : " depth units")
    << "; 8 level, 4 at 45&deg; above, 4 at 45&deg; below), all looking at yaw "
    << Fmt("%.1f", h.yaw_deg) << "&deg;, pitch " << Fmt("%.1f", h.pitch_deg)
    << "&deg; with a vertical field of view of " << Fmt("%.1f", h.fov_deg) << "&deg; (view hints "
    << (e.hints_derived ? "derived from the panorama" : "of the 3D photo") << "; content yaw ["
    << Fmt("%.1f", h.content_yaw_min_deg) << ", " << Fmt("%.1f", h.content_yaw_max_deg)
    << "]&deg;, pitch [" << Fmt("%.1f", h.content_pitch_min_deg) << ", "
    << Fmt("%.1f", h.content_pitch_max_deg)
    << "]&deg;). <b>Tears</b>: pixels inside the captured field of view (what a hole-free proxy "
       "of the captured content covers from the same eye) that show no surface. <b>Stretched "
       "fill</b>: covered pixels there drawn by a triangle whose longest edge spans more than "
    << Fmt("%g", e.stretch_factor)
    << " times the view's median triangle."
    << (e.sheet_stretch > 0
            ? " With the backdrop, mesh triangles that look more than " + Fmt("%g", e.sheet_stretch) +
                  " times larger from the eye than from the centre (sheets across depth steps) are "
                  "left out, as the viewer does."
            : std::string())
    << "</p>\n"
       "<table><tr><th class=\"l\"></th><th>tears</th><th>stretched fill</th></tr>\n"
    << "<tr><td class=\"l\">centre</td><td>" << Percent(e.centre_tears) << "</td><td>"
    << Percent(e.centre_stretched) << "</td></tr>\n"
    << "<tr><td class=\"l\">boundary, mean of 16</td><td>" << Percent(e.boundary_tears_mean)
    << "</td><td>" << Percent(e.boundary_stretched_mean) << "</td></tr>\n"
    << "<tr><td class=\"l\">boundary, worst</td><td>" << Percent(e.boundary_tears_max)
    << "</td><td>" << Percent(e.boundary_stretched_max) << "</td></tr></table>\n";
  s << "<table><tr><th class=\"l\">view</th><th>eye (x, y, z)</th><th>captured pixels</th>"
       "<th>tears</th><th>stretched fill</th><th>median triangle (px)</th></tr>\n";
  for (const ViewerViewResult& v : e.views)
    s << "<tr><td class=\"l\">" << util::HtmlEscape(v.name) << "</td><td>"
      << Fmt("%.3g", v.camera.position[0]) << ", " << Fmt("%.3g", v.camera.position[1]) << ", "
      << Fmt("%.3g", v.camera.position[2]) << "</td><td>" << v.captured_pixels << "</td><td>"
      << Percent(v.tear_fraction) << "</td><td>" << Percent(v.stretched_fraction) << "</td><td>"
      << Fmt("%.2f", v.median_triangle_px) << "</td></tr>\n";
  s << "</table>\n";
  if (e.views.empty() || e.views[0].classes.empty()) return s.str();
  const int factor = std::max(1, e.width / std::max(16, thumbnail_width));
  s << "<p>Heatmaps: the rendering dimmed; <span style=\"color:#f00\">red</span> tears, <span "
       "style=\"color:#f90\">orange</span> stretched fill, dark blue outside the captured field "
       "of view. Top row: the centre (left) and the views above; middle: level views by azimuth "
       "from straight ahead (0&deg;) clockwise seen from above; bottom: the views below. A "
       "thumbnail pixel is red or orange if any of the "
    << factor << "&times;" << factor << " pixels it stands for is.</p>\n";
  s << "<div style=\"display:grid;grid-template-columns:repeat(" << kColumns
    << ",auto);gap:4px;justify-content:start\">\n";
  for (size_t k = 0; k < e.views.size(); ++k) {
    const ViewerViewResult& v = e.views[k];
    int column, row;
    ViewerGridCell(static_cast<int>(k), &column, &row);
    const Image8 thumb = ViewerHeatmapThumbnail(v, factor);
    s << "<figure style=\"grid-column:" << column + 1 << ";grid-row:" << row + 1
      << ";margin:0\"><img alt=\"" << util::HtmlEscape(v.name) << "\" src=\""
      << PngDataUri(thumb, thumb.width()) << "\"><figcaption>" << util::HtmlEscape(v.name)
      << ": tears " << Percent(v.tear_fraction) << ", stretched " << Percent(v.stretched_fraction)
      << "</figcaption></figure>\n";
  }
  s << "</div>\n";
  return s.str();
}

void WriteViewerHeatmaps(const ViewerViewsEvaluation& e, const std::string& dir,
                         const std::string& prefix) {
  namespace fs = std::filesystem;
  for (size_t k = 0; k < e.views.size(); ++k) {
    if (e.views[k].classes.empty()) continue;
    char index[24];
    std::snprintf(index, sizeof index, "%02zu", k);
    const fs::path path =
        fs::path(dir) / (prefix + "viewer_" + index + "_" + FileName(e.views[k].name) + ".png");
    io::WritePng(path.string(), ViewerHeatmap(e.views[k]));
  }
  const Image8 grid = ViewerHeatmapGrid(e, 2);
  if (!grid.empty()) io::WritePng((fs::path(dir) / (prefix + "viewer_grid.png")).string(), grid);
}

}  // namespace casual3d::eval

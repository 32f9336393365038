#include "reconstruct/eval/viewer_views.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "reconstruct/eval/captured_field.h"
#include "reconstruct/render/derived_view_hints.h"

namespace casual3d::eval {
namespace {

constexpr int kNumViews = 17;

struct EyeOffset {
  const char* ring;
  double latitude_deg, azimuth_deg;
};

// The 16 boundary eyes of the header, in order.
const EyeOffset kBoundary[kNumViews - 1] = {
    {"level", 0, 0},    {"level", 0, 45},    {"level", 0, 90},    {"level", 0, 135},
    {"level", 0, 180},  {"level", 0, 225},   {"level", 0, 270},   {"level", 0, 315},
    {"above", 45, 45},  {"above", 45, 135},  {"above", 45, 225},  {"above", 45, 315},
    {"below", -45, 45}, {"below", -45, 135}, {"below", -45, 225}, {"below", -45, 315}};

double Radians(double deg) { return deg * kPi / 180.0; }

Eigen::Vector3d Position(const float* positions, uint32_t vertex) {
  const float* p = positions + 3 * size_t{vertex};
  return {p[0], p[1], p[2]};
}

// Screen size of triangle `t` seen from `eye` with focal length `focal_px`
// (header: largest visual angle of its edges times the focal length).
double TriangleScreenSize(const Mesh& mesh, size_t t, const Eigen::Vector3d& eye, double focal_px) {
  Eigen::Vector3d a[3];
  for (int k = 0; k < 3; ++k) {
    a[k] = Position(mesh.positions.data(), mesh.indices[3 * t + k]) - eye;
    const double n = a[k].norm();
    if (!(n > 0)) return 0.0;
    a[k] /= n;
  }
  double chord = 0;
  for (int k = 0; k < 3; ++k) chord = std::max(chord, (a[k] - a[(k + 1) % 3]).norm());
  return 2.0 * std::asin(std::min(1.0, chord / 2)) * focal_px;
}

}  // namespace

std::vector<render::GlCamera> ViewerCameras(const ViewHints& hints) {
  render::GlCamera base;
  base.yaw_deg = hints.yaw_deg;
  base.pitch_deg = std::clamp(hints.pitch_deg, -89.0, 89.0);
  base.fov_y_deg = std::clamp(hints.fov_deg, 10.0, 120.0);
  std::vector<render::GlCamera> cameras(kNumViews, base);
  for (int k = 1; k < kNumViews; ++k) {
    const EyeOffset& e = kBoundary[k - 1];
    const Vec3d d =
        LonLatToDirection(Radians(hints.yaw_deg + e.azimuth_deg), Radians(e.latitude_deg));
    cameras[k].position[0] = hints.volume_radius * d.x;
    cameras[k].position[1] = hints.volume_radius * d.y;
    cameras[k].position[2] = hints.volume_radius * d.z;
  }
  return cameras;
}

std::vector<std::string> ViewerCameraNames() {
  std::vector<std::string> names = {"centre"};
  for (const EyeOffset& e : kBoundary)
    names.push_back(std::string(e.ring) + " az " + std::to_string(int(e.azimuth_deg)));
  return names;
}

ViewerViewResult MeasureViewerView(const Mesh& mesh, const render::GlCamera& camera,
                                   const render::RenderResult& r, const Image8& field,
                                   double stretch_factor) {
  const int w = r.mask.width(), h = r.mask.height();
  if (r.triangle_ids.width() != w || r.triangle_ids.height() != h || field.width() != w ||
      field.height() != h)
    throw std::invalid_argument(
        "viewer view: the rendering needs triangle ids and a field mask of " + std::to_string(w) +
        "x" + std::to_string(h) + " pixels");
  ViewerViewResult out;
  out.camera = camera;
  const render::PinholeView view = render::ViewFromGlCamera(camera, w, h);
  const Eigen::Vector3d eye(camera.position[0], camera.position[1], camera.position[2]);

  // Screen sizes of the distinct drawn triangles, and their median.
  std::vector<uint32_t> drawn;
  drawn.reserve(size_t(w) * h);
  for (size_t i = 0; i < r.triangle_ids.size(); ++i)
    if (r.triangle_ids.data()[i] != render::kNoTriangle) drawn.push_back(r.triangle_ids.data()[i]);
  std::sort(drawn.begin(), drawn.end());
  drawn.erase(std::unique(drawn.begin(), drawn.end()), drawn.end());
  std::vector<double> size(drawn.size());
  for (size_t k = 0; k < drawn.size(); ++k)
    size[k] = TriangleScreenSize(mesh, drawn[k], eye, view.fy);
  if (!size.empty()) {
    std::vector<double> sorted = size;
    std::nth_element(sorted.begin(), sorted.begin() + sorted.size() / 2, sorted.end());
    out.median_triangle_px = sorted[sorted.size() / 2];
  }
  const double limit = stretch_factor * out.median_triangle_px;

  out.classes = Image8(w, h, 1, static_cast<uint8_t>(ViewerPixel::kOutside));
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      if (!field.at(x, y)) continue;
      ++out.captured_pixels;
      ViewerPixel c = ViewerPixel::kGood;
      const uint32_t id = r.triangle_ids.at(x, y);
      if (id == render::kNoTriangle) {
        c = ViewerPixel::kTear;
        ++out.tear_pixels;
      } else {
        const size_t k = std::lower_bound(drawn.begin(), drawn.end(), id) - drawn.begin();
        if (size[k] > limit) {
          c = ViewerPixel::kStretched;
          ++out.stretched_pixels;
        }
      }
      out.classes.at(x, y) = static_cast<uint8_t>(c);
    }
  if (out.captured_pixels > 0) out.tear_fraction = double(out.tear_pixels) / out.captured_pixels;
  const int64_t covered = out.captured_pixels - out.tear_pixels;
  if (covered > 0) out.stretched_fraction = double(out.stretched_pixels) / covered;
  return out;
}

ViewerViewsEvaluation EvaluateViewerViews(const TwoLayerPanorama& pano, const Mesh& mesh,
                                          ImageView<const uint8_t> atlas,
                                          const std::optional<ViewHints>& hints,
                                          const ViewerViewsOptions& options) {
  if (const Status st = options.Check(); !st.ok())
    throw std::invalid_argument("viewer views: " + st.message());
  ViewerViewsEvaluation eval;
  eval.hints = render::ResolveViewHints(pano, options.derive_hints ? std::nullopt : hints,
                                        &eval.hints_derived);
  eval.width = options.width;
  eval.height = options.height;
  eval.stretch_factor = options.stretch_factor;
  if (options.vertex_colors_from_triangle != UINT64_MAX) eval.sheet_stretch = options.sheet_stretch;
  const CapturedField field(pano, eval.hints, options.closing_deg);

  render::RenderOptions render_options;
  render_options.num_threads = options.num_threads;
  render_options.want_triangle_ids = true;
  render_options.vertex_colors_from_triangle = options.vertex_colors_from_triangle;
  render_options.sheet_stretch = eval.sheet_stretch;
  // Clipping planes around the content whatever its unit (models from
  // structure from motion have arbitrary scale), as the viewer sets them.
  double near_m = 0, far_m = 0;
  if (pano.NodeDepthRange(&near_m, &far_m)) {
    render_options.near_m = std::min(render_options.near_m, 0.01 * near_m);
    render_options.far_m = std::max(render_options.far_m, 1.5 * far_m);
  }

  const std::vector<render::GlCamera> cameras = ViewerCameras(eval.hints);
  const std::vector<std::string> names = ViewerCameraNames();
  for (int k = 0; k < kNumViews; ++k) {
    const render::PinholeView view =
        render::ViewFromGlCamera(cameras[k], options.width, options.height);
    render::RenderResult r = render::RenderMesh(mesh, atlas, view, render_options);
    ViewerViewResult v = MeasureViewerView(mesh, cameras[k], r, field.Mask(view, render_options),
                                           options.stretch_factor);
    v.name = names[k];
    if (options.keep_images) {
      v.render = std::move(r.color);
    } else {
      v.classes = Image8();
    }
    eval.views.push_back(std::move(v));
  }

  eval.centre_tears = eval.views[0].tear_fraction;
  eval.centre_stretched = eval.views[0].stretched_fraction;
  for (int k = 1; k < kNumViews; ++k) {
    const ViewerViewResult& v = eval.views[k];
    eval.boundary_tears_mean += v.tear_fraction / (kNumViews - 1);
    eval.boundary_stretched_mean += v.stretched_fraction / (kNumViews - 1);
    eval.boundary_tears_max = std::max(eval.boundary_tears_max, v.tear_fraction);
    eval.boundary_stretched_max = std::max(eval.boundary_stretched_max, v.stretched_fraction);
  }
  return eval;
}

Image8 ViewerHeatmap(const ViewerViewResult& view) {
  const int w = view.classes.width(), h = view.classes.height();
  Image8 out(w, h, 3, 0);
  const bool has_render = view.render.width() == w && view.render.height() == h;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      uint8_t* o = &out.at(x, y);
      const auto c = static_cast<ViewerPixel>(view.classes.at(x, y));
      if (c == ViewerPixel::kTear) {
        o[0] = 255, o[1] = 0, o[2] = 0;
        continue;
      }
      if (c == ViewerPixel::kStretched) {
        o[0] = 255, o[1] = 150, o[2] = 0;
        continue;
      }
      for (int ch = 0; ch < 3; ++ch) {
        const double v = has_render ? view.render.at(x, y, ch) : 128;
        o[ch] = static_cast<uint8_t>(c == ViewerPixel::kGood ? 0.4 * v : 0.15 * v + (ch == 2) * 60);
      }
    }
  return out;
}

}  // namespace casual3d::eval

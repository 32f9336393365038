#include "reconstruct/render/mesh_renderer.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

#include "base/parallel_for.h"
#include "format/sheet_stretch.h"

namespace casual3d::render {
namespace {

constexpr int kMaxSide = 16384;
// Vertex positions are snapped to 1/4096 pixel, so that edge functions are
// exact integers: shared edges are decided identically by both triangles.
constexpr int64_t kSubpixel = 4096;
constexpr int64_t kHalfPixel = kSubpixel / 2;
// Rows per unit of parallel work.
constexpr int kBandRows = 16;
// Attributes interpolated across triangles: u, v, r, g, b.
constexpr int kNumAttrs = 5;
// A triangle clipped by 6 planes has at most 3 + 6 vertices.
constexpr int kMaxPolygon = 9;
constexpr int kNumPlanes = 6;

struct ClipVertex {
  double p[3];  // Camera frame.
  double attr[kNumAttrs];
};

struct ScreenVertex {
  int64_t x, y;  // Pixels * kSubpixel.
  double inv_z;
  double attr_over_z[kNumAttrs];
};

// Inside the half-space n . p + d >= 0.
struct Plane {
  double n[3];
  double d;
  double Distance(const double* p) const { return n[0] * p[0] + n[1] * p[1] + n[2] * p[2] + d; }
};

int64_t FloorDiv(int64_t a, int64_t b) {  // b > 0.
  const int64_t q = a / b;
  return (a % b != 0 && a < 0) ? q - 1 : q;
}
int64_t CeilDiv(int64_t a, int64_t b) { return -FloorDiv(-a, b); }  // b > 0.

std::string Dims(int w, int h) { return std::to_string(w) + "x" + std::to_string(h); }

class Rasterizer {
 public:
  Rasterizer(const Mesh& mesh, ImageView<const uint8_t> atlas, const PinholeView& view,
             const RenderOptions& options)
      : mesh_(mesh), atlas_(atlas), view_(view), options_(options) {
    // A guard band of one image size around the image: side planes clip only
    // there, so visible pixels never see side-clipping vertices, and snapped
    // coordinates stay below 2^28 (edge functions below 2^58, within int64).
    const double g = std::max(view.width, view.height);
    const double w = view.width, h = view.height;
    planes_[0] = {{0, 0, 1}, -options.near_m};
    planes_[1] = {{0, 0, -1}, options.far_m};
    planes_[2] = {{view.fx, 0, view.cx + g}, 0};
    planes_[3] = {{-view.fx, 0, w + g - view.cx}, 0};
    planes_[4] = {{0, view.fy, view.cy + g}, 0};
    planes_[5] = {{0, -view.fy, h + g - view.cy}, 0};
    num_threads_ = base::ResolveThreads(options.num_threads);
    const Eigen::Vector3d eye = -view.rotation.transpose() * view.translation;
    for (int k = 0; k < 3; ++k) eye_[k] = eye[k];
  }

  RenderResult Run() {
    TransformVertices();
    BinTriangles();
    zbuffer_.assign(static_cast<size_t>(view_.width) * view_.height,
                    std::numeric_limits<float>::infinity());
    RenderResult result;
    result.color = Image8(view_.width, view_.height, 3);
    for (int y = 0; y < view_.height; ++y) {
      uint8_t* row = result.color.row(y);
      for (int x = 0; x < view_.width; ++x) {
        for (int c = 0; c < 3; ++c) row[3 * x + c] = options_.background[c];
      }
    }
    color_ = &result.color;
    if (options_.want_triangle_ids) {
      result.triangle_ids = Image<uint32_t>(view_.width, view_.height, 1, kNoTriangle);
      ids_ = result.triangle_ids.data();
    }
    base::ParallelFor(0, num_bands_, num_threads_,
                [&](int64_t band) { RasterBand(static_cast<int>(band)); });

    result.depth = ImageF(view_.width, view_.height, 1, 0.0f);
    result.mask = Image8(view_.width, view_.height, 1, 0);
    for (size_t i = 0; i < zbuffer_.size(); ++i) {
      if (std::isfinite(zbuffer_[i])) {
        result.depth.data()[i] = zbuffer_[i];
        result.mask.data()[i] = 255;
        ++result.covered_pixels;
      }
    }
    return result;
  }

 private:
  void TransformVertices() {
    const size_t n = mesh_.num_vertices();
    cam_.resize(3 * n);
    const int64_t kChunk = 1 << 16;
    const int64_t chunks = (static_cast<int64_t>(n) + kChunk - 1) / kChunk;
    base::ParallelFor(0, chunks, num_threads_, [&](int64_t chunk) {
      const size_t end = std::min(n, static_cast<size_t>((chunk + 1) * kChunk));
      for (size_t i = static_cast<size_t>(chunk * kChunk); i < end; ++i) {
        const Eigen::Vector3d p(mesh_.positions[3 * i], mesh_.positions[3 * i + 1],
                                mesh_.positions[3 * i + 2]);
        const Eigen::Vector3d c = view_.rotation * p + view_.translation;
        cam_[3 * i] = c.x();
        cam_[3 * i + 1] = c.y();
        cam_[3 * i + 2] = c.z();
      }
    });
  }

  // A mesh triangle stretched beyond options_.sheet_stretch seen from the
  // eye (format/sheet_stretch.h); the backdrop's triangles never are.
  bool HiddenSheet(size_t triangle) const {
    if (!(options_.sheet_stretch > 0) || triangle >= options_.vertex_colors_from_triangle) return false;
    const float* p = mesh_.positions.data();
    const uint32_t* i = &mesh_.indices[3 * triangle];
    return SheetStretch(p + 3 * size_t{i[0]}, p + 3 * size_t{i[1]}, p + 3 * size_t{i[2]}, eye_) >
           options_.sheet_stretch;
  }

  bool UsesAtlas(size_t triangle) const {
    return options_.color_source == ColorSource::kAtlas && triangle < options_.vertex_colors_from_triangle;
  }

  ClipVertex LoadVertex(uint32_t index, bool atlas) const {
    ClipVertex v;
    for (int k = 0; k < 3; ++k) v.p[k] = cam_[3 * size_t{index} + k];
    if (atlas) {
      v.attr[0] = mesh_.uvs[2 * size_t{index}];
      v.attr[1] = mesh_.uvs[2 * size_t{index} + 1];
      v.attr[2] = v.attr[3] = v.attr[4] = 0.0;
    } else {
      v.attr[0] = v.attr[1] = 0.0;
      for (int c = 0; c < 3; ++c) v.attr[2 + c] = mesh_.colors[3 * size_t{index} + c];
    }
    return v;
  }

  // Clips triangle `t` against the view's planes and projects it; returns the
  // number of polygon vertices written to `out` (0 if nothing is left).
  int ClipAndProject(size_t t, ScreenVertex* out) const {
    ClipVertex buffers[2][kMaxPolygon];
    ClipVertex* poly = buffers[0];
    int count = 3;
    bool all_inside = true;
    for (int k = 0; k < 3; ++k) {
      poly[k] = LoadVertex(mesh_.indices[3 * t + k], UsesAtlas(t));
      for (int c = 0; c < 3; ++c) {
        if (!std::isfinite(poly[k].p[c])) return 0;
      }
      for (const Plane& plane : planes_) {
        if (plane.Distance(poly[k].p) < 0.0) all_inside = false;
      }
    }
    if (!all_inside) {
      int which = 0;
      for (const Plane& plane : planes_) {
        ClipVertex* in = buffers[which];
        ClipVertex* out_poly = buffers[1 - which];
        int out_count = 0;
        for (int k = 0; k < count; ++k) {
          const ClipVertex& a = in[k];
          const ClipVertex& b = in[(k + 1) % count];
          const double da = plane.Distance(a.p), db = plane.Distance(b.p);
          if (da >= 0.0) out_poly[out_count++] = a;
          if ((da >= 0.0) != (db >= 0.0)) {
            // Interpolate from the inside endpoint, so that the two triangles
            // sharing this edge compute bit-identical intersection points.
            const ClipVertex& from = da >= 0.0 ? a : b;
            const ClipVertex& to = da >= 0.0 ? b : a;
            const double d_from = da >= 0.0 ? da : db, d_to = da >= 0.0 ? db : da;
            const double s = d_from / (d_from - d_to);
            ClipVertex& v = out_poly[out_count++];
            for (int c = 0; c < 3; ++c) v.p[c] = from.p[c] + s * (to.p[c] - from.p[c]);
            for (int c = 0; c < kNumAttrs; ++c) {
              v.attr[c] = from.attr[c] + s * (to.attr[c] - from.attr[c]);
            }
          }
        }
        count = out_count;
        which = 1 - which;
        if (count < 3) return 0;
      }
      poly = buffers[which];
    }
    for (int k = 0; k < count; ++k) {
      const ClipVertex& v = poly[k];
      const double inv_z = 1.0 / v.p[2];
      const double sx = view_.fx * v.p[0] * inv_z + view_.cx;
      const double sy = view_.fy * v.p[1] * inv_z + view_.cy;
      out[k].x = std::llround(sx * kSubpixel);
      out[k].y = std::llround(sy * kSubpixel);
      out[k].inv_z = inv_z;
      for (int c = 0; c < kNumAttrs; ++c) out[k].attr_over_z[c] = v.attr[c] * inv_z;
    }
    return count;
  }

  // Rows [first, last] whose pixel centres the polygon can cover; false if none.
  bool RowRange(const ScreenVertex* poly, int count, int* first, int* last) const {
    int64_t y_min = poly[0].y, y_max = poly[0].y;
    for (int k = 1; k < count; ++k) {
      y_min = std::min(y_min, poly[k].y);
      y_max = std::max(y_max, poly[k].y);
    }
    const int64_t j0 = std::max<int64_t>(0, CeilDiv(y_min - kHalfPixel, kSubpixel));
    const int64_t j1 = std::min<int64_t>(view_.height - 1, FloorDiv(y_max - kHalfPixel, kSubpixel));
    if (j0 > j1) return false;
    *first = static_cast<int>(j0);
    *last = static_cast<int>(j1);
    return true;
  }

  // Lists, per band of rows, the triangles that may cover it, in index order.
  void BinTriangles() {
    num_bands_ = (view_.height + kBandRows - 1) / kBandRows;
    const size_t num_triangles = mesh_.num_triangles();
    const int64_t kChunk = 1 << 15;
    const int64_t chunks = (static_cast<int64_t>(num_triangles) + kChunk - 1) / kChunk;
    std::vector<std::vector<std::vector<uint32_t>>> per_chunk(chunks);
    base::ParallelFor(0, chunks, num_threads_, [&](int64_t chunk) {
      std::vector<std::vector<uint32_t>>& lists = per_chunk[chunk];
      lists.resize(num_bands_);
      ScreenVertex poly[kMaxPolygon];
      const size_t end = std::min(num_triangles, static_cast<size_t>((chunk + 1) * kChunk));
      for (size_t t = static_cast<size_t>(chunk * kChunk); t < end; ++t) {
        const int count = ClipAndProject(t, poly);
        int first, last;
        if (count < 3 || !RowRange(poly, count, &first, &last)) continue;
        if (HiddenSheet(t)) continue;  // Tested only for triangles in view.
        for (int band = first / kBandRows; band <= last / kBandRows; ++band) {
          lists[band].push_back(static_cast<uint32_t>(t));
        }
      }
    });
    bands_.assign(num_bands_, {});
    for (int band = 0; band < num_bands_; ++band) {
      size_t total = 0;
      for (const auto& lists : per_chunk) total += lists[band].size();
      bands_[band].reserve(total);
      for (auto& lists : per_chunk) {
        bands_[band].insert(bands_[band].end(), lists[band].begin(), lists[band].end());
        std::vector<uint32_t>().swap(lists[band]);
      }
    }
  }

  void RasterBand(int band) {
    const int row_begin = band * kBandRows;
    const int row_end = std::min(view_.height, row_begin + kBandRows);
    ScreenVertex poly[kMaxPolygon];
    for (uint32_t t : bands_[band]) {
      const int count = ClipAndProject(t, poly);
      for (int k = 1; k + 1 < count; ++k) {
        RasterTriangle(poly[0], poly[k], poly[k + 1], t, row_begin, row_end);
      }
    }
  }

  void RasterTriangle(const ScreenVertex& p0, const ScreenVertex& p1_in, const ScreenVertex& p2_in,
                      uint32_t triangle, int row_begin, int row_end) {
    const ScreenVertex* v[3] = {&p0, &p1_in, &p2_in};
    int64_t area =
        (v[1]->x - v[0]->x) * (v[2]->y - v[0]->y) - (v[1]->y - v[0]->y) * (v[2]->x - v[0]->x);
    if (area == 0) return;
    if (area < 0) {  // Back faces are drawn: make the orientation positive.
      std::swap(v[1], v[2]);
      area = -area;
    }
    // Edge k is opposite vertex k: E_k(p) = A p.x + B p.y + C, positive inside.
    int64_t A[3], B[3], C[3], bias[3];
    for (int k = 0; k < 3; ++k) {
      const ScreenVertex& a = *v[(k + 1) % 3];
      const ScreenVertex& b = *v[(k + 2) % 3];
      A[k] = a.y - b.y;
      B[k] = b.x - a.x;
      C[k] = -(A[k] * a.x + B[k] * a.y);
      // Top-left rule: centres exactly on a left edge (interior to its right)
      // or a top edge (horizontal, interior below) are inside.
      const bool top_left = A[k] > 0 || (A[k] == 0 && B[k] > 0);
      bias[k] = top_left ? 0 : -1;
    }
    int first, last;
    {
      ScreenVertex tri[3] = {*v[0], *v[1], *v[2]};
      if (!RowRange(tri, 3, &first, &last)) return;
    }
    first = std::max(first, row_begin);
    last = std::min(last, row_end - 1);
    const double inv_area = 1.0 / static_cast<double>(area);
    const int width = view_.width;
    for (int j = first; j <= last; ++j) {
      const int64_t py = j * kSubpixel + kHalfPixel;
      int64_t lo = 0, hi = width - 1;
      for (int k = 0; k < 3 && lo <= hi; ++k) {
        // Pixels i with A (256 i + 128) + K >= 0.
        const int64_t K = B[k] * py + C[k] + bias[k];
        if (A[k] > 0) {
          lo = std::max(lo, CeilDiv(-K - kHalfPixel * A[k], kSubpixel * A[k]));
        } else if (A[k] < 0) {
          hi = std::min(hi, FloorDiv(K + kHalfPixel * A[k], -kSubpixel * A[k]));
        } else if (K < 0) {
          hi = -1;
        }
      }
      for (int64_t i = lo; i <= hi; ++i) {
        const int64_t px = i * kSubpixel + kHalfPixel;
        double b[3];
        for (int k = 0; k < 3; ++k) {
          b[k] = static_cast<double>(A[k] * px + B[k] * py + C[k]) * inv_area;
        }
        const double inv_z = b[0] * v[0]->inv_z + b[1] * v[1]->inv_z + b[2] * v[2]->inv_z;
        const float z = static_cast<float>(1.0 / inv_z);
        const size_t pixel = static_cast<size_t>(j) * width + static_cast<size_t>(i);
        if (!(z < zbuffer_[pixel])) continue;
        zbuffer_[pixel] = z;
        if (ids_ != nullptr) ids_[pixel] = triangle;
        double attr[kNumAttrs];
        for (int c = 0; c < kNumAttrs; ++c) {
          attr[c] = (b[0] * v[0]->attr_over_z[c] + b[1] * v[1]->attr_over_z[c] +
                     b[2] * v[2]->attr_over_z[c]) /
                    inv_z;
        }
        uint8_t* out = color_->row(j) + 3 * i;
        if (UsesAtlas(triangle)) {
          SampleAtlas(attr[0], attr[1], out);
        } else {
          for (int c = 0; c < 3; ++c) {
            out[c] = static_cast<uint8_t>(std::clamp(std::lround(attr[2 + c]), 0L, 255L));
          }
        }
      }
    }
  }

  // OpenGL LINEAR filtering with REPEAT in u and CLAMP_TO_EDGE in v.
  void SampleAtlas(double u, double v, uint8_t* out) const {
    const int w = atlas_.width(), h = atlas_.height();
    const double x = u * w - 0.5, y = v * h - 0.5;
    const double xf = std::floor(x), yf = std::floor(y);
    const double ax = x - xf, ay = y - yf;
    // Wrap in double first: uv far outside [0, 1] must not overflow an int.
    const double x_wrapped = xf - w * std::floor(xf / w);
    int x0 = static_cast<int>(x_wrapped);
    if (x0 >= w) x0 -= w;
    const int x1 = x0 + 1 == w ? 0 : x0 + 1;
    const int y0 = static_cast<int>(std::clamp(yf, 0.0, static_cast<double>(h - 1)));
    const int y1 = static_cast<int>(std::clamp(yf + 1.0, 0.0, static_cast<double>(h - 1)));
    const uint8_t* r0 = atlas_.row(y0);
    const uint8_t* r1 = atlas_.row(y1);
    const int ch = atlas_.channels();
    for (int c = 0; c < 3; ++c) {
      const double top = r0[x0 * ch + c] + ax * (r0[x1 * ch + c] - r0[x0 * ch + c]);
      const double bottom = r1[x0 * ch + c] + ax * (r1[x1 * ch + c] - r1[x0 * ch + c]);
      const double value = top + ay * (bottom - top);
      out[c] = static_cast<uint8_t>(std::clamp(std::lround(value), 0L, 255L));
    }
  }

  const Mesh& mesh_;
  ImageView<const uint8_t> atlas_;
  const PinholeView& view_;
  const RenderOptions& options_;
  Plane planes_[kNumPlanes];
  int num_threads_ = 1;
  double eye_[3] = {0, 0, 0};  // The camera centre in the panorama frame.
  std::vector<double> cam_;
  int num_bands_ = 0;
  std::vector<std::vector<uint32_t>> bands_;
  std::vector<float> zbuffer_;
  Image8* color_ = nullptr;
  uint32_t* ids_ = nullptr;  // RenderResult::triangle_ids when wanted.
};

void CheckInputs(const Mesh& mesh, ImageView<const uint8_t> atlas, const PinholeView& view,
                 const RenderOptions& options) {
  const Status options_status = options.Check();
  if (!options_status.ok()) {
    throw std::invalid_argument("render options: " + options_status.message());
  }
  const Status view_status = view.Check();
  if (!view_status.ok()) throw std::invalid_argument("render view: " + view_status.message());
  if (mesh.positions.size() % 3 != 0) {
    throw std::invalid_argument("mesh: positions has " + std::to_string(mesh.positions.size()) +
                                " floats, not a multiple of 3");
  }
  if (mesh.indices.size() % 3 != 0) {
    throw std::invalid_argument("mesh: indices has " + std::to_string(mesh.indices.size()) +
                                " entries, not a multiple of 3");
  }
  const size_t n = mesh.num_vertices();
  if (n > std::numeric_limits<uint32_t>::max() ||
      mesh.num_triangles() > std::numeric_limits<uint32_t>::max()) {
    throw std::invalid_argument("mesh: more than 2^32 vertices or triangles");
  }
  if (options.color_source == ColorSource::kAtlas) {
    if (mesh.uvs.size() != 2 * n) {
      throw std::invalid_argument("mesh: uvs has " + std::to_string(mesh.uvs.size()) +
                                  " floats for " + std::to_string(n) + " vertices (need 2 each)");
    }
    if (atlas.empty() || atlas.channels() < 3) {
      throw std::invalid_argument("colour atlas: need a non-empty RGB image, got " +
                                  Dims(atlas.width(), atlas.height()) + " with " +
                                  std::to_string(atlas.channels()) + " channels");
    }
  }
  if ((options.color_source != ColorSource::kAtlas ||
       options.vertex_colors_from_triangle < mesh.num_triangles()) &&
      mesh.colors.size() != 3 * n) {
    throw std::invalid_argument("mesh: colors has " + std::to_string(mesh.colors.size()) +
                                " bytes for " + std::to_string(n) + " vertices (need 3 each)");
  }
  for (size_t i = 0; i < mesh.indices.size(); ++i) {
    if (mesh.indices[i] >= n) {
      throw std::invalid_argument("mesh: index " + std::to_string(mesh.indices[i]) +
                                  " of triangle " + std::to_string(i / 3) + " is out of range (" +
                                  std::to_string(n) + " vertices)");
    }
  }
}

}  // namespace

Status RenderOptions::Check() const {
  if (!(near_m > 0.0) || !std::isfinite(near_m)) {
    return InvalidArgument("near_m " + std::to_string(near_m) + " must be positive and finite");
  }
  if (!(far_m > near_m) || !std::isfinite(far_m)) {
    return InvalidArgument("far_m " + std::to_string(far_m) +
                           " must be finite and larger than near_m " + std::to_string(near_m));
  }
  if (num_threads < 0 || num_threads > 256) {
    return InvalidArgument("num_threads " + std::to_string(num_threads) +
                           " is out of range [0, 256] (0 = all cores)");
  }
  if (!(sheet_stretch >= 0) || !std::isfinite(sheet_stretch)) {
    return InvalidArgument("sheet_stretch " + std::to_string(sheet_stretch) +
                           " must be finite and at least 0 (0 draws every triangle)");
  }
  return Status::Ok();
}

Status PinholeView::Check() const {
  if (width < 1 || height < 1 || width > kMaxSide || height > kMaxSide) {
    return InvalidArgument("image size " + Dims(width, height) + " is out of range (1 to " +
                           std::to_string(kMaxSide) + " per side)");
  }
  if (!(fx > 0.0) || !(fy > 0.0) || !std::isfinite(fx) || !std::isfinite(fy)) {
    return InvalidArgument("focal lengths must be positive and finite");
  }
  if (!std::isfinite(cx) || !std::isfinite(cy)) {
    return InvalidArgument("principal point must be finite");
  }
  if (!rotation.allFinite() || !translation.allFinite()) {
    return InvalidArgument("view transform must be finite");
  }
  return Status::Ok();
}

PinholeView ViewFromPhoto(const geometry::Camera& camera, const geometry::Pose& pose,
                          const PanoramaFrame& frame) {
  std::string why;
  if (!camera.IsValid(&why)) {
    throw std::invalid_argument("camera " + std::to_string(camera.camera_id) + ": " + why);
  }
  Eigen::Matrix3d frame_rotation;
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) frame_rotation(r, c) = frame.rotation[3 * r + c];
  }
  const Eigen::Vector3d centre(frame.centre[0], frame.centre[1], frame.centre[2]);
  // p_world = F^T p_panorama + centre; x_cam = R_cam p_world + t_cam.
  PinholeView view;
  view.width = camera.width;
  view.height = camera.height;
  view.fx = camera.FocalX();
  view.fy = camera.FocalY();
  view.cx = camera.PrincipalX();
  view.cy = camera.PrincipalY();
  view.rotation = pose.R() * frame_rotation.transpose();
  view.translation = pose.R() * centre + pose.translation;
  return view;
}

PinholeView ViewFromGlCamera(const GlCamera& camera, int width, int height) {
  if (!(std::abs(camera.pitch_deg) < 90.0)) {
    throw std::invalid_argument("viewer camera: pitch_deg " + std::to_string(camera.pitch_deg) +
                                " must be inside (-90, 90)");
  }
  if (!(camera.fov_y_deg > 0.0 && camera.fov_y_deg < 180.0)) {
    throw std::invalid_argument("viewer camera: fov_y_deg " + std::to_string(camera.fov_y_deg) +
                                " must be inside (0, 180)");
  }
  if (!std::isfinite(camera.yaw_deg) || !std::isfinite(camera.position[0]) ||
      !std::isfinite(camera.position[1]) || !std::isfinite(camera.position[2])) {
    throw std::invalid_argument("viewer camera: yaw and position must be finite");
  }
  if (width < 1 || height < 1 || width > kMaxSide || height > kMaxSide) {
    throw std::invalid_argument("viewer camera: image size " + Dims(width, height) +
                                " is out of range (1 to " + std::to_string(kMaxSide) + ")");
  }
  const double yaw = camera.yaw_deg * kPi / 180.0, pitch = camera.pitch_deg * kPi / 180.0;
  const Vec3d f = LonLatToDirection(yaw, pitch);
  const Eigen::Vector3d forward(f.x, f.y, f.z);
  const Eigen::Vector3d right(std::cos(yaw), 0.0, std::sin(yaw));
  const Eigen::Vector3d up = right.cross(forward);
  PinholeView view;
  view.width = width;
  view.height = height;
  view.fy = 0.5 * height / std::tan(0.5 * camera.fov_y_deg * kPi / 180.0);
  view.fx = view.fy;  // Square pixels: the GL aspect is width / height.
  view.cx = 0.5 * width;
  view.cy = 0.5 * height;
  // Camera rows: +X right, +Y down (image rows grow downwards), +Z forward.
  view.rotation.row(0) = right.transpose();
  view.rotation.row(1) = -up.transpose();
  view.rotation.row(2) = forward.transpose();
  const Eigen::Vector3d eye(camera.position[0], camera.position[1], camera.position[2]);
  view.translation = -(view.rotation * eye);
  return view;
}

RenderResult RenderMesh(const Mesh& mesh, ImageView<const uint8_t> atlas, const PinholeView& view,
                        const RenderOptions& options) {
  CheckInputs(mesh, atlas, view, options);
  Rasterizer rasterizer(mesh, atlas, view, options);
  return rasterizer.Run();
}

}  // namespace casual3d::render

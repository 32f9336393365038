#include "reconstruct/warp/warp.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include <Eigen/Core>

namespace casual3d::warp {
namespace {

constexpr double kDegToRad = kPi / 180.0;

// Per-vertex data of the depth-map grid mesh.
struct GridVertex {
  double u = 0, v = 0;     // Panorama pixel coordinates (u not yet unwrapped).
  float z = 0;             // Normalised depth in [0, 1).
  float src_x = 0, src_y = 0;  // Continuous coordinates in the source image.
  Eigen::Vector3d cam = Eigen::Vector3d::Zero();  // Position in the source camera frame.
  bool valid = false;
};

double WrapSigned(double du, double width) {
  // Into [-width/2, width/2).
  du = std::fmod(du + 0.5 * width, width);
  if (du < 0) du += width;
  return du - 0.5 * width;
}

// Bilinear sample of an RGB image at continuous coordinates (COLMAP/ours:
// pixel centres at i + 0.5), clamped at the border.
void SampleBilinear(const Image8& img, float x, float y, uint8_t out[3]) {
  const float fx = std::clamp(x - 0.5f, 0.0f, static_cast<float>(img.width() - 1));
  const float fy = std::clamp(y - 0.5f, 0.0f, static_cast<float>(img.height() - 1));
  const int x0 = static_cast<int>(fx), y0 = static_cast<int>(fy);
  const int x1 = std::min(x0 + 1, img.width() - 1), y1 = std::min(y0 + 1, img.height() - 1);
  const float ax = fx - x0, ay = fy - y0;
  for (int c = 0; c < 3; ++c) {
    const float top = img.at(x0, y0, c) * (1 - ax) + img.at(x1, y0, c) * ax;
    const float bottom = img.at(x0, y1, c) * (1 - ax) + img.at(x1, y1, c) * ax;
    out[c] = static_cast<uint8_t>(std::lround(top * (1 - ay) + bottom * ay));
  }
}

// Accumulates fragments of one view into its front and back crops.
class LayerRasterizer {
 public:
  LayerRasterizer(int pano_width, int pano_height, int x0, int y0, int crop_width,
                  int crop_height, const Image8& source, double near_m)
      : pano_width_(pano_width), pano_height_(pano_height), x0_(x0), y0_(y0),
        crop_width_(crop_width), crop_height_(crop_height), source_(source), near_m_(near_m),
        front_key_(crop_width, crop_height, 1, std::numeric_limits<float>::infinity()),
        back_key_(crop_width, crop_height, 1, std::numeric_limits<float>::infinity()) {
    for (WarpedLayer* layer : {&result_.front, &result_.back}) {
      layer->x0 = x0;
      layer->y0 = y0;
      layer->rgb = Image8(crop_width, crop_height, 3, 0);
      layer->depth_m = ImageF(crop_width, crop_height, 1, 0.0f);
      layer->stretch = ImageF(crop_width, crop_height, 1, 0.0f);
    }
  }

  // Rasterizes triangle (a, b, c) whose u coordinates are already unwrapped
  // consistently. `stretch` is the triangle's stretch penalty.
  void Triangle(const GridVertex& a, double ua, const GridVertex& b, double ub,
                const GridVertex& c, double uc, float stretch) {
    // Place the triangle relative to the crop (see WarpView for the unwrap).
    const double crop_centre = x0_ + 0.5 * crop_width_;
    const double umin = std::min({ua, ub, uc});
    const double shift = crop_centre + WrapSigned(umin - crop_centre, pano_width_) - umin;
    ua += shift;
    ub += shift;
    uc += shift;
    const double va = a.v, vb = b.v, vc = c.v;
    const double area = (ub - ua) * (vc - va) - (uc - ua) * (vb - va);
    if (std::abs(area) < 1e-12) return;
    const double inv_area = 1.0 / area;
    const int col_begin = static_cast<int>(std::ceil(std::min({ua, ub, uc}) - 0.5));
    const int col_end = static_cast<int>(std::floor(std::max({ua, ub, uc}) - 0.5));
    const int row_begin = std::max(0, static_cast<int>(std::ceil(std::min({va, vb, vc}) - 0.5)));
    const int row_end =
        std::min(pano_height_ - 1, static_cast<int>(std::floor(std::max({va, vb, vc}) - 0.5)));
    for (int row = row_begin; row <= row_end; ++row) {
      const double py = row + 0.5;
      const int cy = row - y0_;
      if (cy < 0 || cy >= crop_height_) continue;
      for (int col = col_begin; col <= col_end; ++col) {
        const double px = col + 0.5;
        // Barycentric weights via edge functions; the sign convention makes
        // them positive inside for either winding.
        double w0 = ((ub - px) * (vc - py) - (uc - px) * (vb - py)) * inv_area;
        double w1 = ((uc - px) * (va - py) - (ua - px) * (vc - py)) * inv_area;
        double w2 = 1.0 - w0 - w1;
        if (w0 < 0 || w1 < 0 || w2 < 0) continue;
        // Pixels on a shared edge may be drawn by both triangles; they carry
        // the same depth there, so the depth test makes that harmless.
        int cx = col - x0_;
        if (crop_width_ == pano_width_) {
          cx %= pano_width_;
          if (cx < 0) cx += pano_width_;
        }
        if (cx < 0 || cx >= crop_width_) continue;
        const float z = static_cast<float>(w0 * a.z + w1 * b.z + w2 * c.z);
        const float front_key = 0.5f * (z + stretch);
        const float back_key = 0.5f * (1.0f - z + stretch);
        const bool front_wins = front_key < front_key_.at(cx, cy);
        const bool back_wins = back_key < back_key_.at(cx, cy);
        if (!front_wins && !back_wins) continue;
        const float sx = static_cast<float>(w0 * a.src_x + w1 * b.src_x + w2 * c.src_x);
        const float sy = static_cast<float>(w0 * a.src_y + w1 * b.src_y + w2 * c.src_y);
        uint8_t rgb[3];
        SampleBilinear(source_, sx, sy, rgb);
        const float depth = static_cast<float>(near_m_ / (1.0 - z));
        if (front_wins) Store(&result_.front, &front_key_, cx, cy, front_key, rgb, depth, stretch);
        if (back_wins) Store(&result_.back, &back_key_, cx, cy, back_key, rgb, depth, stretch);
      }
    }
  }

  WarpedView Take() { return std::move(result_); }

 private:
  static void Store(WarpedLayer* layer, ImageF* keys, int cx, int cy, float key,
                    const uint8_t rgb[3], float depth, float stretch) {
    keys->at(cx, cy) = key;
    for (int c = 0; c < 3; ++c) layer->rgb.at(cx, cy, c) = rgb[c];
    layer->depth_m.at(cx, cy) = depth;
    layer->stretch.at(cx, cy) = stretch;
  }

  int pano_width_, pano_height_, x0_, y0_, crop_width_, crop_height_;
  const Image8& source_;
  double near_m_;
  ImageF front_key_, back_key_;
  WarpedView result_;
};

// True if the panorama direction `dir` (panorama frame) falls inside the
// view's image, in front of the camera.
bool DirectionInView(const Eigen::Vector3d& dir_pano, const Eigen::Matrix3d& R_cam_from_pano,
                     const geometry::Camera& camera) {
  const Eigen::Vector3d d = R_cam_from_pano * dir_pano;
  if (d.z() <= 1e-9) return false;
  const double x = camera.FocalX() * d.x() / d.z() + camera.PrincipalX();
  const double y = camera.FocalY() * d.y() / d.z() + camera.PrincipalY();
  return x >= 0 && y >= 0 && x <= camera.width && y <= camera.height;
}

}  // namespace

bool WarpedLayer::ToCrop(int x, int y, int pano_width, int* cx, int* cy) const {
  *cy = y - y0;
  if (*cy < 0 || *cy >= height()) return false;
  int dx = x - x0;
  dx %= pano_width;
  if (dx < 0) dx += pano_width;
  *cx = dx;
  return dx < width();
}

WarpedView WarpView(const SourceView& view, const PanoramaFrame& frame,
                    const WarpOptions& options) {
  if (const Status st = options.Check(); !st.ok())
    throw std::invalid_argument("warp options: " + st.message());
  if (view.rgb == nullptr || view.depth_m == nullptr || view.rgb->channels() != 3 ||
      view.depth_m->channels() != 1 || view.rgb->empty() || view.depth_m->empty()) {
    throw std::invalid_argument("warp: a view needs an RGB image and a 1-channel depth map");
  }
  const int W = options.pano_width, H = options.pano_height;
  const ImageF& depth = *view.depth_m;
  const Image8& rgb = *view.rgb;
  const geometry::Camera& cam = view.camera;
  // Depth-map pixel (i, j) centre maps to image coordinates through this scale.
  const double scale_x = static_cast<double>(cam.width) / depth.width();
  const double scale_y = static_cast<double>(cam.height) / depth.height();
  const double img_scale_x = static_cast<double>(rgb.width()) / cam.width;
  const double img_scale_y = static_cast<double>(rgb.height()) / cam.height;

  Eigen::Matrix3d R_pano_from_world;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) R_pano_from_world(r, c) = frame.rotation[3 * r + c];
  const Eigen::Vector3d centre(frame.centre[0], frame.centre[1], frame.centre[2]);
  const Eigen::Matrix3d R_world_from_cam = view.pose.R().transpose();
  const Eigen::Vector3d cam_centre = view.pose.Center();
  // Panorama-frame position of a camera-frame point: R_pw (R_wc q + C - c).
  const Eigen::Matrix3d R_pano_from_cam = R_pano_from_world * R_world_from_cam;
  const Eigen::Vector3d t_pano = R_pano_from_world * (cam_centre - centre);

  const int gw = depth.width(), gh = depth.height();
  std::vector<GridVertex> grid(static_cast<size_t>(gw) * gh);
  const double fx = cam.FocalX(), fy = cam.FocalY(), cx = cam.PrincipalX(), cy = cam.PrincipalY();
  for (int j = 0; j < gh; ++j) {
    for (int i = 0; i < gw; ++i) {
      GridVertex& gv = grid[static_cast<size_t>(j) * gw + i];
      const float d = depth.at(i, j);
      if (!(d > 0) || !std::isfinite(d)) continue;
      const double px = (i + 0.5) * scale_x, py = (j + 0.5) * scale_y;
      gv.cam = Eigen::Vector3d((px - cx) / fx * d, (py - cy) / fy * d, d);
      const Eigen::Vector3d p = R_pano_from_cam * gv.cam + t_pano;
      const double r = p.norm();
      if (!(r > options.near_m)) continue;
      DirectionToEquirectPixel({p.x(), p.y(), p.z()}, W, H, &gv.u, &gv.v);
      gv.z = static_cast<float>(1.0 - options.near_m / r);
      gv.src_x = static_cast<float>(px * img_scale_x);
      gv.src_y = static_cast<float>(py * img_scale_y);
      gv.valid = true;
    }
  }

  // Crop: unwrap columns around the view's optical axis; the full width if a
  // pole is in view or the view covers (almost) all longitudes.
  const Eigen::Vector3d axis = R_pano_from_cam * Eigen::Vector3d::UnitZ();
  double u_axis, v_axis;
  DirectionToEquirectPixel({axis.x(), axis.y(), axis.z()}, W, H, &u_axis, &v_axis);
  double umin = std::numeric_limits<double>::infinity(), umax = -umin;
  double vmin = umin, vmax = -umin;
  for (const GridVertex& gv : grid) {
    if (!gv.valid) continue;
    const double u = u_axis + WrapSigned(gv.u - u_axis, W);
    umin = std::min(umin, u);
    umax = std::max(umax, u);
    vmin = std::min(vmin, gv.v);
    vmax = std::max(vmax, gv.v);
  }
  if (!(umax >= umin)) {  // No valid depth at all: an empty warp.
    WarpedView empty;
    for (WarpedLayer* layer : {&empty.front, &empty.back}) {
      layer->rgb = Image8(1, 1, 3, 0);
      layer->depth_m = ImageF(1, 1, 1, 0.0f);
      layer->stretch = ImageF(1, 1, 1, 0.0f);
    }
    return empty;
  }
  const Eigen::Matrix3d R_cam_from_pano = R_pano_from_cam.transpose();
  const bool north = DirectionInView(Eigen::Vector3d(0, 1, 0), R_cam_from_pano, cam);
  const bool south = DirectionInView(Eigen::Vector3d(0, -1, 0), R_cam_from_pano, cam);
  int x0, crop_w;
  if (north || south || umax - umin > W - 4) {
    x0 = 0;
    crop_w = W;
  } else {
    const int first = static_cast<int>(std::floor(umin)) - 1;
    x0 = WrapColumn(first, W);
    crop_w = std::min(W, static_cast<int>(std::ceil(umax)) + 1 - first);
  }
  const int y0 = north ? 0 : std::max(0, static_cast<int>(std::floor(vmin)) - 1);
  const int y1 = south ? H : std::min(H, static_cast<int>(std::ceil(vmax)) + 1);

  LayerRasterizer raster(W, H, x0, y0, crop_w, std::max(1, y1 - y0), rgb, options.near_m);
  const double tau_rad = options.tau_stretch_deg * kDegToRad;
  const double max_span = options.max_triangle_width_fraction * W;
  const double min_ratio = options.min_edge_depth_ratio;
  auto emit = [&](const GridVertex& a, const GridVertex& b, const GridVertex& c) {
    if (!a.valid || !b.valid || !c.valid) return;
    const double ua = a.u;
    const double ub = ua + WrapSigned(b.u - ua, W);
    const double uc = ua + WrapSigned(c.u - ua, W);
    if (std::max({ua, ub, uc}) - std::min({ua, ub, uc}) > max_span) return;
    if (min_ratio > 0) {
      // The depth-map values (z in the photo's camera frame).
      const double da = a.cam.z(), db = b.cam.z(), dc = c.cam.z();
      if (std::min({da, db, dc}) < min_ratio * std::max({da, db, dc})) return;
    }
    // Eq. 6: grazing angle between the triangle and the ray from the photo's camera.
    const Eigen::Vector3d n = (b.cam - a.cam).cross(c.cam - a.cam);
    const Eigen::Vector3d ray = a.cam + b.cam + c.cam;
    const double nn = n.norm(), rn = ray.norm();
    double stretch = 1.0;
    if (nn > 0 && rn > 0) {
      const double alpha = std::asin(std::min(1.0, std::abs(n.dot(ray)) / (nn * rn)));
      stretch = 1.0 - std::min(alpha / tau_rad, 1.0);
    }
    raster.Triangle(a, ua, b, ub, c, uc, static_cast<float>(stretch));
  };
  for (int j = 0; j + 1 < gh; ++j) {
    for (int i = 0; i + 1 < gw; ++i) {
      const GridVertex& v00 = grid[static_cast<size_t>(j) * gw + i];
      const GridVertex& v10 = grid[static_cast<size_t>(j) * gw + i + 1];
      const GridVertex& v01 = grid[static_cast<size_t>(j + 1) * gw + i];
      const GridVertex& v11 = grid[static_cast<size_t>(j + 1) * gw + i + 1];
      emit(v00, v10, v11);
      emit(v00, v11, v01);
    }
  }
  return raster.Take();
}

}  // namespace casual3d::warp

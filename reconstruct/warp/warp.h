#pragma once

// Front and back surface warping (paper Sec. 4.4.1).
//
// Each photo's depth map is triangulated into a grid mesh (vertices at pixel
// centres) and rasterized into the central equirectangular panorama of the 3D
// photo (format/equirect.h). Two depth tests run in one pass:
//   front: keeps the fragment with the smallest z' = (z + s) / 2,
//   back:  keeps the fragment with the smallest z'' = (1 - z + s) / 2,
// where z in [0, 1] grows with the distance from the panorama centre and
// s in [0, 1] is the stretch penalty of Eq. 6, s = 1 - min(alpha / tau_stretch, 1),
// with alpha the grazing angle between the triangle and the ray from the
// photo's own camera. The paper writes the back test as z'' = 1 - z'; applied
// literally that would prefer the most stretched triangles, so the back test
// here inverts only the depth and keeps the stretch penalty (spec/stage-panorama.md).
//
// Outputs are cropped to the columns and rows the photo covers, so that many
// photos fit in memory at 8192x4096.

#include <cstdint>
#include <string>
#include <vector>

#include "format/equirect.h"
#include "format/image.h"
#include "reconstruct/geometry/camera.h"
#include "reconstruct/geometry/pose.h"
#include "reconstruct/util/options_fields.h"

namespace casual3d::warp {

struct WarpOptions {
  // Panorama size in pixels; width must be 2 * height (equirectangular).
  int pano_width = 4096;
  int pano_height = 2048;
  // Sec. 4.4.1: grazing angle below which a triangle counts as stretched, degrees.
  double tau_stretch_deg = 1.66;
  // Depth normalisation: z = 1 - near_m / r, clamped to [0, 1]; metres, > 0.
  double near_m = 0.05;
  // Triangles whose projection spans more than this fraction of the panorama
  // width are dropped (they wrap around a pole); (0, 0.5].
  double max_triangle_width_fraction = 0.125;
  // Triangles whose vertices' depth-map values have a ratio
  // min / max below this span a depth edge of the photo: they are not drawn,
  // so that no ramp of made-up depths between the two sides (a rubber sheet)
  // reaches the panorama; the gap is filled by other photos, the gap filling
  // and the back layer. [0, 1); 0 draws every triangle. At 0.9 a floor
  // keeps its triangles down to about 0.6 degrees of grazing (adjacent
  // photo pixels 1 mrad apart); measurements: docs/DECISIONS.md, "Warp: no
  // triangles across a photo's depth edges".
  double min_edge_depth_ratio = 0.9;

  // Returns an empty string if valid, else "field value: reason".
  template <typename Self, typename Visitor>
  static void DescribeFields(Self& o, Visitor& v) {
    using R = util::Rule;
    v.Field("pano_width", o.pano_width, R::Closed(1, 65536), "Panorama width, pixels (the panorama stage sets it)");
    v.Field("pano_height", o.pano_height, R::AtLeast(1), "Panorama height, pixels: width / 2");
    v.Field("tau_stretch_deg", o.tau_stretch_deg, R::Open(0, 90), "Grazing angle below which a triangle is stretched, degrees (Sec. 4.4.1)");
    v.Field("near_m", o.near_m, R::Above(0), "Depth normalisation z = 1 - near_m / r, metres");
    v.Field("max_triangle_width_fraction", o.max_triangle_width_fraction, R::OpenClosed(0, 0.5),
            "Triangles wider than this fraction of the panorama are dropped");
    v.Field("min_edge_depth_ratio", o.min_edge_depth_ratio, R::ClosedOpen(0, 1),
            "Triangles whose depth ratio min / max is below this are not drawn; 0 draws all");
    v.Require(o.pano_width == 2 * o.pano_height, "pano_width", "must be 2 * pano_height");
  }
  Status Check() const { return util::CheckFields(*this); }
};

// One photo with its depth map. The camera must be undistorted (pinhole part
// is used); depth is metres along the optical axis, same size as the image or
// a uniformly scaled version of it; non-finite or <= 0 depth means "no depth".
struct SourceView {
  const Image8* rgb = nullptr;      // 3 channels, sRGB.
  const ImageF* depth_m = nullptr;  // 1 channel.
  geometry::Camera camera;
  geometry::Pose pose;  // World to camera.
};

// One warped layer of one photo, cropped. Panorama pixel (x, y) with
// x = WrapColumn(x0 + cx), y = y0 + cy is stored at crop pixel (cx, cy).
struct WarpedLayer {
  int x0 = 0;  // First column (may be any value in [0, pano_width)).
  int y0 = 0;  // First row.
  Image8 rgb;       // 3 channels; valid where depth_m > 0.
  ImageF depth_m;   // Distance from the panorama centre along the ray; 0 = empty.
  ImageF stretch;   // Stretch penalty s in [0, 1] of the winning fragment.

  int width() const { return depth_m.width(); }
  int height() const { return depth_m.height(); }
  // Crop coordinates of panorama pixel (x, y); false if outside the crop.
  bool ToCrop(int x, int y, int pano_width, int* cx, int* cy) const;
};

struct WarpedView {
  WarpedLayer front;
  WarpedLayer back;
};

// Warps one view. Throws std::invalid_argument on invalid options or inputs.
WarpedView WarpView(const SourceView& view, const PanoramaFrame& frame, const WarpOptions& options);

}  // namespace casual3d::warp

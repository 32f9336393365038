#pragma once

// Native software renderer of a 3D photo's mesh (format/mesh.h): colour, depth
// and coverage seen by a pinhole camera. It is the reference for virtual
// rephotography (paper Sec. 6.3: render the 3D photo from each photo's pose and
// compare) and for the WebGL viewer's browser test, so it samples and fills
// exactly as documented here and as wasm-viewer/js/renderer.js does.
//
// Rasterization rules:
//  * Pixel (i, j) (row 0 at the top of the image) is covered by a triangle when
//    its centre (i + 0.5, j + 0.5) lies inside the triangle's projection, with
//    vertex positions snapped to 1/4096 pixel and the top-left rule deciding
//    centres exactly on an edge: triangles sharing an edge cover every pixel
//    along it exactly once (no cracks, no double coverage).
//  * Triangles are clipped against the near and far planes (camera-frame depth
//    near_m <= z <= far_m) before projection; attributes are interpolated
//    perspective-correctly. Back faces are drawn (no culling).
//  * Z-buffer on the camera-frame depth z (metres along the optical axis); of
//    triangles at exactly the same depth the one earlier in the index list wins.
//  * Colour: bilinear sampling of the colour atlas at the interpolated uv, as
//    OpenGL's LINEAR filter without mipmaps: texel (x, y) has its centre at
//    ((x + 0.5) / width, (y + 0.5) / height) in uv; columns wrap (REPEAT, the
//    panorama's +-180 degree seam), rows clamp to the atlas (CLAMP_TO_EDGE).
//    Values are interpolated in the stored (sRGB) encoding and rounded to the
//    nearest integer. Alternatively, Mesh::colors interpolated per vertex.
//  * Output is deterministic: the same input gives the same bytes for any
//    thread count.

#include <Eigen/Core>
#include <cstdint>

#include "format/equirect.h"
#include "format/image.h"
#include "format/mesh.h"
#include "format/status.h"
#include "reconstruct/geometry/camera.h"
#include "reconstruct/geometry/pose.h"

namespace casual3d::render {

enum class ColorSource {
  kAtlas,         // Bilinear sample of the colour atlas at Mesh::uvs.
  kVertexColors,  // Mesh::colors interpolated across each triangle.
};

struct RenderOptions {
  ColorSource color_source = ColorSource::kAtlas;
  // With kAtlas: triangles from this index on take Mesh::colors instead (a
  // backdrop appended to the mesh, format/backdrop.h, as the viewer draws it).
  uint64_t vertex_colors_from_triangle = UINT64_MAX;
  // Triangles before vertex_colors_from_triangle that look more than this
  // many times larger from the view's eye than from the panorama's centre
  // (format/sheet_stretch.h: sheets across depth steps) are not drawn, as the
  // viewer does where it draws the backdrop; 0 draws every triangle. >= 0.
  double sheet_stretch = 0.0;
  // Clipping planes, metres along the optical axis; 0 < near_m < far_m. The
  // defaults are the WebGL viewer's (wasm-viewer/js/camera.js).
  double near_m = 0.05;
  double far_m = 2000.0;
  // Colour of uncovered pixels (RGB).
  uint8_t background[3] = {0, 0, 0};
  // Worker threads; 0 uses all cores. Range [0, 256]. Does not change output.
  int num_threads = 0;
  // Also output, per pixel, the index of the triangle that drew it
  // (RenderResult::triangle_ids); off by default, costing nothing then.
  bool want_triangle_ids = false;

  // InvalidArgument naming the first field out of range.
  Status Check() const;
};

struct RenderResult {
  Image8 color;  // width x height x 3, RGB; `background` where uncovered.
  ImageF depth;  // width x height x 1, camera-frame z in metres; 0 where uncovered.
  Image8 mask;   // width x height x 1, 255 where covered, 0 elsewhere.
  int64_t covered_pixels = 0;
  // Only with RenderOptions::want_triangle_ids: width x height x 1, the index
  // (into Mesh::indices / 3) of the triangle whose fragment won the z-test at
  // each pixel, kNoTriangle where uncovered. Empty otherwise.
  Image<uint32_t> triangle_ids;
};

constexpr uint32_t kNoTriangle = 0xffffffffu;

// A pinhole view of the panorama frame (format/equirect.h):
//   x_cam = rotation * p_panorama + translation
// in a camera frame with +X right, +Y down, +Z forward (COLMAP's), then
//   pixel = (fx * x / z + cx, fy * y / z + cy)
// with pixel centres at (i + 0.5, j + 0.5) (spec/projection.md Sec. 1).
struct PinholeView {
  int width = 0;                          // Pixels, 1 to 16384.
  int height = 0;                         // Pixels, 1 to 16384.
  double fx = 0, fy = 0, cx = 0, cy = 0;  // Pixels; fx, fy > 0.
  Eigen::Matrix3d rotation = Eigen::Matrix3d::Identity();
  Eigen::Vector3d translation = Eigen::Vector3d::Zero();

  // InvalidArgument if the size, focal lengths or transform are unusable.
  Status Check() const;
};

// The view of a photo: the camera's pinhole part (distortion is ignored: the
// rendering is of an undistorted photo with the same intrinsics; see
// photo_renderer.h for rendering with the distortion) at `pose`
// (world to camera), with `frame` relating the world to the panorama frame
// (p_panorama = R_frame * (p_world - centre)).
PinholeView ViewFromPhoto(const geometry::Camera& camera, const geometry::Pose& pose,
                          const PanoramaFrame& frame);

// An OpenGL-style viewer camera in the panorama frame, as the WebGL viewer
// (wasm-viewer/js/camera.js) defines it.
struct GlCamera {
  double position[3] = {0, 0, 0};  // Eye, panorama frame, metres.
  // Longitude of the viewing direction: 0 looks along -Z, +90 along +X.
  double yaw_deg = 0.0;
  // Latitude of the viewing direction: +90 looks up (+Y). Range (-90, 90).
  double pitch_deg = 0.0;
  // Vertical field of view, degrees. Range (0, 180).
  double fov_y_deg = 75.0;
};

// The view of `camera` rendered into a width x height image, matching WebGL:
// forward f = LonLatToDirection(yaw, pitch), right = (cos yaw, 0, sin yaw),
// up = right x f (no roll); the perspective matrix is OpenGL's with
// aspect = width / height, so fy = fx = (height / 2) / tan(fov_y / 2) and
// (cx, cy) = (width / 2, height / 2). Row 0 is the TOP of the screen: WebGL's
// readPixels returns the bottom row first, PNG screenshots the top row first.
// Throws std::invalid_argument if pitch, fov or the size is out of range.
PinholeView ViewFromGlCamera(const GlCamera& camera, int width, int height);

// Renders `mesh` (positions in the panorama frame, metres) seen by `view`.
// `atlas` is the colour atlas the uvs refer to (RGB, 3 channels; mesh.h: front
// colour panorama above the back one); it may be empty when
// options.color_source is kVertexColors. Throws std::invalid_argument naming
// the input when options, view, atlas or mesh are inconsistent (array sizes,
// an index out of range).
RenderResult RenderMesh(const Mesh& mesh, ImageView<const uint8_t> atlas, const PinholeView& view,
                        const RenderOptions& options = {});

}  // namespace casual3d::render

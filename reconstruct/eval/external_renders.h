#pragma once

// Rephotography of renderings made elsewhere: another renderer of the same 3D
// photo (three.js showing the GLB that `casual3d export` wrote, a game engine,
// a second implementation of the format) is given the evaluated photos'
// cameras, renders one image per photo, and `casual3d evaluate` scores those
// images exactly as it scores its own renderings.
//
// Cameras (RephotoCamerasJson): a JSON document
//   {"format": "casual3d-rephoto-cameras", "version": 1,
//    "frame": "panorama",   // = glTF: +X right, +Y up, -Z forward; metres or model units
//    "near": n, "far": f,   // clip planes the native rephotography uses
//    "cameras": [{"name": "IMG_4026.JPG", "image": "IMG_4026.png",
//                 "width": W, "height": H, "fx": .., "fy": .., "cx": .., "cy": ..,
//                 "view_matrix": [16], "projection_matrix": [16]}, ...]}
// Pixel centres are at (i + 0.5, j + 0.5) with row 0 at the top
// (spec/projection.md Sec. 1). view_matrix takes a point of the panorama
// frame to OpenGL's eye frame (+X right, +Y up, looking along -Z);
// projection_matrix is OpenGL's clip transform for the intrinsics, the clip
// planes and a viewport of W x H with row 0 at the top of the image. Both
// are column-major, as WebGL and three.js's Matrix4.fromArray take them.
//
// Renderings (ReadExternalRender): DIR/<image> per camera, a PNG of W x H
// pixels, RGBA (alpha 0 where the renderer drew nothing) or RGB (every pixel
// covered).

#include <string>
#include <vector>

#include "format/image.h"
#include "reconstruct/render/mesh_renderer.h"

namespace casual3d::eval {

struct NamedView {
  std::string name;  // The photo's file name.
  render::PinholeView view;
};

// The file name of the rendering of photo `name`: its stem with ".png".
std::string ExternalRenderName(const std::string& name);

// OpenGL's column-major view and projection matrices of `view` (see above).
void GlMatrices(const render::PinholeView& view, double near, double far, double view_matrix[16],
                double projection_matrix[16]);

// The cameras document above. Throws std::invalid_argument when near/far are
// not 0 < near < far or a view fails PinholeView::Check.
std::string RephotoCamerasJson(const std::vector<NamedView>& views, double near, double far);

// The views of a cameras document (RephotoCamerasJson's inverse, for tools
// that render from it), in its order. Throws std::runtime_error naming
// `path` when it cannot be read, is not such a document, or a view fails
// PinholeView::Check.
std::vector<NamedView> ReadRephotoCameras(const std::string& path);

struct ExternalRender {
  Image8 color;  // width x height x 3.
  Image8 mask;   // width x height x 1: 255 where covered.
};

// Reads DIR/ExternalRenderName(name). Throws std::runtime_error naming the
// file when it is missing, not a PNG/decodable image, or not width x height.
ExternalRender ReadExternalRender(const std::string& dir, const std::string& name, int width,
                                  int height);

}  // namespace casual3d::eval

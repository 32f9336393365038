#pragma once

// A tiny ray-cast scene with exact depth for the dense stage's tests: textured
// (or uniformly coloured) fronto-parallel rectangles (a far wall, a near
// board, a thin pole) in front of a textureless sky, seen by pinhole cameras
// looking along +Z. Test-only.

#include <array>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "format/image.h"
#include "reconstruct/depth/view.h"

namespace casual3d::depth::testing {

struct ToyRect {
  double z = 1.0;                      // Plane Z = z (world), metres.
  double x0 = -1, x1 = 1, y0 = -1, y1 = 1;  // Extent, metres.
  double cells_per_m = 20.0;           // Texture frequency; 0 = uniform `color`.
  unsigned seed = 1;
  std::array<float, 3> color = {0.5f, 0.5f, 0.5f};  // RGB of an untextured rectangle.
};

struct ToyScene {
  std::vector<ToyRect> rects;
  // The default: wall at 6 m (top part open to the sky), board at 2 m, pole at 1.2 m.
  static ToyScene Default();
};

struct ToyShot {
  ImageF color;  // RGB in [0, 1].
  ImageF depth;  // Metres along the optical axis, +inf for sky.
};

// Renders `scene` from `camera` (2x2 supersampled colour, centre-ray depth).
ToyShot Render(const ToyScene& scene, const PinholeCamera& camera, double gain = 1.0,
               double offset = 0.0);

// A DenseView of a rendering (grey = luma of the colour), with `range`.
DenseView MakeView(const ToyScene& scene, const PinholeCamera& camera, DepthRange range,
                   double gain = 1.0, double offset = 0.0, ImageF* depth = nullptr);

// A camera with R = I at centre `c` (world = camera axes), size w x h, focal f.
PinholeCamera ToyCamera(const Eigen::Vector3d& c, int w, int h, double f);

// Writes a dense-stage workspace: images/NNNN.png, sparse/ (text COLMAP model
// with points sampled on the surfaces and their tracks) and gt/NNNN.exr
// ("Z", +inf sky). Cameras on a `rows` x `cols` grid with `spacing` metres.
void WriteToyWorkspace(const std::string& dir, const ToyScene& scene, int rows, int cols,
                       double spacing, int w, int h, double f);

}  // namespace casual3d::depth::testing

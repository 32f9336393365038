#pragma once

// The triangle mesh of a 3D photo (spec/: "Mesh construction"): built from a
// TwoLayerPanorama so that triangles exist exactly where nodes are linked, depth
// edges stay open and the back layer fills disocclusions. The same sources build
// natively and with Emscripten and must give the same mesh.

#include <cstdint>
#include <vector>

#include "format/status.h"
#include "format/two_layer.h"

namespace casual3d {

// Vertex arrays are parallel; one vertex per used node (plus duplicates where
// the +-180 degree seam needs u = 1 instead of u = 0).
struct Mesh {
  std::vector<float> positions;  // x, y, z per vertex: panorama frame, metres.
  std::vector<float> normals;    // x, y, z per vertex; (0, 0, 0) where unlit.
  // u, v per vertex into the colour atlas: the front layer's colour panorama
  // (width x height) stacked above the back layer's (the atlas is width x
  // 2*height); the centre of node (x, y, layer) is at
  // ((x + 0.5) / width, (y + 0.5 + layer * height) / (2 * height)).
  std::vector<float> uvs;
  std::vector<uint8_t> colors;    // r, g, b per vertex (sRGB), the node's colour.
  std::vector<uint32_t> indices;  // 3 per triangle, counter-clockwise seen from the centre.

  size_t num_vertices() const { return positions.size() / 3; }
  size_t num_triangles() const { return indices.size() / 3; }
};

}  // namespace casual3d

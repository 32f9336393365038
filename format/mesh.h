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

// Vertex arrays are parallel; one vertex per used node, plus copies of nodes
// whose uv points into the other layer's half of the atlas (below), plus
// copies of the column-0 nodes that triangles across the +-180 degree seam
// use, with u = (width + 0.5) / width: textures must repeat horizontally
// (spec/mesh.md).
struct Mesh {
  std::vector<float> positions;  // x, y, z per vertex: panorama frame, metres.
  std::vector<float> normals;    // x, y, z per vertex; (0, 0, 0) where unlit.
  // u, v per vertex into the colour atlas (format/color_atlas.h): the front
  // layer's colour panorama (width x height) stacked above the back layer's
  // (the atlas is width x 2*height), each half filled with the other layer's
  // colour where its own node is absent. A vertex of node (x, y, layer) has
  // uv ((x + 0.5) / width, (y + 0.5 + half * height) / (2 * height)), where
  // half is the atlas half of its triangles: its own layer, except in a
  // triangle joining front and back nodes, which samples one half only so
  // that interpolation never crosses the rows between the halves
  // (spec/mesh.md Sec. 4.4).
  std::vector<float> uvs;
  std::vector<uint8_t> colors;    // r, g, b per vertex (sRGB), the node's colour.
  std::vector<uint32_t> indices;  // 3 per triangle, counter-clockwise seen from the centre.

  size_t num_vertices() const { return positions.size() / 3; }
  size_t num_triangles() const { return indices.size() / 3; }
};

}  // namespace casual3d

#pragma once

// Which mesh of a panorama to build: shared by build_mesh and export_glb.

#include <cstdint>

#include "format/mesh.h"
#include "format/mesh_simplify.h"
#include "format/status.h"
#include "format/two_layer.h"

namespace casual3d::python {

struct MeshChoice {
  // false: the full mesh (format/mesh_builder.h), one vertex per node;
  // true: the simplified mesh (format/mesh_simplify.h) under the two limits.
  bool simplify = true;
  int64_t max_triangles = MeshSimplifyOptions().max_triangles;
  double max_relative_error = MeshSimplifyOptions().max_relative_error;
  bool include_back_layer = true;
  int num_threads = 0;  // 0: all hardware threads.
};

// Builds the chosen mesh of `pano` (validating it first). For a simplified
// mesh, `facts` receives the simplifier's figures (its mesh moved out).
StatusOr<Mesh> BuildAnyMesh(const TwoLayerPanorama& pano, const MeshChoice& choice,
                            SimplifiedMesh* facts);

}  // namespace casual3d::python

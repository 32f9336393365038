#pragma once

// Grid-aware simplification of the 3D photo mesh (spec/mesh.md Sec. 5).
//
// Works on the two-layer panorama rather than on a triangle soup: square
// blocks of 2^k x 2^k pixel quads whose nodes all belong to one layer, are
// linked around every quad (so the block has no open depth edge inside) and
// lie within a thin slab around a plane are replaced by a coarse patch over
// the block's corners. Blocks form a quadtree; a patch takes every vertex that
// neighbouring geometry uses on its border (a fan from a corner or from the
// block's centre node), so the result has no cracks between levels and open
// edges stay open.
//
// Error bound: each merged block's original nodes and patch vertices lie in a
// slab |n.p - c| <= delta with 2 delta / (|c| - delta) <= the block's error e.
// Along any ray from the centre through that slab, the depths of the original
// surface and of the patch therefore differ by at most e relative to the
// original depth. The reported bound is the largest e of the merged blocks.
//
// Standard library only; results are identical natively and in wasm (the same
// arithmetic as mesh_builder.h, no unordered containers).

#include <cstdint>

#include "format/mesh.h"
#include "format/mesh_builder.h"
#include "format/status.h"
#include "format/two_layer.h"

namespace casual3d {

struct MeshSimplifyOptions {
  // Triangle budget. The result is the finest mesh (the smallest error
  // threshold) with at most this many triangles, never coarser than
  // max_relative_error allows. 0: as coarse as max_relative_error allows.
  // Range [0, 2^31]. The default fits the 4096 x 2048 ground truth of the
  // default synthetic scene (26.6 M triangles in full, 0.62 M at 1 %).
  int64_t max_triangles = 1000000;
  // Largest relative depth error of a merged block (see above), a fraction of
  // the depth: 0.01 = 1 %. Range (0, 0.5].
  double max_relative_error = 0.01;
  // Largest merged block, in pixel quads per side: a power of two in [2, 256].
  // 128 lets the sky and large walls of a 4096-wide panorama merge at 1 %.
  int max_block_size = 128;
  // As MeshBuildOptions.
  bool include_back_layer = true;
  bool validate_input = true;
  int64_t max_pixels = int64_t{8192} * 4096;
  // Threads for the per-pixel passes (format/parallel.h); 0: all hardware
  // threads. The mesh does not depend on it. Range [0, 256].
  int num_threads = 0;

  // InvalidArgument naming the field when a value is out of range.
  Status Check() const;
};

struct SimplifiedMesh {
  Mesh mesh;
  // Largest relative depth error of any merged block (0 if none was merged).
  double error_bound = 0.0;
  // Triangles of BuildMesh() on the same panorama.
  int64_t full_triangles = 0;
  // Number of merged blocks (quadtree leaves larger than one quad).
  int64_t merged_blocks = 0;
  // false if even max_relative_error left more than max_triangles triangles.
  bool budget_met = true;
};

// Builds the mesh of BuildMesh() and simplifies it as described above, in
// O(pixels * log2(max_block_size)) time. Errors: as BuildMesh(), plus options
// out of range (kInvalidArgument).
StatusOr<SimplifiedMesh> BuildSimplifiedMesh(const TwoLayerPanorama& pano,
                                             const MeshSimplifyOptions& options = {});

}  // namespace casual3d

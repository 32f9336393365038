#pragma once

// Mesh construction (spec/mesh.md, Sec. 2-4): turns a TwoLayerPanorama into a
// triangle mesh with triangles exactly where nodes are linked, so that depth
// edges stay open and back-layer nodes fill disocclusions (paper Sec. 4.4.3).
//
// The result depends only on the panorama: vertex order, triangle order and
// every float are identical natively and in the Emscripten build (positions are
// computed in double with a polynomial sine/cosine of our own and rounded to
// float once; the library is compiled without FMA contraction).

#include <cstdint>
#include <vector>

#include "format/mesh.h"
#include "format/status.h"
#include "format/two_layer.h"

namespace casual3d {

// Hard limit on width * height for mesh building: 16384 x 8192 pixels. Keeps
// node references below 2^31 and vertex indices below 2^32.
constexpr int64_t kMeshPixelLimit = int64_t{16384} * 8192;

struct MeshBuildOptions {
  // Largest panorama accepted, in pixels (width * height); larger inputs are
  // refused with kLimitExceeded. Range [1, kMeshPixelLimit]. The default,
  // 8192 x 4096, can need about 3 GB for the finished full mesh.
  int64_t max_pixels = int64_t{8192} * 4096;
  // false: back-layer nodes are ignored (a front-only mesh, with holes where
  // the front layer has depth edges).
  bool include_back_layer = true;
  // false skips TwoLayerPanorama::Validate() (O(pixels)) when the caller has
  // just validated the panorama. The builder never reads out of bounds either
  // way, but on an invalid panorama the mesh is unspecified.
  bool validate_input = true;
  // Threads for the per-pixel passes (format/parallel.h); 0: all hardware
  // threads. The mesh does not depend on it. Range [0, 256].
  int num_threads = 0;

  // InvalidArgument naming the field when a value is out of range.
  Status Check() const;
};

// Builds the mesh of spec/mesh.md: one vertex per node used by a triangle, plus
// a copy with its uv in the other layer's atlas half where a triangle joining
// front and back nodes needs it, plus seam copies; triangles counter-clockwise
// seen from the centre. Every triangle's uvs lie in one half of the atlas
// (format/color_atlas.h). Errors:
// options out of range (kInvalidArgument), panorama larger than
// options.max_pixels (kLimitExceeded), width below 2 (kInvalidArgument), or
// an invalid panorama (the status of Validate()).
StatusOr<Mesh> BuildMesh(const TwoLayerPanorama& pano, const MeshBuildOptions& options = {});

// The input checks of BuildMesh (limit, validation or, without validation,
// array sizes; width at least 2), shared with the simplifier.
Status CheckMeshInput(const TwoLayerPanorama& pano, int64_t max_pixels, bool validate);

// A reference to a node used while assembling a mesh: (pixel index * 2 + layer),
// with bit 31 set for the seam copy of a column-0 node (u = 1 + 0.5 / width).
// MeshAssembler::Finish sets bit 30 internally on references whose uv lies in
// the other layer's half of the atlas (spec/mesh.md Sec. 4.4); callers never
// set it.
using NodeRef = uint32_t;
constexpr NodeRef kSeamBit = 0x80000000u;
constexpr NodeRef kOtherHalfBit = 0x40000000u;
constexpr NodeRef kNodeMask = 0x3fffffffu;
inline NodeRef MakeNodeRef(const TwoLayerPanorama& p, int x, int y, int layer, bool seam) {
  return static_cast<NodeRef>(p.index(x, y) * 2 + layer) | (seam ? kSeamBit : 0u);
}

// Collects triangles over node references and turns them into a Mesh with the
// vertex rules of spec/mesh.md Sec. 3. Shared by BuildMesh and BuildSimplifiedMesh so
// that both give identical vertices for the same node. The panorama must
// outlive the assembler and have at most kMeshPixelLimit pixels.
class MeshAssembler {
 public:
  explicit MeshAssembler(const TwoLayerPanorama& pano) : pano_(pano) {}

  // Appends a triangle; a, b, c must name present nodes, counter-clockwise.
  void AddTriangle(NodeRef a, NodeRef b, NodeRef c) {
    refs_.push_back(a);
    refs_.push_back(b);
    refs_.push_back(c);
  }
  void Reserve(size_t triangles) { refs_.reserve(3 * triangles); }
  size_t num_triangles() const { return refs_.size() / 3; }
  // The triangles added so far, 3 references each.
  const std::vector<NodeRef>& refs() const { return refs_; }

  // Chooses each triangle's atlas half (spec/mesh.md Sec. 4.4), then builds
  // the vertices: every referenced (node, atlas half) in (row, column, layer,
  // own half before other half) order, then every referenced seam copy in
  // (row, layer, half) order. Triangles keep the order in which they were
  // added. Leaves the assembler empty. Up to `num_threads` threads (resolved
  // as in format/parallel.h) share the work; the mesh does not depend on it.
  Mesh Finish(int num_threads = 1);

  // Appends the triangles of `other` after those added so far and leaves
  // `other` empty. Both must be of the same panorama.
  void Append(MeshAssembler* other) {
    refs_.insert(refs_.end(), other->refs_.begin(), other->refs_.end());
    other->refs_ = std::vector<NodeRef>();
  }

 private:
  // Marks with kOtherHalfBit the references of every triangle that joins
  // front and back nodes whose layer is not the triangle's atlas half.
  void ChooseAtlasHalves(int num_threads);

  const TwoLayerPanorama& pano_;
  std::vector<NodeRef> refs_;
};

// Appends the triangles of pixel quad (x, y) .. (x + 1, y + 1) (columns wrap)
// following spec/mesh.md Sec. 4. `use_back` false ignores back-layer nodes.
// `skip_layers` (bit l set: skip layer l) omits the triangles whose corner
// node is of a skipped layer; the simplifier uses it for quads inside a merged
// block, whose only triangles of that layer are the quad's two.
// Precondition: 0 <= x < width, 0 <= y < height - 1.
void AddQuadTriangles(const TwoLayerPanorama& pano, int x, int y, bool use_back,
                      unsigned skip_layers, MeshAssembler* out);
// The number of triangles AddQuadTriangles would add, without adding them.
int CountQuadTriangles(const TwoLayerPanorama& pano, int x, int y, bool use_back,
                       unsigned skip_layers);

// Which part of pixel quad (x, y) its triangles cover seen from the centre.
// Every triangle's vertices lie on the rays of the quad's corner pixels, so
// seen from the centre a corner triangle covers one half of the quad; the
// diagonals cut the quad into four quarters, returned as bits: kQuarterTop
// (towards A-B), kQuarterLeft (A-C), kQuarterRight (B-D), kQuarterBottom (C-D).
// 0xF: the quad is closed; anything less is a tear seen from the centre.
// `skip_layers` as for AddQuadTriangles (1u << kFront: only the triangles
// whose corner node is a back node). Precondition as AddQuadTriangles.
constexpr unsigned kQuarterTop = 1, kQuarterLeft = 2, kQuarterRight = 4, kQuarterBottom = 8;
unsigned QuadCoverage(const TwoLayerPanorama& pano, int x, int y, bool use_back = true,
                      unsigned skip_layers = 0);

// sin and cos of `angle_rad` in [-4 pi, 4 pi] computed with + and * only, so
// that native and wasm builds agree bit for bit. Absolute error below 1e-15.
void DeterministicSinCos(double angle_rad, double* sin_out, double* cos_out);

}  // namespace casual3d

#pragma once

// The paper's two-layer panorama (Sec. 3 and 4.4.3): an equirectangular grid
// (see equirect.h) in which each pixel holds up to two nodes, front (layer 0)
// and back (layer 1). Each node has a colour, a depth, a normal, a label (F or
// B) and links to nodes of its 4 neighbours. spec/ is the normative text.

#include <cstdint>
#include <memory>
#include <new>
#include <optional>
#include <utility>
#include <vector>

#include "format/equirect.h"
#include "format/status.h"
#include "format/view_hints.h"

namespace casual3d {

enum Layer : int { kFront = 0, kBack = 1 };
constexpr int kNumLayers = 2;

// Neighbour directions. Right/left wrap around the +-180 degree seam.
enum Direction : int { kRight = 0, kDown = 1, kLeft = 2, kUp = 3 };
constexpr int kNumDirections = 4;
inline Direction Opposite(Direction d) { return static_cast<Direction>((d + 2) & 3); }

// Node label (Sec. 4.4.3): F nodes come from the front stitch, B nodes from the
// back stitch or were relabelled B by colour fringe removal.
enum class NodeLabel : uint8_t { kF = 0, kB = 1 };

// A link names which node of the neighbouring pixel a node connects to.
enum class Link : uint8_t { kNone = 0, kFront = 1, kBack = 2 };

// Packs the 4 links of a node into one byte: bits 2d..2d+1 hold direction d.
inline Link GetLink(uint8_t links, Direction d) {
  return static_cast<Link>((links >> (2 * d)) & 3);
}
inline uint8_t SetLink(uint8_t links, Direction d, Link l) {
  return static_cast<uint8_t>((links & ~(3u << (2 * d))) | (static_cast<unsigned>(l) << (2 * d)));
}

// The allocator of the node arrays: std::allocator, except that resize()
// without a value leaves new elements (bytes and floats) uninitialised, so
// that a decoder which writes every element does not pay for zeroing them
// first. assign(n, v), resize(n, v) and copies initialise as usual.
template <typename T>
struct NodeArrayAllocator : std::allocator<T> {
  using value_type = T;
  template <typename U>
  struct rebind {
    using other = NodeArrayAllocator<U>;
  };
  NodeArrayAllocator() = default;
  template <typename U>
  NodeArrayAllocator(const NodeArrayAllocator<U>&) noexcept {}
  template <typename U>
  void construct(U* p) noexcept {
    ::new (static_cast<void*>(p)) U;
  }
  template <typename U, typename... Args>
  void construct(U* p, Args&&... args) {
    ::new (static_cast<void*>(p)) U(std::forward<Args>(args)...);
  }
};
template <typename T>
using NodeArray = std::vector<T, NodeArrayAllocator<T>>;

// Arrays of one layer, each width*height long (times 3 for rgb and normal),
// row-major. A pixel without a node of this layer has present 0 and all its
// other fields zero.
struct LayerData {
  NodeArray<uint8_t> present;  // 1 if the node exists.
  NodeArray<uint8_t> rgb;      // sRGB colour, 8 bits per channel.
  NodeArray<float> depth_m;    // Distance from the frame centre along the ray, > 0, finite.
  NodeArray<float> normal;     // Unit normal in the panorama frame, or (0,0,0): unlit (sky).
  NodeArray<uint8_t> label;    // NodeLabel.
  NodeArray<uint8_t> links;    // 4 Links packed as above.
};

// Where Validate() or ValidateLinks() found the problem they report, when it
// is at a node.
struct NodeProblem {
  int layer = -1, x = -1, y = -1;  // The node; layer -1: not at a node (sizes, frame).
  bool link = false;               // One of the node's links is wrong.
  // The pixel the wrong link points at; -1 when it points outside the panorama.
  int target_x = -1, target_y = -1;
};

class TwoLayerPanorama {
 public:
  TwoLayerPanorama() = default;
  // All nodes absent. Precondition: width, height > 0 (see Validate for limits).
  TwoLayerPanorama(int width, int height);
  // Arrays of the right sizes with unspecified contents, for a decoder that
  // writes every element of every array before anything reads them (the
  // package reader: a level's tiles cover it). Precondition as above.
  static TwoLayerPanorama Unfilled(int width, int height);

  int width() const { return width_; }
  int height() const { return height_; }
  size_t index(int x, int y) const { return static_cast<size_t>(y) * width_ + x; }

  LayerData& layer(int l) { return layers_[l]; }
  const LayerData& layer(int l) const { return layers_[l]; }

  bool present(int l, int x, int y) const { return layers_[l].present[index(x, y)] != 0; }

  // The pixel next to (x, y) in direction d; false past the top or bottom row.
  // Inline: the per-node loops of fusion and normals call it for every link.
  bool Neighbour(int x, int y, Direction d, int* nx, int* ny) const {
    switch (d) {
      case kRight:
        *nx = x + 1 == width_ ? 0 : x + 1;
        *ny = y;
        return true;
      case kLeft:
        *nx = x == 0 ? width_ - 1 : x - 1;
        *ny = y;
        return true;
      case kDown:
        if (y + 1 >= height_) return false;
        *nx = x;
        *ny = y + 1;
        return true;
      case kUp:
        if (y <= 0) return false;
        *nx = x;
        *ny = y - 1;
        return true;
    }
    return false;
  }

  // Smallest and largest depth of the present nodes of both layers (finite
  // ones only); false, leaving both untouched, when there is no such node.
  bool NodeDepthRange(double* near_m, double* far_m) const;

  PanoramaFrame& frame() { return frame_; }
  const PanoramaFrame& frame() const { return frame_; }
  // How the 3D photo should be looked at (format/view_hints.h); empty when
  // unknown (packages of version 1.0, panoramas made by hand).
  std::optional<ViewHints>& view_hints() { return view_hints_; }
  const std::optional<ViewHints>& view_hints() const { return view_hints_; }

  // Checks sizes, value ranges, and that every link is mutual and points at an
  // existing node. Returns the first problem found, naming layer and pixel,
  // and, if `where` is not null, stores where it is.
  // Rows are scanned on up to `num_threads` threads (format/parallel.h; 0: all
  // hardware threads); the result does not depend on it.
  Status Validate(int num_threads = 1, NodeProblem* where = nullptr) const;
  // Validate() for a panorama whose node values are valid by construction,
  // such as the output of FinishDecodedPanorama (format/tile_codec.h): checks
  // sizes, the frame and every link, but not each node's values. A panorama
  // that fails is scanned node by node, naming its first problem exactly as
  // Validate() would.
  Status ValidateLinks(int num_threads = 1, NodeProblem* where = nullptr) const;

  bool operator==(const TwoLayerPanorama& o) const;

 private:
  // The body of Validate (nodes true) and ValidateLinks (nodes false): the
  // size and frame checks, then a single branch-light scan that only says
  // whether every node (if `nodes`) and link is valid, and the node-by-node
  // scan that names the first problem (run only when the first one fails).
  Status Check(bool nodes, int num_threads, NodeProblem* where) const;
  // The single scan; kCheckNodes false checks the links only.
  template <bool kCheckNodes>
  bool ScanIsValid(int num_threads) const;
  Status FirstNodeOrLinkProblem(NodeProblem* where = nullptr) const;
  friend struct TwoLayerPanoramaTestAccess;  // two_layer_test.cc compares the two scans.

  int width_ = 0;
  int height_ = 0;
  LayerData layers_[kNumLayers];
  PanoramaFrame frame_;
  std::optional<ViewHints> view_hints_;
};

}  // namespace casual3d

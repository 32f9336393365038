#include "format/mesh_simplify.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

namespace casual3d {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
// Candidate error thresholds: max_relative_error * 2^(-i/4), i = 0..kNumSteps-1,
// then 0 (exactly planar blocks only). 2^(-1/4) rounded to double.
constexpr int kNumSteps = 80;
constexpr double kQuarterOctave = 0.84089641525371454303;

// Pixel-centre direction tables, the same arithmetic as MeshAssembler::Finish.
struct Directions {
  std::vector<double> sin_lon, cos_lon, sin_lat, cos_lat;
  Directions(int w, int h) : sin_lon(w), cos_lon(w), sin_lat(h), cos_lat(h) {
    for (int x = 0; x < w; ++x) {
      DeterministicSinCos(((x + 0.5) / w - 0.5) * 2.0 * kPi, &sin_lon[x], &cos_lon[x]);
    }
    for (int y = 0; y < h; ++y) {
      DeterministicSinCos((0.5 - (y + 0.5) / h) * kPi, &sin_lat[y], &cos_lat[y]);
    }
  }
};

// The quadtree of one layer. Level 0 holds pixel quads (x, y) .. (x+1, y+1),
// level k blocks of 2^k x 2^k quads whose top-left quad is (bx 2^k, by 2^k);
// only blocks wholly inside the quad grid (width columns with wrap, height - 1
// rows) exist. error[k][by * nx[k] + bx] is the block's relative error, or
// infinity if it cannot be merged.
class LayerPyramid {
 public:
  LayerPyramid(const TwoLayerPanorama& p, const Directions& dirs, int layer, int levels)
      : p_(p), dirs_(dirs), layer_(layer) {
    const int qw = p.width(), qh = p.height() - 1;
    full_.assign(static_cast<size_t>(qw) * qh, 0);
    for (int y = 0; y < qh; ++y) {
      for (int x = 0; x < qw; ++x) full_[static_cast<size_t>(y) * qw + x] = FullQuad(x, y);
    }
    nx_.push_back(qw);
    ny_.push_back(qh);
    error_.emplace_back();  // Level 0 uses full_.
    for (int k = 1; k <= levels; ++k) {
      const int s = 1 << k;
      nx_.push_back(qw / s);
      ny_.push_back(qh / s);
      error_.emplace_back(static_cast<size_t>(nx_[k]) * ny_[k], kInf);
      for (int by = 0; by < ny_[k]; ++by) {
        for (int bx = 0; bx < nx_[k]; ++bx) error_[k][Index(k, bx, by)] = BlockError(k, bx, by);
      }
    }
  }

  int levels() const { return static_cast<int>(error_.size()) - 1; }
  int nx(int k) const { return nx_[k]; }
  int ny(int k) const { return ny_[k]; }
  size_t Index(int k, int bx, int by) const { return static_cast<size_t>(by) * nx_[k] + bx; }
  double Error(int k, int bx, int by) const { return error_[k][Index(k, bx, by)]; }
  // The parent's error, or infinity if the parent block does not exist.
  double ParentError(int k, int bx, int by) const {
    if (k == levels()) return kInf;
    const int px = bx / 2, py = by / 2;
    if (px >= nx_[k + 1] || py >= ny_[k + 1]) return kInf;
    return error_[k + 1][Index(k + 1, px, py)];
  }

 private:
  int Column(int x) const { return x == p_.width() ? 0 : x; }
  int LinkLayer(int x, int y, Direction d) const {
    const Link l = GetLink(p_.layer(layer_).links[p_.index(Column(x), y)], d);
    return l == Link::kFront ? kFront : l == Link::kBack ? kBack : -1;
  }
  bool Present(int x, int y) const { return p_.layer(layer_).present[p_.index(Column(x), y)]; }

  // All four corners are nodes of this layer, linked around the quad.
  uint8_t FullQuad(int x, int y) const {
    if (!Present(x, y) || !Present(x + 1, y) || !Present(x, y + 1) || !Present(x + 1, y + 1)) {
      return 0;
    }
    return LinkLayer(x, y, kRight) == layer_ && LinkLayer(x, y, kDown) == layer_ &&
           LinkLayer(x + 1, y, kDown) == layer_ && LinkLayer(x, y + 1, kRight) == layer_ &&
           LinkLayer(x + 1, y, kLeft) == layer_ && LinkLayer(x, y + 1, kUp) == layer_ &&
           LinkLayer(x + 1, y + 1, kUp) == layer_ && LinkLayer(x + 1, y + 1, kLeft) == layer_;
  }

  void Position(int x, int y, double out[3]) const {
    const int c = Column(x);
    const double depth = p_.layer(layer_).depth_m[p_.index(c, y)];
    const double horizontal = dirs_.cos_lat[y] * depth;
    out[0] = horizontal * dirs_.sin_lon[c];
    out[1] = dirs_.sin_lat[y] * depth;
    out[2] = -(horizontal * dirs_.cos_lon[c]);
  }

  // Spec/mesh.md Sec. 5.2: the children must be mergeable; the plane normal is
  // the cross product of the block's diagonals; the slab is the range of n.p
  // over the block's (s+1)^2 nodes.
  double BlockError(int k, int bx, int by) const {
    const int s = 1 << k;
    const int x0 = bx * s, y0 = by * s;
    double children = 0.0;
    for (int j = 0; j < 2; ++j) {
      for (int i = 0; i < 2; ++i) {
        if (k == 1) {
          if (!full_[static_cast<size_t>(y0 + j) * nx_[0] + x0 + i]) return kInf;
        } else {
          children = std::max(children, Error(k - 1, 2 * bx + i, 2 * by + j));
        }
      }
    }
    if (children == kInf) return kInf;
    double a[3], b[3], c[3], d[3];
    Position(x0, y0, a);
    Position(x0 + s, y0, b);
    Position(x0, y0 + s, c);
    Position(x0 + s, y0 + s, d);
    const double u[3] = {d[0] - a[0], d[1] - a[1], d[2] - a[2]};
    const double v[3] = {c[0] - b[0], c[1] - b[1], c[2] - b[2]};
    double n[3] = {u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]};
    const double len = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    if (!(len > 0.0)) return kInf;
    for (double& e : n) e /= len;
    double lo = kInf, hi = -kInf;
    for (int y = y0; y <= y0 + s; ++y) {
      for (int x = x0; x <= x0 + s; ++x) {
        double q[3];
        Position(x, y, q);
        const double t = n[0] * q[0] + n[1] * q[1] + n[2] * q[2];
        lo = std::min(lo, t);
        hi = std::max(hi, t);
      }
    }
    const double delta = 0.5 * (hi - lo);
    const double offset = std::fabs(0.5 * (hi + lo));
    if (!(offset > delta)) return kInf;  // The slab contains the centre.
    return std::max(children, 2.0 * delta / (offset - delta));
  }

  const TwoLayerPanorama& p_;
  const Directions& dirs_;
  int layer_;
  std::vector<uint8_t> full_;
  std::vector<int> nx_, ny_;
  std::vector<std::vector<double>> error_;
};

struct Leaf {
  int layer, level, x0, y0;
  double error;
};

// The merged blocks at threshold tau, ordered by (layer, level from largest,
// block row, block column).
std::vector<Leaf> SelectLeaves(const std::vector<LayerPyramid>& pyramids, double tau) {
  std::vector<Leaf> leaves;
  if (tau < 0) return leaves;
  for (size_t l = 0; l < pyramids.size(); ++l) {
    const LayerPyramid& py = pyramids[l];
    for (int k = py.levels(); k >= 1; --k) {
      for (int by = 0; by < py.ny(k); ++by) {
        for (int bx = 0; bx < py.nx(k); ++bx) {
          const double e = py.Error(k, bx, by);
          if (e <= tau && !(py.ParentError(k, bx, by) <= tau)) {
            leaves.push_back({static_cast<int>(l), k, bx << k, by << k, e});
          }
        }
      }
    }
  }
  return leaves;
}

// Builds the simplified mesh for a set of leaves (spec/mesh.md Sec. 5.4).
Mesh Assemble(const TwoLayerPanorama& p, bool use_back, const std::vector<Leaf>& leaves) {
  const int w = p.width(), qh = p.height() - 1;
  std::vector<uint8_t> covered(static_cast<size_t>(w) * qh, 0);
  for (const Leaf& leaf : leaves) {
    const int s = 1 << leaf.level;
    for (int y = leaf.y0; y < leaf.y0 + s; ++y) {
      for (int x = leaf.x0; x < leaf.x0 + s; ++x) {
        covered[static_cast<size_t>(y) * w + x] |= static_cast<uint8_t>(1u << leaf.layer);
      }
    }
  }
  MeshAssembler out(p);
  out.Reserve(2 * static_cast<size_t>(w) * qh / 4 + 1024);
  for (int y = 0; y < qh; ++y) {
    for (int x = 0; x < w; ++x) {
      AddQuadTriangles(p, x, y, use_back, covered[static_cast<size_t>(y) * w + x], &out);
    }
  }
  // Nodes that geometry outside a leaf uses: every vertex of the remaining
  // pixel-quad triangles and every leaf corner.
  std::vector<uint8_t> kept(static_cast<size_t>(w) * p.height() * 2, 0);
  for (NodeRef r : out.refs()) kept[r & ~kSeamBit] = 1;
  auto node = [&](int x, int y, int layer) { return p.index(x == w ? 0 : x, y) * 2 + layer; };
  for (const Leaf& leaf : leaves) {
    const int s = 1 << leaf.level;
    kept[node(leaf.x0, leaf.y0, leaf.layer)] = 1;
    kept[node(leaf.x0 + s, leaf.y0, leaf.layer)] = 1;
    kept[node(leaf.x0, leaf.y0 + s, leaf.layer)] = 1;
    kept[node(leaf.x0 + s, leaf.y0 + s, leaf.layer)] = 1;
  }
  std::vector<NodeRef> ring;
  for (const Leaf& leaf : leaves) {
    const int s = 1 << leaf.level, x0 = leaf.x0, y0 = leaf.y0, l = leaf.layer;
    auto ref = [&](int x, int y) {
      return x == w ? MakeNodeRef(p, 0, y, l, true) : MakeNodeRef(p, x, y, l, false);
    };
    // Border counter-clockwise seen from the centre: down the left side, right
    // along the bottom, up the right side, left along the top. corner[] holds
    // the ring positions of A, C, D, B; side i runs from corner i to i + 1.
    ring.clear();
    size_t corner[4];
    corner[0] = ring.size();
    for (int y = y0; y < y0 + s; ++y) {
      if (y == y0 || kept[node(x0, y, l)]) ring.push_back(ref(x0, y));
    }
    corner[1] = ring.size();
    for (int x = x0; x < x0 + s; ++x) {
      if (x == x0 || kept[node(x, y0 + s, l)]) ring.push_back(ref(x, y0 + s));
    }
    corner[2] = ring.size();
    for (int y = y0 + s; y > y0; --y) {
      if (y == y0 + s || kept[node(x0 + s, y, l)]) ring.push_back(ref(x0 + s, y));
    }
    corner[3] = ring.size();
    for (int x = x0 + s; x > x0; --x) {
      if (x == x0 + s || kept[node(x, y0, l)]) ring.push_back(ref(x, y0));
    }
    const size_t n = ring.size();
    if (n == 4) {
      // Corners A, C, D, B: the two triangles of a pixel quad (A-D diagonal).
      out.AddTriangle(ring[3], ring[0], ring[2]);
      out.AddTriangle(ring[1], ring[2], ring[0]);
      continue;
    }
    // A fan from a corner whose two sides have no extra vertex has no
    // degenerate triangle and needs n - 2 triangles; otherwise fan from the
    // block's centre node (n triangles).
    auto side_extra = [&](int i) {
      const size_t end = i == 3 ? n : corner[i + 1];
      return end - corner[i] > 1;
    };
    int apex = -1;
    for (int c = 0; c < 4 && apex < 0; ++c) {
      if (!side_extra(c) && !side_extra((c + 3) & 3)) apex = c;
    }
    if (apex >= 0) {
      const size_t v = corner[apex];
      for (size_t i = 1; i + 1 < n; ++i) {
        out.AddTriangle(ring[v], ring[(v + i) % n], ring[(v + i + 1) % n]);
      }
    } else {
      const NodeRef centre = ref(x0 + s / 2, y0 + s / 2);
      for (size_t i = 0; i < n; ++i) out.AddTriangle(centre, ring[i], ring[(i + 1) % n]);
    }
  }
  return out.Finish();
}

}  // namespace

Status MeshSimplifyOptions::Check() const {
  if (max_triangles < 0 || max_triangles > (int64_t{1} << 31)) {
    return InvalidArgument("max_triangles " + std::to_string(max_triangles) +
                           " is outside [0, 2^31]");
  }
  if (!(max_relative_error > 0.0 && max_relative_error <= 0.5)) {
    return InvalidArgument("max_relative_error " + std::to_string(max_relative_error) +
                           " is outside (0, 0.5]");
  }
  if (max_block_size < 2 || max_block_size > 256 || (max_block_size & (max_block_size - 1))) {
    return InvalidArgument("max_block_size " + std::to_string(max_block_size) +
                           " is not a power of two in [2, 256]");
  }
  MeshBuildOptions build;
  build.max_pixels = max_pixels;
  return build.Check();
}

StatusOr<SimplifiedMesh> BuildSimplifiedMesh(const TwoLayerPanorama& pano,
                                             const MeshSimplifyOptions& options) {
  CASUAL3D_RETURN_IF_ERROR(options.Check());
  CASUAL3D_RETURN_IF_ERROR(CheckMeshInput(pano, options.max_pixels, options.validate_input));
  const int w = pano.width(), qh = pano.height() - 1;
  const bool use_back = options.include_back_layer;

  SimplifiedMesh result;
  for (int y = 0; y < qh; ++y) {
    for (int x = 0; x < w; ++x)
      result.full_triangles += CountQuadTriangles(pano, x, y, use_back, 0);
  }

  int levels = 0;
  while ((2 << levels) <= options.max_block_size) ++levels;
  const Directions dirs(w, pano.height());
  std::vector<LayerPyramid> pyramids;
  for (int l = 0; l < (use_back ? kNumLayers : 1); ++l) {
    pyramids.emplace_back(pano, dirs, l, levels);
  }

  // Candidate thresholds, coarsest first, and the triangle count each would
  // give before border vertices are added to the patches: a leaf of 2^k x 2^k
  // quads replaces 2 * 4^k triangles by 2. A block is a leaf for thresholds in
  // [its error, its parent's error).
  double steps[kNumSteps + 1];
  steps[0] = options.max_relative_error;
  for (int i = 1; i < kNumSteps; ++i) steps[i] = steps[i - 1] * kQuarterOctave;
  steps[kNumSteps] = 0.0;
  auto step_of = [&](double e) {  // The last (finest) step i with e <= steps[i], or -1.
    if (!(e <= steps[0])) return -1;
    int lo = 0, hi = kNumSteps;  // steps[lo] >= e; find the largest such index.
    while (lo < hi) {
      const int mid = (lo + hi + 1) / 2;
      if (e <= steps[mid]) {
        lo = mid;
      } else {
        hi = mid - 1;
      }
    }
    return lo;
  };
  std::vector<int64_t> saving(kNumSteps + 2, 0);  // Difference array over step indices.
  for (const LayerPyramid& py : pyramids) {
    for (int k = 1; k <= py.levels(); ++k) {
      const int64_t s = (int64_t{2} << (2 * k)) - 2;
      for (int by = 0; by < py.ny(k); ++by) {
        for (int bx = 0; bx < py.nx(k); ++bx) {
          const int last = step_of(py.Error(k, bx, by));
          if (last < 0) continue;
          const int parent = step_of(py.ParentError(k, bx, by));
          // A leaf at steps i with e <= steps[i] < parent error: i in (parent, last].
          saving[parent + 1] += s;
          saving[last + 1] -= s;
        }
      }
    }
  }
  std::vector<int64_t> estimate(kNumSteps + 1);
  int64_t running = 0;
  for (int i = 0; i <= kNumSteps; ++i) {
    running += saving[i];
    estimate[i] = result.full_triangles - running;
  }

  // The finest threshold whose estimate fits the budget. Patches take extra
  // border vertices (more triangles than estimated), so while the result is
  // over budget, retry with the estimate lowered by the measured excess.
  int64_t target = options.max_triangles;
  for (int attempt = 0; attempt < 8; ++attempt) {
    int step = 0;  // Coarsest: max_relative_error.
    double tau = steps[0];
    if (options.max_triangles > 0 && result.full_triangles <= target) {
      tau = -1.0;  // No merging needed.
    } else if (options.max_triangles > 0) {
      while (step < kNumSteps && estimate[step + 1] <= target) ++step;
      tau = steps[step];
    }
    const std::vector<Leaf> leaves = SelectLeaves(pyramids, tau);
    result.mesh = Assemble(pano, use_back, leaves);
    result.merged_blocks = static_cast<int64_t>(leaves.size());
    result.error_bound = 0.0;
    for (const Leaf& leaf : leaves) result.error_bound = std::max(result.error_bound, leaf.error);
    const int64_t triangles = static_cast<int64_t>(result.mesh.num_triangles());
    result.budget_met = options.max_triangles == 0 || triangles <= options.max_triangles;
    if (result.budget_met || step == 0) break;
    const int64_t excess = triangles - estimate[step];
    target = std::min(target - 1, options.max_triangles - excess);
  }
  return result;
}

}  // namespace casual3d

#include "reconstruct/normals/normals.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "base/parallel_for.h"

namespace casual3d::normals {
namespace {

using Vec3 = Eigen::Vector3f;

// The nodes of both layers, numbered layer * n + pixel. A node's neighbours
// are read from the panorama's links when needed, not stored: at 8192x4096
// every byte per node is 67 MB. The positions serve the raw normals only,
// and are freed once those are computed.
struct NodeGraph {
  const TwoLayerPanorama* pano = nullptr;  // Its links; its normals are the output.
  int width = 0, height = 0;
  size_t n = 0;  // Pixels.
  std::vector<uint8_t> present;        // 2n.
  std::vector<Vec3> position;          // 2n.
  std::vector<float> luminance;        // 2n, in [0, 1].

  // The node `node`, at pixel (x, y), links to in direction `dir`; -1: none.
  int64_t next(size_t node, int x, int y, int dir) const {
    const int layer = node >= n ? kBack : kFront;
    const Link link = GetLink(pano->layer(layer).links[node - layer * n], static_cast<Direction>(dir));
    if (link == Link::kNone) return -1;
    int nx, ny;
    if (!pano->Neighbour(x, y, static_cast<Direction>(dir), &nx, &ny)) return -1;
    return static_cast<int64_t>((link == Link::kFront ? 0 : n) + pano->index(nx, ny));
  }
  // Unit direction of pixel `pixel`'s centre.
  Vec3 ray(size_t pixel) const {
    const Vec3d d = EquirectPixelToDirection(static_cast<double>(pixel % width) + 0.5,
                                             static_cast<double>(pixel / width) + 0.5, width, height);
    return Vec3(static_cast<float>(d.x), static_cast<float>(d.y), static_cast<float>(d.z));
  }
};

// Runs fn(node, x, y) for every node of both layers, a row at a time on all
// cores.
template <typename Fn>
void ParallelNodes(const NodeGraph& g, Fn fn) {
  const int64_t rows = 2 * static_cast<int64_t>(g.height);
  const int threads = static_cast<int>(std::min<int64_t>(rows, base::ResolveThreads(0)));
  base::ParallelFor(0, rows, threads, [&](int64_t row) {
    const size_t first = static_cast<size_t>(row) * g.width;
    const int y = static_cast<int>(row % g.height);
    for (int x = 0; x < g.width; ++x) fn(first + x, x, y);
  });
}

NodeGraph BuildGraph(const TwoLayerPanorama& pano) {
  NodeGraph g;
  g.pano = &pano;
  g.width = pano.width();
  g.height = pano.height();
  g.n = static_cast<size_t>(g.width) * g.height;
  g.present.assign(2 * g.n, 0);
  g.position.assign(2 * g.n, Vec3::Zero());
  g.luminance.assign(2 * g.n, 0.0f);
  for (int l = 0; l < kNumLayers; ++l) {
    const LayerData& layer = pano.layer(l);
    for (int y = 0; y < g.height; ++y) {
      for (int x = 0; x < g.width; ++x) {
        const size_t i = pano.index(x, y);
        if (!layer.present[i]) continue;
        const size_t node = l * g.n + i;
        g.present[node] = 1;
        g.position[node] = g.ray(i) * layer.depth_m[i];
        const uint8_t* c = &layer.rgb[3 * i];
        g.luminance[node] = (0.2126f * c[0] + 0.7152f * c[1] + 0.0722f * c[2]) / 255.0f;
      }
    }
  }
  return g;
}

// Tangent of the surface along one grid axis from the linked neighbours
// (central difference where both exist, else one-sided); false if none.
bool Tangent(const NodeGraph& g, size_t node, int x, int y, int forward, int backward, Vec3* t) {
  const int64_t f = g.next(node, x, y, forward), b = g.next(node, x, y, backward);
  if (f >= 0 && b >= 0) {
    *t = g.position[f] - g.position[b];
  } else if (f >= 0) {
    *t = g.position[f] - g.position[node];
  } else if (b >= 0) {
    *t = g.position[node] - g.position[b];
  } else {
    return false;
  }
  return true;
}

// The rotation taking unit vector a onto unit vector b by the smallest angle.
Eigen::Matrix3f MinimalRotation(const Vec3& a, const Vec3& b) {
  return Eigen::Quaternionf::FromTwoVectors(a, b).toRotationMatrix();
}

// 1. Normals from the tangents of Tangent(), oriented towards the centre,
// then smoothed over the link graph (Eq. 5, binary weights):
// x_i = (w_i x'_i + s sum_j x_j) / (w_i + s deg_i), where w_i is 1 for a node
// with a raw normal (a unit vector) and 0 for one without (left at zero).
// Frees the graph's positions.
std::vector<Vec3> SmoothBaseNormals(NodeGraph* graph, const NormalOptions& options) {
  const NodeGraph& g = *graph;
  const size_t num_nodes = 2 * g.n;
  std::vector<Vec3> raw(num_nodes, Vec3::Zero());
  ParallelNodes(g, [&](size_t node, int x, int y) {
    if (!g.present[node]) return;
    Vec3 tu, tv;
    if (!Tangent(g, node, x, y, kRight, kLeft, &tu) || !Tangent(g, node, x, y, kDown, kUp, &tv)) return;
    Vec3 nrm = tu.cross(tv);
    const float len = nrm.norm();
    // A raw normal is a unit vector or left zero: the smoothing's weight
    // below tells them apart by that.
    if (!(len > 0) || !std::isfinite(len)) return;
    nrm /= len;
    if (nrm.dot(g.position[node]) > 0) nrm = -nrm;
    raw[node] = nrm;
  });
  graph->position = std::vector<Vec3>();

  const float s = static_cast<float>(options.smoothness);
  std::vector<Vec3> base = raw, next(num_nodes, Vec3::Zero());
  for (int it = 0; it < options.iterations; ++it) {
    ParallelNodes(g, [&](size_t node, int x, int y) {
      if (!g.present[node]) return;
      const float weight = raw[node] == Vec3::Zero() ? 0.0f : 1.0f;
      Vec3 sum = weight * raw[node];
      float total = weight;
      for (int d = 0; d < kNumDirections; ++d) {
        const int64_t j = g.next(node, x, y, d);
        if (j < 0) continue;
        sum += s * base[j];
        total += s;
      }
      next[node] = total > 0 ? Vec3(sum / total) : Vec3::Zero();
    });
    base.swap(next);
  }
  return base;
}

// 2. Detail: the luminance's low pass over the link graph (a graph box blur
// repeated detail_radius times); the detail is luminance minus this.
std::vector<float> LowPassLuminance(const NodeGraph& g, int detail_radius) {
  const size_t num_nodes = 2 * g.n;
  std::vector<float> low = g.luminance, low_next(num_nodes, 0.0f);
  for (int it = 0; it < detail_radius; ++it) {
    ParallelNodes(g, [&](size_t node, int x, int y) {
      if (!g.present[node]) return;
      float sum = low[node];
      int count = 1;
      for (int d = 0; d < kNumDirections; ++d) {
        const int64_t j = g.next(node, x, y, d);
        if (j >= 0) {
          sum += low[j];
          ++count;
        }
      }
      low_next[node] = sum / count;
    });
    low.swap(low_next);
  }
  return low;
}

// 3. Combine (Eq. 14 to 16): each node's base normal tilted by the gradient of
// the luminance detail along the links, written to the layers' normals.
void CombineWithDetail(const NodeGraph& g, const std::vector<Vec3>& base,
                       const std::vector<float>& low, const NormalOptions& options,
                       TwoLayerPanorama* pano) {
  auto detail = [&](int64_t node) { return g.luminance[node] - low[node]; };
  auto derivative = [&](size_t node, int x, int y, int forward, int backward) {
    const int64_t f = g.next(node, x, y, forward), b = g.next(node, x, y, backward);
    if (f >= 0 && b >= 0) return 0.5f * (detail(f) - detail(b));
    if (f >= 0) return detail(f) - detail(node);
    if (b >= 0) return detail(node) - detail(b);
    return 0.0f;
  };
  const float k = static_cast<float>(options.detail_strength);
  ParallelNodes(g, [&](size_t node, int x, int y) {
    if (!g.present[node]) return;
    const size_t pixel = node % g.n;
    const Vec3 r = g.ray(pixel);
    Vec3 nf = base[node];
    if (!(nf.norm() > 1e-6f)) nf = -r;  // No geometry around: face the centre.
    nf.normalize();
    Vec3 n = nf;
    if (k > 0) {
      // East and south unit vectors of the pixel (image x and y).
      const float lon = std::atan2(r.x(), -r.z());
      const float lat = std::asin(std::clamp(r.y(), -1.0f, 1.0f));
      const Vec3 east(std::cos(lon), 0.0f, std::sin(lon));
      const Vec3 south(std::sin(lat) * std::sin(lon), -std::cos(lat),
                       -std::sin(lat) * std::cos(lon));
      const float hx = derivative(node, x, y, kRight, kLeft);
      const float hy = derivative(node, x, y, kDown, kUp);
      // Detail normal in the radial frame R_s: facing the centre, tilted by
      // the height gradient (brighter is nearer).
      const Vec3 ni = (-r - k * hx * east - k * hy * south).normalized();
      // n_c = R_f^-1 R_s n_i: carry the tilt from facing the centre (-r) to
      // the base normal, by the minimal rotation (defined for floors too).
      n = (MinimalRotation(-r, nf) * ni).normalized();
    }
    float* out = &pano->layer(static_cast<int>(node / g.n)).normal[3 * pixel];
    for (int c = 0; c < 3; ++c) out[c] = n[c];
  });
}

// Sky candidates: front nodes beyond `far` whose luminance spread over the
// pixel and its linked neighbours is at most sky_max_texture, and whose colour
// is bluish or bright.
std::vector<uint8_t> SkyCandidates(const NodeGraph& g, const LayerData& front, float far,
                                   const NormalOptions& options) {
  std::vector<uint8_t> candidate(g.n, 0);
  for (size_t i = 0; i < g.n; ++i) {
    if (!front.present[i] || front.depth_m[i] < far) continue;
    const int x = static_cast<int>(i % g.width), y = static_cast<int>(i / g.width);
    // Texture: luminance spread over the pixel and its linked neighbours.
    float sum = g.luminance[i], sum2 = sum * sum;
    int count = 1;
    for (int d = 0; d < kNumDirections; ++d) {
      const int64_t j = g.next(i, x, y, d);
      if (j < 0) continue;
      sum += g.luminance[j];
      sum2 += g.luminance[j] * g.luminance[j];
      ++count;
    }
    const float mean = sum / count;
    const float var = std::max(0.0f, sum2 / count - mean * mean);
    const uint8_t* c = &front.rgb[3 * i];
    const bool sky_color = c[2] >= c[0] || mean > 0.6f;
    candidate[i] = std::sqrt(var) <= options.sky_max_texture && sky_color;
  }
  return candidate;
}

// 4. Sky: far, untextured front nodes connected to the top of the content
// (1 per pixel).
std::vector<uint8_t> DetectSky(const NodeGraph& g, const TwoLayerPanorama& pano,
                               const NormalOptions& options) {
  std::vector<uint8_t> sky(g.n, 0);
  if (!options.detect_sky) return sky;
  std::vector<float> depths;
  depths.reserve(g.n);
  const LayerData& front = pano.layer(kFront);
  for (size_t i = 0; i < g.n; ++i)
    if (front.present[i]) depths.push_back(front.depth_m[i]);
  if (depths.empty()) return sky;
  const size_t k99 = depths.size() * 99 / 100;
  std::nth_element(depths.begin(), depths.begin() + k99, depths.end());
  const float far = depths[k99] * static_cast<float>(options.sky_depth_fraction);
  const std::vector<uint8_t> candidate = SkyCandidates(g, front, far, options);
  // Flood fill from candidates at the top of the content (no front node above).
  std::vector<size_t> stack;
  for (size_t i = 0; i < g.n; ++i) {
    const size_t y = i / g.width;
    if (candidate[i] && (y == 0 || !front.present[i - g.width])) {
      sky[i] = 1;
      stack.push_back(i);
    }
  }
  while (!stack.empty()) {
    const size_t i = stack.back();
    stack.pop_back();
    const int x = static_cast<int>(i % g.width), y = static_cast<int>(i / g.width);
    for (int d = 0; d < kNumDirections; ++d) {
      int nx, ny;
      if (!pano.Neighbour(x, y, static_cast<Direction>(d), &nx, &ny)) continue;
      const size_t j = pano.index(nx, ny);
      if (candidate[j] && !sky[j]) {
        sky[j] = 1;
        stack.push_back(j);
      }
    }
  }
  return sky;
}

}  // namespace

NormalStats ComputeNormals(TwoLayerPanorama* pano, const NormalOptions& options) {
  if (const Status st = options.Check(); !st.ok())
    throw std::invalid_argument("normal options: " + st.message());
  NodeGraph g = BuildGraph(*pano);
  {
    const std::vector<Vec3> base = SmoothBaseNormals(&g, options);
    const std::vector<float> low = LowPassLuminance(g, options.detail_radius);
    CombineWithDetail(g, base, low, options, pano);
  }
  const std::vector<uint8_t> sky = DetectSky(g, *pano, options);

  // Sky nodes are unlit (0, 0, 0).
  NormalStats stats;
  for (int l = 0; l < kNumLayers; ++l) {
    LayerData& layer = pano->layer(l);
    for (size_t i = 0; i < g.n; ++i) {
      if (!layer.present[i]) continue;
      ++stats.nodes;
      if (l != kFront || !sky[i]) continue;
      ++stats.sky_nodes;
      for (int c = 0; c < 3; ++c) layer.normal[3 * i + c] = 0.0f;
    }
  }
  return stats;
}

}  // namespace casual3d::normals

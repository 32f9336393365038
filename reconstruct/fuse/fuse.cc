#include "reconstruct/fuse/fuse.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <vector>

namespace casual3d::fuse {
namespace {

Link LinkTo(int layer) { return layer == kFront ? Link::kFront : Link::kBack; }

float DepthRatio(float a, float b) { return a < b ? a / b : b / a; }

class Graph {
 public:
  Graph(TwoLayerPanorama* pano, const FuseOptions& options)
      : pano_(*pano), tau_(static_cast<float>(options.tau_dratio)),
        tau_grazing_(static_cast<float>(options.tau_grazing)),
        smooth_tolerance_(static_cast<float>(options.smooth_tolerance)) {}

  bool present(int layer, size_t i) const { return pano_.layer(layer).present[i] != 0; }
  float depth(int layer, size_t i) const { return pano_.layer(layer).depth_m[i]; }
  Link link(int layer, size_t i, Direction d) const {
    return GetLink(pano_.layer(layer).links[i], d);
  }
  void set_link(int layer, size_t i, Direction d, Link l) {
    uint8_t& links = pano_.layer(layer).links[i];
    links = SetLink(links, d, l);
  }

  // Recomputes the links across the edge from pixel (x, y) in direction d
  // (step 2 of Fig. 9).
  void ConnectEdge(int x, int y, Direction d) {
    int nx, ny;
    if (!pano_.Neighbour(x, y, d, &nx, &ny)) return;
    const size_t p = pano_.index(x, y), q = pano_.index(nx, ny);
    const Direction back_dir = Opposite(d);
    for (int l = 0; l < kNumLayers; ++l) {
      if (present(l, p)) set_link(l, p, d, Link::kNone);
      if (present(l, q)) set_link(l, q, back_dir, Link::kNone);
    }
    struct Pair {
      int lp, lq;
      float ratio;
    };
    Pair pairs[4];
    int count = 0;
    for (int lp = 0; lp < kNumLayers; ++lp) {
      if (!present(lp, p)) continue;
      for (int lq = 0; lq < kNumLayers; ++lq) {
        if (!present(lq, q)) continue;
        pairs[count++] = {lp, lq, DepthRatio(depth(lp, p), depth(lq, q))};
      }
    }
    if (count == 0) return;
    // Most similar first; ties keep the (front, front), (front, back), ... order.
    std::stable_sort(pairs, pairs + count,
                     [](const Pair& a, const Pair& b) { return a.ratio > b.ratio; });
    if (!OneSurface(x, y, d, nx, ny, pairs[0].lp, pairs[0].lq, pairs[0].ratio)) return;
    Connect(p, pairs[0].lp, d, q, pairs[0].lq);
    if (pairs[0].lp != pairs[0].lq) return;  // A crossing pair leaves no non-crossing partner.
    const int other = 1 - pairs[0].lp;
    for (int k = 1; k < count; ++k) {
      if (pairs[k].lp == other && pairs[k].lq == other) {
        if (OneSurface(x, y, d, nx, ny, other, other, pairs[k].ratio)) {
          Connect(p, other, d, q, other);
        }
        break;
      }
    }
  }

  // Whether node lp at (x, y) and node lq at its neighbour (nx, ny) in
  // direction d show one surface (see FuseOptions).
  bool OneSurface(int x, int y, Direction d, int nx, int ny, int lp, int lq, float ratio) const {
    if (ratio > tau_) return true;
    if (!(ratio > tau_grazing_)) return false;
    const size_t p = pano_.index(x, y), q = pano_.index(nx, ny);
    const float step = std::log(depth(lq, q) / depth(lp, p));
    int ox, oy;
    if (pano_.Neighbour(x, y, Opposite(d), &ox, &oy)) {  // The step before p.
      const size_t o = pano_.index(ox, oy);
      if (present(lp, o) && std::abs(step - std::log(depth(lp, p) / depth(lp, o))) <= smooth_tolerance_) {
        return true;
      }
    }
    int rx, ry;
    if (pano_.Neighbour(nx, ny, d, &rx, &ry)) {  // The step after q.
      const size_t r = pano_.index(rx, ry);
      if (present(lq, r) && std::abs(step - std::log(depth(lq, r) / depth(lq, q))) <= smooth_tolerance_) {
        return true;
      }
    }
    return false;
  }

  void ConnectAround(int x, int y) {
    for (int d = 0; d < kNumDirections; ++d) {
      const Direction dir = static_cast<Direction>(d);
      ConnectEdge(x, y, dir);
    }
  }

 private:
  void Connect(size_t p, int lp, Direction d, size_t q, int lq) {
    set_link(lp, p, d, LinkTo(lq));
    set_link(lq, q, Opposite(d), LinkTo(lp));
  }

  TwoLayerPanorama& pano_;
  float tau_, tau_grazing_, smooth_tolerance_;
};

void ClearNode(LayerData* layer, size_t i) {
  layer->present[i] = 0;
  layer->rgb[3 * i] = layer->rgb[3 * i + 1] = layer->rgb[3 * i + 2] = 0;
  layer->depth_m[i] = 0.0f;
  layer->label[i] = 0;
  layer->links[i] = 0;
}

bool ValidDepth(float d) { return d > 0 && std::isfinite(d); }

// Throws std::invalid_argument unless the four panoramas are present, of one
// size, 1-channel depth and RGB colour, twice as wide as high.
void CheckInput(const FuseInput& input) {
  if (!input.front_rgb || !input.front_depth_m || !input.back_rgb || !input.back_depth_m) {
    throw std::invalid_argument("fuse: front and back colour and depth are required");
  }
  const int W = input.front_depth_m->width(), H = input.front_depth_m->height();
  for (const ImageF* d : {input.front_depth_m, input.back_depth_m}) {
    if (d->width() != W || d->height() != H || d->channels() != 1) {
      throw std::invalid_argument("fuse: depth panoramas must be 1-channel and the same size");
    }
  }
  for (const Image8* c : {input.front_rgb, input.back_rgb}) {
    if (c->width() != W || c->height() != H || c->channels() != 3) {
      throw std::invalid_argument("fuse: colour panoramas must be RGB and as large as the depth");
    }
  }
  if (W != 2 * H || W <= 0) throw std::invalid_argument("fuse: panorama width must be 2 * height");
}

// Step 1: the nodes of both stitches. Returns, per pixel, 1 where the back
// stitch repeated the front surface (its colour is used by fringe removal).
std::vector<uint8_t> PlaceNodes(const FuseInput& input, float tau, TwoLayerPanorama* pano,
                                FuseStats* stats) {
  LayerData& F = pano->layer(kFront);
  LayerData& B = pano->layer(kBack);
  const size_t n = static_cast<size_t>(pano->width()) * pano->height();
  std::vector<uint8_t> redundant(n, 0);
  auto put = [](LayerData* layer, size_t i, const Image8& rgb, float depth, NodeLabel label) {
    layer->present[i] = 1;
    for (int c = 0; c < 3; ++c) layer->rgb[3 * i + c] = rgb.data()[3 * i + c];
    layer->depth_m[i] = depth;
    layer->label[i] = static_cast<uint8_t>(label);
  };
  for (size_t i = 0; i < n; ++i) {
    const float df = input.front_depth_m->data()[i];
    const float db = input.back_depth_m->data()[i];
    const bool has_front = ValidDepth(df), has_back = ValidDepth(db);
    if (has_front) {
      put(&F, i, *input.front_rgb, df, NodeLabel::kF);
      ++stats->front_nodes;
    }
    if (!has_back) continue;
    ++stats->back_nodes_in;
    if (!has_front) {
      put(&F, i, *input.back_rgb, db, NodeLabel::kB);  // Only the back stitch saw it.
    } else if (DepthRatio(df, db) > tau) {
      redundant[i] = 1;  // Step 1.
      ++stats->back_nodes_redundant;
    } else if (db > df) {
      put(&B, i, *input.back_rgb, db, NodeLabel::kB);
    }
  }
  return redundant;
}

// A node that spreads to its unlinked neighbours in the next ring.
struct Spawner {
  size_t pixel;
  int layer;
};

// Step 3: grows the back layer one ring at a time, `rings` rings: a pixel with
// a front node and no back node takes the mean depth and colour of the
// unlinked nodes beside it that lie clearly behind its front node, and keeps
// it only if it links to a neighbour and lies within rings * (1 - df / db) + 1
// rings of the captured nodes (df its front node's depth, db its own).
void GrowBackLayer(int rings, float tau, Graph* graph, TwoLayerPanorama* pano, FuseStats* stats) {
  const int W = pano->width();
  LayerData& F = pano->layer(kFront);
  LayerData& B = pano->layer(kBack);
  const size_t n = static_cast<size_t>(W) * pano->height();
  std::vector<Spawner> frontier;
  for (size_t i = 0; i < n; ++i) {
    for (int l = 0; l < kNumLayers; ++l) {
      if (pano->layer(l).present[i]) frontier.push_back({i, l});
    }
  }
  std::vector<float> sum_depth(n, 0.0f), sum_rgb(3 * n, 0.0f);
  std::vector<int> spawn_count(n, 0);
  std::vector<size_t> touched;
  for (int ring = 0; ring < rings && !frontier.empty(); ++ring) {
    touched.clear();
    for (const Spawner& s : frontier) {
      const int x = static_cast<int>(s.pixel % W), y = static_cast<int>(s.pixel / W);
      const LayerData& layer = pano->layer(s.layer);
      for (int d = 0; d < kNumDirections; ++d) {
        const Direction dir = static_cast<Direction>(d);
        if (GetLink(layer.links[s.pixel], dir) != Link::kNone) continue;
        int nx, ny;
        if (!pano->Neighbour(x, y, dir, &nx, &ny)) continue;
        const size_t q = pano->index(nx, ny);
        if (!F.present[q] || B.present[q]) continue;
        // Only a candidate clearly behind q's front node can be kept.
        const float ds = layer.depth_m[s.pixel];
        if (!(F.depth_m[q] < ds && DepthRatio(F.depth_m[q], ds) <= tau)) continue;
        if (spawn_count[q] == 0) touched.push_back(q);
        ++spawn_count[q];
        sum_depth[q] += ds;
        for (int c = 0; c < 3; ++c) sum_rgb[3 * q + c] += layer.rgb[3 * s.pixel + c];
      }
    }
    std::sort(touched.begin(), touched.end());
    std::vector<Spawner> next;
    for (size_t q : touched) {
      const float count = static_cast<float>(spawn_count[q]);
      const float depth = sum_depth[q] / count;
      spawn_count[q] = 0;
      sum_depth[q] = 0.0f;
      uint8_t rgb[3];
      for (int c = 0; c < 3; ++c) {
        rgb[c] = static_cast<uint8_t>(std::lround(std::clamp(sum_rgb[3 * q + c] / count, 0.0f, 255.0f)));
        sum_rgb[3 * q + c] = 0.0f;
      }
      if (!(F.depth_m[q] < depth && DepthRatio(F.depth_m[q], depth) <= tau)) continue;
      // Only as far as the viewing volume can open behind q's front node: a
      // moving eye opens a gap between two surfaces in proportion to
      // 1 - df / db, and `rings` is the gap in front of a far background. A
      // surface just behind the front one (the noisy far side of a trunk)
      // grows about three rings at 4096 and leaves the pixels behind the
      // foreground to the background, which a moving eye does see there.
      if (ring + 1 > rings * (1.0 - F.depth_m[q] / depth) + 1.0) continue;
      B.present[q] = 1;
      B.depth_m[q] = depth;
      for (int c = 0; c < 3; ++c) B.rgb[3 * q + c] = rgb[c];
      B.label[q] = static_cast<uint8_t>(NodeLabel::kB);
      const int x = static_cast<int>(q % W), y = static_cast<int>(q / W);
      graph->ConnectAround(x, y);
      // Keep the candidate only if it links to a neighbour: an unlinked one
      // would be an isolated fragment of hallucinated surface.
      if (B.links[q] == 0) {
        ClearNode(&B, q);
        graph->ConnectAround(x, y);
        continue;
      }
      ++stats->back_nodes_hallucinated;
      next.push_back({q, kBack});
    }
    frontier.swap(next);
  }
}

// Step 4: spreads the B label from B nodes onto linked front nodes, `rings`
// rings; a relabelled front node where the back stitch repeated it
// (`redundant`) takes the back stitch's colour.
void SpreadBackLabel(int rings, const std::vector<uint8_t>& redundant, const Image8& back_rgb,
                     TwoLayerPanorama* pano, FuseStats* stats) {
  const int W = pano->width();
  LayerData& F = pano->layer(kFront);
  const LayerData& B = pano->layer(kBack);
  const size_t n = static_cast<size_t>(W) * pano->height();
  std::vector<Spawner> wave;
  for (size_t i = 0; i < n; ++i) {
    if (B.present[i]) wave.push_back({i, kBack});
    if (F.present[i] && F.label[i] == static_cast<uint8_t>(NodeLabel::kB)) wave.push_back({i, kFront});
  }
  for (int ring = 0; ring < rings && !wave.empty(); ++ring) {
    std::vector<Spawner> next;
    for (const Spawner& s : wave) {
      const int x = static_cast<int>(s.pixel % W), y = static_cast<int>(s.pixel / W);
      const uint8_t links = pano->layer(s.layer).links[s.pixel];
      for (int d = 0; d < kNumDirections; ++d) {
        if (GetLink(links, static_cast<Direction>(d)) != Link::kFront) continue;
        int nx, ny;
        if (!pano->Neighbour(x, y, static_cast<Direction>(d), &nx, &ny)) continue;
        const size_t q = pano->index(nx, ny);
        if (F.label[q] == static_cast<uint8_t>(NodeLabel::kB)) continue;
        F.label[q] = static_cast<uint8_t>(NodeLabel::kB);
        ++stats->front_nodes_relabelled;
        if (redundant[q]) {
          for (int c = 0; c < 3; ++c) F.rgb[3 * q + c] = back_rgb.data()[3 * q + c];
        }
        next.push_back({q, kFront});
      }
    }
    wave.swap(next);
  }
}

// Undirected links of both layers, each counted once (from its right and
// down ends).
int64_t CountLinks(const TwoLayerPanorama& pano) {
  const size_t n = static_cast<size_t>(pano.width()) * pano.height();
  int64_t links = 0;
  for (int l = 0; l < kNumLayers; ++l) {
    const LayerData& layer = pano.layer(l);
    for (size_t i = 0; i < n; ++i) {
      if (!layer.present[i]) continue;
      links += GetLink(layer.links[i], kRight) != Link::kNone;
      links += GetLink(layer.links[i], kDown) != Link::kNone;
    }
  }
  return links;
}

}  // namespace

TwoLayerPanorama Fuse(const FuseInput& input, const FuseOptions& options, FuseStats* stats_out) {
  if (const Status st = options.Check(); !st.ok())
    throw std::invalid_argument("fuse options: " + st.message());
  CheckInput(input);
  const int W = input.front_depth_m->width(), H = input.front_depth_m->height();
  FuseStats stats;
  const float tau = static_cast<float>(options.tau_dratio);
  TwoLayerPanorama pano(W, H);
  pano.frame() = input.frame;
  const std::vector<uint8_t> redundant = PlaceNodes(input, tau, &pano, &stats);

  // Step 2: connectivity of every edge (right and down cover all of them).
  Graph graph(&pano, options);
  for (int y = 0; y < H; ++y) {
    for (int x = 0; x < W; ++x) {
      graph.ConnectEdge(x, y, kRight);
      graph.ConnectEdge(x, y, kDown);
    }
  }
  GrowBackLayer(static_cast<int>(std::lround(options.expansion_fraction * W)), tau, &graph, &pano, &stats);
  SpreadBackLabel(static_cast<int>(std::lround(options.fringe_fraction * W)), redundant, *input.back_rgb,
                  &pano, &stats);
  stats.links += CountLinks(pano);
  if (stats_out) *stats_out = stats;
  return pano;
}

}  // namespace casual3d::fuse

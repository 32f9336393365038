#include "reconstruct/fuse/seal.h"

#include <algorithm>
#include <stdexcept>
#include <vector>

#include "format/mesh_builder.h"

namespace casual3d::fuse {
namespace {

float Ratio(float a, float b) { return a < b ? a / b : b / a; }
Link LinkTo(int layer) { return layer == kFront ? Link::kFront : Link::kBack; }

// Everything a node holds, to undo an edit.
struct NodeCopy {
  uint8_t present, rgb[3], label, links;
  float depth, normal[3];
};
struct SavedPixel {
  size_t index;
  NodeCopy nodes[kNumLayers];
};

class Sealer {
 public:
  Sealer(TwoLayerPanorama* pano, const SealOptions& options)
      : p_(*pano), min_ratio_(static_cast<float>(options.min_link_ratio)),
        tau_(static_cast<float>(options.tau_dratio)) {}

  bool AllFront(int x, int y) const {
    const int xb = x + 1 == p_.width() ? 0 : x + 1;
    const LayerData& f = p_.layer(kFront);
    return f.present[p_.index(x, y)] && f.present[p_.index(xb, y)] && f.present[p_.index(x, y + 1)] &&
           f.present[p_.index(xb, y + 1)];
  }
  bool Open(int x, int y) const { return AllFront(x, y) && QuadCoverage(p_, x, y) != 0xFu; }

  // Tries the edits of quad (x, y); true if one was kept.
  bool SealQuad(int x, int y, SealStats* stats) {
    const int W = p_.width();
    const int xb = x + 1 == W ? 0 : x + 1;
    struct Edge {
      int px, py, qx, qy;
      Direction d;
    };
    const Edge edges[4] = {{x, y, xb, y, kRight}, {x, y + 1, xb, y + 1, kRight},
                           {x, y, x, y + 1, kDown}, {xb, y, xb, y + 1, kDown}};
    const int corner_x[4] = {x, xb, x, xb}, corner_y[4] = {y, y, y + 1, y + 1};
    int best_kind = -1, best_gain = 0, best_pref = -1;
    int best_a = 0, best_b = 0, best_c = 0;  // Edit parameters.
    // Links across the quad's edges.
    for (int e = 0; e < 4; ++e) {
      const Edge& E = edges[e];
      for (int lp = 0; lp < kNumLayers; ++lp) {
        for (int lq = 0; lq < kNumLayers; ++lq) {
          if (!Present(lp, E.px, E.py) || !Present(lq, E.qx, E.qy)) continue;
          if (Linked(lp, E.px, E.py, E.d, lq)) continue;
          const float r = Ratio(Depth(lp, E.px, E.py), Depth(lq, E.qx, E.qy));
          if (!(r > min_ratio_)) continue;
          if (lp != lq && Linked(1 - lp, E.px, E.py, E.d, 1 - lq)) continue;  // Would cross.
          Begin(E.px, E.py, E.qx, E.qy);
          MakeLink(E.px, E.py, lp, E.d, lq);
          const int gain = Score(E.px, E.py, E.qx, E.qy) - before_;
          Undo();
          const int pref = r > tau_ ? 3 : r > 0.9f ? 2 : 0;
          if (Better(gain, pref, best_gain, best_pref)) {
            best_kind = 0, best_gain = gain, best_pref = pref;
            best_a = e, best_b = lp, best_c = lq;
          }
        }
      }
    }
    // A back node at corner k extending a farther node of the quad.
    for (int k = 0; k < 4; ++k) {
      if (Present(kBack, corner_x[k], corner_y[k])) continue;
      const float dk = Depth(kFront, corner_x[k], corner_y[k]);
      for (int m = 0; m < 4; ++m) {
        if (m == k || (m ^ k) == 3) continue;  // 4-neighbours only (not the diagonal).
        for (int lm = 0; lm < kNumLayers; ++lm) {
          if (!Present(lm, corner_x[m], corner_y[m])) continue;
          const float dm = Depth(lm, corner_x[m], corner_y[m]);
          if (!(dm > dk && Ratio(dk, dm) <= tau_)) continue;
          Begin(corner_x[k], corner_y[k], corner_x[k], corner_y[k]);
          AddBackNode(corner_x[k], corner_y[k], corner_x[m], corner_y[m], lm);
          const int gain = ScoreAround(corner_x[k], corner_y[k]) - before_;
          Undo();
          if (Better(gain, 1, best_gain, best_pref)) {
            best_kind = 1, best_gain = gain, best_pref = 1;
            best_a = k, best_b = m, best_c = lm;
          }
        }
      }
    }
    if (best_kind < 0) return false;
    if (best_kind == 0) {
      const Edge& E = edges[best_a];
      MakeLink(E.px, E.py, best_b, E.d, best_c);
      ++stats->links_made;
    } else {
      AddBackNode(corner_x[best_a], corner_y[best_a], corner_x[best_b], corner_y[best_b], best_c);
      ++stats->back_nodes_added;
    }
    return true;
  }

 private:
  static bool Better(int gain, int pref, int best_gain, int best_pref) {
    return gain > 0 && (gain > best_gain || (gain == best_gain && pref > best_pref));
  }
  bool Present(int l, int x, int y) const { return p_.layer(l).present[p_.index(x, y)] != 0; }
  float Depth(int l, int x, int y) const { return p_.layer(l).depth_m[p_.index(x, y)]; }
  bool Linked(int l, int x, int y, Direction d, int to) const {
    return GetLink(p_.layer(l).links[p_.index(x, y)], d) == LinkTo(to);
  }

  // Clears the link of node (l, x, y) towards d and its partner's link back.
  void Unlink(int l, int x, int y, Direction d) {
    uint8_t& links = p_.layer(l).links[p_.index(x, y)];
    const Link old = GetLink(links, d);
    if (old == Link::kNone) return;
    links = SetLink(links, d, Link::kNone);
    int nx, ny;
    if (!p_.Neighbour(x, y, d, &nx, &ny)) return;
    uint8_t& back = p_.layer(old == Link::kFront ? kFront : kBack).links[p_.index(nx, ny)];
    back = SetLink(back, Opposite(d), Link::kNone);
  }

  // Links node lp at (x, y) to node lq of its neighbour in direction d.
  void MakeLink(int x, int y, int lp, Direction d, int lq) {
    int nx, ny;
    if (!p_.Neighbour(x, y, d, &nx, &ny)) return;
    Unlink(lp, x, y, d);
    Unlink(lq, nx, ny, Opposite(d));
    uint8_t& a = p_.layer(lp).links[p_.index(x, y)];
    a = SetLink(a, d, LinkTo(lq));
    uint8_t& b = p_.layer(lq).links[p_.index(nx, ny)];
    b = SetLink(b, Opposite(d), LinkTo(lp));
  }

  // A back node at (x, y) with the depth and colour of node lm at (mx, my),
  // linked to every neighbour node within tau whose link slot is free, the
  // source node always.
  void AddBackNode(int x, int y, int mx, int my, int lm) {
    LayerData& B = p_.layer(kBack);
    const LayerData& M = p_.layer(lm);
    const size_t i = p_.index(x, y), j = p_.index(mx, my);
    B.present[i] = 1;
    B.depth_m[i] = M.depth_m[j];
    for (int c = 0; c < 3; ++c) {
      B.rgb[3 * i + c] = M.rgb[3 * j + c];
      B.normal[3 * i + c] = 0.0f;
    }
    B.label[i] = static_cast<uint8_t>(NodeLabel::kB);
    B.links[i] = 0;
    for (int dd = 0; dd < kNumDirections; ++dd) {
      const Direction d = static_cast<Direction>(dd);
      int nx, ny;
      if (!p_.Neighbour(x, y, d, &nx, &ny)) continue;
      const bool source = nx == mx && ny == my;
      int pick = -1;
      float best = tau_;
      for (int l = 0; l < kNumLayers; ++l) {
        if (!Present(l, nx, ny)) continue;
        if (source && l != lm) continue;
        const bool free = GetLink(p_.layer(l).links[p_.index(nx, ny)], Opposite(d)) == Link::kNone;
        if (!source && !free) continue;
        const float r = Ratio(B.depth_m[i], Depth(l, nx, ny));
        if (source || r > best) {
          pick = l;
          best = r;
          if (source) break;
        }
      }
      if (pick < 0) continue;
      // Would it cross the front's link to pick's other layer? Fronts linked
      // to the neighbour's back node across this edge block a back-to-front link.
      if (pick == kFront && Linked(kFront, x, y, d, kBack)) continue;
      MakeLink(x, y, kBack, d, pick);
    }
  }

  // Undo log: the four nodes of two pixels (may be the same pixel).
  void Begin(int x0, int y0, int x1, int y1) {
    saved_.clear();
    for (auto [x, y] : {std::pair{x0, y0}, std::pair{x1, y1}}) {
      // The pixel and its four neighbours: links of neighbours change too.
      Save(x, y);
      for (int d = 0; d < kNumDirections; ++d) {
        int nx, ny;
        if (p_.Neighbour(x, y, static_cast<Direction>(d), &nx, &ny)) Save(nx, ny);
      }
    }
    before_ = x0 == x1 && y0 == y1 ? ScoreAround(x0, y0) : Score(x0, y0, x1, y1);
  }
  void Save(int x, int y) {
    const size_t i = p_.index(x, y);
    for (const SavedPixel& s : saved_)
      if (s.index == i) return;
    SavedPixel entry;
    entry.index = i;
    for (int l = 0; l < kNumLayers; ++l) {
      const LayerData& L = p_.layer(l);
      NodeCopy& c = entry.nodes[l];
      c.present = L.present[i];
      c.label = L.label[i];
      c.links = L.links[i];
      c.depth = L.depth_m[i];
      for (int k = 0; k < 3; ++k) {
        c.rgb[k] = L.rgb[3 * i + k];
        c.normal[k] = L.normal[3 * i + k];
      }
    }
    saved_.push_back(entry);
  }
  void Undo() {
    for (const SavedPixel& s : saved_) {
      const size_t i = s.index;
      for (int l = 0; l < kNumLayers; ++l) {
        LayerData& L = p_.layer(l);
        const NodeCopy& c = s.nodes[l];
        L.present[i] = c.present;
        L.label[i] = c.label;
        L.links[i] = c.links;
        L.depth_m[i] = c.depth;
        for (int k = 0; k < 3; ++k) {
          L.rgb[3 * i + k] = c.rgb[k];
          L.normal[3 * i + k] = c.normal[k];
        }
      }
    }
  }

  // Closed quarters of the quads touching pixel (x, y) (only quads with four
  // front corners count).
  int QuadScore(int qx, int qy) const {
    if (qy < 0 || qy > p_.height() - 2) return 0;
    qx = WrapColumn(qx, p_.width());
    if (!AllFront(qx, qy)) return 0;
    return __builtin_popcount(QuadCoverage(p_, qx, qy));
  }
  int ScoreAround(int x, int y) const {
    // Pixel (x, y) and its 4-neighbours change: quads within one pixel.
    int s = 0;
    for (int qy = y - 2; qy <= y + 1; ++qy)
      for (int qx = x - 2; qx <= x + 1; ++qx) s += QuadScore(qx, qy);
    return s;
  }
  int Score(int x0, int y0, int x1, int y1) const {
    // Quads touching either pixel (links of both change) and their partners.
    int s = 0;
    const int xl = std::min(x0, x1), yl = std::min(y0, y1);
    const int xr = xl + (x0 != x1 ? 1 : 0), yr = yl + (y0 != y1 ? 1 : 0);
    const bool wrapped = (x0 == 0 && x1 == p_.width() - 1) || (x1 == 0 && x0 == p_.width() - 1);
    if (wrapped) return ScoreAround(x0, y0) + ScoreAround(x1, y1);
    for (int qy = yl - 1; qy <= yr; ++qy)
      for (int qx = xl - 1; qx <= xr; ++qx) s += QuadScore(qx, qy);
    return s;
  }

  TwoLayerPanorama& p_;
  float min_ratio_, tau_;
  std::vector<SavedPixel> saved_;
  int before_ = 0;
};

}  // namespace

std::string SealOptions::Check() const {
  if (!(min_link_ratio > 0 && min_link_ratio < 1)) return "min_link_ratio: must be in (0, 1)";
  if (!(tau_dratio > min_link_ratio && tau_dratio < 1))
    return "tau_dratio: must be in (min_link_ratio, 1)";
  if (max_passes < 1 || max_passes > 32) return "max_passes: must be in [1, 32]";
  return "";
}

int64_t CountOpenQuads(const TwoLayerPanorama& pano) {
  int64_t open = 0;
  for (int y = 0; y + 1 < pano.height(); ++y)
    for (int x = 0; x < pano.width(); ++x) {
      const int xb = x + 1 == pano.width() ? 0 : x + 1;
      const LayerData& f = pano.layer(kFront);
      if (f.present[pano.index(x, y)] && f.present[pano.index(xb, y)] &&
          f.present[pano.index(x, y + 1)] && f.present[pano.index(xb, y + 1)] &&
          QuadCoverage(pano, x, y) != 0xFu)
        ++open;
    }
  return open;
}

SealStats SealTears(TwoLayerPanorama* pano, const SealOptions& options) {
  const std::string why = options.Check();
  if (!why.empty()) throw std::invalid_argument("seal options: " + why);
  SealStats stats;
  Sealer sealer(pano, options);
  const int W = pano->width(), H = pano->height();
  std::vector<int> open;  // Quad indices y * W + x.
  for (int y = 0; y + 1 < H; ++y)
    for (int x = 0; x < W; ++x)
      if (sealer.Open(x, y)) open.push_back(y * W + x);
  stats.open_quads_before = static_cast<int64_t>(open.size());
  for (int pass = 0; pass < options.max_passes && !open.empty(); ++pass) {
    bool changed = false;
    std::vector<int> still;
    for (int q : open) {
      const int x = q % W, y = q / W;
      if (!sealer.Open(x, y)) continue;
      if (sealer.SealQuad(x, y, &stats)) changed = true;
      if (sealer.Open(x, y)) still.push_back(q);
    }
    open.swap(still);
    if (!changed) break;
  }
  stats.open_quads_after = CountOpenQuads(*pano);
  return stats;
}

}  // namespace casual3d::fuse

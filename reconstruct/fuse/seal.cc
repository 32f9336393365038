#include "reconstruct/fuse/seal.h"

#include <algorithm>
#include <stdexcept>
#include <tuple>
#include <utility>
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

// Whether the four corners of pixel quad (x, y) have nodes of `layer`.
bool AllPresent(const TwoLayerPanorama& p, int layer, int x, int y) {
  const int xb = x + 1 == p.width() ? 0 : x + 1;
  const LayerData& l = p.layer(layer);
  return l.present[p.index(x, y)] && l.present[p.index(xb, y)] && l.present[p.index(x, y + 1)] &&
         l.present[p.index(xb, y + 1)];
}

class Sealer {
 public:
  Sealer(TwoLayerPanorama* pano, const SealOptions& options)
      : p_(*pano), min_ratio_(static_cast<float>(options.min_link_ratio)),
        tau_(static_cast<float>(options.tau_dratio)),
        continuous_ratio_(static_cast<float>(options.continuous_ratio)) {}

  bool AllFront(int x, int y) const { return AllPresent(p_, kFront, x, y); }
  bool AllBack(int x, int y) const { return AllPresent(p_, kBack, x, y); }
  bool Open(int x, int y) const { return AllFront(x, y) && QuadCoverage(p_, x, y) != 0xFu; }
  // A quad whose four corners have back nodes that the back layer's own
  // triangles leave open: a tear in a disocclusion, seen from off-centre.
  bool BackOpen(int x, int y) const {
    return AllBack(x, y) && QuadCoverage(p_, x, y, true, 1u << kFront) != 0xFu;
  }
  // A quad of one continuous front surface (four front corners whose depths
  // lie within the ratio `continuous_ratio` of each other) that the front
  // layer's own triangles leave open: closed seen from the centre by back
  // nodes behind it, it opens as soon as the eye moves.
  bool FrontOnlyOpen(int x, int y) const {
    if (!AllFront(x, y)) return false;
    if (!Continuous(x, y)) return false;
    return QuadCoverage(p_, x, y, true, 1u << kBack) != 0xFu;
  }
  // Whether closed back quads count in the score (the back-layer round);
  // closed front quarters always weigh more.
  void set_score_back(bool on) { score_back_ = on; }
  // Whether the front layer's own closed quarters of continuous quads count
  // (the front-surface round); below every quarter closed seen from the
  // centre, above every back quarter.
  void set_score_front_only(bool on) { score_front_only_ = on; }

  // Tries the edits of quad (x, y); true if some were kept. `behind`: also
  // links across any depth step between two nodes that both lie clearly
  // behind the quad's nearest front node, and pairs of edits (where three
  // surfaces meet behind a foreground edge, two layers cannot hold them
  // all, and closing the quad can take two links).
  bool SealQuad(int x, int y, bool behind, SealStats* stats) {
    const size_t base_mark = log_.size();
    const int base = WindowScore(x, y);
    std::vector<Edit> first;
    Candidates(x, y, behind, &first);
    Edit best[2];
    int best_count = 0, best_gain = 0, best_pref = -1000;
    std::vector<Edit> kept_for_pairs;
    for (const Edit& e : first) {
      Apply(e);
      const int gain = WindowScore(x, y) - base;
      Restore(base_mark);
      if (Better(gain, e.pref, best_gain, best_pref)) {
        best[0] = e, best_count = 1, best_gain = gain, best_pref = e.pref;
      }
      if (gain >= 0) kept_for_pairs.push_back(e);
    }
    if (best_count == 0 && behind) {
      std::vector<Edit> second;
      for (const Edit& e1 : kept_for_pairs) {
        Apply(e1);
        const size_t mark = log_.size();
        Candidates(x, y, behind, &second);
        for (const Edit& e2 : second) {
          Apply(e2);
          const int gain = WindowScore(x, y) - base;
          Restore(mark);
          if (Better(gain, e1.pref + e2.pref, best_gain, best_pref)) {
            best[0] = e1, best[1] = e2, best_count = 2, best_gain = gain, best_pref = e1.pref + e2.pref;
          }
        }
        Restore(base_mark);
      }
    }
    for (int i = 0; i < best_count; ++i) {
      Apply(best[i]);
      if (best[i].kind == Edit::kLink) ++stats->links_made;
      else ++stats->back_nodes_added;
    }
    log_.resize(base_mark);  // Kept: forget the undo entries.
    return best_count > 0;
  }

 private:
  static bool Better(int gain, int pref, int best_gain, int best_pref) {
    return gain > 0 && (gain > best_gain || (gain == best_gain && pref > best_pref));
  }
  bool Present(int l, int x, int y) const { return p_.layer(l).present[p_.index(x, y)] != 0; }
  bool Continuous(int x, int y) const {
    const int xb = x + 1 == p_.width() ? 0 : x + 1;
    const float d[4] = {Depth(kFront, x, y), Depth(kFront, xb, y), Depth(kFront, x, y + 1),
                        Depth(kFront, xb, y + 1)};
    return *std::min_element(d, d + 4) > continuous_ratio_ * *std::max_element(d, d + 4);
  }
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

  // One edit: a link from node (la, ax, ay) towards d to the neighbour's
  // node of layer lb; or a back node at (ax, ay) extending node (lb, bx, by).
  struct Edit {
    enum Kind { kLink, kBackNode } kind = kLink;
    int ax = 0, ay = 0, la = 0, bx = 0, by = 0, lb = 0;
    Direction d = kRight;
    int pref = 0;
  };

  // The edits of quad (x, y) in its current state.
  void Candidates(int x, int y, bool behind, std::vector<Edit>* out) const {
    out->clear();
    const int xb = x + 1 == p_.width() ? 0 : x + 1;
    struct Side {
      int px, py;
      Direction d;
    };
    const Side sides[4] = {{x, y, kRight}, {x, y + 1, kRight}, {x, y, kDown}, {xb, y, kDown}};
    const int cx[4] = {x, xb, x, xb}, cy[4] = {y, y, y + 1, y + 1};
    float nearest = Depth(kFront, cx[0], cy[0]);
    for (int k = 1; k < 4; ++k) nearest = std::min(nearest, Depth(kFront, cx[k], cy[k]));
    const float behind_depth = nearest / tau_;
    for (const Side& S : sides) {
      int qx, qy;
      if (!p_.Neighbour(S.px, S.py, S.d, &qx, &qy)) continue;
      for (int lp = 0; lp < kNumLayers; ++lp) {
        for (int lq = 0; lq < kNumLayers; ++lq) {
          if (!Present(lp, S.px, S.py) || !Present(lq, qx, qy)) continue;
          if (Linked(lp, S.px, S.py, S.d, lq)) continue;
          if (lp != lq && Linked(1 - lp, S.px, S.py, S.d, 1 - lq)) continue;  // Would cross.
          const float dp = Depth(lp, S.px, S.py), dq = Depth(lq, qx, qy);
          const float r = Ratio(dp, dq);
          const bool step = !(r > min_ratio_);
          if (step && !(behind && dp >= behind_depth && dq >= behind_depth)) continue;
          Edit e;
          e.kind = Edit::kLink;
          e.ax = S.px, e.ay = S.py, e.la = lp, e.bx = qx, e.by = qy, e.lb = lq, e.d = S.d;
          e.pref = step ? -1 : r > tau_ ? 3 : r > 0.9f ? 2 : 0;
          out->push_back(e);
        }
      }
    }
    // A back node at corner k extending a farther 4-neighbour node of the quad.
    for (int k = 0; k < 4; ++k) {
      if (Present(kBack, cx[k], cy[k])) continue;
      const float dk = Depth(kFront, cx[k], cy[k]);
      for (int m = 0; m < 4; ++m) {
        if (m == k || (m ^ k) == 3) continue;  // Not the diagonal.
        for (int lm = 0; lm < kNumLayers; ++lm) {
          if (!Present(lm, cx[m], cy[m])) continue;
          const float dm = Depth(lm, cx[m], cy[m]);
          if (!(dm > dk && Ratio(dk, dm) <= tau_)) continue;
          Edit e;
          e.kind = Edit::kBackNode;
          e.ax = cx[k], e.ay = cy[k], e.bx = cx[m], e.by = cy[m], e.lb = lm;
          e.pref = 1;
          out->push_back(e);
        }
      }
    }
  }

  // Applies `e`, logging what it changes.
  void Apply(const Edit& e) {
    if (e.kind == Edit::kLink) {
      Save(e.ax, e.ay);
      Save(e.bx, e.by);
      MakeLink(e.ax, e.ay, e.la, e.d, e.lb);
    } else {
      Save(e.ax, e.ay);
      for (int d = 0; d < kNumDirections; ++d) {
        int nx, ny;
        if (p_.Neighbour(e.ax, e.ay, static_cast<Direction>(d), &nx, &ny)) Save(nx, ny);
      }
      AddBackNode(e.ax, e.ay, e.bx, e.by, e.lb);
    }
  }

  void Save(int x, int y) {
    const size_t i = p_.index(x, y);
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
    log_.push_back(entry);
  }
  // Undoes everything logged after `mark`, newest first.
  void Restore(size_t mark) {
    while (log_.size() > mark) {
      const SavedPixel& s = log_.back();
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
      log_.pop_back();
    }
  }

  // Closed quarters of the quads touching pixel (x, y) (only quads with four
  // front corners count).
  int QuadScore(int qx, int qy) const {
    if (qy < 0 || qy > p_.height() - 2) return 0;
    qx = WrapColumn(qx, p_.width());
    int s = 0;
    // A quarter closed seen from the centre outweighs every other quarter
    // of the 5x5 window (at most 25 * 4 * (16 + 1) = 1700), so that no edit
    // trades closure seen from the centre for closure elsewhere; a front
    // surface's own quarter outweighs every back quarter (at most 100).
    if (AllFront(qx, qy)) {
      s += 4096 * __builtin_popcount(QuadCoverage(p_, qx, qy));
      if (score_front_only_ && Continuous(qx, qy))
        s += 128 * __builtin_popcount(QuadCoverage(p_, qx, qy, true, 1u << kBack));
    }
    if (score_back_ && AllBack(qx, qy))
      s += __builtin_popcount(QuadCoverage(p_, qx, qy, true, 1u << kFront));
    return s;
  }
  // Closed quarters of the quads within two of quad (x, y): every quad
  // that touches a pixel an edit of (x, y) can change.
  int WindowScore(int x, int y) const {
    int s = 0;
    for (int qy = y - 2; qy <= y + 2; ++qy)
      for (int qx = x - 2; qx <= x + 2; ++qx) s += QuadScore(qx, qy);
    return s;
  }

  TwoLayerPanorama& p_;
  float min_ratio_, tau_;
  std::vector<SavedPixel> log_;
  bool score_back_ = false;
  bool score_front_only_ = false;
  float continuous_ratio_ = 0.9f;
};

}  // namespace

int64_t CountOpenQuads(const TwoLayerPanorama& pano) {
  int64_t open = 0;
  for (int y = 0; y + 1 < pano.height(); ++y)
    for (int x = 0; x < pano.width(); ++x)
      open += AllPresent(pano, kFront, x, y) && QuadCoverage(pano, x, y) != 0xFu;
  return open;
}

namespace {

// The quads `is_open` says are open, sealed pass by pass until a pass
// changes nothing (at most max_passes); returns how many were open before
// and stay open after.
template <typename IsOpen>
std::pair<int64_t, int64_t> SealPasses(Sealer* sealer, int width, int height, int max_passes,
                                       bool behind, IsOpen is_open, SealStats* stats) {
  std::vector<int> open;  // Quad indices y * width + x.
  for (int y = 0; y + 1 < height; ++y)
    for (int x = 0; x < width; ++x)
      if (is_open(x, y)) open.push_back(y * width + x);
  const int64_t before = static_cast<int64_t>(open.size());
  for (int pass = 0; pass < max_passes && !open.empty(); ++pass) {
    bool changed = false;
    std::vector<int> still;
    for (int q : open) {
      const int x = q % width, y = q / width;
      if (!is_open(x, y)) continue;
      if (sealer->SealQuad(x, y, behind, stats)) changed = true;
      if (is_open(x, y)) still.push_back(q);
    }
    open.swap(still);
    if (!changed) break;
  }
  return {before, static_cast<int64_t>(open.size())};
}

}  // namespace

SealStats SealTears(TwoLayerPanorama* pano, const SealOptions& options) {
  if (const Status st = options.Check(); !st.ok())
    throw std::invalid_argument("seal options: " + st.message());
  SealStats stats;
  Sealer sealer(pano, options);
  const int W = pano->width(), H = pano->height();
  const auto front_open = [&](int x, int y) { return sealer.Open(x, y); };
  // Local edits within one surface first; then, for what is left, links
  // between surfaces behind the foreground and pairs of edits.
  stats.open_quads_before =
      SealPasses(&sealer, W, H, options.max_passes, false, front_open, &stats).first;
  SealPasses(&sealer, W, H, options.max_passes, true, front_open, &stats);
  // Then continuous front surfaces whose own triangles leave a quad open
  // (closed from the centre only by what lies behind them).
  sealer.set_score_front_only(true);
  const auto front_only_open = [&](int x, int y) { return sealer.FrontOnlyOpen(x, y); };
  std::tie(stats.front_surface_open_quads_before, stats.front_surface_open_quads_after) =
      SealPasses(&sealer, W, H, options.max_passes, true, front_only_open, &stats);
  // Then tears of the back layer (noisy depth behind an edge), within one
  // surface, without opening anything seen from the centre.
  sealer.set_score_back(true);
  const auto back_open = [&](int x, int y) { return sealer.BackOpen(x, y); };
  std::tie(stats.back_open_quads_before, stats.back_open_quads_after) =
      SealPasses(&sealer, W, H, options.max_passes, false, back_open, &stats);
  // Counted last, after every round (edits close more than they open
  // locally, not quad by quad).
  stats.open_quads_after = CountOpenQuads(*pano);
  return stats;
}

}  // namespace casual3d::fuse

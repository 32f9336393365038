#include "reconstruct/depth/flat_regions.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <limits>
#include <numeric>
#include <stdexcept>
#include <string>

#include <Eigen/Dense>

#include "reconstruct/depth/flat_region_steps.h"
#include "reconstruct/util/union_find.h"

namespace casual3d::depth {
namespace flat {
namespace {

constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();

float Dist2(const float* a, const float* b) {
  const float d0 = a[0] - b[0], d1 = a[1] - b[1], d2 = a[2] - b[2];
  return d0 * d0 + d1 * d1 + d2 * d2;
}

// Bilinear RGB sample at continuous pixel-index coordinates (u, v); false
// when outside [0, w - 1] x [0, h - 1].
bool SampleRgb(const ImageF& img, float u, float v, float out[3]) {
  if (!(u >= 0.0f && v >= 0.0f && u <= img.width() - 1.0f && v <= img.height() - 1.0f)) return false;
  const int x0 = std::min(static_cast<int>(u), img.width() - 2);
  const int y0 = std::min(static_cast<int>(v), img.height() - 2);
  const float fx = u - x0, fy = v - y0;
  for (int c = 0; c < 3; ++c) {
    const float top = img.at(x0, y0, c) + fx * (img.at(x0 + 1, y0, c) - img.at(x0, y0, c));
    const float bot = img.at(x0, y0 + 1, c) + fx * (img.at(x0 + 1, y0 + 1, c) - img.at(x0, y0 + 1, c));
    out[c] = top + fy * (bot - top);
  }
  return true;
}

// Per neighbour: the plane-induced homography and per-channel exposure gain
// (reference colour / neighbour colour) estimated at confident anchors.
struct Neighbor {
  const ImageF* color = nullptr;
  PlaneHomography hom;
  float gain[3] = {1.0f, 1.0f, 1.0f};
};

void EstimateGain(const ImageF& color, const ImageF& photo_weight, const ImageF& anchors, Neighbor* nb) {
  std::vector<float> ratio[3];
  for (int y = 0; y < color.height(); y += 2)
    for (int x = 0; x < color.width(); x += 2) {
      const float d = anchors.at(x, y);
      if (!(d > 0) || photo_weight.at(x, y) < 0.5f) continue;
      float u, v, s[3];
      if (!nb->hom.Project(static_cast<float>(x), static_cast<float>(y), 1.0f / d, &u, &v)) continue;
      if (!SampleRgb(*nb->color, u, v, s)) continue;
      for (int c = 0; c < 3; ++c)
        if (s[c] > 0.02f && color.at(x, y, c) > 0.02f) ratio[c].push_back(color.at(x, y, c) / s[c]);
    }
  for (int c = 0; c < 3; ++c) {
    if (ratio[c].size() < 50) continue;
    auto mid = ratio[c].begin() + ratio[c].size() / 2;
    std::nth_element(ratio[c].begin(), mid, ratio[c].end());
    nb->gain[c] = std::min(2.0f, std::max(0.5f, *mid));
  }
}

// Depth of the colour edge at e (as a fractional label, into e->label): for
// each label, e and its normal are projected into every neighbour, whose
// colour profile across the projected edge is compared with the
// reference's (a shift of a fraction of a pixel moves the transition
// samples). Neighbours weigh by how far the edge moves along its normal
// over the label range (one whose epipolar lines run along the edge says
// nothing); labels that fewer than half of the seeing neighbours cover are
// left out (one neighbour alone matches by chance). False when the minimum
// is not clear.
bool MeasureEdge(const std::vector<Neighbor>& nbs, const float* region_color, const std::vector<float>& inv_of,
                 EdgePoint* e) {
  const int L = static_cast<int>(inv_of.size());
  std::vector<float> cost(L, 0.0f), weight(L, 0.0f);
  for (const Neighbor& nb : nbs) {
    float u0, v0, u1, v1, un, vn;
    if (!nb.hom.Project(e->x, e->y, inv_of[0], &u0, &v0) || !nb.hom.Project(e->x, e->y, inv_of[L - 1], &u1, &v1) ||
        !nb.hom.Project(e->x + e->nx, e->y + e->ny, inv_of[L - 1], &un, &vn))
      continue;
    float dx = un - u1, dy = vn - v1;
    const float dl = std::hypot(dx, dy);
    if (dl < 1e-4f) continue;
    dx /= dl;
    dy /= dl;
    const float motion = std::abs((u0 - u1) * dx + (v0 - v1) * dy);
    const float wn = std::min(1.0f, motion / 4.0f);
    if (wn < 0.05f) continue;
    float ref[3];
    for (int c = 0; c < 3; ++c) ref[c] = region_color[c] / nb.gain[c];
    const float inv_scale = 1.0f / e->scale;
    for (int k = 0; k < L; ++k) {
      float u, v;
      if (!nb.hom.Project(e->x, e->y, inv_of[k], &u, &v)) continue;
      float sad = 0, s[3];
      bool ok = true;
      for (int i = 0; i < kProfile && ok; ++i) {
        const float o = kProfileStart + i * kProfileStep;
        if (!(ok = SampleRgb(*nb.color, u + o * dx, v + o * dy, s))) break;
        const float d = std::abs(s[0] - ref[0]) + std::abs(s[1] - ref[1]) + std::abs(s[2] - ref[2]);
        sad += std::abs(std::min(1.0f, d * inv_scale) - e->profile[i]);
      }
      if (!ok) continue;
      cost[k] += wn * sad / kProfile;
      weight[k] += wn;
    }
  }
  const float min_weight = std::max(1.0f, 0.5f * *std::max_element(weight.begin(), weight.end()));
  int best = -1, valid = 0;
  double sum = 0;
  for (int k = 0; k < L; ++k) {
    if (weight[k] < min_weight) {
      cost[k] = kNaN;
      continue;
    }
    cost[k] /= weight[k];
    sum += cost[k];
    ++valid;
    if (best < 0 || cost[k] < cost[best]) best = k;
  }
  if (best < 0 || valid < L / 4) return false;
  if (cost[best] > 0.35f || sum / valid - cost[best] < 0.12) return false;
  float frac = 0.0f;
  if (best > 0 && best + 1 < L && !std::isnan(cost[best - 1]) && !std::isnan(cost[best + 1])) {
    const float den = cost[best - 1] - 2 * cost[best] + cost[best + 1];
    if (den > 1e-6f) frac = std::min(0.5f, std::max(-0.5f, 0.5f * (cost[best - 1] - cost[best + 1]) / den));
  }
  e->label = best + frac;
  return true;
}

// Whose edge: the surface just beyond it (the median label of the first
// three textured pixels with a depth, within 8 pixels).
//   kOwned: farther than the edge by more than owned_margin labels: the
//     region occludes it, the edge is the region's silhouette.
//   kThin: the region's own pixels come back within merge_gap pixels: a
//     thin occluder (a pole) crosses the region; its edge says only that the
//     region lies behind.
//   kAtBeyond: at the edge's depth: an occluder's edge, or the region
//     standing on that surface (a contact).
EdgePoint::Kind Classify(const EdgePoint& e, int g, const std::vector<int>& group, const ImageF& anchors,
                         const ImageF& photo_weight, const CostVolume& grid, const FlatRegionOptions& options) {
  const int w = anchors.width(), h = anchors.height();
  for (int t = 1; t <= options.merge_gap; ++t) {
    const int ox = static_cast<int>(std::lround(e.x + (t - 0.5f) * e.nx));
    const int oy = static_cast<int>(std::lround(e.y + (t - 0.5f) * e.ny));
    if (ox < 0 || oy < 0 || ox >= w || oy >= h) break;
    if (group[static_cast<size_t>(oy) * w + ox] == g) return EdgePoint::Kind::kThin;
  }
  float beyond[3];
  int found = 0;
  for (int t = 1; t <= 8 && found < 3; ++t) {
    const int ox = static_cast<int>(std::lround(e.x + (t - 0.5f) * e.nx));
    const int oy = static_cast<int>(std::lround(e.y + (t - 0.5f) * e.ny));
    if (ox < 0 || oy < 0 || ox >= w || oy >= h) break;
    const size_t o = static_cast<size_t>(oy) * w + ox;
    const float d = anchors.data()[o];
    if (!(d > 0) || photo_weight.data()[o] < 0.15f) continue;
    beyond[found++] = static_cast<float>(grid.LabelOfDepth(d));
  }
  if (found < 2) return EdgePoint::Kind::kUnknown;
  std::sort(beyond, beyond + found);
  const float b = beyond[found / 2];
  if (b > e.label + options.owned_margin) return EdgePoint::Kind::kOwned;
  if (std::abs(b - e.label) <= options.owned_margin) return EdgePoint::Kind::kAtBeyond;
  return EdgePoint::Kind::kUnknown;
}

// Touching points (within `touch` labels: owned ones count twice, those
// at the surface beyond once, thin occluders' not at all) and violations
// (points farther than the plane by more than `touch`: the plane would lie
// in front of an edge).
void Score(const Plane& pl, const std::vector<EdgePoint>& pts, double touch, int* touching, int* violations) {
  int t = 0, v = 0;
  for (const EdgePoint& e : pts) {
    const double r = pl.At(e.x, e.y) - e.label;
    if (std::abs(r) <= touch) {
      t += e.owned() ? 2 : e.kind == EdgePoint::Kind::kThin ? 0 : 1;
    } else if (r < -touch) {
      ++v;
    }
  }
  *touching = t;
  *violations = v;
}

struct GroupShape {
  std::array<float, 3> color = {0, 0, 0};
  std::vector<std::pair<float, float>> samples;  // A subset of the group's pixels.
  bool touches_top = false;                      // Reaches the image's top row.
};

// The plane fitting of FitPlane over the points `use` accepts (violations
// are counted over all points): RANSAC over constant planes (one point) and
// planes through three points, scored by touching points among the planes
// with (nearly) no violation and labels inside the sweep's range over the
// group, then iteratively reweighted least squares on the touching points
// (owned ones weighted twice, Tukey's biweight on the residuals) with the
// slopes damped, so that points along one line leave the slope across it
// at zero. Returns false when no plane touches enough points.
template <typename Use>
bool FitPlaneOver(const std::vector<EdgePoint>& pts, Use&& use, const GroupShape& shape,
                  const FlatRegionOptions& options, int num_labels, uint64_t seed, Plane* out) {
  std::vector<int> usable, owned_index;
  for (int i = 0; i < static_cast<int>(pts.size()); ++i)
    if (use(pts[i])) {
      usable.push_back(i);
      if (pts[i].owned()) owned_index.push_back(i);
    }
  const int np = static_cast<int>(pts.size());
  if (static_cast<int>(usable.size()) < options.min_touching) return false;
  uint64_t rng = seed | 1;
  auto next_random = [&](uint64_t bound) {
    rng ^= rng << 13;
    rng ^= rng >> 7;
    rng ^= rng << 17;
    return rng % bound;
  };
  const double touch = options.touch_labels;
  const int max_violations = static_cast<int>(std::floor((1.0 - options.behind_fraction) * np));
  auto touching_of = [&](const Plane& pl, int* violations) {
    int t = 0, v = 0;
    for (const EdgePoint& e : pts) {
      const double r = pl.At(e.x, e.y) - e.label;
      if (r < -touch) ++v;
      else if (r <= touch && use(e)) t += e.owned() ? 2 : 1;
    }
    *violations = v;
    return t;
  };
  auto plausible = [&](const Plane& pl) {
    if (std::abs(pl.a) > 0.5 || std::abs(pl.b) > 0.5) return false;
    int outside = 0;
    for (const auto& [x, y] : shape.samples) {
      const double k = pl.At(x, y);
      outside += k < -0.5 || k > num_labels - 0.5;
    }
    return outside <= static_cast<int>(0.02 * shape.samples.size());
  };
  Plane best;
  int best_touching = -1;
  auto consider = [&](const Plane& pl) {
    int v;
    const int t = touching_of(pl, &v);
    if (v <= max_violations && t > best_touching && plausible(pl)) {
      best_touching = t;
      best = pl;
    }
  };
  auto pick = [&](bool from_owned) -> const EdgePoint& {
    return from_owned ? pts[owned_index[next_random(owned_index.size())]] : pts[usable[next_random(usable.size())]];
  };
  for (int it = 0; it < 300; ++it) consider(Plane{0, 0, pick(!owned_index.empty() && it % 2 == 0).label});
  for (int it = 0; it < 1500; ++it) {
    const bool from_owned = owned_index.size() >= 3 && it % 2 == 0;
    const EdgePoint& p0 = pick(from_owned);
    const EdgePoint& p1 = pick(from_owned);
    const EdgePoint& p2 = pick(from_owned);
    const double area = std::abs((p1.x - p0.x) * (p2.y - p0.y) - (p2.x - p0.x) * (p1.y - p0.y));
    if (area < 100.0) continue;
    Eigen::Matrix3d A;
    A << p0.x, p0.y, 1, p1.x, p1.y, 1, p2.x, p2.y, 1;
    const Eigen::Vector3d sol = A.fullPivLu().solve(Eigen::Vector3d(p0.label, p1.label, p2.label));
    consider(Plane{sol[0], sol[1], sol[2]});
  }
  if (best_touching < std::max(options.min_touching, static_cast<int>(options.min_touching_fraction * np)))
    return false;

  auto touches = [&](const Plane& pl, const EdgePoint& e) { return use(e) && std::abs(pl.At(e.x, e.y) - e.label) <= touch; };
  Plane pl = best;
  {
    // Touching points along one line leave the slope across it open: start
    // from their median depth rather than from a hypothesis that tilted
    // through them by chance.
    double mx = 0, my = 0, sxx = 0, syy = 0, sxy = 0;
    std::vector<float> labels;
    for (const EdgePoint& e : pts)
      if (touches(best, e)) {
        labels.push_back(e.label);
        mx += e.x;
        my += e.y;
      }
    const double m = static_cast<double>(labels.size());
    mx /= m;
    my /= m;
    for (const EdgePoint& e : pts)
      if (touches(best, e)) {
        sxx += (e.x - mx) * (e.x - mx);
        syy += (e.y - my) * (e.y - my);
        sxy += (e.x - mx) * (e.y - my);
      }
    const double tr = (sxx + syy) / m, det = (sxx * syy - sxy * sxy) / (m * m);
    const double minor = 0.5 * tr - std::sqrt(std::max(0.0, 0.25 * tr * tr - det));
    if (minor < 100.0) {  // Spread across the line below 10 pixels.
      std::nth_element(labels.begin(), labels.begin() + labels.size() / 2, labels.end());
      pl = Plane{0, 0, labels[labels.size() / 2]};
    }
  }
  for (int iter = 0; iter < 6; ++iter) {
    const double cut = iter == 0 ? touch : std::max(0.5, 0.75 * touch);
    auto weight_of = [&](const EdgePoint& e) {
      const double r = (pl.At(e.x, e.y) - e.label) / cut;
      return !use(e) || std::abs(r) >= 1 ? 0.0 : (e.owned() ? 2.0 : 1.0) * (1 - r * r) * (1 - r * r);
    };
    double mx = 0, my = 0, sw = 0;
    for (const EdgePoint& e : pts) {
      const double wgt = weight_of(e);
      mx += wgt * e.x;
      my += wgt * e.y;
      sw += wgt;
    }
    if (sw <= 0) break;
    mx /= sw;
    my /= sw;
    Eigen::Matrix3d AtA = Eigen::Matrix3d::Zero();
    Eigen::Vector3d Atb = Eigen::Vector3d::Zero();
    for (const EdgePoint& e : pts) {
      const double wgt = weight_of(e);
      if (wgt <= 0) continue;
      const Eigen::Vector3d row(e.x - mx, e.y - my, 1.0);
      AtA += wgt * row * row.transpose();
      Atb += wgt * row * e.label;
    }
    // One label^2 per (label/pixel)^2 of slope and unit of weight:
    // negligible for real slopes, decisive where the points span no extent.
    AtA(0, 0) += sw;
    AtA(1, 1) += sw;
    const Eigen::Vector3d sol = AtA.ldlt().solve(Atb);
    pl = Plane{sol[0], sol[1], sol[2] - sol[0] * mx - sol[1] * my};
  }
  int v;
  const int t = touching_of(pl, &v);
  *out = v <= max_violations && t >= best_touching / 2 && plausible(pl) ? pl : best;
  return true;
}

// A group's plane, on one of three grounds:
//   silhouette: its touching points include min_owned owned points;
//   enclosed: touching points on the region's upper and lower side and on
//     a side (a hole in a surface);
//   contact: a plane through the points where the region stands on the
//     surface below (edges at the surface beyond, outward normal down).
// None for a region that looks like sky (bluish and reaching the top of the
// photo): sky lies behind everything it borders, the skyline it seems to
// stand on included.
PlaneFit FitPlane(const std::vector<EdgePoint>& pts, const GroupShape& shape, const FlatRegionOptions& options,
                  int num_labels, uint64_t seed) {
  PlaneFit fit;
  const double touch = options.touch_labels;
  auto stats = [&](const Plane& pl, int* touching, int* owned, int* up, int* down, int* lr) {
    *touching = *owned = *up = *down = *lr = 0;
    for (const EdgePoint& e : pts) {
      if (std::abs(pl.At(e.x, e.y) - e.label) > touch || e.kind == EdgePoint::Kind::kThin) continue;
      *touching += e.owned() ? 2 : 1;
      *owned += e.owned();
      *down += e.ny > 0.5f;
      *up += e.ny < -0.5f;
      *lr += std::abs(e.nx) > 0.5f;
    }
  };
  const bool sky_like = shape.touches_top && shape.color[2] > std::max(shape.color[0], shape.color[1]) + 0.03f;
  const int side = options.min_side_points;
  Plane pl;
  int t, o, up, down, lr;
  if (FitPlaneOver(pts, [](const EdgePoint& e) { return e.kind != EdgePoint::Kind::kThin; }, shape, options,
                   num_labels, seed, &pl)) {
    stats(pl, &t, &o, &up, &down, &lr);
    if (o >= options.min_owned || (!sky_like && up >= side && down >= side && lr >= side)) {
      fit.ok = true;  // Silhouette or enclosed.
      fit.plane = pl;
      return fit;
    }
  }
  if (sky_like) return fit;
  fit.ok = FitPlaneOver(pts, [](const EdgePoint& e) { return e.kind == EdgePoint::Kind::kAtBeyond && e.ny > 0.5f; },
                        shape, options, num_labels, seed + 1, &fit.plane);  // Contact.
  return fit;
}

}  // namespace


namespace {

// Regions of nearly constant colour among the flat pixels: region id per
// pixel (-1 not flat, -2 in a region too small to keep), its mean colour
// and area (0 for a dropped region).
void GrowRegions(const ImageF& color, const ImageF& photo_weight, const FlatRegionOptions& options,
                 std::vector<int>* region_out, std::vector<std::array<double, 3>>* mean_out,
                 std::vector<int>* area_out) {
  const int w = color.width(), h = color.height();
  const size_t n = static_cast<size_t>(w) * h;
  std::vector<int>& region = *region_out;
  std::vector<std::array<double, 3>>& mean = *mean_out;
  std::vector<int>& area = *area_out;
  region.assign(n, -1);
  const float step2 = static_cast<float>(options.color_step * options.color_step);
  const float spread2 = static_cast<float>(options.color_spread * options.color_spread);
  std::vector<int> stack, members;
  const float max_w = static_cast<float>(options.max_photo_weight);
  for (size_t s = 0; s < n; ++s) {
    if (region[s] != -1 || photo_weight.data()[s] >= max_w) continue;
    const int id = static_cast<int>(mean.size());
    double sum[3] = {0, 0, 0};
    members.clear();
    stack.assign(1, static_cast<int>(s));
    region[s] = id;
    while (!stack.empty()) {
      const int p = stack.back();
      stack.pop_back();
      members.push_back(p);
      const float* cp = color.data() + 3 * static_cast<size_t>(p);
      for (int c = 0; c < 3; ++c) sum[c] += cp[c];
      const float m[3] = {static_cast<float>(sum[0] / members.size()), static_cast<float>(sum[1] / members.size()),
                          static_cast<float>(sum[2] / members.size())};
      const int px = p % w, py = p / w;
      const int nbr[4][2] = {{px - 1, py}, {px + 1, py}, {px, py - 1}, {px, py + 1}};
      for (const auto& q : nbr) {
        if (q[0] < 0 || q[1] < 0 || q[0] >= w || q[1] >= h) continue;
        const size_t qi = static_cast<size_t>(q[1]) * w + q[0];
        if (region[qi] != -1 || photo_weight.data()[qi] >= max_w) continue;
        const float* cq = color.data() + 3 * qi;
        if (Dist2(cp, cq) > step2 || Dist2(m, cq) > spread2) continue;
        region[qi] = id;
        stack.push_back(static_cast<int>(qi));
      }
    }
    if (static_cast<int>(members.size()) < options.min_region_pixels) {
      for (int p : members) region[p] = -2;  // Too small: no region, not revisited.
      mean.push_back({0, 0, 0});
      area.push_back(0);
      continue;
    }
    mean.push_back({sum[0] / members.size(), sum[1] / members.size(), sum[2] / members.size()});
    area.push_back(static_cast<int>(members.size()));
  }
}

// Joins regions of similar colour that a thin occluder separates: from each
// region pixel, look along the four axes across at most merge_gap pixels of
// other content for another region.
void JoinRegions(const std::vector<int>& region, const std::vector<std::array<double, 3>>& mean, int w,
                 int h, const FlatRegionOptions& options, util::UnionFind* uf) {
  const double mc2 = options.merge_color * options.merge_color;
  auto similar = [&](int a, int b) {
    double d = 0;
    for (int c = 0; c < 3; ++c) d += (mean[a][c] - mean[b][c]) * (mean[a][c] - mean[b][c]);
    return d <= mc2;
  };
  const int dirs[4][2] = {{1, 0}, {-1, 0}, {0, 1}, {0, -1}};
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const int a = region[static_cast<size_t>(y) * w + x];
      if (a < 0) continue;
      for (const auto& d : dirs) {
        const int x1 = x + d[0], y1 = y + d[1];
        if (x1 < 0 || y1 < 0 || x1 >= w || y1 >= h || region[static_cast<size_t>(y1) * w + x1] == a) continue;
        for (int s = 1; s <= options.merge_gap + 1; ++s) {
          const int xs = x + s * d[0], ys = y + s * d[1];
          if (xs < 0 || ys < 0 || xs >= w || ys >= h) break;
          const int b = region[static_cast<size_t>(ys) * w + xs];
          if (b == a) break;
          if (b >= 0) {
            if (similar(a, b)) uf->Union(a, b);
            break;
          }
        }
      }
    }
}

// The colour edge outward of the boundary pixel (x, y) of a region of colour
// `region_color` along e's normal: the first pixel outward (within
// kMaxMarch) that looks different from the region. The flat pixels can stop
// short of it, where the colour-weighted texture measure sees texture
// beyond. Its position to a fraction of a pixel: where the colour difference
// to the region, sampled along the normal in quarter pixels, first reaches
// half of its value 1.5 pixels further out (an error of half a pixel there
// is an error of half a pixel of disparity). Sets e's position, scale and
// profile; false when there is no clear edge or the profile leaves the image.
bool LocateColorEdge(const ImageF& color, int x, int y, const float* region_color,
                      const FlatRegionOptions& options, EdgePoint* e) {
  constexpr float kMaxMarch = 6.0f, kStep = 0.25f;
  auto diff_at = [&](float t, float* d) {
    float s[3];
    if (!SampleRgb(color, x + t * e->nx, y + t * e->ny, s)) return false;
    *d = std::abs(s[0] - region_color[0]) + std::abs(s[1] - region_color[1]) + std::abs(s[2] - region_color[2]);
    return true;
  };
  float t_out = -1.0f, d_out = 0.0f;
  for (float t = 0.5f; t <= kMaxMarch; t += kStep) {
    float d;
    if (!diff_at(t, &d)) break;
    if (d >= options.edge_contrast) {
      float d2;
      if (diff_at(t + 1.5f, &d2) && d2 >= options.edge_contrast) {
        t_out = t;
        d_out = std::max(d, d2);
      }
      break;
    }
  }
  if (t_out < 0) return false;
  const float half = 0.5f * d_out;
  float prev_t = 0.0f, prev_d = 0.0f;
  diff_at(0.0f, &prev_d);
  bool found = false;
  for (float t = kStep; t <= t_out + 1.5f; t += kStep) {
    float d;
    if (!diff_at(t, &d)) break;
    if (d >= half) {
      const float f = d > prev_d ? (half - prev_d) / (d - prev_d) : 0.0f;
      const float te = prev_t + f * (t - prev_t);
      e->x = x + te * e->nx;
      e->y = y + te * e->ny;
      found = true;
      break;
    }
    prev_t = t;
    prev_d = d;
  }
  if (!found) return false;
  e->scale = std::max(static_cast<float>(options.edge_contrast), 0.8f * d_out);
  bool inside_image = true;
  for (int i = 0; i < kProfile && inside_image; ++i) {
    float s3[3];
    const float o = kProfileStart + i * kProfileStep;
    inside_image = SampleRgb(color, e->x + o * e->nx, e->y + o * e->ny, s3);
    const float d = std::abs(s3[0] - region_color[0]) + std::abs(s3[1] - region_color[1]) +
                    std::abs(s3[2] - region_color[2]);
    e->profile[i] = std::min(1.0f, d / e->scale);
  }
  return inside_image;
}

// Step 2: the depth and ownership of each group's edges (at most
// max_edge_points per group, evenly subsampled), the points with a clear
// minimum only.
std::vector<std::vector<EdgePoint>> MeasureGroupEdges(
    const FlatGroups& groups, std::vector<std::vector<EdgePoint>>* points,
    const std::vector<Neighbor>& nbs, const std::vector<float>& inv_of, const ImageF& anchors,
    const ImageF& photo_weight, const CostVolume& grid, long long min_area,
    const FlatRegionOptions& options, FlatRegionStats* stats) {
  std::vector<std::vector<EdgePoint>> measured(groups.size());
  for (int g = 0; g < groups.size(); ++g) {
    if (groups.area[g] < min_area) continue;
    ++stats->groups;
    std::vector<EdgePoint>& pts = (*points)[g];
    if (pts.size() > static_cast<size_t>(options.max_edge_points)) {
      std::vector<EdgePoint> kept;
      const double stride = static_cast<double>(pts.size()) / options.max_edge_points;
      for (int i = 0; i < options.max_edge_points; ++i) kept.push_back(pts[static_cast<size_t>(i * stride)]);
      pts.swap(kept);
    }
    for (const EdgePoint& e : pts) {
      EdgePoint m = e;
      if (!MeasureEdge(nbs, groups.color[g].data(), inv_of, &m)) continue;
      m.kind = Classify(m, g, groups.group, anchors, photo_weight, grid, options);
      measured[g].push_back(m);
    }
    stats->edge_points += static_cast<int>(measured[g].size());
  }
  return measured;
}

// Step 3: a plane per group of at least `min_area` pixels from its own
// edges (FitPlane); the groups with and without one.
std::vector<PlaneFit> FitGroupPlanes(const FlatGroups& groups, int w,
                                     const std::vector<std::vector<EdgePoint>>& measured,
                                     long long min_area, int num_labels,
                                     const FlatRegionOptions& options,
                                     std::vector<int>* fitted_groups,
                                     std::vector<int>* unfitted_groups) {
  const size_t n = groups.group.size();
  std::vector<PlaneFit> fits(groups.size());
  for (int g = 0; g < groups.size(); ++g) {
    if (groups.area[g] < min_area) continue;
    GroupShape shape;
    shape.color = groups.color[g];
    for (size_t p = 0; p < n; p += 7)
      if (groups.group[p] == g) shape.samples.emplace_back(static_cast<float>(p % w), static_cast<float>(p / w));
    for (int x = 0; x < w && !shape.touches_top; ++x) shape.touches_top = groups.group[x] == g;
    fits[g] = FitPlane(measured[g], shape, options, num_labels, 0x9E3779B97F4A7C15ull + g);
    (fits[g].ok ? fitted_groups : unfitted_groups)->push_back(g);
  }
  return fits;
}

}  // namespace

FlatGroups SegmentFlatGroups(const ImageF& color, const ImageF& photo_weight,
                             const FlatRegionOptions& options) {
  const int w = color.width(), h = color.height();
  const size_t n = static_cast<size_t>(w) * h;
  std::vector<int> region;
  std::vector<std::array<double, 3>> mean;
  std::vector<int> area;
  GrowRegions(color, photo_weight, options, &region, &mean, &area);
  const int num_regions = static_cast<int>(mean.size());
  FlatGroups groups;
  if (num_regions == 0) return groups;
  util::UnionFind uf(num_regions);
  JoinRegions(region, mean, w, h, options, &uf);
  groups.group.assign(n, -1);
  groups.area.assign(num_regions, 0);
  std::vector<std::array<double, 3>> group_sum(num_regions, {0, 0, 0});
  for (size_t p = 0; p < n; ++p) {
    if (region[p] < 0) continue;
    const int g = uf.Find(region[p]);
    groups.group[p] = g;
    ++groups.area[g];
    for (int c = 0; c < 3; ++c) group_sum[g][c] += color.data()[3 * p + c];
  }
  groups.color.assign(num_regions, {0, 0, 0});
  for (int g = 0; g < num_regions; ++g)
    if (groups.area[g] > 0)
      for (int c = 0; c < 3; ++c) groups.color[g][c] = static_cast<float>(group_sum[g][c] / groups.area[g]);
  return groups;
}

std::vector<std::vector<EdgePoint>> FindEdgePoints(const ImageF& color, const FlatGroups& groups,
                                                   long long min_area,
                                                   const FlatRegionOptions& options) {
  const int w = color.width(), h = color.height();
  const std::vector<int>& group = groups.group;
  std::vector<std::vector<EdgePoint>> points(groups.size());
  for (int y = 1; y + 1 < h; ++y)
    for (int x = 1; x + 1 < w; ++x) {
      const size_t p = static_cast<size_t>(y) * w + x;
      const int g = group[p];
      if (g < 0 || groups.area[g] < min_area) continue;
      bool boundary = false;
      for (const auto& q : {p - 1, p + 1, p - w, p + w}) boundary |= group[q] != g;
      if (!boundary) continue;
      // Gradient of the group's indicator over a 5x5 window.
      float gx = 0, gy = 0;
      for (int v = -2; v <= 2; ++v)
        for (int u = -2; u <= 2; ++u) {
          const int xx = std::min(w - 1, std::max(0, x + u)), yy = std::min(h - 1, std::max(0, y + v));
          const float in = group[static_cast<size_t>(yy) * w + xx] == g ? 1.0f : 0.0f;
          gx += u * in;
          gy += v * in;
        }
      const float len = std::hypot(gx, gy);
      if (len < 1e-3f) continue;
      EdgePoint e;
      e.nx = -gx / len;
      e.ny = -gy / len;
      if (LocateColorEdge(color, x, y, groups.color[g].data(), options, &e)) points[g].push_back(e);
    }
  return points;
}

void AdoptPlanes(const FlatGroups& groups, int w, int h,
                 const std::vector<std::vector<EdgePoint>>& measured,
                 const std::vector<int>& fitted_groups, const std::vector<int>& unfitted_groups,
                 const FlatRegionOptions& options, std::vector<PlaneFit>* fits) {
  const std::vector<std::array<float, 3>>& color = groups.color;
  std::vector<std::array<int, 4>> box(groups.size(), {w, h, -1, -1});
  for (size_t p = 0; p < groups.group.size(); ++p) {
    const int g = groups.group[p];
    if (g < 0) continue;
    const int x = static_cast<int>(p % w), y = static_cast<int>(p / w);
    box[g] = {std::min(box[g][0], x), std::min(box[g][1], y), std::max(box[g][2], x), std::max(box[g][3], y)};
  }
  const double adopt2 = 4.0 * options.merge_color * options.merge_color;
  for (int g : unfitted_groups) {
    int best = -1, best_touching = -1;
    for (int f : fitted_groups) {
      double d2 = 0;
      for (int c = 0; c < 3; ++c) d2 += (color[g][c] - color[f][c]) * (color[g][c] - color[f][c]);
      if (d2 > adopt2) continue;
      const int gap = std::max({box[f][0] - box[g][2], box[g][0] - box[f][2], box[f][1] - box[g][3],
                                box[g][1] - box[f][3], 0});
      if (gap > options.adopt_distance) continue;
      int touching, violations;
      Score((*fits)[f].plane, measured[g], options.touch_labels, &touching, &violations);
      const int np = static_cast<int>(measured[g].size());
      if (violations > static_cast<int>(std::floor((1.0 - options.behind_fraction) * np))) continue;
      if (touching > best_touching) {
        best_touching = touching;
        best = f;
      }
    }
    if (best >= 0) (*fits)[g] = (*fits)[best];
  }
}

std::vector<float> AssignPriors(const ImageF& color, const ImageF& photo_weight,
                                const FlatGroups& groups, const std::vector<PlaneFit>& fits,
                                int num_labels, const FlatRegionOptions& options,
                                FlatRegionStats* stats) {
  const int w = color.width(), h = color.height();
  const size_t n = static_cast<size_t>(w) * h;
  const int L = num_labels;
  const std::vector<int>& group = groups.group;
  std::vector<float> prior(n, kNaN);
  const float spread2 = static_cast<float>(options.color_spread * options.color_spread);
  const float extend_w = static_cast<float>(options.extend_max_photo_weight);
  for (int g = 0; g < groups.size(); ++g) {
    if (!fits[g].ok) continue;
    ++stats->fitted;
    const Plane& pl = fits[g].plane;
    std::vector<int> stack;
    auto assign = [&](size_t p) {
      const double k = pl.At(static_cast<double>(p % w), static_cast<double>(p / w));
      prior[p] = static_cast<float>(std::min<double>(L - 1, std::max(0.0, k)));
      ++stats->pixels;
    };
    for (size_t p = 0; p < n; ++p)
      if (group[p] == g) {
        assign(p);
        stack.push_back(static_cast<int>(p));
      }
    while (!stack.empty()) {
      const int p = stack.back();
      stack.pop_back();
      const int px = p % w, py = p / w;
      const int nbr[4][2] = {{px - 1, py}, {px + 1, py}, {px, py - 1}, {px, py + 1}};
      for (const auto& q : nbr) {
        if (q[0] < 0 || q[1] < 0 || q[0] >= w || q[1] >= h) continue;
        const size_t qi = static_cast<size_t>(q[1]) * w + q[0];
        if (!std::isnan(prior[qi]) || group[qi] >= 0 || photo_weight.data()[qi] >= extend_w) continue;
        if (Dist2(groups.color[g].data(), color.data() + 3 * qi) > spread2) continue;
        assign(qi);
        stack.push_back(static_cast<int>(qi));
      }
    }
  }
  return prior;
}

}  // namespace flat

std::vector<float> FlatRegionPriors(const ImageF& color, const ImageF& photo_weight,
                                    const PinholeCamera& camera, const ImageF& anchors,
                                    const std::vector<FlatRegionNeighbor>& neighbors,
                                    const CostVolume& grid, const FlatRegionOptions& options,
                                    FlatRegionStats* stats) {
  const Status st = options.Check();
  if (!st.ok()) throw std::invalid_argument(st.message());
  const int w = color.width(), h = color.height();
  if (color.channels() != 3 || photo_weight.width() != w || photo_weight.height() != h ||
      anchors.width() != w || anchors.height() != h || camera.width != w || camera.height != h)
    throw std::invalid_argument("flat regions: colour, w_photo, anchors and camera differ in size");
  for (const FlatRegionNeighbor& nb : neighbors)
    if (!nb.color || nb.color->channels() != 3 || nb.color->width() != nb.camera.width ||
        nb.color->height() != nb.camera.height)
      throw std::invalid_argument("flat regions: a neighbour's colour image and camera differ in size");
  const size_t n = static_cast<size_t>(w) * h;
  FlatRegionStats local;
  if (stats) *stats = local;
  if (!options.enabled || neighbors.empty() || grid.num_labels < 2)
    return std::vector<float>(n, flat::kNaN);
  const int L = grid.num_labels;

  // 1. Groups of flat pixels, and their boundary points.
  const flat::FlatGroups groups = flat::SegmentFlatGroups(color, photo_weight, options);
  if (groups.size() == 0) return std::vector<float>(n, flat::kNaN);
  const long long min_area = std::max<long long>(1, std::llround(options.min_area_fraction * n));
  std::vector<std::vector<flat::EdgePoint>> points =
      flat::FindEdgePoints(color, groups, min_area, options);

  // Neighbours' homographies and gains.
  std::vector<flat::Neighbor> nbs(neighbors.size());
  for (size_t j = 0; j < neighbors.size(); ++j) {
    nbs[j].color = neighbors[j].color;
    nbs[j].hom = ComputePlaneHomography(camera, neighbors[j].camera);
    flat::EstimateGain(color, photo_weight, anchors, &nbs[j]);
  }
  std::vector<float> inv_of(L);
  for (int k = 0; k < L; ++k) inv_of[k] = static_cast<float>(grid.InvDepthOfLabel(k));

  // 2. Edge depths and ownership, per group.
  const std::vector<std::vector<flat::EdgePoint>> measured = flat::MeasureGroupEdges(
      groups, &points, nbs, inv_of, anchors, photo_weight, grid, min_area, options, &local);
  // 3. A plane per group from its own edges.
  std::vector<int> fitted_groups, unfitted_groups;
  std::vector<flat::PlaneFit> fits = flat::FitGroupPlanes(groups, w, measured, min_area, L, options,
                                                          &fitted_groups, &unfitted_groups);
  // 4. A group without a plane of its own takes that of a fitted group of the
  // same colour close by (the parts of a wall that poles cut apart), when
  // its own edges agree: (nearly) none in front of the plane.
  flat::AdoptPlanes(groups, w, h, measured, fitted_groups, unfitted_groups, options, &fits);
  // 5. Priors: the plane over the group's pixels and the pixels of its
  // colour connected to it that the flat test left out (a strip of wall
  // between two close poles, whose windows hold the poles' texture).
  std::vector<float> prior = flat::AssignPriors(color, photo_weight, groups, fits, L, options, &local);
  if (stats) *stats = local;
  return prior;
}

}  // namespace casual3d::depth

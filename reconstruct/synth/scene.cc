#include "reconstruct/synth/scene.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>

namespace casual3d::synth {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kHugeExtentM = 30.0;  // Solids larger than this skip the BVH.

bool HitsBox(const Eigen::Vector3d& lo, const Eigen::Vector3d& hi, const Eigen::Vector3d& o,
             const Eigen::Vector3d& inv_d, double t_max) {
  double t0 = 0.0, t1 = t_max;
  for (int k = 0; k < 3; ++k) {
    double ta = (lo[k] - o[k]) * inv_d[k];
    double tb = (hi[k] - o[k]) * inv_d[k];
    if (ta > tb) std::swap(ta, tb);
    // NaN (0 * inf when the origin is on a slab plane) is treated as a hit.
    t0 = ta > t0 ? ta : t0;
    t1 = tb < t1 ? tb : t1;
    if (t0 > t1) return false;
  }
  return true;
}

}  // namespace

Scene::Scene(std::vector<Primitive> primitives, std::vector<Material> materials)
    : primitives_(std::move(primitives)), materials_(std::move(materials)) {
  bounds_lo_.resize(primitives_.size());
  bounds_hi_.resize(primitives_.size());
  for (size_t i = 0; i < primitives_.size(); ++i) {
    PrimitiveBounds(primitives_[i], &bounds_lo_[i], &bounds_hi_[i]);
    const double extent = (bounds_hi_[i] - bounds_lo_[i]).maxCoeff();
    if (primitives_[i].is_moving || extent > kHugeExtentM) {
      unbounded_.push_back(static_cast<int>(i));
    } else {
      order_.push_back(static_cast<int>(i));
    }
  }
  if (!order_.empty()) {
    nodes_.reserve(2 * order_.size());
    Build(0, static_cast<int>(order_.size()), 0);
  }
}

int Scene::Build(int first, int count, int depth) {
  const int index = static_cast<int>(nodes_.size());
  nodes_.emplace_back();
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(kInf), hi = -lo;
  Eigen::Vector3d clo = lo, chi = hi;  // Centroid bounds.
  for (int i = first; i < first + count; ++i) {
    const int p = order_[i];
    lo = lo.cwiseMin(bounds_lo_[p]);
    hi = hi.cwiseMax(bounds_hi_[p]);
    const Eigen::Vector3d c = 0.5 * (bounds_lo_[p] + bounds_hi_[p]);
    clo = clo.cwiseMin(c);
    chi = chi.cwiseMax(c);
  }
  nodes_[index].lo = lo;
  nodes_[index].hi = hi;
  if (count <= 2 || depth > 40) {
    nodes_[index].first = first;
    nodes_[index].count = count;
    return index;
  }
  int axis = 0;
  (chi - clo).maxCoeff(&axis);
  const int mid = first + count / 2;
  // Median split along the widest centroid axis; ties broken by index for determinism.
  std::nth_element(order_.begin() + first, order_.begin() + mid, order_.begin() + first + count,
                   [&](int a, int b) {
                     const double ca = bounds_lo_[a][axis] + bounds_hi_[a][axis];
                     const double cb = bounds_lo_[b][axis] + bounds_hi_[b][axis];
                     return ca < cb || (ca == cb && a < b);
                   });
  const int left = Build(first, mid - first, depth + 1);
  const int right = Build(mid, first + count - mid, depth + 1);
  nodes_[index].left = left;
  nodes_[index].right = right;
  return index;
}

template <typename Visit>
void Scene::Traverse(const Eigen::Vector3d& origin, const Eigen::Vector3d& dir, double t_max,
                     Visit&& visit) const {
  for (int p : unbounded_) visit(p);
  if (nodes_.empty()) return;
  const Eigen::Vector3d inv_d(1.0 / dir.x(), 1.0 / dir.y(), 1.0 / dir.z());
  int stack[128];
  int top = 0;
  stack[top++] = 0;
  while (top > 0) {
    const Node& node = nodes_[stack[--top]];
    if (!HitsBox(node.lo, node.hi, origin, inv_d, t_max)) continue;
    if (node.left < 0) {
      for (int i = node.first; i < node.first + node.count; ++i) visit(order_[i]);
    } else {
      stack[top++] = node.right;
      stack[top++] = node.left;
    }
  }
}

Scene Scene::Displaced(const Eigen::Vector3d& offset_m) const {
  Scene moved = *this;
  for (int p : unbounded_) {
    if (moved.primitives_[p].is_moving) moved.primitives_[p].centre += offset_m;
  }
  return moved;
}

bool Scene::TraceClosest(const Eigen::Vector3d& origin, const Eigen::Vector3d& dir, double t_min,
                         Hit* hit) const {
  double best = kInf;
  int best_prim = -1, best_face = 0;
  auto test = [&](int p) {
    Interval iv;
    if (!IntersectPrimitive(primitives_[p], origin, dir, &iv)) return;
    if (iv.t_in > t_min && (iv.t_in < best || (iv.t_in == best && p < best_prim))) {
      best = iv.t_in;
      best_prim = p;
      best_face = iv.face_in;
    }
  };
  for (int p : unbounded_) test(p);
  if (!nodes_.empty()) {
    // Front-to-back traversal, pruning boxes beyond the best hit so far.
    const Eigen::Vector3d inv_d(1.0 / dir.x(), 1.0 / dir.y(), 1.0 / dir.z());
    int stack[128];
    int top = 0;
    stack[top++] = 0;
    while (top > 0) {
      const Node& node = nodes_[stack[--top]];
      if (!HitsBox(node.lo, node.hi, origin, inv_d, best)) continue;
      if (node.left < 0) {
        for (int i = node.first; i < node.first + node.count; ++i) test(order_[i]);
        continue;
      }
      // Visit the child whose centre is nearer along the ray first.
      const Node& l = nodes_[node.left];
      const Node& r = nodes_[node.right];
      const double dl = (l.lo + l.hi - 2.0 * origin).dot(dir);
      const double dr = (r.lo + r.hi - 2.0 * origin).dot(dir);
      if (dl <= dr) {
        stack[top++] = node.right;
        stack[top++] = node.left;
      } else {
        stack[top++] = node.left;
        stack[top++] = node.right;
      }
    }
  }
  if (best_prim < 0) return false;
  hit->t = best;
  hit->primitive = best_prim;
  hit->face = best_face;
  return true;
}

int Scene::TraceTwoSurfaces(const Eigen::Vector3d& origin, const Eigen::Vector3d& dir, Hit* first,
                            Hit* second, bool* into_ground) const {
  struct Entry {
    Interval iv;
    int prim;
  };
  thread_local std::vector<Entry> entries;
  entries.clear();
  Traverse(origin, dir, kInf, [&](int p) {
    Interval iv;
    if (IntersectPrimitive(primitives_[p], origin, dir, &iv) && iv.t_out > 0) {
      entries.push_back({iv, p});
    }
  });
  std::sort(entries.begin(), entries.end(), [](const Entry& a, const Entry& b) {
    return a.iv.t_in < b.iv.t_in || (a.iv.t_in == b.iv.t_in && a.prim < b.prim);
  });
  // Merge overlapping (or touching) intervals into runs of solid matter.
  *into_ground = false;
  int found = 0;
  bool run_has_ground = false;
  double run_end = -kInf;
  for (const Entry& e : entries) {
    const double tolerance = 1e-6 * std::max(1.0, std::abs(run_end));
    const bool ground = primitives_[e.prim].is_ground;
    if (e.iv.t_in <= run_end + tolerance || e.iv.t_in <= 0) {
      // Continues the current run (or the origin is inside this solid, whose
      // inside is not a visible surface).
      run_end = std::max(run_end, e.iv.t_out);
      run_has_ground = run_has_ground || ground;
      continue;
    }
    if (found > 0 && run_has_ground) break;  // Nothing is behind the ground.
    if (found == 2) break;
    Hit* h = found == 0 ? first : second;
    h->t = e.iv.t_in;
    h->primitive = e.prim;
    h->face = e.iv.face_in;
    run_end = e.iv.t_out;
    run_has_ground = ground;
    ++found;
  }
  if (found == 1 && run_has_ground) *into_ground = true;
  return found;
}

Eigen::Vector3d Scene::Normal(const Hit& hit, const Eigen::Vector3d& origin,
                              const Eigen::Vector3d& dir) const {
  return PrimitiveNormal(primitives_[hit.primitive], origin + hit.t * dir, hit.face);
}

Eigen::Vector3d Scene::Shade(const Hit& hit, const Eigen::Vector3d& origin,
                             const Eigen::Vector3d& dir, double pixel_angle_rad) const {
  const Primitive& prim = primitives_[hit.primitive];
  const Eigen::Vector3d p = origin + hit.t * dir;
  const Eigen::Vector3d n = PrimitiveNormal(prim, p, hit.face);
  const double cos_view = std::max(0.2, std::abs(n.dot(dir)));
  const double footprint = hit.t * pixel_angle_rad / cos_view;
  const Eigen::Vector3d albedo =
      EvaluateAlbedo(materials_[prim.material], p, PrimitiveFaceUv(prim, p, hit.face), footprint);
  // Lambertian: sun plus a hemispherical sky/ground ambient term (no shadows).
  const Eigen::Vector3d sky_ambient(0.42, 0.48, 0.58), ground_ambient(0.20, 0.19, 0.16);
  const double up = 0.5 + 0.5 * n.y();
  const Eigen::Vector3d ambient = ground_ambient + (sky_ambient - ground_ambient) * up;
  const Eigen::Vector3d sun(1.05, 1.0, 0.92);
  const double lambert = std::max(0.0, n.dot(sun_direction_));
  return albedo.cwiseProduct(ambient + sun * lambert);
}

Eigen::Vector3d Scene::Sky(const Eigen::Vector3d& dir) const {
  const Eigen::Vector3d horizon(0.78, 0.84, 0.92), zenith(0.22, 0.38, 0.78);
  const double e = std::max(0.0, dir.y());
  const double t = std::pow(e, 0.6);
  Eigen::Vector3d c = horizon + (zenith - horizon) * t;
  const double glow = std::max(0.0, dir.dot(sun_direction_));
  c += Eigen::Vector3d(0.35, 0.3, 0.2) * std::pow(glow, 24.0);
  return c;
}

}  // namespace casual3d::synth

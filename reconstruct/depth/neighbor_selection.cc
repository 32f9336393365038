#include "reconstruct/depth/neighbor_selection.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>
#include <unordered_map>

namespace casual3d::depth {

namespace {

// Angle at x between the rays to the two camera centres, degrees.
double TriangulationAngleDeg(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& x) {
  const Eigen::Vector3d ra = (a - x).normalized();
  const Eigen::Vector3d rb = (b - x).normalized();
  return std::acos(std::min(1.0, std::max(-1.0, ra.dot(rb)))) * (180.0 / M_PI);
}

// A shared point's contribution g(theta) to a pair's score (neighbor_selection.h).
double AngleScore(double t_deg, const NeighborOptions& options) {
  if (!(t_deg <= options.max_angle_deg)) return 0.0;
  const double g = std::min(1.0, t_deg / options.theta_good_deg);
  return g * g;
}

// Reorders the first `num_primary` views of `order` (the primary pairs, ranked
// by score) by greedy coverage of view i's points (neighbor_selection.h).
// Ties in gain keep the score order.
void CoverageOrder(int i, const std::vector<NeighborInput>& views,
                   const std::vector<std::pair<long long, Eigen::Vector3d>>& point_positions,
                   const std::vector<std::vector<int>>& seen, const NeighborOptions& options,
                   size_t num_primary, std::vector<int>* order) {
  if (num_primary < 2) return;
  // Reference point index -> slot, and per candidate its (slot, g) pairs.
  const std::vector<int>& mine = seen[i];
  std::unordered_map<int, int> slot;
  slot.reserve(mine.size());
  for (size_t s = 0; s < mine.size(); ++s) slot[mine[s]] = static_cast<int>(s);
  std::vector<std::vector<std::pair<int, float>>> gains(num_primary);
  for (size_t c = 0; c < num_primary; ++c) {
    const int j = (*order)[c];
    for (int p : seen[j]) {
      auto it = slot.find(p);
      if (it == slot.end()) continue;
      const double g =
          AngleScore(TriangulationAngleDeg(views[i].center, views[j].center, point_positions[p].second), options);
      if (g > 0.0) gains[c].push_back({it->second, static_cast<float>(g)});
    }
  }
  std::vector<int> coverage(mine.size(), 0);  // Picked views that observe each point.
  std::vector<char> taken(num_primary, 0);
  std::vector<int> picked;
  const size_t picks = std::min(num_primary, static_cast<size_t>(options.coverage_picks));
  while (picked.size() < picks) {
    int best = -1;
    double best_gain = 0.0;
    for (size_t c = 0; c < num_primary; ++c) {
      if (taken[c]) continue;
      double gain = 0.0;
      for (const auto& [s, g] : gains[c]) gain += coverage[s] < options.coverage_k ? g : 0.0f;
      if (gain > best_gain) {  // Strict: ties keep the score order.
        best_gain = gain;
        best = static_cast<int>(c);
      }
    }
    if (best < 0) break;  // Everything covered coverage_k times: the rest by score.
    taken[best] = 1;
    picked.push_back((*order)[best]);
    for (const auto& sg : gains[best]) ++coverage[sg.first];
  }
  std::vector<int> result = picked;
  for (size_t c = 0; c < order->size(); ++c)
    if (c >= num_primary || !taken[c]) result.push_back((*order)[c]);
  *order = std::move(result);
}

}  // namespace

std::vector<std::vector<int>> RankNeighbors(
    const std::vector<NeighborInput>& views,
    const std::vector<std::pair<long long, Eigen::Vector3d>>& point_positions,
    const NeighborOptions& options) {
  const Status st = options.Check();
  if (!st.ok()) throw std::invalid_argument(st.message());
  const int n = static_cast<int>(views.size());
  std::unordered_map<long long, int> point_index;
  for (size_t i = 0; i < point_positions.size(); ++i) point_index[point_positions[i].first] = static_cast<int>(i);
  // Which views observe each point.
  std::vector<std::vector<int>> observers(point_positions.size());
  for (int v = 0; v < n; ++v)
    for (long long id : views[v].point_ids) {
      auto it = point_index.find(id);
      if (it != point_index.end()) observers[it->second].push_back(v);
    }
  for (auto& o : observers) {
    std::sort(o.begin(), o.end());
    o.erase(std::unique(o.begin(), o.end()), o.end());
  }
  // The points each view observes, by index.
  std::vector<std::vector<int>> seen(n);
  for (size_t p = 0; p < observers.size(); ++p)
    for (int v : observers[p]) seen[v].push_back(static_cast<int>(p));

  // Pairwise angle lists, accumulated per point.
  std::vector<std::vector<std::vector<float>>> angles(n, std::vector<std::vector<float>>(n));
  for (size_t p = 0; p < observers.size(); ++p) {
    const auto& obs = observers[p];
    const Eigen::Vector3d& x = point_positions[p].second;
    for (size_t a = 0; a < obs.size(); ++a)
      for (size_t b = a + 1; b < obs.size(); ++b)
        angles[obs[a]][obs[b]].push_back(
            static_cast<float>(TriangulationAngleDeg(views[obs[a]].center, views[obs[b]].center, x)));
  }

  // Fallback score from geometry alone.
  std::vector<double> baselines;
  for (int i = 0; i < n; ++i)
    for (int j = i + 1; j < n; ++j) baselines.push_back((views[i].center - views[j].center).norm());
  double median_baseline = 1.0;
  if (!baselines.empty()) {
    std::nth_element(baselines.begin(), baselines.begin() + baselines.size() / 2, baselines.end());
    median_baseline = std::max(1e-12, baselines[baselines.size() / 2]);
  }
  auto fallback = [&](int i, int j) {
    const double c = std::max(0.0, views[i].direction.dot(views[j].direction));
    const double b = (views[i].center - views[j].center).norm();
    return c * std::min(1.0, b / median_baseline);
  };

  std::vector<std::vector<int>> ranked(n);
  for (int i = 0; i < n; ++i) {
    // (primary, score): primary pairs (enough shared points with usable angles) first.
    std::vector<std::pair<std::pair<int, double>, int>> cand;
    for (int j = 0; j < n; ++j) {
      if (j == i) continue;
      std::vector<float> a = i < j ? angles[i][j] : angles[j][i];
      int primary = 0;
      double score = fallback(i, j);
      if (static_cast<int>(a.size()) >= options.min_shared_points) {
        std::nth_element(a.begin(), a.begin() + a.size() / 2, a.end());
        const double med = a[a.size() / 2];
        if (med >= options.min_angle_deg && med <= options.max_angle_deg) {
          primary = 1;
          score = 0.0;
          for (float t : a) score += AngleScore(t, options);
        }
      }
      cand.push_back({{primary, score}, j});
    }
    std::sort(cand.begin(), cand.end(), [](const auto& x, const auto& y) {
      if (x.first.first != y.first.first) return x.first.first > y.first.first;
      if (x.first.second != y.first.second) return x.first.second > y.first.second;
      return x.second < y.second;
    });
    size_t num_primary = 0;
    for (const auto& c : cand) {
      ranked[i].push_back(c.second);
      num_primary += c.first.first == 1;
    }
    if (options.coverage_k > 0)
      CoverageOrder(i, views, point_positions, seen, options, num_primary, &ranked[i]);
  }
  return ranked;
}

}  // namespace casual3d::depth

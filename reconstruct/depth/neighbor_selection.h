#pragma once

// Neighbour selection for the plane sweep (Sec. 4.3.1): for each photo, the
// other photos ranked by how useful they are as stereo partners.
//
// Score of view j for reference i (our choice; the supplement is lost):
//   sum over sparse points seen by both of g(theta), g(theta) = min(1, theta / theta_good)^2
// where theta is the triangulation angle at the point: shared points show
// overlap, the angle term rewards the baseline that makes depth measurable.
// Views sharing fewer than min_shared_points, or whose median triangulation
// angle is below min_angle_deg (no measurable parallax) or above
// max_angle_deg (too different for patch matching), are ranked after all
// the others by the fallback score. When a model has no usable points, views
// are ranked by the fallback: cos(angle between optical axes), positive only,
// times min(1, baseline / median baseline).
//
// Coverage (our addition): the ranked views are picked greedily so that every
// part of the reference has partners, not only the part most views share.
// Each pick maximises the score restricted to the reference's points that
// fewer than coverage_k picked views observe (the coverage the sweep's best-k
// aggregation needs); once every point is covered coverage_k times, the rest
// follow by score. The first coverage_k picks are the best-scoring views. At
// the ends of a partial rig the highest-scoring views all lie on one side,
// and the plain score leaves the other side of the frame with one partner or
// none (docs/DECISIONS.md, "Dense: neighbours picked for coverage").

#include <vector>

#include <Eigen/Core>

#include "format/status.h"
#include "reconstruct/util/options_fields.h"

namespace casual3d::depth {

struct NeighborOptions {
  double theta_good_deg = 5.0;    // Triangulation angle with full score, degrees. (0, 90].
  double min_angle_deg = 0.1;     // Median angle below which a pair has no parallax. [0, 90).
  double max_angle_deg = 45.0;    // Median angle above which patches differ too much. (0, 180].
  int min_shared_points = 10;     // Shared sparse points for a ranked pair. [1, 1e6].
  // Partners each point should have before the next pick may favour the
  // points already covered; 0 = rank by the plain score alone. One more than
  // the sweep's best_k of 2 (measurements: docs/DECISIONS.md, "Dense:
  // neighbours picked for coverage"). [0, 16].
  int coverage_k = 3;
  // Picks made greedily for coverage; later ranks go by score. [1, 64].
  int coverage_picks = 16;

  template <typename Self, typename Visitor>
  static void DescribeFields(Self& o, Visitor& v) {
    using R = util::Rule;
    v.Field("theta_good_deg", o.theta_good_deg, R::OpenClosed(0, 90), "Triangulation angle with full score, degrees");
    v.Field("min_angle_deg", o.min_angle_deg, R::ClosedOpen(0, 90), "Median angle below which a pair has no parallax, degrees");
    v.Field("max_angle_deg", o.max_angle_deg, R::OpenClosed(0, 180), "Median angle above which patches differ too much, degrees");
    v.Field("min_shared_points", o.min_shared_points, R::Closed(1, 1e6), "Shared sparse points for a ranked pair");
    v.Field("coverage_k", o.coverage_k, R::Closed(0, 16),
            "Neighbours are picked so that each part of the photo has this many partners (0: by score alone)");
    v.Field("coverage_picks", o.coverage_picks, R::Closed(1, 64), "Picks made greedily for coverage");
    v.Require(o.max_angle_deg > o.min_angle_deg, "max_angle_deg", "must exceed min_angle_deg");
  }
  Status Check() const { return util::CheckFields(*this); }
};

// What neighbour selection needs to know about one view.
struct NeighborInput {
  Eigen::Vector3d center = Eigen::Vector3d::Zero();     // Camera centre, world.
  Eigen::Vector3d direction = Eigen::Vector3d::UnitZ(); // Optical axis, world (unit).
  std::vector<long long> point_ids;                     // Sparse points it observes (any order).
};

// Returns, for every view, the other views ordered best first (all of them;
// callers take the first few). `points` holds the sparse points' positions,
// indexed by the ids in point_ids (via `point_positions`, a map from id to
// position built by the caller as a sorted vector of (id, xyz)).
std::vector<std::vector<int>> RankNeighbors(
    const std::vector<NeighborInput>& views,
    const std::vector<std::pair<long long, Eigen::Vector3d>>& point_positions,
    const NeighborOptions& options);

}  // namespace casual3d::depth

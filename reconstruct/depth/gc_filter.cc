#include "reconstruct/depth/gc_filter.h"

#include <cmath>
#include <stdexcept>
#include <string>

#include "base/parallel_for.h"

namespace casual3d::depth {

ImageF GeometricConsistencyFilter(int ref, const std::vector<const DenseView*>& views,
                                  const std::vector<const ImageF*>& depth_maps,
                                  const std::vector<int>& others, double inv_step,
                                  const GcFilterOptions& options, int num_threads) {
  const Status st = options.Check();
  if (!st.ok()) throw std::invalid_argument(st.message());
  const ImageF& src = *depth_maps[ref];
  const PinholeCamera& cr = views[ref]->camera;
  ImageF out(src.width(), src.height(), 1, 0.0f);
  const double tol = options.tolerance_labels * inv_step;

  // Relative pose from the reference camera to each checked view, and K_j.
  struct Check {
    Eigen::Matrix3d r;
    Eigen::Vector3d t;
    const PinholeCamera* cam;
    const ImageF* depth;
  };
  std::vector<Check> checks;
  for (int j : others) {
    if (j == ref || static_cast<int>(checks.size()) >= options.max_views) continue;
    Check c;
    c.cam = &views[j]->camera;
    c.r = c.cam->R * cr.R.transpose();
    c.t = c.cam->t - c.r * cr.t;
    c.depth = depth_maps[j];
    checks.push_back(c);
  }
  const int min_support = std::min<int>(options.min_support, static_cast<int>(checks.size()));
  if (min_support == 0) return out;

  base::ParallelFor(0, src.height(), base::ResolveThreads(num_threads), [&](int64_t yy) {
    const int y = static_cast<int>(yy);
    for (int x = 0; x < src.width(); ++x) {
      const double d = src.at(x, y);
      if (!(d > 0)) continue;
      const Eigen::Vector3d p_ref(((x + 0.5) - cr.cx) / cr.fx * d, ((y + 0.5) - cr.cy) / cr.fy * d,
                                  d);
      int support = 0, violations = 0;
      for (const Check& c : checks) {
        const Eigen::Vector3d pj = c.r * p_ref + c.t;
        if (pj.z() <= 0) continue;
        const double u = c.cam->fx * pj.x() / pj.z() + c.cam->cx;
        const double v = c.cam->fy * pj.y() / pj.z() + c.cam->cy;
        const int xi = static_cast<int>(std::floor(u)), yi = static_cast<int>(std::floor(v));
        if (xi < 0 || yi < 0 || xi >= c.depth->width() || yi >= c.depth->height()) continue;
        const double dj = c.depth->at(xi, yi);
        if (!(dj > 0)) continue;
        const double diff = 1.0 / pj.z() - 1.0 / dj;  // > 0: the point is nearer than j's surface.
        if (std::abs(diff) <= tol) {
          ++support;
        } else if (diff > 0) {
          ++violations;
        }
      }
      if (support >= min_support && violations <= options.max_violation_ratio * support)
        out.at(x, y) = static_cast<float>(d);
    }
  });
  return out;
}

}  // namespace casual3d::depth

#include "reconstruct/stitch/full_warps.h"

#include <cmath>

namespace casual3d::stitch {

void BlendMembers(const FullWarps& warps, int best, int x, int y, float front_depth,
                  const StitchOptions& options, std::vector<std::pair<int, double>>* members) {
  members->clear();
  int lx, ly;
  warps.layer(best).ToCrop(x, y, warps.width, &lx, &ly);
  const float depth = warps.layer(best).depth_m.at(lx, ly);
  for (int l = 0; l < static_cast<int>(warps.full.size()); ++l) {
    const warp::WarpedLayer& other = warps.layer(l);
    int ox, oy;
    // The same tests the chosen photo passed (on the back layer, not in
    // front of the front), then the depth agreement.
    if (!warps.Usable(l, x, y, front_depth, &ox, &oy)) continue;
    const float d = other.depth_m.at(ox, oy);
    if (l != best && std::abs(d - depth) > options.blend_depth_tolerance * depth) continue;
    members->emplace_back(l, std::exp(-kUpsampleStretchWeight * other.stretch.at(ox, oy)));
  }
}

uint64_t BlendKey(const std::vector<std::pair<int, double>>& members) {
  uint64_t h = 1469598103934665603ull;
  for (const auto& e : members) {
    h ^= static_cast<uint64_t>(e.first) + 1;
    h *= 1099511628211ull;
  }
  return h;
}

}  // namespace casual3d::stitch

#pragma once

// The built-in synthetic scene: an outdoor courtyard around a rig centre, built
// to exercise the difficulties of casual 3D photography (Hedman et al. 2017):
//   near objects at 0.6-2 m with thin structures and depth edges (a stone
//   pedestal with a ball, a cube on a 8 mm stand, a cluster of 5-9 mm rods, a
//   slanted rod, a post), far geometry at 5-30 m (a brick building, facades,
//   trees, rocks, a fence), a large textureless wall (about 7 x 4 m at 6 m),
//   sky at infinity with a gradient, and repeated textures (bricks whose
//   colours repeat every 4 x 3 bricks, window grids, fence posts every 0.5 m).
// The rig centre looks along -Z (forward) from kRigCentre; the forward view
// holds the near objects, the textureless wall, the brick building and sky.
// The scene surrounds the centre in every direction (360 x 180 degrees), with
// the ground a 45 m disc (beyond it, below the horizon, is the sky's horizon colour).

#include <cstdint>

#include <Eigen/Core>

#include "reconstruct/synth/scene.h"

namespace casual3d::synth {

// Rig centre in world coordinates (metres): eye height 1.5 m above the ground.
inline Eigen::Vector3d DefaultRigCentre() { return Eigen::Vector3d(0.0, 1.5, 0.0); }

// Builds the scene. `seed` varies the textures (the layout is fixed). The one
// moving object (a blue ball about 1.7 m ahead) is at its position at time 0;
// use Scene::Displaced to move it.
Scene BuildDefaultScene(uint64_t seed);

}  // namespace casual3d::synth

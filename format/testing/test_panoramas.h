#pragma once

// Procedural two-layer panoramas for tests and benchmarks of format/: a room of
// planes around the centre with a sphere in front of one wall, so that the front
// layer has depth edges and the back layer fills the disocclusion behind the
// sphere. Deterministic; standard library only.

#include "format/two_layer.h"

namespace casual3d {
namespace testing {

struct RoomOptions {
  bool with_sphere = true;      // The foreground object; without it all nodes are planar.
  bool with_back_layer = true;  // Back nodes (the room) behind the sphere.
  double sphere_radius_m = 0.6;
  double sphere_centre[3] = {0.4, -0.3, -1.6};  // Panorama frame, metres.
};

// A closed box room x in [-2.0, 3.0], y in [-1.5, 2.5], z in [-4.0, 2.5]
// (metres), every pixel has a front node; with a sphere, back nodes exist
// behind it. Links come from LinkByDepthRatio(0.75).
TwoLayerPanorama MakeRoomPanorama(int width, int height, const RoomOptions& options = {});

// A sphere of radius `radius_m` around the centre: every front node at that
// depth, normals pointing inwards, fully linked. No back layer.
TwoLayerPanorama MakeSpherePanorama(int width, int height, float radius_m);

// Recomputes all links as Sec. 4.4.3 step 2 does: for each pair of neighbouring
// pixels, the node pair with the most similar depth is linked if
// min(d)/max(d) > min_ratio; then the other pair that does not cross it, if any,
// is linked under the same test.
void LinkByDepthRatio(TwoLayerPanorama* pano, float min_ratio);

}  // namespace testing
}  // namespace casual3d

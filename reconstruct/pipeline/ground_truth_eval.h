#pragma once

// Compares a two-layer panorama with a synthetic capture's ground truth
// (reconstruct/synth/ground_truth_panorama.h: first and second surface along
// every ray from the rig centre), with the measures of the panorama stages'
// acceptance (spec/stage-panorama.md, "Evaluation"):
//   front accuracy: of the pixels with a finite ground-truth first surface and
//     a front node, the fraction within 3% relative depth;
//   back near edges: of the pixels within 5 pixels of a ground-truth depth edge
//     (a pixel whose first surface is at least 10% nearer than a pixel within
//     5 pixels) that have a ground-truth second surface and a front node (are
//     inside the reconstructed field of view), the fraction with a back node;
//   links across edges: of the 4-neighbour pairs whose ground-truth first
//     surfaces differ by more than 10% in depth and are not one smooth surface
//     (each pixel's depth is more than 10% off the plane through its
//     neighbour's point with its normal: a grazing floor is no edge), and whose
//     front nodes both lie within 5% of their ground truth (so that they do
//     show the two surfaces), the fraction linked front to front.
// The panorama and the ground truth must have the same size and frame.

#include <string>

#include "format/image.h"
#include "format/two_layer.h"

namespace casual3d::pipeline {

struct GroundTruthComparison {
  long front_truth_pixels = 0;   // Finite ground-truth first surface.
  long front_covered = 0;        // ... with a front node.
  long front_within_3pct = 0;
  long back_edge_pixels = 0;     // Second surface within 5 px of a depth edge.
  long back_edge_present = 0;    // ... with a back node.
  long edge_pairs = 0;           // Depth-edge pairs whose nodes match the truth.
  long edge_pairs_linked = 0;

  double FrontAccuracy() const { return front_covered ? double(front_within_3pct) / front_covered : 0; }
  double FrontCoverage() const { return front_truth_pixels ? double(front_covered) / front_truth_pixels : 0; }
  double BackNearEdges() const { return back_edge_pixels ? double(back_edge_present) / back_edge_pixels : 0; }
  double LinksAcrossEdges() const { return edge_pairs ? double(edge_pairs_linked) / edge_pairs : 0; }
};

// `front_depth` and `back_depth`: ground-truth distances (1 channel each,
// +inf sky, NaN where there is no second surface); `front_normal`: the first
// surface's unit normals (3 channels, panorama frame; zero for sky).
// If `map` is not null it receives an RGB picture of the comparison: grey
// front nodes within 3%, red front nodes off by more, black uncovered; near
// depth edges with a second surface, green where a back node exists and
// magenta where it is missing.
GroundTruthComparison CompareWithGroundTruth(const TwoLayerPanorama& pano, const ImageF& front_depth,
                                             const ImageF& back_depth, const ImageF& front_normal,
                                             Image8* map = nullptr);

// Reads front.Z, back.Z and front.N* of a ground-truth panorama.exr and compares.
// Throws std::runtime_error naming the file on a missing file or size mismatch.
GroundTruthComparison CompareWithGroundTruthFile(const TwoLayerPanorama& pano,
                                                 const std::string& panorama_exr,
                                                 Image8* map = nullptr);

}  // namespace casual3d::pipeline

#pragma once

// The ground-truth panorama of a synthetic capture: from the rig centre, for
// each pixel of an equirectangular grid (format/equirect.h: panorama frame +X
// right, +Y up, -Z forward; one ray through each pixel centre), the first and
// the second surface along the ray (see Scene: the second surface is where the
// ray next enters solid matter after leaving the first solid, or the sky).
//
// Channels (float, in this order in memory; OpenEXR stores them sorted):
//   front.R front.G front.B  linear radiance at exposure 1 (sky: the sky colour)
//   front.Z                  distance from the centre along the ray, metres; +inf for sky
//   front.NX front.NY front.NZ  unit outward normal, panorama frame; 0 0 0 for sky
//   back.R back.G back.B back.Z back.NX back.NY back.NZ  the same for the second
//     surface: the sky (Z = +inf, normal 0) when the ray leaves the first solid
//     into the open; Z = NaN and colour and normal 0 where there is no second
//     surface (the first is the sky, or the ray ends in the ground, which is
//     solid all the way down).
// The moving object, if any, is where it is in the first photo.

#include <array>
#include <string>

#include "format/equirect.h"
#include "format/image.h"
#include "reconstruct/synth/scene.h"

namespace casual3d::synth {

enum PanoramaChannel : int {
  kFrontR = 0, kFrontG, kFrontB, kFrontZ, kFrontNX, kFrontNY, kFrontNZ,
  kBackR, kBackG, kBackB, kBackZ, kBackNX, kBackNY, kBackNZ,
  kNumPanoramaChannels
};

// The OpenEXR channel names, indexed by PanoramaChannel.
const std::array<std::string, kNumPanoramaChannels>& PanoramaChannelNames();

struct GroundTruthPanorama {
  ImageF pixels;        // width x height x kNumPanoramaChannels.
  PanoramaFrame frame;  // Panorama frame in world coordinates.
};

// Renders the ground-truth panorama of `scene` seen from `frame`'s centre.
// `width` = 2 * `height` is usual; both > 0. num_threads 0: all cores.
GroundTruthPanorama RenderGroundTruthPanorama(const Scene& scene, const PanoramaFrame& frame,
                                              int width, int height, int num_threads);

}  // namespace casual3d::synth

#pragma once

// Deprecated: the earlier names of format/color_atlas.h, kept so that code
// written against them still builds (docs/SDK.md, "Deprecated names"). New
// code includes format/color_atlas.h and calls BuildColorAtlas.

#include "format/color_atlas.h"

namespace casual3d {

// BuildColorAtlas(pano, channels).
[[deprecated("use BuildColorAtlas (format/color_atlas.h)")]] inline Image8 BuildColourAtlas(
    const TwoLayerPanorama& pano, int channels = 3) {
  return BuildColorAtlas(pano, channels);
}

}  // namespace casual3d

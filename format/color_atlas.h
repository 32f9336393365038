#pragma once

// The colour atlas that Mesh::uvs address (format/mesh.h, spec/mesh.md Sec. 3):
// the front layer's colour panorama above the back layer's, with the fill rule
// that lets a triangle joining front and back nodes sample one half only. The
// one implementation used by the glTF export, the WebAssembly viewer and the
// renderer tests.

#include <cstdint>

#include "format/image.h"
#include "format/two_layer.h"

namespace casual3d {

// The atlas of `pano`: width x 2*height, `channels` 3 (RGB) or 4 (RGBA, alpha
// 255), sRGB as stored. Texel (x, y + layer * height) holds the colour of node
// (x, y, layer); where that node is absent it holds the colour of the other
// layer's node at (x, y) (the fill rule, normative in spec/mesh.md Sec. 3), and
// black where neither layer has a node. Returns an empty image if `channels`
// is neither 3 nor 4 or the panorama is empty. O(width * height).
Image8 BuildColorAtlas(const TwoLayerPanorama& pano, int channels = 3);

}  // namespace casual3d

#pragma once

// The `graph_sha256` of spec/package.md Sec. 9 (the conformance vectors'
// expected.json): the bytes `present`, `label` and `links` of the front layer
// (each width * height bytes, row-major), then the same for the back layer,
// and their SHA-256. Used by the tests that write and check expected.json and
// by the test of the spec's worked example, so that the example and the
// vectors follow one definition.

#include <cstdint>
#include <string>
#include <vector>

#include "format/sha256.h"
#include "format/two_layer.h"

namespace casual3d::testing {

// 6 * width * height bytes: front present, label, links; back present, label, links.
inline std::vector<uint8_t> GraphBytes(const TwoLayerPanorama& pano) {
  std::vector<uint8_t> bytes;
  bytes.reserve(6 * static_cast<size_t>(pano.width()) * pano.height());
  for (int l = 0; l < kNumLayers; ++l) {
    const LayerData& layer = pano.layer(l);
    bytes.insert(bytes.end(), layer.present.begin(), layer.present.end());
    bytes.insert(bytes.end(), layer.label.begin(), layer.label.end());
    bytes.insert(bytes.end(), layer.links.begin(), layer.links.end());
  }
  return bytes;
}

// SHA-256 of GraphBytes, 64 lowercase hex digits.
inline std::string GraphSha256Hex(const TwoLayerPanorama& pano) {
  const std::vector<uint8_t> bytes = GraphBytes(pano);
  return Sha256Hex(bytes.data(), bytes.size());
}

}  // namespace casual3d::testing

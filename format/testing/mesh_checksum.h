#pragma once

// A 64-bit FNV-1a checksum over every array of a Mesh, and the deterministic
// "blocks" panorama it is tested on. Used by golden tests that pin the exact
// output of the mesh builder and the simplifier: the same values come out of
// the Emscripten build, so a change of either checksum means native and wasm
// meshes, or the spec (spec/mesh.md), changed.

#include <cstddef>
#include <cstdint>

#include "format/mesh.h"
#include "format/testing/test_panoramas.h"
#include "format/two_layer.h"

namespace casual3d {
namespace testing {

inline uint64_t Fnv1a(const void* data, size_t bytes, uint64_t h) {
  const unsigned char* b = static_cast<const unsigned char*>(data);
  for (size_t i = 0; i < bytes; ++i) {
    h ^= b[i];
    h *= 1099511628211ull;
  }
  return h;
}

inline uint64_t MeshChecksum(const Mesh& m) {
  uint64_t h = 1469598103934665603ull;
  h = Fnv1a(m.positions.data(), m.positions.size() * sizeof(float), h);
  h = Fnv1a(m.normals.data(), m.normals.size() * sizeof(float), h);
  h = Fnv1a(m.uvs.data(), m.uvs.size() * sizeof(float), h);
  h = Fnv1a(m.colors.data(), m.colors.size(), h);
  h = Fnv1a(m.indices.data(), m.indices.size() * sizeof(uint32_t), h);
  return h;
}

// 512 x 256: a background at 3-4 m with a diagonal pattern of near blocks at
// 1-1.05 m, back nodes behind the blocks; depths from integer arithmetic only,
// linked by LinkByDepthRatio(0.75).
inline TwoLayerPanorama MakeBlocksPanorama() {
  const int w = 512, h = 256;
  TwoLayerPanorama p(w, h);
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      const size_t i = p.index(x, y);
      const bool near = (x / 40 + y / 30) % 5 == 0;
      auto set = [&](int l, float depth) {
        LayerData& d = p.layer(l);
        d.present[i] = 1;
        d.depth_m[i] = depth;
        d.normal[3 * i + 2] = 1.0f;
        d.label[i] = static_cast<uint8_t>(l);
        d.rgb[3 * i] = static_cast<uint8_t>(x & 255);
        d.rgb[3 * i + 1] = static_cast<uint8_t>(y & 255);
        d.rgb[3 * i + 2] = static_cast<uint8_t>(l * 100);
      };
      const float background = 3.0f + 0.01f * ((x + 2 * y) % 100);
      set(kFront, near ? 1.0f + 0.001f * ((x * 7 + y * 3) % 50) : background);
      if (near) set(kBack, background);
    }
  }
  LinkByDepthRatio(&p, 0.75f);
  return p;
}

}  // namespace testing
}  // namespace casual3d

// libFuzzer target for the mesh builder and the simplifier: bytes become a
// small two-layer panorama (possibly invalid), which goes through BuildMesh and
// BuildSimplifiedMesh with and without validation. Neither may crash, and every
// mesh they return must be well formed.
//
// Input layout: byte 0 = width - 1 (mod 64) + 1, byte 1 = height (mod 32) + 1,
// byte 2 = mode bits (1: repair into a valid panorama, 2: skip validation,
// 4: front layer only, 8: tight triangle budget), then per node (front layer,
// then back layer, row-major) 6 bytes: present, depth code, normal code,
// label, links, colour. Missing bytes read as zero.

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <cstring>

#include "format/mesh_builder.h"
#include "format/mesh_simplify.h"
#include "format/two_layer.h"

namespace {

using casual3d::Direction;
using casual3d::kNumDirections;
using casual3d::kNumLayers;
using casual3d::LayerData;
using casual3d::Link;
using casual3d::Mesh;
using casual3d::TwoLayerPanorama;

class ByteReader {
 public:
  ByteReader(const uint8_t* data, size_t size) : data_(data), size_(size) {}
  uint8_t Next() { return pos_ < size_ ? data_[pos_++] : 0; }

 private:
  const uint8_t* data_;
  size_t size_;
  size_t pos_ = 0;
};

float DecodeDepth(uint8_t code, bool repair) {
  if (!repair) {
    switch (code) {
      case 0:
        return 0.0f;
      case 1:
        return -1.0f;
      case 2:
        return NAN;
      case 3:
        return INFINITY;
      case 4:
        return 1e-38f;
      case 5:
        return 3e38f;
      default:
        break;
    }
  }
  return 0.25f * (1 + (code & 0x7f)) * ((code & 0x80) ? 8.0f : 1.0f);
}

void DecodeNormal(uint8_t code, bool repair, float n[3]) {
  static const float kAxes[6][3] = {{1, 0, 0},  {-1, 0, 0}, {0, 1, 0},
                                    {0, -1, 0}, {0, 0, 1},  {0, 0, -1}};
  if (code < 6) {
    std::memcpy(n, kAxes[code], sizeof(float) * 3);
  } else if (code < 12 && !repair) {
    n[0] = code == 6 ? NAN : 0.5f;  // Not unit length or not finite.
    n[1] = n[2] = 0.5f;
  } else {
    n[0] = n[1] = n[2] = 0.0f;
  }
}

// Drops every link that is not mutual or points at an absent node or outside.
void Repair(TwoLayerPanorama* p) {
  bool changed = true;
  while (changed) {
    changed = false;
    for (int l = 0; l < kNumLayers; ++l) {
      LayerData& d = p->layer(l);
      for (int y = 0; y < p->height(); ++y) {
        for (int x = 0; x < p->width(); ++x) {
          const size_t i = p->index(x, y);
          for (int di = 0; di < kNumDirections; ++di) {
            const Direction dir = static_cast<Direction>(di);
            const Link link = casual3d::GetLink(d.links[i], dir);
            if (link == Link::kNone) continue;
            int nx, ny;
            bool ok = static_cast<int>(link) <= 2 && p->Neighbour(x, y, dir, &nx, &ny);
            if (ok) {
              const int t = link == Link::kFront ? 0 : 1;
              const size_t j = p->index(nx, ny);
              ok = p->layer(t).present[j] &&
                   casual3d::GetLink(p->layer(t).links[j], casual3d::Opposite(dir)) ==
                       (l == 0 ? Link::kFront : Link::kBack);
            }
            if (!ok) {
              d.links[i] = casual3d::SetLink(d.links[i], dir, Link::kNone);
              changed = true;
            }
          }
        }
      }
    }
  }
}

// `valid_input`: the panorama passed validation, so positions must be finite.
void CheckMesh(const Mesh& m, bool valid_input) {
  const size_t v = m.num_vertices();
  if (m.normals.size() != 3 * v || m.uvs.size() != 2 * v || m.colors.size() != 3 * v ||
      m.indices.size() % 3 != 0) {
    std::abort();
  }
  for (uint32_t i : m.indices) {
    if (i >= v) std::abort();
  }
  if (!valid_input) return;  // Without validation the values are unspecified.
  for (float f : m.positions) {
    if (!std::isfinite(f)) std::abort();
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  ByteReader in(data, size);
  const int w = 1 + in.Next() % 64;
  const int h = 1 + in.Next() % 32;
  const uint8_t mode = in.Next();
  const bool repair = mode & 1;
  TwoLayerPanorama pano(w, h);
  for (int l = 0; l < kNumLayers; ++l) {
    LayerData& d = pano.layer(l);
    for (int y = 0; y < h; ++y) {
      for (int x = 0; x < w; ++x) {
        const size_t i = pano.index(x, y);
        const uint8_t present = in.Next();
        const uint8_t depth = in.Next(), normal = in.Next(), label = in.Next();
        const uint8_t links = in.Next(), color = in.Next();
        if (repair && !(present & 1)) continue;  // Absent nodes stay all zero.
        d.present[i] = repair ? 1 : present % 3;
        d.depth_m[i] = DecodeDepth(depth, repair);
        DecodeNormal(normal, repair, &d.normal[3 * i]);
        d.label[i] = repair ? (label & 1) : label % 3;
        d.links[i] = links;
        d.rgb[3 * i] = color;
        d.rgb[3 * i + 1] = static_cast<uint8_t>(color * 7);
        d.rgb[3 * i + 2] = static_cast<uint8_t>(color * 13);
      }
    }
  }
  if (repair) {
    Repair(&pano);
    if (!pano.Validate().ok()) std::abort();  // Repair must make it valid.
  }

  casual3d::MeshBuildOptions build;
  build.validate_input = !(mode & 2);
  build.include_back_layer = !(mode & 4);
  const bool valid = pano.Validate().ok();
  auto mesh = casual3d::BuildMesh(pano, build);
  if (mesh.ok()) CheckMesh(*mesh, valid);
  if (repair && w >= 2 && build.validate_input && !mesh.ok()) std::abort();

  casual3d::MeshSimplifyOptions simplify;
  simplify.validate_input = build.validate_input;
  simplify.include_back_layer = build.include_back_layer;
  simplify.max_triangles = (mode & 8) ? 4 : 0;
  simplify.max_block_size = 2 << (mode >> 5);  // 2 .. 256.
  auto simplified = casual3d::BuildSimplifiedMesh(pano, simplify);
  if (simplified.ok()) {
    CheckMesh(simplified->mesh, valid);
    // Merging never adds triangles, and the full count matches BuildMesh.
    if (valid && mesh.ok() &&
        (simplified->mesh.num_triangles() > mesh->num_triangles() ||
         simplified->full_triangles != static_cast<int64_t>(mesh->num_triangles()))) {
      std::abort();
    }
  }
  return 0;
}

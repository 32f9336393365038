#pragma once

// A raw, lossless byte form of a TwoLayerPanorama ("panorama blob") used to hand
// exactly the same panorama to the native and the wasm mesh builders (the Node
// equivalence test) without any image codec in between. Not a distribution
// format: packages and master files are.
//
// Layout (all integers and floats little-endian):
//   bytes 0..7   magic "C3DPANO1"
//   u32          width, u32 height            (each 1..kMaxBlobSide)
//   f64 x 12     frame: centre[3], rotation[9] (row-major)
//   per layer (front, then back), each array width*height elements long:
//     u8 present, u8 rgb[3], f32 depth_m, f32 normal[3], u8 label, u8 links
//
// A mesh blob ("C3DMESH1") carries a Mesh the same way:
//   magic, u32 num_vertices, u32 num_indices, then f32 positions[3n],
//   f32 normals[3n], f32 uvs[2n], u8 colors[3n], u32 indices[num_indices].

#include <cstdint>
#include <string>
#include <vector>

#include "format/mesh.h"
#include "format/status.h"
#include "format/two_layer.h"

namespace casual3d::viewer {

// Largest width or height a blob may declare (keeps allocation bounded).
constexpr uint32_t kMaxBlobSide = 16384;
// Largest number of pixels (width * height) a blob may declare.
constexpr uint64_t kMaxBlobPixels = uint64_t{8192} * 4096;

// Serializes `pano` (which must have consistent array sizes) to a blob.
std::vector<uint8_t> SerializePanorama(const TwoLayerPanorama& pano);

// Parses a blob; InvalidData on a bad magic or truncation, LimitExceeded on
// sizes beyond the limits above. Does not call Validate().
StatusOr<TwoLayerPanorama> ParsePanorama(const uint8_t* data, size_t size);

// Serializes a mesh to a mesh blob.
std::vector<uint8_t> SerializeMesh(const Mesh& mesh);

// Parses a mesh blob; InvalidData on a bad magic, truncation or index out of range.
StatusOr<Mesh> ParseMesh(const uint8_t* data, size_t size);

}  // namespace casual3d::viewer

#pragma once

// The vertex data of an exported glTF file (gltf_export.h) and its Draco
// compression (KHR_draco_mesh_compression, Debian's libdraco). Internal to
// the encoder library.

#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "encoder/gltf_export.h"
#include "format/mesh.h"
#include "format/status.h"

namespace casual3d::encoder::gltf {

// Vertex data as stored in the file.
struct ExportMesh {
  std::vector<float> positions;  // 3 per vertex.
  std::vector<float> normals;    // 3 per vertex, unit length; empty without normals.
  std::vector<float> uvs;        // 2 per vertex.
  std::vector<uint32_t> indices;
};

// Makes every normal unit length (see gltf_export.h: unlit vertices face the
// centre). Computed in double so that the float result is within the glTF
// validator's unit-length tolerance.
std::vector<float> UnitNormals(const Mesh& mesh);

// Draco-compresses `in`; on return `out` holds the mesh as a decoder will see it
// (Draco may reorder and duplicate vertices, and quantizes values), which is
// what the glTF accessors' counts and bounds must describe.
Status DracoCompress(const ExportMesh& in, const GltfExportOptions& options,
                     std::vector<uint8_t>* bitstream, ExportMesh* out,
                     std::map<std::string, int>* attribute_ids, int* position_bits_used);

}  // namespace casual3d::encoder::gltf

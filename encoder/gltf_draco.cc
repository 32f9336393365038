#include "encoder/gltf_draco.h"

#include <algorithm>
#include <cmath>
#include <memory>
#include <utility>

#include <draco/compression/decode.h>
#include <draco/compression/encode.h>
#include <draco/mesh/mesh.h>

namespace casual3d::encoder {
namespace gltf {

// Makes every normal unit length (see the header: unlit vertices face the
// centre). Computed in double so that the float result is within the glTF
// validator's unit-length tolerance.
std::vector<float> UnitNormals(const Mesh& mesh) {
  const size_t n = mesh.num_vertices();
  std::vector<float> out(3 * n);
  for (size_t v = 0; v < n; ++v) {
    const float* nv = &mesh.normals[3 * v];
    double x = nv[0], y = nv[1], z = nv[2];
    double len = std::sqrt(x * x + y * y + z * z);
    if (!(len > 1e-6) || !std::isfinite(len)) {
      x = -mesh.positions[3 * v];
      y = -mesh.positions[3 * v + 1];
      z = -mesh.positions[3 * v + 2];
      len = std::sqrt(x * x + y * y + z * z);
      // A vertex at the centre itself (depth 0 never occurs in a valid
      // panorama): face forward, towards the default view direction.
      if (!(len > 1e-12)) x = 0, y = 0, z = 1, len = 1;
    }
    out[3 * v] = static_cast<float>(x / len);
    out[3 * v + 1] = static_cast<float>(y / len);
    out[3 * v + 2] = static_cast<float>(z / len);
  }
  return out;
}

// Draco-compresses `in`; on return `out` holds the mesh as a decoder will see it
// (Draco may reorder and duplicate vertices, and quantizes values), which is
// what the glTF accessors' counts and bounds must describe.
Status DracoCompress(const ExportMesh& in, const GltfExportOptions& options,
                     std::vector<uint8_t>* bitstream, ExportMesh* out,
                     std::map<std::string, int>* attribute_ids, int* position_bits_used) {
  const size_t n = in.positions.size() / 3;
  draco::Mesh mesh;
  mesh.set_num_points(static_cast<uint32_t>(n));
  auto add = [&](draco::GeometryAttribute::Type type, int components,
                 const std::vector<float>& data) {
    draco::GeometryAttribute att;
    att.Init(type, nullptr, static_cast<uint8_t>(components), draco::DT_FLOAT32, false,
             sizeof(float) * components, 0);
    const int id = mesh.AddAttribute(att, /*identity_mapping=*/true, static_cast<uint32_t>(n));
    draco::PointAttribute* pa = mesh.attribute(id);
    for (size_t v = 0; v < n; ++v) {
      pa->SetAttributeValue(draco::AttributeValueIndex(static_cast<uint32_t>(v)),
                            &data[components * v]);
    }
    return id;
  };
  const int position_id = add(draco::GeometryAttribute::POSITION, 3, in.positions);
  const int normal_id =
      in.normals.empty() ? -1 : add(draco::GeometryAttribute::NORMAL, 3, in.normals);
  const int uv_id = add(draco::GeometryAttribute::TEX_COORD, 2, in.uvs);
  for (size_t t = 0; t + 2 < in.indices.size(); t += 3) {
    draco::Mesh::Face face;
    for (int k = 0; k < 3; ++k) face[k] = draco::PointIndex(in.indices[t + k]);
    mesh.AddFace(face);
  }

  draco::Encoder encoder;
  const int speed = 10 - options.draco_compression_level;
  encoder.SetSpeedOptions(speed, speed);
  const int position_bits = options.draco_position_bits > 0 ? options.draco_position_bits
                                                            : DracoPositionBits(in.positions);
  *position_bits_used = position_bits;
  encoder.SetAttributeQuantization(draco::GeometryAttribute::POSITION, position_bits);
  encoder.SetAttributeQuantization(draco::GeometryAttribute::NORMAL, options.draco_normal_bits);
  encoder.SetAttributeQuantization(draco::GeometryAttribute::TEX_COORD,
                                   options.draco_texcoord_bits);
  encoder.SetEncodingMethod(draco::MESH_EDGEBREAKER_ENCODING);
  draco::EncoderBuffer buffer;
  const draco::Status encoded = encoder.EncodeMeshToBuffer(mesh, &buffer);
  if (!encoded.ok()) return InternalError("Draco encoder: " + encoded.error_msg_string());
  bitstream->assign(buffer.data(), buffer.data() + buffer.size());

  // Decode what was written: the accessors must match the decoded mesh, and a
  // failing round trip must never reach a file.
  draco::DecoderBuffer decoder_buffer;
  decoder_buffer.Init(reinterpret_cast<const char*>(bitstream->data()), bitstream->size());
  draco::Decoder decoder;
  auto decoded_or = decoder.DecodeMeshFromBuffer(&decoder_buffer);
  if (!decoded_or.ok()) {
    return InternalError("Draco round trip: " + decoded_or.status().error_msg_string());
  }
  const std::unique_ptr<draco::Mesh> decoded = std::move(decoded_or).value();
  const size_t m = decoded->num_points();
  auto fetch = [&](int id, int components, std::vector<float>* data) -> Status {
    if (id < 0) return Status::Ok();
    const draco::PointAttribute* pa =
        decoded->GetAttributeByUniqueId(mesh.attribute(id)->unique_id());
    if (pa == nullptr) return InternalError("Draco round trip lost an attribute");
    data->resize(components * m);
    for (uint32_t p = 0; p < m; ++p) {
      if (!pa->ConvertValue<float>(pa->mapped_index(draco::PointIndex(p)),
                                   static_cast<int8_t>(components), &(*data)[components * p])) {
        return InternalError("Draco round trip: unreadable attribute value");
      }
    }
    (*attribute_ids)[id == position_id ? "POSITION"
                     : id == normal_id ? "NORMAL"
                                       : "TEXCOORD_0"] =
        static_cast<int>(mesh.attribute(id)->unique_id());
    return Status::Ok();
  };
  CASUAL3D_RETURN_IF_ERROR(fetch(position_id, 3, &out->positions));
  CASUAL3D_RETURN_IF_ERROR(fetch(normal_id, 3, &out->normals));
  CASUAL3D_RETURN_IF_ERROR(fetch(uv_id, 2, &out->uvs));
  out->indices.resize(3 * static_cast<size_t>(decoded->num_faces()));
  for (draco::FaceIndex f(0); f < decoded->num_faces(); ++f) {
    const auto& face = decoded->face(f);
    for (int k = 0; k < 3; ++k) out->indices[3 * f.value() + k] = face[k].value();
  }
  return Status::Ok();
}

}  // namespace gltf

int DracoPositionBits(const std::vector<float>& positions, double relative_step) {
  double lo[3] = {1e300, 1e300, 1e300}, hi[3] = {-1e300, -1e300, -1e300};
  double nearest = 1e300;
  for (size_t i = 0; i + 2 < positions.size(); i += 3) {
    double r2 = 0;
    for (int k = 0; k < 3; ++k) {
      const double v = positions[i + k];
      lo[k] = std::min(lo[k], v);
      hi[k] = std::max(hi[k], v);
      r2 += v * v;
    }
    if (r2 > 0) nearest = std::min(nearest, std::sqrt(r2));
  }
  const double extent = std::max({hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]});
  if (!(extent > 0) || !(nearest < 1e300) || !(relative_step > 0)) return 14;
  const double bits = std::ceil(std::log2(extent / (relative_step * nearest)));
  return static_cast<int>(std::clamp(bits, 14.0, 30.0));
}

}  // namespace casual3d::encoder

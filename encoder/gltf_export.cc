#include "encoder/gltf_export.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <limits>
#include <map>
#include <memory>
#include <sstream>
#include <utility>


// The one translation unit that compiles tinygltf's implementation (see
// gltf_tinygltf.h for why it is not taken from libtinygltf.so).
#define TINYGLTF_IMPLEMENTATION
#include "base/atomic_file.h"
#include "encoder/gltf_draco.h"
#include "encoder/gltf_texture.h"
#include "encoder/gltf_tinygltf.h"
#include "format/color_atlas.h"
#include "format/version.h"

namespace casual3d::encoder {
namespace {

using gltf::DracoCompress;
using gltf::EncodeJpeg;
using gltf::EncodePng;
using gltf::ExportMesh;
using gltf::FitTextureSize;
using gltf::ResizeArea;
using gltf::UnitNormals;

constexpr int kMinTextureSize = 16;
constexpr int kMaxTextureSize = 16384;
constexpr int kArrayBuffer = 34962;         // GL_ARRAY_BUFFER
constexpr int kElementArrayBuffer = 34963;  // GL_ELEMENT_ARRAY_BUFFER
constexpr char kDracoExtension[] = "KHR_draco_mesh_compression";
constexpr char kUnlitExtension[] = "KHR_materials_unlit";

std::string Range(const char* name, int value, int lo, int hi) {
  return std::string(name) + " " + std::to_string(value) + " is outside " + std::to_string(lo) +
         ".." + std::to_string(hi);
}

// ---------------------------------------------------------------------------
// glTF assembly.

// Appends `bytes` to the binary buffer (4-byte aligned, as glTF requires for
// vertex data) and adds a buffer view over them; returns the view's index.
int AddBufferView(tinygltf::Model* model, const void* bytes, size_t size, int target) {
  std::vector<unsigned char>& data = model->buffers[0].data;
  data.resize((data.size() + 3) & ~size_t{3}, 0);
  tinygltf::BufferView view;
  view.buffer = 0;
  view.byteOffset = data.size();
  view.byteLength = size;
  view.target = target;
  const auto* p = static_cast<const unsigned char*>(bytes);
  data.insert(data.end(), p, p + size);
  model->bufferViews.push_back(view);
  return static_cast<int>(model->bufferViews.size() - 1);
}

// Adds a float accessor of `components` per element (over buffer view `view`,
// or without one for Draco-compressed data); `bounds` adds min and max.
int AddFloatAccessor(tinygltf::Model* model, int view, const std::vector<float>& data,
                     int components, bool bounds) {
  tinygltf::Accessor accessor;
  accessor.bufferView = view;
  accessor.componentType = TINYGLTF_COMPONENT_TYPE_FLOAT;
  accessor.count = data.size() / components;
  accessor.type = components == 3 ? TINYGLTF_TYPE_VEC3 : TINYGLTF_TYPE_VEC2;
  if (bounds) {
    accessor.minValues.assign(components, std::numeric_limits<double>::infinity());
    accessor.maxValues.assign(components, -std::numeric_limits<double>::infinity());
    for (size_t i = 0; i < data.size(); ++i) {
      const int k = static_cast<int>(i % components);
      accessor.minValues[k] = std::min<double>(accessor.minValues[k], data[i]);
      accessor.maxValues[k] = std::max<double>(accessor.maxValues[k], data[i]);
    }
  }
  model->accessors.push_back(accessor);
  return static_cast<int>(model->accessors.size() - 1);
}

}  // namespace

// The one atlas of format/color_atlas.h, whose fill rule the mesh's uvs rely on.
Image8 BuildColorAtlas(const TwoLayerPanorama& pano) { return ::casual3d::BuildColorAtlas(pano, 3); }

Status GltfExportOptions::Check() const {
  if (texture_format != TextureFormat::kPng && texture_format != TextureFormat::kJpeg) {
    return InvalidArgument("texture_format is neither PNG nor JPEG");
  }
  if (jpeg_quality < 1 || jpeg_quality > 100) {
    return InvalidArgument(Range("jpeg_quality", jpeg_quality, 1, 100));
  }
  if (max_texture_size < kMinTextureSize || max_texture_size > kMaxTextureSize) {
    return InvalidArgument(
        Range("max_texture_size", max_texture_size, kMinTextureSize, kMaxTextureSize));
  }
  if (draco_position_bits < 0 || draco_position_bits > 30) {
    return InvalidArgument(Range("draco_position_bits", draco_position_bits, 0, 30));
  }
  if (draco_normal_bits < 1 || draco_normal_bits > 30) {
    return InvalidArgument(Range("draco_normal_bits", draco_normal_bits, 1, 30));
  }
  if (draco_texcoord_bits < 1 || draco_texcoord_bits > 30) {
    return InvalidArgument(Range("draco_texcoord_bits", draco_texcoord_bits, 1, 30));
  }
  if (draco_compression_level < 0 || draco_compression_level > 10) {
    return InvalidArgument(Range("draco_compression_level", draco_compression_level, 0, 10));
  }
  return Status::Ok();
}

Status CheckMeshForExport(const Mesh& mesh) {
  if (mesh.positions.size() % 3 != 0) {
    return InvalidArgument("mesh: positions hold " + std::to_string(mesh.positions.size()) +
                           " floats, not a multiple of 3");
  }
  const size_t n = mesh.num_vertices();
  if (n == 0) return InvalidArgument("mesh: no vertices");
  if (n >= std::numeric_limits<uint32_t>::max()) {
    return InvalidArgument("mesh: " + std::to_string(n) + " vertices, more than 32-bit indices");
  }
  if (!mesh.normals.empty() && mesh.normals.size() != 3 * n) {
    return InvalidArgument("mesh: " + std::to_string(mesh.normals.size()) + " normal floats for " +
                           std::to_string(n) + " vertices (need 3 per vertex or none)");
  }
  if (mesh.uvs.size() != 2 * n) {
    return InvalidArgument("mesh: " + std::to_string(mesh.uvs.size()) + " uv floats for " +
                           std::to_string(n) + " vertices (need 2 per vertex)");
  }
  if (mesh.indices.empty() || mesh.indices.size() % 3 != 0) {
    return InvalidArgument("mesh: " + std::to_string(mesh.indices.size()) +
                           " indices, not a positive multiple of 3");
  }
  for (size_t i = 0; i < mesh.indices.size(); ++i) {
    if (mesh.indices[i] >= n) {
      return InvalidArgument("mesh: index " + std::to_string(i) + " is " +
                             std::to_string(mesh.indices[i]) + ", past the " + std::to_string(n) +
                             " vertices");
    }
  }
  for (size_t i = 0; i < mesh.positions.size(); ++i) {
    if (!std::isfinite(mesh.positions[i])) {
      return InvalidArgument("mesh: vertex " + std::to_string(i / 3) +
                             " has a non-finite position");
    }
  }
  for (size_t i = 0; i < mesh.uvs.size(); ++i) {
    if (!std::isfinite(mesh.uvs[i])) {
      return InvalidArgument("mesh: vertex " + std::to_string(i / 2) + " has a non-finite uv");
    }
  }
  return Status::Ok();
}

namespace {

// The texture: the atlas fitted within max_texture_size and encoded as PNG
// or JPEG; *texture points at the image encoded (the atlas or *resized).
StatusOr<std::vector<uint8_t>> EncodeTexture(const Image8& atlas, const GltfExportOptions& options,
                                             Image8* resized, const Image8** texture) {
  int tex_width = 0, tex_height = 0;
  FitTextureSize(atlas.width(), atlas.height(), options.max_texture_size, &tex_width, &tex_height);
  *texture = &atlas;
  if (tex_width != atlas.width() || tex_height != atlas.height()) {
    *resized = ResizeArea(atlas, tex_width, tex_height);
    *texture = resized;
  }
  if (options.texture_format == TextureFormat::kPng) return EncodePng(**texture);
  return EncodeJpeg(**texture, options.jpeg_quality);
}

// Adds the mesh's data to `model` and `primitive`: the Draco bitstream with
// accessors without buffer views, or plain attribute and index buffers.
// Returns the bytes of vertex and index data (or of the bitstream).
size_t AddMeshData(const ExportMesh& stored, const std::vector<uint8_t>& draco_bytes,
                   const std::map<std::string, int>& draco_ids, bool draco, tinygltf::Model* model,
                   tinygltf::Primitive* primitive) {
  uint32_t max_index = 0;
  for (uint32_t i : stored.indices) max_index = std::max(max_index, i);
  size_t mesh_bytes = 0;
  // Indices: unsigned short when they fit (the 65535 value is reserved as a
  // primitive restart in some APIs, so it is avoided).
  const bool short_indices = max_index < 65535;
  tinygltf::Accessor index_accessor;
  index_accessor.componentType =
      short_indices ? TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT : TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT;
  index_accessor.count = stored.indices.size();
  index_accessor.type = TINYGLTF_TYPE_SCALAR;
  if (draco) {
    // Accessors without buffer views: the data is in the Draco bitstream.
    const int view = AddBufferView(model, draco_bytes.data(), draco_bytes.size(), 0);
    mesh_bytes = draco_bytes.size();
    primitive->attributes["POSITION"] = AddFloatAccessor(model, -1, stored.positions, 3, true);
    if (!stored.normals.empty()) {
      primitive->attributes["NORMAL"] = AddFloatAccessor(model, -1, stored.normals, 3, false);
    }
    primitive->attributes["TEXCOORD_0"] = AddFloatAccessor(model, -1, stored.uvs, 2, false);
    tinygltf::Value::Object attributes;
    for (const auto& [name, id] : draco_ids) attributes[name] = tinygltf::Value(id);
    tinygltf::Value::Object extension;
    extension["bufferView"] = tinygltf::Value(view);
    extension["attributes"] = tinygltf::Value(std::move(attributes));
    primitive->extensions[kDracoExtension] = tinygltf::Value(std::move(extension));
  } else {
    auto add_attribute = [&](const std::vector<float>& data, int components, bool bounds) {
      const int view =
          AddBufferView(model, data.data(), data.size() * sizeof(float), kArrayBuffer);
      mesh_bytes += data.size() * sizeof(float);
      return AddFloatAccessor(model, view, data, components, bounds);
    };
    primitive->attributes["POSITION"] = add_attribute(stored.positions, 3, true);
    if (!stored.normals.empty())
      primitive->attributes["NORMAL"] = add_attribute(stored.normals, 3, false);
    primitive->attributes["TEXCOORD_0"] = add_attribute(stored.uvs, 2, false);
    if (short_indices) {
      std::vector<uint16_t> narrow(stored.indices.begin(), stored.indices.end());
      index_accessor.bufferView =
          AddBufferView(model, narrow.data(), narrow.size() * 2, kElementArrayBuffer);
      mesh_bytes += narrow.size() * 2;
    } else {
      index_accessor.bufferView = AddBufferView(model, stored.indices.data(),
                                                stored.indices.size() * 4, kElementArrayBuffer);
      mesh_bytes += stored.indices.size() * 4;
    }
  }
  model->accessors.push_back(index_accessor);
  primitive->indices = static_cast<int>(model->accessors.size() - 1);
  return mesh_bytes;
}

// Adds the texture's image, its sampler and the one material.
void AddMaterial(const std::vector<uint8_t>& image_bytes, const GltfExportOptions& options,
                 tinygltf::Model* model) {
  tinygltf::Image image;
  image.name = "colour atlas";
  image.mimeType = options.texture_format == TextureFormat::kPng ? "image/png" : "image/jpeg";
  image.bufferView = AddBufferView(model, image_bytes.data(), image_bytes.size(), 0);
  model->images.push_back(image);
  tinygltf::Sampler sampler;
  sampler.magFilter = TINYGLTF_TEXTURE_FILTER_LINEAR;
  sampler.minFilter = TINYGLTF_TEXTURE_FILTER_LINEAR_MIPMAP_LINEAR;
  sampler.wrapS = TINYGLTF_TEXTURE_WRAP_REPEAT;  // Seam copies have u > 1.
  sampler.wrapT = TINYGLTF_TEXTURE_WRAP_CLAMP_TO_EDGE;
  model->samplers.push_back(sampler);
  tinygltf::Texture gltf_texture;
  gltf_texture.sampler = 0;
  gltf_texture.source = 0;
  model->textures.push_back(gltf_texture);
  tinygltf::Material material;
  material.name = "3D photo";
  material.pbrMetallicRoughness.baseColorTexture.index = 0;
  material.pbrMetallicRoughness.metallicFactor = 0.0;
  material.pbrMetallicRoughness.roughnessFactor = 1.0;
  material.doubleSided = options.double_sided;
  if (options.unlit) {
    material.extensions[kUnlitExtension] = tinygltf::Value(tinygltf::Value::Object());
    model->extensionsUsed.push_back(kUnlitExtension);
  }
  model->materials.push_back(material);
}

// Adds the mesh of `primitive`, its node and the scene.
void AddScene(const tinygltf::Primitive& primitive, tinygltf::Model* model) {
  tinygltf::Mesh gltf_mesh;
  gltf_mesh.name = "3D photo";
  gltf_mesh.primitives.push_back(primitive);
  model->meshes.push_back(gltf_mesh);
  tinygltf::Node node;
  node.name = "3D photo";
  node.mesh = 0;
  model->nodes.push_back(node);
  tinygltf::Scene scene;
  scene.nodes.push_back(0);
  model->scenes.push_back(scene);
  model->defaultScene = 0;
}

// EncodeGlb's work; the GLB as a string (what the glTF serializer gives).
StatusOr<std::string> EncodeGlbString(const Mesh& mesh, const Image8& atlas,
                                      const GltfExportOptions& options, GltfExportStats* stats) {
  CASUAL3D_RETURN_IF_ERROR(options.Check());
  CASUAL3D_RETURN_IF_ERROR(CheckMeshForExport(mesh));
  if (atlas.empty() || (atlas.channels() != 3 && atlas.channels() != 4)) {
    return InvalidArgument("colour atlas: need a non-empty 8-bit RGB or RGBA image, got " +
                           std::to_string(atlas.width()) + "x" + std::to_string(atlas.height()) +
                           " with " + std::to_string(atlas.channels()) + " channels");
  }
  Image8 resized;
  const Image8* texture = nullptr;
  CASUAL3D_ASSIGN_OR_RETURN(std::vector<uint8_t> image_bytes,
                            EncodeTexture(atlas, options, &resized, &texture));

  // Vertex data (no axis change: see the header).
  ExportMesh plain;
  plain.positions = mesh.positions;
  plain.uvs = mesh.uvs;
  plain.indices = mesh.indices;
  if (options.normals && !mesh.normals.empty()) plain.normals = UnitNormals(mesh);
  ExportMesh stored;
  std::vector<uint8_t> draco_bytes;
  std::map<std::string, int> draco_ids;
  int position_bits = 0;
  if (options.draco) {
    CASUAL3D_RETURN_IF_ERROR(
        DracoCompress(plain, options, &draco_bytes, &stored, &draco_ids, &position_bits));
  } else {
    stored = std::move(plain);
  }

  tinygltf::Model model;
  model.asset.version = "2.0";
  model.asset.generator = std::string("casual3d ") + kVersion;
  model.buffers.resize(1);
  tinygltf::Primitive primitive;
  primitive.mode = TINYGLTF_MODE_TRIANGLES;
  const size_t mesh_bytes = AddMeshData(stored, draco_bytes, draco_ids, options.draco, &model, &primitive);
  AddMaterial(image_bytes, options, &model);
  primitive.material = 0;
  if (options.draco) {
    model.extensionsUsed.push_back(kDracoExtension);
    model.extensionsRequired.push_back(kDracoExtension);
  }
  AddScene(primitive, &model);
  // The BIN chunk length must be a multiple of 4; the serializer pads it.
  model.buffers[0].data.resize((model.buffers[0].data.size() + 3) & ~size_t{3}, 0);

  std::ostringstream stream;
  tinygltf::TinyGLTF writer;
  if (!writer.WriteGltfSceneToStream(&model, stream, /*prettyPrint=*/false,
                                     /*writeBinary=*/true)) {
    return InternalError("glTF serializer failed");
  }
  std::string glb = stream.str();
  if (stats) {
    stats->num_vertices = stored.positions.size() / 3;
    stats->num_triangles = stored.indices.size() / 3;
    stats->texture_width = texture->width();
    stats->texture_height = texture->height();
    stats->texture_bytes = image_bytes.size();
    stats->draco_position_bits = position_bits;
    stats->mesh_bytes = mesh_bytes;
    stats->file_bytes = glb.size();
  }
  return glb;
}

}  // namespace

StatusOr<std::vector<uint8_t>> EncodeGlb(const Mesh& mesh, const Image8& atlas,
                                         const GltfExportOptions& options, GltfExportStats* stats) {
  CASUAL3D_ASSIGN_OR_RETURN(std::string glb, EncodeGlbString(mesh, atlas, options, stats));
  return std::vector<uint8_t>(glb.begin(), glb.end());
}

Status ExportGlb(const Mesh& mesh, const Image8& atlas, const GltfExportOptions& options,
                 const std::string& path, GltfExportStats* stats) {
  CASUAL3D_ASSIGN_OR_RETURN(std::string glb, EncodeGlbString(mesh, atlas, options, stats));

  return base::WriteFileAtomic(path, glb);
}

}  // namespace casual3d::encoder

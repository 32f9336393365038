#include "encoder/gltf_export.h"

#include <algorithm>
#include <cmath>
#include <csetjmp>
#include <cstdio>
#include <cstring>
#include <limits>
#include <map>
#include <memory>
#include <sstream>
#include <utility>

// (<jpeglib.h> needs <cstdio>, included above.)
#include <draco/compression/decode.h>
#include <draco/compression/encode.h>
#include <draco/mesh/mesh.h>
#include <jpeglib.h>
#include <png.h>

// The one translation unit that compiles tinygltf's implementation (see
// gltf_tinygltf.h for why it is not taken from libtinygltf.so).
#define TINYGLTF_IMPLEMENTATION
#include "base/atomic_file.h"
#include "encoder/gltf_tinygltf.h"
#include "format/colour_atlas.h"
#include "format/version.h"

namespace casual3d::encoder {
namespace {

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
// Texture: shrink to the size limit, then encode as PNG or JPEG.

// For each output index of a 1-D area resampling from `src` to `dst` samples,
// the source samples it covers and their weights (summing to 1).
struct Tap {
  int src;
  float weight;
};
std::vector<std::vector<Tap>> AreaTaps(int src, int dst) {
  std::vector<std::vector<Tap>> taps(dst);
  const double scale = static_cast<double>(src) / dst;
  for (int i = 0; i < dst; ++i) {
    const double lo = i * scale, hi = (i + 1) * scale;
    for (int s = static_cast<int>(std::floor(lo)); s < std::min<double>(src, std::ceil(hi)); ++s) {
      const double overlap = std::min<double>(hi, s + 1) - std::max<double>(lo, s);
      if (overlap > 1e-9) taps[i].push_back({s, static_cast<float>(overlap / scale)});
    }
  }
  return taps;
}

// Area-average resize (separable). Each output pixel is the mean of the source
// area it covers, so shrinking never aliases and uniform regions stay exact.
Image8 ResizeArea(const Image8& src, int width, int height) {
  const int c = src.channels();
  const auto xtaps = AreaTaps(src.width(), width);
  const auto ytaps = AreaTaps(src.height(), height);
  std::vector<float> rows(static_cast<size_t>(width) * src.height() * c);
  for (int y = 0; y < src.height(); ++y) {
    const uint8_t* in = src.row(y);
    float* out = &rows[static_cast<size_t>(y) * width * c];
    for (int x = 0; x < width; ++x) {
      for (const Tap& t : xtaps[x]) {
        for (int k = 0; k < c; ++k) out[x * c + k] += t.weight * in[t.src * c + k];
      }
    }
  }
  Image8 dst(width, height, c);
  std::vector<float> acc(static_cast<size_t>(width) * c);
  for (int y = 0; y < height; ++y) {
    std::fill(acc.begin(), acc.end(), 0.0f);
    for (const Tap& t : ytaps[y]) {
      const float* in = &rows[static_cast<size_t>(t.src) * width * c];
      for (size_t i = 0; i < acc.size(); ++i) acc[i] += t.weight * in[i];
    }
    uint8_t* out = dst.row(y);
    for (size_t i = 0; i < acc.size(); ++i) {
      out[i] = static_cast<uint8_t>(std::clamp(std::lround(acc[i]), 0L, 255L));
    }
  }
  return dst;
}

// The stored texture size: the atlas scaled so that its longest side is at most
// max_size, with an even height so the front (top) and back (bottom) halves of
// the atlas map onto whole rows.
void FitTextureSize(int width, int height, int max_size, int* out_width, int* out_height) {
  if (width <= max_size && height <= max_size) {
    *out_width = width;
    *out_height = height;
    return;
  }
  const double scale = static_cast<double>(max_size) / std::max(width, height);
  *out_width = std::clamp(static_cast<int>(std::lround(width * scale)), 1, max_size);
  int h = std::clamp(static_cast<int>(std::lround(height * scale)), 1, max_size);
  if (height % 2 == 0 && h % 2 == 1) h = h == max_size ? h - 1 : h + 1;
  *out_height = std::max(h, 1);
}

StatusOr<std::vector<uint8_t>> EncodePng(const Image8& image) {
  png_image png;
  std::memset(&png, 0, sizeof(png));
  png.version = PNG_IMAGE_VERSION;
  png.width = static_cast<png_uint_32>(image.width());
  png.height = static_cast<png_uint_32>(image.height());
  png.format = image.channels() == 4 ? PNG_FORMAT_RGBA : PNG_FORMAT_RGB;
  const png_int_32 stride = image.width() * image.channels();
  png_alloc_size_t size = 0;
  if (!png_image_write_to_memory(&png, nullptr, &size, 0, image.data(), stride, nullptr)) {
    std::string message = png.message;
    png_image_free(&png);
    return InternalError("PNG encoder: " + message);
  }
  std::vector<uint8_t> bytes(size);
  if (!png_image_write_to_memory(&png, bytes.data(), &size, 0, image.data(), stride, nullptr)) {
    std::string message = png.message;
    png_image_free(&png);
    return InternalError("PNG encoder: " + message);
  }
  bytes.resize(size);
  return bytes;
}

// libjpeg reports errors through a callback that must not return: it jumps
// back. Everything libjpeg touches lives in this struct (in memory, not in
// registers that longjmp may restore to stale values).
struct JpegJob {
  jpeg_compress_struct cinfo;
  jpeg_error_mgr err;
  std::jmp_buf jump;
  char message[JMSG_LENGTH_MAX] = {};
  unsigned char* out = nullptr;
  unsigned long out_size = 0;       // NOLINT(runtime/int): libjpeg's type.
  const uint8_t* pixels = nullptr;  // Tightly packed RGB rows.
  int width = 0, height = 0, quality = 0;
};

void JpegErrorExit(j_common_ptr cinfo) {
  auto* job = static_cast<JpegJob*>(cinfo->client_data);
  (*cinfo->err->format_message)(cinfo, job->message);
  std::longjmp(job->jump, 1);
}

// Runs the compression; false (with job->message) if libjpeg failed.
bool RunJpeg(JpegJob* job) {
  job->cinfo.err = jpeg_std_error(&job->err);
  job->err.error_exit = JpegErrorExit;
  if (setjmp(job->jump)) {
    jpeg_destroy_compress(&job->cinfo);
    return false;
  }
  jpeg_create_compress(&job->cinfo);
  job->cinfo.client_data = job;
  jpeg_mem_dest(&job->cinfo, &job->out, &job->out_size);
  job->cinfo.image_width = static_cast<JDIMENSION>(job->width);
  job->cinfo.image_height = static_cast<JDIMENSION>(job->height);
  job->cinfo.input_components = 3;
  job->cinfo.in_color_space = JCS_RGB;
  jpeg_set_defaults(&job->cinfo);
  jpeg_set_quality(&job->cinfo, job->quality, TRUE);
  job->cinfo.optimize_coding = TRUE;
  jpeg_start_compress(&job->cinfo, TRUE);
  while (job->cinfo.next_scanline < job->cinfo.image_height) {
    JSAMPROW row = const_cast<JSAMPROW>(
        job->pixels + static_cast<size_t>(job->cinfo.next_scanline) * job->width * 3);
    jpeg_write_scanlines(&job->cinfo, &row, 1);
  }
  jpeg_finish_compress(&job->cinfo);
  jpeg_destroy_compress(&job->cinfo);
  return true;
}

StatusOr<std::vector<uint8_t>> EncodeJpeg(const Image8& image, int quality) {
  // libjpeg takes RGB only: drop alpha (documented in the header).
  std::vector<uint8_t> rgb;
  if (image.channels() == 4) {
    rgb.resize(static_cast<size_t>(image.width()) * image.height() * 3);
    for (size_t i = 0, n = rgb.size() / 3; i < n; ++i) {
      std::memcpy(&rgb[i * 3], image.data() + i * 4, 3);
    }
  }
  auto job = std::make_unique<JpegJob>();
  job->pixels = image.channels() == 4 ? rgb.data() : image.data();
  job->width = image.width();
  job->height = image.height();
  job->quality = quality;
  const bool ok = RunJpeg(job.get());
  std::vector<uint8_t> bytes;
  if (ok) bytes.assign(job->out, job->out + job->out_size);
  std::free(job->out);
  if (!ok) return InternalError(std::string("JPEG encoder: ") + job->message);
  return bytes;
}

// ---------------------------------------------------------------------------
// Vertex data as stored in the file.

struct ExportMesh {
  std::vector<float> positions;  // 3 per vertex.
  std::vector<float> normals;    // 3 per vertex, unit length; empty without normals.
  std::vector<float> uvs;        // 2 per vertex.
  std::vector<uint32_t> indices;
};

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

// The one atlas of format/colour_atlas.h, whose fill rule the mesh's uvs rely on.
Image8 BuildColourAtlas(const TwoLayerPanorama& pano) { return ::casual3d::BuildColourAtlas(pano, 3); }

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

  // Texture.
  int tex_width = 0, tex_height = 0;
  FitTextureSize(atlas.width(), atlas.height(), options.max_texture_size, &tex_width, &tex_height);
  Image8 resized;
  const Image8* texture = &atlas;
  if (tex_width != atlas.width() || tex_height != atlas.height()) {
    resized = ResizeArea(atlas, tex_width, tex_height);
    texture = &resized;
  }
  const bool png = options.texture_format == TextureFormat::kPng;
  CASUAL3D_ASSIGN_OR_RETURN(std::vector<uint8_t> image_bytes,
                            png ? EncodePng(*texture) : EncodeJpeg(*texture, options.jpeg_quality));

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
  const size_t num_vertices = stored.positions.size() / 3;
  uint32_t max_index = 0;
  for (uint32_t i : stored.indices) max_index = std::max(max_index, i);

  tinygltf::Model model;
  model.asset.version = "2.0";
  model.asset.generator = std::string("casual3d ") + kVersion;
  model.buffers.resize(1);

  tinygltf::Primitive primitive;
  primitive.mode = TINYGLTF_MODE_TRIANGLES;
  size_t mesh_bytes = 0;
  // Indices: unsigned short when they fit (the 65535 value is reserved as a
  // primitive restart in some APIs, so it is avoided).
  const bool short_indices = max_index < 65535;
  tinygltf::Accessor index_accessor;
  index_accessor.componentType =
      short_indices ? TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT : TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT;
  index_accessor.count = stored.indices.size();
  index_accessor.type = TINYGLTF_TYPE_SCALAR;
  if (options.draco) {
    // Accessors without buffer views: the data is in the Draco bitstream.
    const int view = AddBufferView(&model, draco_bytes.data(), draco_bytes.size(), 0);
    mesh_bytes = draco_bytes.size();
    primitive.attributes["POSITION"] = AddFloatAccessor(&model, -1, stored.positions, 3, true);
    if (!stored.normals.empty()) {
      primitive.attributes["NORMAL"] = AddFloatAccessor(&model, -1, stored.normals, 3, false);
    }
    primitive.attributes["TEXCOORD_0"] = AddFloatAccessor(&model, -1, stored.uvs, 2, false);
    tinygltf::Value::Object attributes;
    for (const auto& [name, id] : draco_ids) attributes[name] = tinygltf::Value(id);
    tinygltf::Value::Object extension;
    extension["bufferView"] = tinygltf::Value(view);
    extension["attributes"] = tinygltf::Value(std::move(attributes));
    primitive.extensions[kDracoExtension] = tinygltf::Value(std::move(extension));
  } else {
    auto add_attribute = [&](const std::vector<float>& data, int components, bool bounds) {
      const int view =
          AddBufferView(&model, data.data(), data.size() * sizeof(float), kArrayBuffer);
      mesh_bytes += data.size() * sizeof(float);
      return AddFloatAccessor(&model, view, data, components, bounds);
    };
    primitive.attributes["POSITION"] = add_attribute(stored.positions, 3, true);
    if (!stored.normals.empty())
      primitive.attributes["NORMAL"] = add_attribute(stored.normals, 3, false);
    primitive.attributes["TEXCOORD_0"] = add_attribute(stored.uvs, 2, false);
    if (short_indices) {
      std::vector<uint16_t> narrow(stored.indices.begin(), stored.indices.end());
      index_accessor.bufferView =
          AddBufferView(&model, narrow.data(), narrow.size() * 2, kElementArrayBuffer);
      mesh_bytes += narrow.size() * 2;
    } else {
      index_accessor.bufferView = AddBufferView(&model, stored.indices.data(),
                                                stored.indices.size() * 4, kElementArrayBuffer);
      mesh_bytes += stored.indices.size() * 4;
    }
  }
  model.accessors.push_back(index_accessor);
  primitive.indices = static_cast<int>(model.accessors.size() - 1);

  // Image, sampler, texture, material.
  tinygltf::Image image;
  image.name = "colour atlas";
  image.mimeType = png ? "image/png" : "image/jpeg";
  image.bufferView = AddBufferView(&model, image_bytes.data(), image_bytes.size(), 0);
  model.images.push_back(image);
  tinygltf::Sampler sampler;
  sampler.magFilter = TINYGLTF_TEXTURE_FILTER_LINEAR;
  sampler.minFilter = TINYGLTF_TEXTURE_FILTER_LINEAR_MIPMAP_LINEAR;
  sampler.wrapS = TINYGLTF_TEXTURE_WRAP_REPEAT;  // Seam copies have u > 1.
  sampler.wrapT = TINYGLTF_TEXTURE_WRAP_CLAMP_TO_EDGE;
  model.samplers.push_back(sampler);
  tinygltf::Texture gltf_texture;
  gltf_texture.sampler = 0;
  gltf_texture.source = 0;
  model.textures.push_back(gltf_texture);
  tinygltf::Material material;
  material.name = "3D photo";
  material.pbrMetallicRoughness.baseColorTexture.index = 0;
  material.pbrMetallicRoughness.metallicFactor = 0.0;
  material.pbrMetallicRoughness.roughnessFactor = 1.0;
  material.doubleSided = options.double_sided;
  if (options.unlit) {
    material.extensions[kUnlitExtension] = tinygltf::Value(tinygltf::Value::Object());
    model.extensionsUsed.push_back(kUnlitExtension);
  }
  model.materials.push_back(material);
  primitive.material = 0;
  if (options.draco) {
    model.extensionsUsed.push_back(kDracoExtension);
    model.extensionsRequired.push_back(kDracoExtension);
  }

  tinygltf::Mesh gltf_mesh;
  gltf_mesh.name = "3D photo";
  gltf_mesh.primitives.push_back(primitive);
  model.meshes.push_back(gltf_mesh);
  tinygltf::Node node;
  node.name = "3D photo";
  node.mesh = 0;
  model.nodes.push_back(node);
  tinygltf::Scene scene;
  scene.nodes.push_back(0);
  model.scenes.push_back(scene);
  model.defaultScene = 0;
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
    stats->num_vertices = num_vertices;
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

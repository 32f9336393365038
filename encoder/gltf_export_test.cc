#include "encoder/gltf_export.h"

#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <csetjmp>
#include <cstdio>  // Before <jpeglib.h>, which needs FILE.
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include <jpeglib.h>
#include <png.h>

#include <draco/compression/decode.h>
#include <draco/mesh/mesh.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "base/testing/scratch_dir.h"
#include "encoder/gltf_tinygltf.h"
#include "format/mesh_builder.h"
#include "format/mesh_simplify.h"
#include "format/testing/test_panoramas.h"

namespace casual3d::encoder {
namespace {

namespace fs = std::filesystem;

// A band of a sphere of radius 5 m around the centre, as a (columns+1) x
// (rows+1) vertex grid, triangles counter-clockwise seen from the centre like
// format/mesh.h's. Vertices in the first `unlit_rows` rows get the unlit
// normal (0, 0, 0); the others face the centre with a tilt so that they are
// not all equal to the fallback. UVs address a width x height atlas.
Mesh MakeSphereBand(int columns, int rows, int unlit_rows) {
  Mesh mesh;
  const double radius = 5.0;
  for (int j = 0; j <= rows; ++j) {
    for (int i = 0; i <= columns; ++i) {
      const double lon = (static_cast<double>(i) / columns - 0.5) * 2.0;  // -1..1 rad
      const double lat = (0.5 - static_cast<double>(j) / rows) * 1.6;     // 0.8..-0.8 rad
      const Vec3d d = LonLatToDirection(lon, lat);
      mesh.positions.insert(mesh.positions.end(),
                            {static_cast<float>(radius * d.x), static_cast<float>(radius * d.y),
                             static_cast<float>(radius * d.z)});
      if (j < unlit_rows) {
        mesh.normals.insert(mesh.normals.end(), {0.0f, 0.0f, 0.0f});
      } else {
        // Not unit length on purpose: the exporter must normalize.
        mesh.normals.insert(mesh.normals.end(),
                            {static_cast<float>(-2.0 * d.x + 0.5), static_cast<float>(-2.0 * d.y),
                             static_cast<float>(-2.0 * d.z)});
      }
      mesh.uvs.insert(mesh.uvs.end(), {static_cast<float>((i + 0.5) / (columns + 1)),
                                       static_cast<float>((j + 0.5) / (2.0 * (rows + 1)))});
      mesh.colors.insert(mesh.colors.end(), {200, 100, 50});
    }
  }
  const int stride = columns + 1;
  for (int j = 0; j < rows; ++j) {
    for (int i = 0; i < columns; ++i) {
      const uint32_t a = j * stride + i, b = a + 1, c = a + stride, d = c + 1;
      // Seen from the centre, +lon goes right and +j goes down, so a, c, b is
      // counter-clockwise.
      mesh.indices.insert(mesh.indices.end(), {a, c, b, b, c, d});
    }
  }
  return mesh;
}

// An RGB atlas with a different, exactly known colour in every pixel.
Image8 MakeAtlas(int width, int height) {
  Image8 atlas(width, height, 3);
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      atlas.at(x, y, 0) = static_cast<uint8_t>(x * 255 / std::max(1, width - 1));
      atlas.at(x, y, 1) = static_cast<uint8_t>(y * 255 / std::max(1, height - 1));
      atlas.at(x, y, 2) = static_cast<uint8_t>(128 + 100 * std::sin(0.05 * (x + y)));
    }
  }
  return atlas;
}

struct Parsed {
  tinygltf::Model model;
  std::string error;
  std::string warning;
  bool ok = false;
};

// tinygltf image loader for the tests (casual3d builds tinygltf without stb):
// decodes PNG with libpng and JPEG with libjpeg into RGBA, as tinygltf's own
// loader does by default.
struct JpegError {
  jpeg_error_mgr base;
  std::jmp_buf jump;
};
void JpegErrorExit(j_common_ptr cinfo) {
  std::longjmp(reinterpret_cast<JpegError*>(cinfo->err)->jump, 1);
}

bool DecodeImage(tinygltf::Image* image, const int, std::string* err, std::string*, int, int,
                 const unsigned char* bytes, int size, void*) {
  std::vector<unsigned char> rgb;
  int width = 0, height = 0;
  if (size >= 8 && png_sig_cmp(bytes, 0, 8) == 0) {
    png_image png;
    std::memset(&png, 0, sizeof(png));
    png.version = PNG_IMAGE_VERSION;
    if (!png_image_begin_read_from_memory(&png, bytes, size)) return false;
    png.format = PNG_FORMAT_RGBA;
    width = png.width, height = png.height;
    image->image.resize(PNG_IMAGE_SIZE(png));
    if (!png_image_finish_read(&png, nullptr, image->image.data(), 0, nullptr)) return false;
  } else if (size >= 3 && bytes[0] == 0xFF && bytes[1] == 0xD8 && bytes[2] == 0xFF) {
    jpeg_decompress_struct cinfo;
    JpegError jerr;
    cinfo.err = jpeg_std_error(&jerr.base);
    jerr.base.error_exit = JpegErrorExit;
    if (setjmp(jerr.jump)) {
      jpeg_destroy_decompress(&cinfo);
      if (err) *err += "bad JPEG";
      return false;
    }
    jpeg_create_decompress(&cinfo);
    jpeg_mem_src(&cinfo, bytes, static_cast<unsigned long>(size));
    jpeg_read_header(&cinfo, TRUE);
    cinfo.out_color_space = JCS_EXT_RGBA;
    jpeg_start_decompress(&cinfo);
    width = cinfo.output_width, height = cinfo.output_height;
    image->image.resize(static_cast<size_t>(width) * height * 4);
    while (cinfo.output_scanline < cinfo.output_height) {
      JSAMPROW row = &image->image[static_cast<size_t>(cinfo.output_scanline) * width * 4];
      jpeg_read_scanlines(&cinfo, &row, 1);
    }
    jpeg_finish_decompress(&cinfo);
    jpeg_destroy_decompress(&cinfo);
  } else {
    if (err) *err += "not a PNG or JPEG image";
    return false;
  }
  image->width = width;
  image->height = height;
  image->component = 4;
  image->bits = 8;
  image->pixel_type = TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE;
  return true;
}

// The JSON chunk of a GLB.
nlohmann::json GlbJson(const std::vector<uint8_t>& glb) {
  uint32_t length = 0;
  std::memcpy(&length, glb.data() + 12, 4);
  return nlohmann::json::parse(glb.begin() + 20, glb.begin() + 20 + length);
}

Parsed ParseGlb(const std::vector<uint8_t>& glb) {
  Parsed p;
  tinygltf::TinyGLTF loader;
  loader.SetImageLoader(DecodeImage, nullptr);
  p.ok = loader.LoadBinaryFromMemory(&p.model, &p.error, &p.warning, glb.data(),
                                     static_cast<unsigned int>(glb.size()));
  return p;
}

// Reads a tightly packed accessor of floats (or unsigned indices) from the model.
template <typename T>
std::vector<T> ReadAccessor(const tinygltf::Model& model, int index) {
  const tinygltf::Accessor& a = model.accessors.at(index);
  const tinygltf::BufferView& v = model.bufferViews.at(a.bufferView);
  const unsigned char* p = model.buffers.at(v.buffer).data.data() + v.byteOffset + a.byteOffset;
  const int components = tinygltf::GetNumComponentsInType(a.type);
  std::vector<T> out(a.count * components);
  for (size_t i = 0; i < out.size(); ++i) {
    switch (a.componentType) {
      case TINYGLTF_COMPONENT_TYPE_FLOAT: {
        float f;
        std::memcpy(&f, p + 4 * i, 4);
        out[i] = static_cast<T>(f);
        break;
      }
      case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: {
        uint16_t s;
        std::memcpy(&s, p + 2 * i, 2);
        out[i] = static_cast<T>(s);
        break;
      }
      case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT: {
        uint32_t u;
        std::memcpy(&u, p + 4 * i, 4);
        out[i] = static_cast<T>(u);
        break;
      }
      default:
        ADD_FAILURE() << "unexpected component type " << a.componentType;
    }
  }
  return out;
}

GltfExportOptions PngOptions() {
  GltfExportOptions options;
  options.texture_format = TextureFormat::kPng;
  return options;
}

TEST(GltfExportTest, PlainGlbRoundTripsThroughTinyGltf) {
  const Mesh mesh = MakeSphereBand(24, 12, 3);
  const Image8 atlas = MakeAtlas(25, 26);
  GltfExportStats stats;
  auto glb = EncodeGlb(mesh, atlas, PngOptions(), &stats);
  ASSERT_TRUE(glb.ok()) << glb.status().ToString();
  EXPECT_EQ(std::string(glb->begin(), glb->begin() + 4), "glTF");
  EXPECT_EQ(glb->size() % 4, 0u);
  EXPECT_EQ(stats.file_bytes, glb->size());
  EXPECT_EQ(stats.num_vertices, mesh.num_vertices());
  EXPECT_EQ(stats.num_triangles, mesh.num_triangles());

  const Parsed p = ParseGlb(*glb);
  ASSERT_TRUE(p.ok) << p.error;
  EXPECT_TRUE(p.warning.empty()) << p.warning;
  const tinygltf::Model& m = p.model;
  EXPECT_EQ(m.asset.version, "2.0");
  ASSERT_EQ(m.meshes.size(), 1u);
  ASSERT_EQ(m.meshes[0].primitives.size(), 1u);
  ASSERT_EQ(m.nodes.size(), 1u);
  EXPECT_TRUE(m.nodes[0].matrix.empty() && m.nodes[0].rotation.empty());  // No axis change.
  ASSERT_EQ(m.scenes.size(), 1u);
  const tinygltf::Primitive& prim = m.meshes[0].primitives[0];
  EXPECT_EQ(prim.mode, TINYGLTF_MODE_TRIANGLES);
  ASSERT_EQ(prim.attributes.count("POSITION"), 1u);
  ASSERT_EQ(prim.attributes.count("NORMAL"), 1u);
  ASSERT_EQ(prim.attributes.count("TEXCOORD_0"), 1u);

  // Positions: exact, with exact bounds.
  const tinygltf::Accessor& pos = m.accessors[prim.attributes.at("POSITION")];
  EXPECT_EQ(pos.count, mesh.num_vertices());
  const std::vector<float> positions = ReadAccessor<float>(m, prim.attributes.at("POSITION"));
  EXPECT_EQ(positions, mesh.positions);
  ASSERT_EQ(pos.minValues.size(), 3u);
  ASSERT_EQ(pos.maxValues.size(), 3u);
  for (int k = 0; k < 3; ++k) {
    float lo = 1e30f, hi = -1e30f;
    for (size_t v = 0; v < mesh.num_vertices(); ++v) {
      lo = std::min(lo, mesh.positions[3 * v + k]);
      hi = std::max(hi, mesh.positions[3 * v + k]);
    }
    EXPECT_EQ(pos.minValues[k], lo);
    EXPECT_EQ(pos.maxValues[k], hi);
  }

  // Normals: unit length; unlit ones face the centre; lit ones keep direction.
  const std::vector<float> normals = ReadAccessor<float>(m, prim.attributes.at("NORMAL"));
  ASSERT_EQ(normals.size(), mesh.normals.size());
  for (size_t v = 0; v < mesh.num_vertices(); ++v) {
    const float* n = &normals[3 * v];
    EXPECT_NEAR(n[0] * n[0] + n[1] * n[1] + n[2] * n[2], 1.0, 1e-6) << "vertex " << v;
    const float* src = &mesh.normals[3 * v];
    const float* p3 = &mesh.positions[3 * v];
    const bool unlit = src[0] == 0 && src[1] == 0 && src[2] == 0;
    const float* ref = unlit ? p3 : src;
    const double sign = unlit ? -1.0 : 1.0;
    const double len = std::sqrt(ref[0] * ref[0] + ref[1] * ref[1] + ref[2] * ref[2]);
    for (int k = 0; k < 3; ++k) EXPECT_NEAR(n[k], sign * ref[k] / len, 1e-6) << "vertex " << v;
  }

  // Texture coordinates and indices: exact.
  EXPECT_EQ(ReadAccessor<float>(m, prim.attributes.at("TEXCOORD_0")), mesh.uvs);
  const tinygltf::Accessor& idx = m.accessors[prim.indices];
  EXPECT_EQ(idx.componentType, TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT);
  EXPECT_EQ(ReadAccessor<uint32_t>(m, prim.indices), mesh.indices);
  EXPECT_EQ(m.bufferViews[idx.bufferView].target, 34963);
  EXPECT_EQ(m.bufferViews[pos.bufferView].target, 34962);

  // Buffer views: 4-byte aligned, inside the one buffer, not overlapping.
  ASSERT_EQ(m.buffers.size(), 1u);
  size_t end = 0;
  for (const tinygltf::BufferView& v : m.bufferViews) {
    EXPECT_EQ(v.byteOffset % 4, 0u);
    EXPECT_GE(v.byteOffset, end);
    end = v.byteOffset + v.byteLength;
    EXPECT_LE(end, m.buffers[0].data.size());
  }

  // Texture: PNG, lossless, the atlas itself; unlit material.
  ASSERT_EQ(m.images.size(), 1u);
  EXPECT_EQ(m.images[0].mimeType, "image/png");
  EXPECT_EQ(m.images[0].width, atlas.width());
  EXPECT_EQ(m.images[0].height, atlas.height());
  ASSERT_EQ(m.images[0].component, 4);  // tinygltf expands to RGBA.
  int mismatches = 0;
  for (int y = 0; y < atlas.height(); ++y) {
    for (int x = 0; x < atlas.width(); ++x) {
      for (int c = 0; c < 3; ++c) {
        mismatches += m.images[0].image[(y * atlas.width() + x) * 4 + c] != atlas.at(x, y, c);
      }
    }
  }
  EXPECT_EQ(mismatches, 0);
  EXPECT_EQ(stats.texture_width, atlas.width());
  ASSERT_EQ(m.materials.size(), 1u);
  EXPECT_EQ(m.materials[0].extensions.count("KHR_materials_unlit"), 1u);
  EXPECT_EQ(m.materials[0].pbrMetallicRoughness.baseColorTexture.index, 0);
  EXPECT_EQ(m.materials[0].pbrMetallicRoughness.metallicFactor, 0.0);
  EXPECT_FALSE(m.materials[0].doubleSided);
  ASSERT_EQ(m.samplers.size(), 1u);
  EXPECT_EQ(m.samplers[0].wrapS, TINYGLTF_TEXTURE_WRAP_REPEAT);
  EXPECT_EQ(m.samplers[0].wrapT, TINYGLTF_TEXTURE_WRAP_CLAMP_TO_EDGE);
  EXPECT_EQ(m.extensionsUsed, std::vector<std::string>{"KHR_materials_unlit"});
  EXPECT_TRUE(m.extensionsRequired.empty());
}

TEST(GltfExportTest, TrianglesFaceTheCentre) {
  // glTF front faces are counter-clockwise; for a viewer at the origin the
  // geometric normal of every exported triangle must point back at it.
  const Mesh mesh = MakeSphereBand(8, 4, 0);
  auto glb = EncodeGlb(mesh, MakeAtlas(9, 10), PngOptions());
  ASSERT_TRUE(glb.ok());
  const Parsed p = ParseGlb(*glb);
  ASSERT_TRUE(p.ok) << p.error;
  const auto& prim = p.model.meshes[0].primitives[0];
  const std::vector<float> pos = ReadAccessor<float>(p.model, prim.attributes.at("POSITION"));
  const std::vector<uint32_t> idx = ReadAccessor<uint32_t>(p.model, prim.indices);
  for (size_t t = 0; t < idx.size(); t += 3) {
    const float* a = &pos[3 * idx[t]];
    const float* b = &pos[3 * idx[t + 1]];
    const float* c = &pos[3 * idx[t + 2]];
    const double e1[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
    const double e2[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
    const double n[3] = {e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2],
                         e1[0] * e2[1] - e1[1] * e2[0]};
    EXPECT_LT(n[0] * a[0] + n[1] * a[1] + n[2] * a[2], 0.0) << "triangle " << t / 3;
  }
}

// Decodes the Draco bitstream a primitive points at.
std::unique_ptr<draco::Mesh> DecodeDraco(const tinygltf::Model& m, const tinygltf::Primitive& prim,
                                         std::map<std::string, int>* ids) {
  const tinygltf::Value& ext = prim.extensions.at("KHR_draco_mesh_compression");
  const tinygltf::BufferView& v = m.bufferViews.at(ext.Get("bufferView").Get<int>());
  const tinygltf::Value& attributes = ext.Get("attributes");
  for (const std::string& key : attributes.Keys()) (*ids)[key] = attributes.Get(key).Get<int>();
  draco::DecoderBuffer buffer;
  buffer.Init(reinterpret_cast<const char*>(m.buffers[v.buffer].data.data() + v.byteOffset),
              v.byteLength);
  draco::Decoder decoder;
  auto decoded = decoder.DecodeMeshFromBuffer(&buffer);
  if (!decoded.ok()) return nullptr;
  return std::move(decoded).value();
}

TEST(GltfExportTest, DracoGlbDecodesToTheMeshWithinQuantization) {
  const Mesh mesh = MakeSphereBand(40, 20, 4);
  const Image8 atlas = MakeAtlas(41, 42);
  GltfExportOptions options;
  options.draco = true;
  GltfExportStats stats, plain_stats;
  auto glb = EncodeGlb(mesh, atlas, options, &stats);
  ASSERT_TRUE(glb.ok()) << glb.status().ToString();
  ASSERT_TRUE(EncodeGlb(mesh, atlas, GltfExportOptions(), &plain_stats).ok());
  // Draco must actually compress: under a third of the raw vertex and index data.
  EXPECT_LT(stats.mesh_bytes * 3, plain_stats.mesh_bytes);
  EXPECT_LT(stats.file_bytes, plain_stats.file_bytes);

  const Parsed p = ParseGlb(*glb);
  ASSERT_TRUE(p.ok) << p.error;
  const tinygltf::Model& m = p.model;
  EXPECT_EQ(m.extensionsRequired, std::vector<std::string>{"KHR_draco_mesh_compression"});
  EXPECT_EQ(m.images[0].mimeType, "image/jpeg");
  const tinygltf::Primitive& prim = m.meshes[0].primitives[0];
  ASSERT_EQ(prim.extensions.count("KHR_draco_mesh_compression"), 1u);
  std::map<std::string, int> ids;
  const std::unique_ptr<draco::Mesh> decoded = DecodeDraco(m, prim, &ids);
  ASSERT_NE(decoded, nullptr);
  ASSERT_EQ(ids.size(), 3u);

  // Accessors describe the decoded data: counts and exact position bounds.
  const tinygltf::Accessor& pos = m.accessors[prim.attributes.at("POSITION")];
  // In the file, Draco-compressed accessors have no buffer view.
  const nlohmann::json json = GlbJson(*glb);
  for (const auto& accessor : json.at("accessors")) EXPECT_FALSE(accessor.contains("bufferView"));
  EXPECT_EQ(json.at("extensionsUsed"),
            nlohmann::json({"KHR_materials_unlit", "KHR_draco_mesh_compression"}));
  EXPECT_EQ(pos.count, decoded->num_points());
  EXPECT_EQ(m.accessors[prim.attributes.at("NORMAL")].count, decoded->num_points());
  EXPECT_EQ(m.accessors[prim.attributes.at("TEXCOORD_0")].count, decoded->num_points());
  EXPECT_EQ(m.accessors[prim.indices].count, 3 * decoded->num_faces());
  EXPECT_EQ(decoded->num_faces(), mesh.num_triangles());
  // tinygltf's own Draco path reads the same data.
  EXPECT_EQ(ReadAccessor<float>(m, prim.attributes.at("POSITION")).size(),
            3 * decoded->num_points());
  EXPECT_EQ(ReadAccessor<uint32_t>(m, prim.indices).size(), 3 * decoded->num_faces());
  EXPECT_EQ(stats.num_triangles, mesh.num_triangles());
  const draco::PointAttribute* dpos = decoded->GetAttributeByUniqueId(ids.at("POSITION"));
  const draco::PointAttribute* dnrm = decoded->GetAttributeByUniqueId(ids.at("NORMAL"));
  const draco::PointAttribute* duv = decoded->GetAttributeByUniqueId(ids.at("TEXCOORD_0"));
  ASSERT_TRUE(dpos && dnrm && duv);
  std::vector<double> lo(3, 1e30), hi(3, -1e30);

  // Every decoded vertex is an input vertex within the quantization step:
  // positions span 10 m at 14 bits (0.6 mm), uvs 1 at 14 bits.
  const double pos_tolerance = 10.0 / (1 << 14);
  const double uv_tolerance = 1.0 / (1 << 14);
  const Parsed plain = ParseGlb(*EncodeGlb(mesh, atlas, GltfExportOptions()));
  const auto& plain_prim = plain.model.meshes[0].primitives[0];
  const std::vector<float> ref_normals =
      ReadAccessor<float>(plain.model, plain_prim.attributes.at("NORMAL"));
  double worst_pos = 0, worst_uv = 0, worst_normal_deg = 0;
  for (uint32_t i = 0; i < decoded->num_points(); ++i) {
    float xyz[3], n[3], uv[2];
    dpos->GetMappedValue(draco::PointIndex(i), xyz);
    dnrm->GetMappedValue(draco::PointIndex(i), n);
    duv->GetMappedValue(draco::PointIndex(i), uv);
    for (int k = 0; k < 3; ++k)
      lo[k] = std::min<double>(lo[k], xyz[k]), hi[k] = std::max<double>(hi[k], xyz[k]);
    size_t best = 0;
    double best_d = 1e30;
    for (size_t v = 0; v < mesh.num_vertices(); ++v) {
      const float* q = &mesh.positions[3 * v];
      const double d = std::hypot(q[0] - xyz[0], q[1] - xyz[1], q[2] - xyz[2]);
      if (d < best_d) best_d = d, best = v;
    }
    worst_pos = std::max(worst_pos, best_d);
    worst_uv = std::max({worst_uv, std::abs(double{uv[0]} - mesh.uvs[2 * best]),
                         std::abs(double{uv[1]} - mesh.uvs[2 * best + 1])});
    const float* r = &ref_normals[3 * best];
    const double dot = std::clamp<double>(n[0] * r[0] + n[1] * r[1] + n[2] * r[2], -1.0, 1.0);
    worst_normal_deg = std::max(worst_normal_deg, std::acos(dot) * 180.0 / kPi);
  }
  EXPECT_LE(worst_pos, pos_tolerance);
  EXPECT_LE(worst_uv, uv_tolerance);
  EXPECT_LT(worst_normal_deg, 0.5);  // 10-bit octahedral normals.
  for (int k = 0; k < 3; ++k) {
    EXPECT_FLOAT_EQ(pos.minValues[k], lo[k]);
    EXPECT_FLOAT_EQ(pos.maxValues[k], hi[k]);
  }
}

TEST(GltfExportTest, AutomaticDracoPositionBitsKeepNearVerticesWithinTheirDepthBound) {
  // Near vertices at 1 m and a far one at 1000 m: 14 bits over the box
  // would move the near ones by about 12 cm; the automatic bits keep them
  // within 0.1% of their distance.
  std::vector<float> positions = {1, 0, 0, 0, 1, 0, 0, 0, -1, -1000, 0, 0, 0, 0, 1000};
  const int bits = DracoPositionBits(positions);
  EXPECT_EQ(bits, 20);  // log2(1001 / 1e-3) = 19.9.
  EXPECT_LE(bits, 30);
  EXPECT_EQ(DracoPositionBits({1, 0, 0, 0, 1, 0}), 14);  // A small box: the floor.

  Mesh mesh = MakeSphereBand(40, 20, 4);
  for (size_t v = 0; v < mesh.num_vertices(); ++v) {
    // Scale the band's first row out to 500 times the rest.
    if (v % 41 == 0)
      for (int k = 0; k < 3; ++k) mesh.positions[3 * v + k] *= 500.0f;
  }
  const Image8 atlas = MakeAtlas(41, 42);
  GltfExportOptions options;
  options.draco = true;
  GltfExportStats stats;
  auto glb = EncodeGlb(mesh, atlas, options, &stats);
  ASSERT_TRUE(glb.ok()) << glb.status().ToString();
  EXPECT_EQ(stats.draco_position_bits, DracoPositionBits(mesh.positions));
  EXPECT_GT(stats.draco_position_bits, 14);
  const Parsed p = ParseGlb(*glb);
  ASSERT_TRUE(p.ok) << p.error;
  std::map<std::string, int> ids;
  const std::unique_ptr<draco::Mesh> decoded =
      DecodeDraco(p.model, p.model.meshes[0].primitives[0], &ids);
  ASSERT_NE(decoded, nullptr);
  const draco::PointAttribute* dpos = decoded->GetAttributeByUniqueId(ids.at("POSITION"));
  double worst = 0;
  for (uint32_t i = 0; i < decoded->num_points(); ++i) {
    float xyz[3];
    dpos->GetMappedValue(draco::PointIndex(i), xyz);
    double best = 1e30;
    for (size_t v = 0; v < mesh.num_vertices(); ++v) {
      const float* q = &mesh.positions[3 * v];
      best = std::min<double>(best, std::hypot(q[0] - xyz[0], q[1] - xyz[1], q[2] - xyz[2]) /
                                std::hypot(q[0], q[1], q[2]));
    }
    worst = std::max(worst, best);
  }
  EXPECT_LE(worst, 1e-3);
}

TEST(GltfExportTest, LargeMeshUsesUnsignedIntIndices) {
  const Mesh mesh = MakeSphereBand(300, 250, 0);  // 75,551 vertices.
  ASSERT_GT(mesh.num_vertices(), 65535u);
  auto glb = EncodeGlb(mesh, MakeAtlas(64, 64), GltfExportOptions());
  ASSERT_TRUE(glb.ok());
  const Parsed p = ParseGlb(*glb);
  ASSERT_TRUE(p.ok) << p.error;
  const auto& prim = p.model.meshes[0].primitives[0];
  EXPECT_EQ(p.model.accessors[prim.indices].componentType, TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT);
  EXPECT_EQ(ReadAccessor<uint32_t>(p.model, prim.indices), mesh.indices);
}

TEST(GltfExportTest, LargeAtlasIsShrunkByAreaAverage) {
  const Mesh mesh = MakeSphereBand(4, 2, 0);
  Image8 atlas(400, 300, 3);
  // Left half red, right half blue: a 4x reduction keeps the two halves pure
  // and puts no other colour anywhere (the edge falls between output pixels).
  for (int y = 0; y < atlas.height(); ++y) {
    for (int x = 0; x < atlas.width(); ++x) atlas.at(x, y, x < 200 ? 0 : 2) = 255;
  }
  GltfExportOptions options = PngOptions();
  options.max_texture_size = 100;
  GltfExportStats stats;
  auto glb = EncodeGlb(mesh, atlas, options, &stats);
  ASSERT_TRUE(glb.ok());
  EXPECT_EQ(stats.texture_width, 100);
  EXPECT_EQ(stats.texture_height, 76);  // 75 rounded up to keep the halves apart.
  const Parsed p = ParseGlb(*glb);
  ASSERT_TRUE(p.ok) << p.error;
  const tinygltf::Image& image = p.model.images[0];
  ASSERT_EQ(image.width, 100);
  ASSERT_EQ(image.height, 76);
  for (int y = 0; y < image.height; ++y) {
    for (int x = 0; x < image.width; ++x) {
      const unsigned char* px = &image.image[(y * image.width + x) * 4];
      ASSERT_EQ(px[0], x < 50 ? 255 : 0) << x << "," << y;
      ASSERT_EQ(px[1], 0);
      ASSERT_EQ(px[2], x < 50 ? 0 : 255) << x << "," << y;
    }
  }
}

TEST(GltfExportTest, JpegTextureIsCloseToTheAtlas) {
  const Mesh mesh = MakeSphereBand(4, 2, 0);
  const Image8 atlas = MakeAtlas(128, 128);
  GltfExportStats stats;
  auto glb = EncodeGlb(mesh, atlas, GltfExportOptions(), &stats);
  ASSERT_TRUE(glb.ok());
  const Parsed p = ParseGlb(*glb);
  ASSERT_TRUE(p.ok) << p.error;
  const tinygltf::Image& image = p.model.images[0];
  EXPECT_EQ(image.mimeType, "image/jpeg");
  ASSERT_EQ(image.width, 128);
  double sse = 0;
  for (int y = 0; y < 128; ++y) {
    for (int x = 0; x < 128; ++x) {
      for (int c = 0; c < 3; ++c) {
        const double d = image.image[(y * 128 + x) * image.component + c] - atlas.at(x, y, c);
        sse += d * d;
      }
    }
  }
  const double psnr = 10.0 * std::log10(255.0 * 255.0 / (sse / (128.0 * 128 * 3)));
  EXPECT_GT(psnr, 38.0);  // Quality 90 on a smooth gradient.
  EXPECT_LT(stats.texture_bytes, 128u * 128 * 3 / 4);
}

TEST(GltfExportTest, NormalsCanBeLeftOutAndMaterialOptionsApply) {
  const Mesh mesh = MakeSphereBand(6, 3, 1);
  GltfExportOptions options;
  options.normals = false;
  options.unlit = false;
  options.double_sided = true;
  auto glb = EncodeGlb(mesh, MakeAtlas(8, 8), options);
  ASSERT_TRUE(glb.ok());
  const Parsed p = ParseGlb(*glb);
  ASSERT_TRUE(p.ok) << p.error;
  EXPECT_EQ(p.model.meshes[0].primitives[0].attributes.count("NORMAL"), 0u);
  EXPECT_TRUE(p.model.materials[0].extensions.empty());
  EXPECT_TRUE(p.model.materials[0].doubleSided);
  EXPECT_TRUE(p.model.extensionsUsed.empty());

  // A mesh without normals exports without them, Draco included.
  Mesh bare = mesh;
  bare.normals.clear();
  options.draco = true;
  glb = EncodeGlb(bare, MakeAtlas(8, 8), options);
  ASSERT_TRUE(glb.ok()) << glb.status().ToString();
  const Parsed q = ParseGlb(*glb);
  ASSERT_TRUE(q.ok) << q.error;
  EXPECT_EQ(q.model.meshes[0].primitives[0].attributes.count("NORMAL"), 0u);
}

TEST(GltfExportTest, RejectsBadOptionsMeshesAndAtlases) {
  const Mesh mesh = MakeSphereBand(4, 2, 0);
  const Image8 atlas = MakeAtlas(8, 8);
  auto expect_invalid = [&](const Mesh& m, const Image8& a, const GltfExportOptions& o,
                            const std::string& needle) {
    auto r = EncodeGlb(m, a, o);
    ASSERT_FALSE(r.ok()) << needle;
    EXPECT_EQ(r.status().code(), StatusCode::kInvalidArgument);
    EXPECT_NE(r.status().message().find(needle), std::string::npos) << r.status().message();
  };
  GltfExportOptions o;
  o.jpeg_quality = 0;
  expect_invalid(mesh, atlas, o, "jpeg_quality 0");
  o = GltfExportOptions();
  o.max_texture_size = 20000;
  expect_invalid(mesh, atlas, o, "max_texture_size 20000");
  o = GltfExportOptions();
  o.draco_position_bits = -1;
  expect_invalid(mesh, atlas, o, "draco_position_bits -1");
  o.draco_position_bits = 31;
  expect_invalid(mesh, atlas, o, "draco_position_bits 31");
  o = GltfExportOptions();
  o.draco_compression_level = 11;
  expect_invalid(mesh, atlas, o, "draco_compression_level 11");

  Mesh bad = mesh;
  bad.indices.back() = static_cast<uint32_t>(mesh.num_vertices());
  expect_invalid(bad, atlas, GltfExportOptions(), "past the");
  bad = mesh;
  bad.indices.pop_back();
  expect_invalid(bad, atlas, GltfExportOptions(), "multiple of 3");
  bad = mesh;
  bad.uvs.pop_back();
  expect_invalid(bad, atlas, GltfExportOptions(), "uv floats");
  bad = mesh;
  bad.positions[4] = std::nanf("");
  expect_invalid(bad, atlas, GltfExportOptions(), "vertex 1 has a non-finite position");
  bad = mesh;
  bad.normals.resize(3);
  expect_invalid(bad, atlas, GltfExportOptions(), "normal floats");
  expect_invalid(Mesh(), atlas, GltfExportOptions(), "no vertices");
  expect_invalid(mesh, Image8(), GltfExportOptions(), "colour atlas");
  expect_invalid(mesh, Image8(4, 4, 1), GltfExportOptions(), "colour atlas");
}

// The earlier name keeps working (docs/SDK.md, "Deprecated names").
TEST(GltfExportTest, DeprecatedNameBuildsTheSameAtlas) {
  const TwoLayerPanorama pano = testing::MakeRoomPanorama(64, 32);
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wdeprecated-declarations"
  const Image8 old = BuildColourAtlas(pano);
#pragma GCC diagnostic pop
  EXPECT_EQ(old.vector(), BuildColorAtlas(pano).vector());
}

TEST(GltfExportTest, ColorAtlasStacksLayersAndFillsAbsentNodes) {
  const TwoLayerPanorama pano = testing::MakeRoomPanorama(64, 32);
  const Image8 atlas = BuildColorAtlas(pano);
  ASSERT_EQ(atlas.width(), 64);
  ASSERT_EQ(atlas.height(), 64);
  ASSERT_EQ(atlas.channels(), 3);
  int back_nodes = 0, filled = 0;
  for (int y = 0; y < 32; ++y) {
    for (int x = 0; x < 64; ++x) {
      const size_t i = pano.index(x, y);
      const LayerData& front = pano.layer(kFront);
      const LayerData& back = pano.layer(kBack);
      ASSERT_TRUE(front.present[i]);  // The room has a front node everywhere.
      for (int c = 0; c < 3; ++c) ASSERT_EQ(atlas.at(x, y, c), front.rgb[3 * i + c]);
      const LayerData& expected = back.present[i] ? back : front;
      back_nodes += back.present[i];
      filled += !back.present[i];
      for (int c = 0; c < 3; ++c) ASSERT_EQ(atlas.at(x, y + 32, c), expected.rgb[3 * i + c]);
    }
  }
  EXPECT_GT(back_nodes, 0);
  EXPECT_GT(filled, 0);
}

// The texel a uv addresses, with the sampler's wrapping (u repeats, v clamps).
const unsigned char* Texel(const tinygltf::Image& image, float u, float v) {
  int x = static_cast<int>(std::floor(u * image.width)) % image.width;
  if (x < 0) x += image.width;
  const int y = std::clamp(static_cast<int>(std::floor(v * image.height)), 0, image.height - 1);
  return &image.image[(static_cast<size_t>(y) * image.width + x) * image.component];
}

TEST(GltfExportTest, BuiltMeshTexturesEveryVertexWithItsNodeColor) {
  TwoLayerPanorama pano = testing::MakeRoomPanorama(96, 48);
  // Make the top rows unlit (sky), as reconstructions do.
  for (int y = 0; y < 4; ++y) {
    for (int x = 0; x < pano.width(); ++x) {
      for (int c = 0; c < 3; ++c) pano.layer(kFront).normal[3 * pano.index(x, y) + c] = 0.0f;
    }
  }
  auto mesh = BuildMesh(pano);
  ASSERT_TRUE(mesh.ok()) << mesh.status().ToString();
  auto glb = EncodeGlb(*mesh, BuildColorAtlas(pano), PngOptions());
  ASSERT_TRUE(glb.ok()) << glb.status().ToString();
  const Parsed p = ParseGlb(*glb);
  ASSERT_TRUE(p.ok) << p.error;
  const auto& prim = p.model.meshes[0].primitives[0];
  const std::vector<float> uvs = ReadAccessor<float>(p.model, prim.attributes.at("TEXCOORD_0"));
  const std::vector<float> normals = ReadAccessor<float>(p.model, prim.attributes.at("NORMAL"));
  ASSERT_EQ(uvs.size(), 2 * mesh->num_vertices());
  EXPECT_EQ(ReadAccessor<uint32_t>(p.model, prim.indices).size(), mesh->indices.size());
  const tinygltf::Image& image = p.model.images[0];
  int wrong = 0, seam = 0;
  for (size_t v = 0; v < mesh->num_vertices(); ++v) {
    seam += uvs[2 * v] > 1.0f;
    const unsigned char* texel = Texel(image, uvs[2 * v], uvs[2 * v + 1]);
    for (int c = 0; c < 3; ++c) wrong += texel[c] != mesh->colors[3 * v + c];
    const float* n = &normals[3 * v];
    ASSERT_NEAR(n[0] * n[0] + n[1] * n[1] + n[2] * n[2], 1.0, 1e-6);
  }
  EXPECT_EQ(wrong, 0);
  EXPECT_GT(seam, 0);  // The seam copies were checked too.
}

TEST(GltfExportTest, SimplifiedMeshMeetsTheTriangleBudget) {
  const TwoLayerPanorama pano = testing::MakeRoomPanorama(256, 128);
  MeshSimplifyOptions simplify;
  simplify.max_triangles = 12000;
  auto simplified = BuildSimplifiedMesh(pano, simplify);
  ASSERT_TRUE(simplified.ok()) << simplified.status().ToString();
  ASSERT_TRUE(simplified->budget_met)
      << simplified->mesh.num_triangles() << " of " << simplified->full_triangles;
  GltfExportOptions options;
  options.draco = true;
  GltfExportStats stats;
  auto glb = EncodeGlb(simplified->mesh, BuildColorAtlas(pano), options, &stats);
  ASSERT_TRUE(glb.ok()) << glb.status().ToString();
  EXPECT_EQ(stats.num_triangles, simplified->mesh.num_triangles());
  EXPECT_LE(stats.num_triangles, 12000u);
  EXPECT_LT(stats.num_triangles, static_cast<size_t>(simplified->full_triangles) / 4);
  const Parsed p = ParseGlb(*glb);
  ASSERT_TRUE(p.ok) << p.error;
  EXPECT_EQ(p.model.accessors[p.model.meshes[0].primitives[0].indices].count,
            3 * stats.num_triangles);
}

class GltfExportFileTest : public casual3d::testing::TestWithScratchDir {};

TEST_F(GltfExportFileTest, WritesAtomicallyAndReplaces) {
  const Mesh mesh = MakeSphereBand(6, 3, 1);
  const Image8 atlas = MakeAtlas(8, 8);
  const fs::path out = dir_ / "photo.glb";
  {
    std::ofstream old(out);
    old << "old";
  }
  GltfExportStats stats;
  ASSERT_TRUE(ExportGlb(mesh, atlas, GltfExportOptions(), out.string(), &stats).ok());
  std::ifstream in(out, std::ios::binary);
  const std::vector<uint8_t> bytes((std::istreambuf_iterator<char>(in)),
                                   std::istreambuf_iterator<char>());
  EXPECT_EQ(bytes, *EncodeGlb(mesh, atlas, GltfExportOptions()));  // Deterministic too.
  EXPECT_EQ(bytes.size(), stats.file_bytes);
  size_t files = 0;
  for (const auto& entry : fs::directory_iterator(dir_)) files += entry.is_regular_file();
  EXPECT_EQ(files, 1u);  // No temporary left behind.
  struct stat st;
  ASSERT_EQ(::stat(out.c_str(), &st), 0);
  EXPECT_NE(st.st_mode & S_IRGRP, 0u) << "the file should have a new file's usual mode, not 0600";
}

TEST_F(GltfExportFileTest, FailsCleanlyWhenTheFolderIsMissing) {
  const fs::path out = dir_ / "missing" / "photo.glb";
  const Status s =
      ExportGlb(MakeSphereBand(4, 2, 0), MakeAtlas(8, 8), GltfExportOptions(), out.string());
  EXPECT_EQ(s.code(), StatusCode::kIoError);
  EXPECT_NE(s.message().find(out.string()), std::string::npos) << s.message();
  EXPECT_FALSE(fs::exists(out));
}

TEST_F(GltfExportFileTest, InvalidInputLeavesTheOldFileAlone) {
  const fs::path out = dir_ / "photo.glb";
  {
    std::ofstream old(out);
    old << "old";
  }
  Mesh bad = MakeSphereBand(4, 2, 0);
  bad.indices.push_back(0);
  EXPECT_FALSE(ExportGlb(bad, MakeAtlas(8, 8), GltfExportOptions(), out.string()).ok());
  EXPECT_EQ(fs::file_size(out), 3u);
}

}  // namespace
}  // namespace casual3d::encoder

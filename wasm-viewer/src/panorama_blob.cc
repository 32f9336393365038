#include "wasm-viewer/src/panorama_blob.h"

#include <cstring>

namespace casual3d::viewer {
namespace {

constexpr char kPanoMagic[8] = {'C', '3', 'D', 'P', 'A', 'N', 'O', '1'};
constexpr char kMeshMagic[8] = {'C', '3', 'D', 'M', 'E', 'S', 'H', '1'};

// Both targets (x86-64 and wasm32) are little-endian, so plain copies give the
// documented byte order.
static_assert(sizeof(float) == 4 && sizeof(double) == 8, "IEEE-754 sizes expected");

class Writer {
 public:
  template <typename T>
  void Put(const T& v) {
    const size_t at = bytes_.size();
    bytes_.resize(at + sizeof(T));
    std::memcpy(bytes_.data() + at, &v, sizeof(T));
  }
  template <typename T, typename A>
  void PutArray(const std::vector<T, A>& v) {
    const size_t at = bytes_.size();
    bytes_.resize(at + v.size() * sizeof(T));
    if (!v.empty()) std::memcpy(bytes_.data() + at, v.data(), v.size() * sizeof(T));
  }
  void PutBytes(const char* p, size_t n) { bytes_.insert(bytes_.end(), p, p + n); }
  std::vector<uint8_t> Take() { return std::move(bytes_); }

 private:
  std::vector<uint8_t> bytes_;
};

class Reader {
 public:
  Reader(const uint8_t* data, size_t size) : data_(data), size_(size) {}
  template <typename T>
  bool Get(T* v) {
    if (size_ - at_ < sizeof(T)) return false;
    std::memcpy(v, data_ + at_, sizeof(T));
    at_ += sizeof(T);
    return true;
  }
  template <typename T, typename A>
  bool GetArray(size_t n, std::vector<T, A>* v) {
    if (n > (size_ - at_) / sizeof(T)) return false;
    v->resize(n);
    if (n) std::memcpy(v->data(), data_ + at_, n * sizeof(T));
    at_ += n * sizeof(T);
    return true;
  }
  bool Magic(const char (&m)[8]) {
    if (size_ - at_ < 8 || std::memcmp(data_ + at_, m, 8) != 0) return false;
    at_ += 8;
    return true;
  }
  bool AtEnd() const { return at_ == size_; }

 private:
  const uint8_t* data_;
  size_t size_;
  size_t at_ = 0;
};

// The arrays of a layer in blob order, each with its elements per pixel. The
// blob writer and reader both go through these lists, so the two cannot drift.
template <typename Layer, typename Visit>
bool VisitLayerArrays(Layer& L, Visit&& visit) {
  return visit(L.present, 1) && visit(L.rgb, 3) && visit(L.depth_m, 1) && visit(L.normal, 3) &&
         visit(L.label, 1) && visit(L.links, 1);
}

// The vertex arrays of a mesh in blob order, each with its elements per vertex
// (the index array follows them).
template <typename MeshT, typename Visit>
bool VisitVertexArrays(MeshT& mesh, Visit&& visit) {
  return visit(mesh.positions, 3) && visit(mesh.normals, 3) && visit(mesh.uvs, 2) &&
         visit(mesh.colors, 3);
}

}  // namespace

std::vector<uint8_t> SerializePanorama(const TwoLayerPanorama& pano) {
  Writer w;
  w.PutBytes(kPanoMagic, 8);
  w.Put(static_cast<uint32_t>(pano.width()));
  w.Put(static_cast<uint32_t>(pano.height()));
  for (double c : pano.frame().centre) w.Put(c);
  for (double r : pano.frame().rotation) w.Put(r);
  for (int l = 0; l < kNumLayers; ++l) {
    VisitLayerArrays(pano.layer(l), [&w](const auto& v, size_t) {
      w.PutArray(v);
      return true;
    });
  }
  return w.Take();
}

StatusOr<TwoLayerPanorama> ParsePanorama(const uint8_t* data, size_t size) {
  Reader r(data, size);
  if (!r.Magic(kPanoMagic)) return InvalidData("panorama blob: bad magic (expected C3DPANO1)");
  uint32_t width = 0, height = 0;
  if (!r.Get(&width) || !r.Get(&height)) return InvalidData("panorama blob: truncated header");
  if (width == 0 || height == 0 || width > kMaxBlobSide || height > kMaxBlobSide ||
      uint64_t{width} * height > kMaxBlobPixels) {
    return LimitExceeded("panorama blob: size " + std::to_string(width) + "x" +
                         std::to_string(height) + " is empty or beyond the limit");
  }
  TwoLayerPanorama pano(static_cast<int>(width), static_cast<int>(height));
  for (double& c : pano.frame().centre) {
    if (!r.Get(&c)) return InvalidData("panorama blob: truncated frame");
  }
  for (double& c : pano.frame().rotation) {
    if (!r.Get(&c)) return InvalidData("panorama blob: truncated frame");
  }
  const size_t n = size_t{width} * height;
  for (int l = 0; l < kNumLayers; ++l) {
    const bool read = VisitLayerArrays(pano.layer(l), [&r, n](auto& v, size_t per_pixel) {
      return r.GetArray(per_pixel * n, &v);
    });
    if (!read) return InvalidData("panorama blob: truncated layer " + std::to_string(l));
  }
  if (!r.AtEnd()) return InvalidData("panorama blob: trailing bytes");
  return pano;
}

std::vector<uint8_t> SerializeMesh(const Mesh& mesh) {
  Writer w;
  w.PutBytes(kMeshMagic, 8);
  w.Put(static_cast<uint32_t>(mesh.num_vertices()));
  w.Put(static_cast<uint32_t>(mesh.indices.size()));
  VisitVertexArrays(mesh, [&w](const auto& v, size_t) {
    w.PutArray(v);
    return true;
  });
  w.PutArray(mesh.indices);
  return w.Take();
}

StatusOr<Mesh> ParseMesh(const uint8_t* data, size_t size) {
  Reader r(data, size);
  if (!r.Magic(kMeshMagic)) return InvalidData("mesh blob: bad magic (expected C3DMESH1)");
  uint32_t nv = 0, ni = 0;
  if (!r.Get(&nv) || !r.Get(&ni)) return InvalidData("mesh blob: truncated header");
  Mesh mesh;
  const bool read = VisitVertexArrays(
      mesh, [&r, nv](auto& v, size_t per_vertex) { return r.GetArray(per_vertex * nv, &v); });
  if (!read || !r.GetArray(ni, &mesh.indices) || !r.AtEnd()) {
    return InvalidData("mesh blob: truncated or trailing bytes");
  }
  for (uint32_t i : mesh.indices) {
    if (i >= nv) return InvalidData("mesh blob: index " + std::to_string(i) + " out of range");
  }
  return mesh;
}

}  // namespace casual3d::viewer

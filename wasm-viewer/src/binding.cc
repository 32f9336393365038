// The C binding of the format library for the WebAssembly viewer: a thin layer
// that hands bytes and pixels in from JavaScript and results back out through
// the wasm heap. Every function is exported by name (wasm-viewer/CMakeLists.txt)
// and wrapped by js/format-module.js; nothing here throws or aborts on bad input.
//
// Ownership: objects returned by *_open / *_parse_* / *_assemble / c3d_build_mesh
// belong to the caller, who frees them with the matching *_free. Pointers
// returned by accessors stay valid until the object is freed. A function that
// fails returns 0 (or null) and sets the message read by c3d_last_error().

#include <emscripten/emscripten.h>

#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "format/color_atlas.h"
#include "format/image.h"
#include "format/manifest.h"
#include "format/backdrop.h"
#include "format/mesh.h"
#include "format/mesh_builder.h"
#include "format/mesh_simplify.h"
#include "format/package_reader.h"
#include "format/parallel.h"
#include "format/sha256.h"
#include "format/single_file.h"
#include "format/tile_codec.h"
#include "format/two_layer.h"
#include "wasm-viewer/src/panorama_blob.h"

namespace casual3d::viewer {
namespace {

std::string g_last_error;

void SetError(const std::string& message) { g_last_error = message; }
void SetError(const Status& status) { g_last_error = status.ToString(); }

// A package being read: its validated manifest and the panorama of the level
// being assembled.
struct Reader {
  std::unique_ptr<PackageReader> reader;
  int level = -1;  // The level being assembled, -1: none.
  std::string level_json;
};

struct Panorama {
  TwoLayerPanorama pano;
  // Whether pano passed Validate() (the reader's FinishLevel validates): the
  // mesh builders then skip their own O(pixels) validation.
  bool validated = false;
  std::vector<uint8_t> atlas;  // RGBA, width x 2*height, built on demand.
};

struct MeshResult {
  Mesh mesh;
  double max_error = 0.0;  // Relative depth error bound reported by the simplifier.
};

std::string JsonString(const std::string& s) {
  std::string out = "\"";
  for (char c : s) {
    if (c == '"' || c == '\\') {
      out += '\\';
      out += c;
    } else if (static_cast<unsigned char>(c) < 0x20) {
      char buf[8];
      std::snprintf(buf, sizeof(buf), "\\u%04x",
                    static_cast<unsigned>(static_cast<unsigned char>(c)));
      out += buf;
    } else {
      out += c;
    }
  }
  return out + "\"";
}

// A built mesh as a MeshResult, or null with the error recorded.
MeshResult* TakeMesh(StatusOr<Mesh> mesh) {
  if (!mesh.ok()) {
    SetError(mesh.status());
    return nullptr;
  }
  auto* r = new MeshResult();
  r->mesh = std::move(mesh).value();
  return r;
}

}  // namespace
}  // namespace casual3d::viewer

using casual3d::viewer::MeshResult;
using casual3d::viewer::TakeMesh;
using casual3d::viewer::Panorama;
using casual3d::viewer::Reader;
using casual3d::viewer::SetError;

extern "C" {

// The message of the last failure ("" if none).
EMSCRIPTEN_KEEPALIVE const char* c3d_last_error() { return casual3d::viewer::g_last_error.c_str(); }

// Threads the library's loops use (format/parallel.h): 1 in the build without
// threads, min(hardware threads, CASUAL3D_MAX_THREADS) in the threaded one.
EMSCRIPTEN_KEEPALIVE int c3d_num_threads() { return casual3d::ResolveThreads(0); }

// --- Panoramas -----------------------------------------------------------------

// Parses a panorama blob (src/panorama_blob.h); null on error.
EMSCRIPTEN_KEEPALIVE Panorama* c3d_panorama_parse_blob(const uint8_t* data, size_t size) {
  auto parsed = casual3d::viewer::ParsePanorama(data, size);
  if (!parsed.ok()) {
    SetError(parsed.status());
    return nullptr;
  }
  auto* p = new Panorama();
  p->pano = std::move(parsed).value();
  return p;
}

EMSCRIPTEN_KEEPALIVE void c3d_panorama_free(Panorama* p) { delete p; }
EMSCRIPTEN_KEEPALIVE int c3d_panorama_width(const Panorama* p) { return p->pano.width(); }
EMSCRIPTEN_KEEPALIVE int c3d_panorama_height(const Panorama* p) { return p->pano.height(); }

// 1 if the panorama passes TwoLayerPanorama::Validate(), else 0 (error set).
EMSCRIPTEN_KEEPALIVE int c3d_panorama_validate(Panorama* p) {
  const casual3d::Status s = p->pano.Validate(0);
  if (!s.ok()) SetError(s);
  p->validated = s.ok();
  return s.ok() ? 1 : 0;
}

// The colour atlas of format/color_atlas.h as RGBA (alpha 255): width x
// 2*height, the front layer's colours above the back layer's, each half filled
// from the other layer where its node is absent (the mesh's uvs rely on it).
// Owned by the panorama.
EMSCRIPTEN_KEEPALIVE const uint8_t* c3d_panorama_atlas_rgba(Panorama* p) {
  casual3d::Image8 atlas = casual3d::BuildColorAtlas(p->pano, 4);
  p->atlas = std::move(atlas.vector());
  return p->atlas.data();
}

// One array of one layer (0 front, 1 back) of the panorama, width*height
// elements (times 3 for rgb and normal), row-major, absent nodes zero (format/
// two_layer.h LayerData): field 0 present (bytes), 1 rgb (bytes), 2 depth_m
// (float32), 3 normal (float32), 4 label (bytes), 5 links (bytes). Owned by
// the panorama; null for an unknown layer or field.
EMSCRIPTEN_KEEPALIVE const void* c3d_panorama_layer(const Panorama* p, int layer, int field) {
  if (layer < 0 || layer > 1) return nullptr;
  const casual3d::LayerData& L = p->pano.layer(layer);
  switch (field) {
    case 0: return L.present.data();
    case 1: return L.rgb.data();
    case 2: return L.depth_m.data();
    case 3: return L.normal.data();
    case 4: return L.label.data();
    case 5: return L.links.data();
    default: return nullptr;
  }
}

// --- Meshes --------------------------------------------------------------------

// Builds the mesh of spec/mesh.md. max_triangles > 0 simplifies it to that budget
// with BuildSimplifiedMesh (max_error_rel: the largest relative depth error
// allowed, 0: the library's default); max_triangles 0 with max_error_rel > 0
// simplifies as far as that error allows (mesh.md Sec. 5, no budget); both 0
// keep the full mesh. Null on error.
EMSCRIPTEN_KEEPALIVE MeshResult* c3d_build_mesh(const Panorama* p, double max_triangles,
                                                double max_error_rel) {
  casual3d::MeshBuildOptions options;
  options.validate_input = !p->validated;
  if (max_triangles > 0 || max_error_rel > 0) {
    casual3d::MeshSimplifyOptions simplify;
    simplify.validate_input = !p->validated;
    simplify.max_triangles = static_cast<int64_t>(max_triangles);
    if (max_error_rel > 0) simplify.max_relative_error = max_error_rel;
    auto simplified = casual3d::BuildSimplifiedMesh(p->pano, simplify);
    if (!simplified.ok()) {
      SetError(simplified.status());
      return nullptr;
    }
    auto* r = new MeshResult();
    r->mesh = std::move(simplified->mesh);
    r->max_error = simplified->error_bound;
    return r;
  }
  return TakeMesh(casual3d::BuildMesh(p->pano, options));
}

// Builds the backdrop drawn behind the mesh (format/backdrop.h) with cells of
// cell_px pixels (0: the library's default). Null on error.
EMSCRIPTEN_KEEPALIVE MeshResult* c3d_build_backdrop(const Panorama* p, int cell_px) {
  casual3d::BackdropOptions options;
  options.cell_px = cell_px;
  return TakeMesh(casual3d::BuildBackdrop(p->pano, options));
}

EMSCRIPTEN_KEEPALIVE void c3d_mesh_free(MeshResult* m) { delete m; }
EMSCRIPTEN_KEEPALIVE uint32_t c3d_mesh_num_vertices(const MeshResult* m) {
  return static_cast<uint32_t>(m->mesh.num_vertices());
}
EMSCRIPTEN_KEEPALIVE uint32_t c3d_mesh_num_indices(const MeshResult* m) {
  return static_cast<uint32_t>(m->mesh.indices.size());
}
EMSCRIPTEN_KEEPALIVE const float* c3d_mesh_positions(const MeshResult* m) {
  return m->mesh.positions.data();
}
EMSCRIPTEN_KEEPALIVE const float* c3d_mesh_normals(const MeshResult* m) {
  return m->mesh.normals.data();
}
EMSCRIPTEN_KEEPALIVE const float* c3d_mesh_uvs(const MeshResult* m) { return m->mesh.uvs.data(); }
EMSCRIPTEN_KEEPALIVE const uint8_t* c3d_mesh_colors(const MeshResult* m) {
  return m->mesh.colors.data();
}
EMSCRIPTEN_KEEPALIVE const uint32_t* c3d_mesh_indices(const MeshResult* m) {
  return m->mesh.indices.data();
}
EMSCRIPTEN_KEEPALIVE double c3d_mesh_max_error(const MeshResult* m) { return m->max_error; }

// --- Packages ------------------------------------------------------------------

// Parses and validates manifest.json; null on error.
EMSCRIPTEN_KEEPALIVE Reader* c3d_reader_open(const char* bytes, size_t size) {
  auto created = casual3d::PackageReader::Create(std::string_view(bytes, size));
  if (!created.ok()) {
    SetError(created.status());  // Its messages name manifest.json and the field.
    return nullptr;
  }
  auto* r = new Reader();
  r->reader = std::make_unique<casual3d::PackageReader>(std::move(created).value());
  return r;
}

EMSCRIPTEN_KEEPALIVE void c3d_reader_free(Reader* r) { delete r; }
EMSCRIPTEN_KEEPALIVE int c3d_reader_num_levels(const Reader* r) { return r->reader->num_levels(); }
// Largest encodable depth of the package (manifest depth_encoding.far_m), metres.
EMSCRIPTEN_KEEPALIVE double c3d_reader_depth_far_m(const Reader* r) {
  return r->reader->manifest().depth.far_m;
}

// The MIME type of the package's tile images ("image/webp"; format/
// tile_image_format.h): what the JavaScript decoder decodes them as.
EMSCRIPTEN_KEEPALIVE const char* c3d_reader_tile_image_type(const Reader* r) {
  return r->reader->image_format().mime_type;
}

// What a level needs, as JSON: {"width", "height", "tiles": [{"x", "y", "w",
// "h", "files": [{"kind", "path", "bytes", "sha256", "width", "height"}]}]},
// kinds in TileImageKind order. Owned by the reader until the next call.
EMSCRIPTEN_KEEPALIVE const char* c3d_reader_level_json(Reader* r, int level) {
  using casual3d::viewer::JsonString;
  const casual3d::Manifest& m = r->reader->manifest();
  if (level < 0 || level >= static_cast<int>(m.levels.size())) {
    SetError("level " + std::to_string(level) + " is not in the package");
    return nullptr;
  }
  const casual3d::LevelEntry& L = m.levels[level];
  std::string j = "{\"width\":" + std::to_string(L.width) +
                  ",\"height\":" + std::to_string(L.height) + ",\"tiles\":[";
  for (size_t t = 0; t < L.tiles.size(); ++t) {
    int x, y, w, h;
    m.TileRect(level, static_cast<int>(t), &x, &y, &w, &h);
    j += (t ? ",{" : "{") + std::string("\"x\":") + std::to_string(x) +
         ",\"y\":" + std::to_string(y) + ",\"w\":" + std::to_string(w) +
         ",\"h\":" + std::to_string(h) + ",\"files\":[";
    for (int k = 0; k < casual3d::kNumTileImageKinds; ++k) {
      const auto kind = static_cast<casual3d::TileImageKind>(k);
      const std::string& path = L.tiles[t].files[k];
      const casual3d::FileEntry* f = m.FindFile(path);
      int iw, ih;
      casual3d::TileImageSize(kind, w, h, &iw, &ih, m.normal.type);
      j += (k ? ",{" : "{") + std::string("\"kind\":") +
           JsonString(casual3d::TileImageKindName(kind)) + ",\"path\":" + JsonString(path) +
           ",\"bytes\":" + std::to_string(f ? f->bytes : 0) +
           ",\"sha256\":" + JsonString(f ? f->sha256 : "") + ",\"width\":" + std::to_string(iw) +
           ",\"height\":" + std::to_string(ih) + "}";
    }
    j += "]}";
  }
  j += "]}";
  r->level_json = std::move(j);
  return r->level_json.c_str();
}

// Checks a fetched file against the manifest's size and SHA-256. 1 if it
// matches, else 0 with an error naming the file.
EMSCRIPTEN_KEEPALIVE int c3d_reader_check_file(const Reader* r, const char* path,
                                               const uint8_t* data, size_t size) {
  const casual3d::Status s = r->reader->VerifyFile(path, data, size);
  if (!s.ok()) SetError(s);
  return s.ok() ? 1 : 0;
}

// Adds the decoded pixels of image `kind` (TileImageKind; `channels` 3 or 4,
// tightly packed rows) of tile `tile` of `level`. Adding to another level than
// the one being assembled starts that level and discards the other. 1 on
// success, else 0 with the error set.
EMSCRIPTEN_KEEPALIVE int c3d_reader_add_image(Reader* r, int level, int tile, int kind,
                                              const uint8_t* pixels, int width, int height,
                                              int channels) {
  if (kind < 0 || kind >= casual3d::kNumTileImageKinds || (channels != 3 && channels != 4) ||
      width <= 0 || height <= 0) {
    SetError("c3d_reader_add_image: kind, channels or image size out of range");
    return 0;
  }
  if (r->level != level) {
    const casual3d::Status s = r->reader->BeginLevel(level);
    if (!s.ok()) {
      SetError(s);
      r->level = -1;
      return 0;
    }
    r->level = level;
  }
  casual3d::ImageView<const uint8_t> view(pixels, width, height, channels,
                                          static_cast<std::ptrdiff_t>(width) * channels);
  const casual3d::Status s =
      r->reader->AddTileImage(tile, static_cast<casual3d::TileImageKind>(kind), view, 0);
  if (!s.ok()) {
    SetError(s);
    return 0;
  }
  return 1;
}

// Finishes the level whose images were added (every image of every tile) and
// validates it; returns its panorama (caller frees) or null with the error set.
EMSCRIPTEN_KEEPALIVE Panorama* c3d_reader_assemble(Reader* r, int level) {
  if (r->level != level) {
    SetError("level " + std::to_string(level) + ": no tile images were added");
    return nullptr;
  }
  r->level = -1;
  auto pano = r->reader->FinishLevel(0);
  if (!pano.ok()) {
    SetError("level " + std::to_string(level) + ": " + pano.status().ToString());
    return nullptr;
  }
  auto* p = new Panorama();
  p->pano = std::move(pano).value();
  p->validated = true;  // FinishLevel validated it.
  return p;
}

// --- Single-file containers (.c3d) ----------------------------------------------

// The directory of a single-file container of `total_size` bytes from its first
// `available` bytes (data), for a reader that fetches the file in ranges. As
// JSON [{"path", "offset", "size"}] (owned by the library until the next call),
// checked as ParseSingleFileDirectory checks it. When the directory reaches
// past `available`, returns null with *needed set to the bytes to fetch before
// calling again; on an invalid container returns null with the error set and
// *needed 0.
EMSCRIPTEN_KEEPALIVE const char* c3d_single_file_directory(const uint8_t* data, size_t available,
                                                           double total_size, double* needed) {
  static std::string json;
  *needed = 0;
  const uint64_t total = static_cast<uint64_t>(total_size);
  if (available > total) available = static_cast<size_t>(total);
  auto le = [data](size_t at, int n) {
    uint64_t v = 0;
    for (int i = n - 1; i >= 0; --i) v = (v << 8) | data[at + i];
    return v;
  };
  // Walk the directory's entry lengths to find where it ends. Only a header
  // that ParseSingleFileDirectory accepts is walked; it refuses any other from
  // the first 16 bytes alone, and reads no further than the directory's end.
  if (available < total) {
    if (available < 16) {
      *needed = static_cast<double>(std::min<uint64_t>(total, 16));
      return nullptr;
    }
    const uint64_t count = le(12, 4);
    const bool header_ok = std::memcmp(data, casual3d::kSingleFileMagic, 8) == 0 &&
                           le(8, 2) == casual3d::kSingleFileVersionMajor && count > 0 &&
                           count <= casual3d::kMaxSingleFileEntries && count * 19 <= total - 16;
    if (header_ok) {
      uint64_t pos = 16;
      bool complete = true;
      for (uint64_t i = 0; i < count && complete; ++i) {
        complete = pos + 2 <= available;
        if (complete) pos += 2 + le(static_cast<size_t>(pos), 2) + 16;
        complete = complete && pos <= available;
      }
      if (!complete) {
        // At least twice as much, so that a long directory takes few round trips.
        *needed = static_cast<double>(
            std::min<uint64_t>(total, std::max<uint64_t>(pos + 273, 2 * uint64_t{available})));
        return nullptr;
      }
    }
  }
  auto entries = casual3d::ParseSingleFileDirectory(data, static_cast<size_t>(total));
  if (!entries.ok()) {
    SetError(entries.status());
    return nullptr;
  }
  using casual3d::viewer::JsonString;
  json = "[";
  for (size_t i = 0; i < entries->size(); ++i) {
    const casual3d::SingleFileEntry& e = (*entries)[i];
    json += (i ? ",{" : "{") + std::string("\"path\":") + JsonString(e.path) +
            ",\"offset\":" + std::to_string(e.offset) + ",\"size\":" + std::to_string(e.size) + "}";
  }
  json += "]";
  return json.c_str();
}

}  // extern "C"

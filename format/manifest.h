#pragma once

// The manifest of a casual3d web package (manifest.json): what the package
// holds and where each file is. spec/package.md is the normative text; this is
// its model, parser, serializer and validator. Standard library only, no
// exceptions; the parser takes untrusted bytes.
//
// Versioning: "version" is "major.minor". Readers refuse an unknown major
// (kUnsupportedVersion) and ignore members they do not know, so a minor
// version may add optional members. This reader reads majors 1 and 2; 2.0 is
// 1.2 with levels that may leave out halvings between level 0 and the
// coarsest (spec/package.md Sec. 2) and graph images of right and down links
// only (Sec. 4.1).

#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "format/equirect.h"
#include "format/reader_checks.h"
#include "format/status.h"
#include "format/tile_codec.h"
#include "format/view_hints.h"

namespace casual3d {

constexpr const char* kPackageFormatName = "casual3d";
// The majors this reader reads. Writers write the lowest version whose
// members and rules they use: 1.0 without "view", 1.1 with it, 1.2 with lossy
// normals ("octahedral-lossy"), 2.0 when a level is left out (then with any
// of those).
constexpr int kOldestPackageVersionMajor = 1;
constexpr int kPackageVersionMajor = 2;
constexpr bool IsKnownPackageMajor(int major) {
  return major >= kOldestPackageVersionMajor && major <= kPackageVersionMajor;
}
constexpr const char* kManifestFileName = "manifest.json";

// Limits of spec/package.md, "Limits".
constexpr int kMaxPackageWidth = 32768;
constexpr int kMaxPackageHeight = 16384;
constexpr int kMinTileSize = 16;
constexpr int kMaxTileSize = 4096;
constexpr int kMaxLevels = 8;
constexpr int kMaxTilesPerLevel = 16384;
constexpr uint64_t kMaxFileBytes = 256ull << 20;     // One tile file.
constexpr size_t kMaxManifestBytes = 16u << 20;      // manifest.json.
constexpr size_t kMaxPathBytes = 255;

// One tile of a level: the paths of its images (relative to the package folder).
struct TileEntry {
  std::string files[kNumTileImageKinds];  // Indexed by TileImageKind.
};

// One level of detail. Level 0 is the full resolution; level k has the size
// (width >> s) x (height >> s) for a shift s that grows with k: s = k in
// version 1.x, any larger shift than level k-1's from 2.0, where a writer may
// leave out halvings (spec/package.md Sec. 2). Tiles cover the level in a
// grid of tile_size squares (the last column and row may be smaller), listed
// row by row.
struct LevelEntry {
  int width = 0;
  int height = 0;
  int columns = 0;
  int rows = 0;
  std::vector<TileEntry> tiles;  // columns * rows, row-major.
};

// A file of the package with its size and SHA-256 (lower-case hex).
struct FileEntry {
  std::string path;
  uint64_t bytes = 0;
  std::string sha256;
};

struct Manifest {
  int version_major = kOldestPackageVersionMajor;  // Writers: the lowest version
  int version_minor = 0;                            // whose members and rules they use.
  std::string generator;  // Free text naming the writing program (optional).
  int width = 0;          // Full-resolution panorama size, pixels.
  int height = 0;
  PanoramaFrame frame;
  // "view" (version 1.1, optional): how to look at the 3D photo.
  std::optional<ViewHints> view;
  int tile_size = 512;    // Pixels per tile side at every level.
  DepthQuantization depth;    // depth_encoding
  NormalQuantization normal;  // normal_encoding
  std::vector<LevelEntry> levels;  // Finest first.
  std::vector<FileEntry> files;

  // How tiles are quantized; in version 2.x graph images hold right and down
  // links only (a major this reader does not know, read with the
  // unknown-major check off, is read as 1.x).
  TileQuantization quantization() const { return {depth, normal, version_major == 2}; }

  // The entry of `path`, or nullptr.
  const FileEntry* FindFile(const std::string& path) const;
  // Pixel rectangle of tile `tile` of `level` (preconditions: both in range).
  void TileRect(int level, int tile, int* x, int* y, int* w, int* h) const;
  // Sum of the sizes of all files of `level` (bytes), not counting the manifest.
  uint64_t LevelBytes(int level) const;

  // Checks everything a reader relies on: version, limits, the level sizes and
  // tile grids, that every tile path is a safe relative path listed in
  // `files` exactly once, sizes and checksums well formed, depth encoding
  // (near_m < far_m). The named rules among these (unknown-major,
  // path-escape, near-equals-far) are enforced only when on in `checks`.
  Status Validate(const ReaderChecks& checks = ReaderChecks()) const;
};

// True if `path` is a safe package-relative path: 1..255 bytes of
// [A-Za-z0-9._-] in '/'-separated components, none empty, "." or "..", not
// starting with '/', so that it cannot escape the package folder.
bool IsSafePackagePath(std::string_view path);

// The nesting limit of manifest.json: arrays and objects enclosing each other,
// the root object counting 1 (spec/package.md Sec. 3).
constexpr int kMaxManifestNesting = 16;

// Parses and validates manifest.json. Errors name the field ("levels[1].tiles[3]:
// ...") or the byte offset of a JSON syntax error. Integer members accept any
// JSON number with an integral value (64, 64.0 and 6.4e1 alike). The named
// rules (unknown-major, nesting-too-deep and those of Validate) are enforced
// when on in `checks`.
StatusOr<Manifest> ParseManifest(std::string_view bytes,
                                 const ReaderChecks& checks = ReaderChecks());

// Serializes a manifest as JSON with a trailing newline: pretty-printed with a
// 2-space indent, or without any white space when `compact` (about 40% fewer
// bytes for the same members).
std::string SerializeManifest(const Manifest& manifest, bool compact = false);

}  // namespace casual3d

#pragma once

// Writes a two-layer panorama as a casual3d web package (spec/package.md): a
// folder of static files, manifest.json plus per level and tile a lossy colour
// WebP and lossless depth, normal and graph WebPs; or the same files as one
// single-file container (.c3d).

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "format/manifest.h"
#include "format/status.h"
#include "format/two_layer.h"
#include "format/version.h"

namespace casual3d::encoder {

struct PackageOptions {
  // Tile side, pixels, at every level: [kMinTileSize, kMaxTileSize] (16..4096).
  int tile_size = 512;
  // Levels of detail computed, 1..kMaxLevels; 0 = automatic: halve while the
  // coarsest level is wider than 512 pixels and its size is even. One fewer
  // is stored when omit_level_width leaves one out.
  int levels = 0;
  // Leave out the level more than half this and at most this many pixels
  // wide (2048: the 2048 level of 4096 and 8192 panoramas, the 1536 one of
  // 6144), unless it is level 0 or the coarsest (package version 2.0, which
  // 1.x readers refuse; spec/package.md Sec. 2); 0 writes every level
  // (version 1.x). The others are computed by halving as before, so they
  // have the same pixels either way.
  int omit_level_width = 0;
  // Lossy WebP quality of the colour images, 0..100.
  float color_quality = 90.0f;
  // libwebp method (speed/size, 0 fastest .. 6 smallest) for colour images.
  int color_method = 3;
  // Lossless WebP effort (0..100) and method (0..6) for depth, normal, graph.
  float lossless_effort = 25.0f;
  int lossless_method = 1;
  // Depth code bits (8..16; spec/package.md, depth_encoding): 12 keeps the
  // relative depth error below 0.09% for far/near up to 1000.
  int depth_bits = 12;
  // Octahedral normal bits per coordinate (4..8): 8 gives at most ~0.9 degrees.
  int normal_bits = 8;
  // Normals as lossy images (spec/package.md 1.2, "octahedral-lossy") instead
  // of lossless codes of normal_bits: each tile at the lowest WebP quality
  // whose decoded normals are within normal_mean_error_deg on average and
  // normal_p99_error_deg at the 99th percentile of the panorama's, over the
  // tile's lit present nodes (lossy_normal_tile.h); bounds in degrees,
  // [1, 90]. The manifest declares the bounds and says version 1.2 (2.0
  // when a level is left out).
  bool lossy_normals = false;
  double normal_mean_error_deg = 2.5;
  double normal_p99_error_deg = 9.0;
  // Fill the depth and normal codes of absent nodes with codes of nearby
  // present nodes (absent_fill.h) instead of zeros: the decoded panorama is
  // the same, the lossless tiles smaller (4-9% on reconstructions). Off by
  // default so that archives and the spec's vectors keep their bytes.
  bool fill_absent = false;
  // manifest.json without white space (about 40% smaller) instead of
  // pretty-printed.
  bool compact_manifest = false;
  // Threads encoding tiles; 0 = all cores.
  int num_threads = 0;
  // Written to the manifest's "generator" member: the writing program.
  std::string generator = std::string("casual3d ") + kVersion;

  Status Check() const;
};

// The settings for web delivery of reconstructed 3D photos, used by
// `casual3d encode` and `casual3d reconstruct` (docs/PERFORMANCE.md, "Package
// size of reconstructions"; docs/DECISIONS.md, "Delivery budget" and "Lossy
// normals"): PackageOptions' defaults but 5-bit normals (angular error at most
// 8.1 degrees, about 2.6 on average against 8 bits on reconstructions, whose
// normals are noisier than that), no level of 1025..2048 pixels wide
// (omit_level_width: the viewer steps from 1024 to 4096, and a 4096x2048
// package is about a quarter smaller), 9-bit depth (relative error at most
// exp(ln(far_m / near_m) / 1020) - 1: 0.68% for far/near = 1000; the viewer's
// simplifier allows one code step beyond its 1%, wasm-viewer/js/mesh-error.js),
// absent nodes filled (fill_absent), lossless WebP method 4, effort 75 and a compact
// manifest. Lossy normals (lossy_normals, `encode --lossy-normals`) are not
// among them: they save 15% of the demo's package but cost the viewer 9% more
// CPU to decode and save nothing on fern and sceaux.
PackageOptions DeliveryPackageOptions();

// Sizes and timing of an encoded package.
struct PackageStats {
  uint64_t total_bytes = 0;               // All files including manifest.json.
  std::vector<uint64_t> level_bytes;      // Tile files per level (finest first).
  uint64_t manifest_bytes = 0;
  int num_files = 0;
};

// The files of a package in memory: manifest.json first, then the tile files
// sorted by path.
using PackageFiles = std::vector<std::pair<std::string, std::vector<uint8_t>>>;

// Encodes `pano` (which must Validate()) into package files. Fails with
// kInvalidArgument naming the option or the panorama problem (for example a
// size that cannot be halved `levels - 1` times).
StatusOr<PackageFiles> EncodePackage(const TwoLayerPanorama& pano, const PackageOptions& options,
                                     PackageStats* stats = nullptr);

// EncodePackage at another colour quality: the depth, normal and graph tiles
// are copied from `earlier`, the files EncodePackage gave for the same
// panorama with options that differ from `options` in color_quality only
// (the caller's promise, not checked: lossy normal tiles depend on
// color_method, and the manifest declares the options given here), and only
// the colour tiles are encoded again (package_fit.h).
StatusOr<PackageFiles> ReencodeColor(const TwoLayerPanorama& pano, const PackageOptions& options,
                                     const PackageFiles& earlier, PackageStats* stats = nullptr);

// Writes package files into folder `dir` atomically: everything goes to a
// temporary folder next to it that then replaces `dir`. An existing `dir` is
// replaced only if it is empty or holds a package (a manifest.json); anything
// else is refused, so that no unrelated folder is ever deleted.
Status WritePackageFolder(const PackageFiles& files, const std::string& dir);

// Writes package files as one single-file container at `path`, atomically.
Status WritePackageSingleFile(const PackageFiles& files, const std::string& path);

}  // namespace casual3d::encoder

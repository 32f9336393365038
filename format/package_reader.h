#pragma once

// Reads a casual3d web package (spec/package.md) back into a two-layer
// panorama at a chosen level of detail. Standard library only, no exceptions:
// every entry point takes untrusted bytes and returns a Status.
//
// Two ways to use it:
//  - ReadPackage(): one call with a FileSource and an ImageDecoderFactory,
//    which gives the decoder of the package's tile image format (native
//    tools: FolderFileSource or SingleFileSource and encoder::TileImageDecoders()
//    of encoder/tile_image_codec.h).
//  - PackageReader: step by step, for callers that fetch and decode files
//    themselves (the WebAssembly viewer: JavaScript fetches the files the
//    reader names, decodes them with the browser's decoder for the MIME type of
//    image_format() and hands in the RGBA pixels).

#include <cstdint>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "format/file_source.h"
#include "format/image.h"
#include "format/manifest.h"
#include "format/status.h"
#include "format/tile_codec.h"
#include "format/tile_image_format.h"
#include "format/two_layer.h"

namespace casual3d {

// Decodes a compressed image (WebP in packages 1.x and 2.x) to 8-bit pixels with 3
// (RGB) or 4 (RGBA) channels. Must be safe to call from several threads.
class ImageDecoder {
 public:
  virtual ~ImageDecoder() = default;
  virtual StatusOr<Image8> Decode(const uint8_t* data, size_t size) const = 0;
};

// Gives the decoder of a tile image format: how ReadPackage picks the decoder
// from the manifest (TileImageFormatOf). Must be safe to call from several
// threads.
class ImageDecoderFactory {
 public:
  virtual ~ImageDecoderFactory() = default;
  // The decoder of `format`, living as long as the factory; a Status naming
  // the format if there is none.
  virtual StatusOr<const ImageDecoder*> DecoderFor(const TileImageFormat& format) const = 0;
};

struct ReadOptions;

// Step-by-step reader of one package.
class PackageReader {
 public:
  // Parses and validates manifest.json. `checks`: the named rules to enforce
  // (format/reader_checks.h; all by default) here and in every later step.
  static StatusOr<PackageReader> Create(std::string_view manifest_bytes,
                                        const ReaderChecks& checks = ReaderChecks());

  const Manifest& manifest() const { return manifest_; }
  // The format of the tile images (TileImageFormatOf(manifest())).
  const TileImageFormat& image_format() const { return *image_format_; }
  int num_levels() const { return static_cast<int>(manifest_.levels.size()); }

  // Paths of the files needed to assemble `level` (tile by tile, in the order
  // colour, depth, normal, graph). Empty for a level out of range.
  std::vector<std::string> FilesForLevel(int level) const;

  // Checks a fetched file against the manifest: its size, its SHA-256 and,
  // for the depth, normal and graph images, that it is lossless
  // (image_format().check_lossless). Call it for every file before decoding it.
  Status VerifyFile(const std::string& path, const uint8_t* data, size_t size) const;

  // Starts assembling `level`: allocates its (empty) panorama. Fails with
  // kLimitExceeded if the level has more than `max_pixels` pixels.
  Status BeginLevel(int level, int64_t max_pixels = int64_t{1} << 25);

  // Hands in the decoded image of `kind` for tile `tile` (row-major index) of
  // the level being assembled; the image is 3- or 4-channel 8-bit. Tiles and
  // kinds may come in any order; calls for different (tile, kind) pairs may run
  // concurrently.
  // Its rows are decoded on up to `num_threads` threads (DecodeTileImage).
  Status AddTileImage(int tile, TileImageKind kind, ImageView<const uint8_t> pixels,
                      int num_threads = 1);

  // Decodes a compressed file of tile `tile` with `decoder` and adds it.
  Status AddTileFile(int tile, TileImageKind kind, const uint8_t* data, size_t size,
                     const ImageDecoder& decoder);

  // After every image of every tile was added: checks present nodes and
  // clears absent ones (FinishDecodedPanorama; a message names the tile file
  // of a bad value), validates the links (TwoLayerPanorama::ValidateLinks; a
  // message names the graph file of the node whose link is wrong, and that of
  // the node it points at when another tile holds it) and returns the
  // panorama. The reader can then begin another level. Its messages do not
  // name the level: the caller does. Up to `num_threads` threads share the
  // passes over the nodes.
  StatusOr<TwoLayerPanorama> FinishLevel(int num_threads = 1);

 private:
  PackageReader(Manifest manifest, const ReaderChecks& checks);
  friend StatusOr<TwoLayerPanorama> ReadPackage(const FileSource&, const ImageDecoderFactory&,
                                                const ReadOptions&, Manifest*);
  // The path of the `kind` image of the tile holding pixel (x, y) of the
  // level being assembled.
  const std::string& TileFileAt(int x, int y, TileImageKind kind) const;

  Manifest manifest_;
  ReaderChecks checks_;
  const TileImageFormat* image_format_;
  // Per entry of manifest_.files: the TileImageKind of the tile image using
  // it, or -1 for an entry no tile uses.
  std::vector<int8_t> file_kinds_;
  std::shared_ptr<TileDecoder> tile_decoder_;
  int level_ = -1;
  TwoLayerPanorama pano_;
  std::vector<uint8_t> received_;  // One per (tile, kind).
};

struct ReadOptions {
  int level = 0;                  // Level of detail, 0 = full resolution.
  int num_threads = 1;            // Threads decoding tiles, 1..256.
  bool verify_checksums = true;   // Check each file's SHA-256 against the manifest.
  int64_t max_pixels = int64_t{1} << 25;  // Refuse larger levels (memory bound).
  // The named rules to enforce (all by default; verify_checksums false also
  // switches checksum-mismatch off). Switching them off is for conformance
  // tests.
  ReaderChecks checks;

  Status Check() const;
};

// Reads manifest.json from `source` and parses it (ParseManifest, enforcing
// `checks`); every message names manifest.json. ReadPackage does this first;
// a caller that reports problems per level calls it once before the levels,
// so that a problem of the manifest is not reported as one of a level.
StatusOr<Manifest> ReadManifest(const FileSource& source,
                                const ReaderChecks& checks = ReaderChecks());

// Reads manifest.json and all tiles of `options.level` from `source`, decodes
// them with the decoder `decoders` gives for the package's tile image format
// and returns the level's panorama. If `manifest_out` is not null it receives
// the manifest.
StatusOr<TwoLayerPanorama> ReadPackage(const FileSource& source,
                                       const ImageDecoderFactory& decoders,
                                       const ReadOptions& options = ReadOptions(),
                                       Manifest* manifest_out = nullptr);

// The same with one decoder for whatever format the package holds.
StatusOr<TwoLayerPanorama> ReadPackage(const FileSource& source, const ImageDecoder& decoder,
                                       const ReadOptions& options = ReadOptions(),
                                       Manifest* manifest_out = nullptr);

}  // namespace casual3d

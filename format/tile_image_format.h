#pragma once

// The image format of a package's tile files: the one place for its name,
// file extension and MIME type, and for the container rule that tells a
// lossless image from a lossy one (spec/package.md Sec. 4). Packages 1.x hold
// WebP. Readers and writers choose the format from the manifest
// (TileImageFormatOf); the pixels are decoded by a codec outside format/
// (encoder/tile_image_codec.h natively, the browser's decoder in the viewer),
// chosen by the format's name or MIME type. Standard library only.

#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>

#include "format/manifest.h"
#include "format/status.h"
#include "format/tile_codec.h"

namespace casual3d {

struct TileImageFormat {
  const char* name;        // "webp": what codecs are registered under.
  const char* label;       // "WebP": for messages.
  const char* extension;   // ".webp": of the file names writers give (TileFileName).
  const char* mime_type;   // "image/webp": for browsers' decoders and web servers.
  // Checks the container of a depth, normal or graph image `kind_name` at
  // `path`: ok when it is a still losslessly coded image; kInvalidData naming
  // the file and the coding otherwise. A malformed container passes (the
  // decoder refuses it). Reads only within [data, data + size).
  Status (*check_lossless)(const std::string& path, const char* kind_name, const uint8_t* data,
                           size_t size);
};

// WebP (RIFF container; lossless when VP8L, WebpContainerCoding).
const TileImageFormat& WebpTileImageFormat();

// The tile image format of packages of major version `major`: WebP for 1 and 2;
// kUnsupportedVersion naming the version otherwise.
StatusOr<const TileImageFormat*> TileImageFormatForVersion(int major);

// The tile image format of the package of `manifest` (its version).
inline StatusOr<const TileImageFormat*> TileImageFormatOf(const Manifest& manifest) {
  return TileImageFormatForVersion(manifest.version_major);
}

// The format called `name` ("webp"); kNotFound naming it and the known ones.
StatusOr<const TileImageFormat*> FindTileImageFormat(std::string_view name);

// The format whose file extension is `extension` (".webp", lower case), or
// nullptr: for serving tile files with their MIME type.
const TileImageFormat* TileImageFormatByExtension(std::string_view extension);

// The file name writers give a tile image (spec/package.md Sec. 3, "Paths"):
// "l<level>/<row>-<column>.<kind><extension>", e.g. "l0/1-3.graph.webp".
std::string TileFileName(int level, int row, int column, TileImageKind kind,
                         const TileImageFormat& format);

}  // namespace casual3d

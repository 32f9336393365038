#include "format/tile_image_format.h"

namespace casual3d {
namespace {

Status CheckWebpLossless(const std::string& path, const char* kind_name, const uint8_t* data,
                         size_t size) {
  const WebpCoding coding = WebpContainerCoding(data, size);
  if (coding == WebpCoding::kLossy)
    return InvalidData(path + ": a " + kind_name +
                       " image must be lossless WebP (VP8L); this one is lossy (VP8)");
  if (coding == WebpCoding::kNotStill)
    return InvalidData(path + ": a " + kind_name +
                       " image must be a still lossless WebP image; this one is animated");
  return Status::Ok();
}

constexpr TileImageFormat kWebp = {"webp", "WebP", ".webp", "image/webp", CheckWebpLossless};

// Every format this library knows, by name.
constexpr const TileImageFormat* kFormats[] = {&kWebp};

}  // namespace

const TileImageFormat& WebpTileImageFormat() { return kWebp; }

StatusOr<const TileImageFormat*> TileImageFormatForVersion(int major) {
  if (IsKnownPackageMajor(major)) return &kWebp;
  return UnsupportedVersion("packages of major version " + std::to_string(major) +
                            " have no known tile image format (1.x and 2.x: WebP)");
}

StatusOr<const TileImageFormat*> FindTileImageFormat(std::string_view name) {
  std::string known;
  for (const TileImageFormat* f : kFormats) {
    if (name == f->name) return f;
    known += (known.empty() ? "" : ", ") + std::string(f->name);
  }
  return NotFound("no tile image format \"" + std::string(name) + "\" (known: " + known + ")");
}

const TileImageFormat* TileImageFormatByExtension(std::string_view extension) {
  for (const TileImageFormat* f : kFormats)
    if (extension == f->extension) return f;
  return nullptr;
}

std::string TileFileName(int level, int row, int column, TileImageKind kind,
                         const TileImageFormat& format) {
  return "l" + std::to_string(level) + "/" + std::to_string(row) + "-" + std::to_string(column) +
         "." + TileImageKindName(kind) + format.extension;
}

}  // namespace casual3d

#include "reconstruct/io/heif_io.h"

#include <libheif/heif.h>

#include <cstdint>
#include <cstring>
#include <memory>
#include <vector>

#include "reconstruct/io/file_util.h"

namespace casual3d::io {
namespace {

struct ContextDeleter {
  void operator()(heif_context* c) const { heif_context_free(c); }
};
struct HandleDeleter {
  void operator()(heif_image_handle* h) const { heif_image_handle_release(h); }
};
struct ImageDeleter {
  void operator()(heif_image* i) const { heif_image_release(i); }
};
using Context = std::unique_ptr<heif_context, ContextDeleter>;
using Handle = std::unique_ptr<heif_image_handle, HandleDeleter>;

// Opens the primary image; on failure returns null and sets `why`.
Handle OpenPrimary(const std::string& bytes, Context* context, std::string* why) {
  context->reset(heif_context_alloc());
  heif_error err = heif_context_read_from_memory_without_copy(context->get(), bytes.data(),
                                                              bytes.size(), nullptr);
  if (err.code != heif_error_Ok) {
    *why = err.message;
    return nullptr;
  }
  heif_image_handle* handle = nullptr;
  err = heif_context_get_primary_image_handle(context->get(), &handle);
  if (err.code != heif_error_Ok) {
    *why = err.message;
    return nullptr;
  }
  return Handle(handle);
}

}  // namespace

bool LooksLikeHeif(const std::string& bytes) {
  if (bytes.size() < 12 || bytes.compare(4, 4, "ftyp") != 0) return false;
  const std::string brand = bytes.substr(8, 4);
  for (const char* b : {"heic", "heix", "heim", "heis", "hevc", "hevx", "mif1", "msf1"}) {
    if (brand == b) return true;
  }
  return false;
}

Image8 DecodeHeif(const std::string& bytes, const std::string& name, int max_side,
                  HeifImageInfo* info) {
  Context context;
  std::string why;
  const Handle handle = OpenPrimary(bytes, &context, &why);
  if (!handle) throw IoException(name + ": not a decodable HEIF image (" + why + ")");
  const int width = heif_image_handle_get_width(handle.get());
  const int height = heif_image_handle_get_height(handle.get());
  if (width > max_side || height > max_side) {
    throw IoException(name + ": image of " + std::to_string(width) + "x" + std::to_string(height) +
                  " exceeds the limit of " + std::to_string(max_side) + " pixels per side");
  }
  const int bits = heif_image_handle_get_luma_bits_per_pixel(handle.get());
  const bool high = bits > 8;
  heif_image* raw = nullptr;
  // Transformations (irot, imir, clap) are applied: the result is upright.
  const heif_error err =
      heif_decode_image(handle.get(), &raw, heif_colorspace_RGB,
                        high ? heif_chroma_interleaved_RRGGBB_LE : heif_chroma_interleaved_RGB,
                        nullptr);
  if (err.code != heif_error_Ok) {
    throw IoException(name + ": not a decodable HEIF image (" + err.message + ")");
  }
  const std::unique_ptr<heif_image, ImageDeleter> image(raw);
  int stride = 0;
  const uint8_t* plane = heif_image_get_plane_readonly(image.get(), heif_channel_interleaved, &stride);
  const int w = heif_image_get_width(image.get(), heif_channel_interleaved);
  const int h = heif_image_get_height(image.get(), heif_channel_interleaved);
  if (plane == nullptr || w <= 0 || h <= 0) throw IoException(name + ": HEIF image without pixels");
  Image8 out(w, h, 3);
  if (!high) {
    for (int y = 0; y < h; ++y) std::memcpy(&out.at(0, y, 0), plane + static_cast<size_t>(y) * stride, w * 3);
  } else {
    const int range_bits = heif_image_get_bits_per_pixel_range(image.get(), heif_channel_interleaved);
    const double max_value = (1 << (range_bits > 0 ? range_bits : bits)) - 1;
    for (int y = 0; y < h; ++y) {
      const uint8_t* row = plane + static_cast<size_t>(y) * stride;
      for (int i = 0; i < w * 3; ++i) {
        const int v = row[2 * i] | (row[2 * i + 1] << 8);  // Little-endian samples.
        const double scaled = v * 255.0 / max_value + 0.5;
        (&out.at(0, y, 0))[i] = static_cast<uint8_t>(scaled > 255 ? 255 : scaled);
      }
    }
  }
  if (info) info->bits_per_channel = bits > 0 ? bits : 8;
  return out;
}

std::string HeifExifTiff(const std::string& bytes) {
  if (!LooksLikeHeif(bytes)) return "";
  Context context;
  std::string why;
  const Handle handle = OpenPrimary(bytes, &context, &why);
  if (!handle) return "";
  heif_item_id id = 0;
  if (heif_image_handle_get_list_of_metadata_block_IDs(handle.get(), "Exif", &id, 1) < 1) return "";
  const size_t size = heif_image_handle_get_metadata_size(handle.get(), id);
  if (size < 4) return "";
  std::string block(size, '\0');
  if (heif_image_handle_get_metadata(handle.get(), id, block.data()).code != heif_error_Ok) return "";
  // HEIF's Exif item: a 4-byte big-endian offset to the TIFF header, then the data
  // (usually "Exif\0\0" and the TIFF header).
  const uint32_t offset = (static_cast<uint8_t>(block[0]) << 24) | (static_cast<uint8_t>(block[1]) << 16) |
                          (static_cast<uint8_t>(block[2]) << 8) | static_cast<uint8_t>(block[3]);
  if (size < 12 || offset > size - 12) return "";
  return block.substr(4 + offset);
}

}  // namespace casual3d::io

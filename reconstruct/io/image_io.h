#pragma once

// Reading photos (JPEG, PNG, TIFF and whatever else OpenCV's imgcodecs decodes,
// and HEIF/HEIC through heif_io.h) into casual3d::Image8, and writing JPEG and PNG. Pixels are RGB (not OpenCV's BGR).
// Every write is atomic (temporary file, then rename). Failures throw IoException
// naming the file: "photos/IMG_7.jpg: not a decodable image".

#include <cstdint>
#include <string>

#include "format/image.h"
#include "reconstruct/io/file_util.h"

namespace casual3d::io {

struct ReadImageOptions {
  // Rotate/flip the pixels as the EXIF Orientation tag says. Off by default:
  // COLMAP and the rest of the pipeline see the pixels as stored.
  bool apply_exif_orientation = false;
  // Decoded width/height limit in pixels (each side); larger images are refused
  // rather than exhausting memory.
  int max_side = 32768;
  // > 0: a JPEG may be decoded at 1/2, 1/4 or 1/8 of its size (libjpeg's DCT
  // scaling: a fraction of the memory and time of a full decode) as long as the
  // result keeps at least this many pixels. 0: always full size.
  int64_t min_decoded_pixels = 0;  // Range >= 0.
};

// What DecodeImage found besides the pixels.
struct DecodedImageInfo {
  std::string format;      // "jpeg", "png", "tiff", "heif" or "other".
  int full_width = 0;      // Size of the stored image at full resolution, upright
  int full_height = 0;     // (after any orientation applied), pixels.
  int reduction = 1;       // The decoder scaled each side by 1/reduction (1, 2, 4, 8).
};

// Reads an image file as 8-bit RGB (3 channels); grey images are expanded to
// RGB, alpha is dropped, 16-bit images are scaled to 8 bits.
Image8 ReadImage(const std::string& path, const ReadImageOptions& options = {},
                 DecodedImageInfo* info = nullptr);

// Decodes image bytes (any imgcodecs format, or HEIF) as ReadImage does; `name`
// is used in error messages. A JPEG whose data stops before its end-of-image
// marker is refused as truncated (libjpeg would fill the rest with grey).
Image8 DecodeImage(const std::string& bytes, const std::string& name,
                   const ReadImageOptions& options = {}, DecodedImageInfo* info = nullptr);

// Whether JPEG bytes hold a complete image: the segments and the entropy-coded
// scans run up to an end-of-image marker. False for truncated files or non-JPEG data.
bool JpegIsComplete(const std::string& bytes);

// The stored (not oriented) size of a JPEG from its frame header; false if
// there is none before the data ends.
bool JpegSize(const std::string& bytes, int* width, int* height);

struct JpegOptions {
  int quality = 95;  // libjpeg quality, 1..100.
  bool Check(std::string* why) const;
};

// Encodes an RGB (3 channels) or grey (1 channel) 8-bit view as JPEG.
std::string EncodeJpeg(const ImageView<const uint8_t>& image, const JpegOptions& options = {});
// Writes a JPEG file atomically. Throws IoException (bad options, bad channel count,
// or the write failed).
void WriteJpeg(const std::string& path, const ImageView<const uint8_t>& image,
               const JpegOptions& options = {});

inline void WriteJpeg(const std::string& path, const Image8& image, const JpegOptions& options = {}) {
  WriteJpeg(path, image.view(), options);
}

// Writes an 8-bit PNG (1, 3 = RGB or 4 = RGBA channels) atomically, lossless.
void WritePng(const std::string& path, const ImageView<const uint8_t>& image);
inline void WritePng(const std::string& path, const Image8& image) { WritePng(path, image.view()); }

}  // namespace casual3d::io

#pragma once

// Reading photos (JPEG, PNG and whatever else OpenCV's imgcodecs decodes) into
// casual3d::Image8, and writing JPEG and PNG. Pixels are RGB (not OpenCV's BGR).
// Every write is atomic (temporary file, then rename). Failures throw IoError
// naming the file: "photos/IMG_7.jpg: not a decodable image".

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
};

// Reads an image file as 8-bit RGB (3 channels); grey images are expanded to
// RGB, alpha is dropped, 16-bit images are scaled to 8 bits.
Image8 ReadImage(const std::string& path, const ReadImageOptions& options = {});

// Decodes image bytes (any imgcodecs format) as ReadImage does; `name` is used in
// error messages.
Image8 DecodeImage(const std::string& bytes, const std::string& name,
                   const ReadImageOptions& options = {});

struct JpegOptions {
  int quality = 95;  // libjpeg quality, 1..100.
  bool Check(std::string* why) const;
};

// Encodes an RGB (3 channels) or grey (1 channel) 8-bit view as JPEG.
std::string EncodeJpeg(const ImageView<const uint8_t>& image, const JpegOptions& options = {});
// Writes a JPEG file atomically. Throws IoError (bad options, bad channel count,
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

#pragma once

// Float OpenEXR images with named channels, through base/exr_file.h: depth
// maps ("Z"), ground-truth panoramas ("front.R", ..., "back.Z"), and any
// other multi-channel float data. Pixels are interleaved in casual3d::ImageF in
// the order of the channel names given. Writes are atomic (temporary file, then
// rename); failures throw IoException naming the file.
//
// Note: OpenEXR stores channels sorted by name; ReadExr returns them in that
// (file) order, ReadExrChannels in the order asked for.

#include <string>
#include <vector>

#include "base/exr_file.h"
#include "format/image.h"
#include "reconstruct/io/file_util.h"

namespace casual3d::io {

using base::ExrCompression;
using base::ExrPixelType;  // kFloat or kHalf here.

struct ExrWriteOptions {
  ExrCompression compression = ExrCompression::kZip;  // Lossless in all cases.
  // kHalf stores 16-bit floats (smaller, about 3 significant digits; +inf and
  // NaN survive); kFloat stores the values exactly.
  ExrPixelType pixel_type = ExrPixelType::kFloat;
  // If not empty, the stored type of each channel (overrides pixel_type); must
  // have one entry per channel.
  std::vector<ExrPixelType> channel_types;
  int num_threads = 0;  // Compression threads; 0: OpenEXR's global default.
};

struct ExrImage {
  std::vector<std::string> channels;  // Channel names, in the order of `pixels`' channels.
  ImageF pixels;                      // width x height x channels.size().
};

// Limit on each side of an image that the readers accept.
constexpr int kMaxExrSide = 65536;

// Writes `pixels` with one named channel per image channel. Throws IoException if
// the names are empty, duplicated or fewer/more than the channels, or the
// write fails; `path` is then left untouched.
void WriteExr(const std::string& path, const ImageView<const float>& pixels,
              const std::vector<std::string>& channel_names, const ExrWriteOptions& options = {});

inline void WriteExr(const std::string& path, const ImageF& pixels,
                     const std::vector<std::string>& channel_names,
                     const ExrWriteOptions& options = {}) {
  WriteExr(path, pixels.view(), channel_names, options);
}

// Reads every channel (converted to float) in the file's order.
ExrImage ReadExr(const std::string& path);

// Reads the named channels, in the order given (converted to float). Throws
// IoException naming the first missing channel.
ImageF ReadExrChannels(const std::string& path, const std::vector<std::string>& channel_names);

// The channel names stored in the file (sorted, as OpenEXR keeps them).
std::vector<std::string> ReadExrChannelNames(const std::string& path);

}  // namespace casual3d::io

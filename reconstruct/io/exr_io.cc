#include "reconstruct/io/exr_io.h"

#include <algorithm>
#include <vector>

namespace casual3d::io {
namespace {

base::ExrReader Open(const std::string& path) {
  StatusOr<base::ExrReader> in = base::ExrReader::Open(path);
  ThrowIfError(in.status());
  if (in->width() > kMaxExrSide || in->height() > kMaxExrSide) {
    throw IoException(path + ": OpenEXR data window of " + std::to_string(in->width()) + "x" +
                      std::to_string(in->height()) + " exceeds " + std::to_string(kMaxExrSide) +
                      " pixels per side");
  }
  return std::move(*in);
}

ImageF ReadInto(base::ExrReader& in, const std::vector<std::string>& names) {
  const int nc = static_cast<int>(names.size());
  const int w = static_cast<int>(in.width()), h = static_cast<int>(in.height());
  ImageF pixels(w, h, std::max(nc, 1));
  if (nc == 0) return pixels;
  std::vector<base::ExrSlice> slices;
  for (int c = 0; c < nc; ++c) {
    slices.push_back({names[c], base::ExrPixelType::kFloat,
                      reinterpret_cast<char*>(pixels.data() + c), sizeof(float) * nc,
                      sizeof(float) * nc * w});
  }
  ThrowIfError(in.ReadRows(0, h, slices));
  return pixels;
}

}  // namespace

void WriteExr(const std::string& path, const ImageView<const float>& pixels,
              const std::vector<std::string>& channel_names, const ExrWriteOptions& options) {
  if (pixels.empty()) throw IoException(path + ": cannot write an empty OpenEXR image");
  if (static_cast<int>(channel_names.size()) != pixels.channels()) {
    throw IoException(path + ": " + std::to_string(channel_names.size()) +
                      " channel names for an image of " + std::to_string(pixels.channels()) +
                      " channels");
  }
  if (!options.channel_types.empty() && options.channel_types.size() != channel_names.size()) {
    throw IoException(path + ": " + std::to_string(options.channel_types.size()) +
                      " channel types for " + std::to_string(channel_names.size()) + " channels");
  }
  for (ExrPixelType type : options.channel_types)
    if (type == ExrPixelType::kUint)
      throw IoException(path + ": float images store no UINT channels");
  if (options.pixel_type == ExrPixelType::kUint)
    throw IoException(path + ": float images store no UINT channels");
  base::ExrHeader header;
  header.width = pixels.width();
  header.height = pixels.height();
  header.compression = options.compression;
  std::vector<base::ExrSlice> slices;
  const size_t x_stride = sizeof(float) * pixels.channels();
  const size_t y_stride = sizeof(float) * static_cast<size_t>(pixels.stride());
  char* data = reinterpret_cast<char*>(const_cast<float*>(pixels.data()));
  for (size_t c = 0; c < channel_names.size(); ++c) {
    header.channels.push_back({channel_names[c], options.channel_types.empty()
                                                     ? options.pixel_type
                                                     : options.channel_types[c]});
    slices.push_back({channel_names[c], base::ExrPixelType::kFloat, data + c * sizeof(float),
                      x_stride, y_stride});
  }
  StatusOr<base::ExrWriter> out = base::ExrWriter::Create(path, header, options.num_threads);
  ThrowIfError(out.status());
  ThrowIfError(out->WriteRows(pixels.height(), slices));
  ThrowIfError(out->Commit());
}

std::vector<std::string> ReadExrChannelNames(const std::string& path) {
  base::ExrReader in = Open(path);
  std::vector<std::string> names;
  for (const base::ExrChannel& c : in.channels()) names.push_back(c.name);
  return names;
}

ExrImage ReadExr(const std::string& path) {
  base::ExrReader in = Open(path);
  ExrImage result;
  for (const base::ExrChannel& c : in.channels()) result.channels.push_back(c.name);
  if (result.channels.empty()) throw IoException(path + ": OpenEXR file has no channels");
  result.pixels = ReadInto(in, result.channels);
  return result;
}

ImageF ReadExrChannels(const std::string& path, const std::vector<std::string>& channel_names) {
  if (channel_names.empty()) throw IoException(path + ": no OpenEXR channels requested");
  base::ExrReader in = Open(path);
  return ReadInto(in, channel_names);
}

}  // namespace casual3d::io

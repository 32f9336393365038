#include "reconstruct/io/exr_io.h"

#include <algorithm>
#include <cstdio>
#include <memory>
#include <set>
#include <vector>

#include <OpenEXR/ImfChannelList.h>
#include <OpenEXR/ImfFrameBuffer.h>
#include <OpenEXR/ImfHeader.h>
#include <OpenEXR/ImfInputFile.h>
#include <OpenEXR/ImfOutputFile.h>
#include <OpenEXR/ImfThreading.h>
#include <Imath/ImathBox.h>
#include <Imath/half.h>

namespace casual3d::io {
namespace {

Imf::Compression ToImf(ExrCompression c) {
  switch (c) {
    case ExrCompression::kNone:
      return Imf::NO_COMPRESSION;
    case ExrCompression::kZip:
      return Imf::ZIP_COMPRESSION;
    case ExrCompression::kPiz:
      return Imf::PIZ_COMPRESSION;
  }
  return Imf::ZIP_COMPRESSION;
}

struct OpenedInput {
  std::unique_ptr<Imf::InputFile> file;
  int width = 0;
  int height = 0;
  int min_x = 0;
  int min_y = 0;
};

OpenedInput Open(const std::string& path) {
  OpenedInput in;
  std::FILE* probe = std::fopen(path.c_str(), "rb");
  if (probe == nullptr) throw IoError(path + ": cannot open (no such file or not readable)");
  std::fclose(probe);
  try {
    in.file = std::make_unique<Imf::InputFile>(path.c_str());
  } catch (const std::exception& e) {
    throw IoError(path + ": not a readable OpenEXR file (" + e.what() + ")");
  }
  const Imath::Box2i dw = in.file->header().dataWindow();
  const long w = static_cast<long>(dw.max.x) - dw.min.x + 1;
  const long h = static_cast<long>(dw.max.y) - dw.min.y + 1;
  if (w <= 0 || h <= 0 || w > kMaxExrSide || h > kMaxExrSide) {
    throw IoError(path + ": OpenEXR data window of " + std::to_string(w) + "x" +
                  std::to_string(h) + " is empty or exceeds " + std::to_string(kMaxExrSide) +
                  " pixels per side");
  }
  in.width = static_cast<int>(w);
  in.height = static_cast<int>(h);
  in.min_x = dw.min.x;
  in.min_y = dw.min.y;
  return in;
}

ImageF ReadInto(OpenedInput& in, const std::string& path, const std::vector<std::string>& names) {
  const Imf::ChannelList& list = in.file->header().channels();
  for (const std::string& n : names) {
    const Imf::Channel* ch = list.findChannel(n);
    if (ch == nullptr) throw IoError(path + ": OpenEXR channel '" + n + "' is missing");
    if (ch->xSampling != 1 || ch->ySampling != 1) {
      throw IoError(path + ": OpenEXR channel '" + n + "' is subsampled (unsupported)");
    }
  }
  const int nc = static_cast<int>(names.size());
  ImageF pixels(in.width, in.height, std::max(nc, 1));
  if (nc == 0) return pixels;
  const size_t x_stride = sizeof(float) * nc;
  const size_t y_stride = x_stride * in.width;
  // The frame buffer's base points at the (virtual) pixel (0, 0) of the data window's frame.
  char* base = reinterpret_cast<char*>(pixels.data()) -
               static_cast<ptrdiff_t>(in.min_x) * static_cast<ptrdiff_t>(x_stride) -
               static_cast<ptrdiff_t>(in.min_y) * static_cast<ptrdiff_t>(y_stride);
  Imf::FrameBuffer fb;
  for (int c = 0; c < nc; ++c) {
    fb.insert(names[c], Imf::Slice(Imf::FLOAT, base + c * sizeof(float), x_stride, y_stride));
  }
  try {
    in.file->setFrameBuffer(fb);
    in.file->readPixels(in.min_y, in.min_y + in.height - 1);
  } catch (const std::exception& e) {
    throw IoError(path + ": corrupt OpenEXR pixel data (" + e.what() + ")");
  }
  return pixels;
}

}  // namespace

void WriteExr(const std::string& path, const ImageView<const float>& pixels,
              const std::vector<std::string>& channel_names, const ExrWriteOptions& options) {
  if (pixels.empty()) throw IoError(path + ": cannot write an empty OpenEXR image");
  if (static_cast<int>(channel_names.size()) != pixels.channels()) {
    throw IoError(path + ": " + std::to_string(channel_names.size()) +
                  " channel names for an image of " + std::to_string(pixels.channels()) +
                  " channels");
  }
  std::set<std::string> unique;
  for (const std::string& n : channel_names) {
    if (n.empty() || !unique.insert(n).second) {
      throw IoError(path + ": OpenEXR channel name '" + n + "' is empty or repeated");
    }
  }
  Imf::Header header(pixels.width(), pixels.height());
  header.compression() = ToImf(options.compression);
  if (!options.channel_types.empty() && options.channel_types.size() != channel_names.size()) {
    throw IoError(path + ": " + std::to_string(options.channel_types.size()) +
                  " channel types for " + std::to_string(channel_names.size()) + " channels");
  }
  for (size_t c = 0; c < channel_names.size(); ++c) {
    const ExrPixelType type =
        options.channel_types.empty() ? options.pixel_type : options.channel_types[c];
    header.channels().insert(channel_names[c],
                             Imf::Channel(type == ExrPixelType::kHalf ? Imf::HALF : Imf::FLOAT));
  }

  const size_t x_stride = sizeof(float) * pixels.channels();
  const size_t y_stride = sizeof(float) * static_cast<size_t>(pixels.stride());
  char* base = reinterpret_cast<char*>(const_cast<float*>(pixels.data()));
  Imf::FrameBuffer fb;
  // OpenEXR does not convert float to half on output: half channels are
  // converted here into their own planes.
  std::vector<std::vector<Imath::half>> half_planes;
  const size_t w = pixels.width(), h = pixels.height();
  for (int c = 0; c < pixels.channels(); ++c) {
    const ExrPixelType type =
        options.channel_types.empty() ? options.pixel_type : options.channel_types[c];
    if (type == ExrPixelType::kHalf) {
      std::vector<Imath::half>& plane = half_planes.emplace_back(w * h);
      for (size_t y = 0; y < h; ++y)
        for (size_t x = 0; x < w; ++x) plane[y * w + x] = Imath::half(pixels.at(x, y, c));
      fb.insert(channel_names[c], Imf::Slice(Imf::HALF, reinterpret_cast<char*>(plane.data()),
                                             sizeof(Imath::half), sizeof(Imath::half) * w));
    } else {
      fb.insert(channel_names[c],
                Imf::Slice(Imf::FLOAT, base + c * sizeof(float), x_stride, y_stride));
    }
  }
  const std::string tmp = TemporaryPathFor(path);
  try {
    const int threads = options.num_threads > 0 ? options.num_threads : Imf::globalThreadCount();
    Imf::OutputFile out(tmp.c_str(), header, threads);
    out.setFrameBuffer(fb);
    out.writePixels(pixels.height());
  } catch (const std::exception& e) {
    std::remove(tmp.c_str());
    throw IoError(path + ": cannot write OpenEXR (" + e.what() + ")");
  }
  CommitTemporary(tmp, path);
}

std::vector<std::string> ReadExrChannelNames(const std::string& path) {
  OpenedInput in = Open(path);
  std::vector<std::string> names;
  const Imf::ChannelList& list = in.file->header().channels();
  for (auto it = list.begin(); it != list.end(); ++it) names.emplace_back(it.name());
  return names;
}

ExrImage ReadExr(const std::string& path) {
  OpenedInput in = Open(path);
  ExrImage result;
  const Imf::ChannelList& list = in.file->header().channels();
  for (auto it = list.begin(); it != list.end(); ++it) result.channels.emplace_back(it.name());
  if (result.channels.empty()) throw IoError(path + ": OpenEXR file has no channels");
  result.pixels = ReadInto(in, path, result.channels);
  return result;
}

ImageF ReadExrChannels(const std::string& path, const std::vector<std::string>& channel_names) {
  if (channel_names.empty()) throw IoError(path + ": no OpenEXR channels requested");
  OpenedInput in = Open(path);
  return ReadInto(in, path, channel_names);
}

}  // namespace casual3d::io

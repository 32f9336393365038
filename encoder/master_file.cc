#include "encoder/master_file.h"

#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cstdint>
#include <exception>
#include <filesystem>
#include <system_error>
#include <thread>
#include <vector>

#include <Imath/ImathMatrix.h>
#include <Imath/ImathVec.h>
#include <OpenEXR/ImfChannelList.h>
#include <OpenEXR/ImfFrameBuffer.h>
#include <OpenEXR/ImfHeader.h>
#include <OpenEXR/ImfInputFile.h>
#include <OpenEXR/ImfMatrixAttribute.h>
#include <OpenEXR/ImfOutputFile.h>
#include <OpenEXR/ImfStringAttribute.h>
#include <OpenEXR/ImfTestFile.h>
#include <OpenEXR/ImfVecAttribute.h>

namespace casual3d::encoder {
namespace {

constexpr const char* kFormatName = "casual3d-master";
constexpr int kVersionMajor = 1;
constexpr int kVersionMinor = 0;
// Rows converted per strip: bounds the temporary buffers to a few MB.
constexpr int kStripRows = 64;

const char* const kLayerPrefix[kNumLayers] = {"front.", "back."};

// Byte-valued fields of LayerData stored as UINT channels, with their maxima.
struct ByteChannel {
  const char* name;
  int component;  // Component within an interleaved array (rgb), else 0.
  int stride;     // Components per pixel of the array.
  uint32_t max_value;
};
const ByteChannel kByteChannels[] = {
    {"present", 0, 1, 1}, {"R", 0, 3, 255}, {"G", 1, 3, 255},
    {"B", 2, 3, 255},     {"label", 0, 1, 1}, {"links", 0, 1, 255},
};
constexpr int kNumByteChannels = sizeof(kByteChannels) / sizeof(kByteChannels[0]);

struct FloatChannel {
  const char* name;
  int component;
  int stride;
};
const FloatChannel kFloatChannels[] = {
    {"Z", 0, 1}, {"N.X", 0, 3}, {"N.Y", 1, 3}, {"N.Z", 2, 3}};
constexpr int kNumFloatChannels = sizeof(kFloatChannels) / sizeof(kFloatChannels[0]);

NodeArray<uint8_t>& ByteArray(LayerData& layer, int channel) {
  switch (channel) {
    case 0: return layer.present;
    case 1: case 2: case 3: return layer.rgb;
    case 4: return layer.label;
    default: return layer.links;
  }
}
const NodeArray<uint8_t>& ByteArray(const LayerData& layer, int channel) {
  return ByteArray(const_cast<LayerData&>(layer), channel);
}
NodeArray<float>& FloatArray(LayerData& layer, int channel) {
  return channel == 0 ? layer.depth_m : layer.normal;
}

// OpenEXR (de)compresses blocks of scanlines on this many threads.
int NumThreads() { return static_cast<int>(std::max(1u, std::thread::hardware_concurrency())); }

std::string TempPathFor(const std::string& path) {
  static std::atomic<int> counter{0};
  return path + ".tmp-" + std::to_string(::getpid()) + "-" + std::to_string(counter++);
}

void WriteExr(const TwoLayerPanorama& pano, const std::string& path) {
  const int w = pano.width(), h = pano.height();
  Imf::Header header(w, h);
  header.compression() = Imf::ZIP_COMPRESSION;
  header.insert("casual3d.format", Imf::StringAttribute(kFormatName));
  header.insert("casual3d.version",
                Imf::StringAttribute(std::to_string(kVersionMajor) + "." +
                                     std::to_string(kVersionMinor)));
  const PanoramaFrame& f = pano.frame();
  header.insert("casual3d.centre",
                Imf::V3dAttribute(Imath::V3d(f.centre[0], f.centre[1], f.centre[2])));
  const double* r = f.rotation;
  header.insert("casual3d.rotation", Imf::M33dAttribute(Imath::M33d(
                                         r[0], r[1], r[2], r[3], r[4], r[5], r[6], r[7], r[8])));
  if (pano.view_hints())
    header.insert("casual3d.view", Imf::StringAttribute(SerializeViewHints(*pano.view_hints())));
  for (int l = 0; l < kNumLayers; ++l) {
    for (const ByteChannel& c : kByteChannels)
      header.channels().insert(std::string(kLayerPrefix[l]) + c.name, Imf::Channel(Imf::UINT));
    for (const FloatChannel& c : kFloatChannels)
      header.channels().insert(std::string(kLayerPrefix[l]) + c.name, Imf::Channel(Imf::FLOAT));
  }
  Imf::OutputFile file(path.c_str(), header, NumThreads());

  // UINT channels need 32-bit source data: convert one strip at a time.
  const size_t strip_pixels = static_cast<size_t>(w) * kStripRows;
  std::vector<uint32_t> words(strip_pixels * kNumLayers * kNumByteChannels);
  for (int y0 = 0; y0 < h; y0 += kStripRows) {
    const int rows = std::min(kStripRows, h - y0);
    Imf::FrameBuffer fb;
    for (int l = 0; l < kNumLayers; ++l) {
      const LayerData& layer = pano.layer(l);
      for (int c = 0; c < kNumByteChannels; ++c) {
        const ByteChannel& bc = kByteChannels[c];
        uint32_t* dst = words.data() + (l * kNumByteChannels + c) * strip_pixels;
        const uint8_t* src = ByteArray(layer, c).data();
        const size_t first = static_cast<size_t>(y0) * w;
        for (size_t i = 0; i < static_cast<size_t>(rows) * w; ++i)
          dst[i] = src[(first + i) * bc.stride + bc.component];
        // OpenEXR addresses base + x * xStride + y * yStride with absolute y.
        char* base = reinterpret_cast<char*>(dst) -
                     static_cast<ptrdiff_t>(y0) * w * static_cast<ptrdiff_t>(sizeof(uint32_t));
        fb.insert(std::string(kLayerPrefix[l]) + bc.name,
                  Imf::Slice(Imf::UINT, base, sizeof(uint32_t), sizeof(uint32_t) * w));
      }
      for (const FloatChannel& fc : kFloatChannels) {
        const float* src = (fc.stride == 1 ? layer.depth_m : layer.normal).data() + fc.component;
        fb.insert(std::string(kLayerPrefix[l]) + fc.name,
                  Imf::Slice(Imf::FLOAT, reinterpret_cast<char*>(const_cast<float*>(src)),
                             sizeof(float) * fc.stride, sizeof(float) * fc.stride * w));
      }
    }
    file.setFrameBuffer(fb);
    file.writePixels(rows);
  }
}

// Parses "major.minor"; false if malformed.
bool ParseVersion(const std::string& s, int* major, int* minor) {
  const size_t dot = s.find('.');
  if (dot == std::string::npos || dot == 0 || dot + 1 == s.size() || s.size() > 12) return false;
  for (size_t i = 0; i < s.size(); ++i)
    if (i != dot && (s[i] < '0' || s[i] > '9')) return false;
  *major = std::stoi(s.substr(0, dot));
  *minor = std::stoi(s.substr(dot + 1));
  return true;
}

StatusOr<TwoLayerPanorama> ReadExr(const std::string& path) {
  Imf::InputFile file(path.c_str(), NumThreads());
  const Imf::Header& header = file.header();
  const auto* format = header.findTypedAttribute<Imf::StringAttribute>("casual3d.format");
  if (format == nullptr || format->value() != kFormatName)
    return InvalidData(path + ": an OpenEXR file but not a casual3d master file (attribute "
                       "casual3d.format is missing or not \"casual3d-master\")");
  const auto* version = header.findTypedAttribute<Imf::StringAttribute>("casual3d.version");
  int major = 0, minor = 0;
  if (version == nullptr || !ParseVersion(version->value(), &major, &minor))
    return InvalidData(path + ": attribute casual3d.version is missing or not \"major.minor\"");
  if (major != kVersionMajor)
    return UnsupportedVersion(path + ": master file version " + version->value() +
                              " is not supported (this build reads 1.x)");

  const Imath::Box2i dw = header.dataWindow();
  const int64_t w64 = static_cast<int64_t>(dw.max.x) - dw.min.x + 1;
  const int64_t h64 = static_cast<int64_t>(dw.max.y) - dw.min.y + 1;
  if (dw.min.x != 0 || dw.min.y != 0 || w64 <= 0 || h64 <= 0)
    return InvalidData(path + ": the data window must start at (0,0) and be non-empty");
  if (w64 > kMaxMasterWidth || h64 > kMaxMasterHeight)
    return LimitExceeded(path + ": " + std::to_string(w64) + "x" + std::to_string(h64) +
                         " exceeds the master file limit of " + std::to_string(kMaxMasterWidth) +
                         "x" + std::to_string(kMaxMasterHeight));
  const int w = static_cast<int>(w64), h = static_cast<int>(h64);

  for (int l = 0; l < kNumLayers; ++l) {
    for (const ByteChannel& c : kByteChannels) {
      const std::string name = std::string(kLayerPrefix[l]) + c.name;
      const Imf::Channel* ch = header.channels().findChannel(name);
      if (ch == nullptr || ch->type != Imf::UINT || ch->xSampling != 1 || ch->ySampling != 1)
        return InvalidData(path + ": channel " + name + " is missing or not full-resolution UINT");
    }
    for (const FloatChannel& c : kFloatChannels) {
      const std::string name = std::string(kLayerPrefix[l]) + c.name;
      const Imf::Channel* ch = header.channels().findChannel(name);
      if (ch == nullptr || ch->type != Imf::FLOAT || ch->xSampling != 1 || ch->ySampling != 1)
        return InvalidData(path + ": channel " + name +
                           " is missing or not full-resolution FLOAT");
    }
  }

  TwoLayerPanorama pano(w, h);
  PanoramaFrame& frame = pano.frame();
  if (const auto* a = header.findTypedAttribute<Imf::V3dAttribute>("casual3d.centre")) {
    frame.centre[0] = a->value().x;
    frame.centre[1] = a->value().y;
    frame.centre[2] = a->value().z;
  } else {
    return InvalidData(path + ": attribute casual3d.centre (v3d) is missing");
  }
  if (const auto* a = header.findTypedAttribute<Imf::M33dAttribute>("casual3d.rotation")) {
    for (int i = 0; i < 9; ++i) frame.rotation[i] = a->value()[i / 3][i % 3];
  } else {
    return InvalidData(path + ": attribute casual3d.rotation (m33d) is missing");
  }
  if (const auto* a = header.findTypedAttribute<Imf::StringAttribute>("casual3d.view")) {
    StatusOr<ViewHints> hints = ParseViewHints(a->value());
    if (!hints.ok())
      return InvalidData(path + ": attribute casual3d.view: " + hints.status().message());
    pano.view_hints() = *hints;
  }

  const size_t strip_pixels = static_cast<size_t>(w) * kStripRows;
  std::vector<uint32_t> words(strip_pixels * kNumLayers * kNumByteChannels);
  for (int y0 = 0; y0 < h; y0 += kStripRows) {
    const int rows = std::min(kStripRows, h - y0);
    Imf::FrameBuffer fb;
    for (int l = 0; l < kNumLayers; ++l) {
      LayerData& layer = pano.layer(l);
      for (int c = 0; c < kNumByteChannels; ++c) {
        uint32_t* dst = words.data() + (l * kNumByteChannels + c) * strip_pixels;
        char* base = reinterpret_cast<char*>(dst) -
                     static_cast<ptrdiff_t>(y0) * w * static_cast<ptrdiff_t>(sizeof(uint32_t));
        fb.insert(std::string(kLayerPrefix[l]) + kByteChannels[c].name,
                  Imf::Slice(Imf::UINT, base, sizeof(uint32_t), sizeof(uint32_t) * w));
      }
      for (int c = 0; c < kNumFloatChannels; ++c) {
        const FloatChannel& fc = kFloatChannels[c];
        float* dst = FloatArray(layer, c).data() + fc.component;
        fb.insert(std::string(kLayerPrefix[l]) + fc.name,
                  Imf::Slice(Imf::FLOAT, reinterpret_cast<char*>(dst), sizeof(float) * fc.stride,
                             sizeof(float) * fc.stride * w));
      }
    }
    file.setFrameBuffer(fb);
    file.readPixels(y0, y0 + rows - 1);
    for (int l = 0; l < kNumLayers; ++l) {
      LayerData& layer = pano.layer(l);
      for (int c = 0; c < kNumByteChannels; ++c) {
        const ByteChannel& bc = kByteChannels[c];
        const uint32_t* src = words.data() + (l * kNumByteChannels + c) * strip_pixels;
        uint8_t* dst = ByteArray(layer, c).data();
        const size_t first = static_cast<size_t>(y0) * w;
        for (size_t i = 0; i < static_cast<size_t>(rows) * w; ++i) {
          if (src[i] > bc.max_value) {
            const size_t p = first + i;
            return InvalidData(path + ": channel " + kLayerPrefix[l] + bc.name + " at pixel (" +
                               std::to_string(p % w) + ", " + std::to_string(p / w) +
                               ") holds " + std::to_string(src[i]) + ", above its maximum " +
                               std::to_string(bc.max_value));
          }
          dst[(first + i) * bc.stride + bc.component] = static_cast<uint8_t>(src[i]);
        }
      }
    }
  }
  Status valid = pano.Validate();
  if (!valid.ok()) return InvalidData(path + ": " + valid.message());
  return pano;
}

}  // namespace

Status WriteMasterFile(const TwoLayerPanorama& pano, const std::string& path) {
  Status valid = pano.Validate();
  if (!valid.ok())
    return InvalidArgument("refusing to write " + path + ": the panorama is invalid: " +
                           valid.message());
  const std::string tmp = TempPathFor(path);
  try {
    WriteExr(pano, tmp);
  } catch (const std::exception& e) {
    std::error_code ignored;
    std::filesystem::remove(tmp, ignored);
    return IoError(path + ": cannot write the master file: " + e.what());
  }
  std::error_code ec;
  std::filesystem::rename(tmp, path, ec);
  if (ec) {
    std::error_code ignored;
    std::filesystem::remove(tmp, ignored);
    return IoError(path + ": cannot move the finished master file into place: " + ec.message());
  }
  return Status::Ok();
}

StatusOr<TwoLayerPanorama> ReadMasterFile(const std::string& path) {
  std::error_code ec;
  if (!std::filesystem::exists(path, ec))
    return NotFound(path + ": no such master file");
  try {
    if (!Imf::isOpenExrFile(path.c_str()))
      return InvalidData(path + ": not an OpenEXR file");
    return ReadExr(path);
  } catch (const std::exception& e) {
    return InvalidData(path + ": cannot read the master file: " + e.what());
  }
}

}  // namespace casual3d::encoder

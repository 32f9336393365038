#include "encoder/master_file.h"

#include <algorithm>
#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "base/exr_file.h"
#include "base/parallel_for.h"

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
int NumThreads() { return base::ResolveThreads(0); }

std::string ChannelName(int layer, const char* name) {
  return std::string(kLayerPrefix[layer]) + name;
}

base::ExrHeader MasterHeader(const TwoLayerPanorama& pano) {
  base::ExrHeader header;
  header.width = pano.width();
  header.height = pano.height();
  header.compression = base::ExrCompression::kZip;
  header.string_attributes = {
      {"casual3d.format", kFormatName},
      {"casual3d.version", std::to_string(kVersionMajor) + "." + std::to_string(kVersionMinor)}};
  if (pano.view_hints())
    header.string_attributes.emplace_back("casual3d.view", SerializeViewHints(*pano.view_hints()));
  const PanoramaFrame& f = pano.frame();
  header.v3d_attributes = {{"casual3d.centre", {f.centre[0], f.centre[1], f.centre[2]}}};
  std::array<double, 9> rotation;
  std::copy(f.rotation, f.rotation + 9, rotation.begin());
  header.m33d_attributes = {{"casual3d.rotation", rotation}};
  for (int l = 0; l < kNumLayers; ++l) {
    for (const ByteChannel& c : kByteChannels)
      header.channels.push_back({ChannelName(l, c.name), base::ExrPixelType::kUint});
    for (const FloatChannel& c : kFloatChannels)
      header.channels.push_back({ChannelName(l, c.name), base::ExrPixelType::kFloat});
  }
  return header;
}

// The slices of a strip of `rows` rows from row y0: the byte-valued channels
// as 32-bit words in `words` (UINT channels need them), the float channels
// straight from the layers' arrays.
std::vector<base::ExrSlice> StripSlices(const TwoLayerPanorama& pano, int y0,
                                        std::vector<uint32_t>& words) {
  const int w = pano.width();
  const size_t strip_pixels = static_cast<size_t>(w) * kStripRows;
  std::vector<base::ExrSlice> slices;
  for (int l = 0; l < kNumLayers; ++l) {
    for (int c = 0; c < kNumByteChannels; ++c) {
      uint32_t* dst = words.data() + (l * kNumByteChannels + c) * strip_pixels;
      slices.push_back({ChannelName(l, kByteChannels[c].name), base::ExrPixelType::kUint,
                        reinterpret_cast<char*>(dst), sizeof(uint32_t), sizeof(uint32_t) * w});
    }
    for (int c = 0; c < kNumFloatChannels; ++c) {
      const FloatChannel& fc = kFloatChannels[c];
      const float* src = FloatArray(const_cast<LayerData&>(pano.layer(l)), c).data() +
                         static_cast<size_t>(y0) * w * fc.stride + fc.component;
      slices.push_back({ChannelName(l, fc.name), base::ExrPixelType::kFloat,
                        reinterpret_cast<char*>(const_cast<float*>(src)), sizeof(float) * fc.stride,
                        sizeof(float) * fc.stride * w});
    }
  }
  return slices;
}

Status WriteExr(const TwoLayerPanorama& pano, const std::string& path) {
  const int w = pano.width(), h = pano.height();
  CASUAL3D_ASSIGN_OR_RETURN(base::ExrWriter file,
                            base::ExrWriter::Create(path, MasterHeader(pano), NumThreads()));
  // UINT channels need 32-bit source data: convert one strip at a time.
  const size_t strip_pixels = static_cast<size_t>(w) * kStripRows;
  std::vector<uint32_t> words(strip_pixels * kNumLayers * kNumByteChannels);
  for (int y0 = 0; y0 < h; y0 += kStripRows) {
    const int rows = std::min(kStripRows, h - y0);
    for (int l = 0; l < kNumLayers; ++l) {
      const LayerData& layer = pano.layer(l);
      for (int c = 0; c < kNumByteChannels; ++c) {
        const ByteChannel& bc = kByteChannels[c];
        uint32_t* dst = words.data() + (l * kNumByteChannels + c) * strip_pixels;
        const uint8_t* src = ByteArray(layer, c).data();
        const size_t first = static_cast<size_t>(y0) * w;
        for (size_t i = 0; i < static_cast<size_t>(rows) * w; ++i)
          dst[i] = src[(first + i) * bc.stride + bc.component];
      }
    }
    CASUAL3D_RETURN_IF_ERROR(file.WriteRows(rows, StripSlices(pano, y0, words)));
  }
  return file.Commit();
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

StatusOr<TwoLayerPanorama> ReadExr(base::ExrReader& file, const std::string& path) {
  const std::optional<std::string> format = file.StringAttribute("casual3d.format");
  if (!format || *format != kFormatName)
    return InvalidData(path + ": an OpenEXR file but not a casual3d master file (attribute "
                       "casual3d.format is missing or not \"casual3d-master\")");
  const std::optional<std::string> version = file.StringAttribute("casual3d.version");
  int major = 0, minor = 0;
  if (!version || !ParseVersion(*version, &major, &minor))
    return InvalidData(path + ": attribute casual3d.version is missing or not \"major.minor\"");
  if (major != kVersionMajor)
    return UnsupportedVersion(path + ": master file version " + *version +
                              " is not supported (this build reads 1.x)");

  const int64_t w64 = file.width(), h64 = file.height();
  if (file.min_x() != 0 || file.min_y() != 0)
    return InvalidData(path + ": the data window must start at (0,0) and be non-empty");
  if (w64 > kMaxMasterWidth || h64 > kMaxMasterHeight)
    return LimitExceeded(path + ": " + std::to_string(w64) + "x" + std::to_string(h64) +
                         " exceeds the master file limit of " + std::to_string(kMaxMasterWidth) +
                         "x" + std::to_string(kMaxMasterHeight));
  const int w = static_cast<int>(w64), h = static_cast<int>(h64);

  for (int l = 0; l < kNumLayers; ++l) {
    for (const ByteChannel& c : kByteChannels) {
      const std::string name = ChannelName(l, c.name);
      const base::ExrChannel* ch = file.FindChannel(name);
      if (ch == nullptr || ch->type != base::ExrPixelType::kUint || !ch->full_resolution)
        return InvalidData(path + ": channel " + name + " is missing or not full-resolution UINT");
    }
    for (const FloatChannel& c : kFloatChannels) {
      const std::string name = ChannelName(l, c.name);
      const base::ExrChannel* ch = file.FindChannel(name);
      if (ch == nullptr || ch->type != base::ExrPixelType::kFloat || !ch->full_resolution)
        return InvalidData(path + ": channel " + name +
                           " is missing or not full-resolution FLOAT");
    }
  }

  TwoLayerPanorama pano(w, h);
  PanoramaFrame& frame = pano.frame();
  const std::optional<std::array<double, 3>> centre = file.V3dAttribute("casual3d.centre");
  if (!centre) return InvalidData(path + ": attribute casual3d.centre (v3d) is missing");
  std::copy(centre->begin(), centre->end(), frame.centre);
  const std::optional<std::array<double, 9>> rotation = file.M33dAttribute("casual3d.rotation");
  if (!rotation) return InvalidData(path + ": attribute casual3d.rotation (m33d) is missing");
  std::copy(rotation->begin(), rotation->end(), frame.rotation);
  if (const std::optional<std::string> view = file.StringAttribute("casual3d.view")) {
    StatusOr<ViewHints> hints = ParseViewHints(*view);
    if (!hints.ok())
      return InvalidData(path + ": attribute casual3d.view: " + hints.status().message());
    pano.view_hints() = *hints;
  }

  const size_t strip_pixels = static_cast<size_t>(w) * kStripRows;
  std::vector<uint32_t> words(strip_pixels * kNumLayers * kNumByteChannels);
  for (int y0 = 0; y0 < h; y0 += kStripRows) {
    const int rows = std::min(kStripRows, h - y0);
    CASUAL3D_RETURN_IF_ERROR(file.ReadRows(y0, rows, StripSlices(pano, y0, words)));
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
  return WriteExr(pano, path);
}

StatusOr<TwoLayerPanorama> ReadMasterFile(const std::string& path) {
  StatusOr<base::ExrReader> file = base::ExrReader::Open(path, NumThreads());
  if (!file.ok()) {
    if (file.status().code() == StatusCode::kNotFound)
      return NotFound(path + ": no such master file");
    return file.status();
  }
  return ReadExr(*file, path);
}

}  // namespace casual3d::encoder

#include "reconstruct/io/image_io.h"

#include <cstring>
#include <vector>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "reconstruct/io/cv_bridge.h"
#include "reconstruct/io/heif_io.h"

namespace casual3d::io {
namespace {

// Converts 1-, 3- or 4-channel 8-bit RGB(A) to what imencode expects (grey, BGR, BGRA).
cv::Mat ToEncoderLayout(const ImageView<const uint8_t>& image, const std::string& name) {
  if (image.empty()) throw IoException(name + ": cannot write an empty image");
  const cv::Mat mat = ToMat(image);
  cv::Mat out;
  switch (image.channels()) {
    case 1:
      return mat;
    case 3:
      cv::cvtColor(mat, out, cv::COLOR_RGB2BGR);
      return out;
    case 4:
      cv::cvtColor(mat, out, cv::COLOR_RGBA2BGRA);
      return out;
    default:
      throw IoException(name + ": cannot write an image with " + std::to_string(image.channels()) +
                    " channels (expected 1, 3 or 4)");
  }
}

std::string Encode(const cv::Mat& mat, const char* ext, const std::vector<int>& params,
                   const std::string& name) {
  std::vector<uchar> buffer;
  bool ok = false;
  try {
    ok = cv::imencode(ext, mat, buffer, params);
  } catch (const cv::Exception& e) {
    throw IoException(name + ": cannot encode (" + e.what() + ")");
  }
  if (!ok) throw IoException(name + ": cannot encode");
  return std::string(buffer.begin(), buffer.end());
}

}  // namespace

bool JpegIsComplete(const std::string& bytes) {
  const auto* b = reinterpret_cast<const uint8_t*>(bytes.data());
  const size_t n = bytes.size();
  if (n < 4 || b[0] != 0xFF || b[1] != 0xD8) return false;
  size_t p = 2;
  while (p + 2 <= n) {
    if (b[p] != 0xFF) return false;  // Not at a marker: corrupt.
    const uint8_t m = b[p + 1];
    if (m == 0xFF) {  // Fill byte before a marker.
      ++p;
      continue;
    }
    if (m == 0xD9) return true;  // End of image.
    if (m == 0x01 || (m >= 0xD0 && m <= 0xD7)) {  // Markers without a length.
      p += 2;
      continue;
    }
    if (p + 4 > n) return false;
    const size_t length = (static_cast<size_t>(b[p + 2]) << 8) | b[p + 3];
    if (length < 2 || p + 2 + length > n) return false;
    p += 2 + length;
    if (m != 0xDA) continue;
    // Entropy-coded data after a start of scan: runs to the next marker other
    // than a stuffed 0xFF00 or a restart marker.
    while (p + 1 < n) {
      const void* ff = std::memchr(b + p, 0xFF, n - p - 1);
      if (ff == nullptr) return false;
      p = static_cast<const uint8_t*>(ff) - b;
      const uint8_t next = b[p + 1];
      if (next == 0x00 || (next >= 0xD0 && next <= 0xD7)) {
        p += 2;
      } else if (next == 0xFF) {
        ++p;
      } else {
        break;
      }
    }
  }
  return false;
}

bool JpegSize(const std::string& bytes, int* width, int* height) {
  const auto* b = reinterpret_cast<const uint8_t*>(bytes.data());
  const size_t n = bytes.size();
  if (n < 4 || b[0] != 0xFF || b[1] != 0xD8) return false;
  size_t p = 2;
  while (p + 4 <= n && b[p] == 0xFF) {
    const uint8_t m = b[p + 1];
    if (m == 0xFF) {
      ++p;
      continue;
    }
    const size_t length = (static_cast<size_t>(b[p + 2]) << 8) | b[p + 3];
    const bool sof = m >= 0xC0 && m <= 0xCF && m != 0xC4 && m != 0xC8 && m != 0xCC;
    if (sof && length >= 7 && p + 9 <= n) {
      *height = (b[p + 5] << 8) | b[p + 6];
      *width = (b[p + 7] << 8) | b[p + 8];
      return *width > 0 && *height > 0;
    }
    if (m == 0xDA || length < 2) return false;
    p += 2 + length;
  }
  return false;
}

Image8 DecodeImage(const std::string& bytes, const std::string& name,
                   const ReadImageOptions& options, DecodedImageInfo* info) {
  if (bytes.empty()) throw IoException(name + ": not a decodable image (empty file)");
  DecodedImageInfo found;
  if (LooksLikeHeif(bytes)) {
    Image8 image = DecodeHeif(bytes, name, options.max_side);
    if (info) *info = {"heif", image.width(), image.height(), 1};
    return image;
  }
  int flags = cv::IMREAD_COLOR;  // 8-bit, 3 channels (BGR), grey and CMYK converted, 16 bits scaled.
  int stored_width = 0, stored_height = 0;
  const bool jpeg = JpegSize(bytes, &stored_width, &stored_height);
  if (jpeg) {
    found.format = "jpeg";
    if (!JpegIsComplete(bytes)) {
      throw IoException(name + ": truncated JPEG (the data ends before the end-of-image marker)");
    }
    const int64_t pixels = static_cast<int64_t>(stored_width) * stored_height;
    if (options.min_decoded_pixels > 0) {
      for (int r : {8, 4, 2}) {
        if (pixels / (static_cast<int64_t>(r) * r) >= options.min_decoded_pixels) {
          found.reduction = r;
          break;
        }
      }
    }
    if (found.reduction == 2) flags = cv::IMREAD_REDUCED_COLOR_2;
    if (found.reduction == 4) flags = cv::IMREAD_REDUCED_COLOR_4;
    if (found.reduction == 8) flags = cv::IMREAD_REDUCED_COLOR_8;
  } else if (bytes.compare(0, 8, "\x89PNG\r\n\x1a\n", 8) == 0) {
    found.format = "png";
  } else if (bytes.compare(0, 4, "II*\0", 4) == 0 || bytes.compare(0, 4, "MM\0*", 4) == 0) {
    found.format = "tiff";
  } else {
    found.format = "other";
  }
  if (!options.apply_exif_orientation) flags |= cv::IMREAD_IGNORE_ORIENTATION;
  const cv::Mat buffer(1, static_cast<int>(bytes.size()), CV_8UC1,
                       const_cast<char*>(bytes.data()));
  cv::Mat decoded;
  try {
    decoded = cv::imdecode(buffer, flags);
  } catch (const cv::Exception&) {
    decoded.release();
  }
  if (decoded.empty() || decoded.type() != CV_8UC3) {
    throw IoException(name + ": not a decodable image");
  }
  if (decoded.cols > options.max_side || decoded.rows > options.max_side) {
    throw IoException(name + ": image of " + std::to_string(decoded.cols) + "x" +
                  std::to_string(decoded.rows) + " exceeds the limit of " +
                  std::to_string(options.max_side) + " pixels per side");
  }
  if (jpeg) {
    // The orientation may have turned the image a quarter: match the sides.
    const bool turned = (decoded.cols > decoded.rows) != (stored_width > stored_height);
    found.full_width = turned ? stored_height : stored_width;
    found.full_height = turned ? stored_width : stored_height;
  } else {
    found.full_width = decoded.cols;
    found.full_height = decoded.rows;
  }
  Image8 image(decoded.cols, decoded.rows, 3);
  cv::Mat rgb = ToMat(image);
  cv::cvtColor(decoded, rgb, cv::COLOR_BGR2RGB);  // Writes into `image` (same size and type).
  if (info) *info = found;
  return image;
}

Image8 ReadImage(const std::string& path, const ReadImageOptions& options,
                 DecodedImageInfo* info) {
  return DecodeImage(ReadFile(path), path, options, info);
}

bool JpegOptions::Check(std::string* why) const {
  if (quality < 1 || quality > 100) {
    if (why) *why = "JPEG quality " + std::to_string(quality) + " is outside 1..100";
    return false;
  }
  return true;
}

std::string EncodeJpeg(const ImageView<const uint8_t>& image, const JpegOptions& options) {
  std::string why;
  if (!options.Check(&why)) throw IoException(why);
  if (image.channels() != 1 && image.channels() != 3) {
    throw IoException("JPEG needs 1 or 3 channels, got " + std::to_string(image.channels()));
  }
  // Baseline, no chroma subsampling change: libjpeg's output is a pure function
  // of the pixels and the quality, so captures are reproducible byte for byte.
  return Encode(ToEncoderLayout(image, "JPEG"), ".jpg",
                {cv::IMWRITE_JPEG_QUALITY, options.quality}, "JPEG");
}

void WriteJpeg(const std::string& path, const ImageView<const uint8_t>& image,
               const JpegOptions& options) {
  std::string why;
  if (!options.Check(&why)) throw IoException(path + ": " + why);
  if (image.channels() != 1 && image.channels() != 3) {
    throw IoException(path + ": JPEG needs 1 or 3 channels, got " +
                  std::to_string(image.channels()));
  }
  WriteFileAtomic(path, Encode(ToEncoderLayout(image, path), ".jpg",
                               {cv::IMWRITE_JPEG_QUALITY, options.quality}, path));
}

void WritePng(const std::string& path, const ImageView<const uint8_t>& image) {
  WriteFileAtomic(path, Encode(ToEncoderLayout(image, path), ".png",
                               {cv::IMWRITE_PNG_COMPRESSION, 6}, path));
}

}  // namespace casual3d::io

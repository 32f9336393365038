#include "reconstruct/io/image_io.h"

#include <vector>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "reconstruct/io/cv_bridge.h"

namespace casual3d::io {
namespace {

// Converts 1-, 3- or 4-channel 8-bit RGB(A) to what imencode expects (grey, BGR, BGRA).
cv::Mat ToEncoderLayout(const ImageView<const uint8_t>& image, const std::string& name) {
  if (image.empty()) throw IoError(name + ": cannot write an empty image");
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
      throw IoError(name + ": cannot write an image with " + std::to_string(image.channels()) +
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
    throw IoError(name + ": cannot encode (" + e.what() + ")");
  }
  if (!ok) throw IoError(name + ": cannot encode");
  return std::string(buffer.begin(), buffer.end());
}

}  // namespace

Image8 DecodeImage(const std::string& bytes, const std::string& name,
                   const ReadImageOptions& options) {
  if (bytes.empty()) throw IoError(name + ": not a decodable image (empty file)");
  const cv::Mat buffer(1, static_cast<int>(bytes.size()), CV_8UC1,
                       const_cast<char*>(bytes.data()));
  int flags = cv::IMREAD_COLOR;  // 8-bit, 3 channels (BGR), grey expanded.
  if (!options.apply_exif_orientation) flags |= cv::IMREAD_IGNORE_ORIENTATION;
  cv::Mat decoded;
  try {
    decoded = cv::imdecode(buffer, flags);
  } catch (const cv::Exception&) {
    decoded.release();
  }
  if (decoded.empty() || decoded.type() != CV_8UC3) {
    throw IoError(name + ": not a decodable image");
  }
  if (decoded.cols > options.max_side || decoded.rows > options.max_side) {
    throw IoError(name + ": image of " + std::to_string(decoded.cols) + "x" +
                  std::to_string(decoded.rows) + " exceeds the limit of " +
                  std::to_string(options.max_side) + " pixels per side");
  }
  Image8 image(decoded.cols, decoded.rows, 3);
  cv::Mat rgb = ToMat(image);
  cv::cvtColor(decoded, rgb, cv::COLOR_BGR2RGB);  // Writes into `image` (same size and type).
  return image;
}

Image8 ReadImage(const std::string& path, const ReadImageOptions& options) {
  return DecodeImage(ReadFile(path), path, options);
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
  if (!options.Check(&why)) throw IoError(why);
  if (image.channels() != 1 && image.channels() != 3) {
    throw IoError("JPEG needs 1 or 3 channels, got " + std::to_string(image.channels()));
  }
  // Baseline, no chroma subsampling change: libjpeg's output is a pure function
  // of the pixels and the quality, so captures are reproducible byte for byte.
  return Encode(ToEncoderLayout(image, "JPEG"), ".jpg",
                {cv::IMWRITE_JPEG_QUALITY, options.quality}, "JPEG");
}

void WriteJpeg(const std::string& path, const ImageView<const uint8_t>& image,
               const JpegOptions& options) {
  std::string why;
  if (!options.Check(&why)) throw IoError(path + ": " + why);
  if (image.channels() != 1 && image.channels() != 3) {
    throw IoError(path + ": JPEG needs 1 or 3 channels, got " +
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

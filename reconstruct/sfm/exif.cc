#include "reconstruct/sfm/exif.h"

#include <libexif/exif-data.h>
#include <libexif/exif-loader.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <utility>

#include "reconstruct/io/file_util.h"
#include "reconstruct/io/heif_io.h"

namespace casual3d::sfm {
namespace {

struct ExifDataDeleter {
  void operator()(ExifData* d) const { exif_data_unref(d); }
};

std::string Trim(std::string s) {
  const auto not_space = [](unsigned char c) { return !std::isspace(c) && c != 0; };
  s.erase(s.begin(), std::find_if(s.begin(), s.end(), not_space));
  s.erase(std::find_if(s.rbegin(), s.rend(), not_space).base(), s.end());
  return s;
}

ExifEntry* Find(ExifData* data, ExifTag tag) {
  for (int ifd = 0; ifd < EXIF_IFD_COUNT; ++ifd) {
    if (ExifEntry* e = exif_content_get_entry(data->ifd[ifd], tag)) return e;
  }
  return nullptr;
}

std::string AsciiValue(ExifData* data, ExifTag tag) {
  ExifEntry* e = Find(data, tag);
  if (e == nullptr || e->format != EXIF_FORMAT_ASCII || e->data == nullptr) return "";
  return Trim(std::string(reinterpret_cast<const char*>(e->data), e->size));
}

// First component of a SHORT, LONG or RATIONAL entry as a double; 0 if absent.
double NumberValue(ExifData* data, ExifTag tag) {
  ExifEntry* e = Find(data, tag);
  if (e == nullptr || e->data == nullptr || e->components < 1) return 0.0;
  const ExifByteOrder order = exif_data_get_byte_order(data);
  switch (e->format) {
    case EXIF_FORMAT_SHORT:
      if (e->size < 2) return 0.0;
      return exif_get_short(e->data, order);
    case EXIF_FORMAT_LONG:
      if (e->size < 4) return 0.0;
      return exif_get_long(e->data, order);
    case EXIF_FORMAT_RATIONAL: {
      if (e->size < 8) return 0.0;
      const ExifRational r = exif_get_rational(e->data, order);
      return r.denominator == 0 ? 0.0 : static_cast<double>(r.numerator) / r.denominator;
    }
    default:
      return 0.0;
  }
}

ExifInfo FromExifData(std::unique_ptr<ExifData, ExifDataDeleter> data) {
  ExifInfo info;
  if (!data) return info;
  info.present = true;
  const double orientation = NumberValue(data.get(), EXIF_TAG_ORIENTATION);
  if (orientation >= 1 && orientation <= 8) info.orientation = static_cast<int>(orientation);
  info.focal_mm = NumberValue(data.get(), EXIF_TAG_FOCAL_LENGTH);
  info.focal_35mm = NumberValue(data.get(), EXIF_TAG_FOCAL_LENGTH_IN_35MM_FILM);
  info.pixel_width = static_cast<int>(NumberValue(data.get(), EXIF_TAG_PIXEL_X_DIMENSION));
  const double fp_res = NumberValue(data.get(), EXIF_TAG_FOCAL_PLANE_X_RESOLUTION);
  const double fp_unit = NumberValue(data.get(), EXIF_TAG_FOCAL_PLANE_RESOLUTION_UNIT);
  // Resolution unit: 2 = inch (the default), 3 = centimetre, 4 = millimetre.
  double mm_per_unit = 25.4;
  if (fp_unit == 3) mm_per_unit = 10.0;
  if (fp_unit == 4) mm_per_unit = 1.0;
  if (fp_res > 0) info.focal_plane_px_per_mm = fp_res / mm_per_unit;
  info.make = AsciiValue(data.get(), EXIF_TAG_MAKE);
  info.model = AsciiValue(data.get(), EXIF_TAG_MODEL);
  if (!std::isfinite(info.focal_mm) || info.focal_mm < 0) info.focal_mm = 0;
  if (!std::isfinite(info.focal_35mm) || info.focal_35mm < 0) info.focal_35mm = 0;
  return info;
}

}  // namespace

ExifInfo ReadExif(const std::string& path) {
  std::string bytes;
  try {
    bytes = io::ReadFile(path);
  } catch (const std::exception&) {
    return {};
  }
  return ExifFromFileBytes(bytes);
}

ExifInfo ExifFromFileBytes(const std::string& bytes) {
  std::string exif = bytes;
  if (io::LooksLikeHeif(bytes)) {
    const std::string tiff = io::HeifExifTiff(bytes);
    if (tiff.empty()) return {};
    exif = std::string("Exif\0\0", 6) + tiff;  // The header exif_data_load_data looks for.
    return FromExifData(std::unique_ptr<ExifData, ExifDataDeleter>(exif_data_new_from_data(
        reinterpret_cast<const unsigned char*>(exif.data()), static_cast<unsigned int>(exif.size()))));
  }
  if (exif.empty()) return {};
  // The loader (as exif_data_new_from_file uses) yields no data when the bytes
  // hold no EXIF block, unlike exif_data_new_from_data.
  ExifLoader* loader = exif_loader_new();
  if (loader == nullptr) return {};
  exif_loader_write(loader, reinterpret_cast<unsigned char*>(exif.data()),
                    static_cast<unsigned int>(exif.size()));
  std::unique_ptr<ExifData, ExifDataDeleter> data(exif_loader_get_data(loader));
  exif_loader_unref(loader);
  return FromExifData(std::move(data));
}

double FocalPixelsFromExif(const ExifInfo& exif, int width, int height, int original_long_side) {
  if (width <= 0 || height <= 0) return 0.0;
  if (exif.focal_35mm > 0) {
    // The 35 mm equivalent keeps the diagonal field of view of a 36x24 mm frame.
    const double diagonal_px = std::hypot(width, height);
    return exif.focal_35mm * diagonal_px / std::hypot(36.0, 24.0);
  }
  if (exif.focal_mm > 0 && exif.focal_plane_px_per_mm > 0 && original_long_side > 0) {
    const double scale = static_cast<double>(std::max(width, height)) / original_long_side;
    return exif.focal_mm * exif.focal_plane_px_per_mm * scale;
  }
  return 0.0;
}

}  // namespace casual3d::sfm

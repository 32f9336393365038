#include "reconstruct/io/jpeg_exif.h"

#include <cmath>
#include <cstdint>
#include <stdexcept>
#include <vector>

namespace casual3d::io {
namespace {

// TIFF types.
constexpr uint16_t kAscii = 2, kShort = 3, kLong = 4, kRational = 5;

struct Entry {
  uint16_t tag;
  uint16_t type;
  uint32_t count;
  std::vector<uint8_t> data;  // Little-endian payload.
};

void Put16(std::vector<uint8_t>* b, uint16_t v) {
  b->push_back(v & 0xFF);
  b->push_back(v >> 8);
}
void Put32(std::vector<uint8_t>* b, uint32_t v) {
  for (int i = 0; i < 4; ++i) b->push_back((v >> (8 * i)) & 0xFF);
}

Entry Ascii(uint16_t tag, const std::string& s) {
  Entry e{tag, kAscii, static_cast<uint32_t>(s.size() + 1), {}};
  e.data.assign(s.begin(), s.end());
  e.data.push_back(0);
  return e;
}
Entry Rational(uint16_t tag, double value) {
  // Three decimals are plenty for focal lengths and resolutions.
  Entry e{tag, kRational, 1, {}};
  Put32(&e.data, static_cast<uint32_t>(std::llround(value * 1000.0)));
  Put32(&e.data, 1000);
  return e;
}
Entry Short(uint16_t tag, uint16_t value) {
  Entry e{tag, kShort, 1, {}};
  Put16(&e.data, value);
  Put16(&e.data, 0);
  return e;
}
Entry Long(uint16_t tag, uint32_t value) {
  Entry e{tag, kLong, 1, {}};
  Put32(&e.data, value);
  return e;
}

// Writes an IFD at `offset` (from the TIFF header) with its out-of-line data
// right after it; returns the bytes. Entries must be sorted by tag.
std::vector<uint8_t> WriteIfd(const std::vector<Entry>& entries, uint32_t offset) {
  std::vector<uint8_t> ifd, extra;
  const uint32_t data_start = offset + 2 + 12 * static_cast<uint32_t>(entries.size()) + 4;
  Put16(&ifd, static_cast<uint16_t>(entries.size()));
  for (const Entry& e : entries) {
    Put16(&ifd, e.tag);
    Put16(&ifd, e.type);
    Put32(&ifd, e.count);
    if (e.data.size() <= 4) {
      std::vector<uint8_t> inline_value = e.data;
      inline_value.resize(4, 0);
      ifd.insert(ifd.end(), inline_value.begin(), inline_value.end());
    } else {
      Put32(&ifd, data_start + static_cast<uint32_t>(extra.size()));
      extra.insert(extra.end(), e.data.begin(), e.data.end());
      if (extra.size() % 2) extra.push_back(0);  // Word alignment.
    }
  }
  Put32(&ifd, 0);  // No next IFD.
  ifd.insert(ifd.end(), extra.begin(), extra.end());
  return ifd;
}

}  // namespace

std::string InsertExif(const std::string& jpeg, const ExifFields& fields) {
  if (jpeg.size() < 4 || static_cast<uint8_t>(jpeg[0]) != 0xFF ||
      static_cast<uint8_t>(jpeg[1]) != 0xD8) {
    throw std::invalid_argument("InsertExif: not JPEG data (no SOI marker)");
  }
  if (fields.make.size() > 255 || fields.model.size() > 255) {
    throw std::invalid_argument("InsertExif: make and model must be at most 255 characters");
  }
  std::vector<Entry> exif_entries;
  if (fields.focal_mm > 0) exif_entries.push_back(Rational(0x920A, fields.focal_mm));
  if (fields.focal_plane_px_per_mm > 0) {
    exif_entries.push_back(Rational(0xA20E, fields.focal_plane_px_per_mm * 10.0));
    exif_entries.push_back(Rational(0xA20F, fields.focal_plane_px_per_mm * 10.0));
    exif_entries.push_back(Short(0xA210, 3));  // Centimetres.
  }
  std::vector<Entry> ifd0;
  if (!fields.make.empty()) ifd0.push_back(Ascii(0x010F, fields.make));
  if (!fields.model.empty()) ifd0.push_back(Ascii(0x0110, fields.model));
  // IFD0 size is known before its pointer value is, so compute it with a placeholder.
  std::vector<Entry> ifd0_with_pointer = ifd0;
  if (!exif_entries.empty()) ifd0_with_pointer.push_back(Long(0x8769, 0));
  const uint32_t ifd0_offset = 8;
  const uint32_t exif_offset =
      ifd0_offset + static_cast<uint32_t>(WriteIfd(ifd0_with_pointer, ifd0_offset).size());
  if (!exif_entries.empty()) ifd0_with_pointer.back() = Long(0x8769, exif_offset);

  std::vector<uint8_t> tiff = {'I', 'I', 0x2A, 0x00};
  Put32(&tiff, ifd0_offset);
  const std::vector<uint8_t> ifd0_bytes = WriteIfd(ifd0_with_pointer, ifd0_offset);
  tiff.insert(tiff.end(), ifd0_bytes.begin(), ifd0_bytes.end());
  if (!exif_entries.empty()) {
    const std::vector<uint8_t> exif_bytes = WriteIfd(exif_entries, exif_offset);
    tiff.insert(tiff.end(), exif_bytes.begin(), exif_bytes.end());
  }
  const size_t segment_length = 2 + 6 + tiff.size();
  if (segment_length > 0xFFFF) throw std::invalid_argument("InsertExif: EXIF block too large");

  std::string out = jpeg.substr(0, 2);
  out += static_cast<char>(0xFF);
  out += static_cast<char>(0xE1);
  out += static_cast<char>(segment_length >> 8);
  out += static_cast<char>(segment_length & 0xFF);
  out.append("Exif\0\0", 6);
  out.append(reinterpret_cast<const char*>(tiff.data()), tiff.size());
  // Copy the rest, dropping existing EXIF APP1 segments among the leading markers.
  size_t pos = 2;
  while (pos + 4 <= jpeg.size() && static_cast<uint8_t>(jpeg[pos]) == 0xFF) {
    const uint8_t marker = static_cast<uint8_t>(jpeg[pos + 1]);
    if (marker < 0xE0 || marker > 0xEF) break;  // Only APPn segments are skipped over.
    const size_t len = (static_cast<uint8_t>(jpeg[pos + 2]) << 8) | static_cast<uint8_t>(jpeg[pos + 3]);
    if (len < 2 || pos + 2 + len > jpeg.size()) break;
    const bool is_exif = marker == 0xE1 && len >= 8 && jpeg.compare(pos + 4, 6, std::string("Exif\0\0", 6)) == 0;
    if (!is_exif) out.append(jpeg, pos, 2 + len);
    pos += 2 + len;
  }
  out.append(jpeg, pos, std::string::npos);
  return out;
}

}  // namespace casual3d::io

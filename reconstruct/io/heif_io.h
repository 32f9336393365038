#pragma once

// HEIF/HEIC photos (the default format of iPhones) through libheif: decoding
// the primary image to 8-bit RGB and reading its Exif metadata block.
// Orientation: HEIF stores it as transformative properties (irot, imir) that
// libheif applies while decoding, so the decoded pixels are upright; the Exif
// Orientation tag inside a HEIF is informative only (ISO/IEC 23008-12) and is
// not applied again.

#include <string>

#include "format/image.h"

namespace casual3d::io {

// True if `bytes` start with an ISO base media "ftyp" box of a HEIF brand
// (heic, heix, heim, heis, hevc, hevx, mif1, msf1).
bool LooksLikeHeif(const std::string& bytes);

struct HeifImageInfo {
  int bits_per_channel = 8;  // Of the stored image (8, 10 or 12).
};

// Decodes the primary image of a HEIF file as upright 8-bit RGB; images with
// more than 8 bits per channel are scaled (value * 255 / (2^bits - 1), rounded).
// Throws IoException naming `name` for undecodable data or an image larger than
// `max_side` pixels per side.
Image8 DecodeHeif(const std::string& bytes, const std::string& name, int max_side,
                  HeifImageInfo* info = nullptr);

// The primary image's first Exif metadata block as a TIFF structure (starting
// with "II" or "MM"), the 4-byte offset header of HEIF's Exif item removed;
// empty if there is none or the data is not a readable HEIF.
std::string HeifExifTiff(const std::string& bytes);

}  // namespace casual3d::io

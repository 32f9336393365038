#pragma once

// Writing a minimal EXIF block (APP1) into JPEG bytes, as cameras do: make,
// model, focal length and focal-plane resolution, so that tools reading the
// photos (the sparse stage, COLMAP) find the focal length in pixels. Used for
// synthetic captures, whose photos would otherwise carry no calibration hint.

#include <string>

namespace casual3d::io {

struct ExifFields {
  std::string make;                    // Tag 0x010F; empty: omitted.
  std::string model;                   // Tag 0x0110; empty: omitted.
  double focal_mm = 0.0;               // FocalLength (0x920A); > 0 to write.
  // Sensor pixels per millimetre; written as FocalPlaneX/YResolution (0xA20E,
  // 0xA20F) in pixels per centimetre with FocalPlaneResolutionUnit 3. > 0 to write.
  double focal_plane_px_per_mm = 0.0;
};

// Returns `jpeg` with an EXIF APP1 segment inserted right after the SOI marker
// (any existing APP1 EXIF segment is dropped). Throws std::invalid_argument if
// `jpeg` does not start with a JPEG SOI marker or a string is too long.
std::string InsertExif(const std::string& jpeg, const ExifFields& fields);

}  // namespace casual3d::io

#pragma once

// The EXIF fields the sparse stage needs from a photo: orientation, focal
// length (mm and 35 mm equivalent), focal-plane resolution, make and model.
// Read with libexif from JPEG files and from the Exif block of HEIF files;
// files without EXIF (PNG, TIFF, stripped JPEG) give empty fields.

#include <string>

namespace casual3d::sfm {

struct ExifInfo {
  bool present = false;      // The file has an EXIF block.
  int orientation = 1;       // EXIF orientation 1..8 (1 = upright).
  double focal_mm = 0.0;     // FocalLength; 0 if absent.
  double focal_35mm = 0.0;   // FocalLengthIn35mmFilm; 0 if absent.
  // FocalPlaneX/YResolution in pixels per millimetre of sensor, for the
  // sensor's own (stored, unrotated) pixel grid; 0 if absent.
  double focal_plane_px_per_mm = 0.0;
  int pixel_width = 0;       // PixelXDimension of the stored image; 0 if absent.
  std::string make;          // Trimmed; empty if absent.
  std::string model;         // Trimmed; empty if absent.
};

// Reads the EXIF block of `path`. A file without EXIF, or with a malformed
// EXIF block, yields present = false; never throws for bad bytes.
ExifInfo ReadExif(const std::string& path);

// The same from the bytes of a whole file (JPEG or HEIF).
ExifInfo ExifFromFileBytes(const std::string& bytes);

// The focal length in pixels for an image of `width` x `height` pixels (after
// the orientation has been applied and after any resizing, so pass the working
// size) from EXIF: the 35 mm equivalent (defined on the 43.27 mm diagonal of a
// 36x24 mm frame), else focal_mm with the focal-plane resolution, else 0 (no
// prior). `original_long_side` is the long side of the stored photo in pixels,
// used to rescale the focal-plane resolution.
double FocalPixelsFromExif(const ExifInfo& exif, int width, int height, int original_long_side);

}  // namespace casual3d::sfm

#pragma once

// Photo import for the sparse stage: lists a folder of photos (JPEG, PNG, TIFF,
// HEIF/HEIC), reads their EXIF (orientation, focal length, make and model),
// decodes them upright (large JPEGs at a reduced size straight from the
// decoder), downsamples them to the working resolution (Sec. 4.1: the paper's
// depth maps are about 900x1350) and writes them for COLMAP, together with the
// focal-length prior at the working size and the grouping into cameras (one
// shared calibration per device, upright size and focal length: portrait and
// landscape photos, or photos of different sizes from one phone, get one each).
//
// Bad files among good ones: unreadable, truncated and undecodable files, and
// files with the same bytes as an earlier one (by name order), are skipped and
// listed; the import goes on while at least min_photos usable photos remain.

#include <functional>
#include <string>
#include <vector>

#include "format/status.h"
#include "reconstruct/sfm/exif.h"
#include "reconstruct/util/options_fields.h"

namespace casual3d::sfm {

struct PhotoImportOptions {
  // Working resolution in megapixels; larger photos are downsampled (area
  // filter) to about this many pixels, smaller ones are kept as they are.
  double working_megapixels = 1.2;  // Range [0.05, 100]. Sec. 4.1: ~900x1350.
  // Unreadable, truncated or corrupt photos: skip them with a warning (true) or
  // stop with an error naming them (false). Duplicates are always skipped.
  bool skip_unreadable = true;
  // Photos from different devices (EXIF make or model differ): use one
  // calibration per device (true) or stop with an error listing them.
  bool allow_mixed_devices = false;
  // Focal length prior in pixels at the photos' original size; overrides EXIF
  // (needed for photos without EXIF). 0: from EXIF, or none.
  double focal_px = 0.0;  // Range 0 or [1, 1e6].
  int jpeg_quality = 95;  // Range [50, 100]; quality of the re-encoded photos.
  int min_photos = 3;     // Range [2, 1e6]; fewer photos is an error.

  template <typename Self, typename Visitor>
  static void DescribeFields(Self& o, Visitor& v) {
    using R = util::Rule;
    v.Field("working_megapixels", o.working_megapixels, R::Closed(0.05, 100), "Working resolution, megapixels (Sec. 4.1: ~900x1350)");
    v.Field("skip_unreadable", o.skip_unreadable, R::Any(), "Skip unreadable photos with a warning rather than stop");
    v.Field("allow_mixed_devices", o.allow_mixed_devices, R::Any(), "Allow photos from several devices, one calibration each");
    v.Field("focal_px", o.focal_px, R::ZeroOr(R::Closed(1, 1e6)),
            "Focal length prior at the photos' original size, pixels; 0 = from EXIF");
    v.Field("jpeg_quality", o.jpeg_quality, R::Closed(50, 100), "Quality of the re-encoded photos");
    v.Field("min_photos", o.min_photos, R::Closed(2, 1e6), "Fewer usable photos is an error");
  }
  Status Check() const { return util::CheckFields(*this); }
};

struct ImportedPhoto {
  std::string source;       // File name in the input folder.
  // File name in the output folder: `source` for JPEG and PNG, else
  // `source` + ".jpg" (the photo is written as JPEG).
  std::string name;
  int original_width = 0;   // Upright (after EXIF orientation), pixels.
  int original_height = 0;
  int width = 0;            // Written (working) size, pixels.
  int height = 0;
  double focal_px = 0.0;    // Focal prior at the working size; 0 = none.
  std::string device;       // "make model" or "unknown camera".
  int group = 0;            // Index into PhotoImport::groups.
  ExifInfo exif;
};

// Photos that share one camera calibration in COLMAP.
struct CameraGroup {
  std::string device;
  int width = 0;
  int height = 0;
  double focal_px = 0.0;  // Prior at the working size; 0 = none (COLMAP's default).
  std::vector<int> photos;  // Indices into PhotoImport::photos.
};

// A file of the input folder that was left out.
struct SkippedPhoto {
  std::string file;    // File name in the input folder.
  std::string reason;  // "truncated JPEG ...", "same bytes as IMG_3.jpg", ...
};

struct PhotoImport {
  std::vector<ImportedPhoto> photos;  // Sorted by source name.
  std::vector<CameraGroup> groups;
  std::vector<SkippedPhoto> skipped;  // In name order.
};

// True for the file names the stage treats as photos (.jpg, .jpeg, .png, .tif,
// .tiff, .heic, .heif, any case; not hidden files).
bool IsPhotoFileName(const std::string& name);

// Imports every photo of `input_dir` (not recursive) into `output_dir` (must
// exist). `on_photo(done, total)` is called after each photo (may be empty).
// Throws std::runtime_error with one clear line for: a missing input folder,
// fewer than min_photos usable photos (saying how many there are and why the
// others were left out), unreadable photos (naming them) when not skipped,
// mixed devices unless allowed, or a failed write.
PhotoImport ImportPhotos(const std::string& input_dir, const std::string& output_dir,
                         const PhotoImportOptions& options,
                         const std::function<void(int, int)>& on_photo);

}  // namespace casual3d::sfm

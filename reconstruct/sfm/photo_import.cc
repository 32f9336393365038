#include "reconstruct/sfm/photo_import.h"

#include <dirent.h>
#include <sys/stat.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <map>
#include <set>
#include <sstream>
#include <stdexcept>
#include <tuple>
#include <utility>

#include <opencv2/imgproc.hpp>

#include "format/sha256.h"
#include "reconstruct/io/cv_bridge.h"
#include "reconstruct/io/file_util.h"
#include "reconstruct/io/image_io.h"

namespace casual3d::sfm {
namespace {

std::string Lower(std::string s) {
  for (char& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

bool EndsWith(const std::string& s, const std::string& suffix) {
  return s.size() >= suffix.size() && s.compare(s.size() - suffix.size(), suffix.size(), suffix) == 0;
}

std::string DeviceName(const ExifInfo& exif) {
  std::string make = exif.make, model = exif.model;
  // Phones often repeat the make in the model ("Canon" "Canon EOS 5D").
  if (!make.empty() && Lower(model).rfind(Lower(make), 0) == 0) make.clear();
  std::string name = make.empty() ? model : (model.empty() ? make : make + " " + model);
  return name.empty() ? "unknown camera" : name;
}

std::string JoinList(const std::vector<std::string>& items, size_t max_items) {
  std::string out;
  for (size_t i = 0; i < items.size() && i < max_items; ++i) out += (i ? ", " : "") + items[i];
  if (items.size() > max_items) out += ", ... (" + std::to_string(items.size()) + " in all)";
  return out;
}

}  // namespace

bool IsPhotoFileName(const std::string& name) {
  const std::string l = Lower(name);
  return !name.empty() && name[0] != '.' &&
         (EndsWith(l, ".jpg") || EndsWith(l, ".jpeg") || EndsWith(l, ".png") ||
          EndsWith(l, ".tif") || EndsWith(l, ".tiff") || EndsWith(l, ".heic") ||
          EndsWith(l, ".heif"));
}

namespace {

// The photo files of `input_dir` (by extension; regular files only), sorted;
// throws if fewer than options.min_photos.
std::vector<std::string> ListPhotoFiles(const std::string& input_dir, const PhotoImportOptions& options) {
  DIR* dir = ::opendir(input_dir.c_str());
  if (dir == nullptr) {
    throw std::runtime_error(input_dir + ": cannot open the photo folder: " + std::strerror(errno));
  }
  std::vector<std::string> names;
  while (dirent* e = ::readdir(dir)) {
    const std::string name = e->d_name;
    struct stat st;
    if (IsPhotoFileName(name) && ::stat((input_dir + "/" + name).c_str(), &st) == 0 &&
        S_ISREG(st.st_mode)) {
      names.push_back(name);
    }
  }
  ::closedir(dir);
  std::sort(names.begin(), names.end());
  if (static_cast<int>(names.size()) < options.min_photos) {
    throw std::runtime_error(input_dir + ": found " + std::to_string(names.size()) +
                             " photos (.jpg, .jpeg, .png, .tif, .tiff, .heic, .heif); a 3D photo needs at least " +
                             std::to_string(options.min_photos) +
                             " overlapping photos (the paper's captures have 20 to 200)");
  }
  return names;
}

// Writes `image` (decoded from a file of info.full_width x full_height) into
// OUTPUT_DIR at the working size, as PNG if it was one, else as JPEG; sets
// the photo's name and working size.
void WriteWorkingPhoto(Image8 image, const io::DecodedImageInfo& info, const std::string& name,
                       const std::string& output_dir, const PhotoImportOptions& options,
                       ImportedPhoto* photo) {
  const double pixels = static_cast<double>(image.width()) * image.height();
  const double full_pixels = static_cast<double>(info.full_width) * info.full_height;
  const double scale = std::min(1.0, std::sqrt(options.working_megapixels * 1e6 / full_pixels));
  const std::string lower = Lower(name);
  const bool png = EndsWith(lower, ".png");
  const bool keep_name = png || EndsWith(lower, ".jpg") || EndsWith(lower, ".jpeg");
  photo->name = keep_name ? name : name + ".jpg";
  const std::string out_path = output_dir + "/" + photo->name;
  const int target_width = std::max(1, static_cast<int>(std::lround(info.full_width * scale)));
  const int target_height = std::max(1, static_cast<int>(std::lround(info.full_height * scale)));
  if (target_width < image.width() && target_height < image.height() &&
      target_width * static_cast<double>(target_height) < pixels) {
    photo->width = target_width;
    photo->height = target_height;
    Image8 small(photo->width, photo->height, image.channels());
    cv::Mat dst = io::ToMat(small);
    cv::resize(io::ToMat(image), dst, dst.size(), 0, 0, cv::INTER_AREA);
    image = std::move(small);
  } else {
    photo->width = image.width();
    photo->height = image.height();
  }
  if (png) {
    io::WritePng(out_path, std::as_const(image).view());
  } else {
    io::JpegOptions jpeg;
    jpeg.quality = options.jpeg_quality;
    io::WriteJpeg(out_path, std::as_const(image).view(), jpeg);
  }
}

// Imports the photo file `name`: read, checked against the files before it
// (`first_with_hash`: SHA-256 of the bytes -> file name), decoded upright,
// written at the working size, with its device and focal prior. Returns
// false with the reason it was skipped.
bool ImportPhoto(const std::string& input_dir, const std::string& name, const std::string& output_dir,
                 const PhotoImportOptions& options, std::map<std::string, std::string>* first_with_hash,
                 ImportedPhoto* photo, std::string* skipped) {
  const std::string path = input_dir + "/" + name;
  std::string bytes;
  try {
    bytes = io::ReadFile(path);
  } catch (const std::exception& e) {
    *skipped = std::string(e.what()).substr(path.size() + 2);  // The reason after "path: ".
    return false;
  }
  const std::string hash = Sha256Hex(reinterpret_cast<const uint8_t*>(bytes.data()), bytes.size());
  if (!bytes.empty()) {
    const auto [it, fresh] = first_with_hash->emplace(hash, name);
    if (!fresh) {
      *skipped = "same bytes as " + it->second;
      return false;
    }
  }
  photo->source = name;
  photo->exif = ExifFromFileBytes(bytes);
  Image8 image;
  io::DecodedImageInfo info;
  try {
    io::ReadImageOptions read_options;
    read_options.apply_exif_orientation = true;
    // Large JPEGs come out of libjpeg at 1/2..1/8 size, never below the working size.
    read_options.min_decoded_pixels = static_cast<int64_t>(options.working_megapixels * 1e6);
    image = io::DecodeImage(bytes, name, read_options, &info);
  } catch (const std::exception& e) {
    *skipped = std::string(e.what()).substr(name.size() + 2);
    return false;
  }
  bytes.clear();
  bytes.shrink_to_fit();
  photo->original_width = info.full_width;
  photo->original_height = info.full_height;
  WriteWorkingPhoto(std::move(image), info, name, output_dir, options, photo);
  const int long_side = std::max(photo->original_width, photo->original_height);
  if (options.focal_px > 0) {
    // The prior scales with the working size (sizes are rounded per axis;
    // the long side carries the least relative rounding).
    photo->focal_px = options.focal_px * std::max(photo->width, photo->height) / long_side;
  } else {
    photo->focal_px = FocalPixelsFromExif(photo->exif, photo->width, photo->height, long_side);
  }
  photo->device = DeviceName(photo->exif);
  return true;
}

// Throws if unreadable files were skipped and options.skip_unreadable is
// off, or if fewer than options.min_photos photos are usable.
void CheckUsable(const std::string& input_dir, size_t num_files, const PhotoImport& result,
                 const PhotoImportOptions& options) {
  std::vector<std::string> unreadable;
  for (const SkippedPhoto& s : result.skipped) {
    if (s.reason.rfind("same bytes as ", 0) != 0) unreadable.push_back(s.file + ": " + s.reason);
  }
  if (!unreadable.empty() && !options.skip_unreadable) {
    throw std::runtime_error(input_dir + ": " + JoinList(unreadable, 5) +
                             "; remove or replace the file, or drop --strict-photos");
  }
  if (static_cast<int>(result.photos.size()) < options.min_photos) {
    std::vector<std::string> why;
    for (const SkippedPhoto& s : result.skipped) why.push_back(s.file + ": " + s.reason);
    throw std::runtime_error(input_dir + ": " + std::to_string(result.photos.size()) +
                             " usable photos of " + std::to_string(num_files) + "; at least " +
                             std::to_string(options.min_photos) + " are needed (left out: " +
                             JoinList(why, 4) + ")");
  }
}

// Devices by EXIF make and model. Sizes alone do not make another device: a
// phone writes photos of several sizes, and every size is its own camera group.
// Photos without EXIF (PNG, TIFF, edited copies) may come from any of them.
// Throws if several devices took the photos and options.allow_mixed_devices
// is off.
void CheckOneDevice(const std::string& input_dir, const PhotoImport& result,
                    const PhotoImportOptions& options) {
  std::map<std::string, std::vector<std::string>> devices;
  for (const auto& p : result.photos) {
    if (p.exif.present && p.device != "unknown camera") devices[p.device].push_back(p.source);
  }
  if (devices.size() > 1 && !options.allow_mixed_devices) {
    std::vector<std::string> list;
    for (const auto& [device, photos] : devices) {
      list.push_back(device + " (" + std::to_string(photos.size()) + " photos, e.g. " +
                     photos.front() + ")");
    }
    throw std::runtime_error(input_dir + ": photos come from " + std::to_string(devices.size()) +
                             " different cameras: " + JoinList(list, 4) +
                             "; capture with one camera, or pass --mixed-cameras to calibrate "
                             "each camera separately");
  }
}

// Camera groups: device, upright working size and focal prior (0.1 px bins).
void GroupCameras(PhotoImport* result) {
  std::map<std::tuple<std::string, int, int, long>, int> group_of;
  for (size_t i = 0; i < result->photos.size(); ++i) {
    ImportedPhoto& p = result->photos[i];
    const auto key = std::make_tuple(p.device, p.width, p.height, std::lround(p.focal_px * 10));
    auto it = group_of.find(key);
    if (it == group_of.end()) {
      CameraGroup g;
      g.device = p.device;
      g.width = p.width;
      g.height = p.height;
      g.focal_px = p.focal_px;
      result->groups.push_back(g);
      it = group_of.emplace(key, static_cast<int>(result->groups.size()) - 1).first;
    }
    p.group = it->second;
    result->groups[it->second].photos.push_back(static_cast<int>(i));
  }
}

}  // namespace

PhotoImport ImportPhotos(const std::string& input_dir, const std::string& output_dir,
                         const PhotoImportOptions& options,
                         const std::function<void(int, int)>& on_photo) {
  const Status status = options.Check();
  if (!status.ok()) throw std::invalid_argument("photo import options: " + status.message());
  const std::vector<std::string> names = ListPhotoFiles(input_dir, options);
  PhotoImport result;
  std::map<std::string, std::string> first_with_hash;  // SHA-256 of the bytes -> file name.
  int done = 0;
  for (const std::string& name : names) {
    ImportedPhoto photo;
    std::string skipped;
    if (ImportPhoto(input_dir, name, output_dir, options, &first_with_hash, &photo, &skipped))
      result.photos.push_back(photo);
    else
      result.skipped.push_back({name, skipped});
    if (on_photo) on_photo(++done, static_cast<int>(names.size()));
  }
  CheckUsable(input_dir, names.size(), result, options);
  CheckOneDevice(input_dir, result, options);
  GroupCameras(&result);
  return result;
}

}  // namespace casual3d::sfm

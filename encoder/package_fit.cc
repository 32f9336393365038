#include "encoder/package_fit.h"

#include <cmath>
#include <cstdio>
#include <string>
#include <utility>

namespace casual3d::encoder {
namespace {

// KB (1024 bytes) with one decimal, so that a package just over its budget
// does not read as the budget.
std::string Kb(uint64_t bytes) {
  char text[32];
  std::snprintf(text, sizeof text, "%.1f KB", static_cast<double>(bytes) / 1024.0);
  return text;
}

}  // namespace

Status PackageFitOptions::Check() const {
  if (!(min_color_quality >= 0.0f && min_color_quality <= 100.0f))
    return InvalidArgument("min_color_quality " + std::to_string(min_color_quality) +
                           " is outside [0, 100]");
  return Status::Ok();
}

StatusOr<PackageFit> EncodePackageWithin(const TwoLayerPanorama& pano, const PackageOptions& options,
                                         const PackageFitOptions& fit) {
  CASUAL3D_RETURN_IF_ERROR(fit.Check());
  PackageFit best;
  best.options = options;
  CASUAL3D_ASSIGN_OR_RETURN(best.files, EncodePackage(pano, options, &best.stats));
  best.encodings = 1;
  const auto fits = [&](const PackageStats& s) { return fit.max_bytes == 0 || s.total_bytes <= fit.max_bytes; };
  if (fits(best.stats)) return best;

  // Step 2: lossy normals, kept when they make the package smaller.
  if (fit.allow_lossy_normals && !options.lossy_normals) {
    PackageOptions lossy = options;
    lossy.lossy_normals = true;
    PackageStats stats;
    CASUAL3D_ASSIGN_OR_RETURN(PackageFiles files, EncodePackage(pano, lossy, &stats));
    ++best.encodings;
    if (stats.total_bytes < best.stats.total_bytes) {
      best.files = std::move(files);
      best.stats = std::move(stats);
      best.options = lossy;
      if (fits(best.stats)) return best;
    }
  }

  // Step 3: the highest whole colour quality in [floor, given) that fits,
  // from `best`'s other tiles (`best` changes only after the last encoding).
  const PackageFiles& base = best.files;
  const PackageOptions base_options = best.options;
  const auto at_quality = [&](int quality, PackageFit* out) -> Status {
    out->options = base_options;
    out->options.color_quality = static_cast<float>(quality);
    CASUAL3D_ASSIGN_OR_RETURN(out->files, ReencodeColor(pano, out->options, base, &out->stats));
    ++best.encodings;
    return Status::Ok();
  };
  int low = static_cast<int>(std::ceil(fit.min_color_quality));
  int high = static_cast<int>(std::ceil(options.color_quality));  // Does not fit.
  if (low < high) {
    PackageFit floor;
    CASUAL3D_RETURN_IF_ERROR(at_quality(low, &floor));
    if (fits(floor.stats)) {
      // Invariant: `floor` (at quality `low`) fits; quality `high` does not.
      while (high - low > 1) {
        const int mid = low + (high - low) / 2;
        PackageFit trial;
        CASUAL3D_RETURN_IF_ERROR(at_quality(mid, &trial));
        if (fits(trial.stats)) {
          low = mid;
          floor = std::move(trial);
        } else {
          high = mid;
        }
      }
      floor.encodings = best.encodings;
      return floor;
    }
    if (floor.stats.total_bytes < best.stats.total_bytes) {
      floor.encodings = best.encodings;
      best = std::move(floor);
    }
  }
  const PackageOptions& o = best.options;
  const std::string floor_advice =
      low < high ? "a lower colour quality floor"
                 : "a colour quality floor below the given quality " +
                       std::to_string(static_cast<int>(std::lround(options.color_quality)));
  return InvalidArgument(
      "the package does not fit in " + Kb(fit.max_bytes) + ": the smallest was " + Kb(best.stats.total_bytes) +
      " (colour quality " + std::to_string(static_cast<int>(std::lround(o.color_quality))) +
      (o.lossy_normals ? ", lossy normals" : ", lossless normals") + "); allow more bytes, " + floor_advice +
      ", or encode a narrower panorama");
}

}  // namespace casual3d::encoder

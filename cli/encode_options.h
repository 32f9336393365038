#pragma once

// The options of `casual3d encode` (cli/encode_command.cc), described once
// (reconstruct/util/options_fields.h) for the flags' help and range checks.
//
// encoder::PackageOptions lives in encoder/, below reconstruct/util, so it
// keeps its own Check(); the fields the flags set are described here with
// the same ranges (cli/command_options_test.cc holds them to it).

#include <string>

#include "encoder/package_writer.h"
#include "format/manifest.h"
#include "format/status.h"
#include "reconstruct/util/options_fields.h"

namespace casual3d::cli {

struct EncodeCommandOptions {
  std::string master;        // Input master file (OpenEXR).
  std::string output;        // Output package folder.
  std::string single_file;   // Optional .c3d output.
  bool viewer = true;        // Add index.html and the viewer to the folder.
  std::string capture;       // Optional sparse stage output whose advice the page shows.
  std::string title;         // The page's title; empty: the output folder's name.
  // Web delivery settings; --depth-bits 12 --normal-bits 8 keep each node's
  // value as closely as PackageOptions' defaults.
  encoder::PackageOptions package = encoder::DeliveryPackageOptions();
  // A byte budget for the whole package (encoder/package_fit.h): 0 = none.
  int max_kb = 0;
  float min_quality = 75.0f;  // The lowest colour quality the budget may use.

  template <typename Self, typename Visitor>
  static void DescribeFields(Self& o, Visitor& v) {
    using R = util::Rule;
    v.Field("package.color_quality", o.package.color_quality, R::Closed(0, 100),
            "Colour WebP quality");
    v.Field("package.tile_size", o.package.tile_size, R::Closed(kMinTileSize, kMaxTileSize),
            "Tile side in pixels");
    v.Field("package.levels", o.package.levels, R::ZeroOr(R::Closed(1, kMaxLevels)),
            "Levels of detail computed (one fewer stored with --omit-level-width); 0 = "
            "automatic");
    v.Field("package.omit_level_width", o.package.omit_level_width, R::AtLeast(0),
            "Leave out the level more than half this and at most this many pixels wide (the "
            "2048 one of a 4096 or 8192 panorama, 1536 of 6144) unless it is the finest or the "
            "coarsest (package version 2.0, which 1.x readers refuse); 0 writes every level "
            "(1.x)");
    v.Field("package.depth_bits", o.package.depth_bits, R::Closed(8, 16),
            "Bits of the log-depth code (9: relative error at most 0.68% for far/near 1000; "
            "10 for 0.34%, 12 for 0.084%)");
    v.Field("package.normal_bits", o.package.normal_bits, R::Closed(4, 8),
            "Bits per octahedral normal coordinate (5: angular error at most 8.1 degrees; 8 for "
            "1 degree)");
    v.Field("package.lossy_normals", o.package.lossy_normals, R::Any(),
            "Normals as lossy images within the two error bounds below (package version 1.2) "
            "instead of lossless codes of --normal-bits");
    v.Field("package.normal_mean_error_deg", o.package.normal_mean_error_deg, R::Closed(1, 90),
            "Lossy normals: each tile's mean angular error at most this, degrees");
    v.Field("package.normal_p99_error_deg", o.package.normal_p99_error_deg, R::Closed(1, 90),
            "Lossy normals: each tile's 99th-percentile angular error at most this, degrees");
    v.Field("max_kb", o.max_kb, R::AtLeast(0),
            "Fit the package's tiles and manifest in this many KB (1024 bytes): lossy normals "
            "first, then colour quality down to --min-quality; fails naming the smallest size "
            "reached. 0 = no budget");
    v.Field("min_quality", o.min_quality, R::Closed(0, 100),
            "Lowest colour quality --max-kb may use");
    v.Field("package.num_threads", o.package.num_threads, R::Closed(0, 256),
            "Encoding threads; 0 = all cores", util::Keyed::kNo);
  }
  // The described ranges, then encoder::PackageOptions::Check.
  Status Check() const {
    CASUAL3D_RETURN_IF_ERROR(util::CheckFields(*this));
    return package.Check();
  }
};

}  // namespace casual3d::cli

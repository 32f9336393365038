#pragma once

// Fitting a web package into a byte budget (`casual3d encode --max-kb`): the
// settings a site with a delivery budget would otherwise search by hand, in
// the order of what they cost the person viewing the photo.
//
//   1. the given settings;
//   2. lossy normals (spec/package.md 1.2) within the given error bounds,
//      when allowed: shading within declared bounds, but more decoding work
//      for the viewer;
//   3. lower colour quality, down to a floor: the highest quality that fits,
//      by bisection over whole quality steps (only the colour tiles are
//      encoded again: ReencodeColor).
//
// Stops at the first step that fits; fails naming the smallest package it
// reached when none does.

#include <cstdint>

#include "encoder/package_writer.h"
#include "format/status.h"
#include "format/two_layer.h"

namespace casual3d::encoder {

struct PackageFitOptions {
  // The package's files (tiles and manifest.json; not a viewer page beside
  // them, and a .c3d adds its index of 16 bytes plus about 20 and the path's
  // length per file) at most this many bytes; 0: no budget, the given
  // settings as they are.
  uint64_t max_bytes = 0;
  // The lowest colour quality step 3 may use, [0, 100]; step 3 is skipped
  // when it is not below the given quality.
  float min_color_quality = 75.0f;
  // Whether step 2 may switch to lossy normals.
  bool allow_lossy_normals = true;

  Status Check() const;
};

struct PackageFit {
  PackageFiles files;
  PackageStats stats;
  PackageOptions options;  // The settings that fit.
  int encodings = 0;       // Packages (or colour sets) encoded on the way.
};

// Encodes `pano` with `options`, changed as above until the package fits in
// fit.max_bytes. Fails with kInvalidArgument for bad options or when the
// package cannot fit, naming the smallest size reached and its settings;
// with EncodePackage's errors otherwise.
StatusOr<PackageFit> EncodePackageWithin(const TwoLayerPanorama& pano, const PackageOptions& options,
                                         const PackageFitOptions& fit);

}  // namespace casual3d::encoder

#pragma once

// The normal images of the "octahedral-lossy" encoding (spec/package.md Sec.
// 4.3.1): each tile is coded at the lowest lossy WebP quality whose decoded
// normals keep the bounds the manifest declares (mean and 99th percentile of
// the angle to the panorama's normals over the tile's lit present nodes), so
// that smooth tiles cost little and none breaks the bounds.

#include <cstdint>
#include <vector>

#include "encoder/tile_image_codec.h"
#include "format/image.h"
#include "format/status.h"
#include "format/tile_codec.h"
#include "format/two_layer.h"

namespace casual3d::encoder {

// Angles, degrees, between the normals of a tile's lit present nodes and
// those decoded from its image.
struct NormalTileError {
  double mean_deg = 0.0;
  double p99_deg = 0.0;  // The 99th percentile (nearest rank).
  int64_t nodes = 0;     // Lit present nodes compared.
};

// The error of `decoded` (a lossy normal image of the tile [x0, x0+w) x [y0,
// y0+h) of `pano`, 2w x 2h, 3 or 4 channels, G holding the codes) against
// the panorama's normals. Unlit nodes (zero normal) are marked by the image's
// alpha, which WebP keeps exactly, and are not compared.
NormalTileError MeasureNormalTileError(const TwoLayerPanorama& pano, int x0, int y0, int w, int h,
                                       ImageView<const uint8_t> decoded);

// The lossy qualities tried, lowest first; above the last, the image is coded
// lossless (its 8-bit codes are then within 0.91 degrees).
const std::vector<float>& LossyNormalQualities();

// Encodes `image` (EncodeTileImage's lossy normal image of that tile, absent
// nodes filled or not) with `codec` at the lowest quality of
// LossyNormalQualities() (by bisection) whose decoded normals are within
// q.mean_error_deg and q.p99_error_deg, with the speed/size trade-off
// `lossy_method`; or, when none is, with the lossless `lossless` settings.
// `error`, if not null, receives the chosen coding's error.
StatusOr<std::vector<uint8_t>> EncodeLossyNormalTile(const TwoLayerPanorama& pano, int x0, int y0,
                                                     int w, int h, const Image8& image,
                                                     const NormalQuantization& q,
                                                     const TileImageCodec& codec, int lossy_method,
                                                     const TileEncodeSettings& lossless,
                                                     NormalTileError* error = nullptr);

}  // namespace casual3d::encoder

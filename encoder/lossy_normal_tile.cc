#include "encoder/lossy_normal_tile.h"

#include <algorithm>
#include <cmath>

namespace casual3d::encoder {

NormalTileError MeasureNormalTileError(const TwoLayerPanorama& pano, int x0, int y0, int w, int h,
                                       ImageView<const uint8_t> decoded) {
  constexpr double kDegrees = 180.0 / 3.14159265358979323846;
  const int c = decoded.channels();
  std::vector<float> angles;
  angles.reserve(static_cast<size_t>(w) * h);
  for (int l = 0; l < kNumLayers; ++l) {
    const LayerData& L = pano.layer(l);
    for (int y = 0; y < h; ++y) {
      const uint8_t* row = decoded.row(l * h + y);
      for (int x = 0; x < w; ++x) {
        const size_t i = pano.index(x0 + x, y0 + y);
        const float* n = &L.normal[3 * i];
        const double length = std::sqrt(double{n[0]} * n[0] + double{n[1]} * n[1] +
                                         double{n[2]} * n[2]);
        if (!L.present[i] || !(length > 0)) continue;
        const uint8_t code[2] = {row[c * x + 1], row[c * (w + x) + 1]};
        float d[3];
        DecodeOctahedralLossy(code, d);
        const double cosine = (n[0] * d[0] + n[1] * d[1] + n[2] * d[2]) / length;
        angles.push_back(static_cast<float>(std::acos(std::clamp(cosine, -1.0, 1.0)) * kDegrees));
      }
    }
  }
  NormalTileError e;
  e.nodes = static_cast<int64_t>(angles.size());
  if (angles.empty()) return e;
  double sum = 0;
  for (float a : angles) sum += a;
  e.mean_deg = sum / angles.size();
  const size_t rank = static_cast<size_t>(std::ceil(0.99 * angles.size())) - 1;
  std::nth_element(angles.begin(), angles.begin() + rank, angles.end());
  e.p99_deg = angles[rank];
  return e;
}

const std::vector<float>& LossyNormalQualities() {
  // Steps of 5: at 10 the tiles that need 85 or 95 took 90 or 100, and the
  // demo's level-0 normals were 23% larger.
  static const std::vector<float> qualities = [] {
    std::vector<float> q;
    for (int v = 5; v <= 100; v += 5) q.push_back(static_cast<float>(v));
    return q;
  }();
  return qualities;
}

StatusOr<std::vector<uint8_t>> EncodeLossyNormalTile(const TwoLayerPanorama& pano, int x0, int y0,
                                                     int w, int h, const Image8& image,
                                                     const NormalQuantization& q,
                                                     const TileImageCodec& codec, int lossy_method,
                                                     const TileEncodeSettings& lossless,
                                                     NormalTileError* error) {
  struct Coded {
    std::vector<uint8_t> bytes;
    NormalTileError error;
    bool ok = false;
  };
  auto code = [&](const TileEncodeSettings& settings) -> StatusOr<Coded> {
    Coded coded;
    CASUAL3D_ASSIGN_OR_RETURN(coded.bytes, codec.Encode(image.view(), settings));
    CASUAL3D_ASSIGN_OR_RETURN(Image8 decoded, codec.Decode(coded.bytes.data(), coded.bytes.size()));
    coded.error =
        MeasureNormalTileError(pano, x0, y0, w, h, static_cast<const Image8&>(decoded).view());
    coded.ok = coded.error.mean_deg <= q.mean_error_deg && coded.error.p99_deg <= q.p99_error_deg;
    return coded;
  };
  // Bisection for the lowest passing quality: the error falls as the quality
  // rises (not strictly, so the result is a passing quality, not always the
  // lowest one).
  const std::vector<float>& qualities = LossyNormalQualities();
  int lo = 0, hi = static_cast<int>(qualities.size());  // Passing: some index in [lo, hi].
  Coded best;
  while (lo < hi) {
    const int mid = (lo + hi) / 2;
    TileEncodeSettings lossy;
    lossy.quality = qualities[mid];
    lossy.method = lossy_method;
    CASUAL3D_ASSIGN_OR_RETURN(Coded coded, code(lossy));
    if (coded.ok) {
      best = std::move(coded);
      hi = mid;
    } else {
      lo = mid + 1;
    }
  }
  if (!best.ok) {
    CASUAL3D_ASSIGN_OR_RETURN(best, code(lossless));
    if (!best.ok)
      return InternalError("lossless normal codes exceed the bounds (mean " +
                           std::to_string(best.error.mean_deg) + ", p99 " +
                           std::to_string(best.error.p99_deg) + " degrees)");
  }
  if (error != nullptr) *error = best.error;
  return std::move(best.bytes);
}

}  // namespace casual3d::encoder

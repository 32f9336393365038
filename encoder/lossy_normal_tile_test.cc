#include "encoder/lossy_normal_tile.h"

#include <cmath>
#include <random>

#include <gtest/gtest.h>

#include "encoder/absent_fill.h"
#include "format/package_test_scene.h"
#include "format/tile_image_format.h"

namespace casual3d::encoder {
namespace {

// A panorama whose normals are the test scene's, turned by noise of `noise`
// radians (0: smooth), with a few unlit nodes.
TwoLayerPanorama NoisyNormals(double noise) {
  TwoLayerPanorama pano = casual3d::testing::MakePackageTestPanorama(128, 64);
  std::mt19937 rng(7);
  std::normal_distribution<float> g(0.0f, static_cast<float>(noise));
  for (int l = 0; l < kNumLayers; ++l) {
    LayerData& L = pano.layer(l);
    for (size_t i = 0; i < L.present.size(); ++i) {
      float* n = &L.normal[3 * i];
      if (n[0] == 0 && n[1] == 0 && n[2] == 0) continue;  // Unlit stays so.
      for (int c = 0; c < 3; ++c) n[c] += g(rng);
      const float length = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
      for (int c = 0; c < 3; ++c) n[c] /= length;
    }
  }
  for (int x = 10; x < 20; ++x) std::fill_n(&pano.layer(kFront).normal[3 * pano.index(x, 2)], 3, 0.0f);
  return pano;
}

TileEncodeSettings Lossless() {
  TileEncodeSettings s;
  s.lossless = true;
  s.quality = 25.0f;
  s.method = 1;
  return s;
}

struct Coded {
  std::vector<uint8_t> bytes;
  NormalTileError error;
  Image8 decoded;
};

Coded Code(const TwoLayerPanorama& pano, const NormalQuantization& q) {
  TileQuantization tq;
  tq.normal = q;
  Image8 image = EncodeTileImage(pano, 0, 0, pano.width(), pano.height(), TileImageKind::kNormal, tq);
  FillAbsentCodes(pano, 0, 0, pano.width(), pano.height(), &image);
  const TileImageCodec* codec = *TileImageCodecFor(WebpTileImageFormat());
  Coded c;
  StatusOr<std::vector<uint8_t>> bytes =
      EncodeLossyNormalTile(pano, 0, 0, pano.width(), pano.height(), image, q, *codec, 3,
                            Lossless(), &c.error);
  EXPECT_TRUE(bytes.ok()) << bytes.status().ToString();
  c.bytes = *bytes;
  c.decoded = *codec->Decode(c.bytes.data(), c.bytes.size());
  return c;
}

NormalQuantization Bounds(double mean, double p99) {
  NormalQuantization q;
  q.type = NormalEncoding::kOctahedralLossy;
  q.mean_error_deg = mean;
  q.p99_error_deg = p99;
  return q;
}

TEST(LossyNormalTileTest, KeepsTheBoundsItDeclares) {
  for (double noise : {0.0, 0.05, 0.3}) {
    const TwoLayerPanorama pano = NoisyNormals(noise);
    for (const auto& [mean, p99] : {std::make_pair(1.0, 3.0), std::make_pair(2.5, 8.0)}) {
      const Coded c = Code(pano, Bounds(mean, p99));
      // The error reported is the error of what a reader decodes.
      const NormalTileError again =
          MeasureNormalTileError(pano, 0, 0, pano.width(), pano.height(),
                                 static_cast<const Image8&>(c.decoded).view());
      EXPECT_EQ(again.nodes, c.error.nodes);
      EXPECT_DOUBLE_EQ(again.mean_deg, c.error.mean_deg);
      EXPECT_LE(c.error.mean_deg, mean) << noise;
      EXPECT_LE(c.error.p99_deg, p99) << noise;
      EXPECT_GT(c.error.nodes, 1000);
      // The unlit nodes keep alpha 0, exactly.
      ASSERT_EQ(c.decoded.channels(), 4);
      int unlit = 0;
      for (int y = 0; y < pano.height(); ++y) {
        for (int x = 0; x < pano.width(); ++x) {
          const size_t i = pano.index(x, y);
          if (!pano.layer(kFront).present[i]) continue;
          const float* n = &pano.layer(kFront).normal[3 * i];
          const bool lit = n[0] != 0 || n[1] != 0 || n[2] != 0;
          unlit += !lit;
          ASSERT_EQ(c.decoded.at(x, y, 3), lit ? 255 : 0) << x << ", " << y;
        }
      }
      EXPECT_GE(unlit, 10);
    }
  }
}

TEST(LossyNormalTileTest, LooserBoundsAndSmootherNormalsCostFewerBytes) {
  const TwoLayerPanorama smooth = NoisyNormals(0.0), noisy = NoisyNormals(0.05);
  const size_t tight = Code(noisy, Bounds(1.0, 3.0)).bytes.size();
  const size_t loose = Code(noisy, Bounds(2.5, 8.0)).bytes.size();
  EXPECT_LT(loose, tight);
  EXPECT_LT(Code(smooth, Bounds(2.5, 8.0)).bytes.size(), loose);
}

TEST(LossyNormalTileTest, ErrorOfAnExactImageIsTheCodeStep) {
  const TwoLayerPanorama pano = NoisyNormals(0.05);
  TileQuantization tq;
  tq.normal = Bounds(2.5, 8.0);
  const Image8 image =
      EncodeTileImage(pano, 0, 0, pano.width(), pano.height(), TileImageKind::kNormal, tq);
  const NormalTileError e = MeasureNormalTileError(pano, 0, 0, pano.width(), pano.height(), image.view());
  EXPECT_LT(e.p99_deg, 1.0);  // 8-bit octahedral codes: within 0.91 degrees.
  EXPECT_LT(e.mean_deg, e.p99_deg);
  int64_t lit = 0;
  for (int l = 0; l < kNumLayers; ++l)
    for (size_t i = 0; i < pano.layer(l).present.size(); ++i) {
      const float* n = &pano.layer(l).normal[3 * i];
      lit += pano.layer(l).present[i] && (n[0] != 0 || n[1] != 0 || n[2] != 0);
    }
  EXPECT_EQ(e.nodes, lit);
}

}  // namespace
}  // namespace casual3d::encoder

#include "format/tile_codec.h"

#include <cmath>

#include <gtest/gtest.h>

#include "format/package_test_scene.h"

namespace casual3d {
namespace {

ImageView<const uint8_t> V(const Image8& image) { return image.view(); }

TEST(TileCodecTest, DepthCodesFollowTheFormulaAndBound) {
  for (int bits : {8, 12, 16}) {
    DepthQuantization q;
    q.near_m = 0.5;
    q.far_m = 500.0;
    q.bits = bits;
    ASSERT_TRUE(q.Check().ok());
    EXPECT_EQ(QuantizeDepth(0.5, q), 1);
    EXPECT_EQ(QuantizeDepth(500.0, q), q.MaxCode());
    EXPECT_EQ(QuantizeDepth(0.01, q), 1);         // Clamped.
    EXPECT_EQ(QuantizeDepth(1e6, q), q.MaxCode());  // Clamped.
    EXPECT_DOUBLE_EQ(DequantizeDepth(1, q), 0.5);
    EXPECT_NEAR(DequantizeDepth(q.MaxCode(), q), 500.0, 1e-9);
    EXPECT_EQ(DequantizeDepth(0, q), 0.0);
    double worst = 0;
    for (double d = 0.5; d < 500; d *= 1.0007) {
      const double back = DequantizeDepth(QuantizeDepth(d, q), q);
      worst = std::max(worst, std::fabs(back / d - 1));
    }
    EXPECT_LE(worst, q.MaxRelativeError() * (1 + 1e-9));
    EXPECT_GT(worst, q.MaxRelativeError() * 0.9);  // The bound is tight.
  }
  DepthQuantization q12;
  q12.near_m = 1;
  q12.far_m = 1000;
  q12.bits = 12;
  EXPECT_NEAR(q12.MaxRelativeError(), 0.000844, 0.000005);
  DepthQuantization bad;
  bad.near_m = 0;
  EXPECT_FALSE(bad.Check().ok());
  bad.near_m = 2;
  bad.far_m = 1;
  EXPECT_FALSE(bad.Check().ok());
  bad.far_m = 3;
  bad.bits = 17;
  EXPECT_FALSE(bad.Check().ok());
}

TEST(TileCodecTest, OctahedralNormalsWithinOneDegree) {
  NormalQuantization q;
  double worst = 0;
  for (int i = 0; i < 20000; ++i) {
    // Fibonacci sphere directions.
    const double z = 1 - 2 * (i + 0.5) / 20000, r = std::sqrt(1 - z * z), phi = i * 2.39996323;
    const float n[3] = {float(r * std::cos(phi)), float(r * std::sin(phi)), float(z)};
    uint8_t code[2];
    EncodeOctahedral(n, q, code);
    ASSERT_NE(code[0], 0);
    ASSERT_NE(code[1], 0);
    float back[3];
    ASSERT_TRUE(DecodeOctahedral(code, q, back));
    const double dot = n[0] * back[0] + n[1] * back[1] + n[2] * back[2];
    worst = std::max(worst, std::acos(std::fmin(1.0, dot)) * 180 / M_PI);
    EXPECT_NEAR(std::sqrt(back[0] * back[0] + back[1] * back[1] + back[2] * back[2]), 1.0, 1e-6);
  }
  EXPECT_LT(worst, 0.95);
  const float zero[3] = {0, 0, 0};
  uint8_t code[2];
  EncodeOctahedral(zero, q, code);
  EXPECT_EQ(code[0], 0);
  EXPECT_EQ(code[1], 0);
  const uint8_t invalid[2] = {0, 7};
  float out[3];
  EXPECT_FALSE(DecodeOctahedral(invalid, q, out));
  NormalQuantization six;
  six.bits = 6;
  const uint8_t above[2] = {64, 3};
  EXPECT_FALSE(DecodeOctahedral(above, six, out));
}

TEST(TileCodecTest, TileRoundTripKeepsTheGraphExactly) {
  const TwoLayerPanorama pano = casual3d::testing::MakePackageTestPanorama(96, 48);
  TileQuantization q;
  q.depth.near_m = 2.0;
  q.depth.far_m = 100.0;
  q.depth.bits = 16;
  const TileDecoder decoder(q);
  TwoLayerPanorama out(96, 48);
  out.frame() = pano.frame();
  // Tiles of 40x32 with partial tiles at the right and bottom.
  for (int y0 = 0; y0 < 48; y0 += 32) {
    for (int x0 = 0; x0 < 96; x0 += 40) {
      const int w = std::min(40, 96 - x0), h = std::min(32, 48 - y0);
      for (int k = 0; k < kNumTileImageKinds; ++k) {
        const Image8 image = EncodeTileImage(pano, x0, y0, w, h, static_cast<TileImageKind>(k), q);
        int iw, ih;
        TileImageSize(static_cast<TileImageKind>(k), w, h, &iw, &ih);
        ASSERT_EQ(image.width(), iw);
        ASSERT_EQ(image.height(), ih);
        Status s = DecodeTileImage(image.view(), static_cast<TileImageKind>(k), x0, y0, w, h,
                                   decoder, &out);
        ASSERT_TRUE(s.ok()) << s.ToString();
      }
    }
  }
  ASSERT_TRUE(FinishDecodedPanorama(&out).ok());
  ASSERT_TRUE(out.Validate().ok()) << out.Validate().ToString();
  for (int l = 0; l < kNumLayers; ++l) {
    EXPECT_EQ(out.layer(l).present, pano.layer(l).present);
    EXPECT_EQ(out.layer(l).links, pano.layer(l).links);
    EXPECT_EQ(out.layer(l).label, pano.layer(l).label);
    EXPECT_EQ(out.layer(l).rgb, pano.layer(l).rgb);  // Colour is exact before WebP.
    for (size_t i = 0; i < pano.layer(l).present.size(); ++i) {
      if (!pano.layer(l).present[i]) continue;
      ASSERT_NEAR(out.layer(l).depth_m[i] / pano.layer(l).depth_m[i], 1.0,
                  q.depth.MaxRelativeError() * 1.001);
    }
  }
}

TEST(TileCodecTest, HostileImagesAreRefused) {
  TwoLayerPanorama out(32, 16);
  TileQuantization q;
  q.depth.bits = 10;
  const TileDecoder decoder(q);
  Image8 graph(16, 16, 4, 0);
  graph.at(3, 2, 2) = 0x40;  // Reserved flag bit.
  Status s = DecodeTileImage(V(graph), TileImageKind::kGraph, 0, 0, 16, 16, decoder, &out);
  EXPECT_EQ(s.code(), StatusCode::kInvalidData);
  EXPECT_NE(s.message().find("(3, 2)"), std::string::npos) << s.message();
  Image8 depth(16, 32, 3, 0);
  depth.at(1, 1, 0) = 0x04;  // Code 1024 > 1023.
  EXPECT_EQ(DecodeTileImage(V(depth), TileImageKind::kDepth, 0, 0, 16, 16, decoder, &out).code(),
            StatusCode::kInvalidData);
  Image8 wrong(16, 16, 3, 0);  // Depth images are w x 2h.
  EXPECT_EQ(DecodeTileImage(V(wrong), TileImageKind::kDepth, 0, 0, 16, 16, decoder, &out).code(),
            StatusCode::kInvalidData);
  Image8 gray(16, 32, 1, 0);
  EXPECT_EQ(DecodeTileImage(V(gray), TileImageKind::kColor, 0, 0, 16, 16, decoder, &out).code(),
            StatusCode::kInvalidData);
  EXPECT_EQ(DecodeTileImage(V(depth), TileImageKind::kDepth, 20, 0, 16, 16, decoder, &out).code(),
            StatusCode::kInvalidArgument);
  // A present node without depth.
  TwoLayerPanorama p(4, 4);
  p.layer(kFront).present[5] = 1;
  EXPECT_EQ(FinishDecodedPanorama(&p).code(), StatusCode::kInvalidData);
}

// The decoder's look-up tables must give exactly DecodeOctahedral and
// DequantizeDepth, for RGB and RGBA images alike.
TEST(TileCodecTest, TableDecodingMatchesTheReferenceFunctions) {
  for (int normal_bits : {8, 6}) {
    TileQuantization q;
    q.depth.near_m = 0.5;
    q.depth.far_m = 300.0;
    q.depth.bits = 16;
    q.normal.bits = normal_bits;
    const TileDecoder decoder(q);
    const int m = q.normal.MaxCode();
    for (int channels : {3, 4}) {
      // Front: every valid code pair (c0, c1) = (x + 1, y + 1); back: depth
      // codes spread over the whole range, normals (0, 0).
      TwoLayerPanorama out(m, m);
      Image8 normal(m, 2 * m, channels, 0), depth(m, 2 * m, channels, 0);
      for (int y = 0; y < m; ++y) {
        for (int x = 0; x < m; ++x) {
          normal.at(x, y, 0) = static_cast<uint8_t>(x + 1);
          normal.at(x, y, 1) = static_cast<uint8_t>(y + 1);
          const int code = (y * m + x) * 65535 / (m * m - 1);
          depth.at(x, m + y, 0) = static_cast<uint8_t>(code >> 8);
          depth.at(x, m + y, 1) = static_cast<uint8_t>(code & 255);
        }
      }
      ASSERT_TRUE(
          DecodeTileImage(V(normal), TileImageKind::kNormal, 0, 0, m, m, decoder, &out).ok());
      ASSERT_TRUE(DecodeTileImage(V(depth), TileImageKind::kDepth, 0, 0, m, m, decoder, &out).ok());
      for (int y = 0; y < m; ++y) {
        for (int x = 0; x < m; ++x) {
          const size_t i = out.index(x, y);
          const uint8_t code[2] = {static_cast<uint8_t>(x + 1), static_cast<uint8_t>(y + 1)};
          float expected[3];
          ASSERT_TRUE(DecodeOctahedral(code, q.normal, expected));
          for (int c = 0; c < 3; ++c) ASSERT_EQ(out.layer(kFront).normal[3 * i + c], expected[c]);
          for (int c = 0; c < 3; ++c) ASSERT_EQ(out.layer(kBack).normal[3 * i + c], 0.0f);
          const uint16_t depth_code = static_cast<uint16_t>((y * m + x) * 65535 / (m * m - 1));
          ASSERT_EQ(out.layer(kBack).depth_m[i],
                    static_cast<float>(DequantizeDepth(depth_code, q.depth)));
        }
      }
    }
  }
}

// PackageReader::FinishLevel checks only the links of a decoded level
// (TwoLayerPanorama::ValidateLinks): every value the decoder tables can give
// must be one Validate() accepts. Each valid normal code of every bit depth
// and each depth code of extreme quantizations, as present front nodes of a
// panorama without links.
TEST(TileCodecTest, EveryDecodableValueIsValidForValidate) {
  for (int normal_bits = 4; normal_bits <= 8; ++normal_bits) {
    TileQuantization q;
    q.normal.bits = normal_bits;
    const TileDecoder decoder(q);
    const int m = q.normal.MaxCode();
    TwoLayerPanorama pano(m + 1, m + 1);
    LayerData& F = pano.layer(kFront);
    int valid = 0;
    for (int c0 = 0; c0 <= m; ++c0) {
      for (int c1 = 0; c1 <= m; ++c1) {
        const uint8_t code[2] = {static_cast<uint8_t>(c0), static_cast<uint8_t>(c1)};
        if (!decoder.NormalValid(code)) continue;
        ++valid;
        const size_t i = pano.index(c0, c1);
        F.present[i] = 1;
        F.depth_m[i] = 1.0f;
        for (int c = 0; c < 3; ++c) F.normal[3 * i + c] = decoder.Normal(code)[c];
      }
    }
    EXPECT_EQ(valid, m * m + 1) << normal_bits << " bits";  // (1..M)^2 and (0, 0).
    const Status s = pano.Validate();
    EXPECT_TRUE(s.ok()) << normal_bits << " bits: " << s.ToString();
  }
  struct Range {
    double near_m, far_m;
    int bits;
  };
  for (const Range& r : {Range{1e-3, 1e6, 16}, Range{0.5, 0.5, 8}, Range{1e-4, 1e5, 8},
                         Range{2.0, 2e9, 16}}) {
    TileQuantization q;
    q.depth.near_m = r.near_m;
    q.depth.far_m = r.far_m;
    q.depth.bits = r.bits;
    ASSERT_TRUE(q.Check().ok());
    const TileDecoder decoder(q);
    const int codes = q.depth.MaxCode();
    TwoLayerPanorama pano(256, (codes + 255) / 256);
    LayerData& F = pano.layer(kFront);
    for (int code = 1; code <= codes; ++code) {
      const size_t i = static_cast<size_t>(code - 1);
      F.present[i] = 1;
      F.depth_m[i] = decoder.Depth(static_cast<uint16_t>(code));
    }
    const Status s = pano.Validate();
    EXPECT_TRUE(s.ok()) << r.near_m << ".." << r.far_m << " m: " << s.ToString();
  }
}

// A depth range that the manifest allows (finite doubles) but 32-bit floats
// cannot hold decodes to infinity, which FinishDecodedPanorama refuses.
TEST(TileCodecTest, DepthsBeyondFloatRangeAreRefused) {
  TileQuantization q;
  q.depth.near_m = 1e36;
  q.depth.far_m = 1e40;
  ASSERT_TRUE(q.Check().ok());
  const TileDecoder decoder(q);
  TwoLayerPanorama p(4, 1);
  for (int x = 0; x < 4; ++x) p.layer(kFront).present[p.index(x, 0)] = 1;
  Image8 depth(4, 2, 3, 0);
  for (int x = 0; x < 4; ++x) {
    const int code = x < 3 ? 1 : q.depth.MaxCode();
    depth.at(x, 0, 0) = static_cast<uint8_t>(code >> 8);
    depth.at(x, 0, 1) = static_cast<uint8_t>(code & 255);
  }
  ASSERT_TRUE(DecodeTileImage(V(depth), TileImageKind::kDepth, 0, 0, 4, 1, decoder, &p).ok());
  const Status s = FinishDecodedPanorama(&p);
  EXPECT_EQ(s.code(), StatusCode::kInvalidData);
  EXPECT_NE(s.message().find("front node at pixel (3, 0) has a depth beyond the range of 32-bit"),
            std::string::npos)
      << s.ToString();
}

// Errors name the first invalid pixel in row, column, layer order, whichever
// layer it is in.
TEST(TileCodecTest, ErrorsNameTheFirstInvalidPixel) {
  TileQuantization q;
  q.depth.bits = 10;
  q.normal.bits = 6;
  const TileDecoder decoder(q);
  TwoLayerPanorama out(16, 8);
  Image8 normal(16, 16, 4, 0);
  normal.at(5, 3, 0) = 7;       // Front (5, 3): one zero coordinate.
  normal.at(2, 8 + 3, 1) = 70;  // Back (2, 3): 70 > 63, invalid; comes first.
  normal.at(1, 8 + 6, 0) = 9;   // Back (1, 6): later row.
  Status s = DecodeTileImage(V(normal), TileImageKind::kNormal, 0, 0, 16, 8, decoder, &out);
  EXPECT_EQ(s.code(), StatusCode::kInvalidData);
  EXPECT_NE(s.message().find("(2, 3) (back)"), std::string::npos) << s.message();
  Image8 depth(16, 16, 3, 0);
  depth.at(9, 2, 0) = 0x05;      // Front (9, 2): code 1280 > 1023.
  depth.at(4, 8 + 2, 0) = 0x04;  // Back (4, 2): code 1024, the first.
  s = DecodeTileImage(V(depth), TileImageKind::kDepth, 0, 0, 16, 8, decoder, &out);
  EXPECT_EQ(s.code(), StatusCode::kInvalidData);
  EXPECT_NE(s.message().find("code 1024"), std::string::npos) << s.message();
  EXPECT_NE(s.message().find("(4, 2)"), std::string::npos) << s.message();
}

// Rows are decoded in bands on several threads: the panorama and the first
// invalid pixel named must not depend on how many.
TEST(TileCodecTest, SameResultForEveryThreadCount) {
  const TwoLayerPanorama pano = casual3d::testing::MakePackageTestPanorama(96, 64);
  TileQuantization q;
  q.depth.near_m = 2.0;
  q.depth.far_m = 100.0;
  q.depth.bits = 12;
  const TileDecoder decoder(q);
  TwoLayerPanorama reference;
  for (int threads : {1, 2, 3, 8}) {
    TwoLayerPanorama out(96, 64);
    out.frame() = pano.frame();
    for (int k = 0; k < kNumTileImageKinds; ++k) {
      const Image8 image = EncodeTileImage(pano, 0, 0, 96, 64, static_cast<TileImageKind>(k), q);
      ASSERT_TRUE(DecodeTileImage(image.view(), static_cast<TileImageKind>(k), 0, 0, 96, 64,
                                  decoder, &out, threads)
                      .ok());
    }
    ASSERT_TRUE(FinishDecodedPanorama(&out, threads).ok());
    ASSERT_TRUE(out.ValidateLinks(threads).ok());
    if (threads == 1) {
      reference = out;
    } else {
      EXPECT_TRUE(out == reference) << threads << " threads";
    }
    // Two bad pixels in different bands: the earlier row is named.
    Image8 graph(96, 64, 4, 0);
    graph.at(40, 50, 2) = 0x80;
    graph.at(70, 9, 2) = 0x20;
    const Status s =
        DecodeTileImage(V(graph), TileImageKind::kGraph, 0, 0, 96, 64, decoder, &out, threads);
    EXPECT_NE(s.message().find("(70, 9)"), std::string::npos) << threads << ": " << s.message();
    Image8 depth(96, 128, 3, 0);
    depth.at(30, 60, 0) = 0xff;     // Front (30, 60): code 65280 > 4095.
    depth.at(3, 64 + 5, 0) = 0xff;  // Back (3, 5): rows come first, so it is named.
    const Status d =
        DecodeTileImage(V(depth), TileImageKind::kDepth, 0, 0, 96, 64, decoder, &out, threads);
    EXPECT_NE(d.message().find("(3, 5)"), std::string::npos) << threads << ": " << d.message();
  }
}

}  // namespace
}  // namespace casual3d

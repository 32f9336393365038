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

// Graph images of right and down links only (version 2.x): the left and up
// links come back exactly, across tiles, the seam and the two layers.
TEST(TileCodecTest, RightAndDownLinksGiveBackEveryLink) {
  TwoLayerPanorama pano = casual3d::testing::MakePackageTestPanorama(96, 48, 5);
  // Cross-layer links: where a front node's right link is cut (a depth edge)
  // and the back node beside it is linked from the left by a back node, the
  // front node takes that link over.
  int cross = 0;
  for (int y = 0; y < 48; ++y) {
    for (int x = 0; x < 96; ++x) {
      int nx, ny;
      pano.Neighbour(x, y, kRight, &nx, &ny);
      const size_t i = pano.index(x, y), j = pano.index(nx, ny);
      uint8_t& front = pano.layer(kFront).links[i];
      uint8_t& back = pano.layer(kBack).links[i];
      uint8_t& to = pano.layer(kBack).links[j];
      if (!pano.layer(kFront).present[i] || !pano.layer(kBack).present[j]) continue;
      if (GetLink(front, kRight) != Link::kNone || GetLink(to, kLeft) != Link::kBack) continue;
      back = SetLink(back, kRight, Link::kNone);
      front = SetLink(front, kRight, Link::kBack);
      to = SetLink(to, kLeft, Link::kFront);
      ++cross;
    }
  }
  ASSERT_TRUE(pano.Validate().ok()) << pano.Validate().ToString();
  TileQuantization q;
  q.depth.near_m = 2.0;
  q.depth.far_m = 100.0;
  q.right_down_links = true;
  const TileDecoder decoder(q);
  TwoLayerPanorama out(96, 48);
  for (int y0 = 0; y0 < 48; y0 += 32) {
    for (int x0 = 0; x0 < 96; x0 += 40) {
      const int w = std::min(40, 96 - x0), h = std::min(32, 48 - y0);
      for (int k = 0; k < kNumTileImageKinds; ++k) {
        const Image8 image = EncodeTileImage(pano, x0, y0, w, h, static_cast<TileImageKind>(k), q);
        if (k == static_cast<int>(TileImageKind::kGraph)) {
          for (int y = 0; y < h; ++y) {
            for (int x = 0; x < w; ++x) {
              const uint8_t* px = &image.at(x, y);
              ASSERT_EQ((px[0] | px[1]) & 0xF0, 0);
            }
          }
        }
        ASSERT_TRUE(DecodeTileImage(image.view(), static_cast<TileImageKind>(k), x0, y0, w, h,
                                    decoder, &out).ok());
      }
    }
  }
  ASSERT_TRUE(FinishDecodedPanorama(&out).ok());
  ASSERT_TRUE(CompleteLinks(&out).ok());
  EXPECT_GT(cross, 0);
  for (int l = 0; l < kNumLayers; ++l) {
    EXPECT_EQ(out.layer(l).links, pano.layer(l).links) << l;
  }
  EXPECT_TRUE(out.ValidateLinks().ok());

  // Left or up bits at a present node: refused naming it, dropped with the
  // check off.
  TwoLayerPanorama bad = out;
  const size_t i = bad.index(20, 8);
  ASSERT_TRUE(bad.layer(kFront).present[i]);
  const TwoLayerPanorama stored = [&] {
    TwoLayerPanorama p = out;
    for (int l = 0; l < kNumLayers; ++l)
      for (uint8_t& links : p.layer(l).links) links &= 0x0F;
    return p;
  }();
  bad = stored;
  bad.layer(kFront).links[i] |= 0x40;
  DecodedNodeProblem problem;
  const Status refused = CompleteLinks(&bad, ReaderChecks(), &problem);
  EXPECT_EQ(refused.message(), "graph image: front node at pixel (20, 8) has left or up link bits "
                               "set (this version stores right and down links only)");
  EXPECT_EQ(problem.x, 20);
  EXPECT_EQ(problem.y, 8);
  EXPECT_EQ(problem.kind, TileImageKind::kGraph);
  bad = stored;
  bad.layer(kFront).links[i] |= 0x40;
  ReaderChecks off;
  off.Disable(ReaderCheck::kLeftUpLinkBits);
  ASSERT_TRUE(CompleteLinks(&bad, off).ok());
  EXPECT_EQ(bad.layer(kFront).links, out.layer(kFront).links);

  // A right link into an absent node, or two into one node's left side:
  // ValidateLinks refuses what CompleteLinks leaves.
  for (int trial = 0; trial < 2; ++trial) {
    bad = stored;
    bool made = false;
    for (size_t n = 0; n < bad.layer(kBack).present.size() && !made; ++n) {
      const int x = static_cast<int>(n % 96), y = static_cast<int>(n / 96);
      int nx, ny;
      bad.Neighbour(x, y, kRight, &nx, &ny);
      const size_t j = bad.index(nx, ny);
      uint8_t& links = bad.layer(kBack).links[n];
      if (!bad.layer(kBack).present[n] || GetLink(links, kRight) != Link::kNone) continue;
      if (trial == 0 && !bad.layer(kBack).present[j]) {
        links = SetLink(links, kRight, Link::kBack);  // Into an absent node.
        made = true;
      } else if (trial == 1 && bad.layer(kFront).present[j] && bad.layer(kFront).present[n] &&
                 GetLink(bad.layer(kFront).links[n], kRight) == Link::kFront) {
        links = SetLink(links, kRight, Link::kFront);  // The front node's side, taken.
        made = true;
      }
    }
    ASSERT_TRUE(made) << trial;
    ASSERT_TRUE(CompleteLinks(&bad).ok());
    EXPECT_FALSE(bad.ValidateLinks().ok()) << trial;
  }
}

TEST(TileCodecTest, LossyNormalCodesWithinOneDegreeAndUnlitByAlpha) {
  double worst = 0;
  for (int i = 0; i < 20000; ++i) {
    const double z = 1 - 2 * (i + 0.5) / 20000, r = std::sqrt(1 - z * z), phi = i * 2.39996323;
    const float n[3] = {float(r * std::cos(phi)), float(r * std::sin(phi)), float(z)};
    uint8_t code[2];
    ASSERT_TRUE(EncodeOctahedralLossy(n, code));
    float back[3];
    DecodeOctahedralLossy(code, back);
    const double dot = n[0] * back[0] + n[1] * back[1] + n[2] * back[2];
    worst = std::max(worst, std::acos(std::min(1.0, dot)) * 180 / 3.14159265358979);
  }
  EXPECT_LT(worst, 0.92);  // As 8-bit "octahedral" codes: below 1 degree.
  const float zero[3] = {0, 0, 0};
  uint8_t code[2];
  EXPECT_FALSE(EncodeOctahedralLossy(zero, code));

  // A tile round trip before any lossy coding: 2w x 2h RGBA, the codes in G,
  // unlit nodes by alpha 0; decoded 3-channel images have no unlit node.
  TwoLayerPanorama pano = casual3d::testing::MakePackageTestPanorama(48, 32);
  for (int x = 5; x < 9; ++x) std::fill_n(&pano.layer(kFront).normal[3 * pano.index(x, 3)], 3, 0.0f);
  TileQuantization q;
  q.depth.near_m = 2.0;
  q.depth.far_m = 100.0;
  q.normal.type = NormalEncoding::kOctahedralLossy;
  q.normal.mean_error_deg = 2;
  q.normal.p99_error_deg = 5;
  ASSERT_TRUE(q.Check().ok()) << q.Check().ToString();
  EXPECT_FALSE(TileImageIsLossless(TileImageKind::kNormal, q.normal.type));
  EXPECT_TRUE(TileImageIsLossless(TileImageKind::kNormal));
  EXPECT_TRUE(TileImageIsLossless(TileImageKind::kDepth, q.normal.type));
  const Image8 image = EncodeTileImage(pano, 0, 0, 48, 32, TileImageKind::kNormal, q);
  int iw, ih;
  TileImageSize(TileImageKind::kNormal, 48, 32, &iw, &ih, q.normal.type);
  EXPECT_EQ(iw, 96);
  EXPECT_EQ(ih, 64);
  ASSERT_EQ(image.width(), 96);
  ASSERT_EQ(image.height(), 64);
  ASSERT_EQ(image.channels(), 4);
  EXPECT_EQ(image.at(6, 3, 3), 0);
  EXPECT_EQ(image.at(6 + 48, 3, 3), 0);
  const TileDecoder decoder(q);
  for (int channels : {4, 3}) {
    Image8 input(96, 64, channels);
    for (int y = 0; y < 64; ++y)
      for (int x = 0; x < 96; ++x)
        for (int c = 0; c < channels; ++c) input.at(x, y, c) = image.at(x, y, c);
    TwoLayerPanorama out = pano;
    ASSERT_TRUE(DecodeTileImage(V(input), TileImageKind::kNormal, 0, 0, 48, 32, decoder, &out)
                    .ok());
    for (int l = 0; l < kNumLayers; ++l) {
      for (size_t i = 0; i < pano.layer(l).present.size(); ++i) {
        if (!pano.layer(l).present[i]) continue;
        const float* a = &pano.layer(l).normal[3 * i];
        const float* b = &out.layer(l).normal[3 * i];
        const bool unlit = a[0] == 0 && a[1] == 0 && a[2] == 0;
        if (unlit && channels == 4) {
          EXPECT_TRUE(b[0] == 0 && b[1] == 0 && b[2] == 0) << i;
        } else if (!unlit) {
          EXPECT_GT(a[0] * b[0] + a[1] * b[1] + a[2] * b[2], std::cos(0.92 * 3.14159265 / 180)) << i;
        }
      }
    }
  }
  // A lossless-size image is the wrong size for lossy normals.
  Image8 narrow(48, 64, 3);
  EXPECT_FALSE(
      DecodeTileImage(V(narrow), TileImageKind::kNormal, 0, 0, 48, 32, decoder, &pano).ok());
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
  depth.at(1, 1, 0) = 0x04;  // Code 1024 > 1023 at a present node.
  out.layer(kFront).present[out.index(1, 1)] = 1;
  ASSERT_TRUE(DecodeTileImage(V(depth), TileImageKind::kDepth, 0, 0, 16, 16, decoder, &out).ok());
  EXPECT_EQ(FinishDecodedPanorama(&out).code(), StatusCode::kInvalidData);
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
        float reference[3];
        if (!DecodeOctahedral(code, q.normal, reference)) {
          EXPECT_TRUE(std::isnan(decoder.Normal(code)[0])) << c0 << ", " << c1;
          continue;
        }
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

// Invalid depth and normal codes are refused at present nodes, naming the
// first (front layer first, then row by row) and its image kind, and ignored
// and cleared at absent nodes (spec/package.md Sec. 5).
TEST(TileCodecTest, InvalidCodesAreRefusedAtPresentNodesAndClearedAtAbsentOnes) {
  TileQuantization q;
  q.depth.bits = 10;
  q.normal.bits = 6;
  const TileDecoder decoder(q);
  auto decode = [&](const Image8& depth, const Image8& normal, TwoLayerPanorama* out,
                    DecodedNodeProblem* problem) {
    Image8 graph(16, 8, 3, 0);
    for (int y = 0; y < 8; ++y)
      for (int x = 0; x < 16; ++x) graph.at(x, y, 2) = (x + y) % 2 ? 1 : 3;  // Front, some back.
    EXPECT_TRUE(DecodeTileImage(V(graph), TileImageKind::kGraph, 0, 0, 16, 8, decoder, out).ok());
    EXPECT_TRUE(DecodeTileImage(V(depth), TileImageKind::kDepth, 0, 0, 16, 8, decoder, out).ok());
    EXPECT_TRUE(DecodeTileImage(V(normal), TileImageKind::kNormal, 0, 0, 16, 8, decoder, out).ok());
    return FinishDecodedPanorama(out, 1, ReaderChecks(), problem);
  };
  Image8 depth(16, 16, 3, 0), normal(16, 16, 4, 0);
  for (int y = 0; y < 16; ++y)
    for (int x = 0; x < 16; ++x) depth.at(x, y, 1) = 9;  // Code 9 everywhere.
  normal.at(1, 8 + 0, 0) = 70;   // Back (1, 0) is absent: 70 > 63 is ignored.
  depth.at(3, 8 + 0, 0) = 0xff;  // Back (3, 0) is absent: code 65289 is ignored.
  depth.at(2, 8 + 1, 1) = 0;     // Back (2, 1) is absent: code 0 is fine.
  depth.at(5, 3, 2) = 77;        // The unused B channel is ignored.
  TwoLayerPanorama out(16, 8);
  DecodedNodeProblem problem;
  Status s = decode(depth, normal, &out, &problem);
  ASSERT_TRUE(s.ok()) << s.ToString();
  EXPECT_EQ(out.layer(kBack).depth_m[out.index(3, 0)], 0.0f);
  EXPECT_EQ(out.layer(kBack).normal[3 * out.index(1, 0)], 0.0f);
  EXPECT_EQ(out.layer(kFront).depth_m[out.index(5, 3)], out.layer(kFront).depth_m[out.index(4, 3)]);

  normal.at(5, 3, 0) = 7;         // Front (5, 3): one zero coordinate.
  normal.at(2, 8 + 2, 1) = 70;    // Back (2, 2), present: after every front node.
  depth.at(9, 6, 0) = 0x05;       // Front (9, 6): code 1289 > 1023, a later row.
  s = decode(depth, normal, &out, &problem);
  EXPECT_EQ(s.code(), StatusCode::kInvalidData);
  EXPECT_NE(s.message().find("front node at pixel (5, 3) has an invalid octahedral normal code"),
            std::string::npos)
      << s.message();
  EXPECT_EQ(problem.kind, TileImageKind::kNormal);
  normal.at(5, 3, 0) = 0;
  s = decode(depth, normal, &out, &problem);
  EXPECT_NE(s.message().find("front node at pixel (9, 6) has a depth code above the maximum"),
            std::string::npos)
      << s.message();
  EXPECT_EQ(problem.kind, TileImageKind::kDepth);
  EXPECT_EQ(problem.x, 9);
  EXPECT_EQ(problem.y, 6);
  depth.at(9, 6, 0) = 0;
  s = decode(depth, normal, &out, &problem);
  EXPECT_NE(s.message().find("back node at pixel (2, 2) has an invalid octahedral"),
            std::string::npos)
      << s.message();
}

// Each named check switched off: the value it would refuse is read as
// documented in tile_codec.h.
TEST(TileCodecTest, ChecksSwitchedOff) {
  TileQuantization q;
  q.depth.bits = 8;
  q.normal.bits = 4;
  Image8 depth(2, 4, 3, 0), normal(2, 4, 3, 0), graph(2, 2, 3, 0), wide(3, 4, 3, 0);
  for (int x = 0; x < 2; ++x) graph.at(x, 0, 2) = 1;  // Front nodes in row 0.
  depth.at(0, 0, 0) = 1;      // Code 256 > 255.
  depth.at(1, 0, 1) = 0;      // Code 0 at a present node.
  normal.at(0, 0, 0) = 3;     // (3, 0): invalid.
  graph.at(1, 1, 2) = 0x40;   // Reserved bit at an absent pixel.
  auto run = [&](const ReaderChecks& checks, TwoLayerPanorama* out) {
    const TileDecoder decoder(q, checks);
    Status s = DecodeTileImage(V(graph), TileImageKind::kGraph, 0, 0, 2, 2, decoder, out);
    if (s.ok()) s = DecodeTileImage(V(wide), TileImageKind::kColor, 0, 0, 2, 2, decoder, out);
    if (s.ok()) s = DecodeTileImage(V(depth), TileImageKind::kDepth, 0, 0, 2, 2, decoder, out);
    if (s.ok()) s = DecodeTileImage(V(normal), TileImageKind::kNormal, 0, 0, 2, 2, decoder, out);
    if (s.ok()) s = FinishDecodedPanorama(out, 1, checks);
    return s;
  };
  TwoLayerPanorama out(2, 2);
  EXPECT_NE(run(ReaderChecks(), &out).message().find("reserved flag bits"), std::string::npos);
  ReaderChecks off;
  off.Disable(ReaderCheck::kReservedFlagBits);
  EXPECT_NE(run(off, &out).message().find("color image is 3x4, expected 2x4"), std::string::npos)
      << run(off, &out).message();
  off.Disable(ReaderCheck::kWrongTileSize);
  EXPECT_NE(run(off, &out).message().find("(0, 0) has a depth code above"), std::string::npos);
  off.Disable(ReaderCheck::kDepthCodeAboveMax);
  EXPECT_NE(run(off, &out).message().find("(0, 0) has an invalid octahedral"), std::string::npos);
  off.Disable(ReaderCheck::kNormalCodeInvalid);
  EXPECT_NE(run(off, &out).message().find("(1, 0) has no depth (code 0)"), std::string::npos);
  off.Disable(ReaderCheck::kPresentNodeWithoutDepth);
  ASSERT_TRUE(run(off, &out).ok()) << run(off, &out).ToString();
  EXPECT_EQ(out.layer(kFront).depth_m[0], static_cast<float>(DequantizeDepth(255, q.depth)));
  EXPECT_EQ(out.layer(kFront).normal[0], 0.0f);
  EXPECT_EQ(out.layer(kFront).depth_m[1], 0.0f);
}

// WebpContainerCoding reads the RIFF chunks only: simple lossy and lossless
// files, the extended form (VP8X, then ALPH and VP8, or VP8L), animations and
// malformed containers.
TEST(TileCodecTest, WebpContainerCodingTellsLosslessFromLossy) {
  auto file = [](std::vector<std::pair<std::string, uint32_t>> chunks) {
    std::vector<uint8_t> out = {'R', 'I', 'F', 'F', 0, 0, 0, 0, 'W', 'E', 'B', 'P'};
    for (const auto& [tag, size] : chunks) {
      out.insert(out.end(), tag.begin(), tag.end());
      for (int i = 0; i < 4; ++i) out.push_back(static_cast<uint8_t>(size >> (8 * i)));
      out.resize(out.size() + size + (size & 1), 0);
    }
    const uint32_t riff = static_cast<uint32_t>(out.size() - 8);
    for (int i = 0; i < 4; ++i) out[4 + i] = static_cast<uint8_t>(riff >> (8 * i));
    return out;
  };
  auto coding = [](const std::vector<uint8_t>& b) { return WebpContainerCoding(b.data(), b.size()); };
  EXPECT_EQ(coding(file({{"VP8L", 5}})), WebpCoding::kLossless);
  EXPECT_EQ(coding(file({{"VP8 ", 10}})), WebpCoding::kLossy);
  EXPECT_EQ(coding(file({{"VP8X", 10}, {"ICCP", 3}, {"VP8L", 5}})), WebpCoding::kLossless);
  EXPECT_EQ(coding(file({{"VP8X", 10}, {"ALPH", 7}, {"VP8 ", 10}})), WebpCoding::kLossy);
  EXPECT_EQ(coding(file({{"VP8X", 10}, {"ANIM", 6}, {"ANMF", 30}})), WebpCoding::kNotStill);
  EXPECT_EQ(coding(file({{"ALPH", 7}, {"VP8L", 5}})), WebpCoding::kNotWebp);  // No VP8X first.
  EXPECT_EQ(coding(file({{"VP8X", 10}})), WebpCoding::kNotWebp);             // No image.
  std::vector<uint8_t> truncated = file({{"VP8X", 10}, {"VP8L", 5}});
  truncated.resize(30);  // Ends inside the VP8X chunk.
  EXPECT_EQ(coding(truncated), WebpCoding::kNotWebp);
  EXPECT_EQ(WebpContainerCoding(truncated.data(), 12), WebpCoding::kNotWebp);
}

// Ties round half up (away from zero; every argument is >= 0), package.md
// Sec. 4.2 and 4.3: 4-bit normals put u = 0.5 at (0.5 + 1) / 2 * 14 = 10.5,
// coded 1 + 11; 8-bit depths with far / near = 16 put d = 8 near at 254 *
// 0.75 = 190.5, coded 1 + 191.
TEST(TileCodecTest, TiesRoundHalfUp) {
  NormalQuantization n;
  n.bits = 4;
  const float diagonal[3] = {0.70710677f, 0.70710677f, 0.0f};
  uint8_t code[2];
  EncodeOctahedral(diagonal, n, code);
  EXPECT_EQ(code[0], 12);
  EXPECT_EQ(code[1], 12);
  DepthQuantization d;
  d.near_m = 1.0;
  d.far_m = 16.0;
  d.bits = 8;
  ASSERT_EQ(std::log(8.0) / std::log(16.0) * 254, 190.5);  // An exact tie.
  EXPECT_EQ(QuantizeDepth(8.0, d), 192);
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
    // Two bad present nodes in different chunks: the first is named.
    TwoLayerPanorama bad = reference;
    bad.layer(kFront).depth_m[bad.index(30, 60)] = 0.0f;
    bad.layer(kFront).depth_m[bad.index(3, 5)] = -1.0f;
    const Status d = FinishDecodedPanorama(&bad, threads);
    EXPECT_NE(d.message().find("(3, 5) has a depth code above"), std::string::npos)
        << threads << ": " << d.message();
  }
}

}  // namespace
}  // namespace casual3d

#include "reconstruct/stitch/stitch.h"

#include <cmath>
#include <random>
#include <utility>

#include <gtest/gtest.h>

#include "reconstruct/warp/test_scene.h"

namespace casual3d::stitch {
namespace {

namespace wt = warp::testing;

struct Capture {
  std::vector<Image8> rgb;
  std::vector<ImageF> depth;
  std::vector<warp::SourceView> views;
  std::vector<ViewGeometry> geometry;
};

// Four cameras on a small cross around the centre, all looking forward.
Capture MakeCapture(const wt::SquareScene& scene) {
  const Eigen::Vector3d centres[] = {{0.15, 0, 0}, {-0.15, 0, 0}, {0, 0.15, 0}, {0, -0.15, 0}};
  Capture cap;
  cap.rgb.resize(4);
  cap.depth.resize(4);
  for (int i = 0; i < 4; ++i) {
    const geometry::Camera cam = wt::MakeCamera(320, 240, 70.0);
    const geometry::Pose pose = wt::ForwardPose(centres[i]);
    wt::RenderSquareScene(scene, cam, pose, &cap.depth[i], &cap.rgb[i]);
    cap.geometry.push_back({{centres[i].x(), centres[i].y(), centres[i].z()}});
  }
  for (int i = 0; i < 4; ++i) {
    cap.views.push_back({&cap.rgb[i], &cap.depth[i], wt::MakeCamera(320, 240, 70.0),
                         wt::ForwardPose(centres[i])});
  }
  return cap;
}

std::vector<warp::WarpedView> Warp(const Capture& cap, int width) {
  warp::WarpOptions options;
  options.pano_width = width;
  options.pano_height = width / 2;
  std::vector<warp::WarpedView> warps;
  for (const warp::SourceView& view : cap.views) warps.push_back(warp::WarpView(view, PanoramaFrame(), options));
  return warps;
}

// The labelling solved at 256x128 for the tests' 1024x512 panoramas.
StitchOptions SmallSolve() {
  StitchOptions options;
  options.solve_width = 256;
  options.solve_height = 128;
  return options;
}

// The front layer (1024x512) stitched from the same warps twice: with the
// options of SmallSolve, and with `change` made to them.
struct TwoFronts {
  std::vector<warp::WarpedView> full;  // The warps at 1024x512.
  StitchedLayer defaults, changed;
};
template <typename Change>
TwoFronts StitchFrontTwice(const Capture& cap, Change&& change) {
  const int W = 1024;
  StitchOptions options = SmallSolve();
  const auto coarse = Warp(cap, options.solve_width);
  TwoFronts out;
  out.full = Warp(cap, W);
  out.defaults = StitchFront(out.full, coarse, cap.geometry, W, options);
  change(&options);
  out.changed = StitchFront(out.full, coarse, cap.geometry, W, options);
  return out;
}

TEST(StitchTest, FrontAndBackLayersMatchTheScene) {
  wt::SquareScene scene;
  Capture cap = MakeCapture(scene);
  // A floater in photo 0: a blob of wrong, near depth on the background.
  for (int y = 30; y < 60; ++y)
    for (int x = 250; x < 290; ++x) cap.depth[0].at(x, y) *= 0.5f;

  const StitchOptions options = SmallSolve();
  const int W = 1024;
  const auto full = Warp(cap, W);
  const auto coarse = Warp(cap, options.solve_width);
  const StitchedLayer front = StitchFront(full, coarse, cap.geometry, W, options);
  const StitchedLayer back = StitchBack(full, coarse, cap.geometry, front, options);

  // Front: within the photos' common field of view, the depth is the true
  // first surface almost everywhere (the floater is rejected by GC).
  int checked = 0, good = 0, floater = 0;
  int behind = 0, behind_ok = 0;
  for (int y = 200; y < 312; ++y) {
    for (int x = 420; x < 604; ++x) {
      const Vec3d d = EquirectPixelToDirection(x + 0.5, y + 0.5, W, W / 2);
      const double truth = wt::SquareSceneRadialDepth(scene, d);
      // Skip pixels within 1.5 pixels of a true depth edge (sampling ambiguity).
      bool edge = false;
      for (double oy : {-1.5, 1.5})
        for (double ox : {-1.5, 1.5}) {
          const Vec3d e = EquirectPixelToDirection(x + 0.5 + ox, y + 0.5 + oy, W, W / 2);
          edge |= std::abs(wt::SquareSceneRadialDepth(scene, e) - truth) > 0.1 * truth;
        }
      if (edge) continue;
      const float est = front.depth_m.at(x, y);
      ASSERT_GT(est, 0) << x << "," << y;
      ++checked;
      if (std::abs(est - truth) < 0.01 * truth) ++good;
      if (est < 0.85 * truth) ++floater;
      // Back: where the front is the square, the back is the plane wherever
      // some photo saw behind the square's edge.
      if (truth < 2.0 && back.depth_m.at(x, y) > 0) {
        ++behind;
        if (back.depth_m.at(x, y) > 3.5f) ++behind_ok;
      }
      if (back.depth_m.at(x, y) > 0) {
        EXPECT_GE(back.depth_m.at(x, y), est * 0.97f) << "back in front of front at " << x << "," << y;
      }
    }
  }
  EXPECT_GT(good, checked * 97 / 100);
  EXPECT_EQ(floater, 0);
  EXPECT_GT(behind_ok, 200);
  EXPECT_EQ(front.label.width(), W);
  EXPECT_GE(front.energy, 0.0);
}

TEST(StitchTest, BlendingAveragesTheWarpsThatAgreeInDepth) {
  wt::SquareScene scene;
  Capture cap = MakeCapture(scene);
  // Photo i is brighter by 12 i in red (an exposure difference) and has its
  // own depth noise of up to 1%; photo 0 also has a floater: near depth and
  // red 250 on a patch of the background.
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> noise(-0.01f, 0.01f);
  for (int i = 0; i < 4; ++i)
    for (float& d : cap.depth[i].vector()) d *= 1.0f + noise(rng);
  for (int i = 0; i < 4; ++i)
    for (int y = 0; y < 240; ++y)
      for (int x = 0; x < 320; ++x) cap.rgb[i].at(x, y, 0) += static_cast<uint8_t>(12 * i);
  for (int y = 30; y < 60; ++y) {
    for (int x = 250; x < 290; ++x) {
      cap.depth[0].at(x, y) *= 0.5f;
      cap.rgb[0].at(x, y, 0) = 250;
    }
  }
  const int W = 1024;
  const TwoFronts fronts = StitchFrontTwice(cap, [](StitchOptions* o) { o->blend_depth_tolerance = 0; });
  const StitchedLayer& single = fronts.changed;
  const StitchedLayer& blended = fronts.defaults;

  // On the background plane seen by all four photos, away from the square and
  // the floater, the depth is the plane's and the blended red is the plain scene's (10) plus the mean
  // offset (18); unblended, it is one photo's (10 + 12 i).
  int checked = 0, near_mean = 0, single_is_one_photo = 0;
  double single_sq = 0, blended_sq = 0;
  for (int y = 230; y < 282; ++y) {
    for (int x = 440; x < 584; ++x) {
      const Vec3d d = EquirectPixelToDirection(x + 0.5, y + 0.5, W, W / 2);
      if (wt::SquareSceneRadialDepth(scene, d) < 3.0) continue;
      const double truth = wt::SquareSceneRadialDepth(scene, d);
      ASSERT_NEAR(blended.depth_m.at(x, y), truth, 0.01 * truth) << x << "," << y;
      single_sq += std::pow(single.depth_m.at(x, y) / truth - 1, 2);
      blended_sq += std::pow(blended.depth_m.at(x, y) / truth - 1, 2);
      int seen = 0;
      for (const warp::WarpedView& v : fronts.full) {
        int cx, cy;
        seen += v.front.ToCrop(x, y, W, &cx, &cy) && v.front.depth_m.at(cx, cy) > 0;
      }
      if (seen < 4) continue;
      ++checked;
      near_mean += std::abs(blended.rgb.at(x, y, 0) - 28) <= 3;
      const int s = single.rgb.at(x, y, 0) - 10;
      single_is_one_photo += s >= -1 && s <= 37 && (s + 1) % 12 <= 2;
    }
  }
  ASSERT_GT(checked, 500);
  EXPECT_GT(near_mean, checked * 95 / 100);
  EXPECT_GT(single_is_one_photo, checked * 95 / 100);
  // The photos' independent depth noise averages out (four photos: about
  // half the error).
  EXPECT_LT(std::sqrt(blended_sq / checked), 0.7 * std::sqrt(single_sq / checked));
  // The floater's colour never reaches the blended background: photo 0's
  // warp there is at half the depth, outside the tolerance.
  for (int y = 0; y < W / 2; ++y) {
    for (int x = 0; x < W; ++x) {
      if (blended.depth_m.at(x, y) > 3.0f) {
        ASSERT_LT(blended.rgb.at(x, y, 0), 60) << x << "," << y;
      }
    }
  }
}

// Photos 2 and 3 miss the square (their depth maps and colours show the
// plane behind it), as real depth maps miss a thin structure that others
// hold; photos 0 and 1 see it.
Capture SquareMissedByTwo(const wt::SquareScene& scene) {
  Capture cap = MakeCapture(scene);
  wt::SquareScene no_square = scene;
  no_square.half_size = 0;
  for (int i = 2; i < 4; ++i)
    wt::RenderSquareScene(no_square, cap.views[i].camera, cap.views[i].pose, &cap.depth[i], &cap.rgb[i]);
  return cap;
}

// The front stitched with the SmallSolve options and front_support `support`.
StitchedLayer FrontWithSupport(const Capture& cap, const std::vector<warp::WarpedView>& full,
                               const std::vector<warp::WarpedView>& coarse, int W, int support) {
  StitchOptions options = SmallSolve();
  options.front_support = support;
  return StitchFront(full, coarse, cap.geometry, W, options);
}

TEST(StitchTest, FrontKeepsANearSurfaceTwoPhotosAgreeOn) {
  const wt::SquareScene scene;
  const Capture cap = SquareMissedByTwo(scene);
  const int W = 1024;
  const auto full = Warp(cap, W);
  const auto coarse = Warp(cap, SmallSolve().solve_width);
  const StitchedLayer kept = FrontWithSupport(cap, full, coarse, W, 2);
  const StitchedLayer labelled = FrontWithSupport(cap, full, coarse, W, 0);

  // Where the square's interior is seen by both photos 0 and 1 (unstretched),
  // the front holds it; the labelling alone shows the plane at some of them.
  int checked = 0, kept_near = 0, labelled_near = 0;
  for (int y = 0; y < W / 2; ++y) {
    for (int x = 0; x < W; ++x) {
      const Vec3d d = EquirectPixelToDirection(x + 0.5, y + 0.5, W, W / 2);
      const double truth = wt::SquareSceneRadialDepth(scene, d);
      if (!(truth > 0 && truth < 2.0)) continue;
      // Away from the square's edges.
      const Vec3d e = EquirectPixelToDirection(x + 4.5, y + 4.5, W, W / 2);
      const Vec3d f = EquirectPixelToDirection(x - 3.5, y - 3.5, W, W / 2);
      if (!(wt::SquareSceneRadialDepth(scene, e) < 2.0 && wt::SquareSceneRadialDepth(scene, f) < 2.0)) continue;
      int seen = 0;
      for (int i = 0; i < 2; ++i) {
        int cx, cy;
        seen += full[i].front.ToCrop(x, y, W, &cx, &cy) &&
                std::abs(full[i].front.depth_m.at(cx, cy) / truth - 1) < 0.01 &&
                full[i].front.stretch.at(cx, cy) < 0.1f;
      }
      if (seen < 2) continue;
      ++checked;
      kept_near += std::abs(kept.depth_m.at(x, y) / truth - 1) < 0.02 && kept.rgb.at(x, y, 0) > 200;
      labelled_near += std::abs(labelled.depth_m.at(x, y) / truth - 1) < 0.02;
    }
  }
  ASSERT_GT(checked, 2000);
  EXPECT_EQ(kept_near, checked);
  EXPECT_LT(labelled_near, checked);
}

TEST(StitchTest, StretchedFragmentsDoNotSupportANearSurface) {
  // As above, but photo 1's warp of the square is made of moderately
  // stretched fragments (stretch 0.35, as along a depth map's fattened edge
  // against the sky): photo 0 alone then holds the square unstretched, which
  // is not enough, and the front is the labelling's.
  const Capture cap = SquareMissedByTwo(wt::SquareScene());
  const int W = 1024;
  auto full = Warp(cap, W);
  auto coarse = Warp(cap, SmallSolve().solve_width);
  int stretched = 0;
  for (auto* warps : {&full, &coarse}) {
    warp::WarpedLayer& layer = (*warps)[1].front;
    for (int y = 0; y < layer.depth_m.height(); ++y)
      for (int x = 0; x < layer.depth_m.width(); ++x)
        if (layer.depth_m.at(x, y) > 0 && layer.depth_m.at(x, y) < 2.0f) {
          layer.stretch.at(x, y) = std::max(layer.stretch.at(x, y), 0.35f);
          ++stretched;
        }
  }
  ASSERT_GT(stretched, 2000);
  const StitchedLayer ruled = FrontWithSupport(cap, full, coarse, W, 2);
  const StitchedLayer labelled = FrontWithSupport(cap, full, coarse, W, 0);
  // The rule has something to change: the labelling shows the plane behind
  // the square where photo 0 holds the square unstretched.
  int plane_behind = 0;
  for (int y = 0; y < W / 2; ++y) {
    for (int x = 0; x < W; ++x) {
      int cx, cy;
      plane_behind += full[0].front.ToCrop(x, y, W, &cx, &cy) && full[0].front.depth_m.at(cx, cy) > 0 &&
                      full[0].front.depth_m.at(cx, cy) < 2.0f && full[0].front.stretch.at(cx, cy) < 0.1f &&
                      labelled.depth_m.at(x, y) > 2.0f;
    }
  }
  ASSERT_GT(plane_behind, 100);
  EXPECT_EQ(ruled.depth_m.vector(), labelled.depth_m.vector());
  EXPECT_EQ(ruled.label.vector(), labelled.label.vector());
}

// A plain wall seen by four photos of different exposures: where the set of
// blended photos changes (at the border of a photo's field of view), the
// blend jumps by the exposure difference; the seam blend evens the jumps out
// and keeps the colours within the photos' range.
TEST(StitchTest, SeamsBetweenPhotosOfDifferentExposureFade) {
  wt::SquareScene scene;
  scene.half_size = 0;  // The plane alone.
  Capture cap = MakeCapture(scene);
  for (int i = 0; i < 4; ++i) {
    for (int y = 0; y < 240; ++y) {
      for (int x = 0; x < 320; ++x) {
        cap.rgb[i].at(x, y, 0) = static_cast<uint8_t>(80 + 25 * i);
        cap.rgb[i].at(x, y, 1) = 100;
        cap.rgb[i].at(x, y, 2) = static_cast<uint8_t>(150 - 10 * i);
      }
    }
  }
  const int W = 1024;
  const TwoFronts fronts = StitchFrontTwice(cap, [](StitchOptions* o) { o->seam_blend_length = 0; });
  const StitchedLayer& plain = fronts.changed;
  const StitchedLayer& blended = fronts.defaults;

  // Steps of more than 2 levels between labelled neighbours, in any channel.
  auto jumps = [&](const StitchedLayer& layer) {
    int n = 0;
    for (int y = 0; y + 1 < W / 2; ++y) {
      for (int x = 0; x + 1 < W; ++x) {
        if (layer.label.at(x, y) < 0) continue;
        for (const auto& [qx, qy] : {std::pair{x + 1, y}, std::pair{x, y + 1}}) {
          if (layer.label.at(qx, qy) < 0) continue;
          bool jump = false;
          for (int c = 0; c < 3; ++c) jump |= std::abs(layer.rgb.at(qx, qy, c) - layer.rgb.at(x, y, c)) > 2;
          n += jump;
        }
      }
    }
    return n;
  };
  const int before = jumps(plain), after = jumps(blended);
  EXPECT_GT(before, 200);
  EXPECT_LT(after, before / 20) << before;
  for (int y = 0; y < W / 2; ++y) {
    for (int x = 0; x < W; ++x) {
      if (blended.label.at(x, y) < 0) continue;
      ASSERT_EQ(blended.label.at(x, y), plain.label.at(x, y));
      ASSERT_EQ(blended.depth_m.at(x, y), plain.depth_m.at(x, y));
      ASSERT_GE(blended.rgb.at(x, y, 0), 78);
      ASSERT_LE(blended.rgb.at(x, y, 0), 157);
    }
  }
}

TEST(StitchTest, OptionsAreChecked) {
  StitchOptions options;
  EXPECT_TRUE(options.Check().ok());
  options.solve_width = 300;
  EXPECT_FALSE(options.Check().ok());
  options = StitchOptions();
  options.gc_depth_tolerance = 0;
  EXPECT_FALSE(options.Check().ok());
  options = StitchOptions();
  options.blend_depth_tolerance = 1;
  EXPECT_FALSE(options.Check().ok());
  options = StitchOptions();
  options.front_support = -1;
  EXPECT_FALSE(options.Check().ok());
  options.front_support = 1;
  EXPECT_FALSE(options.Check().ok());
  options.front_support = 0;
  EXPECT_TRUE(options.Check().ok());
}

}  // namespace
}  // namespace casual3d::stitch

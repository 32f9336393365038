#include "reconstruct/depth/fullres_refine.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <stdexcept>
#include <vector>

#include "reconstruct/depth/plane_sweep.h"
#include "reconstruct/depth/testing/toy_scene.h"

namespace casual3d::depth {
namespace {

using testing::MakeView;
using testing::ToyCamera;
using testing::ToyScene;

constexpr int kWidth = 160, kHeight = 120;
constexpr double kFocal = 200.0;

double Median(std::vector<double> v) {
  std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
  return v[v.size() / 2];
}

// The sweep's label grid: 60 labels uniform in inverse depth between 1 and
// 20 m (only the grid fields of the volume are used). One label is a
// disparity of about 0.64 px for the 0.2 m baseline below.
CostVolume LabelGrid() {
  CostVolume grid;
  grid.width = kWidth;
  grid.height = kHeight;
  grid.num_labels = 60;
  grid.inv_near = 1.0;
  grid.inv_far = 1.0 / 20.0;
  return grid;
}

double InvStep(const CostVolume& grid) {
  return (grid.inv_near - grid.inv_far) / (grid.num_labels - 1);
}

// A reference view and four neighbours (left, right, up, down; 0.2 m and
// 0.15 m baselines) with different exposures. The views are rendered at the
// "full" resolution itself: gray / camera stand for gray_full / camera_full.
struct Rig {
  DenseView ref;
  std::vector<DenseView> nbs;
  ImageF gt;  // Reference depth, metres.

  std::vector<RefineNeighbor> Neighbors() const {
    std::vector<RefineNeighbor> out;
    for (const DenseView& v : nbs) out.push_back({&v.gray, v.camera});
    return out;
  }
};

Rig MakeRig(const ToyScene& scene, double baseline = 0.2) {
  Rig rig;
  const DepthRange range{1.0, 20.0};
  rig.ref =
      MakeView(scene, ToyCamera({0, 0, 0}, kWidth, kHeight, kFocal), range, 1.0, 0.0, &rig.gt);
  rig.nbs.push_back(
      MakeView(scene, ToyCamera({baseline, 0, 0}, kWidth, kHeight, kFocal), range, 1.3, -0.08));
  rig.nbs.push_back(
      MakeView(scene, ToyCamera({-baseline, 0, 0}, kWidth, kHeight, kFocal), range, 0.8, 0.1));
  rig.nbs.push_back(MakeView(scene, ToyCamera({0, 0.75 * baseline, 0}, kWidth, kHeight, kFocal),
                             range, 1.1, 0.0));
  rig.nbs.push_back(MakeView(scene, ToyCamera({0, -0.75 * baseline, 0}, kWidth, kHeight, kFocal),
                             range, 0.9, 0.05));
  return rig;
}

// A textured plane at depth z covering every view.
Rig MakePlaneRig(double z) {
  ToyScene scene;
  scene.rects.push_back({z, -50, 50, -50, 50, 15.0, 5});
  return MakeRig(scene);
}

ImageF ConstantDepth(double z) { return ImageF(kWidth, kHeight, 1, static_cast<float>(z)); }

long long CountChanged(const ImageF& a, const ImageF& b) {
  long long n = 0;
  for (size_t i = 0; i < a.size(); ++i) n += a.data()[i] != b.data()[i];
  return n;
}

bool SameImage(const ImageF& a, const ImageF& b) {
  return a.width() == b.width() && a.height() == b.height() && a.channels() == b.channels() &&
         CountChanged(a, b) == 0;
}

TEST(FullResRefineOptions, DefaultsAreValid) {
  EXPECT_TRUE(FullResRefineOptions().Check().ok());
  EXPECT_TRUE(BoundaryRelabelOptions().Check().ok());
}

TEST(FullResRefineOptions, RejectsOutOfRangeValues) {
  auto bad = [](auto edit) {
    FullResRefineOptions o;
    edit(&o);
    return !o.Check().ok();
  };
  EXPECT_TRUE(bad([](FullResRefineOptions* o) { o->window_radius = 0; }));
  EXPECT_TRUE(bad([](FullResRefineOptions* o) { o->window_radius = 16; }));
  EXPECT_TRUE(bad([](FullResRefineOptions* o) { o->search_labels = 0.0; }));
  EXPECT_TRUE(bad([](FullResRefineOptions* o) { o->search_labels = 8.5; }));
  EXPECT_TRUE(bad([](FullResRefineOptions* o) { o->steps = 8; }));  // Even.
  EXPECT_TRUE(bad([](FullResRefineOptions* o) { o->steps = 1; }));
  EXPECT_TRUE(bad([](FullResRefineOptions* o) { o->steps = 67; }));
  EXPECT_TRUE(bad([](FullResRefineOptions* o) { o->best_k = 0; }));
  EXPECT_TRUE(bad([](FullResRefineOptions* o) { o->occlusion_truncation = 1.5; }));
  EXPECT_TRUE(bad([](FullResRefineOptions* o) { o->ncc_epsilon = -1.0; }));
  EXPECT_TRUE(bad([](FullResRefineOptions* o) { o->texture_sigma = 0.0; }));
  EXPECT_TRUE(bad([](FullResRefineOptions* o) { o->min_texture = NAN; }));
}

TEST(BoundaryRelabelOptions, RejectsOutOfRangeValues) {
  auto bad = [](auto edit) {
    BoundaryRelabelOptions o;
    edit(&o);
    return !o.Check().ok();
  };
  EXPECT_TRUE(bad([](BoundaryRelabelOptions* o) { o->radius = 0; }));
  EXPECT_TRUE(bad([](BoundaryRelabelOptions* o) { o->radius = 33; }));
  EXPECT_TRUE(bad([](BoundaryRelabelOptions* o) { o->window_radius = 0; }));
  EXPECT_TRUE(bad([](BoundaryRelabelOptions* o) { o->window_step = 7; }));  // Above window_radius.
  EXPECT_TRUE(bad([](BoundaryRelabelOptions* o) { o->window_step = 0; }));
  EXPECT_TRUE(bad([](BoundaryRelabelOptions* o) { o->min_jump_labels = -1.0; }));
  EXPECT_TRUE(bad([](BoundaryRelabelOptions* o) { o->sigma_color = 0.0; }));
  EXPECT_TRUE(bad([](BoundaryRelabelOptions* o) { o->min_gain = 2.0; }));
  EXPECT_TRUE(bad([](BoundaryRelabelOptions* o) { o->best_k = 17; }));
  EXPECT_TRUE(bad([](BoundaryRelabelOptions* o) { o->max_neighbors = 0; }));
  EXPECT_TRUE(bad([](BoundaryRelabelOptions* o) { o->texture_sigma = 0.0; }));
  EXPECT_TRUE(bad([](BoundaryRelabelOptions* o) { o->min_texture = 1.5; }));
}

// A plane 0.4 labels from the nearest label, starting at that label's depth:
// the search around the current depth moves it close to the truth.
TEST(RefineFullResolution, LocatesAPlaneBetweenLabels) {
  const CostVolume grid = LabelGrid();
  const double z = grid.DepthOfLabel(30.4);
  const Rig rig = MakePlaneRig(z);
  const double truth = grid.LabelOfDepth(z);
  ASSERT_NEAR(truth, 30.4, 1e-6);
  const ImageF start = ConstantDepth(grid.DepthOfLabel(30));
  FullResRefineOptions opt;
  FullResRefineStats stats;
  const ImageF refined = RefineFullResolution(rig.ref.gray, rig.ref.camera, start, rig.Neighbors(),
                                              InvStep(grid), opt, 2, &stats);
  ASSERT_EQ(refined.width(), kWidth);
  ASSERT_EQ(refined.height(), kHeight);
  std::vector<double> err_start, err_refined;
  double max_move = 0;
  for (int y = 0; y < kHeight; ++y)
    for (int x = 0; x < kWidth; ++x) {
      const double k = grid.LabelOfDepth(refined.at(x, y));
      max_move = std::max(max_move, std::abs(k - 30.0));
      if (x < 12 || y < 12 || x >= kWidth - 12 || y >= kHeight - 12) continue;
      err_start.push_back(std::abs(grid.LabelOfDepth(start.at(x, y)) - truth));
      err_refined.push_back(std::abs(k - truth));
    }
  const double m_start = Median(err_start), m_refined = Median(err_refined);
  std::printf(
      "median label error %.4f -> %.4f; max move %.4f labels; refined %lld of %lld textured\n",
      m_start, m_refined, max_move, stats.refined, stats.textured);
  // Measured: 0.4000 -> 0.0092, max move 0.62 labels, all 19200 pixels textured and refined.
  EXPECT_LT(m_refined, 0.05);
  EXPECT_LE(max_move, opt.search_labels + 1e-3);
  EXPECT_EQ(stats.refined, CountChanged(start, refined));
  EXPECT_GT(stats.textured, 0.9 * kWidth * kHeight);
}

// Pixels whose reference window is uniform (no texture) keep their depth
// exactly; the textured pixels around them move.
TEST(RefineFullResolution, LeavesUntexturedPixelsAlone) {
  const CostVolume grid = LabelGrid();
  Rig rig = MakePlaneRig(grid.DepthOfLabel(30.4));
  // A constant grey block in the reference only.
  const int bx0 = 50, bx1 = 90, by0 = 40, by1 = 80;
  for (int y = by0; y < by1; ++y)
    for (int x = bx0; x < bx1; ++x) rig.ref.gray.at(x, y) = 0.5f;
  const ImageF start = ConstantDepth(grid.DepthOfLabel(30));
  FullResRefineOptions opt;
  FullResRefineStats stats;
  const ImageF refined = RefineFullResolution(rig.ref.gray, rig.ref.camera, start, rig.Neighbors(),
                                              InvStep(grid), opt, 2, &stats);
  const int r = opt.window_radius;
  int flat = 0, flat_kept = 0, outside = 0, outside_moved = 0;
  for (int y = 0; y < kHeight; ++y)
    for (int x = 0; x < kWidth; ++x) {
      if (x >= bx0 + r && x < bx1 - r && y >= by0 + r && y < by1 - r) {
        ++flat;
        flat_kept += refined.at(x, y) == start.at(x, y);
      } else if (x < bx0 - r || x >= bx1 + r || y < by0 - r || y >= by1 + r) {
        ++outside;
        outside_moved += refined.at(x, y) != start.at(x, y);
      }
    }
  std::printf("flat pixels kept %d of %d; textured pixels moved %d of %d; %lld textured\n",
              flat_kept, flat, outside_moved, outside, stats.textured);
  // Measured: 900 of 900 kept, 16700 of 16700 moved, 18300 textured.
  EXPECT_EQ(flat_kept, flat);
  EXPECT_GT(outside_moved, 0.95 * outside);
  EXPECT_LE(stats.textured, static_cast<long long>(kWidth) * kHeight - flat);
  EXPECT_EQ(stats.refined, CountChanged(start, refined));
}

// The search stays within +-search_labels of the current depth, however far
// the truth is: a start three labels off never moves by more than the range.
TEST(RefineFullResolution, StaysWithinTheSearchRange) {
  const CostVolume grid = LabelGrid();
  const Rig rig = MakePlaneRig(grid.DepthOfLabel(30));
  const std::vector<RefineNeighbor> nbs = rig.Neighbors();
  for (double search : {1.0, 2.0}) {
    FullResRefineOptions opt;
    opt.search_labels = search;
    opt.steps = search > 1 ? 17 : 9;
    const ImageF start = ConstantDepth(grid.DepthOfLabel(33));
    const ImageF refined =
        RefineFullResolution(rig.ref.gray, rig.ref.camera, start, nbs, InvStep(grid), opt, 2);
    double max_move = 0;
    int moved = 0;
    for (int y = 0; y < kHeight; ++y)
      for (int x = 0; x < kWidth; ++x) {
        const double move = std::abs(grid.LabelOfDepth(refined.at(x, y)) - 33.0);
        max_move = std::max(max_move, move);
        moved += move > 1e-3;
      }
    std::printf(
        "search +-%.1f labels, truth 3 labels away: max move %.4f labels, %d pixels moved\n",
        search, max_move, moved);
    // Measured: 0.87 and 0.97 labels (180 and 114 pixels moved, at noise minima).
    EXPECT_LE(max_move, search + 1e-3);
  }
  // Within reach (1.5 labels off, search +-2) the start moves to the truth.
  FullResRefineOptions opt;
  opt.search_labels = 2.0;
  opt.steps = 17;
  const ImageF start = ConstantDepth(grid.DepthOfLabel(31.5));
  const ImageF refined =
      RefineFullResolution(rig.ref.gray, rig.ref.camera, start, nbs, InvStep(grid), opt, 2);
  std::vector<double> err;
  for (int y = 12; y < kHeight - 12; ++y)
    for (int x = 12; x < kWidth - 12; ++x)
      err.push_back(std::abs(grid.LabelOfDepth(refined.at(x, y)) - 30.0));
  std::printf("start 1.5 labels off, search +-2: median label error %.4f\n", Median(err));
  // Measured: 0.0063.
  EXPECT_LT(Median(err), 0.05);
}

// Offsets are independent: the result does not depend on the number of threads.
TEST(RefineFullResolution, ThreadCountDoesNotChangeTheResult) {
  const CostVolume grid = LabelGrid();
  const Rig rig = MakePlaneRig(grid.DepthOfLabel(30.4));
  const ImageF start = ConstantDepth(grid.DepthOfLabel(30));
  const FullResRefineOptions opt;
  const ImageF one = RefineFullResolution(rig.ref.gray, rig.ref.camera, start, rig.Neighbors(),
                                          InvStep(grid), opt, 1);
  const ImageF four = RefineFullResolution(rig.ref.gray, rig.ref.camera, start, rig.Neighbors(),
                                           InvStep(grid), opt, 4);
  EXPECT_TRUE(SameImage(one, four));
  EXPECT_GT(CountChanged(start, one), 0);
}

TEST(RefineFullResolution, DisabledOrWithoutNeighboursReturnsTheInput) {
  const CostVolume grid = LabelGrid();
  const Rig rig = MakePlaneRig(grid.DepthOfLabel(30.4));
  const ImageF start = ConstantDepth(grid.DepthOfLabel(30));
  FullResRefineOptions off;
  off.enabled = false;
  EXPECT_TRUE(SameImage(RefineFullResolution(rig.ref.gray, rig.ref.camera, start, rig.Neighbors(),
                                             InvStep(grid), off, 1),
                        start));
  EXPECT_TRUE(SameImage(RefineFullResolution(rig.ref.gray, rig.ref.camera, start, {}, InvStep(grid),
                                             FullResRefineOptions()),
                        start));
}

TEST(RefineFullResolution, RejectsBadOptionsAndSizes) {
  const CostVolume grid = LabelGrid();
  const Rig rig = MakePlaneRig(5.0);
  const std::vector<RefineNeighbor> nbs = rig.Neighbors();
  const ImageF start = ConstantDepth(5.0);
  const double step = InvStep(grid);
  const PinholeCamera& cam = rig.ref.camera;
  const ImageF& gray = rig.ref.gray;
  FullResRefineOptions bad;
  bad.steps = 4;
  EXPECT_THROW(RefineFullResolution(gray, cam, start, nbs, step, bad), std::invalid_argument);
  const FullResRefineOptions opt;
  EXPECT_THROW(
      RefineFullResolution(gray, cam, ImageF(kWidth - 1, kHeight, 1, 5.0f), nbs, step, opt),
      std::invalid_argument);
  EXPECT_THROW(
      RefineFullResolution(gray, cam.Resized(kWidth / 2, kHeight / 2), start, nbs, step, opt),
      std::invalid_argument);
  EXPECT_THROW(RefineFullResolution(rig.ref.color, cam, start, nbs, step, opt),
               std::invalid_argument);
  EXPECT_THROW(RefineFullResolution(gray, cam, start, nbs, 0.0, opt), std::invalid_argument);
  std::vector<RefineNeighbor> missing = nbs;
  missing[1].gray = nullptr;
  EXPECT_THROW(RefineFullResolution(gray, cam, start, missing, step, opt), std::invalid_argument);
  std::vector<RefineNeighbor> resized = nbs;
  resized[0].camera = resized[0].camera.Resized(kWidth * 2, kHeight * 2);
  EXPECT_THROW(RefineFullResolution(gray, cam, start, resized, step, opt), std::invalid_argument);
}

// A near textured board (2 m) in front of a textured wall (6 m) filling the
// view, in different colours (the texture's palette follows the seed): the
// colour weights tell the two apart.
ToyScene BoardScene() {
  ToyScene scene;
  scene.rects.push_back({6.0, -50, 50, -50, 50, 8.0, 11});
  scene.rects.push_back({2.0, -0.3, 0.3, -0.2, 0.2, 20.0, 5});
  return scene;
}

// The depth map with the near side spread `band` pixels (Euclidean) over the
// far side: each pixel takes the nearest depth within that distance; with
// `thin`, the far side spread over the near one instead.
ImageF Fatten(const ImageF& depth, int band, bool thin = false) {
  ImageF out = depth;
  for (int y = 0; y < depth.height(); ++y)
    for (int x = 0; x < depth.width(); ++x)
      for (int dy = -band; dy <= band; ++dy)
        for (int dx = -band; dx <= band; ++dx) {
          const int u = x + dx, v = y + dy;
          if (dx * dx + dy * dy > band * band || u < 0 || v < 0 || u >= depth.width() ||
              v >= depth.height())
            continue;
          out.at(x, y) = thin ? std::max(out.at(x, y), depth.at(u, v))
                              : std::min(out.at(x, y), depth.at(u, v));
        }
  return out;
}

// Pixels whose (2 radius + 1)^2 window holds a single depth.
std::vector<bool> UniformWindows(const ImageF& depth, int radius) {
  const int w = depth.width(), h = depth.height();
  std::vector<bool> out(static_cast<size_t>(w) * h, true);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      for (int v = std::max(0, y - radius); v <= std::min(h - 1, y + radius) && out[y * w + x]; ++v)
        for (int u = std::max(0, x - radius); u <= std::min(w - 1, x + radius); ++u)
          if (depth.at(u, v) != depth.at(x, y)) {
            out[static_cast<size_t>(y) * w + x] = false;
            break;
          }
  return out;
}

// Fattening: the board's depth spread 6 pixels over the wall. Relabelling
// gives most of that band the wall's depth back and keeps the board's own
// pixels; pixels away from depth edges are not touched.
void CheckRemovesFattening(const BoundaryRelabelOptions& opt) {
  const CostVolume grid = LabelGrid();
  const Rig rig = MakeRig(BoardScene());
  const ImageF fat = Fatten(rig.gt, 6);
  long long changed = -1;
  const ImageF out = RelabelBoundaries(rig.ref.color, rig.ref.gray, rig.ref.camera, fat,
                                       rig.Neighbors(), InvStep(grid), opt, 2, &changed);
  const std::vector<bool> uniform = UniformWindows(fat, opt.radius);
  int band = 0, band_fixed = 0, board = 0, board_kept = 0, far = 0, far_untouched = 0;
  for (int y = 0; y < kHeight; ++y)
    for (int x = 0; x < kWidth; ++x) {
      const float truth = rig.gt.at(x, y);
      const double err = std::abs(grid.LabelOfDepth(out.at(x, y)) - grid.LabelOfDepth(truth));
      if (fat.at(x, y) != truth) {
        ++band;
        band_fixed += err <= 1.0;
      } else if (truth < 3.0f) {
        ++board;
        board_kept += out.at(x, y) == truth;
      }
      if (uniform[static_cast<size_t>(y) * kWidth + x]) {
        ++far;
        far_untouched += out.at(x, y) == fat.at(x, y);
      }
    }
  std::printf(
      "band pixels fixed %d of %d (%.1f%%); board pixels kept %d of %d (%.1f%%); changed %lld\n",
      band_fixed, band, 100.0 * band_fixed / band, board_kept, board, 100.0 * board_kept / board,
      changed);
  // Measured: 1288 of 1288 band pixels fixed, 2398 of 2400 board pixels kept, 1290 changed.
  EXPECT_GT(band, 1000);
  EXPECT_GT(far, 0);
  EXPECT_GE(band_fixed, 0.9 * band);
  EXPECT_GE(board_kept, 0.98 * board);
  EXPECT_EQ(far_untouched, far);
  EXPECT_EQ(changed, CountChanged(fat, out));
}

TEST(RelabelBoundaries, RemovesFattening) { CheckRemovesFattening(BoundaryRelabelOptions()); }

// Matching windows whose radius is not a multiple of the sample step (5 and
// 2: samples at -4, -2, ..., 4, the centre among them) and the full window.
// Measured: 1288 of 1288 band pixels fixed in both, 2396 and 2397 of 2400
// board pixels kept.
TEST(RelabelBoundaries, RemovesFatteningWithOtherWindowSamplings) {
  BoundaryRelabelOptions odd;
  odd.window_radius = 5;
  odd.window_step = 2;
  CheckRemovesFattening(odd);
  BoundaryRelabelOptions full;
  full.window_radius = 5;
  full.window_step = 1;
  CheckRemovesFattening(full);
}

// A band window whose radius is not a multiple of its sample step (4): 22
// takes 12 samples a side (-22, -18, ..., 22), more than a radius of 20.
TEST(RelabelBoundaries, RemovesFatteningWithAnOddBandRadius) {
  BoundaryRelabelOptions opt;
  opt.radius = 22;
  CheckRemovesFattening(opt);
}

// A slope is no depth edge: a depth map ramping from 2.5 m to 8 m across a
// textured plane at 4 m spans more than min_jump_labels over every band
// window but steps by a tenth of a label between pixels. Nothing in it is
// tested or changed, even where the wall's depth would match better.
TEST(RelabelBoundaries, LeavesSlopesAlone) {
  const CostVolume grid = LabelGrid();
  const Rig rig = MakePlaneRig(4.0);
  ImageF ramp(kWidth, kHeight, 1);
  for (int y = 0; y < kHeight; ++y)
    for (int x = 0; x < kWidth; ++x) {
      const double inv = 1.0 / 2.5 + (1.0 / 8.0 - 1.0 / 2.5) * x / (kWidth - 1);
      ramp.at(x, y) = static_cast<float>(1.0 / inv);
    }
  const BoundaryRelabelOptions opt;
  // The ramp's span over a band window, in labels: well above min_jump_labels.
  const double span = (1.0 / 2.5 - 1.0 / 8.0) * (2 * opt.radius) / (kWidth - 1) / InvStep(grid);
  ASSERT_GT(span, opt.min_jump_labels);
  long long changed = -1;
  const ImageF out = RelabelBoundaries(rig.ref.color, rig.ref.gray, rig.ref.camera, ramp,
                                       rig.Neighbors(), InvStep(grid), opt, 2, &changed);
  EXPECT_EQ(changed, 0);
  EXPECT_TRUE(SameImage(out, ramp));
  // The same ramp with a step of 6 labels in the middle is an edge: pixels
  // on its near side within the radius are tested, and some move to the
  // wall (the plane at 4 m lies between the ramp's two sides there).
  ImageF stepped = ramp;
  for (int y = 0; y < kHeight; ++y)
    for (int x = kWidth / 2; x < kWidth; ++x)
      stepped.at(x, y) = static_cast<float>(1.0 / (1.0 / ramp.at(x, y) - 6 * InvStep(grid)));
  const ImageF out2 = RelabelBoundaries(rig.ref.color, rig.ref.gray, rig.ref.camera, stepped,
                                        rig.Neighbors(), InvStep(grid), opt, 2, &changed);
  EXPECT_GT(changed, 0);
}

// max_neighbors: only the first neighbours count, as if the others were not given.
TEST(RelabelBoundaries, TestsOnlyTheFirstMaxNeighbors) {
  const CostVolume grid = LabelGrid();
  const Rig rig = MakeRig(BoardScene());
  const ImageF fat = Fatten(rig.gt, 6);
  const std::vector<RefineNeighbor> all = rig.Neighbors();
  const std::vector<RefineNeighbor> first(all.begin(), all.begin() + 2);
  BoundaryRelabelOptions two;
  two.max_neighbors = 2;
  long long c_all = -1, c_first = -1;
  const ImageF capped = RelabelBoundaries(rig.ref.color, rig.ref.gray, rig.ref.camera, fat, all, InvStep(grid),
                                          two, 1, &c_all);
  const ImageF given = RelabelBoundaries(rig.ref.color, rig.ref.gray, rig.ref.camera, fat, first,
                                         InvStep(grid), BoundaryRelabelOptions(), 1, &c_first);
  EXPECT_TRUE(SameImage(capped, given));
  EXPECT_EQ(c_all, c_first);
  EXPECT_GT(c_all, 0);
}

// The opposite error: the wall's depth spread 3 pixels over the board. Only
// farther candidates are tested (fattening moves the near side's depth
// outwards), so the board's edge stays as it is and the wall is untouched.
TEST(RelabelBoundaries, TestsOnlyFartherCandidates) {
  const CostVolume grid = LabelGrid();
  const Rig rig = MakeRig(BoardScene());
  const ImageF thin = Fatten(rig.gt, 3, true);
  long long changed = -1;
  const ImageF out = RelabelBoundaries(rig.ref.color, rig.ref.gray, rig.ref.camera, thin,
                                       rig.Neighbors(), InvStep(grid), BoundaryRelabelOptions(), 2,
                                       &changed);
  int band = 0, band_fixed = 0, wall = 0, wall_kept = 0;
  for (int y = 0; y < kHeight; ++y)
    for (int x = 0; x < kWidth; ++x) {
      const float truth = rig.gt.at(x, y);
      if (thin.at(x, y) != truth) {
        ++band;
        band_fixed += std::abs(grid.LabelOfDepth(out.at(x, y)) - grid.LabelOfDepth(truth)) <= 1.0;
      } else if (truth > 3.0f) {
        ++wall;
        wall_kept += out.at(x, y) == truth;
      }
    }
  EXPECT_GT(band, 0);
  EXPECT_EQ(band_fixed, 0);
  EXPECT_EQ(wall_kept, wall);
  EXPECT_EQ(changed, CountChanged(thin, out));
}

// Rows are independent: the result does not depend on the number of threads.
TEST(RelabelBoundaries, ThreadCountDoesNotChangeTheResult) {
  const CostVolume grid = LabelGrid();
  const Rig rig = MakeRig(BoardScene());
  const ImageF fat = Fatten(rig.gt, 6);
  const BoundaryRelabelOptions opt;
  long long c1 = -1, c3 = -1;
  const ImageF one = RelabelBoundaries(rig.ref.color, rig.ref.gray, rig.ref.camera, fat,
                                       rig.Neighbors(), InvStep(grid), opt, 1, &c1);
  const ImageF three = RelabelBoundaries(rig.ref.color, rig.ref.gray, rig.ref.camera, fat,
                                         rig.Neighbors(), InvStep(grid), opt, 3, &c3);
  EXPECT_TRUE(SameImage(one, three));
  EXPECT_EQ(c1, c3);
  EXPECT_GT(c1, 0);
}

TEST(RelabelBoundaries, DisabledOrWithoutNeighboursReturnsTheInput) {
  const CostVolume grid = LabelGrid();
  const Rig rig = MakeRig(BoardScene());
  const ImageF fat = Fatten(rig.gt, 6);
  BoundaryRelabelOptions off;
  off.enabled = false;
  long long changed = -1;
  EXPECT_TRUE(SameImage(RelabelBoundaries(rig.ref.color, rig.ref.gray, rig.ref.camera, fat,
                                          rig.Neighbors(), InvStep(grid), off, 1, &changed),
                        fat));
  EXPECT_EQ(changed, 0);
  changed = -1;
  EXPECT_TRUE(SameImage(RelabelBoundaries(rig.ref.color, rig.ref.gray, rig.ref.camera, fat, {},
                                          InvStep(grid), BoundaryRelabelOptions(), 1, &changed),
                        fat));
  EXPECT_EQ(changed, 0);
}

TEST(RelabelBoundaries, RejectsBadOptionsAndSizes) {
  const CostVolume grid = LabelGrid();
  const Rig rig = MakeRig(BoardScene());
  const std::vector<RefineNeighbor> nbs = rig.Neighbors();
  const double step = InvStep(grid);
  const DenseView& ref = rig.ref;
  BoundaryRelabelOptions bad;
  bad.window_step = bad.window_radius + 1;
  EXPECT_THROW(RelabelBoundaries(ref.color, ref.gray, ref.camera, rig.gt, nbs, step, bad),
               std::invalid_argument);
  const BoundaryRelabelOptions opt;
  // The grey image where the colour one belongs.
  EXPECT_THROW(RelabelBoundaries(ref.gray, ref.gray, ref.camera, rig.gt, nbs, step, opt),
               std::invalid_argument);
  EXPECT_THROW(RelabelBoundaries(ref.color, ref.gray, ref.camera,
                                 ImageF(kWidth, kHeight - 1, 1, 5.0f), nbs, step, opt),
               std::invalid_argument);
  EXPECT_THROW(RelabelBoundaries(ref.color, ref.gray, ref.camera.Resized(kWidth * 2, kHeight * 2),
                                 rig.gt, nbs, step, opt),
               std::invalid_argument);
}

}  // namespace
}  // namespace casual3d::depth

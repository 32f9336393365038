#include "reconstruct/depth/plane_sweep.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>
#include <random>

#include "reconstruct/depth/huge_pages.h"
#include "reconstruct/depth/sweep_kernels.h"
#include "reconstruct/depth/testing/toy_scene.h"

namespace casual3d::depth {
namespace {

using testing::MakeView;
using testing::ToyCamera;
using testing::ToyRect;
using testing::ToyScene;

// Fraction of interior pixels whose WTA label is within `tol` labels of the truth.
double FractionWithinLabels(const CostVolume& vol, const ImageF& wta, const ImageF& gt, double tol,
                            int border) {
  int ok = 0, total = 0;
  for (int y = border; y < wta.height() - border; ++y)
    for (int x = border; x < wta.width() - border; ++x) {
      ++total;
      if (wta.at(x, y) > 0 &&
          std::abs(vol.LabelOfDepth(wta.at(x, y)) - vol.LabelOfDepth(gt.at(x, y))) <= tol)
        ++ok;
    }
  return static_cast<double>(ok) / total;
}

// A straightforward reference of ComputeCostVolume: per pixel, label and
// neighbour, each window pixel is warped through its own homography and the
// five ZNCC moments are summed directly, in double precision.
struct ReferenceVolume {
  std::vector<double> cost;  // Pixel-major, as CostVolume::cost.
  std::vector<double> photo_weight;
};

double ClampedBilinear(const ImageF& img, double x, double y) {
  const int w = img.width(), h = img.height();
  x = std::min(std::max(x, 0.0), w - 1.0);
  y = std::min(std::max(y, 0.0), h - 1.0);
  const int x0 = std::min(static_cast<int>(x), std::max(0, w - 2));
  const int y0 = std::min(static_cast<int>(y), std::max(0, h - 2));
  const int x1 = std::min(x0 + 1, w - 1), y1 = std::min(y0 + 1, h - 1);
  const double fx = x - x0, fy = y - y0;
  const double top = img.at(x0, y0) * (1 - fx) + img.at(x1, y0) * fx;
  const double bot = img.at(x0, y1) * (1 - fx) + img.at(x1, y1) * fx;
  return top * (1 - fy) + bot * fy;
}

ReferenceVolume ReferenceSweep(const DenseView& ref, const std::vector<const DenseView*>& nbs,
                               const SweepOptions& opt) {
  const int w = ref.gray.width(), h = ref.gray.height(), L = opt.num_depths, r = opt.window_radius;
  ReferenceVolume out;
  out.cost.resize(static_cast<size_t>(w) * h * L);
  out.photo_weight.resize(static_cast<size_t>(w) * h);
  const double inv_near = 1.0 / ref.range.near_m, inv_far = 1.0 / ref.range.far_m;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      // Window of the reference, clipped to the image.
      std::vector<std::pair<int, int>> win;
      for (int dy = -r; dy <= r; ++dy)
        for (int dx = -r; dx <= r; ++dx)
          if (x + dx >= 0 && x + dx < w && y + dy >= 0 && y + dy < h)
            win.emplace_back(x + dx, y + dy);
      double si = 0, sii = 0;
      for (const auto& [u, v] : win) {
        si += ref.gray.at(u, v);
        sii += ref.gray.at(u, v) * ref.gray.at(u, v);
      }
      const double cnt = static_cast<double>(win.size());
      const double var_i = std::max(0.0, sii / cnt - (si / cnt) * (si / cnt));
      const size_t p = static_cast<size_t>(y) * w + x;
      out.photo_weight[p] = var_i / (var_i + opt.texture_sigma * opt.texture_sigma);
      for (int k = 0; k < L; ++k) {
        const double depth = 1.0 / (inv_near + (inv_far - inv_near) * k / (L - 1));
        std::vector<double> costs;
        for (const DenseView* nb : nbs) {
          // Position of a reference pixel centre on the plane, seen by the neighbour.
          auto project = [&](int u, int v, double* px, double* py) {
            const Eigen::Vector3d world = ref.camera.Unproject(u, v, depth);
            const Eigen::Vector3d c = nb->camera.R * world + nb->camera.t;
            if (!(c.z() > 0)) return false;
            *px = nb->camera.fx * c.x() / c.z() + nb->camera.cx - 0.5;
            *py = nb->camera.fy * c.y() / c.z() + nb->camera.cy - 0.5;
            return true;
          };
          auto inside = [&](double px, double py) {
            return px >= -0.5 && py >= -0.5 && px <= nb->gray.width() - 0.5 &&
                   py <= nb->gray.height() - 0.5;
          };
          double cx, cy;
          if (!project(x, y, &cx, &cy) || !inside(cx, cy)) continue;
          double sj = 0, sjj = 0, sij = 0;
          for (const auto& [u, v] : win) {
            // Window pixels that the neighbour does not see count as black.
            double px = 0, py = 0;
            const bool seen = project(u, v, &px, &py) && inside(px, py);
            const double j = seen ? ClampedBilinear(nb->gray, px, py) : 0.0;
            sj += j;
            sjj += j * j;
            sij += j * ref.gray.at(u, v);
          }
          const double var_j = std::max(0.0, sjj / cnt - (sj / cnt) * (sj / cnt));
          const double cov = sij / cnt - (si / cnt) * (sj / cnt);
          const double ncc = cov / std::sqrt((var_i + opt.ncc_epsilon) * (var_j + opt.ncc_epsilon));
          costs.push_back(std::min(1.0, std::max(0.0, 1.0 - ncc)));
        }
        double c = 1.0;
        if (!costs.empty()) {
          std::sort(costs.begin(), costs.end());
          const int kk = std::min<int>(opt.best_k, static_cast<int>(costs.size()));
          c = 0;
          for (int q = 0; q < kk; ++q) c += std::min(costs[q], costs[0] + opt.occlusion_truncation) / kk;
        }
        out.cost[p * L + k] = c;
      }
    }
  return out;
}

// A view of random texture (bilinearly enlarged noise, so that sub-pixel
// positions matter) seen by a camera at `centre`, rotated by `angle_rad`
// about `axis`.
DenseView RandomView(int w, int h, const Eigen::Vector3d& centre, const Eigen::Vector3d& axis,
                     double angle_rad, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u01(0.0f, 1.0f);
  const int gw = w / 3 + 2, gh = h / 3 + 2;
  std::vector<float> grid(static_cast<size_t>(gw) * gh);
  for (float& v : grid) v = u01(rng);
  DenseView v;
  v.name = "random" + std::to_string(seed);
  v.camera.width = w;
  v.camera.height = h;
  v.camera.fx = v.camera.fy = 0.9 * w;
  v.camera.cx = 0.5 * w + 0.7;
  v.camera.cy = 0.5 * h - 0.4;
  v.camera.R = Eigen::AngleAxisd(angle_rad, axis.normalized()).toRotationMatrix();
  v.camera.t = -v.camera.R * centre;
  v.range = {1.0, 8.0};
  v.gray = ImageF(w, h, 1);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const float gx = x / 3.0f, gy = y / 3.0f;
      const int x0 = static_cast<int>(gx), y0 = static_cast<int>(gy);
      const float fx = gx - x0, fy = gy - y0;
      auto g = [&](int a, int b) { return grid[static_cast<size_t>(b) * gw + a]; };
      v.gray.at(x, y) = (1 - fy) * ((1 - fx) * g(x0, y0) + fx * g(x0 + 1, y0)) +
                        fy * ((1 - fx) * g(x0, y0 + 1) + fx * g(x0 + 1, y0 + 1)) + 0.1f * u01(rng);
    }
  return v;
}

TEST(PlaneSweep, MatchesAStraightforwardReference) {
  const DenseView ref = RandomView(37, 29, {0, 0, 0}, {0, 1, 0}, 0.0, 1);
  // Neighbours of other sizes, rotated and translated; parts of the reference
  // fall outside each of them at some depths.
  const DenseView a = RandomView(41, 31, {0.3, 0.05, 0}, {0, 1, 0}, 0.06, 2);
  const DenseView b = RandomView(33, 27, {-0.25, 0.1, 0.1}, {1, 0.3, 0}, -0.05, 3);
  const DenseView c = RandomView(37, 29, {0.05, -0.3, -0.05}, {0.2, 0.1, 1}, 0.08, 4);
  SweepOptions opt;
  opt.num_depths = 23;
  opt.window_radius = 2;
  opt.best_k = 2;
  opt.num_threads = 2;
  const CostVolume fast = ComputeCostVolume(ref, {&a, &b, &c}, opt);
  const ReferenceVolume slow = ReferenceSweep(ref, {&a, &b, &c}, opt);
  ASSERT_EQ(fast.cost.size(), slow.cost.size());
  double max_err = 0.0, sum_err = 0.0;
  int large = 0, partial = 0;
  for (size_t i = 0; i < slow.cost.size(); ++i) {
    const double e = std::abs(fast.cost[i] - slow.cost[i]);
    max_err = std::max(max_err, e);
    sum_err += e;
    large += e > 1e-3;
    partial += slow.cost[i] < 1.0;
  }
  // The case must exercise real matches, not only unseen pixels.
  EXPECT_GT(partial, static_cast<int>(slow.cost.size() / 2));
  // Float arithmetic against double: tiny differences, except where a warped
  // centre sits on a neighbour's border within float rounding.
  EXPECT_LT(sum_err / slow.cost.size(), 2e-5);
  EXPECT_LE(large, static_cast<int>(slow.cost.size() / 2000));
  EXPECT_LT(max_err, 0.05);
  for (size_t i = 0; i < slow.photo_weight.size(); ++i)
    ASSERT_NEAR(fast.photo_weight.data()[i], slow.photo_weight[i], 1e-4);

  // Any number of threads gives the same volume.
  opt.num_threads = 1;
  const CostVolume single = ComputeCostVolume(ref, {&a, &b, &c}, opt);
  EXPECT_EQ(single.cost, fast.cost);
  // best_k larger than the number of seeing neighbours averages those that see.
  opt.best_k = 3;
  const CostVolume all = ComputeCostVolume(ref, {&a, &b, &c}, opt);
  const ReferenceVolume all_ref = ReferenceSweep(ref, {&a, &b, &c}, opt);
  double all_err = 0.0;
  for (size_t i = 0; i < all_ref.cost.size(); ++i)
    all_err += std::abs(all.cost[i] - all_ref.cost[i]);
  EXPECT_LT(all_err / all_ref.cost.size(), 2e-5);
}

TEST(PlaneSweep, RecoversAPlaneDespiteExposureChanges) {
  ToyScene scene;
  scene.rects.push_back({3.0, -50, 50, -50, 50, 8.0, 5});
  const DepthRange range{1.0, 20.0};
  ImageF gt;
  const DenseView ref = MakeView(scene, ToyCamera({0, 0, 0}, 160, 120, 150), range, 1.0, 0.0, &gt);
  // Different gain and offset per neighbour: ZNCC must not care.
  const DenseView a = MakeView(scene, ToyCamera({0.2, 0, 0}, 160, 120, 150), range, 1.3, -0.08);
  const DenseView b = MakeView(scene, ToyCamera({-0.2, 0, 0}, 160, 120, 150), range, 0.8, 0.1);
  const DenseView c = MakeView(scene, ToyCamera({0, 0.15, 0}, 160, 120, 150), range, 1.1, 0.0);
  SweepOptions opt;
  opt.num_threads = 2;
  const CostVolume vol = ComputeCostVolume(ref, {&a, &b, &c}, opt);
  ASSERT_EQ(vol.num_labels, 220);
  ASSERT_EQ(vol.cost.size(), 160u * 120u * 220u);
  EXPECT_NEAR(vol.DepthOfLabel(0), 1.0, 1e-9);
  EXPECT_NEAR(vol.DepthOfLabel(219), 20.0, 1e-9);
  const ImageF wta = WinnerTakesAll(vol, 2);
  // Away from the image border (where neighbours do not overlap), nearly all
  // pixels pick the true plane's label or its neighbour.
  EXPECT_GE(FractionWithinLabels(vol, wta, gt, 1.0, 12), 0.97);
  // Costs are normalised to [0, 1] and the textured plane gets a high w_photo
  // (its texture is random colour cells, which the colour-weighted texture
  // measure partly discounts: 0.46 here, 0.60 with the plain variance).
  float mn = 2, mx = -1;
  for (float v : vol.cost) {
    mn = std::min(mn, v);
    mx = std::max(mx, v);
  }
  EXPECT_GE(mn, 0.0f);
  EXPECT_LE(mx, 1.0f);
  EXPECT_GT(vol.photo_weight.at(80, 60), 0.4f);
  SweepOptions plain = opt;
  plain.texture_color_sigma = 0.0;
  EXPECT_GT(ComputeCostVolume(ref, {&a, &b, &c}, plain).photo_weight.at(80, 60), 0.55f);
}

// The volume takes a kept buffer from the pool without zeroing it: every
// cost must still be written, whatever the buffer held before.
TEST(PlaneSweep, OverwritesEveryCostOfAKeptBuffer) {
  ToyScene scene;
  scene.rects.push_back({3.0, -50, 50, -50, 50, 8.0, 5});
  const DepthRange range{1.0, 20.0};
  const DenseView ref = MakeView(scene, ToyCamera({0, 0, 0}, 160, 120, 150), range);
  const DenseView a = MakeView(scene, ToyCamera({0.2, 0, 0}, 160, 120, 150), range);
  const DenseView b = MakeView(scene, ToyCamera({-0.2, 0, 0}, 160, 120, 150), range);
  SweepOptions opt;
  opt.num_threads = 2;
  const CostVolume plain = ComputeCostVolume(ref, {&a, &b}, opt);
  BufferPool pool(1);
  std::vector<float> stale(plain.cost.size(), std::numeric_limits<float>::quiet_NaN());
  pool.Give(&stale);
  const CostVolume pooled = ComputeCostVolume(ref, {&a, &b}, opt, &pool);
  ASSERT_EQ(pooled.cost.size(), plain.cost.size());
  size_t differ = 0;
  for (size_t i = 0; i < plain.cost.size(); ++i) differ += !(pooled.cost[i] == plain.cost[i]);
  EXPECT_EQ(differ, 0u);
}

TEST(PlaneSweep, BestKAveragingSurvivesAnOccludingNeighbour) {
  // The plane at 4 m; a board at 1 m hides the centre from neighbour `occ` only.
  ToyScene scene;
  scene.rects.push_back({4.0, -50, 50, -50, 50, 6.0, 9});
  ToyScene occluded = scene;
  occluded.rects.push_back({1.0, 0.35, 0.9, -0.4, 0.4, 30.0, 3});
  const DepthRange range{0.5, 30.0};
  ImageF gt;
  const DenseView ref = MakeView(scene, ToyCamera({0, 0, 0}, 160, 120, 150), range, 1.0, 0.0, &gt);
  const DenseView a = MakeView(scene, ToyCamera({0.25, 0, 0}, 160, 120, 150), range);
  const DenseView b = MakeView(scene, ToyCamera({-0.25, 0, 0}, 160, 120, 150), range);
  // The occluder sits in front of this neighbour only (it is off to the side
  // of the reference's view of the plane).
  const DenseView occ = MakeView(occluded, ToyCamera({0.6, 0, 0}, 160, 120, 150), range);
  SweepOptions opt;
  opt.best_k = 2;
  const CostVolume vol = ComputeCostVolume(ref, {&a, &b, &occ}, opt);
  EXPECT_GE(FractionWithinLabels(vol, WinnerTakesAll(vol), gt, 1.0, 14), 0.95);
}

TEST(PlaneSweep, SlotMeanCapsCostsAboveTheBestPlusTheTruncation) {
  // Six pixels (four in SIMD, two in the scalar tail), two slots each, best first.
  const float inv = sweep::kInvalidCost;
  const std::vector<float> slots = {0.1f, 0.1f, 0.5f, inv, 0.2f, 0.3f,   // Slot 0.
                                    0.9f, 0.2f, 0.6f, inv, 1.0f, inv};   // Slot 1.
  std::vector<float> out(6);
  sweep::MeanOfSlots(slots.data(), 6, 2, 0.2f, out.data());
  const std::vector<float> capped = {0.2f, 0.15f, 0.55f, 1.0f, 0.3f, 0.3f};
  for (int x = 0; x < 6; ++x) EXPECT_FLOAT_EQ(out[x], capped[x]) << x;
  sweep::MeanOfSlots(slots.data(), 6, 2, 1.0f, out.data());  // The plain mean.
  const std::vector<float> plain = {0.5f, 0.15f, 0.55f, 1.0f, 0.6f, 0.3f};
  for (int x = 0; x < 6; ++x) EXPECT_FLOAT_EQ(out[x], plain[x]) << x;
  SweepOptions opt;
  opt.occlusion_truncation = 1.5;
  EXPECT_FALSE(opt.Check().ok());
}

TEST(SweepKernels, ZnccWindowSumsMatchThePlainSums) {
  // Rows of 37 pixels (vector bodies and a scalar tail), radii 1-9 (fixed and
  // generic tap counts), with and without an old row leaving the totals:
  // every output must equal the plain scalar expression to the bit.
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> uni(0.0f, 1.0f);
  const int width = 37;
  for (int r = 1; r <= 9; ++r)
    for (int leaves = 0; leaves <= 1; ++leaves) {
      const int padded = width + 2 * r;
      std::vector<float> j(padded, 0.0f), i(padded, 0.0f);
      for (int x = r; x < r + width; ++x) {
        j[x] = uni(rng);
        i[x] = uni(rng);
      }
      std::vector<float> out[3], acc[3], old[3], want_acc[3];
      for (int k = 0; k < 3; ++k) {
        out[k].assign(width, -1.0f);
        acc[k].resize(width);
        old[k].resize(width);
        for (int x = 0; x < width; ++x) {
          acc[k][x] = uni(rng);
          old[k][x] = uni(rng);
        }
        want_acc[k] = acc[k];
      }
      float* const outs[3] = {out[0].data(), out[1].data(), out[2].data()};
      float* const accs[3] = {acc[0].data(), acc[1].data(), acc[2].data()};
      const float* const olds[3] = {old[0].data(), old[1].data(), old[2].data()};
      sweep::ZnccWindowSums(j.data(), i.data(), width, r, outs, accs, leaves ? olds : nullptr);
      for (int x = 0; x < width; ++x) {
        float s[3] = {j[x], j[x] * j[x], j[x] * i[x]};
        for (int d = 1; d <= 2 * r; ++d) {
          s[0] += j[x + d];
          s[1] += j[x + d] * j[x + d];
          s[2] += j[x + d] * i[x + d];
        }
        for (int k = 0; k < 3; ++k) {
          float a = want_acc[k][x] + s[k];
          if (leaves) a -= old[k][x];
          EXPECT_EQ(out[k][x], s[k]) << "r " << r << " x " << x << " sum " << k;
          EXPECT_EQ(acc[k][x], a) << "r " << r << " x " << x << " sum " << k << " leaves " << leaves;
        }
      }
    }
}

TEST(SweepKernels, PerPixelWarpMatchesThePlaneWarp) {
  // A 40x30 source with a smooth pattern; a row whose homography moves and
  // scales the pixels, part of it falling outside the source.
  const int sw = 40, sh = 30, width = 64;
  std::vector<float> src(static_cast<size_t>(sw) * sh);
  for (int y = 0; y < sh; ++y)
    for (int x = 0; x < sw; ++x) src[static_cast<size_t>(y) * sw + x] = std::sin(0.3f * x) + 0.1f * y;
  const float b[3] = {12.0f, -3.0f, 0.05f};
  const float p0[3] = {-5.0f, 14.0f, 1.0f}, step[3] = {0.8f, 0.02f, 0.001f};
  // With the same inverse depth everywhere, the per-pixel warp is the plane
  // warp of that plane: p0 + inv * b.
  for (float inv : {0.0f, 0.25f, 1.5f}) {
    sweep::HomographyRow plane;
    for (int c = 0; c < 3; ++c) {
      plane.p0[c] = p0[c] + inv * b[c];
      plane.step[c] = step[c];
    }
    sweep::HomographyRow base;
    for (int c = 0; c < 3; ++c) {
      base.p0[c] = p0[c];
      base.step[c] = step[c];
    }
    const std::vector<float> invs(width, inv);
    std::vector<float> v1(width), i1(width), v2(width), i2(width);
    sweep::WarpRow(src.data(), sw, sh, plane, width, v1.data(), i1.data());
    sweep::WarpRowPerPixel(src.data(), sw, sh, base, invs.data(), b, width, v2.data(), i2.data());
    int inside = 0;
    for (int x = 0; x < width; ++x) {
      EXPECT_NEAR(v2[x], v1[x], 1e-4f) << "inv " << inv << " x " << x;
      EXPECT_EQ(i2[x], i1[x]) << "inv " << inv << " x " << x;
      inside += i1[x] == 0.0f;
    }
    EXPECT_GT(inside, 10);
    EXPECT_LT(inside, width);
  }
  // A different inverse depth per pixel: each pixel as the plane warp of its own plane.
  std::vector<float> invs(width);
  for (int x = 0; x < width; ++x) invs[x] = 0.02f * (x % 13);
  std::vector<float> v(width), iv(width);
  sweep::HomographyRow base;
  for (int c = 0; c < 3; ++c) {
    base.p0[c] = p0[c];
    base.step[c] = step[c];
  }
  sweep::WarpRowPerPixel(src.data(), sw, sh, base, invs.data(), b, width, v.data(), iv.data());
  for (int x = 0; x < width; ++x) {
    sweep::HomographyRow plane;
    for (int c = 0; c < 3; ++c) {
      plane.p0[c] = p0[c] + invs[x] * b[c];
      plane.step[c] = step[c];
    }
    std::vector<float> v1(width), i1(width);
    sweep::WarpRow(src.data(), sw, sh, plane, width, v1.data(), i1.data());
    EXPECT_NEAR(v[x], v1[x], 1e-4f) << x;
    EXPECT_EQ(iv[x], i1[x]) << x;
  }
}

TEST(PlaneSweep, RejectsInvalidOptionsAndInputs) {
  SweepOptions opt;
  opt.num_depths = 1;
  EXPECT_FALSE(opt.Check().ok());
  opt = SweepOptions();
  opt.window_radius = 0;
  EXPECT_FALSE(opt.Check().ok());
  ToyScene scene = ToyScene::Default();
  const DenseView ref = MakeView(scene, ToyCamera({0, 0, 0}, 32, 24, 30), {1.0, 10.0});
  EXPECT_THROW(ComputeCostVolume(ref, {}, SweepOptions()), std::invalid_argument);
  DenseView bad = ref;
  bad.range = {5.0, 2.0};
  EXPECT_THROW(ComputeCostVolume(bad, {&ref}, SweepOptions()), std::invalid_argument);
}

}  // namespace
}  // namespace casual3d::depth

namespace casual3d::depth {
namespace {

// A flat grey wall (left) beside a textured yellow stripe (right, x >= 20):
// the wall pixels two columns from the stripe see its texture in their 7x7
// window. The colour-weighted texture measure must call them flat; the plain
// window variance calls them textured.
TEST(PlaneSweep, TextureWeightIgnoresADifferentlyColoredNeighbour) {
  const int w = 40, h = 20;
  DenseView v;
  v.name = "stripe";
  v.camera = testing::ToyCamera({0, 0, 0}, w, h, 30);
  v.range = {1.0, 10.0};
  v.gray = ImageF(w, h, 1);
  v.color = ImageF(w, h, 3);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const bool stripe = x >= 20;
      const float t = stripe ? ((x * 7 + y * 13) % 5) * 0.08f : 0.0f;
      const float rgb[3] = {stripe ? 0.8f + 0.5f * t : 0.6f, stripe ? 0.7f + 0.5f * t : 0.6f,
                            stripe ? 0.15f + t : 0.57f};
      for (int c = 0; c < 3; ++c) v.color.at(x, y, c) = rgb[c];
      v.gray.at(x, y) = 0.3f * rgb[0] + 0.59f * rgb[1] + 0.11f * rgb[2];
    }
  DenseView nb = v;
  nb.camera = testing::ToyCamera({0.1, 0, 0}, w, h, 30);
  SweepOptions opt;
  opt.num_depths = 8;
  const CostVolume weighted = ComputeCostVolume(v, {&nb}, opt);
  opt.texture_color_sigma = 0.0;
  const CostVolume plain = ComputeCostVolume(v, {&nb}, opt);
  EXPECT_GT(plain.photo_weight.at(18, 10), 0.5f);
  EXPECT_LT(weighted.photo_weight.at(18, 10), 0.05f);
  EXPECT_LT(weighted.photo_weight.at(5, 10), 0.01f);   // Far from the stripe: flat either way.
  EXPECT_GT(weighted.photo_weight.at(30, 10), 0.5f);  // The stripe's own texture stays.
  opt.texture_color_sigma = -1.0;
  EXPECT_THROW(ComputeCostVolume(v, {&nb}, opt), std::invalid_argument);
}

}  // namespace
}  // namespace casual3d::depth

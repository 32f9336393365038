#include "reconstruct/depth/plane_sweep.h"

#include <algorithm>
#include <cmath>
#include <optional>
#include <stdexcept>
#include <string>

#include "base/parallel_for.h"
#include "reconstruct/depth/huge_pages.h"
#include "reconstruct/depth/sweep_kernels.h"
#include "reconstruct/depth/zncc_stream.h"

namespace casual3d::depth {
namespace {

// Per neighbour: its view and the plane-induced homography.
struct NeighborWarp {
  const DenseView* view = nullptr;
  PlaneHomography hom;
};

}  // namespace

PlaneHomography ComputePlaneHomography(const PinholeCamera& ref, const PinholeCamera& neighbor) {
  const Eigen::Matrix3d r_rel = neighbor.R * ref.R.transpose();
  const Eigen::Vector3d t_rel = neighbor.t - r_rel * ref.t;
  const Eigen::Matrix3d a = neighbor.K() * r_rel * ref.KInverse();
  const Eigen::Vector3d b = neighbor.K() * t_rel;
  PlaneHomography h;
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) h.a[r][c] = static_cast<float>(a(r, c));
    h.b[r] = static_cast<float>(b[r]);
  }
  return h;
}

CostVolume ComputeCostVolume(const DenseView& ref, const std::vector<const DenseView*>& neighbors,
                             const SweepOptions& options, BufferPool* pool) {
  const Status st = options.Check();
  if (!st.ok()) throw std::invalid_argument("plane sweep: " + st.message());
  if (neighbors.empty())
    throw std::invalid_argument("plane sweep: " + ref.name + ": no neighbours");
  if (!(ref.range.near_m > 0.0 && ref.range.far_m > ref.range.near_m))
    throw std::invalid_argument("plane sweep: " + ref.name + ": invalid depth range");
  const int w = ref.gray.width(), h = ref.gray.height();
  const size_t n = static_cast<size_t>(w) * h;
  const int r = options.window_radius;
  const int num_labels = options.num_depths;
  const int threads = base::ResolveThreads(options.num_threads);

  CostVolume vol;
  vol.width = w;
  vol.height = h;
  vol.num_labels = num_labels;
  vol.inv_near = 1.0 / ref.range.near_m;
  vol.inv_far = 1.0 / ref.range.far_m;

  // Reference window statistics, computed once.
  const float* gi = ref.gray.data();
  const float eps = static_cast<float>(options.ncc_epsilon);
  const ReferenceWindows windows = ComputeReferenceWindows(gi, w, h, r, eps);
  const float tsig2 = static_cast<float>(options.texture_sigma * options.texture_sigma);
  vol.photo_weight = ImageF(w, h, 1);
  for (size_t i = 0; i < n; ++i) vol.photo_weight.data()[i] = windows.variance[i] / (windows.variance[i] + tsig2);
  if (options.texture_color_sigma > 0.0 && ref.color.width() == w && ref.color.height() == h &&
      ref.color.channels() == 3) {
    // Texture of the pixel's own surface: the window's grey variance with
    // colour-similarity weights to the centre pixel.
    const float inv2s2 =
        static_cast<float>(1.0 / (2.0 * options.texture_color_sigma * options.texture_color_sigma));
    base::ParallelFor(0, h, threads, [&](int64_t yy) {
      const int y = static_cast<int>(yy);
      for (int x = 0; x < w; ++x) {
        const float* c0 = &ref.color.at(x, y, 0);
        float sw = 0.0f, s1 = 0.0f, s2 = 0.0f;
        for (int v = std::max(0, y - r); v <= std::min(h - 1, y + r); ++v)
          for (int u = std::max(0, x - r); u <= std::min(w - 1, x + r); ++u) {
            const float* c = &ref.color.at(u, v, 0);
            const float d2 = (c[0] - c0[0]) * (c[0] - c0[0]) + (c[1] - c0[1]) * (c[1] - c0[1]) +
                             (c[2] - c0[2]) * (c[2] - c0[2]);
            const float wq = std::exp(-d2 * inv2s2);
            const float g = gi[static_cast<size_t>(v) * w + u];
            sw += wq;
            s1 += wq * g;
            s2 += wq * g * g;
          }
        const float m = s1 / sw;
        const float var = std::max(0.0f, s2 / sw - m * m);
        vol.photo_weight.data()[static_cast<size_t>(y) * w + x] = var / (var + tsig2);
      }
    });
  }

  std::vector<NeighborWarp> warps(neighbors.size());
  for (size_t j = 0; j < neighbors.size(); ++j) {
    warps[j].view = neighbors[j];
    warps[j].hom = ComputePlaneHomography(ref.camera, neighbors[j]->camera);
  }

  // Planes are handed out in groups of kGroup. A thread sweeps each plane of
  // its group row by row (all working rows stay in cache), keeps the group
  // plane-major in a small buffer, then writes it into the pixel-major volume
  // (kGroup consecutive floats per pixel).
  constexpr int kGroup = 16;
  const int num_nb = static_cast<int>(neighbors.size());
  const int best_k = std::min(options.best_k, num_nb);
  const float truncation = static_cast<float>(options.occlusion_truncation);
  const int num_groups = (num_labels + kGroup - 1) / kGroup;
  // Every label of every pixel is written below (the groups cover all labels).
  TakeBufferForOverwrite(pool, &vol.cost, n * num_labels);
  // Per thread: a ZNCC stream and the group's buffer, made on its first group.
  struct Scratch {
    std::optional<ZnccStream> stream;
    std::vector<float> group;
  };
  std::vector<Scratch> scratch(std::min(threads, num_groups));
  base::ParallelFor(0, num_groups, threads, [&](int64_t group_index, int thread) {
    Scratch& own = scratch[thread];
    if (!own.stream) {
      own.stream.emplace(w, h, r, num_nb, best_k, truncation, eps, gi, &windows);
      own.group.resize(static_cast<size_t>(kGroup) * n);
    }
    ZnccStream& stream = *own.stream;
    std::vector<float>& group = own.group;
    const int k0 = static_cast<int>(group_index) * kGroup, k1 = std::min(num_labels, k0 + kGroup);
    for (int k = k0; k < k1; ++k) {
      const float inv_d = static_cast<float>(vol.InvDepthOfLabel(k));
      float* plane = group.data() + static_cast<size_t>(k - k0) * n;
      stream.Run(
          [&](int j, int y, float* values, float* invalid) {
            const NeighborWarp& wp = warps[j];
            sweep::WarpRow(wp.view->gray.data(), wp.view->gray.width(), wp.view->gray.height(),
                           wp.hom.Row(y, inv_d), w, values, invalid);
          },
          [&](int y) { return plane + static_cast<size_t>(y) * w; });
    }
    // Plane-major group to pixel-major volume.
    sweep::PlanesToPixelMajor(group.data(), n, k1 - k0, vol.cost.data() + k0, num_labels);
  });
  return vol;
}

ImageF WinnerTakesAll(const CostVolume& volume, int num_threads) {
  ImageF depth(volume.width, volume.height, 1, 0.0f);
  const int L = volume.num_labels;
  base::ParallelFor(0, volume.height, base::ResolveThreads(num_threads), [&](int64_t y) {
    for (int x = 0; x < volume.width; ++x) {
      const float* c = volume.Costs(x, static_cast<int>(y));
      int best = 0;
      for (int k = 1; k < L; ++k)
        if (c[k] < c[best]) best = k;
      depth.at(x, static_cast<int>(y)) =
          c[best] >= 1.0f ? 0.0f : static_cast<float>(volume.DepthOfLabel(best));
    }
  });
  return depth;
}

}  // namespace casual3d::depth

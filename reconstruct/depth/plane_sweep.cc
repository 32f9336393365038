#include "reconstruct/depth/plane_sweep.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <stdexcept>
#include <string>
#include <thread>

#include "reconstruct/depth/parallel.h"
#include "reconstruct/depth/sweep_kernels.h"

namespace casual3d::depth {
namespace {

// Mean over a (2r+1)^2 window clipped to the image, for one plane. `tmp` has
// width*height elements; `acc` has `width` elements.
void BoxMean(const float* in, float* out, int w, int h, int r, float* tmp, float* acc,
             const float* inv_count) {
  // Horizontal sums with a running window.
  for (int y = 0; y < h; ++y) {
    const float* row = in + static_cast<size_t>(y) * w;
    float* dst = tmp + static_cast<size_t>(y) * w;
    float s = 0.0f;
    for (int x = 0; x < std::min(r, w); ++x) s += row[x];
    for (int x = 0; x < w; ++x) {
      if (x + r < w) s += row[x + r];
      if (x - r - 1 >= 0) s -= row[x - r - 1];
      dst[x] = s;
    }
  }
  // Vertical running sums over whole rows (contiguous, vectorisable).
  std::fill(acc, acc + w, 0.0f);
  for (int y = 0; y < std::min(r, h); ++y) {
    const float* row = tmp + static_cast<size_t>(y) * w;
    for (int x = 0; x < w; ++x) acc[x] += row[x];
  }
  for (int y = 0; y < h; ++y) {
    if (y + r < h) {
      const float* add = tmp + static_cast<size_t>(y + r) * w;
      for (int x = 0; x < w; ++x) acc[x] += add[x];
    }
    if (y - r - 1 >= 0) {
      const float* sub = tmp + static_cast<size_t>(y - r - 1) * w;
      for (int x = 0; x < w; ++x) acc[x] -= sub[x];
    }
    float* dst = out + static_cast<size_t>(y) * w;
    const float* ic = inv_count + static_cast<size_t>(y) * w;
    for (int x = 0; x < w; ++x) dst[x] = acc[x] * ic[x];
  }
}

// Per neighbour, precomputed parts of the plane-induced homography: for the
// fronto-parallel plane Z_ref = d, x_n ~ A x_ref + (1/d) b with
// A = K_n R_rel K_ref^-1 and b = K_n t_rel (Hartley & Zisserman, Sec. 13.1).
struct NeighborWarp {
  const DenseView* view = nullptr;
  float a[3][3] = {{0, 0, 0}, {0, 0, 0}, {0, 0, 0}};
  float b[3] = {0, 0, 0};

  // Row y of the homography of the plane with inverse depth inv_d, with the
  // pixel-centre offsets (x + 0.5, y + 0.5) folded in.
  sweep::HomographyRow Row(int y, float inv_d) const {
    sweep::HomographyRow row;
    const float v = y + 0.5f;
    for (int c = 0; c < 3; ++c) {
      row.p0[c] = a[c][1] * v + a[c][2] + b[c] * inv_d + a[c][0] * 0.5f;
      row.step[c] = a[c][0];
    }
    return row;
  }
};

// The rolling state of one neighbour while a plane is swept top to bottom:
// the horizontal window sums of J, J^2 and I*J for the last 2r+2 rows (a
// ring), their vertical running sums, and the centre validity per row.
struct NeighborRows {
  NeighborRows(int width, int radius)
      : ring_rows(2 * radius + 2),
        ring_j(static_cast<size_t>(ring_rows) * width),
        ring_jj(ring_j.size()),
        ring_ij(ring_j.size()),
        ring_invalid(ring_j.size()),
        acc_j(width),
        acc_jj(width),
        acc_ij(width) {}
  int ring_rows;
  std::vector<float> ring_j, ring_jj, ring_ij, ring_invalid;
  std::vector<float> acc_j, acc_jj, acc_ij;
};

}  // namespace

Status SweepOptions::Check() const {
  if (num_depths < 2 || num_depths > 4096)
    return InvalidArgument("num_depths " + std::to_string(num_depths) + " outside [2, 4096]");
  if (window_radius < 1 || window_radius > 15)
    return InvalidArgument("window_radius " + std::to_string(window_radius) + " outside [1, 15]");
  if (best_k < 1 || best_k > 16)
    return InvalidArgument("best_k " + std::to_string(best_k) + " outside [1, 16]");
  if (!(ncc_epsilon >= 0.0 && ncc_epsilon <= 1.0))
    return InvalidArgument("ncc_epsilon " + std::to_string(ncc_epsilon) + " outside [0, 1]");
  if (!(texture_sigma > 0.0 && texture_sigma <= 1.0))
    return InvalidArgument("texture_sigma " + std::to_string(texture_sigma) + " outside (0, 1]");
  if (!(texture_color_sigma >= 0.0 && texture_color_sigma <= 10.0))
    return InvalidArgument("texture_color_sigma outside [0, 10]");
  if (!(occlusion_truncation >= 0.0 && occlusion_truncation <= 1.0))
    return InvalidArgument("occlusion_truncation outside [0, 1]");
  if (num_threads < 0) return InvalidArgument("num_threads must be >= 0");
  return Status::Ok();
}

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
                             const SweepOptions& options) {
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
  const int threads = ResolveThreads(options.num_threads);

  CostVolume vol;
  vol.width = w;
  vol.height = h;
  vol.num_labels = num_labels;
  vol.inv_near = 1.0 / ref.range.near_m;
  vol.inv_far = 1.0 / ref.range.far_m;

  // Reference window statistics, computed once: 1/count, mean, variance.
  std::vector<float> inv_count(n), mean_i(n), inv_std_i(n), tmp(n), acc(w), ii(n), var_i(n);
  for (int y = 0; y < h; ++y) {
    const int ny = std::min(y + r, h - 1) - std::max(y - r, 0) + 1;
    for (int x = 0; x < w; ++x) {
      const int nx = std::min(x + r, w - 1) - std::max(x - r, 0) + 1;
      inv_count[static_cast<size_t>(y) * w + x] = 1.0f / static_cast<float>(nx * ny);
    }
  }
  const float* gi = ref.gray.data();
  for (size_t i = 0; i < n; ++i) ii[i] = gi[i] * gi[i];
  BoxMean(gi, mean_i.data(), w, h, r, tmp.data(), acc.data(), inv_count.data());
  BoxMean(ii.data(), var_i.data(), w, h, r, tmp.data(), acc.data(), inv_count.data());
  const float eps = static_cast<float>(options.ncc_epsilon);
  const float tsig2 = static_cast<float>(options.texture_sigma * options.texture_sigma);
  vol.photo_weight = ImageF(w, h, 1);
  for (size_t i = 0; i < n; ++i) {
    const float var = std::max(0.0f, var_i[i] - mean_i[i] * mean_i[i]);
    var_i[i] = var;
    inv_std_i[i] = 1.0f / std::sqrt(var + eps);
    vol.photo_weight.data()[i] = var / (var + tsig2);
  }
  if (options.texture_color_sigma > 0.0 && ref.color.width() == w && ref.color.height() == h &&
      ref.color.channels() == 3) {
    // Texture of the pixel's own surface: the window's grey variance with
    // colour-similarity weights to the centre pixel.
    const float inv2s2 =
        static_cast<float>(1.0 / (2.0 * options.texture_color_sigma * options.texture_color_sigma));
    ParallelFor(0, h, threads, [&](int64_t yy) {
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
    const PlaneHomography hom = ComputePlaneHomography(ref.camera, neighbors[j]->camera);
    warps[j].view = neighbors[j];
    std::copy(&hom.a[0][0], &hom.a[0][0] + 9, &warps[j].a[0][0]);
    std::copy(hom.b, hom.b + 3, warps[j].b);
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
  vol.cost.resize(n * num_labels);
  std::atomic<int> next_group(0);
  auto worker = [&]() {
    std::vector<NeighborRows> rows(num_nb, NeighborRows(w, r));
    // Rows padded with r zeros on both sides: J, J^2 and I*J.
    std::vector<float> pad_j(w + 2 * r, 0.0f), pad_jj(pad_j.size(), 0.0f),
        pad_ij(pad_j.size(), 0.0f);
    std::vector<float> cost_row(w), slots(static_cast<size_t>(best_k) * w);
    std::vector<float> group(static_cast<size_t>(kGroup) * n);
    for (;;) {
      const int group_index = next_group.fetch_add(1);
      if (group_index >= num_groups) break;
      const int k0 = group_index * kGroup, k1 = std::min(num_labels, k0 + kGroup);
      for (int k = k0; k < k1; ++k) {
        const float inv_d = static_cast<float>(vol.InvDepthOfLabel(k));
        float* plane = group.data() + static_cast<size_t>(k - k0) * n;
        for (NeighborRows& nr : rows) {
          std::fill(nr.acc_j.begin(), nr.acc_j.end(), 0.0f);
          std::fill(nr.acc_jj.begin(), nr.acc_jj.end(), 0.0f);
          std::fill(nr.acc_ij.begin(), nr.acc_ij.end(), 0.0f);
        }
        // Row yi enters the window sums; row yo = yi - r leaves complete.
        for (int yi = 0; yi < h + r; ++yi) {
          const int yo = yi - r;
          if (yo >= 0) std::fill(slots.begin(), slots.end(), sweep::kInvalidCost);
          for (int j = 0; j < num_nb; ++j) {
            NeighborRows& nr = rows[j];
            if (yi < h) {
              const NeighborWarp& wp = warps[j];
              const size_t slot = static_cast<size_t>(yi % nr.ring_rows) * w;
              sweep::WarpRow(wp.view->gray.data(), wp.view->gray.width(), wp.view->gray.height(),
                             wp.Row(yi, inv_d), w, pad_j.data() + r, nr.ring_invalid.data() + slot);
              const float* gi_row = gi + static_cast<size_t>(yi) * w;
              for (int x = 0; x < w; ++x) {
                const float jv = pad_j[r + x];
                pad_jj[r + x] = jv * jv;
                pad_ij[r + x] = jv * gi_row[x];
              }
              float* hj = nr.ring_j.data() + slot;
              float* hjj = nr.ring_jj.data() + slot;
              float* hij = nr.ring_ij.data() + slot;
              sweep::WindowSumAccumulate(pad_j.data(), w, r, hj, nr.acc_j.data());
              sweep::WindowSumAccumulate(pad_jj.data(), w, r, hjj, nr.acc_jj.data());
              sweep::WindowSumAccumulate(pad_ij.data(), w, r, hij, nr.acc_ij.data());
            }
            if (yo < 0) continue;
            if (yo - r - 1 >= 0) {
              const size_t old = static_cast<size_t>((yo - r - 1) % nr.ring_rows) * w;
              sweep::SubtractRow(nr.ring_j.data() + old, w, nr.acc_j.data());
              sweep::SubtractRow(nr.ring_jj.data() + old, w, nr.acc_jj.data());
              sweep::SubtractRow(nr.ring_ij.data() + old, w, nr.acc_ij.data());
            }
            const size_t o = static_cast<size_t>(yo) * w;
            sweep::ZnccRowInputs in;
            in.sum_j = nr.acc_j.data();
            in.sum_jj = nr.acc_jj.data();
            in.sum_ij = nr.acc_ij.data();
            in.inv_count = inv_count.data() + o;
            in.mean_i = mean_i.data() + o;
            in.inv_std_i = inv_std_i.data() + o;
            in.invalid = nr.ring_invalid.data() + static_cast<size_t>(yo % nr.ring_rows) * w;
            sweep::ZnccCostRow(in, eps, w, cost_row.data());
            // Occlusion-robust aggregation: mean of the best_k valid neighbours,
            // each capped at the best one's cost plus the truncation.
            sweep::InsertSmallest(cost_row.data(), w, best_k, slots.data());
          }
          if (yo >= 0)
            sweep::MeanOfSlots(slots.data(), w, best_k, truncation, plane + static_cast<size_t>(yo) * w);
        }
      }
      // Plane-major group to pixel-major volume.
      sweep::PlanesToPixelMajor(group.data(), n, k1 - k0, vol.cost.data() + k0, num_labels);
    }
  };
  {
    std::vector<std::thread> pool;
    for (int t = 1; t < std::min(threads, num_groups); ++t) pool.emplace_back(worker);
    worker();
    for (auto& th : pool) th.join();
  }
  return vol;
}

ImageF WinnerTakesAll(const CostVolume& volume, int num_threads) {
  ImageF depth(volume.width, volume.height, 1, 0.0f);
  const int L = volume.num_labels;
  ParallelFor(0, volume.height, ResolveThreads(num_threads), [&](int64_t y) {
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

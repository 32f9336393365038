#include "reconstruct/depth/plane_sweep.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <stdexcept>
#include <string>
#include <thread>

#include "reconstruct/depth/parallel.h"

namespace casual3d::depth {
namespace {

constexpr float kInvalidCost = 2.0f;  // Marks "this neighbour does not see the pixel".

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
};

// Bilinear sample with clamping to the border (window pixels that fall just
// outside the neighbour keep a sensible value; the centre's own validity is
// checked separately).
inline float Bilinear(const float* img, int w, int h, float x, float y) {
  x = std::min(std::max(x, 0.0f), static_cast<float>(w - 1));
  y = std::min(std::max(y, 0.0f), static_cast<float>(h - 1));
  const int x0 = std::min(static_cast<int>(x), w - 2 < 0 ? 0 : w - 2);
  const int y0 = std::min(static_cast<int>(y), h - 2 < 0 ? 0 : h - 2);
  const float fx = x - x0, fy = y - y0;
  const float* p = img + static_cast<size_t>(y0) * w + x0;
  const int dx = w > 1 ? 1 : 0;
  const size_t dy = h > 1 ? static_cast<size_t>(w) : 0;
  const float top = p[0] + fx * (p[dx] - p[0]);
  const float bot = p[dy] + fx * (p[dy + dx] - p[dy]);
  return top + fy * (bot - top);
}

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
  if (num_threads < 0) return InvalidArgument("num_threads must be >= 0");
  return Status::Ok();
}

CostVolume ComputeCostVolume(const DenseView& ref, const std::vector<const DenseView*>& neighbors,
                             const SweepOptions& options) {
  const Status st = options.Check();
  if (!st.ok()) throw std::invalid_argument("plane sweep: " + st.message());
  if (neighbors.empty()) throw std::invalid_argument("plane sweep: " + ref.name + ": no neighbours");
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

  // Homography parts per neighbour: A (3x3, float) and b.
  const Eigen::Matrix3d kinv_ref = ref.camera.KInverse();
  std::vector<NeighborWarp> warps(neighbors.size());
  for (size_t j = 0; j < neighbors.size(); ++j) {
    const DenseView& nb = *neighbors[j];
    const Eigen::Matrix3d r_rel = nb.camera.R * ref.camera.R.transpose();
    const Eigen::Vector3d t_rel = nb.camera.t - r_rel * ref.camera.t;
    const Eigen::Matrix3d a = nb.camera.K() * r_rel * kinv_ref;
    const Eigen::Vector3d b = nb.camera.K() * t_rel;
    warps[j].view = &nb;
    for (int rr = 0; rr < 3; ++rr) {
      for (int c = 0; c < 3; ++c) warps[j].a[rr][c] = static_cast<float>(a(rr, c));
      warps[j].b[rr] = static_cast<float>(b[rr]);
    }
  }

  // Plane-major scratch volume: each plane is written by one thread.
  std::vector<float> planes(n * num_labels);
  const int num_nb = static_cast<int>(neighbors.size());
  const int best_k = std::min(options.best_k, num_nb);
  std::atomic<int> next_plane(0);
  auto worker = [&]() {
    // Horizontal window sums of J, J^2 and I*J (one image each), one warped row,
    // the vertical accumulators, and the per-neighbour costs of one plane.
    std::vector<float> hj(n), hjj(n), hij(n), jrow(w), acc_j(w), acc_jj(w), acc_ij(w);
    std::vector<float> nb_cost(n * num_nb);
    for (;;) {
      const int k = next_plane.fetch_add(1);
      if (k >= num_labels) break;
      const float inv_d = static_cast<float>(vol.InvDepthOfLabel(k));
      for (int j = 0; j < num_nb; ++j) {
        const NeighborWarp& wp = warps[j];
        const int nw = wp.view->gray.width(), nh = wp.view->gray.height();
        const float* src = wp.view->gray.data();
        float* cost = nb_cost.data() + static_cast<size_t>(j) * n;
        // Warp row by row (x_n ~ A (u, v, 1) + b / d is affine in u along a
        // row) and take horizontal window sums right away.
        for (int y = 0; y < h; ++y) {
          const float v = y + 0.5f;
          const float* gi_row = gi + static_cast<size_t>(y) * w;
          float* cost_row = cost + static_cast<size_t>(y) * w;
          const float px0 = wp.a[0][1] * v + wp.a[0][2] + wp.b[0] * inv_d + wp.a[0][0] * 0.5f;
          const float py0 = wp.a[1][1] * v + wp.a[1][2] + wp.b[1] * inv_d + wp.a[1][0] * 0.5f;
          const float pz0 = wp.a[2][1] * v + wp.a[2][2] + wp.b[2] * inv_d + wp.a[2][0] * 0.5f;
          for (int x = 0; x < w; ++x) {
            // One rounding per coordinate (no accumulated drift along the row).
            const float px = px0 + wp.a[0][0] * x;
            const float py = py0 + wp.a[1][0] * x;
            const float pz = pz0 + wp.a[2][0] * x;
            float val = 0.0f;
            bool inside = false;
            if (pz > 1e-9f) {
              const float iz = 1.0f / pz;
              const float u = px * iz - 0.5f, vv = py * iz - 0.5f;
              inside = u >= -0.5f && vv >= -0.5f && u <= nw - 0.5f && vv <= nh - 0.5f;
              if (inside) val = Bilinear(src, nw, nh, u, vv);
            }
            cost_row[x] = inside ? 0.0f : kInvalidCost;
            jrow[x] = val;
          }
          float* dj = hj.data() + static_cast<size_t>(y) * w;
          float* djj = hjj.data() + static_cast<size_t>(y) * w;
          float* dij = hij.data() + static_cast<size_t>(y) * w;
          float sj = 0.0f, sjj = 0.0f, sij = 0.0f;
          for (int x = 0; x < std::min(r, w); ++x) {
            sj += jrow[x];
            sjj += jrow[x] * jrow[x];
            sij += jrow[x] * gi_row[x];
          }
          for (int x = 0; x < w; ++x) {
            if (x + r < w) {
              const float a = jrow[x + r];
              sj += a;
              sjj += a * a;
              sij += a * gi_row[x + r];
            }
            if (x - r - 1 >= 0) {
              const float a = jrow[x - r - 1];
              sj -= a;
              sjj -= a * a;
              sij -= a * gi_row[x - r - 1];
            }
            dj[x] = sj;
            djj[x] = sjj;
            dij[x] = sij;
          }
        }
        // Vertical window sums over whole rows (contiguous, vectorisable),
        // fused with the ZNCC.
        std::fill(acc_j.begin(), acc_j.end(), 0.0f);
        std::fill(acc_jj.begin(), acc_jj.end(), 0.0f);
        std::fill(acc_ij.begin(), acc_ij.end(), 0.0f);
        auto add_row = [&](int yy, float sign) {
          const size_t o = static_cast<size_t>(yy) * w;
          for (int x = 0; x < w; ++x) {
            acc_j[x] += sign * hj[o + x];
            acc_jj[x] += sign * hjj[o + x];
            acc_ij[x] += sign * hij[o + x];
          }
        };
        for (int y = 0; y < std::min(r, h); ++y) add_row(y, 1.0f);
        for (int y = 0; y < h; ++y) {
          if (y + r < h) add_row(y + r, 1.0f);
          if (y - r - 1 >= 0) add_row(y - r - 1, -1.0f);
          const size_t o = static_cast<size_t>(y) * w;
          const float* ic = inv_count.data() + o;
          const float* mi = mean_i.data() + o;
          const float* isi = inv_std_i.data() + o;
          float* c = cost + o;
          for (int x = 0; x < w; ++x) {
            const float mj = acc_j[x] * ic[x];
            const float var_j = std::max(0.0f, acc_jj[x] * ic[x] - mj * mj);
            const float cov = acc_ij[x] * ic[x] - mi[x] * mj;
            const float ncc = cov * isi[x] / std::sqrt(var_j + eps);
            const float e = std::min(1.0f, std::max(0.0f, 1.0f - ncc));
            c[x] = c[x] == 0.0f ? e : kInvalidCost;
          }
        }
      }
      // Occlusion-robust aggregation: mean of the best_k valid neighbours.
      float* plane = planes.data() + static_cast<size_t>(k) * n;
      float c[16];
      for (size_t i = 0; i < n; ++i) {
        int m = 0;
        for (int j = 0; j < num_nb && m < 16; ++j) {
          const float v = nb_cost[static_cast<size_t>(j) * n + i];
          if (v < kInvalidCost) c[m++] = v;
        }
        if (m == 0) {
          plane[i] = 1.0f;
          continue;
        }
        const int kk = std::min(best_k, m);
        std::partial_sort(c, c + kk, c + m);
        float sum = 0.0f;
        for (int q = 0; q < kk; ++q) sum += c[q];
        plane[i] = sum / kk;
      }
    }
  };
  {
    std::vector<std::thread> pool;
    for (int t = 1; t < threads; ++t) pool.emplace_back(worker);
    worker();
    for (auto& th : pool) th.join();
  }

  // Blocked transpose to pixel-major.
  vol.cost.resize(n * num_labels);
  constexpr size_t kBlock = 64;
  const size_t num_blocks = (n + kBlock - 1) / kBlock;
  ParallelFor(0, static_cast<int64_t>(num_blocks), threads, [&](int64_t bi) {
    const size_t p0 = bi * kBlock, p1 = std::min(n, p0 + kBlock);
    for (int k = 0; k < num_labels; ++k) {
      const float* src = planes.data() + static_cast<size_t>(k) * n;
      for (size_t p = p0; p < p1; ++p) vol.cost[p * num_labels + k] = src[p];
    }
  }, 16);
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

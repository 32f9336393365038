#pragma once

// The photo-consistency loop that the plane sweep (plane_sweep.cc) and the
// full-resolution refinement (fullres_refine.cc) share: for one hypothesis
// (a plane, or a per-pixel depth map plus an offset), every neighbour's
// warped grey image is streamed top to bottom through cache-resident rows,
// its window sums of J, J^2 and I*J are kept as running sums over the last
// 2r+1 rows, and each finished output row gets the ZNCC cost per neighbour
// and the occlusion-robust mean of the best_k of them (sweep_kernels.h).
// Only the warp differs between the callers; it is passed in.

#include <algorithm>
#include <cmath>
#include <vector>

#include "reconstruct/depth/sweep_kernels.h"

namespace casual3d::depth {

// Window statistics of a reference grey image: 1 / window pixel count, window
// mean and 1 / sqrt(window variance + epsilon), and the plain window variance,
// for (2r+1)^2 windows clipped to the image.
struct ReferenceWindows {
  std::vector<float> inv_count, mean, inv_std, variance;
};
ReferenceWindows ComputeReferenceWindows(const float* gray, int width, int height, int radius,
                                         float epsilon);

// Mean over a (2r+1)^2 window clipped to the image. `tmp` has width*height
// elements; `acc` has `width` elements.
void BoxMean(const float* in, float* out, int w, int h, int r, float* tmp, float* acc, const float* inv_count);

// One thread's buffers for streaming hypotheses; reuse it across hypotheses.
class ZnccStream {
 public:
  ZnccStream(int width, int height, int radius, int num_neighbors, int best_k, float truncation,
             float epsilon, const float* ref_gray, const ReferenceWindows* windows)
      : w_(width),
        h_(height),
        r_(radius),
        best_k_(std::min(best_k, num_neighbors)),
        truncation_(truncation),
        epsilon_(epsilon),
        gray_(ref_gray),
        windows_(windows),
        rows_(num_neighbors, Rows(width, radius)),
        pad_j_(width + 2 * radius, 0.0f),
        pad_i_(pad_j_.size(), 0.0f),
        cost_row_(width),
        slots_(static_cast<size_t>(best_k_) * width) {}

  // Streams one hypothesis. warp(j, y, values, invalid) writes row y of
  // neighbour j's warped grey image into values[0, width) and its validity
  // into invalid[0, width) (sweep::WarpRow's outputs). destination(y) returns
  // where output row y's aggregated costs go (width floats).
  template <typename Warp, typename Destination>
  void Run(Warp&& warp, Destination&& destination) {
    const int w = w_, r = r_;
    for (Rows& nr : rows_) {
      std::fill(nr.acc_j.begin(), nr.acc_j.end(), 0.0f);
      std::fill(nr.acc_jj.begin(), nr.acc_jj.end(), 0.0f);
      std::fill(nr.acc_ij.begin(), nr.acc_ij.end(), 0.0f);
    }
    // Row yi enters the window sums; row yo = yi - r leaves complete, and
    // row yo - r - 1 leaves the running sums.
    for (int yi = 0; yi < h_ + r; ++yi) {
      const int yo = yi - r;
      if (yo >= 0) std::fill(slots_.begin(), slots_.end(), sweep::kInvalidCost);
      if (yi < h_) std::copy(gray_ + static_cast<size_t>(yi) * w, gray_ + static_cast<size_t>(yi + 1) * w,
                             pad_i_.begin() + r);
      for (size_t j = 0; j < rows_.size(); ++j) {
        Rows& nr = rows_[j];
        const bool leaves = yo - r - 1 >= 0;
        const size_t old = leaves ? static_cast<size_t>((yo - r - 1) % nr.ring_rows) * w : 0;
        if (yi < h_) {
          const size_t slot = static_cast<size_t>(yi % nr.ring_rows) * w;
          warp(static_cast<int>(j), yi, pad_j_.data() + r, nr.ring_invalid.data() + slot);
          float* const out[3] = {nr.ring_j.data() + slot, nr.ring_jj.data() + slot, nr.ring_ij.data() + slot};
          float* const acc[3] = {nr.acc_j.data(), nr.acc_jj.data(), nr.acc_ij.data()};
          const float* const gone[3] = {nr.ring_j.data() + old, nr.ring_jj.data() + old, nr.ring_ij.data() + old};
          sweep::ZnccWindowSums(pad_j_.data(), pad_i_.data(), w, r, out, acc, leaves ? gone : nullptr);
        } else if (leaves) {
          sweep::SubtractRow(nr.ring_j.data() + old, w, nr.acc_j.data());
          sweep::SubtractRow(nr.ring_jj.data() + old, w, nr.acc_jj.data());
          sweep::SubtractRow(nr.ring_ij.data() + old, w, nr.acc_ij.data());
        }
        if (yo < 0) continue;
        const size_t o = static_cast<size_t>(yo) * w;
        sweep::ZnccRowInputs in;
        in.sum_j = nr.acc_j.data();
        in.sum_jj = nr.acc_jj.data();
        in.sum_ij = nr.acc_ij.data();
        in.inv_count = windows_->inv_count.data() + o;
        in.mean_i = windows_->mean.data() + o;
        in.inv_std_i = windows_->inv_std.data() + o;
        in.invalid = nr.ring_invalid.data() + static_cast<size_t>(yo % nr.ring_rows) * w;
        sweep::ZnccCostRow(in, epsilon_, w, cost_row_.data());
        // Occlusion-robust aggregation: mean of the best_k valid neighbours,
        // each capped at the best one's cost plus the truncation.
        sweep::InsertSmallest(cost_row_.data(), w, best_k_, slots_.data());
      }
      if (yo >= 0) sweep::MeanOfSlots(slots_.data(), w, best_k_, truncation_, destination(yo));
    }
  }

 private:
  // A neighbour's horizontal window sums of J, J^2 and I*J for the last 2r+2
  // rows (a ring), their vertical running sums, and the centre validity per row.
  struct Rows {
    Rows(int width, int radius)
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

  int w_, h_, r_, best_k_;
  float truncation_, epsilon_;
  const float* gray_;
  const ReferenceWindows* windows_;
  std::vector<Rows> rows_;
  // Rows padded with r zeros on both sides: J and I.
  std::vector<float> pad_j_, pad_i_;
  std::vector<float> cost_row_, slots_;
};

}  // namespace casual3d::depth

#pragma once

// Weighted medians of labels over a window (the edge-aware median, the
// bilateral median pruning): a histogram of weights over the labels, filled
// row by row and read once.

#include <algorithm>
#include <limits>

namespace casual3d::depth {

// Over `bins` floats that are zero before the first AddRow and again after
// MedianAndClear.
class LabelHistogram {
 public:
  explicit LabelHistogram(float* bins) : bins_(bins) {}

  // Adds weights[i] to label labels[i] for i < n; negative labels are
  // skipped. Labels come in runs (a labelling is piecewise constant): a
  // run's weights are summed in a register and added to its bin once,
  // instead of a chain of dependent adds to one bin.
  void AddRow(const int* labels, const float* weights, int n) {
    int run_label = n > 0 ? labels[0] : -1;
    float run_sum = 0.0f;
    for (int i = 0; i < n; ++i) {
      const int k = labels[i];
      if (k != run_label) {
        Add(run_label, run_sum);
        run_label = k;
        run_sum = 0.0f;
      }
      run_sum += weights[i];
    }
    Add(run_label, run_sum);
  }

  // The least label whose cumulative weight reaches half of `total` (the
  // sum of the weights added; the greatest label added if rounding keeps
  // the sum short of it, -1 if nothing was added). Zeroes the bins.
  int MedianAndClear(float total) {
    if (kmax_ < 0) return -1;
    float acc = 0.0f;
    int median = kmax_;
    for (int k = kmin_; k <= kmax_; ++k) {
      acc += bins_[k];
      if (acc >= 0.5f * total) {
        median = k;
        break;
      }
    }
    std::fill(bins_ + kmin_, bins_ + kmax_ + 1, 0.0f);
    kmin_ = std::numeric_limits<int>::max();
    kmax_ = -1;
    return median;
  }

 private:
  void Add(int label, float weight) {
    if (label < 0) return;
    bins_[label] += weight;
    kmin_ = std::min(kmin_, label);
    kmax_ = std::max(kmax_, label);
  }

  float* bins_;
  int kmin_ = std::numeric_limits<int>::max();
  int kmax_ = -1;
};

}  // namespace casual3d::depth

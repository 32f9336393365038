#pragma once

// Multi-label MRF energy minimisation on a 4-connected pixel grid by alpha
// expansion (Boykov, Veksler and Zabih 2001) with the graph construction of
// Kolmogorov and Zabih (2004), solved with the Boykov-Kolmogorov max-flow
// (Debian's libmaxflow).
//
//   E(l) = sum_p D(p, l_p) + sum_{(p,q) 4-neighbours} V(p, q, l_p, l_q)
//
// The pairwise term need not be a metric: where an expansion move's pairwise
// table is not submodular it is truncated (Rother et al. 2005), and a move is
// kept only if it lowers the true energy, so the energy never increases.
// Data costs at or above kInfiniteCost forbid a label at a pixel.

#include <cstdint>
#include <functional>
#include <string>
#include <vector>
#include "reconstruct/util/options_fields.h"

namespace casual3d::stitch {

constexpr float kInfiniteCost = 1e9f;

struct AlphaExpansionOptions {
  int max_cycles = 4;  // Full sweeps over all labels; >= 1.
  // Stop when a whole cycle lowers the energy by less than this fraction.
  double min_relative_decrease = 1e-4;
  template <typename Self, typename Visitor>
  static void DescribeFields(Self& o, Visitor& v) {
    using R = util::Rule;
    v.Field("max_cycles", o.max_cycles, R::AtLeast(1), "Full sweeps over all labels");
    v.Field("min_relative_decrease", o.min_relative_decrease, R::AtLeast(0),
            "Stop when a cycle lowers the energy by less than this fraction");
  }
  Status Check() const { return util::CheckFields(*this); }
};

class GridMrf {
 public:
  // V(p, q, lp, lq): pixels as indices y * width + x; q is the right or lower
  // neighbour of p (or column 0 for the last column when wrap_x). Must return
  // 0 when lp == lq.
  using Pairwise = std::function<float(int p, int q, int lp, int lq)>;

  // Data costs are stored densely: width * height * num_labels floats,
  // initialised to kInfiniteCost.
  GridMrf(int width, int height, int num_labels, bool wrap_x);

  int width() const { return width_; }
  int height() const { return height_; }
  int num_labels() const { return num_labels_; }
  float& data_cost(int pixel, int label) {
    return data_[static_cast<size_t>(pixel) * num_labels_ + label];
  }
  float data_cost(int pixel, int label) const {
    return data_[static_cast<size_t>(pixel) * num_labels_ + label];
  }

  // Total energy of a labelling (one label per pixel).
  double Energy(const std::vector<int>& labels, const Pairwise& pairwise) const;

  // Minimises the energy starting from the cheapest data label per pixel.
  // Pixels with no allowed label get label -1 and take no part.
  std::vector<int> Solve(const Pairwise& pairwise, const AlphaExpansionOptions& options) const;

  // The same, starting from `initial` (-1 entries are replaced by the
  // cheapest data label).
  std::vector<int> Solve(std::vector<int> initial, const Pairwise& pairwise,
                         const AlphaExpansionOptions& options) const;

 private:
  // One expansion move for `alpha`; returns true if the labelling changed
  // and lowered the energy (then *labels and *energy are updated).
  bool Expand(int alpha, const Pairwise& pairwise, std::vector<int>* labels,
              double* energy) const;

  int width_, height_, num_labels_;
  bool wrap_x_;
  std::vector<float> data_;
};

}  // namespace casual3d::stitch

#include "reconstruct/stitch/alpha_expansion.h"

#include <algorithm>
#include <cmath>
#include <memory>
#include <stdexcept>

#include <maxflow.h>

namespace casual3d::stitch {

GridMrf::GridMrf(int width, int height, int num_labels, bool wrap_x)
    : width_(width), height_(height), num_labels_(num_labels), wrap_x_(wrap_x) {
  if (width <= 0 || height <= 0 || num_labels <= 0) {
    throw std::invalid_argument("GridMrf: width, height and num_labels must be positive");
  }
  data_.assign(static_cast<size_t>(width) * height * num_labels, kInfiniteCost);
}

double GridMrf::Energy(const std::vector<int>& labels, const Pairwise& pairwise) const {
  double energy = 0.0;
  for (int y = 0; y < height_; ++y) {
    for (int x = 0; x < width_; ++x) {
      const int p = y * width_ + x;
      const int lp = labels[p];
      if (lp < 0) continue;
      energy += data_cost(p, lp);
      const bool has_right = x + 1 < width_ || (wrap_x_ && width_ > 1);
      if (has_right) {
        const int q = y * width_ + (x + 1 < width_ ? x + 1 : 0);
        if (labels[q] >= 0 && labels[q] != lp) energy += pairwise(p, q, lp, labels[q]);
      }
      if (y + 1 < height_) {
        const int q = p + width_;
        if (labels[q] >= 0 && labels[q] != lp) energy += pairwise(p, q, lp, labels[q]);
      }
    }
  }
  return energy;
}

std::vector<int> GridMrf::Solve(const Pairwise& pairwise,
                                const AlphaExpansionOptions& options) const {
  return Solve(std::vector<int>(static_cast<size_t>(width_) * height_, -1), pairwise, options);
}

std::vector<int> GridMrf::Solve(std::vector<int> labels, const Pairwise& pairwise,
                                const AlphaExpansionOptions& options) const {
  if (const Status st = options.Check(); !st.ok())
    throw std::invalid_argument("alpha expansion options: " + st.message());
  const int n = width_ * height_;
  if (static_cast<int>(labels.size()) != n) {
    throw std::invalid_argument("GridMrf::Solve: initial labelling has the wrong size");
  }
  std::vector<char> label_used(num_labels_, 0);
  for (int p = 0; p < n; ++p) {
    int best = -1;
    float best_cost = kInfiniteCost;
    for (int l = 0; l < num_labels_; ++l) {
      const float c = data_cost(p, l);
      if (c < kInfiniteCost) label_used[l] = 1;
      if (c < best_cost) {
        best_cost = c;
        best = l;
      }
    }
    if (labels[p] < 0 || labels[p] >= num_labels_ || data_cost(p, labels[p]) >= kInfiniteCost) {
      labels[p] = best;
    }
  }
  double energy = Energy(labels, pairwise);
  for (int cycle = 0; cycle < options.max_cycles; ++cycle) {
    const double before = energy;
    for (int alpha = 0; alpha < num_labels_; ++alpha) {
      if (label_used[alpha]) Expand(alpha, pairwise, &labels, &energy);
    }
    if (before - energy <= options.min_relative_decrease * std::abs(before)) break;
  }
  return labels;
}

bool GridMrf::Expand(int alpha, const Pairwise& pairwise, std::vector<int>* labels_in,
                     double* energy) const {
  std::vector<int>& labels = *labels_in;
  const int n = width_ * height_;
  std::vector<int> node(n, -1);
  int num_nodes = 0;
  for (int p = 0; p < n; ++p) {
    if (labels[p] >= 0 && labels[p] != alpha && data_cost(p, alpha) < kInfiniteCost) {
      node[p] = num_nodes++;
    }
  }
  if (num_nodes == 0) return false;

  using Graph = maxflow::Graph_DDD;
  auto graph = std::make_unique<Graph>(num_nodes, 2 * num_nodes);
  graph->add_node(num_nodes);
  // Unary costs of each node for x = 0 (keep its label) and x = 1 (take alpha).
  std::vector<double> cost0(num_nodes), cost1(num_nodes);
  for (int p = 0; p < n; ++p) {
    if (node[p] < 0) continue;
    cost0[node[p]] = data_cost(p, labels[p]);
    cost1[node[p]] = data_cost(p, alpha);
  }
  auto add_pair = [&](int p, int q) {
    const int a = labels[p], b = labels[q];
    if (a < 0 || b < 0) return;
    const int np = node[p], nq = node[q];
    if (np < 0 && nq < 0) return;
    if (nq < 0) {  // q keeps b.
      if (a != b) cost0[np] += pairwise(p, q, a, b);
      if (alpha != b) cost1[np] += pairwise(p, q, alpha, b);
      return;
    }
    if (np < 0) {  // p keeps a.
      if (a != b) cost0[nq] += pairwise(p, q, a, b);
      if (a != alpha) cost1[nq] += pairwise(p, q, a, alpha);
      return;
    }
    const double e00 = a == b ? 0.0 : pairwise(p, q, a, b);
    const double e01 = pairwise(p, q, a, alpha);
    const double e10 = pairwise(p, q, alpha, b);
    double e00t = e00;
    // Truncation of a non-submodular table: lower e00 until e00 <= e01 + e10.
    if (e00t > e01 + e10) e00t = e01 + e10;
    // E = e00 + (e10 - e00) x_p + (0 - e10) x_q + (e01 + e10 - e00) (1 - x_p) x_q.
    cost0[np] += e00t;
    cost1[np] += e10;
    cost1[nq] -= e10;
    const double c = e01 + e10 - e00t;
    if (c > 0) graph->add_edge(np, nq, c, 0.0);
  };
  for (int y = 0; y < height_; ++y) {
    for (int x = 0; x < width_; ++x) {
      const int p = y * width_ + x;
      if (x + 1 < width_) {
        add_pair(p, p + 1);
      } else if (wrap_x_ && width_ > 1) {
        add_pair(p, y * width_);
      }
      if (y + 1 < height_) add_pair(p, p + width_);
    }
  }
  for (int i = 0; i < num_nodes; ++i) {
    const double m = std::min(cost0[i], cost1[i]);
    // Source side = keep (x = 0): cutting the sink edge costs cost0.
    graph->add_tweights(i, cost1[i] - m, cost0[i] - m);
  }
  graph->maxflow();
  std::vector<int> proposal = labels;
  bool changed = false;
  for (int p = 0; p < n; ++p) {
    if (node[p] >= 0 && graph->what_segment(node[p]) == Graph::SINK) {
      proposal[p] = alpha;
      changed = true;
    }
  }
  if (!changed) return false;
  const double new_energy = Energy(proposal, pairwise);
  if (new_energy >= *energy) return false;
  labels.swap(proposal);
  *energy = new_energy;
  return true;
}

}  // namespace casual3d::stitch

#pragma once

// Multi-label MRF on a 4-connected grid with truncated-linear pairwise terms,
// minimised by sequential tree-reweighted message passing (TRW-S,
// Kolmogorov 2006). The dense stage uses it for Eq. 1:
//   E(x) = sum_i U_i(x_i) + sum_(i,j) w_ij * min(|x_i - x_j|, T)
// where U is the data term (Eq. 3 plus Eq. 4) and w_ij * min(|.|, T) is
// lambda_smooth * w_color * w_depth (Eq. 2) with w_depth truncated linear in
// the label (inverse depth) difference. Messages are computed in O(L) per
// edge with the lower-envelope distance transform of Felzenszwalb and
// Huttenlocher (2006), so one iteration costs O(pixels * labels).
//
// Memory: one message of L labels per edge, half of what storing both
// directions takes, stored as half floats where the CPU has F16C (about
// 2 * pixels * L * 2 bytes, otherwise 4; see TrwsMessageBytes). Speed: the
// distance transforms run on eight labels at a time with AVX2 where the CPU
// has it (bit-identical to the SSE2 code used otherwise), the beliefs and
// labelling costs are vectorised loops, and each node's data is prefetched
// two nodes ahead.

#include <cstddef>
#include <cstdint>
#include <vector>

namespace casual3d::depth {

struct GridMrf {
  int width = 0;
  int height = 0;
  int num_labels = 0;
  std::vector<float> unary;  // (y * width + x) * num_labels + label.
  std::vector<float>
      weight_right;  // width*height: weight of edge (x,y)-(x+1,y), >= 0; last column unused.
  std::vector<float>
      weight_down;     // width*height: weight of edge (x,y)-(x,y+1), >= 0; last row unused.
  int truncation = 1;  // T, in labels (>= 1).
};

struct TrwsOptions {
  int max_iterations = 12;  // Forward+backward passes. [1, 1000].
  double relative_tolerance =
      1e-4;          // A pass "improves" when the best energy drops by more. [0, 1].
  int patience = 3;  // Stop after this many passes without improvement. [1, 1000].
  // Send messages with AVX2 where the CPU has it. The results are the same to
  // the bit either way (the tests compare the two).
  bool avx2_messages = true;
  // Store the messages as IEEE half floats where the CPU has AVX2 and F16C
  // (TrwsHalfMessagesAvailable): half the memory and memory traffic; the
  // arithmetic stays in float. The messages lie in [0, w T] and are rounded
  // to 11 significant bits when stored.
  bool half_messages = true;
};

struct TrwsResult {
  std::vector<uint16_t> labels;       // Best labelling found, row-major.
  double energy = 0.0;                // Its energy.
  int iterations = 0;                 // Passes run (each a forward and a backward sweep).
  std::vector<double> pass_energies;  // Energy of the labelling of each pass, in order.
};

class BufferPool;  // huge_pages.h

// Minimises the MRF. Requires num_labels in [1, 65535], consistent sizes and
// non-negative edge weights (throws std::invalid_argument otherwise).
// Deterministic. With a `pool`, the message storage comes from it and goes
// back to it (the result does not depend on it).
TrwsResult SolveTrws(const GridMrf& mrf, const TrwsOptions& options = TrwsOptions(),
                     BufferPool* pool = nullptr);

// Bytes of message storage SolveTrws allocates for a width x height grid,
// with half or float messages.
size_t TrwsMessageBytes(int width, int height, int num_labels, bool half = false);

// True when SolveTrws can store half messages on this CPU.
bool TrwsHalfMessagesAvailable();

// Energy of a labelling.
double MrfEnergy(const GridMrf& mrf, const std::vector<uint16_t>& labels);

}  // namespace casual3d::depth

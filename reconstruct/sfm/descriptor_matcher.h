#pragma once

// Nearest-neighbour matching of SIFT descriptors on the CPU, the part of
// COLMAP's exhaustive and sequential matchers that dominates the sparse stage
// (COLMAP 3.8's CPU matcher multiplies the descriptor matrices in 32-bit
// integers: about 0.23 s per pair of 2048-feature photos on 2 cores).
//
// The criteria are COLMAP's (SiftMatchingOptions): the similarity of two
// descriptors is their dot product (descriptors are unsigned bytes scaled to
// length 512), turned into the angle acos(dot / 512^2); a feature of photo A
// matches its most similar feature of photo B when that angle is at most
// `max_distance` and below `max_ratio` times the angle to the second most
// similar one; with `cross_check` the same must hold from B to A. Ties go to
// the lower index, and a tie for the best fails the ratio test.
//
// Speed: the dot products are sums of at most 128 products of bytes, below
// 2^24, so single-precision floats hold them exactly whatever the order of
// summation. They are computed in tiles of 4 x 16 with the best two of every
// row and column kept as the tiles go (no distance matrix is stored), eight
// lanes at a time; the loader picks an AVX2+FMA build where the CPU has it.
// Results are the same on every path.

#include <cstdint>
#include <functional>
#include <string>
#include <utility>
#include <vector>

namespace casual3d::sfm {

inline constexpr int kSiftDimensions = 128;

// One photo's descriptors: rows x 128 bytes, row-major.
struct SiftDescriptors {
  int rows = 0;
  std::vector<uint8_t> data;
};

struct DescriptorMatchOptions {
  double max_ratio = 0.8;     // COLMAP's SiftMatching.max_ratio. (0, 1].
  double max_distance = 0.7;  // COLMAP's SiftMatching.max_distance (radians). (0, pi/2].
  bool cross_check = true;    // COLMAP's SiftMatching.cross_check.
};

// Matches as (index in a, index in b), in increasing order of the index in a.
using FeatureMatches = std::vector<std::pair<uint32_t, uint32_t>>;

// Matches the descriptors of two photos. Deterministic. Throws
// std::invalid_argument when a descriptor array does not hold rows x 128
// bytes or the options are out of range.
FeatureMatches MatchDescriptors(const SiftDescriptors& a, const SiftDescriptors& b,
                                const DescriptorMatchOptions& options = DescriptorMatchOptions());

// Pairs (i < j) of photos 0..n-1 to match: every pair.
std::vector<std::pair<int, int>> ExhaustivePairs(int n);

// Pairs of photos in capture (name) order that COLMAP's sequential matcher
// without loop detection considers: each photo with the next overlap - 1 ones
// and with those 2^k ahead for k < overlap (quadratic overlap).
std::vector<std::pair<int, int>> SequentialPairs(int n, int overlap);

// Matches every pair on `num_threads` threads (0 = all cores). Result i
// belongs to pairs[i]. on_pair(done, total) is called, one call at a time, as
// pairs finish (may be empty); when it returns false no further pair is
// started and the unstarted pairs' results stay empty.
std::vector<FeatureMatches> MatchPairs(const std::vector<SiftDescriptors>& photos,
                                       const std::vector<std::pair<int, int>>& pairs,
                                       const DescriptorMatchOptions& options, int num_threads,
                                       const std::function<bool(int, int)>& on_pair);

}  // namespace casual3d::sfm

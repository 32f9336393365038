#include "reconstruct/sfm/descriptor_matcher.h"

#include <algorithm>
#include <cmath>
#include <random>
#include <stdexcept>

#include <gtest/gtest.h>

#include "reconstruct/sfm/testing/sift_like.h"

namespace casual3d::sfm {
namespace {

using testing::RandomSiftDescriptors;
using testing::SiftLikeBytes;

// b: a's rows in a shuffled order with noise, plus unrelated rows.
SiftDescriptors Perturbed(const SiftDescriptors& a, int extra, double noise, std::mt19937* rng) {
  std::vector<int> order(a.rows);
  for (int i = 0; i < a.rows; ++i) order[i] = i;
  std::shuffle(order.begin(), order.end(), *rng);
  std::normal_distribution<double> n(0.0, noise);
  SiftDescriptors b;
  for (int i : order) {
    std::vector<double> v(kSiftDimensions);
    for (int k = 0; k < kSiftDimensions; ++k)
      v[k] = std::max(0.0, a.data[static_cast<size_t>(i) * kSiftDimensions + k] + n(*rng));
    const std::vector<uint8_t> bytes = SiftLikeBytes(v);
    b.data.insert(b.data.end(), bytes.begin(), bytes.end());
  }
  const SiftDescriptors more = RandomSiftDescriptors(extra, rng);
  b.data.insert(b.data.end(), more.data.begin(), more.data.end());
  b.rows = a.rows + extra;
  return b;
}

// COLMAP's rules written out directly: integer dot products, one scan per
// feature, first strictly greater wins.
FeatureMatches Reference(const SiftDescriptors& a, const SiftDescriptors& b,
                         const DescriptorMatchOptions& o) {
  auto dot = [&](int i, int j) {
    long s = 0;
    for (int k = 0; k < kSiftDimensions; ++k)
      s += static_cast<long>(a.data[static_cast<size_t>(i) * kSiftDimensions + k]) *
           b.data[static_cast<size_t>(j) * kSiftDimensions + k];
    return s;
  };
  auto accept = [&](long best, long second, int index) {
    if (index < 0) return -1;
    const double bd = std::acos(std::min(1.0, best / (512.0 * 512.0)));
    const double sd = std::acos(std::min(1.0, second / (512.0 * 512.0)));
    if (bd > o.max_distance || bd >= o.max_ratio * sd) return -1;
    return index;
  };
  auto one_way = [&](bool from_a, int i) {
    long best = 0, second = 0;
    int index = -1;
    const int n = from_a ? b.rows : a.rows;
    for (int j = 0; j < n; ++j) {
      const long d = from_a ? dot(i, j) : dot(j, i);
      if (d > best) {
        second = best;
        best = d;
        index = j;
      } else if (d > second) {
        second = d;
      }
    }
    return accept(best, second, index);
  };
  FeatureMatches out;
  for (int i = 0; i < a.rows; ++i) {
    const int j = one_way(true, i);
    if (j < 0) continue;
    if (o.cross_check && one_way(false, j) != i) continue;
    out.emplace_back(i, j);
  }
  return out;
}

TEST(DescriptorMatcherTest, EqualsTheStraightforwardRulesOnManySizes) {
  std::mt19937 rng(7);
  // Sizes that are and are not multiples of the 4 x 16 tiles.
  for (auto [na, extra] : {std::pair{1, 0}, {3, 2}, {4, 12}, {17, 30}, {63, 1}, {200, 57}}) {
    const SiftDescriptors a = RandomSiftDescriptors(na, &rng);
    const SiftDescriptors b = Perturbed(a, extra, 6.0, &rng);
    for (bool cross : {true, false}) {
      DescriptorMatchOptions o;
      o.cross_check = cross;
      const FeatureMatches got = MatchDescriptors(a, b, o);
      EXPECT_EQ(got, Reference(a, b, o)) << na << " x " << na + extra << " cross " << cross;
    }
    // Both directions.
    EXPECT_EQ(MatchDescriptors(b, a), Reference(b, a, DescriptorMatchOptions()));
  }
}

TEST(DescriptorMatcherTest, FindsPlantedCorrespondences) {
  std::mt19937 rng(11);
  const SiftDescriptors a = RandomSiftDescriptors(500, &rng);
  const SiftDescriptors b = Perturbed(a, 300, 4.0, &rng);
  const FeatureMatches m = MatchDescriptors(a, b);
  EXPECT_GT(m.size(), 450u);
  // Every match is to the row that was planted from it: same bytes up to noise.
  for (const auto& [i, j] : m) {
    ASSERT_LT(j, 500u);
    long d = 0;
    for (int k = 0; k < kSiftDimensions; ++k) {
      const long e = static_cast<long>(a.data[i * kSiftDimensions + k]) - b.data[j * kSiftDimensions + k];
      d += e * e;
    }
    EXPECT_LT(std::sqrt(static_cast<double>(d)), 120.0);
  }
}

TEST(DescriptorMatcherTest, RatioDistanceAndTies) {
  std::mt19937 rng(3);
  const SiftDescriptors a = RandomSiftDescriptors(1, &rng);
  // Two identical candidates: a tie for the best fails the ratio test.
  SiftDescriptors twice;
  twice.rows = 2;
  twice.data = a.data;
  twice.data.insert(twice.data.end(), a.data.begin(), a.data.end());
  EXPECT_TRUE(MatchDescriptors(a, twice).empty());
  DescriptorMatchOptions loose;
  loose.max_ratio = 1.0;  // best >= 1.0 * second still fails on a tie.
  EXPECT_TRUE(MatchDescriptors(a, twice, loose).empty());
  // One candidate, identical: matches (the second best is 0: 90 degrees).
  SiftDescriptors once;
  once.rows = 1;
  once.data = a.data;
  EXPECT_EQ(MatchDescriptors(a, once), (FeatureMatches{{0, 0}}));
  // One unrelated candidate: its angle exceeds max_distance.
  const SiftDescriptors other = RandomSiftDescriptors(1, &rng);
  DescriptorMatchOptions tight;
  tight.max_distance = 0.05;
  EXPECT_TRUE(MatchDescriptors(a, other, tight).empty());
  // Empty photos match nothing.
  EXPECT_TRUE(MatchDescriptors(a, SiftDescriptors()).empty());
}

TEST(DescriptorMatcherTest, RejectsMalformedInput) {
  SiftDescriptors bad;
  bad.rows = 2;
  bad.data.resize(100);
  std::mt19937 rng(1);
  const SiftDescriptors good = RandomSiftDescriptors(3, &rng);
  EXPECT_THROW(MatchDescriptors(bad, good), std::invalid_argument);
  DescriptorMatchOptions o;
  o.max_ratio = 0;
  EXPECT_THROW(MatchDescriptors(good, good, o), std::invalid_argument);
  EXPECT_THROW(MatchPairs({good}, {{0, 1}}, DescriptorMatchOptions(), 1, nullptr),
               std::invalid_argument);
}

TEST(DescriptorMatcherTest, PairLists) {
  EXPECT_EQ(ExhaustivePairs(4).size(), 6u);
  EXPECT_TRUE(ExhaustivePairs(1).empty());
  // overlap 2: the next photo, and those 1 and 2 ahead (quadratic).
  const std::vector<std::pair<int, int>> want = {{0, 1}, {0, 2}, {1, 2}, {1, 3}, {2, 3}, {2, 4}, {3, 4}};
  EXPECT_EQ(SequentialPairs(5, 2), want);
  // overlap 4 over 20 photos: offsets 1, 2, 3 and 4, 8.
  const auto seq = SequentialPairs(20, 4);
  for (const auto& [i, j] : seq) {
    const int d = j - i;
    EXPECT_TRUE(d == 1 || d == 2 || d == 3 || d == 4 || d == 8) << d;
  }
  EXPECT_EQ(seq.size(), 19u + 18u + 17u + 16u + 12u);
}

TEST(DescriptorMatcherTest, MatchPairsOnThreadsEqualsOnePairAtATime) {
  std::mt19937 rng(5);
  std::vector<SiftDescriptors> photos;
  photos.push_back(RandomSiftDescriptors(120, &rng));
  for (int i = 0; i < 4; ++i) photos.push_back(Perturbed(photos[0], 20 * i, 5.0, &rng));
  const auto pairs = ExhaustivePairs(5);
  int calls = 0, last = 0;
  const auto all = MatchPairs(photos, pairs, DescriptorMatchOptions(), 3, [&](int done, int total) {
    ++calls;
    last = done;
    EXPECT_EQ(total, 10);
    return true;
  });
  ASSERT_EQ(all.size(), pairs.size());
  EXPECT_EQ(calls, 10);
  EXPECT_EQ(last, 10);
  for (size_t k = 0; k < pairs.size(); ++k)
    EXPECT_EQ(all[k], MatchDescriptors(photos[pairs[k].first], photos[pairs[k].second]));
  // Stopping after the third pair: no pair is started afterwards.
  calls = 0;
  const auto stopped = MatchPairs(photos, pairs, DescriptorMatchOptions(), 1, [&](int done, int) {
    ++calls;
    return done < 3;
  });
  EXPECT_EQ(calls, 3);
  for (size_t k = 3; k < pairs.size(); ++k) EXPECT_TRUE(stopped[k].empty());
  EXPECT_EQ(stopped[2], all[2]);
}

}  // namespace
}  // namespace casual3d::sfm

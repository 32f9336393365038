#include "format/f64x2.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <random>

namespace casual3d::internal {
namespace {

uint64_t Bits(double x) {
  uint64_t b;
  std::memcpy(&b, &x, sizeof(b));
  return b;
}

// Every operation of the vector version gives the plain version's bits, lane
// by lane, on random values and on signed zeros, infinities, tiny and huge
// numbers (the simplifier's results must not depend on the build).
TEST(F64x2Test, VectorOperationsGiveThePlainBits) {
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> uniform(-4.0, 4.0);
  const double inf = std::numeric_limits<double>::infinity();
  const double specials[] = {0.0, -0.0, 1.0, -1.0, inf, -inf, 1e-310, -1e-310, 1e300, 3.5};
  auto value = [&](int i) {
    return i % 3 == 0 ? specials[rng() % 10] : uniform(rng) * std::exp2(uniform(rng) * 8);
  };
  for (int trial = 0; trial < 20000; ++trial) {
    double a[2], b[2];
    for (int l = 0; l < 2; ++l) {
      a[l] = value(trial + l);
      b[l] = value(trial + 2 * l + 1);
    }
    const plain::F64x2 pa = plain::LoadF64x2(a), pb = plain::LoadF64x2(b);
    const F64x2 va = LoadF64x2(a), vb = LoadF64x2(b);
    const plain::F64x2 expected[] = {pa + pb,
                                     pa - pb,
                                     pa * pb,
                                     pa / pb,
                                     plain::SqrtF64x2(pa * pa),
                                     plain::MinF64x2(pa, pb),
                                     plain::MaxF64x2(pa, pb),
                                     plain::UnpackLo(pa, pb),
                                     plain::UnpackHi(pa, pb),
                                     plain::SplatF64x2(a[1])};
    const F64x2 got[] = {va + vb,          va - vb,          va * vb,           va / vb,
                         SqrtF64x2(va * va), MinF64x2(va, vb), MaxF64x2(va, vb),
                         UnpackLo(va, vb), UnpackHi(va, vb), SplatF64x2(a[1])};
    for (size_t op = 0; op < sizeof(got) / sizeof(got[0]); ++op) {
      const double e0 = plain::Lane0(expected[op]), e1 = plain::Lane1(expected[op]);
      const double g0 = Lane0(got[op]), g1 = Lane1(got[op]);
      if (std::isnan(e0) || std::isnan(e1)) continue;  // Not used with NaN.
      ASSERT_EQ(Bits(g0), Bits(e0)) << "op " << op << " a " << a[0] << " b " << b[0];
      ASSERT_EQ(Bits(g1), Bits(e1)) << "op " << op << " a " << a[1] << " b " << b[1];
    }
  }
}

}  // namespace
}  // namespace casual3d::internal

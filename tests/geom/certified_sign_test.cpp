// SPDX-License-Identifier: GPL-3.0-or-later
#include "fiberfluid/geom/certified_sign.hpp"

#include <gtest/gtest.h>

#include <array>
#include <cstdlib>
#include <random>

namespace fiberfluid::geom {
namespace {

// Integer coordinates below 2^20 give determinants that __int128 holds
// exactly: the reference the float signs are checked against.
using Point = std::array<long long, 3>;
__extension__ using Int128 = __int128;  // GCC and clang: exact products of three 21-bit numbers

Int128 exact_orientation(const Point& a, const Point& b, const Point& c, const Point& d) {
  Int128 u[3], v[3], w[3];
  for (int k = 0; k < 3; ++k) {
    u[k] = b[k] - a[k];
    v[k] = c[k] - a[k];
    w[k] = d[k] - a[k];
  }
  return w[0] * (u[1] * v[2] - u[2] * v[1]) + w[1] * (u[2] * v[0] - u[0] * v[2]) +
         w[2] * (u[0] * v[1] - u[1] * v[0]);
}

int sign(Int128 x) { return x > 0 ? 1 : x < 0 ? -1 : 0; }

std::array<double, 3> to_double(const Point& p, double scale, double offset) {
  return {offset + scale * static_cast<double>(p[0]), offset + scale * static_cast<double>(p[1]),
          offset + scale * static_cast<double>(p[2])};
}

TEST(CertifiedSign, NeverContradictsTheExactSignAndDecidesGenericCases) {
  std::mt19937_64 random(7);
  std::uniform_int_distribution<long long> coordinate(-(1 << 19), 1 << 19);
  std::uniform_int_distribution<long long> small(-3, 3);
  long long decided = 0, degenerate = 0, degenerate_decided = 0, contradictions = 0;
  for (int trial = 0; trial < 200000; ++trial) {
    Point a, b, c, d;
    for (int k = 0; k < 3; ++k) {
      a[k] = coordinate(random);
      b[k] = coordinate(random);
      c[k] = coordinate(random);
    }
    if (trial % 2 == 0) {
      for (int k = 0; k < 3; ++k) d[k] = coordinate(random);
    } else {  // on the plane of a, b, c, or one unit off it
      const long long s = small(random), t = small(random);
      for (int k = 0; k < 3; ++k) d[k] = a[k] + s * (b[k] - a[k]) + t * (c[k] - a[k]);
      d[trial % 3] += (trial / 2) % 3 - 1;
    }
    const Int128 volume = exact_orientation(a, b, c, d);
    const int expected = sign(volume);
    // Half the trials shifted to 1 + k 2^-30: still exact images of the
    // integers (the determinant is translation-invariant), but the float
    // differences now cancel the leading digits.
    const double scale = trial % 4 < 2 ? 1.0 : 0x1p-30, offset = trial % 4 < 2 ? 0.0 : 1.0;
    const auto da = to_double(a, scale, offset), db = to_double(b, scale, offset),
               dc = to_double(c, scale, offset), dd = to_double(d, scale, offset);
    const int got = certified_orientation(da.data(), db.data(), dc.data(), dd.data());
    if (got != 0 && got != expected) ++contradictions;
    decided += got != 0;
    if (trial % 2 == 1 && volume >= -1 && volume <= 1) {
      ++degenerate;
      degenerate_decided += got != 0;
    }
  }
  EXPECT_EQ(contradictions, 0);
  EXPECT_GT(decided, 100000);                 // random points: nearly all certified
  EXPECT_GT(degenerate, 10000);               // the near-coplanar half was exercised
  EXPECT_LT(degenerate_decided, degenerate);  // and there the filter says "unsure"
}

TEST(CertifiedSign, TheMeanOfTwoVolumesIsTheMidpointsSign) {
  // orientation(a, b, c, m) at m = (p + q) / 2 is the mean of the volumes at p
  // and q: p and q on either side at distances 1 and 3 put m on q's side,
  // and symmetric distances put m on the plane (unsure, never a sign).
  const double a[3] = {0, 0, 0}, b[3] = {1, 0, 0}, c[3] = {0, 1, 0};
  const double p[3] = {0.3, 0.2, -1.0}, q[3] = {0.1, 0.6, 3.0}, r[3] = {0.9, -4.0, 1.0};
  double dp, bp, dq, bq, dr, br;
  orientation_with_bound(a, b, c, p, dp, bp);
  orientation_with_bound(a, b, c, q, dq, bq);
  orientation_with_bound(a, b, c, r, dr, br);
  EXPECT_EQ(certified_mean_sign(dp, bp, dq, bq), 1);
  EXPECT_EQ(certified_mean_sign(dp, bp, dr, br), 0);
  EXPECT_EQ(certified_mean_sign(-dq, bq, dp, bp), -1);
}

TEST(CertifiedSign, FilterRangeExcludesWhatCouldUnderflowOrOverflow) {
  EXPECT_TRUE(coordinate_in_filter_range(0.0));
  EXPECT_TRUE(coordinate_in_filter_range(-3.5e-12));
  EXPECT_TRUE(coordinate_in_filter_range(1e60));
  EXPECT_FALSE(coordinate_in_filter_range(1e-70));
  EXPECT_FALSE(coordinate_in_filter_range(-2e70));
  EXPECT_FALSE(coordinate_in_filter_range(std::nan("")));
}

}  // namespace
}  // namespace fiberfluid::geom

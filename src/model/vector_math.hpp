// SPDX-License-Identifier: GPL-3.0-or-later
// Elementary functions written so that a loop of them vectorises: no calls,
// no branches (glibc's exp is a call per element unless -ffast-math, which
// the project does not use). The laws' block evaluation runs on them.
#pragma once

#include <cmath>
#include <cstdint>
#include <cstring>

namespace fiberfluid::model {

// exp(x) to within 2 ulp of the correctly rounded value, for x in
// [-708, ln(DBL_MAX)] (tested against std::exp:
// FiberLaw.TheVectorExponentialIsWithinTwoUlp); above, +inf (an overflow
// stays visible to a law's checks); below, 0 (std::exp's subnormals there
// are flushed). NaN stays NaN; exp(0) is exactly 1.
//
// The classic reduction (Cody and Waite; Muller, "Elementary Functions",
// ch. 11): x = k ln2 + r with k = round(x / ln2), |r| <= ln2 / 2, ln2 split
// in two so that k ln2_hi is exact; exp(r) by its Taylor series to degree 13
// (truncation below 5e-18 relative); 2^k put into the exponent field (as
// 2^(k-1) times 2, so that k = 1024 fits).
inline double vector_exp(double x) {
  constexpr double kShift = 0x1.8p52;  // t = x / ln2 + kShift: k in t's low bits
  constexpr double kLog2e = 0x1.71547652b82fep0;
  constexpr double kLn2Hi = 0x1.62e42fefa3800p-1, kLn2Lo = 0x1.ef35793c76730p-45;
  constexpr double kHighest = 709.782712893384;  // ln(DBL_MAX)
  const double given = x;
  x = x < -708.0 ? -708.0 : x;
  x = x > kHighest ? kHighest : x;
  const double t = x * kLog2e + kShift;
  const double k = t - kShift;
  const double r = (x - k * kLn2Hi) - k * kLn2Lo;
  double p = 1.0 / 6227020800.0;  // 1 / 13!
  p = p * r + 1.0 / 479001600.0;
  p = p * r + 1.0 / 39916800.0;
  p = p * r + 1.0 / 3628800.0;
  p = p * r + 1.0 / 362880.0;
  p = p * r + 1.0 / 40320.0;
  p = p * r + 1.0 / 5040.0;
  p = p * r + 1.0 / 720.0;
  p = p * r + 1.0 / 120.0;
  p = p * r + 1.0 / 24.0;
  p = p * r + 1.0 / 6.0;
  p = p * r + 0.5;
  p = p * r + 1.0;
  p = p * r + 1.0;
  // 2^k: k + 1023 in the exponent field (t's bits are kShift's plus k).
  std::uint64_t t_bits, shift_bits;  // unsigned: a NaN's bits wrap, defined
  std::memcpy(&t_bits, &t, sizeof t);
  std::memcpy(&shift_bits, &kShift, sizeof kShift);
  const std::uint64_t scale_bits = (t_bits - shift_bits + 1022) << 52;  // 2^(k-1)
  double scale;
  std::memcpy(&scale, &scale_bits, sizeof scale);
  const double value = p * scale * 2.0;
  return given > kHighest ? HUGE_VAL : (given < -708.0 ? 0.0 : value);
}

}  // namespace fiberfluid::model

// SPDX-License-Identifier: GPL-3.0-or-later
// Orientation signs in plain doubles, trusted only where a forward error
// bound certifies them: the float pre-filter in front of CGAL's exact
// predicates (the pruning and the convexity check). The bounds are
// Shewchuk's (Adaptive Precision Floating-Point Arithmetic and Fast Robust
// Geometric Predicates, 1997: orient3d's errboundA = (7 + 56 eps) eps and
// orient2d's (3 + 16 eps) eps times the permanent, with eps = 2^-53; 8 eps and
// 4 eps are used here). They assume no overflow or underflow, which
// coordinate_in_filter_range guarantees for the inputs.
#pragma once

#include <cmath>

namespace fiberfluid::geom {

inline constexpr double kOrientationErrorFactor = 8.0 * 0x1p-53;
inline constexpr double kOrientation2dErrorFactor = 4.0 * 0x1p-53;

// Inputs whose every coordinate is 0 or of magnitude in [1e-60, 1e60]: their
// differences, and products of three of them, neither overflow nor underflow.
inline bool coordinate_in_filter_range(double x) {
  const double a = std::abs(x);
  return a == 0.0 || (a >= 1e-60 && a <= 1e60);
}

inline int certified(double det, double bound) { return det > bound ? 1 : det < -bound ? -1 : 0; }

// det[b - a, c - a, d - a] in doubles and the bound on its error.
inline void orientation_with_bound(const double* a, const double* b, const double* c,
                                   const double* d, double& det, double& bound) {
  const double ux = b[0] - a[0], uy = b[1] - a[1], uz = b[2] - a[2];
  const double vx = c[0] - a[0], vy = c[1] - a[1], vz = c[2] - a[2];
  const double wx = d[0] - a[0], wy = d[1] - a[1], wz = d[2] - a[2];
  const double uyvz = uy * vz, uzvy = uz * vy, uzvx = uz * vx, uxvz = ux * vz, uxvy = ux * vy,
               uyvx = uy * vx;
  det = wx * (uyvz - uzvy) + wy * (uzvx - uxvz) + wz * (uxvy - uyvx);
  bound = kOrientationErrorFactor * (std::abs(wx) * (std::abs(uyvz) + std::abs(uzvy)) +
                                     std::abs(wy) * (std::abs(uzvx) + std::abs(uxvz)) +
                                     std::abs(wz) * (std::abs(uxvy) + std::abs(uyvx)));
}

// The sign of det[b - a, c - a, d - a] (CGAL::orientation(a, b, c, d): +1 when
// d is in front of the plane of a, b, c seen counter-clockwise), or 0 when the
// doubles cannot tell it from zero.
inline int certified_orientation(const double* a, const double* b, const double* c,
                                 const double* d) {
  double det, bound;
  orientation_with_bound(a, b, c, d, det, bound);
  return certified(det, bound);
}

// The 2D orientation (b - a) x (d - a) in coordinates u, w of 3D points, and
// the bound on its error.
inline void orientation_2d_with_bound(const double* a, const double* b, const double* d, int u,
                                      int w, double& det, double& bound) {
  const double left = (b[u] - a[u]) * (d[w] - a[w]), right = (b[w] - a[w]) * (d[u] - a[u]);
  det = left - right;
  bound = kOrientation2dErrorFactor * (std::abs(left) + std::abs(right));
}

// The sign of the mean of two evaluated determinants with their bounds, or 0.
// The predicates at the midpoint of p and q are linear in that point, so
// they are such means, and the midpoint is never rounded.
inline int certified_mean_sign(double first, double first_bound, double second,
                               double second_bound) {
  const double sum = first + second;
  return certified(sum,
                   first_bound + second_bound + 0x1p-52 * (std::abs(first) + std::abs(second)));
}

}  // namespace fiberfluid::geom

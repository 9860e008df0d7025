// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
// A fiber's reading (strain, tension, force), and how it is made from the
// fiber's force coefficients: what the surface-tension term (terms.cpp) and
// the bulk-fiber term (bulk_fiber_term.cpp) report for a fiber.

#include <Eigen/Core>

#include "fiberfluid/model/pair_stencil.hpp"

namespace fiberfluid::model {

// One fiber at a state, for reports (a fibers .vtu, a face's surface
// tension): its ends i < j, its strain e = r / L - 1, the force it exerts on
// its end i (axis factors applied; on j the opposite) and that force's
// component along the fiber towards j, its tension (positive when it pulls
// its ends together). A vector spring's force also has a part across the
// fiber, so |force| can exceed |tension|; a central fiber's cannot.
struct FiberReading {
  int i = 0, j = 0;
  double strain = 0.0;
  Eigen::Vector3d force = Eigen::Vector3d::Zero();
  double tension = 0.0;
};

namespace detail {

// A fiber's reading from its force coefficients (pair_stencil.hpp): the
// residual's part on i is m (c1 g), the force the fiber exerts on i its
// opposite. b = x_i - x_j, d = u_i - u_j, L its reference length.
template <class K>
inline FiberReading read_fiber(int i, int j, const PairCoefficients& c, const Eigen::Vector3d& b,
                               const Eigen::Vector3d& d, double L, const Eigen::Vector3d& m) {
  FiberReading out;
  out.i = i;
  out.j = j;
  const double r = b.norm();
  out.strain = fiber_strain(r, L);
  Eigen::Vector3d residual;
  for (int a = 0; a < 3; ++a) residual[a] = m[a] * pair_force<K>(c, b[a], d[a]);
  out.force = -residual;
  out.tension = residual.dot(b) / r;  // the force on i along x_j - x_i
  return out;
}

}  // namespace detail
}  // namespace fiberfluid::model

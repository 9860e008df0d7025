// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
// A fiber's reading (strain, tension, force) from its force coefficients:
// what the surface-tension term (terms.cpp) and the bulk-fiber term
// (bulk_fiber_term.cpp) report for a fiber. Internal to those two files.

#include <Eigen/Core>

#include "fiberfluid/model/pair_stencil.hpp"
#include "fiberfluid/model/terms.hpp"

namespace fiberfluid::model::detail {

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

}  // namespace fiberfluid::model::detail

// SPDX-License-Identifier: GPL-3.0-or-later
// The fiber stencils: the one place where the weight of a fiber and the
// coefficients of its force and tangent in a deformed state are written.
// Every pair kernel (FiberSystem, the Laplacians, the Newton residual,
// tangent and parameter derivatives) uses these.
#pragma once

#include <Eigen/Core>

namespace fiberfluid::model {

// Bulk fiber weight (paper Eq. 6): a_ij = h_ij (|S_i| + |S_j|) / L_ij, with
// h_ij = 1 / (2 (N-1)), or the pruned connection count (PairFactors).
inline double bulk_weight(double h, double area_i, double area_j, double length) {
  return h * (area_i + area_j) / length;
}

// Surface fiber weight (paper Eq. 7): (|S_i| + |S_k|) / (2 |s_i - s_k|^2).
inline double surface_weight(double area_i, double area_k, double length_squared) {
  return (area_i + area_k) / (2.0 * length_squared);
}

// A fiber's strain from its current and reference lengths: e = r / L - 1.
// Every pair loop takes the strain from here (the secant modulus Y(e), the
// tangent's slope Y'(e), a law parameter's derivative dY/dtheta(e)).
inline double fiber_strain(double current, double length) { return current / length - 1.0; }

// A bulk fiber (i, j) at a deformed state (model.md section 7). With
// d = u_i - u_j, b = x_i - x_j, r = |b|, e = r / L - 1, the force on i along
// axis a (m_a: the axis factor) is
//   f_a = m_a a Y(e) d_a
// and its 3x3 tangent block, df_a/du_i,b = -df_a/du_j,b, is
//   T = m_a (c1 I + c2 d b^T),  c1 = a Y(e),  c2 = a Y'(e) / (r L):
// not symmetric once Y depends on the strain. A parameter theta of the law
// adds m_a a dY/dtheta d_a. The pair kernels store or stream c1 and c2.
inline double modulus_coefficient(double weight, double modulus) { return weight * modulus; }
inline double slope_coefficient(double weight, double slope, double current, double length) {
  return weight * slope / (current * length);
}

}  // namespace fiberfluid::model

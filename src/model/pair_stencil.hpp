// SPDX-License-Identifier: GPL-3.0-or-later
// The fiber stencils: the one place where the weight of a fiber, its force in
// a deformed state, its tangent and its parameter derivatives are written.
// Every pair kernel (FiberSystem, the Laplacians, the Newton residual and
// tangent) uses these.
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

// A bulk fiber (i, j) at a deformed state (model.md section 7). With
// d = u_i - u_j, e = |x_i - x_j| / L - 1 and n = (x_i - x_j) / |x_i - x_j|,
// the force on i along axis a is
//   f_a = a m_a Y(e) d_a                             (m_a: the axis factor)
// and its 3x3 tangent block, df_a/du_i,b = -df_a/du_j,b, is
//   T_ab = a m_a (Y(e) delta_ab + Y'(e) d_a n_b / L),
// not symmetric once Y depends on the strain. The force on j is -f.
struct BulkFiber {
  double weight = 0.0;   // a_ij, from the reference
  double length = 1.0;   // L_ij, the reference length
  double modulus = 0.0;  // Y(e)
  double slope = 0.0;    // Y'(e)
  Eigen::Vector3d d = Eigen::Vector3d::Zero();  // u_i - u_j
  Eigen::Vector3d n = Eigen::Vector3d::Zero();  // current unit direction from j to i

  Eigen::Vector3d force(const Eigen::Vector3d& factors) const {
    return weight * modulus * factors.cwiseProduct(d);
  }
  // T w without forming T.
  Eigen::Vector3d tangent_times(const Eigen::Vector3d& factors, const Eigen::Vector3d& w) const {
    return weight * factors.cwiseProduct(modulus * w + (slope * n.dot(w) / length) * d);
  }
  Eigen::Matrix3d tangent(const Eigen::Vector3d& factors) const {
    return weight * factors.asDiagonal() *
           (modulus * Eigen::Matrix3d::Identity() + (slope / length) * d * n.transpose());
  }
  // df/dtheta for a law parameter with dY/dtheta = dmodulus.
  Eigen::Vector3d force_derivative(const Eigen::Vector3d& factors, double dmodulus) const {
    return weight * dmodulus * factors.cwiseProduct(d);
  }
};

}  // namespace fiberfluid::model

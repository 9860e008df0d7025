// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once

#include <Eigen/Core>
#include <vector>

#include "fiberfluid/model/model.hpp"

namespace fiberfluid::model {

// The hydrostatic load (paper Eq. 4's fluid weight): the fluid pushes on
// vertex i with rho |a| h_i S_i, h_i its depth below a level along the
// acceleration a. Written once here; the paper's incremental scheme measures
// depth below the highest point of the geometry it linearises at
// (hydrostatic_depths), Newton's equilibrium below the highest reference
// point (a fixed level, so that q_i is smooth in x).

// The level of the highest point of X along a: min_i x_i . a / |a| (0 for a = 0).
double hydrostatic_level(const Eigen::MatrixXd& X, const Eigen::Vector3d& acceleration);
// h_i = x_i . a / |a| - level for every row of X (zeros for a = 0). X: #V by dim.
Eigen::VectorXd hydrostatic_heads(const Eigen::MatrixXd& X, const Eigen::Vector3d& acceleration,
                                  double level);
// Depth below X's own highest point: heads at hydrostatic_level(X, a), >= 0.
Eigen::VectorXd hydrostatic_depths(const Eigen::MatrixXd& X, const Eigen::Vector3d& acceleration);
// The pressure per unit depth of a hydrostatic load at load factor f: f rho |a|.
double hydrostatic_pressure_per_depth(const Load& load, double factor);

// The exact form of a pressure q (one value per vertex, linear over each
// face): integrated against the linear shape functions of each face,
//   F_i = sum over faces f at i of A_f (q_i + sum_{j in f} q_j) / (m (m + 1)),
// m the face's corners (3; 2 for a 2D polygon's segments), A_f its area
// vector (outward, |A_f| its area). The forces sum to the integral of q n over
// the surface, exactly: for the fluid's weight rho a V (divergence theorem).
// #V by dim.
Eigen::MatrixXd exact_pressure_forces(const Eigen::MatrixXd& X, const Eigen::MatrixXi& F,
                                      const Eigen::VectorXd& q);

// The exact form's weights: the share of face f's area vector at its corner
// i, w_if = (q_i + sum_{j in f} q_j) / (m (m + 1)), so that
// dw_if/dq_v = (1 + [i = v]) / (m (m + 1)). The forces and their tangents use it.
struct ExactFaceShares {
  ExactFaceShares(const Eigen::MatrixXi& F, const Eigen::VectorXd& q);
  double w(int i, Eigen::Index f) const { return per_pressure * (q[i] + face_sum[f]); }
  Eigen::VectorXd q, face_sum;  // per vertex; per face, q summed over its corners
  double per_pressure;          // 1 / (m (m + 1))
};

// The load part of the right-hand side B (paper Eq. 4) at positions X with
// vertex area vectors S (#V by dim), each load scaled by factors[l]. Length
// dim * N + 1; the last (volume) entry is 0.
Eigen::VectorXd load_vector(const Model& model, const Eigen::MatrixXd& X, const Eigen::MatrixXd& S,
                            const std::vector<double>& factors);

// Factors of every load after step k of n.
std::vector<double> load_factors(const Model& model, int step, int steps);

}  // namespace fiberfluid::model

// SPDX-License-Identifier: GPL-3.0-or-later
// A part of Newton's tangent that the contacts add to the bulk's: J + K + C J
// in the full layout, K a stiffness (a sliding contact's friction along its
// slide) and C a mix of the bulk's rows (its friction's dependence on the
// normal force, which is the bulk's residual at the held normal row).
#pragma once

#include <Eigen/Core>
#include <Eigen/SparseCore>

namespace fiberfluid::solve {

struct AddedTangent {
  Eigen::SparseMatrix<double> stiffness;  // K
  Eigen::SparseMatrix<double> row_mix;    // C: row r of J gets C(r, s) times row s

  // J <- J + K + C J. The mixed rows are never themselves mixed into others
  // (tangential rows take normal ones), so C J is read from J in place.
  void add_to(Eigen::MatrixXd& J) const {
    for (int s = 0; s < row_mix.outerSize(); ++s)
      for (Eigen::SparseMatrix<double>::InnerIterator it(row_mix, s); it; ++it)
        J.row(it.row()) += it.value() * J.row(s);
    if (stiffness.nonZeros() > 0) J += stiffness;
  }
  void add_to(Eigen::SparseMatrix<double>& J) const {
    if (row_mix.nonZeros() > 0) {
      const Eigen::SparseMatrix<double> mixed = row_mix * J;
      J += mixed;
    }
    if (stiffness.nonZeros() > 0) J += stiffness;
  }
  // Jw <- Jw + K w + C Jw (the product of the sum, from the bulk's J w).
  void add_to_product(const Eigen::VectorXd& w, Eigen::VectorXd& Jw) const {
    if (row_mix.nonZeros() > 0) {
      const Eigen::VectorXd mixed = row_mix * Jw;
      Jw += mixed;
    }
    if (stiffness.nonZeros() > 0) Jw += stiffness * w;
  }
};

}  // namespace fiberfluid::solve

// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once

#include <Eigen/Core>
#include <Eigen/LU>
#include <map>
#include <memory>
#include <vector>

#include "fiberfluid/model/dof_map.hpp"
#include "fiberfluid/model/equilibrium.hpp"
#include "fiberfluid/model/fiber_system.hpp"
#include "fiberfluid/solve/dense_lu.hpp"
#include "fiberfluid/solve/linear_solver.hpp"
#include "fiberfluid/solve/stepping.hpp"
#include "fiberfluid/solve/sparse_lu.hpp"
#include "fiberfluid/solve/status.hpp"

namespace fiberfluid::solve {

// Solves with the Newton tangent dR/dx at one state, over the unknowns a
// DofMap leaves free: the dense LU of the reduced tangent, the sparse LU of
// it (fibers within a horizon: N times the neighbours entries), or GMRES on the
// tangent as an operator (its pair coefficients stored), right-preconditioned
// by the LU of the tangent at an earlier state (`reused`: a modified
// Newton's factor, whose GMRES restores the exact Newton step; dense, or
// sparse where the fibers are a horizon's lists) or by the
// structured secant solve (the reference bordered system with each
// bulk weight times Y(e_ij); for central fibers each axis block's weights
// also times that axis's share of the fiber's direction). The preconditioner is kept between states and
// refactored when its own held set changes or GMRES needs clearly more
// iterations per decade than just after its last factorisation. Its held set
// may be a subset of the tangent's (the supports without the paddle
// contacts, which come and go): the extra held unknowns are then held in
// its solve by a capacitance correction (Woodbury; Hager, SIAM Rev. 31
// (1989) 221), one preconditioner solve per unknown the first time it is
// held, kept until the next factorisation, instead of a factorisation per
// change of the contacts.
//
// The Newton stepper prepares one per iteration. With
// SteppingOptions::keep_final_tangent the summary keeps it prepared at the
// solution, for sensitivities du/dtheta = -K_T^{-1} dR/dtheta (calibration).
// It refers to the Equilibrium (shared) and through it to the Model, which
// must outlive it.
class TangentSolve {
 public:
  TangentSolve(std::shared_ptr<const model::Equilibrium> equilibrium,
               const SteppingOptions& options, TangentSolver kind);

  TangentSolver kind() const { return kind_; }
  SolverKind preconditioner_kind() const { return preconditioner_kind_; }
  int factorizations() const { return factorizations_; }
  int single_precision_factorizations() const { return single_precision_factorizations_; }
  const model::DofMap& dofs() const { return dofs_; }
  const Eigen::VectorXd& state() const { return x_; }

  // Makes the tangent at x (loads `factors`, held set `dofs`) ready to solve;
  // the preconditioner holds `preconditioner_dofs` (a subset of `dofs`;
  // nullptr: the same set).
  Status prepare(const Eigen::VectorXd& x, const std::vector<double>& factors,
                 const model::DofMap& dofs, const model::DofMap* preconditioner_dofs = nullptr);
  // The residual R(x) (Equilibrium::residual), with the tangent at x stored
  // on the way where this solve stores its tangent: a prepare() at x then
  // skips its pass over the fiber pairs (Newton's accepted trial is the next
  // iterate). The tangent prepared before is gone: prepare() again to solve.
  Eigen::VectorXd residual(const Eigen::VectorXd& x, const std::vector<double>& factors);
  // J_ff y = b over the reduced unknowns (DofMap layout); krylov stops at the
  // relative residual `tolerance`. iterations (krylov) is added to.
  Status solve(const Eigen::VectorXd& b, double tolerance, Eigen::VectorXd* y,
               int* iterations = nullptr);
  // The same in the full layout: rows of b at held unknowns are ignored and
  // y is zero there (a held unknown does not move). For dR/dtheta this gives
  // du/dtheta = -solve_full(dR/dtheta).
  Status solve_full(const Eigen::VectorXd& b, Eigen::VectorXd* y, double tolerance = 1e-12);

 private:
  Status factor_preconditioner();
  Status factor_tangent_preconditioner();
  Status factor_dense_tangent(const model::DofMap& dofs, bool single = false);
  Status factor_sparse_tangent(const model::DofMap& dofs);
  void note_new_factor();  // a preconditioner factored: counts, caches and the refresh rule reset
  bool reused_factor_still_serves() const;
  Status preconditioner_solve(const Eigen::VectorXd& in, Eigen::VectorXd* out) const;
  Status update_capacitance();
  Eigen::VectorXd apply(const Eigen::VectorXd& reduced) const;
  Eigen::VectorXd precondition(const Eigen::VectorXd& reduced) const;

  std::shared_ptr<const model::Equilibrium> equilibrium_;
  SteppingOptions options_;
  TangentSolver kind_;
  Eigen::VectorXd x_;
  std::vector<double> factors_;
  model::DofMap dofs_;
  model::DofMap preconditioner_dofs_;
  bool ready_ = false;
  // Dense (and reused: the LU of the tangent at an earlier state, single
  // precision where it serves).
  std::unique_ptr<DenseLU> lu_;
  // Sparse (its scaling in row_scale_, column_scale_ as the dense one's),
  // and reused where the fibers are a horizon's lists: the sparse LU of the
  // tangent at an earlier state.
  std::unique_ptr<SparseLU> sparse_lu_;
  bool reuses_sparse_lu_ = false;
  bool reused_factor_ok_ = false;  // the reused factor succeeded (and is current)
  // The reused dense factor is rounded to single precision until GMRES
  // fails just after such a factorisation.
  bool single_factor_ = true;
  // The dense tangent is equilibrated before its LU (rows, then columns, by
  // their largest entries): force rows of a stiff material and the volume
  // row differ by many orders, which would make a sound system look singular.
  Eigen::VectorXd row_scale_, column_scale_;
  // Krylov.
  bool store_ = true;
  model::TangentOperator stored_;
  std::unique_ptr<model::FiberSystem> secant_;
  std::unique_ptr<LinearSolver> preconditioner_;
  SolverKind preconditioner_kind_ = SolverKind::Auto;
  std::vector<char> preconditioned_held_;
  // The capacitance correction: the unknowns the tangent holds beyond the
  // preconditioner's (their index in the preconditioner's layout), the
  // preconditioner's solve of each one's unit vector (P^-1 e_h, cached by
  // unknown until the next factorisation), and the LU of their rows.
  std::vector<int> extra_held_;
  std::map<int, Eigen::VectorXd> unit_solves_;
  Eigen::MatrixXd extra_columns_;
  Eigen::PartialPivLU<Eigen::MatrixXd> capacitance_;
  double baseline_rate_ = -1.0;  // gmres iterations per decade after the last factorisation
  bool refactor_ = false, just_factored_ = false;
  int factorizations_ = 0, single_precision_factorizations_ = 0;
};

}  // namespace fiberfluid::solve

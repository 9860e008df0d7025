// SPDX-License-Identifier: GPL-3.0-or-later
// Newton's tangent solve: the interface every strategy implements, the
// factory that makes one by kind, the rule that picks a kind, and what each
// kind costs (for the resource estimate before a run).
//
// The strategies, one file each beside this header:
//   dense_tangent.cpp    the dense LU of the reduced tangent, every iteration
//   sparse_tangent.cpp   its sparse LU (fibers within a horizon: N times the
//                        neighbours entries)
//   secant_krylov.cpp    GMRES on the tangent as an operator, preconditioned by
//                        the structured secant solve            (kind "krylov")
//   reused_tangent.cpp   GMRES preconditioned by the LU of the tangent at an
//                        earlier state (a modified Newton's factor)
// krylov_tangent.hpp holds what the two GMRES strategies share (the stored
// operator, the refresh rule, the capacitance correction for unknowns held
// since the factorisation); tangent_lu.hpp the equilibrated LU of the tangent.
#pragma once

#include <Eigen/Core>
#include <memory>
#include <vector>

#include "fiberfluid/model/dof_map.hpp"
#include "fiberfluid/model/equilibrium.hpp"
#include "fiberfluid/solve/cost_model.hpp"
#include "fiberfluid/solve/linear_solver.hpp"
#include "fiberfluid/solve/status.hpp"
#include "fiberfluid/solve/stepping.hpp"
#include "fiberfluid/solve/tangent/added_tangent.hpp"

namespace fiberfluid::solve {

// Solves with the Newton tangent dR/dx at one state, over the unknowns a
// DofMap leaves free. The Newton stepper prepares one per iteration. With
// SteppingOptions::keep_final_tangent the summary keeps it prepared at the
// solution, for sensitivities du/dtheta = -K_T^{-1} dR/dtheta (calibration).
// It refers to the Equilibrium (shared) and through it to the Model, which
// must outlive it.
class TangentSolve {
 public:
  virtual ~TangentSolve() = default;

  TangentSolver kind() const { return kind_; }
  // The backend of the factor it solves with (the preconditioner's, for GMRES).
  SolverKind preconditioner_kind() const { return preconditioner_kind_; }
  int factorizations() const { return factorizations_; }
  int single_precision_factorizations() const { return single_precision_factorizations_; }
  const model::DofMap& dofs() const { return dofs_; }
  const Eigen::VectorXd& state() const { return x_; }

  // What the contacts add to the bulk's tangent from the next prepare() on
  // (empty: nothing): the sliding contacts' friction. A GMRES strategy takes
  // it into its operator, and into its factor when it refactors.
  void set_added_tangent(AddedTangent added) { added_ = std::move(added); }

  // Makes the tangent at x (loads `factors`, held set `dofs`) ready to solve;
  // a preconditioner holds `preconditioner_dofs` (a subset of `dofs`;
  // nullptr: the same set).
  virtual Status prepare(const Eigen::VectorXd& x, const std::vector<double>& factors,
                         const model::DofMap& dofs,
                         const model::DofMap* preconditioner_dofs = nullptr) = 0;
  // The residual R(x) (Equilibrium::residual). A strategy that stores its
  // tangent stores the one at x on the way, so that a prepare() at x skips
  // its pass over the fiber pairs (Newton's accepted trial is the next
  // iterate); the tangent prepared before is then gone: prepare() again.
  virtual Eigen::VectorXd residual(const Eigen::VectorXd& x, const std::vector<double>& factors);
  // J_ff y = b over the reduced unknowns (DofMap layout); GMRES stops at the
  // relative residual `tolerance`. iterations (GMRES) is added to.
  virtual Status solve(const Eigen::VectorXd& b, double tolerance, Eigen::VectorXd* y,
                       int* iterations = nullptr) = 0;
  // The same in the full layout: rows of b at held unknowns are ignored and
  // y is zero there (a held unknown does not move). For dR/dtheta this gives
  // du/dtheta = -solve_full(dR/dtheta).
  Status solve_full(const Eigen::VectorXd& b, Eigen::VectorXd* y, double tolerance = 1e-12);

 protected:
  TangentSolve(std::shared_ptr<const model::Equilibrium> equilibrium,
               const SteppingOptions& options, TangentSolver kind, SolverKind preconditioner_kind);
  // Keeps the state, loads and held sets of a prepare().
  void take_state(const Eigen::VectorXd& x, const std::vector<double>& factors,
                  const model::DofMap& dofs, const model::DofMap* preconditioner_dofs);

  std::shared_ptr<const model::Equilibrium> equilibrium_;
  SteppingOptions options_;
  SolverKind preconditioner_kind_;
  Eigen::VectorXd x_;
  std::vector<double> factors_;
  model::DofMap dofs_;
  model::DofMap preconditioner_dofs_;
  AddedTangent added_;
  bool ready_ = false;
  int factorizations_ = 0, single_precision_factorizations_ = 0;

 private:
  TangentSolver kind_;
};

// What `requested` means for a Newton run with `reduced_unknowns` (the
// unknowns left after the supports): Auto is dense up to 600 then Krylov
// for the vector spring. Central fibers, whose tangent the secant
// preconditioner fits poorly, up to 50,000 unknowns: dense up to 600; then
// stored as neighbour lists (`sparse_fibers`, a horizon) the sparse LU up to
// 4,000 and the reused sparse LU above; else the reused dense LU (20 GB at
// 50,000). Above 50,000, Krylov.
TangentSolver choose_tangent(TangentSolver requested, int reduced_unknowns,
                             model::FiberKinematics kinematics, bool sparse_fibers);

// The strategy `kind` (not Auto: choose_tangent first).
std::unique_ptr<TangentSolve> make_tangent_solve(
    std::shared_ptr<const model::Equilibrium> equilibrium, const SteppingOptions& options,
    TangentSolver kind);

// A Newton run's sizes, as a tangent strategy's cost sees them.
struct TangentCostCase {
  double vertices = 0.0, dim = 0.0;  // N, d
  double pairs = 0.0;                // fibers visited
  double unknowns = 0.0;             // d N + 1
  double newton_unknowns = 0.0;      // after the supports
  double steps = 0.0;                // load steps
  double product_seconds = 0.0;      // one bulk product K v (every axis block)
  double residual_seconds = 0.0;     // one residual
  bool sparse_fibers = false;        // a horizon's lists
  int krylov_restart = 0;            // GMRES's restart length
  // One factorisation and solve of the factor the strategy starts from (the
  // backend tangent_factor_backend names).
  BackendCost factor;
};
struct TangentCost {
  double bytes = 0.0, seconds = 0.0;
};
// The Newton steps with the tangent strategy `kind`: its factorisations,
// iterations and (for the GMRES strategies) products and preconditioner.
TangentCost tangent_cost(TangentSolver kind, const TangentCostCase& c, const KernelSpeed& speed);
// The backend whose factor `kind` costs (TangentCostCase::factor): the dense
// LU for the dense tangent and the reused dense one, else `structured` (the
// structured system's choice).
SolverKind tangent_factor_backend(TangentSolver kind, bool sparse_fibers, SolverKind structured);

}  // namespace fiberfluid::solve

// SPDX-License-Identifier: GPL-3.0-or-later
// What the two GMRES tangent strategies share (internal to solve/tangent/):
// GMRES on the tangent as an operator (its pair coefficients stored when
// they fit), right-preconditioned by a factor kept between states. The
// factor is refreshed when its own held set changes or GMRES needs clearly
// more iterations per decade than just after its last factorisation. Its
// held set may be a subset of the tangent's (the supports without the
// paddle contacts, which come and go): the extra held unknowns are then held
// in its solve by a capacitance correction (Woodbury; Hager, SIAM Rev. 31
// (1989) 221), one preconditioner solve per unknown the first time it is
// held, kept until the next factorisation, instead of a factorisation per
// change of the contacts.
//
// A strategy supplies the factor: when it is kept or refactored in a
// prepare(), a refactorisation after GMRES fails, and a solve with it.
#pragma once

#include <Eigen/LU>
#include <map>
#include <memory>
#include <vector>

#include "fiberfluid/solve/tangent/tangent_solve.hpp"

namespace fiberfluid::solve {

class KrylovTangent : public TangentSolve {
 public:
  Status prepare(const Eigen::VectorXd& x, const std::vector<double>& factors,
                 const model::DofMap& dofs, const model::DofMap* preconditioner_dofs) final;
  Eigen::VectorXd residual(const Eigen::VectorXd& x, const std::vector<double>& factors) final;
  Status solve(const Eigen::VectorXd& b, double tolerance, Eigen::VectorXd* y,
               int* iterations) final;

 protected:
  // `refresh_floor`: GMRES iterations per decade up to which the factor is
  // kept whatever its rate just after the factorisation.
  KrylovTangent(std::shared_ptr<const model::Equilibrium> equilibrium,
                const SteppingOptions& options, TangentSolver kind, SolverKind preconditioner_kind,
                double refresh_floor);

  // In prepare(): keeps the factor or refactors it, and sets
  // preconditioner_dofs_ to the set it holds.
  virtual Status keep_or_refactor() = 0;
  // After GMRES failed with a factor just made: whether to refactor and try
  // once more (a strategy that can make a better factor says so and does).
  virtual bool retry_with_fresh_factor() { return false; }
  // After GMRES failed: a new factor over the set it should hold.
  virtual Status refactor() = 0;
  // P^-1 in in the preconditioner's layout.
  virtual Status preconditioner_solve(const Eigen::VectorXd& in, Eigen::VectorXd* out) const = 0;

  // The most unknowns held beyond the preconditioner's that the capacitance
  // correction takes (each costs one preconditioner solve when first held).
  static constexpr size_t kMostCapacitanceHeld = 256;

  // A factor was made: counts, caches and the refresh rule reset.
  void note_new_factor();
  // Asks for a new factor at the next prepare() (GMRES slowed down).
  bool refactor_requested() const { return refactor_; }
  const std::vector<char>& preconditioned_held() const { return preconditioned_held_; }

 private:
  Status update_capacitance();
  Eigen::VectorXd apply(const Eigen::VectorXd& reduced) const;
  Eigen::VectorXd precondition(const Eigen::VectorXd& reduced) const;

  double refresh_floor_;
  bool store_ = true;
  model::TangentOperator stored_;
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
};

// The cost of a GMRES strategy's Newton steps: `factorizations` of
// `factor_seconds`, per Newton iteration a residual and `products` GMRES
// products (three bulk products and one preconditioner solve each);
// `factor_bytes` plus the stored operator and GMRES's basis.
TangentCost krylov_cost(const TangentCostCase& c, double factorizations, double factor_seconds,
                        double factor_bytes, double preconditioner_solve_seconds, double products);

}  // namespace fiberfluid::solve

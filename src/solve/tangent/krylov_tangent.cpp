// SPDX-License-Identifier: GPL-3.0-or-later
#include "fiberfluid/solve/tangent/krylov_tangent.hpp"

#include <algorithm>
#include <cmath>
#include <iterator>

#include "fiberfluid/solve/gmres.hpp"
#include "fiberfluid/solve/tangent/strategies.hpp"
#include "fiberfluid/util/run_control.hpp"

namespace fiberfluid::solve {

KrylovTangent::KrylovTangent(std::shared_ptr<const model::Equilibrium> equilibrium,
                             const SteppingOptions& options, TangentSolver kind,
                             SolverKind preconditioner_kind, double refresh_floor)
    : TangentSolve(std::move(equilibrium), options, kind, preconditioner_kind),
      refresh_floor_(refresh_floor) {
  // The pair coefficients are stored when they fit in a quarter of the
  // memory budget; else each product recomputes them.
  store_ = equilibrium_->stored_tangent_bytes() < 0.25 * memory_budget_bytes();
}

Status KrylovTangent::prepare(const Eigen::VectorXd& x, const std::vector<double>& factors,
                              const model::DofMap& dofs, const model::DofMap* preconditioner_dofs) {
  take_state(x, factors, dofs, preconditioner_dofs);
  if (store_) equilibrium_->linearize(x_, factors_, stored_);  // reuses the arrays
  Status status = keep_or_refactor();
  if (!status.ok) return status;
  status = update_capacitance();
  if (!status.ok) return status;
  ready_ = true;
  return {};
}

Eigen::VectorXd KrylovTangent::residual(const Eigen::VectorXd& x,
                                        const std::vector<double>& factors) {
  if (!store_) return equilibrium_->residual(x, factors);
  ready_ = false;  // stored_ now holds the tangent at x
  return equilibrium_->residual(x, factors, stored_);
}

Eigen::VectorXd KrylovTangent::apply(const Eigen::VectorXd& reduced) const {
  Eigen::VectorXd w = Eigen::VectorXd::Zero(equilibrium_->num_unknowns());
  dofs_.scatter(reduced, w);  // held entries stay zero
  Eigen::VectorXd product =
      store_ ? stored_.apply(w) : equilibrium_->tangent_product(x_, factors_, w);
  added_.add_to_product(w, product);
  return dofs_.reduce(product);
}

// The held unknowns of the tangent that the preconditioner leaves free (at
// most a few hundred: beyond, they stay free in its solve, as GMRES can
// still cope), with the preconditioner's solve of each one's unit vector
// and the capacitance matrix C = E^T P^-1 E of their rows.
Status KrylovTangent::update_capacitance() {
  extra_held_.clear();
  if (preconditioner_dofs_.num_reduced() == dofs_.num_reduced()) return {};
  std::vector<int> position(static_cast<size_t>(equilibrium_->num_unknowns()), -1);
  const std::vector<int>& index = preconditioner_dofs_.full_index();
  for (size_t k = 0; k < index.size(); ++k)
    position[static_cast<size_t>(index[k])] = static_cast<int>(k);
  std::vector<int> dofs;
  for (int d : dofs_.held_dofs())
    if (!preconditioner_dofs_.held(d)) dofs.push_back(d);
  if (dofs.empty() || dofs.size() > kMostCapacitanceHeld) return {};
  // Contacts wander over a long run: the solves of unknowns no longer held
  // go once the cache holds twice the most that are held at once.
  if (unit_solves_.size() > 2 * kMostCapacitanceHeld)
    for (auto it = unit_solves_.begin(); it != unit_solves_.end();)
      it = std::binary_search(dofs.begin(), dofs.end(), it->first) ? std::next(it)
                                                                   : unit_solves_.erase(it);
  const Eigen::Index m = preconditioner_dofs_.num_reduced();
  extra_columns_.resize(m, static_cast<Eigen::Index>(dofs.size()));
  for (size_t c = 0; c < dofs.size(); ++c) {
    auto cached = unit_solves_.find(dofs[c]);
    if (cached == unit_solves_.end()) {
      Eigen::VectorXd unit = Eigen::VectorXd::Zero(m), column;
      unit[position[static_cast<size_t>(dofs[c])]] = 1.0;
      const Status status = preconditioner_solve(unit, &column);
      if (!status.ok) return Status::failure("newton: the preconditioner: " + status.message);
      cached = unit_solves_.emplace(dofs[c], std::move(column)).first;
    }
    extra_columns_.col(static_cast<Eigen::Index>(c)) = cached->second;
  }
  for (int d : dofs) extra_held_.push_back(position[static_cast<size_t>(d)]);
  Eigen::MatrixXd C(extra_held_.size(), extra_held_.size());
  for (size_t r = 0; r < extra_held_.size(); ++r)
    C.row(static_cast<Eigen::Index>(r)) = extra_columns_.row(extra_held_[r]);
  capacitance_.compute(C);
  return {};
}

// The preconditioner's solve, through its own layout when it holds fewer
// unknowns: the tangent's held unknowns enter as zeros, and the capacitance
// correction keeps them at zero in the solution, y = P^-1 b - Z C^-1 (P^-1 b)_H
// with Z = P^-1 E: the solve of the preconditioner's block over the
// tangent's free unknowns alone.
Eigen::VectorXd KrylovTangent::precondition(const Eigen::VectorXd& reduced) const {
  const bool same_layout = preconditioner_dofs_.num_reduced() == dofs_.num_reduced();
  Eigen::VectorXd in = reduced;
  if (!same_layout) {
    Eigen::VectorXd full = Eigen::VectorXd::Zero(equilibrium_->num_unknowns());
    dofs_.scatter(reduced, full);
    in = preconditioner_dofs_.reduce(full);
  }
  Eigen::VectorXd out;
  if (!preconditioner_solve(in, &out).ok) return Eigen::VectorXd::Constant(reduced.size(), NAN);
  if (same_layout) return out;
  if (!extra_held_.empty()) {
    Eigen::VectorXd at_held(static_cast<Eigen::Index>(extra_held_.size()));
    for (size_t r = 0; r < extra_held_.size(); ++r)
      at_held[static_cast<Eigen::Index>(r)] = out[extra_held_[r]];
    out -= extra_columns_ * capacitance_.solve(at_held);
  }
  Eigen::VectorXd full = Eigen::VectorXd::Zero(equilibrium_->num_unknowns());
  preconditioner_dofs_.scatter(out, full);
  return dofs_.reduce(full);
}

Status KrylovTangent::solve(const Eigen::VectorXd& b, double tolerance, Eigen::VectorXd* y,
                            int* iterations) {
  if (!ready_) return Status::failure("newton: the tangent was not prepared");
  const LinearOperator apply_tangent = [this](const Eigen::VectorXd& v) { return apply(v); };
  const LinearOperator precondition = [this](const Eigen::VectorXd& v) {
    return this->precondition(v);
  };
  GmresOptions gmres_options;
  gmres_options.tolerance = tolerance;
  gmres_options.restart = options_.newton.krylov_restart;
  gmres_options.max_iterations = options_.newton.krylov_max_iterations;
  const auto run_gmres = [&] {
    y->resize(0);
    GmresResult run = gmres(apply_tangent, precondition, b, *y, gmres_options);
    if (iterations != nullptr) *iterations += run.iterations;
    return run;
  };
  GmresResult result = run_gmres();
  // The factor ages as the strains move: refactor when gmres needs clearly
  // more iterations per decade of residual reduction than it did just after
  // the last factorisation (and more than the strategy's floor).
  const double rate = result.iterations / std::max(1.0, -std::log10(tolerance));
  if (baseline_rate_ < 0.0)
    baseline_rate_ = rate;
  else if (rate > std::max(2.0 * baseline_rate_ + 1.0, refresh_floor_))
    refactor_ = true;
  // A failure with an aged factor refactors and tries again. One just after a
  // factorisation is final, unless the strategy can make a better factor.
  while (!result.status.ok) {
    if (just_factored_ && !retry_with_fresh_factor()) break;
    Status status = refactor();
    if (status.ok) status = update_capacitance();
    if (!status.ok) return status;
    result = run_gmres();
  }
  just_factored_ = false;
  return result.status.ok ? Status{} : Status::failure("newton: " + result.status.message);
}

void KrylovTangent::note_new_factor() {
  ++factorizations_;
  unit_solves_.clear();  // solves with the factor replaced
  preconditioned_held_ = preconditioner_dofs_.held_flags();
  baseline_rate_ = -1.0;
  refactor_ = false;
  just_factored_ = true;
}

TangentCost krylov_cost(const TangentCostCase& c, double factorizations, double factor_seconds,
                        double factor_bytes, double preconditioner_solve_seconds, double products) {
  // The stored pair coefficients (when they fit a quarter of the budget)
  // and GMRES's basis.
  const double stored = 2.0 * 8.0 * (c.sparse_fibers ? 2.0 * c.pairs : c.vertices * c.vertices);
  TangentCost cost;
  cost.bytes = factor_bytes + ((stored < 0.25 * memory_budget_bytes() ? stored : 0.0) +
                               8.0 * c.unknowns * (c.krylov_restart + 2));
  const double iterations = c.steps * kNewtonIterationsPerStep;
  cost.seconds = factorizations * factor_seconds +
                 iterations * (c.residual_seconds +
                               products * (3.0 * c.product_seconds + preconditioner_solve_seconds));
  return cost;
}

}  // namespace fiberfluid::solve

// SPDX-License-Identifier: GPL-3.0-or-later
#include "fiberfluid/solve/newton/newton_solver.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

#include "fiberfluid/util/progress.hpp"
#include "fiberfluid/util/run_control.hpp"

namespace fiberfluid::solve {

// Inexact Newton's forcing term: the relative residual a Krylov solve of
// J dx = -R stops at, for a Newton residual `norm` (relative). As accurate as
// the residual it corrects (0.1 norm: the convergence stays quadratic), but
// never sharper than the tolerance asks (0.5 tolerance / norm: the last
// iteration lands just below the tolerance, not decades below it); Eisenstat
// and Walker, SIAM J. Sci. Comput. 17 (1996) 16, with the safeguard against
// oversolving of Kelley, "Iterative Methods for Linear and Nonlinear
// Equations" (SIAM 1995), eq. 6.20.
double forcing_term(double norm, const NewtonOptions& options) {
  const double quadratic = 0.1 * norm, enough = 0.5 * options.residual_tolerance / norm;
  return std::max(options.krylov_tolerance, std::min(0.1, std::max(quadratic, enough)));
}

NewtonSolver::NewtonSolver(const model::Model& model, const SteppingOptions& options,
                           SteppingSummary& summary)
    : model_(model),
      options_(options),
      newton_(options.newton),
      summary_(summary),
      equilibrium_(std::make_shared<const model::Equilibrium>(model)),
      supports_(model::DofMap::from_constraints(model)),
      contacts_(model, supports_) {
  const Eigen::MatrixXd& V = model.surface.V;
  diagonal_ = (V.colwise().maxCoeff() - V.colwise().minCoeff()).norm();
  const TangentSolver kind =
      choose_tangent(newton_.tangent, supports_.num_reduced(), model.material.kinematics,
                     equilibrium_->sparse_fibers());
  chosen_ = make_tangent_solve(equilibrium_, options, kind);
  tangent_ = chosen_;
  tangent_kind_ = chosen_kind_ = kind;
  summary_.tangent = kind;
  summary_.solver = tangent_->preconditioner_kind();
}

std::string NewtonSolver::tangent_name() const {
  return std::string("the ") + to_string(tangent_kind_) + " tangent";
}

bool NewtonSolver::use_exact_tangent(const std::string& why) {
  if (tangent_kind_ == TangentSolver::Dense || tangent_kind_ == TangentSolver::Sparse) return false;
  const TangentSolver exact =
      equilibrium_->sparse_fibers() ? TangentSolver::Sparse : TangentSolver::Dense;
  const double n = supports_.num_reduced() + 1.0;
  if (exact == TangentSolver::Dense && 16.0 * n * n > memory_budget_bytes()) return false;
  if (!exact_) exact_ = make_tangent_solve(equilibrium_, options_, exact);
  tangent_ = exact_;
  tangent_kind_ = exact;
  if (first_stall_.empty())
    first_stall_ = "step " + std::to_string(summary_.steps.size() + 1) + ": " + why;
  ++exact_pieces_;
  summary_.tangent_fallback = "the exact " + std::string(to_string(exact)) + " tangent took " +
                              std::to_string(exact_pieces_) + " piece(s) where the " +
                              to_string(chosen_kind_) + " one stalled, first at " + first_stall_;
  return true;
}

void NewtonSolver::use_chosen_tangent() {
  tangent_ = chosen_;
  tangent_kind_ = chosen_kind_;
}

// The tangent solve prepared at x (the solution), for the summary.
std::shared_ptr<TangentSolve> NewtonSolver::final_tangent(const LoadPoint& at,
                                                          const Eigen::VectorXd& x) {
  tangent_->set_added_tangent(contacts_.friction_tangent(x, residual_));
  if (!tangent_->prepare(x, at.factors, held_map(), &supports_).ok) return nullptr;
  return tangent_;
}

// Solves R = 0 at `at` from x (updated in place): Newton inside an
// active-set loop for the paddles. "" or why it failed.
//
// A vertex that passes a paddle joins its set as soon as an iterate shows
// it (feasibility first); a vertex leaves only at an equilibrium of the
// current set, where its contact force is that of a solution and not of an
// iterate on the way to one. Releasing on iterates made the set chatter at
// first touch: a body held at one point rocked from one paddle to the other
// and back, every iteration, for ever (issue 42). Holding the set fixed
// within each solve and updating it between solves is the usual active-set
// strategy of implicit contact (Wriggers, Computational Contact Mechanics,
// 2nd ed. 2006, section 6.3; Sierra/SolidMechanics' "control contact").
std::string NewtonSolver::solve(const LoadPoint& at, Eigen::VectorXd& x, StepRecord& record) {
  record.contacts_added += contacts_.add_penetrating(at, x);
  for (int round = 0; round < newton_.max_contact_rounds; ++round) {
    if (!model_.paddles.empty()) ++record.contact_rounds;
    const model::DofMap dofs = held_map();
    contacts_.apply_held_values(at, dofs, x);
    bool converged = false;
    const std::string why = newton(at, dofs, x, record, &converged);
    if (!why.empty()) return why;
    const int released = converged ? contacts_.release_pulling(residual_) : 0;
    const int added = contacts_.add_penetrating(at, x);
    record.contacts_released += released;
    record.contacts_added += added;
    if (!converged || released > 0 || added > 0) continue;
    // The set is settled; Coulomb's law then settles the friction forces.
    const int slid = contacts_.update_friction(residual_, x, newton_.friction_tolerance);
    record.friction_updates += slid;
    if (slid == 0) {
      contacts_.accept(x);
      return {};
    }
  }
  return "the paddle contact did not settle in " + std::to_string(newton_.max_contact_rounds) +
         " active-set rounds (newton.max_contact_rounds" +
         (contacts_.any_friction() ? std::string(", newton.friction_tolerance") : "") + ")";
}

// du/dtheta = -K_T^{-1} dR/dtheta at the solution x, one tangent solve per
// parameter, the held set (supports and contacts) fixed. "" or why not.
// `residual_change` receives dR/dtheta along the solution's change,
// K_T du/dtheta + dR/dtheta: zero at the free rows, and at the held ones
// the change of the supports' and paddles' forces.
std::string NewtonSolver::sensitivities(const LoadPoint& at, const Eigen::VectorXd& x,
                                        const std::vector<std::string>& names, Eigen::MatrixXd* out,
                                        Eigen::MatrixXd* residual_change) {
  const std::shared_ptr<TangentSolve> tangent = final_tangent(at, x);
  if (!tangent) return "the tangent at the solution could not be factored";
  const Eigen::MatrixXd dR = equilibrium_->parameter_derivatives(x, names);
  out->resize(x.size(), dR.cols());
  residual_change->resize(x.size(), dR.cols());
  for (Eigen::Index c = 0; c < dR.cols(); ++c) {
    Eigen::VectorXd du;
    const Status status = tangent->solve_full(-dR.col(c), &du);
    if (!status.ok) return names[static_cast<size_t>(c)] + ": " + status.message;
    out->col(c) = du;
    residual_change->col(c) = equilibrium_->tangent_product(x, at.factors, du) + dR.col(c);
  }
  return {};
}

// The residual at x (and the tangent prepared there), the sliding contacts'
// friction forces at x in (their tangent is set before each prepare).
Eigen::VectorXd NewtonSolver::residual(const Eigen::VectorXd& x,
                                       const std::vector<double>& factors) {
  Eigen::VectorXd R = tangent_->residual(x, factors);
  contacts_.add_friction(x, R);
  return R;
}

// The relative residual of the state x (gauge: the scale of x's loads and
// reactions, or of the states accepted before, whichever is larger).
double NewtonSolver::measure(const LoadPoint& at, const model::DofMap& dofs,
                             const Eigen::VectorXd& x, const Eigen::VectorXd& R,
                             double* scale) const {
  const double s = gauge_.scale_at(*equilibrium_, dofs, x, at.factors, R);
  if (scale) *scale = s;
  return equilibrium_->relative_norm(dofs.reduce(R), s);
}

// Newton iterations with the held set `dofs`, until converged (*converged
// true) or, after an iteration, until a vertex passes a paddle: the set
// grows as the iterates go, rather than after a full solve with each set
// (solve() says why it shrinks only at a solution). "" or why it failed.
std::string NewtonSolver::newton(const LoadPoint& at, const model::DofMap& dofs, Eigen::VectorXd& x,
                                 StepRecord& record, bool* converged) {
  *converged = false;
  Eigen::VectorXd R = residual(x, at.factors);
  double last_move = std::numeric_limits<double>::infinity();
  for (int it = 0;; ++it) {
    if (cancel_requested()) return "interrupted";
    const Eigen::VectorXd r = dofs.reduce(R);
    double scale = 0.0;
    const double norm = measure(at, dofs, x, R, &scale);
    record.residual_norms.push_back(norm);
    if (!std::isfinite(norm)) return "the residual is not finite";
    // Converged: the residual is small, or it has stalled at rounding
    // level (a little above the tolerance) while the corrections vanish.
    const bool small_move = last_move <= newton_.increment_tolerance * diagonal_;
    if (norm <= newton_.residual_tolerance ||
        (small_move && norm <= 1e3 * newton_.residual_tolerance)) {
      residual_ = R;
      gauge_.commit(scale);
      *converged = true;
      return {};
    }
    if (it > 0 && contacts_.add_penetrating(at, x, false) > 0) {
      residual_ = R;
      return {};
    }
    if (it == newton_.max_iterations) {
      std::ostringstream out;
      out << "newton: no convergence in " << it << " iterations (relative residual " << norm
          << ", newton.residual_tolerance " << newton_.residual_tolerance << ", " << tangent_name()
          << ")";
      return out.str();
    }
    Eigen::VectorXd dx;
    const double forcing = forcing_term(norm, newton_);
    tangent_->set_added_tangent(contacts_.friction_tangent(x, R));
    const Status status = prepare_and_solve(x, at.factors, dofs, -r, forcing, record, &dx);
    if (!status.ok) return status.message + " (" + tangent_name() + ")";
    // Backtracking: halve the step until the residual falls (Armijo).
    Eigen::VectorXd step = Eigen::VectorXd::Zero(x.size());
    dofs.scatter(dx, step);
    contacts_.stop_at_cones(x, R, step);
    double alpha = 1.0;
    Eigen::VectorXd trial, R_trial;
    for (int halving = 0;; ++halving) {
      trial = x + alpha * step;
      R_trial = residual(trial, at.factors);
      const double trial_norm = measure(at, dofs, trial, R_trial);
      if (!newton_.line_search || trial_norm <= (1.0 - 1e-4 * alpha) * norm ||
          trial_norm <= newton_.residual_tolerance)
        break;
      if (halving == 12)
        return "newton: the line search found no decrease of the residual (relative " +
               std::to_string(norm) + ", " + tangent_name() + ")";
      alpha *= 0.5;
      ++record.line_search_halvings;
    }
    x = trial;
    R = R_trial;
    last_move = alpha * dx.head(dx.size() - 1).cwiseAbs().maxCoeff();
    ++record.newton_iterations;
    ++summary_.newton_iterations;
    report_progress("newton iteration", record.newton_iterations, 0.0);
  }
}

// Solves J y = b with the tangent as last prepared (Krylov to the relative
// residual `forcing`), counting its iterations in the step and the run.
Status NewtonSolver::solve_prepared(const Eigen::VectorXd& b, double forcing, StepRecord& record,
                                    Eigen::VectorXd* y) {
  int iterations = 0;
  const Status status = tangent_->solve(b, forcing, y, &iterations);
  record.krylov_iterations += iterations;
  summary_.krylov_iterations += iterations;
  return status;
}

// Prepares the tangent at (x, factors) over `dofs`, then solve_prepared;
// the run's factorisations and preconditioner kept up to date.
Status NewtonSolver::prepare_and_solve(const Eigen::VectorXd& x, const std::vector<double>& factors,
                                       const model::DofMap& dofs, const Eigen::VectorXd& b,
                                       double forcing, StepRecord& record, Eigen::VectorXd* y) {
  Status status = tangent_->prepare(x, factors, dofs, &supports_);
  if (status.ok) status = solve_prepared(b, forcing, record, y);
  summary_.factorizations = chosen_->factorizations() + (exact_ ? exact_->factorizations() : 0);
  summary_.single_precision_factorizations = chosen_->single_precision_factorizations();
  summary_.solver = chosen_->preconditioner_kind();
  return status;
}

}  // namespace fiberfluid::solve

// SPDX-License-Identifier: GPL-3.0-or-later
// Newton's method for the equilibrium at one load point (internal to the
// Newton scheme): iterations with a backtracking line search inside the
// paddles' active-set loop, the tangent solved by the strategy chosen for
// the run, the sensitivities at a solution, and arc-length continuation.
#pragma once

#include <Eigen/Core>
#include <array>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "fiberfluid/model/dof_map.hpp"
#include "fiberfluid/model/equilibrium.hpp"
#include "fiberfluid/model/model.hpp"
#include "fiberfluid/solve/newton/contact_set.hpp"
#include "fiberfluid/solve/newton/newton.hpp"
#include "fiberfluid/solve/stepping.hpp"
#include "fiberfluid/solve/stepping_common.hpp"
#include "fiberfluid/solve/tangent/tangent_solve.hpp"

namespace fiberfluid::solve {

// Inexact Newton's forcing term: the relative residual a Krylov solve of
// J dx = -R stops at, for a Newton residual `norm` (relative).
double forcing_term(double norm, const NewtonOptions& options);

class NewtonSolver {
 public:
  // Refers to the model, the options and the summary (which it keeps up to
  // date: iterations, factorisations, the tangent and preconditioner run).
  NewtonSolver(const model::Model& model, const SteppingOptions& options, SteppingSummary& summary);

  const model::Equilibrium& equilibrium() const { return *equilibrium_; }
  const model::Model& model() const { return model_; }
  // The tangent solve prepared at x (the solution), for the summary.
  std::shared_ptr<TangentSolve> final_tangent(const LoadPoint& at, const Eigen::VectorXd& x);

  // Solves R = 0 at `at` from x (updated in place): Newton inside an
  // active-set loop for the paddles. "" or why it failed.
  std::string solve(const LoadPoint& at, Eigen::VectorXd& x, StepRecord& record);

  // du/dtheta = -K_T^{-1} dR/dtheta at the solution x, one tangent solve per
  // parameter, the held set (supports and contacts) fixed. "" or why not.
  // `residual_change` receives dR/dtheta along the solution's change,
  // K_T du/dtheta + dR/dtheta: zero at the free rows, and at the held ones
  // the change of the supports' and paddles' forces.
  std::string sensitivities(const LoadPoint& at, const Eigen::VectorXd& x,
                            const std::vector<std::string>& names, Eigen::MatrixXd* out,
                            Eigen::MatrixXd* residual_change);

  // Records a converged point of the path at t: "" or why the run stops.
  using KeepStep = std::function<std::string(StepRecord&, double, Clock::time_point)>;
  // Arc-length continuation from the point t = 1 in summary.unknowns on to
  // the final load t = n (arc_length.cpp). "" or why it stopped.
  std::string follow_arc_length(int n, SteppingSummary& summary, const KeepStep& keep);

  // After a successful solve: the residual at the held unknowns is the force
  // each support or paddle exerts on the body.
  const Eigen::VectorXd& last_residual() const { return residual_; }
  // A sliding contact's friction force on the body (zero for the others).
  Eigen::Vector3d friction_force(int vertex) const { return contacts_.friction_force(vertex); }
  bool sliding(int vertex) const { return contacts_.sliding(vertex); }
  // Per vertex: the paddle in contact, or -1.
  const std::vector<int>& contact_paddle() const { return contacts_.paddle_of(); }
  // The supports' map with the contact unknowns held too.
  model::DofMap held_map() const { return contacts_.held_map(); }
  // A warm start's contact set (ContactSet::touch_planes).
  void touch_planes(const LoadPoint& at, const Eigen::VectorXd& x) {
    contacts_.touch_planes(at, x);
  }
  // Where the tangent chosen is inexact (GMRES: krylov, reused) and the
  // exact one affordable: switches to the exact LU (sparse for a horizon's
  // lists, else dense) until use_chosen_tangent, counting it in
  // summary.tangent_fallback. False when the exact tangent is in use already
  // or the dense LU would not fit the memory budget. A piece of a step that
  // failed is tried again so before the step is cut: GMRES on a poor
  // preconditioner can stall a line search that the exact tangent passes
  // (issue 59, class 7).
  bool use_exact_tangent(const std::string& why);
  // Back to the tangent chosen (after a piece the exact one solved).
  void use_chosen_tangent();
  // "the reused tangent": the tangent strategy now in use, for messages.
  std::string tangent_name() const;
  // Snapshot and restore of the contact state, for a step that is cut.
  using ContactState = ContactSet::State;
  ContactState contact_state() const { return contacts_.state(); }
  void restore(const ContactState& state) { contacts_.restore(state); }

 private:
  // The residual at x, the sliding contacts' friction forces in.
  Eigen::VectorXd residual(const Eigen::VectorXd& x, const std::vector<double>& factors);
  // The relative residual of the state x (gauge: the scale of x's loads and
  // reactions, or of the states accepted before, whichever is larger).
  double measure(const LoadPoint& at, const model::DofMap& dofs, const Eigen::VectorXd& x,
                 const Eigen::VectorXd& R, double* scale = nullptr) const;
  // Newton iterations with the held set `dofs`, until converged (*converged
  // true) or, after an iteration, until a vertex passes a paddle. "" or why
  // it failed.
  std::string newton(const LoadPoint& at, const model::DofMap& dofs, Eigen::VectorXd& x,
                     StepRecord& record, bool* converged);
  // Solves J y = b with the tangent as last prepared (Krylov to the relative
  // residual `forcing`), counting its iterations in the step and the run.
  Status solve_prepared(const Eigen::VectorXd& b, double forcing, StepRecord& record,
                        Eigen::VectorXd* y);
  // Prepares the tangent at (x, factors) over `dofs`, then solve_prepared;
  // the run's factorisations and preconditioner kept up to date.
  Status prepare_and_solve(const Eigen::VectorXd& x, const std::vector<double>& factors,
                           const model::DofMap& dofs, const Eigen::VectorXd& b, double forcing,
                           StepRecord& record, Eigen::VectorXd* y);

  // Arc length (arc_length.cpp).
  static double parabola_peak(const std::vector<std::array<double, 2>>& path);
  static std::string limit_note(const SteppingSummary& summary);
  std::vector<double> factors_at(double t, int n) const;
  Eigen::VectorXd path_derivative(const model::DofMap& dofs, const Eigen::VectorXd& x, double t,
                                  int n, bool ahead) const;
  std::string arc_step(int n, const model::DofMap& dofs, const Eigen::VectorXd& x0, double t0,
                       double arc, const Eigen::VectorXd& previous, double previous_dt,
                       Eigen::VectorXd* x, double* t, StepRecord& record);

  const model::Model& model_;
  const SteppingOptions& options_;
  const NewtonOptions& newton_;
  SteppingSummary& summary_;
  std::shared_ptr<const model::Equilibrium> equilibrium_;
  model::DofMap supports_;  // supports and prescribed values
  ContactSet contacts_;     // refers to supports_
  Eigen::VectorXd residual_;
  double diagonal_ = 1.0;  // the body's bounding-box diagonal
  ResidualGauge gauge_;
  std::shared_ptr<TangentSolve> tangent_;             // in use: chosen_ or exact_
  std::shared_ptr<TangentSolve> chosen_, exact_;      // exact_: made on first use
  TangentSolver tangent_kind_ = TangentSolver::Auto;  // tangent_'s
  TangentSolver chosen_kind_ = TangentSolver::Auto;
  int exact_pieces_ = 0;     // pieces the exact tangent took over
  std::string first_stall_;  // where and why the chosen one first stalled
};

}  // namespace fiberfluid::solve

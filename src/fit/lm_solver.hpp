// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once

// This project's Levenberg-Marquardt fits (one calibration, or several
// specimens at once) on Ceres. Included only by the .cpp files that include
// Ceres already (its headers compile slowly).

#include <ceres/ceres.h>

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "fiberfluid/fit/parameters.hpp"

namespace fiberfluid::fit {

inline ceres::Solver::Options lm_solver(int max_iterations, double function_tolerance,
                                        double parameter_tolerance,
                                        double initial_trust_region_radius) {
  ceres::Solver::Options solver;
  solver.minimizer_type = ceres::TRUST_REGION;
  solver.trust_region_strategy_type = ceres::LEVENBERG_MARQUARDT;
  solver.linear_solver_type = ceres::DENSE_QR;
  // Each Jacobian column scaled to unit size before the step is solved (Ceres'
  // Jacobi scaling; also its default), so the damping weighs a modulus and an
  // exponent alike whatever their units (Moré's scaled Levenberg-Marquardt).
  solver.jacobi_scaling = true;
  solver.initial_trust_region_radius = initial_trust_region_radius;
  solver.max_num_iterations = max_iterations;
  solver.function_tolerance = function_tolerance;
  solver.parameter_tolerance = parameter_tolerance;
  solver.gradient_tolerance = 1e-16;
  solver.num_threads = 1;  // the forward runs are threaded themselves
  solver.logging_type = ceres::SILENT;
  solver.update_state_every_iteration = true;  // the iteration callbacks read the point
  // With bounds, Ceres follows every trust-region step with a projected
  // Armijo line search (TrustRegionMinimizer::DoLineSearch), by default up to
  // 20 cost evaluations. Here each is a whole forward run, and a trial point
  // whose run failed was retried at shorter and shorter steps, each failing
  // slowly. One evaluation, the projected step itself, leaves the damping to
  // Levenberg-Marquardt's own region.
  solver.max_num_line_search_step_size_iterations = 1;
  return solver;
}

// How far one step may go, and the fit's stopping rules.
struct LmSteps {
  int max_iterations = 50;
  double function_tolerance = 1e-12, parameter_tolerance = 1e-8;
  double initial_trust_region_radius = 1e4;
  // A log-scaled variable moves by at most log(max_step_factor) per step, a
  // linear one between finite bounds by max_step_share of its range.
  double max_step_factor = 4.0;
  double max_step_share = 0.05;
};

// Levenberg-Marquardt with a bounded step and the bounds an active set.
// Each iteration is one Ceres solve of one iteration from the current point,
// the trust radius carried from solve to solve, so that the damping adapts
// as in one solve.
//
// The bounded step: each solve's bounds are the fit's intersected with a box
// around the current point, `reach` wide either side (log(max_step_factor)
// for a log-scaled variable, max_step_share of its range for a linear one);
// Ceres projects a step that leaves them onto them. The box halves after a
// rejected step and doubles back after an accepted one (a box trust region).
// The linear variables' box came after a fit of Y0 exp(beta e) to a real
// silicone curve took beta from 0 to 11.3 in its first step while Y0 only
// doubled, then spent 32 more runs coming back along the Y0-beta valley. Why: the damping bounds a
// step only through the scaled Jacobian. Along a direction the data barely
// see (gamma beside Y on a small body) the first, nearly Gauss-Newton steps
// go to the bounds (gamma from 0.002 to 100 N/m), where the forward run
// fails slowly. In the box, the well-seen part of a step is kept whole (Y
// from 5 times its value to within 0.01% in three steps on the bending
// phantom); refusing such steps instead made Ceres shrink its radius until
// every part was tiny, and shortening a step as a whole to the box kept the
// runaway part's direction at the cost of the rest.
//
// The active set: a variable on its bound whose gradient pushes it out is
// held for the iteration (a SubsetManifold), so that the step of the others
// is their own least-squares step, not the projection of a joint step whose
// held part was cut off: with Y on its bound and -0.97 correlated with
// gamma, projected steps crept along gamma for 50 iterations
// (fit_liver_fem); the active-set step converges in 19 (the active-set
// treatment of bounds: Nocedal and Wright, Numerical Optimization, 2nd ed.
// 2006, section 16.7).
//
// `callback` sees the iterations numbered as in one solve (iteration 0
// once). Returns the last solve's summary.
inline ceres::Solver::Summary solve_in_moving_box(ceres::Problem& problem, double* phi,
                                                  const std::vector<Parameter>& parameters,
                                                  const Eigen::VectorXd& lower,
                                                  const Eigen::VectorXd& upper,
                                                  const LmSteps& steps,
                                                  ceres::IterationCallback* callback) {
  // Passes Ceres' iterations on, numbered across the solves.
  class Renumbered final : public ceres::IterationCallback {
   public:
    Renumbered(ceres::IterationCallback* inner, const double* phi, int size)
        : inner_(inner), phi_(phi), size_(size) {}
    ceres::CallbackReturnType operator()(const ceres::IterationSummary& s) override {
      reached = Eigen::Map<const Eigen::VectorXd>(phi_, size_);  // the current point
      radius = s.trust_region_radius;
      if (s.iteration > 0) accepted = s.step_is_successful;
      if (s.iteration == 0 && started_) return ceres::SOLVER_CONTINUE;  // the same point again
      started_ = true;
      ceres::IterationSummary renumbered = s;
      renumbered.iteration = s.iteration == 0 ? 0 : ++steps;
      return inner_ != nullptr ? (*inner_)(renumbered) : ceres::SOLVER_CONTINUE;
    }
    int steps = 0;            // iterations after the 0th, over every solve
    double radius = 0.0;      // Ceres' trust radius after the last one
    bool accepted = false;    // the last step
    Eigen::VectorXd reached;  // the current point at the last iteration

   private:
    ceres::IterationCallback* inner_;
    const double* phi_;
    int size_;
    bool started_ = false;
  } renumbered(callback, phi, static_cast<int>(parameters.size()));

  const int P = static_cast<int>(parameters.size());
  // Each variable's widest half-box, and the share of it in use (1 at first).
  std::vector<double> widest(static_cast<size_t>(P));
  for (int k = 0; k < P; ++k) {
    const double range = upper[k] - lower[k];
    // A linear variable with an open bound has no scale to share: unboxed.
    widest[static_cast<size_t>(k)] =
        parameters[static_cast<size_t>(k)].log_scale ? std::log(steps.max_step_factor)
        : std::isfinite(range)                       ? steps.max_step_share * range
                                                     : std::numeric_limits<double>::infinity();
  }
  double reach = 1.0;
  double radius = steps.initial_trust_region_radius;
  ceres::Solver::Summary summary;
  for (;;) {
    // The gradient at the current point (its runs are kept: no new run).
    problem.SetManifold(phi, nullptr);
    std::vector<double> gradient;
    double cost = 0.0;
    std::vector<int> held;
    if (problem.Evaluate(ceres::Problem::EvaluateOptions(), &cost, nullptr, &gradient, nullptr))
      for (int k = 0; k < P; ++k) {
        if (!on_bound(phi[k], lower[k], upper[k])) continue;
        const bool at_lower = phi[k] - lower[k] < upper[k] - phi[k];
        const double g = gradient[static_cast<size_t>(k)];
        if (at_lower ? g > 0.0 : g < 0.0) held.push_back(k);  // descent leaves the bounds
      }
    if (static_cast<int>(held.size()) == P) {  // every variable pressed on its bound
      summary.termination_type = ceres::CONVERGENCE;
      summary.message = "every parameter is held on a bound by the gradient.";
      return summary;
    }
    if (!held.empty()) problem.SetManifold(phi, new ceres::SubsetManifold(P, held));
    for (int k = 0; k < P; ++k) {
      const double half = reach * widest[static_cast<size_t>(k)];
      const double low = std::max(lower[k], phi[k] - half);
      const double high = std::min(upper[k], phi[k] + half);
      if (std::isfinite(low)) problem.SetParameterLowerBound(phi, k, low);
      if (std::isfinite(high)) problem.SetParameterUpperBound(phi, k, high);
    }
    ceres::Solver::Options options =
        lm_solver(1, steps.function_tolerance, steps.parameter_tolerance, radius);
    options.callbacks.push_back(&renumbered);
    const int before = renumbered.steps;
    ceres::Solve(options, &problem, &summary);
    // Stopped by the callback (an interrupt, a budget): Ceres puts the solve's
    // start back into phi; the point its last iteration reached is the one
    // to keep (issue 43: an interrupted fit kept its start).
    if (summary.termination_type == ceres::USER_FAILURE && renumbered.reached.size() == P)
      Eigen::Map<Eigen::VectorXd>(phi, P) = renumbered.reached;
    // One iteration per solve: Ceres' "no convergence" is the next step's cue.
    if (summary.termination_type != ceres::NO_CONVERGENCE) return summary;
    if (renumbered.steps == before) return summary;
    if (renumbered.steps >= steps.max_iterations) {
      summary.message = "Maximum number of iterations reached.";
      return summary;
    }
    radius = renumbered.radius;
    reach = renumbered.accepted ? std::min(1.0, 2.0 * reach) : 0.5 * reach;
  }
}

}  // namespace fiberfluid::fit

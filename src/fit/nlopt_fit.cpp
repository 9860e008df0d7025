// SPDX-License-Identifier: GPL-3.0-or-later
// Derivative-free fits (NLopt): BOBYQA locally; DIRECT-L or CRS2 globally
// within the bounds, then BOBYQA from the best point the global search found.
#include <nlopt.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>

#include "fiberfluid/fit/optimizers.hpp"
#include "fiberfluid/util/error.hpp"
#include "fiberfluid/util/run_control.hpp"

namespace fiberfluid::fit {
namespace {

// What a failed forward run costs: far above any real cost, yet finite (the
// quadratic models of BOBYQA do not survive infinities).
constexpr double kFailedCost = 1e30;

struct NloptCost {
  NloptCost(EvaluationCache& e, const FitProblem& p, const FitOptions& o, OptimizerOutcome& out)
      : evaluations(e), fit_problem(p), options(o), outcome(out) {}
  EvaluationCache& evaluations;
  const FitProblem& fit_problem;
  const FitOptions& options;
  OptimizerOutcome& outcome;
  std::chrono::steady_clock::time_point start = std::chrono::steady_clock::now();
  double best = std::numeric_limits<double>::infinity();
  Eigen::VectorXd best_phi;
  int calls = 0;
  nlopt_opt running = nullptr;  // the optimiser calling, stopped on a requested interruption
  bool spent = false;           // a point was refused: max_evaluations ran out

  double operator()(const double* x) {
    const int P = fit_problem.parameters().size();
    const Eigen::VectorXd phi = Eigen::Map<const Eigen::VectorXd>(x, P);
    // max_evaluations bounds the forward runs, the start's included (as for
    // Levenberg-Marquardt), not NLopt's calls: its own limit counts calls
    // that the cache answers and DIRECT-L finishes a sweep past it. A point
    // that would need one run more is not run, and the search stops.
    if (evaluations.kept(phi, false) == nullptr &&
        evaluations.forward_runs >= options.max_evaluations) {
      spent = true;
      if (running) nlopt_force_stop(running);
      return kFailedCost;
    }
    const Evaluation& e = evaluations.at(phi, false);
    ++calls;
    const double cost = e.ok && std::isfinite(fit_problem.cost(e.residuals))
                            ? fit_problem.cost(e.residuals)
                            : kFailedCost;
    if (cancel_requested() && running) nlopt_force_stop(running);
    if (cost < best) {
      best = cost;
      best_phi = phi;
      IterationRecord r;
      r.iteration = calls;
      r.cost = r.trial_cost = cost;
      r.values = fit_problem.parameters().values(phi);
      r.forward_runs = evaluations.forward_runs;
      r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      outcome.iterations.push_back(r);
      if (options.progress) options.progress(r);
    }
    return cost;
  }
  static double call(unsigned, const double* x, double*, void* data) {
    return (*static_cast<NloptCost*>(data))(x);
  }
};

std::string describe(nlopt_result r) {
  switch (r) {
    case NLOPT_SUCCESS:
      return "success";
    case NLOPT_STOPVAL_REACHED:
      return "the cost reached its target";
    case NLOPT_FTOL_REACHED:
      return "converged: the cost changes less than function_tolerance";
    case NLOPT_XTOL_REACHED:
      return "converged: the parameters change less than parameter_tolerance";
    case NLOPT_MAXEVAL_REACHED:
      return "stopped at max_evaluations";
    case NLOPT_MAXTIME_REACHED:
      return "stopped at the time limit";
    case NLOPT_FAILURE:
      return "failure";
    case NLOPT_INVALID_ARGS:
      return "invalid arguments (bounds?)";
    case NLOPT_OUT_OF_MEMORY:
      return "out of memory";
    case NLOPT_ROUNDOFF_LIMITED:
      return "limited by rounding";
    case NLOPT_FORCED_STOP:
      return "stopped";
    default:
      break;
  }
  return "unknown result";
}

// One NLopt run of `algorithm` from phi (updated to the best point).
nlopt_result minimise(nlopt_algorithm algorithm, const FitProblem& fit_problem,
                      const FitOptions& options, NloptCost& objective, Eigen::VectorXd& phi,
                      int max_evaluations) {
  // NLopt reads a limit of 0 or less as none: a phase left without
  // evaluations (the global half of max_evaluations 1, or the local rest
  // after a global phase that spent them all) does not run.
  if (max_evaluations < 1) return NLOPT_MAXEVAL_REACHED;
  const ParameterMap& map = fit_problem.parameters();
  const int P = map.size();
  nlopt_opt opt = nlopt_create(algorithm, static_cast<unsigned>(P));
  const Eigen::VectorXd lower = map.lower_phi(), upper = map.upper_phi();
  nlopt_set_lower_bounds(opt, lower.data());
  nlopt_set_upper_bounds(opt, upper.data());
  nlopt_set_min_objective(opt, &NloptCost::call, &objective);
  objective.running = opt;
  nlopt_set_ftol_rel(opt, options.function_tolerance);
  nlopt_set_xtol_rel(opt, options.parameter_tolerance);
  nlopt_set_maxeval(opt, max_evaluations);
  // First steps: a factor e^0.3 for log-scaled parameters; for linear ones
  // a tenth of the value (alignment: 0.05 rad, 5% of the body's length).
  Eigen::VectorXd step(P);
  for (int k = 0; k < P; ++k) {
    const Parameter& p = map.parameters()[static_cast<size_t>(k)];
    step[k] = p.log_scale                            ? 0.3
              : p.name.rfind("rotation_", 0) == 0    ? 0.05 / p.scale
              : p.name.rfind("translation_", 0) == 0 ? 0.05 * fit_problem.body_length() / p.scale
                                                     : 0.1 * std::max(std::abs(phi[k]), 1e-3);
    if (std::isfinite(lower[k]) && std::isfinite(upper[k]))
      step[k] = std::min(step[k], 0.25 * (upper[k] - lower[k]));
  }
  nlopt_set_initial_step(opt, step.data());
  double value = 0.0;
  Eigen::VectorXd x = phi;
  const nlopt_result result = nlopt_optimize(opt, x.data(), &value);
  objective.running = nullptr;
  nlopt_destroy(opt);
  if (objective.best_phi.size() == P) phi = objective.best_phi;
  return result;
}

}  // namespace

OptimizerOutcome fit_nlopt(EvaluationCache& evaluations, const FitProblem& fit_problem,
                           const FitOptions& options, const Eigen::VectorXd& start) {
  OptimizerOutcome outcome;
  const ParameterMap& map = fit_problem.parameters();
  Eigen::VectorXd phi = start;
  NloptCost objective(evaluations, fit_problem, options, outcome);
  // The start (run before the search) is its first point: the best so far
  // even when max_evaluations leaves no run for another.
  objective(start.data());
  nlopt_result result;
  if (options.method == Method::Bobyqa) {
    result =
        minimise(NLOPT_LN_BOBYQA, fit_problem, options, objective, phi, options.max_evaluations);
  } else {
    const Eigen::VectorXd lower = map.lower_phi(), upper = map.upper_phi();
    for (int k = 0; k < map.size(); ++k)
      if (!std::isfinite(lower[k]) || !std::isfinite(upper[k]))
        throw InputError("parameter \"" + map.parameters()[static_cast<size_t>(k)].name +
                         "\": a global search (" + to_string(options.method) +
                         ") needs finite lower and upper bounds");
    const int global = std::max(1, options.max_evaluations / 2);
    minimise(options.method == Method::DirectL ? NLOPT_GN_DIRECT_L : NLOPT_GN_CRS2_LM, fit_problem,
             options, objective, phi, global);
    result = cancel_requested() || objective.spent
                 ? NLOPT_FORCED_STOP
                 : minimise(NLOPT_LN_BOBYQA, fit_problem, options, objective, phi,
                            options.max_evaluations - evaluations.forward_runs);
  }
  if (objective.spent && !cancel_requested()) result = NLOPT_MAXEVAL_REACHED;
  outcome.phi = phi;
  if (cancel_requested())
    outcome.status = FitStatus::Interrupted;
  else if (!(objective.best < kFailedCost))
    outcome.status = FitStatus::ForwardRunsFailed;
  else if (result == NLOPT_MAXEVAL_REACHED)
    outcome.status = FitStatus::IterationLimit;
  else if (result > 0)
    outcome.status = FitStatus::Converged;
  else
    outcome.status = FitStatus::OptimizerFailed;
  outcome.message = std::string(to_string(options.method)) + ": " + describe(result) + " after " +
                    std::to_string(objective.calls) + " evaluations";
  return outcome;
}

}  // namespace fiberfluid::fit

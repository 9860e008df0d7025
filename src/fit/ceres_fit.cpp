// SPDX-License-Identifier: GPL-3.0-or-later
// Levenberg-Marquardt (Ceres) and the covariance at the optimum.
#include <ceres/ceres.h>
#include <ceres/manifold.h>
#include <glog/logging.h>

#include <chrono>
#include <limits>
#include <memory>

#include "fiberfluid/fit/lm_solver.hpp"
#include "fiberfluid/fit/optimizers.hpp"
#include "fiberfluid/util/run_control.hpp"

namespace fiberfluid::fit {
namespace {

// One forward run serves every residual at one point: Ceres asks residual
// by residual (each its own block, so that a robust loss acts on each
// distance), and the cache keeps the run.
class SharedEvaluation {
 public:
  explicit SharedEvaluation(EvaluationCache& cache, int max_runs = std::numeric_limits<int>::max())
      : cache_(cache), max_runs_(max_runs) {}

  const Evaluation& at(const double* phi, bool with_jacobian) {
    // Analytic sensitivities cost a few tangent solves next to a whole
    // forward run: take them always, so that an accepted trial point needs
    // no second run when Ceres asks for its Jacobian.
    with_jacobian = with_jacobian || cache_.objective().analytic_jacobian();
    const int P = cache_.objective().variables().size();
    return cache_.at(Eigen::Map<const Eigen::VectorXd>(phi, P), with_jacobian);
  }
  // False when the point would need forward runs beyond max_evaluations
  // (a kept point needs none).
  bool affordable(const double* phi, bool with_jacobian) const {
    const Objective& objective = cache_.objective();
    if (cache_.forward_runs < max_runs_) return true;
    with_jacobian = with_jacobian || objective.analytic_jacobian();
    return cache_.kept(Eigen::Map<const Eigen::VectorXd>(phi, objective.variables().size()),
                       with_jacobian) != nullptr;
  }
  const EvaluationCache& cache() const { return cache_; }

 private:
  EvaluationCache& cache_;
  int max_runs_;
};

class DistanceResidual final : public ceres::CostFunction {
 public:
  DistanceResidual(SharedEvaluation* shared, int index, int parameters)
      : shared_(shared), index_(index) {
    set_num_residuals(1);
    mutable_parameter_block_sizes()->push_back(parameters);
  }
  bool Evaluate(double const* const* phi, double* residuals, double** jacobians) const override {
    const bool with_jacobian = jacobians != nullptr && jacobians[0] != nullptr;
    if (!shared_->affordable(phi[0], with_jacobian)) return false;  // the recorder stops the fit
    const Evaluation& e = shared_->at(phi[0], with_jacobian);
    if (!e.ok) return false;  // a failed forward run: Ceres rejects the step
    residuals[0] = e.residuals[index_];
    if (with_jacobian)
      for (Eigen::Index k = 0; k < e.jacobian.cols(); ++k) jacobians[0][k] = e.jacobian(index_, k);
    return true;
  }

 private:
  SharedEvaluation* shared_;
  int index_;
};

std::unique_ptr<ceres::LossFunction> make_loss(const FitOptions& options) {
  switch (options.loss) {
    case Loss::Huber:
      return std::make_unique<ceres::HuberLoss>(options.loss_scale);
    case Loss::Cauchy:
      return std::make_unique<ceres::CauchyLoss>(options.loss_scale);
    case Loss::Squared:
      break;
  }
  return nullptr;
}

// The problem over phi: one residual block per distance, bounds on phi.
struct CeresProblem {
  SharedEvaluation shared;
  std::unique_ptr<ceres::LossFunction> loss;
  ceres::Problem problem;

  CeresProblem(EvaluationCache& cache, const FitOptions& options, Eigen::VectorXd& phi,
               int max_runs = std::numeric_limits<int>::max())
      : shared(cache, max_runs), loss(make_loss(options)), problem(problem_options()) {
    const Objective& objective = cache.objective();
    const Variables& map = objective.variables();
    for (int i = 0; i < objective.num_residuals(); ++i)
      problem.AddResidualBlock(new DistanceResidual(&shared, i, map.size()), loss.get(),
                               phi.data());
    const Eigen::VectorXd lower = map.lower_phi(), upper = map.upper_phi();
    for (int k = 0; k < map.size(); ++k) {
      if (std::isfinite(lower[k])) problem.SetParameterLowerBound(phi.data(), k, lower[k]);
      if (std::isfinite(upper[k])) problem.SetParameterUpperBound(phi.data(), k, upper[k]);
    }
  }
  static ceres::Problem::Options problem_options() {
    ceres::Problem::Options o;
    o.loss_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;  // one loss for every block
    return o;
  }
};

class Recorder final : public ceres::IterationCallback {
 public:
  Recorder(const Objective& objective, const FitOptions& options, const Eigen::VectorXd& phi,
           const SharedEvaluation& shared, OptimizerOutcome& outcome)
      : objective_(objective),
        options_(options),
        phi_(phi),
        shared_(shared),
        outcome_(outcome),
        start_(std::chrono::steady_clock::now()) {}
  ceres::CallbackReturnType operator()(const ceres::IterationSummary& s) override {
    IterationRecord r =
        lm_iteration(s.iteration, s.step_is_successful, s.cost, outcome_.iterations);
    // A trial point whose forward run failed since the last report: say why,
    // not its stand-in cost. (Ceres reports no iteration for a trial point
    // it could not evaluate: it shrinks the region and tries again.)
    const int failed = shared_.cache().failed_runs;
    if (failed > failures_seen_) r.trial_failure = shared_.cache().last_failure;
    failures_seen_ = failed;
    r.values = objective_.variables().values(phi_);  // update_state_every_iteration
    r.forward_runs = shared_.cache().forward_runs;
    r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
    outcome_.iterations.push_back(r);
    if (options_.progress) options_.progress(r);
    // max_evaluations bounds the forward runs (as for NLopt's methods); the
    // point reached is kept.
    evaluations_spent = r.forward_runs >= options_.max_evaluations;
    return cancel_requested() || evaluations_spent ? ceres::SOLVER_ABORT : ceres::SOLVER_CONTINUE;
  }
  bool evaluations_spent = false;

 private:
  const Objective& objective_;
  const FitOptions& options_;
  const Eigen::VectorXd& phi_;
  const SharedEvaluation& shared_;
  OptimizerOutcome& outcome_;
  std::chrono::steady_clock::time_point start_;
  int failures_seen_ = 0;
};

}  // namespace

IterationRecord lm_iteration(int iteration, bool step_taken, double cost,
                             const std::vector<IterationRecord>& earlier) {
  IterationRecord r;
  r.iteration = iteration;
  // Ceres reports a rejected step's cost as the iteration's cost; the
  // current point's is the last accepted one.
  r.accepted = iteration == 0 || step_taken;
  r.trial_cost = cost;
  r.cost = r.accepted || earlier.empty() ? cost : earlier.back().cost;
  return r;
}

OptimizerOutcome fit_levenberg_marquardt(EvaluationCache& evaluations, const FitOptions& options,
                                         const Eigen::VectorXd& start) {
  const Objective& objective = evaluations.objective();
  const Variables& variables = objective.variables();
  OptimizerOutcome outcome;
  Eigen::VectorXd phi = start;
  CeresProblem p(evaluations, options, phi, options.max_evaluations);
  Recorder recorder(objective, options, phi, p.shared, outcome);
  LmSteps steps;
  steps.max_iterations = options.max_iterations;
  steps.function_tolerance = options.function_tolerance;
  steps.parameter_tolerance = options.parameter_tolerance;
  steps.initial_trust_region_radius = options.initial_trust_region_radius;
  steps.max_step_factor = options.max_step_factor;
  steps.max_step_share = options.max_step_share;
  const ceres::Solver::Summary summary =
      solve_in_moving_box(p.problem, phi.data(), variables.parameters(), variables.lower_phi(),
                          variables.upper_phi(), steps, &recorder);
  outcome.phi = phi;  // the best point: Ceres keeps it in phi, also when stopped
  outcome.message = "levenberg-marquardt: " + summary.message;
  switch (summary.termination_type) {
    case ceres::CONVERGENCE:
      outcome.status = FitStatus::Converged;
      break;
    case ceres::NO_CONVERGENCE:
      outcome.status = FitStatus::IterationLimit;
      outcome.message += " (max_iterations " + std::to_string(options.max_iterations) + ")";
      break;
    case ceres::USER_SUCCESS:
    case ceres::USER_FAILURE:
      outcome.status = cancel_requested() ? FitStatus::Interrupted : FitStatus::OptimizerFailed;
      if (recorder.evaluations_spent && !cancel_requested()) {
        outcome.status = FitStatus::IterationLimit;
        outcome.message =
            "levenberg-marquardt: stopped at " + std::to_string(evaluations.forward_runs) +
            " forward runs (max_evaluations " + std::to_string(options.max_evaluations) + ")";
      }
      break;
    case ceres::FAILURE:
      // Ceres fails when a point it must have (the Jacobian at an accepted
      // point, a finite-difference run) cannot be evaluated.
      outcome.status = p.shared.cache().failed_runs > 0 ? FitStatus::ForwardRunsFailed
                                                        : FitStatus::OptimizerFailed;
      if (p.shared.cache().failed_runs > 0) outcome.message += ": " + p.shared.cache().last_failure;
      break;
  }
  // A stop asked for ends Ceres in whichever way the runs it cut short lead to.
  if (cancel_requested()) outcome.status = FitStatus::Interrupted;
  return outcome;
}

bool phi_covariance(EvaluationCache& evaluations, const FitOptions& options,
                    const Eigen::VectorXd& at, Eigen::MatrixXd* covariance,
                    const std::vector<int>& held) {
  Eigen::VectorXd phi = at;
  CeresProblem p(evaluations, options, phi);
  if (!held.empty())  // the covariance is then the ambient one, 0 where held
    p.problem.SetManifold(phi.data(),
                          new ceres::SubsetManifold(static_cast<int>(phi.size()), held));
  ceres::Covariance::Options o;
  o.algorithm_type = ceres::DENSE_SVD;  // reports a rank-deficient J instead of failing obscurely
  o.num_threads = 1;
  ceres::Covariance c(o);
  const std::vector<std::pair<const double*, const double*>> blocks = {{phi.data(), phi.data()}};
  // A rank-deficient J is an answer here (the fit says "not identifiable"
  // and why), not an error for glog to print on stderr.
  const int log_level = FLAGS_minloglevel;
  FLAGS_minloglevel = google::GLOG_FATAL;
  const bool ok = c.Compute(blocks, &p.problem);
  FLAGS_minloglevel = log_level;
  if (!ok) return false;
  const int P = evaluations.objective().variables().size();
  Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> C(P, P);
  if (!c.GetCovarianceBlock(phi.data(), phi.data(), C.data())) return false;
  *covariance = C;
  return covariance->allFinite();
}

}  // namespace fiberfluid::fit

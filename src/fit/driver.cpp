// SPDX-License-Identifier: GPL-3.0-or-later
// The fit's driver: the start's probe and a stiffer start where it fails,
// the optimiser, the run at the optimum (along the path, where it was warm
// started), and the estimate's ending.
#include "fiberfluid/fit/driver.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <sstream>

#include "fiberfluid/fit/evaluation_cache.hpp"
#include "fiberfluid/fit/optimizers.hpp"
#include "fiberfluid/fit/uncertainty.hpp"
#include "fiberfluid/util/run_control.hpp"

namespace fiberfluid::fit {

FitDriver::FitDriver(const FitProblem& problem) : problem_(problem) {}

FitResult FitDriver::result_from(const Eigen::VectorXd& phi) const {
  const FitProblem& m = problem_;
  const int P = m.parameters().size();
  const double nan = std::numeric_limits<double>::quiet_NaN();
  FitResult result;
  result.method = m.options().method;
  result.analytic_jacobian = m.analytic_jacobian();
  result.names = m.parameters().names();
  result.initial = result.values = m.parameters().values(phi);
  result.standard_errors = result.lower_95 = result.upper_95 = Eigen::VectorXd::Constant(P, nan);
  result.correlation = Eigen::MatrixXd::Constant(P, P, nan);
  result.initial_cost = result.final_cost = nan;
  return result;
}

FitResult FitDriver::result_at(const Eigen::VectorXd& phi) const {
  FitResult result = result_from(phi);
  const Evaluation at = problem_.evaluate(phi, false, Eigen::VectorXd());
  result.forward_runs = at.forward_runs;
  if (!at.ok) {
    result.status = cancel_requested() ? FitStatus::Interrupted : FitStatus::ForwardRunsFailed;
    result.message = "the forward run failed: " + at.message;
    return result;
  }
  problem_.describe(at, result);
  result.initial_cost = result.final_cost;
  result.status = FitStatus::Converged;
  result.success = true;
  return result;
}

void FitDriver::check_along_path(const Eigen::VectorXd& phi, const Evaluation& warm,
                                 FitResult& result) const {
  const Evaluation path = problem_.evaluate(phi, false, Eigen::VectorXd());
  if (!path.ok) {
    if (cancel_requested()) return;
    result.warm_start_note = "the run along the load path at the fitted values failed (" +
                             path.message +
                             "): the fit's warm-started equilibrium is not reached from the "
                             "unloaded body";
    return;
  }
  // Both are equilibria to Newton's tolerance: the same one agrees far below
  // the distances' scale; another one (a branch) differs at it.
  const double gap = (path.residuals - warm.residuals).lpNorm<Eigen::Infinity>();
  const double scale =
      std::max(warm.residuals.lpNorm<Eigen::Infinity>(), 1e-9 * problem_.body_length());
  if (gap > 1e-4 * scale) {
    std::ostringstream note;
    note << "the run along the load path at the fitted values differs from the warm-started one "
            "by up to "
         << gap << " m in a residual (the residuals reach " << scale
         << " m): another equilibrium; the path's is reported (fit with \"warm_start\": false)";
    result.warm_start_note = note.str();
  }
  problem_.describe(path, result);  // the path's run: every step's record
}

namespace {

// When the covariance at the optimum fails: the parameters the data cannot
// see one by one (a column of zeros, a log-scaled one sunk to its bound) are
// held at their values, so that the others keep their estimates and
// intervals (`covariance`, `held`). Returns "" when that gives a covariance,
// else why the fit is not identifiable.
std::string hold_unseen(const FitProblem& m, EvaluationCache& evaluations,
                        const Eigen::VectorXd& phi, Eigen::MatrixXd* covariance,
                        std::vector<int>* held) {
  const Evaluation* with_jacobian = evaluations.kept(phi, true);
  if (with_jacobian == nullptr || !with_jacobian->ok)
    return "the Jacobian at the optimum could not be evaluated: " + evaluations.last_failure;
  const Eigen::MatrixXd& J = with_jacobian->jacobian;
  *held = parameters_to_hold(J, m.parameters(), phi);
  if (!held->empty() && static_cast<int>(held->size()) < m.parameters().size() &&
      phi_covariance(evaluations, m.options(), phi, covariance, *held))
    return "";
  held->clear();
  std::vector<std::string> names;
  for (const Parameter& p : m.parameters().parameters()) names.push_back(p.name);
  return unidentifiable_because(J, names);
}

// The fitted parameters that scale the body's stiffness: the law's moduli
// (Y, Y0, Y_t, Y_c), gamma and the axis factors.
bool scales_stiffness(const std::string& name) {
  return (!name.empty() && name[0] == 'Y') || name == "gamma" || name.rfind("factor_", 0) == 0;
}

// A start probe's limits: a step cut at most twice, a piece given at most 12
// Newton iterations. A start that needs more is too soft for its load more
// often than not, and a stiffer start costs less than the failing step's
// remaining cuts (the layered phantom from Y/5: the probe gives up after
// 72 s, the full run after 109 s).
constexpr int kProbeCuts = 2;
constexpr int kProbeIterations = 12;

}  // namespace

Evaluation FitDriver::probe_start(const Eigen::VectorXd& phi, bool with_jacobian,
                                  const Eigen::VectorXd& warm_start) const {
  solve::SteppingOptions stepping = problem_.stepping();
  stepping.newton.max_step_cuts = std::min(stepping.newton.max_step_cuts, kProbeCuts);
  stepping.newton.max_iterations = std::min(stepping.newton.max_iterations, kProbeIterations);
  if (problem_.warm_starts()) stepping.warm_start = warm_start;
  return problem_.evaluate(phi, with_jacobian, std::move(stepping), true);
}

// A forward run that fails at the start is most often a material too soft
// for its load: a face turns over, or the run runs away. With every modulus
// and gamma times s the equilibrium at the full load is the start's at 1/s
// of it (the pressure times s): the same body with the load divided by s.
// So the start is stiffened by 2, 4, ... 1024, within the bounds, and a
// stiffened start whose end the failed probe passed (its state at step n/s)
// is solved from there, warm; the others walk their paths (a runaway at a
// step too large for a soft body need not recur on a stiffer one). A body
// moved only by prescribed motions and paddles has nothing to stiffen
// against.
std::optional<Eigen::VectorXd> FitDriver::stiffer_start(const Eigen::VectorXd& start_phi,
                                                        const Evaluation& failed_probe,
                                                        EvaluationCache& evaluations,
                                                        bool with_sensitivities,
                                                        double* factor) const {
  const FitProblem& m = problem_;
  if (m.model().loads.empty()) return std::nullopt;
  const std::vector<Parameter>& parameters = m.parameters().parameters();
  const Eigen::VectorXd upper = m.parameters().upper_phi();
  std::vector<int> stiffness;
  for (int k = 0; k < m.parameters().size(); ++k)
    if (scales_stiffness(parameters[static_cast<size_t>(k)].name)) stiffness.push_back(k);
  if (stiffness.empty()) return std::nullopt;
  const Eigen::VectorXd start = m.parameters().values(start_phi);
  const int n = m.stepping().steps;
  for (double s = 2.0; s <= kStiffest && !cancel_requested(); s *= 2.0) {
    Eigen::VectorXd phi = start_phi;
    bool moved = false;
    for (int k : stiffness) {
      const Parameter& p = parameters[static_cast<size_t>(k)];
      const double value = s * start[k];
      const double wanted = p.to_phi(value);
      phi[k] = std::min(wanted, upper[k]);
      moved |= phi[k] > start_phi[k];
    }
    if (!moved) return std::nullopt;  // every stiffness on its upper bound
    Eigen::VectorXd warm;             // the probe's state at n/s, its pressure times s
    if (const auto at = failed_probe.path_states.find(static_cast<int>(step_at_share(n, s)));
        at != failed_probe.path_states.end()) {
      warm = at->second;
      warm[warm.size() - 1] *= s;
    }
    if (evaluations.add(phi, with_sensitivities, probe_start(phi, with_sensitivities, warm))) {
      *factor = s;
      return phi;
    }
  }
  return std::nullopt;
}

// A start too soft for its load fails fast in a probe, and a stiffer start
// is looked for; only when none runs is the start run in full.
std::optional<Eigen::VectorXd> FitDriver::starting_point(
    const Eigen::VectorXd& start_phi, bool with_sensitivities, EvaluationCache& evaluations,
    FitResult& result, std::pair<FitStatus, std::string>* ending) const {
  const auto stop = [&](FitStatus status, std::string message) {
    *ending = {status, std::move(message)};
    return std::optional<Eigen::VectorXd>();
  };
  if (evaluations.kept(start_phi, with_sensitivities) == nullptr) {
    const Evaluation probe = probe_start(start_phi, with_sensitivities);
    if (evaluations.add(start_phi, with_sensitivities, probe) == nullptr) {
      if (cancel_requested()) return stop(FitStatus::Interrupted, "interrupted at the start");
      double factor = 1.0;
      const std::optional<Eigen::VectorXd> stiffer =
          stiffer_start(start_phi, probe, evaluations, with_sensitivities, &factor);
      if (cancel_requested()) return stop(FitStatus::Interrupted, "interrupted at the start");
      if (stiffer) {
        std::ostringstream note;
        note << "the forward run at the starting parameters failed, in a probe that gives up "
                "after "
             << kProbeCuts << " halvings of a step or " << kProbeIterations
             << " Newton iterations (" << probe.message
             << "); the fit started from the moduli and gamma times " << factor
             << ", the softest such start whose run succeeds";
        result.start_note = note.str();
        return stiffer;
      } else if (const Evaluation& given = evaluations.at(start_phi, with_sensitivities);
                 !given.ok) {
        if (cancel_requested()) return stop(FitStatus::Interrupted, "interrupted at the start");
        return stop(FitStatus::StartFailed,
                    "the forward run at the starting parameters failed: " + given.message +
                        (problem_.model().loads.empty()
                             ? ""
                             : " (and with the moduli and gamma up to 1024 times the start's, "
                               "within their bounds)"));
      }
    }
  }
  return start_phi;
}

namespace {

// The factor s that brings a run's small-load forces onto the measured ones,
// by weighted least squares over each curve's rows below a quarter of its
// largest measured force (at least its first three): where an exponent or a
// stiffening barely acts. NaN when there are no such rows.
double small_load_factor(const FitProblem& m, const Evaluation& e) {
  double fitted = 0.0, own = 0.0;
  for (size_t k = 0; k < m.force_curves().size() && k < e.forces.size(); ++k) {
    const ForceCurve& curve = m.force_curves()[k];
    const double largest = largest_measured(curve);
    const std::vector<double> weights = row_weights(curve, m.force_weight(k));  // as the fit's
    for (size_t r = 0; r < curve.force.size() && r < e.forces[k].size(); ++r) {
      const double measured = curve.force[r], simulated = e.forces[k][r];
      if (r >= 3 && std::abs(measured) > 0.25 * largest) continue;
      const double w = weights[r];
      fitted += w * w * simulated * measured;
      own += w * w * simulated * simulated;
    }
  }
  return own > 0.0 ? fitted / own : std::numeric_limits<double>::quiet_NaN();
}

}  // namespace

// With every modulus and gamma times s, a body moved by paddles and held
// motions alone passes through the same states with every force (and the
// pressure) times s. So the start's own run tells the scale that its
// small-load forces want, and the fit's steps are left the law's shape.
Eigen::VectorXd FitDriver::scaled_start(const Eigen::VectorXd& phi, bool with_sensitivities,
                                        EvaluationCache& evaluations, FitResult& result) const {
  const FitProblem& m = problem_;
  if (!m.options().scale_start || m.options().method != Method::LevenbergMarquardt ||
      !m.model().loads.empty() || m.force_curves().empty())
    return phi;
  const std::vector<Parameter>& parameters = m.parameters().parameters();
  // The law's stresses (its moduli, a spline's tension and rises) and gamma;
  // the axis factors only where no modulus is fitted (they multiply it).
  std::vector<int> stiffness, factors;
  for (int k = 0; k < m.parameters().size(); ++k) {
    const std::string& name = parameters[static_cast<size_t>(k)].name;
    if (name.rfind("factor_", 0) == 0) {
      factors.push_back(k);
    } else if (scales_stiffness(name) || name == "mu" || name == "T1" ||
               name.rfind("rise", 0) == 0) {
      stiffness.push_back(k);
    }
  }
  const bool modulus = std::any_of(stiffness.begin(), stiffness.end(), [&](int k) {
    return parameters[static_cast<size_t>(k)].name != "gamma";
  });
  if (!modulus) stiffness.insert(stiffness.end(), factors.begin(), factors.end());
  if (stiffness.empty()) return phi;
  const Evaluation start = evaluations.at(phi, with_sensitivities);  // kept: no run
  const double s = small_load_factor(m, start);
  if (!(s > 0.0) || !std::isfinite(s) || std::abs(std::log(s)) < std::log(1.05)) return phi;
  const Eigen::VectorXd values = m.parameters().values(phi);
  const Eigen::VectorXd lower = m.parameters().lower_phi(), upper = m.parameters().upper_phi();
  Eigen::VectorXd scaled = phi;
  for (int k : stiffness) {
    const double value = s * values[k];
    const double wanted = parameters[static_cast<size_t>(k)].to_phi(value);
    scaled[k] = std::clamp(wanted, lower[k], upper[k]);
  }
  const Evaluation& at = evaluations.at(scaled, with_sensitivities);
  std::ostringstream note;
  note << "the moduli and gamma scaled by " << s << " to the start's small-load forces";
  if (at.ok && m.cost(at.residuals) < m.cost(start.residuals)) {
    note << " (cost " << m.cost(start.residuals) << " to " << m.cost(at.residuals) << ")";
    result.start_note += (result.start_note.empty() ? "" : "; then ") + note.str();
    return scaled;
  }
  note << ": not kept (" << (at.ok ? "its cost is not lower" : "its run failed: " + at.message)
       << ")";
  result.start_note += (result.start_note.empty() ? "" : "; then ") + note.str();
  return phi;
}

FitResult FitDriver::run_from(const Eigen::VectorXd& start_phi) const {
  const FitProblem& m = problem_;
  const auto start = std::chrono::steady_clock::now();
  const int P = m.parameters().size();
  // Sized from the start, whatever the ending: a report never reads past them.
  FitResult result = result_from(start_phi);
  EvaluationCache evaluations(problem_);
  auto finish = [&](FitStatus status, std::string message) {
    result.status = status;
    result.success = converged(status);
    if (!message.empty()) result.message = std::move(message);
    result.forward_runs = evaluations.forward_runs;
    result.warm_started_runs = evaluations.warm_started_runs;
    result.sensitivity_solves = evaluations.sensitivity_solves;
    result.failed_runs = evaluations.failed_runs;
    result.failures_by_cause = evaluations.failures_by_cause;
    result.failed_examples = evaluations.failed_examples;
    result.seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return result;
  };
  // The start, as Levenberg-Marquardt will ask for it (with analytic
  // sensitivities): a failure here is the user's to fix, not a rejected step.
  const bool levenberg_marquardt = m.options().method == Method::LevenbergMarquardt;
  const bool with_sensitivities = levenberg_marquardt && m.analytic_jacobian();
  std::pair<FitStatus, std::string> ending;
  std::optional<Eigen::VectorXd> phi0 =
      starting_point(start_phi, with_sensitivities, evaluations, result, &ending);
  if (!phi0) return finish(ending.first, ending.second);
  result.initial_cost = problem_.cost(evaluations.at(*phi0, with_sensitivities).residuals);
  phi0 = scaled_start(*phi0, with_sensitivities, evaluations, result);
  if (cancel_requested()) return finish(FitStatus::Interrupted, "");
  const Evaluation& first = evaluations.at(*phi0, with_sensitivities);
  if (!std::isfinite(problem_.cost(first.residuals)))
    return finish(FitStatus::NotIdentifiable, "the cost at the start is not finite");

  const OptimizerOutcome outcome = levenberg_marquardt
                                       ? fit_levenberg_marquardt(evaluations, m.options(), *phi0)
                                       : fit_nlopt(evaluations, m, m.options(), *phi0);
  result.message = outcome.message;
  result.iterations = outcome.iterations;
  result.values = m.parameters().values(outcome.phi);
  if (!result.iterations.empty()) result.final_cost = result.iterations.back().cost;

  // At the optimum (usually kept from the optimiser): the run and the
  // distances. An interrupted fit takes only what it has already run.
  const Evaluation* kept = evaluations.kept(outcome.phi, false);
  if (outcome.status == FitStatus::Interrupted && (kept == nullptr || !kept->ok))
    return finish(FitStatus::Interrupted, "");
  const Evaluation best =
      kept != nullptr ? *kept : evaluations.at(outcome.phi, false);  // a copy: entries move
  if (!best.ok) {
    if (cancel_requested()) return finish(FitStatus::Interrupted, "");
    return finish(FitStatus::ForwardRunsFailed,
                  "the forward run at the fitted parameters failed: " + best.message);
  }
  problem_.describe(best, result);
  if (best.summary.warm_started) {
    check_along_path(outcome.phi, best, result);
    evaluations.forward_runs += 1;
  }
  describe_bounds(m.parameters(), outcome.phi, false, result);
  if (outcome.status != FitStatus::Converged) return finish(outcome.status, "");

  // Converged: is it an estimate? The covariance needs a full-rank Jacobian.
  Eigen::MatrixXd covariance;
  result.covariance_ok = phi_covariance(evaluations, m.options(), outcome.phi, &covariance);
  if (cancel_requested()) return finish(FitStatus::Interrupted, "");
  std::vector<int> held;
  if (!result.covariance_ok) {
    // Why not, and whether holding the parameters the data cannot see mends it.
    result.status_detail = hold_unseen(m, evaluations, outcome.phi, &covariance, &held);
    if (!result.status_detail.empty()) return finish(FitStatus::NotIdentifiable, "");
    result.covariance_ok = true;
  }
  const int dof = m.num_residuals() - P;
  const double variance = dof > 0 ? 2.0 * result.final_cost / dof : 0.0;
  describe_estimates(m.parameters(), outcome.phi, covariance, variance, result);
  describe_unseen(held, result);
  if (m.options().check_intervals) {
    const int runs_before = evaluations.forward_runs;
    check_interval_ends(evaluations, problem_, outcome.phi, covariance, variance, result);
    result.interval_runs = evaluations.forward_runs - runs_before;
    if (cancel_requested()) return finish(FitStatus::Interrupted, "");
  }
  return finish(result.at_bounds.empty() ? FitStatus::Converged : FitStatus::ConvergedAtBounds, "");
}

}  // namespace fiberfluid::fit

// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once

// What a fit takes and gives (calibration.hpp's Calibration and every part
// of the fit): the measured steps, the methods, losses and statuses by name,
// the options and their one check, an evaluation at one point, a result.

#include <Eigen/Core>
#include <functional>
#include <limits>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "fiberfluid/fit/force_curve.hpp"
#include "fiberfluid/fit/parameters.hpp"
#include "fiberfluid/fit/target.hpp"
#include "fiberfluid/model/model.hpp"
#include "fiberfluid/solve/stepping.hpp"
#include "fiberfluid/util/names.hpp"

namespace fiberfluid::fit {

// A measured surface tied to the load step it was measured at.
struct MeasuredStep {
  Target target;
  int step = 0;  // 1..stepping.steps
};

enum class Method {
  LevenbergMarquardt,  // Ceres, with Jacobians (analytic for Newton)
  Bobyqa,              // NLopt, local and derivative-free
  DirectL,             // NLopt, global within the bounds, then BOBYQA from its best point
  Crs2,                // NLopt, global (controlled random search), then BOBYQA
};
inline constexpr auto kMethodNames =
    names_of<Method>({{Method::LevenbergMarquardt, "levenberg-marquardt"},
                      {Method::Bobyqa, "bobyqa"},
                      {Method::DirectL, "direct-l"},
                      {Method::Crs2, "crs2"}});
inline const char* to_string(Method method) { return kMethodNames.name(method); }
// "levenberg-marquardt", "bobyqa", "direct-l", "crs2"; throws InputError listing them.
inline Method method_from_string(const std::string& name) {
  return kMethodNames.parse(name, "method");
}

enum class Loss { Squared, Huber, Cauchy };
inline constexpr auto kLossNames =
    names_of<Loss>({{Loss::Squared, "squared"}, {Loss::Huber, "huber"}, {Loss::Cauchy, "cauchy"}});
inline const char* to_string(Loss loss) { return kLossNames.name(loss); }
// "squared", "huber", "cauchy"; throws InputError listing them.
inline Loss loss_from_string(const std::string& name) { return kLossNames.parse(name, "loss"); }

// How a fit ended. Only Converged gives an estimate to take as it is.
enum class FitStatus {
  Converged,          // the optimiser converged inside the bounds; standard errors are valid
  ConvergedAtBounds,  // converged with parameters on their bounds: those are the bounds, not estimates
  IterationLimit,     // max_iterations (LM) or max_evaluations (NLopt) ran out first
  NotIdentifiable,    // the distances cannot tell the parameters apart, or do not change with one
  ForwardRunsFailed,  // the optimiser stopped because forward runs failed
  StartFailed,        // the forward run at the starting parameters failed: the set-up
  OptimizerFailed,    // the optimiser stopped for another reason (its message says which)
  Interrupted,        // SIGINT or SIGTERM: the best point so far
};
// "converged", "converged_at_bounds", "iteration_limit", ... as in fit.json.
inline constexpr auto kFitStatusNames =
    names_of<FitStatus>({{FitStatus::Converged, "converged"},
                         {FitStatus::ConvergedAtBounds, "converged_at_bounds"},
                         {FitStatus::IterationLimit, "iteration_limit"},
                         {FitStatus::NotIdentifiable, "not_identifiable"},
                         {FitStatus::ForwardRunsFailed, "forward_runs_failed"},
                         {FitStatus::StartFailed, "start_failed"},
                         {FitStatus::OptimizerFailed, "optimizer_failed"},
                         {FitStatus::Interrupted, "interrupted"}});
inline const char* to_string(FitStatus status) { return kFitStatusNames.name(status); }
// Converged or ConvergedAtBounds: the optimiser converged (FitResult::success).
inline bool converged(FitStatus status) {
  return status == FitStatus::Converged || status == FitStatus::ConvergedAtBounds;
}

// A forward run that failed during a fit: where, and why.
struct FailedRun {
  Eigen::VectorXd values;  // the parameters' values
  std::string message;
};

struct IterationRecord {
  int iteration = 0;
  double cost = 0.0;  // 1/2 sum rho(r^2), m^2, at the current point
  // Levenberg-Marquardt: whether this iteration's trial point was accepted,
  // and its cost (a rejected one costs more than `cost`).
  bool accepted = true;
  double trial_cost = 0.0;
  // Why the forward run of a trial point tried in this iteration failed, if
  // one did (the step is then rejected, or a smaller one accepted).
  std::string trial_failure;
  Eigen::VectorXd values;  // the parameters' values at the current point
  int forward_runs = 0;    // so far
  double seconds = 0.0;    // since the start
};

struct FitOptions {
  Method method = Method::LevenbergMarquardt;
  // Analytic Jacobians need the Newton scheme; with the incremental scheme
  // (or when asked) they are central differences of whole runs.
  bool finite_differences = false;
  double difference_step = 1e-5;  // in the fitted variable (log or linear)
  // Also the distances from each target's points to the simulated surface:
  // catches a simulated surface that covers only part of the target.
  bool symmetric = false;
  Loss loss = Loss::Squared;
  double loss_scale = 1e-3;  // m: where Huber and Cauchy start to discount
  // The model vertices whose distances count (empty: all), e.g. without the clamped region.
  std::vector<int> counted_vertices;
  int max_iterations = 50;            // Levenberg-Marquardt iterations
  int max_evaluations = 400;          // NLopt objective evaluations (each a forward run)
  double function_tolerance = 1e-12;  // relative change of the cost that ends the fit
  double parameter_tolerance = 1e-8;  // relative change of the parameters
  // Levenberg-Marquardt's first trust region (Ceres' radius: the damping
  // starts at the scaled diagonal over it). The default (Ceres') starts with
  // nearly Gauss-Newton steps; about 10 damps the first steps, which pays
  // when a far start makes the full steps overshoot (each rejected step
  // costs a forward run and only halves the region).
  double initial_trust_region_radius = 1e4;
  // Levenberg-Marquardt: a trial point may change a log-scaled parameter by
  // at most this factor from the current point (a larger step is refused
  // without a forward run, and the region shrinks): a far start takes a few
  // more steps instead of trial runs at the bounds that fail slowly.
  double max_step_factor = 4.0;
  // And a linear parameter between finite bounds (an exponent: beta in
  // [-20, 20]) by at most this share of its range: every such step is
  // bounded, not only the log-scaled ones'. (One with an open bound has no
  // scale to share and is not boxed.)
  double max_step_share = 0.05;
  // Levenberg-Marquardt on force curves of a body moved by paddles and held
  // motions alone: before the first step, every fitted modulus and gamma is
  // scaled by the factor that matches the start's small-load forces (rows
  // below a quarter of the curve's largest force), since every force scales
  // with them exactly. One forward run; the scaled start is kept only when
  // its cost is lower.
  bool scale_start = true;
  // Solve each trial point's final state from the nearest point already run
  // (SteppingOptions::warm_start) instead of walking the load path again:
  // where every target and force curve reads the final step only and the
  // path's end does not depend on the way there (solve::check_warm_start).
  // A trial whose warm start fails walks the path; the optimum is run along
  // the path once more and checked against its warm-started run.
  bool warm_start = true;
  // After a converged fit, check each linearised 95% interval's ends on the
  // profile likelihood and move out an end the data leave open (at most 8
  // forward runs per parameter; FitResult::interval_notes). Off by default:
  // a profile point far from every run so far walks the whole load path,
  // which on a slow body costs more than the fit.
  bool check_intervals = false;
  // Called after every iteration (LM) or every improvement (NLopt).
  std::function<void(const IterationRecord&)> progress;
};

// The one check of a fit's options, whichever front end set them: throws
// InputError naming the option (as the "fit" section spells it) and what
// was expected. Calibration's constructor calls it.
void check_options(const FitOptions& options);

// The residuals at one point of the parameter space, and their Jacobian.
struct Evaluation {
  bool ok = false;
  std::string message;        // why the forward run failed
  Eigen::VectorXd residuals;  // m: the forward distances, the symmetric ones, the force misfits
  Eigen::MatrixXd jacobian;   // d residual / d phi (phi: the fitted variables)
  solve::SteppingSummary summary;
  std::vector<Eigen::MatrixXd> positions;   // per target: the model's positions at its step
  std::vector<std::vector<double>> forces;  // per force curve: the simulated force per row (N)
  int forward_runs = 0;
  int sensitivity_solves = 0;
  int warm_started_runs = 0;  // of forward_runs: solved from a nearby point's final state
  // A failed start probe's converged states at the steps nearest n/2, n/4,
  // ... (step -> unknowns): Calibration::stiffer_start warm-starts from them.
  std::map<int, Eigen::VectorXd> path_states;
};

// How a fitted force curve misses its measurement.
struct ForceMisfit {
  std::vector<double> simulated;    // per row (N), at the fitted values
  double rms = 0.0, largest = 0.0;  // of simulated - measured (N)
  double scale = 0.0;               // the largest measured |force| (N): the shares' reference
  double weight = 0.0;              // m per N, as used
  bool relative = false;            // weighed by each row's share of its force
  double share(double value) const { return scale > 0.0 ? value / scale : 0.0; }
  // The rms of (simulated - measured) / |measured| over the rows with a force.
  double rms_relative = std::numeric_limits<double>::quiet_NaN();
  // Whether what is left is the data's noise or the model's form: the
  // measurement's scatter (the rms of its sd column, N; NaN without one), and
  // the runs test on the misfit's signs in row order (Wald and Wolfowitz
  // 1940: the runs of one sign against those that random signs would give).
  double scatter = std::numeric_limits<double>::quiet_NaN();
  int runs = 0;
  double runs_expected = 0.0, runs_z = std::numeric_limits<double>::quiet_NaN();
  bool systematic = false;
  std::string verdict;  // one sentence saying which, and why
};

// What a target of a registered kind (ResidualBlock::describe) reports at the
// fitted values: its kind, its label and its figures by name.
struct TargetReport {
  std::string kind, label;
  std::map<std::string, double> figures;
  // Its rows, when it has any to show (a material test's points): the
  // columns' names and one row of values each, written as fit_other_K.csv.
  std::vector<std::string> columns;
  std::vector<std::vector<std::string>> rows;
};

struct FitResult {
  FitStatus status = FitStatus::StartFailed;
  bool success = false;  // Converged or ConvergedAtBounds: the optimiser converged
  std::string message;
  // Why the status is what it is, in a sentence: the parameters at their
  // bounds and their strongest correlation, the parameter no distance
  // depends on, ... (empty for Converged).
  std::string status_detail;
  // Where the forward run at the given start failed and the fit went on from
  // a stiffer start that runs: what failed and where it started ("" when the
  // given start ran).
  std::string start_note;
  // Forward runs whose final state was solved from a nearby point's
  // (FitOptions::warm_start), and, when the path's run at the optimum does
  // not reproduce its warm-started one (another equilibrium: a branch the
  // path does not follow), what differs ("" when it does, or none ran).
  int warm_started_runs = 0;
  std::string warm_start_note;
  std::vector<std::string> at_bounds;  // the parameters on a bound (ConvergedAtBounds)
  // The parameters the data cannot see (a Jacobian column that is 0, or lost
  // in the others'): held at their values, with no interval, so that the
  // others keep theirs (those of a fit with these fixed).
  std::vector<std::string> unseen;
  Method method = Method::LevenbergMarquardt;
  bool analytic_jacobian = true;
  std::vector<std::string> names;
  Eigen::VectorXd initial, values;
  // From the covariance at the optimum (Ceres), scaled by the residual
  // variance 2 cost / (residuals - parameters); intervals are 95%, in log
  // scale for log-scaled parameters (so they stay positive).
  bool covariance_ok = false;
  Eigen::VectorXd standard_errors, lower_95, upper_95;
  Eigen::MatrixXd correlation;
  // The intervals' ends checked on the profile (FitOptions::check_intervals):
  // per parameter, "" where the linearised ends stand, else how an end moved
  // out (the data do not bound it on that side, or the cost rises more
  // slowly than the quadratic's); the forward runs the checks took (in
  // forward_runs too).
  std::vector<std::string> interval_notes;
  int interval_runs = 0;
  std::vector<IterationRecord> iterations;
  double initial_cost = 0.0, final_cost = 0.0;
  int forward_runs = 0, sensitivity_solves = 0;
  int failed_runs = 0;  // trial points whose forward run failed: rejected steps
  // The failed runs counted by cause (their message with the numbers taken
  // out: "step #: runaway: face # turned over"), and the first few whole.
  std::map<std::string, int> failures_by_cause;
  std::vector<FailedRun> failed_examples;
  double seconds = 0.0;
  // At the fitted values: the run, and per target the distance of every
  // model vertex (NaN where it does not count) and its statistics. Empty
  // when no run at the fitted values exists (StartFailed, and Interrupted
  // before the best point was run again).
  solve::SteppingSummary summary;
  std::vector<Eigen::MatrixXd> positions;
  std::vector<Eigen::VectorXd> vertex_distances;
  std::vector<DistanceStatistics> statistics;
  DistanceStatistics overall;
  std::vector<ForceMisfit> force_misfits;   // per force curve, at the fitted values
  std::vector<TargetReport> other_targets;  // per target of another kind, in order
};

}  // namespace fiberfluid::fit

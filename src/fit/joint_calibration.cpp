// SPDX-License-Identifier: GPL-3.0-or-later
#include "fiberfluid/fit/joint_calibration.hpp"

#include <algorithm>
#include <chrono>
#include <limits>
#include <set>

#include "fiberfluid/fit/evaluation_cache.hpp"
#include "fiberfluid/fit/fit_archive.hpp"
#include "fiberfluid/fit/objective.hpp"
#include "fiberfluid/fit/optimizers.hpp"
#include "fiberfluid/fit/uncertainty.hpp"
#include "fiberfluid/util/byte_archive.hpp"
#include "fiberfluid/util/error.hpp"
#include "fiberfluid/util/run_control.hpp"

namespace fiberfluid::fit {
namespace {

// What rank 0 asks of every rank, with the point.
enum class Command : int {
  Evaluate = 1,  // the residuals (and the Jacobian) at phi
  Describe = 2,  // each specimen's run and distances at phi
  Stop = 3,      // the fit is over
};

std::string command_bytes(Command command, bool with_jacobian, const Eigen::VectorXd& phi) {
  ByteWriter out;
  out(command, with_jacobian, phi);
  return out.take();
}

}  // namespace

JointCalibration::JointCalibration(std::vector<std::string> specimen_names,
                                   std::vector<const Calibration*> specimens,
                                   std::vector<std::string> shared, JointOptions options)
    : specimen_names_(std::move(specimen_names)),
      specimens_(std::move(specimens)),
      options_(std::move(options)) {
  if (specimens_.size() < 2 || specimens_.size() != specimen_names_.size())
    throw InputError("specimens: a calibration over specimens needs two or more (got " +
                     std::to_string(specimens_.size()) + ")");
  if (std::set<std::string>(specimen_names_.begin(), specimen_names_.end()).size() !=
      specimen_names_.size())
    throw InputError("specimens: two specimens have the same name");
  if (std::set<std::string>(shared.begin(), shared.end()).size() != shared.size())
    throw InputError("shared: a parameter is named twice");
  const auto parameter_in = [&](size_t s, const std::string& name) {
    const std::vector<Parameter>& own = specimens_[s]->parameters().parameters();
    for (size_t k = 0; k < own.size(); ++k)
      if (own[k].name == name) return static_cast<int>(k);
    return -1;
  };
  joint_of_.resize(specimens_.size());
  for (size_t s = 0; s < specimens_.size(); ++s) {
    const std::string& specimen = specimen_names_[s];
    if (specimens_[s]->options().loss != Loss::Squared)
      throw InputError("specimen \"" + specimen +
                       "\": a calibration over specimens fits squared distances; its "
                       "objective.loss is " +
                       to_string(specimens_[s]->options().loss));
    joint_of_[s].assign(static_cast<size_t>(specimens_[s]->parameters().size()), -1);
  }
  std::vector<Parameter> parameters;
  for (const std::string& name : shared) {
    const int first = parameter_in(0, name);
    for (size_t s = 0; s < specimens_.size(); ++s) {
      const int k = parameter_in(s, name);
      if (k < 0)
        throw InputError("specimen \"" + specimen_names_[s] + "\" does not fit \"" + name +
                         "\", which is shared: add it to the specimen's fit.parameters");
      const Parameter &p = specimens_[s]->parameters().parameters()[static_cast<size_t>(k)],
                      &q = specimens_[0]->parameters().parameters()[static_cast<size_t>(first)];
      if (p.lower != q.lower || p.upper != q.upper || p.log_scale != q.log_scale ||
          p.scale != q.scale)
        throw InputError("specimen \"" + specimen_names_[s] + "\": the shared \"" + name +
                         "\" has other bounds or another scale than in specimen \"" +
                         specimen_names_[0] + "\": a shared parameter is one variable");
      joint_of_[s][static_cast<size_t>(k)] = static_cast<int>(parameters.size());
    }
    parameters.push_back(specimens_[0]->parameters().parameters()[static_cast<size_t>(first)]);
    names_.push_back(name);
  }
  shared_ = static_cast<int>(parameters.size());
  for (size_t s = 0; s < specimens_.size(); ++s) {
    const std::vector<Parameter>& own = specimens_[s]->parameters().parameters();
    for (size_t k = 0; k < own.size(); ++k) {
      if (joint_of_[s][k] >= 0) continue;
      joint_of_[s][k] = static_cast<int>(parameters.size());
      parameters.push_back(own[k]);
      names_.push_back(specimen_names_[s] + "." + own[k].name);
    }
    residuals_ += specimens_[s]->num_residuals();
  }
  if (shared_ == static_cast<int>(parameters.size()) && shared.empty())
    throw InputError("shared: expected the names of the parameters the specimens share");
  variables_ = Variables(std::move(parameters));
}

bool JointCalibration::analytic_jacobian() const {
  return std::all_of(specimens_.begin(), specimens_.end(),
                     [](const Calibration* c) { return c->analytic_jacobian(); });
}

Eigen::VectorXd JointCalibration::specimen_phi(size_t s, const Eigen::VectorXd& phi) const {
  const std::vector<int>& joint = joint_of_[s];
  Eigen::VectorXd own(static_cast<Eigen::Index>(joint.size()));
  for (size_t k = 0; k < joint.size(); ++k) own[static_cast<Eigen::Index>(k)] = phi[joint[k]];
  return own;
}

std::string JointCalibration::specimen_evaluation(size_t s, const Eigen::VectorXd& phi,
                                                  bool with_jacobian) const {
  Evaluation e = specimens_[s]->evaluate(specimen_phi(s, phi), with_jacobian);
  e.summary = {};  // the residuals travel, not the run
  e.positions.clear();
  e.forces.clear();
  return pack_evaluation(e);
}

std::string JointCalibration::specimen_result(size_t s, const Eigen::VectorXd& phi) const {
  return pack_fit_result(specimens_[s]->result_at(specimen_phi(s, phi)));
}

namespace {

// The specimens' residual blocks stacked over the joint variables (each
// specimen's rows in turn, its Jacobian's columns at its variables' joint
// places), the specimens dealt out at every point: what the optimisers and
// the covariance of a single fit see.
class JointObjective final : public Objective {
 public:
  JointObjective(const JointCalibration& joint, const WorkDealer& deal, const Broadcast& broadcast)
      : joint_(joint), deal_(deal), broadcast_(broadcast) {}

  const Variables& variables() const override { return joint_.variables(); }
  int num_residuals() const override { return joint_.num_residuals(); }
  bool analytic_jacobian() const override { return joint_.analytic_jacobian(); }
  bool warm_starts() const override { return false; }

  Evaluation evaluate(const Eigen::VectorXd& phi, bool with_jacobian,
                      const Eigen::VectorXd&) const override {
    std::string command = command_bytes(Command::Evaluate, with_jacobian, phi);
    broadcast_(command);
    const size_t specimens = joint_.specimen_names().size();
    std::vector<Evaluation> parts(specimens);
    std::vector<char> arrived(specimens, 0);
    deal_(
        specimens, [&](size_t s) { return joint_.specimen_evaluation(s, phi, with_jacobian); },
        [&](size_t s, int, std::string&& bytes) {
          parts[s] = unpack_evaluation(bytes);
          arrived[s] = 1;
        });
    Evaluation joint;
    joint.ok = true;
    joint.residuals.resize(joint_.num_residuals());
    if (with_jacobian) joint.jacobian.setZero(joint_.num_residuals(), phi.size());
    Eigen::Index row = 0;
    for (size_t s = 0; s < parts.size(); ++s) {
      const Evaluation& e = parts[s];
      joint.forward_runs += e.forward_runs;
      joint.sensitivity_solves += e.sensitivity_solves;
      if (!arrived[s] || !e.ok) {
        if (joint.ok)
          joint.message = "specimen \"" + joint_.specimen_names()[s] +
                          "\": " + (arrived[s] ? e.message : std::string("interrupted"));
        joint.ok = false;
        continue;
      }
      const Eigen::Index rows = e.residuals.size();
      joint.residuals.segment(row, rows) = e.residuals;
      if (with_jacobian)
        for (Eigen::Index k = 0; k < e.jacobian.cols(); ++k)
          joint.jacobian.block(row, joint_.joint_index(s, static_cast<int>(k)), rows, 1) =
              e.jacobian.col(k);
      row += rows;
    }
    return joint;
  }

 private:
  const JointCalibration& joint_;
  const WorkDealer& deal_;
  const Broadcast& broadcast_;
};

// Sends Stop to the serving ranks when the fit ends, however it ends.
class StopsServers {
 public:
  explicit StopsServers(const Broadcast& broadcast) : broadcast_(broadcast) {}
  ~StopsServers() {
    std::string stop = command_bytes(Command::Stop, false, Eigen::VectorXd());
    broadcast_(stop);
  }
  StopsServers(const StopsServers&) = delete;
  StopsServers& operator=(const StopsServers&) = delete;

 private:
  const Broadcast& broadcast_;
};

// A single fit's options for the joint one: Levenberg-Marquardt on squared
// distances, bounded by iterations alone.
FitOptions single_fit_options(const JointOptions& joint) {
  FitOptions o;
  o.method = Method::LevenbergMarquardt;
  o.loss = Loss::Squared;
  o.max_iterations = joint.max_iterations;
  o.max_evaluations = std::numeric_limits<int>::max();
  o.function_tolerance = joint.function_tolerance;
  o.parameter_tolerance = joint.parameter_tolerance;
  o.max_step_factor = joint.max_step_factor;
  o.progress = joint.progress;
  return o;
}

}  // namespace

// The single fit's optimiser, covariance and estimate on the stacked
// objective; what is the joint fit's own is the dealing of the specimens
// and each specimen's report at the optimum.
JointFitResult JointCalibration::run(const WorkDealer& deal_given,
                                     const Broadcast& broadcast_given) const {
  const auto began = std::chrono::steady_clock::now();
  const WorkDealer deal = deal_given ? deal_given : WorkDealer(deal_in_order);
  const Broadcast broadcast = broadcast_given ? broadcast_given : Broadcast([](std::string&) {});
  const StopsServers stops(broadcast);
  const int P = variables_.size();
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const FitOptions options = single_fit_options(options_);
  // The estimate as a single fit describes it (bounds, errors, intervals).
  FitResult estimate;
  estimate.names = names_;
  estimate.initial = estimate.values = variables_.values(variables_.initial_phi());
  estimate.standard_errors = estimate.lower_95 = estimate.upper_95 =
      Eigen::VectorXd::Constant(P, nan);
  estimate.correlation = Eigen::MatrixXd::Constant(P, P, nan);
  JointFitResult result;
  result.names = names_;
  result.shared = shared_;
  result.residuals = residuals_;
  result.initial_cost = result.final_cost = nan;
  JointObjective objective(*this, deal, broadcast);
  EvaluationCache evaluations(objective);
  const auto finish = [&](FitStatus status, std::string message) {
    result.status = status;
    result.success = converged(status);
    if (!message.empty()) result.message = std::move(message);
    result.status_detail = estimate.status_detail;
    result.initial = estimate.initial;
    result.values = estimate.values;
    result.covariance_ok = estimate.covariance_ok;
    result.standard_errors = estimate.standard_errors;
    result.lower_95 = estimate.lower_95;
    result.upper_95 = estimate.upper_95;
    result.correlation = estimate.correlation;
    result.evaluations = evaluations.evaluations;
    result.seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - began).count();
    return result;
  };
  const Eigen::VectorXd start = variables_.initial_phi();
  const Evaluation& first = evaluations.at(start, true);
  if (!first.ok) {
    if (cancel_requested()) return finish(FitStatus::Interrupted, "interrupted at the start");
    return finish(FitStatus::StartFailed,
                  "the forward run at the starting parameters failed: " + first.message);
  }
  result.initial_cost = 0.5 * first.residuals.squaredNorm();

  const OptimizerOutcome outcome = fit_levenberg_marquardt(evaluations, options, start);
  result.message = outcome.message;
  result.iterations = outcome.iterations;
  estimate.values = variables_.values(outcome.phi);
  if (outcome.status != FitStatus::Converged) return finish(outcome.status, "");

  // At the optimum: the cost, the bounds, each specimen's run and distances
  // (dealt out too), then the covariance.
  const Evaluation best = evaluations.at(outcome.phi, true);  // a copy: entries move
  if (!best.ok)
    return finish(FitStatus::ForwardRunsFailed,
                  "the forward run at the fitted parameters failed: " + best.message);
  result.final_cost = 0.5 * best.residuals.squaredNorm();
  describe_bounds(variables_, outcome.phi, false, estimate);
  std::string describe = command_bytes(Command::Describe, false, outcome.phi);
  broadcast(describe);
  result.specimens.resize(specimens_.size());
  deal(
      specimens_.size(), [&](size_t s) { return specimen_result(s, outcome.phi); },
      [&](size_t s, int, std::string&& bytes) { result.specimens[s] = unpack_fit_result(bytes); });
  Eigen::MatrixXd covariance;
  estimate.covariance_ok = phi_covariance(evaluations, options, outcome.phi, &covariance);
  if (!estimate.covariance_ok) {
    estimate.status_detail = unidentifiable_because(best.jacobian, names_);
    return finish(FitStatus::NotIdentifiable, "");
  }
  const int dof = residuals_ - P;
  const double variance = dof > 0 ? 2.0 * result.final_cost / dof : 0.0;
  describe_estimates(variables_, outcome.phi, covariance, variance, estimate);
  return finish(estimate.at_bounds.empty() ? FitStatus::Converged : FitStatus::ConvergedAtBounds,
                "");
}

void JointCalibration::serve(const WorkDealer& deal, const Broadcast& broadcast) const {
  for (;;) {
    std::string bytes;
    broadcast(bytes);
    Command command = Command::Stop;
    bool with_jacobian = false;
    Eigen::VectorXd phi;
    ByteReader in(bytes);
    in(command, with_jacobian, phi);
    if (command == Command::Stop) return;
    deal(
        specimens_.size(),
        [&](size_t s) {
          return command == Command::Evaluate ? specimen_evaluation(s, phi, with_jacobian)
                                              : specimen_result(s, phi);
        },
        [](size_t, int, std::string&&) {});
  }
}

}  // namespace fiberfluid::fit

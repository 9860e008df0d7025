// SPDX-License-Identifier: GPL-3.0-or-later
#include "fiberfluid/fit/joint_calibration.hpp"

#include <ceres/ceres.h>

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <deque>
#include <set>

#include "fiberfluid/fit/fit_archive.hpp"
#include "fiberfluid/fit/lm_solver.hpp"
#include "fiberfluid/fit/optimizers.hpp"
#include "fiberfluid/util/byte_archive.hpp"
#include "fiberfluid/util/error.hpp"

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

double phi_of(const Parameter& p, double value) { return p.log_scale ? std::log(value) : value; }
double value_of(const Parameter& p, double phi) { return p.log_scale ? std::exp(phi) : phi; }

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
  for (const std::string& name : shared) {
    const int first = parameter_in(0, name);
    for (size_t s = 0; s < specimens_.size(); ++s) {
      const int k = parameter_in(s, name);
      if (k < 0)
        throw InputError("specimen \"" + specimen_names_[s] + "\" does not fit \"" + name +
                         "\", which is shared: add it to the specimen's fit.parameters");
      const Parameter &p = specimens_[s]->parameters().parameters()[static_cast<size_t>(k)],
                      &q = specimens_[0]->parameters().parameters()[static_cast<size_t>(first)];
      if (p.lower != q.lower || p.upper != q.upper || p.log_scale != q.log_scale)
        throw InputError("specimen \"" + specimen_names_[s] + "\": the shared \"" + name +
                         "\" has other bounds or another scale than in specimen \"" +
                         specimen_names_[0] + "\": a shared parameter is one variable");
      joint_of_[s][static_cast<size_t>(k)] = static_cast<int>(parameters_.size());
    }
    parameters_.push_back(specimens_[0]->parameters().parameters()[static_cast<size_t>(first)]);
    names_.push_back(name);
  }
  shared_ = static_cast<int>(parameters_.size());
  for (size_t s = 0; s < specimens_.size(); ++s) {
    const std::vector<Parameter>& own = specimens_[s]->parameters().parameters();
    for (size_t k = 0; k < own.size(); ++k) {
      if (joint_of_[s][k] >= 0) continue;
      joint_of_[s][k] = static_cast<int>(parameters_.size());
      parameters_.push_back(own[k]);
      names_.push_back(specimen_names_[s] + "." + own[k].name);
    }
    residuals_ += specimens_[s]->num_residuals();
  }
  if (shared_ == static_cast<int>(parameters_.size()) && shared.empty())
    throw InputError("shared: expected the names of the parameters the specimens share");
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

// The joint residuals (each specimen's in turn) and Jacobian at one point,
// the specimens dealt out. The last few points are kept: Ceres asks for a
// point's Jacobian after its residuals, and for the current point again
// after a rejected trial one.
class JointEvaluator {
 public:
  JointEvaluator(const JointCalibration& joint, const std::vector<const Calibration*>& specimens,
                 const WorkDealer& deal, const Broadcast& broadcast)
      : joint_(joint), specimens_(specimens), deal_(deal), broadcast_(broadcast) {}

  // False when a specimen's forward run failed (why in message()).
  bool at(const Eigen::VectorXd& phi, bool with_jacobian) {
    for (auto it = kept_.begin(); it != kept_.end(); ++it)
      if (it->phi == phi && (it->has_jacobian || !with_jacobian)) {
        std::rotate(kept_.begin(), it, std::next(it));
        return kept_.front().ok;
      }
    kept_.push_front(evaluate(phi, with_jacobian));
    if (kept_.size() > kKept) kept_.pop_back();
    if (!kept_.front().ok) last_failure_ = kept_.front().message;
    return kept_.front().ok;
  }
  const Eigen::VectorXd& residuals() const { return kept_.front().residuals; }
  const Eigen::MatrixXd& jacobian() const { return kept_.front().jacobian; }
  const std::string& message() const { return kept_.front().message; }
  // Why the last point whose run failed failed ("" if none did).
  const std::string& last_failure() const { return last_failure_; }
  int evaluations = 0, forward_runs = 0;

 private:
  struct Point {
    Eigen::VectorXd phi, residuals;
    Eigen::MatrixXd jacobian;
    bool has_jacobian = false, ok = true;
    std::string message;
  };
  static constexpr size_t kKept = 3;

  Point evaluate(const Eigen::VectorXd& phi, bool with_jacobian) {
    std::string command = command_bytes(Command::Evaluate, with_jacobian, phi);
    broadcast_(command);
    std::vector<Evaluation> parts(specimens_.size());
    std::vector<char> arrived(specimens_.size(), 0);
    deal_(
        specimens_.size(),
        [&](size_t s) { return joint_.specimen_evaluation(s, phi, with_jacobian); },
        [&](size_t s, int, std::string&& bytes) {
          parts[s] = unpack_evaluation(bytes);
          arrived[s] = 1;
        });
    ++evaluations;
    Point point;
    point.phi = phi;
    point.has_jacobian = with_jacobian;
    point.residuals.resize(joint_.num_residuals());
    point.jacobian.setZero(joint_.num_residuals(), phi.size());
    Eigen::Index row = 0;
    for (size_t s = 0; s < parts.size(); ++s) {
      const Evaluation& e = parts[s];
      forward_runs += e.forward_runs;
      if (!arrived[s] || !e.ok) {
        point.ok = false;
        if (point.message.empty())
          point.message = "specimen \"" + joint_.specimen_names()[s] +
                          "\": " + (arrived[s] ? e.message : std::string("interrupted"));
        continue;
      }
      const Eigen::Index rows = e.residuals.size();
      point.residuals.segment(row, rows) = e.residuals;
      if (with_jacobian)
        for (Eigen::Index k = 0; k < e.jacobian.cols(); ++k)
          point.jacobian.block(row, joint_.joint_index(s, static_cast<int>(k)), rows, 1) =
              e.jacobian.col(k);
      row += rows;
    }
    return point;
  }

  const JointCalibration& joint_;
  const std::vector<const Calibration*>& specimens_;
  const WorkDealer& deal_;
  const Broadcast& broadcast_;
  std::deque<Point> kept_;
  std::string last_failure_;
};

// The whole joint residual as one Ceres block over all the variables.
class JointCost final : public ceres::CostFunction {
 public:
  JointCost(JointEvaluator& evaluator, int residuals, int variables) : evaluator_(evaluator) {
    set_num_residuals(residuals);
    mutable_parameter_block_sizes()->push_back(variables);
  }
  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override {
    const Eigen::Map<const Eigen::VectorXd> phi(parameters[0], parameter_block_sizes()[0]);
    const bool with_jacobian = jacobians != nullptr && jacobians[0] != nullptr;
    if (!evaluator_.at(phi, with_jacobian)) return false;
    Eigen::Map<Eigen::VectorXd>(residuals, num_residuals()) = evaluator_.residuals();
    if (with_jacobian)  // Ceres' blocks are row-major
      Eigen::Map<Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>>(
          jacobians[0], num_residuals(), parameter_block_sizes()[0]) = evaluator_.jacobian();
    return true;
  }

 private:
  JointEvaluator& evaluator_;
};

class JointRecorder final : public ceres::IterationCallback {
 public:
  JointRecorder(const std::vector<Parameter>& parameters, const Eigen::VectorXd& phi,
                const JointEvaluator& evaluator, const JointOptions& options,
                std::vector<IterationRecord>& iterations)
      : parameters_(parameters),
        phi_(phi),
        evaluator_(evaluator),
        options_(options),
        iterations_(iterations),
        start_(std::chrono::steady_clock::now()) {}
  ceres::CallbackReturnType operator()(const ceres::IterationSummary& s) override {
    IterationRecord r = lm_iteration(s.iteration, s.step_is_successful, s.cost, iterations_);
    r.values.resize(phi_.size());
    for (Eigen::Index k = 0; k < phi_.size(); ++k)
      r.values[k] = value_of(parameters_[static_cast<size_t>(k)], phi_[k]);
    r.forward_runs = evaluator_.forward_runs;
    r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
    iterations_.push_back(r);
    if (options_.progress) options_.progress(r);
    return cancel_requested() ? ceres::SOLVER_ABORT : ceres::SOLVER_CONTINUE;
  }

 private:
  const std::vector<Parameter>& parameters_;
  const Eigen::VectorXd& phi_;
  const JointEvaluator& evaluator_;
  const JointOptions& options_;
  std::vector<IterationRecord>& iterations_;
  std::chrono::steady_clock::time_point start_;
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

}  // namespace

JointFitResult JointCalibration::run(const WorkDealer& deal_given,
                                     const Broadcast& broadcast_given) const {
  const auto began = std::chrono::steady_clock::now();
  const WorkDealer deal = deal_given ? deal_given : WorkDealer(deal_in_order);
  const Broadcast broadcast = broadcast_given ? broadcast_given : Broadcast([](std::string&) {});
  const StopsServers stops(broadcast);
  const int P = static_cast<int>(parameters_.size());
  const double nan = std::numeric_limits<double>::quiet_NaN();
  JointFitResult result;
  result.names = names_;
  result.shared = shared_;
  result.residuals = residuals_;
  Eigen::VectorXd phi(P), lower(P), upper(P);
  for (int k = 0; k < P; ++k) {
    const Parameter& p = parameters_[static_cast<size_t>(k)];
    phi[k] = phi_of(p, p.initial);
    lower[k] = std::isfinite(p.lower) ? phi_of(p, p.lower) : -INFINITY;
    upper[k] = std::isfinite(p.upper) ? phi_of(p, p.upper) : INFINITY;
  }
  const auto values = [&](const Eigen::VectorXd& at) {
    Eigen::VectorXd v(P);
    for (int k = 0; k < P; ++k) v[k] = value_of(parameters_[static_cast<size_t>(k)], at[k]);
    return v;
  };
  result.initial = result.values = values(phi);
  result.standard_errors = result.lower_95 = result.upper_95 = Eigen::VectorXd::Constant(P, nan);
  result.correlation = Eigen::MatrixXd::Constant(P, P, nan);
  result.initial_cost = result.final_cost = nan;
  JointEvaluator evaluator(*this, specimens_, deal, broadcast);
  const auto finish = [&](FitStatus status, std::string message) {
    result.status = status;
    result.success = converged(status);
    if (!message.empty()) result.message = std::move(message);
    result.evaluations = evaluator.evaluations;
    result.seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - began).count();
    return result;
  };
  if (!evaluator.at(phi, true)) {
    if (cancel_requested()) return finish(FitStatus::Interrupted, "interrupted at the start");
    return finish(FitStatus::StartFailed,
                  "the forward run at the starting parameters failed: " + evaluator.message());
  }
  result.initial_cost = 0.5 * evaluator.residuals().squaredNorm();

  ceres::Problem problem;
  problem.AddResidualBlock(new JointCost(evaluator, residuals_, P), nullptr, phi.data());
  JointRecorder recorder(parameters_, phi, evaluator, options_, result.iterations);
  LmSteps steps;
  steps.max_iterations = options_.max_iterations;
  steps.function_tolerance = options_.function_tolerance;
  steps.parameter_tolerance = options_.parameter_tolerance;
  steps.max_step_factor = options_.max_step_factor;
  const ceres::Solver::Summary summary =
      solve_in_moving_box(problem, phi.data(), parameters_, lower, upper, steps, &recorder);
  result.message = "levenberg-marquardt: " + summary.message;
  result.values = values(phi);
  if (cancel_requested()) return finish(FitStatus::Interrupted, "");
  if (summary.termination_type == ceres::NO_CONVERGENCE)
    return finish(FitStatus::IterationLimit, "");
  if (summary.termination_type != ceres::CONVERGENCE)
    return finish(evaluator.last_failure().empty() ? FitStatus::OptimizerFailed
                                                   : FitStatus::ForwardRunsFailed,
                  "");

  // At the optimum: the covariance of phi from the Jacobian, (J^T J)^-1.
  if (!evaluator.at(phi, true))
    return finish(FitStatus::ForwardRunsFailed,
                  "the forward run at the fitted parameters failed: " + evaluator.message());
  result.final_cost = 0.5 * evaluator.residuals().squaredNorm();
  const Eigen::MatrixXd& J = evaluator.jacobian();
  const Eigen::MatrixXd normal = J.transpose() * J;
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eigen(normal);
  const double largest = eigen.eigenvalues().cwiseAbs().maxCoeff();
  result.covariance_ok = largest > 0.0 && eigen.eigenvalues().minCoeff() > 1e-12 * largest;
  std::vector<std::string> at_bounds;
  for (int k = 0; k < P; ++k)
    if (on_bound(phi[k], lower[k], upper[k])) {
      at_bounds.push_back(names_[static_cast<size_t>(k)]);
      result.status_detail += (result.status_detail.empty() ? "" : "; ") +
                              names_[static_cast<size_t>(k)] + " is on a bound";
    }
  // Each specimen's run and distances at the optimum, dealt out too.
  std::string describe = command_bytes(Command::Describe, false, phi);
  broadcast(describe);
  result.specimens.resize(specimens_.size());
  deal(
      specimens_.size(), [&](size_t s) { return specimen_result(s, phi); },
      [&](size_t s, int, std::string&& bytes) { result.specimens[s] = unpack_fit_result(bytes); });
  if (!result.covariance_ok) {
    result.status_detail =
        "J^T J at the optimum is singular: the specimens' distances cannot "
        "tell the parameters apart";
    return finish(FitStatus::NotIdentifiable, "");
  }
  const Eigen::MatrixXd covariance = eigen.eigenvectors() *
                                     eigen.eigenvalues().cwiseInverse().asDiagonal() *
                                     eigen.eigenvectors().transpose();
  const int dof = residuals_ - P;
  const double variance = dof > 0 ? 2.0 * result.final_cost / dof : 0.0;
  for (int k = 0; k < P; ++k) {
    for (int j = 0; j < P; ++j)
      result.correlation(k, j) = covariance(k, j) / std::sqrt(covariance(k, k) * covariance(j, j));
    if (on_bound(phi[k], lower[k], upper[k])) continue;  // a bound is no estimate
    const double sigma = std::sqrt(std::max(0.0, variance * covariance(k, k)));
    const bool log = parameters_[static_cast<size_t>(k)].log_scale;
    result.standard_errors[k] = log ? result.values[k] * sigma : sigma;
    result.lower_95[k] = value_of(parameters_[static_cast<size_t>(k)], phi[k] - 1.96 * sigma);
    result.upper_95[k] = value_of(parameters_[static_cast<size_t>(k)], phi[k] + 1.96 * sigma);
  }
  return finish(at_bounds.empty() ? FitStatus::Converged : FitStatus::ConvergedAtBounds, "");
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

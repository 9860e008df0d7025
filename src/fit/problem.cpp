// SPDX-License-Identifier: GPL-3.0-or-later
#include "fiberfluid/fit/problem.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <stdexcept>

#include "fiberfluid/fit/residuals/blocks.hpp"
#include "fiberfluid/solve/newton/newton.hpp"
#include "fiberfluid/util/error.hpp"

namespace fiberfluid::fit {

Eigen::Matrix<double, 3, Eigen::Dynamic> ForwardRun::vertex_sensitivity(const Eigen::MatrixXd& S,
                                                                        int vertex) const {
  const int nv = model.num_vertices();
  Eigen::Matrix<double, 3, Eigen::Dynamic> dx = Eigen::MatrixXd::Zero(3, map.size());
  for (size_t j = 0; j < map.material_indices().size(); ++j) {
    const int k = map.material_indices()[j];
    for (int a = 0; a < 3; ++a)
      dx(a, k) = S(a * nv + vertex, static_cast<Eigen::Index>(j)) * dvalue[k];
  }
  return dx;
}

FitProblem::FitProblem(model::Model model, solve::SteppingOptions stepping,
                       std::vector<MeasuredStep> targets, std::vector<Parameter> parameters,
                       FitOptions options, std::vector<ForceCurve> force_curves,
                       std::vector<BlockMaker> more_blocks)
    : model_(std::move(model)),
      stepping_(std::move(stepping)),
      curves_(std::move(force_curves)),
      map_(std::move(parameters), model_.material, model_.dim()),
      options_(std::move(options)) {
  check_options(options_);
  if (model_.dim() != 3) throw InputError("calibration fits 3D surfaces; this model is 2D");
  if (targets.empty() && curves_.empty() && more_blocks.empty())
    throw InputError(
        "nothing to fit to: no target surface and no force curve (nor another target)");
  for (const std::string& name : map_.material_names())
    if (name == "friction" && !model_.has_coulomb_paddle())
      throw InputError(
          "parameter \"friction\": no paddle has \"contact\": \"coulomb\", so no run "
          "would feel it");
  const int n = model_.num_vertices();
  if (options_.counted_vertices.empty()) {
    for (int i = 0; i < n; ++i) counted_.push_back(i);
  } else {
    counted_ = options_.counted_vertices;
    std::sort(counted_.begin(), counted_.end());
    counted_.erase(std::unique(counted_.begin(), counted_.end()), counted_.end());
    if (counted_.front() < 0 || counted_.back() >= n)
      throw InputError("counted vertices: vertex " +
                       std::to_string(counted_.front() < 0 ? counted_.front() : counted_.back()) +
                       " does not exist (the model has " + std::to_string(n) + ")");
  }
  const Eigen::MatrixXd& V = model_.surface.V;
  length_ = (V.colwise().maxCoeff() - V.colwise().minCoeff()).maxCoeff();

  // The blocks, in row order: each scan's distances, then each curve's misfits.
  for (size_t t = 0; t < targets.size(); ++t)
    blocks_.push_back(std::make_unique<ScanDistances>(targets[t], t, model_, stepping_.steps,
                                                      counted_, options_.symmetric, length_));
  for (size_t c = 0; c < curves_.size(); ++c) {
    auto block =
        std::make_unique<ForceCurveMisfits>(curves_[c], c, model_, stepping_.steps, length_);
    curve_weights_.push_back(block->weight());
    blocks_.push_back(std::move(block));
  }
  for (const BlockMaker& make : more_blocks)
    blocks_.push_back(make(BlockContext{model_, stepping_.steps, length_}));
  for (const auto& block : blocks_) {
    residuals_ += block->rows();
    for (int k : block->steps()) state_steps_.push_back(k);
  }
  std::sort(state_steps_.begin(), state_steps_.end());
  state_steps_.erase(std::unique(state_steps_.begin(), state_steps_.end()), state_steps_.end());

  analytic_ = !options_.finite_differences && stepping_.scheme == solve::Scheme::Newton &&
              solve::check_sensitivities(model_).ok;
  if (residuals_ < map_.size())
    throw InputError("fewer distances (" + std::to_string(residuals_) + ") than parameters (" +
                     std::to_string(map_.size()) + ")");
  stepping_.keep_final_tangent = false;
  {
    solve::SteppingOptions probe = stepping_;  // any start of the right size
    probe.warm_start = Eigen::VectorXd::Zero(model_.dim() * model_.num_vertices() + 1);
    warm_starts_ = options_.warm_start && stepping_.scheme == solve::Scheme::Newton &&
                   state_steps_ == std::vector<int>{stepping_.steps} &&
                   solve::check_warm_start(model_, probe).ok;
  }
  // The material with the starts, so that model() shows what the fit begins from.
  model_.material = map_.material(model_.material, map_.values(map_.initial_phi()));
  if (const Status law = model_.material.law.check(); !law.ok)
    throw InputError("the starting material: " + law.message);
}

FitProblem::~FitProblem() = default;

double FitProblem::cost(const Eigen::VectorXd& r) const {
  const double d = options_.loss_scale, d2 = d * d;
  double sum = 0.0;
  for (Eigen::Index i = 0; i < r.size(); ++i) {
    const double s = r[i] * r[i];
    switch (options_.loss) {
      case Loss::Squared:
        sum += s;
        break;
      case Loss::Huber:
        sum += s <= d2 ? s : 2.0 * d * std::sqrt(s) - d2;
        break;  // Ceres' HuberLoss
      case Loss::Cauchy:
        sum += d2 * std::log1p(s / d2);
        break;  // Ceres' CauchyLoss
    }
  }
  return 0.5 * sum;
}

namespace {

// The record of step k in a run (a warm-started run holds its last step only).
const solve::StepRecord& record_of(const solve::SteppingSummary& summary, int k) {
  for (const solve::StepRecord& record : summary.steps)
    if (record.step == k) return record;
  throw std::logic_error("calibration: the run has no record of step " + std::to_string(k));
}

}  // namespace

Evaluation FitProblem::evaluate(const Eigen::VectorXd& phi, bool with_jacobian,
                                const Eigen::VectorXd& warm_start) const {
  solve::SteppingOptions stepping = stepping_;
  if (warm_starts_) stepping.warm_start = warm_start;
  return evaluate(phi, with_jacobian, std::move(stepping), false);
}

solve::SteppingSummary FitProblem::run_forward(const model::Model& model,
                                               const solve::SteppingOptions& options,
                                               std::map<int, StepState>& at,
                                               std::map<int, Eigen::VectorXd>* path_states) const {
  return solve::solve_load_steps(
      model, options, [&](const solve::StepRecord& r, const Eigen::VectorXd& x) {
        if (path_states && near_a_halving(r.step, options.steps)) (*path_states)[r.step] = x;
        if (!std::binary_search(state_steps_.begin(), state_steps_.end(), r.step)) return;
        StepState& state = at[r.step];
        state.x = x;
        for (const auto& block : blocks_) state.observed.push_back(block->observe(model, r));
      });
}

Evaluation FitProblem::evaluate(const Eigen::VectorXd& phi, bool with_jacobian,
                                solve::SteppingOptions stepping, bool keep_path_states) const {
  const ParameterMap& map = map_;
  const size_t nb = blocks_.size();
  Evaluation e;
  const Eigen::VectorXd values = map.values(phi);
  model::Model changed = model_;
  changed.material = map.material(model_.material, values);
  if (const Status law = changed.material.law.check(); !law.ok) {
    e.message = "the material at these parameters: " + law.message;
    return e;
  }
  // Sensitivities du/dtheta of the states at the steps read: from the
  // Newton stepper, or central differences of whole runs in phi.
  const bool sensitivities_wanted = with_jacobian && !map.material_names().empty();
  if (sensitivities_wanted && analytic_)
    stepping.sensitivities = {map.material_names(), state_steps_};
  std::map<int, StepState> states;
  if (state_steps_.empty()) {
    // No target reads the body (material tests alone): its run would go unread.
    e.summary.success = true;
  } else {
    e.summary = run_forward(changed, stepping, states, keep_path_states ? &e.path_states : nullptr);
    e.forward_runs = 1;
  }
  e.warm_started_runs = e.summary.warm_started ? 1 : 0;
  if (!e.summary.success) {
    e.message = e.summary.message;
    return e;
  }
  e.path_states.clear();  // only a failed probe's are wanted
  ForwardRun run{changed, map, values, map.value_derivatives(phi), with_jacobian, {}, {}};
  const int nm = static_cast<int>(map.material_names().size());
  // Per block, per step read: what the block observed and its derivatives.
  std::vector<std::map<int, StepReadings>> readings(nb);
  for (const auto& [step, state] : states) {
    run.states[step] = state.x;
    for (size_t b = 0; b < nb; ++b) readings[b][step].observed = state.observed[b];
  }
  if (sensitivities_wanted && analytic_) {
    for (int step : state_steps_) {
      const solve::StepRecord& record = record_of(e.summary, step);
      run.sensitivities[step] = record.sensitivities.state;
      e.sensitivity_solves += static_cast<int>(record.sensitivities.state.cols());
      for (size_t b = 0; b < nb; ++b)
        readings[b][step].sensitivities = blocks_[b]->observed_sensitivities(changed, record, nm);
    }
  } else if (sensitivities_wanted && !state_steps_.empty()) {
    e.message = central_differences(phi, states, run, readings,
                                    keep_path_states ? &e.path_states : nullptr, e);
    if (!e.message.empty()) return e;
  }
  e.residuals.resize(residuals_);
  if (with_jacobian) e.jacobian = Eigen::MatrixXd::Zero(residuals_, map.size());
  Eigen::Index row = 0;
  for (size_t b = 0; b < nb; ++b) {
    e.message = blocks_[b]->evaluate(run, readings[b], row, e);
    if (!e.message.empty()) return e;
    row += blocks_[b]->rows();
  }
  e.ok = e.residuals.allFinite() && (!with_jacobian || e.jacobian.allFinite());
  if (!e.ok) e.message = "non-finite distances or forces";
  return e;
}

std::string FitProblem::central_differences(const Eigen::VectorXd& phi,
                                            const std::map<int, StepState>& states, ForwardRun& run,
                                            std::vector<std::map<int, StepReadings>>& readings,
                                            std::map<int, Eigen::VectorXd>* path_states,
                                            Evaluation& e) const {
  const ParameterMap& map = map_;
  const size_t nb = blocks_.size();
  const int nm = static_cast<int>(map.material_names().size());
  for (int step : state_steps_) {
    run.sensitivities[step].resize(states.at(step).x.size(), nm);
    for (size_t b = 0; b < nb; ++b)
      readings[b][step].sensitivities.resize(
          static_cast<Eigen::Index>(states.at(step).observed[b].size()), nm);
  }
  for (int j = 0; j < nm; ++j) {
    const int k = map.material_indices()[static_cast<size_t>(j)];
    const double h = options_.difference_step * std::max(1.0, std::abs(phi[k]));
    std::map<int, StepState> plus, minus;
    for (double sign : {1.0, -1.0}) {
      Eigen::VectorXd shifted = phi;
      shifted[k] += sign * h;
      model::Model moved = model_;
      moved.material = map.material(model_.material, map.values(shifted));
      solve::SteppingOptions shifted_stepping = stepping_;
      if (warm_starts_) shifted_stepping.warm_start = e.summary.unknowns;  // phi's, next door
      const solve::SteppingSummary s =
          run_forward(moved, shifted_stepping, sign > 0 ? plus : minus, path_states);
      ++e.forward_runs;
      e.warm_started_runs += s.warm_started ? 1 : 0;
      if (!s.success) return "a finite-difference run failed: " + s.message;
    }
    for (int step : state_steps_) {  // du/dtheta, as the stepper gives it
      const double denominator = 2.0 * h * run.dvalue[k];
      run.sensitivities[step].col(j) = (plus.at(step).x - minus.at(step).x) / denominator;
      for (size_t b = 0; b < nb; ++b) {
        Eigen::MatrixXd& d = readings[b][step].sensitivities;
        for (Eigen::Index i = 0; i < d.rows(); ++i)
          d(i, j) = (plus.at(step).observed[b][static_cast<size_t>(i)] -
                     minus.at(step).observed[b][static_cast<size_t>(i)]) /
                    denominator;
      }
    }
  }
  return "";
}

void FitProblem::describe(const Evaluation& best, FitResult& result) const {
  result.final_cost = cost(best.residuals);
  result.summary = best.summary;
  result.positions = best.positions;
  result.vertex_distances.clear();  // described afresh (a warm start's check describes twice)
  result.statistics.clear();
  result.force_misfits.clear();
  result.other_targets.clear();
  Eigen::Index row = 0;
  for (const auto& block : blocks_) {
    block->describe(best, row, result);
    row += block->rows();
  }
  // Every counted vertex's distance, scan by scan in vertex order (as the rows stand).
  std::vector<double> all;
  for (const Eigen::VectorXd& distances : result.vertex_distances)
    for (const int i : counted_) all.push_back(distances[i]);
  result.overall = distance_statistics(
      Eigen::Map<const Eigen::VectorXd>(all.data(), static_cast<Eigen::Index>(all.size())),
      length_);
}

}  // namespace fiberfluid::fit

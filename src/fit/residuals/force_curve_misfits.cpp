// SPDX-License-Identifier: GPL-3.0-or-later
// A force curve's misfits: each row placed between the run's steps by its
// travel, the force read from the paddle's or the support's record, its
// derivatives from the record's force sensitivities.
#include <algorithm>
#include <cmath>
#include <sstream>

#include "fiberfluid/fit/force_misfit.hpp"
#include "fiberfluid/fit/residuals/blocks.hpp"
#include "fiberfluid/util/error.hpp"

namespace fiberfluid::fit {
namespace {

// The force a curve reads from a step's record: its paddle's or its
// support group's (before the curve's sign convention).
Eigen::Vector3d curve_force_vector(const ForceCurve& curve, const solve::StepRecord& record) {
  const size_t i = static_cast<size_t>(curve.index);
  if (curve.source == ForceCurve::Source::Paddle)
    return i < record.paddles.size() ? record.paddles[i].force : Eigen::Vector3d::Zero();
  return i < record.reactions.size() ? record.reactions[i] : Eigen::Vector3d::Zero();
}

const ForceCurve& checked(const ForceCurve& curve, const model::Model& model) {
  if (const Status usable = check_force_curve(curve, model); !usable.ok)
    throw InputError(curve.label + ": " + usable.message);
  return curve;
}

}  // namespace

ForceCurveMisfits::ForceCurveMisfits(const ForceCurve& curve, size_t index,
                                     const model::Model& model, int steps, double length)
    : curve_(checked(curve, model)), index_(index), rows_(plan(model, steps)) {
  const double largest = largest_measured(curve_);
  if (curve_.weight == 0.0 && largest == 0.0)
    throw InputError(curve_.label +
                     ": every measured force is 0: give the curve a weight (m per N)");
  weight_ = curve_.weight > 0.0 ? curve_.weight : length / largest;
  row_weights_ = row_weights(curve_, weight_);
}

// The rows: where each reads the run. Throws InputError naming the curve for
// a step outside the run, a travel the run does not reach, or a travel that
// does not change with every step.
std::vector<ForceCurveMisfits::Row> ForceCurveMisfits::plan(const model::Model& model,
                                                            int steps) const {
  const ForceCurve& curve = curve_;
  std::vector<Row> rows;
  if (curve.by_step) {
    for (size_t r = 0; r < curve.at.size(); ++r) {
      const double k = curve.at[r];
      if (!(k >= 1 && k <= steps && k == std::floor(k))) {
        std::ostringstream why;
        why << curve.label << ": row " << r + 1 << ": step " << k
            << " is not one of the run's steps 1.." << steps;
        throw InputError(why.str());
      }
      rows.push_back({static_cast<int>(k), static_cast<int>(k), 0.0});
    }
    return rows;
  }
  std::vector<double> travel(static_cast<size_t>(steps) + 1);
  for (int k = 0; k <= steps; ++k)
    travel[static_cast<size_t>(k)] = curve_travel(curve, model, k, steps);
  const double direction = travel[1] > travel[0] ? 1.0 : -1.0;  // as the first step goes
  for (int k = 1; k <= steps; ++k) {
    const double change = travel[static_cast<size_t>(k)] - travel[static_cast<size_t>(k) - 1];
    if (!(direction * change > 0.0)) {
      std::ostringstream why;
      why << curve.label << ": the travel does not move on with every step (step " << k << ": from "
          << travel[static_cast<size_t>(k) - 1] << " to " << travel[static_cast<size_t>(k)]
          << " m): rows cannot be placed by travel; tie them to steps (a step column)";
      throw InputError(why.str());
    }
  }
  for (size_t r = 0; r < curve.at.size(); ++r) {
    const double t = curve.at[r];
    int k = 0;
    while (k < steps && direction * (t - travel[static_cast<size_t>(k) + 1]) > 0.0) ++k;
    if (k == steps || direction * (t - travel[static_cast<size_t>(k)]) < 0.0) {
      std::ostringstream why;
      why << curve.label << ": row " << r + 1 << ": travel " << t
          << " m is outside the run's, from " << travel.front() << " to " << travel.back() << " m";
      throw InputError(why.str());
    }
    const double low = travel[static_cast<size_t>(k)], high = travel[static_cast<size_t>(k) + 1];
    rows.push_back({k, k + 1, (t - low) / (high - low)});
  }
  return rows;
}

std::vector<int> ForceCurveMisfits::steps() const {
  std::vector<int> steps;
  for (const Row& row : rows_)
    for (int k : {row.k0, row.k1})
      if (k >= 1) steps.push_back(k);
  std::sort(steps.begin(), steps.end());
  steps.erase(std::unique(steps.begin(), steps.end()), steps.end());
  return steps;
}

std::vector<double> ForceCurveMisfits::observe(const model::Model& model,
                                               const solve::StepRecord& record) const {
  return {curve_force(curve_, model, curve_force_vector(curve_, record))};
}

Eigen::MatrixXd ForceCurveMisfits::observed_sensitivities(const model::Model& model,
                                                          const solve::StepRecord& record,
                                                          int material_parameters) const {
  const size_t i = static_cast<size_t>(curve_.index);
  const Eigen::MatrixXd& d = curve_.source == ForceCurve::Source::Paddle
                                 ? record.sensitivities.paddle_forces[i]
                                 : record.sensitivities.reactions[i];
  Eigen::MatrixXd row(1, material_parameters);
  for (int j = 0; j < material_parameters; ++j) {
    Eigen::Vector3d column = d.col(j);
    row(0, j) = curve_force(curve_, model, column);
  }
  return row;
}

std::string ForceCurveMisfits::evaluate(const ForwardRun& run,
                                        const std::map<int, StepReadings>& readings,
                                        Eigen::Index row, Evaluation& e) const {
  const ParameterMap& map = run.map;
  const int nm = static_cast<int>(map.material_names().size());
  if (e.forces.size() <= index_) e.forces.resize(index_ + 1);
  std::vector<double>& forces = e.forces[index_];
  forces.clear();
  for (size_t r = 0; r < curve_.force.size(); ++r, ++row) {
    const Row& at = rows_[r];
    double force = 0.0;
    Eigen::RowVectorXd gradient = Eigen::RowVectorXd::Zero(nm);
    for (const auto& [k, share] : {std::pair{at.k0, 1.0 - at.s}, std::pair{at.k1, at.s}}) {
      if (k == 0 || share == 0.0) continue;  // the unloaded reference: no force
      const StepReadings& reading = readings.at(k);
      force += share * reading.observed[0];
      if (run.with_jacobian && nm > 0) gradient += share * reading.sensitivities.row(0);
    }
    forces.push_back(force);
    e.residuals[row] = row_weights_[r] * (force - curve_.force[r]);
    if (!run.with_jacobian) continue;
    for (int j = 0; j < nm; ++j) {
      const int k = map.material_indices()[static_cast<size_t>(j)];
      e.jacobian(row, k) = row_weights_[r] * gradient[j] * run.dvalue[k];
    }
  }
  return "";
}

void ForceCurveMisfits::describe(const Evaluation& e, Eigen::Index, FitResult& result) const {
  if (result.force_misfits.size() <= index_) result.force_misfits.resize(index_ + 1);
  result.force_misfits[index_] = force_misfit(curve_, e.forces.at(index_), weight_);
}

}  // namespace fiberfluid::fit

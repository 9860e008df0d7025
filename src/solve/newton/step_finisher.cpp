// SPDX-License-Identifier: GPL-3.0-or-later
#include "fiberfluid/solve/newton/step_finisher.hpp"

#include <algorithm>
#include <limits>
#include <sstream>
#include <string>

#include "fiberfluid/geom/area_vectors.hpp"
#include "fiberfluid/model/assembly.hpp"
#include "fiberfluid/model/dof_map.hpp"
#include "fiberfluid/solve/stepping_common.hpp"

namespace fiberfluid::solve {
namespace {

bool partition_holds(const model::DofPartition& partition, int dof) {
  return std::binary_search(partition.constrained.begin(), partition.constrained.end(), dof);
}

}  // namespace

StepFinisher::StepFinisher(const model::Model& model, const SteppingOptions& options,
                           NewtonSolver& solver, const model::DofPartition& partition,
                           SteppingSummary& summary)
    : model_(model),
      options_(options),
      solver_(solver),
      partition_(partition),
      summary_(summary),
      reference_volume_(solver.equilibrium().reference_volume()),
      last_face_areas_(geom::face_area_vectors(model.surface.V, model.surface.F)),
      groups_(std::max<size_t>(1, model.constraint_groups.size())) {
  const auto gauge = std::find(model.constraint_groups.begin(), model.constraint_groups.end(),
                               std::string("gauge"));
  if (gauge != model.constraint_groups.end())
    gauge_group_ = static_cast<int>(gauge - model.constraint_groups.begin());
}

void StepFinisher::compare_with(const Eigen::VectorXd& x) {
  last_face_areas_ = geom::face_area_vectors(model::positions(model_, x), model_.surface.F);
}

std::string StepFinisher::finish(const LoadPoint& at, const Eigen::VectorXd& x,
                                 StepRecord& record) {
  const int nv = model_.num_vertices(), dim = model_.dim(), k = record.step;
  const Eigen::MatrixXd X = model::positions(model_, x);
  const double volume = geom::enclosed_volume(X, model_.surface.F);
  if (const Status state =
          check_no_runaway(model_, options_, x, X, volume, reference_volume_, last_face_areas_);
      !state.ok)
    return "step " + std::to_string(k) + ": runaway: " + state.message;

  // Forces on the body: supports per group, paddles, and the loads.
  const Eigen::VectorXd& R = solver_.last_residual();
  const Eigen::VectorXd F = solver_.equilibrium().external_forces(x, at.factors);
  record.reactions.assign(groups_, Eigen::Vector3d::Zero());
  summary_.reaction_forces = Eigen::MatrixXd::Zero(nv, dim);
  for (size_t c = 0; c < partition_.constrained.size(); ++c) {
    const int d = partition_.constrained[c];
    const model::Constraint& constraint =
        model_.constraints[static_cast<size_t>(partition_.constraint_of[c])];
    record.reactions[static_cast<size_t>(constraint.group) % groups_][d / nv] += R[d];
    summary_.reaction_forces(d % nv, d / nv) = R[d];
  }
  // A clamp's mirror layer holds the body through its fibers, not its rows.
  const std::vector<Eigen::Vector3d> layers = solver_.equilibrium().support_forces(x);
  for (size_t g = 0; g < layers.size(); ++g) record.reactions[g % groups_] += layers[g];
  // A gauge holds a rotation that nothing else holds, and is free of force
  // only where the loads do not turn the body about it. The set-up checks the
  // loads at their full factors on the rest shape; at this step's factors
  // and shape they may (two loads that cancel only at the last step, an
  // anisotropic body): a gauge that carries a force means no equilibrium.
  if (gauge_group_ >= 0) {
    const double carried = record.reactions[static_cast<size_t>(gauge_group_)].norm();
    const double scale = F.lpNorm<1>() + R.head(static_cast<Eigen::Index>(dim) * nv).lpNorm<1>();
    if (carried > 1e-6 * scale) {
      std::ostringstream why;
      why << "step " << k << ": the gauge (group \"gauge\") carries " << carried << " N, "
          << carried / scale
          << " of the forces on the body: the loads turn it about the rotation the supports "
             "leave free, so there is no equilibrium without a support that holds it (hold a "
             "vertex away from the axis, or make the paddles \"sticking\")";
      return why.str();
    }
  }
  record.paddles.resize(model_.paddles.size());
  for (size_t p = 0; p < model_.paddles.size(); ++p) {
    record.paddles[p].plane = at.planes[p];
    record.paddles[p].travel = at.planes[p] - model_.paddles[p].position;
  }
  const model::DofMap held = solver_.held_map();
  for (int v = 0; v < nv; ++v) {
    const int p = solver_.contact_paddle()[static_cast<size_t>(v)];
    if (p < 0) continue;
    StepRecord::PaddleState& state = record.paddles[static_cast<size_t>(p)];
    ++state.contacts;
    // A sliding vertex's tangential force is its friction, not a held row's.
    const Eigen::Vector3d friction = solver_.friction_force(v);
    if (solver_.sliding(v)) ++state.sliding;
    for (int a = 0; a < dim; ++a)
      if (held.held(a * nv + v) && !partition_holds(partition_, a * nv + v)) {
        state.force[a] += R[a * nv + v];
        summary_.reaction_forces(v, a) = R[a * nv + v];
      } else if (friction[a] != 0.0) {
        state.force[a] += friction[a];
        summary_.reaction_forces(v, a) = friction[a];
      }
  }
  for (int a = 0; a < dim; ++a) record.applied_force[a] = F.segment(a * nv, nv).sum();
  for (int v = 0; v < nv; ++v) {
    bool any = false;
    for (int a = 0; a < dim; ++a) any = any || held.held(a * nv + v);
    if (!any) continue;
    StepRecord::HeldForce force;
    force.vertex = v;
    force.paddle = solver_.contact_paddle()[static_cast<size_t>(v)];
    force.force.head(dim) = summary_.reaction_forces.row(v).transpose();
    record.held_forces.push_back(force);
  }
  record.load_factors = at.factors;
  record.pressure = x[model_.pressure_dof()];
  record.volume = volume;
  record.volume_drift = (volume - reference_volume_) / reference_volume_;
  record.max_displacement = (X - model_.surface.V).rowwise().norm().maxCoeff();
  record.residual = record.residual_norms.empty() ? 0.0 : record.residual_norms.back();
  const std::vector<int>& wanted = options_.sensitivities.steps;
  if (!options_.sensitivities.parameters.empty() &&
      std::find(wanted.begin(), wanted.end(), k) != wanted.end()) {
    Eigen::MatrixXd residual_change;
    const std::string why = solver_.sensitivities(at, x, options_.sensitivities.parameters,
                                                  &record.sensitivities.state, &residual_change);
    if (!why.empty()) return "step " + std::to_string(k) + ": sensitivities: " + why;
    force_sensitivities(residual_change, record);
  }
  return {};
}

size_t StepFinisher::group_of(size_t c) const {
  const int constraint = partition_.constraint_of[c];
  return static_cast<size_t>(model_.constraints[static_cast<size_t>(constraint)].group) % groups_;
}

void StepFinisher::force_sensitivities(const Eigen::MatrixXd& residual_change,
                                       StepRecord& record) const {
  const int nv = model_.num_vertices(), dim = model_.dim();
  const Eigen::Index P = residual_change.cols();
  std::vector<Eigen::MatrixXd>& reactions = record.sensitivities.reactions;
  reactions.assign(groups_, Eigen::MatrixXd::Zero(3, P));
  for (size_t c = 0; c < partition_.constrained.size(); ++c) {
    const int d = partition_.constrained[c];
    const size_t g = group_of(c);
    reactions[g].row(d / nv) += residual_change.row(d);
  }
  for (const model::MirrorLayer& layer : model_.mirror_layers)
    reactions[static_cast<size_t>(layer.group) % groups_].setConstant(
        std::numeric_limits<double>::quiet_NaN());
  std::vector<Eigen::MatrixXd>& paddle_forces = record.sensitivities.paddle_forces;
  paddle_forces.assign(record.paddles.size(), Eigen::MatrixXd::Zero(3, P));
  const model::DofMap held = solver_.held_map();
  for (int v = 0; v < nv; ++v) {
    const int p = solver_.contact_paddle()[static_cast<size_t>(v)];
    if (p < 0) continue;
    for (int a = 0; a < dim; ++a)
      if (held.held(a * nv + v) && !partition_holds(partition_, a * nv + v))
        paddle_forces[static_cast<size_t>(p)].row(a) += residual_change.row(a * nv + v);
  }
}

}  // namespace fiberfluid::solve

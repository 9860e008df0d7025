// SPDX-License-Identifier: GPL-3.0-or-later
// What both steppers share (internal header): their clock, their start and
// failure, and the checks before the run and after every step.
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <string>
#include <vector>

#include "model/dof_map.hpp"
#include "model/equilibrium.hpp"
#include "model/model.hpp"
#include "solve/load_stepper.hpp"

namespace fiberfluid::solve {

using Clock = std::chrono::steady_clock;

inline double seconds_since(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

// The summary of a run that has not solved anything yet: zero unknowns.
inline SteppingSummary empty_summary(const model::Model& model, Scheme scheme) {
  SteppingSummary summary;
  summary.scheme = scheme;
  summary.unknowns = Eigen::VectorXd::Zero(model.num_unknowns());
  return summary;
}

// The summary, ended with a failure: why, and the time since start.
inline SteppingSummary failed(SteppingSummary& summary, const std::string& why,
                              Clock::time_point start) {
  summary.message = why;
  summary.total_seconds = seconds_since(start);
  return summary;
}

// Why the run cannot start, or "": invalid options, or a singular setup.
std::string setup_problem(const model::Model& model, const SteppingOptions& options);

// Why the state reached after a step is a runaway rather than a result, or
// "": non-finite unknowns, a face turned over since the last accepted step
// (last_face_areas, the face area vectors then: updated when the faces are
// checked and none turned), a volume change beyond options.max_volume_change.
std::string runaway_reason(const model::Model& model, const SteppingOptions& options,
                           const Eigen::VectorXd& unknowns, const Eigen::MatrixXd& X, double volume,
                           double reference_volume, Eigen::MatrixXd& last_face_areas);

// How far a state is from equilibrium, relative (Equilibrium::relative_norm):
// the free rows of R over the largest force seen so far along the path (the
// loads, or the held rows: the reactions), the volume row over dim C0 V0.
class ResidualGauge {
 public:
  double measure(const model::Equilibrium& problem, const model::DofMap& dofs,
                 const Eigen::VectorXd& x, const std::vector<double>& factors) {
    const Eigen::VectorXd R = problem.residual(x, factors);
    update_scale(problem, dofs, x, factors, R);
    return problem.relative_norm(dofs.reduce(R), peak_force_);
  }
  // Raises the force scale with the loads and the held rows of R at x.
  void update_scale(const model::Equilibrium& problem, const model::DofMap& dofs,
                    const Eigen::VectorXd& x, const std::vector<double>& factors,
                    const Eigen::VectorXd& R) {
    const Eigen::VectorXd F = problem.external_forces(x, factors);
    double held = 0.0;
    for (int d : dofs.held_dofs()) held += R[d] * R[d];
    peak_force_ = std::max({peak_force_, F.head(F.size() - 1).norm(), std::sqrt(held)});
  }
  double force_scale() const { return peak_force_; }

 private:
  double peak_force_ = 0.0;
};

}  // namespace fiberfluid::solve

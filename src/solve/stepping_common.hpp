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

#include "fiberfluid/model/dof_map.hpp"
#include "fiberfluid/model/equilibrium.hpp"
#include "fiberfluid/model/model.hpp"
#include "fiberfluid/solve/stepping.hpp"
#include "fiberfluid/util/status.hpp"

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

// Whether the run can start (why not): invalid options, or a singular setup.
Status check_setup(const model::Model& model, const SteppingOptions& options);

// Whether the state reached after a step is a result, not a runaway (why
// not): non-finite unknowns, a fold since the last accepted step (a face whose
// normal reversed and now faces against its neighbours, or a surface that
// crosses itself; last_face_areas, the face area vectors then: updated when
// the faces pass), a volume change beyond options.max_volume_change.
Status check_no_runaway(const model::Model& model, const SteppingOptions& options,
                        const Eigen::VectorXd& unknowns, const Eigen::MatrixXd& X, double volume,
                        double reference_volume, Eigen::MatrixXd& last_face_areas);

// How far a state is from equilibrium, relative (Equilibrium::relative_norm):
// the free rows of R over a force scale, the volume row over dim C0 V0. The
// scale is the largest of the forces at the state measured (its loads, and
// its held rows of R: the reactions) and of those at the states accepted
// before (commit). A trial iterate never raises the scale for the states
// after it: a wild iterate's huge reactions would make the next iterate look
// converged.
class ResidualGauge {
 public:
  // The relative residual of x; the scale of x is committed (x is accepted).
  double measure(const model::Equilibrium& problem, const model::DofMap& dofs,
                 const Eigen::VectorXd& x, const std::vector<double>& factors) {
    const Eigen::VectorXd R = problem.residual(x, factors);
    const double scale = scale_at(problem, dofs, x, factors, R);
    commit(scale);
    return problem.relative_norm(dofs.reduce(R), scale);
  }
  // The force scale of the state x with residual R: the accepted states'
  // scale, raised by x's loads and reactions.
  double scale_at(const model::Equilibrium& problem, const model::DofMap& dofs,
                  const Eigen::VectorXd& x, const std::vector<double>& factors,
                  const Eigen::VectorXd& R) const {
    const Eigen::VectorXd F = problem.external_forces(x, factors);
    double held = 0.0;
    for (int d : dofs.held_dofs()) held += R[d] * R[d];
    return std::max({accepted_scale_, F.head(F.size() - 1).norm(), std::sqrt(held)});
  }
  // Keeps a scale once its state is accepted (a converged step).
  void commit(double scale) { accepted_scale_ = std::max(accepted_scale_, scale); }

 private:
  double accepted_scale_ = 0.0;
};

}  // namespace fiberfluid::solve

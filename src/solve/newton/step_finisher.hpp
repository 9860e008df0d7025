// SPDX-License-Identifier: GPL-3.0-or-later
// What every converged Newton step leaves behind (internal to the Newton
// scheme): its record (forces on the body, volume, pressure, sensitivities)
// after the runaway checks.
#pragma once

#include <Eigen/Core>
#include <string>

#include "fiberfluid/model/boundary_conditions.hpp"
#include "fiberfluid/model/model.hpp"
#include "fiberfluid/solve/newton/newton_solver.hpp"
#include "fiberfluid/solve/stepping.hpp"

namespace fiberfluid::solve {

class StepFinisher {
 public:
  // Refers to every argument, which must outlive it.
  StepFinisher(const model::Model& model, const SteppingOptions& options, NewtonSolver& solver,
               const model::DofPartition& partition, SteppingSummary& summary);

  // The state the next step's runaway checks compare with (a warm start's;
  // the unloaded body at first).
  void compare_with(const Eigen::VectorXd& x);

  // "" or why the run stops (a runaway, failed sensitivities).
  std::string finish(const LoadPoint& at, const Eigen::VectorXd& x, StepRecord& record);

 private:
  // The support group (an index into StepRecord::reactions) of the c-th held unknown.
  size_t group_of(size_t c) const;
  // The reactions' and paddle forces' derivatives, read off the held rows of
  // the residual's change (columns: the parameters). A group whose mirror
  // layer carries part of its reaction gets NaN: the layer's fibers are not
  // differentiated here.
  void force_sensitivities(const Eigen::MatrixXd& residual_change, StepRecord& record) const;

  const model::Model& model_;
  const SteppingOptions& options_;
  NewtonSolver& solver_;
  const model::DofPartition& partition_;
  SteppingSummary& summary_;
  double reference_volume_;
  Eigen::MatrixXd last_face_areas_;
  size_t groups_;
  int gauge_group_ = -1;  // the group "gauge" (case_builder's free-rotation holds), or -1
};

}  // namespace fiberfluid::solve

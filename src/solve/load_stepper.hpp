// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once

#include <Eigen/Core>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "model/boundary_conditions.hpp"
#include "model/fiber_system.hpp"
#include "model/model.hpp"
#include "solve/linear_solver.hpp"

namespace fiberfluid::solve {

// The paper's incremental scheme (model.md section 6): at step k,
//   A(x_{k-1}) dx_k = B(x_{k-1}, f_k) - B(x_{k-1}, f_{k-1}),
// a forward-Euler walk along the load path.
struct SteppingOptions {
  int steps = 1;                  // number of load steps n
  bool rebuild_matrix = false;    // rebuild A (lengths, area vectors) from x_{k-1} each step
  bool update_load_geometry = true;  // loads from x_{k-1} (the paper) or from the reference
  model::BoundaryMethod boundary_method = model::BoundaryMethod::Elimination;
  double penalty = 1e9;           // the paper's diagonal value, for BoundaryMethod::Penalty
  SolverKind solver = SolverKind::Auto;  // the linear backend; Auto chooses by size
  PcgOptions pcg;                 // for SolverKind::PCG
  // Runaway guards: a step that changes the enclosed volume by more than this
  // fraction of the reference volume, or turns a face over, ends the run.
  double max_volume_change = 0.5;
  bool stop_on_inverted_faces = true;

  bool IsValid(std::string* why) const;
};

struct StepRecord {
  int step = 0;                       // 1..n
  std::vector<double> load_factors;   // one per load, after this step
  double pressure = 0.0;              // P after this step
  double volume = 0.0;                // enclosed volume (area in 2D) after this step
  double max_displacement = 0.0;      // max_i |u_i|
  double seconds = 0.0;               // wall time of this step
  // Force that each constraint group (Model::constraint_groups) exerts on the
  // body, and the sum of the external loads; they sum to zero at equilibrium.
  std::vector<Eigen::Vector3d> reactions;
  Eigen::Vector3d applied_force = Eigen::Vector3d::Zero();
};

struct SteppingSummary {
  bool success = false;
  std::string message;                // why it failed, or "" on success
  std::vector<StepRecord> steps;
  Eigen::VectorXd unknowns;           // final [u_x.. u_y.. (u_z..) P]
  Eigen::MatrixXd reaction_forces;    // #V by dim: the support force on each vertex at the end
  SolverKind solver = SolverKind::Auto;  // the backend that ran
  // The bordered system the backend factored last (reduced, boundary
  // conditions applied): what was actually solved.
  std::shared_ptr<const model::FiberSystem> system;
  SolverStatistics solver_statistics;
  int factorizations = 0;
  double assemble_seconds = 0.0;
  double factorize_seconds = 0.0;
  double solve_seconds = 0.0;
  double total_seconds = 0.0;

  std::string BriefReport() const;
};

// Called after each step with its record and the unknowns reached.
using StepObserver = std::function<void(const StepRecord&, const Eigen::VectorXd&)>;

// Runs the load steps. Expected numerical failures (a singular setup, a
// singular matrix, a runaway: non-finite values, a face turned over, a volume
// change beyond max_volume_change) come back as success = false with a
// message naming the step and the cause.
SteppingSummary solve_load_steps(const model::Model& model, const SteppingOptions& options,
                                 const StepObserver& observer = {});

}  // namespace fiberfluid::solve

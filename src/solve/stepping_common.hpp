// SPDX-License-Identifier: GPL-3.0-or-later
// What both steppers share (internal header): their clock, their start and
// failure, and the checks before the run and after every step.
#pragma once

#include <Eigen/Core>
#include <chrono>
#include <string>

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
// "": non-finite unknowns, a face turned over, a volume change beyond
// options.max_volume_change.
std::string runaway_reason(const model::Model& model, const SteppingOptions& options,
                           const Eigen::VectorXd& unknowns, const Eigen::MatrixXd& X,
                           double volume, double reference_volume,
                           const Eigen::MatrixXd& reference_face_areas);

}  // namespace fiberfluid::solve

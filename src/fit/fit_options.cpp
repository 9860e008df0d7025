// SPDX-License-Identifier: GPL-3.0-or-later
// A fit's options and statuses by name, and the one check of its options.
#include <limits>
#include <sstream>
#include <string>

#include "fiberfluid/fit/calibration.hpp"
#include "fiberfluid/util/error.hpp"

namespace fiberfluid::fit {

const char* to_string(Method method) {
  switch (method) {
    case Method::LevenbergMarquardt:
      return "levenberg-marquardt";
    case Method::Bobyqa:
      return "bobyqa";
    case Method::DirectL:
      return "direct-l";
    case Method::Crs2:
      return "crs2";
  }
  return "?";
}

const char* to_string(Loss loss) {
  switch (loss) {
    case Loss::Squared:
      return "squared";
    case Loss::Huber:
      return "huber";
    case Loss::Cauchy:
      return "cauchy";
  }
  return "?";
}

Method method_from_string(const std::string& name) {
  for (Method m : {Method::LevenbergMarquardt, Method::Bobyqa, Method::DirectL, Method::Crs2})
    if (name == to_string(m)) return m;
  throw InputError("method: expected levenberg-marquardt, bobyqa, direct-l or crs2, got \"" +
                   name.substr(0, 40) + "\"");
}

Loss loss_from_string(const std::string& name) {
  for (Loss l : {Loss::Squared, Loss::Huber, Loss::Cauchy})
    if (name == to_string(l)) return l;
  throw InputError("loss: expected squared, huber or cauchy, got \"" + name.substr(0, 40) + "\"");
}

void check_options(const FitOptions& o) {
  auto positive = [](const char* name, double x, double largest, const char* what) {
    if (!(x > 0.0 && x <= largest)) {
      std::ostringstream message;
      message << name << ": expected " << what << ", got " << x;
      throw InputError(message.str());
    }
  };
  positive("difference_step", o.difference_step, 0.5,
           "a step in the fitted variable above 0 and at most 0.5 (a share of the value, or of "
           "its logarithm)");
  positive("loss_scale", o.loss_scale, std::numeric_limits<double>::max(),
           "a positive finite length in m");
  positive("function_tolerance", o.function_tolerance, 1.0, "a relative change in (0, 1]");
  positive("parameter_tolerance", o.parameter_tolerance, 1.0, "a relative change in (0, 1]");
  positive("initial_trust_region_radius", o.initial_trust_region_radius,
           std::numeric_limits<double>::max(), "a positive finite number");
  if (!(o.max_step_factor > 1.0 && o.max_step_factor <= std::numeric_limits<double>::max()))
    throw InputError("max_step_factor: expected a finite factor above 1, got " +
                     std::to_string(o.max_step_factor));
  if (o.max_iterations < 1 || o.max_iterations > 100000)
    throw InputError("max_iterations: expected 1 to 100000, got " +
                     std::to_string(o.max_iterations));
  if (o.max_evaluations < 1 || o.max_evaluations > 10000000)
    throw InputError("max_evaluations: expected 1 to 10000000, got " +
                     std::to_string(o.max_evaluations));
}

const char* to_string(FitStatus status) {
  switch (status) {
    case FitStatus::Converged:
      return "converged";
    case FitStatus::ConvergedAtBounds:
      return "converged_at_bounds";
    case FitStatus::IterationLimit:
      return "iteration_limit";
    case FitStatus::NotIdentifiable:
      return "not_identifiable";
    case FitStatus::ForwardRunsFailed:
      return "forward_runs_failed";
    case FitStatus::StartFailed:
      return "start_failed";
    case FitStatus::OptimizerFailed:
      return "optimizer_failed";
    case FitStatus::Interrupted:
      return "interrupted";
  }
  return "?";
}

}  // namespace fiberfluid::fit

// SPDX-License-Identifier: GPL-3.0-or-later
// The one check of a fit's options.
#include <limits>
#include <sstream>
#include <string>

#include "fiberfluid/fit/fit_types.hpp"
#include "fiberfluid/util/error.hpp"

namespace fiberfluid::fit {

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
  if (!(o.max_step_share > 0.0 && o.max_step_share <= 1.0))
    throw InputError("max_step_share: expected a share of the range above 0 and at most 1, got " +
                     std::to_string(o.max_step_share));
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

}  // namespace fiberfluid::fit

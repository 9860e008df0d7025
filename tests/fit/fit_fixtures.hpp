// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
// Small pieces the calibration tests share.

#include <string>

#include "model/model_fixtures.hpp"

#include "fiberfluid/fit/parameters.hpp"
#include "fiberfluid/geom/generators.hpp"
#include "fiberfluid/model/boundary_conditions.hpp"
#include "fiberfluid/solve/stepping.hpp"

namespace fiberfluid::testing {

// The Newton scheme in `steps` steps, converged far below the fits' tolerances.
inline solve::SteppingOptions newton(int steps) {
  solve::SteppingOptions o;
  o.scheme = solve::Scheme::Newton;
  o.steps = steps;
  o.newton.residual_tolerance = 1e-13;
  return o;
}

// A small hanging sphere (42 vertices, its cap above half the radius held)
// with a stiffening law (Y0 3000, beta 5), its fluid (300 kg/m^3) under
// `gravity` m/s^2, and surface tension `gamma`.
inline model::Model hanging_sphere(double radius = 1.0, double gravity = 10.0,
                                   double gamma = 300.0) {
  model::Model m;
  m.surface = geom::icosphere(1, radius);
  m.material.law = model::FiberLaw::exponential(3000.0, 5.0);
  m.material.surface_tension = gamma;
  const std::string cap = "z >= " + std::to_string(0.5 * radius);
  for (int v : model::select_half_space(m.surface.V, model::parse_half_space(cap, 3)))
    for (int a = 0; a < 3; ++a) m.constraints.push_back({v, a, 0.0, {}});
  m.loads = {hydrostatic_load({0.0, 0.0, -gravity}, 300.0)};
  return m;
}

// A fitted parameter by name, from `start`, in log scale unless asked otherwise.
inline fit::Parameter parameter(const std::string& name, double start, bool log = true) {
  fit::Parameter p;
  p.name = name;
  p.initial = start;
  p.log_scale = log;
  return p;
}

}  // namespace fiberfluid::testing

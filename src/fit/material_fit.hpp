// SPDX-License-Identifier: GPL-3.0-or-later
// A hyperelastic law fitted to a material test at material level (no body):
// the law's parameters so that its homogeneous responses meet the measured
// nominal stresses, weighed as relative misfits (a test's small stresses
// count as much as its large ones), by the single fit's Levenberg-Marquardt
// on an Objective.
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "fiberfluid/fit/fit_types.hpp"
#include "fiberfluid/material/material_test.hpp"

namespace fiberfluid::fit {

struct MaterialFitResult {
  FitStatus status = FitStatus::StartFailed;
  std::string message;
  material::HyperelasticLaw law = material::HyperelasticLaw::neo_hookean(0.0);  // at the fit
  double initial_rms = 0.0, rms = 0.0;  // rms relative misfit at the start and the fit
  std::vector<IterationRecord> iterations;
  int evaluations = 0;
};

// From `start` (its parameters are the start; every one is fitted).
// options: max_iterations and the tolerances (method and loss are
// Levenberg-Marquardt on squares).
MaterialFitResult fit_material_test(const material::HyperelasticLaw& start,
                                    const std::vector<material::TestPoint>& points,
                                    const FitOptions& options = {});

}  // namespace fiberfluid::fit

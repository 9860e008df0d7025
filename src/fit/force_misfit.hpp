// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
// What a force curve's misfit says at the fitted values: how large it is, and
// whether it is the data's noise or the model's form.

#include <vector>

#include "fiberfluid/fit/fit_types.hpp"
#include "fiberfluid/fit/force_curve.hpp"

namespace fiberfluid::fit {

// A curve's misfit at `simulated` (per row, N): its sizes, and whether it
// is systematic: more than twice the measurement's scatter (when the curve
// has one), or its signs in fewer runs than random signs would give (z below
// -1.96, the one-sided 2.5% level; from 10 rows).
ForceMisfit force_misfit(const ForceCurve& curve, const std::vector<double>& simulated,
                         double weight);

}  // namespace fiberfluid::fit

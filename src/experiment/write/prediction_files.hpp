// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
// A prediction's section of summary.json: the estimate it ran at and each
// figure's band. (The bands beside steps.csv's columns are steps_csv's, from
// RunResult::bands.)

#include <vector>

#include <nlohmann/json.hpp>

#include "fiberfluid/experiment/run/prediction.hpp"

namespace fiberfluid::experiment {

nlohmann::json prediction_json(const Experiment& experiment, const FittedEstimate& estimate,
                               const std::vector<RunBands>& bands);

}  // namespace fiberfluid::experiment

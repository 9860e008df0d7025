// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once

#include <nlohmann/json.hpp>

#include "fiberfluid/experiment/run/results.hpp"
#include "fiberfluid/experiment/spec/experiment.hpp"

namespace fiberfluid::experiment {

// The summary.json document: the experiment, its units, per run the stepping
// options and per step load factors, pressure, volume, largest displacement,
// reactions and wall time, then the final figures and the checks of the
// expected ones, and the result's summary_sections.
nlohmann::json summary_json(const Experiment& experiment, const ExperimentResult& result);

// A number for a JSON file: null when it is not finite (JSON has no NaN).
nlohmann::json finite_or_null(double x);

}  // namespace fiberfluid::experiment

// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once

#include <string>

#include "fiberfluid/experiment/run/results.hpp"
#include "fiberfluid/experiment/spec/experiment.hpp"

namespace fiberfluid::experiment {

// CSV tables (comma-separated, one header line, SI units in the column names):
// per load step of a run (with the Newton and paddle records); the
// load-displacement curve (load factors, paddle travel and force, largest
// displacement, pressure, volume); per input vertex at the end of a run; one
// row per variant of a sweep. A prediction's run (RunResult::bands) has
// COLUMN_lower95 and COLUMN_upper95 after every column its bands name.
std::string steps_csv(const Case& c, const RunResult& run);
std::string load_displacement_csv(const Case& c, const RunResult& run);
std::string vertices_csv(const Case& c, const RunResult& run);
std::string comparison_csv(const Experiment& experiment, const ExperimentResult& result);

}  // namespace fiberfluid::experiment

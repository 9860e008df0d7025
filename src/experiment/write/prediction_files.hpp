// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
// A prediction's files: each run's steps.csv with a band beside every
// banded column (COLUMN_lower95, COLUMN_upper95), and summary.json's
// "prediction" section (the estimate it ran at and each figure's band).

#include <filesystem>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "fiberfluid/experiment/run/prediction.hpp"

namespace fiberfluid::experiment {

// `steps_csv` (csv_tables.hpp) with COLUMN_lower95 and COLUMN_upper95 after
// every column the bands hold, row by row ("nan" where a step has none).
std::string with_band_columns(const std::string& steps_csv, const RunBands& bands);

nlohmann::json prediction_json(const Experiment& experiment, const FittedEstimate& estimate,
                               const std::vector<RunBands>& bands);

// Into a finished run's folder before it is moved into place
// (OutputWriter::finish's filler): the banded steps.csv of each run and the
// "prediction" section added to summary.json.
void write_prediction(const std::filesystem::path& folder, const Experiment& experiment,
                      const FittedEstimate& estimate, const std::vector<RunBands>& bands);

}  // namespace fiberfluid::experiment

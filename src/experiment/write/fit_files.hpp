// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
// What a fit writes into its output folder: fit.json and its tables, or a
// calibration over specimens' calibration.json with a folder per specimen.

#include <array>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "fiberfluid/experiment/run/fit_setup.hpp"
#include "fiberfluid/experiment/run/results.hpp"
#include "fiberfluid/experiment/write/file_names.hpp"

namespace fiberfluid::experiment {

// fit.json: fitted values, errors and intervals, correlation, iterations,
// distance statistics per target and overall; with the checks; and for a
// multi-start search, its starts and the optima they reached.
nlohmann::json fit_json(const Experiment& experiment, const FitSetup& setup,
                        const fit::FitResult& result, const ExperimentResult& run,
                        const fit::MultistartResult* search = nullptr,
                        const MeshCheck* mesh_check = nullptr);

// Writes, into `folder`: fit.json, fit_iterations.csv, fit_distances.csv and
// fit_target_K.vtu (the simulated surface at the target's step, with the
// distance to the target as point data); for a multi-start search also
// fit_starts.csv (one row per start: where it began and ended, its cost, the
// optimum it reached, the rank that ran it).
void write_fit_files(const std::filesystem::path& folder, const Experiment& experiment,
                     const FitSetup& setup, const fit::FitResult& result,
                     const ExperimentResult& run, const fit::MultistartResult* search = nullptr,
                     const MeshCheck* mesh_check = nullptr);

// Writes calibration.json (the shared parameters with their intervals, each
// specimen's own and its distance statistics, the iterations, the checks),
// calibration_iterations.csv, and per specimen a folder SPECIMEN/ with its
// fit files at the joint optimum (write_fit_files: fit.json,
// fit_distances.csv, fit_target_K.vtu, ...).
void write_joint_files(const std::filesystem::path& folder, const Experiment& experiment,
                       const JointSetup& setup, const fit::JointFitResult& result,
                       const ExperimentResult& checked);

}  // namespace fiberfluid::experiment

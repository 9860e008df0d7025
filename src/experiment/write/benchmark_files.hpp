// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
// What a benchmark's run (run/benchmark.hpp) writes and prints: the
// command's lines, metrics.csv and benchmark.json.

#include <array>
#include <filesystem>
#include <string>

#include "fiberfluid/experiment/run/benchmark.hpp"
#include "fiberfluid/experiment/write/file_names.hpp"

namespace fiberfluid::experiment {

// Writes the files of benchmark_files (file_names.hpp) into `folder`: the
// final boundaries when the run has them.
void write_benchmark_files(const std::filesystem::path& folder, const BenchmarkSpec& spec,
                           const BenchmarkResult& result);

// One line per series: its E_n, E_s, E_i at 1 s, 2 s, 5 s and the end, or
// where it diverged, and its time (for the command's report).
std::string benchmark_report(const BenchmarkResult& result);

// metrics.csv: time_s, series, E_n, E_s, E_i (one row per series and time).
std::string benchmark_csv(const BenchmarkResult& result);
// benchmark.json: the scene, the solvers, times and the fiber model's choice.
std::string benchmark_json(const BenchmarkSpec& spec, const BenchmarkResult& result);

}  // namespace fiberfluid::experiment

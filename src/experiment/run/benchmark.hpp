// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
// Running a benchmark (spec/benchmark_spec.hpp): the implicit Newmark
// reference, each solver against it time step by time step, other
// materials, and the fibers-and-fluid model on the scene's surface. What it
// gives is written by write/benchmark_files.hpp.

#include <Eigen/Core>
#include <functional>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "fiberfluid/experiment/spec/benchmark_spec.hpp"
#include "fiberfluid/fem/scenes.hpp"
#include "fiberfluid/geom/surface.hpp"

namespace fiberfluid::experiment {

// One approximation against the reference, per time step.
struct MetricSeries {
  std::string label;  // e.g. "explicit", "MP1/quasi-static", "fiber-model"
  bool ok = true;
  std::string message;           // why it stopped (diverged) when not ok
  double seconds = 0.0;          // wall time of its integration (or the fiber model's run)
  long long sweeps = 0;          // Gauss-Seidel sweeps
  std::string interior_weights;  // "volume" (FEM nodes) or "surface" (|S_i|: a surface model)
  std::vector<double> times, energy_norm, surface, interior;  // E_s is NaN between metrics steps
};

struct FiberModelReport {
  double Y = 0.0, gamma = 0.0;
  std::string how;  // "given" or how the fit went
  int vertices = 0;
  double static_energy_norm = 0.0;  // E_n of its static state against the FEM's it was fitted to
  std::string target;               // that static state: "this mesh" or "cells x R"
};

struct BenchmarkResult {
  bool ok = true;
  std::string message;
  fem::Scene scene;
  double reference_seconds = 0.0;
  long long reference_sweeps = 0;
  std::vector<MetricSeries> series;
  std::optional<FiberModelReport> fiber;
  std::map<std::string, double> figures;
  // The final deformed boundaries (for the OBJ files): the reference, the fiber model.
  geom::Surface reference_final, fiber_final;
};

// Runs the benchmark. `progress(done, total)` counts the runs (the
// reference, each solver, the fiber model).
BenchmarkResult run_benchmark(const BenchmarkSpec& spec,
                              const std::function<void(int done, int total)>& progress = {});

}  // namespace fiberfluid::experiment

// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once

// The accuracy benchmarks of Alterovitz and Goldberg (docs: benchmarks.md)
// as experiments ("kind": "benchmark"): a scene (the block and needle, or
// the bending rod), finite-element solvers run on it and compared with the
// implicit Newmark reference at the same mesh and step, time step by time
// step (E_n, E_s, E_i); optionally the same scene with other materials
// against that reference (the paper's Fig. 11), and the fibers-and-fluid
// model on the scene's surface with the same supports and loads.

#include <Eigen/Core>
#include <filesystem>
#include <functional>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "fiberfluid/fem/dynamics.hpp"
#include "fiberfluid/fem/scenes.hpp"
#include "fiberfluid/geom/surface.hpp"

namespace fiberfluid::experiment {

class Fields;

struct BenchmarkSpec {
  enum class Scene { BlockNeedle, BendingRod };
  Scene scene = Scene::BlockNeedle;
  fem::BlockOptions block;
  fem::RodOptions rod;
  std::string material_label = "MP1";    // the preset's name, or "custom"
  double step = 1.0 / 30.0;              // s, the paper's h
  double duration = 10.0;                // s
  int metrics_every = 1;                 // compute E_s every k-th step (E_n, E_i every step)
  std::vector<fem::Integrator> solvers;  // against the implicit Newmark reference
  fem::IntegrationOptions linear;        // Cholesky, or the paper's Gauss-Seidel
  // The same scene with another material, each solver against the reference.
  struct OtherMaterial {
    std::string label;
    fem::MaterialPreset material;
    std::vector<fem::Integrator> solvers;
  };
  std::vector<OtherMaterial> other_materials;
  // The fibers-and-fluid model on the scene's boundary (quasi-static).
  struct FiberModel {
    bool enabled = false;
    bool fit = true;  // Y and gamma fitted to the FEM's static shape; else given
    double Y = 0.0, gamma = 0.0;
    int steps = 10;  // load steps of the rod's gravity (the block: one per time step of the push)
    bool newton = false;  // the Newton scheme instead of the paper's incremental one
    // Central fibers (they bend; Newton only) instead of the paper's vector
    // spring, within a horizon (m; 0: every pair), with the rod's clamp as a
    // mirror layer as deep as the horizon.
    bool central = false;
    double horizon = 0.0;
    bool mirror_layer = false;
  };
  FiberModel fiber;
  // The rod's static state again on finer grids, each cell split ratio^k
  // times per axis (k = 1..levels), sampled at this mesh's nodes (a refined
  // grid keeps them): how far the benchmark's mesh is from a converged static
  // shape, with the observed order; the fiber model is then fitted to the
  // finest. levels = 0: none.
  struct StaticReference {
    int levels = 0;
    int ratio = 2;
  };
  StaticReference static_reference;
};

// Reads the benchmark fields of an experiment document (everything but
// name, description, kind and expected). Throws InputError naming the field.
BenchmarkSpec read_benchmark(Fields& root);

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

// One line per series: its E_n, E_s, E_i at 1 s, 2 s, 5 s and the end, or
// where it diverged, and its time (for the command's report).
std::string benchmark_report(const BenchmarkResult& result);

// metrics.csv: time_s, series, E_n, E_s, E_i (one row per series and time).
std::string benchmark_csv(const BenchmarkResult& result);
// benchmark.json: the scene, the solvers, times and the fiber model's choice.
std::string benchmark_json(const BenchmarkSpec& spec, const BenchmarkResult& result);

}  // namespace fiberfluid::experiment

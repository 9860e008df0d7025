// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once

#include <filesystem>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "geom/surface.hpp"
#include "model/model.hpp"
#include "solve/load_stepper.hpp"

namespace fiberfluid::app {

// A figure the experiment expects, checked after the run: either a value
// with an absolute tolerance, or bounds.
struct ExpectedFigure {
  std::string figure;                     // e.g. "max_displacement", "position.0.x"
  std::optional<double> value;
  double tolerance = 0.0;                 // |actual - value| <= tolerance
  std::optional<double> at_most, at_least;
  Eigen::MatrixXd matrix;                 // for matrix figures ("system_matrix")
  std::string note;                       // where the number comes from
};

struct OutputOptions {
  bool vtk = true;   // one .vtu per load step and a .pvd series
  bool obj = true;   // final.obj, the deformed surface in input vertex order
  int every = 1;     // write every k-th step's .vtu (the last always)
};

// What the fiber pruning did (issue 4), for the summary.
struct FiberReport {
  bool pruning = true;         // "fibers.pruning": "auto" (prune a concave body) or "off"
  bool convex = false;         // the fast path: nothing to prune
  long long pairs = 0;         // fibers in all, N (N-1) / 2
  long long kept = 0;
  int min_per_vertex = 0, max_per_vertex = 0;
  double mean_per_vertex = 0.0;
  double seconds = 0.0;
  long long exact_fallbacks = 0;  // pairs decided by exact constructions
  std::string write = "none";     // "kept" or "pruned": DIR/fibers.vtu
};

// A named surface for an "areas" experiment (the paper's Table 1).
struct NamedSurface {
  std::string name;
  geom::Surface surface;
};

// One simulation, fully resolved: the whole experiment when it does not
// sweep, or one variant of a sweep (the base document with the variant's
// JSON merge patch applied).
struct Case {
  std::string variant;        // "" unless the experiment sweeps
  nlohmann::json patch;       // the variant's merge patch (null without a sweep)
  // The surface as given (input vertex order), the model on its used
  // vertices, and the map between the two.
  geom::Surface input_surface;
  std::vector<int> model_to_input;
  model::Model model;
  solve::SteppingOptions stepping;
  FiberReport fibers;
};

// A parsed and validated experiment file.
struct Experiment {
  enum class Kind { Simulate, Areas };
  Kind kind = Kind::Simulate;
  std::string name;
  std::string description;
  std::filesystem::path source;  // the JSON file ("" for a document built in a program)

  std::vector<Case> cases;       // Simulate: one, or one per variant
  OutputOptions output;

  // Areas:
  std::vector<NamedSurface> area_surfaces;

  std::vector<ExpectedFigure> expected;
  std::vector<std::string> warnings;  // e.g. from the mesh reader

  bool sweeps() const { return !cases.empty() && !cases.front().variant.empty(); }
};

// Reads and validates an experiment file. Throws InputError naming the file
// and the field (e.g. "sphere.json: material.Y: expected a positive number")
// for an unknown field, a wrong type, a missing or bad mesh, a selection that
// selects nothing; nothing is written.
Experiment load_experiment(const std::filesystem::path& path);

// The same from a JSON document built in a program (e.g. a Python dict):
// relative mesh paths are taken from `folder`, and errors name `label`.
Experiment parse_experiment(const nlohmann::json& document, const std::filesystem::path& folder,
                            const std::string& label);

// Reads a mesh file and checks it (closed, manifold, outward, ...), optionally
// flipping an inward mesh first. Throws InputError naming the file.
geom::Surface load_checked_surface(const std::filesystem::path& path, bool flip,
                                   std::vector<std::string>* warnings);

}  // namespace fiberfluid::app

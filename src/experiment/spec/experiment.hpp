// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
// An experiment as read and built: its kind, each kind's spec (the cases of
// a simulation, the surfaces of an area study, a benchmark's scene, a
// calibration's specimens) and what is checked after the run. read/ makes
// one from a document; run/ runs it; write/ writes its results.

#include <Eigen/Core>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "fiberfluid/experiment/spec/benchmark_spec.hpp"
#include "fiberfluid/experiment/spec/case_spec.hpp"
#include "fiberfluid/experiment/spec/fem_reference_spec.hpp"
#include "fiberfluid/experiment/spec/fit_spec.hpp"
#include "fiberfluid/geom/surface.hpp"
#include "fiberfluid/util/names.hpp"

namespace fiberfluid::experiment {

// A figure the experiment expects, checked after the run: either a value
// with an absolute tolerance, or bounds.
struct ExpectedFigure {
  std::string figure;  // e.g. "max_displacement", "position.0.x"
  std::optional<double> value;
  double tolerance = 0.0;  // |actual - value| <= tolerance
  std::optional<double> at_most, at_least;
  Eigen::MatrixXd matrix;  // for matrix figures ("system_matrix")
  std::string note;        // where the number comes from
};

struct OutputOptions {
  bool vtk = true;  // one .vtu per load step and a .pvd series
  bool obj = true;  // final.obj, the deformed surface in input vertex order
  int every = 1;    // write every k-th step's .vtu (the last always)
  // "ascii", "compressed" (zlib, base64 inline) or "auto": compressed from
  // kCompressedVtkVertices vertices on, where ASCII files grow large.
  std::string vtk_format = "auto";
};
constexpr int kCompressedVtkVertices = 10000;

// A named surface for an "areas" experiment (the paper's Table 1).
struct NamedSurface {
  std::string name;
  geom::Surface surface;
};

struct NamedSurfaceSpec {
  std::string name;
  SurfaceSpec surface;
};

// One specimen of a calibration over several: an experiment file with a
// "fit" section (its surface, loads, targets and parameters).
struct SpecimenSpec {
  FieldName field;
  std::string name;
  std::filesystem::path file;
};

// "kind": "calibration": one material fitted to several specimens at once.
struct CalibrationSpec {
  std::vector<SpecimenSpec> specimens;
  std::vector<std::string> shared;  // the parameters every specimen shares
  int max_iterations = 50;
};

// A parsed and validated experiment file.
struct Experiment {
  enum class Kind { Simulate, Areas, Benchmark, Calibration };
  Kind kind = Kind::Simulate;
  std::string name;
  std::string description;
  std::filesystem::path source;  // the JSON file ("" for a document built in a program)
  // The document as read, and as the reader understood it: every default
  // filled in, file paths absolute, each variant whole (experiment.json and
  // experiment.resolved.json in the output folder; reading the resolved one
  // gives the same experiment).
  nlohmann::json document, resolved;

  // As parsed (read_experiment), and as built (build_experiment):
  std::vector<CaseSpec> specs;  // Simulate: one, or one per variant
  std::vector<Case> cases;
  OutputOptions output;

  // Areas:
  std::vector<NamedSurfaceSpec> area_specs;
  std::vector<NamedSurface> area_surfaces;

  std::optional<BenchmarkSpec> benchmark;  // Benchmark: the scene, solvers and comparisons

  // Calibration: the specimens and what they share, as parsed; and the
  // specimens' experiments, as loaded (build_experiment).
  std::optional<CalibrationSpec> calibration;
  std::vector<Experiment> specimens;

  std::optional<FitSpec> fit;
  // "fem_reference": also solve the simulation by linear FEM on tetrahedra
  // and write its deformed boundary (fem_reference.obj) as a target.
  std::optional<FemReferenceSpec>
      fem_reference;  // the "fit" section: what `fiberfluid fit` calibrates

  std::vector<ExpectedFigure> expected;
  std::vector<std::string> warnings;  // e.g. from the mesh reader

  bool sweeps() const { return !specs.empty() && !specs.front().variant.empty(); }
  // Whether build_experiment has made what running needs (read_experiment leaves it unbuilt).
  bool built() const {
    if (kind == Kind::Calibration)
      return calibration && specimens.size() == calibration->specimens.size();
    return kind != Kind::Simulate || (!cases.empty() && cases.size() == specs.size());
  }
};
inline constexpr auto kExperimentKindNames =
    names_of<Experiment::Kind>({{Experiment::Kind::Simulate, "simulate"},
                                {Experiment::Kind::Areas, "areas"},
                                {Experiment::Kind::Benchmark, "benchmark"},
                                {Experiment::Kind::Calibration, "calibration"}});

// Throws std::logic_error unless the experiment is built: a program that ran
// read_experiment without build_experiment is told so instead of crashing.
void require_built(const Experiment& experiment);

}  // namespace fiberfluid::experiment

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
#include <stdexcept>
#include <string>
#include <variant>
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

struct Experiment;

// "kind": "simulate" (the default): one case, or one per variant of a sweep.
struct Simulation {
  std::vector<CaseSpec> specs;  // as parsed (read_experiment): one, or one per variant
  std::vector<Case> cases;      // as built (build_experiment), in the same order
  OutputOptions output;
  std::optional<FitSpec> fit;  // the "fit" section: what `fiberfluid fit` calibrates
  // "fem_reference": the simulation solved by FEM on tetrahedra too, its
  // deformed boundary written (fem_reference.obj) as a target.
  std::optional<FemReferenceSpec> fem_reference;

  bool sweeps() const { return !specs.empty() && !specs.front().variant.empty(); }
};

// "kind": "areas": named surfaces measured (the paper's Table 1).
struct AreaStudy {
  std::vector<NamedSurfaceSpec> specs;  // as parsed
  std::vector<NamedSurface> surfaces;   // as built
};

// "kind": "calibration": the specimens and what they share, as parsed; and
// the specimens' experiments, as loaded (build_experiment).
struct CalibrationStudy {
  CalibrationSpec spec;
  std::vector<Experiment> specimens;
};

// A parsed and validated experiment file: what every kind has, and the
// kind's own part (a simulation, an area study, a benchmark, a calibration
// over specimens), of which it has exactly one.
struct Experiment {
  // The alternatives of `content`, in its order.
  enum class Kind { Simulate, Areas, Benchmark, Calibration };
  std::string name;
  std::string description;
  std::filesystem::path source;  // the JSON file ("" for a document built in a program)
  // The document as read, and as the reader understood it: every default
  // filled in, file paths absolute, each variant whole (experiment.json and
  // experiment.resolved.json in the output folder; reading the resolved one
  // gives the same experiment).
  nlohmann::json document, resolved;

  std::variant<Simulation, AreaStudy, BenchmarkSpec, CalibrationStudy> content;

  std::vector<ExpectedFigure> expected;
  std::vector<std::string> warnings;  // e.g. from the mesh reader

  Kind kind() const { return static_cast<Kind>(content.index()); }
  // The kind's part. Asking another kind's is a program's mistake
  // (std::logic_error naming both): the file's "kind" chose it.
  Simulation& simulation() { return part<Simulation>("a simulation"); }
  const Simulation& simulation() const { return part<Simulation>("a simulation"); }
  AreaStudy& areas() { return part<AreaStudy>("an area study"); }
  const AreaStudy& areas() const { return part<AreaStudy>("an area study"); }
  const BenchmarkSpec& benchmark() const { return part<BenchmarkSpec>("a benchmark"); }
  CalibrationStudy& calibration() { return part<CalibrationStudy>("a calibration"); }
  const CalibrationStudy& calibration() const { return part<CalibrationStudy>("a calibration"); }
  // A simulation's "fit" and "fem_reference" sections; null when it has none
  // or is of another kind.
  const FitSpec* fit() const {
    const Simulation* s = std::get_if<Simulation>(&content);
    return s && s->fit ? &*s->fit : nullptr;
  }
  const FemReferenceSpec* fem_reference() const {
    const Simulation* s = std::get_if<Simulation>(&content);
    return s && s->fem_reference ? &*s->fem_reference : nullptr;
  }

  // A simulation with variants.
  bool sweeps() const {
    const Simulation* s = std::get_if<Simulation>(&content);
    return s && s->sweeps();
  }
  // Whether build_experiment has made what running needs (read_experiment leaves it unbuilt).
  bool built() const;

 private:
  template <class Part>
  Part& part(const char* what) {
    return const_cast<Part&>(static_cast<const Experiment&>(*this).part<Part>(what));
  }
  template <class Part>
  const Part& part(const char* what) const;
};

inline constexpr auto kExperimentKindNames =
    names_of<Experiment::Kind>({{Experiment::Kind::Simulate, "simulate"},
                                {Experiment::Kind::Areas, "areas"},
                                {Experiment::Kind::Benchmark, "benchmark"},
                                {Experiment::Kind::Calibration, "calibration"}});

template <class Part>
const Part& Experiment::part(const char* what) const {
  if (const Part* p = std::get_if<Part>(&content)) return *p;
  throw std::logic_error("experiment " + name + " is not " + what);
}

inline bool Experiment::built() const {
  switch (kind()) {
    case Kind::Calibration:
      return calibration().specimens.size() == calibration().spec.specimens.size();
    case Kind::Simulate:
      return !simulation().cases.empty() && simulation().cases.size() == simulation().specs.size();
    default:
      return true;
  }
}

// Throws std::logic_error unless the experiment is built: a program that ran
// read_experiment without build_experiment is told so instead of crashing.
void require_built(const Experiment& experiment);

}  // namespace fiberfluid::experiment

// SPDX-License-Identifier: GPL-3.0-or-later
#include "fuzz_entries.hpp"

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <nlohmann/json.hpp>

#include "fiberfluid/experiment/experiment.hpp"
#include "fiberfluid/experiment/run/compare.hpp"
#include "fiberfluid/experiment/run/fit_setup.hpp"
#include "fiberfluid/experiment/run/runner.hpp"
#include "fiberfluid/experiment/write/output_folder.hpp"
#include "fiberfluid/geom/area_vectors.hpp"
#include "fiberfluid/geom/generators.hpp"
#include "fiberfluid/geom/mesh_check.hpp"
#include "fiberfluid/geom/mesh_io.hpp"
#include "fiberfluid/material/hyperelastic_law.hpp"
#include "fiberfluid/material/material_test.hpp"
#include "fiberfluid/util/error.hpp"
#include "fiberfluid/util/run_control.hpp"

namespace fiberfluid::fuzz {
namespace {

// A broken invariant: abort, which libFuzzer and the replay test report.
void require(bool holds, const char* what) {
  if (holds) return;
  std::fprintf(stderr, "fuzz invariant broken: %s\n", what);
  std::abort();
}

// ---------------------------------------------------------------- meshes
void read_mesh(geom::MeshFormat format, const char* name, const uint8_t* data, size_t size) {
  const std::string bytes(reinterpret_cast<const char*>(data), size);
  geom::ReadResult read;
  try {
    read = geom::read_surface_bytes(bytes, format, name);
  } catch (const InputError&) {
    return;
  }
  const geom::Surface& s = read.surface;
  require(s.dim == 2 || s.dim == 3, "the dimension is 2 or 3");
  require(s.V.cols() == s.dim && s.F.cols() == s.dim, "V and F have dim columns");
  require(s.V.allFinite(), "a read surface has finite coordinates");
  require(s.F.size() == 0 || (s.F.minCoeff() >= 0 && s.F.maxCoeff() < s.num_vertices()),
          "face indices refer to vertices");
  const geom::MeshReport report = geom::inspect(s);
  if (!report.ok()) {
    require(!report.problems.front().empty(), "a rejected surface says why");
    return;
  }
  const double volume = geom::enclosed_volume(s.V, s.F);
  require(std::isfinite(volume) && volume > 0.0, "a usable surface encloses a positive volume");
  const geom::VertexAreaVectors areas = geom::vertex_area_vectors(s.V, s.F);
  require(areas.S.allFinite(), "area vectors are finite");
}

// ---------------------------------------------------------------- material tests
// A material test read is finite and positive where it must be, and every
// law's stress at its points is finite.
void read_material_test(const uint8_t* data, size_t size) {
  const std::string bytes(reinterpret_cast<const char*>(data), size);
  std::vector<material::TestPoint> points;
  try {
    points = material::read_material_test_text(bytes, "fuzz.csv");
  } catch (const InputError& e) {
    require(std::string(e.what()).find("fuzz.csv") != std::string::npos,
            "a refused material test names its file");
    return;
  }
  require(!points.empty(), "a read material test has points");
  const material::HyperelasticLaw law = material::HyperelasticLaw::named("ogden3", 4e5);
  for (const material::TestPoint& p : points) {
    require(std::isfinite(p.stretch) && p.stretch > 0.0, "stretches are positive and finite");
    require(std::isfinite(p.nominal_stress), "stresses are finite");
    const double s = material::nominal_stress(law, p.test, p.stretch);
    require(std::isfinite(s), "a law's stress at a read stretch is finite");
  }
}

// ---------------------------------------------------------------- experiments
// Through the program's own reader (its nesting limit included).
std::optional<nlohmann::json> parse_json(const uint8_t* data, size_t size) {
  try {
    return experiment::parse_json(std::string(reinterpret_cast<const char*>(data), size),
                                  "fuzz.json");
  } catch (const InputError& e) {
    require(std::string(e.what()).size() < 1000, "a JSON error quotes a short excerpt");
    return std::nullopt;
  }
}

// Names that make paths never leave the output root: out/NAME is one
// folder below out/, or the name is refused.
void check_output_name(const std::string& name) {
  std::filesystem::path folder;
  try {
    folder = experiment::output_folder("", name);
  } catch (const InputError&) {
    return;
  }
  require(folder.parent_path() == "out" && folder.filename() == name && name != ".." &&
              name != "." && name.find('/') == std::string::npos,
          "an accepted name is one folder below out/");
}

const std::filesystem::path kExperiments = FIBERFLUID_EXPERIMENTS;

void read_experiment(const uint8_t* data, size_t size) {
  const std::optional<nlohmann::json> document = parse_json(data, size);
  if (!document) return;
  try {
    const experiment::Experiment ex =
        experiment::read_experiment(*document, kExperiments, "fuzz.json");
    check_output_name(ex.name);
    if (ex.kind() != experiment::Experiment::Kind::Simulate) return;
    for (const experiment::CaseSpec& spec : ex.simulation().specs) {
      if (!spec.variant.empty()) check_output_name(spec.variant);
      std::string why;
      require(spec.stepping.IsValid(&why), "parsed stepping options are valid");
    }
  } catch (const InputError&) {
  }
}

// Above this no model runs within SmallBudgets (0.02 s in Release).
constexpr int kMostGeneratedVertices = 20000;

// Small budgets while one input runs (the replay test shares the process).
struct SmallBudgets {
  SmallBudgets() { set_memory_budget(256.0 * 1024 * 1024), set_time_budget(0.02); }
  ~SmallBudgets() { set_memory_budget(0.0), set_time_budget(0.0); }
};

// A model is built and run only when its estimate is small (0.02 s in Release,
// a second or so in this instrumented build): the fuzzer looks for wrong
// answers and crashes, not for long runs, which the estimate refuses before
// pruning.
void build_and_run(const uint8_t* data, size_t size) {
  const std::optional<nlohmann::json> document = parse_json(data, size);
  if (!document) return;
  const SmallBudgets budgets;  // the estimate refuses longer cases before pruning
  try {
    experiment::Experiment ex = experiment::read_experiment(*document, kExperiments, "fuzz.json");
    if (ex.kind() != experiment::Experiment::Kind::Simulate || ex.simulation().specs.size() > 4)
      return;
    // Nor for long mesh checks: a generated surface larger than any the
    // estimate would let run (an icosphere subdivided 7 times has 163,842
    // vertices, and CGAL's self-intersection test takes 19 s of the 25 s
    // timeout under ASan) is not built.
    for (const experiment::CaseSpec& spec : ex.simulation().specs)
      if (spec.surface.generate && spec.surface.generate().num_vertices() > kMostGeneratedVertices)
        return;
    experiment::build_experiment(ex);
    ex.simulation().fem_reference.reset();  // tetrahedral meshing: seconds per input
    experiment::RunOptions options;
    options.jobs = 1;
    const experiment::ExperimentResult result = experiment::run_experiment(ex, {}, options);
    for (const experiment::RunResult& run : result.runs) {
      if (!run.summary.success) {
        require(!run.summary.message.empty(), "a failed run says why");
        continue;
      }
      require(run.summary.unknowns.allFinite(), "a successful run's unknowns are finite");
      for (const solve::StepRecord& r : run.summary.steps)
        require(std::isfinite(r.pressure) && std::isfinite(r.volume) &&
                    std::isfinite(r.max_displacement),
                "a successful run's step records are finite");
    }
  } catch (const InputError&) {
  }
}

// The fit section (issue 27): read, set up on the built model, the options
// checked as every front end's are; when the case is small, one forward run
// at the start. Only InputError may stop it.
void set_up_fit(const uint8_t* data, size_t size) {
  const std::optional<nlohmann::json> document = parse_json(data, size);
  if (!document) return;
  const SmallBudgets budgets;
  try {
    experiment::Experiment ex = experiment::read_experiment(*document, kExperiments, "fuzz.json");
    check_output_name(ex.name);
    if (!ex.fit()) return;
    fit::check_options(ex.fit()->options);  // read_fit checked them: they pass again
    experiment::build_experiment(ex);
    const experiment::FitSetup setup = experiment::setup_fit(ex);
    const fit::Calibration& c = *setup.calibration;
    require(c.num_residuals() >= c.parameters().size(),
            "a fit has at least one distance per parameter");
    const fit::Evaluation e = c.evaluate(c.parameters().initial_phi(), false);
    if (!e.ok) {
      require(!e.message.empty(), "a failed forward run says why");
      return;
    }
    require(e.residuals.size() == c.num_residuals() && e.residuals.allFinite() &&
                (e.residuals.array() >= 0.0).all(),
            "distances are finite and not negative");
  } catch (const InputError&) {
  }
}

// `compare` (issue 27): a mesh read from the input against a unit square or
// cube, both ways round. Every metric it gives is finite; E_s of a solid
// with itself is 0.
void compare_with_unit(int dim, const uint8_t* data, size_t size) {
  const std::string bytes(reinterpret_cast<const char*>(data), size);
  geom::Surface m;
  try {
    m = geom::read_surface_bytes(bytes, geom::MeshFormat::Obj, "fuzz.obj").surface;
  } catch (const InputError&) {
    return;
  }
  if (m.dim != dim || m.num_vertices() > 2000) return;
  const geom::Surface unit =
      dim == 2 ? geom::rectangle({0, 0}, {1, 1}) : geom::box({0, 0, 0}, {1, 1, 1}, {1, 1, 1});
  for (const bool fuzzed_first : {true, false}) {
    try {
      const experiment::Comparison c =
          fuzzed_first ? experiment::compare_surfaces(m, unit, nullptr, "fuzz.obj", "unit")
                       : experiment::compare_surfaces(unit, m, nullptr, "unit", "fuzz.obj");
      if (c.surface_error) {
        require(std::isfinite(*c.surface_error) && *c.surface_error >= -1e-9,
                "E_s is finite and not negative");
        require(std::isfinite(*c.reference_measure) && *c.reference_measure > 0.0,
                "|M| is positive");
      } else {
        require(dim == 3 && !c.surface_error_missing.empty(), "a missing E_s says why (3D only)");
      }
      if (c.distances)
        require(std::isfinite(c.distances->mean) && std::isfinite(c.distances->largest) &&
                    c.distances->largest >= 0.0,
                "distances are finite");
    } catch (const InputError&) {
    }
  }
}

}  // namespace

const std::vector<Target>& targets() {
  using geom::MeshFormat;
  static const std::vector<Target> all = {
      {"obj", ".obj",
       [](const uint8_t* d, size_t n) { read_mesh(MeshFormat::Obj, "fuzz.obj", d, n); }},
      {"off", ".off",
       [](const uint8_t* d, size_t n) { read_mesh(MeshFormat::Off, "fuzz.off", d, n); }},
      {"stl_ascii", ".stl",
       [](const uint8_t* d, size_t n) { read_mesh(MeshFormat::Stl, "fuzz.stl", d, n); }},
      {"stl_binary", ".stl",
       [](const uint8_t* d, size_t n) { read_mesh(MeshFormat::Stl, "fuzz.stl", d, n); }},
      {"ply_ascii", ".ply",
       [](const uint8_t* d, size_t n) { read_mesh(MeshFormat::Ply, "fuzz.ply", d, n); }},
      {"ply_binary", ".ply",
       [](const uint8_t* d, size_t n) { read_mesh(MeshFormat::Ply, "fuzz.ply", d, n); }},
      {"experiment", ".json", read_experiment},
      {"model_setup", ".json", build_and_run},
      {"fit_section", ".json", set_up_fit},
      {"compare_2d", ".obj", [](const uint8_t* d, size_t n) { compare_with_unit(2, d, n); }},
      {"compare_3d", ".obj", [](const uint8_t* d, size_t n) { compare_with_unit(3, d, n); }},
      {"material_test", ".csv", read_material_test},
  };
  return all;
}

const Target* find_target(const std::string& name) {
  for (const Target& t : targets())
    if (name == t.name) return &t;
  return nullptr;
}

}  // namespace fiberfluid::fuzz

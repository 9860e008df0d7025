// SPDX-License-Identifier: GPL-3.0-or-later
#include "fiberfluid/experiment/experiment.hpp"

#include <algorithm>
#include <fstream>
#include <stdexcept>
#include <string>
#include <utility>

#include "fiberfluid/experiment/run/case_builder.hpp"
#include "fiberfluid/experiment/write/output_folder.hpp"
#include "fiberfluid/util/error.hpp"

namespace fiberfluid::experiment {

using nlohmann::json;

void require_built(const Experiment& experiment) {
  if (!experiment.built())
    throw std::logic_error("experiment " + experiment.name +
                           " is not built: call build_experiment after read_experiment (or "
                           "parse_experiment, load_experiment)");
}

namespace {

// Each specimen's file, read and built; its errors name it.
void build_calibration(CalibrationStudy& study, std::vector<std::string>& warnings) {
  study.specimens.clear();
  for (const SpecimenSpec& s : study.spec.specimens) {
    // A specimen is a simulation, never a calibration (which could list itself).
    static thread_local bool inside_calibration = false;
    if (inside_calibration)
      throw InputError(s.file.string() +
                       ": a specimen of a calibration is a simulation with "
                       "a \"fit\" section, not a calibration");
    inside_calibration = true;
    Experiment specimen;
    try {
      specimen = load_experiment(s.file);
    } catch (...) {
      inside_calibration = false;
      throw;
    }
    inside_calibration = false;
    if (!specimen.fit())
      s.field.fail("experiment", s.file.string() +
                                     " has no \"fit\" section: a specimen "
                                     "brings its targets and parameters");
    for (const std::string& w : specimen.warnings) warnings.push_back(s.name + ": " + w);
    study.specimens.push_back(std::move(specimen));
  }
}

// Every case, a sweep's variants on one surface pruned once.
void build_simulation(Simulation& sim, const geom::Surface* surface,
                      std::vector<std::string>& warnings) {
  sim.cases.clear();
  for (const CaseSpec& spec : sim.specs) {
    const auto same = std::find_if(sim.specs.begin(), sim.specs.end(), [&](const CaseSpec& s) {
      return s.surface_key == spec.surface_key;
    });
    const size_t earlier = static_cast<size_t>(same - sim.specs.begin());
    if (earlier < sim.cases.size())
      sim.cases.push_back(build_case(spec, sim.cases[earlier]));
    else if (surface != nullptr)
      sim.cases.push_back(build_case(spec, *surface, &warnings));
    else
      sim.cases.push_back(build_case(spec, &warnings));
    for (const std::string& note : sim.cases.back().notes)
      warnings.push_back(spec.variant.empty() ? note : spec.variant + ": " + note);
  }
}

}  // namespace

void build_experiment(Experiment& ex, const geom::Surface* surface) {
  switch (ex.kind()) {
    case Experiment::Kind::Simulate:
      build_simulation(ex.simulation(), surface, ex.warnings);
      break;
    case Experiment::Kind::Areas: {
      AreaStudy& areas = ex.areas();
      areas.surfaces.clear();
      for (const NamedSurfaceSpec& named : areas.specs)
        areas.surfaces.push_back({named.name, build_surface(named.surface, &ex.warnings)});
      break;
    }
    case Experiment::Kind::Calibration:
      build_calibration(ex.calibration(), ex.warnings);
      break;
    case Experiment::Kind::Benchmark:
      break;  // its scene is built when it runs
  }
}

Experiment parse_experiment(const json& document, const std::filesystem::path& folder,
                            const std::string& label) {
  Experiment ex = read_experiment(document, folder, label);
  build_experiment(ex);
  return ex;
}

Experiment load_experiment(const std::filesystem::path& path) {
  std::ifstream in(path);
  if (!in) throw InputError(path.string() + ": cannot open the experiment file");
  json document = parse_json(in, path.string());
  if (document.is_object() && !document.contains("name"))
    document["name"] = folder_name_from(path.stem().string());
  Experiment ex = parse_experiment(document, path.parent_path(), path.string());
  ex.source = path;
  return ex;
}

}  // namespace fiberfluid::experiment

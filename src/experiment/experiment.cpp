// SPDX-License-Identifier: GPL-3.0-or-later
#include "fiberfluid/experiment/experiment.hpp"

#include <algorithm>
#include <cstdint>
#include <fstream>
#include <functional>
#include <iterator>
#include <stdexcept>
#include <string>
#include <system_error>
#include <utility>

#include "fiberfluid/bridge/fem_bridge.hpp"
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

// Every file a resolved experiment names: the readers resolve each file they
// will read (a mesh, a fit's targets and force curves, a material test, a
// specimen, start_from) to an absolute path, so these are the strings that
// name an existing regular file by an absolute path.
void for_each_named_file(const json& node,
                         const std::function<void(const std::filesystem::path&)>& visit) {
  if (node.is_object() || node.is_array()) {
    for (const json& child : node) for_each_named_file(child, visit);
  } else if (node.is_string()) {
    const std::filesystem::path path(node.get<std::string>());
    std::error_code error;
    if (path.is_absolute() && std::filesystem::is_regular_file(path, error)) visit(path);
  }
}

}  // namespace

void build_experiment(Experiment& ex, const geom::Surface* surface) {
  switch (ex.kind()) {
    case Experiment::Kind::Simulate:
      build_simulation(ex.simulation(), surface, ex.warnings);
      // A FEM reference that cannot be posed is refused now, not after the run.
      if (ex.simulation().fem_reference && !ex.simulation().cases.empty())
        if (const Status posable = bridge::check_fem_posable(ex.simulation().cases.front().model);
            !posable.ok)
          throw InputError((ex.source.empty() ? ex.name : ex.source.string()) +
                           ": fem_reference: " + posable.message);
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

std::string experiment_digest(const Experiment& ex) {
  std::uint64_t hash = 14695981039346656037ull;
  const auto add = [&hash](const void* data, size_t size) {
    const auto* bytes = static_cast<const unsigned char*>(data);
    for (size_t k = 0; k < size; ++k) hash = (hash ^ bytes[k]) * 1099511628211ull;
  };
  const auto add_file = [&](const std::filesystem::path& path) {
    std::ifstream in(path, std::ios::binary);
    const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    const std::string marker = in.bad() ? "unreadable" : "";
    add(marker.data(), marker.size());
    add(bytes.data(), bytes.size());
  };
  const auto add_experiment = [&](const Experiment& e) {
    const std::string resolved = e.resolved.dump();
    add(resolved.data(), resolved.size());
    for_each_named_file(e.resolved, add_file);
    if (e.kind() != Experiment::Kind::Simulate) return;
    for (const Case& c : e.simulation().cases) {
      add(c.model.surface.V.data(), sizeof(double) * static_cast<size_t>(c.model.surface.V.size()));
      add(c.model.surface.F.data(), sizeof(int) * static_cast<size_t>(c.model.surface.F.size()));
    }
  };
  add_experiment(ex);
  if (ex.kind() == Experiment::Kind::Calibration)
    for (const Experiment& specimen : ex.calibration().specimens) add_experiment(specimen);
  return std::to_string(hash);
}

}  // namespace fiberfluid::experiment

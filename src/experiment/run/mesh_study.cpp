// SPDX-License-Identifier: GPL-3.0-or-later
#include "fiberfluid/experiment/run/mesh_study.hpp"

#include <chrono>
#include <cmath>
#include <fstream>
#include <limits>
#include <map>
#include <sstream>

#include "fiberfluid/experiment/experiment.hpp"
#include "fiberfluid/experiment/run/runner.hpp"
#include "fiberfluid/util/error.hpp"

namespace fiberfluid::experiment {
namespace {

using json = nlohmann::json;

[[noreturn]] void refuse(const std::string& field, const std::string& why) {
  throw InputError("mesh study: " + field + ": " + why);
}

std::string list(const json& values) {
  std::ostringstream out;
  out << '[';
  for (size_t k = 0; k < values.size(); ++k) out << (k ? ", " : "") << values[k].dump();
  out << ']';
  return out.str();
}

json refined_surface(json document, double factor, std::string* resolution, double* actual_factor) {
  if (!document.contains("surface") || !document["surface"].is_object())
    refuse("surface", "the experiment has no surface to refine");
  json& surface = document["surface"];
  if (surface.contains("remesh_vertices")) {
    // Remeshing comes last (a file's or a generator's surface remeshed): its
    // vertex count is the resolution, whatever made the surface. A surface's
    // vertices grow as the square of the refinement.
    const double vertices = surface["remesh_vertices"].get<double>();
    const long refined = std::lround(vertices * factor * factor);
    surface["remesh_vertices"] = refined;
    *actual_factor = std::sqrt(static_cast<double>(refined) / vertices);
    *resolution = "remesh_vertices " + std::to_string(refined);
  } else if (surface.contains("segments")) {
    json& segments = surface["segments"];
    if (!segments.is_array() || segments.empty() || !segments[0].is_number_integer())
      refuse("surface.segments", "expected a list of counts");
    const double first = segments[0].get<double>();
    for (json& s : segments)
      s = std::max(1, static_cast<int>(std::lround(s.get<double>() * factor)));
    *actual_factor = segments[0].get<double>() / first;
    *resolution = "segments " + list(segments);
  } else if (surface.contains("subdivisions")) {
    // Each subdivision halves the edges: the factor rounded to a power of 2.
    const int more = static_cast<int>(std::lround(std::log2(factor)));
    if (std::abs(std::log2(factor) - more) > 1e-9)
      refuse("surface.subdivisions", "refines by factors of 2: use a ratio of 2");
    surface["subdivisions"] = surface["subdivisions"].get<int>() + more;
    *actual_factor = std::pow(2.0, more);
    *resolution = "subdivisions " + surface["subdivisions"].dump();
  } else {
    refuse("surface",
           "expected the resolution to refine written out: a generator's "
           "\"segments\" or \"subdivisions\", or \"remesh_vertices\"");
  }
  return document;
}

json refined_fem(json document, double factor, std::string* resolution, double* actual_factor) {
  if (!document.contains("fem_reference") || !document["fem_reference"].contains("size") ||
      !document["fem_reference"]["size"].is_number() ||
      !(document["fem_reference"]["size"].get<double>() > 0.0))
    refuse("fem_reference.size", "expected the element size to refine written out (m)");
  const double size = document["fem_reference"]["size"].get<double>() / factor;
  document["fem_reference"]["size"] = size;
  *actual_factor = factor;
  std::ostringstream text;
  text << "size " << size;
  *resolution = text.str();
  return document;
}

}  // namespace

json refined_document(const json& document, StudiedMesh mesh, double factor,
                      std::string* resolution, double* actual_factor) {
  return mesh == StudiedMesh::Surface ? refined_surface(document, factor, resolution, actual_factor)
                                      : refined_fem(document, factor, resolution, actual_factor);
}

MeshStudy run_mesh_study(const std::filesystem::path& experiment_file, const MeshStudySpec& spec,
                         const std::function<void(const std::string&)>& progress) {
  if (spec.levels < 3) throw InputError("mesh study: expected at least 3 levels");
  if (!(spec.ratio > 1.0)) throw InputError("mesh study: expected a refinement ratio above 1");
  std::ifstream in(experiment_file);
  if (!in) throw InputError(experiment_file.string() + ": cannot be read");
  const json document = parse_json(in, experiment_file.string());
  const std::filesystem::path folder = experiment_file.parent_path();
  MeshStudy study;
  study.experiment = experiment_file.string();
  study.mesh = spec.mesh;
  std::vector<std::map<std::string, double>> figures;
  for (int level = 0; level < spec.levels; ++level) {
    std::string resolution;
    double factor = 1.0;
    const json refined =
        refined_document(document, spec.mesh, std::pow(spec.ratio, level), &resolution, &factor);
    const std::string label = experiment_file.string() + " [mesh study level " +
                              std::to_string(level + 1) + ", " + resolution + "]";
    if (progress)
      progress("level " + std::to_string(level + 1) + " of " + std::to_string(spec.levels) + ": " +
               resolution);
    const auto start = std::chrono::steady_clock::now();
    const Experiment ex = parse_experiment(refined, folder, label);
    const ExperimentResult result = run_experiment(ex);
    if (!result.runs_succeeded() || !result.failure.empty())
      throw InputError(label + ": the run failed" +
                       (result.failure.empty() ? "" : ": " + result.failure));
    study.resolutions.push_back(resolution);
    study.sizes.push_back(1.0 / factor);
    study.seconds.push_back(
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
    figures.push_back(result.figures);
  }
  std::vector<std::string> names = spec.figures;
  if (names.empty())
    for (const auto& [name, value] : figures.front()) names.push_back(name);
  for (const std::string& name : names) {
    StudiedFigure f;
    f.name = name;
    for (const auto& level : figures) {
      const auto it = level.find(name);
      if (it == level.end()) break;
      f.values.push_back(it->second);
    }
    if (f.values.size() != figures.size()) {
      if (!spec.figures.empty())
        throw InputError("mesh study: figure \"" + name + "\" is not among the runs' figures");
      continue;  // a figure some level lacks (a paddle's contact count, say)
    }
    const size_t n = f.values.size();
    f.estimate = richardson(f.values[n - 3], f.values[n - 2], f.values[n - 1], study.sizes[n - 3],
                            study.sizes[n - 2], study.sizes[n - 1]);
    study.figures.push_back(std::move(f));
  }
  return study;
}

std::string mesh_study_csv(const MeshStudy& study) {
  std::ostringstream out;
  out.precision(10);
  out << "figure,level,resolution,relative_size,value\n";
  for (const StudiedFigure& f : study.figures)
    for (size_t k = 0; k < f.values.size(); ++k)
      out << f.name << ',' << k + 1 << ",\"" << study.resolutions[k] << "\"," << study.sizes[k]
          << ',' << f.values[k] << '\n';
  return out.str();
}

json mesh_study_json(const MeshStudy& study) {
  json figures = json::object();
  for (const StudiedFigure& f : study.figures) {
    const RichardsonEstimate& e = f.estimate;
    figures[f.name] = {{"values", f.values},
                       {"monotone", e.monotone},
                       {"observed_order", std::isfinite(e.order) ? json(e.order) : json(nullptr)},
                       {"extrapolated", e.extrapolated},
                       {"error_estimate", e.error},
                       {"gci_relative", e.gci}};
  }
  return {{"experiment", study.experiment},
          {"refined", study.mesh == StudiedMesh::Surface ? "surface" : "fem_reference"},
          {"resolutions", study.resolutions},
          {"relative_sizes", study.sizes},
          {"seconds", study.seconds},
          {"figures", figures}};
}

}  // namespace fiberfluid::experiment

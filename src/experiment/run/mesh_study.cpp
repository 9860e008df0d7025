// SPDX-License-Identifier: GPL-3.0-or-later
#include "fiberfluid/experiment/run/mesh_study.hpp"

#include <algorithm>
#include <cctype>
#include <chrono>
#include <cmath>
#include <fstream>
#include <limits>
#include <map>
#include <sstream>

#include "fiberfluid/experiment/experiment.hpp"
#include "fiberfluid/experiment/run/case_builder.hpp"
#include "fiberfluid/experiment/run/runner.hpp"
#include "fiberfluid/experiment/spec/figures.hpp"
#include "fiberfluid/geom/area_vectors.hpp"
#include "fiberfluid/geom/surface.hpp"
#include "fiberfluid/util/error.hpp"
#include "fiberfluid/util/run_control.hpp"

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

namespace {

// One level as planned before anything runs: its document (indices mapped to
// its own vertices), its resolution and its surface's element size.
struct PlannedLevel {
  json document;
  std::string resolution, label;
  double size = 1.0;                         // relative to the coarsest
  std::map<std::string, std::string> names;  // a studied figure's name at this level
};

// The mean element size of a surface (Celik et al. 2008, eq. 1 for a 2D
// grid: the square root of the area per face; the length per segment in 2D).
double element_size(const geom::Surface& s) {
  const double per_face = geom::surface_area(s.V, s.F) / std::max(1, s.num_faces());
  return s.dim == 3 ? std::sqrt(per_face) : per_face;
}

// "/loads/0/vertex" as "loads[0].vertex".
std::string field_of(const json::json_pointer& at) {
  std::string out;
  std::istringstream tokens(at.to_string().substr(1));
  for (std::string token; std::getline(tokens, token, '/');) {
    const bool index = !token.empty() && std::all_of(token.begin(), token.end(), ::isdigit);
    out += index ? "[" + token + "]" : (out.empty() ? "" : ".") + token;
  }
  return out;
}

// Every input-vertex index the document names: a point load's or a marker's
// "vertex", a selection's "vertices". Not inside a surface (its own
// numbers) or the fit section (a study does not fit).
void collect_vertex_indices(const json& node, const json::json_pointer& at, bool with_fit,
                            std::vector<json::json_pointer>* out) {
  if (node.is_object()) {
    for (auto it = node.begin(); it != node.end(); ++it) {
      if (it.key() == "surface" ||
          (at.empty() && ((it.key() == "fit" && !with_fit) || it.key() == "expected")))
        continue;
      const json::json_pointer child = at / it.key();
      if (it.key() == "vertex" && it->is_number_integer()) {
        out->push_back(child);
      } else if (it.key() == "vertices" && it->is_array()) {
        for (size_t k = 0; k < it->size(); ++k)
          if ((*it)[k].is_number_integer()) out->push_back(child / k);
      } else {
        collect_vertex_indices(*it, child, with_fit, out);
      }
    }
  } else if (node.is_array()) {
    for (size_t k = 0; k < node.size(); ++k) collect_vertex_indices(node[k], at / k, with_fit, out);
  }
}

// The vertex of `other` at `given`'s vertex `index`: the same point to
// rounding, or InputError naming the field. An index names another point on
// another mesh, so a load, a support or a figure would move. `what` names
// the other mesh ("level 3 (segments [9, 5, 5])").
int same_point(const geom::Surface& given, const geom::Surface& other, long index,
               const std::string& field, const std::string& what) {
  if (index < 0 || index >= given.num_vertices())
    return static_cast<int>(index);  // its reader says
  const Eigen::VectorXd p = given.V.row(index).transpose();
  const double tolerance = 1e-9 * geom::bounding_box_diagonal(given.V);
  int nearest = -1;
  double best = std::numeric_limits<double>::infinity();
  for (int k = 0; k < other.num_vertices(); ++k) {
    const double d = (other.V.row(k).transpose() - p).norm();
    if (d < best) best = d, nearest = k;
  }
  if (best <= tolerance) return nearest;
  std::ostringstream at;
  at << '(';
  for (int a = 0; a < p.size(); ++a) at << (a ? ", " : "") << p[a];
  at << ')';
  throw InputError(field + ": input vertex " + std::to_string(index) + " at " + at.str() +
                   " is no vertex of " + what +
                   ": an index names another point on another mesh. Select a region by "
                   "\"where\" or \"box\" (the same on every mesh), or refine by a ratio that "
                   "keeps the coarse vertices (2 for a generator's segments)");
}

// A vertex figure ("position.12.z", a variant's "v1.displacement.3.x"): the
// offset of its index in the name, and the index; npos when it is none.
size_t vertex_figure_index(const std::string& name, long* index) {
  for (const std::string prefix : {"position.", "displacement."}) {
    const size_t at = name.rfind(prefix);
    if (at == std::string::npos || (at > 0 && name[at - 1] != '.')) continue;
    const size_t begin = at + prefix.size(), dot = name.find('.', begin);
    if (dot == std::string::npos || dot == begin || dot + 2 != name.size()) continue;
    const std::string digits = name.substr(begin, dot - begin);
    if (!std::all_of(digits.begin(), digits.end(), ::isdigit) || digits.size() > 9) continue;
    *index = std::stol(digits);
    return begin;
  }
  return std::string::npos;
}

// Every level's counts of a generator's segments grow: rounding that leaves a
// count as it was refines the mesh along some directions only, and a study
// of it is no refinement (Celik's h assumes all directions refined).
void check_every_count_grows(const std::vector<PlannedLevel>& levels, double ratio) {
  for (size_t k = 1; k < levels.size(); ++k) {
    if (levels[k].resolution == levels[k - 1].resolution) {
      std::ostringstream text;
      text << "a ratio of " << ratio << " leaves level " << k + 1 << " as level " << k << " ("
           << levels[k].resolution << "): two equal levels would give an error of 0; use a larger "
           << "ratio";
      refuse("--ratio", text.str());
    }
    const json& before = levels[k - 1].document["surface"];
    const json& after = levels[k].document["surface"];
    if (!after.contains("segments") || after.contains("remesh_vertices")) continue;
    for (size_t a = 0; a < after["segments"].size(); ++a)
      if (after["segments"][a].get<int>() <= before["segments"][a].get<int>()) {
        // The least ratio whose every level refines every count.
        double least = ratio;
        const auto grows = [&](double r) {
          const json& first = levels[0].document["surface"]["segments"];
          for (size_t level = 1; level < levels.size(); ++level)
            for (const json& count : first)
              if (std::lround(count.get<double>() * std::pow(r, level)) <=
                  std::lround(count.get<double>() * std::pow(r, level - 1)))
                return false;
          return true;
        };
        while (least < 4.0 && !grows(least)) least += 0.01;
        std::ostringstream text;
        text << "a ratio of " << ratio << " refines " << levels[k - 1].resolution << " to "
             << levels[k].resolution << " at level " << k + 1
             << ", leaving a count as it was: the mesh would be refined along some directions "
                "only. Use a ratio of at least "
             << least;
        refuse("surface.segments", text.str());
      }
  }
}

// The levels' documents, resolutions and sizes, every vertex index mapped to
// the same point of each level, before any level runs.
std::vector<PlannedLevel> plan_levels(const json& document, const std::filesystem::path& folder,
                                      const std::string& file, const MeshStudySpec& spec) {
  std::vector<PlannedLevel> levels(spec.levels);
  std::vector<geom::Surface> surfaces;
  std::vector<double> sizes;
  for (int k = 0; k < spec.levels; ++k) {
    PlannedLevel& level = levels[k];
    double factor = 1.0;
    level.document =
        refined_document(document, spec.mesh, std::pow(spec.ratio, k), &level.resolution, &factor);
    level.label =
        file + " [mesh study level " + std::to_string(k + 1) + ", " + level.resolution + "]";
    if (spec.mesh == StudiedMesh::FemReference) {
      level.size = 1.0 / factor;
      continue;
    }
    surfaces.push_back(surface_of(level.document, folder, level.label));
    sizes.push_back(element_size(surfaces.back()));
    level.size = sizes.back() / sizes.front();
  }
  if (spec.mesh == StudiedMesh::Surface) check_every_count_grows(levels, spec.ratio);
  // Figures checked on the coarsest level's experiment, before it runs.
  const Experiment coarsest = read_experiment(levels[0].document, folder, levels[0].label);
  for (const std::string& name : spec.figures) {
    if (name.rfind("fit.", 0) == 0)
      refuse("--figure", "\"" + name + "\": a study runs the experiment, not its fit");
    if (const Status known = check_figure(coarsest, name, /*fit_figures=*/true); !known.ok)
      refuse("--figure", known.message);
  }
  if (spec.mesh == StudiedMesh::FemReference) {
    for (PlannedLevel& level : levels)
      for (const std::string& name : spec.figures) level.names[name] = name;
    return levels;
  }
  for (int k = 1; k < spec.levels; ++k) {
    PlannedLevel& level = levels[k];
    const std::string what = "level " + std::to_string(k + 1) + " (" + level.resolution + ")";
    level.document = with_same_vertices(document, surfaces[0], level.document, surfaces[k], what,
                                        /*with_fit=*/false);
  }
  for (int k = 0; k < spec.levels; ++k) {
    PlannedLevel& level = levels[k];
    const std::string what = "level " + std::to_string(k + 1) + " (" + level.resolution + ")";
    for (const std::string& name : spec.figures) {
      long index = 0;
      const size_t begin = vertex_figure_index(name, &index);
      if (begin == std::string::npos) {
        level.names[name] = name;
        continue;
      }
      if (index >= surfaces[0].num_vertices())
        refuse("--figure", "\"" + name + "\": the surface has " +
                               std::to_string(surfaces[0].num_vertices()) + " vertices");
      const int mapped = same_point(surfaces[0], surfaces[k], index, "--figure " + name, what);
      level.names[name] =
          name.substr(0, begin) + std::to_string(mapped) + name.substr(name.find('.', begin));
    }
  }
  return levels;
}

// A level's figures: the run's, and the vertex figures asked for.
std::map<std::string, double> level_figures(const Experiment& ex, const ExperimentResult& result,
                                            const PlannedLevel& level) {
  std::map<std::string, double> figures = result.figures;
  const Simulation& sim = ex.simulation();
  for (const auto& [name, here] : level.names) {
    if (figures.count(here)) {
      figures[name] = figures[here];
      continue;
    }
    for (size_t r = 0; r < sim.cases.size(); ++r) {
      const std::string prefix = sim.specs[r].variant.empty() ? "" : sim.specs[r].variant + ".";
      if (here.rfind(prefix, 0) != 0 || !result.runs[r].summary.success) continue;
      if (const auto value = run_figure(sim.cases[r], result.runs[r], here.substr(prefix.size())))
        figures[name] = *value;
    }
  }
  return figures;
}

}  // namespace

json with_same_vertices(const json& document, const geom::Surface& surface, json other,
                        const geom::Surface& other_surface, const std::string& what,
                        bool with_fit) {
  std::vector<json::json_pointer> indices;
  collect_vertex_indices(document, json::json_pointer(), with_fit, &indices);
  for (const json::json_pointer& at : indices)
    other[at] = same_point(surface, other_surface, document[at].get<long>(), field_of(at), what);
  return other;
}

geom::Surface surface_of(const json& document, const std::filesystem::path& folder,
                         const std::string& label) {
  const Experiment unbuilt = read_experiment(document, folder, label);
  if (unbuilt.kind() != Experiment::Kind::Simulate)
    throw InputError(label + ": kind: expected a simulation, whose surface can be refined");
  std::vector<std::string> warnings;
  return build_surface(unbuilt.simulation().specs.front().surface, &warnings);
}

MeshStudy run_mesh_study(const std::filesystem::path& experiment_file, const MeshStudySpec& spec,
                         const std::function<void(const std::string&)>& progress) {
  if (spec.levels < 3) throw InputError("mesh study: expected at least 3 levels");
  if (!(spec.ratio > 1.0) || !std::isfinite(spec.ratio))
    throw InputError("mesh study: expected a refinement ratio above 1");
  std::ifstream in(experiment_file);
  if (!in || std::filesystem::is_directory(experiment_file))
    throw InputError(experiment_file.string() + ": cannot be read");
  const json document = parse_json(in, experiment_file.string());
  const std::filesystem::path folder = experiment_file.parent_path();
  const std::vector<PlannedLevel> levels =
      plan_levels(document, folder, experiment_file.string(), spec);
  MeshStudy study;
  study.experiment = experiment_file.string();
  study.mesh = spec.mesh;
  study.planned_levels = spec.levels;
  std::vector<std::map<std::string, double>> figures;
  for (int k = 0; k < spec.levels; ++k) {
    const PlannedLevel& level = levels[k];
    if (progress)
      progress("level " + std::to_string(k + 1) + " of " + std::to_string(spec.levels) + ": " +
               level.resolution);
    const auto start = std::chrono::steady_clock::now();
    std::string failure;
    try {
      const Experiment ex = parse_experiment(level.document, folder, level.label);
      throw_if_cancelled("the mesh study");
      const ExperimentResult result = run_experiment(ex);
      throw_if_cancelled("the mesh study");
      if (!result.failure.empty()) failure = result.failure;
      for (const RunResult& run : result.runs)
        if (!run.summary.success && failure.empty())
          failure = (run.variant.empty() ? "" : run.variant + ": ") + run.summary.message;
      if (failure.empty()) figures.push_back(level_figures(ex, result, level));
    } catch (const Interrupted&) {
      throw;  // Ctrl-C: nothing is written, as for a run
    } catch (const std::exception& e) {
      if (k == 0 && dynamic_cast<const InputError*>(&e)) throw;  // bad input: nothing ran
      failure = e.what();
    }
    if (!failure.empty()) {
      // The levels before it are kept (DIR.failed): minutes of work.
      study.failure = failure.rfind(level.label, 0) == 0 ? failure : level.label + ": " + failure;
      break;
    }
    study.resolutions.push_back(level.resolution);
    study.sizes.push_back(level.size);
    study.seconds.push_back(
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
  }
  if (figures.empty()) return study;
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
      // A figure some level lacks (a paddle's contact count, an optional
      // figure asked for): said, and the levels' work kept.
      if (!spec.figures.empty())
        study.warnings.push_back("figure \"" + name + "\" is not given by every level's run");
      continue;
    }
    f.estimated = f.values.size() >= 3;  // a study cut short has no order
    if (f.estimated) f.estimate = richardson(f.values, study.sizes);
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
  const auto number = [](double v) { return std::isfinite(v) ? json(v) : json(nullptr); };
  json figures = json::object();
  for (const StudiedFigure& f : study.figures) {
    const RichardsonEstimate& e = f.estimate;
    if (!f.estimated) {  // fewer than three levels ran
      figures[f.name] = {{"values", f.values}, {"trend", nullptr}};
      continue;
    }
    figures[f.name] = {{"values", f.values},
                       {"trend", metrics::trend_name(e.trend)},
                       {"monotone", e.monotone},
                       {"observed_order", number(e.order)},
                       {"extrapolated", number(e.extrapolated)},
                       {"error_estimate", number(e.error)},
                       {"gci_relative", number(e.gci)}};
  }
  json out = {{"experiment", study.experiment},
              {"refined", study.mesh == StudiedMesh::Surface ? "surface" : "fem_reference"},
              {"levels", study.planned_levels},
              {"levels_run", study.resolutions.size()},
              {"resolutions", study.resolutions},
              {"relative_sizes", study.sizes},
              {"seconds", study.seconds},
              {"figures", figures}};
  if (!study.failure.empty()) out["failure"] = study.failure;
  if (!study.warnings.empty()) out["warnings"] = study.warnings;
  return out;
}

}  // namespace fiberfluid::experiment

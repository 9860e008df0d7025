// SPDX-License-Identifier: GPL-3.0-or-later
#include "app/outputs.hpp"

#include <cstdio>

#include "geom/area_vectors.hpp"
#include "geom/mesh_io.hpp"
#include "geom/vtk_writer.hpp"
#include "model/assembly.hpp"

namespace fiberfluid::app {
namespace {

using nlohmann::json;

json stepping_json(const solve::SteppingOptions& s) {
  return {{"steps", s.steps},
          {"rebuild_matrix", s.rebuild_matrix},
          {"update_load_geometry", s.update_load_geometry},
          {"boundary_method", model::to_string(s.boundary_method)},
          {"penalty", s.penalty},
          {"solver", solve::to_string(s.solver)},
          {"tolerance", s.pcg.tolerance},
          {"max_iterations", s.pcg.max_iterations}};
}

json run_json(const Experiment& ex, const ExperimentResult& result, const RunResult& run) {
  json steps = json::array();
  for (const solve::StepRecord& r : run.summary.steps) {
    json factors = json::object();
    for (size_t l = 0; l < ex.model.loads.size(); ++l)
      factors[ex.model.loads[l].label] = r.load_factors[l];
    steps.push_back({{"step", r.step},
                     {"load_factors", factors},
                     {"pressure", r.pressure},
                     {"volume", r.volume},
                     {"max_displacement", r.max_displacement},
                     {"seconds", r.seconds}});
  }
  json final_figures = json::object();
  const std::string prefix = run.variant.empty() ? "" : run.variant + ".";
  for (const auto& [name, value] : result.figures)
    if (name.rfind(prefix, 0) == 0) final_figures[name.substr(prefix.size())] = value;
  return {{"variant", run.variant},
          {"solver", solve::to_string(run.summary.solver)},
          {"pcg_iterations", run.summary.solver_statistics.iterations},
          {"factorization_flops", run.summary.solver_statistics.factorization_flops},
          {"stepping", stepping_json(run.stepping)},
          {"success", run.summary.success},
          {"message", run.summary.message},
          {"factorizations", run.summary.factorizations},
          {"seconds", {{"assemble", run.summary.assemble_seconds},
                       {"factorize", run.summary.factorize_seconds},
                       {"solve", run.summary.solve_seconds},
                       {"total", run.summary.total_seconds}}},
          {"steps", steps},
          {"final", final_figures}};
}

}  // namespace

json summary_json(const Experiment& ex, const ExperimentResult& result) {
  json doc;
  doc["experiment"] = ex.name;
  doc["description"] = ex.description;
  doc["source"] = ex.source.string();
  doc["fiberfluid_version"] = FIBERFLUID_VERSION;
  doc["kind"] = ex.kind == Experiment::Kind::Areas ? "areas" : "simulate";
  if (ex.kind == Experiment::Kind::Simulate) {
    doc["surface"] = {{"dimension", ex.input_surface.dim},
                      {"vertices", ex.input_surface.num_vertices()},
                      {"used_vertices", ex.model.num_vertices()},
                      {"faces", ex.input_surface.num_faces()}};
    const FiberReport& f = ex.fibers;
    doc["fibers"] = {{"pruning", f.pruning ? "auto" : "off"},
                     {"convex", f.convex},
                     {"connection_count", model::to_string(ex.model.connection_count)},
                     {"in_all", f.pairs},
                     {"kept", f.kept},
                     {"pruned", f.pairs - f.kept},
                     {"kept_per_vertex", {{"min", f.min_per_vertex},
                                          {"mean", f.mean_per_vertex},
                                          {"max", f.max_per_vertex}}},
                     {"pruning_seconds", f.seconds},
                     {"exact_fallbacks", f.exact_fallbacks}};
    json runs = json::array();
    for (const RunResult& run : result.runs) runs.push_back(run_json(ex, result, run));
    doc["runs"] = runs;
  }
  doc["figures"] = result.figures;
  json checks = json::array();
  for (const FigureCheck& c : result.checks)
    checks.push_back({{"figure", c.expected.figure},
                      {"actual", c.actual},
                      {"passed", c.passed},
                      {"report", c.Describe()},
                      {"note", c.expected.note}});
  doc["checks"] = checks;
  doc["warnings"] = ex.warnings;
  return doc;
}

OutputWriter::OutputWriter(const Experiment& experiment, std::filesystem::path folder)
    : experiment_(experiment), folder_(std::move(folder)) {}

std::filesystem::path OutputWriter::run_folder(size_t run) const {
  const std::string& variant = experiment_.variants[run].name;
  return variant.empty() ? folder_ : folder_ / variant;
}

void OutputWriter::begin() {
  std::filesystem::create_directories(folder_);
  if (experiment_.kind != Experiment::Kind::Simulate) return;
  series_.assign(experiment_.variants.size(), {});
  write_fibers();
  for (size_t r = 0; r < experiment_.variants.size(); ++r) {
    if (!experiment_.output.vtk) continue;
    std::filesystem::create_directories(run_folder(r) / "vtk");
    write_state(r, 0, Eigen::VectorXd::Zero(experiment_.model.num_unknowns()));
  }
}

void OutputWriter::write_fibers() const {
  const std::string& which = experiment_.fibers.write;
  if (which == "none") return;
  const model::Model& m = experiment_.model;
  std::vector<std::pair<int, int>> lines;
  for (int i = 0; i < m.num_vertices(); ++i)
    for (int j = i + 1; j < m.num_vertices(); ++j) {
      const bool kept = !m.fibers || m.fibers->kept(i, j);
      if (kept == (which == "kept")) lines.emplace_back(i, j);
    }
  geom::write_lines_vtu(folder_ / "fibers.vtu", m.surface.V, lines);
}

void OutputWriter::write_state(size_t run, int step, const Eigen::VectorXd& unknowns) {
  const model::Model& m = experiment_.model;
  geom::Surface deformed = experiment_.input_surface;
  deformed.V = input_positions(experiment_, unknowns);
  const int n = deformed.num_vertices(), dim = deformed.dim;
  const Eigen::MatrixXd U = deformed.V - experiment_.input_surface.V;
  // Area vectors of the current geometry, zero on vertices in no face.
  Eigen::MatrixXd S = Eigen::MatrixXd::Zero(n, dim);
  const Eigen::MatrixXd model_S =
      geom::vertex_area_vectors(m.surface.V + model::displacements(m, unknowns), m.surface.F).S;
  for (size_t k = 0; k < experiment_.model_to_input.size(); ++k)
    S.row(experiment_.model_to_input[k]) = model_S.row(static_cast<Eigen::Index>(k));
  char name[32];
  std::snprintf(name, sizeof name, "step_%04d.vtu", step);
  geom::write_vtu(run_folder(run) / "vtk" / name, deformed,
                  {{"displacement", U},
                   {"displacement_magnitude", U.rowwise().norm()},
                   {"area_vector", S}});
  series_[run].emplace_back(step, std::string("vtk/") + name);
}

void OutputWriter::on_step(size_t run, const solve::StepRecord& record,
                           const Eigen::VectorXd& unknowns) {
  const bool last = record.step == experiment_.variants[run].stepping.steps;
  if (experiment_.output.vtk && (last || record.step % experiment_.output.every == 0))
    write_state(run, record.step, unknowns);
}

void OutputWriter::finish(const ExperimentResult& result) {
  for (size_t r = 0; r < result.runs.size(); ++r) {
    if (experiment_.output.vtk) geom::write_pvd(run_folder(r) / "series.pvd", series_[r]);
    if (experiment_.output.obj && result.runs[r].summary.success) {
      geom::Surface deformed = experiment_.input_surface;
      deformed.V = input_positions(experiment_, result.runs[r].summary.unknowns);
      geom::write_obj(run_folder(r) / "final.obj", deformed);
    }
  }
  geom::write_text_file(folder_ / "summary.json", summary_json(experiment_, result).dump(2) + "\n");
}

}  // namespace fiberfluid::app

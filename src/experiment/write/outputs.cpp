// SPDX-License-Identifier: GPL-3.0-or-later
#include "fiberfluid/experiment/write/outputs.hpp"

#include <algorithm>
#include <cstdio>
#include <iomanip>
#include <sstream>
#include <utility>

#include "fiberfluid/experiment/run/runner.hpp"
#include "fiberfluid/experiment/write/benchmark_files.hpp"
#include "fiberfluid/experiment/write/csv_tables.hpp"
#include "fiberfluid/experiment/write/output_folder.hpp"
#include "fiberfluid/experiment/write/summary_json.hpp"
#include "fiberfluid/fem/mesh_tools.hpp"
#include "fiberfluid/geom/area_vectors.hpp"
#include "fiberfluid/geom/mesh_io.hpp"
#include "fiberfluid/geom/vtk_writer.hpp"
#include "fiberfluid/model/assembly.hpp"
#include "fiberfluid/model/equilibrium.hpp"
#include "fiberfluid/model/held_edge.hpp"
#include "fiberfluid/util/error.hpp"

namespace fiberfluid::experiment {

namespace fs = std::filesystem;
using namespace output_files;

OutputWriter::OutputWriter(const Experiment& experiment, fs::path folder)
    : experiment_(experiment), target_(std::move(folder)), result_folder_(target_) {
  require_built(experiment_);
  check_replaceable(target_);
}

OutputWriter::~OutputWriter() { abandon(); }

void OutputWriter::abandon() noexcept {
  if (staging_.empty()) return;  // begin() never made it
  std::error_code ignored;       // finish() moved it away already
  fs::remove_all(staging_, ignored);
  staging_.clear();
}

fs::path OutputWriter::run_folder(size_t run) const {
  const std::string& variant = experiment_.simulation().cases[run].variant;
  return variant.empty() ? staging_ : staging_ / variant;
}

void OutputWriter::begin() {
  staging_ = create_staging_folder(target_, experiment_.name);
  geom::write_text_file(staging_ / kIncompleteMark,
                        "fiberfluid is writing this folder, or was stopped while it did: "
                        "these are not the results of a complete run.\n");
  if (experiment_.kind() != Experiment::Kind::Simulate) return;
  series_.assign(experiment_.simulation().cases.size(), {});
  equilibria_.clear();
  equilibria_.resize(experiment_.simulation().cases.size());  // made when a run first writes
  write_fibers();
  for (size_t r = 0; r < experiment_.simulation().cases.size(); ++r) {
    fs::create_directories(run_folder(r));
    if (!experiment_.simulation().output.vtk) continue;
    fs::create_directories(run_folder(r) / kVtk);
    const model::Model& m = experiment_.simulation().cases[r].model;
    write_state(r, 0, Eigen::VectorXd::Zero(m.num_unknowns()),
                std::vector<double>(m.loads.size(), 0.0));
  }
}

namespace {

// The fibers that fibers.write names, as pairs (i, j) of the model's
// vertices, i < j.
std::vector<std::pair<int, int>> written_fibers(const Case& c) {
  const model::Model& m = c.model;
  std::vector<std::pair<int, int>> lines;
  if (c.fibers.write == "kept" && m.fibers && m.fibers->sparse()) {  // a horizon's lists
    for (int i = 0; i < m.num_vertices(); ++i)
      m.fibers->for_each_kept(i, [&](int j) {
        if (j > i) lines.emplace_back(i, j);
      });
  } else {
    for (int i = 0; i < m.num_vertices(); ++i)
      for (int j = i + 1; j < m.num_vertices(); ++j) {
        const bool kept = !m.fibers || m.fibers->kept(i, j);
        if (kept == (c.fibers.write == "kept")) lines.emplace_back(i, j);
      }
  }
  return lines;
}

// How a file of `size` rows is stored (output.vtk_format).
geom::VtkEncoding vtk_encoding(const std::string& format, size_t size) {
  return format == "compressed" ||
                 (format == "auto" && size >= static_cast<size_t>(kCompressedVtkVertices))
             ? geom::VtkEncoding::Compressed
             : geom::VtkEncoding::Ascii;
}

// Each face's surface tension: the mean size of the forces of its edges'
// fibers (N); `edges` sorted by their ends, as Equilibrium gives them.
Eigen::VectorXd face_surface_tension(const geom::Surface& s,
                                     const std::vector<model::FiberReading>& edges) {
  const auto force_of = [&](int i, int j) {
    const std::pair<int, int> ends = std::minmax(i, j);
    const auto at = std::lower_bound(edges.begin(), edges.end(), ends,
                                     [](const model::FiberReading& e, std::pair<int, int> key) {
                                       return std::make_pair(e.i, e.j) < key;
                                     });
    return at != edges.end() && at->i == ends.first && at->j == ends.second ? at->force.norm()
                                                                            : 0.0;
  };
  Eigen::VectorXd out(s.num_faces());
  for (int f = 0; f < s.num_faces(); ++f) {
    if (s.F.cols() == 2) {  // 2D: the face is its edge
      out[f] = force_of(s.F(f, 0), s.F(f, 1));
      continue;
    }
    out[f] = (force_of(s.F(f, 0), s.F(f, 1)) + force_of(s.F(f, 1), s.F(f, 2)) +
              force_of(s.F(f, 2), s.F(f, 0))) /
             3.0;
  }
  return out;
}

}  // namespace

void OutputWriter::write_fibers() const {
  const Case& c = experiment_.simulation().cases.front();
  if (c.fibers.write == "none") return;
  const std::vector<std::pair<int, int>> lines = written_fibers(c);
  const Eigen::MatrixXd& S = c.model.surface.V;
  Eigen::VectorXd rest(static_cast<Eigen::Index>(lines.size()));
  for (size_t k = 0; k < lines.size(); ++k)
    rest[static_cast<Eigen::Index>(k)] = (S.row(lines[k].first) - S.row(lines[k].second)).norm();
  geom::VtuContent content;
  content.cells = {{"rest_length", rest}};
  content.encoding = vtk_encoding(experiment_.simulation().output.vtk_format, lines.size());
  geom::write_lines_vtu(staging_ / kFibers, S, lines, content);
}

// Made on a run's first use, by the thread that runs it (each run's slot is
// its own): a sweep whose runs write no .vtu builds none.
const model::Equilibrium& OutputWriter::equilibrium(size_t run) const {
  std::unique_ptr<const model::Equilibrium>& slot = equilibria_[run];
  if (!slot)
    slot = std::make_unique<const model::Equilibrium>(experiment_.simulation().cases[run].model);
  return *slot;
}

// RUN/fibers_final.vtu: the written fibers at the run's last state, each
// with its strain, its tension and the size of its force (the equilibrium
// equations' fiber forces, model.md section 7).
void OutputWriter::write_final_fibers(size_t run, const Eigen::VectorXd& unknowns) const {
  const Case& c = experiment_.simulation().cases[run];
  const std::vector<std::pair<int, int>> lines = written_fibers(c);
  const std::vector<model::FiberReading> readings =
      equilibrium(run).bulk_fiber_readings(unknowns, lines);
  const auto size = static_cast<Eigen::Index>(lines.size());
  Eigen::VectorXd strain(size), tension(size), force(size);
  for (Eigen::Index k = 0; k < size; ++k) {
    const model::FiberReading& f = readings[static_cast<size_t>(k)];
    strain[k] = f.strain;
    tension[k] = f.tension;
    force[k] = f.force.norm();
  }
  geom::VtuContent content;
  content.cells = {{"strain", strain}, {"tension", tension}, {"force", force}};
  content.encoding = vtk_encoding(experiment_.simulation().output.vtk_format, lines.size());
  geom::write_lines_vtu(run_folder(run) / kFibersFinal, model::positions(c.model, unknowns), lines,
                        content);
}

// One load step for ParaView: Points are the deformed positions (display the
// reference with `reference_position`, or Warp By Vector `displacement` by -1);
// point data displacement, its magnitude, the area vectors, the reference,
// the supports' reactions and the paddles' contact forces on the vertices
// they hold; cell data each face's area over its rest area; field data the step, its
// load factors (one per load, in the file's order) and the pressure.
void OutputWriter::write_state(size_t run, int step, const Eigen::VectorXd& unknowns,
                               const std::vector<double>& load_factors,
                               const std::vector<solve::StepRecord::HeldForce>& held_forces) {
  const Case& c = experiment_.simulation().cases[run];
  const model::Model& m = c.model;
  geom::Surface deformed = c.input_surface;
  deformed.V = input_positions(c, unknowns);
  const int n = deformed.num_vertices(), dim = deformed.dim;
  const Eigen::MatrixXd U = deformed.V - c.input_surface.V;
  // Area vectors of the current geometry, zero on vertices in no face.
  Eigen::MatrixXd S = Eigen::MatrixXd::Zero(n, dim);
  const Eigen::MatrixXd model_S =
      geom::vertex_area_vectors(m.surface.V + model::displacements(m, unknowns), m.surface.F).S;
  for (size_t k = 0; k < c.model_to_input.size(); ++k)
    S.row(c.model_to_input[k]) = model_S.row(static_cast<Eigen::Index>(k));
  const Eigen::VectorXd
      rest = geom::face_area_vectors(c.input_surface.V, c.input_surface.F).rowwise().norm(),
      now = geom::face_area_vectors(deformed.V, deformed.F).rowwise().norm();
  // The supports' and the paddles' forces on the vertices they hold.
  Eigen::MatrixXd support = Eigen::MatrixXd::Zero(n, dim), contact = support;
  for (const solve::StepRecord::HeldForce& h : held_forces) {
    Eigen::MatrixXd& to = h.paddle < 0 ? support : contact;
    to.row(c.model_to_input[static_cast<size_t>(h.vertex)]) = h.force.head(dim).transpose();
  }
  geom::VtuContent content;
  content.points = {{"displacement", U},
                    {"displacement_magnitude", U.rowwise().norm()},
                    {"area_vector", S},
                    {"reference_position", c.input_surface.V},
                    {"support_reaction", support},
                    {"contact_force", contact}};
  content.cells = {
      {"area_change", now.cwiseQuotient(rest)},
      {"surface_tension_force",
       face_surface_tension(m.surface, equilibrium(run).surface_fiber_readings(unknowns))}};
  content.field = {{"step", {static_cast<double>(step)}},
                   {"load_factors", load_factors},
                   {"pressure", {unknowns[m.pressure_dof()]}}};
  content.encoding =
      vtk_encoding(experiment_.simulation().output.vtk_format, static_cast<size_t>(n));
  char name[32];
  std::snprintf(name, sizeof name, "step_%04d.vtu", step);
  geom::write_vtu(run_folder(run) / kVtk / name, deformed, content);
  series_[run].emplace_back(step, std::string(kVtk) + "/" + name);
}

void OutputWriter::on_step(size_t run, const solve::StepRecord& record,
                           const Eigen::VectorXd& unknowns) {
  const bool last = record.step == experiment_.simulation().cases[run].stepping.steps;
  if (experiment_.simulation().output.vtk &&
      (last || record.step % experiment_.simulation().output.every == 0))
    write_state(run, record.step, unknowns, record.load_factors, record.held_forces);
}

void OutputWriter::write_fem_path(const FemReferenceResult& f) {
  std::filesystem::create_directories(staging_ / kFemReferenceVtk);
  std::vector<std::pair<double, std::string>> series;
  const fem::Boundary boundary = fem::boundary(f.mesh);
  for (size_t k = 0; k < f.path.size(); ++k) {
    geom::Surface deformed = f.rest_boundary;
    Eigen::MatrixXd U(deformed.num_vertices(), 3);
    for (int v = 0; v < deformed.num_vertices(); ++v)
      U.row(v) = f.path[k].row(boundary.nodes[static_cast<size_t>(v)]);
    deformed.V += U;
    char name[32];
    std::snprintf(name, sizeof name, "step_%04zu.vtu", k + 1);
    geom::write_vtu(staging_ / kFemReferenceVtk / name, deformed,
                    {{"displacement", U}, {"displacement_magnitude", U.rowwise().norm()}});
    series.emplace_back(static_cast<double>(k + 1), std::string(kFemReferenceVtk) + "/" + name);
  }
  geom::write_pvd(staging_ / kFemReferenceSeries, series);
}

void OutputWriter::finish(const ExperimentResult& result, const FolderFiller& more) {
  for (size_t r = 0; r < result.runs.size(); ++r) {
    const Case& c = experiment_.simulation().cases[r];
    const RunResult& run = result.runs[r];
    if (experiment_.simulation().output.vtk) geom::write_pvd(run_folder(r) / kSeries, series_[r]);
    geom::write_text_file(run_folder(r) / kSteps, steps_csv(c, run));
    geom::write_text_file(run_folder(r) / kLoadDisplacement, load_displacement_csv(c, run));
    if (!run.summary.success) continue;
    geom::write_text_file(run_folder(r) / kVertices, vertices_csv(c, run));
    if (c.fibers.write != "none") write_final_fibers(r, run.summary.unknowns);
    if (experiment_.simulation().output.obj) {
      geom::Surface deformed = c.input_surface;
      deformed.V = input_positions(c, run.summary.unknowns);
      geom::write_obj(run_folder(r) / kFinal, deformed);
    }
  }
  if (experiment_.sweeps())
    geom::write_text_file(staging_ / kComparison, comparison_csv(experiment_, result));
  if (result.fem_reference) {  // the target for a fit, and the same with its displacement
    const FemReferenceResult& f = *result.fem_reference;
    geom::write_obj(staging_ / kFemReference, f.deformed_boundary);
    Eigen::MatrixXd U = f.deformed_boundary.V - f.rest_boundary.V;
    geom::write_vtu(staging_ / kFemReferenceVtu, f.deformed_boundary,
                    {{"displacement", U}, {"displacement_magnitude", U.rowwise().norm()}});
    // A nonlinear FEM's load path: its boundary after each step, a series.
    if (f.path.size() > 1) write_fem_path(f);
  }
  if (result.benchmark) {
    write_benchmark_files(staging_, experiment_.benchmark(), *result.benchmark);
  }
  geom::write_text_file(staging_ / kSummary, summary_json(experiment_, result).dump(2) + "\n");
  write_experiment_files();
  if (more) more(staging_);

  if (result.runs_succeeded() && result.failure.empty()) {
    place(target_);
    return;
  }
  std::string why = result.failure.empty() ? "" : result.failure + "\n";
  for (const RunResult& run : result.runs)
    if (!run.summary.success)
      why += (run.variant.empty() ? "" : run.variant + ": ") + run.summary.message + "\n";
  set_aside(kFailedMark, "failed", "this run failed", why);
}

// The experiment as read (experiment.json) and as resolved
// (experiment.resolved.json: `fiberfluid run` on it repeats this run). A
// surface that a program gave is written beside them (input_surface.obj,
// 17 digits), and the resolved file reads it from there.
void OutputWriter::write_experiment_files() const {
  if (experiment_.document.is_null()) return;  // built without a document
  geom::write_text_file(staging_ / kExperiment, experiment_.document.dump(2) + "\n");
  nlohmann::json resolved = experiment_.resolved;
  const bool given_surface = experiment_.kind() == Experiment::Kind::Simulate &&
                             !experiment_.simulation().cases.empty() &&
                             !resolved.contains("surface") && !resolved.contains("variants");
  if (given_surface) {
    geom::write_obj(staging_ / kInputSurface, experiment_.simulation().cases.front().input_surface);
    resolved["surface"] = {{"file", kInputSurface}};
  }
  geom::write_text_file(staging_ / kResolved, resolved.dump(2) + "\n");
}

void OutputWriter::keep_interrupted(const std::string& why, const FolderFiller& more) {
  if (more) more(staging_);
  set_aside(kInterruptedMark, "interrupted", "this run was interrupted", why + "\n");
}

void OutputWriter::set_aside(const char* mark, const char* suffix, const std::string& what,
                             const std::string& why) {
  geom::write_text_file(staging_ / mark, what + "; the last complete result (if any) is in " +
                                             target_.filename().string() + "\n" + why);
  fs::path aside = target_;
  aside += std::string(".") + suffix;
  place(aside);
}

void OutputWriter::place(const fs::path& where) {
  fs::remove(staging_ / kIncompleteMark);
  // From here on the folder is never removed: a move that fails names it.
  const fs::path staged = std::exchange(staging_, fs::path());
  move_into_place(staged, where, &warnings_);
  result_folder_ = where;
}

}  // namespace fiberfluid::experiment

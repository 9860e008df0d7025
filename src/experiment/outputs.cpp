// SPDX-License-Identifier: GPL-3.0-or-later
#include "fiberfluid/experiment/outputs.hpp"

#include <algorithm>
#include <cstdio>
#include <iomanip>
#include <sstream>
#include <utility>

#include "fiberfluid/experiment/build_info.hpp"
#include "fiberfluid/experiment/output_folder.hpp"
#include "fiberfluid/fem/mesh_tools.hpp"
#include "fiberfluid/geom/area_vectors.hpp"
#include "fiberfluid/geom/mesh_io.hpp"
#include "fiberfluid/geom/vtk_writer.hpp"
#include "fiberfluid/model/assembly.hpp"
#include "fiberfluid/model/equilibrium.hpp"
#include "fiberfluid/model/held_edge.hpp"
#include "fiberfluid/util/error.hpp"

namespace fiberfluid::experiment {
namespace {

using nlohmann::json;
namespace fs = std::filesystem;

const char kAxes[] = "xyz";

json vector_json(const Eigen::Vector3d& v, int dim) {
  json out = json::array();
  for (int a = 0; a < dim; ++a) out.push_back(v[a]);
  return out;
}

json newton_options_json(const solve::NewtonOptions& n) {
  return {
      {"residual_tolerance", n.residual_tolerance},
      {"increment_tolerance", n.increment_tolerance},
      {"max_iterations", n.max_iterations},
      {"max_step_cuts", n.max_step_cuts},
      {"line_search", n.line_search},
      {"tangent", solve::to_string(n.tangent)},
      {"krylov_tolerance", n.krylov_tolerance},
      {"krylov_restart", n.krylov_restart},
      {"krylov_max_iterations", n.krylov_max_iterations},
      {"max_contact_rounds", n.max_contact_rounds},
      {"predictor", n.predictor},
      {"control", n.control == solve::NewtonOptions::Control::ArcLength ? "arc_length" : "load"},
      {"max_arc_steps", n.max_arc_steps}};
}

json stepping_json(const solve::SteppingOptions& s) {
  json out = {{"scheme", solve::to_string(s.scheme)},
              {"steps", s.steps},
              {"rebuild_matrix", s.rebuild_matrix},
              {"update_load_geometry", s.update_load_geometry},
              {"boundary_method", model::to_string(s.boundary_method)},
              {"penalty", s.penalty},
              {"solver", solve::to_string(s.solver)},
              {"tolerance", s.pcg.tolerance},
              {"max_iterations", s.pcg.max_iterations},
              {"max_volume_change", s.max_volume_change},
              {"stop_on_inverted_faces", s.stop_on_inverted_faces}};
  if (s.scheme == solve::Scheme::Newton) out["newton"] = newton_options_json(s.newton);
  return out;
}

json law_json(const model::Material& material, int dim) {
  const model::FiberLaw& law = material.law;
  json out = {{"type", law.name()}};
  for (const std::string& name : law.parameter_names()) out[name] = law.parameter(name);
  for (const model::LawModel::Setting& s : law.settings())
    out[s.name] = s.scalar && s.values.size() == 1 ? json(s.values[0]) : json(s.values);
  out["axis_factors"] = vector_json(material.axis_factors, dim);
  out["gamma"] = material.surface_tension;
  out["kinematics"] = model::kinematics_name(material.kinematics);
  return out;
}

// Passes over every fiber pair: computed (lengths and the law) and stored
// (a stored tangent read).
json pair_passes_json(const model::PairPasses& p) {
  return {{"computed", p.computed}, {"stored", p.stored}};
}

// A Newton run's passes over the pairs in all, and per Newton iteration.
json run_pair_passes_json(const solve::SteppingSummary& s) {
  model::PairPasses total;
  for (const solve::StepRecord& r : s.steps) total += r.pair_passes;
  json out = pair_passes_json(total);
  const double iterations = std::max(1, s.newton_iterations);
  out["computed_per_newton_iteration"] = static_cast<double>(total.computed) / iterations;
  out["stored_per_newton_iteration"] = static_cast<double>(total.stored) / iterations;
  return out;
}

// The Newton and contact records of a step (Newton scheme only).
void add_newton_json(const model::Model& m, const solve::StepRecord& r, json& step) {
  step["newton"] = {{"iterations", r.newton_iterations},
                    {"residual_norms", r.residual_norms},
                    {"line_search_halvings", r.line_search_halvings},
                    {"krylov_iterations", r.krylov_iterations},
                    {"pair_passes", pair_passes_json(r.pair_passes)},
                    {"step_cuts", r.step_cuts},
                    {"pieces", r.pieces},
                    {"volume_drift", r.volume_drift}};
  json paddles = json::object();
  for (size_t p = 0; p < r.paddles.size() && p < m.paddles.size(); ++p)
    paddles[m.paddles[p].label] = {{"plane", r.paddles[p].plane},
                                   {"travel", r.paddles[p].travel},
                                   {"force", vector_json(r.paddles[p].force, m.dim())},
                                   {"contacts", r.paddles[p].contacts}};
  if (!m.paddles.empty()) {
    step["paddles"] = paddles;
    step["newton"]["contact"] = {{"rounds", r.contact_rounds},
                                 {"added", r.contacts_added},
                                 {"released", r.contacts_released}};
  }
}

std::string group_name(const model::Model& m, size_t g) {
  return g < m.constraint_groups.size() ? m.constraint_groups[g] : "supports";
}

json reactions_json(const model::Model& m, const solve::StepRecord& r) {
  json out = json::object();
  for (size_t g = 0; g < r.reactions.size(); ++g)
    out[group_name(m, g)] = vector_json(r.reactions[g], m.dim());
  return out;
}

// What the case was expected to cost before it ran (experiment/resources.hpp).
json estimate_json(const ResourceEstimate& e) {
  json parts = json::array();
  for (const ResourcePart& p : e.parts)
    parts.push_back({{"name", p.name}, {"bytes", p.bytes}, {"seconds", p.seconds}});
  return {
      {"peak_bytes", e.peak_bytes}, {"seconds", e.seconds}, {"solver", e.solver}, {"parts", parts}};
}

json run_json(const Case& c, const ExperimentResult& result, const RunResult& run) {
  const model::Model& m = c.model;
  json steps = json::array();
  for (const solve::StepRecord& r : run.summary.steps) {
    json factors = json::object();
    for (size_t l = 0; l < m.loads.size(); ++l) factors[m.loads[l].label] = r.load_factors[l];
    steps.push_back({{"step", r.step},
                     {"load_factors", factors},
                     {"pressure", r.pressure},
                     {"volume", r.volume},
                     {"max_displacement", r.max_displacement},
                     {"equilibrium_residual", r.residual},
                     {"applied_force", vector_json(r.applied_force, m.dim())},
                     {"reactions", reactions_json(m, r)},
                     {"seconds", r.seconds}});
    if (run.summary.scheme == solve::Scheme::Newton) add_newton_json(m, r, steps.back());
  }
  json final_figures = json::object();
  const std::string prefix = run.variant.empty() ? "" : run.variant + ".";
  for (const auto& [name, value] : result.figures)
    if (name.rfind(prefix, 0) == 0 && (!run.variant.empty() || name.rfind("fibers.", 0) != 0))
      final_figures[name.substr(prefix.size())] = value;
  json paddle_axes = json::object();  // which force component each paddle's curve shows
  for (const model::Paddle& p : m.paddles) paddle_axes[p.label] = std::string(1, kAxes[p.axis]);
  return {{"variant", run.variant},
          {"patch", c.patch},
          {"paddle_axes", paddle_axes},
          {"solver", solve::to_string(run.summary.solver)},
          {"pcg_iterations", run.summary.solver_statistics.iterations},
          {"factorization_flops", run.summary.solver_statistics.factorization_flops},
          {"stepping", stepping_json(c.stepping)},
          {"material", law_json(m.material, m.dim())},
          {"newton_iterations", run.summary.newton_iterations},
          {"krylov_iterations", run.summary.krylov_iterations},
          {"pair_passes", run_pair_passes_json(run.summary)},
          {"limit_load_factor", std::isnan(run.summary.limit_load_factor)
                                    ? json(nullptr)
                                    : json(run.summary.limit_load_factor)},
          {"success", run.summary.success},
          {"message", run.summary.message},
          {"factorizations", run.summary.factorizations},
          {"single_precision_factorizations", run.summary.single_precision_factorizations},
          {"seconds",
           {{"assemble", run.summary.assemble_seconds},
            {"factorize", run.summary.factorize_seconds},
            {"solve", run.summary.solve_seconds},
            {"total", run.summary.total_seconds}}},
          {"estimate", estimate_json(c.estimate)},
          {"steps", steps},
          {"final", final_figures}};
}

// The clamps' mirror layers: which support, its plane and depth.
json mirror_layers_json(const model::Model& m) {
  json layers = json::array();
  for (const model::MirrorLayer& layer : m.mirror_layers)
    layers.push_back({{"support", m.constraint_groups.at(static_cast<size_t>(layer.group))},
                      {"point", {layer.point.x(), layer.point.y(), layer.point.z()}},
                      {"normal", {layer.normal.x(), layer.normal.y(), layer.normal.z()}},
                      {"depth", layer.depth}});
  return layers;
}

// The supports whose edge is split: which, and how many edge vertices.
json split_edges_json(const model::Model& m) {
  json edges = json::array();
  for (const model::HeldEdge& edge : m.held_edges)
    edges.push_back({{"support", m.constraint_groups.at(static_cast<size_t>(edge.group))},
                     {"edge_vertices", model::held_edge_vertices(m, edge.held).size()}});
  return edges;
}

json fibers_json(const Case& c) {
  const FiberReport& f = c.fibers;
  return {{"kinematics", model::kinematics_name(c.model.material.kinematics)},
          {"mirror_layers", mirror_layers_json(c.model)},
          {"split_edges", split_edges_json(c.model)},
          {"horizon", f.horizon > 0.0 ? json(f.horizon) : json(nullptr)},  // m; null: every pair
          {"pruning", f.pruning ? "auto" : "off"},
          {"convex", f.convex},
          {"connection_count", model::to_string(c.model.connection_count)},
          {"product", c.model.treecode_tolerance > 0.0 ? "treecode" : "exact"},
          {"treecode_tolerance", c.model.treecode_tolerance},
          {"in_all", f.pairs},
          {"kept", f.kept},
          {"pruned", f.pairs - f.kept},
          {"kept_per_vertex",
           {{"min", f.min_per_vertex}, {"mean", f.mean_per_vertex}, {"max", f.max_per_vertex}}},
          {"pruning_seconds", f.seconds},
          {"exact_fallbacks", f.exact_fallbacks}};
}

// A CSV field: quoted when it holds a comma, a quote or a line break.
std::string csv_field(const std::string& text) {
  if (text.find_first_of(",\"\n\r") == std::string::npos) return text;
  std::string out = "\"";
  for (char ch : text) out += ch == '"' ? std::string("\"\"") : std::string(1, ch);
  return out + "\"";
}

// Rows of cells joined by commas, numbers with 17 significant digits.
class CsvTable {
 public:
  void header(const std::string& name) { cells_.push_back(csv_field(name)); }
  void text(const std::string& value) { cells_.push_back(csv_field(value)); }
  void number(double value) {
    std::ostringstream out;
    out << std::setprecision(17) << value;
    cells_.push_back(out.str());
  }
  void end_row() {
    for (size_t k = 0; k < cells_.size(); ++k) out_ << (k ? "," : "") << cells_[k];
    out_ << "\n";
    cells_.clear();
  }
  std::string str() const { return out_.str(); }

 private:
  std::vector<std::string> cells_;
  std::ostringstream out_;
};

}  // namespace

json summary_json(const Experiment& ex, const ExperimentResult& result) {
  json doc;
  doc["experiment"] = ex.name;
  doc["description"] = ex.description;
  doc["source"] = ex.source.string();
  doc["fiberfluid_version"] = program_version();
  json build = json::object();
  for (const auto& [name, value] : build_info()) build[name] = value;
  doc["build"] = build;
  doc["kind"] = ex.kind == Experiment::Kind::Areas         ? "areas"
                : ex.kind == Experiment::Kind::Benchmark   ? "benchmark"
                : ex.kind == Experiment::Kind::Calibration ? "calibration"
                                                           : "simulate";
  if (!result.failure.empty()) doc["failure"] = result.failure;
  doc["units"] = {{"length", "m"},
                  {"displacement", "m"},
                  {"force", "N"},
                  {"pressure", "Pa"},
                  {"volume", "m^3 (m^2 in 2D)"},
                  {"Y", "Pa"},
                  {"gamma", "N/m"},
                  {"time", "s"}};
  doc["success"] = result.runs_succeeded();
  if (ex.kind == Experiment::Kind::Simulate) {
    const Case& first = ex.cases.front();
    doc["surface"] = {{"dimension", first.input_surface.dim},
                      {"vertices", first.input_surface.num_vertices()},
                      {"used_vertices", first.model.num_vertices()},
                      {"faces", first.input_surface.num_faces()}};
    doc["fibers"] = fibers_json(first);
    json runs = json::array();
    for (size_t r = 0; r < result.runs.size(); ++r)
      runs.push_back(run_json(ex.cases[r], result, result.runs[r]));
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
  doc["peak_resident_bytes"] = peak_resident_bytes();  // of the whole process so far
  return doc;
}

// Per paddle: its travel and the force on the body along its axis (all
// components and the contact count when `full`).
static void paddle_headers(CsvTable& t, const model::Paddle& p, int dim, bool full) {
  t.header("paddle_" + p.label + "_travel_m");
  if (full) {
    t.header("paddle_" + p.label + "_plane_m");
    for (int a = 0; a < dim; ++a) t.header("paddle_" + p.label + "_force_" + kAxes[a] + "_N");
    t.header("paddle_" + p.label + "_contacts");
  } else {
    t.header("paddle_" + p.label + "_force_N");
  }
}

static void paddle_numbers(CsvTable& t, const model::Model& m, const solve::StepRecord& r, int dim,
                           bool full) {
  for (size_t p = 0; p < m.paddles.size(); ++p) {
    const solve::StepRecord::PaddleState s =
        p < r.paddles.size() ? r.paddles[p] : solve::StepRecord::PaddleState{};
    t.number(s.travel);
    if (full) {
      t.number(s.plane);
      for (int a = 0; a < dim; ++a) t.number(s.force[a]);
      t.number(s.contacts);
    } else {
      t.number(s.force[m.paddles[p].axis]);
    }
  }
}

std::string steps_csv(const Case& c, const RunResult& run) {
  const model::Model& m = c.model;
  const int dim = m.dim();
  const size_t groups = std::max<size_t>(1, m.constraint_groups.size());
  CsvTable t;
  t.header("step");
  for (const model::Load& load : m.loads) t.header("load_factor_" + load.label);
  t.header("pressure_Pa");
  t.header(dim == 3 ? "volume_m3" : "area_m2");
  t.header("max_displacement_m");
  for (int a = 0; a < dim; ++a) t.header(std::string("applied_force_") + kAxes[a] + "_N");
  for (size_t g = 0; g < groups; ++g)
    for (int a = 0; a < dim; ++a) t.header("reaction_" + group_name(m, g) + "_" + kAxes[a] + "_N");
  for (const model::Paddle& p : m.paddles) paddle_headers(t, p, dim, true);
  const bool newton = run.summary.scheme == solve::Scheme::Newton;
  if (newton)
    for (const char* h : {"newton_iterations", "line_search_halvings", "krylov_iterations",
                          "step_cuts", "volume_drift"})
      t.header(h);
  t.header("equilibrium_residual");
  t.header("seconds");
  t.end_row();
  for (const solve::StepRecord& r : run.summary.steps) {
    t.number(r.step);
    for (double f : r.load_factors) t.number(f);
    t.number(r.pressure);
    t.number(r.volume);
    t.number(r.max_displacement);
    for (int a = 0; a < dim; ++a) t.number(r.applied_force[a]);
    for (size_t g = 0; g < groups; ++g)
      for (int a = 0; a < dim; ++a) t.number(g < r.reactions.size() ? r.reactions[g][a] : 0.0);
    paddle_numbers(t, m, r, dim, true);
    if (newton) {
      t.number(r.newton_iterations);
      t.number(r.line_search_halvings);
      t.number(r.krylov_iterations);
      t.number(r.step_cuts);
      t.number(r.volume_drift);
    }
    t.number(r.residual);
    t.number(r.seconds);
    t.end_row();
  }
  return t.str();
}

std::string load_displacement_csv(const Case& c, const RunResult& run) {
  const model::Model& m = c.model;
  const int dim = m.dim();
  CsvTable t;
  t.header("step");
  for (const model::Load& load : m.loads) t.header("load_factor_" + load.label);
  for (const model::Paddle& p : m.paddles) paddle_headers(t, p, dim, false);
  t.header("max_displacement_m");
  t.header("pressure_Pa");
  t.header(dim == 3 ? "volume_m3" : "area_m2");
  t.end_row();
  for (const solve::StepRecord& r : run.summary.steps) {
    t.number(r.step);
    for (double f : r.load_factors) t.number(f);
    paddle_numbers(t, m, r, dim, false);
    t.number(r.max_displacement);
    t.number(r.pressure);
    t.number(r.volume);
    t.end_row();
  }
  return t.str();
}

std::string vertices_csv(const Case& c, const RunResult& run) {
  const int dim = c.input_surface.dim;
  const Eigen::MatrixXd& S = c.input_surface.V;
  const Eigen::MatrixXd U = input_positions(c, run.summary.unknowns) - S;
  Eigen::MatrixXd reactions = Eigen::MatrixXd::Zero(S.rows(), dim);
  if (run.summary.reaction_forces.rows() == c.model.num_vertices())
    for (size_t m = 0; m < c.model_to_input.size(); ++m)
      reactions.row(c.model_to_input[m]) =
          run.summary.reaction_forces.row(static_cast<Eigen::Index>(m));
  CsvTable t;
  t.header("vertex");
  for (int a = 0; a < dim; ++a) t.header(std::string(1, kAxes[a]) + "_m");
  for (int a = 0; a < dim; ++a) t.header(std::string("u") + kAxes[a] + "_m");
  t.header("u_magnitude_m");
  for (int a = 0; a < dim; ++a) t.header(std::string("reaction_") + kAxes[a] + "_N");
  t.end_row();
  for (Eigen::Index i = 0; i < S.rows(); ++i) {
    t.number(static_cast<double>(i));
    for (int a = 0; a < dim; ++a) t.number(S(i, a));
    for (int a = 0; a < dim; ++a) t.number(U(i, a));
    t.number(U.row(i).norm());
    for (int a = 0; a < dim; ++a) t.number(reactions(i, a));
    t.end_row();
  }
  return t.str();
}

std::string comparison_csv(const Experiment& ex, const ExperimentResult& result) {
  const char* figures[] = {"max_displacement", "final_pressure", "final_volume",
                           "volume_change_relative"};
  const char* headers[] = {"max_displacement_m", "final_pressure_Pa", "final_volume_m3",
                           "volume_change_relative"};
  CsvTable t;
  t.header("variant");
  t.header("success");
  t.header("steps");
  for (const char* h : headers) t.header(h);
  // Reactions at the end, per group of the first case (variants may differ).
  const model::Model& first = ex.cases.front().model;
  const size_t groups = first.constraint_groups.size();
  for (size_t g = 0; g < groups; ++g)
    for (int a = 0; a < first.dim(); ++a)
      t.header("reaction_" + group_name(first, g) + "_" + kAxes[a] + "_N");
  // Paddles at the end (those of the first case, by label): force along the axis, contacts.
  for (const model::Paddle& p : first.paddles) {
    t.header("paddle_" + p.label + "_force_N");
    t.header("paddle_" + p.label + "_contacts");
  }
  t.header("seconds");
  t.header("rank");  // the MPI rank that ran it (0 in a one-process run)
  t.header("message");
  t.header("patch");
  t.end_row();
  for (size_t r = 0; r < result.runs.size(); ++r) {
    const RunResult& run = result.runs[r];
    const solve::SteppingSummary& s = run.summary;
    t.text(run.variant);
    t.text(s.success ? "true" : "false");
    t.number(static_cast<double>(s.steps.size()));
    for (const char* f : figures) {  // as the runner computed them; none for a failed run
      const auto value = result.figures.find(run.variant + "." + f);
      if (value != result.figures.end())
        t.number(value->second);
      else
        t.text("");
    }
    const bool same_groups = ex.cases[r].model.constraint_groups == first.constraint_groups;
    for (size_t g = 0; g < groups; ++g)
      for (int a = 0; a < first.dim(); ++a) {
        if (s.success && same_groups && !s.steps.empty())
          t.number(s.steps.back().reactions[g][a]);
        else
          t.text("");
      }
    for (const model::Paddle& p : first.paddles)
      for (const std::string what : {"paddle_force.", "paddle_contacts."}) {
        const auto value = result.figures.find(run.variant + "." + what + p.label);
        if (value != result.figures.end())
          t.number(value->second);
        else
          t.text("");
      }
    t.number(s.total_seconds);
    t.number(run.rank);
    t.text(s.message);
    t.text(ex.cases[r].patch.is_null() ? "" : ex.cases[r].patch.dump());
    t.end_row();
  }
  return t.str();
}

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
  const std::string& variant = experiment_.cases[run].variant;
  return variant.empty() ? staging_ : staging_ / variant;
}

void OutputWriter::begin() {
  staging_ = create_staging_folder(target_, experiment_.name);
  geom::write_text_file(staging_ / "INCOMPLETE",
                        "fiberfluid is writing this folder, or was stopped while it did: "
                        "these are not the results of a complete run.\n");
  if (experiment_.kind != Experiment::Kind::Simulate) return;
  series_.assign(experiment_.cases.size(), {});
  equilibria_.clear();
  equilibria_.resize(experiment_.cases.size());  // made when a run first writes
  write_fibers();
  for (size_t r = 0; r < experiment_.cases.size(); ++r) {
    fs::create_directories(run_folder(r));
    if (!experiment_.output.vtk) continue;
    fs::create_directories(run_folder(r) / "vtk");
    const model::Model& m = experiment_.cases[r].model;
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
  const Case& c = experiment_.cases.front();
  if (c.fibers.write == "none") return;
  const std::vector<std::pair<int, int>> lines = written_fibers(c);
  const Eigen::MatrixXd& S = c.model.surface.V;
  Eigen::VectorXd rest(static_cast<Eigen::Index>(lines.size()));
  for (size_t k = 0; k < lines.size(); ++k)
    rest[static_cast<Eigen::Index>(k)] = (S.row(lines[k].first) - S.row(lines[k].second)).norm();
  geom::VtuContent content;
  content.cells = {{"rest_length", rest}};
  content.encoding = vtk_encoding(experiment_.output.vtk_format, lines.size());
  geom::write_lines_vtu(staging_ / "fibers.vtu", S, lines, content);
}

// Made on a run's first use, by the thread that runs it (each run's slot is
// its own): a sweep whose runs write no .vtu builds none.
const model::Equilibrium& OutputWriter::equilibrium(size_t run) const {
  std::unique_ptr<const model::Equilibrium>& slot = equilibria_[run];
  if (!slot) slot = std::make_unique<const model::Equilibrium>(experiment_.cases[run].model);
  return *slot;
}

// RUN/fibers_final.vtu: the written fibers at the run's last state, each
// with its strain, its tension and the size of its force (the equilibrium
// equations' fiber forces, model.md section 7).
void OutputWriter::write_final_fibers(size_t run, const Eigen::VectorXd& unknowns) const {
  const Case& c = experiment_.cases[run];
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
  content.encoding = vtk_encoding(experiment_.output.vtk_format, lines.size());
  geom::write_lines_vtu(run_folder(run) / "fibers_final.vtu", model::positions(c.model, unknowns),
                        lines, content);
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
  const Case& c = experiment_.cases[run];
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
  content.encoding = vtk_encoding(experiment_.output.vtk_format, static_cast<size_t>(n));
  char name[32];
  std::snprintf(name, sizeof name, "step_%04d.vtu", step);
  geom::write_vtu(run_folder(run) / "vtk" / name, deformed, content);
  series_[run].emplace_back(step, std::string("vtk/") + name);
}

void OutputWriter::on_step(size_t run, const solve::StepRecord& record,
                           const Eigen::VectorXd& unknowns) {
  const bool last = record.step == experiment_.cases[run].stepping.steps;
  if (experiment_.output.vtk && (last || record.step % experiment_.output.every == 0))
    write_state(run, record.step, unknowns, record.load_factors, record.held_forces);
}

void OutputWriter::write_fem_path(const FemReferenceResult& f) {
  std::filesystem::create_directories(staging_ / "fem_reference_vtk");
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
    geom::write_vtu(staging_ / "fem_reference_vtk" / name, deformed,
                    {{"displacement", U}, {"displacement_magnitude", U.rowwise().norm()}});
    series.emplace_back(static_cast<double>(k + 1), std::string("fem_reference_vtk/") + name);
  }
  geom::write_pvd(staging_ / "fem_reference_series.pvd", series);
}

void OutputWriter::finish(const ExperimentResult& result, const FolderFiller& more) {
  for (size_t r = 0; r < result.runs.size(); ++r) {
    const Case& c = experiment_.cases[r];
    const RunResult& run = result.runs[r];
    if (experiment_.output.vtk) geom::write_pvd(run_folder(r) / "series.pvd", series_[r]);
    geom::write_text_file(run_folder(r) / "steps.csv", steps_csv(c, run));
    geom::write_text_file(run_folder(r) / "load_displacement.csv", load_displacement_csv(c, run));
    if (!run.summary.success) continue;
    geom::write_text_file(run_folder(r) / "vertices.csv", vertices_csv(c, run));
    if (c.fibers.write != "none") write_final_fibers(r, run.summary.unknowns);
    if (experiment_.output.obj) {
      geom::Surface deformed = c.input_surface;
      deformed.V = input_positions(c, run.summary.unknowns);
      geom::write_obj(run_folder(r) / "final.obj", deformed);
    }
  }
  if (experiment_.sweeps())
    geom::write_text_file(staging_ / "comparison.csv", comparison_csv(experiment_, result));
  if (result.fem_reference) {  // the target for a fit, and the same with its displacement
    const FemReferenceResult& f = *result.fem_reference;
    geom::write_obj(staging_ / "fem_reference.obj", f.deformed_boundary);
    Eigen::MatrixXd U = f.deformed_boundary.V - f.rest_boundary.V;
    geom::write_vtu(staging_ / "fem_reference.vtu", f.deformed_boundary,
                    {{"displacement", U}, {"displacement_magnitude", U.rowwise().norm()}});
    // A nonlinear FEM's load path: its boundary after each step, a series.
    if (f.path.size() > 1) write_fem_path(f);
  }
  if (result.benchmark) {
    const BenchmarkResult& b = *result.benchmark;
    geom::write_text_file(staging_ / "metrics.csv", benchmark_csv(b));
    geom::write_text_file(staging_ / "benchmark.json", benchmark_json(*experiment_.benchmark, b));
    if (b.reference_final.num_vertices() > 0)
      geom::write_obj(staging_ / "reference_final.obj", b.reference_final);
    if (b.fiber_final.num_vertices() > 0)
      geom::write_obj(staging_ / "fiber_model_final.obj", b.fiber_final);
  }
  geom::write_text_file(staging_ / "summary.json",
                        summary_json(experiment_, result).dump(2) + "\n");
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
  set_aside("FAILED", "failed", "this run failed", why);
}

// The experiment as read (experiment.json) and as resolved
// (experiment.resolved.json: `fiberfluid run` on it repeats this run). A
// surface that a program gave is written beside them (input_surface.obj,
// 17 digits), and the resolved file reads it from there.
void OutputWriter::write_experiment_files() const {
  if (experiment_.document.is_null()) return;  // built without a document
  geom::write_text_file(staging_ / "experiment.json", experiment_.document.dump(2) + "\n");
  nlohmann::json resolved = experiment_.resolved;
  const bool given_surface = experiment_.kind == Experiment::Kind::Simulate &&
                             !experiment_.cases.empty() && !resolved.contains("surface") &&
                             !resolved.contains("variants");
  if (given_surface) {
    geom::write_obj(staging_ / "input_surface.obj", experiment_.cases.front().input_surface);
    resolved["surface"] = {{"file", "input_surface.obj"}};
  }
  geom::write_text_file(staging_ / "experiment.resolved.json", resolved.dump(2) + "\n");
}

void OutputWriter::keep_interrupted(const std::string& why, const FolderFiller& more) {
  if (more) more(staging_);
  set_aside("INTERRUPTED", "interrupted", "this run was interrupted", why + "\n");
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
  fs::remove(staging_ / "INCOMPLETE");
  // From here on the folder is never removed: a move that fails names it.
  const fs::path staged = std::exchange(staging_, fs::path());
  move_into_place(staged, where, &warnings_);
  result_folder_ = where;
}

}  // namespace fiberfluid::experiment

// SPDX-License-Identifier: GPL-3.0-or-later
#include "fiberfluid/experiment/write/summary_json.hpp"

#include <cmath>
#include <sstream>

#include "fiberfluid/experiment/run/resources.hpp"
#include "fiberfluid/experiment/write/build_info.hpp"
#include "fiberfluid/model/assembly.hpp"
#include "fiberfluid/model/held_edge.hpp"
#include "fiberfluid/model/report_names.hpp"

namespace fiberfluid::experiment {
namespace {

using nlohmann::json;

using model::axis_name;
using model::constraint_group_name;

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
      {"friction_tolerance", n.friction_tolerance},
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
                                   {"contacts", r.paddles[p].contacts},
                                   {"sliding", r.paddles[p].sliding}};
  if (!m.paddles.empty()) {
    step["paddles"] = paddles;
    step["newton"]["contact"] = {{"rounds", r.contact_rounds},
                                 {"added", r.contacts_added},
                                 {"released", r.contacts_released},
                                 {"friction_updates", r.friction_updates}};
  }
}

json reactions_json(const model::Model& m, const solve::StepRecord& r) {
  json out = json::object();
  for (size_t g = 0; g < r.reactions.size(); ++g)
    out[constraint_group_name(m, g)] = vector_json(r.reactions[g], m.dim());
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
  for (const model::Paddle& p : m.paddles) paddle_axes[p.label] = std::string(1, axis_name(p.axis));
  return {{"variant", run.variant},
          {"patch", c.patch},
          {"paddle_axes", paddle_axes},
          {"solver", solve::to_string(run.summary.solver)},
          {"tangent", solve::to_string(run.summary.tangent)},
          {"tangent_fallback", run.summary.tangent_fallback},
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
          {"weights", model::to_string(c.model.fiber_weights)},
          // The line measure has no count (model.hpp, FiberWeights).
          {"connection_count", c.model.fiber_weights == model::FiberWeights::Lines
                                   ? json(nullptr)
                                   : json(model::to_string(c.model.connection_count))},
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

}  // namespace

json finite_or_null(double x) { return std::isfinite(x) ? json(x) : json(nullptr); }

json summary_json(const Experiment& ex, const ExperimentResult& result) {
  json doc;
  doc["experiment"] = ex.name;
  doc["description"] = ex.description;
  doc["source"] = ex.source.string();
  doc["fiberfluid_version"] = program_version();
  json build = json::object();
  for (const auto& [name, value] : build_info()) build[name] = value;
  doc["build"] = build;
  doc["kind"] = kExperimentKindNames.name(ex.kind());
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
  if (ex.kind() == Experiment::Kind::Simulate) {
    const Case& first = ex.simulation().cases.front();
    doc["surface"] = {{"dimension", first.input_surface.dim},
                      {"vertices", first.input_surface.num_vertices()},
                      {"used_vertices", first.model.num_vertices()},
                      {"faces", first.input_surface.num_faces()}};
    doc["fibers"] = fibers_json(first);
    json runs = json::array();
    for (size_t r = 0; r < result.runs.size(); ++r)
      runs.push_back(run_json(ex.simulation().cases[r], result, result.runs[r]));
    doc["runs"] = runs;
  }
  doc["figures"] = result.figures;
  for (const auto& [name, section] : result.summary_sections.items()) doc[name] = section;
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

}  // namespace fiberfluid::experiment

// SPDX-License-Identifier: GPL-3.0-or-later
#include "app/fitting.hpp"

#include <cmath>
#include <limits>
#include <sstream>

#include "geom/error.hpp"
#include "geom/mesh_io.hpp"
#include "geom/vtk_writer.hpp"
#include "model/assembly.hpp"
#include "model/equilibrium.hpp"

namespace fiberfluid::app {
namespace {

using nlohmann::json;

// NaN and infinities as JSON null.
json number(double x) { return std::isfinite(x) ? json(x) : json(nullptr); }

json statistics_json(const fit::DistanceStatistics& s) {
  return {{"count", s.count},
          {"mean", number(s.mean)},
          {"rms", number(s.rms)},
          {"standard_deviation", number(s.standard_deviation)},
          {"largest", number(s.largest)},
          {"share_of_length",
           {{"mean", number(s.share(s.mean))},
            {"rms", number(s.share(s.rms))},
            {"standard_deviation", number(s.share(s.standard_deviation))},
            {"largest", number(s.share(s.largest))}}}};
}

}  // namespace

FitSetup setup_fit(const Experiment& ex, std::function<void(const fit::IterationRecord&)> progress) {
  if (!ex.fit) throw InputError(ex.source.string() + ": no \"fit\" section: nothing to calibrate");
  if (ex.cases.size() != 1) throw InputError(ex.source.string() + ": a fit calibrates one simulation");
  const FitSpec& spec = *ex.fit;
  const Case& c = ex.cases.front();
  FitSetup setup;
  for (const FitTargetSpec& t : spec.targets) {
    fit::Target target;
    try {
      target = fit::read_target(t.file);
    } catch (const InputError& e) {
      t.field.fail("file", e.what());
    }
    const int step = t.step == 0 ? c.stepping.steps : t.step;
    if (step > c.stepping.steps)
      t.field.fail("step", "load step " + std::to_string(step) + " is beyond the run's " +
                               std::to_string(c.stepping.steps) + " steps");
    setup.targets.push_back({target, step});
  }
  std::vector<fit::Parameter> parameters;
  for (const FitParameterSpec& p : spec.parameters) {
    fit::Parameter parameter;
    parameter.name = p.name;
    const bool alignment = fit::is_alignment_parameter(p.name);
    if (!alignment && !model::is_material_parameter(c.model.material, p.name)) {
      std::string known;
      for (const std::string& n : model::material_parameter_names(c.model.material, 3))
        known += (known.empty() ? "" : ", ") + n;
      p.field.fail("name", "\"" + p.name + "\" is not a parameter of this material (" + known +
                               ") or of the alignment (rotation_x..z, translation_x..z)");
    }
    parameter.initial =
        p.start ? *p.start : alignment ? 0.0 : fit::material_parameter(c.model.material, p.name);
    if (p.lower) parameter.lower = *p.lower;
    if (p.upper) parameter.upper = *p.upper;
    parameter.log_scale = p.log_scale.value_or(fit::log_scale_by_default(p.name));
    parameters.push_back(parameter);
  }
  fit::FitOptions options = spec.options;
  options.progress = std::move(progress);
  if (spec.exclude) {
    const std::vector<int> excluded = resolve_selection(*spec.exclude, c);
    std::vector<char> out(static_cast<size_t>(c.model.num_vertices()), 0);
    for (int v : excluded) out[static_cast<size_t>(v)] = 1;
    for (int v = 0; v < c.model.num_vertices(); ++v)
      if (!out[static_cast<size_t>(v)]) options.counted_vertices.push_back(v);
    if (options.counted_vertices.empty())
      spec.exclude->field.fail("", "excludes every vertex: no distance would count");
  }
  try {
    setup.calibration = std::make_unique<fit::Calibration>(c.model, c.stepping, setup.targets,
                                                           parameters, options);
  } catch (const InputError& e) {
    spec.field.fail("", e.what());
  }
  return setup;
}

std::map<std::string, double> fit_figures(const fit::FitResult& r) {
  std::map<std::string, double> figures;
  for (size_t k = 0; k < r.names.size(); ++k)
    figures["fit." + r.names[k]] = r.values[static_cast<Eigen::Index>(k)];
  figures["fit.cost"] = r.final_cost;
  figures["fit.forward_runs"] = r.forward_runs;
  figures["fit.distance_mean"] = r.overall.mean;
  figures["fit.distance_rms"] = r.overall.rms;
  figures["fit.distance_sd"] = r.overall.standard_deviation;
  figures["fit.distance_largest"] = r.overall.largest;
  figures["fit.distance_sd_share"] = r.overall.share(r.overall.standard_deviation);
  return figures;
}

Experiment with_fitted_material(const Experiment& experiment, const fit::Calibration& calibration,
                                const fit::FitResult& result) {
  Experiment fitted = experiment;
  const fit::ParameterMap& map = calibration.parameters();
  model::Material& material = fitted.cases.front().model.material;
  material = map.material(material, result.values);
  return fitted;
}

json fit_json(const Experiment& ex, const FitSetup& setup, const fit::FitResult& r,
              const ExperimentResult& run) {
  const fit::Calibration& c = *setup.calibration;
  json parameters = json::array();
  for (size_t k = 0; k < r.names.size(); ++k) {
    const Eigen::Index i = static_cast<Eigen::Index>(k);
    const fit::Parameter& p = c.parameters().parameters()[k];
    parameters.push_back({{"name", r.names[k]},
                          {"initial", r.initial[i]},
                          {"value", r.values[i]},
                          {"standard_error", number(r.standard_errors[i])},
                          {"interval_95", {number(r.lower_95[i]), number(r.upper_95[i])}},
                          {"bounds", {number(p.lower), number(p.upper)}},
                          {"log_scale", p.log_scale}});
  }
  json correlation = json::array();
  for (Eigen::Index a = 0; a < r.correlation.rows(); ++a) {
    json row = json::array();
    for (Eigen::Index b = 0; b < r.correlation.cols(); ++b) row.push_back(number(r.correlation(a, b)));
    correlation.push_back(row);
  }
  json iterations = json::array();
  for (const fit::IterationRecord& it : r.iterations) {
    json values = json::object();
    for (size_t k = 0; k < r.names.size(); ++k) values[r.names[k]] = it.values[static_cast<Eigen::Index>(k)];
    iterations.push_back({{"iteration", it.iteration}, {"cost", it.cost},
                          {"accepted", it.accepted}, {"trial_cost", it.trial_cost},
                          {"values", values}, {"forward_runs", it.forward_runs},
                          {"seconds", it.seconds}});
  }
  json targets = json::array();
  for (size_t t = 0; t < setup.targets.size(); ++t)
    targets.push_back({{"file", setup.targets[t].target.label},
                       {"step", setup.targets[t].step},
                       {"read", setup.targets[t].target.description},
                       {"distance", statistics_json(r.statistics[t])}});
  json checks = json::array();
  for (const FigureCheck& check : run.checks)
    checks.push_back({{"figure", check.expected.figure}, {"passed", check.passed},
                      {"actual", number(check.actual)}, {"text", check.Describe()}});
  return {{"experiment", ex.name},
          {"success", r.success},
          {"message", r.message},
          {"method", fit::to_string(r.method)},
          {"jacobian", r.analytic_jacobian ? "analytic: Newton sensitivities, one tangent solve per "
                                             "material parameter"
                                           : "finite differences of whole forward runs (central)"},
          {"loss", fit::to_string(ex.fit->options.loss)},
          {"symmetric", ex.fit->options.symmetric},
          {"parameters", parameters},
          {"covariance", r.covariance_ok ? "ceres covariance at the optimum, scaled by the "
                                           "residual variance"
                                         : "not available: the Jacobian is rank deficient"},
          {"correlation", correlation},
          {"cost", {{"initial", r.initial_cost}, {"final", r.final_cost}}},
          {"iterations", iterations},
          {"forward_runs", r.forward_runs},
          {"sensitivity_solves", r.sensitivity_solves},
          {"failed_runs", r.failed_runs},
          {"seconds", r.seconds},
          {"body_length", c.body_length()},
          {"body_length_is", "the largest extent of the rest surface's bounding box"},
          {"targets", targets},
          {"distance", statistics_json(r.overall)},
          {"checks", checks}};
}

void write_fit_files(const std::filesystem::path& folder, const Experiment& ex,
                     const FitSetup& setup, const fit::FitResult& r, const ExperimentResult& run) {
  geom::write_text_file(folder / "fit.json", fit_json(ex, setup, r, run).dump(2) + "\n");
  std::ostringstream iterations;
  iterations << "iteration,cost_m2,accepted,trial_cost_m2,forward_runs,seconds";
  for (const std::string& name : r.names) iterations << "," << name;
  iterations << "\n";
  iterations.precision(12);
  for (const fit::IterationRecord& it : r.iterations) {
    iterations << it.iteration << "," << it.cost << "," << (it.accepted ? 1 : 0) << ","
               << it.trial_cost << "," << it.forward_runs << "," << it.seconds;
    for (Eigen::Index k = 0; k < it.values.size(); ++k) iterations << "," << it.values[k];
    iterations << "\n";
  }
  geom::write_text_file(folder / "fit_iterations.csv", iterations.str());

  const Case& c = ex.cases.front();
  std::ostringstream distances;
  distances.precision(12);
  distances << "vertex,target,step,distance_m\n";
  for (size_t t = 0; t < r.vertex_distances.size(); ++t) {
    const Eigen::VectorXd& d = r.vertex_distances[t];
    for (Eigen::Index v = 0; v < d.size(); ++v)
      if (std::isfinite(d[v]))
        distances << c.model_to_input[static_cast<size_t>(v)] << "," << t << ","
                  << setup.targets[t].step << "," << d[v] << "\n";
    // The simulated surface at the target's step, coloured by the distance
    // (uncounted vertices: 0, and counted = 0 marks them).
    Eigen::VectorXd shown = d, counted = Eigen::VectorXd::Ones(d.size());
    for (Eigen::Index v = 0; v < d.size(); ++v)
      if (!std::isfinite(d[v])) shown[v] = counted[v] = 0.0;
    geom::Surface at_step = c.model.surface;
    at_step.V = r.positions[t];
    geom::write_vtu(folder / ("fit_target_" + std::to_string(t) + ".vtu"), at_step,
                    {{"distance_to_target", shown}, {"counted", counted}});
    geom::Surface scan;
    scan.V = setup.targets[t].target.points;
    scan.F = setup.targets[t].target.triangles;
    if (scan.F.rows() > 0) geom::write_obj(folder / ("fit_target_" + std::to_string(t) + "_scan.obj"), scan);
  }
  geom::write_text_file(folder / "fit_distances.csv", distances.str());
}

}  // namespace fiberfluid::app

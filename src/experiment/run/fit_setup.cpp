// SPDX-License-Identifier: GPL-3.0-or-later
#include "fiberfluid/experiment/run/fit_setup.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <limits>
#include <map>
#include <sstream>

#include "fiberfluid/experiment/run/case_builder.hpp"
#include "fiberfluid/experiment/run/mesh_study.hpp"
#include "fiberfluid/experiment/spec/figures.hpp"
#include "fiberfluid/geom/mesh_io.hpp"
#include "fiberfluid/geom/vtk_writer.hpp"
#include "fiberfluid/model/assembly.hpp"
#include "fiberfluid/model/equilibrium.hpp"
#include "fiberfluid/util/error.hpp"
#include "fiberfluid/util/run_control.hpp"

namespace fiberfluid::experiment {
namespace {

using nlohmann::json;

// A force target read and tied to its paddle or support group; the
// curve's own problems (rows the run cannot place) are the calibration's.
fit::ForceCurve force_curve(const FitForceSpec& spec, const Case& c) {
  fit::ForceCurve curve;
  try {
    curve = fit::read_force_curve(spec.file, spec.columns);
  } catch (const InputError& e) {
    spec.field.fail("file", e.what());
  }
  curve.weight = spec.weight;
  curve.relative = spec.relative;
  const std::vector<std::string>& names = c.model.constraint_groups;
  std::vector<std::string> paddles;
  for (const model::Paddle& p : c.model.paddles) paddles.push_back(p.label);
  const bool paddle = !spec.paddle.empty();
  const std::vector<std::string>& labels = paddle ? paddles : names;
  const std::string& wanted = paddle ? spec.paddle : spec.support;
  const auto found = std::find(labels.begin(), labels.end(), wanted);
  if (found == labels.end()) {
    std::string known;
    for (const std::string& l : labels) known += (known.empty() ? "" : ", ") + l;
    spec.field.fail(paddle ? "paddle" : "support",
                    "no " + std::string(paddle ? "paddle" : "support") + " is labelled \"" +
                        wanted + "\" (" + (known.empty() ? "there is none" : "labels: " + known) +
                        ")");
  }
  curve.source = paddle ? fit::ForceCurve::Source::Paddle : fit::ForceCurve::Source::Support;
  curve.index = static_cast<int>(found - labels.begin());
  curve.axis = paddle ? c.model.paddles[static_cast<size_t>(curve.index)].axis : spec.axis;
  if (const Status usable = fit::check_force_curve(curve, c.model); !usable.ok)
    spec.field.fail("", usable.message);
  return curve;
}

// The force curves' misfits together: root mean square and largest (N),
// and the rms as a share of the largest measured force.
struct OverallForceMisfit {
  double rms = 0.0, largest = 0.0, scale = 0.0;
};
OverallForceMisfit overall_force_misfit(const fit::FitResult& r) {
  OverallForceMisfit o;
  double squares = 0.0;
  size_t rows = 0;
  for (const fit::ForceMisfit& m : r.force_misfits) {
    squares += m.rms * m.rms * static_cast<double>(m.simulated.size());
    rows += m.simulated.size();
    o.largest = std::max(o.largest, m.largest);
    o.scale = std::max(o.scale, m.scale);
  }
  if (rows > 0) o.rms = std::sqrt(squares / static_cast<double>(rows));
  return o;
}

}  // namespace

std::map<std::string, double> fitted_values(const std::filesystem::path& fit_json_file) {
  std::ifstream in(fit_json_file);
  if (!in)
    throw InputError(fit_json_file.string() +
                     ": cannot open (expected the fit.json of an earlier fit)");
  const json doc = parse_json(in, fit_json_file.string());
  std::map<std::string, double> values;
  if (doc.is_object() && doc.contains("parameters") && doc["parameters"].is_array())
    for (const json& p : doc["parameters"])
      if (p.is_object() && p.contains("name") && p["name"].is_string() && p.contains("value") &&
          p["value"].is_number() && std::isfinite(p["value"].get<double>()))
        values[p["name"].get<std::string>()] = p["value"].get<double>();
  if (values.empty())
    throw InputError(fit_json_file.string() +
                     ": expected a fit.json with parameters[].name and "
                     "parameters[].value");
  return values;
}

int fit_exit_status(fit::FitStatus status) {
  switch (status) {
    case fit::FitStatus::Converged:
      return 0;
    case fit::FitStatus::ConvergedAtBounds:
      return 4;
    case fit::FitStatus::Interrupted:
      return 130;
    case fit::FitStatus::NotIdentifiable:
    case fit::FitStatus::IterationLimit:
    case fit::FitStatus::ForwardRunsFailed:
    case fit::FitStatus::StartFailed:
    case fit::FitStatus::OptimizerFailed:
      break;
  }
  return 2;
}

bool fit_result_kept(fit::FitStatus status) { return fit::converged(status); }

FitSetup setup_fit(const Experiment& ex,
                   std::function<void(const fit::IterationRecord&)> progress) {
  if (!ex.fit())
    throw InputError(ex.source.string() + ": no \"fit\" section: nothing to calibrate");
  if (ex.simulation().cases.size() != 1)
    throw InputError(ex.source.string() + ": a fit calibrates one simulation");
  const FitSpec& spec = *ex.fit();
  const Case& c = ex.simulation().cases.front();
  FitSetup setup;
  for (const FitTargetSpec& t : spec.targets) {
    fit::Target target;
    try {
      target = fit::read_target(t.file, t.scale);
    } catch (const InputError& e) {
      t.field.fail("file", e.what());
    }
    const int step = t.step == 0 ? c.stepping.steps : t.step;
    if (step > c.stepping.steps)
      t.field.fail("step", "load step " + std::to_string(step) + " is beyond the run's " +
                               std::to_string(c.stepping.steps) + " steps");
    setup.targets.push_back({target, step});
  }
  for (const FitForceSpec& f : spec.force_curves) setup.force_curves.push_back(force_curve(f, c));
  std::vector<fit::BlockMaker> more_blocks;  // the targets of other kinds, on this case
  for (size_t k = 0; k < spec.kind_targets.size(); ++k)
    more_blocks.push_back(spec.kind_targets[k].bind(c, k));
  // The starts of an earlier fit (an interrupted one, continued).
  std::map<std::string, double> earlier;
  if (spec.start_from) earlier = fitted_values(*spec.start_from);
  std::vector<fit::Parameter> parameters;
  for (const FitParameterSpec& p : spec.parameters) {
    fit::ParameterRequest request = p.request;
    if (spec.start_from) {
      if (!earlier.count(request.name))
        spec.field.fail("start_from",
                        spec.start_from->string() + " has no value for \"" + request.name + "\"");
      request.start = earlier.at(request.name);
    }
    try {
      parameters.push_back(fit::make_parameter(request, c.model.material));
    } catch (const InputError& e) {
      p.field.fail("name", e.what());
    }
    try {  // its start and bounds, by the calibration's own rules, named here
      fit::ParameterMap({parameters.back()}, c.model.material, c.model.dim());
    } catch (const InputError& e) {
      p.field.fail("", e.what());
    }
  }
  // The fit's expected figures, now that its parameters are known good.
  for (size_t k = 0; k < ex.expected.size(); ++k) {
    if (const Status figure = check_figure(ex, ex.expected[k].figure); !figure.ok)
      FieldName{spec.field.file, ""}.fail("expected[" + std::to_string(k) + "].figure",
                                          figure.message);
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
    setup.calibration =
        std::make_unique<fit::Calibration>(c.model, c.stepping, setup.targets, parameters, options,
                                           setup.force_curves, std::move(more_blocks));
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
  if (!r.force_misfits.empty()) {
    const OverallForceMisfit force = overall_force_misfit(r);
    figures["fit.force_rms"] = force.rms;
    figures["fit.force_largest"] = force.largest;
    figures["fit.force_rms_share"] = force.scale > 0.0 ? force.rms / force.scale : 0.0;
    for (size_t k = 0; k < r.force_misfits.size(); ++k) {
      const std::string curve = "fit.force_curves." + std::to_string(k) + ".";
      figures[curve + "rms_relative"] = r.force_misfits[k].rms_relative;
      figures[curve + "systematic"] = r.force_misfits[k].systematic ? 1.0 : 0.0;
    }
  }
  for (size_t k = 0; k < r.other_targets.size(); ++k)
    for (const auto& [name, value] : r.other_targets[k].figures)
      figures["fit.other_targets." + std::to_string(k) + "." + name] = value;
  return figures;
}

Experiment mesh_check_experiment(const Experiment& ex, std::string* resolution) {
  if (!ex.fit() || ex.fit()->mesh_check == "none")
    throw std::logic_error("mesh_check_experiment: the fit asks for no mesh check");
  // The fit as resolved: Levenberg-Marquardt from its values (a multi-start
  // search has found its optimum), nothing checked.
  json document = ex.resolved;
  document.erase("expected");
  json& fit_section = document["fit"];
  fit_section["mesh_check"] = "none";
  for (const char* key : {"start_from", "starts", "same_optimum"}) fit_section.erase(key);
  if (fit_section.value("method", "") == "multistart")
    fit_section["method"] = "levenberg-marquardt";
  const bool by_halves =
      document.contains("surface") && document["surface"].contains("subdivisions");
  const double ratio = by_halves ? 2.0 : 1.5;
  const double factor = ex.fit()->mesh_check == "coarser" ? 1.0 / ratio : ratio;
  const std::filesystem::path folder = ex.source.parent_path();
  try {
    double actual = 0.0;
    json other = refined_document(document, StudiedMesh::Surface, factor, resolution, &actual);
    const std::string label = ex.source.string() + " [mesh check, " + *resolution + "]";
    const geom::Surface given = ex.built() ? ex.simulation().cases.front().input_surface
                                           : surface_of(document, folder, ex.source.string());
    other = with_same_vertices(document, given, other, surface_of(other, folder, label),
                               "the " + ex.fit()->mesh_check + " mesh (" + *resolution + ")",
                               /*with_fit=*/true);
    return parse_experiment(other, folder, label);
  } catch (const InputError& e) {
    throw InputError("fit.mesh_check: " + std::string(e.what()));
  }
}

MeshCheck run_mesh_check(const Experiment& at_fit) {
  MeshCheck check;
  try {
    const Experiment other = mesh_check_experiment(at_fit, &check.resolution);
    FitSetup setup = setup_fit(other, {});
    check.fitted = setup.calibration->run();
  } catch (const Interrupted&) {
    throw;
  } catch (const std::exception& e) {
    check.failure = e.what();
  }
  if (check.failure.empty() && check.fitted.status == fit::FitStatus::Interrupted)
    throw Interrupted("interrupted during the mesh check");
  if (check.failure.empty() && check.fitted.status == fit::FitStatus::StartFailed)
    check.failure = "its fit could not start: " + check.fitted.message;
  return check;
}

std::map<std::string, double> mesh_check_figures(const fit::FitResult& fitted,
                                                 const MeshCheck& check) {
  std::map<std::string, double> figures;
  for (size_t k = 0; k < fitted.names.size() && k < check.fitted.names.size(); ++k) {
    const auto i = static_cast<Eigen::Index>(k);
    figures["fit.mesh_check." + fitted.names[k]] = check.fitted.values[i];
    figures["fit.mesh_shift." + fitted.names[k]] = check.fitted.values[i] - fitted.values[i];
  }
  return figures;
}

void write_material_values(const model::Material& m, int dim, json& material) {
  material["gamma"] = m.surface_tension;
  if (material.contains("law")) {
    for (const std::string& name : m.law.parameter_names())
      material["law"][name] = m.law.parameter(name);
    const bool factored = (m.axis_factors.head(dim).array() != 1.0).any();
    if (factored || material.contains("axis_factors")) {
      material["axis_factors"] = json::array();
      for (int a = 0; a < dim; ++a) material["axis_factors"].push_back(m.axis_factors[a]);
    }
    return;
  }
  const double Y = m.law.parameter("Y");
  const bool per_axis = (material.contains("Y") && material["Y"].is_array()) ||
                        (m.axis_factors.head(dim).array() != 1.0).any();
  if (!per_axis) {
    material["Y"] = Y * m.axis_factors[0];
    return;
  }
  material["Y"] = json::array();
  for (int a = 0; a < dim; ++a) material["Y"].push_back(Y * m.axis_factors[a]);
}

Experiment with_fitted_material(const Experiment& experiment, const fit::Calibration& calibration,
                                const fit::FitResult& result) {
  Experiment fitted = experiment;
  const fit::ParameterMap& map = calibration.parameters();
  model::Material& material = fitted.simulation().cases.front().model.material;
  material = map.material(material, result.values);
  // The folder's run is at the fitted values: so is its
  // experiment.resolved.json, which repeats that run (it said the start's:
  // issue 43, the run and its record built from different specs).
  if (fitted.resolved.is_object() && fitted.resolved.contains("material"))
    write_material_values(material, fitted.simulation().cases.front().model.dim(),
                          fitted.resolved["material"]);
  return fitted;
}

std::map<std::string, double> multistart_figures(const fit::MultistartResult& search) {
  return {{"fit.optima", static_cast<double>(search.optima.size())},
          {"fit.best_optimum_starts",
           search.optima.empty() ? 0.0 : static_cast<double>(search.optima.front().starts.size())}};
}

}  // namespace fiberfluid::experiment

namespace fiberfluid::experiment {

JointSetup setup_joint(const Experiment& ex,
                       std::function<void(const fit::IterationRecord&)> progress) {
  if (ex.kind() != Experiment::Kind::Calibration)
    throw InputError(ex.source.string() + ": not a calibration over specimens");
  require_built(ex);
  const CalibrationSpec& spec = ex.calibration().spec;
  JointSetup setup;
  std::vector<const fit::Calibration*> calibrations;
  std::vector<std::string> names;
  for (size_t s = 0; s < ex.calibration().specimens.size(); ++s) {
    setup.specimens.push_back(setup_fit(ex.calibration().specimens[s]));
    calibrations.push_back(setup.specimens.back().calibration.get());
    names.push_back(spec.specimens[s].name);
  }
  fit::JointOptions options;
  options.max_iterations = spec.max_iterations;
  options.progress = std::move(progress);
  const FieldName root{ex.source.string(), ""};
  try {
    setup.joint = std::make_unique<fit::JointCalibration>(names, calibrations, spec.shared,
                                                          std::move(options));
  } catch (const InputError& e) {
    root.fail("shared", e.what());
  }
  for (size_t k = 0; k < ex.expected.size(); ++k)
    if (const Status figure = check_figure(ex, ex.expected[k].figure); !figure.ok)
      root.fail("expected[" + std::to_string(k) + "].figure", figure.message);
  return setup;
}

std::map<std::string, double> joint_figures(const Experiment& ex, const fit::JointFitResult& r) {
  std::map<std::string, double> figures = {{"fit.cost", r.final_cost}};
  for (size_t k = 0; k < r.names.size(); ++k)
    figures["fit." + r.names[k]] = r.values[static_cast<Eigen::Index>(k)];
  for (size_t s = 0; s < r.specimens.size() && s < ex.calibration().spec.specimens.size(); ++s) {
    const std::string prefix = "fit." + ex.calibration().spec.specimens[s].name + ".";
    const fit::DistanceStatistics& d = r.specimens[s].overall;
    figures[prefix + "distance_mean"] = d.mean;
    figures[prefix + "distance_rms"] = d.rms;
    figures[prefix + "distance_sd"] = d.standard_deviation;
    figures[prefix + "distance_largest"] = d.largest;
    figures[prefix + "distance_sd_share"] = d.share(d.standard_deviation);
  }
  return figures;
}

}  // namespace fiberfluid::experiment

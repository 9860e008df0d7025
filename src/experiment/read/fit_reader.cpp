// SPDX-License-Identifier: GPL-3.0-or-later
// The "fit" section of a simulation: targets, parameters, options.
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "fiberfluid/experiment/read/json_fields.hpp"
#include "fiberfluid/experiment/read/readers.hpp"
#include "fiberfluid/experiment/targets/target_kinds.hpp"
#include "fiberfluid/util/error.hpp"

namespace fiberfluid::experiment {
namespace {

using nlohmann::json;

// A target of "type": "force": a CSV curve of a paddle's or a support's force.
FitForceSpec read_force_target(Fields& t, const std::filesystem::path& folder) {
  FitForceSpec curve;
  curve.field = t.field();
  curve.file = t.string("file");
  if (curve.file.is_relative()) curve.file = folder / curve.file;
  t.resolve("file", absolute_path(curve.file));
  if (t.has("paddle") == t.has("support"))
    t.fail("paddle",
           "expected the label of a paddle, or a support (\"support\"), whose force "
           "the curve measured: one of them");
  if (t.has("paddle")) {
    curve.paddle = t.string("paddle");
  } else {
    curve.support = t.string("support");
    curve.axis = t.choice("axis", "", {"x", "y", "z"})[0] - 'x';  // the reaction's component
  }
  if (t.has("paddle") && t.has("axis"))
    t.fail("axis", "a paddle's force is along its own axis: give axis only with a support");
  if (t.has("weight")) curve.weight = t.positive("weight", 1.0);
  fit::ForceCurveColumns& columns = curve.columns;
  if (t.has("rows_at")) columns.rows_at = t.choice("rows_at", "", {"travel", "step"});
  columns.travel_scale = length_units(t, "travel_units");
  const std::string force = t.choice("force_units", "N", {"N", "mN", "kN"});
  columns.force_scale = force == "mN" ? 1e-3 : force == "kN" ? 1e3 : 1.0;
  // A measured file's own column names, its scatter, the part of it fitted.
  columns.travel = t.string("travel_column", columns.travel);
  columns.step = t.string("step_column", columns.step);
  columns.force = t.string("force_column", columns.force);
  if (t.has("sd_column")) columns.sd = t.string("sd_column");
  if (t.has("range")) {
    const Eigen::VectorXd range = t.vector("range", 2);
    if (!(range[0] <= range[1]))
      t.fail("range", "expected [from, to] with from <= to (in the file's travel units or steps)");
    columns.from = range[0];
    columns.to = range[1];
  }
  curve.relative = t.choice("misfit", "newtons", {"newtons", "relative"}) == "relative";
  t.finish();
  return curve;
}

// fit.targets: the surfaces and force curves.
void read_fit_targets(Fields& f, const std::filesystem::path& folder, FitSpec& spec) {
  std::vector<std::string> types = {"surface", "force"};
  for (const TargetKind& kind : target_kinds()) types.push_back(kind.type);
  for (Fields t : f.objects("targets")) {
    const std::string type = t.choice("type", "surface", types);
    if (type == "force") {
      spec.force_curves.push_back(read_force_target(t, folder));
      continue;
    }
    if (type != "surface") {
      for (const TargetKind& kind : target_kinds())
        if (type == kind.type) spec.kind_targets.push_back(kind.read(t, folder));
      continue;
    }
    FitTargetSpec target;
    target.field = t.field();
    target.file = t.string("file");
    if (target.file.is_relative()) target.file = folder / target.file;
    t.resolve("file", absolute_path(target.file));
    target.step = t.integer("step", 0, 1, 100000);
    if (t.has("scale") && t.has("units"))
      t.fail("units", "give the scan's units or its scale, not both");
    if (t.has("units")) target.scale = length_units(t, "units");
    target.scale = t.positive("scale", target.scale);
    t.finish();
    spec.targets.push_back(target);
  }
  if (spec.targets.empty() && spec.force_curves.empty() && spec.kind_targets.empty())
    f.fail("targets", "expected at least one target (a surface, a force curve, ...)");
}

// fit.parameters: each fitted once.
void read_fit_parameters(Fields& f, FitSpec& spec) {
  for (Fields p : f.objects("parameters")) {
    FitParameterSpec parameter;
    parameter.field = p.field();
    parameter.request.name = p.string("name");
    for (const FitParameterSpec& other : spec.parameters)
      if (other.request.name == parameter.request.name)
        p.fail("name", "\"" + parameter.request.name + "\" is fitted twice");
    if (p.has("start")) parameter.request.start = p.number("start");
    if (p.has("lower")) parameter.request.lower = p.number("lower");
    if (p.has("upper")) parameter.request.upper = p.number("upper");
    if (p.has("log_scale")) parameter.request.log_scale = p.boolean("log_scale", false);
    p.finish();
    spec.parameters.push_back(parameter);
  }
  if (spec.parameters.empty()) f.fail("parameters", "expected at least one parameter to fit");
}

// The fit's method and options.
void read_fit_options(Fields& f, FitSpec& spec) {
  // The options' values are checked once, by fit::check_options, for every
  // front end alike (its messages begin with the option's name); here only
  // their types.
  const auto named = [&f](const std::string& key, const InputError& e) {
    const std::string what = e.what();
    const size_t colon = what.find(": ");
    f.fail(key, colon == std::string::npos ? what : what.substr(colon + 2));
  };
  fit::FitOptions& o = spec.options;
  const std::string method = f.string("method", "levenberg-marquardt");
  if (method == "multistart") {  // Levenberg-Marquardt from many starts
    fit::MultistartOptions multistart;
    multistart.starts = f.integer("starts", multistart.starts, 2, 100000);
    multistart.same_optimum = f.number("same_optimum", multistart.same_optimum);
    try {
      fit::check_options(multistart);
    } catch (const InputError& e) {
      named("same_optimum", e);
    }
    spec.multistart = multistart;
  } else {
    try {
      o.method = fit::method_from_string(method);
    } catch (const InputError&) {
      f.fail("method",
             "expected levenberg-marquardt, bobyqa, direct-l, crs2 or multistart, got \"" +
                 method.substr(0, 40) + "\"");
    }
    for (const char* key : {"starts", "same_optimum"})
      if (f.has(key)) f.fail(key, "only with \"method\": \"multistart\"");
    // Every option is honoured by the method it is given with, or refused.
    if (o.method != fit::Method::LevenbergMarquardt)
      for (const char* key : {"max_iterations", "initial_trust_region_radius", "max_step_factor",
                              "max_step_share", "scale_start"})
        if (f.has(key))
          f.fail(key, "only with levenberg-marquardt or multistart (" + method +
                          " takes no trust-region steps: max_evaluations bounds its runs)");
  }
  o.finite_differences =
      f.choice("jacobian", "analytic", {"analytic", "finite-differences"}) == "finite-differences";
  o.difference_step = f.number("difference_step", o.difference_step);
  if (f.has("objective")) {
    Fields objective = f.object("objective");
    o.symmetric = objective.boolean("symmetric", false);
    try {
      o.loss = fit::loss_from_string(objective.string("loss", "squared"));
    } catch (const InputError& e) {
      named("objective.loss", e);
    }
    o.loss_scale = objective.number("loss_scale", o.loss_scale);
    if (objective.has("exclude")) {
      Fields exclude = objective.object("exclude");
      spec.exclude = read_selection(exclude);
      exclude.finish();
    }
    objective.finish();
  }
  const int any_min = std::numeric_limits<int>::min(), any_max = std::numeric_limits<int>::max();
  o.max_iterations = f.integer("max_iterations", o.max_iterations, any_min, any_max);
  o.max_evaluations = f.integer("max_evaluations", o.max_evaluations, any_min, any_max);
  o.function_tolerance = f.number("function_tolerance", o.function_tolerance);
  o.parameter_tolerance = f.number("parameter_tolerance", o.parameter_tolerance);
  o.initial_trust_region_radius =
      f.number("initial_trust_region_radius", o.initial_trust_region_radius);
  o.max_step_factor = f.number("max_step_factor", o.max_step_factor);
  o.max_step_share = f.number("max_step_share", o.max_step_share);
  o.scale_start = f.boolean("scale_start", o.scale_start);
  o.warm_start = f.boolean("warm_start", o.warm_start);
  o.check_intervals = f.boolean("check_intervals", o.check_intervals);
  try {
    fit::check_options(o);
  } catch (const InputError& e) {
    const std::string what = e.what();
    const std::string option = what.substr(0, what.find(':'));
    named(option == "loss_scale" ? "objective.loss_scale" : option, e);
  }
}

}  // namespace

// A file's length unit ("m", "cm", "mm", "um"; default m) as the factor to m.
double length_units(Fields& f, const std::string& key) {
  const std::string units = f.choice(key, "m", {"m", "cm", "mm", "um"});
  return units == "cm" ? 1e-2 : units == "mm" ? 1e-3 : units == "um" ? 1e-6 : 1.0;
}

FitSpec read_fit(Fields f, const std::filesystem::path& folder) {
  FitSpec spec;
  spec.field = f.field();
  read_fit_targets(f, folder, spec);
  read_fit_parameters(f, spec);
  spec.mesh_check = f.choice("mesh_check", "none", {"none", "coarser", "finer"});
  if (f.has("start_from")) {
    spec.start_from = f.string("start_from");
    if (spec.start_from->is_relative()) spec.start_from = folder / *spec.start_from;
    f.resolve("start_from", absolute_path(*spec.start_from));
  }
  read_fit_options(f, spec);
  f.finish();
  return spec;
}

}  // namespace fiberfluid::experiment

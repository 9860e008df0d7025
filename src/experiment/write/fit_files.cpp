// SPDX-License-Identifier: GPL-3.0-or-later
#include "fiberfluid/experiment/write/fit_files.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <limits>
#include <map>
#include <sstream>

#include "fiberfluid/experiment/write/summary_json.hpp"
#include "fiberfluid/geom/mesh_io.hpp"
#include "fiberfluid/geom/vtk_writer.hpp"
#include "fiberfluid/model/assembly.hpp"
#include "fiberfluid/model/equilibrium.hpp"
#include "fiberfluid/util/error.hpp"

namespace fiberfluid::experiment {
namespace {

using nlohmann::json;

// NaN and infinities as JSON null.

json statistics_json(const fit::DistanceStatistics& s) {
  return {{"count", s.count},
          {"mean", finite_or_null(s.mean)},
          {"rms", finite_or_null(s.rms)},
          {"standard_deviation", finite_or_null(s.standard_deviation)},
          {"largest", finite_or_null(s.largest)},
          {"share_of_length",
           {{"mean", finite_or_null(s.share(s.mean))},
            {"rms", finite_or_null(s.share(s.rms))},
            {"standard_deviation", finite_or_null(s.share(s.standard_deviation))},
            {"largest", finite_or_null(s.share(s.largest))}}}};
}

// Row by row; a NaN entry (no estimate) as null.
json matrix_json(const Eigen::MatrixXd& m) {
  json rows = json::array();
  for (Eigen::Index a = 0; a < m.rows(); ++a) {
    json row = json::array();
    for (Eigen::Index b = 0; b < m.cols(); ++b) row.push_back(finite_or_null(m(a, b)));
    rows.push_back(row);
  }
  return rows;
}

json checks_json(const std::vector<FigureCheck>& checks) {
  json out = json::array();
  for (const FigureCheck& check : checks)
    out.push_back({{"figure", check.expected.figure},
                   {"passed", check.passed},
                   {"actual", finite_or_null(check.actual)},
                   {"text", check.Describe()}});
  return out;
}

json iteration_json(const fit::IterationRecord& it, const std::vector<std::string>& names) {
  json values = json::object();
  for (size_t k = 0; k < names.size(); ++k)
    values[names[k]] = it.values[static_cast<Eigen::Index>(k)];
  json out = {{"iteration", it.iteration}, {"cost", finite_or_null(it.cost)},
              {"accepted", it.accepted},   {"trial_cost", finite_or_null(it.trial_cost)},
              {"values", values},          {"forward_runs", it.forward_runs},
              {"seconds", it.seconds}};
  if (!it.trial_failure.empty()) out["trial_failure"] = it.trial_failure;
  return out;
}

}  // namespace

namespace {

// The optimum (index into search.optima) start s reached, or -1.
int optimum_of(const fit::MultistartResult& search, int s) {
  for (size_t o = 0; o < search.optima.size(); ++o)
    for (int t : search.optima[o].starts)
      if (t == s) return static_cast<int>(o);
  return -1;
}

json multistart_json(const fit::MultistartResult& search, const std::vector<std::string>& names) {
  const auto values_json = [&](const Eigen::VectorXd& values) {
    json out = json::object();
    for (size_t k = 0; k < names.size(); ++k) out[names[k]] = values[static_cast<Eigen::Index>(k)];
    return out;
  };
  json starts = json::array();
  for (size_t s = 0; s < search.starts.size(); ++s) {
    const fit::StartOutcome& o = search.starts[s];
    starts.push_back({{"start", values_json(o.start)},
                      {"end", values_json(o.fit.values)},
                      {"status", fit::to_string(o.fit.status)},
                      {"message", o.fit.message},
                      {"cost", finite_or_null(o.fit.final_cost)},
                      {"optimum", optimum_of(search, static_cast<int>(s))},
                      {"iterations", o.fit.iterations.size()},
                      {"forward_runs", o.fit.forward_runs},
                      {"seconds", o.fit.seconds},
                      {"rank", o.rank}});
  }
  json optima = json::array();
  for (const fit::Optimum& o : search.optima)
    optima.push_back({{"values", values_json(o.values)},
                      {"cost", finite_or_null(o.cost)},
                      {"starts_reached", o.starts.size()},
                      {"starts", o.starts}});
  return {{"starts", starts},
          {"optima", optima},
          {"optima_are",
           "the converged starts' ends, clustered: one optimum where every fitted "
           "variable (log of a log-scaled parameter) agrees to same_optimum of its "
           "range; cheapest first"},
          {"best_start", search.best_start},
          {"best_found_once", search.best_found_once},
          {"seconds", search.seconds}};
}

}  // namespace

namespace {

// fit.json's parameters: each fitted value with its error, interval and bounds.
json parameters_json(const fit::Calibration& c, const fit::FitResult& r) {
  json parameters = json::array();
  for (size_t k = 0; k < r.names.size(); ++k) {
    const Eigen::Index i = static_cast<Eigen::Index>(k);
    const fit::Parameter& p = c.parameters().parameters()[k];
    const bool at_bound =
        std::find(r.at_bounds.begin(), r.at_bounds.end(), r.names[k]) != r.at_bounds.end();
    parameters.push_back(
        {{"name", r.names[k]},
         {"initial", r.initial[i]},
         {"value", finite_or_null(r.values[i])},
         {"at_bound", at_bound},
         {"seen_by_the_data",
          std::find(r.unseen.begin(), r.unseen.end(), r.names[k]) == r.unseen.end()},
         {"standard_error", finite_or_null(r.standard_errors[i])},
         {"interval_95", {finite_or_null(r.lower_95[i]), finite_or_null(r.upper_95[i])}},
         {"interval_note", k < r.interval_notes.size() ? r.interval_notes[k] : ""},
         {"bounds", {finite_or_null(p.lower), finite_or_null(p.upper)}},
         {"log_scale", p.log_scale}});
  }
  return parameters;
}

// fit.json's targets: each scan, the step it was measured at, its distances.
json targets_json(const FitSetup& setup, const fit::FitResult& r) {
  json targets = json::array();
  for (size_t t = 0; t < setup.targets.size(); ++t) {
    json target = {{"file", setup.targets[t].target.label},
                   {"step", setup.targets[t].step},
                   {"read", setup.targets[t].target.description},
                   {"points", setup.targets[t].target.points.rows()}};
    if (t < r.statistics.size()) target["distance"] = statistics_json(r.statistics[t]);
    targets.push_back(target);
  }
  return targets;
}

// fit.json's force curves: what each reads, its weight, its misfit.
json force_curves_json(const Experiment& ex, const FitSetup& setup, const fit::Calibration& c,
                       const fit::FitResult& r) {
  json curves = json::array();
  for (size_t k = 0; k < setup.force_curves.size(); ++k) {
    const fit::ForceCurve& f = setup.force_curves[k];
    const bool paddle = f.source == fit::ForceCurve::Source::Paddle;
    const model::Model& model = ex.simulation().cases.front().model;
    json curve = {
        {"file", f.label},
        {paddle ? "paddle" : "support",
         paddle ? model.paddles[static_cast<size_t>(f.index)].label
                : model.constraint_groups[static_cast<size_t>(f.index)]},
        {"axis", std::string(1, "xyz"[f.axis])},
        {"force_is", paddle ? "the paddle's push into the body along its axis (N)"
                            : "the support's reaction on the body along the axis (N)"},
        {"rows", f.force.size()},
        {"rows_at", f.by_step ? "load steps" : "travel (m), between the steps around it"},
        {"weight", c.force_weight(k)},
        {"weight_is", "m per N: a force misfit of 1 N counts as a distance of this many m"}};
    if (k < r.force_misfits.size()) {
      const fit::ForceMisfit& m = r.force_misfits[k];
      curve["misfit"] = {
          {"weighed", m.relative ? "relative: each row's share of its force" : "in newtons"},
          {"rms", finite_or_null(m.rms)},
          {"largest", finite_or_null(m.largest)},
          {"largest_measured", finite_or_null(m.scale)},
          {"share_of_largest_measured",
           {{"rms", finite_or_null(m.share(m.rms))},
            {"largest", finite_or_null(m.share(m.largest))}}},
          {"rms_relative", finite_or_null(m.rms_relative)},
          {"measurement_scatter", finite_or_null(m.scatter)},
          {"sign_runs", m.runs},
          {"sign_runs_of_noise", finite_or_null(m.runs_expected)},
          {"sign_runs_z", finite_or_null(m.runs_z)},
          {"systematic", m.systematic},
          {"verdict", m.verdict}};
    }
    curves.push_back(curve);
  }
  return curves;
}

}  // namespace

// fit.mesh_check: the other mesh, how its fit ended, and each parameter
// there beside the fit's (its values stand however its fit ended: the status
// says whether they are an optimum).
json mesh_check_json(const Experiment& ex, const fit::FitResult& r, const MeshCheck& check) {
  json out = {{"mesh", ex.fit()->mesh_check}, {"resolution", check.resolution}};
  if (!check.failure.empty()) {
    out["status"] = "failed";
    out["failure"] = check.failure;
    return out;
  }
  out["status"] = fit::to_string(check.fitted.status);
  out["message"] = check.fitted.message;
  json values = json::object();
  for (size_t k = 0; k < r.names.size() && k < check.fitted.names.size(); ++k) {
    const auto i = static_cast<Eigen::Index>(k);
    values[r.names[k]] = {{"value", finite_or_null(check.fitted.values[i])},
                          {"shift", finite_or_null(check.fitted.values[i] - r.values[i])}};
  }
  out["parameters"] = values;
  return out;
}

json fit_json(const Experiment& ex, const FitSetup& setup, const fit::FitResult& r,
              const ExperimentResult& run, const fit::MultistartResult* search,
              const MeshCheck* mesh_check) {
  const fit::Calibration& c = *setup.calibration;
  json iterations = json::array();
  for (const fit::IterationRecord& it : r.iterations)
    iterations.push_back(iteration_json(it, r.names));
  const json parameters = parameters_json(c, r), targets = targets_json(setup, r),
             curves = force_curves_json(ex, setup, c, r);
  json failures = json::object();
  for (const auto& [cause, count] : r.failures_by_cause) failures[cause] = count;
  json examples = json::array();
  for (const fit::FailedRun& f : r.failed_examples) {
    json values = json::object();
    for (size_t k = 0; k < r.names.size(); ++k)
      values[r.names[k]] = f.values[static_cast<Eigen::Index>(k)];
    examples.push_back({{"values", values}, {"message", f.message}});
  }
  const int counted = c.num_counted_vertices();
  int target_points = 0;
  for (const fit::MeasuredStep& t : setup.targets)
    target_points += static_cast<int>(t.target.points.rows());
  size_t force_rows = 0;
  for (const fit::ForceCurve& f : setup.force_curves) force_rows += f.force.size();
  json doc = {
      {"experiment", ex.name},
      {"status", fit::to_string(r.status)},
      {"status_detail", r.status_detail},
      {"success", r.success},
      {"message", r.message},
      {"start_note", r.start_note},
      {"warm_started_runs", r.warm_started_runs},
      {"warm_start_note", r.warm_start_note},
      {"method", fit::to_string(r.method)},
      {"jacobian", r.analytic_jacobian ? "analytic: Newton sensitivities, one tangent solve per "
                                         "material parameter"
                                       : "finite differences of whole forward runs (central)"},
      {"loss", fit::to_string(ex.fit()->options.loss)},
      {"symmetric", ex.fit()->options.symmetric},
      {"parameters", parameters},
      {"covariance", r.covariance_ok ? "ceres covariance at the optimum, scaled by the "
                                       "residual variance"
                                     : "not available (see status)"},
      {"correlation", matrix_json(r.correlation)},
      {"unseen", r.unseen},
      {"cost",
       {{"initial", finite_or_null(r.initial_cost)}, {"final", finite_or_null(r.final_cost)}}},
      {"iterations", iterations},
      {"forward_runs", r.forward_runs},
      {"interval_runs", r.interval_runs},
      {"sensitivity_solves", r.sensitivity_solves},
      {"failed_runs", r.failed_runs},
      {"failed_runs_by_cause", failures},
      {"failed_run_examples", examples},
      {"seconds", r.seconds},
      {"body_length", c.body_length()},
      {"body_length_is", "the largest extent of the rest surface's bounding box"},
      {"counts",
       {{"model_vertices_counted", counted},
        {"targets", setup.targets.size()},
        {"target_points", target_points},
        {"forward_distances", counted * static_cast<int>(setup.targets.size())},
        {"symmetric_distances", ex.fit()->options.symmetric ? target_points : 0},
        {"force_curves", setup.force_curves.size()},
        {"force_rows", force_rows},
        {"residuals", c.num_residuals()},
        {"what_distance_counts",
         "distance.count and targets[].distance.count are forward distances: one per counted "
         "model vertex and target. The symmetric distances (each target point to the simulated "
         "surface), when asked, enter the cost and the residuals, not these statistics"}}},
      {"targets", targets},
      {"force_curves", curves},
      {"checks", checks_json(run.checks)}};
  if (!r.statistics.empty()) doc["distance"] = statistics_json(r.overall);
  if (!r.other_targets.empty()) {  // targets of the registered kinds, each with its figures
    json others = json::array();
    for (size_t k = 0; k < r.other_targets.size(); ++k) {
      const fit::TargetReport& t = r.other_targets[k];
      json figures = json::object();
      for (const auto& [name, value] : t.figures) figures[name] = finite_or_null(value);
      others.push_back({{"type", t.kind}, {"label", t.label}, {"figures", figures}});
    }
    doc["other_targets"] = others;
    doc["counts"]["other_targets"] = others.size();
  }
  if (search != nullptr) {
    doc["method"] = "multistart";
    doc["multistart"] = multistart_json(*search, r.names);
  }
  if (mesh_check != nullptr) doc["mesh_check"] = mesh_check_json(ex, r, *mesh_check);
  return doc;
}

void write_fit_files(const std::filesystem::path& folder, const Experiment& ex,
                     const FitSetup& setup, const fit::FitResult& r, const ExperimentResult& run,
                     const fit::MultistartResult* search, const MeshCheck* mesh_check) {
  geom::write_text_file(folder / fit_files::kReport,
                        fit_json(ex, setup, r, run, search, mesh_check).dump(2) + "\n");
  if (search != nullptr) {
    std::ostringstream starts;
    starts.precision(12);
    starts << "start,rank,status,cost_m2,optimum,iterations,forward_runs,seconds";
    for (const std::string& name : r.names) starts << ",start_" << name;
    for (const std::string& name : r.names) starts << ",end_" << name;
    starts << "\n";
    for (size_t s = 0; s < search->starts.size(); ++s) {
      const fit::StartOutcome& o = search->starts[s];
      starts << s << "," << o.rank << "," << fit::to_string(o.fit.status) << "," << o.fit.final_cost
             << "," << optimum_of(*search, static_cast<int>(s)) << "," << o.fit.iterations.size()
             << "," << o.fit.forward_runs << "," << o.fit.seconds;
      for (Eigen::Index k = 0; k < o.start.size(); ++k) starts << "," << o.start[k];
      for (Eigen::Index k = 0; k < o.fit.values.size(); ++k) starts << "," << o.fit.values[k];
      starts << "\n";
    }
    geom::write_text_file(folder / fit_files::kStarts, starts.str());
  }
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
  geom::write_text_file(folder / fit_files::kIterations, iterations.str());
  for (size_t k = 0; k < r.other_targets.size(); ++k) {  // a target of another kind's rows
    const fit::TargetReport& t = r.other_targets[k];
    if (t.columns.empty()) continue;
    std::ostringstream rows;
    for (size_t c = 0; c < t.columns.size(); ++c) rows << (c ? "," : "") << t.columns[c];
    rows << "\n";
    for (const std::vector<std::string>& row : t.rows) {
      for (size_t c = 0; c < row.size(); ++c) rows << (c ? "," : "") << row[c];
      rows << "\n";
    }
    geom::write_text_file(folder / fit_files::kOtherTarget.name(k), rows.str());
  }
  if (r.positions.size() != setup.targets.size()) return;  // no run at the fitted values
  for (size_t k = 0; k < r.force_misfits.size() && k < setup.force_curves.size(); ++k) {
    const fit::ForceCurve& f = setup.force_curves[k];
    std::ostringstream rows;
    rows.precision(12);
    rows << (f.by_step ? "step" : "travel_m") << ",measured_N,simulated_N,misfit_N\n";
    for (size_t i = 0; i < f.force.size(); ++i) {
      const double simulated = r.force_misfits[k].simulated[i];
      rows << f.at[i] << "," << f.force[i] << "," << simulated << "," << simulated - f.force[i]
           << "\n";
    }
    geom::write_text_file(folder / fit_files::kForceCurve.name(k), rows.str());
  }

  const Case& c = ex.simulation().cases.front();
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
    geom::write_vtu(folder / fit_files::kTargetSurface.name(t), at_step,
                    {{"distance_to_target", shown}, {"counted", counted}});
    geom::Surface scan;
    scan.V = setup.targets[t].target.points;
    scan.F = setup.targets[t].target.triangles;
    if (scan.F.rows() > 0) geom::write_obj(folder / fit_files::kTargetScan.name(t), scan);
  }
  geom::write_text_file(folder / fit_files::kDistances, distances.str());
}

void write_joint_files(const std::filesystem::path& folder, const Experiment& ex,
                       const JointSetup& setup, const fit::JointFitResult& r,
                       const ExperimentResult& checked) {
  json parameters = json::array();
  for (size_t k = 0; k < r.names.size(); ++k) {
    const auto i = static_cast<Eigen::Index>(k);
    parameters.push_back(
        {{"name", r.names[k]},
         {"shared", static_cast<int>(k) < r.shared},
         {"initial", r.initial[i]},
         {"value", finite_or_null(r.values[i])},
         {"standard_error", finite_or_null(r.standard_errors[i])},
         {"interval_95", {finite_or_null(r.lower_95[i]), finite_or_null(r.upper_95[i])}}});
  }
  json specimens = json::array();
  for (size_t s = 0; s < setup.specimens.size(); ++s) {
    json specimen = {{"name", ex.calibration().spec.specimens[s].name},
                     {"experiment", ex.calibration().specimens[s].source.string()},
                     {"body_length", setup.specimens[s].calibration->body_length()},
                     {"residuals", setup.specimens[s].calibration->num_residuals()}};
    if (s < r.specimens.size() && !r.specimens[s].statistics.empty()) {
      const fit::FitResult& f = r.specimens[s];
      specimen["distance"] = statistics_json(f.overall);
      json values = json::object();
      for (size_t k = 0; k < f.names.size(); ++k)
        values[f.names[k]] = f.values[static_cast<Eigen::Index>(k)];
      specimen["values"] = values;
      specimen["cost"] = finite_or_null(f.final_cost);
    }
    specimens.push_back(specimen);
  }
  json iterations = json::array();
  for (const fit::IterationRecord& it : r.iterations)
    iterations.push_back(iteration_json(it, r.names));
  const json doc = {
      {"experiment", ex.name},
      {"status", fit::to_string(r.status)},
      {"status_detail", r.status_detail},
      {"success", r.success},
      {"message", r.message},
      {"method", "levenberg-marquardt over every specimen's distances (analytic Jacobian blocks)"},
      {"shared", ex.calibration().spec.shared},
      {"parameters", parameters},
      {"intervals_are",
       "95%, from (J^T J)^-1 at the optimum scaled by the residual variance 2 "
       "cost / (residuals - parameters); in log scale for log-scaled parameters"},
      {"correlation", matrix_json(r.correlation)},
      {"cost",
       {{"initial", finite_or_null(r.initial_cost)}, {"final", finite_or_null(r.final_cost)}}},
      {"residuals", r.residuals},
      {"evaluations", r.evaluations},
      {"seconds", r.seconds},
      {"specimens", specimens},
      {"iterations", iterations},
      {"checks", checks_json(checked.checks)}};
  geom::write_text_file(folder / fit_files::kCalibration, doc.dump(2) + "\n");
  std::ostringstream rows;
  rows.precision(12);
  rows << "iteration,cost_m2,accepted,forward_runs,seconds";
  for (const std::string& name : r.names) rows << "," << name;
  rows << "\n";
  for (const fit::IterationRecord& it : r.iterations) {
    rows << it.iteration << "," << it.cost << "," << (it.accepted ? 1 : 0) << "," << it.forward_runs
         << "," << it.seconds;
    for (Eigen::Index k = 0; k < it.values.size(); ++k) rows << "," << it.values[k];
    rows << "\n";
  }
  geom::write_text_file(folder / fit_files::kCalibrationIterations, rows.str());
  // Each specimen's fit files at the joint optimum, in a folder of its own.
  for (size_t s = 0; s < r.specimens.size() && s < setup.specimens.size(); ++s) {
    if (r.specimens[s].statistics.empty()) continue;  // no run there
    const std::filesystem::path own = folder / ex.calibration().spec.specimens[s].name;
    std::filesystem::create_directories(own);
    const Experiment at_fit = with_fitted_material(ex.calibration().specimens[s],
                                                   *setup.specimens[s].calibration, r.specimens[s]);
    write_fit_files(own, at_fit, setup.specimens[s], r.specimens[s], ExperimentResult{});
  }
}

}  // namespace fiberfluid::experiment

// SPDX-License-Identifier: GPL-3.0-or-later
// The Python module `fiberfluid`: read and check meshes, build experiments
// from files or dicts, run them (sweeps too) and get the results as numpy
// arrays. A thin layer over fiberfluid::experiment; bad input raises ValueError with
// the library's message.
#include <pybind11/eigen.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <nlohmann/json.hpp>

#include "fiberfluid/experiment/experiment.hpp"
#include "fiberfluid/experiment/fit_workflow.hpp"
#include "fiberfluid/experiment/read/schema.hpp"
#include "fiberfluid/experiment/run/fit_setup.hpp"
#include "fiberfluid/experiment/run/runner.hpp"
#include "fiberfluid/experiment/write/output_folder.hpp"
#include "fiberfluid/experiment/write/outputs.hpp"
#include "fiberfluid/fit/calibration.hpp"
#include "fiberfluid/geom/mesh_check.hpp"
#include "fiberfluid/geom/mesh_io.hpp"
#include "fiberfluid/model/equilibrium.hpp"
#include "fiberfluid/model/report_names.hpp"
#include "fiberfluid/solve/newton/interactive_stepper.hpp"
#include "fiberfluid/util/error.hpp"
#include "fiberfluid/util/run_control.hpp"

namespace py = pybind11;
namespace ff = fiberfluid;

namespace {

// A simulation's cases; none for the other kinds (an area study, a benchmark,
// a calibration over specimens have no run of their own to show).
const std::vector<ff::experiment::Case>& cases_of(const ff::experiment::Experiment& ex) {
  static const std::vector<ff::experiment::Case> none;
  return ex.kind() == ff::experiment::Experiment::Kind::Simulate ? ex.simulation().cases : none;
}

// A plain dict (or list) to JSON, through Python's own json module.
nlohmann::json to_json(const py::object& document) {
  const std::string text = py::module_::import("json").attr("dumps")(document).cast<std::string>();
  return ff::experiment::parse_json(text, "<dict>");
}

py::object to_python(const nlohmann::json& document) {
  return py::module_::import("json").attr("loads")(document.dump());
}

// Per-step records of one run as numpy arrays (SI units).
py::dict steps_dict(const ff::experiment::Case& c, const ff::solve::SteppingSummary& s) {
  const auto n = static_cast<Eigen::Index>(s.steps.size());
  const int dim = c.model.dim();
  Eigen::VectorXi step(n);
  Eigen::VectorXd pressure(n), volume(n), max_displacement(n), residual(n), seconds(n);
  Eigen::MatrixXd applied(n, dim), factors(n, static_cast<Eigen::Index>(c.model.loads.size()));
  const size_t groups = std::max<size_t>(1, c.model.constraint_groups.size());
  std::vector<Eigen::MatrixXd> reactions(groups, Eigen::MatrixXd::Zero(n, dim));
  for (Eigen::Index k = 0; k < n; ++k) {
    const ff::solve::StepRecord& r = s.steps[static_cast<size_t>(k)];
    step[k] = r.step;
    pressure[k] = r.pressure;
    volume[k] = r.volume;
    max_displacement[k] = r.max_displacement;
    residual[k] = r.residual;
    seconds[k] = r.seconds;
    applied.row(k) = r.applied_force.head(dim).transpose();
    for (size_t l = 0; l < r.load_factors.size(); ++l)
      factors(k, static_cast<Eigen::Index>(l)) = r.load_factors[l];
    for (size_t g = 0; g < r.reactions.size() && g < groups; ++g)
      reactions[g].row(k) = r.reactions[g].head(dim).transpose();
  }
  py::dict out;
  out["step"] = step;
  out["pressure"] = pressure;
  out["volume"] = volume;
  out["max_displacement"] = max_displacement;
  out["equilibrium_residual"] = residual;
  out["seconds"] = seconds;
  out["applied_force"] = applied;
  py::dict load_factors;
  for (size_t l = 0; l < c.model.loads.size(); ++l)
    load_factors[py::str(c.model.loads[l].label)] =
        Eigen::VectorXd(factors.col(static_cast<Eigen::Index>(l)));
  out["load_factors"] = load_factors;
  py::dict reaction_dict;
  for (size_t g = 0; g < groups; ++g)
    reaction_dict[py::str(ff::model::constraint_group_name(c.model, g))] = reactions[g];
  out["reactions"] = reaction_dict;
  return out;
}

// One run's results: the deformed surface in input order, the steps, the figures.
py::dict run_dict(const ff::experiment::Experiment& ex,
                  const ff::experiment::ExperimentResult& result, size_t r) {
  const ff::experiment::Case& c = ex.simulation().cases[r];
  const ff::experiment::RunResult& run = result.runs[r];
  py::dict out;
  out["variant"] = run.variant;
  out["success"] = run.summary.success;
  out["message"] = run.summary.message;
  out["solver"] = std::string(ff::solve::to_string(run.summary.solver));
  out["reference_positions"] = c.input_surface.V;
  out["faces"] = c.input_surface.F;
  if (run.summary.success) {
    const Eigen::MatrixXd X = ff::experiment::input_positions(c, run.summary.unknowns);
    out["positions"] = X;
    out["displacements"] = Eigen::MatrixXd(X - c.input_surface.V);
    out["pressure"] = run.summary.unknowns[c.model.pressure_dof()];
  }
  out["steps"] = steps_dict(c, run.summary);
  py::dict figures;
  const std::string prefix = run.variant.empty() ? "" : run.variant + ".";
  for (const auto& [name, value] : result.figures)
    if (name.rfind(prefix, 0) == 0) figures[py::str(name.substr(prefix.size()))] = value;
  out["figures"] = figures;
  return out;
}

// Runs an experiment; with `output`, also writes its result folder as the
// command line does. Returns {"success", "runs": [...], "figures", "checks"}.
py::dict run(const ff::experiment::Experiment& ex, int jobs, const std::string& output) {
  ff::experiment::ExperimentResult result;
  {
    py::gil_scoped_release release;  // a long solve lets other Python threads run
    ff::experiment::RunOptions options;
    options.jobs = jobs;
    if (output.empty()) {
      result = ff::experiment::run_experiment(ex, {}, options);
    } else {
      ff::experiment::OutputWriter writer(ex, ff::experiment::output_folder(output, ex.name));
      writer.begin();
      result = ff::experiment::run_experiment(
          ex,
          [&](size_t run, const ff::solve::StepRecord& record, const Eigen::VectorXd& x) {
            writer.on_step(run, record, x);
          },
          options);
      writer.finish(result);
    }
  }
  py::dict out;
  out["success"] = result.runs_succeeded();
  py::list runs;
  for (size_t r = 0; r < result.runs.size(); ++r) runs.append(run_dict(ex, result, r));
  out["runs"] = runs;
  out["figures"] = result.figures;
  py::list checks;
  for (const ff::experiment::FigureCheck& c : result.checks) {
    py::dict check;
    check["figure"] = c.expected.figure;
    check["actual"] = c.actual;
    check["passed"] = c.passed;
    check["report"] = c.Describe();
    checks.append(check);
  }
  out["checks"] = checks;
  return out;
}

// A force target from Python: force with travel (m) or step, and paddle
// (a label) or support (a label) with axis; the same checks as a file's.
ff::fit::ForceCurve force_curve_from(const py::dict& t, const std::string& label,
                                     const ff::model::Model& model) {
  ff::fit::ForceCurve curve;
  curve.label = label;
  curve.force = t["force"].cast<std::vector<double>>();
  if (t.contains("travel") == t.contains("step"))
    throw ff::InputError(label + ": expected travel (m) or step with the force, one of them");
  curve.by_step = t.contains("step");
  curve.at = t[curve.by_step ? "step" : "travel"].cast<std::vector<double>>();
  if (t.contains("weight")) curve.weight = t["weight"].cast<double>();
  if (t.contains("paddle") == t.contains("support"))
    throw ff::InputError(label + ": expected paddle or support (a label), one of them");
  const bool paddle = t.contains("paddle");
  const std::string wanted = t[paddle ? "paddle" : "support"].cast<std::string>();
  std::vector<std::string> labels;
  if (paddle)
    for (const ff::model::Paddle& p : model.paddles) labels.push_back(p.label);
  else
    labels = model.constraint_groups;
  const auto found = std::find(labels.begin(), labels.end(), wanted);
  if (found == labels.end())
    throw ff::InputError(label + ": no " + (paddle ? "paddle" : "support") + " is labelled \"" +
                         wanted + "\"");
  curve.source =
      paddle ? ff::fit::ForceCurve::Source::Paddle : ff::fit::ForceCurve::Source::Support;
  curve.index = static_cast<int>(found - labels.begin());
  if (paddle) {
    curve.axis = model.paddles[static_cast<size_t>(curve.index)].axis;
  } else {
    const std::string axis = t.contains("axis") ? t["axis"].cast<std::string>() : "";
    if (axis != "x" && axis != "y" && axis != "z")
      throw ff::InputError(label + ": axis: expected x, y or z (the reaction's component)");
    curve.axis = axis[0] - 'x';
  }
  for (const double x : curve.at)
    if (!std::isfinite(x)) throw ff::InputError(label + ": a travel or step is not finite");
  for (const double x : curve.force)
    if (!std::isfinite(x)) throw ff::InputError(label + ": a force is not finite");
  if (const ff::Status usable = ff::fit::check_force_curve(curve, model); !usable.ok)
    throw ff::InputError(label + ": " + usable.message);
  return curve;
}

}  // namespace

// A fit of an experiment's material to measured surfaces given as numpy
// arrays: no JSON needed (fiberfluid.fit).
py::dict fit_experiment(const ff::experiment::Experiment& ex, const py::list& targets,
                        const py::list& parameters, const std::string& method,
                        const std::string& jacobian, bool symmetric, const std::string& loss,
                        double loss_scale, int max_iterations) {
  if (cases_of(ex).size() != 1) throw ff::InputError("fit: the experiment must be one simulation");
  const ff::experiment::Case& c = ex.simulation().cases.front();
  std::vector<ff::fit::MeasuredStep> measured;
  std::vector<ff::fit::ForceCurve> curves;
  for (size_t k = 0; k < targets.size(); ++k) {
    const py::dict t = targets[k].cast<py::dict>();
    const std::string label = "targets[" + std::to_string(k) + "]";
    if (t.contains("force")) {
      curves.push_back(force_curve_from(t, label, c.model));
      continue;
    }
    const double scale = t.contains("scale") ? t["scale"].cast<double>() : 1.0;
    if (!(scale > 0.0) || !std::isfinite(scale))
      throw ff::InputError(label + ": scale: expected a positive finite number");
    const Eigen::MatrixXd V = scale * t["vertices"].cast<Eigen::MatrixXd>();
    const Eigen::MatrixXi F =
        t.contains("faces") ? t["faces"].cast<Eigen::MatrixXi>() : Eigen::MatrixXi();
    const int step = t.contains("step") ? t["step"].cast<int>() : c.stepping.steps;
    measured.push_back({ff::fit::make_target(label, V, F), step});
  }
  // The same set-up and the same checks as the "fit" section of a file:
  // fit::make_parameter, the *_from_string readers and fit::check_options
  // (in Calibration's constructor).
  std::vector<ff::fit::Parameter> fitted;
  for (const py::handle& item : parameters) {
    const py::dict p = item.cast<py::dict>();
    ff::fit::ParameterRequest request;
    request.name = p["name"].cast<std::string>();
    if (p.contains("start")) request.start = p["start"].cast<double>();
    if (p.contains("lower")) request.lower = p["lower"].cast<double>();
    if (p.contains("upper")) request.upper = p["upper"].cast<double>();
    if (p.contains("log_scale")) request.log_scale = p["log_scale"].cast<bool>();
    fitted.push_back(ff::fit::make_parameter(request, c.model.material));
  }
  ff::fit::FitOptions options;
  options.method = ff::fit::method_from_string(method);
  if (jacobian != "analytic" && jacobian != "finite-differences")
    throw ff::InputError("jacobian: expected analytic or finite-differences, got \"" + jacobian +
                         "\"");
  options.finite_differences = jacobian == "finite-differences";
  options.symmetric = symmetric;
  options.loss = ff::fit::loss_from_string(loss);
  options.loss_scale = loss_scale;
  options.max_iterations = max_iterations;
  const ff::fit::Calibration calibration(c.model, c.stepping, measured, fitted, options, curves);
  ff::fit::FitResult r;
  {
    py::gil_scoped_release release;
    r = calibration.run();
  }
  py::dict out;
  out["status"] = ff::fit::to_string(r.status);
  out["status_detail"] = r.status_detail;
  out["success"] = r.success;
  out["message"] = r.message;
  out["failed_runs"] = r.failed_runs;
  out["analytic_jacobian"] = r.analytic_jacobian;
  py::dict values, errors, intervals;
  for (size_t k = 0; k < r.names.size(); ++k) {
    const auto i = static_cast<Eigen::Index>(k);
    if (r.values.size() == 0) break;
    values[py::str(r.names[k])] = r.values[i];
    errors[py::str(r.names[k])] = r.standard_errors[i];
    intervals[py::str(r.names[k])] = py::make_tuple(r.lower_95[i], r.upper_95[i]);
  }
  out["values"] = values;
  out["standard_errors"] = errors;
  out["interval_95"] = intervals;
  out["correlation"] = r.correlation;
  py::list costs;
  for (const auto& it : r.iterations) costs.append(it.cost);
  out["cost_per_iteration"] = costs;
  py::dict distance;
  distance["mean"] = r.overall.mean;
  distance["rms"] = r.overall.rms;
  distance["standard_deviation"] = r.overall.standard_deviation;
  distance["largest"] = r.overall.largest;
  distance["share_of_length"] = r.overall.share(r.overall.standard_deviation);
  out["distance"] = distance;
  py::list forces;
  for (const ff::fit::ForceMisfit& f : r.force_misfits) {
    py::dict misfit;
    misfit["simulated"] = f.simulated;
    misfit["rms"] = f.rms;
    misfit["largest"] = f.largest;
    misfit["share_of_largest_measured"] = f.share(f.rms);
    misfit["weight"] = f.weight;
    misfit["rms_relative"] = f.rms_relative;
    misfit["measurement_scatter"] = f.scatter;
    misfit["systematic"] = f.systematic;
    misfit["verdict"] = f.verdict;
    forces.append(misfit);
  }
  out["force_misfits"] = forces;
  out["forward_runs"] = r.forward_runs;
  out["sensitivity_solves"] = r.sensitivity_solves;
  out["seconds"] = r.seconds;
  py::list positions;
  for (const Eigen::MatrixXd& X : r.positions) positions.append(X);
  out["positions"] = positions;
  return out;
}

// An experiment's run advanced one step at a time (solve::InteractiveStepper)
// on its own copy of the run's case, so that it outlives the Experiment.
class Interactive {
 public:
  Interactive(const ff::experiment::Experiment& ex, const std::string& variant)
      : case_(std::make_shared<const ff::experiment::Case>(pick(ex, variant))),
        stepper_(case_->model, case_->stepping) {}

  // Moves the paddles (plane coordinates, m) and sets the loads' factors,
  // each given as a list in the model's order or a dict by label; what is not
  // given stays where it is. Then solves equilibrium there.
  py::dict step(const py::object& paddles, const py::object& loads) {
    ff::solve::LoadPoint to = stepper_.point();
    set_values(paddles, labels(case_->model.paddles), "paddles", &to.planes);
    set_values(loads, labels(case_->model.loads), "loads", &to.factors);
    ff::solve::InteractiveStepper::Result result;
    {
      py::gil_scoped_release release;
      result = stepper_.step(to);
    }
    const ff::solve::StepRecord& r = result.record;
    py::dict out;
    out["success"] = result.success;
    out["message"] = result.message;
    out["positions"] = positions();
    out["pressure"] = stepper_.unknowns()[case_->model.pressure_dof()];
    out["newton_iterations"] = r.newton_iterations;
    out["krylov_iterations"] = r.krylov_iterations;
    out["step_cuts"] = r.step_cuts;
    out["residual"] = r.residual;
    out["seconds"] = r.seconds;
    out["pair_passes"] = py::dict(py::arg("computed") = r.pair_passes.computed,
                                  py::arg("stored") = r.pair_passes.stored);
    py::dict forces, contacts;
    const auto& model_paddles = case_->model.paddles;
    for (size_t p = 0; p < r.paddles.size() && p < model_paddles.size(); ++p) {
      forces[py::str(model_paddles[p].label)] = Eigen::Vector3d(r.paddles[p].force);
      contacts[py::str(model_paddles[p].label)] = r.paddles[p].contacts;
    }
    out["paddle_forces"] = forces;
    out["contacts"] = contacts;
    return out;
  }

  Eigen::MatrixXd positions() const {
    return ff::experiment::input_positions(*case_, stepper_.unknowns());
  }
  py::dict point() const { return point_dict(stepper_.point()); }
  py::dict scheduled(double t) const {
    const int steps = case_->stepping.steps;
    if (!(t >= 0.0 && t <= steps))
      throw ff::InputError("scheduled: t must be in [0, " + std::to_string(steps) + "]");
    return point_dict(ff::solve::scheduled_point(case_->model, t, steps));
  }
  py::dict point_dict(const ff::solve::LoadPoint& at) const {
    py::dict paddles, loads;
    for (size_t p = 0; p < at.planes.size(); ++p)
      paddles[py::str(case_->model.paddles[p].label)] = at.planes[p];
    for (size_t l = 0; l < at.factors.size(); ++l)
      loads[py::str(case_->model.loads[l].label)] = at.factors[l];
    return py::dict(py::arg("paddles") = paddles, py::arg("loads") = loads);
  }
  int steps_taken() const { return stepper_.steps_taken(); }
  const Eigen::MatrixXi& faces() const { return case_->input_surface.F; }

 private:
  static const ff::experiment::Case& pick(const ff::experiment::Experiment& ex,
                                          const std::string& variant) {
    if (cases_of(ex).empty()) throw ff::InputError(ex.name + ": the experiment has no run");
    if (variant.empty()) return cases_of(ex).front();
    for (const ff::experiment::Case& c : cases_of(ex))
      if (c.variant == variant) return c;
    throw ff::InputError(ex.name + ": no variant named \"" + variant + "\"");
  }
  template <class Item>
  static std::vector<std::string> labels(const std::vector<Item>& items) {
    std::vector<std::string> out;
    for (const Item& item : items) out.push_back(item.label);
    return out;
  }
  // values[i] from a list (one per label) or a dict {label: value}; None leaves them.
  static void set_values(const py::object& given, const std::vector<std::string>& names,
                         const std::string& what, std::vector<double>* values) {
    if (given.is_none()) return;
    if (py::isinstance<py::dict>(given)) {
      for (const auto& [key, value] : given.cast<py::dict>()) {
        const std::string name = py::str(key);
        const auto at = std::find(names.begin(), names.end(), name);
        if (at == names.end())
          throw ff::InputError("interactive step: " + what + ": no " + what + " labelled \"" +
                               name + "\"");
        (*values)[static_cast<size_t>(at - names.begin())] = value.cast<double>();
      }
      return;
    }
    const std::vector<double> list = given.cast<std::vector<double>>();
    if (list.size() != names.size())
      throw ff::InputError("interactive step: " + what + ": " + std::to_string(list.size()) +
                           " values given, the experiment has " + std::to_string(names.size()));
    *values = list;
  }

  std::shared_ptr<const ff::experiment::Case> case_;
  ff::solve::InteractiveStepper stepper_;
};

// fiberfluid.fit_file: an experiment file's fit (or calibration over
// specimens) through the same workflow as `fiberfluid fit`, its folder
// written as the command writes it; returns how it ended and the folder's
// fit.json (calibration.json) as a dict.
py::dict fit_file(const std::filesystem::path& path, const std::string& output) {
  namespace xp = ff::experiment;
  const xp::Experiment ex = xp::load_experiment(path);
  if (ex.kind() != xp::Experiment::Kind::Calibration && !ex.fit())
    throw ff::InputError(path.string() + ": no \"fit\" section (and not a calibration)");
  const std::filesystem::path folder = xp::output_folder(output, ex.name);
  ff::fit::FitStatus status = ff::fit::FitStatus::StartFailed;
  std::filesystem::path written;
  std::vector<std::string> warnings;
  bool runs_succeeded = true;
  std::string failure;
  {
    py::gil_scoped_release release;
    if (ex.kind() == xp::Experiment::Kind::Calibration) {
      const xp::JointSetup setup = xp::setup_joint(ex);
      const xp::CalibrationOutcome done = xp::run_calibration(ex, setup, folder, {}, {});
      status = done.fitted.status;
      written = done.folder;
      warnings = done.warnings;
      failure = done.result.failure;
    } else {
      const xp::FitSetup setup = xp::setup_fit(ex);
      const xp::FitOutcome done = xp::run_fit(ex, setup, folder);
      status = done.fitted.status;
      written = done.folder;
      warnings = done.warnings;
      runs_succeeded = done.interrupted() || done.result.runs_succeeded();
      failure = done.result.failure;
    }
  }
  py::dict out;
  out["status"] = ff::fit::to_string(status);
  out["success"] = ff::fit::converged(status) && runs_succeeded;
  out["exit_status"] = runs_succeeded ? xp::fit_exit_status(status) : 2;
  out["failure"] = failure;
  out["folder"] = written;
  out["warnings"] = warnings;
  const std::filesystem::path report =
      written / (ex.kind() == xp::Experiment::Kind::Calibration ? "calibration.json" : "fit.json");
  std::ifstream in(report);
  out["report"] = in ? to_python(nlohmann::json::parse(in)) : py::object(py::none());
  return out;
}

PYBIND11_MODULE(fiberfluid, m) {
  m.doc() =
      "fiberfluid: the fibers-and-fluid soft-tissue model (Sardinha et al. 2016). "
      "SI units throughout: m, N, Pa.";
  py::register_exception<ff::InputError>(m, "InputError", PyExc_ValueError);
  // Every other exception that reaches Python becomes a Python exception
  // too: an interruption a KeyboardInterrupt, bad JSON a ValueError (the
  // standard library's and CGAL's: RuntimeError, by pybind11's rules).
  py::register_exception_translator([](std::exception_ptr error) {
    try {
      if (error) std::rethrow_exception(error);
    } catch (const ff::Interrupted& e) {
      PyErr_SetString(PyExc_KeyboardInterrupt, e.what());
    } catch (const nlohmann::json::exception& e) {
      PyErr_SetString(PyExc_ValueError, e.what());
    }
  });

  m.def(
      "read_mesh",
      [](const std::filesystem::path& path, bool flip) {
        ff::geom::ReadResult read = ff::geom::read_surface(path);
        if (flip) ff::geom::flip_orientation(read.surface);
        const ff::geom::MeshReport report = ff::geom::inspect(read.surface);
        py::dict out;
        out["vertices"] = read.surface.V;
        out["faces"] = read.surface.F;
        out["dimension"] = read.surface.dim;
        out["ok"] = report.ok();
        out["problems"] = report.problems;
        std::vector<std::string> warnings = read.warnings;
        warnings.insert(warnings.end(), report.warnings.begin(), report.warnings.end());
        out["warnings"] = warnings;
        out["report"] = ff::geom::format_report(report, path.string());
        return out;
      },
      py::arg("path"), py::arg("flip") = false,
      "Reads an OBJ, OFF, STL or PLY surface and checks it. Returns a dict: vertices (#V x 3), "
      "faces, ok, problems, warnings, report (the text of `fiberfluid check`).");

  py::class_<ff::experiment::Experiment>(
      m, "Experiment", "A parsed, validated experiment: one run or a sweep of variants.")
      .def_static("from_file", &ff::experiment::load_experiment, py::arg("path"),
                  "Reads an experiment file (JSON). Raises InputError (a ValueError) naming the "
                  "file and field on bad input.")
      .def_static(
          "from_dict",
          [](const py::object& document, const std::filesystem::path& folder,
             const std::optional<Eigen::MatrixXd>& vertices,
             const std::optional<Eigen::MatrixXi>& faces) {
            ff::experiment::Experiment ex =
                ff::experiment::read_experiment(to_json(document), folder, "<dict>");
            if (vertices.has_value() != faces.has_value())
              throw ff::InputError("<dict>: give both vertices and faces, or neither");
            if (!vertices) {
              ff::experiment::build_experiment(ex);
              return ex;
            }
            ff::geom::Surface surface;
            surface.dim = static_cast<int>(vertices->cols());
            if ((surface.dim != 2 && surface.dim != 3) || faces->cols() != surface.dim)
              throw ff::InputError(
                  "<dict>: vertices must be #V x 3 with faces #F x 3 (or "
                  "#V x 2 with segments #F x 2)");
            surface.V = *vertices;
            surface.F = *faces;
            ff::experiment::build_experiment(ex, &surface);
            return ex;
          },
          py::arg("document"), py::arg("folder") = std::filesystem::path("."),
          py::arg("vertices") = py::none(), py::arg("faces") = py::none(),
          "Builds an experiment from a dict with the fields of an experiment file; relative "
          "mesh paths are taken from `folder`. A program's own surface may be given as "
          "`vertices` (#V x 3) and `faces` (#F x 3, from 0) instead of the dict's \"surface\"; "
          "it is checked like a mesh file.")
      .def_property_readonly("name", [](const ff::experiment::Experiment& ex) { return ex.name; })
      .def_property_readonly("variants",
                             [](const ff::experiment::Experiment& ex) {
                               std::vector<std::string> names;
                               for (const ff::experiment::Case& c : cases_of(ex))
                                 names.push_back(c.variant);
                               return names;
                             })
      .def_property_readonly("warnings",
                             [](const ff::experiment::Experiment& ex) { return ex.warnings; })
      .def_property_readonly(
          "num_vertices",
          [](const ff::experiment::Experiment& ex) {
            return cases_of(ex).empty() ? 0 : cases_of(ex).front().model.num_vertices();
          })
      .def("run", &run, py::arg("jobs") = 0, py::arg("output") = std::string(),
           "Runs every variant (`jobs` at once; 0: one per core). With `output`, writes the "
           "result folder as `fiberfluid run -o` does. Returns a dict with success, runs (each "
           "with positions, displacements, pressure, steps as numpy arrays, figures), figures "
           "and checks.");

  py::class_<Interactive>(
      m, "Interactive",
      "One run of an experiment advanced one Newton step at a time, to paddle planes and load "
      "factors chosen as it goes (a visual or haptic loop). Each step starts from the last "
      "equilibrium and keeps the tangent's preconditioner; a failed step keeps the last "
      "equilibrium.")
      .def(py::init<const ff::experiment::Experiment&, const std::string&>(), py::arg("experiment"),
           py::arg("variant") = std::string(),
           "Starts at the unloaded body of the experiment's run (its first variant, or the one "
           "named), with its stepping options (Newton).")
      .def("step", &Interactive::step, py::arg("paddles") = py::none(),
           py::arg("loads") = py::none(),
           "Moves the paddles (plane coordinates in m: a list in the experiment's order or a "
           "dict by label) and sets the loads' factors (0 unloaded, 1 the full load; likewise), "
           "then solves equilibrium there. What is not given stays. Returns a dict: success, "
           "message, positions (input order), pressure, newton_iterations, krylov_iterations, "
           "step_cuts, residual, seconds, pair_passes, paddle_forces and contacts (by label).")
      .def_property_readonly("positions", &Interactive::positions,
                             "The last equilibrium's vertices (input order, m).")
      .def_property_readonly("faces", &Interactive::faces)
      .def_property_readonly("point", &Interactive::point,
                             "Where the paddles and loads stand: {paddles: {label: plane}, "
                             "loads: {label: factor}}.")
      .def("scheduled", &Interactive::scheduled, py::arg("t"),
           "The experiment's own load path at t (t = k after its step k, linear in between), "
           "as `point` gives it.")
      .def_property_readonly("steps_taken", &Interactive::steps_taken);

  m.def("fit_file", &fit_file, py::arg("path"), py::arg("output") = std::string(),
        "Fits an experiment file's \"fit\" section (or calibrates a \"kind\": \"calibration\" "
        "over its specimens) as `fiberfluid fit` does, writing its folder (default "
        "out/<name>; DIR.failed or DIR.interrupted for a fit that did not converge). Returns a "
        "dict: status, success, exit_status (the command's), failure, folder, warnings, and "
        "report (the folder's fit.json or calibration.json).");
  m.def(
      "fit", &fit_experiment, py::arg("experiment"), py::arg("targets"), py::arg("parameters"),
      py::arg("method") = "levenberg-marquardt", py::arg("jacobian") = "analytic",
      py::arg("symmetric") = false, py::arg("loss") = "squared", py::arg("loss_scale") = 1e-3,
      py::arg("max_iterations") = 50,
      "Fits the material (and optionally a rigid alignment) of a one-run experiment to measured "
      "surfaces. targets: a list of dicts with vertices (#P x 3), faces (#T x 3, omit for a point "
      "cloud), step (default: the last) and scale (the vertices times it are in m), or force "
      "curves: force (N) with travel (m) or step, and paddle (its push into the body) or "
      "support with axis (its reaction), optionally weight (m per N); parameters: "
      "dicts with name (Y0, beta, gamma, factor_x, rotation_y, scale, ...), and optionally start, "
      "lower, upper, log_scale. Options are checked as a file's fit section is (ValueError naming "
      "the option). Returns a dict: status (converged, converged_at_bounds, iteration_limit, "
      "not_identifiable, forward_runs_failed, start_failed, interrupted), status_detail, "
      "success, message, failed_runs, values, standard_errors, interval_95, correlation, "
      "cost_per_iteration, "
      "distance (mean, rms, standard_deviation, largest, share_of_length), force_misfits (per "
      "curve: simulated, rms, largest, share_of_largest_measured, weight, rms_relative, "
      "measurement_scatter, systematic, verdict), forward_runs, "
      "sensitivity_solves, seconds, positions (per target, the model's vertices at the fit).");

  m.def(
      "schema",
      [] {
        return py::module_::import("json").attr("loads")(
            ff::experiment::experiment_schema().dump());
      },
      "The JSON Schema of experiment files (what `fiberfluid schema` prints), as a dict.");

  m.def(
      "summary",
      [](const std::filesystem::path& folder) {
        std::ifstream in(folder / "summary.json");
        if (!in) throw ff::InputError((folder / "summary.json").string() + ": cannot open");
        return to_python(ff::experiment::parse_json(in, (folder / "summary.json").string()));
      },
      py::arg("folder"), "Reads the summary.json of a result folder as a dict.");
  m.attr("__version__") = FIBERFLUID_VERSION;
}

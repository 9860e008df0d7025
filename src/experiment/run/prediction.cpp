// SPDX-License-Identifier: GPL-3.0-or-later
#include "fiberfluid/experiment/run/prediction.hpp"

#include <cmath>
#include <fstream>

#include "fiberfluid/experiment/read/experiment_reader.hpp"
#include "fiberfluid/experiment/run/fit_setup.hpp"
#include "fiberfluid/model/report_names.hpp"
#include "fiberfluid/solve/newton/newton.hpp"
#include "fiberfluid/util/error.hpp"

namespace fiberfluid::experiment {
namespace {

namespace fs = std::filesystem;
using json = nlohmann::json;

// fit.json's fields, each refused by name when it is not what `fit` writes.
class FitFile {
 public:
  explicit FitFile(fs::path file) : file_(std::move(file)) {}
  [[noreturn]] void fail(const std::string& field, const std::string& expected) const {
    throw InputError(file_.string() + ": field \"" + field + "\": expected " + expected +
                     " (as `fiberfluid fit` writes it)");
  }
  const json& member(const json& object, const std::string& key, const std::string& field) const {
    if (!object.is_object() || !object.contains(key)) fail(field, "a field \"" + key + "\"");
    return object.at(key);
  }
  std::string text(const json& object, const std::string& key, const std::string& field) const {
    const json& v = member(object, key, field);
    if (!v.is_string()) fail(field, "a string");
    return v.get<std::string>();
  }
  double finite(const json& object, const std::string& key, const std::string& field) const {
    const json& v = member(object, key, field);
    if (!v.is_number() || !std::isfinite(v.get<double>())) fail(field, "a finite number");
    return v.get<double>();
  }
  // A number, or null (NaN): a standard error the fit could not give.
  double number_or_null(const json& object, const std::string& key,
                        const std::string& field) const {
    const json& v = member(object, key, field);
    if (v.is_null()) return std::nan("");
    if (!v.is_number()) fail(field, "a number or null");
    return v.get<double>();
  }
  const fs::path& path() const { return file_; }

 private:
  fs::path file_;
};

}  // namespace

FittedEstimate read_fitted_estimate(const fs::path& fit_folder) {
  const fs::path file = fit_folder / "fit.json";
  if (!fs::is_regular_file(file))
    throw InputError(file.string() +
                     ": no such file: predict reads the folder `fiberfluid fit` wrote (its "
                     "fit.json)");
  std::ifstream in(file);
  const json doc = parse_json(in, file.string());
  const FitFile f(file);
  FittedEstimate e;
  e.source = file;
  e.experiment = f.text(doc, "experiment", "experiment");
  e.status = f.text(doc, "status", "status");
  const json& success = f.member(doc, "success", "success");
  if (!success.is_boolean()) f.fail("success", "true or false");
  if (!success.get<bool>())
    throw InputError(file.string() + ": the fit ended \"" + e.status +
                     "\" without converging: there is no estimate to predict from");
  const json& parameters = f.member(doc, "parameters", "parameters");
  if (!parameters.is_array() || parameters.empty()) f.fail("parameters", "a list of parameters");
  const Eigen::Index P = static_cast<Eigen::Index>(parameters.size());
  e.values.resize(P);
  Eigen::VectorXd sigma_phi(P);
  std::vector<bool> log_scale(static_cast<size_t>(P));
  for (Eigen::Index k = 0; k < P; ++k) {
    const std::string field = "parameters[" + std::to_string(k) + "]";
    const json& p = parameters[static_cast<size_t>(k)];
    e.names.push_back(f.text(p, "name", field + ".name"));
    e.values[k] = f.finite(p, "value", field + ".value");
    const json& log = f.member(p, "log_scale", field + ".log_scale");
    if (!log.is_boolean()) f.fail(field + ".log_scale", "true or false");
    log_scale[static_cast<size_t>(k)] = log.get<bool>();
    if (log.get<bool>() && !(e.values[k] > 0.0))
      f.fail(field + ".value", "a positive value for a log-scaled parameter");
    const double se = f.number_or_null(p, "standard_error", field + ".standard_error");
    if (std::isfinite(se) && se < 0.0) f.fail(field + ".standard_error", "a number >= 0");
    // The fit's variable is log theta for a log-scaled parameter: se = theta sd(log theta).
    sigma_phi[k] = log.get<bool>() ? se / e.values[k] : se;
  }
  const json& correlation = f.member(doc, "correlation", "correlation");
  const auto correlation_of = [&](Eigen::Index a, Eigen::Index b) {
    if (!correlation.is_array() || correlation.size() != parameters.size())
      f.fail("correlation", std::to_string(P) + " rows, one per parameter");
    const json& row = correlation[static_cast<size_t>(a)];
    if (!row.is_array() || row.size() != parameters.size())
      f.fail("correlation[" + std::to_string(a) + "]", std::to_string(P) + " numbers");
    const json& v = row[static_cast<size_t>(b)];
    if (v.is_null()) return a == b ? 1.0 : 0.0;
    if (!v.is_number() || std::abs(v.get<double>()) > 1.0 + 1e-9)
      f.fail("correlation[" + std::to_string(a) + "][" + std::to_string(b) + "]",
             "a number in [-1, 1]");
    return v.get<double>();
  };
  std::vector<Eigen::Index> banded;
  for (Eigen::Index k = 0; k < P; ++k) {
    const std::string& name = e.names[static_cast<size_t>(k)];
    if (std::isfinite(sigma_phi[k])) {
      banded.push_back(k);
      e.banded.push_back(name);
      e.banded_log_scale.push_back(log_scale[static_cast<size_t>(k)]);
    } else {
      e.held.push_back(name + " = " + std::to_string(e.values[k]) +
                       ": the fit gives it no standard error (on its bound, or not identified), "
                       "so it is held at its value and adds nothing to the bands");
    }
  }
  const Eigen::Index B = static_cast<Eigen::Index>(banded.size());
  e.covariance.resize(B, B);
  for (Eigen::Index a = 0; a < B; ++a)
    for (Eigen::Index b = 0; b < B; ++b)
      e.covariance(a, b) =
          correlation_of(banded[a], banded[b]) * sigma_phi[banded[a]] * sigma_phi[banded[b]];
  return e;
}

void apply_estimate(const FittedEstimate& estimate, Experiment& experiment) {
  const std::string file = experiment.source.empty() ? experiment.name : experiment.source.string();
  if (experiment.kind() != Experiment::Kind::Simulate)
    throw InputError(file + ": predict runs a simulation; this experiment is another kind");
  Simulation& simulation = experiment.simulation();
  for (Case& c : simulation.cases) {
    model::Material& material = c.model.material;
    const int dim = c.model.dim();
    for (size_t k = 0; k < estimate.names.size(); ++k) {
      const std::string& name = estimate.names[k];
      if (!material.has_parameter(name, dim)) {
        std::string known;
        for (const std::string& n : material.parameter_names(dim))
          known += (known.empty() ? "" : ", ") + n;
        throw InputError(estimate.source.string() + " fitted \"" + name + "\", which " + file +
                         "'s material does not have (its parameters: " + known + ")");
      }
      material.set_parameter(material.resolve(name, dim),
                             estimate.values[static_cast<Eigen::Index>(k)]);
    }
    if (const Status law = material.law.check(); !law.ok)
      throw InputError(estimate.source.string() + ": its values make " + file +
                       "'s law invalid: " + law.message);
    if (c.stepping.scheme != solve::Scheme::Newton)
      throw InputError(file +
                       ": field \"stepping.scheme\": predict needs \"newton\" (its bands come "
                       "from Newton's sensitivities of the run)");
    if (const Status exact = solve::check_sensitivities(c.model); !exact.ok)
      throw InputError(file + ": predict cannot band this run: " + exact.message);
    c.stepping.sensitivities.parameters = estimate.banded;
    c.stepping.sensitivities.steps.clear();
    for (int s = 1; s <= c.stepping.steps; ++s) c.stepping.sensitivities.steps.push_back(s);
  }
  // The folder's experiment.resolved.json repeats this run: at these values.
  if (experiment.resolved.is_object() && experiment.resolved.contains("material") &&
      !simulation.cases.empty())
    write_material_values(simulation.cases.front().model.material,
                          simulation.cases.front().model.dim(), experiment.resolved["material"]);
}

namespace {

// sd of a quantity whose derivatives by the banded parameters (theta, one
// per column of `by_theta`'s row) are given: g = df/dphi, var = g^T C g.
Band band_of(double value, const Eigen::RowVectorXd& by_theta, const FittedEstimate& e,
             const Eigen::VectorXd& theta) {
  Band b;
  b.value = value;
  if (by_theta.size() != e.covariance.rows() || e.covariance.rows() == 0) return b;
  Eigen::VectorXd g = by_theta.transpose();
  for (Eigen::Index k = 0; k < g.size(); ++k)
    if (e.banded_log_scale[static_cast<size_t>(k)]) g[k] *= theta[k];
  if (!g.allFinite()) return b;
  b.sd = std::sqrt(std::max(0.0, g.dot(e.covariance * g)));
  return b;
}

// The largest displacement's vertex and its derivative rows.
Band max_displacement_band(const model::Model& m, const Eigen::VectorXd& x,
                           const Eigen::MatrixXd& du, const FittedEstimate& e,
                           const Eigen::VectorXd& theta) {
  const int n = m.num_vertices(), dim = m.dim();
  int largest = 0;
  double size = -1.0;
  for (int i = 0; i < n; ++i) {
    double s = 0.0;
    for (int a = 0; a < dim; ++a) s += x[a * n + i] * x[a * n + i];
    if (s > size) size = s, largest = i;
  }
  const double u = std::sqrt(size);
  Eigen::RowVectorXd by_theta = Eigen::RowVectorXd::Zero(du.cols());
  if (u > 0.0)
    for (int a = 0; a < dim; ++a) by_theta += x[a * n + largest] / u * du.row(a * n + largest);
  return band_of(u, by_theta, e, theta);
}

}  // namespace

std::vector<RunBands> prediction_bands(const Experiment& experiment, const ExperimentResult& result,
                                       const FittedEstimate& estimate,
                                       const std::vector<std::vector<Eigen::VectorXd>>& unknowns) {
  std::vector<RunBands> bands;
  for (size_t r = 0; r < result.runs.size(); ++r) {
    const Case& c = experiment.simulation().cases[r];
    const model::Model& m = c.model;
    const int dim = m.dim();
    Eigen::VectorXd theta(static_cast<Eigen::Index>(estimate.banded.size()));
    for (size_t k = 0; k < estimate.banded.size(); ++k)
      theta[static_cast<Eigen::Index>(k)] = m.material.parameter(estimate.banded[k]);
    RunBands run_bands;
    const std::vector<solve::StepRecord>& steps = result.runs[r].summary.steps;
    for (size_t s = 0; s < steps.size(); ++s) {
      const solve::StepRecord& record = steps[s];
      const solve::StepSensitivities& d = record.sensitivities;
      std::map<std::string, Band> row;
      const bool has = d.state.rows() == m.num_unknowns();
      const Eigen::RowVectorXd none = Eigen::RowVectorXd::Constant(
          static_cast<Eigen::Index>(estimate.banded.size()), std::nan(""));
      row["pressure_Pa"] =
          band_of(record.pressure, has ? Eigen::RowVectorXd(d.state.row(m.pressure_dof())) : none,
                  estimate, theta);
      if (has && r < unknowns.size() && s < unknowns[r].size())
        row["max_displacement_m"] =
            max_displacement_band(m, unknowns[r][s], d.state, estimate, theta);
      for (size_t g = 0; g < record.reactions.size(); ++g)
        for (int a = 0; a < dim; ++a)
          row["reaction_" + model::constraint_group_name(m, g) + "_" + model::axis_name(a) + "_N"] =
              band_of(record.reactions[g][a],
                      g < d.reactions.size() ? Eigen::RowVectorXd(d.reactions[g].row(a)) : none,
                      estimate, theta);
      for (size_t p = 0; p < record.paddles.size(); ++p)
        for (int a = 0; a < dim; ++a)
          row["paddle_" + m.paddles[p].label + "_force_" + model::axis_name(a) + "_N"] = band_of(
              record.paddles[p].force[a],
              p < d.paddle_forces.size() ? Eigen::RowVectorXd(d.paddle_forces[p].row(a)) : none,
              estimate, theta);
      run_bands.steps.push_back(std::move(row));
    }
    if (!run_bands.steps.empty()) {
      const std::map<std::string, Band>& last = run_bands.steps.back();
      if (last.count("max_displacement_m"))
        run_bands.figures["max_displacement"] = last.at("max_displacement_m");
      run_bands.figures["final_pressure"] = last.at("pressure_Pa");
      for (const model::Paddle& p : m.paddles)
        run_bands.figures["paddle_force." + p.label] =
            last.at("paddle_" + p.label + "_force_" + model::axis_name(p.axis) + "_N");
    }
    bands.push_back(std::move(run_bands));
  }
  return bands;
}

}  // namespace fiberfluid::experiment

// SPDX-License-Identifier: GPL-3.0-or-later
#include "fiberfluid/experiment/spec/figures.hpp"

#include <algorithm>
#include <cctype>

#include "fiberfluid/experiment/spec/experiment.hpp"

namespace fiberfluid::experiment {

namespace {

// Run figures that only some runs give (Newton, arc length), and the matrix.
const std::vector<std::string> kOptionalRunFigures = {
    "newton_iterations", "max_newton_iterations_per_step",
    "step_cuts",         "max_equilibrium_residual",
    "limit_load_factor", "system_matrix"};

const std::vector<std::string> kFemFigures = {"element_order",    "nodes",
                                              "tetrahedra",       "mesh_seconds",
                                              "solve_seconds",    "newton_iterations",
                                              "max_displacement", "rest_surface_error",
                                              "volume_change",    "distance_mean",
                                              "distance_sd",      "distance_sd_share",
                                              "distance_largest", "surface_error"};

const std::vector<std::string> kFitFigures = {
    "cost",        "forward_runs",     "distance_mean",    "distance_rms",
    "distance_sd", "distance_largest", "distance_sd_share"};

const std::vector<std::string> kAreaFigures = {"vertices", "faces", "area_faces", "area_vertices",
                                               "volume"};

// "12.y" for a 3D surface: a vertex index and an axis letter.
bool vertex_and_axis(const std::string& rest) {
  const size_t dot = rest.find('.');
  if (dot == std::string::npos || dot == 0 || rest.size() != dot + 2) return false;
  if (!std::all_of(rest.begin(), rest.begin() + static_cast<long>(dot),
                   [](unsigned char c) { return std::isdigit(c); }))
    return false;
  return rest[dot + 1] >= 'x' && rest[dot + 1] <= 'z';
}

// The figures of one case's runs (no variant prefix); with `patterns`, the
// vertex figures' forms (position.I.x) too, for messages.
std::vector<std::string> run_names(const CaseSpec& spec, bool patterns) {
  std::vector<std::string> names = run_figure_names();
  names.insert(names.end(), kOptionalRunFigures.begin(), kOptionalRunFigures.end());
  for (const PaddleSpec& p : spec.paddles) {
    names.push_back("paddle_force." + p.paddle.label);
    names.push_back("paddle_contacts." + p.paddle.label);
  }
  if (patterns) names.insert(names.end(), {"position.I.x", "displacement.I.x"});
  return names;
}

bool is_run_figure(const CaseSpec& spec, const std::string& name) {
  const std::vector<std::string> names = run_names(spec, /*patterns=*/false);
  if (std::find(names.begin(), names.end(), name) != names.end()) return true;
  for (const std::string prefix : {"position.", "displacement."})
    if (name.rfind(prefix, 0) == 0 && vertex_and_axis(name.substr(prefix.size()))) return true;
  return false;
}

std::string listed(const std::vector<std::string>& names) {
  std::string out;
  for (const std::string& n : names) out += (out.empty() ? "" : ", ") + n;
  return out;
}

}  // namespace

const std::vector<std::string>& run_figure_names() {
  static const std::vector<std::string> names = {
      "max_displacement",
      "final_pressure",
      "final_volume",
      "initial_volume",
      "volume_change_relative",
      "mean_displacement_over_diagonal",  // the paper's Eq. 9
      "surface_area",
      "steps",
      "factorizations"};
  return names;
}

std::vector<std::string> run_figure_names(const model::Model& model) {
  std::vector<std::string> names = run_figure_names();
  for (const model::Paddle& p : model.paddles) {
    names.push_back("paddle_force." + p.label);
    names.push_back("paddle_contacts." + p.label);
  }
  return names;
}

std::vector<std::string> calibration_figures(const Experiment& ex) {
  std::vector<std::string> names = {"fit.cost"};
  if (ex.kind() != Experiment::Kind::Calibration) return names;
  for (const std::string& shared : ex.calibration().spec.shared) names.push_back("fit." + shared);
  for (size_t s = 0; s < ex.calibration().specimens.size(); ++s) {
    const std::string prefix = "fit." + ex.calibration().spec.specimens[s].name + ".";
    for (const FitParameterSpec& p : ex.calibration().specimens[s].fit()->parameters)
      if (std::find(ex.calibration().spec.shared.begin(), ex.calibration().spec.shared.end(),
                    p.request.name) == ex.calibration().spec.shared.end())
        names.push_back(prefix + p.request.name);
    for (const char* f :
         {"distance_mean", "distance_rms", "distance_sd", "distance_largest", "distance_sd_share"})
      names.push_back(prefix + f);
  }
  return names;
}

Status check_figure(const Experiment& ex, const std::string& figure, bool fit_figures) {
  const bool fitted = ex.fit() || ex.kind() == Experiment::Kind::Calibration;
  if (!fit_figures && fitted && figure.rfind("fit.", 0) == 0) return {};
  std::vector<std::string> valid;
  switch (ex.kind()) {
    case Experiment::Kind::Calibration:
      for (const std::string& f : calibration_figures(ex)) {
        if (figure == f) return {};
        valid.push_back(f);
      }
      break;
    case Experiment::Kind::Benchmark:
      return {};
    case Experiment::Kind::Areas:
      for (const NamedSurfaceSpec& s : ex.areas().specs)
        for (const std::string& f : kAreaFigures) {
          if (figure == s.name + "." + f) return {};
          valid.push_back(s.name + "." + f);
        }
      break;
    case Experiment::Kind::Simulate: {
      for (const std::string f : {"fibers.in_all", "fibers.kept", "fibers.pruned"}) {
        if (figure == f) return {};
        valid.push_back(f);
      }
      if (ex.fem_reference())
        for (const std::string& f : kFemFigures) {
          if (figure == "fem_reference." + f) return {};
          valid.push_back("fem_reference." + f);
        }
      if (ex.fit()) {
        std::vector<std::string> fitted = kFitFigures;
        for (const FitParameterSpec& p : ex.fit()->parameters) fitted.push_back(p.request.name);
        if (!ex.fit()->force_curves.empty())
          fitted.insert(fitted.end(), {"force_rms", "force_largest", "force_rms_share"});
        if (ex.fit()->multistart) fitted.insert(fitted.end(), {"optima", "best_optimum_starts"});
        for (const std::string& f : fitted) {
          if (figure == "fit." + f) return {};
          valid.push_back("fit." + f);
        }
        // A target of another kind's figures, as fit.json's other_targets[K]
        // lists them: what they are is the kind's.
        for (size_t k = 0; k < ex.fit()->kind_targets.size(); ++k) {
          const std::string prefix = "fit.other_targets." + std::to_string(k) + ".";
          if (figure.rfind(prefix, 0) == 0 && figure.size() > prefix.size()) return {};
          valid.push_back(prefix + "<figure>");
        }
      }
      for (const CaseSpec& spec : ex.simulation().specs) {
        const std::string prefix = spec.variant.empty() ? "" : spec.variant + ".";
        if (figure.rfind(prefix, 0) == 0 && is_run_figure(spec, figure.substr(prefix.size())))
          return {};
        for (const std::string& f : run_names(spec, /*patterns=*/true)) valid.push_back(prefix + f);
      }
      break;
    }
  }
  const size_t shown = 60;  // a sweep multiplies the names: show the first ones
  std::string names = listed(std::vector<std::string>(
      valid.begin(), valid.begin() + static_cast<long>(std::min(shown, valid.size()))));
  if (valid.size() > shown) names += ", ... (" + std::to_string(valid.size()) + " in all)";
  return Status::failure("no figure \"" + figure + "\" in this experiment (expected one of " +
                         names + "; README, \"Figures\", says what each is)");
}

}  // namespace fiberfluid::experiment

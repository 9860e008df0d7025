// SPDX-License-Identifier: GPL-3.0-or-later
#include "fiberfluid/experiment/run/benchmark.hpp"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <iomanip>
#include <limits>
#include <map>
#include <nlohmann/json.hpp>
#include <optional>
#include <sstream>

#include "fiberfluid/bridge/scene_model.hpp"
#include "fiberfluid/fem/mesh_tools.hpp"
#include "fiberfluid/fit/calibration.hpp"
#include "fiberfluid/fit/golden_section.hpp"
#include "fiberfluid/geom/horizon.hpp"
#include "fiberfluid/metrics/convergence.hpp"
#include "fiberfluid/metrics/metrics.hpp"
#include "fiberfluid/model/assembly.hpp"
#include "fiberfluid/model/mirror_layer.hpp"
#include "fiberfluid/solve/stepping.hpp"

namespace fiberfluid::experiment {
namespace {

using fem::Integrator;

double seconds_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

// What every series is compared with: the reference's boundary and nodes.
struct ReferenceFrames {
  const fem::Scene* scene = nullptr;
  fem::Boundary rest;              // the undeformed boundary
  Eigen::VectorXd volume_weights;  // node measures
  double measure = 0.0;            // |Int(M0)|
};

geom::Surface deformed_boundary(const ReferenceFrames& frames, const Eigen::MatrixXd& positions) {
  geom::Surface s = frames.rest.surface;
  for (size_t v = 0; v < frames.rest.nodes.size(); ++v)
    s.V.row(static_cast<Eigen::Index>(v)) = positions.row(frames.rest.nodes[v]);
  return s;
}

// Appends one time step's E_n, E_s and E_i: the reference and the
// approximation as positions of the same nodes (#nodes x dim) with their
// rest positions, E_i's weights and measure, and the boundaries for E_s
// (only on metrics steps: NaN between them, and where a diverging boundary
// crosses itself and bounds no solid).
struct Frame {
  const Eigen::MatrixXd* rest = nullptr;
  const Eigen::VectorXd* weights = nullptr;
  double measure = 0.0;
};
void append_metrics(MetricSeries& s, double t, const Frame& frame, const Eigen::MatrixXd& reference,
                    const Eigen::MatrixXd& approximation, const geom::Surface* reference_boundary,
                    const geom::Surface* approximation_boundary) {
  const Eigen::MatrixXd U = reference - *frame.rest, V = approximation - *frame.rest;
  const int dim = static_cast<int>(U.cols());
  s.times.push_back(t);
  s.energy_norm.push_back(U.norm() > 0.0 ? metrics::relative_energy_norm(U, V)
                                         : std::numeric_limits<double>::quiet_NaN());
  double es = std::numeric_limits<double>::quiet_NaN();
  if (reference_boundary != nullptr) {
    try {
      es = metrics::surface_error(*reference_boundary, *approximation_boundary, "the reference",
                                  s.label);
    } catch (const InputError&) {
    }
  }
  s.surface.push_back(es);
  s.interior.push_back(
      metrics::interior_error(reference, approximation, *frame.weights, frame.measure, dim));
}

bool metrics_step(size_t k, size_t count, int every) {
  return k % static_cast<size_t>(every) == 0 || k + 1 == count;
}

// E_n, E_s, E_i of a FEM trajectory against the reference, step by step.
MetricSeries compare_fem(const ReferenceFrames& frames, const fem::Trajectory& reference,
                         const fem::Trajectory& run, const std::string& label, int metrics_every) {
  MetricSeries out;
  out.label = label;
  out.interior_weights = "volume";
  const int dim = frames.scene->mesh.dim;
  const Eigen::MatrixXd& X0 = frames.scene->mesh.nodes;
  const Frame frame{&X0, &frames.volume_weights, frames.measure};
  const size_t count = std::min(reference.u.size(), run.u.size());
  for (size_t k = 1; k < count; ++k) {
    const Eigen::MatrixXd R = X0 + fem::displacement_rows(reference.u[k], dim),
                          A = X0 + fem::displacement_rows(run.u[k], dim);
    if (metrics_step(k, count, metrics_every)) {
      const geom::Surface reference_boundary = deformed_boundary(frames, R),
                          run_boundary = deformed_boundary(frames, A);
      append_metrics(out, run.times[k], frame, R, A, &reference_boundary, &run_boundary);
    } else {
      append_metrics(out, run.times[k], frame, R, A, nullptr, nullptr);
    }
  }
  return out;
}

// The scene's fiber model with central fibers (model.md: they bend): the
// area count, and within a horizon its pairs with the conical influence and
// the clamp's mirror layer, as an experiment's fibers default to.
void use_central_fibers(model::Model& m, const BenchmarkSpec::FiberModel& spec) {
  m.material.kinematics = model::FiberKinematics::Central;
  m.connection_count = model::ConnectionCount::Area;
  if (!(spec.horizon > 0.0)) return;
  if (spec.horizon < geom::longest_edge(m.surface))
    throw InputError("benchmark: fiber_model.horizon: expected at least the longest mesh edge, " +
                     std::to_string(geom::longest_edge(m.surface)) + " m");
  if (m.fibers) throw std::logic_error("benchmark: a scene's box is convex: nothing is pruned");
  m.fibers = std::make_shared<const geom::FiberMask>(geom::horizon_fibers(m.surface, spec.horizon));
  m.influence = {model::Influence::Kind::Conical, spec.horizon};
  if (!spec.mirror_layer) return;
  model::MirrorLayer layer;
  layer.group = 0;  // the supports
  layer.depth = spec.horizon;
  std::vector<int> held;
  for (const model::Constraint& c : m.constraints)
    if (c.group == 0 && (held.empty() || held.back() != c.vertex)) held.push_back(c.vertex);
  if (const Status plane = model::find_clamp_plane(m.surface.V, held, &layer); !plane.ok)
    throw InputError("benchmark: the rod's clamp has no plane: " + plane.message);
  m.mirror_layers.push_back(layer);
}

struct FiberRun {
  bool ok = false;
  std::string message;
  std::vector<Eigen::MatrixXd> positions;  // per load step 0..steps, boundary vertex order
  double seconds = 0.0;
};

// The scene's fiber model (bridge::fiber_model_of_scene, built once: the
// surface, its fibers) run with Y and gamma set, over `steps` load steps.
FiberRun run_fiber_model(const model::Model& scene_model, double Y, double gamma, int steps,
                         bool newton) {
  const auto start = std::chrono::steady_clock::now();
  model::Model m = scene_model;
  m.material = model::Material::linear(Y, gamma);
  m.material.kinematics = scene_model.material.kinematics;
  solve::SteppingOptions stepping;
  stepping.steps = steps;
  stepping.scheme = newton ? solve::Scheme::Newton : solve::Scheme::Incremental;
  FiberRun out;
  out.positions.assign(static_cast<size_t>(steps) + 1, m.surface.V);
  const solve::SteppingSummary summary = solve::solve_load_steps(
      m, stepping, [&](const solve::StepRecord& record, const Eigen::VectorXd& x) {
        out.positions[static_cast<size_t>(record.step)] = model::positions(m, x);
      });
  out.ok = summary.success;
  out.message = summary.message;
  out.seconds = seconds_since(start);
  return out;
}

// The load step whose load the scene has reached at time t.
size_t fiber_step(const fem::Scene& scene, double t, int steps) {
  return static_cast<size_t>(std::lround(scene.load_factor(t) * steps));
}

// The rod's static state on grids refined ratio^k times (k = 1..levels), at
// this mesh's nodes. Adds per grid its largest displacement (the same points
// on every grid: a pointwise study), the three finest's observed order and
// Richardson extrapolation (mesh_study.hpp), and E_n of this mesh's static
// boundary against the finest's. Returns the finest grid's displacements.
Eigen::MatrixXd refined_statics(const BenchmarkSpec& spec, const fem::Scene& scene,
                                const fem::Boundary& rest, const Eigen::VectorXd& statics,
                                std::map<std::string, double>& figures) {
  const Eigen::MatrixXd& X0 = scene.mesh.nodes;
  const Eigen::MatrixXd coarse = fem::displacement_rows(statics, 3);
  std::vector<double> largest{coarse.rowwise().norm().maxCoeff()}, sizes{1.0};
  figures["static.refine_1.max_displacement"] = largest[0];
  Eigen::MatrixXd finest;
  int refine = 1;
  for (int k = 1; k <= spec.static_reference.levels; ++k) {
    refine *= spec.static_reference.ratio;
    fem::RodOptions options = spec.rod;
    options.cells = spec.rod.cells * refine;
    finest = fem::rod_statics_at(options, X0);
    largest.push_back(finest.rowwise().norm().maxCoeff());
    sizes.push_back(1.0 / refine);
    figures["static.refine_" + std::to_string(refine) + ".max_displacement"] = largest.back();
  }
  const size_t n = largest.size();
  if (n >= 3) {
    const metrics::RichardsonEstimate e = metrics::richardson(
        largest[n - 3], largest[n - 2], largest[n - 1], sizes[n - 3], sizes[n - 2], sizes[n - 1]);
    figures["static.monotone"] = e.monotone ? 1.0 : 0.0;
    if (std::isfinite(e.order)) {
      figures["static.order"] = e.order;
      figures["static.extrapolated_max_displacement"] = e.extrapolated;
      figures["static.gci"] = e.gci;
    }
  }
  figures["reference.static_E_n_to_converged"] = metrics::relative_energy_norm(
      fem::boundary_rows(rest, finest), fem::boundary_rows(rest, coarse));
  return finest;
}

// Y and gamma of the fiber model whose static shape is closest to the FEM's.
// The block is driven by a displacement alone: its shape depends on gamma /
// Y only, so Y = E and gamma is found by a golden-section search on E_n
// (log scale, and gamma = 0). The rod is fitted by the calibration
// (Levenberg-Marquardt on the surface distances to the FEM's static boundary).
FiberModelReport choose_fiber_material(const BenchmarkSpec& spec, const fem::Scene& scene,
                                       const model::Model& scene_model, const fem::Boundary& rest,
                                       const Eigen::MatrixXd& target, int steps) {
  FiberModelReport report;
  const double E = scene.material.young;
  const Eigen::MatrixXd target_u = target - rest.surface.V;
  if (spec.scene == BenchmarkSpec::Scene::BlockNeedle) {
    auto error = [&](double gamma) {
      const FiberRun run = run_fiber_model(scene_model, E, gamma, steps, spec.fiber.newton);
      if (!run.ok) return std::numeric_limits<double>::infinity();
      return metrics::relative_energy_norm(target_u, run.positions.back() - rest.surface.V);
    };
    // gamma / (E L), L = 1 m: from 1e-4 to 10, in log scale.
    const fit::LineMinimum m =
        fit::golden_section_minimum([&](double log_gamma) { return error(std::exp(log_gamma)); },
                                    std::log(1e-4 * E), std::log(10.0 * E), 30);
    const double best = std::exp(m.x), best_error = m.value;
    const double zero_error = error(0.0);
    report.Y = E;
    report.gamma = zero_error <= best_error ? 0.0 : best;
    std::ostringstream how;
    how << "Y = E (the displacement-driven block's shape depends on gamma / Y only); gamma by a "
           "golden-section search on the static E_n (gamma = 0 gives "
        << zero_error << ", the best gamma " << best_error << ")";
    report.how = how.str();
    return report;
  }
  model::Model start = scene_model;
  start.material = model::Material::linear(E, 0.01 * E);
  start.material.kinematics = scene_model.material.kinematics;
  solve::SteppingOptions stepping;
  stepping.steps = steps;
  stepping.scheme = spec.fiber.newton ? solve::Scheme::Newton : solve::Scheme::Incremental;
  std::vector<fit::MeasuredStep> measured = {
      {fit::make_target("the FEM's static boundary", target, rest.surface.F), steps}};
  std::vector<fit::Parameter> parameters(2);
  parameters[0] = {"Y", E, 1e-6 * E, 1e3 * E, true};
  parameters[1] = {"gamma", 0.01 * E, 1e-6 * E, 1e2 * E, true};
  fit::FitOptions options;
  options.symmetric = true;
  const fit::Calibration calibration(start, stepping, measured, parameters, options);
  const fit::FitResult fitted = calibration.run();
  if (fitted.values.size() != 2)
    throw InputError("benchmark: the fiber model's fit failed: " + fitted.message);
  report.Y = fitted.values[0];
  report.gamma = fitted.values[1];
  std::ostringstream how;
  how << "fitted to the FEM's static boundary (Levenberg-Marquardt, symmetric surface distances; "
      << fitted.message << "; " << fitted.forward_runs << " forward runs)";
  for (size_t k = 0; k < parameters.size(); ++k) {
    const double v = fitted.values[static_cast<Eigen::Index>(k)];
    if (v <= parameters[k].lower * (1.0 + 1e-6) || v >= parameters[k].upper * (1.0 - 1e-6))
      how << "; " << parameters[k].name << " stopped at its bound " << v
          << " (the data push it further)";
  }
  report.how = how.str();
  return report;
}

void add_series_figures(const BenchmarkSpec& spec, const MetricSeries& s,
                        std::map<std::string, double>& figures) {
  const std::string& L = s.label;
  figures[L + ".diverged"] = s.ok ? 0.0 : 1.0;
  if (!s.ok && !s.times.empty()) figures[L + ".stopped_at"] = s.times.back();
  figures[L + ".seconds"] = s.seconds;
  const struct {
    const char* name;
    const std::vector<double>& values;
  } metrics[] = {{"E_n", s.energy_norm}, {"E_s", s.surface}, {"E_i", s.interior}};
  for (const auto& m : metrics) {
    auto at = [&](double t) -> std::optional<double> {  // the nearest step with a value
      std::optional<double> best;
      double gap = 0.6 * spec.step * spec.metrics_every;
      for (size_t k = 0; k < s.times.size(); ++k)
        if (std::abs(s.times[k] - t) <= gap && std::isfinite(m.values[k])) {
          gap = std::abs(s.times[k] - t);
          best = m.values[k];
        }
      return best;
    };
    for (double t : {1.0, 2.0, 5.0})
      if (const auto v = at(t))
        figures[L + "." + m.name + ".at_" + std::to_string(static_cast<int>(t)) + "s"] = *v;
    if (s.ok && !s.times.empty())
      if (const auto v = at(s.times.back())) figures[L + "." + m.name + ".final"] = *v;
    double sum = 0.0;
    int count = 0;
    for (size_t k = 0; k < s.times.size(); ++k)
      if (std::isfinite(m.values[k]) && s.times[k] <= 2.0 + 1e-9) sum += m.values[k], ++count;
    if (count > 0) figures[L + "." + m.name + ".mean_to_2s"] = sum / count;
    // The first local minimum: where the quasi-static error touches bottom
    // as the reference swings through the static shape.
    std::vector<size_t> valid;
    for (size_t k = 0; k < s.times.size(); ++k)
      if (std::isfinite(m.values[k])) valid.push_back(k);
    for (size_t j = 1; j + 1 < valid.size(); ++j) {
      const double here = m.values[valid[j]];
      if (here < m.values[valid[j - 1]] && here <= m.values[valid[j + 1]]) {
        figures[L + "." + m.name + ".first_minimum"] = here;
        figures[L + "." + m.name + ".first_minimum_time"] = s.times[valid[j]];
        break;
      }
    }
  }
}

// The fibers-and-fluid model on the scene's boundary, fitted to (or given)
// the static shape, then measured against the reference step by step.
void run_fiber_series(const BenchmarkSpec& spec, const ReferenceFrames& frames,
                      const fem::Trajectory& reference, const Eigen::VectorXd& statics,
                      const std::optional<Eigen::MatrixXd>& converged, BenchmarkResult& result) {
  const fem::Scene& scene = *frames.scene;
  const bool block = spec.scene == BenchmarkSpec::Scene::BlockNeedle;
  const int dim = scene.mesh.dim;
  // The block: one load step per time step of the push, so that each time
  // step has its own quasi-static state; the rod: its gravity in steps.
  const int fiber_steps =
      block ? std::max(1, static_cast<int>(std::lround(scene.push_time / spec.step)))
            : spec.fiber.steps;
  const Eigen::MatrixXd X0 = scene.mesh.nodes;
  // The static shape it is fitted to and measured against: this mesh's, or
  // the finest refined grid's at this mesh's nodes.
  const Eigen::MatrixXd own_static =
      fem::boundary_rows(frames.rest, X0 + fem::displacement_rows(statics, dim));
  const Eigen::MatrixXd target =
      converged ? fem::boundary_rows(frames.rest, X0 + *converged) : own_static;
  model::Model scene_model =
      bridge::fiber_model_of_scene(scene, frames.rest, model::Material::linear(1.0));
  if (spec.fiber.central) use_central_fibers(scene_model, spec.fiber);
  FiberModelReport report;
  if (spec.fiber.fit) {
    report = choose_fiber_material(spec, scene, scene_model, frames.rest, target, fiber_steps);
  } else {
    report.Y = spec.fiber.Y;
    report.gamma = spec.fiber.gamma;
    report.how = "given";
  }
  report.target =
      converged ? "cells x " + std::to_string(static_cast<int>(std::lround(std::pow(
                                   spec.static_reference.ratio, spec.static_reference.levels))))
                : "this mesh";
  const FiberRun run =
      run_fiber_model(scene_model, report.Y, report.gamma, fiber_steps, spec.fiber.newton);
  MetricSeries s;
  s.label = "fiber-model";
  s.ok = run.ok;
  s.message = run.message;
  s.seconds = run.seconds;
  s.interior_weights = "surface";
  report.vertices = frames.rest.surface.num_vertices();
  if (run.ok) {
    const Eigen::VectorXd weights = metrics::boundary_node_measures(frames.rest.surface);
    const Eigen::MatrixXd& rest = frames.rest.surface.V;
    const Frame frame{&rest, &weights, metrics::enclosed_measure(frames.rest.surface)};
    geom::Surface reference_boundary = frames.rest.surface, fiber_boundary = frames.rest.surface;
    for (size_t k = 1; k < reference.u.size(); ++k) {
      const double t = reference.times[k];
      reference_boundary.V =
          fem::boundary_rows(frames.rest, X0 + fem::displacement_rows(reference.u[k], dim));
      fiber_boundary.V = run.positions[fiber_step(scene, t, fiber_steps)];
      const bool surface_step = metrics_step(k, reference.u.size(), spec.metrics_every);
      append_metrics(s, t, frame, reference_boundary.V, fiber_boundary.V,
                     surface_step ? &reference_boundary : nullptr, &fiber_boundary);
    }
    report.static_energy_norm =
        metrics::relative_energy_norm(target - rest, run.positions.back() - rest);
    if (converged)
      result.figures["fiber-model.static_E_n_this_mesh"] =
          metrics::relative_energy_norm(own_static - rest, run.positions.back() - rest);
    result.fiber_final = frames.rest.surface;
    result.fiber_final.V = run.positions.back();
  }
  result.figures["fiber-model.Y"] = report.Y;
  result.figures["fiber-model.gamma"] = report.gamma;
  result.figures["fiber-model.static_E_n"] = report.static_energy_norm;
  result.fiber = report;
  result.series.push_back(std::move(s));
}

}  // namespace

BenchmarkResult run_benchmark(const BenchmarkSpec& spec,
                              const std::function<void(int, int)>& progress) {
  int total = 1 + static_cast<int>(spec.solvers.size()) + (spec.fiber.enabled ? 1 : 0) +
              (spec.static_reference.levels > 0 ? 1 : 0),
      done = 0;
  for (const BenchmarkSpec::OtherMaterial& other : spec.other_materials)
    total += static_cast<int>(other.solvers.size());
  auto tell = [&](const std::string&) {
    if (progress) progress(done++, total);
  };
  const bool block = spec.scene == BenchmarkSpec::Scene::BlockNeedle;
  auto scene_with = [&](const fem::MaterialPreset& material) {
    if (block) {
      fem::BlockOptions o = spec.block;
      o.material = material;
      return fem::needle_block(o);
    }
    fem::RodOptions o = spec.rod;
    o.material = material;
    return fem::bending_rod(o);
  };
  BenchmarkResult result;
  result.scene = block ? fem::needle_block(spec.block) : fem::bending_rod(spec.rod);
  const fem::Scene& scene = result.scene;
  const int steps = static_cast<int>(std::lround(spec.duration / spec.step));
  ReferenceFrames frames;
  frames.scene = &scene;
  frames.rest = fem::boundary(scene.mesh);
  frames.volume_weights = fem::node_measures(scene.mesh);
  frames.measure = frames.volume_weights.sum();
  const int dim = scene.mesh.dim;

  tell("reference (implicit-newmark)");
  auto start = std::chrono::steady_clock::now();
  const fem::Trajectory reference =
      fem::integrate(scene.dynamics, Integrator::ImplicitNewmark, spec.step, steps, spec.linear);
  result.reference_seconds = seconds_since(start);
  result.reference_sweeps = reference.sweeps;
  if (!reference.ok) {
    result.ok = false;
    result.message = "the implicit Newmark reference failed: " + reference.message;
    return result;
  }
  const Eigen::VectorXd statics = fem::static_state(scene);
  result.figures["reference.static_gap"] = (reference.u.back() - statics).norm() / statics.norm();
  result.figures["reference.seconds"] = result.reference_seconds;
  result.reference_final =
      deformed_boundary(frames, scene.mesh.nodes + fem::displacement_rows(reference.u.back(), dim));
  std::optional<Eigen::MatrixXd> converged;  // the finest refined grid's static displacements
  if (spec.static_reference.levels > 0) {
    tell("static reference on finer grids");
    converged = refined_statics(spec, scene, frames.rest, statics, result.figures);
  }

  // One solver on a scene (this one, or another material's) whose static state is given.
  auto run_one = [&](const fem::Scene& on, const Eigen::VectorXd& on_statics, Integrator kind,
                     const std::string& label) {
    tell(label);
    const auto t0 = std::chrono::steady_clock::now();
    const fem::Trajectory run = fem::integrate(on.dynamics, kind, spec.step, steps, spec.linear);
    const double seconds = seconds_since(t0);
    MetricSeries s = compare_fem(frames, reference, run, label, spec.metrics_every);
    s.ok = run.ok;
    s.message = run.message;
    s.seconds = seconds;
    s.sweeps = run.sweeps;
    if (run.ok)
      result.figures[label + ".static_gap"] =
          (run.u.back() - on_statics).norm() / on_statics.norm();
    result.series.push_back(std::move(s));
  };
  for (Integrator kind : spec.solvers) run_one(scene, statics, kind, fem::to_string(kind));
  for (const BenchmarkSpec::OtherMaterial& other : spec.other_materials) {
    const fem::Scene on = scene_with(other.material);
    const Eigen::VectorXd on_statics = fem::static_state(on);
    for (Integrator kind : other.solvers)
      run_one(on, on_statics, kind, other.label + "/" + fem::to_string(kind));
  }

  if (spec.fiber.enabled) {
    tell("fiber model");
    run_fiber_series(spec, frames, reference, statics, converged, result);
  }
  for (const MetricSeries& s : result.series) add_series_figures(spec, s, result.figures);
  if (progress) progress(total, total);
  return result;
}

}  // namespace fiberfluid::experiment

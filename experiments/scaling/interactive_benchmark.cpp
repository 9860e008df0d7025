// SPDX-License-Identifier: GPL-3.0-or-later
// The interactive step (issue 25): an organ of about 1,000 vertices pressed
// by a paddle that a hand moves, one Newton step per frame, each from the
// last equilibrium (solve::InteractiveStepper). Prints the frames per second
// the solver sustains and a step's cost in exact residual passes on the same
// mesh (one pass: lengths, law and forces of every fiber pair).
//   fiberfluid_interactive [--frames 300] [--depth 0.2] [--vertices 1000] [--trace]
//
// The hand: the paddle goes down by `depth` of the organ's height and back
// up, as 1 - cos over the frames (at 30 frames a second and 300 frames, 10 s
// for a press and release of 36 mm).
#include <CLI/CLI.hpp>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "fiberfluid/experiment/experiment.hpp"
#include "fiberfluid/model/equilibrium.hpp"
#include "fiberfluid/solve/newton/interactive_stepper.hpp"
#include "fiberfluid/solve/tangent/tangent_solve.hpp"
#include "fiberfluid/util/omp_wait_policy.hpp"

namespace {

using Clock = std::chrono::steady_clock;
double seconds_between(Clock::time_point a, Clock::time_point b) {
  return std::chrono::duration<double>(b - a).count();
}

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v.empty() ? 0.0 : v[v.size() / 2];
}

}  // namespace

int main(int argc, char** argv) {
  fiberfluid::util::wait_passively_unless_chosen(argv);  // as the fiberfluid program runs
  CLI::App cli{"fiberfluid interactive step: frames per second of a paddle moved by hand"};
  int frames = 300, vertices = 1000, repeat = 20;
  double depth = 0.2;
  std::string tangent = "auto";
  cli.add_option("--frames", frames, "steps of the press and release");
  cli.add_option("--depth", depth, "the press at its deepest, as a share of the organ's height");
  cli.add_option("--vertices", vertices, "the liver remeshed to about this many vertices");
  cli.add_option("--tangent", tangent, "newton.tangent: auto, dense, krylov or sparse")
      ->check(CLI::IsMember({"auto", "dense", "krylov", "sparse"}));
  cli.add_option("--repeat", repeat, "timings of the residual pass (the median is kept)");
  bool trace = false;
  cli.add_flag("--trace", trace, "print each frame's residuals, gmres iterations and contacts");
  CLI11_PARSE(cli, argc, argv);

  std::ifstream in(FIBERFLUID_INTERACTIVE_EXPERIMENT);
  nlohmann::json config = nlohmann::json::parse(in);
  config["surface"]["remesh_vertices"] = vertices;
  config["stepping"]["newton"]["tangent"] = tangent;
  config["expected"] = nlohmann::json::array();
  const auto build_start = Clock::now();
  const fiberfluid::experiment::Experiment ex = fiberfluid::experiment::parse_experiment(
      config, std::filesystem::path(FIBERFLUID_INTERACTIVE_EXPERIMENT).parent_path(),
      FIBERFLUID_INTERACTIVE_EXPERIMENT);
  const fiberfluid::experiment::Case& c = ex.simulation().cases.front();
  const fiberfluid::model::Model& model = c.model;
  const double build_seconds = seconds_between(build_start, Clock::now());

  fiberfluid::solve::InteractiveStepper stepper(model, c.stepping);
  fiberfluid::solve::LoadPoint point = stepper.point();
  const Eigen::MatrixXd& V = model.surface.V;
  const double height = V.col(1).maxCoeff() - V.col(1).minCoeff();
  const double top = point.planes[0];

  std::vector<double> step_seconds;
  long long iterations = 0, krylov = 0, computed = 0, stored = 0, cuts = 0;
  int failed = 0, most_iterations = 0;
  double deepest_force = 0.0;
  const auto run_start = Clock::now();
  for (int k = 1; k <= frames; ++k) {
    const double phase = 2.0 * M_PI * k / frames;
    point.planes[0] = top - depth * height * 0.5 * (1.0 - std::cos(phase));
    const auto start = Clock::now();
    const fiberfluid::solve::InteractiveStepper::Result r = stepper.step(point);
    step_seconds.push_back(seconds_between(start, Clock::now()));
    if (!r.success) {
      ++failed;
      std::fprintf(stderr, "frame %d: %s\n", k, r.message.c_str());
      continue;
    }
    if (trace) {
      std::fprintf(stderr, "frame %d:", k);
      for (double v : r.record.residual_norms) std::fprintf(stderr, " %.1e", v);
      std::fprintf(stderr, " gmres %d contacts %d\n", r.record.krylov_iterations,
                   r.record.paddles[0].contacts);
    }
    iterations += r.record.newton_iterations;
    most_iterations = std::max(most_iterations, r.record.newton_iterations);
    krylov += r.record.krylov_iterations;
    computed += r.record.pair_passes.computed;
    stored += r.record.pair_passes.stored;
    cuts += r.record.step_cuts;
    deepest_force = std::min(deepest_force, r.record.paddles[0].force.y());
  }
  const double run_seconds = seconds_between(run_start, Clock::now());

  // One exact residual pass at the state reached halfway (the deepest press
  // was passed; the last state is the rest again): lengths, law and forces.
  const fiberfluid::model::Equilibrium equilibrium(model);
  const Eigen::VectorXd x = stepper.unknowns();
  std::vector<double> pass_seconds;
  Eigen::VectorXd sink;
  for (int r = 0; r < repeat; ++r) {
    const auto start = Clock::now();
    sink = equilibrium.residual(x, point.factors);
    pass_seconds.push_back(seconds_between(start, Clock::now()));
  }
  const double pass = median(pass_seconds), step = run_seconds / frames;

  const int n = model.num_vertices();
  std::printf(
      "interactive step: liver remeshed to %d vertices (%lld fibers kept), %s tangent\n", n,
      static_cast<long long>(c.fibers.kept),
      fiberfluid::solve::to_string(fiberfluid::solve::choose_tangent(
          c.stepping.newton.tangent, model.num_unknowns(), model.material.kinematics, false)));
  std::printf("  set-up (read, remesh, prune): %.3f s\n", build_seconds);
  std::printf("  %d frames, paddle down %.1f mm and back, deepest push %.2f N, %d failed\n", frames,
              1e3 * depth * height, -deepest_force, failed);
  std::printf("  frames per second: %.1f (mean step %.2f ms, median %.2f ms, slowest %.2f ms)\n",
              frames / run_seconds, 1e3 * step, 1e3 * median(step_seconds),
              1e3 * *std::max_element(step_seconds.begin(), step_seconds.end()));
  std::printf(
      "  per step: %.2f newton iterations (most %d), %.1f gmres iterations, %.2f computed and "
      "%.1f stored pair passes, %lld step cuts in all\n",
      static_cast<double>(iterations) / frames, most_iterations,
      static_cast<double>(krylov) / frames, static_cast<double>(computed) / frames,
      static_cast<double>(stored) / frames, cuts);
  std::printf("  one exact residual pass: %.3f ms; a step costs %.1f of them\n", 1e3 * pass,
              step / pass);
  nlohmann::json line = {{"vertices", n},
                         {"frames", frames},
                         {"frames_per_second", frames / run_seconds},
                         {"mean_step_seconds", step},
                         {"residual_pass_seconds", pass},
                         {"step_in_passes", step / pass},
                         {"newton_iterations_per_step", static_cast<double>(iterations) / frames},
                         {"failed", failed}};
  std::printf("%s\n", line.dump().c_str());
  return failed == 0 ? 0 : 1;
}

// SPDX-License-Identifier: GPL-3.0-or-later
// One case of the scaling benchmark: the sphere experiment (its material,
// supports and loads, experiments/sphere.json) on an icosphere with the given
// subdivisions, solved by one backend. Prints one JSON line with the timings,
// the peak memory of this process and the factorisation rate; run.py runs
// one process per case, so that each peak is its own.
//   fiberfluid_scaling --subdivisions 4 --solver block-cholesky [--save u.bin]
//   fiberfluid_scaling --subdivisions 4 --newton exponential [--tangent krylov]
//   fiberfluid_scaling --gemm-peak     (this machine's BLAS dgemm rate)
#include <sys/resource.h>
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <chrono>
#include <fstream>
#include <iostream>
#include <nlohmann/json.hpp>

#include "fiberfluid/experiment/experiment.hpp"
#include "fiberfluid/experiment/run/runner.hpp"
#include "fiberfluid/util/omp_wait_policy.hpp"
#include "gemm_peak.hpp"

namespace {

double peak_memory_mib() {
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  return usage.ru_maxrss / 1024.0;  // kilobytes on Linux
}

}  // namespace

int main(int argc, char** argv) {
  fiberfluid::util::wait_passively_unless_chosen(argv);  // as the fiberfluid program runs
  CLI::App cli{"fiberfluid scaling benchmark: one case"};
  int subdivisions = 2;
  std::string solver = "dense-lu", save;
  bool gemm_peak = false;
  std::string newton_law, tangent = "auto";
  double beta = 5.0, gravity_scale = 1.0, treecode = 0.0;
  int steps = 0;
  bool no_residual = false;
  cli.add_option("--subdivisions", subdivisions, "icosphere subdivisions (2: 162 vertices)");
  cli.add_option("--solver", solver, "dense-lu, block-cholesky, cholmod or pcg");
  cli.add_option("--save", save, "write the final unknowns as raw doubles");
  cli.add_flag("--gemm-peak", gemm_peak, "measure this machine's dgemm GFLOP/s");
  cli.add_option("--newton", newton_law,
                 "run the Newton scheme with this law: constant or exponential (Y0 = Y)");
  cli.add_option("--beta", beta, "the exponential law's beta");
  cli.add_option("--gravity-scale", gravity_scale, "multiplies the sphere's gravity");
  cli.add_option("--tangent", tangent, "newton tangent solve: auto, dense or krylov");
  cli.add_option("--treecode", treecode,
                 "the bulk product by the treecode with this relative error (pcg)");
  cli.add_option("--steps", steps, "load steps (default: the sphere's 10)");
  cli.add_flag("--no-residual", no_residual, "skip each step's exact O(N^2) residual");
  bool floor = false;
  cli.add_flag("--floor", floor,
               "after the run, measure dgemm and print the run's floor: its factorisations at "
               "the dgemm rate plus its (memory-bound) solves as measured");
  CLI11_PARSE(cli, argc, argv);

  if (gemm_peak) {
    std::cout << nlohmann::json{{"gemm_gflops", gemm_gflops(3000)}}.dump() << std::endl;
    return 0;
  }
  // The sphere experiment with another resolution and backend.
  std::ifstream in(FIBERFLUID_SPHERE_EXPERIMENT);
  nlohmann::json config = nlohmann::json::parse(in);
  config["surface"]["subdivisions"] = subdivisions;
  config["stepping"]["solver"] = solver;
  config["expected"] = nlohmann::json::array();
  // Gravity only: the sphere's 300 N point force on one vertex turns faces
  // over on meshes of 10,242 vertices and more (a point load on ever smaller
  // areas), which the runaway guard rightly stops.
  config["loads"] = nlohmann::json::array({config["loads"][0]});
  for (auto& component : config["loads"][0]["acceleration"])
    component = component.get<double>() * gravity_scale;
  if (treecode > 0.0)
    config["fibers"] = {{"product", "treecode"}, {"treecode_tolerance", treecode}};
  if (steps > 0) config["stepping"]["steps"] = steps;
  if (no_residual) config["stepping"]["measure_residual"] = false;
  if (!newton_law.empty()) {
    config["stepping"]["scheme"] = "newton";
    config["stepping"]["newton"] = {{"tangent", tangent}};
    if (newton_law == "exponential") {
      const double Y = config["material"]["Y"];
      config["material"].erase("Y");
      config["material"]["law"] = {{"type", "exponential"}, {"Y0", Y}, {"beta", beta}};
    }
  }
  const fiberfluid::experiment::Experiment ex =
      fiberfluid::experiment::parse_experiment(config, ".", FIBERFLUID_SPHERE_EXPERIMENT);

  const fiberfluid::experiment::ExperimentResult result =
      fiberfluid::experiment::run_experiment(ex);
  const fiberfluid::experiment::RunResult& run = result.runs.front();
  const auto& s = run.summary;
  double slowest_step = 0.0;
  for (const auto& step : s.steps) slowest_step = std::max(slowest_step, step.seconds);
  nlohmann::json line = {
      {"vertices", ex.simulation().cases.front().model.num_vertices()},
      {"solver", solver},
      {"success", s.success},
      {"message", s.message},
      {"assemble_s", s.assemble_seconds},
      {"factorize_s", s.factorize_seconds},
      {"solve_s", s.solve_seconds},
      {"run_s", s.total_seconds},
      {"slowest_step_s", slowest_step},
      {"peak_mib", peak_memory_mib()},
      {"factorization_gflops", s.solver_statistics.factorization_kernel_seconds > 0
                                   ? s.solver_statistics.factorization_flops /
                                         s.solver_statistics.factorization_kernel_seconds / 1e9
                                   : 0.0},
      {"pcg_iterations", s.solver_statistics.iterations},
      {"treecode_tolerance", treecode},
      {"scheme", fiberfluid::solve::to_string(s.scheme)},
      {"tangent", fiberfluid::solve::to_string(s.tangent)},
      {"newton_iterations", s.newton_iterations},
      {"krylov_iterations", s.krylov_iterations},
      {"factorizations", s.factorizations},
      {"steps", s.steps.size()},
      {"newton_iterations_per_step",
       s.steps.empty() ? 0.0 : double(s.newton_iterations) / double(s.steps.size())},
      {"krylov_iterations_per_solve",
       s.newton_iterations > 0 ? double(s.krylov_iterations) / s.newton_iterations : 0.0},
      {"max_displacement", s.success ? result.figures.at("max_displacement") : 0.0}};
  if (floor) {
    const double gflops = gemm_gflops(3000);
    const double floor_s =
        s.solver_statistics.factorization_flops / (gflops * 1e9) + s.solve_seconds;
    line["gemm_gflops"] = gflops;
    line["floor_s"] = floor_s;
    line["run_over_floor"] = floor_s > 0.0 ? s.total_seconds / floor_s : 0.0;
  }
  std::cout << line.dump() << std::endl;
  if (!save.empty() && s.success)
    std::ofstream(save, std::ios::binary)
        .write(reinterpret_cast<const char*>(s.unknowns.data()),
               static_cast<std::streamsize>(sizeof(double) * s.unknowns.size()));
  return s.success ? 0 : 2;
}

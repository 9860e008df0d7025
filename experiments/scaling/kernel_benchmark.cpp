// SPDX-License-Identifier: GPL-3.0-or-later
// The pair kernels every run is made of (issue 12), timed on the sphere
// experiment's model at one size, against this machine's dgemm peak measured
// in the same run. Prints a table and one JSON line per kernel.
//   fiberfluid_kernels --subdivisions 4 [--repeat 3]
//
// Flops are counted per pair visit as the kernels do the arithmetic (a square
// root or a division counts one): bulk product with 3 columns 21 per ordered
// pair, bulk diagonal 13 per ordered pair, dense block 13 per unordered pair
// (useful work: it computes both triangles, each pair twice),
// Newton tangent product (constant law, recomputed) 50 per ordered pair,
// stored tangent product 27 per ordered pair.
#include <CLI/CLI.hpp>
#include <chrono>
#include <cstdio>
#include <fstream>
#include <functional>
#include <iostream>
#include <nlohmann/json.hpp>

#include "app/experiment.hpp"
#include "gemm_peak.hpp"
#include "model/equilibrium.hpp"
#include "model/fiber_system.hpp"
#include "model/loads.hpp"

namespace {

using fiberfluid::model::BoundaryMethod;

// The best of `repeat` timings of `kernel`, in seconds.
double best_seconds(int repeat, const std::function<void()>& kernel) {
  double best = 1e300;
  for (int r = 0; r < repeat; ++r) {
    const auto start = std::chrono::steady_clock::now();
    kernel();
    best = std::min(best, std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
  }
  return best;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App cli{"fiberfluid pair kernels: time and GFLOP/s against the dgemm peak"};
  int subdivisions = 4, repeat = 3;
  cli.add_option("--subdivisions", subdivisions, "icosphere subdivisions (4: 2,562 vertices)");
  cli.add_option("--repeat", repeat, "timings per kernel (the best is kept)");
  CLI11_PARSE(cli, argc, argv);

  std::ifstream in(FIBERFLUID_SPHERE_EXPERIMENT);
  nlohmann::json config = nlohmann::json::parse(in);
  config["surface"]["subdivisions"] = subdivisions;
  config["expected"] = nlohmann::json::array();
  const fiberfluid::app::Experiment ex =
      fiberfluid::app::parse_experiment(config, ".", FIBERFLUID_SPHERE_EXPERIMENT);
  const fiberfluid::model::Model& model = ex.cases.front().model;
  const int n = model.num_vertices();
  const double ordered = static_cast<double>(n) * (n - 1), unordered = ordered / 2.0;

  const double peak = gemm_gflops(3000);
  const fiberfluid::model::FiberSystem system(model, model.surface.V, BoundaryMethod::Elimination, 1e9);
  const Eigen::MatrixXd V = Eigen::MatrixXd::Random(n, 3);
  const fiberfluid::model::Equilibrium equilibrium(model);
  Eigen::VectorXd x = 1e-3 * Eigen::VectorXd::Random(model.num_unknowns());
  const std::vector<double> factors(model.loads.size(), 1.0);
  const Eigen::VectorXd w = Eigen::VectorXd::Random(model.num_unknowns());
  const fiberfluid::model::TangentOperator stored = equilibrium.linearize(x, factors);

  struct Row {
    const char* name;
    double pairs, flops_per_pair;
    std::function<void()> kernel;
  };
  Eigen::MatrixXd sink;
  Eigen::VectorXd vector_sink;
  const std::vector<Row> rows = {
      {"bulk_product (3 columns)", ordered, 21, [&] { sink = system.bulk_product(V); }},
      {"bulk_diagonal", ordered, 13,
       [&] {
         const fiberfluid::model::FiberSystem fresh(model, model.surface.V,
                                                    BoundaryMethod::Elimination, 1e9);
         vector_sink = fresh.bulk_diagonal();
       }},
      {"dense_block (one axis)", unordered, 13, [&] { sink = system.dense_block(0); }},
      {"tangent_product (recomputed)", ordered, 50,
       [&] { vector_sink = equilibrium.tangent_product(x, factors, w); }},
      {"tangent apply (stored)", ordered, 27, [&] { vector_sink = stored.apply(w); }},
  };
  std::printf("%d vertices, dgemm peak %.1f GFLOP/s\n", n, peak);
  std::printf("%-30s %10s %12s %10s %8s\n", "kernel", "seconds", "Gpairs/s", "GFLOP/s", "% peak");
  for (const Row& row : rows) {
    const double seconds = best_seconds(repeat, row.kernel);
    const double gflops = row.pairs * row.flops_per_pair / seconds / 1e9;
    std::printf("%-30s %10.4f %12.3f %10.2f %7.1f%%\n", row.name, seconds,
                row.pairs / seconds / 1e9, gflops, 100.0 * gflops / peak);
    std::cerr << nlohmann::json{{"vertices", n},         {"kernel", row.name},
                                {"seconds", seconds},    {"gflops", gflops},
                                {"gemm_peak_gflops", peak}}.dump()
              << "\n";
  }
  return 0;
}

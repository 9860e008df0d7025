// SPDX-License-Identifier: GPL-3.0-or-later
// The pair kernels every run is made of (issue 12), timed on the sphere
// experiment's model at one size, against this machine's dgemm peak measured
// in the same run. Prints a table and one JSON line per kernel.
//   fiberfluid_kernels --subdivisions 4 [--repeat 3]
//
// Two flop counts per kernel (a square root or a division counts one):
//   nominal: the arithmetic of the plain row loop, every ordered pair:
//     bulk product with 3 columns 21, bulk diagonal 13, dense block 13 per
//     entry, Newton tangent product (recomputed) 50, stored tangent apply 27.
//     Comparable across versions: the measure of issue 12's table.
//   executed: what the tiled kernels do, each unordered pair once:
//     bulk product 27, bulk diagonal 16, dense block 15, tangent product 59;
//     the stored apply is still a row loop (27 per ordered pair).
// Block Cholesky's solves of the x block (3 columns) by the threaded solve
// and by LAPACK's potrs, in single and double precision.
// Two floors say why not more: the square roots and divisions alone (one of
// each per unordered pair, the divide unit's limit), and writing a fresh
// matrix of the dense block's size (memory and page faults).
#include <CLI/CLI.hpp>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <functional>
#include <iostream>
#include <nlohmann/json.hpp>
#include <stdexcept>
#include <string>
#include <vector>

#include "fiberfluid/experiment/experiment.hpp"
#include "fiberfluid/model/equilibrium.hpp"
#include "fiberfluid/model/fiber_system.hpp"
#include "fiberfluid/model/loads.hpp"
#include "fiberfluid/model/vector_clones.hpp"
#include "fiberfluid/solve/cholesky_solve.hpp"
#include "fiberfluid/util/run_control.hpp"
#include "gemm_peak.hpp"

extern "C" {
void spotrf_(const char*, const int*, float*, const int*, int*, std::size_t);
void spotrs_(const char*, const int*, const int*, const float*, const int*, float*, const int*,
             int*, std::size_t);
void dpotrf_(const char*, const int*, double*, const int*, int*, std::size_t);
void dpotrs_(const char*, const int*, const int*, const double*, const int*, double*, const int*,
             int*, std::size_t);
}

namespace {

using fiberfluid::model::BoundaryMethod;

// One square root and one division per unordered pair of n values, as the
// pair kernels' tiles take them, and nothing else worth counting.
FIBERFLUID_VECTOR_CLONES
double sqrt_div_floor(const std::vector<double>& r2) {
  const int n = static_cast<int>(r2.size());
  double total = 0.0;
#pragma omp parallel for schedule(static, 16) reduction(+ : total)
  for (int i = 0; i < n; ++i) {
    const double* x = r2.data();
    const double xi = x[i];
    double sum = 0.0;
#pragma omp simd reduction(+ : sum)
    for (int j = i + 1; j < n; ++j) sum += xi / std::sqrt(x[j]);
    total += sum;
  }
  return total;
}

// The best of `repeat` timings of `kernel`, in seconds.
double best_seconds(int repeat, const std::function<void()>& kernel) {
  double best = 1e300;
  for (int r = 0; r < repeat; ++r) {
    const auto start = std::chrono::steady_clock::now();
    kernel();
    best = std::min(
        best, std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
  }
  return best;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App cli{"fiberfluid pair kernels: time and GFLOP/s against the dgemm peak"};
  int subdivisions = 4, repeat = 3;
  std::string only, law = "constant";
  cli.add_option("--subdivisions", subdivisions, "icosphere subdivisions (4: 2,562 vertices)");
  cli.add_option("--law", law,
                 "the Newton kernels' law: constant (Y 3000) or exponential (Y0 3000, beta 4)")
      ->check(CLI::IsMember({"constant", "exponential"}));
  cli.add_option("--repeat", repeat, "timings per kernel (the best is kept)");
  cli.add_option("--only", only, "time only the kernels whose name starts with this");
  CLI11_PARSE(cli, argc, argv);

  std::ifstream in(FIBERFLUID_SPHERE_EXPERIMENT);
  nlohmann::json config = nlohmann::json::parse(in);
  config["surface"]["subdivisions"] = subdivisions;
  config["expected"] = nlohmann::json::array();
  const fiberfluid::experiment::Experiment ex =
      fiberfluid::experiment::parse_experiment(config, ".", FIBERFLUID_SPHERE_EXPERIMENT);
  fiberfluid::model::Model model = ex.simulation().cases.front().model;
  if (law == "exponential")
    model.material.law = fiberfluid::model::FiberLaw::exponential(3000.0, 4.0);
  const int n = model.num_vertices();
  const double ordered = static_cast<double>(n) * (n - 1), unordered = ordered / 2.0;

  const double peak = gemm_gflops(3000);
  const fiberfluid::model::FiberSystem system(model, model.surface.V, BoundaryMethod::Elimination,
                                              1e9);
  const Eigen::MatrixXd V = Eigen::MatrixXd::Random(n, 3);
  const fiberfluid::model::Equilibrium equilibrium(model);
  Eigen::VectorXd x = 1e-3 * Eigen::VectorXd::Random(model.num_unknowns());
  const std::vector<double> factors(model.loads.size(), 1.0);
  const Eigen::VectorXd w = Eigen::VectorXd::Random(model.num_unknowns());
  fiberfluid::model::TangentOperator stored = equilibrium.linearize(x, factors);
  Eigen::VectorXd moved = x;

  // Block Cholesky's solves with the sphere's x block factored, in single
  // precision (Newton-Krylov's preconditioner) and double (the incremental
  // scheme), three right-hand sides: the threaded solve against LAPACK's.
  Eigen::MatrixXf factor_single = system.dense_block_single(0);
  Eigen::MatrixXd factor_double = system.dense_block(0);
  const int m = static_cast<int>(factor_double.rows());  // the free vertices
  int info = 0;
  spotrf_("L", &m, factor_single.data(), &m, &info, 1);
  if (info == 0) dpotrf_("L", &m, factor_double.data(), &m, &info, 1);
  if (info != 0) throw std::runtime_error("the sphere's block is not positive definite");
  const Eigen::MatrixXd rhs = Eigen::MatrixXd::Random(m, 3);
  Eigen::MatrixXf solved_single;
  Eigen::MatrixXd solved_double;
  const int three = 3;

  struct Row {
    const char* name;
    double pairs, flops_per_pair;       // nominal: ordered pairs (entries for the block)
    double visits, executed_per_visit;  // executed: pairs visited
    std::function<void()> kernel;
  };
  Eigen::MatrixXd sink;
  Eigen::VectorXd vector_sink;
  double scalar_sink = 0.0;
  std::vector<double> squared_lengths(static_cast<size_t>(n));
  for (int i = 0; i < n; ++i)
    squared_lengths[static_cast<size_t>(i)] = 1.0 + model.surface.V.row(i).squaredNorm();
  // The law over one pair per fiber, a row of 256 strains at a time (as the
  // kernels call it), against libm's exp value by value.
  std::vector<double> strains(256), moduli(256), slopes(256);
  for (size_t k = 0; k < strains.size(); ++k) strains[k] = -0.3 + 0.6 * k / 255.0;
  const auto rows_of_pairs = static_cast<long long>(unordered / 256.0);
  const fiberfluid::model::FiberLaw& the_law = model.material.law;
  const std::vector<Row> rows = {
      {"bulk_product (3 columns)", ordered, 21, unordered, 27,
       [&] { sink = system.bulk_product(V); }},
      {"bulk_diagonal", ordered, 13, unordered, 16,
       [&] {
         const fiberfluid::model::FiberSystem fresh(model, model.surface.V,
                                                    BoundaryMethod::Elimination, 1e9);
         vector_sink = fresh.bulk_diagonal();
       }},
      {"dense_block (one axis)", ordered, 13, unordered, 15, [&] { sink = system.dense_block(0); }},
      {"tangent_product (recomputed)", ordered, 50, unordered, 59,
       [&] { vector_sink = equilibrium.tangent_product(x, factors, w); }},
      {"tangent apply (stored)", ordered, 27, ordered, 27, [&] { vector_sink = stored.apply(w); }},
      // Newton's two passes over the pairs at a state (the law evaluated in each).
      {"residual (Newton)", ordered, 0, unordered, 0,  // pairs per second only
       [&] { vector_sink = equilibrium.residual(x, factors); }},
      {"linearize (store c1, c2)", ordered, 0, unordered, 0,
       [&] {  // at a state other than the one it holds (else it keeps what it has)
         moved[0] = moved[0] == x[0] ? x[0] + 1e-9 : x[0];
         equilibrium.linearize(moved, factors, stored);
       }},
      {"residual and c1, c2 (one pass)", ordered, 0, unordered, 0,
       [&] {  // what a Newton iteration computes over the pairs
         moved[0] = moved[0] == x[0] ? x[0] + 1e-9 : x[0];
         vector_sink = equilibrium.residual(moved, factors, stored);
       }},
      {"law: block evaluation", unordered, 0, unordered, 0,
       [&] {
         for (long long r = 0; r < rows_of_pairs; ++r)
           the_law.evaluate(strains.data(), strains.size(), moduli.data(), slopes.data());
         scalar_sink += moduli[7];
       }},
      {"law: libm exp per value", unordered, 0, unordered, 0,
       [&] {
         for (long long r = 0; r < rows_of_pairs; ++r)
           for (size_t k = 0; k < strains.size(); ++k)
             moduli[k] = 3000.0 * std::exp(4.0 * strains[k]);
         scalar_sink += moduli[7];
       }},
      {"cholesky solve f32, threaded", 0, 0, 0, 0,
       [&] {
         solved_single = rhs.cast<float>();
         fiberfluid::solve::cholesky_solve_in_place(m, factor_single.data(), solved_single.data(),
                                                    3, m);
       }},
      {"cholesky solve f32, spotrs", 0, 0, 0, 0,
       [&] {
         solved_single = rhs.cast<float>();
         spotrs_("L", &m, &three, factor_single.data(), &m, solved_single.data(), &m, &info, 1);
       }},
      {"cholesky solve f64, threaded", 0, 0, 0, 0,
       [&] {
         solved_double = rhs;
         fiberfluid::solve::cholesky_solve_in_place(m, factor_double.data(), solved_double.data(),
                                                    3, m);
       }},
      {"cholesky solve f64, dpotrs", 0, 0, 0, 0,
       [&] {
         solved_double = rhs;
         dpotrs_("L", &m, &three, factor_double.data(), &m, solved_double.data(), &m, &info, 1);
       }},
      {"floor: sqrt + div per pair", unordered, 2, unordered, 2,
       [&] { scalar_sink = sqrt_div_floor(squared_lengths); }},
      {"floor: write a new N x N", ordered, 0, ordered, 0,
       [&] {  // a fresh allocation, as dense_block's (with its huge pages)
         Eigen::MatrixXd fresh(n, n);
         fiberfluid::advise_huge_pages(fresh.data(), 8.0 * static_cast<double>(fresh.size()));
         fresh.setConstant(1.0);
         sink.swap(fresh);
       }},
  };
  std::printf("%d vertices, %s law, dgemm peak %.1f GFLOP/s\n", n, law.c_str(), peak);
  std::printf("%-30s %9s %9s %9s %7s %9s %7s\n", "kernel", "seconds", "Gpairs/s", "nominal",
              "% peak", "executed", "% peak");
  for (const Row& row : rows) {
    if (std::string(row.name).rfind(only, 0) != 0) continue;
    const double seconds = best_seconds(repeat, row.kernel);
    const double nominal = row.pairs * row.flops_per_pair / seconds / 1e9;
    const double executed = row.visits * row.executed_per_visit / seconds / 1e9;
    std::printf("%-30s %9.4f %9.3f %9.2f %6.1f%% %9.2f %6.1f%%\n", row.name, seconds,
                ordered / seconds / 1e9, nominal, 100.0 * nominal / peak, executed,
                100.0 * executed / peak);
    std::cerr << nlohmann::json{{"vertices", n},
                                {"law", law},
                                {"kernel", row.name},
                                {"seconds", seconds},
                                {"nominal_gflops", nominal},
                                {"executed_gflops", executed},
                                {"gemm_peak_gflops", peak}}
                     .dump()
              << "\n";
  }
  if (scalar_sink == 42.0) std::printf("\n");  // keeps the floor's sum alive
  return 0;
}

// SPDX-License-Identifier: GPL-3.0-or-later
// The treecode bulk product (issue 12) against the exact tiled kernel on
// icospheres: its relative error and its time, per size and tolerance.
// Prints a Markdown table and one JSON line per row.
//   fiberfluid_treecode [--subdivisions 4,5,6] [--tolerances 1e-3,1e-4,1e-6,1e-8]
//                       [--exact-up-to 6]   (the exact product beyond is O(N^2) minutes)
#include <CLI/CLI.hpp>
#include <chrono>
#include <cmath>
#include <iostream>
#include <nlohmann/json.hpp>
#include <random>
#include <string>
#include <vector>

#include "fiberfluid/geom/area_vectors.hpp"
#include "fiberfluid/geom/generators.hpp"
#include "fiberfluid/model/bulk_treecode.hpp"
#include "fiberfluid/model/pair_kernels.hpp"

namespace {

using namespace fiberfluid;

double seconds_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"fiberfluid_treecode: the treecode bulk product against the exact one"};
  std::vector<int> subdivisions = {4, 5, 6};
  std::vector<double> tolerances = {1e-3, 1e-4, 1e-6, 1e-8};
  int exact_up_to = 6, degree = 0;
  double theta = 0.0;
  app.add_option("--subdivisions", subdivisions)->delimiter(',');
  app.add_option("--tolerances", tolerances)->delimiter(',');
  app.add_option("--exact-up-to", exact_up_to);
  app.add_option("--degree", degree, "override the tolerance's degree (tuning)");
  app.add_option("--theta", theta, "override the tolerance's theta (tuning)");
  CLI11_PARSE(app, argc, argv);

  std::cout << "| vertices | tolerance | degree | theta | relative error (2-norm) | max row error "
               "/ max row "
               "| diagonal relative error | treecode s | exact s | speed-up |\n"
            << "|---|---|---|---|---|---|---|---|---|---|" << std::endl;
  for (int level : subdivisions) {
    const geom::Surface sphere = geom::icosphere(level);
    const int n = sphere.num_vertices();
    const Eigen::VectorXd area = geom::vertex_area_vectors(sphere.V, sphere.F).magnitude;
    const model::PairFactors factors(nullptr, model::ConnectionCount::Symmetric, n);
    // A smooth displacement field, as the solver's iterates are.
    Eigen::MatrixXd V(n, 3);
    for (int i = 0; i < n; ++i) {
      const Eigen::RowVector3d x = sphere.V.row(i);
      V.row(i) << std::sin(2 * x[0]) + x[1] * x[2], std::cos(3 * x[1]) * x[0], x[2] * x[2] - x[0];
    }
    Eigen::MatrixXd exact;
    Eigen::VectorXd exact_diagonal;
    double exact_seconds = NAN;
    if (level <= exact_up_to) {
      const model::BulkPairs pairs(sphere.V, area, factors);
      pairs.laplacian_product(V);  // warm, as the treecode is
      const auto start = std::chrono::steady_clock::now();
      exact = pairs.laplacian_product(V);
      exact_seconds = seconds_since(start);
      exact_diagonal = pairs.row_sums();
    }
    for (double tolerance : tolerances) {
      model::TreecodeOptions options = model::TreecodeOptions::for_tolerance(tolerance);
      if (degree > 0) options.degree = degree;
      if (theta > 0.0) options.theta = theta;
      const model::BulkTreecode treecode(sphere.V, area, factors, options);
      treecode.laplacian_product(V);  // warm
      const auto start = std::chrono::steady_clock::now();
      const Eigen::MatrixXd approximate = treecode.laplacian_product(V);
      const double seconds = seconds_since(start);
      double error = NAN, row_error = NAN, diagonal_error = NAN;
      if (exact.size() > 0) {
        error = (approximate - exact).norm() / exact.norm();
        row_error =
            (approximate - exact).rowwise().norm().maxCoeff() / exact.rowwise().norm().maxCoeff();
        diagonal_error = (treecode.row_sums() - exact_diagonal).norm() / exact_diagonal.norm();
      }
      std::cout << "| " << n << " | " << tolerance << " | " << options.degree << " | "
                << options.theta << " | " << error << " | " << row_error << " | " << diagonal_error
                << " | " << seconds << " | " << exact_seconds << " | " << exact_seconds / seconds
                << " |" << std::endl;
      std::cerr << nlohmann::json{{"vertices", n},
                                  {"tolerance", tolerance},
                                  {"relative_error", error},
                                  {"row_error", row_error},
                                  {"diagonal_error", diagonal_error},
                                  {"treecode_seconds", seconds},
                                  {"exact_seconds", exact_seconds},
                                  {"direct_terms", treecode.treecode().direct_terms()},
                                  {"proxy_terms", treecode.treecode().proxy_terms()}}
                       .dump()
                << std::endl;
    }
  }
  return 0;
}

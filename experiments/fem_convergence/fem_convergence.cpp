// SPDX-License-Identifier: GPL-3.0-or-later
// The nonlinear FEM reference against closed forms at large strain (issue
// 44): torsion of a thick tube, its inflation in plane strain, and a thick
// sphere's inflation
// (fem/closed_forms.hpp): linear tetrahedra (P1), quadratic ones (P2) and
// quadratic ones with a linear pressure (the mixed form, P2-P1), at four
// refinements. Prints each figure's relative error and the observed order
// log(e_coarse / e_fine) / log(h_coarse / h_fine) between refinements, and
// writes them as CSV.
//
//   build-release/experiments/fem_convergence/fiberfluid_fem_convergence
//       [--levels 4] [--nu 0.4999] [--csv out/fem_convergence.csv]

#include <CLI/CLI.hpp>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <string>
#include <vector>

#include "fiberfluid/fem/closed_forms.hpp"
#include "fiberfluid/util/omp_wait_policy.hpp"

namespace ff = fiberfluid::fem;

namespace {

struct Row {
  std::string problem, figure;
  std::string element;
  int level, nodes;
  double h, computed, exact, error, observed_order, seconds;
  int newton_iterations;
};

}  // namespace

int main(int argc, char** argv) {
  fiberfluid::util::wait_passively_unless_chosen(argv);  // CHOLMOD's threads beside other work
  CLI::App app{"The nonlinear FEM against closed forms: torsion and inflation of a thick tube"};
  int levels = 4;
  double nu = 0.4999;
  std::string csv = "out/fem_convergence.csv";
  std::vector<std::string> elements = {"P1", "P2", "P2-P1"};
  int steps = 16;
  std::vector<std::string> problems = {"torsion", "inflation", "sphere"};
  app.add_option("--levels", levels, "refinements (cells 1, 2, 3, ... across the wall)")
      ->check(CLI::Range(2, 8));
  app.add_option("--nu", nu, "Poisson's ratio of the nearly incompressible solid")
      ->check(CLI::Range(0.3, 0.49999));
  app.add_option("--elements", elements,
                 "P1 (linear tetrahedra), P2 (quadratic), P2-P1 (quadratic with a linear "
                 "pressure: the mixed form)")
      ->check(CLI::IsMember({"P1", "P2", "P2-P1"}));
  app.add_option("--problems", problems,
                 "torsion (a tube twisted), inflation (a tube in plane strain), sphere (a thick "
                 "sphere inflated)")
      ->check(CLI::IsMember({"torsion", "inflation", "sphere"}));
  app.add_option("--steps", steps, "load steps")->check(CLI::Range(1, 1000));
  app.add_option("--csv", csv, "where to write the table");
  CLI11_PARSE(app, argc, argv);

  ff::HyperelasticMaterial material;
  material.kind = ff::Hyperelastic::NeoHookeanNearlyIncompressible;
  material.young = 3.0;  // mu = 1 / (1 + nu) ~ 2/3: the figures scale with mu
  material.poisson = nu;
  std::vector<Row> rows;
  std::printf("%-10s %-12s %6s %5s %7s %8s %14s %14s %10s %6s %7s %6s\n", "problem", "figure",
              "element", "level", "nodes", "h", "computed", "exact", "rel.error", "rate", "s", "newton");
  for (const std::string& problem : problems)
    for (const std::string& element : elements) {
      std::vector<Row> previous;
      for (int level = 1; level <= levels; ++level) {
        ff::TubeMeshSpec tube;
        tube.inner_radius = 0.5;
        tube.outer_radius = 1.0;
        tube.radial = level;
        tube.around = 12 * level;
        tube.along = problem == "torsion" ? level : 1;
        tube.length = problem == "torsion" ? 0.5 : 0.5 / level;  // inflation: one layer, cubic cells
        tube.order = element == "P1" ? 1 : 2;
        ff::HyperelasticOptions options;
        options.steps = steps;
        options.tolerance = 1e-8;
        options.mixed = element == "P2-P1";
        const auto start = std::chrono::steady_clock::now();
        ff::ShellMeshSpec shell;  // radii 0.5 and 1 as the tube's
        shell.around = 2 * level;
        shell.radial = level;
        shell.order = tube.order;
        const ff::ClosedFormRun run =
            problem == "torsion"     ? ff::tube_torsion(tube, material, 1.0, options)  // 100% shear at B
            : problem == "inflation" ? ff::tube_inflation(tube, material, 2.0, options)  // a = 2 A
                                     : ff::sphere_inflation(shell, material, 1.5, options);
        const double seconds =
            std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        const double h = 0.5 / level;
        std::vector<Row> now;
        for (size_t k = 0; k < run.figures.size(); ++k) {
          const ff::ClosedFormFigure& f = run.figures[k];
          Row row{problem, f.name, element, level, run.nodes, h, f.computed, f.exact,
                  f.relative_error(), NAN, seconds, run.newton_iterations};
          if (!previous.empty())
            row.observed_order = std::log(previous[k].error / row.error) / std::log(previous[k].h / h);
          std::printf("%-10s %-12s %6s %5d %7d %8.4f %14.8g %14.8g %10.3e %6.2f %7.2f %6d\n",
                      problem.c_str(), f.name.c_str(), element.c_str(), level, run.nodes, h, f.computed,
                      f.exact, row.error, row.observed_order, seconds, run.newton_iterations);
          std::fflush(stdout);
          now.push_back(row);
          rows.push_back(row);
        }
        previous = now;
      }
    }
  std::ofstream out(csv);
  if (!out) {
    std::fprintf(stderr, "cannot write %s\n", csv.c_str());
    return 1;
  }
  out << "problem,figure,element,level,nodes,h_m,computed,exact,relative_error,observed_order,"
         "seconds,newton_iterations\n";
  for (const Row& r : rows)
    out << r.problem << ',' << r.figure << ',' << r.element << ',' << r.level << ',' << r.nodes << ','
        << r.h << ',' << r.computed << ',' << r.exact << ',' << r.error << ',' << r.observed_order
        << ',' << r.seconds << ',' << r.newton_iterations << '\n';
  std::printf("wrote %s\n", csv.c_str());
  return 0;
}

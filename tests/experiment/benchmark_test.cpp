// SPDX-License-Identifier: GPL-3.0-or-later
// Benchmark experiments: their fields, their runs and their files. The
// paper's findings themselves are the expected figures of
// experiments/benchmark_*.json (run by ExperimentFile) and fem_test.cpp.
#include "fiberfluid/experiment/run/benchmark.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "fiberfluid/experiment/experiment.hpp"
#include "fiberfluid/experiment/run/runner.hpp"
#include "fiberfluid/experiment/write/benchmark_files.hpp"
#include "fiberfluid/experiment/write/outputs.hpp"
#include "fiberfluid/geom/mesh_io.hpp"
#include "fiberfluid/metrics/metrics.hpp"
#include "fiberfluid/util/error.hpp"
#include "test_support.hpp"

namespace fiberfluid::experiment {
namespace {

using testing::ScratchDir;

// A small, short block: 4 x 4 cells, 3 s.
nlohmann::json small_block() {
  return nlohmann::json::parse(R"({
    "name": "small_block",
    "kind": "benchmark",
    "scene": "block-needle",
    "material": "MP1",
    "mesh": {"cells": [4, 4]},
    "time": {"step": 0.0333333333333333, "duration": 3},
    "solvers": ["explicit", "quasi-static"]
  })");
}

Experiment parse(const nlohmann::json& document) {
  return parse_experiment(document, ".", "benchmark.json");
}

void expect_error(nlohmann::json document, const std::string& part) {
  try {
    parse(document);
    ADD_FAILURE() << "no error, expected one mentioning '" << part << "'";
  } catch (const InputError& e) {
    const std::string message = e.what();
    EXPECT_NE(message.find(part), std::string::npos) << message;
    EXPECT_EQ(message.rfind("benchmark.json: ", 0), 0u) << message;
  }
}

TEST(Benchmark, BadFieldsAreNamed) {
  auto with = [](const char* key, const nlohmann::json& value) {
    nlohmann::json d = small_block();
    d[key] = value;
    return d;
  };
  expect_error(with("scene", "cube"), "scene: expected one of block-needle, bending-rod");
  expect_error(with("solvers", {"explicit", "leapfrog"}), "solvers: unknown solver \"leapfrog\"");
  expect_error(with("solvers", {"explicit", "explicit"}), "listed twice");
  expect_error(with("solvers", {"implicit-newmark"}),
               "unknown solver \"implicit-newmark\"");  // the reference
  expect_error(with("mesh", {{"cells", {4, 3}}}), "mesh.cells: expected an even number");
  expect_error(with("mesh", {{"cells", {4, 4}}, {"elements", "hexahedron"}}), "mesh.elements");
  expect_error(with("mesh", {{"cells", {4.5, 4}}}), "mesh.cells: expected whole numbers");
  expect_error(with("material", "MP4"), "material: expected a preset");
  expect_error(with("material", {{"E", 100}, {"nu", 0.5}}), "material.nu");
  expect_error(with("gravity", 9.81), "gravity: only the bending-rod scene");
  expect_error(with("time", {{"step", 0.1}, {"duration", 0.01}}),
               "time.duration: shorter than one step");
  expect_error(with("fiber_model", {{"fit", true}, {"Y", 5}}),
               "fiber_model.fit: give Y and gamma, or fit");
  expect_error(with("linear_solver", {{"method", "jacobi"}}), "linear_solver.method");
  expect_error(with("compare_materials", {{{"material", "MP2"}}}),
               "compare_materials[0].solvers: missing");
  expect_error(with("surface", {{"generator", "cube"}}), "surface: unknown field");
  nlohmann::json rod = small_block();
  rod["scene"] = "bending-rod";
  rod.erase("mesh");
  rod["needle"] = {{"speed", 0.1}};
  expect_error(rod, "needle: only the block-needle scene");
  expect_error(with("static_reference", {{"levels", 2}}),
               "static_reference: only the bending-rod scene");
  rod.erase("needle");
  rod["static_reference"] = {{"levels", 6}};
  expect_error(rod, "static_reference.levels");
  rod["static_reference"] = {{"ratio", 5}};
  expect_error(rod, "static_reference.ratio");
  rod["mesh"] = {{"cells", {40, 20, 20}}};
  rod["static_reference"] = {{"levels", 3}};
  expect_error(rod, "static_reference: the finest grid (cells x 8) has over 150,000 nodes");
}

// A short rod: 4 x 2 x 2 hexahedra, 1 s, quasi-static only.
nlohmann::json small_rod() {
  return nlohmann::json::parse(R"({
    "name": "small_rod",
    "kind": "benchmark",
    "scene": "bending-rod",
    "mesh": {"cells": [4, 2, 2]},
    "time": {"step": 0.0333333333333333, "duration": 1},
    "solvers": ["quasi-static"]
  })");
}

// The rod's static shape on refined grids converges at the trilinear
// hexahedron's second order to the Timoshenko cantilever's deflection, and
// the paper's 4 x 2 x 2 grid is far from it (its elements lock in bending).
TEST(Benchmark, TheRodsStaticShapeConvergesOnRefinedGrids) {
  nlohmann::json d = small_rod();
  d["static_reference"] = {{"levels", 3}, {"ratio", 2}};
  const BenchmarkResult r = run_benchmark(parse(d).benchmark());
  ASSERT_TRUE(r.ok) << r.message;
  const auto& f = r.figures;
  std::vector<double> largest;
  for (const char* refine : {"1", "2", "4", "8"})
    largest.push_back(f.at(std::string("static.refine_") + refine + ".max_displacement"));
  for (size_t k = 1; k < largest.size(); ++k) EXPECT_GT(largest[k], largest[k - 1]);  // locking
  EXPECT_EQ(f.at("static.monotone"), 1.0);
  EXPECT_NEAR(f.at("static.order"), 2.0, 0.3);
  EXPECT_GT(f.at("static.extrapolated_max_displacement"), largest.back());
  // Timoshenko: q L^4 / (8 E I) + q L^2 / (2 kappa G A), q = rho g A, a
  // square of side a (I = a^4 / 12, kappa = 5/6), MP3: E = 7000 Pa, nu = 0.2,
  // 10,000 kg/m^3, g = 0.05 m/s^2, L = 0.5 m, a = 0.25 m. A beam as short as
  // twice its depth is held at its clamped face more stiffly than the
  // beam's clamp, and the corner moves a little more than the axis.
  const double E = 7000.0, G = E / 2.4, a = 0.25, L = 0.5, A = a * a, I = a * a * a * a / 12.0;
  const double q = 10000.0 * 0.05 * A;
  const double timoshenko = q * std::pow(L, 4) / (8 * E * I) + q * L * L / (2 * 5.0 / 6.0 * G * A);
  EXPECT_NEAR(f.at("static.extrapolated_max_displacement") / timoshenko, 1.0, 0.1);
  // The paper's grid against the converged shape, on its boundary.
  EXPECT_GT(f.at("reference.static_E_n_to_converged"), 0.1);
  EXPECT_NE(benchmark_report(r).find("static shape, largest displacement by grid: x1 "),
            std::string::npos);
}

// The fiber model is fitted to the finest grid's static shape when there is
// one, and measured against both. (Central fibers: the vector spring cannot
// bend, and its fits to either shape stop at Y's lower bound.)
TEST(Benchmark, TheRodsFiberModelIsFittedToTheConvergedShape) {
  nlohmann::json d = small_rod();
  d["fiber_model"] = {{"fit", true}, {"steps", 2}, {"kinematics", "central"}, {"horizon", 0.3}};
  const BenchmarkResult own = run_benchmark(parse(d).benchmark());
  d["static_reference"] = {{"levels", 2}};
  const BenchmarkResult converged = run_benchmark(parse(d).benchmark());
  ASSERT_TRUE(own.ok && converged.ok && own.fiber && converged.fiber);
  EXPECT_EQ(own.fiber->target, "this mesh");
  EXPECT_EQ(converged.fiber->target, "cells x 4");
  EXPECT_EQ(own.figures.count("fiber-model.static_E_n_this_mesh"), 0u);
  // Fitted to the softer converged shape: a softer Y, closer to its own
  // target than to the locked grid's.
  EXPECT_LT(converged.fiber->Y, own.fiber->Y);
  EXPECT_LT(converged.figures.at("fiber-model.static_E_n"),
            converged.figures.at("fiber-model.static_E_n_this_mesh"));
}

// The paper's vector spring cannot bend (its best fit drives Y to its lower
// bound); central fibers within a horizon, with the clamp's mirror layer, can:
// fitted to the same static shape, they come several times closer.
TEST(Benchmark, TheRodsCentralFibersBendWhereTheVectorSpringCannot) {
  nlohmann::json d = small_rod();
  d["fiber_model"] = {{"fit", true}, {"steps", 2}, {"scheme", "newton"}};
  const BenchmarkResult vector = run_benchmark(parse(d).benchmark());
  d["fiber_model"] = {{"fit", true}, {"steps", 2}, {"kinematics", "central"}, {"horizon", 0.3}};
  const BenchmarkResult central = run_benchmark(parse(d).benchmark());
  ASSERT_TRUE(vector.ok && central.ok && vector.fiber && central.fiber) << central.message;
  ASSERT_TRUE(central.series.back().ok) << central.series.back().message;
  EXPECT_LT(central.figures.at("fiber-model.static_E_n"),
            0.5 * vector.figures.at("fiber-model.static_E_n"));
  EXPECT_GT(central.fiber->Y, 0.01 * 7000.0);  // a modulus, not a bound

  nlohmann::json bad = small_rod();
  bad["fiber_model"] = {{"kinematics", "central"}, {"scheme", "incremental"}};
  expect_error(bad, "fiber_model.scheme: central fibers run with the Newton scheme only");
  bad["fiber_model"] = {{"horizon", 0.3}};
  expect_error(bad, "fiber_model.horizon: only central fibers");
  bad["fiber_model"] = {{"kinematics", "central"}, {"mirror_layer", true}};
  expect_error(bad, "fiber_model.mirror_layer: a mirror layer is as deep");
}

// Each series has one row per time step, is measured against the reference
// at the same steps, and the figures read off the series.
TEST(Benchmark, SeriesFollowTheReferenceStepByStep) {
  const Experiment ex = parse(small_block());
  ASSERT_EQ(ex.kind(), Experiment::Kind::Benchmark);
  const BenchmarkResult r = run_benchmark(ex.benchmark());
  ASSERT_TRUE(r.ok) << r.message;
  ASSERT_EQ(r.series.size(), 2u);
  for (const MetricSeries& s : r.series) {
    EXPECT_TRUE(s.ok) << s.message;
    ASSERT_EQ(s.times.size(), 90u);  // 3 s of 1/30 s
    EXPECT_NEAR(s.times.back(), 3.0, 1e-12);
    EXPECT_EQ(s.interior_weights, "volume");
    EXPECT_NEAR(r.figures.at(s.label + ".E_n.final"), s.energy_norm.back(), 0.0);
    EXPECT_NEAR(r.figures.at(s.label + ".E_n.at_1s"), s.energy_norm[29], 0.0);
  }
  // Quasi-static is the static state under the needle's position at each time.
  EXPECT_EQ(r.figures.at("quasi-static.static_gap"), 0.0);
  EXPECT_GT(r.figures.at("quasi-static.E_n.mean_to_2s"),
            3.0 * r.figures.at("explicit.E_n.mean_to_2s"));
  const std::string csv = benchmark_csv(r);
  EXPECT_EQ(std::count(csv.begin(), csv.end(), '\n'), 1 + 2 * 90);
  EXPECT_EQ(csv.substr(0, csv.find('\n')), "time_s,series,E_n,E_s,E_i");
}

// The paper's Gauss-Seidel gives the factorisation's series, and says what
// it cost; triangles give the quadrilaterals' answer up to discretisation.
TEST(Benchmark, GaussSeidelAndTrianglesAgreeWithTheDefaults) {
  nlohmann::json d = small_block();
  const BenchmarkResult direct = run_benchmark(parse(d).benchmark());
  d["linear_solver"] = {{"method", "gauss-seidel"}, {"tolerance", 1e-12}};
  const BenchmarkResult swept = run_benchmark(parse(d).benchmark());
  ASSERT_TRUE(direct.ok && swept.ok);
  EXPECT_GT(swept.reference_sweeps, 90);
  EXPECT_EQ(direct.reference_sweeps, 0);
  for (const char* figure :
       {"explicit.E_n.at_2s", "quasi-static.E_i.final", "quasi-static.E_s.at_1s"})
    EXPECT_NEAR(swept.figures.at(figure), direct.figures.at(figure),
                1e-6 * direct.figures.at(figure))
        << figure;
  d.erase("linear_solver");
  d["mesh"]["elements"] = "triangle";
  const BenchmarkResult triangles = run_benchmark(parse(d).benchmark());
  ASSERT_TRUE(triangles.ok);
  EXPECT_EQ(triangles.scene.mesh.elements.cols(), 3);
  const double a = direct.figures.at("quasi-static.E_n.at_1s"),
               b = triangles.figures.at("quasi-static.E_n.at_1s");
  EXPECT_NEAR(b / a, 1.0, 0.2);  // the same physics on another mesh of the same nodes
}

// The fiber model on the block's boundary: given Y and gamma, its series is
// the quasi-static state at each time (so constant once the needle stops),
// measured over the boundary nodes with the |S_i| weights.
TEST(Benchmark, TheFiberModelRunsOnTheScenesBoundary) {
  nlohmann::json d = small_block();
  d["fiber_model"] = {{"Y", 200}, {"gamma", 5}};
  const BenchmarkResult r = run_benchmark(parse(d).benchmark());
  ASSERT_TRUE(r.ok);
  const MetricSeries& fiber = r.series.back();
  ASSERT_EQ(fiber.label, "fiber-model");
  ASSERT_TRUE(fiber.ok) << fiber.message;
  EXPECT_EQ(fiber.interior_weights, "surface");
  ASSERT_EQ(fiber.times.size(), 90u);
  EXPECT_EQ(r.fiber->vertices, 16);  // the boundary of 5 x 5 nodes
  EXPECT_EQ(r.fiber->how, "given");
  // After the push (2 s) the fiber model stands still; the reference is
  // still moving, so the error changes.
  EXPECT_NE(fiber.energy_norm[70], fiber.energy_norm[80]);
  // Its final state, checked independently: the needle vertex moved 16 cm
  // left, and E_s against the reference's final boundary is as reported.
  const geom::Surface& final_surface = r.fiber_final;
  double needle_x = 1.0;
  for (int v = 0; v < final_surface.num_vertices(); ++v)
    if (std::abs(r.scene.mesh.nodes(r.scene.needle, 1) - 0.5) < 1e-12 &&
        (final_surface.V.row(v) - Eigen::RowVector2d(0.84, 0.5)).norm() < 1e-9)
      needle_x = final_surface.V(v, 0);
  EXPECT_NEAR(needle_x, 0.84, 1e-9);
  EXPECT_NEAR(metrics::surface_error(r.reference_final, final_surface), fiber.surface.back(),
              1e-12);
}

// The fiber model fitted to the block's static shape beats the neighbouring
// gammas and gamma = 0.
TEST(Benchmark, TheFittedFiberModelIsTheClosest) {
  nlohmann::json d = small_block();
  d["mesh"]["cells"] = {8, 8};  // on 4 x 4 cells gamma does not change the static shape
  d["solvers"] = {"quasi-static"};
  d["fiber_model"] = {{"fit", true}};
  const BenchmarkResult fitted = run_benchmark(parse(d).benchmark());
  ASSERT_TRUE(fitted.ok && fitted.fiber);
  const double gamma = fitted.fiber->gamma, best = fitted.figures.at("fiber-model.static_E_n");
  const double Y = fitted.fiber->Y;
  EXPECT_EQ(Y, 200.0);  // E: only gamma / Y matters to a displacement-driven shape
  ASSERT_GT(gamma, 0.0);
  for (double other : {0.0, 0.7 * gamma, 1.4 * gamma}) {
    d["fiber_model"] = {{"Y", fitted.fiber->Y}, {"gamma", other}};
    const BenchmarkResult r = run_benchmark(parse(d).benchmark());
    EXPECT_GT(r.figures.at("fiber-model.static_E_n"), best) << "gamma " << other;
  }
}

// `fiberfluid run` writes the tables and the final boundaries; a benchmark
// whose reference fails leaves no result folder, only DIR.failed.
TEST(Benchmark, WritesItsFiles) {
  ScratchDir dir;
  Experiment ex = parse(small_block());
  OutputWriter writer(ex, dir.path() / "out");
  writer.begin();
  const ExperimentResult result = run_experiment(ex);
  writer.finish(result);
  ASSERT_TRUE(result.runs_succeeded());
  const auto folder = dir.path() / "out";
  for (const char* file : {"metrics.csv", "benchmark.json", "summary.json", "reference_final.obj"})
    EXPECT_TRUE(std::filesystem::exists(folder / file)) << file;
  const nlohmann::json info = nlohmann::json::parse(std::ifstream(folder / "benchmark.json"));
  EXPECT_EQ(info["scene"], "block-needle");
  EXPECT_EQ(info["mesh"]["nodes"], 25);
  EXPECT_EQ(info["series"].size(), 2u);
  const nlohmann::json summary = nlohmann::json::parse(std::ifstream(folder / "summary.json"));
  EXPECT_EQ(summary["kind"], "benchmark");
  EXPECT_TRUE(summary["figures"].contains("explicit.E_s.final"));
  const geom::Surface boundary = geom::read_surface(folder / "reference_final.obj").surface;
  EXPECT_EQ(boundary.num_vertices(), 16);

  nlohmann::json starved = small_block();  // the reference cannot converge in 1 sweep
  starved["linear_solver"] = {{"method", "gauss-seidel"}, {"max_sweeps", 1}};
  Experiment bad = parse(starved);
  OutputWriter bad_writer(bad, dir.path() / "bad");
  bad_writer.begin();
  const ExperimentResult failed = run_experiment(bad);
  bad_writer.finish(failed);
  EXPECT_FALSE(failed.runs_succeeded());
  EXPECT_NE(failed.failure.find("Gauss-Seidel did not converge"), std::string::npos)
      << failed.failure;
  EXPECT_FALSE(std::filesystem::exists(dir.path() / "bad"));
  EXPECT_TRUE(std::filesystem::exists(dir.path() / "bad.failed" / "FAILED"));
}

}  // namespace
}  // namespace fiberfluid::experiment

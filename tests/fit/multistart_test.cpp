// SPDX-License-Identifier: GPL-3.0-or-later
// The multi-start search's parts: its starts, its clustering of optima, its
// options, and a fit's result as bytes. (A whole search over MPI ranks is
// tests/mpi's; a whole search here, on a small body, too.)
#include "fiberfluid/fit/multistart.hpp"

#include <gtest/gtest.h>

#include <cmath>

#include "fit/fit_fixtures.hpp"
#include "model/model_fixtures.hpp"

#include "fiberfluid/fit/fit_archive.hpp"
#include "fiberfluid/geom/generators.hpp"
#include "fiberfluid/model/assembly.hpp"
#include "fiberfluid/model/boundary_conditions.hpp"
#include "fiberfluid/util/error.hpp"

namespace fiberfluid::fit {
namespace {

model::Material material() {
  model::Material m;
  m.law = model::FiberLaw::exponential(3000.0, 2.0);
  m.surface_tension = 50.0;
  return m;
}

ParameterMap map_of(std::vector<Parameter> parameters) {
  return ParameterMap(std::move(parameters), material(), 3);
}

// The radical inverses of 1, 2, 3, ... in bases 2 and 3, by hand.
TEST(Multistart, HaltonPointsAreTheRadicalInverses) {
  const Eigen::MatrixXd p = halton_points(4, Eigen::Vector2d(0.0, 0.0), Eigen::Vector2d(1.0, 1.0));
  const double base2[] = {0.5, 0.25, 0.75, 0.125}, base3[] = {1.0 / 3, 2.0 / 3, 1.0 / 9, 4.0 / 9};
  for (int i = 0; i < 4; ++i) {
    EXPECT_DOUBLE_EQ(p(i, 0), base2[i]) << i;
    EXPECT_DOUBLE_EQ(p(i, 1), base3[i]) << i;
  }
  // Mapped onto a box, and spread: in each half of each axis about half the points.
  const Eigen::MatrixXd q =
      halton_points(64, Eigen::Vector3d(-1.0, 10.0, 0.0), Eigen::Vector3d(1.0, 20.0, 5.0));
  for (int k = 0; k < 3; ++k) {
    const double middle = 0.5 * (q.col(k).minCoeff() + q.col(k).maxCoeff());
    const auto below = (q.col(k).array() < middle).count();
    EXPECT_NEAR(static_cast<double>(below), 32.0, 3.0) << k;
  }
  EXPECT_GE(q.minCoeff(), -1.0);
  EXPECT_LE(q.col(1).maxCoeff(), 20.0);
}

// The first start is the parameters' own; the others lie within the bounds,
// evenly in log for a log-scaled parameter (a decade each: the median of
// 1..1000 is near 31.6, not 500).
TEST(Multistart, StartsSpreadOverTheBoundsInTheFittedVariables) {
  const ParameterMap map =
      map_of({{"Y0", 10.0, 1.0, 1000.0, true}, {"beta", 1.0, 0.0, 4.0, false}});
  const Eigen::MatrixXd starts = spread_starts(map, 101);
  ASSERT_EQ(starts.rows(), 101);
  EXPECT_EQ(starts.row(0).transpose(), map.initial_phi());
  std::vector<double> moduli;
  for (int s = 1; s < 101; ++s) {
    const Eigen::VectorXd v = map.values(starts.row(s).transpose());
    EXPECT_GT(v[0], 1.0);
    EXPECT_LT(v[0], 1000.0);
    EXPECT_GT(v[1], 0.0);
    EXPECT_LT(v[1], 4.0);
    moduli.push_back(v[0]);
  }
  std::nth_element(moduli.begin(), moduli.begin() + 50, moduli.end());
  EXPECT_NEAR(std::log10(moduli[50]), 1.5, 0.05);
}

TEST(Multistart, AParameterWithoutBothBoundsIsNamed) {
  const ParameterMap map =
      map_of({{"Y0", 10.0, 1.0, 1000.0, true}, {"beta", 1.0, 0.0, INFINITY, false}});
  try {
    spread_starts(map, 4);
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("\"beta\""), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("upper"), std::string::npos) << e.what();
  }
}

TEST(Multistart, OptionsAreChecked) {
  EXPECT_NO_THROW(check_options(MultistartOptions{}));
  EXPECT_THROW(check_options(MultistartOptions{1, 1e-3}), InputError);
  EXPECT_THROW(check_options(MultistartOptions{8, 0.0}), InputError);
  EXPECT_THROW(check_options(MultistartOptions{8, 1.0}), InputError);
  EXPECT_THROW(check_options(MultistartOptions{8, NAN}), InputError);
}

StartOutcome ended(FitStatus status, double Y0, double beta, double cost) {
  StartOutcome o;
  o.fit.status = status;
  o.fit.values = Eigen::Vector2d(Y0, beta);
  o.fit.final_cost = cost;
  return o;
}

// Ends that agree to a thousandth of each variable's range are one optimum
// (Y0's range is 3 decades in log: 0.1% of it is 0.7% of Y0); the cheapest
// first, listing its starts cheapest first; fits that did not converge are
// no optima.
TEST(Multistart, ConvergedEndsAreClusteredCheapestFirst) {
  const ParameterMap map =
      map_of({{"Y0", 10.0, 1.0, 1000.0, true}, {"beta", 1.0, 0.0, 4.0, false}});
  const std::vector<StartOutcome> starts = {
      ended(FitStatus::Converged, 100.0, 2.0, 0.5),           // A
      ended(FitStatus::Converged, 50.0, 1.0, 0.2),            // B, the best
      ended(FitStatus::Converged, 100.5, 2.003, 0.49),        // A again, its cheapest
      ended(FitStatus::IterationLimit, 50.0, 1.0, 0.1),       // not converged: not counted
      ended(FitStatus::ConvergedAtBounds, 1000.0, 4.0, 0.9),  // C, on its bounds
      ended(FitStatus::Converged, 108.0, 2.0, 0.5),           // 8% from A in Y0: apart
  };
  const std::vector<Optimum> optima = cluster_optima(starts, map, 1e-3);
  ASSERT_EQ(optima.size(), 4u);
  EXPECT_EQ(optima[0].starts, std::vector<int>{1});
  EXPECT_EQ(optima[0].cost, 0.2);
  EXPECT_EQ(optima[1].starts, (std::vector<int>{2, 0}));
  EXPECT_EQ(optima[1].values[0], 100.5);
  EXPECT_EQ(optima[2].starts, std::vector<int>{5});
  EXPECT_EQ(optima[3].starts, std::vector<int>{4});
  // A coarser tolerance joins A and its 8% neighbour.
  EXPECT_EQ(cluster_optima(starts, map, 0.02).size(), 3u);
}

// A whole search on a small body whose truth is known: every start spread
// over the bounds ends at the truth; the result is the best start's fit,
// and a result survives being packed.
TEST(Multistart, ASmallSearchFindsTheTruthFromEveryStart) {
  const model::Model m = testing::hanging_sphere();
  const solve::SteppingOptions stepping = testing::newton(2);
  const solve::SteppingSummary truth = solve::solve_load_steps(m, stepping);
  ASSERT_TRUE(truth.success) << truth.message;
  const Target target = make_target("truth", model::positions(m, truth.unknowns), m.surface.F);
  fit::Parameter Y0 = testing::parameter("Y0", 1000.0);
  Y0.lower = 300.0;
  Y0.upper = 30000.0;
  const Calibration calibration(m, stepping, {{target, 2}}, {Y0});
  const MultistartResult search = run_multistart(calibration, {4, 1e-3});
  ASSERT_EQ(search.starts.size(), 4u);
  EXPECT_DOUBLE_EQ(search.starts[0].start[0], 1000.0);
  ASSERT_EQ(search.optima.size(), 1u);
  EXPECT_EQ(search.optima[0].starts.size(), 4u);
  EXPECT_FALSE(search.best_found_once);
  for (const StartOutcome& s : search.starts) {
    EXPECT_EQ(s.fit.status, FitStatus::Converged) << s.fit.message;
    EXPECT_NEAR(s.fit.values[0], 3000.0, 3e-3) << s.start[0];
  }
  const FitResult& best = search.best();
  EXPECT_EQ(best.values, search.starts[static_cast<size_t>(search.best_start)].fit.values);
  const FitResult back = unpack_fit_result(pack_fit_result(best));
  EXPECT_EQ(pack_fit_result(back), pack_fit_result(best));
  EXPECT_EQ(back.values, best.values);
  EXPECT_EQ(back.summary.unknowns, best.summary.unknowns);
  EXPECT_THROW(unpack_fit_result(pack_fit_result(best) + "!"), std::runtime_error);
}

// What a fit on another rank reports comes back whole: a material test's
// report (its figures and rows) and the parameters the data could not see.
TEST(FitArchive, AnotherKindsReportAndTheUnseenParametersComeBack) {
  FitResult r;
  r.names = {"mu", "gamma"};
  r.unseen = {"gamma"};
  TargetReport report;
  report.kind = "material_test";
  report.label = "Treloar 1944";
  report.figures = {{"rms_relative_misfit", 0.115}, {"points", 40.0}};
  report.columns = {"test", "stretch"};
  report.rows = {{"uniaxial", "1.02"}, {"equibiaxial", "1.1"}};
  r.other_targets = {report};
  const FitResult back = unpack_fit_result(pack_fit_result(r));
  EXPECT_EQ(back.unseen, r.unseen);
  ASSERT_EQ(back.other_targets.size(), 1u);
  EXPECT_EQ(back.other_targets[0].label, "Treloar 1944");
  EXPECT_EQ(back.other_targets[0].figures, report.figures);
  EXPECT_EQ(back.other_targets[0].rows, report.rows);
}

}  // namespace
}  // namespace fiberfluid::fit

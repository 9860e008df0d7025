// SPDX-License-Identifier: GPL-3.0-or-later
// A calibration over several specimens in one process: the shared law and
// each specimen's own gamma recovered from exact data, and the set-ups it
// refuses. (Over MPI ranks: tests/mpi, the two livers.)
#include "fiberfluid/fit/joint_calibration.hpp"

#include <gtest/gtest.h>

#include "fit/fit_fixtures.hpp"
#include "model/model_fixtures.hpp"

#include "fiberfluid/geom/generators.hpp"
#include "fiberfluid/model/assembly.hpp"
#include "fiberfluid/model/boundary_conditions.hpp"
#include "fiberfluid/util/error.hpp"

namespace fiberfluid::fit {
namespace {

using testing::hanging_sphere;
using testing::newton;
using testing::parameter;

// Its deformed surface after the last of `steps` steps, as its target.
std::vector<MeasuredStep> own_surface(const model::Model& m, int steps) {
  const solve::SteppingSummary s = solve::solve_load_steps(m, newton(steps));
  EXPECT_TRUE(s.success) << s.message;
  return {{make_target("truth", model::positions(m, s.unknowns), m.surface.F), steps}};
}

// Started away from the truth: Y0 and beta shared, gamma each specimen's own.
std::vector<Parameter> started(double gamma) {
  return {parameter("Y0", 1500.0), parameter("beta", 3.0, false), parameter("gamma", gamma)};
}

TEST(JointCalibration, RecoversTheSharedLawAndEachSpecimensOwnGamma) {
  const model::Model a = hanging_sphere(1.0, 10.0, 300.0), b = hanging_sphere(1.2, 6.0, 150.0);
  model::Model a_start = a, b_start = b;
  const Calibration ca(a_start, newton(2), own_surface(a, 2), started(400.0));
  const Calibration cb(b_start, newton(2), own_surface(b, 2), started(100.0));
  const JointCalibration joint({"a", "b"}, {&ca, &cb}, {"Y0", "beta"});
  EXPECT_EQ(joint.names(), (std::vector<std::string>{"Y0", "beta", "a.gamma", "b.gamma"}));
  EXPECT_EQ(joint.num_residuals(), ca.num_residuals() + cb.num_residuals());
  // Specimen b's variables in its own order: the shared two, then its gamma (joint index 3).
  EXPECT_EQ(joint.joint_index(1, 2), 3);
  EXPECT_EQ(joint.specimen_phi(1, Eigen::Vector4d(1, 2, 3, 4)), Eigen::Vector3d(1, 2, 4));

  const JointFitResult r = joint.run({}, {});
  ASSERT_EQ(r.status, FitStatus::Converged) << r.message << " " << r.status_detail;
  EXPECT_EQ(r.shared, 2);
  const Eigen::Vector4d truth(3000.0, 5.0, 300.0, 150.0);
  for (int k = 0; k < 4; ++k) EXPECT_NEAR(r.values[k], truth[k], 1e-5 * truth[k]) << r.names[k];
  EXPECT_LT(r.final_cost, 1e-20);
  EXPECT_LT(r.final_cost, 1e-12 * r.initial_cost);
  ASSERT_EQ(r.specimens.size(), 2u);
  for (const FitResult& s : r.specimens) {
    EXPECT_EQ(s.values.size(), 3);  // its own parameters, at the joint optimum
    EXPECT_NEAR(s.values[0], 3000.0, 0.03);
    EXPECT_LT(s.overall.largest, 1e-8);
    EXPECT_TRUE(s.summary.success);
  }
  EXPECT_NEAR(r.specimens[1].values[2], 150.0, 1.5e-3);
  EXPECT_GT(r.evaluations, 2);
  EXPECT_FALSE(r.iterations.empty());
}

// Every set-up it cannot fit is named: a shared parameter a specimen does not
// fit, a shared one with other bounds, a robust loss, one specimen alone.
TEST(JointCalibration, RefusesWhatItCannotFit) {
  const model::Model a = hanging_sphere(1.0, 10.0, 300.0);
  const std::vector<MeasuredStep> targets = own_surface(a, 2);
  const Calibration with_gamma(a, newton(2), targets, started(400.0));
  const Calibration without_beta(a, newton(2), targets,
                                 {parameter("Y0", 1500.0), parameter("gamma", 400.0)});
  std::vector<Parameter> bounded = started(400.0);
  bounded[0].lower = 100.0;
  const Calibration other_bounds(a, newton(2), targets, bounded);
  FitOptions huber;
  huber.loss = Loss::Huber;
  const Calibration robust(a, newton(2), targets, started(400.0), huber);
  const auto expect_refused = [](const std::function<void()>& make, const std::string& part) {
    try {
      make();
      ADD_FAILURE() << "no error, expected one mentioning '" << part << "'";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(part), std::string::npos) << e.what();
    }
  };
  expect_refused(
      [&] {
        JointCalibration({"a", "b"}, {&with_gamma, &without_beta}, {"beta"});
      },
      "specimen \"b\" does not fit \"beta\"");
  expect_refused(
      [&] {
        JointCalibration({"a", "b"}, {&with_gamma, &other_bounds}, {"Y0"});
      },
      "the shared \"Y0\" has other bounds");
  expect_refused(
      [&] {
        JointCalibration({"a", "b"}, {&with_gamma, &robust}, {"Y0"});
      },
      "specimen \"b\": a calibration over specimens fits squared distances");
  expect_refused([&] { JointCalibration({"a"}, {&with_gamma}, {"Y0"}); }, "two or more");
  expect_refused(
      [&] {
        JointCalibration({"a", "a"}, {&with_gamma, &with_gamma}, {"Y0"});
      },
      "the same name");
}

}  // namespace
}  // namespace fiberfluid::fit

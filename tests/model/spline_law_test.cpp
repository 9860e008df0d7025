// SPDX-License-Identifier: GPL-3.0-or-later
// The data-driven fiber law: a monotone quadratic spline of tension against
// stretch (spline_law.cpp).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <random>
#include <string>
#include <vector>

#include "fiberfluid/fit/material_fit.hpp"
#include "fiberfluid/material/hyperelastic_law.hpp"
#include "fiberfluid/material/material_test.hpp"
#include "fiberfluid/model/fiber_law.hpp"
#include "fiberfluid/model/material_response.hpp"
#include "model_fixtures.hpp"

namespace fiberfluid::model {
namespace {

using material::HomogeneousTest;

const std::vector<double> kKnots = {0.4, 0.7, 1.0, 1.5, 2.5, 4.0, 6.0, 8.0};

// A spline whose tension is 0.6 mu l is the neo-Hookean network: the same
// moduli, rest tension and material-level stresses to rounding.
TEST(SplineLaw, AStraightLineOfTensionIsTheNeoHookeanNetwork) {
  const double mu = 4e5;
  const FiberLaw spline = testing::spline_of_line(kKnots, 0.6 * mu, 0.0);
  const FiberLaw neo = FiberLaw::neo_hookean(mu);
  ASSERT_TRUE(spline.check().ok) << spline.check().message;
  EXPECT_DOUBLE_EQ(spline.rest_tension(), neo.rest_tension());
  for (double e : {-0.75, -0.5, -0.1, -3e-5, 0.0, 2e-5, 0.3, 0.5, 3.0, 9.0}) {
    EXPECT_NEAR(spline.modulus(e), neo.modulus(e), 1e-10 * neo.modulus(e)) << e;
    EXPECT_NEAR(spline.slope(e), 0.0, 1e-9 * neo.modulus(e)) << e;
  }
  for (HomogeneousTest test :
       {HomogeneousTest::Uniaxial, HomogeneousTest::Equibiaxial, HomogeneousTest::PureShear})
    for (double l : {0.7, 1.3, 2.0, 5.0}) {
      const double closed =
          material::nominal_stress(material::HyperelasticLaw::named("neo_hookean", mu), test, l);
      EXPECT_NEAR(fiber_network_nominal_stress(spline, test, l), closed, 1e-9 * std::abs(closed))
          << material::to_string(test) << " " << l;
    }
}

// A law of uneven rises: slope and parameter derivatives against central
// differences, on and between knots, near rest and beyond the ends.
TEST(SplineLaw, DerivativesAreTheCentralDifferences) {
  const FiberLaw law = FiberLaw::spline(kKnots, 3e4, {1e3, 2e4, 5e4, 1e5, 4e4, 2e5, 5e5, 1e6});
  ASSERT_TRUE(law.check().ok) << law.check().message;
  const double h = 1e-6;
  for (double e : {-0.8, -0.45, -0.2, -1e-3, -5e-5, 5e-5, 2e-4, 0.25, 0.8, 1.9, 4.4, 6.5, 10.0}) {
    const double fd = (law.modulus(e + h) - law.modulus(e - h)) / (2 * h);
    EXPECT_NEAR(law.slope(e), fd, 1e-5 * law.modulus(e)) << e;
    for (int k = 0; k < static_cast<int>(law.parameters().size()); ++k) {
      FiberLaw up = law, down = law;
      const std::string& name = law.parameter_names()[static_cast<size_t>(k)];
      const double dp = 1e-4 * std::max(1.0, law.parameter(name));
      up.set_parameter(name, law.parameter(name) + dp);
      down.set_parameter(name, law.parameter(name) - dp);
      const double fd_p = (up.modulus(e) - down.modulus(e)) / (2 * dp);
      EXPECT_NEAR(law.modulus_derivative(k, e), fd_p, 1e-7 * (1.0 + std::abs(fd_p)))
          << name << " at " << e;
    }
  }
  EXPECT_EQ(law.rest_tension_derivative(0), 1.0);
  EXPECT_EQ(law.rest_tension_derivative(3), 0.0);
  // The block evaluation is the pointwise one.
  const std::vector<double> strains = {-0.5, 0.0, 0.1, 3.0};
  std::vector<double> Y(strains.size()), Yp(strains.size());
  law.evaluate(strains.data(), strains.size(), Y.data(), Yp.data());
  for (size_t k = 0; k < strains.size(); ++k) {
    EXPECT_DOUBLE_EQ(Y[k], law.modulus(strains[k]));
    EXPECT_DOUBLE_EQ(Yp[k], law.slope(strains[k]));
  }
}

// A network's small-strain Young's modulus is T'(1) + 4 T(1): the slope of
// its uniaxial nominal stress at rest (a constant law's Y; the neo-Hookean
// network's 0.6 mu + 4 x 0.6 mu = 3 mu).
TEST(SplineLaw, SmallStrainModulusIsTheSlopePlusFourTimesTheRestTension) {
  for (double T1 : {0.0, 2e4, 1e5}) {
    const FiberLaw law = FiberLaw::spline(kKnots, T1, {1e3, 2e4, 5e4, 1e5, 4e4, 2e5, 5e5, 1e6});
    const double h = 1e-6;
    const double slope_at_rest = law.modulus(0.0);  // T'(1)
    const double E = fiber_network_nominal_stress(law, HomogeneousTest::Uniaxial, 1.0 + h) / h;
    EXPECT_NEAR(E, slope_at_rest + 4.0 * T1, 1e-4 * E) << T1;
  }
}

// Rises >= 0 make a tension that never falls, whatever their values: the
// property a fit keeps by keeping them positive.
TEST(SplineLaw, NonNegativeRisesNeverLetTheTensionFall) {
  std::mt19937 random(7);
  std::uniform_real_distribution<double> rise(0.0, 1e5);
  for (int trial = 0; trial < 50; ++trial) {
    std::vector<double> rises(kKnots.size());
    for (double& r : rises) r = trial % 5 == 0 ? 0.0 : rise(random);
    rises[static_cast<size_t>(trial) % rises.size()] = 0.0;
    rises[2] += 1.0;  // a tension that rises through rest: a positive modulus
    const FiberLaw law = FiberLaw::spline(kKnots, 1e3, rises);
    double previous = -1e300;
    for (double l = 0.05; l < 10.0; l += 0.01) {
      const double e = l - 1.0;
      const double T = law.rest_tension() + law.modulus(e) * e;
      EXPECT_GE(T, previous - 1e-9 * std::abs(T)) << "trial " << trial << " at l " << l;
      previous = T;
    }
  }
}

TEST(SplineLaw, RefusesKnotsAndRisesThatMakeNoLawNamingThem) {
  const std::vector<double> rises(3, 1e4);
  EXPECT_THROW(FiberLaw::spline({1.5}, 0.0, {1e4}), std::invalid_argument);
  EXPECT_THROW(FiberLaw::spline({0.5, 1.5, 2.0}, 0.0, {1e4, 1e4}), std::invalid_argument);
  const auto refusal = [](const FiberLaw& law) { return law.check().message; };
  EXPECT_NE(refusal(FiberLaw::spline({0.5, 2.0, 1.5}, 0.0, rises)).find("strictly increasing"),
            std::string::npos);
  EXPECT_NE(refusal(FiberLaw::spline({1.2, 1.5, 2.0}, 0.0, rises)).find("span the rest"),
            std::string::npos);
  EXPECT_NE(refusal(FiberLaw::spline({0.5, 1.5, 2.0}, 0.0, {1e4, -1.0, 1e4})).find("rise2"),
            std::string::npos);
  EXPECT_NE(refusal(FiberLaw::spline({0.5, 1.5, 2.0}, -5.0, rises)).find("T1"), std::string::npos);
  // Flat through rest with no tension there: the network has no stiffness.
  EXPECT_NE(refusal(FiberLaw::spline({0.5, 1.5, 2.0}, 0.0, {0.0, 0.0, 1e4})).find("no stiffness"),
            std::string::npos);
  // Flat through rest in tension is a material: its tension stiffens it.
  EXPECT_TRUE(FiberLaw::spline({0.5, 1.5, 2.0}, 1e3, {0.0, 0.0, 1e4}).check().ok);
}

// Treloar's uniaxial and equibiaxial tests fitted together at material level
// by the spline's network, from the neo-Hookean network's line: 11.5% rms
// (uniaxial 9.1%, equibiaxial 14.3%) where the neo-Hookean network is at
// 23.6% (11.5% too on a second layout of 9 knots). The fit makes the tension
// flat from l = 0.6 to 1.6 (three rises on their bound 0) and the shortened
// fibers very stiff, and still misses the rubber's Mooney-type softening: a
// network of fibers each following its own stretch (an affine network) has
// no more to give, and Miehe, Goektepe and Lulei (JMPS 52 (2004) 2617) add a
// non-affine stretch and a tube (area) part to the microsphere for it.
TEST(SplineLaw, TreloarsRubberFittedByItsNetwork) {
  const std::vector<material::TestPoint> points =
      material::read_material_test(std::string(FIBERFLUID_MEASUREMENTS) +
                                   "/treloar_rubber/treloar1944_uniaxial_equibiaxial.csv");
  const std::vector<double> knots = {0.2, 0.6, 1.0, 1.6, 2.5, 4.0, 6.0, 8.0};
  const double mu = 4e5;
  const FiberLaw start = testing::spline_of_line(knots, 0.6 * mu, 0.0);
  fit::FitOptions options;
  options.max_iterations = 300;
  const fit::MaterialFitResult fitted =
      fit::fit_material_test(fit::material_model(start), points, options);
  ASSERT_TRUE(fit::converged(fitted.status)) << fitted.message;
  std::printf(
      "Treloar at material level: the spline network rms %.1f%% (from the neo-Hookean "
      "network's %.1f%%), %zu iterations; T1 and rises (Pa):",
      100 * fitted.rms, 100 * fitted.initial_rms, fitted.iterations.size());
  for (double p : fitted.parameters) std::printf(" %.4g", p);
  std::printf("\n");
  // The start is the neo-Hookean network, whose closed-form fit is 23.6%.
  EXPECT_NEAR(fitted.initial_rms, 0.236, 0.01);
  EXPECT_LT(fitted.rms, 0.55 * fitted.initial_rms);
  EXPECT_GT(fitted.rms, 0.10);  // the affine network's floor, documented in docs/materials.md
  for (double p : fitted.parameters) EXPECT_GE(p, 0.0);
  // The rubber's small-strain shear modulus, about 0.4 MPa (Treloar): E / 3
  // with E = T'(1) + 4 T(1) (a network's small-strain Young's modulus).
  const FiberLaw law = [&] {
    FiberLaw l = start;
    for (size_t k = 0; k < l.parameter_names().size(); ++k)
      l.set_parameter(l.parameter_names()[k], fitted.parameters[static_cast<Eigen::Index>(k)]);
    return l;
  }();
  const double h = 1e-6;
  const double shear_modulus =
      fiber_network_nominal_stress(law, HomogeneousTest::Uniaxial, 1.0 + h) / h / 3.0;
  EXPECT_NEAR(shear_modulus, 4e5, 1.5e5);
}

}  // namespace
}  // namespace fiberfluid::model

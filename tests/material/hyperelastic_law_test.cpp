// SPDX-License-Identifier: GPL-3.0-or-later
// Hyperelastic laws at material level: closed forms of the homogeneous
// tests, the stress as the energy's derivative along each test, and
// Treloar's rubber (1944) fitted at material level.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>

#include "fiberfluid/fit/material_fit.hpp"
#include "fiberfluid/material/hyperelastic_law.hpp"
#include "fiberfluid/material/material_test.hpp"
#include "fiberfluid/model/material_response.hpp"
#include "fiberfluid/util/error.hpp"

namespace fiberfluid::material {
namespace {

const HomogeneousTest kTests[] = {HomogeneousTest::Uniaxial, HomogeneousTest::Equibiaxial,
                                  HomogeneousTest::PureShear};

std::string treloar() {
  return std::string(FIBERFLUID_MEASUREMENTS) +
         "/treloar_rubber/treloar1944_uniaxial_equibiaxial.csv";
}

TEST(HyperelasticLaw, NeoHookeanClosedForms) {
  const double mu = 4e5;
  const HyperelasticLaw law = HyperelasticLaw::neo_hookean(mu);
  for (double l : {0.5, 0.9, 1.3, 3.0}) {
    EXPECT_NEAR(nominal_stress(law, HomogeneousTest::Uniaxial, l), mu * (l - std::pow(l, -2)),
                1e-9 * mu);
    EXPECT_NEAR(nominal_stress(law, HomogeneousTest::Equibiaxial, l), mu * (l - std::pow(l, -5)),
                1e-9 * mu);
    EXPECT_NEAR(nominal_stress(law, HomogeneousTest::PureShear, l), mu * (l - std::pow(l, -3)),
                1e-9 * mu);
  }
  EXPECT_EQ(nominal_stress(law, HomogeneousTest::Uniaxial, 1.0), 0.0);
}

// Mooney-Rivlin uniaxial: P = 2 (l - l^-2) (C10 + C01 / l) (Rivlin and
// Saunders 1951's plot of the reduced stress against 1/l is a line).
TEST(HyperelasticLaw, MooneyRivlinUniaxialIsLinearInTheInverseStretch) {
  const double c10 = 1.8e5, c01 = 2.1e4;
  const HyperelasticLaw law = HyperelasticLaw::mooney_rivlin(c10, c01);
  for (double l : {0.6, 1.5, 4.0})
    EXPECT_NEAR(nominal_stress(law, HomogeneousTest::Uniaxial, l),
                2.0 * (l - std::pow(l, -2)) * (c10 + c01 / l), 1e-9 * c10);
  EXPECT_DOUBLE_EQ(law.shear_modulus(), 2.0 * (c10 + c01));
}

// The same material written as each law: neo-Hookean mu, Mooney-Rivlin
// (mu/2, 0), Yeoh (mu/2, 0, 0), one Ogden term (mu, 2).
TEST(HyperelasticLaw, TheLawsAgreeWhereTheyAreTheSameMaterial) {
  const double mu = 2.5e5;
  const HyperelasticLaw laws[] = {HyperelasticLaw::mooney_rivlin(0.5 * mu, 0.0),
                                  HyperelasticLaw::yeoh(0.5 * mu, 0.0, 0.0),
                                  HyperelasticLaw::ogden({{mu, 2.0}})};
  const HyperelasticLaw neo = HyperelasticLaw::neo_hookean(mu);
  for (const HyperelasticLaw& law : laws) {
    EXPECT_DOUBLE_EQ(law.shear_modulus(), mu) << law.name();
    for (HomogeneousTest t : kTests)
      for (double l : {0.7, 1.2, 2.5})
        EXPECT_NEAR(nominal_stress(law, t, l), nominal_stress(neo, t, l), 1e-9 * mu)
            << law.name() << " " << to_string(t) << " " << l;
  }
}

// Along a test the work of the nominal stress is the energy's change: P =
// dW/dl in uniaxial tension and pure shear, 2 P = dW/dl in equibiaxial
// tension (two axes work). Central differences of W for every law.
TEST(HyperelasticLaw, TheStressIsTheEnergysDerivativeAlongEachTest) {
  const HyperelasticLaw laws[] = {
      HyperelasticLaw::neo_hookean(3e5), HyperelasticLaw::mooney_rivlin(1.6e5, 1.4e4),
      HyperelasticLaw::yeoh(1.7e5, -1.2e3, 40.0),
      HyperelasticLaw::ogden({{6.3e5, 1.3}, {1.2e3, 5.0}, {-1.0e4, -2.0}})};
  for (const HyperelasticLaw& law : laws)
    for (HomogeneousTest t : kTests)
      for (double l : {0.6, 1.1, 2.0, 4.0}) {
        const double h = 1e-5 * l;
        const double dW =
            (law.energy(test_stretches(t, l + h)) - law.energy(test_stretches(t, l - h))) /
            (2.0 * h);
        const double works = t == HomogeneousTest::Equibiaxial ? 2.0 : 1.0;
        EXPECT_NEAR(works * nominal_stress(law, t, l), dW, 1e-6 * std::abs(dW) + 1e-3)
            << law.name() << " " << to_string(t) << " " << l;
      }
}

TEST(HyperelasticLaw, RefusesWhatIsNoMaterial) {
  EXPECT_FALSE(HyperelasticLaw::neo_hookean(-1.0).check().ok);
  EXPECT_FALSE(HyperelasticLaw::neo_hookean(NAN).check().ok);
  EXPECT_NE(HyperelasticLaw::ogden({{1e5, 0.0}}).check().message.find("alpha_1"),
            std::string::npos);
  EXPECT_TRUE(HyperelasticLaw::ogden({{6.3e5, 1.3}, {-1e4, -2.0}}).check().ok);
  EXPECT_THROW(HyperelasticLaw::named("arruda", 1e5), InputError);
  EXPECT_THROW(homogeneous_test("biaxial"), InputError);
}

TEST(MaterialTest, ReadsTreloarsRubber) {
  const std::vector<TestPoint> points = read_material_test(treloar());
  int uniaxial = 0, equibiaxial = 0;
  for (const TestPoint& p : points)
    (p.test == HomogeneousTest::Uniaxial ? uniaxial : equibiaxial) += 1;
  EXPECT_EQ(uniaxial, 25);  // Treloar 1944: 25 uniaxial points to stretch 7.6
  EXPECT_EQ(equibiaxial, 17);
  EXPECT_DOUBLE_EQ(points.front().stretch, 1.0);
  EXPECT_GT(points.back().nominal_stress, 1e6);  // MPa read as Pa
}

TEST(MaterialTest, RefusesABadFileNamingTheLine) {
  const std::string path = testing::TempDir() + "/bad_material_test.csv";
  {
    std::ofstream out(path);
    out << "# a comment\ntest,stretch,nominal_stress_kPa\nuniaxial,1.5,200\nbiaxial,2,300\n";
  }
  try {
    read_material_test(path);
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("bad_material_test.csv:4"), std::string::npos) << e.what();
  }
  {
    std::ofstream out(path);
    out << "test,stretch,force_N\nuniaxial,1.5,200\n";
  }
  EXPECT_THROW(read_material_test(path), InputError);
}

// Treloar's uniaxial and equibiaxial tests fitted together at material level
// (relative misfits): one neo-Hookean modulus cannot follow both over the
// range; three Ogden terms do (Ogden 1972; Ogden, Saccomandi and Sgura 2004).
TEST(MaterialFit, TreloarsRubberTakesThreeOgdenTermsNotOneModulus) {
  const std::vector<TestPoint> points = read_material_test(treloar());
  const fit::MaterialFitResult neo = fit::fit_material_test(
      fit::material_model(HyperelasticLaw::named("neo_hookean", 3e5)), points);
  ASSERT_TRUE(fit::converged(neo.status)) << neo.message;
  // Ogden's exponents and moduli trade along a valley: about 200 iterations
  // from the generic start (each a few microseconds).
  fit::FitOptions options;
  options.max_iterations = 500;
  const HyperelasticLaw ogden_start = HyperelasticLaw::named("ogden3", 3e5);
  const fit::MaterialFitResult ogden =
      fit::fit_material_test(fit::material_model(ogden_start), points, options);
  const HyperelasticLaw fitted = ogden_start.with_parameters(ogden.parameters);
  ASSERT_TRUE(fit::converged(ogden.status)) << ogden.message;
  EXPECT_LT(ogden.rms, 0.10) << ogden.parameters.transpose();
  EXPECT_GT(neo.rms, 2.0 * ogden.rms);
  // Rubber's small-strain shear modulus is about 0.4 MPa (Treloar).
  EXPECT_NEAR(fitted.shear_modulus(), 4e5, 1.5e5);
  std::printf(
      "Treloar at material level: neo-Hookean rms %.1f%% (mu %.3g Pa), three-term Ogden "
      "rms %.1f%% (mu %.3g Pa)\n",
      100 * neo.rms, neo.parameters[0], 100 * ogden.rms, fitted.shear_modulus());
}

// A network of central fibers of a constant law Y is, at small strain, an
// incompressible material of Young's modulus Y: the slopes of the nominal
// stress at l = 1 are E, 2E and 4E/3 in uniaxial, equibiaxial and pure-shear
// tension (a neo-Hookean solid's with mu = E/3).
TEST(FiberNetwork, AConstantLawIsAMaterialOfYoungsModulusY) {
  const double Y = 6e4, h = 1e-5;
  const model::FiberLaw law = model::FiberLaw::constant(Y);
  const std::pair<HomogeneousTest, double> slopes[] = {{HomogeneousTest::Uniaxial, 1.0},
                                                       {HomogeneousTest::Equibiaxial, 2.0},
                                                       {HomogeneousTest::PureShear, 4.0 / 3.0}};
  for (const auto& [test, slope] : slopes) {
    const double P = model::fiber_network_nominal_stress(law, test, 1.0 + h);
    EXPECT_NEAR(P / h, slope * Y, 1e-3 * Y) << to_string(test);
    EXPECT_NEAR(model::fiber_network_nominal_stress(law, test, 1.0), 0.0, 1e-9 * Y);
  }
  // Large stretches: for a constant law, W = 5 Y/2 <(l_d - 1)^2> =
  // 5 Y/6 (I1 - 3) - 5 Y (<l_d> - 1). Its derivative along the uniaxial path,
  // the mean <l_d> over a Fibonacci lattice of 200,000 directions (an
  // independent quadrature), is the nominal stress.
  const auto energy = [&](double l) {
    const Eigen::Vector3d s = test_stretches(HomogeneousTest::Uniaxial, l);
    constexpr int kDirections = 200000;
    double mean = 0.0;
    for (int k = 0; k < kDirections; ++k) {
      const double z = 1.0 - (2.0 * k + 1.0) / kDirections, r = std::sqrt(1.0 - z * z);
      const double phi = k * M_PI * (3.0 - std::sqrt(5.0));
      mean += Eigen::Vector3d(s[0] * r * std::cos(phi), s[1] * r * std::sin(phi), s[2] * z).norm();
    }
    mean /= kDirections;
    return 5.0 * Y / 6.0 * (s.squaredNorm() - 3.0) - 5.0 * Y * (mean - 1.0);
  };
  for (double l : {0.6, 2.0, 4.0}) {
    const double dl = 1e-3;
    const double dW = (energy(l + dl) - energy(l - dl)) / (2.0 * dl);
    EXPECT_NEAR(model::fiber_network_nominal_stress(law, HomogeneousTest::Uniaxial, l), dW,
                1e-4 * std::abs(dW))
        << l;
  }
}

// A stiffening fiber law at material level against Treloar's rubber: the
// figure a body of such fibers could reach if it followed its network.
TEST(MaterialFit, AFiberLawsNetworkFittedToTreloarsRubber) {
  const std::vector<TestPoint> points = read_material_test(treloar());
  fit::FitOptions options;
  options.max_iterations = 200;
  const fit::MaterialFitResult exponential = fit::fit_material_test(
      fit::material_model(model::FiberLaw::exponential(1e6, 0.5)), points, options);
  ASSERT_TRUE(fit::converged(exponential.status)) << exponential.message;
  EXPECT_LT(exponential.rms, exponential.initial_rms);
  std::printf(
      "Treloar at material level: the exponential fiber law's network rms %.1f%% "
      "(Y0 %.3g Pa, beta %.3g)\n",
      100 * exponential.rms, exponential.parameters[0], exponential.parameters[1]);
}

}  // namespace
}  // namespace fiberfluid::material

// SPDX-License-Identifier: GPL-3.0-or-later
#include "fiberfluid/model/fiber_law.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include "fiberfluid/model/vector_math.hpp"

namespace fiberfluid::model {
namespace {

TEST(FiberLaw, ValuesOfEachLaw) {
  EXPECT_EQ(FiberLaw::constant(3000.0).modulus(0.37), 3000.0);
  const FiberLaw exp_law = FiberLaw::exponential(2000.0, 5.0);
  EXPECT_DOUBLE_EQ(exp_law.modulus(0.1), 2000.0 * std::exp(0.5));
  EXPECT_DOUBLE_EQ(exp_law.modulus(0.0), 2000.0);
  const FiberLaw bilinear = FiberLaw::bilinear(3000.0, 1000.0);  // blended over |e| < 0.005
  EXPECT_EQ(bilinear.modulus(0.2), 3000.0);
  EXPECT_EQ(bilinear.modulus(0.005), 3000.0);
  EXPECT_EQ(bilinear.modulus(0.0), 2000.0);
  EXPECT_EQ(bilinear.modulus(-0.2), 1000.0);
  EXPECT_DOUBLE_EQ(bilinear.modulus(0.0025), 1000.0 + 2000.0 * (0.5 + 0.375 - 0.25 / 8));
  const FiberLaw sharp = FiberLaw::bilinear(3000.0, 1000.0, 0.0);
  EXPECT_EQ(sharp.modulus(0.0), 3000.0);
  EXPECT_EQ(sharp.modulus(-1e-9), 1000.0);
  // sigma: (-0.2, -200), (0, 0), (0.1, 100), (0.3, 500): secants 1000, 1000, 1000 and
  // at e = 0.2 sigma = 300, Y = 1500; beyond the table the last segment continues.
  const FiberLaw table = FiberLaw::tabulated({-0.2, 0.0, 0.1, 0.3}, {-200.0, 0.0, 100.0, 500.0});
  EXPECT_DOUBLE_EQ(table.modulus(0.0), 1000.0);
  EXPECT_DOUBLE_EQ(table.modulus(-0.1), 1000.0);
  EXPECT_DOUBLE_EQ(table.modulus(0.2), 1500.0);
  EXPECT_DOUBLE_EQ(table.modulus(0.5), 900.0 / 0.5);
  EXPECT_DOUBLE_EQ(table.modulus(-0.5), 1000.0);
}

// The vectorised exponential (vector_math.hpp) against the library's, in
// units in the last place: over the whole range, over the strains a law
// meets, at the ends of the reduction's intervals (k ln2 / 2), and its
// special values.
TEST(FiberLaw, TheVectorExponentialIsWithinTwoUlp) {
  const auto ulps = [](double x) {
    const double exact = std::exp(x), ours = vector_exp(x);
    const double ulp = std::nextafter(exact, std::numeric_limits<double>::infinity()) - exact;
    return std::abs(ours - exact) / ulp;
  };
  std::mt19937_64 rng(7);
  double worst = 0.0;
  for (const double range : {708.0, 20.0, 1.0}) {
    std::uniform_real_distribution<double> x(-range, range);
    for (int k = 0; k < 200000; ++k) worst = std::max(worst, ulps(x(rng)));
  }
  for (int k = -2040; k <= 2040; ++k)
    for (const double nudge : {-1e-15, 0.0, 1e-15})
      worst = std::max(worst, ulps(k * 0.34657359027997264 + nudge));
  for (const double x : {709.0, 709.5, 709.78}) worst = std::max(worst, ulps(x));  // k = 1024
  EXPECT_LE(worst, 2.0);
  EXPECT_EQ(vector_exp(0.0), 1.0);
  EXPECT_TRUE(std::isnan(vector_exp(std::nan(""))));
  EXPECT_EQ(vector_exp(709.8), HUGE_VAL);  // an overflow stays visible
  EXPECT_EQ(vector_exp(1e6), HUGE_VAL);
  EXPECT_EQ(vector_exp(-1e6), 0.0);
}

// A law's block evaluation (the kernels') gives its pointwise values.
TEST(FiberLaw, TheBlockEvaluationGivesThePointwiseValues) {
  const std::vector<FiberLaw> laws = {
      FiberLaw::exponential(2000.0, 5.0),
      FiberLaw::exponential(1500.0, -3.0),
      FiberLaw::bilinear(3000.0, 1000.0),
      FiberLaw::tabulated({-0.2, 0.0, 0.1, 0.3}, {-200.0, 0.0, 100.0, 500.0}),
      FiberLaw::tabulated({-0.5, -0.3, -0.1, 0.0, 0.05, 0.2, 0.4, 0.8},
                          {-400.0, -200.0, -50.0, 0.0, 30.0, 150.0, 400.0, 1200.0}, 0.0),
      FiberLaw::tabulated({0.0, 0.1, 0.25}, {0.0, 80.0, 300.0})};
  std::vector<double> strain;
  for (int k = 0; k <= 400; ++k) strain.push_back(-0.9 + k * 0.007);
  // On the breakpoints (a segment starts there) and on both sides of the blend's ends.
  for (double e : {-0.5, -0.3, -0.2, -0.1, 0.0, 0.05, 0.1, 0.2, 0.25, 0.3, 0.4, 0.8, -0.005, 0.005,
                   std::nextafter(0.005, 0.0), std::nextafter(-0.005, 0.0)})
    strain.push_back(e);
  strain.resize(700, 0.123);  // past one block of 256 values, and a partial one
  for (const FiberLaw& law : laws) {
    SCOPED_TRACE(law.name());
    std::vector<double> Y(strain.size()), Yp(strain.size()), dY(strain.size());
    law.evaluate(strain.data(), strain.size(), Y.data(), Yp.data());
    for (size_t k = 0; k < strain.size(); ++k) {
      EXPECT_NEAR(Y[k], law.modulus(strain[k]), 1e-15 * std::abs(law.modulus(strain[k])));
      EXPECT_NEAR(Yp[k], law.slope(strain[k]), 1e-15 * std::abs(law.slope(strain[k])) + 1e-300);
    }
    for (int p = 0; p < static_cast<int>(law.parameter_names().size()); ++p) {
      law.evaluate_derivative(p, strain.data(), strain.size(), dY.data());
      for (size_t k = 0; k < strain.size(); ++k) {
        const double expected = law.modulus_derivative(p, strain[k]);
        EXPECT_NEAR(dY[k], expected, 1e-15 * std::abs(expected) + 1e-300);
      }
    }
  }
}

// Issue 29: a table 17.5 kPa below zero strain and 20 kPa above. Sharp, its
// modulus jumps at e = 0; by default the two sides are blended over |e| <
// 0.005 (C1, as the bilinear law), Y(0) their mean; outside, the table.
TEST(FiberLaw, ATablesSlopeJumpAtZeroIsSmoothedByDefault) {
  const std::vector<double> strain = {-0.2, 0.0, 0.2}, stress = {-3500.0, 0.0, 4000.0};
  const FiberLaw sharp = FiberLaw::tabulated(strain, stress, 0.0);
  EXPECT_EQ(sharp.modulus(-1e-12), 17500.0);
  EXPECT_EQ(sharp.modulus(0.0), 20000.0);
  const FiberLaw smooth = FiberLaw::tabulated(strain, stress);
  EXPECT_NEAR(smooth.modulus(-1e-12), smooth.modulus(1e-12), 1e-6);
  EXPECT_DOUBLE_EQ(smooth.modulus(0.0), 18750.0);
  EXPECT_DOUBLE_EQ(smooth.modulus(0.005), 20000.0);
  EXPECT_DOUBLE_EQ(smooth.modulus(-0.005), 17500.0);
  EXPECT_DOUBLE_EQ(smooth.modulus(0.1), 20000.0);
  // C1 at the blend's ends: the slope vanishes there from both sides.
  EXPECT_NEAR(smooth.slope(0.005 - 1e-12), 0.0, 1e-3);
  EXPECT_NEAR(smooth.slope(-0.005 + 1e-12), 0.0, 1e-3);
  // The blend is part of the law's settings (written to the outputs).
  const auto settings = smooth.settings();
  ASSERT_EQ(settings.size(), 3u);
  EXPECT_EQ(settings[2].name, "transition");
  EXPECT_EQ(settings[2].values[0], 0.005);
}

TEST(FiberLaw, SlopesAndParameterDerivativesMatchCentralDifferences) {
  const FiberLaw laws[] = {
      FiberLaw::constant(3000.0), FiberLaw::exponential(2000.0, 5.0),
      FiberLaw::bilinear(3000.0, 1000.0),
      FiberLaw::tabulated({-0.2, 0.0, 0.1, 0.3}, {-200.0, 0.0, 100.0, 500.0}),
      FiberLaw::tabulated({-0.2, 0.0, 0.002, 0.3}, {-3500.0, 0.0, 40.0, 6500.0}, 0.005)};
  for (const FiberLaw& law : laws)
    for (double e : {-0.37, -0.05, -0.004, 0.001, 0.03, 0.17, 0.6}) {
      const double h = 1e-6;
      const double fd = (law.modulus(e + h) - law.modulus(e - h)) / (2 * h);
      EXPECT_NEAR(law.slope(e), fd, 1e-6 * (std::abs(law.modulus(e)) + std::abs(fd)) + 1e-9)
          << law.name() << e;
      for (const std::string& name : law.parameter_names()) {
        const double p = law.parameter(name), step = 1e-6 * std::max(1.0, std::abs(p));
        FiberLaw up = law, down = law;
        up.set_parameter(name, p + step);
        down.set_parameter(name, p - step);
        const double dfd = (up.modulus(e) - down.modulus(e)) / (2 * step);
        EXPECT_NEAR(law.modulus_derivative(name, e), dfd, 1e-6 * std::abs(dfd) + 1e-9)
            << law.name() << " " << name << " at " << e;
      }
    }
}

TEST(FiberLaw, NamedParameters) {
  FiberLaw law = FiberLaw::exponential(2000.0, 5.0);
  EXPECT_EQ(law.parameter_names(), (std::vector<std::string>{"Y0", "beta"}));
  law.set_parameter("beta", 2.0);
  EXPECT_EQ(law.parameter("beta"), 2.0);
  EXPECT_THROW(law.parameter("Y_t"), std::invalid_argument);
  EXPECT_THROW(law.set_parameter("gamma", 1.0), std::invalid_argument);
}

TEST(FiberLaw, BadLawsAreRejectedNamingTheParameter) {
  auto expect_rejected = [](const FiberLaw& law, const std::string& part) {
    const std::string why = law.check().message;
    EXPECT_NE(why.find(part), std::string::npos) << law.name() << ": '" << why << "'";
  };
  EXPECT_TRUE(FiberLaw::exponential(2000.0, 5.0).check().ok);
  expect_rejected(FiberLaw::exponential(-1.0, 5.0), "Y0 must be positive");
  expect_rejected(FiberLaw::exponential(1.0, 800.0), "check beta");  // overflows at e = 2
  expect_rejected(FiberLaw::bilinear(1.0, 0.0), "Y_c must be positive");
  expect_rejected(FiberLaw::bilinear(1.0, 2.0, -0.1), "transition");
  expect_rejected(FiberLaw::constant(-5.0), "Y must be a number >= 0");
  expect_rejected(FiberLaw::tabulated({0.0, 0.1, 0.1}, {0.0, 1.0, 2.0}), "strictly increasing");
  expect_rejected(FiberLaw::tabulated({0.0, 0.1, 0.2}, {0.0, 2.0, 1.0}), "monotone");
  expect_rejected(FiberLaw::tabulated({0.05, 0.1}, {1.0, 2.0}), "(0, 0)");
  expect_rejected(FiberLaw::tabulated({0.0, 0.1}, {0.5, 2.0}), "(0, 0)");
  expect_rejected(FiberLaw::tabulated({0.0}, {0.0}), "at least two");
  expect_rejected(FiberLaw::tabulated({0.0, NAN}, {0.0, 1.0}), "non-finite");
}

}  // namespace
}  // namespace fiberfluid::model

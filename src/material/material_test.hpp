// SPDX-License-Identifier: GPL-3.0-or-later
// A measured material test: nominal stress against stretch in homogeneous
// tests (Treloar's uniaxial and equibiaxial rubber, say), and how a law
// misses it.
#pragma once

#include <functional>
#include <string>
#include <vector>

#include "fiberfluid/material/hyperelastic_law.hpp"

namespace fiberfluid::material {

// The stretches a material test may hold (wider than any real test; a
// law's stress stays finite within them).
inline constexpr double kLeastStretch = 1e-3, kMostStretch = 1e3;

struct TestPoint {
  HomogeneousTest test = HomogeneousTest::Uniaxial;
  double stretch = 1.0;
  double nominal_stress = 0.0;  // Pa
};

// A CSV file of points: a header naming the columns `test` (uniaxial,
// equibiaxial, pure_shear), `stretch` and one of `nominal_stress_Pa`,
// `nominal_stress_kPa`, `nominal_stress_MPa` (other columns are ignored;
// lines starting with # are comments). A stretch lies from 0.001 to 1000. Throws InputError naming the file,
// the line and what was expected.
std::vector<TestPoint> read_material_test(const std::string& path);
// The same from the file's text; `name` is the file named in the errors.
std::vector<TestPoint> read_material_test_text(const std::string& text, const std::string& name);

// A material's nominal stress in a test at a stretch (Pa).
using StressResponse = std::function<double(HomogeneousTest, double)>;

// Whether a point carries information on the scale: a measured stress that
// is not 0 (a test's unloaded point does not). The points a misfit weighs.
inline bool is_loaded(const TestPoint& p) { return p.nominal_stress != 0.0; }
// The loaded points, in order: one per relative misfit.
std::vector<TestPoint> loaded_points(const std::vector<TestPoint>& points);

// The relative misfits (model - measured) / measured at every point whose
// measured stress is not zero (a test's unloaded point carries no
// information on the scale).
std::vector<double> relative_misfits(const StressResponse& stress,
                                     const std::vector<TestPoint>& points);
std::vector<double> relative_misfits(const HyperelasticLaw& law,
                                     const std::vector<TestPoint>& points);
// Their root mean square.
double rms_relative_misfit(const StressResponse& stress, const std::vector<TestPoint>& points);
double rms_relative_misfit(const HyperelasticLaw& law, const std::vector<TestPoint>& points);

}  // namespace fiberfluid::material

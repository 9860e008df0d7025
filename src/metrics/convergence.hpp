// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
// How a value converges as the mesh is refined: the observed order and the
// Richardson-extrapolated value from three levels, with Roache's grid
// convergence index (Roache, "Verification and validation in computational
// science and engineering", 1998, chapter 5; unequal refinement ratios as in
// Celik et al., J. Fluids Eng. 130, 078001, 2008).

#include <vector>

namespace fiberfluid::metrics {

// How a figure's values on meshes coarse to fine change. Changes within
// rounding of the values (1e-12 relative) count as none.
enum class Trend {
  Constant,       // no change at any level: nothing to extrapolate
  Converging,     // changes of one sign, each smaller than the one before
  Oscillating,    // changes of both signs: no order
  NotConverging,  // one sign, but a change no smaller than the one before
};
const char* trend_name(Trend trend);  // "constant", "converging", ...

// The trend of values on successively finer meshes (at least two).
Trend convergence_trend(const std::vector<double>& values);

// The estimate from values on meshes of sizes h1 > h2 > h3 (coarse to fine).
// An order, an extrapolation and an error exist only for a converging
// figure (NaN otherwise); an oscillating one's error is its last change.
struct RichardsonEstimate {
  Trend trend = Trend::Constant;
  bool monotone = false;      // the changes have one sign (or none)
  double order = 0.0;         // observed order p (NaN: none)
  double extrapolated = 0.0;  // the value at h -> 0 (the finest, when constant)
  double error = 0.0;         // |extrapolated - finest|
  double gci = 0.0;  // Roache's grid convergence index of the finest (safety 1.25), relative
};
RichardsonEstimate richardson(double coarse, double medium, double fine, double h_coarse,
                              double h_medium, double h_fine);

// Over any number of levels (at least three): the order and extrapolation
// from the three finest, the trend over every level (a study whose coarse
// levels jump about is not converging because its last three happen to).
RichardsonEstimate richardson(const std::vector<double>& values, const std::vector<double>& sizes);

}  // namespace fiberfluid::metrics

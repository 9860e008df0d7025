// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
// How a value converges as the mesh is refined: the observed order and the
// Richardson-extrapolated value from three levels, with Roache's grid
// convergence index (Roache, "Verification and validation in computational
// science and engineering", 1998, chapter 5; unequal refinement ratios as in
// Celik et al., J. Fluids Eng. 130, 078001, 2008).

namespace fiberfluid::metrics {

// Three values of a figure on meshes of sizes h1 > h2 > h3 (coarse to fine).
struct RichardsonEstimate {
  bool monotone = false;      // the changes have one sign: an order exists
  double order = 0.0;         // observed order p
  double extrapolated = 0.0;  // the value at h -> 0
  double error = 0.0;         // |extrapolated - finest|
  double gci = 0.0;  // Roache's grid convergence index of the finest (safety 1.25), relative
};
RichardsonEstimate richardson(double coarse, double medium, double fine, double h_coarse,
                              double h_medium, double h_fine);

}  // namespace fiberfluid::metrics

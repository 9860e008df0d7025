// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
// The "fem_reference" section of an experiment: the same case solved by FEM
// on tetrahedra, its deformed boundary written as a target for a fit.

#include "fiberfluid/fem/hyperelastic.hpp"
#include "fiberfluid/fem/tet_mesher.hpp"

namespace fiberfluid::experiment {

struct FemReferenceSpec {
  double young = 0.0;    // E (Pa)
  double poisson = 0.3;  // nu
  // "linear" (small strain, the final loads at once) or a neo-Hookean
  // solid solved along the case's load steps (fem::Hyperelastic).
  bool nonlinear = false;
  fem::Hyperelastic hyperelastic = fem::Hyperelastic::NeoHookean;
  // Linear (1) or quadratic (2) tetrahedra; by default 2 for the nonlinear
  // solid (linear tetrahedra lock in bending as nu nears 1/2) and 1 for the
  // linear one (the references fitted so far).
  int order = 1;
  fem::TetMeshOptions mesh;
};

}  // namespace fiberfluid::experiment

// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once

// Why a finite-element stiffness came out singular, told from the setup
// alone: a solver only sees that its factorisation failed, and "too few
// supports?" is one cause of several. Checked in order:
//   1. a rigid motion the held unknowns leave free (the six rigid modes,
//      restricted to the held unknowns, lose rank);
//   2. a flat element (a sliver: an element size larger than the body's
//      thickness, or a mesh that folds);
//   3. a Poisson ratio so close to 1/2 that the bulk stiffness swamps the
//      shear stiffness beyond double precision's digits.

#include <vector>

#include "fiberfluid/fem/fem.hpp"
#include "fiberfluid/util/status.hpp"

namespace fiberfluid::fem {

// The worst tetrahedron's shape: 6 sqrt(2) V / l_rms^3, 1 for a regular
// one, 0 for a flat one, negative for an inverted one (corners 0-3).
struct WorstElement {
  int element = -1;
  double quality = 1.0;
};
WorstElement worst_tetrahedron(const Mesh& mesh);

// Ok when none of the causes above is present; else the first found, named
// with its figures. 3D meshes of tetrahedra (linear or quadratic); a 2D mesh
// is checked for its rigid motions only.
Status diagnose_singular_setup(const Mesh& mesh, double poisson, const std::vector<int>& held_dofs);

}  // namespace fiberfluid::fem

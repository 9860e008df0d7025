// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once

// Large-strain problems whose answers are known in closed form, posed on a
// thick tube (fem::tube_mesh) and solved by the neo-Hookean FEM: the checks
// that the nonlinear reference converges, and at what order. The closed
// forms are the incompressible neo-Hookean solid's (W = mu/2 (I1 - 3); Ogden,
// "Non-linear elastic deformations", 1984, section 5.3: the universal
// deformations of extension, inflation and torsion of a cylinder); the FEM
// solves the nearly incompressible form with a large bulk modulus, which
// tends to them as nu -> 1/2.
//
// - Torsion: the tube's ends and its inner surface follow the torsion
//   r = R, theta = Theta + tau Z, z = Z (the top end turned by tau L); the
//   outer surface is free. Torque on the top end (pi/2) mu tau (B^4 - A^4);
//   axial force -(pi/4) mu tau^2 (B^2 - A^2)^2 (the Poynting effect: the ends
//   must push to keep the length).
// - Inflation in plane strain: the inner surface pushed out from A to a,
//   the ends held along z, the outer surface free; r^2 = R^2 + a^2 - A^2, so
//   the outer surface moves to b = sqrt(B^2 + a^2 - A^2), under the inner
//   pressure mu [ln(a B / (A b)) + (a^2 - A^2) / 2 (1 / a^2 - 1 / b^2)].
// - Inflation of a thick sphere (an octant on its symmetry planes): the
//   inner surface pushed out from A to a, the outer free; r^3 = R^3 + a^3 -
//   A^3, the outer surface at b = (B^3 + a^3 - A^3)^(1/3), under the inner
//   pressure mu [2/l_b + 1/(2 l_b^4) - 2/l_a - 1/(2 l_a^4)], l = r/R.

#include <string>
#include <vector>

#include "fiberfluid/fem/hyperelastic.hpp"
#include "fiberfluid/fem/mesh_tools.hpp"

namespace fiberfluid::fem {

struct ClosedFormFigure {
  std::string name;
  double computed = 0.0, exact = 0.0;
  double relative_error() const { return std::abs(computed - exact) / std::abs(exact); }
};

struct ClosedFormRun {
  std::vector<ClosedFormFigure> figures;
  int nodes = 0, elements = 0, newton_iterations = 0;
};

// `twist` tau in radians per unit length; `inner_stretch` a / A. Both solve
// in options.steps load steps (options.mixed: the u-p form, for quadratic
// tetrahedra); a failed solve throws InputError naming the problem.
ClosedFormRun tube_torsion(const TubeMeshSpec& tube, const HyperelasticMaterial& material,
                           double twist, const HyperelasticOptions& options);
ClosedFormRun tube_inflation(const TubeMeshSpec& tube, const HyperelasticMaterial& material,
                             double inner_stretch, const HyperelasticOptions& options);
ClosedFormRun sphere_inflation(const ShellMeshSpec& shell, const HyperelasticMaterial& material,
                               double inner_stretch, const HyperelasticOptions& options);

}  // namespace fiberfluid::fem

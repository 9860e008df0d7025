// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once

// A finite-element reference for any simulation on a closed 3D surface:
// the body filled with linear tetrahedra (fem::tetrahedralize), the same
// supports, prescribed displacements, point loads and gravity at their
// final load factors, solved quasi-statically by linear elasticity. Its
// deformed boundary is a target surface the calibration can fit
// (fem_reference.obj), a model that no one tuned.
//
// The tetrahedral boundary approximates the surface. A boundary node is held
// where the surface under it is held: when every vertex spanning its
// closest surface point is held on that axis (interpolated values); a held
// vertex that no node reached holds its nearest node. A point load acts on
// the node nearest its vertex; gravity is a body force of the load's density.

#include <Eigen/Core>
#include <map>
#include <string>

#include "fem/fem.hpp"
#include "fem/tet_mesher.hpp"
#include "geom/surface.hpp"

namespace fiberfluid::app {

struct Case;
struct RunResult;
class Fields;

struct FemReferenceSpec {
  double young = 0.0;    // E (Pa)
  double poisson = 0.3;  // nu
  fem::TetMeshOptions mesh;
};
FemReferenceSpec read_fem_reference(Fields& f);

struct FemReferenceResult {
  fem::Mesh mesh;                // the tetrahedra at rest
  Eigen::MatrixXd displacement;  // per node
  geom::Surface rest_boundary, deformed_boundary;
  std::map<std::string, double> figures;  // "fem_reference.*"
};

// Throws InputError for what it cannot pose (a 2D surface, paddles, too few
// supports), naming the "fem_reference" field. `run` is the fiber model's
// run of the same case: its final surface is compared with the FEM's.
FemReferenceResult solve_fem_reference(const Case& c, const RunResult& run,
                                       const FemReferenceSpec& spec);

}  // namespace fiberfluid::app

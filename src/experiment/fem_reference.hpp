// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once

// The "fem_reference" section of an experiment: the FEM of the same case
// (bridge/fem_bridge.hpp) and its comparison with the fiber model's run.

#include <Eigen/Core>
#include <map>
#include <string>
#include <vector>

#include "fiberfluid/fem/fem.hpp"
#include "fiberfluid/fem/hyperelastic.hpp"
#include "fiberfluid/fem/tet_mesher.hpp"
#include "fiberfluid/geom/surface.hpp"

namespace fiberfluid::experiment {

struct Case;
struct RunResult;
class Fields;

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
FemReferenceSpec read_fem_reference(Fields& f);

struct FemReferenceResult {
  fem::Mesh mesh;                     // the tetrahedra at rest
  Eigen::MatrixXd displacement;       // per node
  std::vector<Eigen::MatrixXd> path;  // the displacement after each load step (linear: the last)
  geom::Surface rest_boundary, deformed_boundary;
  std::map<std::string, double> figures;  // "fem_reference.*"
};

// Throws InputError for what it cannot pose (a 2D surface, paddles, too few
// supports), naming the "fem_reference" field. `run` is the fiber model's
// run of the same case: its final surface is compared with the FEM's.
FemReferenceResult solve_fem_reference(const Case& c, const RunResult& run,
                                       const FemReferenceSpec& spec);

}  // namespace fiberfluid::experiment

// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once

// Solving an experiment's "fem_reference" (spec/fem_reference_spec.hpp):
// the FEM of the same case (bridge/fem_bridge.hpp) and its comparison with
// the fiber model's run.

#include <Eigen/Core>
#include <map>
#include <string>
#include <vector>

#include "fiberfluid/experiment/spec/fem_reference_spec.hpp"
#include "fiberfluid/fem/fem.hpp"
#include "fiberfluid/geom/surface.hpp"

namespace fiberfluid::experiment {

struct Case;
struct RunResult;

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

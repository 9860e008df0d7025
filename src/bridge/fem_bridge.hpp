// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once

// A finite-element reference for any simulation on a closed 3D surface:
// the body filled with tetrahedra (fem::tetrahedralize; linear, or made
// quadratic), the same
// supports, prescribed displacements, point loads and gravity at their
// final load factors, solved quasi-statically by linear elasticity; or, by
// neo-Hookean elements (fem/hyperelastic.hpp), along the model's load steps. Its
// deformed boundary is a target surface the calibration can fit
// (fem_reference.obj), a model that no one tuned.
//
// The tetrahedral boundary approximates the surface. A boundary node is held
// where the surface under it is held: when every vertex spanning its
// closest surface point is held on that axis (interpolated values); a held
// vertex that no node reached holds its nearest node. A point load acts on
// the node nearest its vertex; gravity is a body force of the load's density.

#include <Eigen/Core>
#include <stdexcept>
#include <string>
#include <vector>

#include "fiberfluid/fem/fem.hpp"
#include "fiberfluid/fem/hyperelastic.hpp"
#include "fiberfluid/fem/tet_mesher.hpp"
#include "fiberfluid/geom/surface.hpp"
#include "fiberfluid/model/model.hpp"
#include "fiberfluid/util/status.hpp"

namespace fiberfluid::bridge {

struct FemOfModel {
  fem::Mesh mesh;                     // the tetrahedra at rest
  Eigen::MatrixXd displacement;       // per node
  std::vector<Eigen::MatrixXd> path;  // the displacement after each load step (linear: the last)
  int newton_iterations = 0;          // the nonlinear solve's
  geom::Surface rest_boundary, deformed_boundary;
  double mesh_seconds = 0.0, solve_seconds = 0.0;
};

// A FEM that could be posed but not solved: a singular stiffness, a load step
// that would not converge, non-finite displacements. Not bad input: the
// message names the failure and, when the setup shows one, its likely cause
// (fem::diagnose_singular_setup). A requested stop throws Interrupted instead.
class FemSolveFailure : public std::runtime_error {
 public:
  explicit FemSolveFailure(const std::string& why) : std::runtime_error(why) {}
};

// Why a model's body has no FEM here (a 2D surface, paddles): checked before
// any run, so that a failure to pose never comes after a finished fiber run.
Status check_fem_posable(const model::Model& model);

// The FEM of a model's body with every load and prescribed value at its
// factor after step `steps` of `steps`. Throws InputError for what it cannot
// pose (check_fem_posable, a load of an unknown kind) and FemSolveFailure
// for what it cannot solve.
// `order` 1: linear tetrahedra, 2: quadratic ones (fem::to_quadratic; their
// boundary nodes are held and loaded as the corners are) with a linear
// pressure on their corners (the mixed form, which does not lock as nu ->
// 1/2; fem/hyperelastic.hpp).
FemOfModel solve_fem_of_model(const model::Model& model, int steps, const fem::Material& material,
                              const fem::TetMeshOptions& mesh_options, int order = 1);
// The same body of neo-Hookean tetrahedra, solved along the model's `steps`
// load steps (each load's schedule, each prescribed motion's); a step that
// fails (after options.max_step_cuts halvings) throws FemSolveFailure naming it.
FemOfModel solve_hyperelastic_fem_of_model(const model::Model& model, int steps,
                                           const fem::HyperelasticMaterial& material,
                                           const fem::TetMeshOptions& mesh_options, int order = 2,
                                           fem::HyperelasticOptions options = {});

}  // namespace fiberfluid::bridge

// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once

// Geometrically nonlinear finite elements: neo-Hookean tetrahedra, linear (4
// nodes, one point) or quadratic (10 nodes, four points; fem/tetrahedra.hpp),
// in the total Lagrangian form (Bonet and Wood, "Nonlinear continuum mechanics
// for finite element analysis", chapters 6 and 7), solved quasi-statically by
// Newton's method with a line search in load steps. The reference that large
// bending and compression are checked against: it rotates, stiffens and
// conserves volume as a solid does, which the small-strain FEM (fem.hpp)
// cannot.
//
// Deformation gradient F = I + grad u (constant on a linear tetrahedron,
// linear on a straight quadratic one), J = det F. Two strain energies W(F):
// - compressible:          mu/2 (I1 - 3) - mu ln J + lambda/2 (ln J)^2;
// - nearly incompressible: mu/2 (J^(-2/3) I1 - 3) + kappa/2 (J - 1)^2;
// with I1 = tr(F^T F) and mu, lambda, kappa from Young's modulus and Poisson's
// ratio. Both reduce to linear elasticity at small strain. Linear tetrahedra
// lock as nu approaches 1/2 (their constant strain cannot keep the volume of
// every element and still bend); quadratic ones bend with linear strain and
// converge at second order (docs/benchmarks.md, the FEM references).

#include <Eigen/Core>
#include <Eigen/SparseCore>
#include <functional>
#include <string>
#include <vector>

#include "fiberfluid/fem/fem.hpp"
#include "fiberfluid/linalg/status.hpp"

namespace fiberfluid::fem {

enum class Hyperelastic { NeoHookean, NeoHookeanNearlyIncompressible };

// "neo_hookean" and "neo_hookean_incompressible"; from_string throws
// std::invalid_argument naming the valid names.
std::string to_string(Hyperelastic kind);
Hyperelastic hyperelastic_from_string(const std::string& name);

struct HyperelasticMaterial {
  Hyperelastic kind = Hyperelastic::NeoHookean;
  double young = 1.0;  // Pa, the small-strain modulus
  double poisson = 0.3;
  double density = 1.0;  // kg/m^3 (reference)
  double shear_modulus() const { return young / (2.0 * (1.0 + poisson)); }
  double lame_lambda() const { return young * poisson / ((1.0 + poisson) * (1.0 - 2.0 * poisson)); }
  double bulk_modulus() const { return young / (3.0 * (1.0 - 2.0 * poisson)); }
};

// The strain energy per reference volume W(F), the first Piola-Kirchhoff
// stress P = dW/dF, and the stress tangent dP/dF as a 9 x 9 matrix over
// F's entries in column-major order (entry (i, j) at i + 3 j). W is +inf
// where J <= 0 (an inverted element), P and the tangent are then NaN.
double strain_energy(const HyperelasticMaterial& m, const Eigen::Matrix3d& F);
Eigen::Matrix3d first_piola_stress(const HyperelasticMaterial& m, const Eigen::Matrix3d& F);
Eigen::Matrix<double, 9, 9> stress_tangent(const HyperelasticMaterial& m, const Eigen::Matrix3d& F);

// A mesh of tetrahedra (Mesh with dim 3 and 4 or 10 nodes per element)
// displaced by u, in the displacement form (node by node): the internal forces (the gradient of the
// total strain energy) and their Jacobian, the tangent stiffness. `valid`
// (when given) is false when an element is inverted; the forces are then NaN.
Eigen::VectorXd internal_forces(const Mesh& mesh, const HyperelasticMaterial& m,
                                const Eigen::VectorXd& u, bool* valid = nullptr);
Eigen::SparseMatrix<double> tangent_stiffness(const Mesh& mesh, const HyperelasticMaterial& m,
                                              const Eigen::VectorXd& u);
double total_strain_energy(const Mesh& mesh, const HyperelasticMaterial& m,
                           const Eigen::VectorXd& u);

// What acts on the body at the end of load step k (1..steps): dead external
// forces (reference configuration: gravity as M g) and the held unknowns with
// their values. The held unknowns must be the same at every step.
struct LoadState {
  Eigen::VectorXd forces;
  Constraints held;
};
using LoadPath = std::function<LoadState(int step)>;

struct HyperelasticOptions {
  int steps = 10;
  int max_iterations = 30;  // Newton iterations per step
  double tolerance = 1e-9;  // |free residual| / force scale
  int max_step_cuts = 8;    // halvings of a step that fails
  // The mixed (u, p) form: a linear pressure on the corners of quadratic
  // tetrahedra (Taylor-Hood P2-P1), which does not lock as nu -> 1/2; false:
  // the displacement form, W(F) at each point.
  bool mixed = false;
};

struct HyperelasticSolution {
  Eigen::VectorXd u;                  // at the last step reached
  std::vector<Eigen::VectorXd> path;  // u after each load step
  Eigen::VectorXd pressure;           // the mixed form's, per corner node (empty otherwise)
  Eigen::VectorXd forces;  // the internal forces at u: at the held unknowns, the reactions
  int newton_iterations = 0;
  int step_cuts = 0;
  double relative_residual = 0.0;  // at the last state
};

// Newton with a backtracking line search (Armijo on the residual norm; an
// iterate with an inverted element is refused) from u = 0, step by step; a
// step that fails is halved (the load state interpolated linearly) up to
// max_step_cuts times. The status names the step and why it failed;
// `solution` then holds the last converged state. Each tangent is factored
// by CHOLMOD, or by a sparse LU where it is not positive definite.
linalg::Status solve_hyperelastic(const Mesh& mesh, const HyperelasticMaterial& m,
                                  const LoadPath& path, const HyperelasticOptions& options,
                                  HyperelasticSolution* solution);

// Small strain: one solve of the tangent at rest under `state` (its forces
// and held values), which is linear elasticity with E and nu (in the mixed
// form when options.mixed). Fills solution->u, pressure, forces and a
// one-entry path.
linalg::Status solve_small_strain(const Mesh& mesh, const HyperelasticMaterial& m,
                                  const LoadState& state, const HyperelasticOptions& options,
                                  HyperelasticSolution* solution);

}  // namespace fiberfluid::fem

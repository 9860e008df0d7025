// SPDX-License-Identifier: GPL-3.0-or-later
#include "fiberfluid/fem/hyperelastic.hpp"

#include <Eigen/LU>
#include <Eigen/SparseLU>
#include <cmath>
#include <limits>
#include <sstream>
#include <stdexcept>

#include "fiberfluid/fem/free_unknowns.hpp"
#include "fiberfluid/solve/sparse_cholesky.hpp"
#include "fiberfluid/util/error.hpp"

namespace fiberfluid::fem {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

double contract(const Eigen::Matrix3d& A, const Eigen::Matrix3d& B) {
  return (A.array() * B.array()).sum();
}

// A linear tetrahedron at rest: its volume and the gradients of its four
// shape functions (rows), constant over it.
struct RestTetrahedron {
  double volume = 0.0;
  Eigen::Matrix<double, 4, 3> gradients;
};

RestTetrahedron rest_tetrahedron(const Mesh& mesh, int e) {
  const auto node = [&](int k) -> Eigen::Vector3d {
    return mesh.nodes.row(mesh.elements(e, k)).transpose();
  };
  Eigen::Matrix3d D;
  for (int k = 0; k < 3; ++k) D.col(k) = node(k + 1) - node(0);
  RestTetrahedron t;
  t.volume = D.determinant() / 6.0;
  if (!(t.volume > 0.0))
    throw InputError("fem: tetrahedron " + std::to_string(e) + " is inverted or degenerate");
  const Eigen::Matrix3d inverse = D.inverse();  // row k: grad N_(k+1)
  t.gradients.bottomRows<3>() = inverse;
  t.gradients.row(0) = -inverse.colwise().sum();
  return t;
}

void check_tetrahedra(const Mesh& mesh) {
  if (mesh.dim != 3 || mesh.elements.cols() != 4)
    throw InputError("fem: the hyperelastic elements are linear tetrahedra (dim 3, 4 nodes)");
}

// F = I + sum_a u_a grad N_a^T.
Eigen::Matrix3d deformation_gradient(const Mesh& mesh, int e, const RestTetrahedron& t,
                                     const Eigen::VectorXd& u) {
  Eigen::Matrix3d F = Eigen::Matrix3d::Identity();
  for (int a = 0; a < 4; ++a) F += u.segment<3>(3 * mesh.elements(e, a)) * t.gradients.row(a);
  return F;
}

// Every tetrahedron's rest geometry, once per mesh (checked: dim 3, 4 nodes,
// none inverted).
std::vector<RestTetrahedron> rest_geometry(const Mesh& mesh) {
  check_tetrahedra(mesh);
  std::vector<RestTetrahedron> rest(static_cast<size_t>(mesh.elements.rows()));
  for (int e = 0; e < mesh.elements.rows(); ++e)
    rest[static_cast<size_t>(e)] = rest_tetrahedron(mesh, e);
  return rest;
}

Eigen::VectorXd forces_of(const Mesh& mesh, const std::vector<RestTetrahedron>& rest,
                          const HyperelasticMaterial& m, const Eigen::VectorXd& u, bool* valid) {
  Eigen::VectorXd f = Eigen::VectorXd::Zero(mesh.num_dofs());
  bool all_valid = true;
  for (int e = 0; e < mesh.elements.rows(); ++e) {
    const RestTetrahedron& t = rest[static_cast<size_t>(e)];
    const Eigen::Matrix3d F = deformation_gradient(mesh, e, t, u);
    if (!(F.determinant() > 0.0)) all_valid = false;
    const Eigen::Matrix3d P = first_piola_stress(m, F);
    for (int a = 0; a < 4; ++a)  // f_a = V0 P grad N_a
      f.segment<3>(3 * mesh.elements(e, a)) += t.volume * P * t.gradients.row(a).transpose();
  }
  if (valid) *valid = all_valid;
  return f;
}

Eigen::SparseMatrix<double> tangent_of(const Mesh& mesh, const std::vector<RestTetrahedron>& rest,
                                       const HyperelasticMaterial& m, const Eigen::VectorXd& u) {
  std::vector<Eigen::Triplet<double>> entries;
  entries.reserve(static_cast<size_t>(mesh.elements.rows()) * 144);
  for (int e = 0; e < mesh.elements.rows(); ++e) {
    const RestTetrahedron& t = rest[static_cast<size_t>(e)];
    const Eigen::Matrix<double, 9, 9> A = stress_tangent(m, deformation_gradient(mesh, e, t, u));
    // K(3a + i, 3b + k) = V0 sum_jl A(i + 3j, k + 3l) dN_a/dX_j dN_b/dX_l.
    for (int a = 0; a < 4; ++a)
      for (int b = 0; b < 4; ++b)
        for (int i = 0; i < 3; ++i)
          for (int k = 0; k < 3; ++k) {
            double value = 0.0;
            for (int j = 0; j < 3; ++j)
              for (int l = 0; l < 3; ++l)
                value += A(i + 3 * j, k + 3 * l) * t.gradients(a, j) * t.gradients(b, l);
            entries.emplace_back(3 * mesh.elements(e, a) + i, 3 * mesh.elements(e, b) + k,
                                 t.volume * value);
          }
  }
  Eigen::SparseMatrix<double> K(mesh.num_dofs(), mesh.num_dofs());
  K.setFromTriplets(entries.begin(), entries.end());
  return K;
}

double energy_of(const Mesh& mesh, const std::vector<RestTetrahedron>& rest,
                 const HyperelasticMaterial& m, const Eigen::VectorXd& u) {
  double energy = 0.0;
  for (int e = 0; e < mesh.elements.rows(); ++e) {
    const RestTetrahedron& t = rest[static_cast<size_t>(e)];
    energy += t.volume * strain_energy(m, deformation_gradient(mesh, e, t, u));
  }
  return energy;
}

// dP for a direction dF of F (the tangent's action), both forms.
Eigen::Matrix3d stress_differential(const HyperelasticMaterial& m, const Eigen::Matrix3d& F,
                                    const Eigen::Matrix3d& dF) {
  const double J = F.determinant(), mu = m.shear_modulus();
  const Eigen::Matrix3d G = F.inverse().transpose();   // F^-T
  const double trace_G_dF = contract(G, dF);           // d ln J
  const Eigen::Matrix3d dG = -G * dF.transpose() * G;  // d F^-T
  if (m.kind == Hyperelastic::NeoHookean) {
    const double lambda = m.lame_lambda(), log_J = std::log(J);
    return mu * (dF - dG) + lambda * trace_G_dF * G + lambda * log_J * dG;
  }
  const double kappa = m.bulk_modulus(), a = std::pow(J, -2.0 / 3.0), I1 = contract(F, F);
  const double da = -2.0 / 3.0 * a * trace_G_dF, dI1 = 2.0 * contract(F, dF);
  return mu * da * (F - I1 / 3.0 * G) + mu * a * (dF - dI1 / 3.0 * G - I1 / 3.0 * dG) +
         kappa * (2.0 * J - 1.0) * J * trace_G_dF * G + kappa * J * (J - 1.0) * dG;
}

// The linear system's factorization: CHOLMOD for a positive definite
// tangent, else a sparse LU.
solve::Status solve_tangent(const Eigen::SparseMatrix<double>& K, const Eigen::VectorXd& b,
                            Eigen::VectorXd* x) {
  solve::SparseCholesky cholesky;
  cholesky.analyze_pattern(K);
  if (cholesky.factorize(K).ok) {
    *x = cholesky.solve(b);
    return {};
  }
  Eigen::SparseLU<Eigen::SparseMatrix<double>> lu;
  lu.compute(K);
  if (lu.info() != Eigen::Success)
    return solve::Status::failure("the tangent stiffness is singular (too few supports?)");
  *x = lu.solve(b);
  return {};
}

LoadState interpolate(const LoadState& a, const LoadState& b, double s) {
  LoadState out;  // built, not copied then overwritten (GCC 12 warned of a use after free)
  out.forces = (1.0 - s) * a.forces + s * b.forces;
  out.held = b.held;
  for (size_t k = 0; k < out.held.values.size(); ++k)
    out.held.values[k] = (1.0 - s) * a.held.values[k] + s * b.held.values[k];
  return out;
}

// Newton from u (held values already in place) to equilibrium under `state`.
// "" when converged, else why not; u is left at the last iterate.
std::string newton(const Mesh& mesh, const std::vector<RestTetrahedron>& rest,
                   const HyperelasticMaterial& m, const LoadState& state, const FreeUnknowns& split,
                   const HyperelasticOptions& options, Eigen::VectorXd& u,
                   HyperelasticSolution* solution) {
  const auto residual = [&](const Eigen::VectorXd& at, bool* valid) {
    return Eigen::VectorXd(forces_of(mesh, rest, m, at, valid) - state.forces);
  };
  // Relative to the loads and the reactions at the same state (never to a
  // scale carried over from a wild iterate), or at least to mu D^2 (D the
  // body's diagonal: the force of a unit strain across it), so that a state
  // with no force at all (a body turned rigidly) has a scale too.
  const double diagonal =
      (mesh.nodes.colwise().maxCoeff() - mesh.nodes.colwise().minCoeff()).norm();
  const double floor = m.shear_modulus() * diagonal * diagonal;
  const auto relative = [&](const Eigen::VectorXd& R) {
    double held = 0.0;
    for (int d : state.held.dofs) held += R[d] * R[d];
    const double scale = std::max({state.forces.norm(), std::sqrt(held), floor});
    return split.restrict(R).norm() / scale;
  };
  // The total potential energy: strain energy less the dead loads' work.
  const auto potential = [&](const Eigen::VectorXd& at) {
    return energy_of(mesh, rest, m, at) - state.forces.dot(at);
  };
  bool valid = true;
  Eigen::VectorXd R = residual(u, &valid);
  if (!valid) return "an element is inverted at the step's start";
  for (int it = 0;; ++it) {
    const double norm = relative(R);
    solution->relative_residual = norm;
    if (!std::isfinite(norm)) return "the residual is not finite";
    if (norm <= options.tolerance) return {};
    if (it == options.max_iterations) {
      std::ostringstream out;
      out << "no convergence in " << it << " Newton iterations (relative residual " << norm << ")";
      return out.str();
    }
    Eigen::VectorXd du_free;
    const solve::Status status =
        solve_tangent(split.free_block(tangent_of(mesh, rest, m, u)), -split.restrict(R), &du_free);
    if (!status.ok) return status.message;
    Eigen::VectorXd du = Eigen::VectorXd::Zero(u.size());
    split.scatter(du_free, du);
    // Backtracking. The loads are dead and the solid hyperelastic, so the
    // step is judged by the total potential energy (Armijo) where it descends
    // it: a bending body's first Newton step overshoots the residual but not
    // the energy (10 times fewer iterations on a bending cylinder). Where the
    // tangent is indefinite, by the residual norm alone.
    const double slope = split.restrict(R).dot(du_free);  // dPi/dalpha at 0
    const bool by_energy = slope < 0.0;
    const double energy = by_energy ? potential(u) : 0.0;
    double alpha = 1.0;
    for (int halving = 0;; ++halving) {
      const Eigen::VectorXd trial = u + alpha * du;
      bool trial_valid = true;
      const Eigen::VectorXd R_trial = residual(trial, &trial_valid);
      // (The residual's decrease is accepted too: near the solution the
      // energy's change is below its rounding.)
      const bool decrease =
          trial_valid && ((by_energy && potential(trial) <= energy + 1e-4 * alpha * slope) ||
                          relative(R_trial) <= (1.0 - 1e-4 * alpha) * norm);
      if (decrease) {
        u = trial;
        R = R_trial;
        break;
      }
      if (halving == 30)
        return by_energy ? "the line search found no decrease of the energy"
                         : "the line search found no decrease of the residual";
      alpha *= 0.5;
    }
    ++solution->newton_iterations;
  }
}

}  // namespace

std::string to_string(Hyperelastic kind) {
  return kind == Hyperelastic::NeoHookean ? "neo_hookean" : "neo_hookean_incompressible";
}

Hyperelastic hyperelastic_from_string(const std::string& name) {
  if (name == "neo_hookean") return Hyperelastic::NeoHookean;
  if (name == "neo_hookean_incompressible") return Hyperelastic::NeoHookeanNearlyIncompressible;
  throw std::invalid_argument("expected neo_hookean or neo_hookean_incompressible, got \"" + name +
                              "\"");
}

double strain_energy(const HyperelasticMaterial& m, const Eigen::Matrix3d& F) {
  const double J = F.determinant();
  if (!(J > 0.0)) return std::numeric_limits<double>::infinity();
  const double mu = m.shear_modulus(), I1 = contract(F, F);
  if (m.kind == Hyperelastic::NeoHookean) {
    const double log_J = std::log(J);
    return 0.5 * mu * (I1 - 3.0) - mu * log_J + 0.5 * m.lame_lambda() * log_J * log_J;
  }
  return 0.5 * mu * (std::pow(J, -2.0 / 3.0) * I1 - 3.0) +
         0.5 * m.bulk_modulus() * (J - 1.0) * (J - 1.0);
}

Eigen::Matrix3d first_piola_stress(const HyperelasticMaterial& m, const Eigen::Matrix3d& F) {
  const double J = F.determinant();
  if (!(J > 0.0)) return Eigen::Matrix3d::Constant(kNaN);
  const double mu = m.shear_modulus();
  const Eigen::Matrix3d G = F.inverse().transpose();
  if (m.kind == Hyperelastic::NeoHookean) return mu * (F - G) + m.lame_lambda() * std::log(J) * G;
  const double I1 = contract(F, F);
  return mu * std::pow(J, -2.0 / 3.0) * (F - I1 / 3.0 * G) + m.bulk_modulus() * J * (J - 1.0) * G;
}

Eigen::Matrix<double, 9, 9> stress_tangent(const HyperelasticMaterial& m,
                                           const Eigen::Matrix3d& F) {
  Eigen::Matrix<double, 9, 9> A;
  if (!(F.determinant() > 0.0)) return A.setConstant(kNaN);
  for (int l = 0; l < 9; ++l) {
    Eigen::Matrix3d dF = Eigen::Matrix3d::Zero();
    dF(l % 3, l / 3) = 1.0;
    const Eigen::Matrix3d dP = stress_differential(m, F, dF);
    A.col(l) = Eigen::Map<const Eigen::Matrix<double, 9, 1>>(dP.data());
  }
  return A;
}

Eigen::VectorXd internal_forces(const Mesh& mesh, const HyperelasticMaterial& m,
                                const Eigen::VectorXd& u, bool* valid) {
  return forces_of(mesh, rest_geometry(mesh), m, u, valid);
}

Eigen::SparseMatrix<double> tangent_stiffness(const Mesh& mesh, const HyperelasticMaterial& m,
                                              const Eigen::VectorXd& u) {
  return tangent_of(mesh, rest_geometry(mesh), m, u);
}

double total_strain_energy(const Mesh& mesh, const HyperelasticMaterial& m,
                           const Eigen::VectorXd& u) {
  return energy_of(mesh, rest_geometry(mesh), m, u);
}

solve::Status solve_hyperelastic(const Mesh& mesh, const HyperelasticMaterial& m,
                                 const LoadPath& path, const HyperelasticOptions& options,
                                 HyperelasticSolution* solution) {
  check_tetrahedra(mesh);
  if (options.steps < 1) return solve::Status::failure("fem: steps must be at least 1");
  const int n = mesh.num_dofs();
  *solution = HyperelasticSolution{};
  solution->u = Eigen::VectorXd::Zero(n);
  LoadState done = path(1);  // the state at load factor 0: no forces, held at 0
  done.forces.setZero();
  for (double& value : done.held.values) value = 0.0;
  for (int d : done.held.dofs)
    if (d < 0 || d >= n) return solve::Status::failure("fem: a held unknown is out of range");
  const FreeUnknowns split(n, done.held.dofs);
  const std::vector<RestTetrahedron> rest = rest_geometry(mesh);

  for (int step = 1; step <= options.steps; ++step) {
    const LoadState target = path(step);
    if (target.held.dofs != done.held.dofs || target.forces.size() != n)
      return solve::Status::failure("fem: step " + std::to_string(step) +
                                    ": the held unknowns or the force vector changed");
    // Advance from `done` to `target` in pieces, halving a piece that fails.
    double reached = 0.0, piece = 1.0;
    int cuts = 0;
    while (reached < 1.0) {
      const double s = std::min(1.0, reached + piece);
      const LoadState state = interpolate(done, target, s);
      Eigen::VectorXd u = solution->u;
      for (size_t k = 0; k < state.held.dofs.size(); ++k)
        u[state.held.dofs[k]] = state.held.values[k];
      const std::string why = newton(mesh, rest, m, state, split, options, u, solution);
      if (why.empty()) {
        solution->u = u;
        reached = s;
        continue;
      }
      if (cuts == options.max_step_cuts)
        return solve::Status::failure("fem: step " + std::to_string(step) + ": " + why +
                                      "; the step was halved " + std::to_string(cuts) + " times");
      ++cuts;
      ++solution->step_cuts;
      piece *= 0.5;
    }
    done = target;
    solution->path.push_back(solution->u);
  }
  return {};
}

}  // namespace fiberfluid::fem

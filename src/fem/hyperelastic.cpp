// SPDX-License-Identifier: GPL-3.0-or-later
#include "fiberfluid/fem/hyperelastic.hpp"

#include <Eigen/LU>
#include <Eigen/SparseLU>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <sstream>
#include <stdexcept>

#include "fiberfluid/fem/free_unknowns.hpp"
#include "fiberfluid/fem/tetrahedra.hpp"
#include "fiberfluid/solve/sparse_cholesky.hpp"
#include "fiberfluid/util/error.hpp"

namespace fiberfluid::fem {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

double contract(const Eigen::Matrix3d& A, const Eigen::Matrix3d& B) {
  return (A.array() * B.array()).sum();
}

// One quadrature point of an element at rest: its share of the element's
// volume and the gradients of the element's shape functions there (rows).
// A linear tetrahedron has one point (its gradients are constant), a
// quadratic one four (exact for the stiffness of straight edges; curved
// edges are integrated to the same degree).
struct RestPoint {
  double volume = 0.0;
  Eigen::MatrixXd gradients;  // nodes per element x 3
};
using RestElement = std::vector<RestPoint>;

RestElement rest_element(const Mesh& mesh, int e, const TetrahedronRule& rule) {
  const int per = static_cast<int>(mesh.elements.cols());
  Eigen::MatrixXd nodes(per, 3);
  for (int a = 0; a < per; ++a) nodes.row(a) = mesh.nodes.row(mesh.elements(e, a));
  RestElement element;
  Eigen::VectorXd N;
  Eigen::MatrixXd dN;
  for (size_t q = 0; q < rule.points.size(); ++q) {
    tetrahedron_shape(per, rule.points[q], &N, &dN);
    const Eigen::Matrix3d J = nodes.transpose() * dN;  // dX / dxi
    const double det = J.determinant();
    if (!(det > 0.0))
      throw InputError("fem: tetrahedron " + std::to_string(e) + " is inverted or degenerate");
    element.push_back({rule.weights[q] * det, dN * J.inverse()});
  }
  return element;
}

void check_tetrahedra(const Mesh& mesh) {
  if (mesh.dim != 3 || (mesh.elements.cols() != 4 && mesh.elements.cols() != 10))
    throw InputError(
        "fem: the hyperelastic elements are tetrahedra, linear (dim 3, 4 nodes) or quadratic "
        "(10 nodes)");
}

// F = I + sum_a u_a grad N_a^T at one point of element e.
Eigen::Matrix3d deformation_gradient(const Mesh& mesh, int e, const RestPoint& p,
                                     const Eigen::VectorXd& u) {
  Eigen::Matrix3d F = Eigen::Matrix3d::Identity();
  for (int a = 0; a < p.gradients.rows(); ++a)
    F += u.segment<3>(3 * mesh.elements(e, a)) * p.gradients.row(a);
  return F;
}

// Every element's rest geometry, once per mesh (checked: tetrahedra, none
// inverted).
std::vector<RestElement> rest_geometry(const Mesh& mesh) {
  check_tetrahedra(mesh);
  const TetrahedronRule rule =
      tetrahedron_rule(is_quadratic_tetrahedron(static_cast<int>(mesh.elements.cols())) ? 2 : 1);
  std::vector<RestElement> rest(static_cast<size_t>(mesh.elements.rows()));
  for (int e = 0; e < mesh.elements.rows(); ++e)
    rest[static_cast<size_t>(e)] = rest_element(mesh, e, rule);
  return rest;
}

// The solid's energy split as W(F) = W_shape(F) + U(J): U is the part whose
// stiffness (lambda, kappa) grows without bound as nu -> 1/2. Compressible:
// U = lambda/2 (ln J)^2, W_shape = mu/2 (I1 - 3) - mu ln J; nearly
// incompressible: U = kappa/2 (J - 1)^2, W_shape = mu/2 (J^(-2/3) I1 - 3).
struct Volumetric {
  double energy = 0.0, slope = 0.0, curvature = 0.0;  // U, U', U''
};
Volumetric volumetric(const HyperelasticMaterial& m, double J) {
  if (m.kind == Hyperelastic::NeoHookean) {
    const double lambda = m.lame_lambda(), log_J = std::log(J);
    return {0.5 * lambda * log_J * log_J, lambda * log_J / J, lambda * (1.0 - log_J) / (J * J)};
  }
  const double kappa = m.bulk_modulus();
  return {0.5 * kappa * (J - 1.0) * (J - 1.0), kappa * (J - 1.0), kappa};
}

double shape_energy(const HyperelasticMaterial& m, const Eigen::Matrix3d& F, double J) {
  const double mu = m.shear_modulus(), I1 = contract(F, F);
  if (m.kind == Hyperelastic::NeoHookean) return 0.5 * mu * (I1 - 3.0) - mu * std::log(J);
  return 0.5 * mu * (std::pow(J, -2.0 / 3.0) * I1 - 3.0);
}

// dW_shape / dF, with G = F^-T.
Eigen::Matrix3d shape_stress(const HyperelasticMaterial& m, const Eigen::Matrix3d& F, double J,
                             const Eigen::Matrix3d& G) {
  const double mu = m.shear_modulus();
  if (m.kind == Hyperelastic::NeoHookean) return mu * (F - G);
  return mu * std::pow(J, -2.0 / 3.0) * (F - contract(F, F) / 3.0 * G);
}

// The differential of P_shape + dU J F^-T (the stress at a point of an
// element whose volumetric slope is dU) in the direction dF.
Eigen::Matrix3d stress_differential(const HyperelasticMaterial& m, const Eigen::Matrix3d& F,
                                    double J, const Eigen::Matrix3d& G, double dU,
                                    const Eigen::Matrix3d& dF) {
  const double mu = m.shear_modulus();
  const double trace_G_dF = contract(G, dF);           // d ln J
  const Eigen::Matrix3d dG = -G * dF.transpose() * G;  // d F^-T
  const Eigen::Matrix3d d_JG = J * (trace_G_dF * G + dG);
  if (m.kind == Hyperelastic::NeoHookean) return mu * (dF - dG) + dU * d_JG;
  const double a = std::pow(J, -2.0 / 3.0), I1 = contract(F, F);
  const double da = -2.0 / 3.0 * a * trace_G_dF, dI1 = 2.0 * contract(F, dF);
  return mu * da * (F - I1 / 3.0 * G) + mu * a * (dF - dI1 / 3.0 * G - I1 / 3.0 * dG) +
         dU * d_JG;
}

Eigen::Matrix<double, 9, 9> point_tangent(const HyperelasticMaterial& m, const Eigen::Matrix3d& F,
                                          double J, const Eigen::Matrix3d& G, double dU) {
  Eigen::Matrix<double, 9, 9> A;
  for (int l = 0; l < 9; ++l) {
    Eigen::Matrix3d dF = Eigen::Matrix3d::Zero();
    dF(l % 3, l / 3) = 1.0;
    const Eigen::Matrix3d dP = stress_differential(m, F, J, G, dU, dF);
    A.col(l) = Eigen::Map<const Eigen::Matrix<double, 9, 1>>(dP.data());
  }
  return A;
}

// One element's energy, forces and (when asked) tangent, with the
// volumetric energy of its mean dilatation: W_shape at each point plus
// V U(Jbar), Jbar = (sum_q dV_q J_q) / V the ratio of the element's volumes
// (Nagtegaal, Parks and Rice 1974; Simo, Taylor and Pister 1985; Bonet and
// Wood, section 8.6). One pressure per element: a quadratic tetrahedron with
// it is the stable P2-P0 pair and does not lock as nu -> 1/2, where its
// pointwise volume terms do (a thick tube's torque 6% and its axial force
// tenfold off at nu = 0.4999). A linear tetrahedron has one point: Jbar = J.
struct ElementResponse {
  bool valid = true;
  double energy = 0.0;
  Eigen::VectorXd forces;   // 3 per node
  Eigen::MatrixXd tangent;  // when asked
};

ElementResponse respond(const Mesh& mesh, int e, const RestElement& rest,
                        const HyperelasticMaterial& m, const Eigen::VectorXd& u, bool tangent) {
  const int per = static_cast<int>(mesh.elements.cols()), points = static_cast<int>(rest.size());
  ElementResponse out;
  out.forces = Eigen::VectorXd::Zero(3 * per);
  std::vector<Eigen::Matrix3d> F(static_cast<size_t>(points)), G(F.size());
  std::vector<double> J(F.size());
  double volume = 0.0, deformed = 0.0;
  for (int q = 0; q < points; ++q) {
    const RestPoint& p = rest[static_cast<size_t>(q)];
    F[q] = deformation_gradient(mesh, e, p, u);
    J[q] = F[q].determinant();
    if (!(J[q] > 0.0)) {
      out.valid = false;
      out.energy = std::numeric_limits<double>::infinity();
      out.forces.setConstant(kNaN);
      if (tangent) out.tangent = Eigen::MatrixXd::Constant(3 * per, 3 * per, kNaN);
      return out;
    }
    G[q] = F[q].inverse().transpose();
    volume += p.volume;
    deformed += p.volume * J[q];
  }
  const Volumetric U = volumetric(m, deformed / volume);
  out.energy = volume * U.energy;
  Eigen::MatrixXd g = Eigen::MatrixXd::Zero(3, per);  // d(deformed volume) / du_a, per node a
  for (int q = 0; q < points; ++q) {
    const RestPoint& p = rest[static_cast<size_t>(q)];
    out.energy += p.volume * shape_energy(m, F[q], J[q]);
    const Eigen::Matrix3d P = shape_stress(m, F[q], J[q], G[q]) + U.slope * J[q] * G[q];
    const Eigen::MatrixXd JG_grad = p.volume * J[q] * G[q] * p.gradients.transpose();
    g += JG_grad;
    const Eigen::MatrixXd P_grad = p.volume * P * p.gradients.transpose();  // 3 x per
    for (int a = 0; a < per; ++a) out.forces.segment<3>(3 * a) += P_grad.col(a);
  }
  if (!tangent) return out;
  out.tangent = Eigen::MatrixXd::Zero(3 * per, 3 * per);
  Eigen::Matrix<double, 3, 9> C;
  for (int q = 0; q < points; ++q) {
    const RestPoint& p = rest[static_cast<size_t>(q)];
    const Eigen::Matrix<double, 9, 9> A = p.volume * point_tangent(m, F[q], J[q], G[q], U.slope);
    // K(3a + i, 3b + k) = dV sum_jl A(i + 3j, k + 3l) dN_a/dX_j dN_b/dX_l,
    // with C_a(i, k + 3l) = sum_j A(i + 3j, k + 3l) dN_a/dX_j first.
    for (int a = 0; a < per; ++a) {
      C = p.gradients(a, 0) * A.topRows<3>() + p.gradients(a, 1) * A.middleRows<3>(3) +
          p.gradients(a, 2) * A.bottomRows<3>();
      for (int b = 0; b < per; ++b)
        out.tangent.block<3, 3>(3 * a, 3 * b) += p.gradients(b, 0) * C.leftCols<3>() +
                                                 p.gradients(b, 1) * C.middleCols<3>(3) +
                                                 p.gradients(b, 2) * C.rightCols<3>();
    }
  }
  // U''(Jbar) / V g g^T: the volumetric slope's own change (with one point,
  // the pointwise U'' J^2 (G : dF) G).
  const Eigen::Map<const Eigen::VectorXd> flat(g.data(), 3 * per);
  out.tangent += U.curvature / volume * flat * flat.transpose();
  return out;
}

Eigen::VectorXd forces_of(const Mesh& mesh, const std::vector<RestElement>& rest,
                          const HyperelasticMaterial& m, const Eigen::VectorXd& u, bool* valid) {
  Eigen::VectorXd f = Eigen::VectorXd::Zero(mesh.num_dofs());
  bool all_valid = true;
  for (int e = 0; e < mesh.elements.rows(); ++e) {
    const ElementResponse r = respond(mesh, e, rest[static_cast<size_t>(e)], m, u, false);
    all_valid = all_valid && r.valid;
    for (int a = 0; a < mesh.elements.cols(); ++a)
      f.segment<3>(3 * mesh.elements(e, a)) += r.forces.segment<3>(3 * a);
  }
  if (valid) *valid = all_valid;
  return f;
}

Eigen::SparseMatrix<double> tangent_of(const Mesh& mesh, const std::vector<RestElement>& rest,
                                       const HyperelasticMaterial& m, const Eigen::VectorXd& u) {
  const int per = static_cast<int>(mesh.elements.cols());
  std::vector<Eigen::Triplet<double>> entries;
  entries.reserve(static_cast<size_t>(mesh.elements.rows()) * 9 * per * per);
  for (int e = 0; e < mesh.elements.rows(); ++e) {
    const ElementResponse r = respond(mesh, e, rest[static_cast<size_t>(e)], m, u, true);
    for (int a = 0; a < per; ++a)
      for (int b = 0; b < per; ++b)
        for (int i = 0; i < 3; ++i)
          for (int k = 0; k < 3; ++k)
            entries.emplace_back(3 * mesh.elements(e, a) + i, 3 * mesh.elements(e, b) + k,
                                 r.tangent(3 * a + i, 3 * b + k));
  }
  Eigen::SparseMatrix<double> K(mesh.num_dofs(), mesh.num_dofs());
  K.setFromTriplets(entries.begin(), entries.end());
  return K;
}

double energy_of(const Mesh& mesh, const std::vector<RestElement>& rest,
                 const HyperelasticMaterial& m, const Eigen::VectorXd& u) {
  double energy = 0.0;
  for (int e = 0; e < mesh.elements.rows(); ++e)
    energy += respond(mesh, e, rest[static_cast<size_t>(e)], m, u, false).energy;
  return energy;
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
std::string newton(const Mesh& mesh, const std::vector<RestElement>& rest,
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
    if (std::getenv("FF_DEBUG_NEWTON")) std::fprintf(stderr, "it %d residual %.3e\n", it, norm);
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
      if (std::getenv("FF_DEBUG_NEWTON")) std::fprintf(stderr, "  halve %d by_energy %d\n", halving, by_energy);
    }
    ++solution->newton_iterations;
  }
}

// A piece's first iterate: from the last equilibrium u0 along its tangent,
// K_ff du_f = (f - f_int(u0))_f - K_fh du_h for the held values' change du_h
// and the loads' (Wriggers, "Nonlinear finite element methods", 2008,
// section 5.1: the tangent predictor). The free nodes then move with the
// held ones, where holding them still would leave the elements beside the
// held nodes to take the whole change: a nearly incompressible tube twisted
// in 4 steps took hundreds of damped Newton iterations so. The plain guess
// (the held values set, the rest kept) where the tangent cannot be solved or
// its prediction turns an element over.
Eigen::VectorXd predicted_start(const Mesh& mesh, const std::vector<RestElement>& rest,
                                const HyperelasticMaterial& m, const LoadState& state,
                                const FreeUnknowns& split, const Eigen::VectorXd& u0) {
  Eigen::VectorXd plain = u0, held_change = Eigen::VectorXd::Zero(u0.size());
  for (size_t k = 0; k < state.held.dofs.size(); ++k) {
    const int d = state.held.dofs[k];
    plain[d] = state.held.values[k];
    held_change[d] = state.held.values[k] - u0[d];
  }
  const Eigen::SparseMatrix<double> K = tangent_of(mesh, rest, m, u0);
  const Eigen::VectorXd rhs =
      split.restrict(state.forces - forces_of(mesh, rest, m, u0, nullptr) - K * held_change);
  Eigen::VectorXd du_free;
  if (!solve_tangent(split.free_block(K), rhs, &du_free).ok) return plain;
  Eigen::VectorXd predicted = plain;
  Eigen::VectorXd du = Eigen::VectorXd::Zero(u0.size());
  split.scatter(du_free, du);
  predicted += du;
  bool valid = true;
  forces_of(mesh, rest, m, predicted, &valid);
  return valid && du.allFinite() ? predicted : plain;
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
  return shape_energy(m, F, J) + volumetric(m, J).energy;
}

Eigen::Matrix3d first_piola_stress(const HyperelasticMaterial& m, const Eigen::Matrix3d& F) {
  const double J = F.determinant();
  if (!(J > 0.0)) return Eigen::Matrix3d::Constant(kNaN);
  const Eigen::Matrix3d G = F.inverse().transpose();
  return shape_stress(m, F, J, G) + volumetric(m, J).slope * J * G;
}

Eigen::Matrix<double, 9, 9> stress_tangent(const HyperelasticMaterial& m,
                                           const Eigen::Matrix3d& F) {
  Eigen::Matrix<double, 9, 9> A;
  const double J = F.determinant();
  if (!(J > 0.0)) return A.setConstant(kNaN);
  const Eigen::Matrix3d G = F.inverse().transpose();
  const Volumetric U = volumetric(m, J);
  // The pointwise U(J): its slope's own change, U'' J^2 (G : dF) G, joins
  // the terms of point_tangent.
  A = point_tangent(m, F, J, G, U.slope);
  const Eigen::Map<const Eigen::Matrix<double, 9, 1>> g(G.data());
  A += U.curvature * J * J * g * g.transpose();
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
  const std::vector<RestElement> rest = rest_geometry(mesh);

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
      Eigen::VectorXd u = predicted_start(mesh, rest, m, state, split, solution->u);
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

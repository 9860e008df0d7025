// SPDX-License-Identifier: GPL-3.0-or-later
#include "fiberfluid/fem/hyperelastic.hpp"

#include <Eigen/LU>
#include <Eigen/SparseLU>
#include <cmath>
#include <limits>
#include <sstream>
#include <stdexcept>

#include "fiberfluid/fem/free_unknowns.hpp"
#include "fiberfluid/fem/tetrahedra.hpp"
#include "fiberfluid/linalg/sparse_cholesky.hpp"
#include "fiberfluid/util/error.hpp"
#include "fiberfluid/util/run_control.hpp"

namespace fiberfluid::fem {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

double contract(const Eigen::Matrix3d& A, const Eigen::Matrix3d& B) {
  return (A.array() * B.array()).sum();
}

// One quadrature point of an element at rest: its share of the element's
// volume, the gradients of the element's shape functions there (rows), and
// the corners' linear shape functions (the mixed form's pressure). A linear
// tetrahedron has one point (its gradients are constant), a quadratic one
// four (exact for the stiffness of straight edges; curved edges are
// integrated to the same degree).
struct RestPoint {
  double volume = 0.0;
  Eigen::MatrixXd gradients;  // nodes per element x 3
  Eigen::Vector4d corner_weights;
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
    const Eigen::Vector3d& xi = rule.points[q];
    element.push_back({rule.weights[q] * det, dN * J.inverse(),
                       Eigen::Vector4d(1.0 - xi.sum(), xi[0], xi[1], xi[2])});
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

// The solid's energy split as W(F) = W_shape(F) + k/2 theta(J)^2: the
// volumetric part, whose modulus k grows without bound as nu -> 1/2, in a
// measure of volume change theta. Compressible: theta = ln J, k = lambda,
// W_shape = mu/2 (I1 - 3) - mu ln J; nearly incompressible: theta = J - 1,
// k = kappa, W_shape = mu/2 (J^(-2/3) I1 - 3). The pressure p = k theta
// (pointwise in the displacement form, a field of its own in the mixed one).
struct VolumeMeasure {
  double value = 0.0, slope = 0.0, curvature = 0.0;  // theta, theta', theta''
};
VolumeMeasure volume_measure(const HyperelasticMaterial& m, double J) {
  if (m.kind == Hyperelastic::NeoHookean) return {std::log(J), 1.0 / J, -1.0 / (J * J)};
  return {J - 1.0, 1.0, 0.0};
}
double volumetric_modulus(const HyperelasticMaterial& m) {
  return m.kind == Hyperelastic::NeoHookean ? m.lame_lambda() : m.bulk_modulus();
}

double shape_energy(const HyperelasticMaterial& m, const Eigen::Matrix3d& F, double J) {
  const double mu = m.shear_modulus(), I1 = contract(F, F);
  if (m.kind == Hyperelastic::NeoHookean) return 0.5 * mu * (I1 - 3.0) - mu * std::log(J);
  return 0.5 * mu * (std::pow(J, -2.0 / 3.0) * I1 - 3.0);
}

// The state at one point: F, J, G = F^-T and the volume measure.
struct PointState {
  Eigen::Matrix3d F, G;
  double J = 1.0;
  VolumeMeasure theta;
};
PointState point_state(const HyperelasticMaterial& m, const Eigen::Matrix3d& F) {
  PointState s;
  s.F = F;
  s.J = F.determinant();
  if (s.J > 0.0) {
    s.G = F.inverse().transpose();
    s.theta = volume_measure(m, s.J);
  }
  return s;
}

// P = dW_shape/dF + p theta'(J) J G: the stress at a point under pressure p.
Eigen::Matrix3d stress(const HyperelasticMaterial& m, const PointState& s, double p) {
  const double mu = m.shear_modulus();
  const Eigen::Matrix3d volumetric = p * s.theta.slope * s.J * s.G;
  if (m.kind == Hyperelastic::NeoHookean) return mu * (s.F - s.G) + volumetric;
  return mu * std::pow(s.J, -2.0 / 3.0) * (s.F - contract(s.F, s.F) / 3.0 * s.G) + volumetric;
}

// dP/dF at fixed p (9 x 9 over F's entries in column-major order):
// the shape part and p d(theta' J G) = p [(theta'' J + theta') J (G:dF) G +
// theta' J dG], dG = -G dF^T G.
Eigen::Matrix<double, 9, 9> tangent_at_fixed_pressure(const HyperelasticMaterial& m,
                                                      const PointState& s, double p) {
  const double mu = m.shear_modulus(), J = s.J;
  const Eigen::Matrix3d &F = s.F, &G = s.G;
  const double a = std::pow(J, -2.0 / 3.0), I1 = contract(F, F);
  Eigen::Matrix<double, 9, 9> A;
  for (int l = 0; l < 9; ++l) {
    Eigen::Matrix3d dF = Eigen::Matrix3d::Zero();
    dF(l % 3, l / 3) = 1.0;
    const double trace_G_dF = contract(G, dF);  // d ln J
    const Eigen::Matrix3d dG = -G * dF.transpose() * G;
    Eigen::Matrix3d dP =
        p * ((s.theta.curvature * J + s.theta.slope) * J * trace_G_dF * G + s.theta.slope * J * dG);
    if (m.kind == Hyperelastic::NeoHookean) {
      dP += mu * (dF - dG);
    } else {
      const double da = -2.0 / 3.0 * a * trace_G_dF, dI1 = 2.0 * contract(F, dF);
      dP += mu * da * (F - I1 / 3.0 * G) + mu * a * (dF - dI1 / 3.0 * G - I1 / 3.0 * dG);
    }
    A.col(l) = Eigen::Map<const Eigen::Matrix<double, 9, 1>>(dP.data());
  }
  return A;
}

// Where the mixed form's pressure lives: one value per corner node of the
// quadratic tetrahedra (continuous and linear: the Taylor-Hood pair P2-P1),
// numbered after the displacements.
struct PressureField {
  std::vector<int> index;  // per mesh node: its pressure unknown, or -1
  int count = 0;
};
PressureField pressure_field(const Mesh& mesh, bool mixed) {
  PressureField field;
  if (!mixed) return field;
  field.index.assign(static_cast<size_t>(mesh.num_nodes()), -1);
  for (Eigen::Index e = 0; e < mesh.elements.rows(); ++e)
    for (int c = 0; c < 4; ++c) {
      int& k = field.index[static_cast<size_t>(mesh.elements(e, c))];
      if (k < 0) k = mesh.num_dofs() + field.count++;
    }
  return field;
}

// What the solver works with: the mesh, each element's rest geometry, the
// material, and the pressure field when the form is mixed.
struct Discretization {
  const Mesh& mesh;
  const HyperelasticMaterial& m;
  std::vector<RestElement> rest;
  PressureField pressure;
  bool mixed() const { return pressure.count > 0; }
  int unknowns() const { return mesh.num_dofs() + pressure.count; }
};

Discretization discretize(const Mesh& mesh, const HyperelasticMaterial& m, bool mixed) {
  check_tetrahedra(mesh);
  const bool quadratic = is_quadratic_tetrahedron(static_cast<int>(mesh.elements.cols()));
  if (mixed && !quadratic)
    throw InputError(
        "fem: the mixed form needs quadratic tetrahedra (linear ones with a linear "
        "pressure are not stable)");
  Discretization d{mesh, m, {}, pressure_field(mesh, mixed)};
  const TetrahedronRule rule = tetrahedron_rule(quadratic ? 2 : 1);
  d.rest.resize(static_cast<size_t>(mesh.elements.rows()));
  for (int e = 0; e < mesh.elements.rows(); ++e)
    d.rest[static_cast<size_t>(e)] = rest_element(mesh, e, rule);
  return d;
}

// One element's energy, its unknowns' global numbers, forces and (when
// asked) tangent. Displacement form: W(F) at each point. Mixed form (u, p):
// W_shape(F) + p theta(J) - p^2 / (2k) at each point with p interpolated
// from the corners (Bonet and Wood, "Nonlinear continuum mechanics for
// finite element analysis", 2nd ed., section 8.6; Taylor-Hood: Brezzi and
// Fortin, "Mixed and hybrid finite element methods", section VI.6): its
// pressure rows are the volume constraint's residual integral M_i (theta -
// p/k), which the stationary point zeroes. The pair converges at second
// order and does not lock as nu -> 1/2, where quadratic tetrahedra alone do
// (a thick tube twisted at nu = 0.4999, 2 cells across its wall: torque 6%
// and axial force tenfold off; docs/model.md has the table).
struct ElementResponse {
  bool valid = true;
  double energy = 0.0;
  std::vector<int> unknowns;
  Eigen::VectorXd forces;
  Eigen::MatrixXd tangent;  // when asked
};

ElementResponse respond(const Discretization& d, int e, const Eigen::VectorXd& x, bool tangent) {
  const Mesh& mesh = d.mesh;
  const int per = static_cast<int>(mesh.elements.cols()), pressures = d.mixed() ? 4 : 0;
  const int size = 3 * per + pressures;
  ElementResponse out;
  for (int a = 0; a < per; ++a)
    for (int i = 0; i < 3; ++i) out.unknowns.push_back(3 * mesh.elements(e, a) + i);
  Eigen::Vector4d corner_pressure = Eigen::Vector4d::Zero();
  for (int c = 0; c < pressures; ++c) {
    out.unknowns.push_back(d.pressure.index[static_cast<size_t>(mesh.elements(e, c))]);
    corner_pressure[c] = x[out.unknowns.back()];
  }
  out.forces = Eigen::VectorXd::Zero(size);
  if (tangent) out.tangent = Eigen::MatrixXd::Zero(size, size);
  const double k = volumetric_modulus(d.m);
  Eigen::Matrix<double, 3, 9> C;
  for (const RestPoint& point : d.rest[static_cast<size_t>(e)]) {
    const PointState s = point_state(d.m, deformation_gradient(mesh, e, point, x));
    if (!(s.J > 0.0)) {
      out.valid = false;
      out.energy = std::numeric_limits<double>::infinity();
      out.forces.setConstant(kNaN);
      if (tangent) out.tangent.setConstant(kNaN);
      return out;
    }
    const double dV = point.volume;
    const double p = d.mixed() ? point.corner_weights.dot(corner_pressure) : k * s.theta.value;
    out.energy += dV * (shape_energy(d.m, s.F, s.J) + p * s.theta.value - 0.5 * p * p / k);
    const Eigen::MatrixXd P_grad = dV * stress(d.m, s, p) * point.gradients.transpose();
    for (int a = 0; a < per; ++a) out.forces.segment<3>(3 * a) += P_grad.col(a);
    for (int c = 0; c < pressures; ++c)
      out.forces[3 * per + c] += dV * point.corner_weights[c] * (s.theta.value - p / k);
    if (!tangent) continue;
    // d(theta)/du_a = theta' J G grad N_a: the volume change's gradient.
    const Eigen::MatrixXd theta_grad =
        s.theta.slope * s.J * s.G * point.gradients.transpose();  // 3 x per
    const Eigen::Matrix<double, 9, 9> A = dV * tangent_at_fixed_pressure(d.m, s, p);
    // K(3a + i, 3b + k) = dV sum_jl A(i + 3j, k + 3l) dN_a/dX_j dN_b/dX_l,
    // with C_a(i, k + 3l) = sum_j A(i + 3j, k + 3l) dN_a/dX_j first.
    for (int a = 0; a < per; ++a) {
      C = point.gradients(a, 0) * A.topRows<3>() + point.gradients(a, 1) * A.middleRows<3>(3) +
          point.gradients(a, 2) * A.bottomRows<3>();
      for (int b = 0; b < per; ++b)
        out.tangent.block<3, 3>(3 * a, 3 * b) += point.gradients(b, 0) * C.leftCols<3>() +
                                                 point.gradients(b, 1) * C.middleCols<3>(3) +
                                                 point.gradients(b, 2) * C.rightCols<3>();
    }
    const Eigen::Map<const Eigen::VectorXd> g(theta_grad.data(), 3 * per);
    if (!d.mixed()) {  // p = k theta(J) changes with u too: k (dtheta/du)(dtheta/du)^T
      out.tangent.topLeftCorner(3 * per, 3 * per) += dV * k * g * g.transpose();
      continue;
    }
    for (int c = 0; c < pressures; ++c) {
      out.tangent.block(0, 3 * per + c, 3 * per, 1) += dV * point.corner_weights[c] * g;
      out.tangent.block(3 * per + c, 0, 1, 3 * per) += dV * point.corner_weights[c] * g.transpose();
      for (int c2 = 0; c2 < pressures; ++c2)
        out.tangent(3 * per + c, 3 * per + c2) -=
            dV * point.corner_weights[c] * point.corner_weights[c2] / k;
    }
  }
  return out;
}

Eigen::VectorXd forces_of(const Discretization& d, const Eigen::VectorXd& x, bool* valid) {
  Eigen::VectorXd f = Eigen::VectorXd::Zero(d.unknowns());
  bool all_valid = true;
  for (int e = 0; e < d.mesh.elements.rows(); ++e) {
    const ElementResponse r = respond(d, e, x, false);
    all_valid = all_valid && r.valid;
    for (size_t k = 0; k < r.unknowns.size(); ++k)
      f[r.unknowns[k]] += r.forces[static_cast<Eigen::Index>(k)];
  }
  if (valid) *valid = all_valid;
  return f;
}

Eigen::SparseMatrix<double> tangent_of(const Discretization& d, const Eigen::VectorXd& x) {
  std::vector<Eigen::Triplet<double>> entries;
  for (int e = 0; e < d.mesh.elements.rows(); ++e) {
    const ElementResponse r = respond(d, e, x, true);
    if (entries.empty())
      entries.reserve(d.mesh.elements.rows() * r.unknowns.size() * r.unknowns.size());
    for (size_t a = 0; a < r.unknowns.size(); ++a)
      for (size_t b = 0; b < r.unknowns.size(); ++b)
        entries.emplace_back(r.unknowns[a], r.unknowns[b],
                             r.tangent(static_cast<Eigen::Index>(a), static_cast<Eigen::Index>(b)));
  }
  Eigen::SparseMatrix<double> K(d.unknowns(), d.unknowns());
  K.setFromTriplets(entries.begin(), entries.end());
  return K;
}

double energy_of(const Discretization& d, const Eigen::VectorXd& x) {
  double energy = 0.0;
  for (int e = 0; e < d.mesh.elements.rows(); ++e) energy += respond(d, e, x, false).energy;
  return energy;
}

// The linear system's factorization: CHOLMOD for a positive definite
// tangent, else a sparse LU (an indefinite one: the mixed form's, or past a
// limit point) of the system scaled symmetrically by its diagonal: the
// mixed form's pressure block is smaller than its displacement block by
// about (h / D)^2 mu / k (1e-20 for a stiff body on millimetre elements),
// which costs the unscaled LU three digits of the answer.
linalg::Status solve_tangent(const Eigen::SparseMatrix<double>& K, const Eigen::VectorXd& b,
                             Eigen::VectorXd* x) {
  linalg::SparseCholesky cholesky;
  cholesky.analyze_pattern(K);
  if (cholesky.factorize(K).ok) {
    *x = cholesky.solve(b);
    return {};
  }
  Eigen::VectorXd scale(K.rows());
  for (Eigen::Index i = 0; i < K.rows(); ++i) {
    const double diagonal = std::abs(K.coeff(i, i));
    scale[i] = diagonal > 0.0 ? 1.0 / std::sqrt(diagonal) : 1.0;
  }
  const Eigen::SparseMatrix<double> scaled = scale.asDiagonal() * K * scale.asDiagonal();
  Eigen::SparseLU<Eigen::SparseMatrix<double>> lu;
  lu.compute(scaled);
  if (lu.info() != Eigen::Success)
    return linalg::Status::failure("the tangent stiffness is singular");
  *x = scale.asDiagonal() * lu.solve(scale.asDiagonal() * b);
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

// Newton from x (held values already in place) to equilibrium under `state`.
// "" when converged (`internal` then holds the internal forces at x, which
// the next piece and the reactions need), else why not; x is left at the
// last iterate.
std::string newton(const Discretization& d, const LoadState& state, const FreeUnknowns& split,
                   const HyperelasticOptions& options, Eigen::VectorXd& x,
                   HyperelasticSolution* solution, Eigen::VectorXd* internal) {
  const int n = d.mesh.num_dofs();
  const auto residual = [&](const Eigen::VectorXd& at, bool* valid) {
    Eigen::VectorXd R = forces_of(d, at, valid);
    R.head(n) -= state.forces;
    return R;
  };
  // Relative to the loads and the reactions at the same state (never to a
  // scale carried over from a wild iterate), or at least to mu D^2 (D the
  // body's diagonal: the force of a unit strain across it), so that a state
  // with no force at all (a body turned rigidly) has a scale too. The mixed
  // form's volume rows count as the force k / D times their volume error.
  const double diagonal =
      (d.mesh.nodes.colwise().maxCoeff() - d.mesh.nodes.colwise().minCoeff()).norm();
  const double floor = d.m.shear_modulus() * diagonal * diagonal;
  const double pressure_row_scale = volumetric_modulus(d.m) / diagonal;
  const auto relative = [&](const Eigen::VectorXd& R) {
    double held = 0.0;
    for (int k : state.held.dofs) held += R[k] * R[k];
    const double scale = std::max({state.forces.norm(), std::sqrt(held), floor});
    Eigen::VectorXd free = split.restrict(R);
    free.tail(d.pressure.count) *= pressure_row_scale;  // the pressures are never held
    return free.norm() / scale;
  };
  // The total potential energy: strain energy less the dead loads' work.
  const auto potential = [&](const Eigen::VectorXd& at) {
    return energy_of(d, at) - state.forces.dot(at.head(n));
  };
  bool valid = true;
  Eigen::VectorXd R = residual(x, &valid);
  if (!valid) return "an element is inverted at the step's start";
  for (int it = 0;; ++it) {
    const double norm = relative(R);
    solution->relative_residual = norm;
    if (!std::isfinite(norm)) return "the residual is not finite";
    if (norm <= options.tolerance) {
      *internal = R;
      internal->head(n) += state.forces;
      return {};
    }
    if (cancel_requested()) return "interrupted";
    if (it == options.max_iterations) {
      std::ostringstream out;
      out << "no convergence in " << it << " Newton iterations (relative residual " << norm << ")";
      return out.str();
    }
    Eigen::VectorXd dx_free;
    const linalg::Status status =
        solve_tangent(split.free_block(tangent_of(d, x)), -split.restrict(R), &dx_free);
    if (!status.ok) return status.message;
    Eigen::VectorXd dx = Eigen::VectorXd::Zero(x.size());
    split.scatter(dx_free, dx);
    // Backtracking. The loads are dead and the solid hyperelastic, so the
    // step is judged by the total potential energy (Armijo) where it descends
    // it: a bending body's first Newton step overshoots the residual but not
    // the energy (10 times fewer iterations on a bending cylinder). Where the
    // tangent is indefinite, and in the mixed form (a saddle point, not a
    // minimum), by the residual norm alone.
    const double slope = split.restrict(R).dot(dx_free);  // dPi/dalpha at 0
    const bool by_energy = !d.mixed() && slope < 0.0;
    const double energy = by_energy ? potential(x) : 0.0;
    double alpha = 1.0;
    for (int halving = 0;; ++halving) {
      const Eigen::VectorXd trial = x + alpha * dx;
      bool trial_valid = true;
      const Eigen::VectorXd R_trial = residual(trial, &trial_valid);
      // (The residual's decrease is accepted too: near the solution the
      // energy's change is below its rounding.)
      const bool decrease =
          trial_valid && ((by_energy && potential(trial) <= energy + 1e-4 * alpha * slope) ||
                          relative(R_trial) <= (1.0 - 1e-4 * alpha) * norm);
      if (decrease) {
        x = trial;
        R = R_trial;
        break;
      }
      if (cancel_requested()) return "interrupted";
      if (halving == 30)
        return by_energy ? "the line search found no decrease of the energy"
                         : "the line search found no decrease of the residual";
      alpha *= 0.5;
    }
    ++solution->newton_iterations;
  }
}

// A piece's first iterate: from the last equilibrium x0 (internal forces
// internal0) along its tangent,
// K_ff dx_f = (f - f_int(x0))_f - K_fh dx_h for the held values' change dx_h
// and the loads' (Wriggers, "Nonlinear finite element methods", 2008,
// section 5.1: the tangent predictor). The free nodes then move with the
// held ones, where holding them still would leave the elements beside the
// held nodes to take the whole change: a nearly incompressible tube twisted
// in 4 steps took hundreds of damped Newton iterations so. The plain guess
// (the held values set, the rest kept) where the tangent cannot be solved or
// its prediction turns an element over.
Eigen::VectorXd predicted_start(const Discretization& d, const LoadState& state,
                                const FreeUnknowns& split, const Eigen::VectorXd& x0,
                                const Eigen::VectorXd& internal0) {
  Eigen::VectorXd plain = x0, held_change = Eigen::VectorXd::Zero(x0.size());
  for (size_t k = 0; k < state.held.dofs.size(); ++k) {
    const int i = state.held.dofs[k];
    plain[i] = state.held.values[k];
    held_change[i] = state.held.values[k] - x0[i];
  }
  const Eigen::SparseMatrix<double> K = tangent_of(d, x0);
  Eigen::VectorXd unbalanced = -internal0;
  unbalanced.head(d.mesh.num_dofs()) += state.forces;
  Eigen::VectorXd dx_free;
  if (!solve_tangent(split.free_block(K), split.restrict(unbalanced - K * held_change), &dx_free)
           .ok)
    return plain;
  Eigen::VectorXd dx = Eigen::VectorXd::Zero(x0.size());
  split.scatter(dx_free, dx);
  const Eigen::VectorXd predicted = plain + dx;
  bool valid = true;
  forces_of(d, predicted, &valid);
  return valid && dx.allFinite() ? predicted : plain;
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
  const PointState s = point_state(m, F);
  if (!(s.J > 0.0)) return std::numeric_limits<double>::infinity();
  return shape_energy(m, F, s.J) + 0.5 * volumetric_modulus(m) * s.theta.value * s.theta.value;
}

Eigen::Matrix3d first_piola_stress(const HyperelasticMaterial& m, const Eigen::Matrix3d& F) {
  const PointState s = point_state(m, F);
  if (!(s.J > 0.0)) return Eigen::Matrix3d::Constant(kNaN);
  return stress(m, s, volumetric_modulus(m) * s.theta.value);
}

Eigen::Matrix<double, 9, 9> stress_tangent(const HyperelasticMaterial& m,
                                           const Eigen::Matrix3d& F) {
  Eigen::Matrix<double, 9, 9> A;
  const PointState s = point_state(m, F);
  if (!(s.J > 0.0)) return A.setConstant(kNaN);
  // p = k theta(J) moves with F too: dp/dF = k theta' J G, times P's theta' J G.
  const double k = volumetric_modulus(m);
  const Eigen::Matrix3d JG = s.theta.slope * s.J * s.G;
  const Eigen::Map<const Eigen::Matrix<double, 9, 1>> JG_flat(JG.data());
  return tangent_at_fixed_pressure(m, s, k * s.theta.value) + k * JG_flat * JG_flat.transpose();
}

Eigen::VectorXd internal_forces(const Mesh& mesh, const HyperelasticMaterial& m,
                                const Eigen::VectorXd& u, bool* valid) {
  return forces_of(discretize(mesh, m, false), u, valid);
}

Eigen::SparseMatrix<double> tangent_stiffness(const Mesh& mesh, const HyperelasticMaterial& m,
                                              const Eigen::VectorXd& u) {
  return tangent_of(discretize(mesh, m, false), u);
}

double total_strain_energy(const Mesh& mesh, const HyperelasticMaterial& m,
                           const Eigen::VectorXd& u) {
  return energy_of(discretize(mesh, m, false), u);
}

linalg::Status solve_hyperelastic(const Mesh& mesh, const HyperelasticMaterial& m,
                                  const LoadPath& path, const HyperelasticOptions& options,
                                  HyperelasticSolution* solution) {
  check_tetrahedra(mesh);
  if (options.steps < 1) return linalg::Status::failure("fem: steps must be at least 1");
  const Discretization d = discretize(mesh, m, options.mixed);
  const int n = mesh.num_dofs();
  *solution = HyperelasticSolution{};
  Eigen::VectorXd x = Eigen::VectorXd::Zero(d.unknowns());  // u, then the pressures
  LoadState done = path(1);  // the state at load factor 0: no forces, held at 0
  done.forces.setZero();
  for (double& value : done.held.values) value = 0.0;
  for (int k : done.held.dofs)
    if (k < 0 || k >= n) return linalg::Status::failure("fem: a held unknown is out of range");
  const FreeUnknowns split(d.unknowns(), done.held.dofs);
  Eigen::VectorXd internal = forces_of(d, x, nullptr);  // at x, the last equilibrium
  const auto keep = [&] {
    solution->u = x.head(n);
    solution->pressure = x.tail(d.pressure.count);
    solution->forces = internal.head(n);
  };
  keep();

  for (int step = 1; step <= options.steps; ++step) {
    const LoadState target = path(step);
    if (target.held.dofs != done.held.dofs || target.forces.size() != n)
      return linalg::Status::failure("fem: step " + std::to_string(step) +
                                     ": the held unknowns or the force vector changed");
    // Advance from `done` to `target` in pieces, halving a piece that fails.
    double reached = 0.0, piece = 1.0;
    int cuts = 0;
    while (reached < 1.0) {
      const double s = std::min(1.0, reached + piece);
      const LoadState state = interpolate(done, target, s);
      Eigen::VectorXd trial = predicted_start(d, state, split, x, internal);
      const std::string why = newton(d, state, split, options, trial, solution, &internal);
      if (why.empty()) {
        x = trial;
        keep();
        reached = s;
        continue;
      }
      if (cuts == options.max_step_cuts || cancel_requested())
        return linalg::Status::failure("fem: step " + std::to_string(step) + ": " + why +
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

linalg::Status solve_small_strain(const Mesh& mesh, const HyperelasticMaterial& m,
                                  const LoadState& state, const HyperelasticOptions& options,
                                  HyperelasticSolution* solution) {
  const Discretization d = discretize(mesh, m, options.mixed);
  const int n = mesh.num_dofs();
  for (int k : state.held.dofs)
    if (k < 0 || k >= n) return linalg::Status::failure("fem: a held unknown is out of range");
  if (state.forces.size() != n) return linalg::Status::failure("fem: one force per unknown needed");
  const FreeUnknowns split(d.unknowns(), state.held.dofs);
  Eigen::VectorXd x = Eigen::VectorXd::Zero(d.unknowns()), held = x;
  for (size_t k = 0; k < state.held.dofs.size(); ++k)
    held[state.held.dofs[k]] = state.held.values[k];
  const Eigen::SparseMatrix<double> K = tangent_of(d, x);
  Eigen::VectorXd f = Eigen::VectorXd::Zero(d.unknowns());
  f.head(n) = state.forces;
  Eigen::VectorXd free;
  const linalg::Status status =
      solve_tangent(split.free_block(K), split.restrict(f - K * held), &free);
  if (!status.ok) return linalg::Status::failure("fem: " + status.message);
  x = held;
  split.scatter(free, x);
  *solution = HyperelasticSolution{};
  solution->u = x.head(n);
  solution->pressure = x.tail(d.pressure.count);
  solution->forces = (K * x).head(n);
  solution->path.push_back(solution->u);
  return {};
}

}  // namespace fiberfluid::fem

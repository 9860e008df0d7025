// SPDX-License-Identifier: GPL-3.0-or-later
#include "fem/dynamics.hpp"

#include <cmath>
#include <sstream>

#include "fem/free_unknowns.hpp"
#include "solve/sparse_cholesky.hpp"

namespace fiberfluid::fem {
namespace {

using Sparse = Eigen::SparseMatrix<double>;

Sparse diagonal(const Eigen::VectorXd& d) {
  Sparse D(d.size(), d.size());
  D.reserve(Eigen::VectorXi::Ones(d.size()));
  for (Eigen::Index i = 0; i < d.size(); ++i) D.insert(i, i) = d[i];
  return D;
}

// Solves A_ff x_f = r_f: a division for a diagonal A, CHOLMOD otherwise.
class FreeSolve {
 public:
  FreeSolve(const Sparse& A, const FreeUnknowns& split, bool is_diagonal) {
    if (is_diagonal) {
      diagonal_ = split.restrict(A.diagonal());
      ok_ = (diagonal_.array() > 0.0).all();
      return;
    }
    const Sparse block = split.free_block(A);
    cholesky_.analyze_pattern(block);
    ok_ = cholesky_.factorize(block).ok;
  }
  bool ok() const { return ok_; }
  Eigen::VectorXd solve(const Eigen::VectorXd& rhs_free) const {
    return diagonal_.size() > 0 ? Eigen::VectorXd(rhs_free.cwiseQuotient(diagonal_))
                                : cholesky_.solve(rhs_free);
  }

 private:
  Eigen::VectorXd diagonal_;
  solve::SparseCholesky cholesky_;
  bool ok_ = false;
};

}  // namespace

const char* to_string(Integrator integrator) {
  switch (integrator) {
    case Integrator::ImplicitNewmark: return "implicit-newmark";
    case Integrator::ExplicitConsistent: return "explicit";
    case Integrator::ExplicitLumped: return "explicit-lumped";
    case Integrator::ImplicitLumped: return "implicit-lumped";
    case Integrator::QuasiStatic: return "quasi-static";
  }
  return "?";
}

Dynamics make_dynamics(const Mesh& mesh, const Material& material, double alpha, double beta) {
  Dynamics d;
  d.K = stiffness_matrix(mesh, material);
  d.M = mass_matrix(mesh, material);
  d.lumped = d.M * Eigen::VectorXd::Ones(d.M.cols());  // lumped_mass without a second assembly
  d.alpha = alpha;
  d.beta = beta;
  return d;
}

double mechanical_energy(const Dynamics& d, const Eigen::VectorXd& u, const Eigen::VectorXd& v) {
  return 0.5 * v.dot(d.M * v) + 0.5 * u.dot(d.K * u);
}

Trajectory integrate(const Dynamics& d, Integrator integrator, double h, int steps) {
  const int n = static_cast<int>(d.K.rows());
  Trajectory out;
  for (int dof : d.held)
    if (dof < 0 || dof >= n) {
      out.ok = false;
      out.message = "fem: a held unknown is out of range";
      return out;
    }
  const FreeUnknowns split(n, d.held);
  auto force = [&](double t) { return d.force ? d.force(t) : Eigen::VectorXd(Eigen::VectorXd::Zero(n)); };
  auto held_at = [&](double t) {
    Eigen::VectorXd values = d.held_values ? d.held_values(t)
                                           : Eigen::VectorXd(Eigen::VectorXd::Zero(static_cast<Eigen::Index>(d.held.size())));
    return values;
  };
  auto fail = [&](double t, const std::string& why) {
    std::ostringstream message;
    message << to_string(integrator) << " at t = " << t << " s: " << why;
    out.ok = false;
    out.message = message.str();
    return out;
  };
  Eigen::VectorXd u = Eigen::VectorXd::Zero(n), v = Eigen::VectorXd::Zero(n);
  out.times.push_back(0.0);
  out.u.push_back(u);
  out.v.push_back(v);

  if (integrator == Integrator::QuasiStatic) {
    Constraints held;
    for (int s = 1; s <= steps; ++s) {
      const double t = s * h;
      held.dofs = d.held;
      const Eigen::VectorXd values = held_at(t);
      held.values.assign(values.data(), values.data() + values.size());
      const Eigen::VectorXd previous = u;
      const solve::Status status = solve_static(d.K, force(t), held, &u);
      if (!status.ok) return fail(t, status.message);
      out.times.push_back(t);
      out.u.push_back(u);
      out.v.push_back((u - previous) / h);
    }
    return out;
  }

  const bool lumped = integrator == Integrator::ExplicitLumped || integrator == Integrator::ImplicitLumped;
  const bool implicit = integrator == Integrator::ImplicitNewmark || integrator == Integrator::ImplicitLumped;
  const double b = implicit ? 0.5 : 0.0, g = 0.5;  // the paper's Newmark parameters
  const Sparse M = lumped ? diagonal(d.lumped) : d.M;
  // Explicit-lumped damps with a diagonal too, so that nothing needs a solve.
  const Sparse C = integrator == Integrator::ExplicitLumped
                       ? diagonal(d.alpha * d.lumped + d.beta * Eigen::VectorXd(d.K.diagonal()))
                       : Sparse(d.alpha * M + d.beta * d.K);
  const Sparse A = M + (g * h) * C + (b * h * h / 2.0) * d.K;
  const FreeSolve step_solve(A, split, integrator == Integrator::ExplicitLumped);
  const FreeSolve mass_solve(M, split, lumped);
  if (!step_solve.ok() || !mass_solve.ok()) return fail(0.0, "the step matrix is not positive definite");

  // a at rest: M a = f(0) on the free unknowns; the held ones start at rest.
  Eigen::VectorXd a = Eigen::VectorXd::Zero(n);
  split.scatter(mass_solve.solve(split.restrict(force(0.0))), a);

  for (int s = 1; s <= steps; ++s) {
    const double t = s * h;
    const Eigen::VectorXd u_pred = u + h * v + ((1.0 - b) * h * h / 2.0) * a;
    const Eigen::VectorXd v_pred = v + ((1.0 - g) * h) * a;
    // The held unknowns' accelerations: those that reach their path at t.
    Eigen::VectorXd a_next = Eigen::VectorXd::Zero(n);
    const Eigen::VectorXd target = held_at(t);
    for (size_t k = 0; k < d.held.size(); ++k) {
      const int dof = d.held[k];
      a_next[dof] = b > 0.0 ? (target[static_cast<Eigen::Index>(k)] - u_pred[dof]) / (b * h * h / 2.0)
                            : 2.0 * (target[static_cast<Eigen::Index>(k)] - u[dof] - h * v[dof]) / (h * h);
    }
    const Eigen::VectorXd rhs = force(t) - C * v_pred - d.K * u_pred - A * a_next;
    split.scatter(step_solve.solve(split.restrict(rhs)), a_next);
    a = a_next;
    u = u_pred + (b * h * h / 2.0) * a;
    v = v_pred + (g * h) * a;
    for (size_t k = 0; k < d.held.size(); ++k) u[d.held[k]] = target[static_cast<Eigen::Index>(k)];
    if (!u.allFinite() || !v.allFinite()) return fail(t, "the state is no longer finite (diverged)");
    if (u.cwiseAbs().maxCoeff() > d.divergence_scale)
      return fail(t, "a displacement exceeds the divergence scale (diverged)");
    out.times.push_back(t);
    out.u.push_back(u);
    out.v.push_back(v);
  }
  return out;
}

}  // namespace fiberfluid::fem

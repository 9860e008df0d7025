// SPDX-License-Identifier: GPL-3.0-or-later
#include "fiberfluid/fem/dynamics.hpp"

#include <cmath>
#include <sstream>
#include <utility>

#include "fiberfluid/fem/free_unknowns.hpp"
#include "fiberfluid/linalg/sparse_cholesky.hpp"
#include "fiberfluid/util/run_control.hpp"

namespace fiberfluid::fem {
namespace {

using Sparse = Eigen::SparseMatrix<double>;

Sparse diagonal(const Eigen::VectorXd& d) {
  Sparse D(d.size(), d.size());
  D.reserve(Eigen::VectorXi::Ones(d.size()));
  for (Eigen::Index i = 0; i < d.size(); ++i) D.insert(i, i) = d[i];
  return D;
}

// Gauss-Seidel sweeps on a symmetric positive definite matrix (stored by
// rows), from x, until |b - A x| <= tolerance |b|. Returns the sweeps taken,
// or -1 when max_sweeps were not enough.
int gauss_seidel(const Eigen::SparseMatrix<double, Eigen::RowMajor>& A, const Eigen::VectorXd& b,
                 const IntegrationOptions& options, Eigen::VectorXd& x) {
  const double target = options.tolerance * b.norm();
  for (int sweep = 0; sweep <= options.max_sweeps; ++sweep) {
    if ((b - A * x).norm() <= target) return sweep;
    for (Eigen::Index r = 0; r < A.outerSize(); ++r) {
      double sum = b[r], diagonal = 0.0;
      for (Eigen::SparseMatrix<double, Eigen::RowMajor>::InnerIterator it(A, r); it; ++it) {
        if (it.col() == r)
          diagonal = it.value();
        else
          sum -= it.value() * x[it.col()];
      }
      x[r] = sum / diagonal;
    }
  }
  return -1;
}

// Solves A_ff x_f = r_f: a division for a diagonal A, else CHOLMOD or
// Gauss-Seidel (warm-started from the last solution).
class FreeSolve {
 public:
  FreeSolve(const Sparse& A, const FreeUnknowns& split, bool is_diagonal,
            const IntegrationOptions& options)
      : options_(options) {
    if (is_diagonal) {
      diagonal_ = split.restrict(A.diagonal());
      ok_ = (diagonal_.array() > 0.0).all();
      return;
    }
    const Sparse block = split.free_block(A);
    if (options.linear == LinearMethod::GaussSeidel) {
      by_rows_ = block;
      ok_ = (block.diagonal().array() > 0.0).all();
      last_ = Eigen::VectorXd::Zero(block.rows());
      return;
    }
    cholesky_.analyze_pattern(block);
    ok_ = cholesky_.factorize(block).ok;
  }
  bool ok() const { return ok_; }
  long long sweeps() const { return sweeps_; }
  // False when Gauss-Seidel did not converge.
  bool solve(const Eigen::VectorXd& rhs_free, Eigen::VectorXd* x) {
    if (diagonal_.size() > 0) {
      *x = rhs_free.cwiseQuotient(diagonal_);
    } else if (by_rows_.rows() > 0) {
      const int taken = gauss_seidel(by_rows_, rhs_free, options_, last_);
      if (taken < 0) return false;
      sweeps_ += taken;
      *x = last_;
    } else {
      *x = cholesky_.solve(rhs_free);
    }
    return true;
  }

 private:
  IntegrationOptions options_;
  Eigen::VectorXd diagonal_, last_;
  Eigen::SparseMatrix<double, Eigen::RowMajor> by_rows_;
  linalg::SparseCholesky cholesky_;
  bool ok_ = false;
  long long sweeps_ = 0;
};

}  // namespace

const char* to_string(LinearMethod method) {
  return method == LinearMethod::GaussSeidel ? "gauss-seidel" : "cholesky";
}

const char* to_string(Integrator integrator) {
  switch (integrator) {
    case Integrator::ImplicitNewmark:
      return "implicit-newmark";
    case Integrator::ExplicitConsistent:
      return "explicit";
    case Integrator::ExplicitLumped:
      return "explicit-lumped";
    case Integrator::ImplicitLumped:
      return "implicit-lumped";
    case Integrator::QuasiStatic:
      return "quasi-static";
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

namespace {

// The external force at time t (zero when the scene has none).
Eigen::VectorXd force_at(const Dynamics& d, double t) {
  return d.force ? d.force(t) : Eigen::VectorXd(Eigen::VectorXd::Zero(d.K.rows()));
}

// The held unknowns' values at time t, in d.held's order.
Eigen::VectorXd held_values_at(const Dynamics& d, double t) {
  return d.held_values
             ? d.held_values(t)
             : Eigen::VectorXd(Eigen::VectorXd::Zero(static_cast<Eigen::Index>(d.held.size())));
}

// The trajectory so far, stopped at t for `why`.
Trajectory stopped(Trajectory out, Integrator integrator, double t, const std::string& why) {
  std::ostringstream message;
  message << to_string(integrator) << " at t = " << t << " s: " << why;
  out.ok = false;
  out.message = message.str();
  return out;
}

// The quasi-static sequence: K_ff u_f = f_f - K_fh u_h at each step, the
// velocity the difference of two steps.
Trajectory integrate_quasi_static(const Dynamics& d, const FreeUnknowns& split, double h, int steps,
                                  const IntegrationOptions& options, Trajectory out) {
  const int n = static_cast<int>(d.K.rows());
  Eigen::VectorXd u = out.u.back();
  auto fail = [&](double t, const std::string& why) {
    return stopped(out, Integrator::QuasiStatic, t, why);
  };
  auto force = [&](double t) { return force_at(d, t); };
  auto held_at = [&](double t) { return held_values_at(d, t); };
  const std::string no_convergence =
      "Gauss-Seidel did not converge in " + std::to_string(options.max_sweeps) + " sweeps";
  FreeSolve stiffness_solve(d.K, split, false, options);
  if (!stiffness_solve.ok())
    return fail(0.0, "the stiffness is singular on the free unknowns (too few supports?)");
  Eigen::VectorXd free_u;
  for (int s = 1; s <= steps; ++s) {
    const double t = s * h;
    if (cancel_requested()) return fail(t, "interrupted");
    const Eigen::VectorXd previous = u, target = held_at(t);
    Eigen::VectorXd fixed = Eigen::VectorXd::Zero(n);
    for (size_t k = 0; k < d.held.size(); ++k)
      fixed[d.held[k]] = target[static_cast<Eigen::Index>(k)];
    if (!stiffness_solve.solve(split.restrict(force(t) - d.K * fixed), &free_u))
      return fail(t, no_convergence);
    u = fixed;
    split.scatter(free_u, u);
    out.times.push_back(t);
    out.u.push_back(u);
    out.v.push_back((u - previous) / h);
  }
  out.sweeps = stiffness_solve.sweeps();
  return out;
}

}  // namespace

Trajectory integrate(const Dynamics& d, Integrator integrator, double h, int steps,
                     const IntegrationOptions& options) {
  const int n = static_cast<int>(d.K.rows());
  Trajectory out;
  for (int dof : d.held)
    if (dof < 0 || dof >= n) {
      out.ok = false;
      out.message = "fem: a held unknown is out of range";
      return out;
    }
  const FreeUnknowns split(n, d.held);
  auto force = [&](double t) { return force_at(d, t); };
  auto held_at = [&](double t) { return held_values_at(d, t); };
  auto fail = [&](double t, const std::string& why) { return stopped(out, integrator, t, why); };
  Eigen::VectorXd u = Eigen::VectorXd::Zero(n), v = Eigen::VectorXd::Zero(n);
  out.times.push_back(0.0);
  out.u.push_back(u);
  out.v.push_back(v);

  const std::string no_convergence =
      "Gauss-Seidel did not converge in " + std::to_string(options.max_sweeps) + " sweeps";
  if (integrator == Integrator::QuasiStatic)
    return integrate_quasi_static(d, split, h, steps, options, std::move(out));
  const bool lumped =
      integrator == Integrator::ExplicitLumped || integrator == Integrator::ImplicitLumped;
  const bool implicit =
      integrator == Integrator::ImplicitNewmark || integrator == Integrator::ImplicitLumped;
  const double b = implicit ? 0.5 : 0.0, g = 0.5;  // the paper's Newmark parameters
  const Sparse M = lumped ? diagonal(d.lumped) : d.M;
  const Sparse C = d.alpha * M + d.beta * d.K;
  // M a+ + C (v_pred + g h a+) + K (u_pred + b h^2/2 a+) = f+. Explicit-lumped
  // needs no solve: its stiffness-proportional damping acts at the predicted
  // velocity (explicitly), its mass-proportional part at the new one.
  const Sparse A = integrator == Integrator::ExplicitLumped
                       ? diagonal((1.0 + g * h * d.alpha) * d.lumped)
                       : Sparse(M + (g * h) * C + (b * h * h / 2.0) * d.K);
  FreeSolve step_solve(A, split, integrator == Integrator::ExplicitLumped, options);
  FreeSolve mass_solve(M, split, lumped, options);
  if (!step_solve.ok() || !mass_solve.ok())
    return fail(0.0, "the step matrix is not positive definite");

  // a at rest: M a = f(0) on the free unknowns; the held ones start at rest.
  Eigen::VectorXd a = Eigen::VectorXd::Zero(n), free_a;
  if (!mass_solve.solve(split.restrict(force(0.0)), &free_a)) return fail(0.0, no_convergence);
  split.scatter(free_a, a);

  for (int s = 1; s <= steps; ++s) {
    const double t = s * h;
    if (cancel_requested()) return fail(t, "interrupted");
    const Eigen::VectorXd u_pred = u + h * v + ((1.0 - b) * h * h / 2.0) * a;
    const Eigen::VectorXd v_pred = v + ((1.0 - g) * h) * a;
    // The held unknowns' accelerations: those that reach their path at t.
    Eigen::VectorXd a_next = Eigen::VectorXd::Zero(n);
    const Eigen::VectorXd target = held_at(t);
    for (size_t k = 0; k < d.held.size(); ++k) {
      const int dof = d.held[k];
      a_next[dof] =
          b > 0.0 ? (target[static_cast<Eigen::Index>(k)] - u_pred[dof]) / (b * h * h / 2.0)
                  : 2.0 * (target[static_cast<Eigen::Index>(k)] - u[dof] - h * v[dof]) / (h * h);
    }
    const Eigen::VectorXd rhs = force(t) - C * v_pred - d.K * u_pred - A * a_next;
    if (!step_solve.solve(split.restrict(rhs), &free_a)) return fail(t, no_convergence);
    split.scatter(free_a, a_next);
    a = a_next;
    u = u_pred + (b * h * h / 2.0) * a;
    v = v_pred + (g * h) * a;
    for (size_t k = 0; k < d.held.size(); ++k) u[d.held[k]] = target[static_cast<Eigen::Index>(k)];
    if (!u.allFinite() || !v.allFinite())
      return fail(t, "the state is no longer finite (diverged)");
    if (u.cwiseAbs().maxCoeff() > d.divergence_scale)
      return fail(t, "a displacement exceeds the divergence scale (diverged)");
    out.times.push_back(t);
    out.u.push_back(u);
    out.v.push_back(v);
  }
  out.sweeps = step_solve.sweeps() + mass_solve.sweeps();
  return out;
}

}  // namespace fiberfluid::fem

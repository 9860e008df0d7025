// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once

// Time integration of M a + C v + K u = f(t), Rayleigh damping C = alpha M +
// beta K, with the integrators the benchmarks paper compares (docs:
// benchmarks.md; its Newmark convention u+ = u + h v + (1 - b) h^2/2 a +
// b h^2/2 a+, v+ = v + (1 - g) h a + g h a+):
//  - ImplicitNewmark: b = g = 1/2 (the paper's reference; average acceleration);
//  - ExplicitConsistent: b = 0, g = 1/2 with the consistent mass (a solve
//    with M + h C / 2 per step);
//  - ExplicitLumped: b = 0, g = 1/2 with the lumped mass: no linear solve.
//    Its damping alpha M_L + beta K uses the full K: the mass-proportional
//    part acts at the new velocity, the stiffness-proportional part at the
//    predicted one (explicitly, a product with K);
//  - ImplicitLumped: b = g = 1/2 with the lumped mass;
//  - QuasiStatic: K u+ = f+, no history.
// Prescribed unknowns follow a given path u_h(t); their accelerations are
// the ones the integrator's update needs to reach it.

#include <Eigen/Core>
#include <Eigen/SparseCore>
#include <functional>
#include <limits>
#include <string>
#include <vector>

#include "fiberfluid/fem/fem.hpp"

namespace fiberfluid::fem {

enum class Integrator {
  ImplicitNewmark,
  ExplicitConsistent,
  ExplicitLumped,
  ImplicitLumped,
  QuasiStatic
};
const char* to_string(Integrator integrator);

struct Dynamics {
  Eigen::SparseMatrix<double> K, M;                    // stiffness and consistent mass
  Eigen::VectorXd lumped;                              // the lumped mass (row sums of M)
  double alpha = 0.0, beta = 0.0;                      // Rayleigh damping
  std::function<Eigen::VectorXd(double)> force;        // f(t), #dofs; empty: none
  std::vector<int> held;                               // prescribed unknowns
  std::function<Eigen::VectorXd(double)> held_values;  // u at the held unknowns at t; empty: 0
  // A displacement larger than this (e.g. ten times the body's size) means
  // the integration diverged.
  double divergence_scale = std::numeric_limits<double>::infinity();
};

// How the integrators solve their linear systems: a sparse Cholesky
// factorisation once (CHOLMOD), or the paper's Gauss-Seidel sweeps every
// step, warm-started from the last solution, until the residual falls below
// `tolerance` relative to the right-hand side (to show what it costs).
enum class LinearMethod { Cholesky, GaussSeidel };
const char* to_string(LinearMethod method);

struct IntegrationOptions {
  LinearMethod linear = LinearMethod::Cholesky;
  double tolerance = 1e-10;
  int max_sweeps = 100000;  // per solve; more is a failure
};

struct Trajectory {
  bool ok = true;
  std::string message;                // why it stopped (diverged, singular)
  std::vector<double> times;          // 0, h, 2h, ...
  std::vector<Eigen::VectorXd> u, v;  // per time
  long long sweeps = 0;               // Gauss-Seidel sweeps in all (0 with Cholesky)
};

// The matrices of a mesh and material with Rayleigh damping; no loads, no
// held unknowns yet.
Dynamics make_dynamics(const Mesh& mesh, const Material& material, double alpha, double beta);

// From rest (u = v = 0, a from the equation at t = 0), `steps` steps of h.
// Stops with ok = false, naming the time, when the state stops being finite
// or a displacement exceeds divergence_scale (diverged).
// Stops, naming the time, when Gauss-Seidel does not reach its tolerance.
Trajectory integrate(const Dynamics& d, Integrator integrator, double h, int steps,
                     const IntegrationOptions& options = {});

// Total mechanical energy 1/2 v^T M v + 1/2 u^T K u (consistent mass).
double mechanical_energy(const Dynamics& d, const Eigen::VectorXd& u, const Eigen::VectorXd& v);

}  // namespace fiberfluid::fem

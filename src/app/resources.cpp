// SPDX-License-Identifier: GPL-3.0-or-later
#include "app/resources.hpp"

#include <sys/resource.h>

#include <algorithm>
#include <cstdio>
#include <sstream>

#include "app/case_spec.hpp"
#include "geom/error.hpp"
#include "geom/run_control.hpp"

namespace fiberfluid::app {
namespace {

// Typical counts where the work depends on the data (from the scaling and
// Newton benchmarks): PCG iterations per solve, Newton iterations per load
// step, GMRES products per Newton iteration.
constexpr double kPcgIterations = 60.0;
constexpr double kNewtonIterations = 4.0;
constexpr double kKrylovProducts = 20.0;
// Per vertex: the surface, area vectors, unknowns, residuals, outputs.
constexpr double kBytesPerVertex = 4096.0;

// The three axis blocks share one factor when every axis is held alike and
// the material is isotropic (FiberSystem::blocks_equal).
bool blocks_may_be_equal(const CaseSpec& spec) {
  const Eigen::VectorXd& f = spec.material.per_axis;
  if (f.size() > 0 && (f.array() != f[0]).any()) return false;
  for (const ConstraintSpec& c : spec.constraints)
    if (!c.prescribed && !c.axes.empty() && c.axes.size() < 2) return false;
  return true;
}

solve::SolverKind choose(const CaseSpec& spec, double n, int factors) {
  if (spec.stepping.solver != solve::SolverKind::Auto) return spec.stepping.solver;
  if (n <= 600) return solve::SolverKind::DenseLU;  // as solve::choose_solver
  if (8.0 * n * n * (factors + 1) < 0.375 * memory_budget_bytes())
    return solve::SolverKind::BlockCholesky;
  return solve::SolverKind::PCG;
}

std::string seconds_text(double s) {
  char buffer[32];
  if (s < 1.0) std::snprintf(buffer, sizeof buffer, "%.2g s", s);
  else if (s < 120.0) std::snprintf(buffer, sizeof buffer, "%.0f s", s);
  else if (s < 7200.0) std::snprintf(buffer, sizeof buffer, "%.0f min", s / 60.0);
  else std::snprintf(buffer, sizeof buffer, "%.1f h", s / 3600.0);
  return buffer;
}

}  // namespace

std::string ResourceEstimate::describe() const {
  std::ostringstream out;
  out << "about " << format_bytes(peak_bytes) << " and " << seconds_text(seconds) << " (";
  bool first = true;
  for (const ResourcePart& p : parts) {
    if (p.seconds < 0.005 * seconds && p.bytes < 0.05 * peak_bytes) continue;
    out << (first ? "" : ", ") << p.name << " " << seconds_text(p.seconds);
    if (p.bytes >= 0.05 * peak_bytes) out << " / " << format_bytes(p.bytes);
    first = false;
  }
  out << "; " << solver << ")";
  return out.str();
}

ResourceEstimate estimate_resources(const CaseSpec& spec, const geom::Surface& surface,
                                    bool concave, const KernelSpeed& speed) {
  ResourceEstimate e;
  const double N = surface.num_vertices(), d = surface.dim;
  const double pairs = 0.5 * N * (N - 1.0), n_unknowns = d * N + 1.0;
  const solve::SteppingOptions& o = spec.stepping;
  const double steps = o.steps;

  e.parts.push_back({"model", kBytesPerVertex * N, 0.0, true});
  if (spec.fibers.pruning)  // N x F orientation tests when convex; a concave body stops early
    e.parts.push_back({"convexity check", 0.0,
                       N * surface.num_faces() / speed.orientation_tests_per_second});
  if (concave)  // an N x N byte table, kept for the solvers; an AABB tree per thread
    e.parts.push_back({"pruning", N * N + 400.0 * surface.num_faces(),
                       pairs / speed.prune_pairs_per_second, true});

  const int factors = blocks_may_be_equal(spec) ? 1 : static_cast<int>(d);
  const double product = d * pairs / speed.pair_updates_per_second;  // K (or R) once
  const bool newton = o.scheme == solve::Scheme::Newton;
  const bool dense_tangent =
      newton && (o.newton.tangent == solve::TangentSolver::Dense ||
                 (o.newton.tangent == solve::TangentSolver::Auto && n_unknowns <= 600));
  const solve::SolverKind kind =
      dense_tangent ? solve::SolverKind::DenseLU : choose(spec, N, factors);
  e.solver = solve::to_string(kind);

  // One factorisation of the structured system (or the Newton preconditioner).
  ResourcePart factor{"factorisation", 0.0, 0.0};
  switch (kind) {
    case solve::SolverKind::DenseLU:
      factor.bytes = 2.0 * 8.0 * n_unknowns * n_unknowns;  // the matrix and its LU
      factor.seconds = 2.0 / 3.0 * n_unknowns * n_unknowns * n_unknowns /
                           speed.dense_flops_per_second + d * d * product;
      break;
    case solve::SolverKind::BlockCholesky:
      factor.bytes = 8.0 * N * N * (factors + 1);
      factor.seconds = factors * N * N * N / 3.0 / speed.dense_flops_per_second + product;
      break;
    case solve::SolverKind::Cholmod:  // dense bulk blocks: every pair a nonzero
      factor.bytes = d * (12.0 * N * N + 4.0 * N * N);
      factor.seconds = d * N * N * N / 3.0 / speed.sparse_flops_per_second + product;
      break;
    case solve::SolverKind::PCG:  // the surface-tension Laplacian's sparse factor
    case solve::SolverKind::Auto:
      factor.bytes = 64.0 * 40.0 * N;
      factor.seconds = 1e-6 * N;
      break;
  }
  const double solve_seconds = kind == solve::SolverKind::PCG
                                   ? kPcgIterations * product
                                   : d * 8.0 * N * N / speed.dense_flops_per_second;

  if (newton) {
    const double iterations = steps * kNewtonIterations;
    ResourcePart tangent{"newton iterations", 0.0, 0.0};
    if (dense_tangent) {
      tangent.bytes = factor.bytes;
      tangent.seconds = iterations * factor.seconds;
    } else {
      // The stored pair coefficients (when they fit a quarter of the
      // budget), the preconditioner refactored per step, GMRES products.
      const double stored = 2.0 * 8.0 * N * N;
      tangent.bytes = factor.bytes + (stored < 0.25 * memory_budget_bytes() ? stored : 0.0) +
                      8.0 * n_unknowns * (o.newton.krylov_restart + 2);
      tangent.seconds = steps * factor.seconds +
                        iterations * (kKrylovProducts * 3.0 * product + solve_seconds);
    }
    tangent.name = std::to_string(o.steps) + " Newton steps";
    e.parts.push_back(tangent);
  } else {
    const double factorizations = o.rebuild_matrix ? steps : 1.0;
    factor.seconds *= factorizations;
    if (o.rebuild_matrix) factor.name = std::to_string(o.steps) + " factorisations";
    e.parts.push_back(factor);
    const double per_step = solve_seconds + (o.measure_residual ? product : 0.0);
    e.parts.push_back({std::to_string(o.steps) + " load steps", 8.0 * n_unknowns * 8.0,
                       steps * per_step});
  }

  double kept = 0.0, largest = 0.0;
  for (const ResourcePart& p : e.parts) {
    e.seconds += p.seconds;
    if (p.kept) kept += p.bytes;
    else largest = std::max(largest, p.bytes);
  }
  e.peak_bytes = kept + largest;
  return e;
}

void require_within_budget(const ResourceEstimate& estimate, const CaseSpec& spec) {
  const double budget = memory_budget_bytes(), time_budget = time_budget_seconds();
  std::ostringstream why;
  if (estimate.peak_bytes > budget) {
    why << "this case needs " << estimate.describe() << ", more than the memory budget of "
        << format_bytes(budget);
    if (memory_budget_is_set()) why << " set by --max-memory; raise --max-memory";
    else why << " (80% of this machine's memory); --max-memory sets another budget";
    why << ", or use a coarser mesh";
    if (estimate.solver != "pcg") why << " or \"stepping\": {\"solver\": \"pcg\"} (memory O(N))";
  } else if (estimate.seconds > time_budget) {
    why << "this case would take " << estimate.describe() << ", more than --max-time "
        << seconds_text(time_budget) << "; raise --max-time or use a coarser mesh";
  } else {
    return;
  }
  const std::string variant = spec.variant.empty() ? "" : "variants." + spec.variant + ": ";
  throw InputError(spec.surface.field.file + ": " + variant + why.str());
}

double peak_resident_bytes() {
  rusage usage{};
  if (getrusage(RUSAGE_SELF, &usage) != 0) return 0.0;
  return 1024.0 * static_cast<double>(usage.ru_maxrss);  // Linux: kilobytes
}

}  // namespace fiberfluid::app

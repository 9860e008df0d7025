// SPDX-License-Identifier: GPL-3.0-or-later
#include "fiberfluid/experiment/run/resources.hpp"

#include <sys/resource.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>

#include "fiberfluid/experiment/spec/case_spec.hpp"
#include "fiberfluid/geom/fiber_mask.hpp"
#include "fiberfluid/model/treecode.hpp"
#include "fiberfluid/solve/cost_model.hpp"
#include "fiberfluid/util/error.hpp"
#include "fiberfluid/util/run_control.hpp"

namespace fiberfluid::experiment {
namespace {

// The treecode's bulk product (three columns): N log2 N times a factor per
// interpolation degree, measured at 163,842 vertices (README, treecode table).
double treecode_product_seconds(double N, double tolerance) {
  const int degree = model::TreecodeOptions::for_tolerance(tolerance).degree;
  const double per_unit = degree <= 3   ? 2.6e-7
                          : degree <= 4 ? 4.1e-7
                          : degree <= 6 ? 9.3e-7
                                        : 2.1e-6;
  return N * std::log2(std::max(N, 2.0)) * per_unit;
}

// Typical counts where the work depends on the data (scripts/resources.sh:
// the sphere's load steps and Newton steps): PCG iterations per solve, Newton
// iterations per load step, GMRES products per Newton iteration.
constexpr double kNewtonIterations = 2.5;
constexpr double kKrylovProducts = 6.0;
// A reused tangent LU ages over the steps between its factorisations: 9 to
// 16 GMRES products per Newton iteration (issue 42's specimens: the
// compressed cylinder 10 and 9, the bending phantoms 12 and 16).
constexpr double kReusedKrylovProducts = 12.0;
// The process itself (libraries, CGAL, OpenMP pools) and each vertex's
// surface, area vectors, unknowns, outputs.
constexpr double kProcessBytes = 20.0 * 1024 * 1024;
constexpr double kBytesPerVertex = 1024.0;
// The sparse tangent's LU: factor entries per tangent entry at 10,242
// vertices, and one measured factorisation (see sparse_tangent_cost).
constexpr double kSparseFillPerEntry = 12.0;
constexpr double kSparseFactorEntries = 2.76e7, kSparseFactorSeconds = 3.7;

// The sparse LU of a horizon's Newton tangent (UMFPACK): its entries are
// dim^2 (N + 2 pairs); the factors' fill grows as sqrt(N) and the flops as
// the fill^1.5, from a measurement at 10,242 vertices (a horizon of a tenth
// of the radius: 2.28 million entries, 27.6 million in L and U, 3.7 s).
// A solve with the factors reads them once (12 bytes an entry) at about
// 4 GB/s.
struct SparseTangentCost {
  double bytes, factor_seconds, solve_seconds;
};
SparseTangentCost sparse_tangent_cost(double N, double dim, double pairs) {
  const double entries = dim * dim * (N + 2.0 * pairs);
  const double factor_entries = kSparseFillPerEntry * entries * std::sqrt(N / 10242.0);
  return {12.0 * factor_entries + 3.0 * 16.0 * entries,
          kSparseFactorSeconds * std::pow(factor_entries / kSparseFactorEntries, 1.5),
          12.0 * factor_entries / 4e9};
}

solve::SolverKind choose(const model::Model& m, const solve::SteppingOptions& o,
                         const solve::BlockShape& b) {
  if (o.solver != solve::SolverKind::Auto) return o.solver;
  return solve::automatic_solver(m, b.largest, b.factors, memory_budget_bytes());
}

}  // namespace

std::string seconds_text(double s) {
  char buffer[32];
  if (s < 1.0)
    std::snprintf(buffer, sizeof buffer, "%.2g s", s);
  else if (s < 120.0)
    std::snprintf(buffer, sizeof buffer, "%.0f s", s);
  else if (s < 7200.0)
    std::snprintf(buffer, sizeof buffer, "%.0f min", s / 60.0);
  else
    std::snprintf(buffer, sizeof buffer, "%.1f h", s / 3600.0);
  return buffer;
}

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

namespace {

// What a case's sizes make each part cost.
struct CaseSize {
  double N = 0.0, d = 0.0;     // vertices, dimension
  double pairs = 0.0;          // fibers visited
  double unknowns = 0.0;       // d N + 1
  double steps = 0.0;          // load steps
  double product = 0.0;        // seconds of one product K v
  double residual = 0.0;       // seconds of one residual
  bool sparse_fibers = false;  // a horizon's lists
};

// The Newton steps with the tangent strategy chosen: its factorisations,
// iterations and (for the Krylov strategies) products and preconditioner.
ResourcePart newton_steps_cost(const solve::SteppingOptions& o, solve::TangentSolver tangent_kind,
                               const solve::BlockShape& blocks, const ResourcePart& factor,
                               double solve_seconds, const CaseSize& size,
                               const KernelSpeed& speed) {
  const double N = size.N, d = size.d, pairs = size.pairs, unknowns = size.unknowns,
               steps = size.steps, product = size.product, residual = size.residual;
  const bool sparse_fibers = size.sparse_fibers;
  const bool dense_tangent = tangent_kind == solve::TangentSolver::Dense;
  const bool sparse_tangent = tangent_kind == solve::TangentSolver::Sparse;
  const bool reused_tangent = tangent_kind == solve::TangentSolver::Reused;
  const bool reused_sparse = reused_tangent && sparse_fibers;
  const double iterations = steps * kNewtonIterations;
  ResourcePart tangent{std::to_string(o.steps) + " Newton steps", factor.bytes, 0.0};
  if (dense_tangent) {
    tangent.seconds = iterations * (factor.seconds + residual);
  } else if (sparse_tangent) {
    const SparseTangentCost c = sparse_tangent_cost(N, d, pairs);
    tangent.bytes = c.bytes;
    tangent.seconds = iterations * (c.factor_seconds + residual);
  } else {
    // The stored pair coefficients (when they fit a quarter of the
    // budget), the preconditioner once per step, GMRES products.
    const double stored = 2.0 * 8.0 * (sparse_fibers ? 2.0 * pairs : N * N);
    double factor_seconds = factor.seconds, preconditioner_solve = solve_seconds;
    const double krylov_products = reused_tangent ? kReusedKrylovProducts : kKrylovProducts;
    if (reused_tangent && !reused_sparse) {
      // Its factors rounded to single precision (where that serves, as on
      // every specimen measured): a solve reads 4 bytes an entry.
      const double m = blocks.newton_unknowns;
      preconditioner_solve = 4.0 * m * m / speed.factor_bytes_read_per_second;
    }
    if (reused_sparse) {
      const SparseTangentCost c = sparse_tangent_cost(N, d, pairs);
      tangent.bytes = c.bytes;
      factor_seconds = c.factor_seconds;
      preconditioner_solve = c.solve_seconds;
    }
    tangent.bytes += (stored < 0.25 * memory_budget_bytes() ? stored : 0.0) +
                     8.0 * unknowns * (o.newton.krylov_restart + 2);
    const double factorizations = reused_tangent ? 1.0 + 0.25 * steps : steps;
    tangent.seconds =
        factorizations * factor_seconds +
        iterations * (residual + krylov_products * (3.0 * product + preconditioner_solve));
  }
  return tangent;
}

}  // namespace

ResourceEstimate estimate_resources(const model::Model& model, const solve::SteppingOptions& o,
                                    PruningWork pruning, const KernelSpeed& speed) {
  ResourceEstimate e;
  const geom::Surface& surface = model.surface;
  const double N = surface.num_vertices(), d = surface.dim;
  // A horizon stored as neighbour lists: only its pairs are visited.
  const bool sparse_fibers = model.fibers && model.fibers->sparse();
  const double pairs =
      sparse_fibers ? static_cast<double>(model.fibers->num_kept()) : 0.5 * N * (N - 1.0);
  const double unknowns = d * N + 1.0;
  const double steps = o.steps;

  e.parts.push_back({"model", kProcessBytes + kBytesPerVertex * N, 0.0, true});
  if (pruning != PruningWork::None)  // N x F tests when convex; a concave body stops early
    e.parts.push_back(
        {"convexity check", 0.0, N * surface.num_faces() / speed.orientation_tests_per_second});
  // An N x N byte table (a horizon's lists: two ints a pair), kept for the
  // solvers, and per thread an AABB tree and the exact solid (about 12 kB a
  // face in all: the bunny's peak). Only the horizon's pairs are tested.
  if (pruning == PruningWork::Prune)
    e.parts.push_back({"pruning",
                       (sparse_fibers ? 8.0 * pairs : N * N) + 12000.0 * surface.num_faces(),
                       pairs / speed.prune_pairs_per_second, true});

  const solve::BlockShape blocks = solve::block_shape(model, o.boundary_method);
  const double product = model.treecode_tolerance > 0.0  // K v, every axis block
                             ? treecode_product_seconds(N, model.treecode_tolerance)
                             : d * pairs / speed.pair_updates_per_second;
  const double residual = 2.0 * pairs / speed.residual_pairs_per_second;
  const bool newton = o.scheme == solve::Scheme::Newton;
  const solve::TangentSolver tangent_kind = solve::choose_tangent(
      o.newton.tangent, blocks.newton_unknowns, model.material.kinematics, sparse_fibers);
  const bool dense_tangent = newton && tangent_kind == solve::TangentSolver::Dense;
  // The reused tangent LU costs what the dense one does a factorisation; it
  // is then counted as Krylov's preconditioner, refactored about once in four
  // steps (issue 42: 9 and 12 for the compressed cylinder's 40 steps, 1 for the
  // bending phantom's 10).
  const bool reused_tangent = newton && tangent_kind == solve::TangentSolver::Reused;
  // A horizon's lists: the reused factor is the sparse tangent's LU.
  const bool reused_sparse = reused_tangent && sparse_fibers;
  const solve::SolverKind kind = dense_tangent || (reused_tangent && !reused_sparse)
                                     ? solve::SolverKind::DenseLU
                                     : choose(model, o, blocks);
  e.solver = solve::to_string(kind);

  // One factorisation of the structured system (or the Newton preconditioner)
  // and one solve with it: the backend's own cost model.
  const solve::BackendCost cost = solve::backend_cost(kind, blocks, product, speed);
  ResourcePart factor{"factorisation", cost.factor_bytes, cost.factor_seconds};
  const double solve_seconds = cost.solve_seconds;

  if (newton) {
    const CaseSize size{N, d, pairs, unknowns, steps, product, residual, sparse_fibers};
    e.parts.push_back(
        newton_steps_cost(o, tangent_kind, blocks, factor, solve_seconds, size, speed));
  } else {
    const double factorizations = o.rebuild_matrix ? steps : 1.0;
    factor.seconds *= factorizations;
    if (o.rebuild_matrix) factor.name = std::to_string(o.steps) + " factorisations";
    e.parts.push_back(factor);
    const double per_step = solve_seconds + (o.measure_residual ? residual : 0.0);
    e.parts.push_back(
        {std::to_string(o.steps) + " load steps", 8.0 * unknowns * 8.0, steps * per_step});
  }

  double kept = 0.0, largest = 0.0;
  for (const ResourcePart& p : e.parts) {
    e.seconds += p.seconds;
    if (p.kept)
      kept += p.bytes;
    else
      largest = std::max(largest, p.bytes);
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
    if (memory_budget_is_set())
      why << " set by --max-memory; raise --max-memory";
    else
      why << " (80% of this machine's memory); --max-memory sets another budget";
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

}  // namespace fiberfluid::experiment

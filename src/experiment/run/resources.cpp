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
#include "fiberfluid/solve/tangent/tangent_solve.hpp"
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

// The process itself (libraries, CGAL, OpenMP pools) and each vertex's
// surface, area vectors, unknowns, outputs.
constexpr double kProcessBytes = 20.0 * 1024 * 1024;
constexpr double kBytesPerVertex = 1024.0;

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
  // Newton's factor is the tangent strategy's (its own cost says how often).
  const solve::SolverKind kind =
      newton ? solve::tangent_factor_backend(tangent_kind, sparse_fibers, choose(model, o, blocks))
             : choose(model, o, blocks);
  e.solver = solve::to_string(kind);

  // One factorisation of the structured system (or the Newton preconditioner)
  // and one solve with it: the backend's own cost model.
  const solve::BackendCost cost = solve::backend_cost(kind, blocks, product, speed);
  if (newton) {
    solve::TangentCostCase c;
    c.vertices = N, c.dim = d, c.pairs = pairs, c.unknowns = unknowns;
    c.newton_unknowns = blocks.newton_unknowns, c.steps = steps;
    c.product_seconds = product, c.residual_seconds = residual;
    c.sparse_fibers = sparse_fibers, c.krylov_restart = o.newton.krylov_restart;
    c.factor = cost;
    const solve::TangentCost tangent = solve::tangent_cost(tangent_kind, c, speed);
    e.parts.push_back({std::to_string(o.steps) + " Newton steps", tangent.bytes, tangent.seconds});
  } else {
    ResourcePart factor{"factorisation", cost.factor_bytes, cost.factor_seconds};
    const double factorizations = o.rebuild_matrix ? steps : 1.0;
    factor.seconds *= factorizations;
    if (o.rebuild_matrix) factor.name = std::to_string(o.steps) + " factorisations";
    e.parts.push_back(factor);
    const double per_step = cost.solve_seconds + (o.measure_residual ? residual : 0.0);
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

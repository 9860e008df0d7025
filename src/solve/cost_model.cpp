// SPDX-License-Identifier: GPL-3.0-or-later
#include "fiberfluid/solve/cost_model.hpp"

#include <algorithm>
#include <cmath>
#include <vector>

namespace fiberfluid::solve {

BlockShape block_shape(const model::Model& m, model::BoundaryMethod method) {
  const int n = m.num_vertices(), dim = m.dim();
  std::vector<std::vector<bool>> supported(static_cast<size_t>(dim),
                                           std::vector<bool>(static_cast<size_t>(n)));
  for (const model::Constraint& c : m.constraints)
    supported[static_cast<size_t>(c.axis)][static_cast<size_t>(c.vertex)] = true;
  // The penalty method keeps the supported vertices in the blocks.
  const bool eliminated = method == model::BoundaryMethod::Elimination;
  BlockShape b;
  b.dim = dim;
  b.vertices = n;
  bool equal = true;
  for (int a = 0; a < dim; ++a) {
    const auto& s = supported[static_cast<size_t>(a)];
    const int free = static_cast<int>(std::count(s.begin(), s.end(), false));
    b.newton_unknowns += free;
    b.largest = std::max(b.largest, static_cast<double>(eliminated ? free : n));
    equal = equal && s == supported[0] && m.material.axis_factors[a] == m.material.axis_factors[0];
  }
  b.factors = equal ? 1 : dim;
  if (m.fibers && m.fibers->sparse()) b.neighbours = 2.0 * m.fibers->num_kept() / std::max(n, 1);
  return b;
}

BackendCost backend_cost(SolverKind kind, const BlockShape& shape, double product,
                         const KernelSpeed& speed) {
  const double n = shape.largest, factors = shape.factors, d = shape.dim, N = shape.vertices;
  const double m = d * n + 1.0;  // the reduced unknowns
  BackendCost c;
  switch (kind) {
    case SolverKind::DenseLU:  // the assembled matrix, factored in a copy
      c.factor_bytes = 1.2 * 8.0 * m * m;
      c.factor_seconds = 2.0 / 3.0 * m * m * m / speed.factor_flops_per_second + product;
      c.solve_seconds = 2.0 * m * m / speed.triangular_flops_per_second;
      break;
    case SolverKind::BlockCholesky:
      c.factor_bytes = 8.0 * n * n * factors;
      c.factor_seconds = factors * n * n * n / 3.0 / speed.factor_flops_per_second + product;
      // The Schur complement's solves and each step's: forward and back per axis.
      c.solve_seconds = 2.0 * d * 2.0 * n * n / speed.triangular_flops_per_second;
      break;
    case SolverKind::Cholmod:
      if (shape.neighbours > 0.0) {
        // Sparse blocks of a horizon on a surface: nested dissection's top
        // separator is a band of the horizon's width across the body, about
        // 2 sqrt(neighbours / pi) sqrt(n) vertices; its dense front dominates.
        const double separator =
            std::min(n, 2.0 * std::sqrt(shape.neighbours / 3.14159) * std::sqrt(n));
        const double entries = n * shape.neighbours + 2.0 * separator * separator;
        c.factor_bytes = factors * 12.0 * entries;
        c.factor_seconds =
            factors * separator * separator * separator / speed.sparse_flops_per_second + product;
        c.solve_seconds = 2.0 * d * 2.0 * entries / speed.triangular_flops_per_second;
        break;
      }
      // Dense bulk blocks: every pair a nonzero.
      c.factor_bytes = factors * (12.0 * n * n + 4.0 * n * n);
      c.factor_seconds = factors * n * n * n / 3.0 / speed.sparse_flops_per_second + product;
      c.solve_seconds = 2.0 * d * 2.0 * n * n / speed.triangular_flops_per_second;
      break;
    case SolverKind::PCG:  // the bulk diagonal and the surface Laplacian's sparse factor
    case SolverKind::Auto:
      c.factor_bytes = 500.0 * N;
      c.factor_seconds = product;
      c.solve_seconds = (kPcgIterationsPerSolve + 1.0) * product;
      break;
  }
  return c;
}

}  // namespace fiberfluid::solve

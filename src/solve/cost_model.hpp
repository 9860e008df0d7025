// SPDX-License-Identifier: GPL-3.0-or-later
// What the linear backends cost, estimated before a run from the block
// sizes alone: each backend's memory and time for one factorisation and one
// solve (backend_cost), and the axis blocks a model's structured system will
// have (block_shape, FiberSystem's rule). The resource estimate of a whole
// run (experiment/resources) composes these with the pruning and the steps.
#pragma once

#include "fiberfluid/model/boundary_conditions.hpp"
#include "fiberfluid/model/model.hpp"
#include "fiberfluid/solve/linear_solver.hpp"

namespace fiberfluid::solve {

// This machine's speed for the kernels the estimates count (Release build,
// both cores), from scripts/resources.sh on this 2-core machine: rerun it
// and put the figures here on another machine.
struct KernelSpeed {
  double prune_pairs_per_second = 6e5;        // pruning: 5,000-vertex torus, 12.5M pairs in 21 s
                                              // (the bunny's 930k: 0.75 s)
  double orientation_tests_per_second = 4e9;  // the convexity check, counted as N x F tests
                                              // (clusters culled: 10,242 vertices in 0.054 s)
  double factor_flops_per_second = 6.5e10;    // LAPACK dgetrf / dpotrf (69 GFLOP/s measured)
  double triangular_flops_per_second = 1e10;  // solves with a dense factor (memory-bound)
  double factor_bytes_read_per_second = 9e9;  // the same, bytes of a large factor (4,254
                                              // unknowns in single precision: 72 MB in 8 ms)
  double pair_updates_per_second = 4.5e9;     // one fiber pair in one axis block's product (tiled)
  double residual_pairs_per_second = 8e8;     // one ordered pair of the Newton residual (tiled)
  double sparse_flops_per_second = 3e9;       // CHOLMOD on dense bulk blocks
};

// The axis blocks of the structured system as the backends see them: per
// axis the vertices not held by a support (all of them with the penalty
// method); equal (one factor serves all) when every axis holds the same
// vertices with the same axis factor, as FiberSystem::blocks_equal decides.
struct BlockShape {
  int dim = 3;
  double vertices = 0.0;    // N
  double largest = 0.0;     // the largest axis block
  int factors = 1;          // distinct block factors
  int newton_unknowns = 1;  // the supports eliminated (as Newton always does), then P
  double neighbours = 0.0;  // fibers per vertex of a horizon stored sparse (0: dense blocks)
};
BlockShape block_shape(const model::Model& model, model::BoundaryMethod method);

// One factorisation of the structured system and one solve with it, for a
// backend: the bytes the factor holds, its seconds (including the bulk
// products it needs, product_seconds each), and a solve's seconds.
struct BackendCost {
  double factor_bytes = 0.0, factor_seconds = 0.0, solve_seconds = 0.0;
};
// Typical PCG iterations per solve (scripts/resources.sh: the sphere's steps).
constexpr double kPcgIterationsPerSolve = 15.0;
BackendCost backend_cost(SolverKind kind, const BlockShape& shape, double product_seconds,
                         const KernelSpeed& speed = {});

}  // namespace fiberfluid::solve

// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once

namespace fiberfluid::solve {

// Solves L L^T X = B in place for a dense Cholesky factor L (the lower
// triangle of a column-major n x n array, as LAPACK's potrf leaves it) and
// nrhs <= 3 right-hand sides, the columns of X (leading dimension ldx).
//
// Why not LAPACK's potrs: with a few right-hand sides its trsm copies the
// factor into packed panels before reading it, and runs on one thread while
// the solve is bound by memory. Here the factor is read once per triangle, as
// it lies, by all OpenMP threads: blocks of columns, each thread updating
// its own rows (forward) or its own columns' dot products (backward). Every
// entry of X is summed in the same order whatever the thread count: the same
// bits on one thread as on many.
void cholesky_solve_in_place(int n, const double* L, double* X, int nrhs, int ldx);
void cholesky_solve_in_place(int n, const float* L, float* X, int nrhs, int ldx);

}  // namespace fiberfluid::solve

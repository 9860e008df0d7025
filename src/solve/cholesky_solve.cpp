// SPDX-License-Identifier: GPL-3.0-or-later
#include "fiberfluid/solve/cholesky_solve.hpp"

#include <omp.h>

#include <algorithm>
#include <cstddef>
#include <stdexcept>

namespace fiberfluid::solve {
namespace {

// Columns per block: the serial diagonal solves cost n * kBlock / 2 in all,
// and each block costs two barriers.
constexpr int kBlock = 64;

// This thread's share [begin, end) of the range [first, last).
void thread_share(int first, int last, int* begin, int* end) {
  const int threads = omp_get_num_threads(), thread = omp_get_thread_num();
  const long count = last - first;
  *begin = first + static_cast<int>(count * thread / threads);
  *end = first + static_cast<int>(count * (thread + 1) / threads);
}

template <class Scalar, int R>
void solve(int n, const Scalar* L, Scalar* X, int ldx) {
  const auto column = [&](int j) { return L + static_cast<std::ptrdiff_t>(j) * n; };
  Scalar* x[R];
  for (int r = 0; r < R; ++r) x[r] = X + static_cast<std::ptrdiff_t>(r) * ldx;
#pragma omp parallel
  {
    // Forward, L Y = B: solve a diagonal block, then take its columns off the
    // rows below, each thread its own rows, column by column in order.
    for (int j0 = 0; j0 < n; j0 += kBlock) {
      const int j1 = std::min(n, j0 + kBlock);
#pragma omp single
      for (int j = j0; j < j1; ++j) {
        const Scalar* l = column(j);
        for (int r = 0; r < R; ++r) {
          const Scalar y = x[r][j] /= l[j];
          for (int i = j + 1; i < j1; ++i) x[r][i] -= l[i] * y;
        }
      }
      int begin, end;
      thread_share(j1, n, &begin, &end);
      for (int j = j0; j < j1; ++j) {
        const Scalar* l = column(j);
        for (int r = 0; r < R; ++r) {
          const Scalar y = x[r][j];
          Scalar* xr = x[r];
#pragma omp simd
          for (int i = begin; i < end; ++i) xr[i] -= l[i] * y;
        }
      }
#pragma omp barrier
    }
    // Backward, L^T X = Y: row i of L^T is column i of L below the diagonal,
    // read as it lies. Each thread takes whole dot products over the rows
    // already solved, then one thread solves the diagonal block.
    for (int i1 = n; i1 > 0; i1 -= kBlock) {
      const int i0 = std::max(0, i1 - kBlock);
      int begin, end;
      thread_share(i0, i1, &begin, &end);
      for (int i = begin; i < end; ++i) {
        const Scalar* l = column(i);
        Scalar s[R] = {};
        for (int r = 0; r < R; ++r) {
          const Scalar* xr = x[r];
          Scalar sum = 0;
#pragma omp simd reduction(+ : sum)
          for (int k = i1; k < n; ++k) sum += l[k] * xr[k];
          s[r] = sum;
        }
        for (int r = 0; r < R; ++r) x[r][i] -= s[r];
      }
#pragma omp barrier
#pragma omp single
      for (int i = i1 - 1; i >= i0; --i) {
        const Scalar* l = column(i);
        for (int r = 0; r < R; ++r) {
          Scalar sum = 0;
          for (int k = i + 1; k < i1; ++k) sum += l[k] * x[r][k];
          x[r][i] = (x[r][i] - sum) / l[i];
        }
      }
    }
  }
}

template <class Scalar>
void dispatch(int n, const Scalar* L, Scalar* X, int nrhs, int ldx) {
  if (n <= 0) return;
  switch (nrhs) {
    case 0: return;
    case 1: return solve<Scalar, 1>(n, L, X, ldx);
    case 2: return solve<Scalar, 2>(n, L, X, ldx);
    case 3: return solve<Scalar, 3>(n, L, X, ldx);
    default: throw std::invalid_argument("cholesky_solve_in_place: at most 3 right-hand sides");
  }
}

}  // namespace

void cholesky_solve_in_place(int n, const double* L, double* X, int nrhs, int ldx) {
  dispatch(n, L, X, nrhs, ldx);
}
void cholesky_solve_in_place(int n, const float* L, float* X, int nrhs, int ldx) {
  dispatch(n, L, X, nrhs, ldx);
}

}  // namespace fiberfluid::solve

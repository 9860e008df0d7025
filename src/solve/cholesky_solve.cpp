// SPDX-License-Identifier: GPL-3.0-or-later
#include "fiberfluid/solve/cholesky_solve.hpp"

#include "fiberfluid/model/vector_clones.hpp"

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

// Forward: rows [begin, end) of X less L's columns [j0, j1) times their
// solved entries. Four columns at a time: each entry of X is read and
// written once per four columns, not once per column.
template <class Scalar, int R>
FIBERFLUID_VECTOR_CLONES void take_off_columns(const Scalar* L, int n, int j0, int j1, int begin,
                                               int end, Scalar* const* x) {
  const auto column = [&](int j) { return L + static_cast<std::ptrdiff_t>(j) * n; };
  int j = j0;
  for (; j + 4 <= j1; j += 4) {
    const Scalar *l0 = column(j), *l1 = column(j + 1), *l2 = column(j + 2), *l3 = column(j + 3);
    for (int r = 0; r < R; ++r) {
      Scalar* xr = x[r];
      const Scalar y0 = xr[j], y1 = xr[j + 1], y2 = xr[j + 2], y3 = xr[j + 3];
#pragma omp simd
      for (int i = begin; i < end; ++i)
        xr[i] -= (l0[i] * y0 + l1[i] * y1) + (l2[i] * y2 + l3[i] * y3);
    }
  }
  for (; j < j1; ++j) {
    const Scalar* l = column(j);
    for (int r = 0; r < R; ++r) {
      Scalar* xr = x[r];
      const Scalar y = xr[j];
#pragma omp simd
      for (int i = begin; i < end; ++i) xr[i] -= l[i] * y;
    }
  }
}

// Backward: X's rows [begin, end) less the dot products of L's columns (rows
// from `from` on) with the solved entries, the R products in one read of
// each column.
template <class Scalar, int R>
FIBERFLUID_VECTOR_CLONES void take_off_dots(const Scalar* L, int n, int from, int begin, int end,
                                            Scalar* const* x) {
  const Scalar *x0 = x[0], *x1 = x[R > 1 ? 1 : 0], *x2 = x[R > 2 ? 2 : 0];
  for (int i = begin; i < end; ++i) {
    const Scalar* l = L + static_cast<std::ptrdiff_t>(i) * n;
    Scalar s0 = 0, s1 = 0, s2 = 0;
#pragma omp simd reduction(+ : s0, s1, s2)
    for (int k = from; k < n; ++k) {
      s0 += l[k] * x0[k];
      if constexpr (R > 1) s1 += l[k] * x1[k];
      if constexpr (R > 2) s2 += l[k] * x2[k];
    }
    x[0][i] -= s0;
    if constexpr (R > 1) x[1][i] -= s1;
    if constexpr (R > 2) x[2][i] -= s2;
  }
}

template <class Scalar, int R>
void solve(int n, const Scalar* L, Scalar* X, int ldx) {
  const auto column = [&](int j) { return L + static_cast<std::ptrdiff_t>(j) * n; };
  Scalar* x[R];
  for (int r = 0; r < R; ++r) x[r] = X + static_cast<std::ptrdiff_t>(r) * ldx;
#pragma omp parallel
  {
    // Forward, L Y = B: one thread solves a diagonal block, then each takes
    // its columns off its own rows below.
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
      take_off_columns<Scalar, R>(L, n, j0, j1, begin, end, x);
#pragma omp barrier
    }
    // Backward, L^T X = Y: row i of L^T is column i of L below the diagonal,
    // read as it lies. Each thread takes whole dot products over the rows
    // already solved, then one thread solves the diagonal block.
    for (int i1 = n; i1 > 0; i1 -= kBlock) {
      const int i0 = std::max(0, i1 - kBlock);
      int begin, end;
      thread_share(i0, i1, &begin, &end);
      take_off_dots<Scalar, R>(L, n, i1, begin, end, x);
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
    case 0:
      return;
    case 1:
      return solve<Scalar, 1>(n, L, X, ldx);
    case 2:
      return solve<Scalar, 2>(n, L, X, ldx);
    case 3:
      return solve<Scalar, 3>(n, L, X, ldx);
    default:
      throw std::invalid_argument("cholesky_solve_in_place: at most 3 right-hand sides");
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

// SPDX-License-Identifier: GPL-3.0-or-later
// DeformedPairs: the pair passes of a deformed state (forces, the tangent
// product, the stored coefficients), row by row or over a horizon's lists.
#include "fiberfluid/model/pair_kernels.hpp"

#include <omp.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <type_traits>

#include "fiberfluid/geom/fiber_mask.hpp"
#include "fiberfluid/model/pair_stencil.hpp"
#include "fiberfluid/model/pair_tiles.hpp"
#include "fiberfluid/model/vector_clones.hpp"
#include "fiberfluid/util/run_control.hpp"

namespace fiberfluid::model {

namespace {

using detail::for_each_tile_pair;
using detail::ThreadAccumulators;
using detail::with_count;
using Tile = BulkPairs::Tile;

// The lengths and strains of one tile row (pairs (i, j), j in [first, end)),
// into the row arrays at j - j0.
struct DeformedRow {
  const double *s0, *s1, *s2, *x0, *x1, *x2;
};

FIBERFLUID_VECTOR_CLONES
void lengths_row(const DeformedRow& d, int i, int j0, int first, int end, double* L, double* r,
                 double* e) {
  const double si0 = d.s0[i], si1 = d.s1[i], si2 = d.s2[i];
  const double xi0 = d.x0[i], xi1 = d.x1[i], xi2 = d.x2[i];
#pragma omp simd
  for (int j = first; j < end; ++j) {
    const double a0 = si0 - d.s0[j], a1 = si1 - d.s1[j], a2 = si2 - d.s2[j];
    const double b0 = xi0 - d.x0[j], b1 = xi1 - d.x1[j], b2 = xi2 - d.x2[j];
    const double length = pair_length(a0, a1, a2), current = pair_length(b0, b1, b2);
    L[j - j0] = length;
    r[j - j0] = current;
    e[j - j0] = fiber_strain(current, length);
  }
}

// The arrays of one tile row: m (mask), L, r, Y, Y' at j - j0.
struct RowArrays {
  const double *m, *L, *r, *Y, *Yp;
  const double* T0;  // the pair's rest tension (zeros for a law without one)
};

// The pair's coefficients from the row arrays at q (stencil: weight, then policy).
template <class K>
inline PairCoefficients row_coefficients(const RowArrays& row, int q, double area_i, double area_j,
                                         double count_i, double count_j, bool mean) {
  const double a = counted_bulk_weight(row.m[q], area_i, area_j, count_i, count_j, row.L[q], mean);
  return K::coefficients(a, row.Y[q], row.Yp[q], row.r[q], row.L[q], row.T0[q]);
}

// The positions and displacements a row kernel reads (three columns each).
struct PairColumns {
  const double *x[3], *u[3];
};

PairColumns columns_of(const std::vector<double> (&x)[3], const std::vector<double> (&u)[3]) {
  return {{x[0].data(), x[1].data(), x[2].data()}, {u[0].data(), u[1].data(), u[2].data()}};
}

// One loop over row i's pairs (j in [first, end)), each pair's coefficients
// formed once: with kForces its forces summed into out (the term at i, its
// opposite at j); with kTable its coefficients written to k1, k2 at j (the
// lower triangle of the stored tangent's table).
template <class K, bool kMean, bool kForces, bool kTable, class Scalar = float>
FIBERFLUID_VECTOR_CLONES void row_pass(const PairColumns& p, const double* area,
                                       const double* count, int i, int j0, int first, int end,
                                       const RowArrays& row, const std::array<double*, 3>& out,
                                       Scalar* k1 = nullptr, Scalar* k2 = nullptr) {
  const double *x0 = p.x[0], *x1 = p.x[1], *x2 = p.x[2];
  const double *u0 = p.u[0], *u1 = p.u[1], *u2 = p.u[2];
  double *o0 = out[0], *o1 = out[1], *o2 = out[2];
  const double xi0 = x0[i], xi1 = x1[i], xi2 = x2[i], ui0 = u0[i], ui1 = u1[i], ui2 = u2[i];
  const double ai = area[i], ci = count[i];
  double f0 = 0.0, f1 = 0.0, f2 = 0.0;
#pragma omp simd reduction(+ : f0, f1, f2)
  for (int j = first; j < end; ++j) {
    const PairCoefficients c = row_coefficients<K>(row, j - j0, ai, area[j], ci, count[j], kMean);
    if constexpr (kTable) {
      k1[j] = static_cast<Scalar>(c.c1);
      k2[j] = static_cast<Scalar>(c.c2);
    }
    if constexpr (kForces) {
      const double e0 = pair_force<K>(c, xi0 - x0[j], ui0 - u0[j]),
                   e1 = pair_force<K>(c, xi1 - x1[j], ui1 - u1[j]),
                   e2 = pair_force<K>(c, xi2 - x2[j], ui2 - u2[j]);
      f0 += e0, f1 += e1, f2 += e2;
      o0[j] -= e0, o1[j] -= e1, o2[j] -= e2;
    }
  }
  if constexpr (kForces) o0[i] += f0, o1[i] += f1, o2[i] += f2;
}

template <class K, bool kMean>
FIBERFLUID_VECTOR_CLONES void tangent_row(const PairColumns& p, const double* const w[3],
                                          const double* area, const double* count, int i, int j0,
                                          int first, int end, const RowArrays& row,
                                          const std::array<double*, 3>& out) {
  const double *x0 = p.x[0], *x1 = p.x[1], *x2 = p.x[2];
  const double *u0 = p.u[0], *u1 = p.u[1], *u2 = p.u[2];
  const double *w0 = w[0], *w1 = w[1], *w2 = w[2];
  double *o0 = out[0], *o1 = out[1], *o2 = out[2];
  const double xi0 = x0[i], xi1 = x1[i], xi2 = x2[i], ui0 = u0[i], ui1 = u1[i], ui2 = u2[i];
  const double wi0 = w0[i], wi1 = w1[i], wi2 = w2[i], ai = area[i], ci = count[i];
  double p0 = 0.0, p1 = 0.0, p2 = 0.0;
#pragma omp simd reduction(+ : p0, p1, p2)
  for (int j = first; j < end; ++j) {
    const PairCoefficients c = row_coefficients<K>(row, j - j0, ai, area[j], ci, count[j], kMean);
    const double b0 = xi0 - x0[j], b1 = xi1 - x1[j], b2 = xi2 - x2[j];
    const double v0 = wi0 - w0[j], v1 = wi1 - w1[j], v2 = wi2 - w2[j];
    const double b_dot_v = b0 * v0 + b1 * v1 + b2 * v2;
    const double e0 = pair_tangent<K>(c, v0, b_dot_v, b0, ui0 - u0[j]),
                 e1 = pair_tangent<K>(c, v1, b_dot_v, b1, ui1 - u1[j]),
                 e2 = pair_tangent<K>(c, v2, b_dot_v, b2, ui2 - u2[j]);
    p0 += e0, p1 += e1, p2 += e2;
    o0[j] -= e0, o1[j] -= e1, o2[j] -= e2;
  }
  o0[i] += p0, o1[i] += p1, o2[i] += p2;
}

}  // namespace

DeformedPairs::DeformedPairs(const Eigen::MatrixXd& S, const Eigen::MatrixXd& X,
                             const Eigen::MatrixXd& U, const Eigen::VectorXd& area,
                             const PairFactors& factors, const FiberLaw& law,
                             FiberKinematics kinematics)
    : n_(static_cast<int>(S.rows())),
      count_(factors.vertex_counts()),
      mean_(factors.mean_count()),
      area_(area),
      mask_(factors.mask()),
      influence_(factors.influence()),
      lines_(factors.lines()),
      law_(law),
      rest_(law.rest_tension()),
      kinematics_(kinematics) {
  for (int a = 0; a < 3; ++a) {
    s_[a].assign(static_cast<size_t>(n_), 0.0);
    x_[a].assign(static_cast<size_t>(n_), 0.0);
    u_[a].assign(static_cast<size_t>(n_), 0.0);
    if (a >= S.cols()) continue;
    for (int i = 0; i < n_; ++i) {
      s_[a][static_cast<size_t>(i)] = S(i, a);
      x_[a][static_cast<size_t>(i)] = X(i, a);
      u_[a][static_cast<size_t>(i)] = U(i, a);
    }
  }
  if (sparse()) {
    offsets_.assign(static_cast<size_t>(n_) + 1, 0);
    for (int i = 0; i < n_; ++i)
      offsets_[static_cast<size_t>(i) + 1] =
          offsets_[static_cast<size_t>(i)] + mask_->neighbours(i).size();
  }
}

struct DeformedPairs::ListedRow {
  std::vector<double> m, L, r, e, Y, Yp, T0;
  void resize(size_t k) {
    for (std::vector<double>* v : {&m, &L, &r, &e, &Y, &Yp, &T0})
      if (v->size() < k) v->resize(k, 0.0);
  }
  RowArrays arrays() const {
    return {m.data(), L.data(), r.data(), Y.data(), Yp.data(), T0.data()};
  }
};

PairPasses& pair_passes() {
  thread_local PairPasses count;
  return count;
}

template <class Visit>
void DeformedPairs::for_each_listed_row(Visit&& visit) const {
  ++pair_passes().computed;
#pragma omp parallel
  {
    ListedRow row;
#pragma omp for schedule(dynamic, 64)
    for (int i = 0; i < n_; ++i) {
      const std::vector<int>& partners = mask_->neighbours(i);
      const size_t k = partners.size();
      if (k == 0) continue;
      row.resize(k);
      const auto u = static_cast<size_t>(i);
      for (size_t q = 0; q < k; ++q) {
        const auto j = static_cast<size_t>(partners[q]);
        row.L[q] = pair_length(s_[0][u] - s_[0][j], s_[1][u] - s_[1][j], s_[2][u] - s_[2][j]);
        row.r[q] = pair_length(x_[0][u] - x_[0][j], x_[1][u] - x_[1][j], x_[2][u] - x_[2][j]);
        row.e[q] = fiber_strain(row.r[q], row.L[q]);
        row.m[q] = influence_.weighs() ? influence_(row.L[q]) : 1.0;
        if (lines_ != nullptr) {
          const LineMeasure::Pair line = lines_->pair(u, j);
          row.m[q] *= line.measure;
          row.T0[q] = rest_ * line.rest_factor;
        } else if (rest_ != 0.0) {
          row.T0[q] = rest_;
        }
      }
      law_.evaluate(row.e.data(), k, row.Y.data(), row.Yp.data());
      visit(i, partners, row.arrays());
    }
  }
}

template <class Term>
Eigen::MatrixXd DeformedPairs::listed_sums(Term&& term) const {
  Eigen::MatrixXd out = Eigen::MatrixXd::Zero(n_, 3);
  const double *area = area_.data(), *count = count_.data();
  with_kinematics(kinematics_, [&](auto policy) {
    using K = decltype(policy);
    for_each_listed_row([&](int i, const std::vector<int>& partners, const RowArrays& row) {
      double sum[3] = {0.0, 0.0, 0.0};
      for (size_t q = 0; q < partners.size(); ++q) {
        const int j = partners[q];
        const PairCoefficients c = row_coefficients<K>(row, static_cast<int>(q), area[i], area[j],
                                                       count[i], count[j], mean_);
        for (int a = 0; a < 3; ++a)
          sum[a] += term(policy, static_cast<size_t>(i), static_cast<size_t>(j), c, a);
      }
      for (int a = 0; a < 3; ++a) out(i, a) = sum[a];
    });
  });
  return out;
}

void DeformedPairs::listed_coefficients(std::vector<double>* c1, std::vector<double>* c2) const {
  c1->assign(offsets_.back(), 0.0);
  c2->assign(offsets_.back(), 0.0);
  const double *area = area_.data(), *count = count_.data();
  with_kinematics(kinematics_, [&](auto policy) {
    using K = decltype(policy);
    for_each_listed_row([&](int i, const std::vector<int>& partners, const RowArrays& row) {
      const size_t first = offsets_[static_cast<size_t>(i)];
      for (size_t q = 0; q < partners.size(); ++q) {
        const int j = partners[q];
        const PairCoefficients c = row_coefficients<K>(row, static_cast<int>(q), area[i], area[j],
                                                       count[i], count[j], mean_);
        (*c1)[first + q] = c.c1;
        (*c2)[first + q] = c.c2;
      }
    });
  });
}

struct DeformedPairs::RowScratch {
  std::vector<double> m, L, r, e, Y, Yp, T0;
  RowScratch()
      : m(BulkPairs::kTile, 1.0),
        L(BulkPairs::kTile),
        r(BulkPairs::kTile),
        e(BulkPairs::kTile),
        Y(BulkPairs::kTile),
        Yp(BulkPairs::kTile),
        T0(BulkPairs::kTile, 0.0) {}
  RowArrays arrays() const {
    return {m.data(), L.data(), r.data(), Y.data(), Yp.data(), T0.data()};
  }
};

template <class Visit>
void DeformedPairs::for_each_row(Visit&& visit) const {
  ++pair_passes().computed;
  std::vector<RowScratch> scratch(static_cast<size_t>(omp_get_max_threads()));
  const DeformedRow geometry{s_[0].data(), s_[1].data(), s_[2].data(),
                             x_[0].data(), x_[1].data(), x_[2].data()};
  for_each_tile_pair(n_, [&](const Tile& t, int thread) {
    RowScratch& row = scratch[static_cast<size_t>(thread)];
    for (int r = 0; r < t.ni; ++r) {
      const int i = t.i0 + r, first = t.j0 + (t.diagonal ? r + 1 : 0), end = t.j0 + t.nj;
      if (first == end) continue;
      const int q = first - t.j0;
      lengths_row(geometry, i, t.j0, first, end, row.L.data(), row.r.data(), row.e.data());
      law_.evaluate(row.e.data() + q, static_cast<size_t>(end - first), row.Y.data() + q,
                    row.Yp.data() + q);
      if (mask_ != nullptr) {
        const uint8_t* kept = mask_->row(i);
        for (int j = first; j < end; ++j) row.m[static_cast<size_t>(j - t.j0)] = kept[j];
      }
      if (influence_.weighs())  // by the reference length L (the row's)
        for (int j = first; j < end; ++j) {
          const auto k = static_cast<size_t>(j - t.j0);
          row.m[k] = (mask_ != nullptr ? mask_->row(i)[j] : 1.0) * influence_(row.L[k]);
        }
      if (lines_ != nullptr) {  // the measure and the rest tension's factor, one pass
        if (mask_ == nullptr && !influence_.weighs())
          std::fill(row.m.begin() + q, row.m.begin() + (end - t.j0), 1.0);
        for (int j = first; j < end; ++j) {
          const auto k = static_cast<size_t>(j - t.j0);
          const LineMeasure::Pair line =
              lines_->pair(static_cast<size_t>(i), static_cast<size_t>(j));
          row.m[k] *= line.measure;
          row.T0[k] = rest_ * line.rest_factor;
        }
      } else if (rest_ != 0.0) {
        std::fill(row.T0.begin() + q, row.T0.begin() + (end - t.j0), rest_);
      }
      visit(i, t.j0, first, end, row.arrays(), thread);
    }
  });
}

Eigen::MatrixXd DeformedPairs::forces() const {
  if (sparse())
    return listed_sums([&](auto policy, size_t i, size_t j, const PairCoefficients& c, int a) {
      using K = decltype(policy);
      return pair_force<K>(c, x_[a][i] - x_[a][j], u_[a][i] - u_[a][j]);
    });
  const PairColumns p = columns_of(x_, u_);
  ThreadAccumulators forces(n_, 3);
  with_kinematics(kinematics_, [&](auto policy) {
    using K = decltype(policy);
    with_count(mean_, [&](auto mean) {
      for_each_row([&](int i, int j0, int first, int end, const RowArrays& row, int thread) {
        row_pass<K, mean(), true, false>(p, area_.data(), count_.data(), i, j0, first, end, row,
                                         forces.columns(thread));
      });
    });
  });
  return forces.sum();
}

Eigen::MatrixXd DeformedPairs::tangent_product(const Eigen::MatrixXd& W) const {
  std::vector<double> directions[3];
  const double* w[3];
  for (int a = 0; a < 3; ++a) {
    directions[a].assign(static_cast<size_t>(n_), 0.0);
    if (a < W.cols()) std::copy(W.col(a).data(), W.col(a).data() + n_, directions[a].begin());
    w[a] = directions[a].data();
  }
  if (sparse())
    return listed_sums([&](auto policy, size_t i, size_t j, const PairCoefficients& c, int a) {
      using K = decltype(policy);
      double b_dot_v = 0.0;
      for (int k = 0; k < 3; ++k) b_dot_v += (x_[k][i] - x_[k][j]) * (w[k][i] - w[k][j]);
      return pair_tangent<K>(c, w[a][i] - w[a][j], b_dot_v, x_[a][i] - x_[a][j],
                             u_[a][i] - u_[a][j]);
    });
  const PairColumns p = columns_of(x_, u_);
  ThreadAccumulators products(n_, 3);
  with_kinematics(kinematics_, [&](auto policy) {
    using K = decltype(policy);
    with_count(mean_, [&](auto mean) {
      for_each_row([&](int i, int j0, int first, int end, const RowArrays& row, int thread) {
        tangent_row<K, mean()>(p, w, area_.data(), count_.data(), i, j0, first, end, row,
                               products.columns(thread));
      });
    });
  });
  return products.sum();
}

template <class Table>
void DeformedPairs::table_coefficients(Table* c1, Table* c2) const {
  if (sparse()) {
    std::vector<double> k1, k2;
    listed_coefficients(&k1, &k2);
    c1->setZero(n_, n_);
    c2->setZero(n_, n_);
    for (int i = 0; i < n_; ++i) {
      const std::vector<int>& partners = mask_->neighbours(i);
      for (size_t q = 0; q < partners.size(); ++q) {
        using Scalar = typename Table::Scalar;
        (*c1)(i, partners[q]) = static_cast<Scalar>(k1[offsets_[static_cast<size_t>(i)] + q]);
        (*c2)(i, partners[q]) = static_cast<Scalar>(k2[offsets_[static_cast<size_t>(i)] + q]);
      }
    }
    return;
  }
  store_coefficients(c1, c2, nullptr);
}

void DeformedPairs::coefficients(Eigen::MatrixXd* c1, Eigen::MatrixXd* c2) const {
  table_coefficients(c1, c2);
}

void DeformedPairs::coefficients(Eigen::MatrixXf* c1, Eigen::MatrixXf* c2) const {
  table_coefficients(c1, c2);
}

Eigen::MatrixXd DeformedPairs::forces_and_coefficients(Eigen::MatrixXf* c1,
                                                       Eigen::MatrixXf* c2) const {
  if (sparse()) {  // two passes: the lists keep no table to fill on the way
    coefficients(c1, c2);
    return forces();
  }
  ThreadAccumulators forces(n_, 3);
  store_coefficients(c1, c2, &forces);
  return forces.sum();
}

template <class Table>
void DeformedPairs::store_coefficients(Table* c1, Table* c2, ThreadAccumulators* forces) const {
  using Scalar = typename Table::Scalar;
  c1->resize(n_, n_);
  c2->resize(n_, n_);
  advise_huge_pages(c1->data(), sizeof(Scalar) * static_cast<double>(c1->size()));
  advise_huge_pages(c2->data(), sizeof(Scalar) * static_cast<double>(c2->size()));
  const double *area = area_.data(), *count = count_.data();
  const PairColumns p = columns_of(x_, u_);
  with_kinematics(kinematics_, [&](auto policy) {
    using K = decltype(policy);
    with_count(mean_, [&](auto mean) {
      for_each_row([&](int i, int j0, int first, int end, const RowArrays& row, int thread) {
        Scalar* k1 = c1->col(i).data();
        Scalar* k2 = c2->col(i).data();
        if (forces != nullptr)
          row_pass<K, mean(), true, true>(p, area, count, i, j0, first, end, row,
                                          forces->columns(thread), k1, k2);
        else
          row_pass<K, mean(), false, true>(p, area, count, i, j0, first, end, row, {}, k1, k2);
      });
    });
  });
  // The diagonal after the pass, not before: zeroed first, it would be the
  // first touch of every page of both new tables, one thread taking all the
  // page faults that the threaded pass shares out.
  c1->diagonal().setZero();
  c2->diagonal().setZero();
}

namespace {

// The stored tangent's term of the pair (r, j) at r into p: r's position,
// direction and displacement less j's (the stencil's b, v, g), scalars all,
// so that the loop that calls it stays a vector loop.
template <class K>
inline void stored_term(const PairCoefficients& c, double b0, double b1, double b2, double v0,
                        double v1, double v2, double g0, double g1, double g2, double& p0,
                        double& p1, double& p2) {
  const double b_dot_v = b0 * v0 + b1 * v1 + b2 * v2;
  p0 = pair_tangent<K>(c, v0, b_dot_v, b0, g0);
  p1 = pair_tangent<K>(c, v1, b_dot_v, b1, g1);
  p2 = pair_tangent<K>(c, v2, b_dot_v, b2, g2);
}

// The stored tangent product over the pairs of rows i and i + 1: the pair
// (i, i + 1), then (i, j) and (i + 1, j) for j > i + 1 together, which
// reads column j's positions, displacements and directions once for both and
// updates its sums once. Each term is summed into out at its row and its
// opposite (the pair seen from j: b, v and g change sign) into out at j.
// Column i of c1, c2 holds row i's pairs (j > i): one contiguous run.
template <class K>
FIBERFLUID_VECTOR_CLONES void stored_tangent_rows(int i, int n, const float* k1a, const float* k2a,
                                                  const float* k1b, const float* k2b,
                                                  const double* const x[3],
                                                  const double* const d[3],
                                                  const double* const w[3],
                                                  const std::array<double*, 3>& out) {
  const double *x0 = x[0], *x1 = x[1], *x2 = x[2], *d0 = d[0], *d1 = d[1], *d2 = d[2];
  const double *w0 = w[0], *w1 = w[1], *w2 = w[2];
  double *o0 = out[0], *o1 = out[1], *o2 = out[2];
  const int h = i + 1;
  const double xa0 = x0[i], xa1 = x1[i], xa2 = x2[i], da0 = d0[i], da1 = d1[i], da2 = d2[i];
  const double wa0 = w0[i], wa1 = w1[i], wa2 = w2[i];
  const double xb0 = x0[h], xb1 = x1[h], xb2 = x2[h], db0 = d0[h], db1 = d1[h], db2 = d2[h];
  const double wb0 = w0[h], wb1 = w1[h], wb2 = w2[h];
  double sa0, sa1, sa2;  // the pair (i, i + 1) itself
  stored_term<K>({k1a[h], k2a[h]}, xa0 - xb0, xa1 - xb1, xa2 - xb2, wa0 - wb0, wa1 - wb1, wa2 - wb2,
                 da0 - db0, da1 - db1, da2 - db2, sa0, sa1, sa2);
  double sb0 = -sa0, sb1 = -sa1, sb2 = -sa2;
#pragma omp simd reduction(+ : sa0, sa1, sa2, sb0, sb1, sb2)
  for (int j = i + 2; j < n; ++j) {
    const double xj0 = x0[j], xj1 = x1[j], xj2 = x2[j], dj0 = d0[j], dj1 = d1[j], dj2 = d2[j];
    const double wj0 = w0[j], wj1 = w1[j], wj2 = w2[j];
    double pa0, pa1, pa2, pb0, pb1, pb2;
    stored_term<K>({k1a[j], k2a[j]}, xa0 - xj0, xa1 - xj1, xa2 - xj2, wa0 - wj0, wa1 - wj1,
                   wa2 - wj2, da0 - dj0, da1 - dj1, da2 - dj2, pa0, pa1, pa2);
    stored_term<K>({k1b[j], k2b[j]}, xb0 - xj0, xb1 - xj1, xb2 - xj2, wb0 - wj0, wb1 - wj1,
                   wb2 - wj2, db0 - dj0, db1 - dj1, db2 - dj2, pb0, pb1, pb2);
    sa0 += pa0, sa1 += pa1, sa2 += pa2;
    sb0 += pb0, sb1 += pb1, sb2 += pb2;
    o0[j] -= pa0 + pb0, o1[j] -= pa1 + pb1, o2[j] -= pa2 + pb2;
  }
  o0[i] += sa0, o1[i] += sa1, o2[i] += sa2;
  o0[h] += sb0, o1[h] += sb1, o2[h] += sb2;
}

}  // namespace

Eigen::MatrixXd stored_tangent_product(FiberKinematics kinematics, const Eigen::MatrixXd& X,
                                       const Eigen::MatrixXd& U, const Eigen::MatrixXf& C1,
                                       const Eigen::MatrixXf& C2, const Eigen::MatrixXd& W) {
  const int n = static_cast<int>(X.rows()), dim = static_cast<int>(X.cols());
  const std::vector<double> zeros(static_cast<size_t>(n), 0.0);
  const double *x[3], *d[3], *w[3];
  for (int a = 0; a < 3; ++a) {
    x[a] = a < dim ? X.col(a).data() : zeros.data();
    d[a] = a < dim ? U.col(a).data() : zeros.data();
    w[a] = a < dim ? W.col(a).data() : zeros.data();
  }
  // Two rows at a time, dealt out in turn (their lengths fall by two each:
  // the shares balance), a fixed share per thread: the same bits run after
  // run. A last row of its own (n odd) has no pairs j > i.
  ThreadAccumulators products(n, 3);
  with_kinematics(kinematics, [&](auto policy) {
    using K = decltype(policy);
#pragma omp parallel
    {
      const std::array<double*, 3> out = products.columns(omp_get_thread_num());
#pragma omp for schedule(static, 1)
      for (int i = 0; i < n - 1; i += 2)
        stored_tangent_rows<K>(i, n, C1.col(i).data(), C2.col(i).data(), C1.col(i + 1).data(),
                               C2.col(i + 1).data(), x, d, w, out);
    }
  });
  return products.sum();
}

}  // namespace fiberfluid::model

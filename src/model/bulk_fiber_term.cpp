// SPDX-License-Identifier: GPL-3.0-or-later
// The bulk fibers' term of the equilibrium equations (terms.hpp,
// BulkFiberTerm): residual, tangent (dense, listed, stored or as products)
// and readings, through the pair kernels (pair_kernels.hpp).
#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include "fiberfluid/geom/fiber_mask.hpp"
#include "fiberfluid/model/assembly.hpp"
#include "fiberfluid/model/fiber_reading.hpp"
#include "fiberfluid/model/pair_kernels.hpp"
#include "fiberfluid/model/pair_stencil.hpp"
#include "fiberfluid/model/terms.hpp"

namespace fiberfluid::model {
namespace {

using detail::read_fiber;

// Where each vertex's partners start in a sparse mask's pairs listed row by
// row (the listed coefficients' layout), N + 1 entries.
std::vector<size_t> list_offsets(const geom::FiberMask& mask) {
  std::vector<size_t> offsets(static_cast<size_t>(mask.num_vertices()) + 1, 0);
  for (int i = 0; i < mask.num_vertices(); ++i)
    offsets[static_cast<size_t>(i) + 1] =
        offsets[static_cast<size_t>(i)] + mask.neighbours(i).size();
  return offsets;
}

}  // namespace

// ---- Bulk fibers ---------------------------------------------------------------

namespace {

// The bulk fibers at X, U as the tiled kernels visit them.
DeformedPairs deformed_pairs(const TermContext& c, const Eigen::MatrixXd& X,
                             const Eigen::MatrixXd& U) {
  return DeformedPairs(c.model.surface.V, X, U, c.area0, c.pair_factors, c.model.material.law,
                       c.model.material.kinematics);
}

// Column pointers of the reference, current and displacement rows (three
// each; the third is all zeros in 2D).
struct Columns {
  const double* s[3];
  const double* x[3];
  const double* u[3];
  std::vector<double> zeros;

  Columns(const Eigen::MatrixXd& S, const Eigen::MatrixXd& X, const Eigen::MatrixXd& U)
      : zeros(static_cast<size_t>(S.rows()), 0.0) {
    for (int a = 0; a < 3; ++a) {
      const bool has = a < S.cols();
      s[a] = has ? S.col(a).data() : zeros.data();
      x[a] = has ? X.col(a).data() : zeros.data();
      u[a] = has ? U.col(a).data() : zeros.data();
    }
  }
};

// One row's pair state for dR/dtheta: h, L, r, strain, Y, Y' for every j.
struct RowState {
  std::vector<double> h, L, r, e, Y, Yp, dY;
  explicit RowState(size_t n) : h(n), L(n), r(n), e(n), Y(n), Yp(n), dY(n) {}
};

void fill_row(const TermContext& c, int i, const Columns& col, RowState& row) {
  const size_t n = static_cast<size_t>(c.model.num_vertices()), u = static_cast<size_t>(i);
  c.pair_factors.row(i, row.h.data());
  double *L = row.L.data(), *r = row.r.data(), *e = row.e.data();
  const double *s0 = col.s[0], *s1 = col.s[1], *s2 = col.s[2];
  const double *x0 = col.x[0], *x1 = col.x[1], *x2 = col.x[2];
#pragma omp simd
  for (size_t j = 0; j < n; ++j) {
    // j == i: h = 0 makes the pair vanish; lengths 1 there only avoid 0/0.
    L[j] = j == u ? 1.0 : pair_length(s0[u] - s0[j], s1[u] - s1[j], s2[u] - s2[j]);
    r[j] = j == u ? 1.0 : pair_length(x0[u] - x0[j], x1[u] - x1[j], x2[u] - x2[j]);
    e[j] = fiber_strain(r[j], L[j]);
  }
  c.model.material.law.evaluate(e, n, row.Y.data(), row.Yp.data());
}

}  // namespace

void BulkFiberTerm::coefficients(const Eigen::MatrixXd& X, const Eigen::MatrixXd& U,
                                 Eigen::MatrixXf* c1, Eigen::MatrixXf* c2) const {
  deformed_pairs(c_, X, U).coefficients(c1, c2);
}

void BulkFiberTerm::add_residual(const TermState& s, Eigen::VectorXd& R) const {
  const int n = c_.model.num_vertices();
  const Eigen::Vector3d m = c_.model.material.axis_factors;
  const Eigen::MatrixXd bulk = deformed_pairs(c_, s.X, s.U).forces();
  for (int a = 0; a < c_.model.dim(); ++a) R.segment(a * n, n) += m[a] * bulk.col(a);
}

void BulkFiberTerm::add_residual_and_coefficients(const TermState& s, Eigen::VectorXd& R,
                                                  Eigen::MatrixXf* c1, Eigen::MatrixXf* c2) const {
  const int n = c_.model.num_vertices();
  const Eigen::Vector3d m = c_.model.material.axis_factors;
  const Eigen::MatrixXd bulk = deformed_pairs(c_, s.X, s.U).forces_and_coefficients(c1, c2);
  for (int a = 0; a < c_.model.dim(); ++a) R.segment(a * n, n) += m[a] * bulk.col(a);
}

void BulkFiberTerm::add_tangent_product(const TermState& s, const Eigen::VectorXd&,
                                        const Eigen::MatrixXd& W, Eigen::VectorXd& out) const {
  const int n = c_.model.num_vertices();
  const Eigen::Vector3d m = c_.model.material.axis_factors;
  const Eigen::MatrixXd bulk = deformed_pairs(c_, s.X, s.U).tangent_product(W);
  for (int a = 0; a < c_.model.dim(); ++a) out.segment(a * n, n) += m[a] * bulk.col(a);
}

void BulkFiberTerm::add_tangent(const TermState& s, TangentSink& J) const {
  if (sparse()) {
    std::vector<double> c1, c2;
    listed_coefficients(s.X, s.U, &c1, &c2);
    return add_listed_blocks(s.X, s.U, c1, c2, J);
  }
  Eigen::MatrixXd c1, c2;  // in double: the dense tangent is exact
  deformed_pairs(c_, s.X, s.U).coefficients(&c1, &c2);
  if (J.dense() != nullptr) return add_dense_blocks(s.X, s.U, c1, c2, *J.dense());
  // Every pair kept (or a dense mask) into a sparse tangent: N^2 entries.
  const int n = c_.model.num_vertices();
  Eigen::MatrixXd bulk = Eigen::MatrixXd::Zero(c_.model.num_unknowns(), c_.model.num_unknowns());
  add_dense_blocks(s.X, s.U, c1, c2, bulk);
  for (Eigen::Index col = 0; col < c_.model.dim() * n; ++col)
    for (Eigen::Index row = 0; row < c_.model.dim() * n; ++row)
      if (bulk(row, col) != 0.0) J.add(row, col, bulk(row, col));
}

bool BulkFiberTerm::sparse() const {
  return c_.pair_factors.mask() != nullptr && c_.pair_factors.mask()->sparse();
}

void BulkFiberTerm::listed_coefficients(const Eigen::MatrixXd& X, const Eigen::MatrixXd& U,
                                        std::vector<double>* c1, std::vector<double>* c2) const {
  deformed_pairs(c_, X, U).listed_coefficients(c1, c2);
}

std::vector<FiberReading> BulkFiberTerm::readings(
    const TermState& s, const std::vector<std::pair<int, int>>& pairs) const {
  // Each pair's c1, from the kernels that the residual uses.
  std::vector<double> force_coefficient(pairs.size(), 0.0);
  std::vector<double> c1, c2;
  if (sparse()) {
    listed_coefficients(s.X, s.U, &c1, &c2);
    const geom::FiberMask& mask = *c_.pair_factors.mask();
    const std::vector<size_t> offsets = list_offsets(mask);
    for (size_t p = 0; p < pairs.size(); ++p) {
      const auto [i, j] = pairs[p];
      const std::vector<int>& partners = mask.neighbours(i);
      const auto at = std::lower_bound(partners.begin(), partners.end(), j);
      if (at != partners.end() && *at == j)  // not listed: pruned
        force_coefficient[p] =
            c1[offsets[static_cast<size_t>(i)] + static_cast<size_t>(at - partners.begin())];
    }
  } else {
    Eigen::MatrixXd dense_c1, dense_c2;
    deformed_pairs(c_, s.X, s.U).coefficients(&dense_c1, &dense_c2);  // double: exact readings
    for (size_t p = 0; p < pairs.size(); ++p) {  // stored once: row max(i, j), column min
      const auto [i, j] = pairs[p];
      force_coefficient[p] = dense_c1(std::max(i, j), std::min(i, j));
    }
  }
  std::vector<FiberReading> out(pairs.size());
  const Eigen::MatrixXd& V0 = c_.model.surface.V;
  const Eigen::Vector3d m = c_.model.material.axis_factors;
  with_kinematics(c_.model.material.kinematics, [&](auto policy) {
    using K = decltype(policy);
    for (size_t p = 0; p < pairs.size(); ++p) {
      const auto [i, j] = pairs[p];
      out[p] =
          read_fiber<K>(i, j, {force_coefficient[p], 0.0}, padded_row(s.X, i) - padded_row(s.X, j),
                        padded_row(s.U, i) - padded_row(s.U, j),
                        (padded_row(V0, i) - padded_row(V0, j)).norm(), m);
    }
  });
  return out;
}

template <class Body>
void BulkFiberTerm::for_each_listed_row(const std::vector<double>& c1,
                                        const std::vector<double>& c2, Body&& body) const {
  const geom::FiberMask& mask = *c_.pair_factors.mask();
  const int n = c_.model.num_vertices();
  const std::vector<size_t> offsets = list_offsets(mask);
#pragma omp parallel for schedule(dynamic, 64)
  for (int i = 0; i < n; ++i)
    body(i, mask.neighbours(i), c1.data() + offsets[static_cast<size_t>(i)],
         c2.data() + offsets[static_cast<size_t>(i)]);
}

void BulkFiberTerm::add_listed_blocks(const Eigen::MatrixXd& X, const Eigen::MatrixXd& U,
                                      const std::vector<double>& C1, const std::vector<double>& C2,
                                      TangentSink& J) const {
  const int n = c_.model.num_vertices(), dim = c_.model.dim();
  const Eigen::Vector3d m = c_.model.material.axis_factors;
  // Row i's entries: -m_a T_ab(i, j) at (a i, b j) for each partner j, and
  // their sum with the sign turned at (a i, b i); rows gathered per thread.
  std::vector<std::vector<Eigen::Triplet<double>>> rows(static_cast<size_t>(n));
  with_kinematics(c_.model.material.kinematics, [&](auto policy) {
    using K = decltype(policy);
    for_each_listed_row(
        C1, C2, [&](int i, const std::vector<int>& partners, const double* c1, const double* c2) {
          std::vector<Eigen::Triplet<double>>& out = rows[static_cast<size_t>(i)];
          out.reserve(partners.size() * dim * dim + dim * dim);
          double diagonal[3][3] = {{0, 0, 0}, {0, 0, 0}, {0, 0, 0}};
          for (size_t q = 0; q < partners.size(); ++q) {
            const int j = partners[q];
            const PairCoefficients c{c1[q], c2[q]};
            for (int a = 0; a < dim; ++a)
              for (int b = 0; b < dim; ++b) {
                const double t = pair_tangent_entry<K>(c, a == b, X(i, a) - X(j, a),
                                                       U(i, a) - U(j, a), X(i, b) - X(j, b));
                diagonal[a][b] += t;
                out.emplace_back(a * n + i, b * n + j, -m[a] * t);
              }
          }
          for (int a = 0; a < dim; ++a)
            for (int b = 0; b < dim; ++b)
              out.emplace_back(a * n + i, b * n + i, m[a] * diagonal[a][b]);
        });
  });
  for (const auto& row : rows)
    for (const Eigen::Triplet<double>& t : row) J.add(t.row(), t.col(), t.value());
}

void BulkFiberTerm::add_listed_product(const Eigen::MatrixXd& X, const Eigen::MatrixXd& U,
                                       const std::vector<double>& C1, const std::vector<double>& C2,
                                       const Eigen::MatrixXd& W, Eigen::VectorXd& out) const {
  const int n = c_.model.num_vertices(), dim = c_.model.dim();
  const Eigen::Vector3d m = c_.model.material.axis_factors;
  with_kinematics(c_.model.material.kinematics, [&](auto policy) {
    using K = decltype(policy);
    for_each_listed_row(
        C1, C2, [&](int i, const std::vector<int>& partners, const double* c1, const double* c2) {
          double product[3] = {0.0, 0.0, 0.0};
          for (size_t q = 0; q < partners.size(); ++q) {
            const int j = partners[q];
            Eigen::Vector3d b = Eigen::Vector3d::Zero(), v = Eigen::Vector3d::Zero(),
                            d = Eigen::Vector3d::Zero();
            for (int a = 0; a < dim; ++a) {
              b[a] = X(i, a) - X(j, a);
              v[a] = W(i, a) - W(j, a);
              d[a] = U(i, a) - U(j, a);
            }
            const double b_dot_v = b.dot(v);
            for (int a = 0; a < dim; ++a)
              product[a] += pair_tangent<K>({c1[q], c2[q]}, v[a], b_dot_v, b[a], d[a]);
          }
          for (int a = 0; a < dim; ++a) out[a * n + i] += m[a] * product[a];
        });
  });
}

void BulkFiberTerm::add_dense_blocks(const Eigen::MatrixXd& X, const Eigen::MatrixXd& U,
                                     const Eigen::MatrixXd& C1, const Eigen::MatrixXd& C2,
                                     Eigen::MatrixXd& J) const {
  const int n = c_.model.num_vertices(), dim = c_.model.dim();
  const Eigen::Vector3d m = c_.model.material.axis_factors;
  // For j != i: J(a i, b j) = -m_a T_ab(i, j) (the stencil's
  // pair_tangent_entry), and each diagonal block is minus the sum of its
  // row's off-diagonal ones. The coefficients are symmetric, stored once
  // (the lower triangle: column min(i, j), row max(i, j)).
  const auto pair = [&](int i, int j) -> PairCoefficients {
    const int low = std::min(i, j), high = std::max(i, j);
    return {C1(high, low), C2(high, low)};
  };
  with_kinematics(c_.model.material.kinematics, [&](auto policy) {
    using K = decltype(policy);
    // T_ab of the pair (i, j) with its coefficients c.
    const auto block = [&](int i, int j, const PairCoefficients& c, int a, int b) {
      return pair_tangent_entry<K>(c, a == b, X(i, a) - X(j, a), U(i, a) - U(j, a),
                                   X(i, b) - X(j, b));
    };
#pragma omp parallel for schedule(dynamic, 16)
    for (int j = 0; j < n; ++j)
      for (int a = 0; a < dim; ++a)
        for (int b = 0; b < dim; ++b) {
          double* column = J.col(b * n + j).data() + a * n;
          for (int i = 0; i < n; ++i)
            if (i != j) column[i] += -m[a] * block(i, j, pair(i, j), a, b);
        }
#pragma omp parallel for schedule(dynamic, 16)
    for (int i = 0; i < n; ++i)
      for (int a = 0; a < dim; ++a)
        for (int b = 0; b < dim; ++b) {
          double sum = 0.0;
          for (int j = 0; j < n; ++j)
            if (j != i) sum += block(i, j, pair(i, j), a, b);
          J(a * n + i, b * n + i) += m[a] * sum;
        }
  });
}

void BulkFiberTerm::add_stored_product(const Eigen::MatrixXd& X, const Eigen::MatrixXd& U,
                                       const Eigen::MatrixXf& C1, const Eigen::MatrixXf& C2,
                                       const Eigen::MatrixXd& W, Eigen::VectorXd& out) const {
  const int n = c_.model.num_vertices(), dim = c_.model.dim();
  const Eigen::Vector3d m = c_.model.material.axis_factors;
  const Eigen::MatrixXd product =
      stored_tangent_product(c_.model.material.kinematics, X, U, C1, C2, W);
  for (int a = 0; a < dim; ++a) out.segment(a * n, n) += m[a] * product.col(a);
}

void BulkFiberTerm::add_parameter_derivative(const TermState& s, const MaterialParameter& p,
                                             Eigen::Ref<Eigen::VectorXd> column) const {
  if (p.kind == MaterialParameter::Kind::SurfaceTension) return;
  const int n = c_.model.num_vertices(), dim = c_.model.dim();
  const Eigen::Vector3d m = c_.model.material.axis_factors;
  const FiberLaw& law = c_.model.material.law;
  // factor_a: the fiber force of that axis over its factor; a law parameter:
  // m_a times the force's derivative in it.
  const int axis = p.kind == MaterialParameter::Kind::AxisFactor ? p.index : -1;
  const Columns col(c_.model.surface.V, s.X, s.U);
  with_kinematics(c_.model.material.kinematics, [&](auto policy) {
    using K = decltype(policy);
#pragma omp parallel
    {
      RowState row(static_cast<size_t>(n));
#pragma omp for schedule(dynamic, 16)
      for (int i = 0; i < n; ++i) {
        fill_row(c_, i, col, row);
        if (axis < 0) law.evaluate_derivative(p.index, row.e.data(), row.e.size(), row.dY.data());
        const auto u = static_cast<size_t>(i);
        // The rest tension and its derivative, times the pair's factor (line_measure.hpp).
        const double rest = law.rest_tension();
        const double d_rest = axis >= 0 ? 0.0 : law.rest_tension_derivative(p.index);
        const LineMeasure* lines = c_.pair_factors.lines();
        double sum[3] = {0.0, 0.0, 0.0};
        for (size_t j = 0; j < static_cast<size_t>(n); ++j) {
          if (row.h[j] == 0.0) continue;
          const double a =
              bulk_weight(row.h[j], c_.area0[i], c_.area0[static_cast<Eigen::Index>(j)], row.L[j]);
          const double factor =
              (rest != 0.0 || d_rest != 0.0) && lines != nullptr ? lines->rest_factor(u, j) : 1.0;
          const PairCoefficients pc =
              K::coefficients(a, row.Y[j], row.Yp[j], row.r[j], row.L[j], rest * factor);
          const double dY = axis >= 0 ? 0.0 : row.dY[j];
          for (int k = 0; k < 3; ++k) {
            const double b = col.x[k][u] - col.x[k][j], d = col.u[k][u] - col.u[k][j];
            sum[k] += axis >= 0 ? pair_force<K>(pc, b, d)
                                : pair_parameter_force<K>(a, dY, row.r[j], row.L[j], b, d,
                                                          d_rest * factor);
          }
        }
        if (axis >= 0)
          column[axis * n + i] += sum[axis];
        else
          for (int a = 0; a < dim; ++a) column[a * n + i] += m[a] * sum[a];
      }
    }
  });
}

}  // namespace fiberfluid::model

// SPDX-License-Identifier: GPL-3.0-or-later
// BulkPairs: the pair sums of the rest state (row sums, the Laplacian
// product, the off-diagonal blocks), tile by tile.
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

// The set's arrays, indexed by position in the set.
struct SetArrays {
  const double *x0, *x1, *x2, *area, *count;
};

// The multipliers of a tile's rows: m + r * stride (stride 0: one row of ones).
struct Multipliers {
  const double* m;
  int stride;
};

// BulkPairs's weight w_ij from the squared distance r2 (the stencil's
// counted_bulk_weight; DeformedPairs's a is the same at the reference length).
inline double weight(double m, double area_i, double area_j, double count_i, double count_j,
                     double r2, bool mean) {
  return counted_bulk_weight(m, area_i, area_j, count_i, count_j, std::sqrt(r2), mean);
}

// (L V) over one tile for three columns: row sums into out at i, the
// opposite terms (w_ji (v_j - v_i) = -w_ij (v_i - v_j)) into out at j.
template <bool kMean>
FIBERFLUID_VECTOR_CLONES void product_tile(const SetArrays& s, const Tile& t, Multipliers mult,
                                           const double* const v[3],
                                           const std::array<double*, 3>& out) {
  const double *x0 = s.x0, *x1 = s.x1, *x2 = s.x2, *a = s.area, *c = s.count;
  const double *v0 = v[0], *v1 = v[1], *v2 = v[2];
  double *o0 = out[0], *o1 = out[1], *o2 = out[2];
  for (int r = 0; r < t.ni; ++r) {
    const int i = t.i0 + r;
    const double xi = x0[i], yi = x1[i], zi = x2[i], ai = a[i], ci = c[i];
    const double ui = v0[i], vi = v1[i], wi = v2[i];
    const double* m = mult.m + static_cast<size_t>(r) * mult.stride;  // m[j - j0]
    double s0 = 0.0, s1 = 0.0, s2 = 0.0;
#pragma omp simd reduction(+ : s0, s1, s2)
    for (int j = t.j0 + (t.diagonal ? r + 1 : 0); j < t.j0 + t.nj; ++j) {
      const double dx = xi - x0[j], dy = yi - x1[j], dz = zi - x2[j];
      const double w = weight(m[j - t.j0], ai, a[j], ci, c[j], dx * dx + dy * dy + dz * dz, kMean);
      const double e0 = w * (ui - v0[j]), e1 = w * (vi - v1[j]), e2 = w * (wi - v2[j]);
      s0 += e0, s1 += e1, s2 += e2;
      o0[j] -= e0, o1[j] -= e1, o2[j] -= e2;
    }
    o0[i] += s0, o1[i] += s1, o2[i] += s2;
  }
}

// Row sums sum_j w_ij over one tile, into out at i and at j.
template <bool kMean>
FIBERFLUID_VECTOR_CLONES void row_sums_tile(const SetArrays& s, const Tile& t, Multipliers mult,
                                            double* out) {
  const double *x0 = s.x0, *x1 = s.x1, *x2 = s.x2, *a = s.area, *c = s.count;
  for (int r = 0; r < t.ni; ++r) {
    const int i = t.i0 + r;
    const double xi = x0[i], yi = x1[i], zi = x2[i], ai = a[i], ci = c[i];
    const double* m = mult.m + static_cast<size_t>(r) * mult.stride;  // m[j - j0]
    double sum = 0.0;
#pragma omp simd reduction(+ : sum)
    for (int j = t.j0 + (t.diagonal ? r + 1 : 0); j < t.j0 + t.nj; ++j) {
      const double dx = xi - x0[j], dy = yi - x1[j], dz = zi - x2[j];
      const double w = weight(m[j - t.j0], ai, a[j], ci, c[j], dx * dx + dy * dy + dz * dz, kMean);
      sum += w;
      out[j] += w;
    }
    out[i] += sum;
  }
}

// K(j, i) = K(i, j) = -scale w_ij over one tile of a column-major K: the
// columns i of the tile written whole (contiguous), then mirrored into the
// rows i in 32 x 32 blocks, so that the strided side touches 32 pages at a
// time (the TLB's reach) instead of one per column of the tile.
template <bool kMean, class Scalar>
FIBERFLUID_VECTOR_CLONES void block_tile(const SetArrays& s, const Tile& t, Multipliers mult,
                                         double scale, Scalar* K, Eigen::Index ld) {
  const double *x0 = s.x0, *x1 = s.x1, *x2 = s.x2, *a = s.area, *c = s.count;
  for (int r = 0; r < t.ni; ++r) {
    const int i = t.i0 + r;
    const double xi = x0[i], yi = x1[i], zi = x2[i], ai = a[i], ci = c[i];
    const double* m = mult.m + static_cast<size_t>(r) * mult.stride;  // m[j - j0]
    Scalar* column = K + static_cast<Eigen::Index>(i) * ld;
#pragma omp simd
    for (int j = t.j0 + (t.diagonal ? r + 1 : 0); j < t.j0 + t.nj; ++j) {
      const double dx = xi - x0[j], dy = yi - x1[j], dz = zi - x2[j];
      column[j] = static_cast<Scalar>(
          -scale * weight(m[j - t.j0], ai, a[j], ci, c[j], dx * dx + dy * dy + dz * dz, kMean));
    }
  }
  constexpr int B = 32;
  for (int jb = t.j0; jb < t.j0 + t.nj; jb += B)
    for (int ib = t.i0; ib < t.i0 + t.ni && (!t.diagonal || ib <= jb); ib += B)
      for (int j = jb; j < std::min(jb + B, t.j0 + t.nj); ++j) {
        Scalar* row_block = K + static_cast<Eigen::Index>(j) * ld;  // K(i, j), i in the block
        const int end = std::min(ib + B, t.diagonal ? j : t.i0 + t.ni);
        for (int i = ib; i < end; ++i) row_block[i] = K[static_cast<Eigen::Index>(i) * ld + j];
      }
}

}  // namespace

BulkPairs::BulkPairs(const Eigen::MatrixXd& X, const Eigen::VectorXd& area,
                     const PairFactors& factors, const std::vector<int>& vertices)
    : mask_(factors.mask()), influence_(factors.influence()), lines_(factors.lines()) {
  if (influence_.weighs()) reference_positions_ = factors.reference();
  if (vertices.empty()) {
    vertex_.resize(static_cast<size_t>(X.rows()));
    for (size_t k = 0; k < vertex_.size(); ++k) vertex_[k] = static_cast<int>(k);
  } else {
    vertex_ = vertices;
  }
  n_ = static_cast<int>(vertex_.size());
  if (sparse()) {
    position_.assign(static_cast<size_t>(X.rows()), -1);
    for (size_t k = 0; k < vertex_.size(); ++k)
      position_[static_cast<size_t>(vertex_[k])] = static_cast<int>(k);
  }
  const std::vector<double> counts = factors.vertex_counts();
  mean_ = factors.mean_count();
  for (auto& column : x_) column.assign(static_cast<size_t>(n_), 0.0);
  area_.resize(static_cast<size_t>(n_));
  count_.resize(static_cast<size_t>(n_));
  for (size_t k = 0; k < vertex_.size(); ++k) {
    const int v = vertex_[k];
    for (Eigen::Index d = 0; d < X.cols(); ++d) x_[d][k] = X(v, d);
    area_[k] = area[v];
    count_[k] = counts[static_cast<size_t>(v)];
  }
}

void BulkPairs::set_secant_law(const FiberLaw* law, const Eigen::MatrixXd* reference,
                               const Eigen::MatrixXd* strained) {
  law_ = law;
  reference_ = reference;
  strained_ = strained;
}

void BulkPairs::set_axis_projection(int axis, const Eigen::MatrixXd* positions) {
  projection_axis_ = axis;
  projection_positions_ = positions;
}

double BulkPairs::projection(int vi, int vj) const {
  const Eigen::RowVectorXd d = projection_positions_->row(vi) - projection_positions_->row(vj);
  const double squared = d.squaredNorm();
  return (squared > 0.0 ? d[projection_axis_] * d[projection_axis_] / squared : 0.0) +
         kProjectionFloor;
}

void BulkPairs::multipliers(const Tile& t, double* m) const {
  std::vector<double> strain(kTile), modulus(kTile), slope(kTile);
  for (int r = 0; r < t.ni; ++r) {
    const int vi = vertex_[static_cast<size_t>(t.i0 + r)];
    double* row = m + static_cast<size_t>(r) * kTile;
    const int* vj = vertex_.data() + t.j0;
    if (mask_ != nullptr) {
      const uint8_t* kept = mask_->row(vi);
      for (int q = 0; q < t.nj; ++q) row[q] = kept[vj[q]];
    } else {
      std::fill(row, row + t.nj, 1.0);
    }
    if (influence_.weighs())
      for (int q = 0; q < t.nj; ++q)
        if (row[q] != 0.0)
          row[q] *=
              influence_((reference_positions_.row(vi) - reference_positions_.row(vj[q])).norm());
    if (lines_ != nullptr)
      for (int q = 0; q < t.nj; ++q)
        if (row[q] != 0.0 && vj[q] != vi)
          row[q] *= (*lines_)(static_cast<size_t>(vi), static_cast<size_t>(vj[q]));
    if (projection_axis_ >= 0)
      for (int q = 0; q < t.nj; ++q)
        if (row[q] != 0.0 && vj[q] != vi) row[q] *= projection(vi, vj[q]);
    if (law_ == nullptr) continue;
    // The secant modulus at e_ij = |y_i - y_j| / L_ij - 1 (zero where i == j).
    for (int q = 0; q < t.nj; ++q) {
      const double length = (reference_->row(vi) - reference_->row(vj[q])).norm();
      strain[static_cast<size_t>(q)] =
          vj[q] == vi ? 0.0
                      : fiber_strain((strained_->row(vi) - strained_->row(vj[q])).norm(), length);
    }
    law_->evaluate(strain.data(), static_cast<size_t>(t.nj), modulus.data(), slope.data());
    for (int q = 0; q < t.nj; ++q)
      if (row[q] != 0.0) row[q] *= modulus[static_cast<size_t>(q)];  // a pruned fiber stays 0
  }
}

template <class Visit>
void BulkPairs::for_each_tile(Visit&& visit) const {
  const bool weighted = mask_ != nullptr || law_ != nullptr || influence_.weighs() ||
                        lines_ != nullptr || projection_axis_ >= 0;
  // Unweighted: one row of ones serves every row of every tile.
  std::vector<std::vector<double>> m(static_cast<size_t>(omp_get_max_threads()),
                                     std::vector<double>(weighted ? kTile * kTile : kTile, 1.0));
  for_each_tile_pair(n_, [&](const Tile& t, int thread) {
    double* tile_m = m[static_cast<size_t>(thread)].data();
    if (weighted) multipliers(t, tile_m);
    visit(t, Multipliers{tile_m, weighted ? kTile : 0}, thread);
  });
}

double BulkPairs::listed_weight(int r, int c) const {
  const int vi = vertex_[static_cast<size_t>(r)], vj = vertex_[static_cast<size_t>(c)];
  double m = 1.0;
  if (influence_.weighs())
    m = influence_((reference_positions_.row(vi) - reference_positions_.row(vj)).norm());
  if (law_ != nullptr) {
    const double length = (reference_->row(vi) - reference_->row(vj)).norm();
    m *= law_->modulus(fiber_strain((strained_->row(vi) - strained_->row(vj)).norm(), length));
  }
  if (lines_ != nullptr) m *= (*lines_)(static_cast<size_t>(vi), static_cast<size_t>(vj));
  if (projection_axis_ >= 0) m *= projection(vi, vj);
  const auto r_ = static_cast<size_t>(r), c_ = static_cast<size_t>(c);
  const double d0 = x_[0][r_] - x_[0][c_], d1 = x_[1][r_] - x_[1][c_], d2 = x_[2][r_] - x_[2][c_];
  return weight(m, area_[r_], area_[c_], count_[r_], count_[c_], d0 * d0 + d1 * d1 + d2 * d2,
                mean_);
}

template <class Visit>
void BulkPairs::for_each_listed(Visit&& visit) const {
#pragma omp parallel for schedule(dynamic, 64)
  for (int r = 0; r < n_; ++r)
    for (int j : mask_->neighbours(vertex_[static_cast<size_t>(r)])) {
      const int c = position_[static_cast<size_t>(j)];
      if (c >= 0) visit(r, c, listed_weight(r, c));
    }
}

Eigen::VectorXd BulkPairs::row_sums() const {
  if (sparse()) {
    Eigen::VectorXd sums = Eigen::VectorXd::Zero(n_);
    for_each_listed([&](int r, int, double w) { sums[r] += w; });
    return sums;
  }
  const SetArrays s{x_[0].data(), x_[1].data(), x_[2].data(), area_.data(), count_.data()};
  ThreadAccumulators sums(n_, 1);
  with_count(mean_, [&](auto mean) {
    for_each_tile([&](const Tile& t, Multipliers m, int thread) {
      row_sums_tile<mean()>(s, t, m, sums.column(thread, 0));
    });
  });
  return sums.sum().col(0);
}

Eigen::MatrixXd BulkPairs::laplacian_product(const Eigen::MatrixXd& V) const {
  if (sparse()) {  // each row gathers its own pairs: no accumulators
    Eigen::MatrixXd out = Eigen::MatrixXd::Zero(n_, V.cols());
    for_each_listed([&](int r, int c, double w) { out.row(r) += w * (V.row(r) - V.row(c)); });
    return out;
  }
  const SetArrays s{x_[0].data(), x_[1].data(), x_[2].data(), area_.data(), count_.data()};
  const auto k = static_cast<int>(V.cols());
  Eigen::MatrixXd out(n_, k);
  const Eigen::VectorXd zeros = Eigen::VectorXd::Zero(n_);
  // Each pair's weight serves three columns at once; unused ones read zeros.
  for (int first = 0; first < k; first += 3) {
    const int width = std::min(3, k - first);
    const double* columns[3];
    for (int c = 0; c < 3; ++c) columns[c] = c < width ? V.col(first + c).data() : zeros.data();
    ThreadAccumulators products(n_, 3);
    with_count(mean_, [&](auto mean) {
      for_each_tile([&](const Tile& t, Multipliers m, int thread) {
        product_tile<mean()>(s, t, m, columns, products.columns(thread));
      });
    });
    out.middleCols(first, width) = products.sum().leftCols(width);
  }
  return out;
}

void BulkPairs::add_off_diagonal(double scale, std::vector<Eigen::Triplet<double>>* entries) const {
  if (sparse()) {
    std::vector<std::vector<Eigen::Triplet<double>>> rows(static_cast<size_t>(n_));
    for_each_listed([&](int r, int c, double w) {
      rows[static_cast<size_t>(r)].emplace_back(r, c, -scale * w);
    });
    for (const auto& row : rows) entries->insert(entries->end(), row.begin(), row.end());
    return;
  }
  Eigen::MatrixXd K = Eigen::MatrixXd::Zero(n_, n_);
  fill_off_diagonal(scale, &K);
  for (int c = 0; c < n_; ++c)
    for (int r = 0; r < n_; ++r)
      if (r != c && K(r, c) != 0.0) entries->emplace_back(r, c, K(r, c));
}

template <class Matrix>
void BulkPairs::fill_off_diagonal_of(double scale, Matrix* K) const {
  using Scalar = typename Matrix::Scalar;
  if (sparse()) {
    for (int c = 0; c < n_; ++c)
      for (int r = 0; r < n_; ++r)
        if (r != c) (*K)(r, c) = 0;
    for_each_listed([&](int r, int c, double w) { (*K)(r, c) = static_cast<Scalar>(-scale * w); });
    return;
  }
  const SetArrays s{x_[0].data(), x_[1].data(), x_[2].data(), area_.data(), count_.data()};
  Scalar* data = K->data();
  const Eigen::Index ld = K->rows();
  // Tiles write disjoint parts of K: no accumulators.
  with_count(mean_, [&](auto mean) {
    for_each_tile(
        [&](const Tile& t, Multipliers m, int) { block_tile<mean()>(s, t, m, scale, data, ld); });
  });
}

void BulkPairs::fill_off_diagonal(double scale, Eigen::MatrixXd* K) const {
  fill_off_diagonal_of(scale, K);
}

void BulkPairs::fill_off_diagonal(double scale, Eigen::MatrixXf* K) const {
  fill_off_diagonal_of(scale, K);
}

}  // namespace fiberfluid::model

// SPDX-License-Identifier: GPL-3.0-or-later
#include "model/pair_kernels.hpp"

#include <omp.h>

#include <algorithm>
#include <cmath>

#include "geom/fiber_pruning.hpp"

// Each tile loop is compiled three times, and the loader picks the widest the
// CPU has (an ifunc): the default build stays portable. Not with clang (the
// sanitized fuzz build), where the baseline alone is compiled.
#if defined(__GNUC__) && !defined(__clang__) && defined(__x86_64__)
#define FIBERFLUID_VECTOR_CLONES \
  __attribute__((target_clones("arch=x86-64-v4", "arch=x86-64-v3", "default")))
#else
#define FIBERFLUID_VECTOR_CLONES
#endif

namespace fiberfluid::model {
namespace {

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

// w_ij (BulkPairs) from the squared distance r2.
inline double weight(double m, double area_i, double area_j, double count_i, double count_j,
                     double r2) {
  return m * (area_i + area_j) / ((count_i + count_j) * std::sqrt(r2));
}

// (L V) over one tile for three columns: row sums into out at i, the
// opposite terms (w_ji (v_j - v_i) = -w_ij (v_i - v_j)) into out at j.
FIBERFLUID_VECTOR_CLONES
void product_tile(const SetArrays& s, const Tile& t, Multipliers mult, const double* const v[3],
                  double* const out[3]) {
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
      const double w = weight(m[j - t.j0], ai, a[j], ci, c[j], dx * dx + dy * dy + dz * dz);
      const double e0 = w * (ui - v0[j]), e1 = w * (vi - v1[j]), e2 = w * (wi - v2[j]);
      s0 += e0, s1 += e1, s2 += e2;
      o0[j] -= e0, o1[j] -= e1, o2[j] -= e2;
    }
    o0[i] += s0, o1[i] += s1, o2[i] += s2;
  }
}

// Row sums sum_j w_ij over one tile, into out at i and at j.
FIBERFLUID_VECTOR_CLONES
void row_sums_tile(const SetArrays& s, const Tile& t, Multipliers mult, double* out) {
  const double *x0 = s.x0, *x1 = s.x1, *x2 = s.x2, *a = s.area, *c = s.count;
  for (int r = 0; r < t.ni; ++r) {
    const int i = t.i0 + r;
    const double xi = x0[i], yi = x1[i], zi = x2[i], ai = a[i], ci = c[i];
    const double* m = mult.m + static_cast<size_t>(r) * mult.stride;  // m[j - j0]
    double sum = 0.0;
#pragma omp simd reduction(+ : sum)
    for (int j = t.j0 + (t.diagonal ? r + 1 : 0); j < t.j0 + t.nj; ++j) {
      const double dx = xi - x0[j], dy = yi - x1[j], dz = zi - x2[j];
      const double w = weight(m[j - t.j0], ai, a[j], ci, c[j], dx * dx + dy * dy + dz * dz);
      sum += w;
      out[j] += w;
    }
    out[i] += sum;
  }
}

// K(j, i) = K(i, j) = -scale w_ij over one tile of a column-major K: column i
// written whole (contiguous), then mirrored into row i while it is in L1.
FIBERFLUID_VECTOR_CLONES
void block_tile(const SetArrays& s, const Tile& t, Multipliers mult, double scale, double* K,
                Eigen::Index ld) {
  const double *x0 = s.x0, *x1 = s.x1, *x2 = s.x2, *a = s.area, *c = s.count;
  for (int r = 0; r < t.ni; ++r) {
    const int i = t.i0 + r;
    const double xi = x0[i], yi = x1[i], zi = x2[i], ai = a[i], ci = c[i];
    const double* m = mult.m + static_cast<size_t>(r) * mult.stride;  // m[j - j0]
    double* column = K + static_cast<Eigen::Index>(i) * ld;
    const int first = t.j0 + (t.diagonal ? r + 1 : 0), end = t.j0 + t.nj;
#pragma omp simd
    for (int j = first; j < end; ++j) {
      const double dx = xi - x0[j], dy = yi - x1[j], dz = zi - x2[j];
      column[j] = -scale * weight(m[j - t.j0], ai, a[j], ci, c[j], dx * dx + dy * dy + dz * dz);
    }
    for (int j = first; j < end; ++j) K[static_cast<Eigen::Index>(j) * ld + i] = column[j];
  }
}

}  // namespace

BulkPairs::BulkPairs(const Eigen::MatrixXd& X, const Eigen::VectorXd& area,
                     const PairFactors& factors, const std::vector<int>& vertices)
    : mask_(factors.mask()) {
  if (vertices.empty()) {
    vertex_.resize(static_cast<size_t>(X.rows()));
    for (size_t k = 0; k < vertex_.size(); ++k) vertex_[k] = static_cast<int>(k);
  } else {
    vertex_ = vertices;
  }
  n_ = static_cast<int>(vertex_.size());
  const std::vector<double> counts = factors.vertex_counts();
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
    if (law_ == nullptr) continue;
    // The secant modulus at e_ij = |y_i - y_j| / L_ij - 1 (zero where i == j).
    for (int q = 0; q < t.nj; ++q) {
      const double length = (reference_->row(vi) - reference_->row(vj[q])).norm();
      strain[static_cast<size_t>(q)] =
          vj[q] == vi ? 0.0 : (strained_->row(vi) - strained_->row(vj[q])).norm() / length - 1.0;
    }
    law_->evaluate(strain.data(), static_cast<size_t>(t.nj), modulus.data(), slope.data());
    for (int q = 0; q < t.nj; ++q)
      if (row[q] != 0.0) row[q] *= modulus[static_cast<size_t>(q)];  // a pruned fiber stays 0
  }
}

template <class Visit>
void BulkPairs::for_each_tile(Visit&& visit) const {
  std::vector<Tile> tiles;
  for (int i0 = 0; i0 < n_; i0 += kTile)
    for (int j0 = i0; j0 < n_; j0 += kTile)
      tiles.push_back({i0, std::min(kTile, n_ - i0), j0, std::min(kTile, n_ - j0), i0 == j0});
  const bool weighted = mask_ != nullptr || law_ != nullptr;
#pragma omp parallel
  {
    // Unweighted: one row of ones serves every row of every tile.
    std::vector<double> m(weighted ? static_cast<size_t>(kTile) * kTile : kTile, 1.0);
    const Multipliers mult{m.data(), weighted ? kTile : 0};
    const int thread = omp_get_thread_num();
    // A fixed share per thread: the same bits run after run.
#pragma omp for schedule(static, 1)
    for (size_t k = 0; k < tiles.size(); ++k) {
      if (weighted) multipliers(tiles[k], m.data());
      visit(tiles[k], mult, thread);
    }
  }
}

Eigen::VectorXd BulkPairs::row_sums() const {
  const SetArrays s{x_[0].data(), x_[1].data(), x_[2].data(), area_.data(), count_.data()};
  // One accumulator per thread (summed in thread order: deterministic).
  std::vector<Eigen::VectorXd> partial(static_cast<size_t>(omp_get_max_threads()),
                                       Eigen::VectorXd::Zero(n_));
  for_each_tile([&](const Tile& t, Multipliers m, int thread) {
    row_sums_tile(s, t, m, partial[static_cast<size_t>(thread)].data());
  });
  Eigen::VectorXd sums = Eigen::VectorXd::Zero(n_);
  for (const Eigen::VectorXd& p : partial) sums += p;
  return sums;
}

Eigen::MatrixXd BulkPairs::laplacian_product(const Eigen::MatrixXd& V) const {
  const SetArrays s{x_[0].data(), x_[1].data(), x_[2].data(), area_.data(), count_.data()};
  const auto k = static_cast<int>(V.cols());
  Eigen::MatrixXd out(n_, k);
  const Eigen::VectorXd zeros = Eigen::VectorXd::Zero(n_);
  const size_t threads = static_cast<size_t>(omp_get_max_threads());
  // Each pair's weight serves three columns at once; unused ones read zeros.
  for (int first = 0; first < k; first += 3) {
    const int width = std::min(3, k - first);
    const double* columns[3];
    for (int c = 0; c < 3; ++c) columns[c] = c < width ? V.col(first + c).data() : zeros.data();
    std::vector<Eigen::MatrixXd> partial(threads, Eigen::MatrixXd::Zero(n_, 3));
    for_each_tile([&](const Tile& t, Multipliers m, int thread) {
      Eigen::MatrixXd& p = partial[static_cast<size_t>(thread)];
      double* const outs[3] = {p.col(0).data(), p.col(1).data(), p.col(2).data()};
      product_tile(s, t, m, columns, outs);
    });
    Eigen::MatrixXd sum = Eigen::MatrixXd::Zero(n_, 3);
    for (const Eigen::MatrixXd& p : partial) sum += p;
    out.middleCols(first, width) = sum.leftCols(width);
  }
  return out;
}

void BulkPairs::fill_off_diagonal(double scale, Eigen::MatrixXd* K) const {
  const SetArrays s{x_[0].data(), x_[1].data(), x_[2].data(), area_.data(), count_.data()};
  double* data = K->data();
  const Eigen::Index ld = K->rows();
  // Tiles write disjoint parts of K: no accumulators.
  for_each_tile([&](const Tile& t, Multipliers m, int) { block_tile(s, t, m, scale, data, ld); });
}

}  // namespace fiberfluid::model

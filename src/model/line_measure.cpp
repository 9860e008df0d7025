// SPDX-License-Identifier: GPL-3.0-or-later
#include "fiberfluid/model/line_measure.hpp"

#include <omp.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>

#include "fiberfluid/model/pair_stencil.hpp"

namespace fiberfluid::model {

LineMeasure::LineMeasure(const Eigen::MatrixXd& reference, const Eigen::MatrixXd& area_vectors,
                         const geom::FiberMask* fibers, bool balance_rest) {
  for (int a = 0; a < 3; ++a) {
    s_[a].assign(static_cast<size_t>(reference.rows()), 0.0);
    area_[a].assign(static_cast<size_t>(reference.rows()), 0.0);
    if (a >= reference.cols()) continue;
    for (Eigen::Index i = 0; i < reference.rows(); ++i) {
      s_[a][static_cast<size_t>(i)] = reference(i, a);
      area_[a][static_cast<size_t>(i)] = area_vectors(i, a);
    }
  }
  if (balance_rest) balance_rest_tensions(fibers);
}

namespace {

// A fiber with a measure: its ends, m_ij and its unit direction n_ij.
struct MeasuredPair {
  int i, j;
  double m;
  Eigen::Vector3d n;
};

// (L g)_i = sum_j m n n^T (g_i - g_j), rows by vertex, on the OpenMP threads.
Eigen::MatrixXd rest_laplacian(const std::vector<MeasuredPair>& pairs, const Eigen::MatrixXd& g) {
  std::vector<Eigen::MatrixXd> parts(static_cast<size_t>(omp_get_max_threads()));
#pragma omp parallel
  {
    Eigen::MatrixXd& out = parts[static_cast<size_t>(omp_get_thread_num())];
    out = Eigen::MatrixXd::Zero(g.rows(), 3);
#pragma omp for schedule(static)
    for (size_t k = 0; k < pairs.size(); ++k) {
      const MeasuredPair& p = pairs[k];
      const Eigen::Vector3d f = p.m * p.n.dot(g.row(p.i) - g.row(p.j)) * p.n;
      out.row(p.i) += f.transpose();
      out.row(p.j) -= f.transpose();
    }
  }
  Eigen::MatrixXd sum = Eigen::MatrixXd::Zero(g.rows(), 3);
  for (const Eigen::MatrixXd& part : parts)
    if (part.size() > 0) sum += part;
  return sum;
}

void remove_mean(Eigen::MatrixXd& v) { v.rowwise() -= v.colwise().mean(); }

}  // namespace

void LineMeasure::balance_rest_tensions(const geom::FiberMask* fibers) {
  const auto n = static_cast<int>(s_[0].size());
  std::vector<MeasuredPair> pairs;
  const auto add = [&](int i, int j) {
    const double m = (*this)(static_cast<size_t>(i), static_cast<size_t>(j));
    if (!(m > 0.0)) return;
    Eigen::Vector3d d;
    for (int a = 0; a < 3; ++a)
      d[a] = s_[a][static_cast<size_t>(j)] - s_[a][static_cast<size_t>(i)];
    pairs.push_back({i, j, m, d.normalized()});
  };
  for (int i = 0; i < n; ++i) {
    if (fibers != nullptr)
      fibers->for_each_kept(i, [&](int j) {
        if (j > i) add(i, j);
      });
    else
      for (int j = i + 1; j < n; ++j) add(i, j);
  }
  // The right side -(sum_j m n + 5/3 S_i), and the block Jacobi preconditioner.
  Eigen::MatrixXd b(n, 3), S(n, 3);
  for (int i = 0; i < n; ++i)
    for (int a = 0; a < 3; ++a) S(i, a) = area_[a][static_cast<size_t>(i)];
  b = -kRestStress * S;
  std::vector<Eigen::Matrix3d> block(static_cast<size_t>(n), Eigen::Matrix3d::Zero());
  for (const MeasuredPair& p : pairs) {
    b.row(p.i) -= p.m * p.n.transpose();
    b.row(p.j) += p.m * p.n.transpose();
    const Eigen::Matrix3d nn = p.m * p.n * p.n.transpose();
    block[static_cast<size_t>(p.i)] += nn;
    block[static_cast<size_t>(p.j)] += nn;
  }
  const auto misfit = [&](const Eigen::MatrixXd& r) {
    double largest = 0.0;
    for (int i = 0; i < n; ++i)
      largest = std::max(largest, r.row(i).norm() / (kRestStress * S.row(i).norm()));
    return largest;
  };
  balance_.largest_before = misfit(b);
  remove_mean(b);  // zero on a closed surface, but for rounding
  for (Eigen::Matrix3d& B : block) B = B.completeOrthogonalDecomposition().pseudoInverse();
  const auto precondition = [&](const Eigen::MatrixXd& r) {
    Eigen::MatrixXd z(n, 3);
    for (int i = 0; i < n; ++i)
      z.row(i) = (block[static_cast<size_t>(i)] * r.row(i).transpose()).transpose();
    remove_mean(z);
    return z;
  };
  // Conjugate gradients on the singular, consistent system L g = b (g up to
  // a constant, which leaves every factor unchanged).
  Eigen::MatrixXd g = Eigen::MatrixXd::Zero(n, 3), r = b, z = precondition(r), p = z;
  double rz = (r.array() * z.array()).sum();
  const double tolerance = 1e-12 * b.norm();
  constexpr int kMaxIterations = 2000;
  int k = 0;
  for (; k < kMaxIterations && r.norm() > tolerance; ++k) {
    const Eigen::MatrixXd Lp = rest_laplacian(pairs, p);
    const double alpha = rz / (p.array() * Lp.array()).sum();
    g += alpha * p;
    r -= alpha * Lp;
    z = precondition(r);
    const double next = (r.array() * z.array()).sum();
    p = z + (next / rz) * p;
    rz = next;
  }
  balance_.iterations = k;
  balance_.largest_after = misfit(b - rest_laplacian(pairs, g));
  for (int a = 0; a < 3; ++a) rest_[a].assign(g.col(a).data(), g.col(a).data() + n);
  balance_.least_factor = balance_.largest_factor = 1.0;
  for (const MeasuredPair& q : pairs) {
    const double factor = rest_factor(static_cast<size_t>(q.i), static_cast<size_t>(q.j));
    balance_.least_factor = std::min(balance_.least_factor, factor);
    balance_.largest_factor = std::max(balance_.largest_factor, factor);
  }
}

LineMeasure::Pair LineMeasure::pair(size_t i, size_t j) const {
  double d_si = 0.0, d_sj = 0.0, squared = 0.0, along = 0.0;
  const bool balanced = !rest_[0].empty();
  for (int a = 0; a < 3; ++a) {
    const double d = s_[a][j] - s_[a][i];
    d_si += d * area_[a][i];
    d_sj += d * area_[a][j];
    squared += d * d;
    if (balanced) along += (rest_[a][i] - rest_[a][j]) * d;
  }
  const double length = std::sqrt(squared);
  return {line_measure(d_si, d_sj, length), 1.0 + along / length};
}

}  // namespace fiberfluid::model

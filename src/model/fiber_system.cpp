// SPDX-License-Identifier: GPL-3.0-or-later
#include "fiberfluid/model/fiber_system.hpp"

#include <algorithm>
#include <cmath>

#include "fiberfluid/geom/area_vectors.hpp"
#include "fiberfluid/model/fiber_network.hpp"
#include "fiberfluid/model/pair_stencil.hpp"
#include "fiberfluid/util/error.hpp"
#include "fiberfluid/util/run_control.hpp"

namespace fiberfluid::model {
namespace {

// Column-major copies of the coordinates, so the pair loops vectorise.
struct Coordinates {
  std::vector<double> c[3];
  explicit Coordinates(const Eigen::MatrixXd& X) {
    for (int a = 0; a < 3; ++a) {
      c[a].assign(static_cast<size_t>(X.rows()), 0.0);
      if (a < X.cols())
        for (Eigen::Index i = 0; i < X.rows(); ++i) c[a][static_cast<size_t>(i)] = X(i, a);
    }
  }
};

}  // namespace

FiberSystem::FiberSystem(const Model& model, const Eigen::MatrixXd& X, BoundaryMethod method,
                         double penalty)
    : FiberSystem(model, X, DofMap::from_constraints(model), method, penalty) {}

FiberSystem::FiberSystem(const Model& model, const Eigen::MatrixXd& X, const DofMap& dofs,
                         BoundaryMethod method, double penalty, const Eigen::MatrixXd* strained)
    : dim_(model.dim()),
      n_(model.num_vertices()),
      X_(X),
      fibers_(model.fibers),
      factors_(model),
      young_(model.material.young_modulus()),
      gamma_(model.material.surface_tension),
      method_(method),
      penalty_(penalty) {
  const geom::VertexAreaVectors areas = geom::vertex_area_vectors(X, model.surface.F);
  area_ = areas.magnitude;
  S_ = areas.S;
  surface_ = surface_tension_laplacian(X, area_, geom::unique_edges(model.surface));
  if (!model.material.law.is_constant()) {
    // Y_a(e) = m_a Y(e): the factors here, Y(e) in every pair weight.
    law_ = &model.material.law;
    young_ = model.material.axis_factors;
    reference_ = model.surface.V;
    strained_ = strained != nullptr ? *strained : model.surface.V;
  } else if (model.treecode_tolerance > 0.0) {  // refuses factors without one pair factor
    treecode_ = std::make_shared<const BulkTreecode>(X, area_, factors_, model.treecode_tolerance);
  }

  active_.resize(static_cast<size_t>(dim_));
  penalised_.resize(static_cast<size_t>(dim_));
  constrained_.resize(static_cast<size_t>(dim_));
  offsets_.assign(1, 0);
  for (int a = 0; a < dim_; ++a) {
    for (int i = 0; i < n_; ++i) {
      const bool is_fixed = dofs.held(a * n_ + i);
      if (is_fixed) constrained_[static_cast<size_t>(a)].push_back(i);
      if (method == BoundaryMethod::Penalty) {
        if (is_fixed)
          penalised_[static_cast<size_t>(a)].push_back(
              static_cast<int>(active_[static_cast<size_t>(a)].size()));
        active_[static_cast<size_t>(a)].push_back(i);
      } else if (!is_fixed) {
        active_[static_cast<size_t>(a)].push_back(i);
      }
    }
    offsets_.push_back(offsets_.back() + static_cast<int>(active_[static_cast<size_t>(a)].size()));
  }
}

void FiberSystem::pair_row(int i, double* row) const {
  factors_.row(i, row);
  if (law_ == nullptr) return;
  // The secant modulus of each fiber at its strain e_ij = |y_i - y_j| / L_ij - 1.
  for (int j = 0; j < n_; ++j) {
    if (row[j] == 0.0) continue;
    const double length = (reference_.row(i) - reference_.row(j)).norm();
    const double strain = fiber_strain((strained_.row(i) - strained_.row(j)).norm(), length);
    row[j] *= law_->modulus(strain);
  }
}

bool FiberSystem::blocks_equal() const {
  if (projected_) return false;
  for (int a = 1; a < dim_; ++a)
    if (active(a) != active(0) || penalised(a) != penalised(0) || young(a) != young(0))
      return false;
  return true;
}

BulkPairs FiberSystem::bulk_pairs(const std::vector<int>& vertices, int axis) const {
  BulkPairs pairs(X_, area_, factors_, vertices);
  if (law_ != nullptr) pairs.set_secant_law(law_, &reference_, &strained_);
  if (projected_ && axis >= 0) pairs.set_axis_projection(axis, &projection_positions_);
  return pairs;
}

void FiberSystem::project_on_axes(const Eigen::MatrixXd& positions) {
  projected_ = true;
  projection_positions_ = positions;
  for (Eigen::VectorXd& d : bulk_diagonal_) d.resize(0);
}

Eigen::MatrixXd FiberSystem::dense_block(int axis) const {
  return dense_block_in<Eigen::MatrixXd>(axis);
}

Eigen::MatrixXf FiberSystem::dense_block_single(int axis) const {
  return dense_block_in<Eigen::MatrixXf>(axis);
}

template <class Matrix>
Matrix FiberSystem::dense_block_in(int axis) const {
  using Scalar = typename Matrix::Scalar;
  const std::vector<int>& act = active(axis);
  const auto m = static_cast<Eigen::Index>(act.size());
  const double y = young(axis);
  Matrix K(m, m);  // every entry is written below (no pass of zeros first)
  advise_huge_pages(K.data(), sizeof(Scalar) * static_cast<double>(K.size()));
  if (y == 0.0) {
    K.setZero();
  } else {
    bulk_pairs(act, axis).fill_off_diagonal(y, &K);
    // The diagonal gathers the weights to every vertex, active or not.
    const Eigen::VectorXd& diagonal = bulk_diagonal(axis);
    for (Eigen::Index r = 0; r < m; ++r)
      K(r, r) = static_cast<Scalar>(y * diagonal[act[static_cast<size_t>(r)]]);
  }
  if (gamma_ != 0.0) {
    std::vector<int> position(static_cast<size_t>(n_), -1);
    for (size_t k = 0; k < act.size(); ++k)
      position[static_cast<size_t>(act[k])] = static_cast<int>(k);
    for (int col = 0; col < surface_.outerSize(); ++col)
      for (Eigen::SparseMatrix<double>::InnerIterator it(surface_, col); it; ++it) {
        const int r = position[static_cast<size_t>(it.row())],
                  c = position[static_cast<size_t>(it.col())];
        if (r >= 0 && c >= 0) K(r, c) += static_cast<Scalar>(gamma_ * it.value());
      }
  }
  for (int k : penalised(axis)) K(k, k) = static_cast<Scalar>(penalty_);
  return K;
}

const Eigen::VectorXd& FiberSystem::bulk_diagonal(int axis) const {
  const int slot = projected_ ? axis : 0;
  Eigen::VectorXd& diagonal = bulk_diagonal_[slot];
  if (diagonal.size() != n_)
    diagonal =
        treecode_ ? treecode_->row_sums() : bulk_pairs({}, projected_ ? axis : -1).row_sums();
  return diagonal;
}

Eigen::MatrixXd FiberSystem::bulk_product(const Eigen::MatrixXd& V) const {
  if (projected_) {
    Eigen::MatrixXd out(V.rows(), V.cols());
    for (Eigen::Index a = 0; a < V.cols(); ++a)
      out.col(a) = bulk_pairs({}, static_cast<int>(a)).laplacian_product(V.col(a));
    return out;
  }
  return treecode_ ? treecode_->laplacian_product(V) : bulk_pairs().laplacian_product(V);
}

Eigen::MatrixXd FiberSystem::unreduced_rows(const std::vector<int>& vertices,
                                            const Eigen::MatrixXd& U, double P) const {
  const Coordinates x(X_);
  const double *x0 = x.c[0].data(), *x1 = x.c[1].data(), *x2 = x.c[2].data(), *a = area_.data();
  const size_t n = static_cast<size_t>(n_);
  const Eigen::MatrixXd surface = surface_ * U;  // sparse: cheap at every row
  const auto rows = static_cast<Eigen::Index>(vertices.size());
  Eigen::MatrixXd out(rows, dim_);
#pragma omp parallel
  {
    std::vector<double> w(n);
#pragma omp for schedule(dynamic, 8)
    for (Eigen::Index r = 0; r < rows; ++r) {
      const int i = vertices[static_cast<size_t>(r)];
      const size_t u = static_cast<size_t>(i);
      pair_row(i, w.data());  // h_ij, then w_ij in place: one square root per pair
      double* weight = w.data();
#pragma omp simd
      for (size_t j = 0; j < n; ++j) {
        const double dx = x0[u] - x0[j], dy = x1[u] - x1[j], dz = x2[u] - x2[j];
        // h_ii = 0; r2 = 1 there only avoids 0/0.
        const double r2 = j == u ? 1.0 : dx * dx + dy * dy + dz * dz;
        weight[j] = bulk_weight(weight[j], a[u], a[j], std::sqrt(r2));
      }
      for (int axis = 0; axis < dim_; ++axis) {
        const double* v = U.col(axis).data();
        double sum = 0.0;
        if (projected_) {
          const Eigen::MatrixXd& P = projection_positions_;
          for (size_t j = 0; j < n; ++j) {
            if (weight[j] == 0.0 || j == u) continue;
            const Eigen::RowVectorXd d = P.row(i) - P.row(static_cast<Eigen::Index>(j));
            const double share = d[axis] * d[axis] / d.squaredNorm() + BulkPairs::kProjectionFloor;
            sum += weight[j] * share * (v[u] - v[j]);
          }
        } else {
#pragma omp simd reduction(+ : sum)
          for (size_t j = 0; j < n; ++j) sum += weight[j] * (v[u] - v[j]);
        }
        out(r, axis) = young(axis) * sum + gamma_ * surface(i, axis) + S_(i, axis) * P;
      }
    }
  }
  return out;
}

Eigen::SparseMatrix<double> FiberSystem::sparse_block(int axis, bool include_bulk) const {
  const std::vector<int>& act = active(axis);
  std::vector<int> position(static_cast<size_t>(n_), -1);
  for (size_t k = 0; k < act.size(); ++k)
    position[static_cast<size_t>(act[k])] = static_cast<int>(k);
  std::vector<Eigen::Triplet<double>> entries;
  for (int col = 0; col < surface_.outerSize(); ++col)
    for (Eigen::SparseMatrix<double>::InnerIterator it(surface_, col); it; ++it) {
      const int r = position[static_cast<size_t>(it.row())],
                c = position[static_cast<size_t>(it.col())];
      if (r >= 0 && c >= 0) entries.emplace_back(r, c, gamma_ * it.value());
    }
  const auto m = static_cast<Eigen::Index>(act.size());
  Eigen::SparseMatrix<double> K(m, m);
  K.setFromTriplets(entries.begin(), entries.end());
  if (include_bulk && young(axis) != 0.0) {
    if (sparse_fibers()) {  // the listed pairs only: N times the neighbours entries
      std::vector<Eigen::Triplet<double>> bulk;
      bulk_pairs(act, axis).add_off_diagonal(young(axis), &bulk);
      const Eigen::VectorXd& diagonal = bulk_diagonal(axis);
      for (Eigen::Index r = 0; r < m; ++r)
        bulk.emplace_back(r, r, young(axis) * diagonal[act[static_cast<size_t>(r)]]);
      Eigen::SparseMatrix<double> B(m, m);
      B.setFromTriplets(bulk.begin(), bulk.end());
      K += B;
    } else {
      const Eigen::MatrixXd bulk = dense_block(axis) - Eigen::MatrixXd(K);
      K += bulk.sparseView();
    }
  }
  for (int k : penalised(axis)) K.coeffRef(k, k) = penalty_;
  K.makeCompressed();
  return K;
}

Eigen::SparseMatrix<double> FiberSystem::preconditioner_block(int axis) const {
  Eigen::SparseMatrix<double> M = sparse_block(axis, false);
  std::vector<char> is_penalised(active(axis).size(), 0);
  for (int k : penalised(axis)) is_penalised[static_cast<size_t>(k)] = 1;
  for (size_t k = 0; k < active(axis).size(); ++k)
    if (!is_penalised[k])
      M.coeffRef(static_cast<Eigen::Index>(k), static_cast<Eigen::Index>(k)) +=
          young(axis) * bulk_diagonal(axis)[active(axis)[k]];
  return M;
}

bool FiberSystem::sparse_fibers() const { return fibers_ != nullptr && fibers_->sparse(); }

bool FiberSystem::dense_blocks() const {
  if (sparse_fibers()) return false;  // a horizon's fibers: sparse blocks
  for (int a = 0; a < dim_; ++a)
    if (young(a) != 0.0) return true;
  return false;
}

Eigen::VectorXd FiberSystem::border() const {
  Eigen::VectorXd s(offsets_.back());
  for (int a = 0; a < dim_; ++a)
    for (size_t k = 0; k < active(a).size(); ++k)
      s[offset(a) + static_cast<Eigen::Index>(k)] = S_(active(a)[k], a);
  return s;
}

Eigen::VectorXd FiberSystem::apply_K(const Eigen::VectorXd& u) const {
  // Scatter to full length per axis, apply both Laplacians, gather back.
  Eigen::MatrixXd full = Eigen::MatrixXd::Zero(n_, dim_);
  for (int a = 0; a < dim_; ++a)
    for (size_t k = 0; k < active(a).size(); ++k)
      full(active(a)[k], a) = u[offset(a) + static_cast<Eigen::Index>(k)];
  const Eigen::MatrixXd bulk = bulk_product(full);
  const Eigen::MatrixXd surface = surface_ * full;
  Eigen::VectorXd out(u.size());
  for (int a = 0; a < dim_; ++a) {
    for (size_t k = 0; k < active(a).size(); ++k) {
      const int i = active(a)[k];
      out[offset(a) + static_cast<Eigen::Index>(k)] =
          young(a) * bulk(i, a) + gamma_ * surface(i, a);
    }
    // The penalty replaces the diagonal entry: K_kk u_k becomes penalty u_k.
    for (int k : penalised(a)) {
      const Eigen::Index row = offset(a) + k;
      const int i = active(a)[static_cast<size_t>(k)];
      const double diagonal = young(a) * bulk_diagonal(a)[i] + gamma_ * surface_.coeff(i, i);
      out[row] += (penalty_ - diagonal) * u[row];
    }
  }
  return out;
}

Eigen::VectorXd FiberSystem::reduce_rhs(const Eigen::VectorXd& F,
                                        const Eigen::VectorXd& U_c) const {
  Eigen::VectorXd rhs(num_unknowns());
  Eigen::MatrixXd U = Eigen::MatrixXd::Zero(n_, dim_);
  for (int a = 0; a < dim_; ++a) U.col(a) = U_c.segment(a * n_, n_);
  const bool moving = U.cwiseAbs().maxCoeff() > 0.0;
  if (method_ == BoundaryMethod::Penalty) {
    for (int a = 0; a < dim_; ++a) {
      rhs.segment(offset(a), n_) = F.segment(a * n_, n_);
      for (int k : penalised(a))
        rhs[offset(a) + k] = penalty_ * U(active(a)[static_cast<size_t>(k)], a);
    }
    rhs[num_unknowns() - 1] = 0.0;
    return rhs;
  }
  // Elimination: move the prescribed displacements to the right: f - K_fc u_c, -s_c . u_c.
  Eigen::MatrixXd KU = Eigen::MatrixXd::Zero(n_, dim_);
  if (moving) {
    const Eigen::MatrixXd bulk = bulk_product(U);
    const Eigen::MatrixXd surface = surface_ * U;
    for (int a = 0; a < dim_; ++a) KU.col(a) = young(a) * bulk.col(a) + gamma_ * surface.col(a);
  }
  double c = 0.0;
  for (int a = 0; a < dim_; ++a) {
    for (size_t k = 0; k < active(a).size(); ++k) {
      const int i = active(a)[k];
      rhs[offset(a) + static_cast<Eigen::Index>(k)] = F[a * n_ + i] - KU(i, a);
    }
    for (int i : constrained_[static_cast<size_t>(a)]) c -= S_(i, a) * U(i, a);
  }
  rhs[num_unknowns() - 1] = c;
  return rhs;
}

Eigen::VectorXd FiberSystem::expand(const Eigen::VectorXd& reduced,
                                    const Eigen::VectorXd& U_c) const {
  Eigen::VectorXd x(dim_ * n_ + 1);
  x.head(dim_ * n_) = U_c;
  for (int a = 0; a < dim_; ++a)
    for (size_t k = 0; k < active(a).size(); ++k)
      x[a * n_ + active(a)[k]] = reduced[offset(a) + static_cast<Eigen::Index>(k)];
  x[dim_ * n_] = reduced[num_unknowns() - 1];
  return x;
}

Eigen::VectorXd constrained_displacements(const Model& model, int step, int steps) {
  Eigen::VectorXd U_c = Eigen::VectorXd::Zero(model.dim() * model.num_vertices());
  for (const Constraint& c : model.constraints)
    U_c[model.dof(c.vertex, c.axis)] = held_value(model, c, step, steps);
  return U_c;
}

}  // namespace fiberfluid::model

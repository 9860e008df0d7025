// SPDX-License-Identifier: GPL-3.0-or-later
#include "fiberfluid/model/bordered_system.hpp"

#include <algorithm>

namespace fiberfluid::model {

int BorderedSystem::largest_block() const {
  int largest = 0;
  for (int b = 0; b < num_blocks(); ++b) largest = std::max(largest, block_size(b));
  return largest;
}

Eigen::MatrixXd BorderedSystem::dense_matrix() const {
  const int total = num_unknowns(), p = total - 1;
  Eigen::MatrixXd A = Eigen::MatrixXd::Zero(total, total);
  for (int b = 0; b < num_blocks(); ++b) {
    const int start = block_offsets()[static_cast<size_t>(b)], m = block_size(b);
    A.block(start, start, m, m) = dense_block(b);
  }
  const Eigen::VectorXd s = border();
  A.col(p).head(p) = s;
  A.row(p).head(p) = s.transpose();
  return A;
}

DenseBorderedSystem::DenseBorderedSystem(std::vector<Eigen::MatrixXd> blocks,
                                         Eigen::VectorXd border)
    : blocks_(std::move(blocks)), border_(std::move(border)) {
  for (const Eigen::MatrixXd& K : blocks_)
    offsets_.push_back(offsets_.back() + static_cast<int>(K.rows()));
}

bool DenseBorderedSystem::blocks_equal() const {
  for (const Eigen::MatrixXd& K : blocks_)
    if (K.rows() != blocks_[0].rows() || K != blocks_[0]) return false;
  return true;
}

Eigen::SparseMatrix<double> DenseBorderedSystem::sparse_block(int block) const {
  Eigen::SparseMatrix<double> K = blocks_[static_cast<size_t>(block)].sparseView();
  K.makeCompressed();
  return K;
}

Eigen::VectorXd DenseBorderedSystem::apply_K(const Eigen::VectorXd& u) const {
  Eigen::VectorXd out(u.size());
  for (int b = 0; b < num_blocks(); ++b) {
    const int start = offsets_[static_cast<size_t>(b)], m = block_size(b);
    out.segment(start, m) = blocks_[static_cast<size_t>(b)] * u.segment(start, m);
  }
  return out;
}

}  // namespace fiberfluid::model

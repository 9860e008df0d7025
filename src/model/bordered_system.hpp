// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once

#include <Eigen/Core>
#include <Eigen/SparseCore>
#include <string>
#include <vector>

namespace fiberfluid::model {

// The bordered systems the linear backends solve (model.md section 5):
//
//   [ K    s ] [u]   [f]     K = blockdiag(K_0, ..., K_{m-1}), each block
//   [ s^T  0 ] [P] = [c]     symmetric positive definite; s the border
//
// given by its blocks on request (dense, sparse, or a sparse approximation
// for preconditioning) and as an operator. FiberSystem is the provider for
// the fibers-and-fluid model; DenseBorderedSystem wraps explicit matrices.
class BorderedSystem {
 public:
  virtual ~BorderedSystem() = default;

  virtual int num_blocks() const = 0;
  // Start of each block in the unknowns, then the end of the last.
  virtual const std::vector<int>& block_offsets() const = 0;
  int num_unknowns() const { return block_offsets().back() + 1; }  // with P
  int block_size(int block) const {
    return block_offsets()[static_cast<size_t>(block) + 1] -
           block_offsets()[static_cast<size_t>(block)];
  }
  int largest_block() const;
  // All blocks are the same matrix, so one factor serves them all.
  virtual bool blocks_equal() const = 0;
  // The blocks are dense (all pairs coupled), not sparse.
  virtual bool dense_blocks() const = 0;
  // For messages: "the x block" for the model's axes, "block 2" otherwise.
  virtual std::string block_name(int block) const { return "block " + std::to_string(block); }

  virtual Eigen::MatrixXd dense_block(int block) const = 0;
  // The same in single precision, for a single-precision factor. A system
  // that can fill it directly overrides this (no double copy of N^2 first).
  virtual Eigen::MatrixXf dense_block_single(int block) const {
    return dense_block(block).cast<float>();
  }
  virtual Eigen::SparseMatrix<double> sparse_block(int block) const = 0;
  // A sparse, symmetric positive definite approximation of the block that a
  // preconditioner factors.
  virtual Eigen::SparseMatrix<double> preconditioner_block(int block) const = 0;
  // K u over all blocks (the unknowns but P).
  virtual Eigen::VectorXd apply_K(const Eigen::VectorXd& u) const = 0;
  virtual Eigen::VectorXd border() const = 0;

  // The whole bordered matrix, dense.
  Eigen::MatrixXd dense_matrix() const;
};

// A bordered system given by explicit matrices: any K and border.
class DenseBorderedSystem final : public BorderedSystem {
 public:
  DenseBorderedSystem(std::vector<Eigen::MatrixXd> blocks, Eigen::VectorXd border);

  int num_blocks() const override { return static_cast<int>(blocks_.size()); }
  const std::vector<int>& block_offsets() const override { return offsets_; }
  bool blocks_equal() const override;
  bool dense_blocks() const override { return true; }
  Eigen::MatrixXd dense_block(int block) const override {
    return blocks_[static_cast<size_t>(block)];
  }
  Eigen::SparseMatrix<double> sparse_block(int block) const override;
  Eigen::SparseMatrix<double> preconditioner_block(int block) const override {
    return sparse_block(block);
  }
  Eigen::VectorXd apply_K(const Eigen::VectorXd& u) const override;
  Eigen::VectorXd border() const override { return border_; }

 private:
  std::vector<Eigen::MatrixXd> blocks_;
  Eigen::VectorXd border_;
  std::vector<int> offsets_{0};
};

}  // namespace fiberfluid::model

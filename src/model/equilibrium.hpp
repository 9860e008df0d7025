// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once

#include <Eigen/Core>
#include <Eigen/SparseCore>
#include <memory>
#include <string>
#include <vector>

#include "fiberfluid/model/dof_map.hpp"
#include "fiberfluid/model/fiber_network.hpp"
#include "fiberfluid/model/fiber_system.hpp"
#include "fiberfluid/model/model.hpp"
#include "fiberfluid/model/pair_kernels.hpp"
#include "fiberfluid/model/terms.hpp"

namespace fiberfluid::model {

class Equilibrium;

// The tangent at one state as an operator: the bulk fibers' pair
// coefficients (the stencil's c1, c2) stored once (two N x N arrays in single
// precision, bytes_for(N)), so that each product is one pass over memory rather than
// square roots and law evaluations per pair. Equilibrium::linearize builds it.
class TangentOperator {
 public:
  Eigen::VectorXd apply(const Eigen::VectorXd& v) const;  // dR/dx v, full layout
  static double bytes_for(int num_vertices);

 private:
  friend class Equilibrium;
  const Equilibrium* equilibrium_ = nullptr;
  Eigen::VectorXd x_;
  std::vector<double> factors_;
  Eigen::MatrixXd X_, U_;
  Eigen::MatrixXf weighted_modulus_, weighted_slope_;  // column i: the pairs (i, j)
  // Fibers stored as neighbour lists: the kept pairs' coefficients in list order.
  bool listed_ = false;
  std::vector<double> listed_modulus_, listed_slope_;
  // The other terms' state at x_ (positions, area vectors), built at the first
  // product and kept for the next ones. It refers to this operator's x_ and
  // factors_: a copy of the operator builds its own.
  mutable std::shared_ptr<const TermState> state_;
};

// The equilibrium equations of the Newton scheme (model.md section 7) at any
// state x = [u; P] of the paper's layout and load factors lambda:
//
//   R_i = sum_j m f(i, j) + gamma sum_k b_ik (u_i - u_k)
//         + (P - q_i(x)) S_i(x) - F_i(lambda)
//   g   = dim C0 (V(x) - V0)
//
// a sum of named terms (terms.hpp): the bulk fibers f(i, j) of the
// material's kinematics (the vector spring: a_ij Y(e_ij) (u_i - u_j)), with
// the weights a_ij, b_ik of the reference (so a constant law gives exactly
// K u), S_i(x) = C0 sum_{f at i} A_f(x) from the current geometry and the
// reference constant C0 (so dg/dx_i = S_i(x)), q_i = sum over hydrostatic
// loads of lambda rho |a| (depth of x_i below the highest reference point),
// and F the point loads. At the reference with P = 0 and no load, the
// tangent is the paper's A.
//
// Rows of R at held unknowns are the forces the supports (or paddles) exert.
class Equilibrium {
 public:
  // Throws InputError when two vertices coincide, std::invalid_argument for
  // a load of an unknown kind. Keeps a reference to the model.
  explicit Equilibrium(const Model& model);
  Equilibrium(const Equilibrium&) = delete;  // the terms point into it
  Equilibrium& operator=(const Equilibrium&) = delete;

  const Model& model() const { return model_; }
  int num_unknowns() const { return model_.num_unknowns(); }
  double reference_volume() const { return volume0_; }
  // dim C0 V0: the size of g for a relative measure.
  double volume_scale() const { return model_.dim() * C0_ * std::abs(volume0_); }
  double area_constant() const { return C0_; }
  // The terms' names in the order they are summed (bulk fibers first).
  std::vector<std::string> term_names() const;

  Eigen::VectorXd residual(const Eigen::VectorXd& x, const std::vector<double>& factors) const;
  // The same, with the tangent at x stored into `op` on the way, so that
  // linearize(x, factors, op) then costs nothing: one pass over the pairs
  // where the fibers are a table (a Newton line search's trial, which
  // becomes the next iterate), two for neighbour lists.
  Eigen::VectorXd residual(const Eigen::VectorXd& x, const std::vector<double>& factors,
                           TangentOperator& op) const;
  // The loads alone, F_i + q_i S_i (follower), full layout with 0 for g.
  Eigen::VectorXd external_forces(const Eigen::VectorXd& x,
                                  const std::vector<double>& factors) const;
  // The fiber forces alone (bulk and surface), #V by dim.
  Eigen::MatrixXd fiber_forces(const Eigen::VectorXd& x) const;
  // The fibers at x one by one, for reports: the bulk fibers of `pairs`
  // (i < j; a pruned pair reads no force) and the surface-tension fibers,
  // one per mesh edge sorted by its ends. Their forces sum to fiber_forces(x).
  std::vector<FiberReading> bulk_fiber_readings(
      const Eigen::VectorXd& x, const std::vector<std::pair<int, int>>& pairs) const;
  std::vector<FiberReading> surface_fiber_readings(const Eigen::VectorXd& x) const;
  // The force each support group's own fibers (its mirror layer) exert on
  // the body, one per Model::constraint_groups entry (zero without a layer):
  // part of that group's reaction.
  std::vector<Eigen::Vector3d> support_forces(const Eigen::VectorXd& x) const;

  // dR/dx, dense, full layout: the consistent tangent with the dY/de terms,
  // the pressure terms P dS/dx and the follower-load terms.
  Eigen::MatrixXd tangent(const Eigen::VectorXd& x, const std::vector<double>& factors) const;
  // dR/dx as a sparse matrix (full layout): N times the neighbours entries
  // for fibers stored as neighbour lists (a horizon), N^2 otherwise.
  Eigen::SparseMatrix<double> sparse_tangent(const Eigen::VectorXd& x,
                                             const std::vector<double>& factors) const;
  // Whether the bulk fibers are stored as neighbour lists (FiberMask::sparse).
  bool sparse_fibers() const;
  // The bytes linearize() stores (the pair coefficients).
  double stored_tangent_bytes() const;
  // dR/dx v without forming the matrix (O(N^2) pairs, no storage).
  Eigen::VectorXd tangent_product(const Eigen::VectorXd& x, const std::vector<double>& factors,
                                  const Eigen::VectorXd& v) const;
  // The tangent at x as an operator with its pair coefficients stored: for
  // the many products of one Krylov solve.
  TangentOperator linearize(const Eigen::VectorXd& x, const std::vector<double>& factors) const;
  // The same into an existing operator, reusing its arrays (no new pages to
  // fault in); nothing to do when it holds the tangent at (x, factors) already
  // (so a model whose material changes in place needs a fresh operator).
  void linearize(const Eigen::VectorXd& x, const std::vector<double>& factors,
                 TangentOperator& op) const;

  // The size of a residual: the free force rows (reduced) over force_scale
  // and the volume row over volume_scale(), combined as a Euclidean norm.
  double relative_norm(const Eigen::VectorXd& reduced_residual, double force_scale) const;

  // The paper's incremental scheme (model.md sections 3-7) linearises at a
  // geometry X instead: its A with lengths and area vectors from X (and with
  // `strained`, the secant moduli Y(e) at X's strains), the unknowns `dofs`
  // holds eliminated or penalised; and its load vector B at X.
  std::shared_ptr<const FiberSystem> linear_system(const Eigen::MatrixXd& X, const DofMap& dofs,
                                                   BoundaryMethod method, double penalty,
                                                   bool strained) const;
  Eigen::VectorXd load_vector(const Eigen::MatrixXd& X, const std::vector<double>& factors) const;

  // dR/dtheta, one column per name of Material::parameter_names (the law's
  // parameters, "gamma", "factor_x" ...). Throws std::invalid_argument for
  // another name.
  Eigen::MatrixXd parameter_derivatives(const Eigen::VectorXd& x,
                                        const std::vector<std::string>& names) const;

 private:
  friend class TangentOperator;
  // The residual of the terms with this role alone.
  Eigen::VectorXd residual_of(EquilibriumTerm::Role role, const Eigen::VectorXd& x,
                              const std::vector<double>& factors) const;
  // The state an operator is linearised at (x, factors, positions, displacements).
  void set_state(const Eigen::VectorXd& x, const std::vector<double>& factors,
                 TangentOperator& op) const;
  // out += dR/dx v of every term but the bulk fibers.
  void add_other_products(const TermState& s, const Eigen::VectorXd& v, const Eigen::MatrixXd& W,
                          Eigen::VectorXd& out) const;

  const Model& model_;
  PairFactors factors_;
  Eigen::VectorXd area0_;                // |S_i| at the reference
  Eigen::SparseMatrix<double> surface_;  // gamma-free surface Laplacian of the reference
  double C0_ = 0.0, volume0_ = 0.0;
  TermContext context_;  // refers to the members above
  BulkFiberTerm bulk_;
  std::vector<std::unique_ptr<EquilibriumTerm>> terms_;  // the others, in order
};

}  // namespace fiberfluid::model

// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once

#include <Eigen/Core>
#include <Eigen/SparseCore>
#include <memory>
#include <string>
#include <vector>

#include "model/dof_map.hpp"
#include "model/fiber_network.hpp"
#include "model/fiber_system.hpp"
#include "model/model.hpp"
#include "model/pair_kernels.hpp"

namespace fiberfluid::model {

class Equilibrium;

// The names Equilibrium::parameter_derivatives knows for this material: the
// law's parameters, "gamma", and "factor_x" / "factor_y" / "factor_z".
std::vector<std::string> material_parameter_names(const Material& material, int dim);
bool is_material_parameter(const Material& material, const std::string& name);

// The tangent at one state as an operator: the bulk fibers' pair
// coefficients a Y(e) and a Y'(e) / (r L) stored once (two N x N arrays,
// bytes_for(N)), so that each product is one pass over memory rather than
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
  Eigen::MatrixXd weighted_modulus_, weighted_slope_;  // column i: the pairs (i, j)
};

// The equilibrium equations of the Newton scheme (model.md section 7) at any
// state x = [u; P] of the paper's layout and load factors lambda:
//
//   R_i = sum_j a_ij m Y(e_ij) (u_i - u_j) + gamma sum_k b_ik (u_i - u_k)
//         + (P - q_i(x)) S_i(x) - F_i(lambda)
//   g   = dim C0 (V(x) - V0)
//
// with the weights a_ij, b_ik of the reference (so a constant law gives
// exactly K u), S_i(x) = C0 sum_{f at i} A_f(x) from the current geometry and
// the reference constant C0 (so dg/dx_i = S_i(x)), q_i = sum over hydrostatic
// loads of lambda rho |a| (depth of x_i below the highest reference point),
// and F the point loads. At the reference with P = 0 and no load, the
// tangent is the paper's A.
//
// Rows of R at held unknowns are the forces the supports (or paddles) exert.
class Equilibrium {
 public:
  // Throws InputError when two vertices coincide.
  explicit Equilibrium(const Model& model);

  const Model& model() const { return model_; }
  int num_unknowns() const { return model_.num_unknowns(); }
  double reference_volume() const { return volume0_; }
  // dim C0 V0: the size of g for a relative measure.
  double volume_scale() const { return model_.dim() * C0_ * std::abs(volume0_); }
  double area_constant() const { return C0_; }

  Eigen::VectorXd residual(const Eigen::VectorXd& x, const std::vector<double>& factors) const;
  // The loads alone, F_i + q_i S_i (follower), full layout with 0 for g.
  Eigen::VectorXd external_forces(const Eigen::VectorXd& x,
                                  const std::vector<double>& factors) const;
  // The fiber forces alone (bulk and surface), #V by dim.
  Eigen::MatrixXd fiber_forces(const Eigen::VectorXd& x) const;

  // dR/dx, dense, full layout: the consistent tangent with the dY/de terms,
  // the pressure terms P dS/dx and the follower-load terms.
  Eigen::MatrixXd tangent(const Eigen::VectorXd& x, const std::vector<double>& factors) const;
  // dR/dx v without forming the matrix (O(N^2) pairs, no storage).
  Eigen::VectorXd tangent_product(const Eigen::VectorXd& x, const std::vector<double>& factors,
                                  const Eigen::VectorXd& v) const;
  // The tangent at x as an operator with its pair coefficients stored: for
  // the many products of one Krylov solve.
  TangentOperator linearize(const Eigen::VectorXd& x, const std::vector<double>& factors) const;
  // The same into an existing operator, reusing its arrays (no new pages to fault in).
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

  // dR/dtheta, one column per name: a parameter of the law ("Y", "Y0",
  // "beta", "Y_t", "Y_c", "scale"), "gamma", or "factor_x" / "factor_y" /
  // "factor_z". Throws std::invalid_argument for another name.
  Eigen::MatrixXd parameter_derivatives(const Eigen::VectorXd& x,
                                        const std::vector<std::string>& names) const;

 private:
  friend class TangentOperator;
  // The surface-tension, pressure, follower-load and volume rows of dR/dx v.
  void add_non_bulk_product(const Eigen::VectorXd& x, const std::vector<double>& factors,
                            const Eigen::MatrixXd& X, const Eigen::VectorXd& v,
                            Eigen::VectorXd& out) const;
  struct Hydrostatics;  // per-vertex q_i and its gradient, at x
  Hydrostatics hydrostatics(const Eigen::MatrixXd& X, const std::vector<double>& factors) const;
  Eigen::MatrixXd current_area_vectors(const Eigen::MatrixXd& X) const;  // S_i(x)
  // The bulk fibers at positions X, displacements U: forces, tangent
  // products and coefficients, each pair once (pair_kernels.hpp).
  DeformedPairs bulk_pairs(const Eigen::MatrixXd& X, const Eigen::MatrixXd& U) const;
  // The bulk fibers of row i, for the parameter derivatives: the row's h,
  // L, r, Y, Y' (and strains) into the scratch arrays.
  struct Columns;
  void bulk_row(int i, const Columns& c, std::vector<double>* scratch) const;
  template <class Visit>
  void parallel_rows(const Columns& columns, Visit&& visit) const;

  const Model& model_;
  PairFactors factors_;
  Eigen::VectorXd area0_;                 // |S_i| at the reference
  Eigen::SparseMatrix<double> surface_;   // gamma-free surface Laplacian of the reference
  double C0_ = 0.0, volume0_ = 0.0;
  std::vector<double> levels_;            // per load: the highest reference point along a
};

}  // namespace fiberfluid::model

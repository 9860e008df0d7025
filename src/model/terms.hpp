// SPDX-License-Identifier: GPL-3.0-or-later
// The terms of the equilibrium equations (model.md section 7). Equilibrium's
// residual R(x), its tangent dR/dx (dense and as a product) and dR/dtheta are
// sums over these terms:
//
//   bulk fibers       sum_j m_a f_a(i, j)           (the stencil's kinematics)
//   surface tension   gamma sum_k b_ik (u_i - u_k)  (paper Eq. 7)
//   pressure, volume  P S_i(x), and the row g = dim C0 (V(x) - V0)
//   point load        -lambda F                     (one term per load)
//   hydrostatic load  -q_i(x) S_i(x)                (one term per load)
//   mirror layer      fibers to the body's image across a clamp (mirror_layer.hpp)
//   split edge        a held edge's free share as ghosts (held_edge.hpp)
//
// The supports' terms (the last two) are built on this file's (point_fibers.hpp,
// face_area_derivative) and added by Equilibrium.
//
// A new load kind is one new term and its case in make_load_term. Contact
// with the paddles is not a term: contacts are held unknowns of the stepper's
// active set (solve/newton/contact_set.hpp), and their reactions are the residual's rows.
#pragma once

#include <Eigen/Core>
#include <Eigen/SparseCore>
#include <memory>
#include <utility>
#include <vector>

#include "fiberfluid/model/fiber_network.hpp"
#include "fiberfluid/model/fiber_reading.hpp"
#include "fiberfluid/model/model.hpp"

namespace fiberfluid::model {

// What the terms read of the reference configuration (Equilibrium owns it).
struct TermContext {
  const Model& model;
  const PairFactors& pair_factors;
  const Eigen::VectorXd& area0;                // |S_i| at the reference
  const Eigen::SparseMatrix<double>& surface;  // surface_tension_laplacian of the reference
  double C0 = 0.0;                             // the reference area constant
  double volume0 = 0.0;
};

// One state x = [u; P] with what several terms share, computed once.
struct TermState {
  TermState(const TermContext& context, const Eigen::VectorXd& x,
            const std::vector<double>& factors);
  const Eigen::VectorXd& x;
  const std::vector<double>& factors;  // per load
  Eigen::MatrixXd X, U;                // positions and displacements, #V by dim
  Eigen::MatrixXd S;                   // S_i(x) = C0 sum_{f at i} A_f(x), #V by dim
  double P = 0.0;
};

// Where a term's tangent entries go: added into a dense matrix, or listed as
// triplets for a sparse one (duplicates summed when it is built).
class TangentSink {
 public:
  explicit TangentSink(Eigen::MatrixXd& dense) : dense_(&dense) {}
  explicit TangentSink(std::vector<Eigen::Triplet<double>>& entries) : entries_(&entries) {}
  void add(Eigen::Index row, Eigen::Index col, double value) {
    if (dense_ != nullptr)
      (*dense_)(row, col) += value;
    else
      entries_->emplace_back(static_cast<int>(row), static_cast<int>(col), value);
  }
  Eigen::MatrixXd* dense() const { return dense_; }  // null when sparse

 private:
  Eigen::MatrixXd* dense_ = nullptr;
  std::vector<Eigen::Triplet<double>>* entries_ = nullptr;
};

// Row `row` of M (#V by dim) as a 3-vector, zero-padded in 2D.
inline Eigen::Vector3d padded_row(const Eigen::MatrixXd& M, Eigen::Index row) {
  Eigen::Vector3d v = Eigen::Vector3d::Zero();
  v.head(M.cols()) = M.row(row).transpose();
  return v;
}

// dA_f/dx_v for the k-th corner v of face f (dim x dim, padded to 3x3): the
// face area vector's derivative, for the terms whose forces follow the
// surface (pressure, hydrostatic load, a split edge's share of pressure).
Eigen::Matrix3d face_area_derivative(const Eigen::MatrixXd& X, const Eigen::MatrixXi& F,
                                     Eigen::Index f, int k);
// sum_v dA_f/dx_v w_v for face f: the face area vector's rate along W (#V
// by dim), padded to 3.
Eigen::Vector3d face_area_rate(const Eigen::MatrixXd& X, const Eigen::MatrixXi& F, Eigen::Index f,
                               const Eigen::MatrixXd& W);

class EquilibriumTerm {
 public:
  virtual ~EquilibriumTerm() = default;
  // What a term stands for: the tissue's fibers (bulk and surface tension,
  // Equilibrium::fiber_forces), the fluid (pressure and volume), or a load,
  // whose residual is minus the external force it applies (reactions,
  // Equilibrium::external_forces), or a support's own fibers (a clamp's
  // mirror layer), whose forces add to that support's reaction.
  enum class Role { Fibers, Fluid, Load, Support };
  virtual const char* name() const = 0;
  virtual Role role() const = 0;
  // A Support term's group (Model::constraint_groups); -1 for the others.
  virtual int support_group() const { return -1; }
  // R += this term's part at the state (full layout [u; P]).
  virtual void add_residual(const TermState& s, Eigen::VectorXd& R) const = 0;
  // J += its dR/dx (full layout), dense or sparse.
  virtual void add_tangent(const TermState& s, TangentSink& J) const = 0;
  // out += its dR/dx v; W holds v's displacement rows (#V by dim).
  virtual void add_tangent_product(const TermState& s, const Eigen::VectorXd& v,
                                   const Eigen::MatrixXd& W, Eigen::VectorXd& out) const = 0;
  // column += its dR/dtheta for a material parameter (most terms have none).
  virtual void add_parameter_derivative(const TermState& /*s*/, const MaterialParameter& /*p*/,
                                        Eigen::Ref<Eigen::VectorXd> /*column*/) const {}
};

// The bulk fibers: the one term whose pairs are O(N^2). Besides the term's
// interface, it gives the pair coefficients for the stored-coefficient
// tangent operator and applies them.
class BulkFiberTerm final : public EquilibriumTerm {
 public:
  explicit BulkFiberTerm(const TermContext& context) : c_(context) {}
  const char* name() const override { return "bulk fibers"; }
  Role role() const override { return Role::Fibers; }
  void add_residual(const TermState& s, Eigen::VectorXd& R) const override;
  void add_tangent(const TermState& s, TangentSink& J) const override;
  void add_tangent_product(const TermState& s, const Eigen::VectorXd& v, const Eigen::MatrixXd& W,
                           Eigen::VectorXd& out) const override;
  void add_parameter_derivative(const TermState& s, const MaterialParameter& p,
                                Eigen::Ref<Eigen::VectorXd> column) const override;

  // c1 and c2 of every pair (N x N, symmetric, zero diagonal).
  // In single precision: the table Newton-Krylov's stored product reads.
  void coefficients(const Eigen::MatrixXd& X, const Eigen::MatrixXd& U, Eigen::MatrixXf* c1,
                    Eigen::MatrixXf* c2) const;
  // add_residual and coefficients at the same state in one pass (a table).
  void add_residual_and_coefficients(const TermState& s, Eigen::VectorXd& R, Eigen::MatrixXf* c1,
                                     Eigen::MatrixXf* c2) const;
  // out += the tangent times W from stored coefficients (one pass over memory).
  void add_stored_product(const Eigen::MatrixXd& X, const Eigen::MatrixXd& U,
                          const Eigen::MatrixXf& c1, const Eigen::MatrixXf& c2,
                          const Eigen::MatrixXd& W, Eigen::VectorXd& out) const;

  // The same two for fibers stored as neighbour lists (a sparse mask): the
  // coefficients of the kept pairs in list order (DeformedPairs).
  bool sparse() const;
  void listed_coefficients(const Eigen::MatrixXd& X, const Eigen::MatrixXd& U,
                           std::vector<double>* c1, std::vector<double>* c2) const;
  void add_listed_product(const Eigen::MatrixXd& X, const Eigen::MatrixXd& U,
                          const std::vector<double>& c1, const std::vector<double>& c2,
                          const Eigen::MatrixXd& W, Eigen::VectorXd& out) const;

  // The readings of the given pairs (i < j; a pruned pair reads no force).
  std::vector<FiberReading> readings(const TermState& s,
                                     const std::vector<std::pair<int, int>>& pairs) const;

 private:
  // The tangent's entries of the listed pairs (sparse masks).
  void add_listed_blocks(const Eigen::MatrixXd& X, const Eigen::MatrixXd& U,
                         const std::vector<double>& c1, const std::vector<double>& c2,
                         TangentSink& J) const;
  // row(i, partners, c1, c2) for each vertex with its listed coefficients.
  template <class Body>
  void for_each_listed_row(const std::vector<double>& c1, const std::vector<double>& c2,
                           Body&& body) const;
  void add_dense_blocks(const Eigen::MatrixXd& X, const Eigen::MatrixXd& U,
                        const Eigen::MatrixXd& c1, const Eigen::MatrixXd& c2,
                        Eigen::MatrixXd& J) const;
  const TermContext& c_;
};

// The terms other than the bulk fibers and the supports' (Equilibrium adds
// the mirror layers' and the split edges' after these), in the order they
// are summed: surface tension, pressure and volume, one per load of the model.
// Throws std::invalid_argument for a load of an unknown kind.
std::vector<std::unique_ptr<EquilibriumTerm>> make_surface_and_load_terms(const TermContext& c);

// The readings of the surface-tension fibers, one per mesh edge (i < k), in
// the order of geom::unique_edges.
std::vector<FiberReading> surface_fiber_readings(const TermContext& c, const TermState& s);

// The term of one load (the model's load `index`).
std::unique_ptr<EquilibriumTerm> make_load_term(const TermContext& c, size_t index);

}  // namespace fiberfluid::model

// SPDX-License-Identifier: GPL-3.0-or-later
// The bulk fiber pair kernels (issue 12): the sums over all N^2 fiber pairs
// that every run is made of. Each unordered pair is visited once (the weights
// are symmetric), in tiles whose vertex data stays in the L1 cache, on the
// OpenMP threads, and vectorised for the CPU the program runs on: the tile
// loops are compiled for x86-64-v4 (AVX-512), x86-64-v3 (AVX2 and FMA) and the
// portable baseline (GCC's target_clones), and the loader picks one.
//
// Deterministic: with the same thread count the same bits (each thread owns a
// fixed share of the tiles and its own accumulators, summed in thread order).
#pragma once

#include <Eigen/Core>
#include <Eigen/SparseCore>
#include <vector>

#include "fiberfluid/geom/fiber_mask.hpp"

#include "fiberfluid/model/fiber_law.hpp"
#include "fiberfluid/model/fiber_network.hpp"
#include "fiberfluid/model/pair_stencil.hpp"

namespace fiberfluid::model {

namespace detail {
class ThreadAccumulators;  // pair_tiles.hpp
}

// How many times the pair loops of this thread have gone over every fiber
// pair: what a Newton iteration costs (issue 25). A run counts on its own
// thread (a sweep runs each variant on a thread of its own).
struct PairPasses {
  long long computed = 0;  // lengths and the law at a state (DeformedPairs)
  long long stored = 0;    // a stored tangent's coefficients read (TangentOperator::apply)
  PairPasses operator-(const PairPasses& before) const {
    return {computed - before.computed, stored - before.stored};
  }
  PairPasses& operator+=(const PairPasses& more) {
    computed += more.computed;
    stored += more.stored;
    return *this;
  }
};
PairPasses& pair_passes();  // this thread's count

// The bulk weights of a set of vertices (paper Eq. 6, model.md section 5):
//   w_ij = m_ij (|S_i| + |S_j|) / ((c_i + c_j) |x_i - x_j|),
// with c_i from PairFactors::vertex_counts (so that h_ij = 1 / (c_i + c_j)),
// m_ij = 1 for a kept fiber and 0 for a pruned one, times the influence
// omega(L_ij) (PairFactors::influence), and for a strain-dependent law times
// the secant modulus Y(e_ij).
class BulkPairs {
 public:
  // `vertices`: the vertices of the set in order; empty means every row of X.
  // X and area are copied (in the layout the tiles read).
  BulkPairs(const Eigen::MatrixXd& X, const Eigen::VectorXd& area, const PairFactors& factors,
            const std::vector<int>& vertices = {});

  // Each weight times Y(e_ij), e_ij = |y_i - y_j| / |s_i - s_j| - 1: y from
  // `strained`, s from `reference` (#V by dim, rows by vertex). The law and
  // both matrices must outlive this object.
  void set_secant_law(const FiberLaw* law, const Eigen::MatrixXd* reference,
                      const Eigen::MatrixXd* strained);
  // Each weight times the share of axis `axis` in the fiber's direction at
  // `positions`, (d_a / |d|)^2 + kProjectionFloor: the axis block of a
  // central fiber's stiffness a Y d d^T / |d|^2 without its coupling between
  // axes (the separate displacement components of elasticity's
  // preconditioners). `positions` must outlive this object.
  void set_axis_projection(int axis, const Eigen::MatrixXd* positions);
  static constexpr double kProjectionFloor = 0.01;

  int size() const { return n_; }
  // sum_j w_ij for each vertex i of the set.
  Eigen::VectorXd row_sums() const;
  // (L V)_i = sum_j w_ij (V_i - V_j); V: one row per vertex of the set.
  Eigen::MatrixXd laplacian_product(const Eigen::MatrixXd& V) const;
  // K(r, c) = -scale w_rc for r != c over the set (K: size() x size());
  // the diagonal is left as it was. In single precision for a
  // single-precision factor, without a double copy first.
  void fill_off_diagonal(double scale, Eigen::MatrixXd* K) const;
  void fill_off_diagonal(double scale, Eigen::MatrixXf* K) const;
  // The same as triplets (r, c, -scale w_rc), one per kept pair and order:
  // N times the neighbours for a mask stored sparse, N^2 otherwise.
  void add_off_diagonal(double scale, std::vector<Eigen::Triplet<double>>* entries) const;
  // Whether the pairs come from neighbour lists (a sparse mask).
  bool sparse() const { return mask_ != nullptr && mask_->sparse(); }

  // The tile edge: a tile's vertex data (coordinates, area, count, three
  // columns in and out) is 11 arrays of 256 doubles, 22 KB: within L1.
  static constexpr int kTile = 256;

  struct Tile {
    int i0, ni, j0, nj;
    bool diagonal;  // i0 == j0: only the pairs j > i
  };

 private:
  template <class Matrix>
  void fill_off_diagonal_of(double scale, Matrix* K) const;
  // The multipliers m_ij of one tile (row-major, kTile per row), for a
  // pruned body or a strain-dependent law (otherwise every m_ij is 1).
  void multipliers(const Tile& t, double* m) const;
  // for_each_tile_pair with the tile's multipliers: visit(tile, multipliers, thread).
  template <class Visit>
  void for_each_tile(Visit&& visit) const;
  // A sparse mask: visit(r, c, w_rc) for every kept pair of the set seen from
  // each end (positions in the set), rows in parallel, each row's pairs in order.
  template <class Visit>
  void for_each_listed(Visit&& visit) const;
  double listed_weight(int r, int c) const;  // w_rc of a kept pair

  int n_ = 0;
  std::vector<double> x_[3], area_, count_;
  bool mean_ = false;          // the mean count's weights (PairFactors::mean_count)
  std::vector<int> vertex_;    // the set's vertices (mask and law lookups)
  std::vector<int> position_;  // a vertex's position in the set, -1 if not in it (sparse)
  const geom::FiberMask* mask_ = nullptr;
  Influence influence_;                  // weighs each pair by its reference length
  Eigen::MatrixXd reference_positions_;  // for a weighing influence
  const LineMeasure* lines_ = nullptr;   // the factors' (null: the paper's weights)
  const FiberLaw* law_ = nullptr;
  const Eigen::MatrixXd *reference_ = nullptr, *strained_ = nullptr;
  int projection_axis_ = -1;  // none
  const Eigen::MatrixXd* projection_positions_ = nullptr;
  double projection(int vi, int vj) const;
};

// The bulk tangent times W (#V by dim, #V by 3 out, before the axis factors)
// from stored pair coefficients C1, C2 (DeformedPairs::coefficients: only
// the lower triangle is read), at positions X and displacements U: each
// unordered pair read once, its term added at i and subtracted at j, as
// DeformedPairs::tangent_product sums it. The tables are single precision:
// this product is bound by reading them, and it is Newton-Krylov's tangent,
// whose direction GMRES needs to a few digits (the residual stays exact).
Eigen::MatrixXd stored_tangent_product(FiberKinematics kinematics, const Eigen::MatrixXd& X,
                                       const Eigen::MatrixXd& U, const Eigen::MatrixXf& C1,
                                       const Eigen::MatrixXf& C2, const Eigen::MatrixXd& W);

// The bulk fibers at a deformed state, for Newton's residual and tangent
// (model.md section 7, pair_stencil.hpp): per pair the reference length
// L = |s_i - s_j|, the current r = |x_i - x_j|, the strain e = r / L - 1, the
// weight a = h_ij (|S_i| + |S_j|) / L at the reference, and the kinematics'
// coefficients c1, c2 (for the vector spring c1 = a Y(e), c2 = a Y'(e) / (r L)),
// visited as BulkPairs does (each pair once, tiled, threaded, vectorised).
class DeformedPairs {
 public:
  // S, X, U: reference positions, current positions, displacements (#V by
  // dim); area: the reference |S_i|. All are kept by reference.
  DeformedPairs(const Eigen::MatrixXd& S, const Eigen::MatrixXd& X, const Eigen::MatrixXd& U,
                const Eigen::VectorXd& area, const PairFactors& factors, const FiberLaw& law,
                FiberKinematics kinematics);

  // sum_j c1_ij g_ij (the vector spring: g = u_i - u_j), #V by 3 (before the
  // axis factors).
  Eigen::MatrixXd forces() const;
  // The bulk tangent times W (#V by dim): per pair
  //   c1 (w_i - w_j) + c2 ((x_i - x_j) . (w_i - w_j)) g_ij,
  // summed over j; #V by 3, before the axis factors.
  Eigen::MatrixXd tangent_product(const Eigen::MatrixXd& W) const;
  // c1 and c2 of every pair (N x N each, zero diagonal), symmetric and kept
  // once: column i holds the pairs (i, j) with j > i (the lower triangle);
  // the upper one is left unwritten (a neighbour-list mask fills both).
  // In double for the dense tangent, in single for stored_tangent_product.
  void coefficients(Eigen::MatrixXd* c1, Eigen::MatrixXd* c2) const;
  void coefficients(Eigen::MatrixXf* c1, Eigen::MatrixXf* c2) const;
  // forces() and coefficients() in one pass over the pairs (their lengths
  // and the law computed once); two passes for a sparse mask.
  Eigen::MatrixXd forces_and_coefficients(Eigen::MatrixXf* c1, Eigen::MatrixXf* c2) const;

  // A mask stored sparse (neighbour lists): the pairs are visited from both
  // ends, row by row, and their coefficients can be kept in list order.
  bool sparse() const { return mask_ != nullptr && mask_->sparse(); }
  // Row i's coefficients start at offsets()[i] in list order (sparse only).
  const std::vector<size_t>& offsets() const { return offsets_; }
  // c1 and c2 of every kept pair in list order: vertex i's partners j
  // (mask neighbours(i)) at offsets()[i] + k.
  void listed_coefficients(std::vector<double>* c1, std::vector<double>* c2) const;

 private:
  struct RowScratch;
  struct ListedRow;
  // Runs visit(tile, row r, first j, scratch, thread) with the row's lengths,
  // strains, Y, Y' and mask in the scratch.
  template <class Visit>
  void for_each_row(Visit&& visit) const;
  // The sparse counterpart: visit(i, partners, row arrays) for each vertex,
  // rows in parallel, the arrays indexed by the partner's place in the list.
  template <class Visit>
  void for_each_listed_row(Visit&& visit) const;
  // Row i of the result, component a: the sum over i's partners j of
  // term(policy, i, j, coefficients, a) (forces, tangent products).
  template <class Term>
  Eigen::MatrixXd listed_sums(Term&& term) const;
  // The table of c1, c2, and with `forces` the forces summed on the way.
  template <class Table>
  void store_coefficients(Table* c1, Table* c2, detail::ThreadAccumulators* forces) const;
  template <class Table>
  void table_coefficients(Table* c1, Table* c2) const;

  int n_ = 0;
  std::vector<double> s_[3], x_[3], u_[3], count_;
  bool mean_ = false;  // the mean count's weights (PairFactors::mean_count)
  const Eigen::VectorXd& area_;
  const geom::FiberMask* mask_;
  Influence influence_;
  const LineMeasure* lines_;  // the factors' (null: the paper's weights)
  const FiberLaw& law_;
  double rest_;  // the law's rest tension T0 (0: none)
  FiberKinematics kinematics_;
  std::vector<size_t> offsets_;  // sparse: where each row's pairs start (N + 1)
};

}  // namespace fiberfluid::model

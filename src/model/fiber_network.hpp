// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once

#include <Eigen/Core>
#include <Eigen/SparseCore>
#include <memory>
#include <vector>

#include "fiberfluid/model/line_measure.hpp"
#include "fiberfluid/model/model.hpp"

namespace fiberfluid::model {

// The factor h_ij = kept_ij / (2 c_ij) of every bulk fiber at one vertex, so
// that w_ij = h_ij (|S_i| + |S_j|) / |x_i - x_j|; c_ij is N-1 when every pair
// is kept, else the model's connection count. h_ii = 0.
class PairFactors {
 public:
  PairFactors(const geom::FiberMask* fibers, ConnectionCount count, int num_vertices);
  // With an influence that weighs the fibers (conical): kept_ij becomes
  // kept_ij omega(L_ij), L_ij from `reference` (#V by dim, copied),
  // and the counts c_i the sums of those weights.
  PairFactors(const geom::FiberMask* fibers, ConnectionCount count, int num_vertices,
              const Influence& influence, const Eigen::MatrixXd* reference,
              const Eigen::VectorXd& areas = {});
  // With ConnectionCount::Area or Mean, `areas` are the reference |S_i| and
  // c_i = sum_j kept_ij omega(L_ij) |S_j| / |S_i| (model.hpp).
  // The line measure's factors (FiberWeights::Lines): kept_ij times the
  // influence times line_measure, and c_i = |S_i|, so that
  // h_ij (|S_i| + |S_j|) = m_ij: the measure is the whole weight, and every
  // loop that forms h (|S_i| + |S_j|) / L forms it. `reference` and
  // `area_vectors` are #V by 3.
  // With `balance_rest`, the rest tensions' factors too (line_measure.hpp).
  static PairFactors lines(const geom::FiberMask* fibers, const Influence& influence,
                           const Eigen::MatrixXd& reference, const Eigen::MatrixXd& area_vectors,
                           bool balance_rest = false);
  // The factors of a model: its fibers, count and influence at its reference.
  explicit PairFactors(const Model& model);
  // Fills row (length N) with h_ij for j = 0..N-1.
  void row(int i, double* row) const;
  // h_ij of one pair (0 for a pair not joined).
  double factor(int i, int j) const;
  // The same factors in the form the tiled pair kernels use:
  // h_ij = kept_ij / (c_i + c_j), c_i per vertex (N-1 with every pair kept,
  // the mean count with the global count, n_i with the symmetric one).
  std::vector<double> vertex_counts() const;
  // Whether the weights mix the counts by the mean count's formula
  // (mean_connection_factor; the tiled kernels' counted_bulk_weight(..., true)).
  bool mean_count() const { return count_ == ConnectionCount::Mean; }
  const geom::FiberMask* mask() const { return fibers_; }  // null: every pair kept
  const Influence& influence() const { return influence_; }
  // The line measure a weight carries besides the influence (null for the
  // paper's weights): the pair loops multiply m_ij by it.
  const LineMeasure* lines() const { return lines_.get(); }
  // The reference positions the influence weighs by (empty unless it weighs).
  const Eigen::MatrixXd& reference() const { return reference_; }

 private:
  // kept_ij omega(L_ij) for j = 0..N-1 (0 at j = i).
  void weights(int i, double* row) const;
  // omega(L_ij) (1 unless the influence weighs).
  double weight(int i, int j) const;

  const geom::FiberMask* fibers_;
  ConnectionCount count_;
  int n_;
  Influence influence_;
  Eigen::MatrixXd reference_;  // for a weighing influence
  std::vector<double> kept_;   // n_i (weighed by the influence)
  Eigen::VectorXd areas_;      // the reference |S_i|, for the mean count
  double global_ = 0.0;        // the count for ConnectionCount::Global or a full body
  std::shared_ptr<const LineMeasure> lines_;  // FiberWeights::Lines
};

// |x_i - x_j|; throws InputError naming both when they coincide (a fiber of
// zero length).
double checked_fiber_length(const Eigen::MatrixXd& X, int i, int j);

// The surface-tension Laplacian gamma-free (paper Eq. 7), sparse: weight
// (|S_i| + |S_k|) / (2 |x_i - x_k|^2) on every mesh edge (i, k). The one
// builder of it (the linear system, Newton's equilibrium, the oracle).
// Throws InputError when an edge has zero length.
Eigen::SparseMatrix<double> surface_tension_laplacian(const Eigen::MatrixXd& X,
                                                      const Eigen::VectorXd& area,
                                                      const Eigen::MatrixXi& edges);

}  // namespace fiberfluid::model

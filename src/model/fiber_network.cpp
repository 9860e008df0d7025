// SPDX-License-Identifier: GPL-3.0-or-later
#include "fiberfluid/model/fiber_network.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include "fiberfluid/geom/area_vectors.hpp"
#include "fiberfluid/model/pair_stencil.hpp"
#include "fiberfluid/util/error.hpp"

namespace fiberfluid::model {

double checked_fiber_length(const Eigen::MatrixXd& X, int i, int j) {
  const double length = (X.row(i) - X.row(j)).norm();
  if (!(length > 0.0))
    throw InputError("vertices " + std::to_string(i) + " and " + std::to_string(j) +
                     " coincide: the fiber between them has zero length");
  return length;
}

PairFactors::PairFactors(const geom::FiberMask* fibers, ConnectionCount count, int num_vertices)
    : PairFactors(fibers, count, num_vertices, Influence{}, nullptr) {}

namespace {
// |S_i| at the reference, for the area and mean counts (empty otherwise: not
// needed).
Eigen::VectorXd counting_areas(const Model& model) {
  if (!counts_by_area(model.connection_count)) return {};
  return geom::vertex_area_vectors(model.surface.V, model.surface.F).magnitude;
}
}  // namespace

PairFactors PairFactors::lines(const geom::FiberMask* fibers, const Influence& influence,
                               const Eigen::MatrixXd& reference,
                               const Eigen::MatrixXd& area_vectors, bool balance_rest) {
  const int n = static_cast<int>(reference.rows());
  if (reference.cols() != 3 || area_vectors.rows() != n || area_vectors.cols() != 3)
    throw InputError("the line measure weighs fibers through a 3D body (steradians): a " +
                     std::to_string(reference.cols()) + "D surface has no such weights");
  // Built as the symmetric count with every kept_ij = 1, then the counts
  // replaced by the areas (h_ij (|S_i| + |S_j|) = m_ij).
  PairFactors factors(fibers, ConnectionCount::Symmetric, n, influence, &reference);
  factors.lines_ = std::make_shared<LineMeasure>(reference, area_vectors, fibers, balance_rest);
  factors.kept_.assign(static_cast<size_t>(n), 0.0);
  for (int i = 0; i < n; ++i) {
    const double area = area_vectors.row(i).norm();
    if (!(area > 0.0) || !std::isfinite(area))
      throw InputError("vertex " + std::to_string(i) + " has no area vector (|S_" +
                       std::to_string(i) + "| = " + std::to_string(area) +
                       "): the line measure weighs each fiber by its ends' area vectors");
    factors.kept_[static_cast<size_t>(i)] = area;
  }
  return factors;
}

PairFactors::PairFactors(const Model& model)
    : PairFactors(model.fiber_weights == FiberWeights::Lines
                      ? lines(model.fibers.get(), model.influence, model.surface.V,
                              geom::vertex_area_vectors(model.surface.V, model.surface.F).S,
                              model.material.law.rest_tension() != 0.0)
                      : PairFactors(model.fibers.get(), model.connection_count,
                                    model.num_vertices(), model.influence, &model.surface.V,
                                    counting_areas(model))) {}

PairFactors::PairFactors(const geom::FiberMask* fibers, ConnectionCount count, int num_vertices,
                         const Influence& influence, const Eigen::MatrixXd* reference,
                         const Eigen::VectorXd& areas)
    : fibers_(fibers), count_(count), n_(num_vertices), influence_(influence) {
  // The paper divides by N-1, the fibers per vertex, so that Y does not
  // depend on the discretisation; with pruning, by the fibers that exist;
  // with a weighing influence, by their summed weights; with the area count,
  // by the area the fibers reach, in units of the vertex's own.
  global_ = n_ - 1;
  const bool by_area = counts_by_area(count_);
  if (by_area && areas.size() != n_)
    throw std::invalid_argument("the area connection count needs every vertex's area");
  for (Eigen::Index i = 0; by_area && i < areas.size(); ++i)
    if (!(areas[i] > 0.0) || !std::isfinite(areas[i]))
      throw InputError("vertex " + std::to_string(i) + " has no area vector (|S_" +
                       std::to_string(i) + "| = " + std::to_string(areas[i]) +
                       "): \"connection_count\": \"" + to_string(count_) +
                       "\" weighs each vertex by it");
  if (count_ == ConnectionCount::Mean) areas_ = areas;
  if (influence_.weighs()) {
    if (reference == nullptr || reference->rows() != n_)
      throw std::invalid_argument("a weighing influence needs the reference positions");
    if (!(influence_.horizon > 0.0))
      throw std::invalid_argument("a conical influence needs a positive horizon");
    reference_ = *reference;
  }
  if (influence_.weighs() || by_area) {
    // Each kept pair adds omega(L_ij), times |S_j| / |S_i| for the area count.
    const auto counted = [&](int i, int j) {
      return weight(i, j) * (by_area ? areas[j] / areas[i] : 1.0);
    };
    kept_.assign(static_cast<size_t>(n_), 0.0);
    if (fibers_ != nullptr && fibers_->sparse()) {  // only the pairs listed
      for (int i = 0; i < n_; ++i)
        fibers_->for_each_kept(i, [&](int j) { kept_[static_cast<size_t>(i)] += counted(i, j); });
    } else {
      std::vector<double> row(static_cast<size_t>(n_));
      for (int i = 0; i < n_; ++i) {
        weights(i, row.data());
        for (int j = 0; j < n_; ++j)
          if (row[static_cast<size_t>(j)] != 0.0)
            kept_[static_cast<size_t>(i)] +=
                row[static_cast<size_t>(j)] * (by_area ? areas[j] / areas[i] : 1.0);
      }
    }
  } else if (fibers_ != nullptr) {
    const std::vector<int> kept = fibers_->kept_per_vertex();
    kept_.assign(kept.begin(), kept.end());
  } else {
    return;
  }
  double sum = 0.0;
  for (double k : kept_) sum += k;
  global_ = n_ > 0 ? sum / n_ : 0.0;
}

double PairFactors::weight(int i, int j) const {
  const double fade =
      influence_.weighs() ? influence_((reference_.row(i) - reference_.row(j)).norm()) : 1.0;
  return lines_ ? fade * (*lines_)(static_cast<size_t>(i), static_cast<size_t>(j)) : fade;
}

void PairFactors::weights(int i, double* row) const {
  if (fibers_ != nullptr && fibers_->sparse()) {
    std::fill(row, row + n_, 0.0);
    fibers_->for_each_kept(i, [&](int j) { row[j] = weight(i, j); });
    return;
  }
  const uint8_t* kept = fibers_ != nullptr ? fibers_->row(i) : nullptr;
  for (int j = 0; j < n_; ++j) {
    double w = kept != nullptr ? kept[j] : 1.0;
    if (w != 0.0) w *= weight(i, j);
    row[j] = w;
  }
  row[i] = 0.0;
}

double PairFactors::factor(int i, int j) const {
  const bool global = count_ == ConnectionCount::Global || kept_.empty();
  const auto count = [&](int k) { return global ? global_ : kept_[static_cast<size_t>(k)]; };
  const bool joined = fibers_ == nullptr ? i != j : fibers_->kept(i, j);
  if (!joined) return 0.0;
  if (mean_count())
    return mean_connection_factor(weight(i, j), areas_[i], areas_[j], count(i), count(j));
  return connection_factor(weight(i, j), count(i), count(j));
}

std::vector<double> PairFactors::vertex_counts() const {
  if (!kept_.empty() && count_ != ConnectionCount::Global) return kept_;
  return std::vector<double>(static_cast<size_t>(n_), global_);
}

void PairFactors::row(int i, double* row) const {
  if (kept_.empty()) {  // every pair, one count
    std::fill(row, row + n_, connection_factor(1.0, global_, global_));
  } else {
    weights(i, row);
    const bool global = count_ == ConnectionCount::Global;
    const auto count = [&](int k) { return global ? global_ : kept_[static_cast<size_t>(k)]; };
    if (mean_count())
      for (int j = 0; j < n_; ++j)
        row[j] = mean_connection_factor(row[j], areas_[i], areas_[j], count(i), count(j));
    else
      for (int j = 0; j < n_; ++j) row[j] = connection_factor(row[j], count(i), count(j));
  }
  row[i] = 0.0;
}

Eigen::SparseMatrix<double> surface_tension_laplacian(const Eigen::MatrixXd& X,
                                                      const Eigen::VectorXd& area,
                                                      const Eigen::MatrixXi& edges) {
  std::vector<Eigen::Triplet<double>> entries;
  entries.reserve(static_cast<size_t>(4 * edges.rows()));
  for (Eigen::Index e = 0; e < edges.rows(); ++e) {
    const int i = edges(e, 0), k = edges(e, 1);
    checked_fiber_length(X, i, k);  // throws for coincident ends
    const double w = surface_weight(area[i], area[k], (X.row(i) - X.row(k)).squaredNorm());
    entries.insert(entries.end(), {{i, i, w}, {k, k, w}, {i, k, -w}, {k, i, -w}});
  }
  Eigen::SparseMatrix<double> L(X.rows(), X.rows());
  L.setFromTriplets(entries.begin(), entries.end());
  return L;
}

}  // namespace fiberfluid::model

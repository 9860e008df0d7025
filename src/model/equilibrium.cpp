// SPDX-License-Identifier: GPL-3.0-or-later
#include "fiberfluid/model/equilibrium.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <stdexcept>

#include "fiberfluid/geom/area_vectors.hpp"
#include "fiberfluid/model/assembly.hpp"
#include "fiberfluid/model/held_edge.hpp"
#include "fiberfluid/model/mirror_layer.hpp"
#include "fiberfluid/util/error.hpp"

namespace fiberfluid::model {
namespace {

// Two coincident vertices would make a fiber of zero length: sorted by their
// coordinates, equal ones are neighbours (N log N, not N^2).
void require_distinct_vertices(const Eigen::MatrixXd& V) {
  std::vector<int> order(static_cast<size_t>(V.rows()));
  std::iota(order.begin(), order.end(), 0);
  const auto before = [&V](int a, int b) {
    for (Eigen::Index c = 0; c < V.cols(); ++c)
      if (V(a, c) != V(b, c)) return V(a, c) < V(b, c);
    return false;
  };
  std::sort(order.begin(), order.end(), before);
  for (size_t k = 1; k < order.size(); ++k)
    if (V.row(order[k - 1]) == V.row(order[k]))
      throw InputError("vertices " + std::to_string(std::min(order[k - 1], order[k])) + " and " +
                       std::to_string(std::max(order[k - 1], order[k])) +
                       " coincide: the fiber between them has zero length");
}

// The reference quantities, computed before the terms that refer to them.
struct Reference {
  Eigen::VectorXd area;
  double C = 0.0, volume = 0.0;
};

Reference reference_of(const Model& model) {
  require_distinct_vertices(model.surface.V);
  const geom::VertexAreaVectors areas = geom::vertex_area_vectors(model.surface.V, model.surface.F);
  return {areas.magnitude, areas.C, geom::enclosed_volume(model.surface.V, model.surface.F)};
}

}  // namespace

Equilibrium::Equilibrium(const Model& model)
    : model_(model),
      factors_(model),
      context_{model, factors_, area0_, surface_, 0.0, 0.0},
      bulk_(context_) {
  Reference reference = reference_of(model);
  area0_ = std::move(reference.area);
  C0_ = reference.C;
  volume0_ = reference.volume;
  context_.C0 = C0_;
  context_.volume0 = volume0_;
  surface_ = surface_tension_laplacian(model.surface.V, area0_, geom::unique_edges(model.surface));
  terms_ = make_surface_and_load_terms(context_);
  // The supports' terms: they build on the terms above (terms.hpp), not
  // the other way round.
  for (const MirrorLayer& layer : model.mirror_layers)
    terms_.push_back(make_mirror_layer_term(context_, layer));
  for (const HeldEdge& edge : model.held_edges)
    for (auto& term : make_held_edge_terms(context_, edge)) terms_.push_back(std::move(term));
}

std::vector<std::string> Equilibrium::term_names() const {
  std::vector<std::string> names{bulk_.name()};
  for (const auto& term : terms_) names.push_back(term->name());
  return names;
}

Eigen::VectorXd Equilibrium::residual_of(EquilibriumTerm::Role role, const Eigen::VectorXd& x,
                                         const std::vector<double>& factors) const {
  const TermState s(context_, x, factors);
  Eigen::VectorXd R = Eigen::VectorXd::Zero(num_unknowns());
  if (bulk_.role() == role) bulk_.add_residual(s, R);
  for (const auto& term : terms_)
    if (term->role() == role) term->add_residual(s, R);
  return R;
}

Eigen::MatrixXd Equilibrium::fiber_forces(const Eigen::VectorXd& x) const {
  const std::vector<double> no_load(model_.loads.size(), 0.0);
  const Eigen::VectorXd R = residual_of(EquilibriumTerm::Role::Fibers, x, no_load);
  const int n = model_.num_vertices();
  return Eigen::Map<const Eigen::MatrixXd>(R.data(), n, model_.dim());  // [u_x.., u_y.., ..]
}

std::vector<FiberReading> Equilibrium::bulk_fiber_readings(
    const Eigen::VectorXd& x, const std::vector<std::pair<int, int>>& pairs) const {
  const std::vector<double> no_load(model_.loads.size(), 0.0);
  return bulk_.readings(TermState(context_, x, no_load), pairs);
}

std::vector<FiberReading> Equilibrium::surface_fiber_readings(const Eigen::VectorXd& x) const {
  const std::vector<double> no_load(model_.loads.size(), 0.0);
  return model::surface_fiber_readings(context_, TermState(context_, x, no_load));
}

std::vector<Eigen::Vector3d> Equilibrium::support_forces(const Eigen::VectorXd& x) const {
  std::vector<Eigen::Vector3d> forces(model_.constraint_groups.size(), Eigen::Vector3d::Zero());
  const std::vector<double> no_load(model_.loads.size(), 0.0);
  const TermState s(context_, x, no_load);
  const int n = model_.num_vertices();
  for (const auto& term : terms_) {
    const auto group = static_cast<size_t>(term->support_group());
    if (term->role() != EquilibriumTerm::Role::Support || group >= forces.size()) continue;
    Eigen::VectorXd R = Eigen::VectorXd::Zero(num_unknowns());
    term->add_residual(s, R);
    for (int a = 0; a < model_.dim(); ++a) forces[group][a] -= R.segment(a * n, n).sum();
  }
  return forces;
}

Eigen::VectorXd Equilibrium::external_forces(const Eigen::VectorXd& x,
                                             const std::vector<double>& factors) const {
  return -residual_of(EquilibriumTerm::Role::Load, x, factors);  // minus a load's residual
}

Eigen::VectorXd Equilibrium::residual(const Eigen::VectorXd& x,
                                      const std::vector<double>& factors) const {
  const TermState s(context_, x, factors);
  Eigen::VectorXd R = Eigen::VectorXd::Zero(num_unknowns());
  bulk_.add_residual(s, R);
  for (const auto& term : terms_) term->add_residual(s, R);
  return R;
}

Eigen::MatrixXd Equilibrium::tangent(const Eigen::VectorXd& x,
                                     const std::vector<double>& factors) const {
  const TermState s(context_, x, factors);
  Eigen::MatrixXd J = Eigen::MatrixXd::Zero(num_unknowns(), num_unknowns());
  TangentSink sink(J);
  bulk_.add_tangent(s, sink);
  for (const auto& term : terms_) term->add_tangent(s, sink);
  return J;
}

Eigen::SparseMatrix<double> Equilibrium::sparse_tangent(const Eigen::VectorXd& x,
                                                        const std::vector<double>& factors) const {
  const TermState s(context_, x, factors);
  std::vector<Eigen::Triplet<double>> entries;
  TangentSink sink(entries);
  bulk_.add_tangent(s, sink);
  for (const auto& term : terms_) term->add_tangent(s, sink);
  Eigen::SparseMatrix<double> J(num_unknowns(), num_unknowns());
  J.setFromTriplets(entries.begin(), entries.end());  // sums the duplicates
  return J;
}

bool Equilibrium::sparse_fibers() const { return bulk_.sparse(); }

double Equilibrium::stored_tangent_bytes() const {
  if (!bulk_.sparse()) return TangentOperator::bytes_for(model_.num_vertices());
  return 2.0 * 8.0 * 2.0 * static_cast<double>(model_.fibers->num_kept());
}

Eigen::VectorXd Equilibrium::tangent_product(const Eigen::VectorXd& x,
                                             const std::vector<double>& factors,
                                             const Eigen::VectorXd& v) const {
  const TermState s(context_, x, factors);
  const Eigen::MatrixXd W = displacements(model_, v);
  Eigen::VectorXd out = Eigen::VectorXd::Zero(num_unknowns());
  bulk_.add_tangent_product(s, v, W, out);
  add_other_products(s, v, W, out);
  return out;
}

void Equilibrium::add_other_products(const TermState& s, const Eigen::VectorXd& v,
                                     const Eigen::MatrixXd& W, Eigen::VectorXd& out) const {
  for (const auto& term : terms_) term->add_tangent_product(s, v, W, out);
}

double TangentOperator::bytes_for(int num_vertices) {
  return 2.0 * sizeof(float) * num_vertices * static_cast<double>(num_vertices);
}

TangentOperator Equilibrium::linearize(const Eigen::VectorXd& x,
                                       const std::vector<double>& factors) const {
  TangentOperator op;
  linearize(x, factors, op);
  return op;
}

Eigen::VectorXd Equilibrium::residual(const Eigen::VectorXd& x, const std::vector<double>& factors,
                                      TangentOperator& op) const {
  if (bulk_.sparse()) {
    linearize(x, factors, op);
    return residual(x, factors);
  }
  set_state(x, factors, op);
  op.listed_ = false;
  const TermState s(context_, x, factors);
  Eigen::VectorXd R = Eigen::VectorXd::Zero(num_unknowns());
  bulk_.add_residual_and_coefficients(s, R, &op.weighted_modulus_, &op.weighted_slope_);
  for (const auto& term : terms_) term->add_residual(s, R);
  return R;
}

void Equilibrium::set_state(const Eigen::VectorXd& x, const std::vector<double>& factors,
                            TangentOperator& op) const {
  op.equilibrium_ = this;
  op.x_ = x;
  op.factors_ = factors;
  op.X_ = positions(model_, x);
  op.U_ = displacements(model_, x);
  op.state_.reset();
}

void Equilibrium::linearize(const Eigen::VectorXd& x, const std::vector<double>& factors,
                            TangentOperator& op) const {
  if (op.equilibrium_ == this && op.x_.size() == x.size() && op.x_ == x && op.factors_ == factors)
    return;  // stored by residual(x, factors, op)
  set_state(x, factors, op);
  op.listed_ = bulk_.sparse();
  if (op.listed_)
    bulk_.listed_coefficients(op.X_, op.U_, &op.listed_modulus_, &op.listed_slope_);
  else
    bulk_.coefficients(op.X_, op.U_, &op.weighted_modulus_, &op.weighted_slope_);
}

Eigen::VectorXd TangentOperator::apply(const Eigen::VectorXd& v) const {
  ++pair_passes().stored;
  const Equilibrium& eq = *equilibrium_;
  const Eigen::MatrixXd W = displacements(eq.model(), v);
  Eigen::VectorXd out = Eigen::VectorXd::Zero(v.size());
  if (listed_)
    eq.bulk_.add_listed_product(X_, U_, listed_modulus_, listed_slope_, W, out);
  else
    eq.bulk_.add_stored_product(X_, U_, weighted_modulus_, weighted_slope_, W, out);
  if (state_ == nullptr || &state_->x != &x_)
    state_ = std::make_shared<const TermState>(eq.context_, x_, factors_);
  eq.add_other_products(*state_, v, W, out);
  return out;
}

Eigen::MatrixXd Equilibrium::parameter_derivatives(const Eigen::VectorXd& x,
                                                   const std::vector<std::string>& names) const {
  const std::vector<double> no_load(model_.loads.size(), 0.0);  // loads do not depend on theta
  const TermState s(context_, x, no_load);
  Eigen::MatrixXd D =
      Eigen::MatrixXd::Zero(num_unknowns(), static_cast<Eigen::Index>(names.size()));
  for (size_t k = 0; k < names.size(); ++k) {
    // Resolved once (throws for an unknown name), not per pair.
    const MaterialParameter p = model_.material.resolve(names[k], model_.dim());
    const auto column = static_cast<Eigen::Index>(k);
    // The body's forces do not depend on the paddles' friction (a Coulomb
    // contact's sensitivities are refused: check_sensitivities).
    if (p.kind == MaterialParameter::Kind::Friction) continue;
    bulk_.add_parameter_derivative(s, p, D.col(column));
    for (const auto& term : terms_) term->add_parameter_derivative(s, p, D.col(column));
  }
  return D;
}

double Equilibrium::relative_norm(const Eigen::VectorXd& reduced, double force_scale) const {
  const Eigen::Index m = reduced.size() - 1;
  const double force = reduced.head(m).norm() / std::max(force_scale, 1e-300);
  const double volume = reduced[m] / volume_scale();
  return std::hypot(force, volume);
}

std::shared_ptr<const FiberSystem> Equilibrium::linear_system(const Eigen::MatrixXd& X,
                                                              const DofMap& dofs,
                                                              BoundaryMethod method, double penalty,
                                                              bool strained) const {
  return std::make_shared<const FiberSystem>(model_, X, dofs, method, penalty,
                                             strained ? &X : nullptr);
}

Eigen::VectorXd Equilibrium::load_vector(const Eigen::MatrixXd& X,
                                         const std::vector<double>& factors) const {
  return right_hand_side(model_, X, factors);
}

}  // namespace fiberfluid::model

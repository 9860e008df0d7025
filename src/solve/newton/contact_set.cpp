// SPDX-License-Identifier: GPL-3.0-or-later
#include "fiberfluid/solve/newton/contact_set.hpp"

#include <algorithm>
#include <cmath>

#include "fiberfluid/model/boundary_conditions.hpp"
#include "fiberfluid/model/loads.hpp"

namespace fiberfluid::solve {

ContactSet::ContactSet(const model::Model& model, const model::DofMap& supports)
    : model_(model),
      supports_(supports),
      paddle_(static_cast<size_t>(model.num_vertices()), -1),
      stuck_(Eigen::MatrixXd::Zero(model.num_vertices(), model.dim())),
      sliding_(static_cast<size_t>(model.num_vertices()), 0),
      friction_(Eigen::MatrixXd::Zero(model.num_vertices(), model.dim())),
      history_(static_cast<size_t>(model.num_vertices()), 0),
      compliance_(static_cast<size_t>(model.num_vertices()), 0.0),
      last_friction_(Eigen::MatrixXd::Zero(model.num_vertices(), model.dim())),
      last_slide_(Eigen::MatrixXd::Zero(model.num_vertices(), model.dim())) {
  for (const model::Paddle& paddle : model.paddles)
    has_coulomb_ = has_coulomb_ || paddle.contact == model::Paddle::Contact::Coulomb;
  const Eigen::MatrixXd& V = model.surface.V;
  diagonal_ = (V.colwise().maxCoeff() - V.colwise().minCoeff()).norm();
  for (size_t p = 0; p < model.paddles.size(); ++p)
    for (int v : model::touching_at_start(model, model.paddles[p]))
      if (paddle_[static_cast<size_t>(v)] < 0 &&
          !supports_.held(model.paddles[p].axis * model.num_vertices() + v))
        paddle_[static_cast<size_t>(v)] = static_cast<int>(p);
}

bool ContactSet::holds_tangent(int vertex) const {
  const int p = paddle_[static_cast<size_t>(vertex)];
  if (p < 0) return false;
  switch (model_.paddles[static_cast<size_t>(p)].contact) {
    case model::Paddle::Contact::Frictionless:
      return false;
    case model::Paddle::Contact::Sticking:
      return true;
    case model::Paddle::Contact::Coulomb:
      return !sliding_[static_cast<size_t>(vertex)];
  }
  return false;
}

void ContactSet::release(int vertex) {
  paddle_[static_cast<size_t>(vertex)] = -1;
  sliding_[static_cast<size_t>(vertex)] = 0;
  friction_.row(vertex).setZero();
}

model::DofMap ContactSet::held_map() const {
  std::vector<int> contacts;
  const int n = model_.num_vertices();
  for (int v = 0; v < n; ++v) {
    const int p = paddle_[static_cast<size_t>(v)];
    if (p < 0) continue;
    const model::Paddle& paddle = model_.paddles[static_cast<size_t>(p)];
    for (int a = 0; a < model_.dim(); ++a)
      if (a == paddle.axis || holds_tangent(v)) contacts.push_back(a * n + v);
  }
  return supports_.with_held(contacts);
}

void ContactSet::apply_held_values(const LoadPoint& at, const model::DofMap& dofs,
                                   Eigen::VectorXd& x) const {
  const int n = model_.num_vertices();
  for (int d = 0; d < model_.dim() * n; ++d)
    if (supports_.held(d)) x[d] = at.held_values[d];
  for (int v = 0; v < n; ++v) {
    const int p = paddle_[static_cast<size_t>(v)];
    if (p < 0) continue;
    const model::Paddle& paddle = model_.paddles[static_cast<size_t>(p)];
    for (int a = 0; a < model_.dim(); ++a) {
      const int d = a * n + v;
      if (supports_.held(d) || !dofs.held(d)) continue;
      x[d] = a == paddle.axis ? at.planes[static_cast<size_t>(p)] - model_.surface.V(v, a)
                              : stuck_(v, a);
    }
  }
}

int ContactSet::add_penetrating(const LoadPoint& at, const Eigen::VectorXd& x, bool apply,
                                double reach) {
  const int n = model_.num_vertices();
  int added = 0;
  for (size_t p = 0; p < model_.paddles.size(); ++p) {
    const model::Paddle& paddle = model_.paddles[p];
    for (int v = 0; v < n; ++v) {
      if (paddle_[static_cast<size_t>(v)] >= 0 || supports_.held(paddle.axis * n + v)) continue;
      const double coordinate = model_.surface.V(v, paddle.axis) + x[paddle.axis * n + v];
      if (paddle.penetration(coordinate, at.planes[p]) > reach * diagonal_) {
        if (!apply) return 1;
        paddle_[static_cast<size_t>(v)] = static_cast<int>(p);
        sliding_[static_cast<size_t>(v)] = 0;  // a Coulomb contact starts held
        friction_.row(v).setZero();
        for (int a = 0; a < model_.dim(); ++a) stuck_(v, a) = x[a * n + v];
        ++added;
      }
    }
  }
  return added;
}

int ContactSet::release_pulling(const Eigen::VectorXd& R) {
  const int n = model_.num_vertices();
  int released = 0;
  for (int v = 0; v < n; ++v) {
    const int p = paddle_[static_cast<size_t>(v)];
    if (p < 0) continue;
    const model::Paddle& paddle = model_.paddles[static_cast<size_t>(p)];
    const double force = R[paddle.axis * n + v];  // on the body, along the axis
    if (paddle.above ? force > 0.0 : force < 0.0) {
      release(v);
      ++released;
    }
  }
  return released;
}

// Coulomb's law by the return mapping of an implicit step (Simo and Laursen,
// Comput. Struct. 42 (1992) 97; Wriggers, Computational Contact Mechanics,
// 2nd ed. 2006, section 5.2): a held vertex's tangential force within
// friction * N is its stick; one past it slides, the friction of a slide
// opposing the slide over the increment (backward Euler), its size
// friction * N. The normal force N is the last solution's: the solver
// repeats until the friction forces stop changing.
//
// Between solutions a sliding vertex's slide s answers its friction f as
// s(f) = e + c f near the solution, e the slide friction-free and c its
// compliance, measured by the secant of its last two rounds, and the next
// friction is f = -friction N e / |e|: at a fixed point e and s are
// parallel, so this is Coulomb's law, but taking the direction from e rather
// than from s is what converges, a short slide's direction turning with its
// friction (the plain fixed point f = -friction N s / |s| stalled at 0.6 a
// round, and did not converge, on the pressed sphere's slowest vertices). A
// sliding vertex that moves with its friction is held again.
int ContactSet::update_friction(const Eigen::VectorXd& R, const Eigen::VectorXd& x,
                                double tolerance) {
  if (!has_coulomb_) return 0;
  const int n = model_.num_vertices(), dim = model_.dim();
  const double mu = model_.material.friction;
  const auto coulomb = [&](int v) {
    const int p = paddle_[static_cast<size_t>(v)];
    return p >= 0 &&
           model_.paddles[static_cast<size_t>(p)].contact == model::Paddle::Contact::Coulomb;
  };
  // Per Coulomb vertex: its friction bound.
  std::vector<double> bound(static_cast<size_t>(n), 0.0);
  double largest = 0.0;
  for (int v = 0; v < n; ++v) {
    if (!coulomb(v)) continue;
    const int axis = model_.paddles[static_cast<size_t>(paddle_[static_cast<size_t>(v)])].axis;
    bound[static_cast<size_t>(v)] = mu * std::abs(R[axis * n + v]);
    largest = std::max(largest, bound[static_cast<size_t>(v)]);
  }
  const double slack = tolerance * largest, still = 1e-12 * diagonal_;
  int changed = 0;
  for (int v = 0; v < n; ++v) {
    if (!coulomb(v)) continue;
    const size_t i = static_cast<size_t>(v);
    const int axis = model_.paddles[static_cast<size_t>(paddle_[i])].axis;
    const double limit = bound[i];
    Eigen::VectorXd tangential = Eigen::VectorXd::Zero(dim), slide = Eigen::VectorXd::Zero(dim);
    for (int a = 0; a < dim; ++a) {
      if (a == axis || supports_.held(a * n + v)) continue;
      tangential[a] = R[a * n + v];
      slide[a] = x[a * n + v] - stuck_(v, a);
    }
    const Eigen::VectorXd old = friction_.row(v).transpose();
    if (!sliding_[i]) {
      if (tangential.norm() <= limit + slack) continue;  // it sticks
      sliding_[i] = 1;
      history_[i] = 0;
      friction_.row(v) = (tangential * (limit / tangential.norm())).transpose();
      ++changed;
      continue;
    }
    // The slide's compliance: the secant of the last two rounds.
    // (Only from a change of friction that rounding does not swamp; the
    // last good estimate is kept until the next.)
    if (!history_[i]) {
      compliance_[i] = 0.0;
      last_friction_.row(v) = old.transpose();
      last_slide_.row(v) = slide.transpose();
      history_[i] = 1;
    } else {
      const Eigen::VectorXd df = old - last_friction_.row(v).transpose();
      const Eigen::VectorXd ds = slide - last_slide_.row(v).transpose();
      if (df.norm() > 1e-3 * limit) {
        compliance_[i] = std::max(0.0, ds.dot(df) / df.squaredNorm());
        last_friction_.row(v) = old.transpose();
        last_slide_.row(v) = slide.transpose();
      }
    }
    Eigen::VectorXd free_slide = slide - compliance_[i] * old;  // e
    // A secant that turns e away from the slide has read a neighbour's
    // answer, not the vertex's own: the plain step then.
    if (free_slide.dot(slide) <= 0.0) free_slide = slide;
    const bool reversed = slide.norm() > still && slide.dot(old) > 0.0;
    if (reversed) {  // friction outweighs what drives it
      sliding_[i] = 0;
      history_[i] = 0;
      friction_.row(v).setZero();
      ++changed;
      continue;
    }
    Eigen::VectorXd next = Eigen::VectorXd::Zero(dim);
    if (free_slide.norm() > still) {
      next = -limit * free_slide / free_slide.norm();
    } else if (old.norm() > 0.0) {
      next = limit * old / old.norm();
    }
    if ((next - old).norm() > slack) ++changed;
    friction_.row(v) = next.transpose();
  }
  return changed;
}

void ContactSet::add_friction(Eigen::VectorXd& R) const {
  if (!has_coulomb_) return;
  const int n = model_.num_vertices();
  for (int v = 0; v < n; ++v)
    if (sliding_[static_cast<size_t>(v)])
      for (int a = 0; a < model_.dim(); ++a)
        R[a * n + v] -= friction_(v, a);  // R: what a held row would have to supply
}

void ContactSet::accept(const Eigen::VectorXd& x) {
  if (!has_coulomb_) return;
  std::fill(history_.begin(), history_.end(), 0);
  const int n = model_.num_vertices();
  for (int v = 0; v < n; ++v)
    if (sliding_[static_cast<size_t>(v)])
      for (int a = 0; a < model_.dim(); ++a) stuck_(v, a) = x[a * n + v];
}

Eigen::Vector3d ContactSet::friction_force(int vertex) const {
  Eigen::Vector3d f = Eigen::Vector3d::Zero();
  f.head(model_.dim()) = friction_.row(vertex).transpose();
  return f;
}

// Whether paddles at these planes can work (why not): two on one axis, on
// opposite sides, that meet or pass each other (`where`: when, for the message).
Status check_planes(const model::Model& model, const std::vector<double>& planes,
                    const std::string& where) {
  for (size_t p = 0; p < model.paddles.size(); ++p)
    for (size_t q = p + 1; q < model.paddles.size(); ++q) {
      const model::Paddle& a = model.paddles[p];
      const model::Paddle& b = model.paddles[q];
      if (b.axis != a.axis || b.above == a.above) continue;
      const size_t top = a.above ? p : q, bottom = a.above ? q : p;
      const double gap = planes[top] - planes[bottom];
      if (!(gap > 0.0))
        return Status::failure("paddles " + model.paddles[top].label + " and " +
                               model.paddles[bottom].label + " meet or pass each other" + where +
                               " (gap " + std::to_string(gap) + ")");
    }
  return {};
}

// Whether a paddle setup can start (why not): an axis out of range, a paddle
// inside the body at its start.
Status check_paddle_start(const model::Model& model) {
  const Eigen::MatrixXd& V = model.surface.V;
  for (const model::Paddle& a : model.paddles) {
    if (a.axis < 0 || a.axis >= model.dim())
      return Status::failure("paddle " + a.label + ": axis out of range");
    const double mu = model.material.friction;
    if (a.contact == model::Paddle::Contact::Coulomb && !(mu >= 0.0 && std::isfinite(mu)))
      return Status::failure("paddle " + a.label +
                             ": Coulomb contact needs a friction coefficient of at least 0, got " +
                             std::to_string(mu));
    const double extreme = a.above ? V.col(a.axis).maxCoeff() : V.col(a.axis).minCoeff();
    if (a.penetration(extreme, a.position) > 1e-9 * std::abs(extreme) + 1e-300)
      return Status::failure("paddle " + a.label + ": it starts inside the body (position " +
                             std::to_string(a.position) + ", body extends to " +
                             std::to_string(extreme) + ")");
  }
  return {};
}

// Whether a paddle setup can work over `steps` steps (why not).
Status check_paddles(const model::Model& model, int steps) {
  Status status = check_paddle_start(model);
  for (int k = 0; k <= steps && status.ok; ++k)
    status = check_planes(model, scheduled_point(model, k, steps).planes,
                          " at step " + std::to_string(k));
  return status;
}

}  // namespace fiberfluid::solve

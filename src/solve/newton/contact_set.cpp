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
      start_friction_(Eigen::MatrixXd::Zero(model.num_vertices(), model.dim())),
      bound_(static_cast<size_t>(model.num_vertices()), 0.0),
      penalty_(static_cast<size_t>(model.num_vertices()), 0.0) {
  has_coulomb_ = model.has_coulomb_paddle();
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
// 2nd ed. 2006, sections 5.2 and 6.4): a held vertex whose tangential force
// stays within friction * N sticks; past it the vertex slides, its
// tangential unknowns free. A sliding vertex's friction follows its slide s
// over the increment and its normal force N within Newton itself: the trial
// force t = f0 - k s (f0 its friction at the increment's start, k a penalty
// that keeps the elastic part of a slide within kElasticSlide of the body's
// size) is returned onto the cone |f| <= friction * N (f = friction N t/|t|),
// N being the bulk's force at the vertex's held normal row; its consistent
// tangent is friction_tangent's. A sliding vertex whose trial falls inside
// its cone at a solution sticks, held again where its increment started.
// (Lagging the friction's direction and size between solutions instead was a
// fixed point that stalled at the rim of a pressed cylinder.)
int ContactSet::update_friction(const Eigen::VectorXd& R, const Eigen::VectorXd& x,
                                double tolerance) {
  if (!has_coulomb_) return 0;
  const int n = model_.num_vertices();
  double largest = 0.0;
  for (int v = 0; v < n; ++v)
    if (coulomb_axis(v) >= 0) largest = std::max(largest, bound_at(v, R));
  const double slack = tolerance * largest;
  int changed = 0;
  for (int v = 0; v < n; ++v) {
    const int axis = coulomb_axis(v);
    if (axis < 0) continue;
    const size_t i = static_cast<size_t>(v);
    const double limit = bound_at(v, R);
    if (!sliding_[i]) {
      Eigen::VectorXd tangential = Eigen::VectorXd::Zero(model_.dim());
      for (int a : tangential_axes(v, axis)) tangential[a] = R[a * n + v];
      if (tangential.norm() <= limit + slack) continue;  // it sticks
      sliding_[i] = 1;
      start_friction_.row(v) = (tangential * (limit / tangential.norm())).transpose();
      penalty_[i] = std::max(penalty_[i], penalty_for(limit));
      bound_[i] = limit;
      friction_.row(v) = start_friction_.row(v);
      ++changed;
      continue;
    }
    bound_[i] = limit;
    // Inside the cone: it sticks, held where the increment started (its
    // slide since is the trial's elastic part, a few kElasticSlide).
    if (strictly_inside(trial_friction(v, x), limit)) {
      sliding_[i] = 0;
      friction_.row(v).setZero();
      ++changed;
      continue;
    }
    friction_.row(v) = friction_at(v, x, limit).transpose();
  }
  return changed;
}

// On the cone's rim, where every slide starts, the side the residual pushes
// the vertex to: on (R_t . t > 0: Newton's step slides it on, against its
// friction) the slide's, else the stick's. Either tangent alone would stall
// there: the stick's stiffness against a slide that the cone caps, the
// slide's freedom through a cone 2 kElasticSlide across (stop_at_cones).
bool ContactSet::sticks(int vertex, const Eigen::VectorXd& trial, double bound,
                        const Eigen::VectorXd& R) const {
  if (strictly_inside(trial, bound)) return true;
  if (trial.norm() > (1.0 + 1e-9) * bound) return false;
  const int n = model_.num_vertices();
  double push = 0.0;
  for (int a : tangential_axes(vertex, coulomb_axis(vertex))) push += R[a * n + vertex] * trial[a];
  return push <= 0.0;
}

bool ContactSet::strictly_inside(const Eigen::VectorXd& trial, double bound) {
  return trial.norm() < (1.0 - 1e-9) * bound;
}

double ContactSet::penalty_for(double bound) const { return bound / (kElasticSlide * diagonal_); }

int ContactSet::coulomb_axis(int vertex) const {
  const int p = paddle_[static_cast<size_t>(vertex)];
  if (p < 0) return -1;
  const model::Paddle& paddle = model_.paddles[static_cast<size_t>(p)];
  return paddle.coulomb() ? paddle.axis : -1;
}

std::vector<int> ContactSet::tangential_axes(int vertex, int axis) const {
  std::vector<int> axes;
  for (int a = 0; a < model_.dim(); ++a)
    if (a != axis && !supports_.held(a * model_.num_vertices() + vertex)) axes.push_back(a);
  return axes;
}

double ContactSet::bound_at(int vertex, const Eigen::VectorXd& R) const {
  return model_.material.friction *
         std::abs(R[coulomb_axis(vertex) * model_.num_vertices() + vertex]);
}

Eigen::VectorXd ContactSet::trial_friction(int vertex, const Eigen::VectorXd& x) const {
  const int n = model_.num_vertices();
  Eigen::VectorXd trial = Eigen::VectorXd::Zero(model_.dim());
  for (int a : tangential_axes(vertex, coulomb_axis(vertex)))
    trial[a] = start_friction_(vertex, a) -
               penalty_[static_cast<size_t>(vertex)] * (x[a * n + vertex] - stuck_(vertex, a));
  return trial;
}

Eigen::VectorXd ContactSet::friction_at(int vertex, const Eigen::VectorXd& x, double bound) const {
  const Eigen::VectorXd trial = trial_friction(vertex, x);
  const double size = trial.norm();
  return size <= bound ? trial : Eigen::VectorXd(trial * (bound / size));
}

// A slide's cone is thin, 2 kElasticSlide of the body's size across: a
// Newton step that moves a sliding vertex back along its friction would pass
// through it to a friction reversed, and the next step back again. Such a
// vertex's step stops just inside the cone's rim, its friction unchanged,
// where the stick's exact tangent takes over.
void ContactSet::stop_at_cones(const Eigen::VectorXd& x, const Eigen::VectorXd& R,
                               Eigen::VectorXd& step) const {
  if (!has_coulomb_) return;
  const int n = model_.num_vertices();
  for (int v = 0; v < n; ++v) {
    const size_t i = static_cast<size_t>(v);
    if (!sliding_[i]) continue;
    const double bound = bound_at(v, R);
    const Eigen::VectorXd t0 = trial_friction(v, x);
    if (!(bound > 0.0) || sticks(v, t0, bound, R)) continue;  // the stick's tangent is exact
    const std::vector<int> axes = tangential_axes(v, coulomb_axis(v));
    Eigen::VectorXd dt = Eigen::VectorXd::Zero(model_.dim());
    for (int a : axes) dt[a] = -penalty_[i] * step[a * n + v];
    // |t0 + l dt| = bound: the step's entry into the cone and exit from it.
    const double A = dt.squaredNorm(), B = 2.0 * t0.dot(dt), C = t0.squaredNorm() - bound * bound;
    const double discriminant = B * B - 4.0 * A * C;
    if (!(A > 0.0) || discriminant <= 0.0) continue;
    const double root = std::sqrt(discriminant);
    const double entry = (-B - root) / (2.0 * A), exit = (-B + root) / (2.0 * A);
    if (entry <= 0.0 || entry >= 1.0) continue;
    const double stop = entry + 1e-3 * (std::min(exit, 1.0) - entry);
    for (int a : axes) step[a * n + v] *= stop;
  }
}

void ContactSet::add_friction(const Eigen::VectorXd& x, Eigen::VectorXd& R) const {
  if (!has_coulomb_) return;
  const int n = model_.num_vertices();
  for (int v = 0; v < n; ++v) {
    if (!sliding_[static_cast<size_t>(v)]) continue;
    // The normal row is the bulk's (friction enters tangential rows alone).
    const Eigen::VectorXd f = friction_at(v, x, bound_at(v, R));
    for (int a = 0; a < model_.dim(); ++a)
      R[a * n + v] -= f[a];  // R: what a held row would have to supply
  }
}

// dR/dx of the friction in add_friction: R -= f(t, N), t = f0 - k s, so
// dR/ds = k I inside the cone and k (friction N / |t|) (I - n n^T) on it,
// where also dR_t = -friction n dN, dN = sign(R_N) dR_N: the normal row's.
AddedTangent ContactSet::friction_tangent(const Eigen::VectorXd& x,
                                          const Eigen::VectorXd& R) const {
  AddedTangent added;  // empty (0 x 0) without Coulomb paddles: nothing to add
  if (!has_coulomb_) return added;
  const Eigen::Index size = x.size();
  added.stiffness.resize(size, size);
  added.row_mix.resize(size, size);
  const int n = model_.num_vertices();
  const double mu = model_.material.friction;
  std::vector<Eigen::Triplet<double>> stiffness, mix;
  for (int v = 0; v < n; ++v) {
    const size_t i = static_cast<size_t>(v);
    if (!sliding_[i]) continue;
    const double bound = bound_at(v, R);
    if (!(bound > 0.0)) continue;  // no friction, no stiffness
    const int axis = coulomb_axis(v);
    const std::vector<int> axes = tangential_axes(v, axis);
    const Eigen::VectorXd trial = trial_friction(v, x);
    const double k = penalty_[i], length = trial.norm();
    const bool inside = sticks(v, trial, bound, R);
    const Eigen::VectorXd direction = inside ? trial : Eigen::VectorXd(trial / length);
    const double scale = inside ? k : k * bound / length;
    const int normal_row = axis * n + v;
    const double sign = R[normal_row] >= 0.0 ? 1.0 : -1.0;
    for (int a : axes) {
      for (int b : axes) {
        const double value =
            scale * ((a == b ? 1.0 : 0.0) - (inside ? 0.0 : direction[a] * direction[b]));
        if (value != 0.0) stiffness.emplace_back(a * n + v, b * n + v, value);
      }
      if (!inside && direction[a] != 0.0)
        mix.emplace_back(a * n + v, normal_row, -mu * sign * direction[a]);
    }
  }
  added.stiffness.setFromTriplets(stiffness.begin(), stiffness.end());
  added.row_mix.setFromTriplets(mix.begin(), mix.end());
  return added;
}

void ContactSet::accept(const Eigen::VectorXd& x) {
  if (!has_coulomb_) return;
  const int n = model_.num_vertices();
  for (int v = 0; v < n; ++v) {
    const size_t i = static_cast<size_t>(v);
    if (!sliding_[i]) continue;
    const Eigen::VectorXd f = friction_at(v, x, bound_[i]);
    friction_.row(v) = f.transpose();
    start_friction_.row(v) = f.transpose();
    // The penalty keeps up with a normal force that grew.
    penalty_[i] = std::max(penalty_[i], penalty_for(bound_[i]));
    for (int a = 0; a < model_.dim(); ++a) stuck_(v, a) = x[a * n + v];
  }
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
    if (a.coulomb() && !(mu >= 0.0 && std::isfinite(mu)))
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

// SPDX-License-Identifier: GPL-3.0-or-later
#include "fiberfluid/solve/newton/contact_set.hpp"

#include <cmath>

#include "fiberfluid/model/boundary_conditions.hpp"
#include "fiberfluid/model/loads.hpp"

namespace fiberfluid::solve {

ContactSet::ContactSet(const model::Model& model, const model::DofMap& supports)
    : model_(model),
      supports_(supports),
      paddle_(static_cast<size_t>(model.num_vertices()), -1),
      stuck_(Eigen::MatrixXd::Zero(model.num_vertices(), model.dim())) {
  const Eigen::MatrixXd& V = model.surface.V;
  diagonal_ = (V.colwise().maxCoeff() - V.colwise().minCoeff()).norm();
  for (size_t p = 0; p < model.paddles.size(); ++p)
    for (int v : model::touching_at_start(model, model.paddles[p]))
      if (paddle_[static_cast<size_t>(v)] < 0 &&
          !supports_.held(model.paddles[p].axis * model.num_vertices() + v))
        paddle_[static_cast<size_t>(v)] = static_cast<int>(p);
}

model::DofMap ContactSet::held_map() const {
  std::vector<int> contacts;
  const int n = model_.num_vertices();
  for (int v = 0; v < n; ++v) {
    const int p = paddle_[static_cast<size_t>(v)];
    if (p < 0) continue;
    const model::Paddle& paddle = model_.paddles[static_cast<size_t>(p)];
    for (int a = 0; a < model_.dim(); ++a)
      if (a == paddle.axis || paddle.sticking) contacts.push_back(a * n + v);
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
      paddle_[static_cast<size_t>(v)] = -1;
      ++released;
    }
  }
  return released;
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

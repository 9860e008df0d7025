// SPDX-License-Identifier: GPL-3.0-or-later
// Rigid paddles in contact (internal to the Newton scheme): which vertices
// each paddle holds (an active set), the values it holds them at, and the
// checks of a paddle setup.
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "fiberfluid/model/dof_map.hpp"
#include "fiberfluid/model/model.hpp"
#include "fiberfluid/solve/newton/newton.hpp"
#include "fiberfluid/util/status.hpp"

namespace fiberfluid::solve {

// A vertex that passes a paddle joins its set as soon as an iterate shows it
// (feasibility first); a vertex leaves only at an equilibrium of the current
// set (release_pulling, called by the solver at a solution). A frictionless
// paddle holds its axis' unknown on its plane; a sticking one holds every
// axis where the vertex first touched.
class ContactSet {
 public:
  // A body resting on a paddle is held by it from the first iterate.
  // `supports`: the supports' map, which must outlive the set.
  ContactSet(const model::Model& model, const model::DofMap& supports);

  // Per vertex: the paddle holding it, or -1.
  const std::vector<int>& paddle_of() const { return paddle_; }
  // The supports' map with the contact unknowns held too.
  model::DofMap held_map() const;
  // Held values: supports and prescribed values from the path, contact
  // vertices on their planes (and, sticking, where they first touched).
  void apply_held_values(const LoadPoint& at, const model::DofMap& dofs, Eigen::VectorXd& x) const;
  // Vertices past a paddle join its contact set; how many did (with `apply`
  // false, 1 when any would). `reach` (a share of the body's diagonal): how
  // far past the plane a vertex must be; a negative one takes in vertices
  // that stand that close in front of it.
  int add_penetrating(const LoadPoint& at, const Eigen::VectorXd& x, bool apply = true,
                      double reach = 1e-12);
  // Contact vertices whose paddle would have to pull them (the force on the
  // body in `R` at their held unknown) leave the set; how many did.
  int release_pulling(const Eigen::VectorXd& R);
  // A warm start's contact set: the vertices that stand on a paddle's plane
  // (a nearby solution held them there) or past it.
  void touch_planes(const LoadPoint& at, const Eigen::VectorXd& x) {
    add_penetrating(at, x, true, -1e-9);
  }

  // Snapshot and restore, for a step that is cut.
  struct State {
    std::vector<int> paddle;
    Eigen::MatrixXd stuck;
  };
  State state() const { return {paddle_, stuck_}; }
  void restore(const State& state) {
    paddle_ = state.paddle;
    stuck_ = state.stuck;
  }

 private:
  const model::Model& model_;
  const model::DofMap& supports_;
  std::vector<int> paddle_;  // per vertex: its paddle, or -1
  Eigen::MatrixXd stuck_;    // sticking contact: displacement at first touch
  double diagonal_ = 1.0;    // the body's bounding-box diagonal
};

// Whether paddles at these planes can work (why not): two on one axis, on
// opposite sides, that meet or pass each other (`where`: when, for the message).
Status check_planes(const model::Model& model, const std::vector<double>& planes,
                    const std::string& where = "");

// Whether a paddle setup can start (why not): an axis out of range, a paddle
// inside the body at its start.
Status check_paddle_start(const model::Model& model);

// Whether a paddle setup can work over `steps` steps (why not).
Status check_paddles(const model::Model& model, int steps);

}  // namespace fiberfluid::solve

// SPDX-License-Identifier: GPL-3.0-or-later
// Rigid paddles in contact (internal to the Newton scheme): which vertices
// each paddle holds (an active set), the values it holds them at, and the
// checks of a paddle setup.
#pragma once

#include <Eigen/Core>
#include <algorithm>
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
// axis where the vertex first touched. A Coulomb paddle holds a vertex like a
// sticking one while its tangential force stays within friction times its
// normal force; past that the vertex slides, its tangential unknowns free and
// pushed by friction times its normal force against its slide over the load
// increment (update_friction, at each solution of the current set).
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
  // Coulomb's law at a solution (R: its residual, the friction forces in):
  // a held vertex whose tangential force exceeds friction times its normal
  // force slides; a sliding one whose slide turned against its friction is
  // held again; a sliding one's friction follows its normal force and its
  // slide. How many vertices changed state or friction force (by more than
  // `tolerance` of its bound).
  int update_friction(const Eigen::VectorXd& R, const Eigen::VectorXd& x, double tolerance);
  // Puts the sliding vertices' friction forces (on the body) into a residual
  // (R at a held unknown is the force its hold exerts on the body, so a
  // force on the body enters with a minus sign).
  void add_friction(Eigen::VectorXd& R) const;
  // The step is accepted at x: a sliding vertex's next slide is measured
  // from where it is now.
  void accept(const Eigen::VectorXd& x);
  // A sliding vertex's friction force on the body (zero for the others).
  Eigen::Vector3d friction_force(int vertex) const;
  bool sliding(int vertex) const { return sliding_[static_cast<size_t>(vertex)] != 0; }
  bool any_friction() const { return has_coulomb_; }
  // A warm start's contact set: the vertices that stand on a paddle's plane
  // (a nearby solution held them there) or past it.
  void touch_planes(const LoadPoint& at, const Eigen::VectorXd& x) {
    add_penetrating(at, x, true, -1e-9);
  }

  // Snapshot and restore, for a step that is cut.
  struct State {
    std::vector<int> paddle;
    Eigen::MatrixXd stuck;
    std::vector<char> sliding;
    Eigen::MatrixXd friction;
  };
  State state() const { return {paddle_, stuck_, sliding_, friction_}; }
  void restore(const State& state) {
    paddle_ = state.paddle;
    stuck_ = state.stuck;
    sliding_ = state.sliding;
    friction_ = state.friction;
    std::fill(history_.begin(), history_.end(), 0);
  }

 private:
  const model::Model& model_;
  const model::DofMap& supports_;
  std::vector<int> paddle_;  // per vertex: its paddle, or -1
  // Whether a vertex in contact holds the tangential axes (sticking, or a
  // Coulomb vertex that does not slide).
  bool holds_tangent(int vertex) const;
  // Leaves contact: no paddle, no slide.
  void release(int vertex);

  Eigen::MatrixXd stuck_;      // held tangential contact: where it is held (displacement)
  std::vector<char> sliding_;  // per vertex: a Coulomb contact that slides
  Eigen::MatrixXd friction_;   // per sliding vertex: its friction force on the body (N)
  double diagonal_ = 1.0;      // the body's bounding-box diagonal
  bool has_coulomb_ = false;   // a paddle with Coulomb contact
  // A sliding vertex's last round (update_friction): whether there is one in
  // this step, its friction and slide then, and the secant compliance.
  std::vector<char> history_;
  std::vector<double> compliance_;
  Eigen::MatrixXd last_friction_, last_slide_;
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

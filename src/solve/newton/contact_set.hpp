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
#include "fiberfluid/solve/tangent/added_tangent.hpp"
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
// increment, both followed within Newton's iterations (add_friction,
// friction_tangent); update_friction decides at each solution of the current
// set which vertices slide.
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
  // force (by more than `tolerance` of the largest such bound) slides; a
  // sliding one whose friction falls inside that bound sticks, held again
  // where its increment started. How many vertices changed state.
  int update_friction(const Eigen::VectorXd& R, const Eigen::VectorXd& x, double tolerance);
  // Puts the sliding vertices' friction forces at x (on the body) into the
  // bulk's residual R there, whose held normal rows give their normal forces
  // (R at a held unknown is the force its hold exerts on the body, so a
  // force on the body enters with a minus sign).
  void add_friction(const Eigen::VectorXd& x, Eigen::VectorXd& R) const;
  // A Newton step from x (R: the residual there) that would take a sliding
  // vertex into its cone (or through it) stops that vertex just inside.
  void stop_at_cones(const Eigen::VectorXd& x, const Eigen::VectorXd& R,
                     Eigen::VectorXd& step) const;
  // The friction's part of the tangent at x (R: the residual there), the
  // derivative of add_friction (full layout; empty without sliding vertices).
  AddedTangent friction_tangent(const Eigen::VectorXd& x, const Eigen::VectorXd& R) const;
  // The step is accepted at x: a sliding vertex's next slide is measured
  // from where it is now, from the friction it has now.
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
    Eigen::MatrixXd friction, start_friction;
    std::vector<double> bound, penalty;
  };
  State state() const {
    return {paddle_, stuck_, sliding_, friction_, start_friction_, bound_, penalty_};
  }
  void restore(const State& state) {
    paddle_ = state.paddle;
    stuck_ = state.stuck;
    sliding_ = state.sliding;
    friction_ = state.friction;
    start_friction_ = state.start_friction;
    bound_ = state.bound;
    penalty_ = state.penalty;
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

  // A Coulomb contact's paddle axis (-1: not one), and the axes along which
  // it may slide (not its paddle's, not a support's).
  int coulomb_axis(int vertex) const;
  std::vector<int> tangential_axes(int vertex, int axis) const;
  // A sliding vertex's trial friction at x, f0 - k s, and its friction, the
  // trial returned onto the cone of `bound` (update_friction).
  Eigen::VectorXd trial_friction(int vertex, const Eigen::VectorXd& x) const;
  Eigen::VectorXd friction_at(int vertex, const Eigen::VectorXd& x, double bound) const;
  // A Coulomb vertex's bound friction * N, N from R's normal row.
  double bound_at(int vertex, const Eigen::VectorXd& R) const;
  // Whether a sliding vertex's trial friction takes the stick's tangent:
  // inside the cone of `bound`, or on its rim with the residual R pushing it in.
  bool sticks(int vertex, const Eigen::VectorXd& trial, double bound,
              const Eigen::VectorXd& R) const;
  // Whether a trial lies inside the cone of `bound`, clear of its rim.
  static bool strictly_inside(const Eigen::VectorXd& trial, double bound);
  // The penalty k that keeps a slide's elastic part within kElasticSlide.
  double penalty_for(double bound) const;

  // The elastic part of a slide, within which a sliding vertex's trial stays
  // inside its cone: this share of the body's diagonal (sets the penalty).
  static constexpr double kElasticSlide = 1e-8;

  Eigen::MatrixXd stuck_;      // held tangential contact: where it is held (displacement);
                               // sliding: where its slide over the increment starts
  std::vector<char> sliding_;  // per vertex: a Coulomb contact that slides
  Eigen::MatrixXd friction_;   // per sliding vertex: its friction force on the body (N)
                               // at the last solution
  // Per sliding vertex: its friction at the increment's start (f0), its
  // bound friction * N at the last solution and its penalty k.
  Eigen::MatrixXd start_friction_;
  std::vector<double> bound_, penalty_;
  double diagonal_ = 1.0;     // the body's bounding-box diagonal
  bool has_coulomb_ = false;  // a paddle with Coulomb contact
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

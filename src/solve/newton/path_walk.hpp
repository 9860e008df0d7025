// SPDX-License-Identifier: GPL-3.0-or-later
// Walking the load path (internal to the Newton scheme): one step in pieces
// that halve where Newton fails and grow again where it converges easily,
// from guesses extrapolated along the converged points.
#pragma once

#include <Eigen/Core>
#include <functional>
#include <string>
#include <vector>

#include "fiberfluid/solve/newton/newton_solver.hpp"

namespace fiberfluid::solve {

// Extrapolates the solution along the load path from the last converged
// points (Lagrange, up to quadratic): each step's starting guess. On a smooth
// path it leaves Newton little to do, and it shows the paddles' new contacts
// before the first iteration.
class PathPredictor {
 public:
  explicit PathPredictor(int order) : order_(order) {}
  void add(double t, const Eigen::VectorXd& x) {
    points_.push_back({t, x});
    if (static_cast<int>(points_.size()) > order_ + 1) points_.erase(points_.begin());
  }
  bool extrapolates() const { return points_.size() > 1; }
  // The guess at t; the last point when there is nothing to extrapolate from.
  Eigen::VectorXd predict(double t) const {
    Eigen::VectorXd guess = Eigen::VectorXd::Zero(points_.back().x.size());
    for (size_t i = 0; i < points_.size(); ++i) {
      double weight = 1.0;
      for (size_t j = 0; j < points_.size(); ++j)
        if (j != i) weight *= (t - points_[j].t) / (points_[i].t - points_[j].t);
      guess += weight * points_[i].x;
    }
    return guess;
  }

 private:
  struct Point {
    double t;
    Eigen::VectorXd x;
  };
  int order_;
  std::vector<Point> points_;
};

// Solves one step from the solution x at path parameter `from` to the point
// at(to), along the points at(t) between: pieces of 2^-depth of a step,
// `depth` carried from step to step (the pieces the last step ended with).
// A failing piece is halved (at most newton.max_step_cuts deep); a piece that
// converged easily (in at most 3 Newton iterations) doubles the next one
// again, up to the whole step: one hard moment (first touch, a contact front
// passing) costs a few short pieces, and a hard stretch of the path is
// walked in short pieces without failing at each step's start first. A piece
// that fails from the predictor's guess is first tried again from the last
// solution. Each converged piece joins the predictor.
//
// When the line search stalls at about the same residual three cuts in a
// row, shorter pieces will not help (a step too long stalls lower as it is
// cut): the path has no equilibrium to go on to, and the walk stops there,
// saying so, rather than halving on to the limit (a fit's trial point that
// is too soft for its load failed in minutes that way).
//
// "" or why it failed (x and the contact state are then those of the last
// converged piece).
std::string walk_step(NewtonSolver& solver, const std::function<LoadPoint(double)>& at, double from,
                      double to, const NewtonOptions& options, PathPredictor& predictor,
                      Eigen::VectorXd& x, StepRecord& record, int& depth);

}  // namespace fiberfluid::solve

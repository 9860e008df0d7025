// SPDX-License-Identifier: GPL-3.0-or-later
#include "fiberfluid/solve/newton/path_walk.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "fiberfluid/geom/self_intersection.hpp"
#include "fiberfluid/model/assembly.hpp"
#include "fiberfluid/util/run_control.hpp"

namespace fiberfluid::solve {
namespace {

// Why no equilibrium continues the path, in the body's terms where it can
// be told: the surface of the last Newton iterate passes through itself (a
// self-contact ahead, which the model does not treat). "" when nothing is
// seen.
std::string physical_reason(const model::Model& model, const Eigen::VectorXd& iterate) {
  geom::Surface at = model.surface;
  at.V = model::positions(model, iterate);
  if (!at.V.allFinite()) return {};
  if (const auto crossing = geom::find_self_intersection(at))
    return "; the last iterate passes through itself (faces " + std::to_string(crossing->first) +
           " and " + std::to_string(crossing->second) +
           " cross): the path may run into a self-contact, which the model does not treat";
  return {};
}

}  // namespace

std::string walk_step(NewtonSolver& solver, const std::function<LoadPoint(double)>& at, double from,
                      double to, const NewtonOptions& options, PathPredictor& predictor,
                      Eigen::VectorXd& x, StepRecord& record, int& depth) {
  constexpr int kEasyIterations = 3;
  constexpr int kStalledCuts = 3;  // failures in a row at one residual level
  depth = std::min(depth, options.max_step_cuts);
  double reached = from, piece = (to - from) * std::ldexp(1.0, -depth);
  bool predict = options.predictor;
  std::vector<double> stalls;  // the residual of each line-search failure since the last success
  while (reached < to) {
    if (cancel_requested()) return "interrupted";
    const double target = std::min(to, reached + piece);
    const Eigen::VectorXd saved = x;
    const auto contact = solver.contact_state();
    if (predict) x = predictor.predict(target);
    const int iterations_before = record.newton_iterations;
    const size_t norms_before = record.residual_norms.size();
    const std::string why = solver.solve(at(target), x, record);
    if (why.empty()) {
      solver.use_chosen_tangent();  // after a piece the exact tangent took over
      reached = target;
      ++record.pieces;
      predictor.add(reached, x);
      predict = options.predictor;
      stalls.clear();
      if (depth > 0 && record.newton_iterations - iterations_before <= kEasyIterations) {
        --depth;
        piece *= 2.0;
      }
      continue;
    }
    const Eigen::VectorXd iterate = x;
    x = saved;
    solver.restore(contact);
    if (predict && predictor.extrapolates()) {
      predict = false;
      continue;
    }
    if (solver.use_exact_tangent(why)) continue;  // the same piece, on the exact tangent
    const bool stalled = why.rfind("newton: the line search found no decrease", 0) == 0 &&
                         record.residual_norms.size() > norms_before;
    if (stalled) {
      stalls.push_back(record.residual_norms.back());
    } else {
      stalls.clear();
    }
    if (stalls.size() >= static_cast<size_t>(kStalledCuts)) {
      const auto last = stalls.end() - kStalledCuts;
      const auto [low, high] = std::minmax_element(last, stalls.end());
      if (*high <= 2.0 * *low) {
        std::ostringstream out;
        out << why << ", " << kStalledCuts << " cuts in a row (down to " << std::ldexp(1.0, -depth)
            << " of a step): shorter pieces will not help; no equilibrium continues the path "
               "here (a limit or bifurcation point, or a material too soft for the load)"
            << physical_reason(solver.model(), iterate);
        return out.str();
      }
    }
    if (depth == options.max_step_cuts)
      return why + "; the step was halved " + std::to_string(depth) +
             " times (newton.max_step_cuts): the load step is too large or the material too "
             "soft" +
             physical_reason(solver.model(), iterate);
    ++record.step_cuts;
    ++depth;
    piece *= 0.5;
  }
  return {};
}

}  // namespace fiberfluid::solve

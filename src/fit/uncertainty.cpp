// SPDX-License-Identifier: GPL-3.0-or-later
#include "fiberfluid/fit/uncertainty.hpp"

#include <Eigen/Cholesky>
#include <Eigen/SVD>
#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

#include "fiberfluid/fit/evaluation_cache.hpp"
#include "fiberfluid/util/run_control.hpp"

namespace fiberfluid::fit {

void describe_bounds(const Variables& map, const Eigen::VectorXd& phi, bool with_correlation,
                     FitResult& result) {
  const int P = map.size();
  const Eigen::VectorXd lower = map.lower_phi(), upper = map.upper_phi();
  result.at_bounds.clear();
  result.status_detail.clear();
  for (int k = 0; k < P; ++k) {
    if (!on_bound(phi[k], lower[k], upper[k])) continue;
    const std::string& name = result.names[static_cast<size_t>(k)];
    result.at_bounds.push_back(name);
    std::ostringstream why;
    why << name << " = " << result.values[k] << " is on its "
        << (phi[k] - lower[k] <= upper[k] - phi[k] ? "lower" : "upper") << " bound";
    int partner = -1;
    for (int j = 0; j < P && with_correlation; ++j)
      if (j != k && (partner < 0 ||
                     std::abs(result.correlation(k, j)) > std::abs(result.correlation(k, partner))))
        partner = j;
    if (partner >= 0)
      why << " (its correlation with " << result.names[static_cast<size_t>(partner)] << " is "
          << result.correlation(k, partner) << ")";
    result.status_detail += (result.status_detail.empty() ? "" : "; ") + why.str();
  }
}

void describe_estimates(const Variables& map, const Eigen::VectorXd& phi,
                        const Eigen::MatrixXd& covariance, double variance, FitResult& result) {
  const int P = map.size();
  const Eigen::VectorXd lower = map.lower_phi(), upper = map.upper_phi();
  const Eigen::MatrixXd scaled = variance * covariance;
  for (int k = 0; k < P; ++k)
    for (int j = 0; j < P; ++j) {
      const double denominator = std::sqrt(covariance(k, k) * covariance(j, j));
      result.correlation(k, j) = denominator > 0.0 ? covariance(k, j) / denominator : 0.0;
    }
  describe_bounds(map, phi, true, result);
  for (int k = 0; k < P; ++k) {
    if (on_bound(phi[k], lower[k], upper[k]))
      continue;  // a bound is no estimate: no standard error
    const double sigma = std::sqrt(std::max(0.0, scaled(k, k)));
    const Parameter& p = map.parameters()[static_cast<size_t>(k)];
    result.standard_errors[k] = p.value_derivative(phi[k]) * sigma;
    result.lower_95[k] = p.to_value(phi[k] - 1.96 * sigma);
    result.upper_95[k] = p.to_value(phi[k] + 1.96 * sigma);
  }
}

std::string unidentifiable_because(const Eigen::MatrixXd& J,
                                   const std::vector<std::string>& names) {
  for (Eigen::Index k = 0; k < J.cols(); ++k) {
    if (!J.col(k).allFinite())
      return "the derivatives of the distances by \"" + names[static_cast<size_t>(k)] +
             "\" are not finite";
    if (J.col(k).norm() == 0.0)
      return "no distance changes with \"" + names[static_cast<size_t>(k)] +
             "\" (does the load act? is difference_step large enough to move the result?)";
  }
  if (J.cols() < 2) return "the Jacobian is rank deficient";
  const Eigen::JacobiSVD<Eigen::MatrixXd> svd(J, Eigen::ComputeThinV);
  const Eigen::VectorXd v = svd.matrixV().col(J.cols() - 1);
  std::string which;
  for (Eigen::Index k = 0; k < v.size(); ++k)
    if (std::abs(v[k]) >= 0.3)
      which += (which.empty() ? "\"" : ", \"") + names[static_cast<size_t>(k)] + "\"";
  return "the distances cannot tell " + which +
         " apart (the Jacobian is rank deficient): fix "
         "one of them, or add targets that separate them";
}

void describe_unseen(const std::vector<int>& held, FitResult& result) {
  for (const int k : held) {
    const std::string& name = result.names[static_cast<size_t>(k)];
    result.unseen.push_back(name);
    result.standard_errors[k] = result.lower_95[k] = result.upper_95[k] = std::nan("");
    const bool bound =
        std::find(result.at_bounds.begin(), result.at_bounds.end(), name) != result.at_bounds.end();
    std::ostringstream why;
    why << "the data cannot see \"" << name << "\"" << (bound ? " on its bound" : "")
        << " (= " << result.values[k]
        << "): it is held at that value with no interval, and the other parameters' intervals "
           "are those of a fit with it fixed";
    result.status_detail += (result.status_detail.empty() ? "" : "; ") + why.str();
  }
}

std::vector<int> parameters_to_hold(const Eigen::MatrixXd& J, const Variables& map,
                                    const Eigen::VectorXd& phi) {
  const Eigen::VectorXd lower = map.lower_phi(), upper = map.upper_phi();
  std::vector<int> held;
  for (Eigen::Index k = 0; k < J.cols(); ++k)
    if (!J.col(k).allFinite() || J.col(k).norm() == 0.0 || on_bound(phi[k], lower[k], upper[k]))
      held.push_back(static_cast<int>(k));
  return held;
}

// A linearised interval is the quadratic model's: where a parameter's
// effect fades (gamma far below what the load feels, so the cost flattens
// as it goes to zero) the quadratic closes an interval the data leave open,
// and the truth can lie outside it. Each end is checked on the profile
// likelihood (Venzon and Moolgavkar 1988, Appl. Stat. 37:87; Raue et al.
// 2009, Bioinformatics 25:1923): phi_k moved by t, the other parameters
// re-fitted by Gauss-Newton steps. The 95% level is a rise of the cost by
// chi^2_1(0.95)/2 s^2 (s^2 the residual variance). Where the profile at the
// linearised end has risen by less than half of it, the end is moved out:
// by doubling (to the bound, where the cost never rises enough), then by
// interpolation in sqrt(rise), which is linear for a quadratic cost. An end
// is only moved out: a re-fit that stops early leaves the profile above its
// true value, so it can show that an end lies further out, never that it
// lies further in.
void check_interval_ends(EvaluationCache& evaluations, const FitProblem& m,
                         const Eigen::VectorXd& phi, const Eigen::MatrixXd& covariance,
                         double variance, FitResult& result) {
  const int P = m.parameters().size();
  const Eigen::VectorXd lower = m.parameters().lower_phi(), upper = m.parameters().upper_phi();
  const double level = 0.5 * 3.841458820694124 * variance;
  constexpr double kSmallest = 1e-4;  // a half-width in phi below which rounding rules the rise
  constexpr int kDoublings = 10, kRefinements = 3, kRefits = 3, kRunsPerParameter = 8;
  const bool refit = m.analytic_jacobian() && P > 1;  // else the others stay at the optimum
  // How far one move may take each other parameter: a log-scaled one by
  // max_step_factor (as a Levenberg-Marquardt step), a linear one by its
  // linearised 95% half-width (nothing for one on its bound). A parameter
  // the data barely see has a huge variance, and an uncapped move would
  // throw the run far off, to where it may not even run.
  Eigen::VectorXd reach(P);
  for (int j = 0; j < P; ++j)
    reach[j] = on_bound(phi[j], lower[j], upper[j]) || covariance(j, j) == 0.0  // or held
                   ? 0.0
                   : m.parameters().parameters()[static_cast<size_t>(j)].log_scale
                         ? std::log(m.options().max_step_factor)
                         : 1.96 * std::sqrt(std::max(0.0, variance * covariance(j, j)));
  // The checks' forward runs, at most kRunsPerParameter per parameter: past
  // it a profile point is not run, and an end moves out only as far as the
  // points already run show (each run's cost is an upper bound of the
  // profile there, so what they show holds).
  const int budget = kRunsPerParameter;
  result.interval_notes.assign(static_cast<size_t>(P), "");
  for (int k = 0; k < P && !cancel_requested(); ++k) {
    const int runs_before = evaluations.forward_runs;
    const Parameter& parameter = m.parameters().parameters()[static_cast<size_t>(k)];
    const double half = 1.96 * std::sqrt(std::max(0.0, variance * covariance(k, k)));
    if (on_bound(phi[k], lower[k], upper[k]) || !(half > kSmallest) || !(level > 0.0)) continue;
    const Eigen::VectorXd path = covariance.col(k) / covariance(k, k);  // the linearised profile
    auto value = [&](double phi_k) { return parameter.to_value(phi_k); };
    std::ostringstream note;
    for (const int side : {-1, 1}) {
      const double farthest = side < 0 ? lower[k] - phi[k] : upper[k] - phi[k];
      auto clip = [&](double t) {
        return side < 0 ? std::max(t, farthest) : std::min(t, farthest);
      };
      auto capped = [&](const Eigen::VectorXd& from, Eigen::VectorXd to) {
        for (int j = 0; j < P; ++j)
          if (j != k) to[j] = from[j] + std::clamp(to[j] - from[j], -reach[j], reach[j]);
        return Eigen::VectorXd(to.cwiseMax(lower).cwiseMin(upper));
      };
      // The profile's rise at t (infinite where the run fails: no parameters
      // there), re-fitted from the nearest profile point already found (a
      // continuation along the profile), the first from the linearised one.
      std::vector<std::pair<double, Eigen::VectorXd>> found;  // (t, the re-fitted point)
      auto rise = [&](double t) {
        Eigen::VectorXd at = capped(phi, phi + t * path);
        const auto nearest = std::min_element(found.begin(), found.end(), [&](auto& a, auto& b) {
          return std::abs(a.first - t) < std::abs(b.first - t);
        });
        if (nearest != found.end()) {
          at = nearest->second;
          at[k] = std::clamp(phi[k] + t, lower[k], upper[k]);
        }
        double best = std::numeric_limits<double>::infinity();
        Eigen::VectorXd best_at = at;
        for (int step = 0; step <= kRefits && !cancel_requested(); ++step) {
          if (evaluations.forward_runs - runs_before >= budget) break;
          const bool more = refit && step < kRefits;
          const Evaluation& e = evaluations.at(at, more);
          if (!e.ok) break;
          const double before = best, here = m.cost(e.residuals) - result.final_cost;
          if (here < best) best = here, best_at = at;
          if (!more || before - here < 0.05 * level) {  // re-fitted, or as good as
            found.emplace_back(t, best_at);
            break;
          }
          Eigen::MatrixXd J = e.jacobian;
          J.col(k).setZero();  // phi_k stays where the profile puts it
          Eigen::MatrixXd H = J.transpose() * J;
          H(k, k) = 1.0;
          const Eigen::VectorXd g = J.transpose() * e.residuals;
          const Eigen::LDLT<Eigen::MatrixXd> normal(H);
          if (normal.info() != Eigen::Success) break;
          const Eigen::VectorXd move = normal.solve(g);
          if (0.5 * g.dot(move) < 0.05 * level) {  // the step would hardly gain: re-fitted
            found.emplace_back(t, best_at);
            break;
          }
          at = capped(at, at - move);
        }
        return best;
      };
      // The first probe goes at most two Levenberg-Marquardt steps out: the
      // linearised end of a parameter the data barely see lies decades
      // away, where runs are slow or fail.
      const double linearised = clip(side * half);
      const double first = clip(
          side *
          std::min(half, parameter.log_scale ? 2.0 * std::log(m.options().max_step_factor) : half));
      double t_in = first, rise_in = rise(t_in);
      if (!(rise_in < 0.5 * level)) continue;  // the profile's end lies inside the linearised one
      double t = t_in, r = rise_in;
      bool unbounded = false;
      for (int d = 0; d < kDoublings && r < level && !cancel_requested(); ++d) {
        if (t == farthest) {
          unbounded = true;
          break;
        }
        t_in = t, rise_in = r;
        t = clip(2.0 * t);
        r = rise(t);
      }
      if (r < level) unbounded = true;
      if (!unbounded && std::abs(t) <= std::abs(linearised)) continue;  // crossed inside it
      double end = t;
      if (!unbounded) {  // the crossing lies between t_in and t
        for (int i = 0; i < kRefinements && !cancel_requested(); ++i) {
          const double a = std::sqrt(std::max(0.0, rise_in));
          const double b = std::isfinite(r) ? std::sqrt(r) : 2.0 * std::sqrt(level) + a;
          double s = (std::sqrt(level) - a) / (b - a);
          s = std::clamp(std::isfinite(s) ? s : 0.5, 0.1, 0.9);  // keep the bracket shrinking
          const double mid = t_in + s * (t - t_in), r_mid = rise(mid);
          if (r_mid < level) {
            t_in = mid, rise_in = r_mid;
          } else {
            t = mid, r = r_mid;
          }
          if (std::abs(r_mid / level - 1.0) < 0.1) break;
        }
        end = t_in;  // the profile is below the level here: inside the 95% region
        if (std::abs(end) <= std::abs(linearised)) continue;  // none further out below the level
      }
      (side < 0 ? result.lower_95 : result.upper_95)[k] = value(phi[k] + end);
      note << (note.tellp() > 0 ? "; " : "") << (side < 0 ? "lower" : "upper") << " end ";
      if (unbounded)
        note << "at the " << (side < 0 ? "lower" : "upper") << " bound, " << value(phi[k] + end)
             << ": the cost rises by less than the 95% level out there (the data do not bound "
             << parameter.name << (side < 0 ? " from below" : " from above") << ")";
      else
        note << "moved out to at least " << value(phi[k] + end)
             << " (the cost rises more slowly than the quadratic's out to the linearised end, "
             << value(phi[k] + side * half) << ")";
    }
    result.interval_notes[static_cast<size_t>(k)] = note.str();
  }
}

}  // namespace fiberfluid::fit

// SPDX-License-Identifier: GPL-3.0-or-later
#include "solve/load_stepper.hpp"

#include <chrono>
#include <cmath>
#include <sstream>
#include <unistd.h>

#include "geom/area_vectors.hpp"
#include "model/assembly.hpp"
#include "model/loads.hpp"
#include "solve/dense_lu.hpp"

namespace fiberfluid::solve {
namespace {

using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

// The system of one load step with its boundary conditions applied, factored.
class ConstrainedSystem {
 public:
  ConstrainedSystem(const model::DofPartition& partition, const SteppingOptions& options)
      : partition_(partition), options_(options) {}

  Status factorize(Eigen::MatrixXd A) {
    A_ = std::move(A);
    if (options_.boundary_method == model::BoundaryMethod::Penalty) {
      Eigen::MatrixXd penalised = A_;
      Eigen::VectorXd unused = Eigen::VectorXd::Zero(A_.rows());
      model::apply_penalty(partition_, Eigen::VectorXd::Zero(partition_.constrained.size()),
                           options_.penalty, penalised, unused);
      return lu_.factorize(penalised);
    }
    Eigen::MatrixXd A_free;
    Eigen::VectorXd unused;
    model::reduce_system(partition_, Eigen::VectorXd::Zero(partition_.constrained.size()), A_,
                         Eigen::VectorXd::Zero(A_.rows()), A_free, unused);
    return lu_.factorize(A_free);
  }

  // The increment of every unknown for a load increment dB and increments
  // of the prescribed displacements.
  Eigen::VectorXd solve(const Eigen::VectorXd& dB, const Eigen::VectorXd& d_values) const {
    if (options_.boundary_method == model::BoundaryMethod::Penalty) {
      Eigen::VectorXd B = dB;
      for (size_t k = 0; k < partition_.constrained.size(); ++k)
        B[partition_.constrained[k]] = options_.penalty * d_values[static_cast<Eigen::Index>(k)];
      return lu_.solve(B);
    }
    const Eigen::VectorXd free = lu_.solve(model::reduce_rhs(partition_, d_values, A_, dB));
    return model::expand_solution(partition_, free, d_values, static_cast<int>(A_.rows()));
  }

 private:
  const model::DofPartition& partition_;
  const SteppingOptions& options_;
  Eigen::MatrixXd A_;  // before boundary conditions (elimination needs A_fc)
  DenseLU lu_;
};

// Dense LU keeps three copies of the (dN+1)-square system (assembled, with
// boundary conditions, factors): refuse up front when they cannot fit in
// this machine's memory, rather than die in the allocator.
std::string dense_memory_problem(const model::Model& model) {
  const double unknowns = model.num_unknowns();
  const double needed = 3.0 * 8.0 * unknowns * unknowns;
  const double physical =
      static_cast<double>(sysconf(_SC_PHYS_PAGES)) * static_cast<double>(sysconf(_SC_PAGESIZE));
  if (physical <= 0.0 || needed < 0.8 * physical) return {};
  std::ostringstream out;
  out.precision(3);
  out << "the dense LU of " << model.num_unknowns() << " unknowns needs about "
      << needed / (1u << 30) << " GiB, more than this machine's " << physical / (1u << 30)
      << " GiB; use a coarser mesh";
  return out.str();
}

}  // namespace

bool SteppingOptions::IsValid(std::string* why) const {
  if (steps < 1) return *why = "steps must be at least 1", false;
  if (!(penalty > 0.0) || !std::isfinite(penalty))
    return *why = "penalty must be a positive number", false;
  return true;
}

std::string SteppingSummary::BriefReport() const {
  std::ostringstream out;
  out << (success ? "success" : "failure") << ": " << steps.size() << " steps, "
      << factorizations << " factorizations, " << total_seconds << " s";
  if (!success) out << ": " << message;
  return out.str();
}

SteppingSummary solve_load_steps(const model::Model& model, const SteppingOptions& options,
                                 const StepObserver& observer) {
  const Clock::time_point start = Clock::now();
  SteppingSummary summary;
  summary.unknowns = Eigen::VectorXd::Zero(model.num_unknowns());
  auto fail = [&](const std::string& why) {
    summary.message = why;
    summary.total_seconds = seconds_since(start);
    return summary;
  };
  std::string why;
  if (!options.IsValid(&why)) return fail(why);
  why = model::singular_setup_reason(model);
  if (!why.empty()) return fail(why);
  why = dense_memory_problem(model);
  if (!why.empty()) return fail(why);

  const model::DofPartition partition = model::partition_dofs(model);
  ConstrainedSystem system(partition, options);
  const int n = options.steps;
  const Eigen::MatrixXd& reference = model.surface.V;

  for (int k = 1; k <= n; ++k) {
    const Clock::time_point step_start = Clock::now();
    const Eigen::MatrixXd X = model::positions(model, summary.unknowns);

    if (k == 1 || options.rebuild_matrix) {
      Clock::time_point t = Clock::now();
      Eigen::MatrixXd A = model::system_matrix(model, options.rebuild_matrix ? X : reference);
      summary.assemble_seconds += seconds_since(t);
      t = Clock::now();
      const Status status = system.factorize(std::move(A));
      summary.factorize_seconds += seconds_since(t);
      ++summary.factorizations;
      if (!status.ok) return fail("step " + std::to_string(k) + ": " + status.message);
    }

    Clock::time_point t = Clock::now();
    const std::vector<double> now = model::load_factors(model, k, n);
    const std::vector<double> before = model::load_factors(model, k - 1, n);
    std::vector<double> increment(now.size());
    for (size_t l = 0; l < now.size(); ++l) increment[l] = now[l] - before[l];
    const Eigen::VectorXd dB =
        model::right_hand_side(model, options.update_load_geometry ? X : reference, increment);
    const Eigen::VectorXd d_values = model::constrained_values(model, partition, k, n) -
                                     model::constrained_values(model, partition, k - 1, n);
    summary.assemble_seconds += seconds_since(t);

    t = Clock::now();
    summary.unknowns += system.solve(dB, d_values);
    summary.solve_seconds += seconds_since(t);
    if (!summary.unknowns.allFinite())
      return fail("step " + std::to_string(k) + ": the solution is not finite");

    StepRecord record;
    record.step = k;
    record.load_factors = now;
    record.pressure = summary.unknowns[model.pressure_dof()];
    record.volume = geom::enclosed_volume(model::positions(model, summary.unknowns),
                                          model.surface.F);
    record.max_displacement =
        model::displacements(model, summary.unknowns).rowwise().norm().maxCoeff();
    record.seconds = seconds_since(step_start);
    summary.steps.push_back(record);
    if (observer) observer(record, summary.unknowns);
  }
  summary.success = true;
  summary.total_seconds = seconds_since(start);
  return summary;
}

}  // namespace fiberfluid::solve

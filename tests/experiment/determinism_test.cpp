// SPDX-License-Identifier: GPL-3.0-or-later
// The same run gives the same numbers: to the last bit with the same thread
// count, and to 1e-12 (relative) with 1 and with 2 threads (issue 11).
#include <gtest/gtest.h>
#include <omp.h>

#include <cstring>

#include "fiberfluid/experiment/experiment.hpp"
#include "fiberfluid/experiment/run/runner.hpp"
#include "test_support.hpp"

namespace fiberfluid::experiment {
namespace {

struct Outcome {
  Eigen::VectorXd unknowns;
  long long kept_fibers = 0;
};

Outcome run_with(const char* experiment, int threads) {
  const int before = omp_get_max_threads();
  omp_set_num_threads(threads);
  const Experiment ex =
      load_experiment(testing::experiment_file(experiment));  // prunes in parallel
  RunOptions options;
  options.jobs = 1;
  const ExperimentResult result = run_experiment(ex, {}, options);
  omp_set_num_threads(before);
  EXPECT_TRUE(result.runs_succeeded()) << experiment;
  return {result.runs.front().summary.unknowns, ex.simulation().cases.front().fibers.kept};
}

class Determinism : public ::testing::TestWithParam<const char*> {};

TEST_P(Determinism, SameThreadsSameBitsAndOneOrTwoThreadsAgree) {
  const Outcome first = run_with(GetParam(), 2), again = run_with(GetParam(), 2);
  ASSERT_GT(first.unknowns.size(), 0);
  EXPECT_EQ(first.kept_fibers, again.kept_fibers);
  // Bit for bit: not merely close.
  EXPECT_EQ(0, std::memcmp(first.unknowns.data(), again.unknowns.data(),
                           sizeof(double) * static_cast<size_t>(first.unknowns.size())));
  const Outcome serial = run_with(GetParam(), 1);
  EXPECT_EQ(first.kept_fibers, serial.kept_fibers);
  EXPECT_LE((serial.unknowns - first.unknowns).norm(), 1e-12 * first.unknowns.norm());
}

// A pruned body with the paper's incremental scheme; paddles with Newton's
// contact iterations and GMRES.
INSTANTIATE_TEST_SUITE_P(Experiments, Determinism,
                         ::testing::Values("liver_gravity.json", "liver_paddles.json"));

}  // namespace
}  // namespace fiberfluid::experiment

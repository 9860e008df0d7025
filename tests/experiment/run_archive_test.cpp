// SPDX-License-Identifier: GPL-3.0-or-later
// A run's outcome as bytes (what an MPI rank sends back), and the ranks of a
// one-process run. The runs over several ranks are tests/mpi's.
#include "fiberfluid/experiment/run/run_archive.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <limits>
#include <nlohmann/json.hpp>

#include "fiberfluid/experiment/experiment.hpp"
#include "fiberfluid/parallel/ranks.hpp"
#include "fiberfluid/util/run_control.hpp"

namespace fiberfluid::experiment {
namespace {

// A Newton run with a paddle (held forces, paddle states, residual norms),
// with the unknowns after each step, and matrices where runs with
// sensitivities have them.
RunOutcome paddle_run() {
  const nlohmann::json config = nlohmann::json::parse(R"({
    "name": "pressed",
    "surface": {"generator": "icosphere", "subdivisions": 1, "radius": 0.05},
    "material": {"law": {"type": "exponential", "Y0": 20000, "beta": 3}, "gamma": 1},
    "supports": [{"where": "z <= -0.04", "label": "base"}],
    "paddles": [{"label": "press", "axis": "z", "side": "above", "compression": 0.1}],
    "stepping": {"scheme": "newton", "steps": 3}
  })");
  const Experiment ex = parse_experiment(config, ".", "pressed.json");
  RunOutcome outcome;
  outcome.run.variant = "pressed";
  outcome.run.rank = 3;
  outcome.run.summary = solve::solve_load_steps(
      ex.simulation().cases.front().model, ex.simulation().cases.front().stepping,
      [&](const solve::StepRecord&, const Eigen::VectorXd& x) {
        outcome.step_unknowns.push_back(x);
      });
  solve::StepRecord& last = outcome.run.summary.steps.back();
  last.sensitivities.state = Eigen::MatrixXd::Random(outcome.run.summary.unknowns.size(), 2);
  last.sensitivities.reactions = {Eigen::MatrixXd::Random(3, 2)};
  last.sensitivities.reactions.front()(1, 1) = std::numeric_limits<double>::quiet_NaN();
  last.sensitivities.paddle_forces = {Eigen::MatrixXd::Random(3, 2)};
  outcome.run.system_matrix = Eigen::MatrixXd::Random(4, 4);
  return outcome;
}

// Bit for bit, NaN included.
bool same_bits(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b) {
  return a.rows() == b.rows() && a.cols() == b.cols() &&
         (a.size() == 0 ||  // an empty matrix's data() may be null
          std::memcmp(a.data(), b.data(), sizeof(double) * static_cast<size_t>(a.size())) == 0);
}

TEST(RunArchive, AnOutcomeArrivesBitForBit) {
  const RunOutcome sent = paddle_run();
  ASSERT_TRUE(sent.run.summary.success) << sent.run.summary.message;
  ASSERT_EQ(sent.step_unknowns.size(), 3u);
  const std::string bytes = pack_run_outcome(sent);
  const RunOutcome got = unpack_run_outcome(bytes);
  EXPECT_EQ(pack_run_outcome(got), bytes);  // every field, read as it was written

  EXPECT_EQ(got.run.variant, "pressed");
  EXPECT_EQ(got.run.rank, 3);
  EXPECT_TRUE(same_bits(got.run.system_matrix, sent.run.system_matrix));
  const solve::SteppingSummary &s = sent.run.summary, &g = got.run.summary;
  EXPECT_TRUE(g.success);
  EXPECT_EQ(g.scheme, solve::Scheme::Newton);
  EXPECT_EQ(g.newton_iterations, s.newton_iterations);
  EXPECT_TRUE(std::isnan(g.limit_load_factor));  // no limit point: NaN, kept
  EXPECT_TRUE(same_bits(g.unknowns, s.unknowns));
  EXPECT_TRUE(same_bits(g.reaction_forces, s.reaction_forces));
  EXPECT_EQ(g.total_seconds, s.total_seconds);
  ASSERT_EQ(g.steps.size(), s.steps.size());
  for (size_t k = 0; k < s.steps.size(); ++k) {
    EXPECT_TRUE(same_bits(got.step_unknowns[k], sent.step_unknowns[k])) << k;
    const solve::StepRecord &a = s.steps[k], &b = g.steps[k];
    EXPECT_EQ(b.load_factors, a.load_factors);
    EXPECT_EQ(b.residual_norms, a.residual_norms);
    EXPECT_EQ(b.pair_passes.computed, a.pair_passes.computed);
    ASSERT_EQ(b.held_forces.size(), a.held_forces.size());
    for (size_t h = 0; h < a.held_forces.size(); ++h) {
      EXPECT_EQ(b.held_forces[h].vertex, a.held_forces[h].vertex);
      EXPECT_EQ(b.held_forces[h].paddle, a.held_forces[h].paddle);
      EXPECT_EQ(b.held_forces[h].force, a.held_forces[h].force);
    }
    ASSERT_EQ(b.paddles.size(), 1u);
    EXPECT_EQ(b.paddles[0].force, a.paddles[0].force);
    EXPECT_EQ(b.paddles[0].contacts, a.paddles[0].contacts);
    EXPECT_EQ(b.reactions, a.reactions);
  }
  EXPECT_GT(s.steps.back().paddles[0].contacts, 0);
  EXPECT_TRUE(same_bits(g.steps.back().sensitivities.state, s.steps.back().sensitivities.state));
  EXPECT_TRUE(same_bits(g.steps.back().sensitivities.reactions.at(0),
                        s.steps.back().sensitivities.reactions.at(0)));
  EXPECT_TRUE(same_bits(g.steps.back().sensitivities.paddle_forces.at(0),
                        s.steps.back().sensitivities.paddle_forces.at(0)));
}

// A message cut short, with bytes to spare, or with a length beyond its end
// is refused with an exception: never read past, never a huge allocation.
TEST(RunArchive, AMalformedMessageIsRefused) {
  const std::string bytes = pack_run_outcome(paddle_run());
  EXPECT_THROW(unpack_run_outcome(bytes.substr(0, bytes.size() - 1)), std::runtime_error);
  EXPECT_THROW(unpack_run_outcome(bytes.substr(0, 20)), std::runtime_error);
  EXPECT_THROW(unpack_run_outcome(bytes + "x"), std::runtime_error);
  EXPECT_THROW(unpack_run_outcome(""), std::runtime_error);
  std::string huge = bytes;  // the variant name's length, first: 2^62
  const std::uint64_t length = std::uint64_t{1} << 62;
  std::memcpy(huge.data(), &length, sizeof length);
  EXPECT_THROW(unpack_run_outcome(huge), std::runtime_error);
}

// Without a launcher the program is one rank: every item is computed and
// delivered here, in order; Ctrl-C stops the dealing.
TEST(Ranks, OneProcessIsRankZeroOfOne) {
  int argc = 1;
  char name[] = "test";
  char* args[] = {name, nullptr};
  char** argv = args;
  ASSERT_FALSE(parallel::launched_by_mpi());  // ctest does not run this under mpirun
  const parallel::Ranks ranks(&argc, &argv);
  EXPECT_EQ(ranks.rank(), 0);
  EXPECT_EQ(ranks.size(), 1);
  EXPECT_TRUE(ranks.root());
  EXPECT_TRUE(ranks.all_ok(true));
  EXPECT_FALSE(ranks.all_ok(false));
  std::vector<double> values = {1.5, -2.0};
  ranks.sum(values);
  EXPECT_EQ(values, (std::vector<double>{1.5, -2.0}));

  std::vector<std::pair<size_t, std::string>> delivered;
  const auto compute = [](size_t item) { return std::to_string(item * item); };
  ranks.deal(4, compute, [&](size_t item, int rank, std::string&& bytes) {
    EXPECT_EQ(rank, 0);
    delivered.emplace_back(item, bytes);
  });
  EXPECT_EQ(delivered,
            (std::vector<std::pair<size_t, std::string>>{{0, "0"}, {1, "1"}, {2, "4"}, {3, "9"}}));

  delivered.clear();
  ranks.deal(4, compute, [&](size_t item, int, std::string&& bytes) {
    delivered.emplace_back(item, bytes);
    if (item == 1) request_cancel();
  });
  clear_cancel();
  EXPECT_EQ(delivered.size(), 2u);
}

}  // namespace
}  // namespace fiberfluid::experiment

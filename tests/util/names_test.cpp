// SPDX-License-Identifier: GPL-3.0-or-later
#include "fiberfluid/util/names.hpp"

#include <gtest/gtest.h>

#include <set>
#include <string>

#include "fiberfluid/experiment/experiment.hpp"
#include "fiberfluid/fit/calibration.hpp"
#include "fiberfluid/geom/generators.hpp"
#include "fiberfluid/model/boundary_conditions.hpp"
#include "fiberfluid/model/model.hpp"
#include "fiberfluid/solve/linear_solver.hpp"
#include "fiberfluid/solve/stepping.hpp"

namespace fiberfluid {
namespace {

// Each value named once, each name once, and every name read back as its value.
template <class Table>
void expect_one_to_one(const Table& names) {
  std::set<std::string> seen_names;
  std::set<int> seen_values;
  for (const auto& entry : names.entries()) {
    EXPECT_TRUE(seen_names.insert(entry.name).second) << entry.name << " named twice";
    EXPECT_TRUE(seen_values.insert(static_cast<int>(entry.value)).second) << entry.name;
    EXPECT_EQ(names.find(entry.name), entry.value) << entry.name;
    EXPECT_STREQ(names.name(entry.value), entry.name);
  }
}

TEST(Names, EveryTableIsOneToOne) {
  expect_one_to_one(solve::kSchemeNames);
  expect_one_to_one(solve::kTangentSolverNames);
  expect_one_to_one(solve::kControlNames);
  expect_one_to_one(solve::kSolverKindNames);
  expect_one_to_one(model::kBoundaryMethodNames);
  expect_one_to_one(model::kScheduleNames);
  expect_one_to_one(model::kIntegrationNames);
  expect_one_to_one(model::kConnectionCountNames);
  expect_one_to_one(geom::kDomeBaseNames);
  expect_one_to_one(experiment::kExperimentKindNames);
  expect_one_to_one(fit::kMethodNames);
  expect_one_to_one(fit::kLossNames);
  expect_one_to_one(fit::kFitStatusNames);
}

TEST(Names, AnUnknownNameIsRefusedListingTheNames) {
  try {
    fit::kLossNames.parse("absolute", "fit.loss");
    FAIL() << "an unknown name was read";
  } catch (const InputError& e) {
    EXPECT_STREQ(e.what(), "fit.loss: expected squared, huber or cauchy, got \"absolute\"");
  }
  EXPECT_FALSE(solve::kTangentSolverNames.find("Dense"));  // names are exact
  EXPECT_EQ(solve::kTangentSolverNames.listed(), "auto, dense, krylov, sparse or reused");
  // Every status a fit can end with has its fit.json name.
  for (int s = 0; s <= static_cast<int>(fit::FitStatus::Interrupted); ++s)
    EXPECT_STRNE(fit::to_string(static_cast<fit::FitStatus>(s)), "?") << s;
}

}  // namespace
}  // namespace fiberfluid

// SPDX-License-Identifier: GPL-3.0-or-later
// A FEM benchmark scene as a fiber model (bridge::fiber_model_of_scene): the
// scene's held nodes, needle and gravity on the boundary, and the same model
// as an experiment file describes it.
#include "fiberfluid/bridge/scene_model.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <nlohmann/json.hpp>

#include "fiberfluid/experiment/experiment.hpp"
#include "fiberfluid/model/assembly.hpp"
#include "fiberfluid/solve/stepping.hpp"

namespace fiberfluid::bridge {
namespace {

bool held_in_scene(const fem::Scene& scene, int node) {
  return std::binary_search(scene.fixed_nodes.begin(), scene.fixed_nodes.end(), node);
}

TEST(SceneModel, TheBlockHoldsItsFixedNodesAndPushesItsNeedle) {
  const fem::Scene scene = fem::needle_block({});
  const fem::Boundary boundary = fem::boundary(scene.mesh);
  const model::Model m = fiber_model_of_scene(scene, boundary, model::Material::linear(1e4, 5.0));
  ASSERT_EQ(m.dim(), 2);
  EXPECT_EQ(m.material.surface_tension, 5.0);
  EXPECT_TRUE(m.loads.empty());
  int held_vertices = 0, needles = 0;
  for (size_t v = 0; v < boundary.nodes.size(); ++v) {
    held_vertices += held_in_scene(scene, boundary.nodes[v]);
    needles += boundary.nodes[v] == scene.needle;
  }
  ASSERT_EQ(needles, 1);
  ASSERT_GT(held_vertices, 0);
  EXPECT_EQ(m.constraints.size(), static_cast<size_t>(2 * (held_vertices + needles)));
  for (const model::Constraint& c : m.constraints) {
    const int node = boundary.nodes[static_cast<size_t>(c.vertex)];
    if (node == scene.needle) {
      EXPECT_EQ(c.group, 1);
      EXPECT_EQ(c.value, c.axis == 0 ? -scene.needle_travel : 0.0);
    } else {
      EXPECT_TRUE(held_in_scene(scene, node));
      EXPECT_EQ(c.group, 0);
      EXPECT_EQ(c.value, 0.0);
    }
  }
  EXPECT_EQ(m.fibers, nullptr);  // a rectangle is convex: every fiber stays
}

// The rod as an experiment file poses it: the same run, to the last bits
// that the two orders of the constraints allow.
TEST(SceneModel, TheRodRunsAsTheSameExperimentFileRuns) {
  const fem::Scene scene = fem::bending_rod({});
  const fem::Boundary boundary = fem::boundary(scene.mesh);
  const double Y = 2e4, gamma = 30.0;
  const int steps = 3;
  model::Model m = fiber_model_of_scene(scene, boundary, model::Material::linear(Y, gamma));
  ASSERT_EQ(m.loads.size(), 1u);
  EXPECT_EQ(m.loads[0].kind, model::Load::Kind::Hydrostatic);
  EXPECT_EQ(m.loads[0].density, scene.material.density);
  EXPECT_EQ(m.loads[0].acceleration.z(), scene.gravity.z());

  std::vector<int> fixed;
  for (size_t v = 0; v < boundary.nodes.size(); ++v)
    if (held_in_scene(scene, boundary.nodes[v])) fixed.push_back(static_cast<int>(v));
  const std::vector<double> g(scene.gravity.data(), scene.gravity.data() + 3);
  const nlohmann::json doc = {
      {"name", "rod"},
      {"material", {{"Y", Y}, {"gamma", gamma}}},
      {"supports", {{{"vertices", fixed}, {"axes", "xyz"}}}},
      {"loads", {{{"type", "gravity"}, {"acceleration", g}, {"density", scene.material.density}}}},
      {"stepping", {{"steps", steps}}}};
  experiment::Experiment ex = experiment::read_experiment(doc, ".", "the rod's document");
  experiment::build_experiment(ex, &boundary.surface);
  const experiment::Case& c = ex.simulation().cases.front();

  solve::SteppingOptions stepping;
  stepping.steps = steps;
  const solve::SteppingSummary direct = solve::solve_load_steps(m, stepping);
  const solve::SteppingSummary from_file = solve::solve_load_steps(c.model, c.stepping);
  ASSERT_TRUE(direct.success) << direct.message;
  ASSERT_TRUE(from_file.success) << from_file.message;
  const Eigen::MatrixXd X = model::positions(m, direct.unknowns),
                        X_file = model::positions(c.model, from_file.unknowns);
  const double sag = (X - m.surface.V).cwiseAbs().maxCoeff();
  EXPECT_GT(sag, 1e-6);  // it moved
  EXPECT_LT((X - X_file).cwiseAbs().maxCoeff(), 1e-12 * (1.0 + sag));
}

}  // namespace
}  // namespace fiberfluid::bridge

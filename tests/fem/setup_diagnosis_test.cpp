// SPDX-License-Identifier: GPL-3.0-or-later
// Why a FEM stiffness is singular, told from its setup (issue 59, class 5):
// each cause on a mesh that has it and no other, and a sound setup passes.
#include "fiberfluid/fem/setup_diagnosis.hpp"

#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "fiberfluid/fem/mesh_tools.hpp"

namespace fiberfluid::fem {
namespace {

Mesh box_of_tetrahedra() {
  return to_simplices(structured_grid(Eigen::Vector3d(0.04, 0.04, 0.04), Eigen::Vector3i(2, 2, 2)));
}

// Every axis of the nodes in the plane z = 0.
std::vector<int> bottom_held(const Mesh& mesh) {
  std::vector<int> dofs;
  for (int v = 0; v < mesh.num_nodes(); ++v)
    if (mesh.nodes(v, 2) < 1e-12)
      for (int a = 0; a < 3; ++a) dofs.push_back(3 * v + a);
  return dofs;
}

bool says(const Status& s, const std::string& what) {
  return !s.ok && s.message.find(what) != std::string::npos;
}

TEST(SetupDiagnosis, ASoundSetupHasNoCause) {
  const Mesh mesh = box_of_tetrahedra();
  EXPECT_TRUE(diagnose_singular_setup(mesh, 0.3, bottom_held(mesh)).ok);
  EXPECT_NEAR(worst_tetrahedron(mesh).quality, 0.7, 0.3);  // Kuhn tetrahedra of a cube
}

TEST(SetupDiagnosis, TooFewHeldUnknownsAreCounted) {
  const Mesh mesh = box_of_tetrahedra();
  const Status s = diagnose_singular_setup(mesh, 0.3, {0, 1, 2, 5});
  EXPECT_TRUE(says(s, "too few supports: 4 unknowns held")) << s.message;
}

// Nodes held on the line x = y = 0 only: the body may spin about it.
TEST(SetupDiagnosis, ARigidMotionTheSupportsLeaveFreeIsNamed) {
  const Mesh mesh = box_of_tetrahedra();
  std::vector<int> held;
  for (int v = 0; v < mesh.num_nodes(); ++v)
    if (mesh.nodes(v, 0) < 1e-12 && mesh.nodes(v, 1) < 1e-12)
      for (int a = 0; a < 3; ++a) held.push_back(3 * v + a);
  ASSERT_GE(held.size(), 6u);
  const Status s = diagnose_singular_setup(mesh, 0.3, held);
  EXPECT_TRUE(says(s, "leave a rotation about z free")) << s.message;
  // Only z held everywhere at the bottom: the body slides along x and y.
  std::vector<int> only_z;
  for (int v = 0; v < mesh.num_nodes(); ++v)
    if (mesh.nodes(v, 2) < 1e-12) only_z.push_back(3 * v + 2);
  EXPECT_TRUE(says(diagnose_singular_setup(mesh, 0.3, only_z), "free"));
}

TEST(SetupDiagnosis, AFlatTetrahedronIsNamed) {
  Mesh mesh = box_of_tetrahedra();
  // Squash the box to a millionth of its thickness: every element a sliver.
  mesh.nodes.col(2) *= 1e-6;
  const Status s = diagnose_singular_setup(mesh, 0.3, bottom_held(mesh));
  EXPECT_TRUE(says(s, "is flat (shape quality")) << s.message;
  EXPECT_LT(worst_tetrahedron(mesh).quality, 1e-5);
}

TEST(SetupDiagnosis, APoissonRatioAtOneHalfToRoundingIsNamed) {
  const Mesh mesh = box_of_tetrahedra();
  const Status s = diagnose_singular_setup(mesh, 0.4999999999999999, bottom_held(mesh));
  EXPECT_TRUE(says(s, "nu = ")) << s.message;
  EXPECT_TRUE(diagnose_singular_setup(mesh, 0.4999, bottom_held(mesh)).ok);
}

}  // namespace
}  // namespace fiberfluid::fem

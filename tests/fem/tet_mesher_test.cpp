// SPDX-License-Identifier: GPL-3.0-or-later
// The tetrahedral mesher: it fills the surface, its tetrahedra pass the
// patch test, and it is deterministic.
#include "fiberfluid/fem/tet_mesher.hpp"

#include <gtest/gtest.h>

#include "fiberfluid/fem/mesh_tools.hpp"
#include "fiberfluid/geom/generators.hpp"
#include "fiberfluid/geom/mesh_io.hpp"
#include "fiberfluid/metrics/metrics.hpp"
#include "fiberfluid/util/error.hpp"
#include "test_support.hpp"

namespace fiberfluid::fem {
namespace {

double tetrahedra_volume(const Mesh& mesh) { return node_measures(mesh).sum(); }

TEST(TetMesher, FillsTheSurface) {
  const geom::Surface sphere = geom::icosphere(3, 1.0);
  const double volume = metrics::enclosed_measure(sphere);
  const Mesh mesh = tetrahedralize(sphere);
  EXPECT_GT(mesh.elements.rows(), 100);
  EXPECT_EQ(mesh.elements.cols(), 4);
  // Every tetrahedron positively oriented (element_stiffness throws otherwise).
  Eigen::MatrixXd corners(4, 3);
  for (Eigen::Index e = 0; e < mesh.elements.rows(); ++e) {
    for (int a = 0; a < 4; ++a) corners.row(a) = mesh.nodes.row(mesh.elements(e, a));
    ASSERT_NO_THROW(element_stiffness(corners, Material{})) << e;
  }
  // The tetrahedra fill what the surface bounds, to the facet distance.
  EXPECT_NEAR(tetrahedra_volume(mesh) / volume, 1.0, 0.03);
  const Boundary b = boundary(mesh);
  EXPECT_NEAR(metrics::enclosed_measure(b.surface), tetrahedra_volume(mesh), 1e-12);
  EXPECT_LT(metrics::surface_error(sphere, b.surface), 0.05);
  // A finer size, more tetrahedra, closer volume.
  TetMeshOptions fine;
  fine.size = 0.1;
  const Mesh finer = tetrahedralize(sphere, fine);
  EXPECT_GT(finer.elements.rows(), 4 * mesh.elements.rows());
  EXPECT_LT(std::abs(tetrahedra_volume(finer) / volume - 1.0),
            std::abs(tetrahedra_volume(mesh) / volume - 1.0) + 1e-3);
  // The same input, the same mesh.
  const Mesh again = tetrahedralize(sphere);
  ASSERT_EQ(again.nodes.rows(), mesh.nodes.rows());
  EXPECT_EQ((again.nodes - mesh.nodes).cwiseAbs().maxCoeff(), 0.0);
  EXPECT_EQ(again.elements, mesh.elements);
}

// Any linear field is reproduced exactly on the mesher's tetrahedra of an
// organ (the liver), its boundary held at the field.
TEST(TetMesher, ItsTetrahedraPassThePatchTest) {
  geom::Surface liver = geom::read_surface(testing::data_mesh("liver.obj")).surface;
  const Mesh mesh = tetrahedralize(geom::remove_unused_vertices(liver).surface);
  Material m;
  m.poisson = 0.45;
  const Eigen::Matrix3d A = Eigen::Matrix3d::Random() * 0.01;
  const Boundary b = boundary(mesh);
  Constraints held;
  Eigen::VectorXd exact(mesh.num_dofs());
  for (int v = 0; v < mesh.num_nodes(); ++v)
    exact.segment(3 * v, 3) = A * mesh.nodes.row(v).transpose();
  for (int v : b.nodes)
    for (int a = 0; a < 3; ++a) held.hold(3 * v + a, exact[3 * v + a]);
  ASSERT_LT(static_cast<int>(b.nodes.size()), mesh.num_nodes());  // inner nodes exist
  Eigen::VectorXd u;
  ASSERT_TRUE(
      solve_static(stiffness_matrix(mesh, m), Eigen::VectorXd::Zero(mesh.num_dofs()), held, &u).ok);
  EXPECT_LT((u - exact).cwiseAbs().maxCoeff(), 1e-13);
}

TEST(TetMesher, RefusesWhatBoundsNoSolid) {
  geom::Surface open = geom::icosphere(1, 1.0);
  open.F.conservativeResize(open.F.rows() - 1, 3);
  EXPECT_THROW(tetrahedralize(open), InputError);
  EXPECT_THROW(tetrahedralize(geom::polygon(Eigen::MatrixXd::Identity(3, 2))), InputError);
}

}  // namespace
}  // namespace fiberfluid::fem

// SPDX-License-Identifier: GPL-3.0-or-later
#include "fiberfluid/model/assembly.hpp"

#include <gtest/gtest.h>

#include <random>

#include "fiberfluid/geom/area_vectors.hpp"
#include "fiberfluid/geom/mesh_io.hpp"
#include "fiberfluid/model/fiber_network.hpp"
#include "fiberfluid/model/loads.hpp"
#include "fiberfluid/model/reference/dense_assembly.hpp"
#include "fiberfluid/util/error.hpp"
#include "model/model_fixtures.hpp"
#include "test_support.hpp"

namespace fiberfluid::model {
namespace {

using namespace fiberfluid::model::reference;  // the oracle

TEST(Assembly, PaperRectangleMatrixEntryByEntry) {
  const Model m = testing::paper_rectangle_model();
  Eigen::MatrixXd A = system_matrix(m, m.surface.V);
  const DofPartition partition = partition_dofs(m);
  Eigen::VectorXd B = right_hand_side(m, m.surface.V, {1.0, 1.0});
  apply_penalty(partition, Eigen::VectorXd::Zero(3), 1e9, A, B);
  Eigen::MatrixXd paper(9, 9);  // the paper's Eq. 8
  paper << 329, -105, -84, -140, 0, 0, 0, 0, 28, -105, 329, -140, -84, 0, 0, 0, 0, 28, -84, -140,
      1e9, -105, 0, 0, 0, 0, -28, -140, -84, -105, 329, 0, 0, 0, 0, -28, 0, 0, 0, 0, 329, -105, -84,
      -140, 21, 0, 0, 0, 0, -105, 1e9, -140, -84, -21, 0, 0, 0, 0, -84, -140, 1e9, -105, -21, 0, 0,
      0, 0, -140, -84, -105, 329, 21, 28, 28, -28, -28, 21, -21, -21, 21, 0;
  EXPECT_NEAR((A - paper).cwiseAbs().maxCoeff(), 0.0, 1e-10);
  Eigen::VectorXd paper_B(9);
  paper_B << 0, 0, 0, 0, 1680, 0, 0, 1680, 0;
  EXPECT_EQ(B, paper_B);
}

class AssemblyOnMeshes : public ::testing::TestWithParam<const char*> {
 protected:
  Model model() const {
    Model m;
    m.surface =
        geom::remove_unused_vertices(geom::read_surface(testing::data_mesh(GetParam())).surface)
            .surface;
    m.material = Material::linear(Eigen::Vector3d(2.0, 3.0, 5.0));  // anisotropic on purpose
    m.material.surface_tension = 0.7;
    return m;
  }
};

TEST_P(AssemblyOnMeshes, FiberBlocksAreSymmetricLaplaciansAndIgnoreTranslation) {
  const Model m = model();
  const int n = m.num_vertices();
  const Eigen::MatrixXd A = system_matrix(m, m.surface.V);
  for (int a = 0; a < 3; ++a) {
    const Eigen::MatrixXd K = A.block(a * n, a * n, n, n);
    const double scale = K.diagonal().maxCoeff();
    EXPECT_NEAR((K - K.transpose()).cwiseAbs().maxCoeff(), 0.0, 1e-14 * scale);
    // A rigid translation stretches no fiber: zero force.
    EXPECT_NEAR((K * Eigen::VectorXd::Ones(n)).cwiseAbs().maxCoeff(), 0.0, 1e-12 * scale);
    EXPECT_GT(K.diagonal().minCoeff(), 0.0);
    for (int b = 0; b < 3; ++b)
      if (b != a) {
        EXPECT_EQ(A.block(a * n, b * n, n, n).cwiseAbs().maxCoeff(), 0.0);
      }
  }
  // The blocks differ only by their Y: (K_y - K_x) = (Y_y - Y_x) L_bulk.
  const geom::VertexAreaVectors areas = geom::vertex_area_vectors(m.surface.V, m.surface.F);
  const FiberLaplacians L =
      fiber_laplacians(m.surface.V, areas.magnitude, geom::unique_edges(m.surface));
  EXPECT_NEAR((A.block(n, n, n, n) - A.block(0, 0, n, n) - 1.0 * L.bulk).cwiseAbs().maxCoeff(), 0.0,
              1e-12 * L.bulk.diagonal().maxCoeff());
}

TEST_P(AssemblyOnMeshes, VolumeRowIsThreeCTimesTheVolumeGradient) {
  const Model m = model();
  const int n = m.num_vertices();
  const Eigen::MatrixXd A = system_matrix(m, m.surface.V);
  const double C = geom::vertex_area_vectors(m.surface.V, m.surface.F).C;
  const double h = 1e-6 * geom::bounding_box_diagonal(m.surface.V);
  // The volume is linear in each single coordinate, so central differences
  // are exact up to rounding: compare on the scale of the row.
  const double scale = A.row(m.pressure_dof()).cwiseAbs().maxCoeff();
  for (int i = 0; i < n; i += 7) {
    for (int a = 0; a < 3; ++a) {
      Eigen::MatrixXd plus = m.surface.V, minus = m.surface.V;
      plus(i, a) += h;
      minus(i, a) -= h;
      const double gradient =
          (geom::enclosed_volume(plus, m.surface.F) - geom::enclosed_volume(minus, m.surface.F)) /
          (2 * h);
      const double row = A(m.pressure_dof(), m.dof(i, a));
      EXPECT_NEAR(row, 3 * C * gradient, 1e-6 * scale);
      EXPECT_EQ(row, A(m.dof(i, a), m.pressure_dof()));  // bordered symmetrically
    }
  }
}

TEST_P(AssemblyOnMeshes, HydrostaticLoadsSumToThreeCTimesTheFluidWeight) {
  // sum_i h_i S_i = C sum_f A_f (h_a + h_b + h_c) = 3C * integral(h n dA) = 3C V a_hat,
  // exactly, since h is linear: the paper's loads add up to its fluid's weight.
  Model m = model();
  Load gravity;
  gravity.kind = Load::Kind::Hydrostatic;
  gravity.acceleration = {1.0, -2.0, -9.0};
  gravity.density = 1000.0;
  m.loads = {gravity};
  const Eigen::VectorXd B = right_hand_side(m, m.surface.V, {1.0});
  const int n = m.num_vertices();
  Eigen::Vector3d total(B.segment(0, n).sum(), B.segment(n, n).sum(), B.segment(2 * n, n).sum());
  const double C = geom::vertex_area_vectors(m.surface.V, m.surface.F).C;
  const double V = geom::enclosed_volume(m.surface.V, m.surface.F);
  const Eigen::Vector3d weight = 3 * C * gravity.density * V * gravity.acceleration;
  EXPECT_NEAR((total - weight).norm(), 0.0, 1e-9 * weight.norm());
  EXPECT_EQ(B[m.pressure_dof()], 0.0);
}

INSTANTIATE_TEST_SUITE_P(SharedMeshes, AssemblyOnMeshes,
                         ::testing::Values("cube.obj", "icosahedron.obj", "liver.obj",
                                           "sphere_02b.obj"));

TEST(Assembly, HydrostaticDepthIsMeasuredFromTheHighestPoint) {
  Eigen::MatrixXd X(3, 3);
  X << 0, 0, 1, 0, 0, -1, 5, 5, 0.5;
  const Eigen::VectorXd h = hydrostatic_depths(X, {0, 0, -9.81});
  EXPECT_NEAR(h[0], 0.0, 1e-15);
  EXPECT_NEAR(h[1], 2.0, 1e-15);
  EXPECT_NEAR(h[2], 0.5, 1e-15);
}

TEST(Assembly, LinearResidualVanishesAtTheSolution) {
  const Model m = testing::paper_rectangle_model();
  Eigen::VectorXd x(9);  // the paper's solution, exactly (elimination)
  x << -4, -4, 0, 0, 16.0 / 3.0, 0, 0, 16.0 / 3.0, 32;
  const Eigen::VectorXd r = linear_residual(m, x, {1.0, 1.0});
  const DofPartition p = partition_dofs(m);
  for (int d : p.free) EXPECT_NEAR(r[d], 0.0, 1e-10) << "unknown " << d;
}

TEST(Assembly, SchedulesGiveTheirFactors) {
  Schedule ramp, final_only, up_down, table;
  final_only.kind = Schedule::Kind::Final;
  up_down.kind = Schedule::Kind::UpDown;
  table.kind = Schedule::Kind::Table;
  table.values = {0.5, 2.0, 1.0};
  EXPECT_DOUBLE_EQ(ramp.factor(3, 10), 0.3);
  EXPECT_DOUBLE_EQ(final_only.factor(9, 10), 0.0);
  EXPECT_DOUBLE_EQ(final_only.factor(10, 10), 1.0);
  EXPECT_DOUBLE_EQ(up_down.factor(5, 10), 1.0);
  EXPECT_DOUBLE_EQ(up_down.factor(7, 10), 0.6);
  EXPECT_DOUBLE_EQ(up_down.factor(10, 10), 0.0);
  EXPECT_DOUBLE_EQ(table.factor(2, 3), 2.0);
  EXPECT_DOUBLE_EQ(table.factor(0, 3), 0.0);
}

TEST(Assembly, CoincidentVerticesAreReported) {
  Model m = testing::paper_rectangle_model();
  m.surface.V.row(1) = m.surface.V.row(0);
  EXPECT_THROW(system_matrix(m, m.surface.V), InputError);
}

}  // namespace
}  // namespace fiberfluid::model

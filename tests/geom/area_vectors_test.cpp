// SPDX-License-Identifier: GPL-3.0-or-later
#include "fiberfluid/geom/area_vectors.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "fiberfluid/geom/generators.hpp"
#include "fiberfluid/geom/mesh_io.hpp"
#include "test_support.hpp"

namespace fiberfluid::geom {
namespace {

Surface paper_rectangle() {
  Eigen::MatrixXd P(4, 2);
  P << 15, 20, 15, -20, -15, -20, -15, 20;
  return polygon(P);
}

TEST(AreaVectors, RectangleMatchesThePaper) {
  // Paper: S_i = 7 (+-4, +-3), |S_i| = 35, for corners (+-15, +-20).
  const Surface s = paper_rectangle();
  const VertexAreaVectors areas = vertex_area_vectors(s.V, s.F);
  Eigen::MatrixXd expected(4, 2);
  expected << 28, 21, 28, -21, -28, -21, -28, 21;
  EXPECT_NEAR((areas.S - expected).cwiseAbs().maxCoeff(), 0.0, 1e-12);
  for (int i = 0; i < 4; ++i) EXPECT_NEAR(areas.magnitude[i], 35.0, 1e-12);
  EXPECT_NEAR(areas.surface_area, 140.0, 1e-12);
  EXPECT_NEAR(areas.C, 140.0 / (4 * 50.0), 1e-15);  // |sum of the two edge normals| = 50
}

struct Table1Row {
  const char* name;
  Surface surface;
  double area;  // the paper's Table 1, 5 or 6 significant figures
  double tolerance;
};

TEST(AreaVectors, PaperTable1) {
  const Table1Row rows[] = {
      {"octahedron", octahedron(1.0), 6.92820, 5e-6},
      {"icosahedron", icosahedron(1.0), 9.57454, 5e-6},
      {"icosphere 642", icosphere(3, 1.0), 12.5065, 5e-5},
  };
  for (const Table1Row& row : rows) {
    SCOPED_TRACE(row.name);
    const VertexAreaVectors areas = vertex_area_vectors(row.surface.V, row.surface.F);
    EXPECT_NEAR(areas.surface_area, row.area, row.tolerance);
    EXPECT_NEAR(areas.magnitude.sum(), row.area, row.tolerance);
  }
  EXPECT_EQ(icosphere(3).num_vertices(), 642);
  EXPECT_EQ(icosphere(3).num_faces(), 1280);
  EXPECT_NEAR(surface_area(octahedron(1.0).V, octahedron(1.0).F), 4 * std::sqrt(3.0), 1e-12);
}

TEST(AreaVectors, VertexAreasSumToTheSurfaceAreaOnEverySharedMesh) {
  for (const char* name :
       {"cube.obj", "icosahedron.obj", "liver.obj", "sphere_02b.obj", "torus.obj", "Bunny.stl"}) {
    SCOPED_TRACE(name);
    const Surface s = read_surface(testing::data_mesh(name)).surface;
    const VertexAreaVectors areas = vertex_area_vectors(s.V, s.F);
    EXPECT_NEAR(areas.magnitude.sum(), surface_area(s.V, s.F), 1e-10 * areas.surface_area);
    // A closed surface's area vectors cancel.
    EXPECT_LT(face_area_vectors(s.V, s.F).colwise().sum().norm(), 1e-10 * areas.surface_area);
  }
}

TEST(AreaVectors, EnclosedVolumeOfKnownSolids) {
  const Surface unit_cube = cube(1.0);
  EXPECT_NEAR(enclosed_volume(unit_cube.V, unit_cube.F), 1.0, 1e-14);
  const Surface b = box({0, 0, 0}, {2, 3, 4}, {2, 3, 5});
  EXPECT_NEAR(enclosed_volume(b.V, b.F), 24.0, 1e-12);
  EXPECT_NEAR(surface_area(b.V, b.F), 2 * (6 + 8 + 12), 1e-12);
  const Surface fine = icosphere(5, 1.0);
  // Inscribed in the unit sphere: a little less, within 0.1% at 5 subdivisions.
  EXPECT_LT(enclosed_volume(fine.V, fine.F), 4.0 / 3.0 * M_PI);
  EXPECT_GT(enclosed_volume(fine.V, fine.F), 0.999 * 4.0 / 3.0 * M_PI);
  const Surface rect = paper_rectangle();
  EXPECT_NEAR(enclosed_volume(rect.V, rect.F), 1200.0, 1e-12);
}

// The model relies on S_i = dim * C * grad_i(volume) (model.md section 2).
void expect_volume_gradient(const Surface& s, double perturbation) {
  std::mt19937 random(7);
  std::uniform_real_distribution<double> noise(-perturbation, perturbation);
  Eigen::MatrixXd V = s.V;
  for (Eigen::Index k = 0; k < V.size(); ++k) V.data()[k] += noise(random);
  const Eigen::MatrixXd gradient = summed_face_area_vectors(V, s.F) / s.dim;
  const double h = 1e-6;
  for (int i = 0; i < V.rows(); i += 3) {
    for (int a = 0; a < s.dim; ++a) {
      Eigen::MatrixXd plus = V, minus = V;
      plus(i, a) += h;
      minus(i, a) -= h;
      const double fd = (enclosed_volume(plus, s.F) - enclosed_volume(minus, s.F)) / (2 * h);
      EXPECT_NEAR(gradient(i, a), fd, 1e-8) << "vertex " << i << " axis " << a;
    }
  }
}

TEST(AreaVectors, SummedAreaVectorsAreDimTimesTheVolumeGradient) {
  expect_volume_gradient(icosphere(2, 1.0), 0.05);
  expect_volume_gradient(read_surface(testing::data_mesh("liver.obj")).surface, 0.01);
  expect_volume_gradient(rectangle({0, 0}, {3, 2}, 3, 2), 0.05);
}

}  // namespace
}  // namespace fiberfluid::geom

// SPDX-License-Identifier: GPL-3.0-or-later
#include "fiberfluid/geom/generators.hpp"

#include <cmath>

#include <gtest/gtest.h>

#include "fiberfluid/geom/area_vectors.hpp"
#include "fiberfluid/geom/fiber_pruning.hpp"
#include "fiberfluid/geom/mesh_check.hpp"
#include "fiberfluid/util/error.hpp"

namespace fiberfluid::geom {
namespace {

void expect_closed_outward(const Surface& s, int genus = 0) {
  const MeshReport r = inspect(s);
  EXPECT_TRUE(r.ok()) << (r.problems.empty() ? "" : r.problems.front());
  EXPECT_TRUE(r.closed && r.manifold && r.consistently_oriented && r.outward);
  if (s.dim == 3) {
    EXPECT_EQ(r.genus, genus);
  }
}

TEST(Generators, EverySolidIsClosedAndOutward) {
  expect_closed_outward(tetrahedron());
  expect_closed_outward(octahedron());
  expect_closed_outward(icosahedron());
  for (int s = 0; s <= 4; ++s) expect_closed_outward(icosphere(s, 2.0));
  expect_closed_outward(cube());
  expect_closed_outward(box({-1, 0, 2}, {1, 0.5, 3}, {4, 2, 3}));
  expect_closed_outward(dome({0.07, 0.07, 0.06}, 2));
  expect_closed_outward(cylinder(0.02, 0.18, 18, 16));
  expect_closed_outward(cylinder(1.0, 0.5, 1, 3, 1));
  expect_closed_outward(rectangle({0, 0}, {1, 1}, 4, 3));
}

TEST(Generators, Counts) {
  EXPECT_EQ(icosphere(2).num_vertices(), 162);  // the paper's sphere
  EXPECT_EQ(icosphere(2).num_faces(), 320);
  EXPECT_EQ(icosphere(6).num_vertices(), 40962);
  const Surface b = box({0, 0, 0}, {1, 1, 1}, {2, 3, 4});
  // Surface lattice points: all minus interior ones; faces: 2 per square.
  EXPECT_EQ(b.num_vertices(), 3 * 4 * 5 - 1 * 2 * 3);
  EXPECT_EQ(b.num_faces(), 4 * (2 * 3 + 3 * 4 + 2 * 4));
  EXPECT_EQ(rectangle({0, 0}, {1, 1}, 4, 3).num_vertices(), 14);
}

TEST(Generators, ACylindersVolumeAndCountsAreThePrismsInItsCircle) {
  const int along = 10, around = 24, rings = 4;
  const Surface c = cylinder(0.02, 0.18, along, around, rings);
  // The wall's rings, each cap's inner rings and centre.
  EXPECT_EQ(c.num_vertices(), (along + 1) * around + 2 * ((rings - 1) * around + 1));
  // The inscribed 24-gon's area times the length: 12 r^2 sin(2 pi / 24) L.
  const double polygon_area = 0.5 * around * 0.02 * 0.02 * std::sin(2.0 * M_PI / around);
  EXPECT_NEAR(enclosed_volume(c.V, c.F), polygon_area * 0.18, 1e-15);
  EXPECT_NEAR(c.V.col(0).minCoeff(), 0.0, 0.0);
  EXPECT_NEAR(c.V.col(0).maxCoeff(), 0.18, 1e-15);
}

// A cylinder is convex whatever its segments: its far cap and its last
// wall ring share their plane to the bit (0.03 * 9 / 9 is not 0.03, and that
// ulp made the patch test's 9 x 39 cylinder concave, 8,249 fibers pruned).
TEST(Generators, ACylinderIsConvexAtEverySegmentCount) {
  for (const double length : {0.03, 0.18, 0.1, 0.7})
    for (int along = 1; along <= 40; ++along) {
      const Surface c = cylinder(0.025, length, along, 12);
      EXPECT_EQ(c.V.col(0).maxCoeff(), length) << length << " " << along;
      EXPECT_TRUE(is_convex(c)) << length << " " << along;
    }
}

TEST(Generators, VerticesLieOnTheCircumsphere) {
  for (const Surface& s : {tetrahedron(2.5), octahedron(2.5), icosahedron(2.5), icosphere(3, 2.5)})
    EXPECT_NEAR((s.V.rowwise().norm().array() - 2.5).abs().maxCoeff(), 0.0, 1e-12);
}

// The octahedron's dome puts its rim on a loop of edges: every vertex on the
// wall's ellipse is a rim vertex, no face slants between the wall and the
// shell, and the body is convex (the icosahedron's rim zig-zags and is not).
TEST(Generators, OctahedralDomeHasItsRimOnALoopOfEdges) {
  const double a = 0.07, b = 0.05, c = 0.06;
  for (int subdivisions : {0, 1, 3}) {
    const Surface s = dome({a, b, c}, subdivisions, DomeBase::Octahedron);
    expect_closed_outward(s);
    const int twos = 1 << subdivisions;
    EXPECT_EQ(s.num_vertices(), 4 * twos * twos + 2);
    auto on_rim = [&](int v) {
      const double x = s.V(v, 0) / a, y = s.V(v, 1) / b;
      return s.V(v, 2) == 0.0 && std::abs(x * x + y * y - 1.0) < 1e-12;
    };
    int rim = 0;
    for (int v = 0; v < s.num_vertices(); ++v) rim += on_rim(v);
    EXPECT_EQ(rim, 4 * twos);
    for (int f = 0; f < s.num_faces(); ++f) {
      int on_wall = 0, rim_corners = 0;
      for (int k = 0; k < 3; ++k) {
        on_wall += s.V(s.F(f, k), 2) == 0.0;
        rim_corners += on_rim(s.F(f, k));
      }
      // A face touches the wall only along the rim, or lies in it.
      EXPECT_TRUE(on_wall == 3 || on_wall == rim_corners) << "face " << f;
    }
    EXPECT_TRUE(is_convex(s)) << subdivisions << " subdivisions";
  }
  EXPECT_FALSE(is_convex(dome({a, b, c}, 3)));  // the icosahedron's zig-zag rim
}

TEST(Generators, DomeHasAFlatOutwardChestWall) {
  const Surface s = dome({0.07, 0.07, 0.06}, 2);
  const Eigen::MatrixXd A = face_area_vectors(s.V, s.F);
  int wall_faces = 0;
  for (int f = 0; f < s.num_faces(); ++f) {
    const bool on_wall = s.V(s.F(f, 0), 2) == 0 && s.V(s.F(f, 1), 2) == 0 && s.V(s.F(f, 2), 2) == 0;
    if (!on_wall) continue;
    ++wall_faces;
    EXPECT_LT(A(f, 2), 0.0) << "wall face " << f << " must point down, out of the body";
    EXPECT_NEAR(A.row(f).head<2>().norm(), 0.0, 1e-15);
  }
  EXPECT_GT(wall_faces, 40);
  EXPECT_NEAR(s.V.col(2).maxCoeff(), 0.06, 1e-12);
  EXPECT_GE(s.V.col(2).minCoeff(), 0.0);
  // Close to half an ellipsoid: 2/3 pi a b c, within the faceting error.
  EXPECT_NEAR(enclosed_volume(s.V, s.F), 2.0 / 3.0 * M_PI * 0.07 * 0.07 * 0.06, 0.05 * 6.2e-4);
}

TEST(Generators, PolygonIsOrientedCounterClockwiseWhateverTheInputOrder) {
  Eigen::MatrixXd clockwise(4, 2);
  clockwise << 15, 20, 15, -20, -15, -20, -15, 20;
  const Surface s = polygon(clockwise);
  EXPECT_EQ(s.V, clockwise);  // vertex order kept
  EXPECT_NEAR(enclosed_volume(s.V, s.F), 1200.0, 1e-12);
  expect_closed_outward(s);
}

TEST(Generators, RejectBadParameters) {
  EXPECT_THROW(icosphere(-1), InputError);
  EXPECT_THROW(icosphere(2, 0.0), InputError);
  EXPECT_THROW(box({0, 0, 0}, {1, 0, 1}), InputError);
  EXPECT_THROW(rectangle({0, 0}, {1, 1}, 0, 1), InputError);
  EXPECT_THROW(polygon(Eigen::MatrixXd::Zero(2, 2)), InputError);
  EXPECT_THROW(cylinder(0.02, 0.18, 4, 2), InputError);
  EXPECT_THROW(cylinder(0.02, -1.0, 4, 8), InputError);
}

}  // namespace
}  // namespace fiberfluid::geom

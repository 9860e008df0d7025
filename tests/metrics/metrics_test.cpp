// SPDX-License-Identifier: GPL-3.0-or-later
// The benchmarks paper's metrics on cases with known answers.
#include "fiberfluid/metrics/metrics.hpp"

#include <gtest/gtest.h>

#include <cmath>

#include "fiberfluid/geom/area_vectors.hpp"
#include "fiberfluid/geom/generators.hpp"
#include "fiberfluid/util/error.hpp"

namespace fiberfluid::metrics {
namespace {

geom::Surface translated(geom::Surface s, const Eigen::RowVectorXd& by) {
  s.V.rowwise() += by;
  return s;
}

TEST(SurfaceError, TwoUnitSquaresOffsetByATenth) {
  const geom::Surface square = geom::rectangle({0.0, 0.0}, {1.0, 1.0}, 3, 2);
  const geom::Surface moved = translated(square, Eigen::RowVector2d(0.1, 0.0));
  EXPECT_NEAR(symmetric_difference_measure(square, moved), 0.2, 1e-15);
  EXPECT_NEAR(surface_error(square, moved), 0.2, 1e-15);
  // Diagonally: the overlap is 0.9 x 0.8.
  const geom::Surface diagonal = translated(square, Eigen::RowVector2d(0.1, 0.2));
  EXPECT_NEAR(surface_error(square, diagonal), 2.0 - 2.0 * 0.72, 1e-15);
  EXPECT_EQ(surface_error(square, square), 0.0);
}

TEST(SurfaceError, CubesAgainstThemselvesAndTranslated) {
  const geom::Surface cube = geom::box({0, 0, 0}, {1, 1, 1}, {2, 3, 1});
  EXPECT_EQ(surface_error(cube, cube), 0.0);
  EXPECT_NEAR(surface_error(cube, translated(cube, Eigen::RowVector3d(0.1, 0.0, 0.0))), 0.2, 1e-14);
  // Overlap 0.9 x 0.8 x 0.7 = 0.504: |xor| = 2 - 1.008.
  EXPECT_NEAR(surface_error(cube, translated(cube, Eigen::RowVector3d(0.1, -0.2, 0.3))), 0.992,
              1e-14);
  // Apart: everything differs.
  EXPECT_NEAR(surface_error(cube, translated(cube, Eigen::RowVector3d(2.0, 0.0, 0.0))), 2.0, 1e-14);
}

TEST(SurfaceError, NestedPolyhedraDifferByTheirVolumes) {
  // A sphere and the same mesh scaled by 0.9 about its centre: nested, so
  // |xor| = |big| - |small| = (1 - 0.729) |big|.
  const geom::Surface big = geom::icosphere(2, 1.0);
  geom::Surface small = big;
  small.V *= 0.9;
  EXPECT_NEAR(surface_error(big, small), 1.0 - 0.729, 1e-12);
  // And the 2D analogue with a rotated square inside a square.
  Eigen::MatrixXd diamond(4, 2);
  diamond << 0.5, 0.0, 1.0, 0.5, 0.5, 1.0, 0.0, 0.5;
  EXPECT_NEAR(surface_error(geom::rectangle({0, 0}, {1, 1}), geom::polygon(diamond)), 0.5, 1e-15);
}

TEST(SurfaceError, SurfacesThatBoundNoSolidAreNamed) {
  geom::Surface open = geom::cube();
  open.F.conservativeResize(open.F.rows() - 1, 3);
  try {
    symmetric_difference_measure(geom::cube(), open, "reference.obj", "scan.obj");
    ADD_FAILURE() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("scan.obj: the mesh is not closed"), std::string::npos)
        << e.what();
  }
  Eigen::MatrixXd bow(4, 2);  // a bow tie crosses itself
  bow << 0, 0, 1, 1, 1, 0, 0, 1;
  geom::Surface tie;
  tie.dim = 2;
  tie.V = bow;
  tie.F.resize(4, 2);
  tie.F << 0, 1, 1, 2, 2, 3, 3, 0;
  EXPECT_THROW(symmetric_difference_measure(geom::rectangle({0, 0}, {1, 1}), tie), InputError);
  geom::Surface nan = geom::cube();
  nan.V(0, 0) = NAN;
  EXPECT_THROW(surface_error(geom::cube(), nan), InputError);
  EXPECT_THROW(symmetric_difference_measure(geom::cube(), geom::rectangle({0, 0}, {1, 1})),
               InputError);
}

// One file, two shells: a box with a box inside it. Oriented both outward, they
// bound no solid (the inner shell would have to face inward to be a cavity), and
// the Booleans' results on such a mesh are undefined: refused by name. Oriented
// as a cavity, the solid is the shell between them.
geom::Surface two_shells(bool inner_faces_inward) {
  const geom::Surface outer = geom::box({0, 0, 0}, {1, 1, 1}, {1, 1, 1});
  geom::Surface inner = geom::box({0.25, 0.25, 0.25}, {0.75, 0.75, 0.75}, {1, 1, 1});
  if (inner_faces_inward) inner.F.col(1).swap(inner.F.col(2));
  geom::Surface both = outer;
  both.V.resize(outer.V.rows() + inner.V.rows(), 3);
  both.V << outer.V, inner.V;
  both.F.resize(outer.F.rows() + inner.F.rows(), 3);
  both.F << outer.F, (inner.F.array() + static_cast<int>(outer.V.rows())).matrix();
  return both;
}

TEST(SurfaceError, TwoShellsBoundASolidOnlyWhenTheInnerOneIsACavity) {
  const geom::Surface unit = geom::box({0, 0, 0}, {1, 1, 1}, {1, 1, 1});
  try {
    symmetric_difference_measure(unit, two_shells(false), "unit", "shells.obj");
    ADD_FAILURE() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("shells.obj: the mesh bounds no volume"),
              std::string::npos)
        << e.what();
  }
  // The cavity is 0.5^3: the unit cube and the hollow one differ by it.
  const geom::Surface hollow = two_shells(true);
  EXPECT_NEAR(symmetric_difference_measure(unit, hollow, "unit", "hollow.obj"), 0.125, 1e-14);
  EXPECT_NEAR(symmetric_difference_measure(hollow, unit, "hollow.obj", "unit"), 0.125, 1e-14);
}

// Vertices in no face (a file's unused points) take no part in the solid:
// far away they would move the volume sums' centre and cost their digits,
// and CGAL's volume predicates fail on them.
TEST(SurfaceError, VerticesInNoFaceAreLeftOut) {
  geom::Surface cube = geom::box({0, 0, 0}, {1, 1, 1}, {2, 2, 2});
  const geom::Surface moved = translated(cube, Eigen::RowVector3d(0.1, 0.0, 0.0));
  cube.V.conservativeResize(cube.V.rows() + 2, 3);
  cube.V.row(cube.V.rows() - 2) << 1e12, -1e12, 3e11;
  cube.V.row(cube.V.rows() - 1) << 0.5, 0.5, 0.5;
  EXPECT_NEAR(surface_error(cube, moved), 0.2, 1e-12);
  EXPECT_NEAR(surface_error(moved, cube), 0.2, 1e-12);
}

TEST(EnergyNorm, HandMadeCases) {
  Eigen::MatrixXd u(2, 2), v(2, 2);
  u << 1, 0, 0, 1;
  v << 1, 0, 0, 0;
  EXPECT_NEAR(relative_energy_norm(u, v), 1.0 / std::sqrt(2.0), 1e-15);
  EXPECT_EQ(relative_energy_norm(u, u), 0.0);
  EXPECT_NEAR(relative_energy_norm(u, 2.0 * u), 1.0, 1e-15);
  EXPECT_THROW(relative_energy_norm(Eigen::MatrixXd::Zero(2, 2), v), InputError);
  EXPECT_THROW(relative_energy_norm(u, Eigen::MatrixXd::Zero(3, 2)), InputError);
}

// Issue 30: volumes summed about the origin cancel for a body far from it
// (a unit cube at 1e8 and the same moved by 0.5 gave E_s = -0.375).
TEST(SurfaceError, ABodyFarFromTheOriginKeepsItsDigits) {
  const Eigen::RowVector3d far(1e8, 1e8, 1e8);
  const geom::Surface cube = translated(geom::box({0, 0, 0}, {1, 1, 1}, {1, 1, 1}), far);
  EXPECT_NEAR(geom::enclosed_volume(cube.V, cube.F), 1.0, 1e-8);
  EXPECT_NEAR(surface_error(cube, translated(cube, Eigen::RowVector3d(0.5, 0.0, 0.0))), 1.0, 1e-8);
  // Moved by 0.5 along each axis: overlap 0.125, |xor| = 2 - 0.25.
  EXPECT_NEAR(surface_error(cube, translated(cube, Eigen::RowVector3d(0.5, 0.5, 0.5))), 1.75, 1e-8);
  // The same in 2D (exact areas there, but the same rule for the inputs).
  const geom::Surface square =
      translated(geom::rectangle({0, 0}, {1, 1}, 1, 1), Eigen::RowVector2d(1e8, 1e8));
  EXPECT_NEAR(surface_error(square, translated(square, Eigen::RowVector2d(0.5, 0.5))), 1.5, 1e-8);
}

// Issue 27: a coordinate of 1e301 reached undefined behaviour inside CGAL's
// Booleans; inputs beyond what the exact kernel and doubles carry are refused.
TEST(SurfaceError, CoordinatesTheExactBooleansCannotCarryAreRefusedByName) {
  auto expect_refused = [](const geom::Surface& a, const geom::Surface& b,
                           const std::string& part) {
    try {
      surface_error(a, b, "m.obj", "m_prime.obj");
      ADD_FAILURE() << "no error, expected one mentioning " << part;
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(part), std::string::npos) << e.what();
    }
  };
  const geom::Surface square = geom::rectangle({0, 0}, {1, 1}, 1, 1);
  geom::Surface huge = square;
  huge.V(2, 0) = 1e301;
  expect_refused(square, huge, "m_prime.obj: vertex 2 has x = ");
  geom::Surface cube = geom::box({0, 0, 0}, {1, 1, 1}, {1, 1, 1});
  geom::Surface far_cube = translated(cube, Eigen::RowVector3d(1e60, 0, 0));
  expect_refused(cube, far_cube, "magnitude at most 1e50");
  // A micrometre body at 1e12 m: its shape has no digits left.
  geom::Surface speck = cube;
  speck.V *= 1e-6;
  speck.V.rowwise() += Eigen::RowVector3d(1e12, 0, 0);
  expect_refused(speck, speck, "too small for its distance from the origin");
}

TEST(InteriorError, WeightedDisplacementErrorOverTheBodysScale) {
  // Two nodes weighted 0.25 and 0.75 of a unit square's area; errors 1 and 2.
  Eigen::MatrixXd p = Eigen::MatrixXd::Zero(2, 2), q(2, 2);
  q << 1, 0, 0, 2;
  EXPECT_NEAR(interior_error(p, q, Eigen::Vector2d(0.25, 0.75), 1.0, 2), 1.75, 1e-15);
  // A body of volume 8 in 3D: divided by 8^(1/3) = 2.
  Eigen::MatrixXd r = Eigen::MatrixXd::Zero(1, 3), s(1, 3);
  s << 3, 4, 0;
  EXPECT_NEAR(interior_error(r, s, Eigen::VectorXd::Constant(1, 8.0), 8.0, 3), 20.0, 1e-14);
  // A rigid translation by t of a surface-only model: E_i = t sum|S_i| / V^(1/3).
  const geom::Surface cube = geom::box({0, 0, 0}, {2, 2, 2}, {2, 2, 2});
  const Eigen::VectorXd w = boundary_node_measures(cube);
  ASSERT_EQ(w.size(), cube.num_vertices());
  EXPECT_GT(w.minCoeff(), 0.0);
  const Eigen::MatrixXd moved = translated(cube, Eigen::RowVector3d(0.0, 0.0, 0.1)).V;
  EXPECT_NEAR(interior_error(cube.V, moved, w, 8.0, 3), 0.1 * w.sum() / 2.0, 1e-14);
  EXPECT_THROW(interior_error(p, q, Eigen::Vector3d(1, 1, 1), 1.0, 2), InputError);
}

}  // namespace
}  // namespace fiberfluid::metrics

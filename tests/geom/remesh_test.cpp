// SPDX-License-Identifier: GPL-3.0-or-later
// Isotropic remeshing to a vertex count: near the count, the same shape, a
// usable closed surface, the same mesh every time.
#include <gtest/gtest.h>

#include "fiberfluid/geom/area_vectors.hpp"
#include "fiberfluid/geom/generators.hpp"
#include "fiberfluid/geom/mesh_check.hpp"
#include "fiberfluid/geom/remesh.hpp"
#include "fiberfluid/util/error.hpp"

namespace fiberfluid::geom {
namespace {

TEST(Remesh, ReachesTheCountOnTheSameShape) {
  const Surface sphere = icosphere(4, 1.0);  // 2,562 vertices
  for (int asked : {300, 1000}) {
    const Surface s = remesh_to_vertices(sphere, asked);
    EXPECT_NEAR(s.num_vertices(), asked, 0.03 * asked);
    const MeshReport report = inspect(s);
    EXPECT_TRUE(report.ok()) << format_report(report, "remeshed");
    // Closed genus 0: F = 2 V - 4. On the unit sphere, every vertex.
    EXPECT_EQ(s.num_faces(), 2 * s.num_vertices() - 4);
    EXPECT_LT((s.V.rowwise().norm().array() - 1.0).abs().maxCoeff(), 1e-2) << asked;
    const double volume = enclosed_volume(s.V, s.F), ball = 4.0 / 3.0 * M_PI;
    // Outward, and about the ball's: an inscribed polyhedron of 300 vertices has 2.1% less.
    EXPECT_NEAR(volume / ball, 1.0, 0.03) << asked;
    // Isotropic: edges within a factor of about two of each other.
    double shortest = 1e300, longest = 0.0;
    for (int f = 0; f < s.num_faces(); ++f)
      for (int c = 0; c < 3; ++c) {
        const double edge = (s.V.row(s.F(f, c)) - s.V.row(s.F(f, (c + 1) % 3))).norm();
        shortest = std::min(shortest, edge);
        longest = std::max(longest, edge);
      }
    EXPECT_LT(longest / shortest, 3.0) << asked;
  }
}

TEST(Remesh, IsDeterministicAndLeavesUnusedVerticesOut) {
  Surface s = icosphere(2, 2.0);
  const Eigen::Index used = s.V.rows();
  s.V.conservativeResize(used + 1, 3);
  s.V.row(used) << 5.0, 5.0, 5.0;  // referenced by no face
  const Surface a = remesh_to_vertices(s, 200), b = remesh_to_vertices(s, 200);
  EXPECT_TRUE(a.V == b.V);
  EXPECT_TRUE(a.F == b.F);
  EXPECT_LT(a.V.cwiseAbs().maxCoeff(), 2.0 + 1e-9);
}

TEST(Remesh, RefusesWhatItCannotRemesh) {
  EXPECT_THROW(remesh_to_vertices(rectangle({0.0, 0.0}, {1.0, 1.0}, 2, 2), 100), InputError);
  EXPECT_THROW(remesh_to_vertices(icosphere(1, 1.0), 3), InputError);
}

}  // namespace
}  // namespace fiberfluid::geom

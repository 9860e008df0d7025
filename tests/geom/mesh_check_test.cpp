// SPDX-License-Identifier: GPL-3.0-or-later
#include "fiberfluid/geom/mesh_check.hpp"

#include <gtest/gtest.h>

#include <limits>

#include "fiberfluid/geom/generators.hpp"
#include "fiberfluid/geom/mesh_io.hpp"
#include "fiberfluid/util/error.hpp"
#include "test_support.hpp"

namespace fiberfluid::geom {
namespace {

void expect_problem(const Surface& s, const std::string& part) {
  const MeshReport r = inspect(s);
  ASSERT_FALSE(r.ok()) << "expected a problem mentioning '" << part << "'";
  EXPECT_NE(r.problems.front().find(part), std::string::npos) << r.problems.front();
  try {
    require_usable(r, "mesh.obj");
    ADD_FAILURE() << "require_usable did not throw";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()).rfind("mesh.obj: ", 0), 0u) << e.what();
  }
}

Surface drop_last_face(Surface s) {
  s.F.conservativeResize(s.F.rows() - 1, 3);
  return s;
}

TEST(MeshCheck, GoodMeshes) {
  const MeshReport r = inspect(read_surface(testing::data_mesh("torus.obj")).surface);
  EXPECT_TRUE(r.ok());
  EXPECT_EQ(r.genus, 1);
  EXPECT_EQ(r.euler_characteristic, 0);
  EXPECT_EQ(r.components, 1);
  EXPECT_NE(format_report(r, "torus.obj").find("genus:         1"), std::string::npos);
}

TEST(MeshCheck, EachBadMeshHasItsOwnMessage) {
  expect_problem(drop_last_face(cube()), "not closed");

  // Closed, manifold, consistently oriented and outward, but one vertex
  // pushed through the far side: its triangles cross others (found from
  // outside, issue 11: it passed the check).
  Surface through = icosphere(1);
  through.V.row(0) *= -1.6;
  expect_problem(through, "the surface intersects itself: triangles");
  // A bow tie: the polygon's segments cross.
  Surface bow_tie;
  bow_tie.dim = 2;
  bow_tie.V.resize(4, 2);
  bow_tie.V << 0, 0, 2, 0, 0, 1, 2, 1;
  bow_tie.F.resize(4, 2);
  bow_tie.F << 0, 1, 1, 2, 2, 3, 3, 0;
  expect_problem(bow_tie, "the surface intersects itself: segments");

  Surface fin = cube();  // a third face on an existing edge
  fin.V.conservativeResize(9, 3);
  fin.V.row(8) << 0, 0, 3;
  fin.F.conservativeResize(13, 3);
  fin.F.row(12) << fin.F(0, 0), fin.F(0, 1), 8;
  expect_problem(fin, "not a 2-manifold: edge");

  Surface flipped_one = icosphere(1);
  std::swap(flipped_one.F(3, 0), flipped_one.F(3, 1));
  expect_problem(flipped_one, "inconsistent orientation");

  Surface inverted = icosphere(1);
  flip_orientation(inverted);
  expect_problem(inverted, "inverted");

  Surface repeated = icosahedron();
  repeated.F(0, 2) = repeated.F(0, 1);
  expect_problem(repeated, "face 0 is degenerate (a repeated vertex)");

  Surface flat = box({0, 0, 0}, {1, 1, 1}, {2, 1, 1});  // collapse a face onto a line
  flat.V.row(flat.F(0, 2)) =
      flat.V.row(flat.F(0, 0)) + 0.5 * (flat.V.row(flat.F(0, 1)) - flat.V.row(flat.F(0, 0)));
  expect_problem(flat, "degenerate (zero area)");

  Surface nan = icosahedron();
  nan.V(5, 1) = std::numeric_limits<double>::quiet_NaN();
  expect_problem(nan, "vertex 5 has a non-finite coordinate");

  Surface out_of_range = icosahedron();
  out_of_range.F(2, 1) = 40;
  expect_problem(out_of_range, "face 2 refers to vertex 40");

  expect_problem(Surface{}, "no faces");

  // Two tetrahedra sharing one vertex: every edge is fine, the vertex is not.
  Surface bowtie;
  const Surface t = tetrahedron();
  bowtie.V.resize(7, 3);
  bowtie.V.topRows(4) = t.V;
  bowtie.V.bottomRows(3) = t.V.bottomRows(3).rowwise() + Eigen::RowVector3d(0, 0, -5);
  bowtie.V.row(0) = Eigen::RowVector3d(0.0, 0.0, -1.0);  // shared apex between both
  bowtie.F.resize(8, 3);
  bowtie.F.topRows(4) = t.F;
  Eigen::MatrixXi second = t.F;
  for (int f = 0; f < 4; ++f)
    for (int c = 0; c < 3; ++c)
      if (second(f, c) > 0) second(f, c) += 3;
  bowtie.F.bottomRows(4) = second;
  const MeshReport r = inspect(bowtie);
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.problems.front().find("vertex 0 form more than one fan"), std::string::npos)
      << r.problems.front();
}

TEST(MeshCheck, PolygonProblems) {
  Surface open = rectangle({0, 0}, {1, 1});
  open.F.conservativeResize(3, 2);
  expect_problem(open, "not closed");
  Surface turned = rectangle({0, 0}, {1, 1});
  std::swap(turned.F(1, 0), turned.F(1, 1));
  expect_problem(turned, "inconsistent orientation");
  Surface inward = rectangle({0, 0}, {1, 1});
  flip_orientation(inward);
  expect_problem(inward, "inverted");
}

TEST(MeshCheck, UnusedVerticesAreAWarningNotAnError) {
  const MeshReport r = inspect(read_surface(testing::data_mesh("liver.obj")).surface);
  EXPECT_TRUE(r.ok());
  ASSERT_EQ(r.warnings.size(), 1u);
  EXPECT_NE(r.warnings[0].find("42 vertices"), std::string::npos);
}

}  // namespace
}  // namespace fiberfluid::geom

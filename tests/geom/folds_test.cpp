// SPDX-License-Identifier: GPL-3.0-or-later
#include "fiberfluid/geom/folds.hpp"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>

#include "fiberfluid/geom/area_vectors.hpp"
#include "fiberfluid/geom/generators.hpp"

namespace fiberfluid::geom {
namespace {

Surface rotated(Surface s, double degrees, const Eigen::Vector3d& axis) {
  const Eigen::Matrix3d R =
      Eigen::AngleAxisd(degrees * M_PI / 180.0, axis.normalized()).toRotationMatrix();
  s.V = s.V * R.transpose();
  return s;
}

int reversed_faces(const Surface& now, const Eigen::MatrixXd& before) {
  const Eigen::MatrixXd after = face_area_vectors(now.V, now.F);
  int n = 0;
  for (int f = 0; f < now.num_faces(); ++f) n += after.row(f).dot(before.row(f)) <= 0.0;
  return n;
}

// A clamped phantom's end swings round past a right angle within one load
// step: most of its faces reverse, and none folded.
TEST(Folds, ABodyRotatedFarIsNotAFold) {
  const Surface rod = cylinder(0.02, 0.15, 52, 24);
  const Eigen::MatrixXd before = face_area_vectors(rod.V, rod.F);
  for (const double degrees : {120.0, 180.0}) {
    const Surface now = rotated(rod, degrees, {0.3, 1.0, 0.2});
    ASSERT_GT(reversed_faces(now, before), rod.num_faces() / 4) << degrees;
    EXPECT_FALSE(find_fold(now, before).has_value()) << degrees;
  }
}

// A vertex slid across the far edge of one of its faces turns that face
// over onto its neighbour: a fold, found whatever the body's rotation.
TEST(Folds, AFaceSlidOverItsNeighbourIsAFold) {
  const Surface sphere = icosphere(3);
  const Eigen::MatrixXd before = face_area_vectors(sphere.V, sphere.F);
  const int f = 7, v = sphere.F(f, 0), a = sphere.F(f, 1), b = sphere.F(f, 2);
  for (const double degrees : {0.0, 150.0}) {
    Surface now = sphere;
    now.V.row(v) = sphere.V.row(a) + sphere.V.row(b) - sphere.V.row(v);
    now = rotated(now, degrees, {1.0, 0.0, 0.0});
    const auto fold = find_fold(now, before);
    ASSERT_TRUE(fold.has_value()) << degrees;
    const Eigen::MatrixXd after = face_area_vectors(now.V, now.F);
    EXPECT_LE(after.row(fold->face).dot(before.row(fold->face)), 0.0)
        << "the face named reversed";
    EXPECT_FALSE(fold->crossing.has_value()) << degrees;
  }
}

// Turned over as a whole (a rotation) while one vertex is pulled through
// the far side: no face folded against its neighbours, but the surface
// crosses itself.
TEST(Folds, ASurfaceThatCrossesItselfIsAFoldNamingTheCrossingFaces) {
  Surface sphere = icosphere(3);
  const Eigen::MatrixXd before = face_area_vectors(sphere.V, sphere.F);
  Surface now = rotated(sphere, 180.0, {1.0, 0.0, 0.0});
  Eigen::Index lowest = 0;
  now.V.col(2).minCoeff(&lowest);
  now.V.row(lowest) << 0.0, 0.0, 1.5;  // through the top
  const auto fold = find_fold(now, before);
  ASSERT_TRUE(fold.has_value());
  ASSERT_TRUE(fold->crossing.has_value());
  EXPECT_NE(fold->crossing->first, fold->crossing->second);
  EXPECT_FALSE(find_fold(rotated(sphere, 180.0, {1.0, 0.0, 0.0}), before).has_value());
}

// The 2D outlines have the same check (neighbours share a vertex).
TEST(Folds, AnOutlineRotatedIsNotAFoldAndOneFoldedIs) {
  Eigen::MatrixXd P(8, 2);
  for (int k = 0; k < 8; ++k) P.row(k) << std::cos(k * M_PI / 4), std::sin(k * M_PI / 4);
  const Surface ring = polygon(P);
  const Eigen::MatrixXd before = face_area_vectors(ring.V, ring.F);
  Surface turned = ring;
  turned.V = -ring.V;  // 180 degrees
  EXPECT_FALSE(find_fold(turned, before).has_value());
  Surface folded = ring;
  folded.V.row(0) << -1.3, 0.1;  // through the middle and out past the far side
  EXPECT_TRUE(find_fold(folded, before).has_value());
}

}  // namespace
}  // namespace fiberfluid::geom

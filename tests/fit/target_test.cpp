// SPDX-License-Identifier: GPL-3.0-or-later
#include "fiberfluid/fit/target.hpp"

#include <gtest/gtest.h>

#include <random>

#include "fiberfluid/geom/generators.hpp"
#include "fiberfluid/util/error.hpp"
#include "test_support.hpp"

namespace fiberfluid::fit {
namespace {

// Point-to-triangle distance by brute force: the plane's foot when it lies
// inside, else the nearest point of the three edges.
double segment_distance(const Eigen::Vector3d& p, const Eigen::Vector3d& a,
                        const Eigen::Vector3d& b) {
  const double t = std::clamp((p - a).dot(b - a) / (b - a).squaredNorm(), 0.0, 1.0);
  return (p - (a + t * (b - a))).norm();
}
double triangle_distance(const Eigen::Vector3d& p, const Eigen::Vector3d& a,
                         const Eigen::Vector3d& b, const Eigen::Vector3d& c) {
  const Eigen::Vector3d n = (b - a).cross(c - a).normalized();
  const Eigen::Vector3d foot = p - n.dot(p - a) * n;
  const bool inside = (b - a).cross(foot - a).dot(n) >= 0 && (c - b).cross(foot - b).dot(n) >= 0 &&
                      (a - c).cross(foot - c).dot(n) >= 0;
  if (inside) return std::abs(n.dot(p - a));
  return std::min(
      {segment_distance(p, a, b), segment_distance(p, b, c), segment_distance(p, c, a)});
}

TEST(TargetDistance, AgreesWithBruteForceOnAnOpenNoisySoup) {
  std::mt19937 rng(7);
  std::normal_distribution<double> noise(0.0, 0.02);
  geom::Surface s = geom::icosphere(2, 1.0);
  for (Eigen::Index i = 0; i < s.V.rows(); ++i)
    for (int a = 0; a < 3; ++a) s.V(i, a) += noise(rng);
  // Open it: drop every face with a corner above z = 0.5.
  std::vector<Eigen::Vector3i> kept;
  for (Eigen::Index f = 0; f < s.F.rows(); ++f) {
    bool high = false;
    for (int k = 0; k < 3; ++k) high |= s.V(s.F(f, k), 2) > 0.5;
    if (!high) kept.push_back(s.F.row(f).transpose());
  }
  Eigen::MatrixXi F(static_cast<Eigen::Index>(kept.size()), 3);
  for (size_t f = 0; f < kept.size(); ++f)
    F.row(static_cast<Eigen::Index>(f)) = kept[f].transpose();
  const Target target = make_target("soup", s.V, F);
  EXPECT_NE(target.description.find("unused points dropped"), std::string::npos)
      << target.description;
  const TargetDistance distance(target);

  std::uniform_real_distribution<double> box(-1.5, 1.5);
  Eigen::MatrixXd queries(300, 3);
  for (Eigen::Index i = 0; i < queries.rows(); ++i) queries.row(i) << box(rng), box(rng), box(rng);
  const auto hits = distance.closest(queries);
  for (Eigen::Index i = 0; i < queries.rows(); ++i) {
    const Eigen::Vector3d p = queries.row(i).transpose();
    double brute = std::numeric_limits<double>::infinity();
    for (Eigen::Index f = 0; f < target.triangles.rows(); ++f)
      brute = std::min(brute, triangle_distance(p, target.points.row(target.triangles(f, 0)),
                                                target.points.row(target.triangles(f, 1)),
                                                target.points.row(target.triangles(f, 2))));
    EXPECT_NEAR(hits[static_cast<size_t>(i)].distance, brute, 1e-12) << i;
    EXPECT_NEAR((hits[static_cast<size_t>(i)].point - p).norm(), brute, 1e-12);
  }
}

TEST(TargetDistance, PointCloudsUseTheNearestPoint) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> box(-1.0, 1.0);
  Eigen::MatrixXd cloud(500, 3), queries(100, 3);
  for (Eigen::Index i = 0; i < cloud.rows(); ++i) cloud.row(i) << box(rng), box(rng), box(rng);
  for (Eigen::Index i = 0; i < queries.rows(); ++i) queries.row(i) << box(rng), box(rng), box(rng);
  const Target target = make_target("cloud", cloud);
  EXPECT_TRUE(target.is_point_cloud());
  EXPECT_EQ(target.description, "a point cloud of 500 points");
  const auto hits = TargetDistance(target).closest(queries);
  for (Eigen::Index i = 0; i < queries.rows(); ++i) {
    const double brute = (cloud.rowwise() - queries.row(i)).rowwise().norm().minCoeff();
    EXPECT_DOUBLE_EQ(hits[static_cast<size_t>(i)].distance, brute);
  }
}

TEST(Targets, ReadSoupsAndCloudsAndSayWhatWasRead) {
  testing::ScratchDir dir;
  // Vertices only: a point cloud.
  const Target cloud = read_target(dir.write("cloud.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\n"));
  EXPECT_TRUE(cloud.is_point_cloud());
  EXPECT_EQ(cloud.points.rows(), 3);
  // An open soup with a degenerate triangle and an unused vertex.
  const Target soup = read_target(
      dir.write("soup.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 2 2 2\nv 2 0 0\nf 1 2 3\nf 1 2 5\n"));
  EXPECT_EQ(soup.triangles.rows(), 1);
  EXPECT_EQ(soup.points.rows(), 3);
  EXPECT_NE(soup.description.find("1 degenerate triangles dropped"), std::string::npos)
      << soup.description;
  // A non-finite coordinate is named.
  try {
    read_target(dir.write("nan.obj", "v 0 0 nan\nv 1 0 0\nv 0 1 0\nf 1 2 3\n"));
    ADD_FAILURE() << "read a NaN";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find(
                  "nan.obj: vertex 0 has a coordinate that is not a finite number"),
              std::string::npos)
        << e.what();
  }
  EXPECT_THROW(read_target(dir.path() / "missing.obj"), InputError);
}

TEST(DistanceStatistics, MeanRmsDeviationAndShare) {
  const Eigen::Vector4d d(1.0, 2.0, 3.0, 4.0);
  const DistanceStatistics s = distance_statistics(d, 100.0);
  EXPECT_DOUBLE_EQ(s.mean, 2.5);
  EXPECT_DOUBLE_EQ(s.rms, std::sqrt(7.5));
  EXPECT_DOUBLE_EQ(s.standard_deviation, std::sqrt(1.25));
  EXPECT_DOUBLE_EQ(s.largest, 4.0);
  EXPECT_DOUBLE_EQ(s.share(s.standard_deviation), std::sqrt(1.25) / 100.0);
}

}  // namespace
}  // namespace fiberfluid::fit

#include "fiberfluid/fit/golden_section.hpp"

namespace fiberfluid::fit {
namespace {

TEST(GoldenSection, FindsTheMinimumOfAUnimodalFunctionAndSkipsFailures) {
  const LineMinimum m =
      golden_section_minimum([](double x) { return (x - 2.0) * (x - 2.0) + 1.0; }, 0.0, 5.0, 40);
  EXPECT_NEAR(m.x, 2.0, 1e-6);
  EXPECT_NEAR(m.value, 1.0, 1e-12);
  EXPECT_EQ(m.evaluations, 42);  // two to start, one per iteration
  // A failed evaluation (NaN) is never taken for the minimum.
  const LineMinimum guarded = golden_section_minimum(
      [](double x) { return x < 1.0 ? std::nan("") : std::abs(x - 3.0); }, 0.0, 4.0, 40);
  EXPECT_NEAR(guarded.x, 3.0, 1e-6);
  EXPECT_THROW(golden_section_minimum([](double x) { return x; }, 1.0, 1.0, 5),
               std::invalid_argument);
}

}  // namespace
}  // namespace fiberfluid::fit

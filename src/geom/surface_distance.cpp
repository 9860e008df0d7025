// SPDX-License-Identifier: GPL-3.0-or-later
// Closest points on a target: CGAL's AABB tree over triangles, or its k-d
// tree over points (CGAL kept inside this file).
#include <CGAL/AABB_traits.h>
#include <CGAL/AABB_tree.h>
#include <CGAL/AABB_triangle_primitive.h>
#include <CGAL/Orthogonal_k_neighbor_search.h>
#include <CGAL/Search_traits_3.h>
#include <CGAL/Search_traits_adapter.h>
#include <CGAL/Simple_cartesian.h>
#include <CGAL/property_map.h>

#include <boost/iterator/counting_iterator.hpp>
#include <optional>

#include "fiberfluid/geom/target.hpp"
#include "fiberfluid/util/run_control.hpp"

namespace fiberfluid::geom {
namespace {

using Kernel = CGAL::Simple_cartesian<double>;
using Point = Kernel::Point_3;
using Triangle = Kernel::Triangle_3;
using TriangleIterator = std::vector<Triangle>::const_iterator;
using Primitive = CGAL::AABB_triangle_primitive<Kernel, TriangleIterator>;
using AabbTree = CGAL::AABB_tree<CGAL::AABB_traits<Kernel, Primitive>>;

using PointMap = CGAL::Pointer_property_map<Point>::const_type;
using SearchTraits =
    CGAL::Search_traits_adapter<std::size_t, PointMap, CGAL::Search_traits_3<Kernel>>;
using NeighborSearch = CGAL::Orthogonal_k_neighbor_search<SearchTraits>;
using KdTree = NeighborSearch::Tree;

Point to_point(const Eigen::Vector3d& v) { return {v.x(), v.y(), v.z()}; }

}  // namespace

struct TargetDistance::Impl {
  Target target;
  std::vector<Point> points;
  std::vector<Triangle> triangles;
  std::optional<AabbTree> aabb;
  std::optional<KdTree> kd;

  PointMap point_map() const { return CGAL::make_property_map(points); }  // points is const here
};

TargetDistance::TargetDistance(const Target& target) : impl_(std::make_unique<Impl>()) {
  Impl& m = *impl_;
  m.target = target;
  for (Eigen::Index i = 0; i < target.points.rows(); ++i)
    m.points.push_back(to_point(target.points.row(i).transpose()));
  if (target.is_point_cloud()) {
    m.kd.emplace(boost::counting_iterator<std::size_t>(0),
                 boost::counting_iterator<std::size_t>(m.points.size()), KdTree::Splitter(),
                 SearchTraits(m.point_map()));
    m.kd->build();
  } else {
    for (Eigen::Index f = 0; f < target.triangles.rows(); ++f)
      m.triangles.emplace_back(m.points[static_cast<size_t>(target.triangles(f, 0))],
                               m.points[static_cast<size_t>(target.triangles(f, 1))],
                               m.points[static_cast<size_t>(target.triangles(f, 2))]);
    m.aabb.emplace(m.triangles.cbegin(), m.triangles.cend());
    m.aabb->accelerate_distance_queries();
    m.aabb->closest_point(
        m.points.front());  // builds what is built lazily, before parallel queries
  }
}

TargetDistance::~TargetDistance() = default;
TargetDistance::TargetDistance(TargetDistance&&) noexcept = default;
TargetDistance& TargetDistance::operator=(TargetDistance&&) noexcept = default;

const Target& TargetDistance::target() const { return impl_->target; }

TargetDistance::Closest TargetDistance::closest(const Eigen::Vector3d& query) const {
  const Impl& m = *impl_;
  const Point q = to_point(query);
  Closest out;
  if (m.kd) {
    NeighborSearch search(*m.kd, q, 1, 0, true, NeighborSearch::Distance(m.point_map()));
    out.primitive = static_cast<int>(search.begin()->first);
    const Point& p = m.points[static_cast<size_t>(out.primitive)];
    out.point = {p.x(), p.y(), p.z()};
  } else {
    const auto hit = m.aabb->closest_point_and_primitive(q);
    out.point = {hit.first.x(), hit.first.y(), hit.first.z()};
    out.primitive = static_cast<int>(hit.second - m.triangles.cbegin());
  }
  out.distance = (out.point - query).norm();
  return out;
}

std::vector<TargetDistance::Closest> TargetDistance::closest(const Eigen::MatrixXd& queries) const {
  std::vector<Closest> out(static_cast<size_t>(queries.rows()));
  // The trees are read-only once built (the AABB tree's distance accelerator
  // is built in the constructor), so queries may run in parallel.
  ThreadFailure failure;
#pragma omp parallel for schedule(static)
  for (Eigen::Index i = 0; i < queries.rows(); ++i) {
    if (failure.happened()) continue;
    try {
      out[static_cast<size_t>(i)] = closest(Eigen::Vector3d(queries.row(i).transpose()));
    } catch (...) {
      failure.capture();
    }
  }
  failure.rethrow_if_any();
  return out;
}

}  // namespace fiberfluid::geom

// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
// A surface measured or computed to take distances to (a scan, a FEM's
// deformed boundary), and the closest points on it: what the fit's surface
// distances, `fiberfluid compare` and the FEM bridge measure with.

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

namespace fiberfluid::geom {

// A measured deformed surface. A scan is rarely a clean closed mesh: any
// triangle soup (open, non-manifold, with holes) is kept as it is, and a file
// with vertices only is a point cloud.
struct Target {
  std::string label;          // for messages: the file, or a name given by the program
  Eigen::MatrixXd points;     // #P x 3: the vertices (a point cloud) or the triangles' corners
  Eigen::MatrixXi triangles;  // #T x 3 indices into points; empty for a point cloud
  std::string description;    // what was read, e.g. "a triangle soup: 5,012 triangles ..."

  bool is_point_cloud() const { return triangles.rows() == 0; }
};

// Reads a target from an OBJ, OFF, STL or PLY file, its coordinates times
// `scale` (a scan in mm: 1e-3). Drops unused vertices and degenerate
// triangles (zero area: they have no closest point of their own) and says so
// in `description`. Throws InputError naming the file for a file it cannot
// read, a non-finite coordinate (also after scaling), or no point at all.
Target read_target(const std::filesystem::path& path, double scale = 1.0);

// The same checks on a target built by a program (e.g. a deformed surface).
Target make_target(std::string label, const Eigen::MatrixXd& points,
                   const Eigen::MatrixXi& triangles = Eigen::MatrixXi());

// Closest points on a target: on its triangles (CGAL's AABB tree) or, for a
// point cloud, the nearest point (a k-d tree). Built once, queried often.
class TargetDistance {
 public:
  explicit TargetDistance(const Target& target);
  ~TargetDistance();
  TargetDistance(TargetDistance&&) noexcept;
  TargetDistance& operator=(TargetDistance&&) noexcept;

  struct Closest {
    Eigen::Vector3d point;  // the closest point of the target
    int primitive = -1;     // its triangle (or its point, for a cloud)
    double distance = 0.0;
  };
  Closest closest(const Eigen::Vector3d& query) const;
  // One per row of `queries` (#Q x 3), in parallel.
  std::vector<Closest> closest(const Eigen::MatrixXd& queries) const;

  const Target& target() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace fiberfluid::geom

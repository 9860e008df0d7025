// SPDX-License-Identifier: GPL-3.0-or-later
#include "fiberfluid/geom/target.hpp"

#include <cmath>
#include <sstream>

#include "fiberfluid/geom/mesh_io.hpp"
#include "fiberfluid/util/error.hpp"

namespace fiberfluid::geom {

Target make_target(std::string label, const Eigen::MatrixXd& points,
                   const Eigen::MatrixXi& triangles) {
  if (points.cols() != 3 || (triangles.size() > 0 && triangles.cols() != 3))
    throw InputError(label + ": a target is #P x 3 points with #T x 3 triangles");
  for (Eigen::Index i = 0; i < points.rows(); ++i)
    if (!points.row(i).allFinite())
      throw InputError(label + ": point " + std::to_string(i) + " has a non-finite coordinate");
  Target t;
  t.label = std::move(label);
  // Keep the triangles with an area; then the points they use (all for a cloud).
  std::vector<Eigen::Vector3i> kept;
  int degenerate = 0;
  for (Eigen::Index f = 0; f < triangles.rows(); ++f) {
    const Eigen::Vector3i c = triangles.row(f).transpose();
    if ((c.array() < 0).any() || (c.array() >= points.rows()).any())
      throw InputError(t.label + ": triangle " + std::to_string(f) +
                       " refers to a point that "
                       "does not exist");
    const Eigen::Vector3d a = points.row(c[0]), b = points.row(c[1]), d = points.row(c[2]);
    if ((b - a).cross(d - a).norm() > 0.0)
      kept.push_back(c);
    else
      ++degenerate;
  }
  std::vector<int> new_index(static_cast<size_t>(points.rows()), triangles.rows() > 0 ? -1 : 0);
  if (triangles.rows() > 0)
    for (const Eigen::Vector3i& c : kept)
      for (int k = 0; k < 3; ++k) new_index[static_cast<size_t>(c[k])] = 0;
  int used = 0;
  for (int& index : new_index)
    if (index == 0) index = used++;
  if (used == 0) throw InputError(t.label + ": no point to fit to");
  t.points.resize(used, 3);
  for (Eigen::Index i = 0; i < points.rows(); ++i)
    if (new_index[static_cast<size_t>(i)] >= 0)
      t.points.row(new_index[static_cast<size_t>(i)]) = points.row(i);
  t.triangles.resize(static_cast<Eigen::Index>(kept.size()), 3);
  for (size_t f = 0; f < kept.size(); ++f)
    for (int k = 0; k < 3; ++k)
      t.triangles(static_cast<Eigen::Index>(f), k) = new_index[static_cast<size_t>(kept[f][k])];

  std::ostringstream what;
  if (t.is_point_cloud()) {
    what << "a point cloud of " << used << " points";
    if (triangles.rows() > 0) what << " (all " << triangles.rows() << " triangles were degenerate)";
  } else {
    what << "a triangle soup of " << t.triangles.rows() << " triangles over " << used << " points";
    if (degenerate > 0) what << "; " << degenerate << " degenerate triangles dropped";
    if (used < points.rows()) what << "; " << points.rows() - used << " unused points dropped";
  }
  t.description = what.str();
  return t;
}

Target read_target(const std::filesystem::path& path, double scale) {
  if (!(scale > 0.0) || !std::isfinite(scale))
    throw InputError(path.string() + ": the scale must be a positive finite number");
  const geom::ReadResult read = geom::read_surface(path);
  if (read.surface.dim != 3)
    throw InputError(path.string() + ": a target is a 3D surface or point cloud, not a 2D polygon");
  Target t = make_target(path.string(), scale * read.surface.V, read.surface.F);
  if (scale != 1.0) {
    std::ostringstream note;
    note << "; coordinates scaled by " << scale << " to m";
    t.description += note.str();
  }
  return t;
}

}  // namespace fiberfluid::geom

// SPDX-License-Identifier: GPL-3.0-or-later
#include "fiberfluid/geom/folds.hpp"

#include <algorithm>
#include <map>
#include <vector>

#include "fiberfluid/geom/area_vectors.hpp"
#include "fiberfluid/geom/self_intersection.hpp"

namespace fiberfluid::geom {
namespace {

// Each face's neighbours: the faces sharing an edge with it (3D), or a
// vertex (2D outlines).
std::vector<std::vector<int>> face_neighbours(const Eigen::MatrixXi& F) {
  const bool triangles = F.cols() == 3;
  std::map<std::pair<int, int>, std::vector<int>> faces_at;  // an edge (or vertex) -> faces
  for (int f = 0; f < F.rows(); ++f)
    for (int c = 0; c < F.cols(); ++c) {
      const int a = F(f, c), b = triangles ? F(f, (c + 1) % 3) : a;
      faces_at[{std::min(a, b), std::max(a, b)}].push_back(f);
    }
  std::vector<std::vector<int>> neighbours(static_cast<size_t>(F.rows()));
  for (const auto& [key, faces] : faces_at)
    for (int f : faces)
      for (int g : faces)
        if (g != f) neighbours[static_cast<size_t>(f)].push_back(g);
  return neighbours;
}

// How face f lies against its neighbours: the dot of its unit normal with
// the sum of theirs (positive on a smooth or creased surface, negative where
// it folded back over them).
double lie_against(const Eigen::MatrixXd& areas, const std::vector<int>& neighbours, int f) {
  Eigen::RowVectorXd around = Eigen::RowVectorXd::Zero(areas.cols());
  for (int g : neighbours) around += areas.row(g).normalized();
  return areas.row(f).normalized().dot(around);
}

}  // namespace

std::optional<Fold> find_fold(const Surface& now, const Eigen::MatrixXd& areas_before) {
  const Eigen::MatrixXd areas = face_area_vectors(now.V, now.F);
  std::vector<int> turned;
  for (int f = 0; f < now.num_faces(); ++f)
    if (areas.row(f).dot(areas_before.row(f)) <= 0.0) turned.push_back(f);
  if (turned.empty()) return std::nullopt;
  const std::vector<std::vector<int>> neighbours = face_neighbours(now.F);
  for (int f : turned) {
    const std::vector<int>& around = neighbours[static_cast<size_t>(f)];
    if (lie_against(areas, around, f) <= 0.0 && lie_against(areas_before, around, f) > 0.0)
      return Fold{f, std::nullopt};
  }
  if (const auto crossing = find_self_intersection(now)) return Fold{turned.front(), crossing};
  return std::nullopt;
}

}  // namespace fiberfluid::geom

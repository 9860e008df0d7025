// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once

#include <filesystem>
#include <string>
#include <utility>
#include <vector>

#include "geom/surface.hpp"

namespace fiberfluid::geom {

// One named point-data array: #V rows, 1 (scalar) or 3 (vector) columns.
// 2D vectors are padded to 3 components, as ParaView expects.
struct PointField {
  std::string name;
  Eigen::MatrixXd values;
};

// Writes a VTK XML unstructured grid (.vtu, ASCII) of the surface: triangles
// in 3D, line segments in 2D (z = 0), with the given point data.
void write_vtu(const std::filesystem::path& path, const Surface& surface,
               const std::vector<PointField>& fields);

// Writes line segments between vertices of X (#V by dim) as a .vtu of
// VTK_LINE cells: the bulk fibers, for a look in ParaView.
void write_lines_vtu(const std::filesystem::path& path, const Eigen::MatrixXd& X,
                     const std::vector<std::pair<int, int>>& lines);

// Writes a ParaView collection (.pvd) listing (time, file) pairs; file names
// are written relative to the .pvd's folder.
void write_pvd(const std::filesystem::path& path,
               const std::vector<std::pair<double, std::string>>& steps);

}  // namespace fiberfluid::geom

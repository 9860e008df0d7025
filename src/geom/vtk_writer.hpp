// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once

#include <filesystem>
#include <string>
#include <utility>
#include <vector>

#include "fiberfluid/geom/surface.hpp"

namespace fiberfluid::geom {

// One named data array: #V rows (point data) or #F rows (cell data), 1
// (scalar) or 3 (vector) columns. 2D vectors are padded to 3 components, as
// ParaView expects.
struct PointField {
  std::string name;
  Eigen::MatrixXd values;
};

// A named list of numbers for the whole data set (VTK field data: a step's
// load factors, its pressure).
struct FieldValues {
  std::string name;
  std::vector<double> values;
};

// How the arrays are stored: ASCII text, or binary compressed with zlib and
// appended raw after the XML (VTK's vtkZLibDataCompressor, UInt64 headers),
// which ParaView and meshio read and which is several times smaller.
enum class VtkEncoding { Ascii, Compressed };

struct VtuContent {
  std::vector<PointField> points;  // point data
  std::vector<PointField> cells;   // cell data, one row per face
  std::vector<FieldValues> field;  // field data
  VtkEncoding encoding = VtkEncoding::Ascii;
};

// Writes a VTK XML unstructured grid (.vtu) of the surface: triangles in 3D,
// line segments in 2D (z = 0), with the given data. Throws
// std::invalid_argument for an array of the wrong row count.
void write_vtu(const std::filesystem::path& path, const Surface& surface,
               const VtuContent& content);
// The same with point data only, in ASCII.
void write_vtu(const std::filesystem::path& path, const Surface& surface,
               const std::vector<PointField>& fields);

// Writes line segments between vertices of X (#V by dim) as a .vtu of
// VTK_LINE cells, with the content's data (cell data one row per line): the
// bulk fibers, for a look in ParaView.
void write_lines_vtu(const std::filesystem::path& path, const Eigen::MatrixXd& X,
                     const std::vector<std::pair<int, int>>& lines, const VtuContent& content = {});

// Writes a ParaView collection (.pvd) listing (time, file) pairs; file names
// are written relative to the .pvd's folder.
void write_pvd(const std::filesystem::path& path,
               const std::vector<std::pair<double, std::string>>& steps);

}  // namespace fiberfluid::geom

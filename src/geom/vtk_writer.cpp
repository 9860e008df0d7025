// SPDX-License-Identifier: GPL-3.0-or-later
#include "geom/vtk_writer.hpp"

#include <iomanip>
#include <sstream>

#include "geom/mesh_io.hpp"
#include "util/error.hpp"

namespace fiberfluid::geom {

void write_vtu(const std::filesystem::path& path, const Surface& s,
               const std::vector<PointField>& fields) {
  const int n = s.num_vertices();
  std::ostringstream out;
  out << std::setprecision(12);
  out << "<?xml version=\"1.0\"?>\n"
      << "<VTKFile type=\"UnstructuredGrid\" version=\"0.1\" byte_order=\"LittleEndian\">\n"
      << "  <UnstructuredGrid>\n"
      << "    <Piece NumberOfPoints=\"" << n << "\" NumberOfCells=\"" << s.num_faces() << "\">\n"
      << "      <PointData>\n";
  for (const PointField& field : fields) {
    if (field.values.rows() != n)
      throw std::invalid_argument("write_vtu: field " + field.name + " has the wrong row count");
    const int components = field.values.cols() == 1 ? 1 : 3;
    out << "        <DataArray type=\"Float64\" Name=\"" << field.name << "\" NumberOfComponents=\""
        << components << "\" format=\"ascii\">\n";
    for (int i = 0; i < n; ++i) {
      out << "         ";
      for (int k = 0; k < components; ++k)
        out << ' ' << (k < field.values.cols() ? field.values(i, k) : 0.0);
      out << '\n';
    }
    out << "        </DataArray>\n";
  }
  out << "      </PointData>\n"
      << "      <Points>\n"
      << "        <DataArray type=\"Float64\" NumberOfComponents=\"3\" format=\"ascii\">\n";
  for (int i = 0; i < n; ++i)
    out << "          " << s.V(i, 0) << ' ' << s.V(i, 1) << ' '
        << (s.V.cols() == 3 ? s.V(i, 2) : 0.0) << '\n';
  out << "        </DataArray>\n"
      << "      </Points>\n"
      << "      <Cells>\n"
      << "        <DataArray type=\"Int64\" Name=\"connectivity\" format=\"ascii\">\n";
  for (int f = 0; f < s.num_faces(); ++f) {
    out << "         ";
    for (int k = 0; k < s.F.cols(); ++k) out << ' ' << s.F(f, k);
    out << '\n';
  }
  out << "        </DataArray>\n"
      << "        <DataArray type=\"Int64\" Name=\"offsets\" format=\"ascii\">\n";
  for (int f = 0; f < s.num_faces(); ++f) out << "          " << (f + 1) * s.F.cols() << '\n';
  out << "        </DataArray>\n"
      << "        <DataArray type=\"UInt8\" Name=\"types\" format=\"ascii\">\n";
  const int cell_type = s.F.cols() == 3 ? 5 : 3;  // VTK_TRIANGLE, VTK_LINE
  for (int f = 0; f < s.num_faces(); ++f) out << "          " << cell_type << '\n';
  out << "        </DataArray>\n"
      << "      </Cells>\n"
      << "    </Piece>\n"
      << "  </UnstructuredGrid>\n"
      << "</VTKFile>\n";
  write_text_file(path, out.str());
}

void write_lines_vtu(const std::filesystem::path& path, const Eigen::MatrixXd& X,
                     const std::vector<std::pair<int, int>>& lines) {
  Surface segments;
  segments.dim = static_cast<int>(X.cols());
  segments.V = X;
  segments.F.resize(static_cast<Eigen::Index>(lines.size()), 2);
  for (size_t k = 0; k < lines.size(); ++k)
    segments.F.row(static_cast<Eigen::Index>(k)) << lines[k].first, lines[k].second;
  write_vtu(path, segments, {});
}

void write_pvd(const std::filesystem::path& path,
               const std::vector<std::pair<double, std::string>>& steps) {
  std::ostringstream out;
  out << std::setprecision(12);
  out << "<?xml version=\"1.0\"?>\n"
      << "<VTKFile type=\"Collection\" version=\"0.1\" byte_order=\"LittleEndian\">\n"
      << "  <Collection>\n";
  for (const auto& [time, file] : steps)
    out << "    <DataSet timestep=\"" << time << "\" group=\"\" part=\"0\" file=\"" << file
        << "\"/>\n";
  out << "  </Collection>\n</VTKFile>\n";
  write_text_file(path, out.str());
}

}  // namespace fiberfluid::geom

// SPDX-License-Identifier: GPL-3.0-or-later
#include "fiberfluid/geom/vtk_writer.hpp"

#include <zlib.h>

#include <cstdint>
#include <cstring>
#include <iomanip>
#include <sstream>
#include <stdexcept>

#include "fiberfluid/geom/mesh_io.hpp"
#include "fiberfluid/util/error.hpp"

namespace fiberfluid::geom {

namespace {

// One array's bytes as VTK compresses them: the header [blocks, block size,
// last block size, compressed sizes] (UInt64) and the zlib-compressed data.
// One block.
std::string compressed(const std::vector<unsigned char>& raw) {
  uLongf size = compressBound(static_cast<uLong>(raw.size()));
  std::vector<unsigned char> packed(size);
  if (compress2(packed.data(), &size, raw.data(), static_cast<uLong>(raw.size()),
                Z_DEFAULT_COMPRESSION) != Z_OK)
    throw std::runtime_error("write_vtu: zlib could not compress an array");
  const uint64_t header[4] = {1, raw.size(), raw.size(), size};
  std::string out(reinterpret_cast<const char*>(header), sizeof header);
  out.append(reinterpret_cast<const char*>(packed.data()), size);
  return out;
}

// The XML and, for compressed files, the arrays' bytes appended after it
// (VTK's raw appended data: each DataArray names its offset into them).
struct VtuText {
  std::ostringstream xml;
  std::string appended;
  VtkEncoding encoding = VtkEncoding::Ascii;
};

// A DataArray of values (written as `type`: Float64, Int64 or UInt8) with
// `components` per tuple.
template <class T>
void data_array(VtuText& out, const char* type, const std::string& name, int components,
                const std::vector<T>& values) {
  const bool binary = out.encoding == VtkEncoding::Compressed && !values.empty();
  out.xml << "        <DataArray type=\"" << type << "\"";
  if (!name.empty()) out.xml << " Name=\"" << name << "\"";
  if (components > 1) out.xml << " NumberOfComponents=\"" << components << "\"";
  if (binary) {
    out.xml << " format=\"appended\" offset=\"" << out.appended.size() << "\"/>\n";
    std::vector<unsigned char> raw(values.size() * sizeof(T));
    std::memcpy(raw.data(), values.data(), raw.size());
    out.appended += compressed(raw);
    return;
  }
  out.xml << " format=\"ascii\">\n";
  for (size_t k = 0; k < values.size(); ++k) {
    out.xml << (k % static_cast<size_t>(components) == 0 ? "          " : " ");
    if constexpr (sizeof(T) == 1)
      out.xml << static_cast<int>(values[k]);
    else
      out.xml << values[k];
    if ((k + 1) % static_cast<size_t>(components) == 0) out.xml << '\n';
  }
  out.xml << "        </DataArray>\n";
}

// A field's rows as tuples of 1 or 3 doubles.
std::vector<double> tuples(const PointField& field, Eigen::Index rows, const char* what) {
  if (field.values.rows() != rows)
    throw std::invalid_argument("write_vtu: " + std::string(what) + " field " + field.name +
                                " has the wrong row count");
  const int components = field.values.cols() == 1 ? 1 : 3;
  std::vector<double> out;
  out.reserve(static_cast<size_t>(rows * components));
  for (Eigen::Index i = 0; i < rows; ++i)
    for (int k = 0; k < components; ++k)
      out.push_back(k < field.values.cols() ? field.values(i, k) : 0.0);
  return out;
}

}  // namespace

void write_vtu(const std::filesystem::path& path, const Surface& s, const VtuContent& content) {
  const int n = s.num_vertices(), faces = s.num_faces();
  VtuText text;
  text.encoding = content.encoding;
  std::ostringstream& out = text.xml;
  out << std::setprecision(17);
  out << "<?xml version=\"1.0\"?>\n"
      << "<VTKFile type=\"UnstructuredGrid\" version=\"1.0\" byte_order=\"LittleEndian\""
      << " header_type=\"UInt64\""
      << (text.encoding == VtkEncoding::Compressed ? " compressor=\"vtkZLibDataCompressor\"" : "")
      << ">\n"
      << "  <UnstructuredGrid>\n";
  if (!content.field.empty()) {
    out << "    <FieldData>\n";
    for (const FieldValues& f : content.field) {
      out << "        <DataArray type=\"Float64\" Name=\"" << f.name << "\" NumberOfTuples=\""
          << f.values.size() << "\" format=\"ascii\">\n          ";
      for (double v : f.values) out << v << ' ';
      out << "\n        </DataArray>\n";
    }
    out << "    </FieldData>\n";
  }
  out << "    <Piece NumberOfPoints=\"" << n << "\" NumberOfCells=\"" << faces << "\">\n"
      << "      <PointData>\n";
  for (const PointField& field : content.points)
    data_array(text, "Float64", field.name, field.values.cols() == 1 ? 1 : 3,
               tuples(field, n, "point"));
  out << "      </PointData>\n      <CellData>\n";
  for (const PointField& field : content.cells)
    data_array(text, "Float64", field.name, field.values.cols() == 1 ? 1 : 3,
               tuples(field, faces, "cell"));
  out << "      </CellData>\n      <Points>\n";
  data_array(text, "Float64", "", 3, tuples({"points", s.V}, n, "point"));
  out << "      </Points>\n      <Cells>\n";
  std::vector<int64_t> connectivity, offsets;
  for (int f = 0; f < faces; ++f) {
    for (int k = 0; k < s.F.cols(); ++k) connectivity.push_back(s.F(f, k));
    offsets.push_back(static_cast<int64_t>(f + 1) * s.F.cols());
  }
  const uint8_t cell_type = s.F.cols() == 3 ? 5 : 3;  // VTK_TRIANGLE, VTK_LINE
  data_array(text, "Int64", "connectivity", 1, connectivity);
  data_array(text, "Int64", "offsets", 1, offsets);
  data_array(text, "UInt8", "types", 1,
             std::vector<uint8_t>(static_cast<size_t>(faces), cell_type));
  out << "      </Cells>\n"
      << "    </Piece>\n"
      << "  </UnstructuredGrid>\n";
  if (!text.appended.empty())  // raw bytes after an underscore, as VTK reads them
    out << "  <AppendedData encoding=\"raw\">\n   _" << text.appended << "\n  </AppendedData>\n";
  out << "</VTKFile>\n";
  write_text_file(path, out.str());
}

void write_vtu(const std::filesystem::path& path, const Surface& s,
               const std::vector<PointField>& fields) {
  VtuContent content;
  content.points = fields;
  write_vtu(path, s, content);
}

void write_lines_vtu(const std::filesystem::path& path, const Eigen::MatrixXd& X,
                     const std::vector<std::pair<int, int>>& lines, const VtuContent& content) {
  Surface segments;
  segments.dim = static_cast<int>(X.cols());
  segments.V = X;
  segments.F.resize(static_cast<Eigen::Index>(lines.size()), 2);
  for (size_t k = 0; k < lines.size(); ++k)
    segments.F.row(static_cast<Eigen::Index>(k)) << lines[k].first, lines[k].second;
  write_vtu(path, segments, content);
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

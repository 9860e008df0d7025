// SPDX-License-Identifier: GPL-3.0-or-later
#include "fiberfluid/geom/mesh_io.hpp"

#include <algorithm>
#include <array>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <iomanip>
#include <map>
#include <sstream>

#include "fiberfluid/util/error.hpp"

namespace fiberfluid::geom {
namespace {

using Triangle = std::array<int, 3>;

struct MeshBuilder {
  std::vector<Eigen::Vector3d> vertices;
  std::vector<Triangle> triangles;
  std::vector<std::array<int, 2>> segments;
  int split_polygons = 0;

  // Fan-splits a polygon of 3 or more corners into triangles.
  void add_polygon(const std::vector<int>& corners) {
    if (corners.size() > 3) ++split_polygons;
    for (size_t k = 1; k + 1 < corners.size(); ++k)
      triangles.push_back({corners[0], corners[k], corners[k + 1]});
  }

  ReadResult finish(const std::string& name) const {
    for (size_t i = 0; i < vertices.size(); ++i)
      if (!vertices[i].allFinite())
        throw InputError(name + ": vertex " + std::to_string(i) +
                         " has a coordinate that is not a finite number");
    ReadResult out;
    if (split_polygons > 0)
      out.warnings.push_back(name + ": " + std::to_string(split_polygons) +
                             " polygons with more than 3 corners were split into triangles");
    const bool polygon_2d = triangles.empty() && !segments.empty() &&
                            std::all_of(vertices.begin(), vertices.end(),
                                        [](const Eigen::Vector3d& v) { return v.z() == 0.0; });
    Surface& s = out.surface;
    s.dim = polygon_2d ? 2 : 3;
    s.V.resize(static_cast<Eigen::Index>(vertices.size()), s.dim);
    for (size_t i = 0; i < vertices.size(); ++i)
      s.V.row(static_cast<Eigen::Index>(i)) = vertices[i].head(s.dim).transpose();
    if (polygon_2d) {
      s.F.resize(static_cast<Eigen::Index>(segments.size()), 2);
      for (size_t f = 0; f < segments.size(); ++f)
        s.F.row(static_cast<Eigen::Index>(f)) << segments[f][0], segments[f][1];
    } else {
      s.F.resize(static_cast<Eigen::Index>(triangles.size()), 3);
      for (size_t f = 0; f < triangles.size(); ++f)
        s.F.row(static_cast<Eigen::Index>(f)) << triangles[f][0], triangles[f][1], triangles[f][2];
    }
    return out;
  }
};

// A count or an index read as a double: the whole number from 0 to `limit`,
// or -1 (converting a double outside int's range to int is undefined, and a
// count larger than the file could hold would only exhaust memory).
long long whole_number(double value, double limit) {
  if (!(value >= 0.0 && value <= limit) || value != std::floor(value)) return -1;
  return static_cast<long long>(value);
}

// "file:line: ", or "file: " where the line is unknown (line 0: binary or
// whitespace-separated data such as a PLY body).
std::string where(const std::filesystem::path& path, int line) {
  return path.string() + (line > 0 ? ":" + std::to_string(line) : "") + ": ";
}

double parse_number(const std::string& token, const std::filesystem::path& path, int line,
                    const char* what) {
  try {
    size_t used = 0;
    const double value = std::stod(token, &used);
    if (used == token.size()) return value;
  } catch (const std::out_of_range&) {
    // std::stod rejects subnormals and overflow; fall through to the error.
  } catch (const std::invalid_argument&) {
  }
  // "nan" and "inf" parse above; anything else is not a number.
  throw InputError(where(path, line) + "expected a number for " + what + ", got '" + token + "'");
}

// ---------------------------------------------------------------- OBJ
int resolve_obj_index(const std::string& token, int vertex_count, const std::filesystem::path& path,
                      int line) {
  const std::string head = token.substr(0, token.find('/'));
  long index = 0;
  try {
    size_t used = 0;
    index = std::stol(head, &used);
    if (used != head.size()) throw std::invalid_argument(head);
  } catch (const std::exception&) {
    throw InputError(where(path, line) + "expected a vertex index, got '" + token + "'");
  }
  const long resolved = index < 0 ? vertex_count + index : index - 1;  // OBJ counts from 1
  if (index == 0 || resolved < 0 || resolved >= vertex_count)
    throw InputError(where(path, line) + "face index " + std::to_string(index) +
                     " is out of range (the file has " + std::to_string(vertex_count) +
                     " vertices so far)");
  return static_cast<int>(resolved);
}

ReadResult read_obj(std::istream& in, const std::filesystem::path& path) {
  MeshBuilder mesh;
  std::string text;
  int line = 0;
  while (std::getline(in, text)) {
    ++line;
    std::istringstream tokens(text);
    std::string keyword;
    if (!(tokens >> keyword) || keyword[0] == '#') continue;
    if (keyword == "v") {
      std::array<std::string, 3> xyz;
      if (!(tokens >> xyz[0] >> xyz[1] >> xyz[2]))
        throw InputError(where(path, line) + "expected 'v x y z'");
      Eigen::Vector3d v;
      for (int k = 0; k < 3; ++k) v[k] = parse_number(xyz[k], path, line, "a coordinate");
      mesh.vertices.push_back(v);
    } else if (keyword == "f" || keyword == "l") {
      std::vector<int> corners;
      std::string token;
      const int count = static_cast<int>(mesh.vertices.size());
      while (tokens >> token) corners.push_back(resolve_obj_index(token, count, path, line));
      if (keyword == "f") {
        if (corners.size() < 3)
          throw InputError(where(path, line) + "a face needs at least 3 vertices, got " +
                           std::to_string(corners.size()));
        mesh.add_polygon(corners);
      } else {
        if (corners.size() < 2)
          throw InputError(where(path, line) + "a line needs at least 2 vertices");
        for (size_t k = 0; k + 1 < corners.size(); ++k)
          mesh.segments.push_back({corners[k], corners[k + 1]});
      }
    }
    // vt, vn, o, g, s, usemtl, mtllib: not needed by the model.
  }
  return mesh.finish(path.string());
}

// ---------------------------------------------------------------- OFF
ReadResult read_off(std::istream& in, const std::filesystem::path& path) {
  // Tokens with comments removed, each remembering its line for messages.
  std::vector<std::pair<std::string, int>> tokens;
  std::string text;
  int line = 0;
  while (std::getline(in, text)) {
    ++line;
    text = text.substr(0, text.find('#'));
    std::istringstream words(text);
    std::string word;
    while (words >> word) tokens.emplace_back(word, line);
  }
  size_t at = 0;
  auto next = [&](const char* what) -> const std::pair<std::string, int>& {
    if (at >= tokens.size())
      throw InputError(path.string() + ": the file ends early, expected " + what);
    return tokens[at++];
  };
  // No count can exceed the tokens the file holds.
  const double most = static_cast<double>(tokens.size());
  auto next_count = [&](const char* what) {
    const auto& [token, l] = next(what);
    const long long value = whole_number(parse_number(token, path, l, what), most);
    if (value < 0)
      throw InputError(where(path, l) + "expected a count for " + what +
                       " (a whole number no "
                       "larger than the file's " +
                       std::to_string(tokens.size()) + " values), got '" + token + "'");
    return static_cast<int>(value);
  };
  if (tokens.empty() || tokens[0].first != "OFF")
    throw InputError(path.string() + ":1: expected the header 'OFF'");
  at = 1;
  const int nv = next_count("the number of vertices");
  const int nf = next_count("the number of faces");
  next_count("the number of edges");
  MeshBuilder mesh;
  for (int i = 0; i < nv; ++i) {
    Eigen::Vector3d v;
    for (int k = 0; k < 3; ++k) {
      const auto& [token, l] = next("a vertex coordinate");
      v[k] = parse_number(token, path, l, "a coordinate");
    }
    mesh.vertices.push_back(v);
  }
  for (int f = 0; f < nf; ++f) {
    const int corners = next_count("the corner count of a face");
    std::vector<int> face;
    for (int k = 0; k < corners; ++k) {
      const auto& [token, l] = next("a face index");
      const long long index = whole_number(parse_number(token, path, l, "a face index"), nv - 1.0);
      if (index < 0)
        throw InputError(where(path, l) + "face index " + token + " is out of range 0.." +
                         std::to_string(nv - 1));
      face.push_back(static_cast<int>(index));
    }
    if (corners < 3)
      throw InputError(path.string() + ": face " + std::to_string(f) + " has fewer than 3 corners");
    mesh.add_polygon(face);
    // Optional per-face colour values run to the end of the line.
    const int face_line = tokens[at - 1].second;
    while (at < tokens.size() && tokens[at].second == face_line) ++at;
  }
  return mesh.finish(path.string());
}

// ---------------------------------------------------------------- STL
// Welds corners with bit-identical coordinates: STL repeats them per face.
// A NaN cannot be ordered (the map's keys), so it is refused here.
struct Welder {
  std::map<std::array<double, 3>, int> index_of;
  MeshBuilder mesh;
  std::string name;
  int add(const std::array<double, 3>& p) {
    if (!std::isfinite(p[0]) || !std::isfinite(p[1]) || !std::isfinite(p[2]))
      throw InputError(name + ": facet " + std::to_string(mesh.triangles.size() + 1) +
                       " has a corner with a coordinate that is not a finite number");
    auto [it, inserted] = index_of.emplace(p, static_cast<int>(mesh.vertices.size()));
    if (inserted) mesh.vertices.emplace_back(p[0], p[1], p[2]);
    return it->second;
  }
};

ReadResult read_stl_ascii(std::istream& in, const std::filesystem::path& path) {
  Welder welder;
  welder.name = path.string();
  std::string text;
  int line = 0;
  std::vector<int> corners;
  while (std::getline(in, text)) {
    ++line;
    std::istringstream tokens(text);
    std::string keyword;
    if (!(tokens >> keyword)) continue;
    if (keyword == "vertex") {
      std::array<std::string, 3> xyz;
      if (!(tokens >> xyz[0] >> xyz[1] >> xyz[2]))
        throw InputError(where(path, line) + "expected 'vertex x y z'");
      std::array<double, 3> p{};
      for (int k = 0; k < 3; ++k) p[k] = parse_number(xyz[k], path, line, "a coordinate");
      corners.push_back(welder.add(p));
    } else if (keyword == "endloop") {
      if (corners.size() != 3)
        throw InputError(where(path, line) + "a facet needs 3 vertices, got " +
                         std::to_string(corners.size()));
      welder.mesh.add_polygon(corners);
      corners.clear();
    }
  }
  if (!corners.empty()) throw InputError(path.string() + ": the file ends inside a facet");
  return welder.mesh.finish(path.string());
}

ReadResult read_stl_binary(const std::string& bytes, const std::filesystem::path& path) {
  if (bytes.size() < 84)
    throw InputError(path.string() + ": truncated binary STL: " + std::to_string(bytes.size()) +
                     " bytes, shorter than the 84-byte header");
  uint32_t count = 0;
  std::memcpy(&count, bytes.data() + 80, 4);
  const uint64_t needed = 84 + 50ull * count;
  if (bytes.size() < needed)
    throw InputError(path.string() + ": truncated binary STL: the header announces " +
                     std::to_string(count) + " triangles (" + std::to_string(needed) +
                     " bytes) but the file has " + std::to_string(bytes.size()) + " bytes");
  Welder welder;
  welder.name = path.string();
  for (uint32_t t = 0; t < count; ++t) {
    const char* record = bytes.data() + 84 + 50ull * t + 12;  // skip the normal
    std::vector<int> corners;
    for (int c = 0; c < 3; ++c) {
      std::array<float, 3> p{};
      std::memcpy(p.data(), record + 12 * c, 12);
      corners.push_back(welder.add({p[0], p[1], p[2]}));
    }
    welder.mesh.add_polygon(corners);
  }
  return welder.mesh.finish(path.string());
}

ReadResult read_stl(const std::string& bytes, const std::filesystem::path& path) {
  // A binary STL may also begin with "solid": its size decides.
  bool binary = bytes.compare(0, 5, "solid") != 0;
  if (!binary && bytes.size() >= 84) {
    uint32_t count = 0;
    std::memcpy(&count, bytes.data() + 80, 4);
    binary = bytes.size() == 84 + 50ull * count && bytes.find("facet") == std::string::npos;
  }
  if (binary) return read_stl_binary(bytes, path);
  std::istringstream in(bytes);
  return read_stl_ascii(in, path);
}

// ---------------------------------------------------------------- PLY
enum class PlyFormat { Ascii, LittleEndian, BigEndian };

struct PlyProperty {
  std::string name;
  std::string type;        // scalar type, or the item type of a list
  std::string count_type;  // empty for scalars
};

struct PlyElement {
  std::string name;
  long count = 0;
  std::vector<PlyProperty> properties;
};

int ply_type_size(const std::string& type, const std::filesystem::path& path) {
  static const std::map<std::string, int> sizes = {
      {"char", 1},  {"uchar", 1},   {"int8", 1},   {"uint8", 1},  {"short", 2}, {"ushort", 2},
      {"int16", 2}, {"uint16", 2},  {"int", 4},    {"uint", 4},   {"int32", 4}, {"uint32", 4},
      {"float", 4}, {"float32", 4}, {"double", 8}, {"float64", 8}};
  auto it = sizes.find(type);
  if (it == sizes.end()) throw InputError(path.string() + ": unknown PLY type '" + type + "'");
  return it->second;
}

class PlyReader {
 public:
  PlyReader(const std::string& bytes, size_t start, PlyFormat format,
            const std::filesystem::path& path)
      : bytes_(bytes), at_(start), format_(format), path_(path) {}

  double read(const std::string& type) {
    if (format_ == PlyFormat::Ascii) {
      while (at_ < bytes_.size() && std::isspace(static_cast<unsigned char>(bytes_[at_]))) ++at_;
      const size_t begin = at_;
      while (at_ < bytes_.size() && !std::isspace(static_cast<unsigned char>(bytes_[at_]))) ++at_;
      if (begin == at_) throw InputError(path_.string() + ": the PLY data ends early");
      return parse_number(bytes_.substr(begin, at_ - begin), path_, 0, "a PLY value");
    }
    const int size = ply_type_size(type, path_);
    if (at_ + size > bytes_.size())
      throw InputError(path_.string() + ": truncated binary PLY: the data ends early");
    unsigned char raw[8];
    std::memcpy(raw, bytes_.data() + at_, size);
    at_ += size;
    if (format_ == PlyFormat::BigEndian) std::reverse(raw, raw + size);
    return decode(raw, type);
  }

 private:
  static double decode(const unsigned char* raw, const std::string& t) {
    auto as = [&](auto value) {
      std::memcpy(&value, raw, sizeof(value));
      return static_cast<double>(value);
    };
    if (t == "char" || t == "int8") return as(int8_t{});
    if (t == "uchar" || t == "uint8") return as(uint8_t{});
    if (t == "short" || t == "int16") return as(int16_t{});
    if (t == "ushort" || t == "uint16") return as(uint16_t{});
    if (t == "int" || t == "int32") return as(int32_t{});
    if (t == "uint" || t == "uint32") return as(uint32_t{});
    if (t == "float" || t == "float32") return as(float{});
    return as(double{});
  }

  const std::string& bytes_;
  size_t at_;
  PlyFormat format_;
  const std::filesystem::path& path_;
};

ReadResult read_ply(const std::string& bytes, const std::filesystem::path& path) {
  const size_t header_end = bytes.find("end_header");
  if (bytes.compare(0, 3, "ply") != 0 || header_end == std::string::npos)
    throw InputError(path.string() + ": expected a PLY header from 'ply' to 'end_header'");
  std::istringstream header(bytes.substr(0, header_end));
  PlyFormat format = PlyFormat::Ascii;
  std::vector<PlyElement> elements;
  std::string text;
  int line = 0;
  while (std::getline(header, text)) {
    ++line;
    std::istringstream tokens(text);
    std::string keyword;
    tokens >> keyword;
    if (keyword == "format") {
      std::string name;
      tokens >> name;
      if (name == "ascii")
        format = PlyFormat::Ascii;
      else if (name == "binary_little_endian")
        format = PlyFormat::LittleEndian;
      else if (name == "binary_big_endian")
        format = PlyFormat::BigEndian;
      else
        throw InputError(where(path, line) + "unknown PLY format '" + name + "'");
    } else if (keyword == "element") {
      PlyElement element;
      std::string count;
      tokens >> element.name >> count;
      // Each item takes at least a byte: no count can exceed the file's size.
      element.count = static_cast<long>(whole_number(
          parse_number(count, path, line, "an element count"), static_cast<double>(bytes.size())));
      if (element.count < 0)
        throw InputError(where(path, line) +
                         "expected an element count no larger than the "
                         "file's " +
                         std::to_string(bytes.size()) + " bytes, got '" + count + "'");
      elements.push_back(element);
    } else if (keyword == "property") {
      if (elements.empty()) throw InputError(where(path, line) + "property before any element");
      PlyProperty property;
      std::string type;
      tokens >> type;
      if (type == "list")
        tokens >> property.count_type >> property.type;
      else
        property.type = type;
      tokens >> property.name;
      elements.back().properties.push_back(property);
    }
  }
  size_t start = bytes.find('\n', header_end);
  start = start == std::string::npos ? bytes.size() : start + 1;
  PlyReader reader(bytes, start, format, path);

  MeshBuilder mesh;
  for (const PlyElement& element : elements) {
    for (long item = 0; item < element.count; ++item) {
      Eigen::Vector3d position = Eigen::Vector3d::Zero();
      std::vector<int> corners;
      for (const PlyProperty& p : element.properties) {
        if (p.count_type.empty()) {
          const double value = reader.read(p.type);
          if (element.name == "vertex" && (p.name == "x" || p.name == "y" || p.name == "z"))
            position[p.name[0] - 'x'] = value;
          continue;
        }
        const long long n =
            whole_number(reader.read(p.count_type), static_cast<double>(bytes.size()));
        if (n < 0)
          throw InputError(path.string() + ": " + element.name + " " + std::to_string(item) +
                           ": a list length that is not a count the file could hold");
        for (long long k = 0; k < n; ++k) {
          // An index beyond int's range is out of range whatever it is.
          const long long c = whole_number(reader.read(p.type), 2147483647.0);
          corners.push_back(c < 0 ? -1 : static_cast<int>(c));
        }
      }
      if (element.name == "vertex") mesh.vertices.push_back(position);
      if (element.name == "face") {
        for (int c : corners)
          if (c < 0 || c >= static_cast<int>(mesh.vertices.size()))
            throw InputError(path.string() + ": face " + std::to_string(item) + " refers to " +
                             (c < 0 ? std::string("an index that is no vertex number")
                                    : "vertex " + std::to_string(c)) +
                             ", outside 0.." + std::to_string(mesh.vertices.size() - 1));
        if (corners.size() < 3)
          throw InputError(path.string() + ": face " + std::to_string(item) +
                           " has fewer than 3 corners");
        mesh.add_polygon(corners);
      }
    }
  }
  return mesh.finish(path.string());
}

}  // namespace

std::optional<MeshFormat> mesh_format_of(const std::filesystem::path& path) {
  std::string ext = path.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  if (ext == ".obj") return MeshFormat::Obj;
  if (ext == ".off") return MeshFormat::Off;
  if (ext == ".stl") return MeshFormat::Stl;
  if (ext == ".ply") return MeshFormat::Ply;
  return std::nullopt;
}

ReadResult read_surface_bytes(const std::string& bytes, MeshFormat format,
                              const std::string& name) {
  if (bytes.empty()) throw InputError(name + ": the file is empty");
  const std::filesystem::path path = name;
  switch (format) {
    case MeshFormat::Stl:
      return read_stl(bytes, path);
    case MeshFormat::Ply:
      return read_ply(bytes, path);
    case MeshFormat::Obj:
    case MeshFormat::Off:
      break;
  }
  std::istringstream in(bytes);
  if (format == MeshFormat::Off) return read_off(in, path);
  ReadResult obj = read_obj(in, path);
  obj.index_base = 1;  // OBJ counts its vertices from 1
  return obj;
}

ReadResult read_surface(const std::filesystem::path& path) {
  const std::optional<MeshFormat> format = mesh_format_of(path);
  if (!format)
    throw InputError(path.string() + ": unknown mesh format '" + path.extension().string() +
                     "' (expected .obj, .off, .stl or .ply)");
  std::ifstream file(path, std::ios::binary);
  if (!file) throw InputError(path.string() + ": cannot open the file");
  std::ostringstream buffer;
  buffer << file.rdbuf();
  return read_surface_bytes(buffer.str(), *format, path.string());
}

void write_text_file(const std::filesystem::path& path, const std::string& content) {
  std::filesystem::path temporary = path;
  temporary += ".partial";
  {
    errno = 0;
    std::ofstream out(temporary, std::ios::binary);
    if (!out)
      throw InputError(path.string() + ": cannot open the file for writing" +
                       (errno != 0 ? std::string(": ") + std::strerror(errno) : std::string()));
    out << content;
    out.close();
    if (out.fail()) {  // a full disk, a file-size limit (EFBIG), a quota
      const std::string why = errno != 0 ? std::strerror(errno) : "unknown cause";
      std::error_code ignored;
      std::filesystem::remove(temporary, ignored);
      throw InputError(path.string() + ": writing failed: " + why);
    }
  }
  std::error_code error;
  std::filesystem::rename(temporary, path, error);
  if (error) throw InputError(path.string() + ": cannot put the file in place: " + error.message());
}

void write_obj(const std::filesystem::path& path, const Surface& s) {
  std::ostringstream out;
  out << std::setprecision(17) << "# written by fiberfluid\n";
  for (int i = 0; i < s.num_vertices(); ++i)
    out << "v " << s.V(i, 0) << ' ' << s.V(i, 1) << ' ' << (s.dim == 3 ? s.V(i, 2) : 0.0) << '\n';
  for (int f = 0; f < s.num_faces(); ++f) {
    out << (s.dim == 3 ? "f" : "l");
    for (int k = 0; k < s.F.cols(); ++k) out << ' ' << s.F(f, k) + 1;
    out << '\n';
  }
  write_text_file(path, out.str());
}

}  // namespace fiberfluid::geom

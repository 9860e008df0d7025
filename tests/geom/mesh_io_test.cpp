// SPDX-License-Identifier: GPL-3.0-or-later
#include "fiberfluid/geom/mesh_io.hpp"

#include <gtest/gtest.h>

#include <cstdint>
#include <cstring>
#include <sstream>

#include "fiberfluid/geom/area_vectors.hpp"
#include "fiberfluid/geom/generators.hpp"
#include "fiberfluid/geom/mesh_check.hpp"
#include "fiberfluid/util/error.hpp"
#include "test_support.hpp"

namespace fiberfluid::geom {
namespace {

using testing::ScratchDir;

// Expects read_surface to throw an InputError whose message contains `part`.
void expect_read_error(const std::filesystem::path& file, const std::string& part) {
  try {
    read_surface(file);
    ADD_FAILURE() << file << ": no error, expected one mentioning '" << part << "'";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find(part), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find(file.filename().string()), std::string::npos)
        << "the message must name the file: " << e.what();
  }
}

struct SharedMesh {
  const char* file;
  int vertices, used, faces, genus;
  bool convex;
};

// Counts from data/meshes/SOURCES.md.
TEST(MeshIO, ReadsEverySharedMesh) {
  const SharedMesh meshes[] = {
      {"icosahedron.obj", 12, 12, 20, 0, true}, {"sphere_02b.obj", 42, 42, 80, 0, true},
      {"cube.obj", 8, 8, 12, 0, true},          {"liver.obj", 181, 139, 274, 0, false},
      {"torus.obj", 800, 800, 1600, 1, false},  {"Bunny.stl", 1366, 1366, 2728, 0, false}};
  for (const SharedMesh& m : meshes) {
    SCOPED_TRACE(m.file);
    const ReadResult read = read_surface(testing::data_mesh(m.file));
    const MeshReport r = inspect(read.surface);
    EXPECT_TRUE(r.ok()) << (r.problems.empty() ? "" : r.problems.front());
    EXPECT_EQ(r.vertices, m.vertices);
    EXPECT_EQ(r.used_vertices, m.used);
    EXPECT_EQ(r.faces, m.faces);
    EXPECT_EQ(r.genus, m.genus);
    EXPECT_TRUE(r.outward);
    EXPECT_EQ(r.warnings.size(), m.used < m.vertices ? 1u : 0u);
  }
}

TEST(MeshIO, ObjFaceFormsNegativeIndicesAndPolygons) {
  ScratchDir dir;
  // A unit cube: quads in four index forms, the last two with negative indices.
  const auto file = dir.write("cube.obj", R"(# unit cube
o cube
v 0 0 0
v 1 0 0
v 1 1 0
v 0 1 0
v 0 0 1
v 1 0 1
v 1 1 1
v 0 1 1
vt 0 0
vn 0 0 1
f 1 4 3 2
f 5/1 6/1 7/1 8/1
f 1//1 2//1 6//1 5//1
f 2/1/1 3/1/1 7/1/1 6/1/1
f -5 -1 -2 -6
f -8 -4 -1 -5
)");
  const ReadResult read = read_surface(file);
  EXPECT_EQ(read.surface.num_vertices(), 8);
  EXPECT_EQ(read.surface.num_faces(), 12);
  ASSERT_EQ(read.warnings.size(), 1u);
  EXPECT_NE(read.warnings[0].find("6 polygons"), std::string::npos) << read.warnings[0];
  const MeshReport r = inspect(read.surface);
  EXPECT_TRUE(r.ok()) << (r.problems.empty() ? "" : r.problems.front());
  EXPECT_NEAR(r.volume, 1.0, 1e-14);
}

TEST(MeshIO, OffReader) {
  ScratchDir dir;
  const auto file = dir.write("tet.off",
                              "OFF\n# a tetrahedron\n4 4 6\n1 1 1\n1 -1 -1\n-1 1 -1\n-1 -1 1\n"
                              "3 0 1 2\n3 0 3 1\n3 0 2 3 255 0 0\n3 1 3 2\n");
  const Surface s = read_surface(file).surface;
  EXPECT_EQ(s.num_vertices(), 4);
  EXPECT_EQ(s.num_faces(), 4);
  EXPECT_NEAR(enclosed_volume(s.V, s.F), 8.0 / 3.0, 1e-14);
}

std::string binary_stl(const Surface& s, int claimed_triangles) {
  std::string bytes(80, ' ');
  const uint32_t count = static_cast<uint32_t>(claimed_triangles);
  bytes.append(reinterpret_cast<const char*>(&count), 4);
  for (int f = 0; f < s.num_faces(); ++f) {
    float record[12] = {0, 0, 0};
    for (int c = 0; c < 3; ++c)
      for (int a = 0; a < 3; ++a) record[3 + 3 * c + a] = static_cast<float>(s.V(s.F(f, c), a));
    bytes.append(reinterpret_cast<const char*>(record), sizeof record);
    bytes.append(2, '\0');
  }
  return bytes;
}

TEST(MeshIO, StlAsciiAndBinaryWeldEqualCoordinates) {
  ScratchDir dir;
  const Surface ico = icosahedron(2.0);
  std::ostringstream ascii;
  ascii.precision(9);  // round-trips a float
  ascii << "solid ico\n";
  for (int f = 0; f < ico.num_faces(); ++f) {
    ascii << "facet normal 0 0 0\nouter loop\n";
    for (int c = 0; c < 3; ++c)
      ascii << "vertex " << static_cast<float>(ico.V(ico.F(f, c), 0)) << ' '
            << static_cast<float>(ico.V(ico.F(f, c), 1)) << ' '
            << static_cast<float>(ico.V(ico.F(f, c), 2)) << "\n";
    ascii << "endloop\nendfacet\n";
  }
  ascii << "endsolid ico\n";
  for (const auto& file : {dir.write("ascii.stl", ascii.str()),
                           dir.write("binary.stl", binary_stl(ico, ico.num_faces()))}) {
    SCOPED_TRACE(file.filename());
    const Surface s = read_surface(file).surface;
    EXPECT_EQ(s.num_vertices(), 12);
    EXPECT_EQ(s.num_faces(), 20);
    EXPECT_TRUE(inspect(s).ok());
    EXPECT_NEAR(surface_area(s.V, s.F), surface_area(ico.V, ico.F), 1e-5);
  }
}

// A PLY of the tetrahedron with an extra vertex property and an extra element.
std::string ply(const std::string& format) {
  const double vertices[4][3] = {{1, 1, 1}, {1, -1, -1}, {-1, 1, -1}, {-1, -1, 1}};
  const int faces[4][3] = {{0, 1, 2}, {0, 3, 1}, {0, 2, 3}, {1, 3, 2}};
  std::ostringstream out;
  out << "ply\nformat " << format << " 1.0\ncomment test\nelement vertex 4\n"
      << "property float x\nproperty float y\nproperty double z\nproperty uchar red\n"
      << "element face 4\nproperty list uchar int vertex_indices\n"
      << "element edge 1\nproperty int vertex1\nproperty int vertex2\nend_header\n";
  const bool big = format == "binary_big_endian";
  auto put = [&](const void* p, size_t n) {
    std::string bytes(static_cast<const char*>(p), n);
    if (big) std::reverse(bytes.begin(), bytes.end());
    out << bytes;
  };
  for (const auto& v : vertices) {
    if (format == "ascii") {
      out << v[0] << ' ' << v[1] << ' ' << v[2] << " 7\n";
      continue;
    }
    const float x = static_cast<float>(v[0]), y = static_cast<float>(v[1]);
    const uint8_t red = 7;
    put(&x, 4);
    put(&y, 4);
    put(&v[2], 8);
    put(&red, 1);
  }
  for (const auto& f : faces) {
    if (format == "ascii") {
      out << "3 " << f[0] << ' ' << f[1] << ' ' << f[2] << "\n";
      continue;
    }
    const uint8_t n = 3;
    put(&n, 1);
    for (int c = 0; c < 3; ++c) put(&f[c], 4);
  }
  if (format == "ascii") {
    out << "0 1\n";
  } else {
    const int32_t a = 0, b = 1;
    put(&a, 4);
    put(&b, 4);
  }
  return out.str();
}

TEST(MeshIO, PlyAsciiAndBinary) {
  ScratchDir dir;
  for (const std::string format : {"ascii", "binary_little_endian", "binary_big_endian"}) {
    SCOPED_TRACE(format);
    const Surface s = read_surface(dir.write(format + ".ply", ply(format))).surface;
    EXPECT_EQ(s.num_vertices(), 4);
    EXPECT_EQ(s.num_faces(), 4);
    EXPECT_NEAR(enclosed_volume(s.V, s.F), 8.0 / 3.0, 1e-12);
  }
}

// Test-side writers, so that every reader sees every shared mesh.
std::string as_off(const Surface& s) {
  std::ostringstream out;
  out.precision(17);
  out << "OFF\n" << s.num_vertices() << ' ' << s.num_faces() << " 0\n";
  for (int i = 0; i < s.num_vertices(); ++i)
    out << s.V(i, 0) << ' ' << s.V(i, 1) << ' ' << s.V(i, 2) << "\n";
  for (int f = 0; f < s.num_faces(); ++f)
    out << "3 " << s.F(f, 0) << ' ' << s.F(f, 1) << ' ' << s.F(f, 2) << "\n";
  return out.str();
}

std::string as_binary_ply(const Surface& s) {
  std::ostringstream out;
  out << "ply\nformat binary_little_endian 1.0\nelement vertex " << s.num_vertices()
      << "\nproperty double x\nproperty double y\nproperty double z\nelement face " << s.num_faces()
      << "\nproperty list uchar int vertex_indices\nend_header\n";
  for (int i = 0; i < s.num_vertices(); ++i)
    for (int a = 0; a < 3; ++a) out.write(reinterpret_cast<const char*>(&s.V(i, a)), 8);
  for (int f = 0; f < s.num_faces(); ++f) {
    const char three = 3;
    out.write(&three, 1);
    for (int c = 0; c < 3; ++c) out.write(reinterpret_cast<const char*>(&s.F(f, c)), 4);
  }
  return out.str();
}

TEST(MeshIO, EveryReaderReadsEverySharedMesh) {
  ScratchDir dir;
  for (const char* name :
       {"cube.obj", "icosahedron.obj", "liver.obj", "sphere_02b.obj", "torus.obj", "Bunny.stl"}) {
    SCOPED_TRACE(name);
    const Surface original =
        remove_unused_vertices(read_surface(testing::data_mesh(name)).surface).surface;
    const double area = surface_area(original.V, original.F);
    const double volume = enclosed_volume(original.V, original.F);
    write_obj(dir.path() / "mesh.obj", original);
    const Surface from_obj = read_surface(dir.path() / "mesh.obj").surface;
    const Surface from_off = read_surface(dir.write("mesh.off", as_off(original))).surface;
    const Surface from_ply = read_surface(dir.write("mesh.ply", as_binary_ply(original))).surface;
    for (const Surface* s : {&from_obj, &from_off, &from_ply}) {
      EXPECT_EQ(s->F, original.F);
      EXPECT_NEAR((s->V - original.V).cwiseAbs().maxCoeff(), 0.0, 1e-15);
    }
    // STL stores floats and no indices: compare what survives.
    const Surface from_stl =
        read_surface(dir.write("mesh.stl", binary_stl(original, original.num_faces()))).surface;
    EXPECT_EQ(from_stl.num_vertices(), original.num_vertices());
    EXPECT_EQ(from_stl.num_faces(), original.num_faces());
    EXPECT_NEAR(surface_area(from_stl.V, from_stl.F), area, 1e-6 * area);
    EXPECT_NEAR(enclosed_volume(from_stl.V, from_stl.F), volume, 1e-6 * volume);
    EXPECT_TRUE(inspect(from_stl).ok());
  }
}

TEST(MeshIO, ObjRoundTripKeepsVertexOrderIn3DAnd2D) {
  ScratchDir dir;
  for (const Surface& original : {icosphere(2, 1.5), rectangle({0, 0}, {3, 2}, 3, 2)}) {
    write_obj(dir.path() / "out.obj", original);
    const Surface back = read_surface(dir.path() / "out.obj").surface;
    EXPECT_EQ(back.dim, original.dim);
    EXPECT_EQ(back.F, original.F);
    EXPECT_NEAR((back.V - original.V).cwiseAbs().maxCoeff(), 0.0, 1e-15);
  }
  EXPECT_FALSE(std::filesystem::exists(dir.path() / "out.obj.partial"));
}

TEST(MeshIO, BadFilesAreRejectedWithTheirOwnMessage) {
  ScratchDir dir;
  expect_read_error(dir.write("empty.obj", ""), "the file is empty");
  expect_read_error(dir.path() / "missing.obj", "cannot open");
  expect_read_error(dir.write("mesh.xyz", "1 2 3"), "unknown mesh format");
  expect_read_error(dir.write("range.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 4\n"),
                    "range.obj:4: face index 4 is out of range");
  expect_read_error(dir.write("zero.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 0 1 2\n"),
                    "face index 0 is out of range");
  expect_read_error(dir.write("word.obj", "v 0 zero 0\n"), "expected a number");
  const Surface ico = icosahedron();
  std::string truncated = binary_stl(ico, ico.num_faces());
  truncated.resize(truncated.size() - 30);
  expect_read_error(dir.write("cut.stl", truncated), "truncated binary STL");
  expect_read_error(dir.write("short.stl", "abc"), "truncated binary STL");
  expect_read_error(dir.write("bad.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 5\n"),
                    "face index 5 is out of range");
  expect_read_error(dir.write("bad.ply",
                              "ply\nformat ascii 1.0\nelement vertex 3\n"
                              "property float x\nproperty float y\nproperty float z\n"
                              "element face 1\nproperty list uchar int vertex_index\n"
                              "end_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 9\n"),
                    "refers to vertex 9");
  expect_read_error(dir.write("word.ply",
                              "ply\nformat ascii 1.0\nelement vertex 1\n"
                              "property float x\nproperty float y\nproperty float z\n"
                              "end_header\n0 zero 0\n"),
                    "word.ply: expected a number for a PLY value, got 'zero'");
}

// Found by fuzzing from outside (issue 11): a NaN the welding map cannot
// order, and counts and indices whose conversion to int was undefined or
// whose size would exhaust memory before the file ran out.
TEST(MeshIO, NonFiniteCoordinatesAndHugeCountsAreErrors) {
  ScratchDir dir;
  expect_read_error(dir.write("nan.stl",
                              "solid t\nfacet normal 0 0 0\nouter loop\nvertex 0 0 0\n"
                              "vertex 1 0 nan\nvertex 0 1 0\nendloop\nendfacet\nendsolid\n"),
                    "nan.stl: facet 1 has a corner with a coordinate that is not a finite number");
  const Surface ico = icosahedron();
  std::string binary = binary_stl(ico, ico.num_faces());
  const float nan = std::numeric_limits<float>::quiet_NaN();
  std::memcpy(&binary[84 + 12], &nan, 4);  // the first corner's x
  expect_read_error(dir.write("nan_binary.stl", binary), "not a finite number");
  expect_read_error(dir.write("nan.obj", "v 0 0 0\nv 1 0 nan\nv 0 1 0\nf 1 2 3\n"),
                    "nan.obj: vertex 1 has a coordinate that is not a finite number");
  expect_read_error(dir.write("inf.off", "OFF\n3 1 0\n0 0 0\n1 inf 0\n0 1 0\n3 0 1 2\n"),
                    "vertex 1 has a coordinate that is not a finite number");
  expect_read_error(dir.write("big.off", "OFF\n3 1e300 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n"),
                    "big.off:2: expected a count for the number of faces");
  expect_read_error(dir.write("many.off", "OFF\n2147483648 1 0\n0 0 0\n"),
                    "expected a count for the number of vertices");
  expect_read_error(dir.write("nan_index.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 nan\n"),
                    "face index nan is out of range 0..2");
  expect_read_error(dir.write("half_index.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 1.5\n"),
                    "face index 1.5 is out of range 0..2");
  const std::string ply_header =
      "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\n"
      "property float y\nproperty float z\nelement face 1\n"
      "property list uchar int vertex_index\nend_header\n0 0 0\n1 0 0\n0 1 0\n";
  expect_read_error(dir.write("big_index.ply", ply_header + "3 0 1 1e300\n"),
                    "face 0 refers to an index that is no vertex number");
  expect_read_error(dir.write("big_list.ply", ply_header + "1e300 0 1 2\n"),
                    "a list length that is not a count");
  expect_read_error(dir.write("big_count.ply",
                              "ply\nformat ascii 1.0\nelement vertex 1e300\nproperty float x\n"
                              "end_header\n0\n"),
                    "big_count.ply:3: expected an element count no larger than the file's");
}

}  // namespace
}  // namespace fiberfluid::geom

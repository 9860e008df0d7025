// SPDX-License-Identifier: GPL-3.0-or-later
// The "surface" of a case (a mesh file or a generator) and of an area study.
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "fiberfluid/experiment/read/json_fields.hpp"
#include "fiberfluid/experiment/read/readers.hpp"
#include "fiberfluid/geom/generators.hpp"
#include "fiberfluid/util/error.hpp"

namespace fiberfluid::experiment {
namespace {

using nlohmann::json;

// ------------------------------------------------------------ surfaces
// A generator's parameters, checked now; the surface is made when the case is
// built. *vertices: about how many vertices it will make (its cost is
// checked against the budgets before it is built).
std::function<geom::Surface()> read_generator(Fields& f, double* vertices) {
  const std::string kind =
      f.choice("generator", "",
               {"icosphere", "tetrahedron", "octahedron", "icosahedron", "cube", "box", "dome",
                "cylinder", "torus", "rectangle", "polygon"});
  if (kind == "icosphere") {
    const int subdivisions = f.integer("subdivisions", 2, 0, 7);
    const double radius = f.positive("radius", 1.0);
    *vertices = 10.0 * std::pow(4.0, subdivisions) + 2.0;
    return [=] { return geom::icosphere(subdivisions, radius); };
  }
  if (kind == "tetrahedron" || kind == "octahedron" || kind == "icosahedron") {
    const double radius = f.positive("radius", 1.0);
    if (kind == "tetrahedron") return [=] { return geom::tetrahedron(radius); };
    if (kind == "octahedron") return [=] { return geom::octahedron(radius); };
    return [=] { return geom::icosahedron(radius); };
  }
  if (kind == "cube") {
    const double edge = f.positive("edge", 1.0);
    return [=] { return geom::cube(edge); };
  }
  if (kind == "box") {
    const Eigen::Vector3d min = f.vector("min", 3), max = f.vector("max", 3);
    Eigen::Vector3i segments = Eigen::Vector3i::Ones();
    if (f.has("segments")) segments = f.counts("segments", 3, 1, 200);
    if ((min.array() >= max.array()).any()) f.fail("max", "must exceed min on every axis");
    const Eigen::Vector3d n = (segments.array() + 1).cast<double>();
    *vertices = 2.0 * (n.x() * n.y() + n.y() * n.z() + n.z() * n.x());
    return [=] { return geom::box(min, max, segments); };
  }
  if (kind == "dome") {
    const Eigen::Vector3d semi_axes = f.vector("semi_axes", 3);
    const int subdivisions = f.integer("subdivisions", 2, 0, 6);
    const geom::DomeBase base =
        f.enumeration("base", geom::DomeBase::Icosahedron, geom::kDomeBaseNames);
    const bool octahedral = base == geom::DomeBase::Octahedron;
    *vertices = (octahedral ? 4.0 : 10.0) * std::pow(4.0, subdivisions) + 2.0;
    return [=] { return geom::dome(semi_axes, subdivisions, base); };
  }
  if (kind == "cylinder") {
    const double radius = f.positive("radius", 1.0), length = f.positive("length", 1.0);
    Eigen::Vector2i segments(24, 24);
    if (f.has("segments")) segments = f.counts("segments", 2, 1, 1000);
    if (segments.y() < 3) f.fail("segments", "expected at least 3 segments around");
    const int cap_rings = f.integer("cap_rings", 0, 0, 1000);
    const double rings =
        segments.x() + 1.0 + 2.0 * (cap_rings > 0 ? cap_rings : segments.y() / 6.0);
    *vertices = rings * segments.y() + 2.0;
    return [=] { return geom::cylinder(radius, length, segments.x(), segments.y(), cap_rings); };
  }
  if (kind == "torus") {
    const double major = f.positive("major_radius", 2.0), minor = f.positive("minor_radius", 0.7);
    if (minor >= major)
      f.fail("minor_radius", "must be below major_radius (a ring, not a spindle)");
    Eigen::Vector2i segments(40, 20);
    if (f.has("segments")) segments = f.counts("segments", 2, 3, 1000);
    *vertices = static_cast<double>(segments.x()) * segments.y();
    return [=] { return geom::torus(major, minor, segments.x(), segments.y()); };
  }
  if (kind == "rectangle") {
    const Eigen::Vector2d min = f.vector("min", 2), max = f.vector("max", 2);
    Eigen::Vector2i segments = Eigen::Vector2i::Ones();
    if (f.has("segments")) segments = f.counts("segments", 2, 1, 1000);
    if ((min.array() >= max.array()).any()) f.fail("max", "must exceed min on both axes");
    return [=] { return geom::rectangle(min, max, segments.x(), segments.y()); };
  }
  // polygon
  const json& points = f.raw("points");
  if (!points.is_array() || points.size() < 3)
    f.fail("points", "expected a list of at least 3 [x, y] points");
  Eigen::MatrixXd P(static_cast<Eigen::Index>(points.size()), 2);
  for (size_t k = 0; k < points.size(); ++k) {
    if (!points[k].is_array() || points[k].size() != 2 || !points[k][0].is_number() ||
        !points[k][1].is_number())
      f.fail("points", "expected [x, y] pairs, got " + excerpt(points[k]));
    P.row(static_cast<Eigen::Index>(k)) << points[k][0].get<double>(), points[k][1].get<double>();
  }
  return [=] { return geom::polygon(P); };
}

// "file" (with "flip") or "generator", then "scale" and "remesh_vertices".
// A file's path as the resolved experiment gives it: absolute, so that it
// reads the same file from any folder.

}  // namespace

std::string absolute_path(const std::filesystem::path& path) {
  return std::filesystem::absolute(path).lexically_normal().string();
}

SurfaceSpec read_surface_spec(Fields& f, const std::filesystem::path& folder) {
  SurfaceSpec spec;
  spec.field = f.field();
  if (f.has("file") == f.has("generator"))
    f.fail("", "expected exactly one of \"file\" or \"generator\"");
  if (f.has("file")) {
    spec.file = f.string("file");
    if (spec.file.is_relative()) spec.file = folder / spec.file;
    f.resolve("file", absolute_path(spec.file));
    spec.flip = f.boolean("flip", false);
  } else {
    spec.generate = read_generator(f, &spec.expected_vertices);
    spec.generator = f.string("generator");
  }
  spec.scale = f.positive("scale", 1.0);
  if (f.has("remesh_vertices")) spec.remesh_vertices = f.integer("remesh_vertices", 0, 20, 1000000);
  return spec;
}

}  // namespace fiberfluid::experiment

// SPDX-License-Identifier: GPL-3.0-or-later
#include "fiberfluid/geom/generators.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "fiberfluid/geom/area_vectors.hpp"
#include "fiberfluid/util/error.hpp"

namespace fiberfluid::geom {
namespace {

Surface from_lists(const std::vector<Eigen::Vector3d>& vertices,
                   const std::vector<Eigen::Vector3i>& faces) {
  Surface s;
  s.dim = 3;
  s.V.resize(static_cast<Eigen::Index>(vertices.size()), 3);
  s.F.resize(static_cast<Eigen::Index>(faces.size()), 3);
  for (size_t i = 0; i < vertices.size(); ++i)
    s.V.row(static_cast<Eigen::Index>(i)) = vertices[i].transpose();
  for (size_t f = 0; f < faces.size(); ++f)
    s.F.row(static_cast<Eigen::Index>(f)) = faces[f].transpose();
  return s;
}

void scale_to_radius(Surface& s, double radius) {
  for (int i = 0; i < s.num_vertices(); ++i) s.V.row(i) *= radius / s.V.row(i).norm();
}

void require_positive(double value, const char* what) {
  if (!(value > 0.0) || !std::isfinite(value))
    throw InputError(std::string(what) + " must be a positive number");
}

}  // namespace

Surface tetrahedron(double radius) {
  require_positive(radius, "tetrahedron radius");
  Surface s = from_lists({{1, 1, 1}, {1, -1, -1}, {-1, 1, -1}, {-1, -1, 1}},
                         {{0, 1, 2}, {0, 3, 1}, {0, 2, 3}, {1, 3, 2}});
  scale_to_radius(s, radius);
  return s;
}

Surface octahedron(double radius) {
  require_positive(radius, "octahedron radius");
  Surface s = from_lists(
      {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}},
      {{0, 2, 4}, {2, 1, 4}, {1, 3, 4}, {3, 0, 4}, {2, 0, 5}, {1, 2, 5}, {3, 1, 5}, {0, 3, 5}});
  scale_to_radius(s, radius);
  return s;
}

Surface icosahedron(double radius) {
  require_positive(radius, "icosahedron radius");
  const double t = (1.0 + std::sqrt(5.0)) / 2.0;
  Surface s = from_lists(
      {{-1, t, 0},
       {1, t, 0},
       {-1, -t, 0},
       {1, -t, 0},
       {0, -1, t},
       {0, 1, t},
       {0, -1, -t},
       {0, 1, -t},
       {t, 0, -1},
       {t, 0, 1},
       {-t, 0, -1},
       {-t, 0, 1}},
      {{0, 11, 5},  {0, 5, 1},  {0, 1, 7},  {0, 7, 10}, {0, 10, 11}, {1, 5, 9}, {5, 11, 4},
       {11, 10, 2}, {10, 7, 6}, {7, 1, 8},  {3, 9, 4},  {3, 4, 2},   {3, 2, 6}, {3, 6, 8},
       {3, 8, 9},   {4, 9, 5},  {2, 4, 11}, {6, 2, 10}, {8, 6, 7},   {9, 8, 1}});
  scale_to_radius(s, radius);
  return s;
}

namespace {
// Splits every triangle of a unit sphere's polyhedron into four, `times`
// times (0 to 8; `what` names the generator in the error), each new midpoint
// pushed to the unit sphere.
Surface subdivided_to_sphere(Surface s, int times, const std::string& what) {
  if (times < 0 || times > 8)
    throw InputError(what + " subdivisions must be between 0 and 8, got " + std::to_string(times));
  for (int level = 0; level < times; ++level) {
    std::vector<Eigen::Vector3d> vertices;
    for (int i = 0; i < s.num_vertices(); ++i) vertices.emplace_back(s.V.row(i).transpose());
    std::map<std::pair<int, int>, int> midpoint;
    auto middle = [&](int a, int b) {
      auto key = std::make_pair(std::min(a, b), std::max(a, b));
      auto it = midpoint.find(key);
      if (it != midpoint.end()) return it->second;
      vertices.push_back((vertices[a] + vertices[b]).normalized());
      return midpoint[key] = static_cast<int>(vertices.size()) - 1;
    };
    std::vector<Eigen::Vector3i> faces;
    for (int f = 0; f < s.num_faces(); ++f) {
      const int a = s.F(f, 0), b = s.F(f, 1), c = s.F(f, 2);
      const int ab = middle(a, b), bc = middle(b, c), ca = middle(c, a);
      faces.insert(faces.end(), {{a, ab, ca}, {b, bc, ab}, {c, ca, bc}, {ab, bc, ca}});
    }
    s = from_lists(vertices, faces);
  }
  return s;
}
}  // namespace

Surface icosphere(int subdivisions, double radius) {
  require_positive(radius, "icosphere radius");
  Surface s = subdivided_to_sphere(icosahedron(1.0), subdivisions, "icosphere");
  s.V *= radius;
  return s;
}

Surface box(const Eigen::Vector3d& min, const Eigen::Vector3d& max,
            const Eigen::Vector3i& segments) {
  for (int a = 0; a < 3; ++a) {
    if (!(max[a] > min[a])) throw InputError("box: max must exceed min on every axis");
    if (segments[a] < 1) throw InputError("box: segments must be at least 1 on every axis");
  }
  // Vertices are keyed by their integer lattice position, so the faces of
  // neighbouring sides share their edge vertices exactly.
  std::map<std::array<int, 3>, int> index_of;
  std::vector<Eigen::Vector3d> vertices;
  auto vertex = [&](const std::array<int, 3>& lattice) {
    auto [it, inserted] = index_of.emplace(lattice, static_cast<int>(vertices.size()));
    if (inserted) {
      Eigen::Vector3d p;
      for (int a = 0; a < 3; ++a)
        p[a] = min[a] + (max[a] - min[a]) * lattice[a] / static_cast<double>(segments[a]);
      vertices.push_back(p);
    }
    return it->second;
  };
  std::vector<Eigen::Vector3i> faces;
  for (int a = 0; a < 3; ++a) {
    const int b = (a + 1) % 3, c = (a + 2) % 3;  // e_b x e_c = e_a
    for (int side : {0, segments[a]}) {
      for (int i = 0; i < segments[b]; ++i)
        for (int j = 0; j < segments[c]; ++j) {
          auto corner = [&](int di, int dj) {
            std::array<int, 3> lattice{};
            lattice[a] = side;
            lattice[b] = i + di;
            lattice[c] = j + dj;
            return vertex(lattice);
          };
          const int p00 = corner(0, 0), p10 = corner(1, 0), p11 = corner(1, 1), p01 = corner(0, 1);
          if (side > 0)
            faces.insert(faces.end(), {{p00, p10, p11}, {p00, p11, p01}});
          else
            faces.insert(faces.end(), {{p00, p11, p10}, {p00, p01, p11}});
        }
    }
  }
  return from_lists(vertices, faces);
}

Surface cube(double edge) {
  require_positive(edge, "cube edge");
  const Eigen::Vector3d half = Eigen::Vector3d::Constant(edge / 2);
  return box(-half, half);
}

Surface dome(const Eigen::Vector3d& semi_axes, int subdivisions, DomeBase base) {
  for (int a = 0; a < 3; ++a) require_positive(semi_axes[a], "dome semi-axes");
  Surface s = subdivided_to_sphere(
      base == DomeBase::Octahedron ? octahedron(1.0) : icosahedron(1.0), subdivisions, "dome");
  for (int i = 0; i < s.num_vertices(); ++i) {
    Eigen::Vector3d p = s.V.row(i).transpose();
    if (p.z() < 0.0) {
      // Angle below the equator -> distance from the rim along the disk.
      const double below = std::asin(std::min(1.0, -p.z()));
      const double rho = 1.0 - below / (M_PI / 2.0);
      const double planar = p.head<2>().norm();
      p.head<2>() =
          planar > 0.0 ? Eigen::Vector2d(p.head<2>() * (rho / planar)) : Eigen::Vector2d::Zero();
      p.z() = 0.0;
    }
    s.V.row(i) = p.cwiseProduct(semi_axes).transpose();
  }
  return s;
}

Surface cylinder(double radius, double length, int along, int around, int cap_rings) {
  require_positive(radius, "cylinder radius");
  require_positive(length, "cylinder length");
  if (along < 1) throw InputError("cylinder: along must be at least 1");
  if (around < 3) throw InputError("cylinder: around must be at least 3");
  if (cap_rings < 0) throw InputError("cylinder: cap_rings must be 0 or more");
  if (cap_rings == 0) cap_rings = std::max(1, static_cast<int>(std::lround(around / (2.0 * M_PI))));
  std::vector<Eigen::Vector3d> vertices;
  std::vector<Eigen::Vector3i> faces;
  const auto ring = [&](double x, double rho) {  // `around` vertices; its first index
    const int first = static_cast<int>(vertices.size());
    for (int j = 0; j < around; ++j) {
      const double theta = 2.0 * M_PI * j / around;
      vertices.emplace_back(x, rho * std::cos(theta), rho * std::sin(theta));
    }
    return first;
  };
  // Quads between two rings, split in two, with normal (around) x (from ->
  // to), or the opposite when `flip`.
  const auto band = [&](int from, int to, bool flip) {
    for (int j = 0; j < around; ++j) {
      const int a = from + j, b = from + (j + 1) % around, c = to + (j + 1) % around, d = to + j;
      if (flip)
        faces.insert(faces.end(), {{a, c, b}, {a, d, c}});
      else
        faces.insert(faces.end(), {{a, b, c}, {a, c, d}});
    }
  };
  std::vector<int> wall;
  // The last ring at `length` exactly, where the far cap is: length * i / along
  // can miss it by an ulp (0.03 * 9 / 9), and a cap an ulp out of its plane
  // is a concave body, whose fibers across the rim are pruned.
  for (int i = 0; i <= along; ++i)
    wall.push_back(ring(i == along ? length : length * i / along, radius));
  for (int i = 0; i < along; ++i)
    band(wall[static_cast<size_t>(i)], wall[static_cast<size_t>(i + 1)], false);
  // Each cap: from its centre out to the wall's end ring.
  for (const bool far_end : {false, true}) {
    const double x = far_end ? length : 0.0;
    const int centre = static_cast<int>(vertices.size());
    vertices.emplace_back(x, 0.0, 0.0);
    int inner = -1;
    for (int k = 1; k <= cap_rings; ++k) {
      const int outer = k == cap_rings ? wall[far_end ? static_cast<size_t>(along) : 0]
                                       : ring(x, radius * k / cap_rings);
      if (inner < 0) {
        for (int j = 0; j < around; ++j) {
          const int a = outer + j, b = outer + (j + 1) % around;
          faces.push_back(far_end ? Eigen::Vector3i(centre, a, b) : Eigen::Vector3i(centre, b, a));
        }
      } else {
        band(inner, outer, far_end);
      }
      inner = outer;
    }
  }
  return from_lists(vertices, faces);
}

Surface torus(double R, double r, int around, int tube) {
  require_positive(r, "torus tube radius");
  if (!(R > r)) throw InputError("torus: the ring radius must exceed the tube radius");
  if (around < 3 || tube < 3) throw InputError("torus: at least 3 segments each way");
  std::vector<Eigen::Vector3d> vertices;
  std::vector<Eigen::Vector3i> faces;
  auto index = [&](int u, int v) { return (u % around) * tube + (v % tube); };
  for (int u = 0; u < around; ++u)
    for (int v = 0; v < tube; ++v) {
      const double a = 2 * M_PI * u / around, b = 2 * M_PI * v / tube;
      vertices.emplace_back((R + r * std::cos(b)) * std::cos(a),
                            (R + r * std::cos(b)) * std::sin(a), r * std::sin(b));
    }
  for (int u = 0; u < around; ++u)
    for (int v = 0; v < tube; ++v) {
      const int p00 = index(u, v), p10 = index(u + 1, v), p11 = index(u + 1, v + 1),
                p01 = index(u, v + 1);
      faces.insert(faces.end(), {{p00, p10, p11}, {p00, p11, p01}});
    }
  Surface s = from_lists(vertices, faces);
  if (enclosed_volume(s.V, s.F) < 0.0) flip_orientation(s);
  return s;
}

Surface polygon(const Eigen::MatrixXd& points) {
  if (points.cols() != 2 || points.rows() < 3)
    throw InputError("polygon: expected at least 3 points with 2 coordinates each");
  Surface s;
  s.dim = 2;
  s.V = points;
  const int n = static_cast<int>(points.rows());
  s.F.resize(n, 2);
  for (int i = 0; i < n; ++i) s.F.row(i) << i, (i + 1) % n;
  if (enclosed_volume(s.V, s.F) < 0.0) {
    for (int i = 0; i < n; ++i) s.F.row(i) << (i + 1) % n, i;
  }
  return s;
}

Surface rectangle(const Eigen::Vector2d& min, const Eigen::Vector2d& max, int nx, int ny) {
  if (!(max.x() > min.x() && max.y() > min.y()))
    throw InputError("rectangle: max must exceed min on both axes");
  if (nx < 1 || ny < 1) throw InputError("rectangle: segments must be at least 1");
  std::vector<Eigen::Vector2d> points;
  const Eigen::Vector2d size = max - min;
  for (int i = 0; i < nx; ++i) points.emplace_back(min.x() + size.x() * i / nx, min.y());
  for (int j = 0; j < ny; ++j) points.emplace_back(max.x(), min.y() + size.y() * j / ny);
  for (int i = nx; i > 0; --i) points.emplace_back(min.x() + size.x() * i / nx, max.y());
  for (int j = ny; j > 0; --j) points.emplace_back(min.x(), min.y() + size.y() * j / ny);
  Eigen::MatrixXd P(static_cast<Eigen::Index>(points.size()), 2);
  for (size_t k = 0; k < points.size(); ++k) P.row(static_cast<Eigen::Index>(k)) = points[k];
  return polygon(P);
}

}  // namespace fiberfluid::geom

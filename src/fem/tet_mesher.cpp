// SPDX-License-Identifier: GPL-3.0-or-later
// CGAL stays in this file (and it compiles slowly: -g0, see CMakeLists.txt).
#include "fiberfluid/fem/tet_mesher.hpp"

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Mesh_complex_3_in_triangulation_3.h>
#include <CGAL/Mesh_criteria_3.h>
#include <CGAL/Mesh_triangulation_3.h>
#include <CGAL/Polyhedral_mesh_domain_with_features_3.h>
#include <CGAL/Surface_mesh.h>
#include <CGAL/make_mesh_3.h>

#include <Eigen/LU>
#include <map>
#include <vector>

#include "fiberfluid/geom/cgal_surface_mesh.hpp"
#include "fiberfluid/util/error.hpp"

namespace fiberfluid::fem {
namespace {

using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using SurfaceMesh = CGAL::Surface_mesh<Kernel::Point_3>;
using Domain = CGAL::Polyhedral_mesh_domain_with_features_3<Kernel, SurfaceMesh>;
using Triangulation = CGAL::Mesh_triangulation_3<Domain, CGAL::Default, CGAL::Sequential_tag>::type;
using Complex = CGAL::Mesh_complex_3_in_triangulation_3<Triangulation, Domain::Corner_index,
                                                        Domain::Curve_index>;
using Criteria = CGAL::Mesh_criteria_3<Triangulation>;

}  // namespace

Mesh tetrahedralize(const geom::Surface& s, const TetMeshOptions& options) {
  if (s.dim != 3 || s.num_faces() == 0)
    throw InputError("tetrahedralize: expected a closed 3D triangle mesh");
  const SurfaceMesh mesh = geom::to_surface_mesh<SurfaceMesh>(s, "tetrahedralize");
  if (!CGAL::is_closed(mesh)) throw InputError("tetrahedralize: the surface is not closed");

  const double diagonal = geom::bounding_box_diagonal(s.V);
  const double size = options.size > 0.0 ? options.size : diagonal / 12.0;
  const double distance = options.facet_distance > 0.0 ? options.facet_distance : size / 20.0;
  Domain domain(mesh);
  // Sharp edges (a box's, a cut organ's) are kept as edges of the mesh, so
  // that its boundary lies on the surface there too.
  if (options.feature_angle < 180.0) domain.detect_features(options.feature_angle);
  namespace p = CGAL::parameters;
  const Criteria criteria(p::edge_size = size, p::facet_angle = 25, p::facet_size = size,
                          p::facet_distance = distance, p::cell_radius_edge_ratio = 3,
                          p::cell_size = size);
  // A manifold boundary (thin parts otherwise meet at an edge or a vertex,
  // and a surface like that bounds no solid for the metrics). No
  // perturbation or exudation: they only polish slivers and cost time. The
  // default random seed keeps the result deterministic.
  const Complex c3t3 =
      CGAL::make_mesh_3<Complex>(domain, criteria, p::no_perturb(), p::no_exude(), p::manifold());

  std::map<Triangulation::Vertex_handle, int> index;
  Mesh out;
  out.dim = 3;
  std::vector<Eigen::Vector3d> nodes;
  std::vector<Eigen::Vector4i> tets;
  for (auto c = c3t3.cells_in_complex_begin(); c != c3t3.cells_in_complex_end(); ++c) {
    Eigen::Vector4i t;
    for (int k = 0; k < 4; ++k) {
      const auto v = c->vertex(k);
      auto [it, added] = index.emplace(v, static_cast<int>(nodes.size()));
      if (added) {
        const auto& q = v->point().point();
        nodes.emplace_back(CGAL::to_double(q.x()), CGAL::to_double(q.y()), CGAL::to_double(q.z()));
      }
      t[k] = it->second;
    }
    Eigen::Matrix3d edges;
    for (int k = 0; k < 3; ++k)
      edges.col(k) = nodes[static_cast<size_t>(t[k + 1])] - nodes[static_cast<size_t>(t[0])];
    if (edges.determinant() < 0.0) std::swap(t[1], t[2]);
    tets.push_back(t);
  }
  if (tets.empty())
    throw InputError(
        "tetrahedralize: the mesher produced no tetrahedra (is the surface outward and free of "
        "self-intersections?)");
  out.nodes.resize(static_cast<Eigen::Index>(nodes.size()), 3);
  for (size_t v = 0; v < nodes.size(); ++v)
    out.nodes.row(static_cast<Eigen::Index>(v)) = nodes[v].transpose();
  out.elements.resize(static_cast<Eigen::Index>(tets.size()), 4);
  for (size_t e = 0; e < tets.size(); ++e)
    out.elements.row(static_cast<Eigen::Index>(e)) = tets[e].transpose();
  return out;
}

}  // namespace fiberfluid::fem

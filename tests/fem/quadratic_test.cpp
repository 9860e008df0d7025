// SPDX-License-Identifier: GPL-3.0-or-later
// Quadratic tetrahedra: their shape functions and quadrature, the meshes made
// of them, small-strain elasticity on them, and the nonlinear mixed form
// against the closed forms of a twisted and an inflated tube.
#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <map>
#include <set>

#include "fiberfluid/fem/closed_forms.hpp"
#include "fiberfluid/fem/fem.hpp"
#include "fiberfluid/fem/mesh_tools.hpp"
#include "fiberfluid/fem/tetrahedra.hpp"
#include "fiberfluid/util/error.hpp"

namespace fiberfluid::fem {
namespace {

double factorial(int n) { return n <= 1 ? 1.0 : n * factorial(n - 1); }

TEST(TetrahedronRule, IntegratesThePolynomialsOfItsDegreeExactly) {
  // The integral of x^a y^b z^c over the reference tetrahedron is
  // a! b! c! / (a + b + c + 3)!.
  for (int degree : {1, 2, 4, 6}) {
    const TetrahedronRule rule = tetrahedron_rule(degree);
    for (double w : rule.weights) EXPECT_GT(w, 0.0);
    for (int a = 0; a <= degree; ++a)
      for (int b = 0; a + b <= degree; ++b)
        for (int c = 0; a + b + c <= degree; ++c) {
          double sum = 0.0;
          for (size_t q = 0; q < rule.points.size(); ++q)
            sum += rule.weights[q] * std::pow(rule.points[q][0], a) *
                   std::pow(rule.points[q][1], b) * std::pow(rule.points[q][2], c);
          const double exact = factorial(a) * factorial(b) * factorial(c) / factorial(a + b + c + 3);
          EXPECT_NEAR(sum, exact, 1e-14) << degree << ": " << a << b << c;
        }
  }
}

TEST(QuadraticTetrahedron, ShapeFunctionsAreOneAtTheirNodeAndSumToOne) {
  std::vector<Eigen::Vector3d> nodes = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  for (const auto& edge : kTetrahedronEdges)
    nodes.push_back(0.5 * (nodes[static_cast<size_t>(edge[0])] + nodes[static_cast<size_t>(edge[1])]));
  Eigen::VectorXd N;
  Eigen::MatrixXd dN;
  for (size_t a = 0; a < nodes.size(); ++a) {
    tetrahedron_shape(10, nodes[a], &N, &dN);
    for (int b = 0; b < 10; ++b) EXPECT_NEAR(N[b], a == static_cast<size_t>(b) ? 1.0 : 0.0, 1e-15);
  }
  const Eigen::Vector3d xi(0.2, 0.15, 0.4), h(1e-7, -2e-7, 3e-7);
  tetrahedron_shape(10, xi, &N, &dN);
  EXPECT_NEAR(N.sum(), 1.0, 1e-15);
  EXPECT_LT(dN.colwise().sum().norm(), 1e-14);
  Eigen::VectorXd N_plus, N_minus;
  Eigen::MatrixXd unused;
  tetrahedron_shape(10, xi + h, &N_plus, &unused);
  tetrahedron_shape(10, xi - h, &N_minus, &unused);
  EXPECT_LT(((N_plus - N_minus) / 2.0 - dN * h).norm(), 1e-15);
  EXPECT_THROW(tetrahedron_shape(8, xi, &N, &dN), InputError);
}

Mesh quadratic_box(int cells) {
  return to_quadratic(to_simplices(
      structured_grid(Eigen::Vector3d(2.0, 1.0, 1.0), Eigen::Vector3i(2 * cells, cells, cells))));
}

TEST(QuadraticTetrahedra, ShareTheirMiddleNodesAndCloseTheirBoundary) {
  const Mesh linear =
      to_simplices(structured_grid(Eigen::Vector3d(2.0, 1.0, 1.0), Eigen::Vector3i(4, 2, 2)));
  const Mesh mesh = to_quadratic(linear);
  // Nodes: the corners and one per edge (Euler: V - E + F - T = 1 for a ball).
  std::set<std::vector<int>> faces;
  for (Eigen::Index e = 0; e < linear.elements.rows(); ++e)
    for (int skip = 0; skip < 4; ++skip) {
      std::vector<int> f;
      for (int k = 0; k < 4; ++k)
        if (k != skip) f.push_back(linear.elements(e, k));
      std::sort(f.begin(), f.end());
      faces.insert(f);
    }
  const int edges = mesh.num_nodes() - linear.num_nodes();
  EXPECT_EQ(linear.num_nodes() - edges + static_cast<int>(faces.size()) -
                static_cast<int>(linear.elements.rows()),
            1);
  // The boundary: each 6-node face in 4 triangles, closed, enclosing 2 m^3.
  const Boundary b = boundary(mesh);
  EXPECT_EQ(b.surface.F.rows(), 4 * boundary(linear).surface.F.rows());
  double volume = 0.0;
  for (Eigen::Index f = 0; f < b.surface.F.rows(); ++f) {
    const Eigen::Vector3d p = b.surface.V.row(b.surface.F(f, 0)),
                          q = b.surface.V.row(b.surface.F(f, 1)),
                          r = b.surface.V.row(b.surface.F(f, 2));
    volume += p.dot(q.cross(r)) / 6.0;
  }
  EXPECT_NEAR(volume, 2.0, 1e-12);
  EXPECT_THROW(node_measures(mesh), InputError);
}

// The generated tubes and shells are conforming (their boundary closes:
// each boundary edge between exactly two boundary triangles), hold their
// solid's volume, and put every quadratic boundary node on its surface.
TEST(QuadraticTetrahedra, TheTubeAndShellMeshesAreConformingAndOnTheirSurfaces) {
  ShellMeshSpec shell;
  shell.around = 3;
  shell.radial = 2;
  TubeMeshSpec tube;
  tube.radial = 2;
  tube.around = 9;
  tube.along = 2;
  for (int order : {1, 2}) {
    shell.order = tube.order = order;
    const double exact_volumes[2] = {M_PI / 6.0 * (1.0 - 0.125), M_PI * (1.0 - 0.25)};
    int which = 0;
    for (const Mesh& mesh : {shell_octant_mesh(shell), tube_mesh(tube)}) {
      const double exact = exact_volumes[which++];
      const Boundary b = boundary(mesh);
      std::map<std::pair<int, int>, int> edges;
      double volume = 0.0;
      for (Eigen::Index f = 0; f < b.surface.F.rows(); ++f) {
        for (int k = 0; k < 3; ++k) {
          const int p = b.surface.F(f, k), q = b.surface.F(f, (k + 1) % 3);
          ++edges[std::minmax(p, q)];
        }
        const Eigen::Vector3d x = b.surface.V.row(b.surface.F(f, 0)),
                              y = b.surface.V.row(b.surface.F(f, 1)),
                              z = b.surface.V.row(b.surface.F(f, 2));
        volume += x.dot(y.cross(z)) / 6.0;
      }
      for (const auto& [edge, count] : edges) EXPECT_EQ(count, 2) << order;
      double tets = 0.0;  // the corners' tetrahedra: all positive
      for (Eigen::Index e = 0; e < mesh.elements.rows(); ++e) {
        Eigen::Matrix3d D;
        for (int k = 0; k < 3; ++k)
          D.col(k) = (mesh.nodes.row(mesh.elements(e, k + 1)) - mesh.nodes.row(mesh.elements(e, 0))).transpose();
        EXPECT_GT(D.determinant(), 0.0);
        tets += D.determinant() / 6.0;
      }
      if (order == 1)  // the boundary of straight tetrahedra holds their volume
        EXPECT_NEAR(volume, tets, 1e-12);
      else  // the curved middle nodes bring the boundary closer to the solid
        EXPECT_LT(std::abs(volume - exact), 0.5 * std::abs(tets - exact));
    }
    // The shell's outer nodes on the unit sphere (its middle nodes too).
    const Mesh mesh = shell_octant_mesh(shell);
    int on_outer = 0;
    for (int v = 0; v < mesh.num_nodes(); ++v)
      if (std::abs(mesh.nodes.row(v).norm() - 1.0) < 1e-12) ++on_outer;
    EXPECT_EQ(on_outer, order == 1 ? 10 : 28);  // (3 + 1)(3 + 2)/2 and (6 + 1)(6 + 2)/2
  }
}

TEST(QuadraticTetrahedra, ReproducePureBendingExactlyWhereLinearOnesCannot) {
  // Pure bending of a bar along x (Timoshenko and Goodier, section 102):
  // u = kappa (x z, -nu y z, -(x^2 + nu (z^2 - y^2)) / 2), stress E kappa z
  // along x alone, no body force. Quadratic, so quadratic elements hold it
  // exactly: K u has no force at any interior node. Linear ones do not (on
  // a uniform grid their stencil happens to; the interior corners are moved).
  Material m;
  m.young = 1000.0;
  m.poisson = 0.3;
  const double kappa = 0.1, nu = m.poisson;
  for (int order : {1, 2}) {
    Mesh linear =
        to_simplices(structured_grid(Eigen::Vector3d(2.0, 1.0, 1.0), Eigen::Vector3i(4, 2, 2)));
    for (int v = 0; v < linear.num_nodes(); ++v) {
      const Eigen::RowVector3d p = linear.nodes.row(v);
      if ((p.array() > 1e-9).all() && (p.array() < Eigen::Array3d(2, 1, 1).transpose() - 1e-9).all())
        linear.nodes.row(v) += 0.1 * Eigen::RowVector3d(std::sin(7.0 * v), std::cos(5.0 * v), 0.5);
    }
    const Mesh mesh = order == 2 ? to_quadratic(linear) : linear;
    Eigen::VectorXd u(mesh.num_dofs());
    for (int v = 0; v < mesh.num_nodes(); ++v) {
      const double x = mesh.nodes(v, 0), y = mesh.nodes(v, 1) - 0.5, z = mesh.nodes(v, 2) - 0.5;
      u.segment<3>(3 * v) << kappa * x * z, -nu * kappa * y * z,
          -0.5 * kappa * (x * x + nu * (z * z - y * y));
    }
    const Eigen::VectorXd f = stiffness_matrix(mesh, m) * u;
    double interior = 0.0, scale = 0.0;
    for (int v = 0; v < mesh.num_nodes(); ++v) {
      const Eigen::RowVector3d p = mesh.nodes.row(v);
      scale = std::max(scale, f.segment<3>(3 * v).norm());
      if ((p.array() > 1e-9).all() && (p.array() < Eigen::Array3d(2, 1, 1).transpose() - 1e-9).all())
        interior = std::max(interior, f.segment<3>(3 * v).norm());
    }
    if (order == 2)
      EXPECT_LT(interior, 1e-12 * scale);
    else
      EXPECT_GT(interior, 1e-3 * scale);
  }
}

TEST(QuadraticTetrahedra, TheirMassAndGravityAddUpToTheBody) {
  const Mesh mesh = quadratic_box(1);
  Material m;
  m.density = 3.0;
  const Eigen::VectorXd f = body_forces(mesh, m, Eigen::Vector3d(0.0, 0.0, -2.0));
  double fz = 0.0;
  for (int v = 0; v < mesh.num_nodes(); ++v) fz += f[3 * v + 2];
  EXPECT_NEAR(fz, -2.0 * 3.0 * 2.0, 1e-12);  // g rho V
  const Eigen::SparseMatrix<double> M = mass_matrix(mesh, m);
  EXPECT_NEAR(Eigen::VectorXd::Ones(M.rows()).dot(M * Eigen::VectorXd::Ones(M.rows())),
              3.0 * 3.0 * 2.0, 1e-11);  // rho V per axis
}

HyperelasticMaterial nearly_incompressible() {
  HyperelasticMaterial m;
  m.kind = Hyperelastic::NeoHookeanNearlyIncompressible;
  m.young = 3.0;
  m.poisson = 0.4999;
  return m;
}

// The mixed form against Ogden's closed forms on the two coarsest meshes of
// experiments/fem_convergence (which runs four and prints the table): the
// error falls at second order or faster, and the finer is close already.
TEST(ClosedForms, ATwistedTubeAndInflatedTubeAndSphereConvergeAtSecondOrder) {
  HyperelasticOptions options;
  options.steps = 8;
  options.tolerance = 1e-8;
  options.mixed = true;
  const auto tube = [](int level, double length) {
    TubeMeshSpec t;
    t.radial = level;
    t.around = 12 * level;
    t.along = length == 0.5 ? level : 1;
    t.length = length;
    t.order = 2;
    return t;
  };
  const auto order = [](double coarse, double fine) { return std::log(coarse / fine) / std::log(2.0); };
  const ClosedFormRun twisted1 = tube_torsion(tube(1, 0.5), nearly_incompressible(), 1.0, options);
  const ClosedFormRun twisted2 = tube_torsion(tube(2, 0.5), nearly_incompressible(), 1.0, options);
  const ClosedFormRun inflated1 =
      tube_inflation(tube(1, 0.5), nearly_incompressible(), 2.0, options);
  const ClosedFormRun inflated2 =
      tube_inflation(tube(2, 0.25), nearly_incompressible(), 2.0, options);
  const auto shell = [](int level) {
    ShellMeshSpec s;
    s.around = 2 * level;
    s.radial = level;
    s.order = 2;
    return s;
  };
  const ClosedFormRun sphere1 = sphere_inflation(shell(1), nearly_incompressible(), 1.5, options);
  const ClosedFormRun sphere2 = sphere_inflation(shell(2), nearly_incompressible(), 1.5, options);
  for (const auto& [coarse, fine] : {std::pair{twisted1, twisted2}, std::pair{inflated1, inflated2},
                                     std::pair{sphere1, sphere2}})
    for (size_t k = 0; k < coarse.figures.size(); ++k) {
      const double e1 = coarse.figures[k].relative_error(), e2 = fine.figures[k].relative_error();
      EXPECT_GT(order(e1, e2), 2.0) << fine.figures[k].name << ": " << e1 << " then " << e2;
      EXPECT_LT(e2, fine.figures[k].name == "axial_force" ? 0.05 : 0.003) << fine.figures[k].name;
    }
  // Two Newton iterations a step: the mixed tangent is the exact one.
  EXPECT_LE(twisted2.newton_iterations, 3 * options.steps);
}

}  // namespace
}  // namespace fiberfluid::fem

namespace fiberfluid::fem {
namespace {

// Every unknown held leaves no system to solve (CHOLMOD crashed on the empty
// matrix): the answer is the held values, and their reactions.
TEST(QuadraticTetrahedra, ABodyHeldEverywhereIsItsHeldValues) {
  TubeMeshSpec tube;  // one cell across and along: every corner on a held surface
  tube.order = 1;
  HyperelasticOptions options;
  options.steps = 2;
  const ClosedFormRun run = tube_torsion(tube, nearly_incompressible(), 1.0, options);
  EXPECT_GT(run.figures[0].computed, run.figures[0].exact);  // locked, but solved
  Eigen::VectorXd u;
  Constraints all;
  const Mesh mesh = tube_mesh(tube);
  for (int d = 0; d < mesh.num_dofs(); ++d) all.hold(d, 0.001 * d);
  Material m;
  ASSERT_TRUE(solve_static(stiffness_matrix(mesh, m), Eigen::VectorXd::Zero(mesh.num_dofs()), all, &u).ok);
  EXPECT_DOUBLE_EQ(u[7], 0.007);
}

}  // namespace
}  // namespace fiberfluid::fem

// SPDX-License-Identifier: GPL-3.0-or-later
// The finite elements verified without the benchmarks paper: the patch
// test, the mass, and a cantilever against beam theory under refinement.
#include "fem/fem.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

namespace fiberfluid::fem {
namespace {

// A grid with its inner nodes moved off the lattice (elements stay convex).
Mesh distorted_grid(int dim) {
  Mesh mesh = structured_grid(Eigen::VectorXd::Ones(dim), Eigen::VectorXi::Constant(dim, 3));
  for (int v = 0; v < mesh.num_nodes(); ++v) {
    const Eigen::RowVectorXd p = mesh.nodes.row(v);
    if ((p.array() > 1e-9).all() && (p.array() < 1.0 - 1e-9).all())
      for (int a = 0; a < dim; ++a) mesh.nodes(v, a) += 0.07 * std::sin(3.0 * v + 1.7 * a);
  }
  return mesh;
}

bool on_boundary(const Eigen::RowVectorXd& p) {
  return (p.array() < 1e-9).any() || (p.array() > 1.0 - 1e-9).any();
}

// Any linear displacement field is reproduced exactly: the boundary nodes
// held at it, the inner ones must follow with no force.
TEST(Fem, PassesThePatchTest) {
  for (int dim : {2, 3}) {
    for (PlaneModel plane : {PlaneModel::Strain, PlaneModel::Stress}) {
      if (dim == 3 && plane == PlaneModel::Stress) continue;
      const Mesh mesh = distorted_grid(dim);
      Material m;
      m.young = 5000.0;
      m.poisson = 0.45;
      m.plane = plane;
      Eigen::MatrixXd A = Eigen::MatrixXd::Random(dim, dim) * 0.01;
      Eigen::VectorXd c = Eigen::VectorXd::Random(dim) * 0.01;
      Constraints held;
      Eigen::VectorXd exact(mesh.num_dofs());
      for (int v = 0; v < mesh.num_nodes(); ++v) {
        const Eigen::VectorXd u = A * mesh.nodes.row(v).transpose() + c;
        exact.segment(dim * v, dim) = u;
        if (on_boundary(mesh.nodes.row(v)))
          for (int a = 0; a < dim; ++a) held.hold(dim * v + a, u[a]);
      }
      ASSERT_LT(static_cast<int>(held.dofs.size()), mesh.num_dofs());  // inner nodes exist
      Eigen::VectorXd u;
      const solve::Status s =
          solve_static(stiffness_matrix(mesh, m), Eigen::VectorXd::Zero(mesh.num_dofs()), held, &u);
      ASSERT_TRUE(s.ok) << s.message;
      EXPECT_LT((u - exact).cwiseAbs().maxCoeff(), 1e-14) << dim << "D";
      // A rigid motion costs no energy: K annihilates it.
      Eigen::VectorXd shift(mesh.num_dofs());
      for (int v = 0; v < mesh.num_nodes(); ++v) shift.segment(dim * v, dim) = c;
      EXPECT_LT((stiffness_matrix(mesh, m) * shift).norm(), 1e-10 * m.young);
    }
  }
}

TEST(Fem, MassMatricesSumToTheTotalMass) {
  for (int dim : {2, 3}) {
    const Mesh mesh = distorted_grid(dim);  // a unit square or cube, inner nodes moved
    Material m;
    m.density = 1140.0;
    const Eigen::SparseMatrix<double> M = mass_matrix(mesh, m);
    // Each component carries the whole mass once.
    EXPECT_NEAR(M.sum(), dim * 1140.0, 1e-9) << dim;
    const Eigen::VectorXd lumped = lumped_mass(mesh, m);
    EXPECT_NEAR(lumped.sum(), dim * 1140.0, 1e-9);
    EXPECT_GT(lumped.minCoeff(), 0.0);
    EXPECT_LT((Eigen::MatrixXd(M) - Eigen::MatrixXd(M).transpose()).norm(), 1e-12);
    // Gravity's consistent forces sum to the weight.
    const Eigen::VectorXd g = Eigen::VectorXd::Unit(dim, dim - 1) * -9.81;
    const Eigen::VectorXd f = body_forces(mesh, m, g);
    double weight = 0.0;
    for (int v = 0; v < mesh.num_nodes(); ++v) weight += f[dim * v + dim - 1];
    EXPECT_NEAR(weight, -9.81 * 1140.0, 1e-8);
  }
}

// Tip deflection of a cantilever (clamped at x = 0, a shear load P on its
// end face), against Timoshenko's beam: d = P L^3 / (3 E I) + P L / (k G A).
double cantilever_tip(int refinement, double* theory) {
  const double L = 1.0, h = 0.1, E = 1e6, P = 1.0;
  const Mesh mesh = structured_grid(Eigen::Vector3d(L, h, h),
                                    Eigen::Vector3i(10 * refinement, refinement, refinement));
  Material m;
  m.young = E;
  m.poisson = 0.0;  // no Poisson coupling at the clamp: the beam theory's setting
  Constraints held;
  Eigen::VectorXd f = Eigen::VectorXd::Zero(mesh.num_dofs());
  const int n = refinement;
  for (int v = 0; v < mesh.num_nodes(); ++v) {
    const Eigen::RowVectorXd p = mesh.nodes.row(v);
    if (p[0] < 1e-12)
      for (int a = 0; a < 3; ++a) held.hold(3 * v + a, 0.0);
    if (p[0] > L - 1e-12) {  // a uniform traction, lumped by each node's face share
      const auto share = [&](double s) { return (s < 1e-12 || s > h - 1e-12) ? 0.5 : 1.0; };
      f[3 * v + 2] = -P * share(p[1]) * share(p[2]) / (n * n);
    }
  }
  Eigen::VectorXd u;
  const solve::Status s = solve_static(stiffness_matrix(mesh, m), f, held, &u);
  EXPECT_TRUE(s.ok) << s.message;
  double tip = 0.0;
  int count = 0;
  for (int v = 0; v < mesh.num_nodes(); ++v)
    if (mesh.nodes(v, 0) > L - 1e-12) {
      tip += u[3 * v + 2];
      ++count;
    }
  const double I = h * h * h * h / 12.0, A = h * h, G = E / 2.0;
  *theory = -(P * L * L * L / (3.0 * E * I) + P * L / (5.0 / 6.0 * G * A));
  return tip / count;
}

TEST(Fem, CantileverConvergesToBeamTheory) {
  std::vector<double> errors;
  double theory = 0.0;
  for (int r : {1, 2, 4}) {
    const double tip = cantilever_tip(r, &theory);
    errors.push_back(std::abs(tip - theory) / std::abs(theory));
    std::printf("refinement %d: tip %.6e, theory %.6e, error %.4f\n", r, tip, theory, errors.back());
  }
  for (size_t k = 1; k < errors.size(); ++k) EXPECT_LT(errors[k], errors[k - 1]);
  const double order = std::log2(errors[1] / errors[2]);
  std::printf("observed order %.2f\n", order);
  EXPECT_GT(order, 1.5);
  EXPECT_LT(errors.back(), 0.05);
}

TEST(Fem, TooFewSupportsIsAStatus) {
  const Mesh mesh = structured_grid(Eigen::Vector2d(1, 1), Eigen::Vector2i(2, 2));
  Eigen::VectorXd u;
  const solve::Status s = solve_static(stiffness_matrix(mesh, Material{}),
                                       Eigen::VectorXd::Ones(mesh.num_dofs()), Constraints{}, &u);
  EXPECT_FALSE(s.ok);
  EXPECT_NE(s.message.find("too few supports"), std::string::npos) << s.message;
}

}  // namespace
}  // namespace fiberfluid::fem

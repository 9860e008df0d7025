// SPDX-License-Identifier: GPL-3.0-or-later
#include "fiberfluid/fem/hyperelastic.hpp"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <string>

#include "fiberfluid/fem/mesh_tools.hpp"

namespace fiberfluid::fem {
namespace {

HyperelasticMaterial material(Hyperelastic kind) {
  HyperelasticMaterial m;
  m.kind = kind;
  m.young = 1000.0;
  m.poisson = 0.4;
  return m;
}

const Hyperelastic kKinds[] = {Hyperelastic::NeoHookean,
                               Hyperelastic::NeoHookeanNearlyIncompressible};

// A general deformation gradient with J > 0, stretched, sheared and rotated.
Eigen::Matrix3d some_deformation() {
  Eigen::Matrix3d F;
  F << 1.3, 0.2, -0.1, 0.05, 0.8, 0.3, -0.2, 0.1, 1.1;
  return F;
}

// A unit cube of 3 x 3 x 3 hexahedra split into tetrahedra.
Mesh unit_cube(int cells = 3) {
  return to_simplices(structured_grid(Eigen::Vector3d::Ones(), Eigen::Vector3i::Constant(cells)));
}

TEST(Hyperelastic, StressIsTheEnergysGradientAndTheTangentTheStresss) {
  const Eigen::Matrix3d F = some_deformation();
  for (Hyperelastic kind : kKinds) {
    const HyperelasticMaterial m = material(kind);
    const Eigen::Matrix3d P = first_piola_stress(m, F);
    const Eigen::Matrix<double, 9, 9> A = stress_tangent(m, F);
    const double h = 1e-6;
    for (int l = 0; l < 9; ++l) {
      Eigen::Matrix3d dF = Eigen::Matrix3d::Zero();
      dF(l % 3, l / 3) = h;
      const double dW = (strain_energy(m, F + dF) - strain_energy(m, F - dF)) / (2 * h);
      EXPECT_NEAR(P(l % 3, l / 3), dW, 1e-6 * P.norm()) << to_string(kind) << " " << l;
      const Eigen::Matrix3d dP =
          (first_piola_stress(m, F + dF) - first_piola_stress(m, F - dF)) / (2 * h);
      for (int k = 0; k < 9; ++k)
        EXPECT_NEAR(A(k, l), dP(k % 3, k / 3), 1e-6 * A.norm()) << to_string(kind) << k << l;
    }
    // A hyperelastic tangent is symmetric (major symmetry).
    EXPECT_LT((A - A.transpose()).norm(), 1e-10 * A.norm());
  }
}

TEST(Hyperelastic, SmallStrainIsLinearElasticity) {
  // P at F = I + eps H is, to first order, the linear stress of the
  // symmetric part of H: lambda tr(e) I + 2 mu e (kappa - 2 mu / 3 for lambda).
  Eigen::Matrix3d H;
  H << 0.3, -0.2, 0.5, 0.1, -0.4, 0.2, 0.7, 0.1, 0.2;
  const double eps = 1e-7;
  const Eigen::Matrix3d e = 0.5 * eps * (H + H.transpose());
  for (Hyperelastic kind : kKinds) {
    const HyperelasticMaterial m = material(kind);
    const Eigen::Matrix3d linear =
        m.lame_lambda() * e.trace() * Eigen::Matrix3d::Identity() + 2.0 * m.shear_modulus() * e;
    const Eigen::Matrix3d P = first_piola_stress(m, Eigen::Matrix3d::Identity() + eps * H);
    EXPECT_LT((P - linear).norm(), 1e-5 * linear.norm()) << to_string(kind);
  }
}

TEST(Hyperelastic, ARigidRotationHasNoEnergyAndNoForce) {
  const Mesh mesh = unit_cube(2);
  const Eigen::Matrix3d R =
      Eigen::AngleAxisd(1.2, Eigen::Vector3d(1.0, -2.0, 0.5).normalized()).toRotationMatrix();
  Eigen::VectorXd u(mesh.num_dofs());
  for (int v = 0; v < mesh.num_nodes(); ++v)
    u.segment<3>(3 * v) = R * mesh.nodes.row(v).transpose() - mesh.nodes.row(v).transpose() +
                          Eigen::Vector3d(0.3, -1.0, 2.0);
  for (Hyperelastic kind : kKinds) {
    const HyperelasticMaterial m = material(kind);
    EXPECT_NEAR(total_strain_energy(mesh, m, u), 0.0, 1e-10);
    EXPECT_LT(internal_forces(mesh, m, u).cwiseAbs().maxCoeff(), 1e-10);
  }
}

// Both element orders: linear tetrahedra, and quadratic ones on a curved
// tube (their forces carry the mean dilatation's coupling of the points).
TEST(Hyperelastic, ForcesAndTangentMatchFiniteDifferences) {
  TubeMeshSpec tube;
  tube.around = 5;
  tube.order = 2;
  for (const Mesh& mesh : {unit_cube(2), tube_mesh(tube)}) {
    Eigen::VectorXd u(mesh.num_dofs());
    for (int v = 0; v < mesh.num_nodes(); ++v) {  // a smooth, large deformation
      const Eigen::Vector3d x = mesh.nodes.row(v).transpose();
      u.segment<3>(3 * v) << 0.2 * x[1] * x[1], -0.15 * x[0] * x[2], 0.1 * std::sin(x[0] + x[1]);
    }
    for (Hyperelastic kind : kKinds) {
      HyperelasticMaterial m = material(kind);
      m.poisson = 0.49;  // a bulk modulus far above the shear modulus
      const std::string what =
          to_string(kind) + ", " + std::to_string(mesh.elements.cols()) + " nodes per element";
      const Eigen::VectorXd f = internal_forces(mesh, m, u);
      const Eigen::MatrixXd K = Eigen::MatrixXd(tangent_stiffness(mesh, m, u));
      const double h = 1e-6;
      for (int d = 0; d < mesh.num_dofs(); d += 7) {
        Eigen::VectorXd up = u, down = u;
        up[d] += h;
        down[d] -= h;
        const double dE =
            (total_strain_energy(mesh, m, up) - total_strain_energy(mesh, m, down)) / (2 * h);
        EXPECT_NEAR(f[d], dE, 1e-6 * f.norm()) << what << " " << d;
        const Eigen::VectorXd column =
            (internal_forces(mesh, m, up) - internal_forces(mesh, m, down)) / (2 * h);
        EXPECT_LT((K.col(d) - column).norm(), 1e-6 * K.norm()) << what << " " << d;
      }
      EXPECT_LT((K - K.transpose()).norm(), 1e-10 * K.norm()) << what;
    }
  }
}

// The unit cube on rollers (x = 0 held in x, y = 0 in y, z = 0 in z), its
// face x = 1 pulled to x = lambda1: a homogeneous uniaxial stretch, exact on
// linear tetrahedra. The lateral stretch lambda2 solves P22 = 0; the force on
// the face is P11 times its reference area 1.
struct Uniaxial {
  double lateral;  // lambda2
  double force;    // P11
};

// The principal nominal stress P_i of a diagonal F = diag(l1, l2, l2),
// written out from the energies (Bonet and Wood, section 6.4.3 and 6.5):
// compressible mu (l_i - 1 / l_i) + lambda ln J / l_i; nearly incompressible
// mu J^(-2/3) (l_i - I1 / (3 l_i)) + kappa J (J - 1) / l_i.
double principal_stress(const HyperelasticMaterial& m, double l1, double l2, int i) {
  const double J = l1 * l2 * l2, I1 = l1 * l1 + 2.0 * l2 * l2, l = i == 0 ? l1 : l2;
  const double mu = m.shear_modulus();
  if (m.kind == Hyperelastic::NeoHookean)
    return mu * (l - 1.0 / l) + m.lame_lambda() * std::log(J) / l;
  return mu * std::pow(J, -2.0 / 3.0) * (l - I1 / (3.0 * l)) + m.bulk_modulus() * J * (J - 1.0) / l;
}

Uniaxial closed_form_uniaxial(const HyperelasticMaterial& m, double lambda1) {
  double low = 0.1, high = 1.0;  // P22 rises with l2: bisect P22 = 0
  for (int it = 0; it < 200; ++it) {
    const double mid = 0.5 * (low + high);
    (principal_stress(m, lambda1, mid, 1) > 0.0 ? high : low) = mid;
  }
  const double l2 = 0.5 * (low + high);
  return {l2, principal_stress(m, lambda1, l2, 0)};
}

// The two element kinds the FEM reference offers: linear tetrahedra in the
// displacement form, and quadratic ones with a linear pressure (P2-P1). A
// homogeneous deformation lies in both spaces, so both must hold it exactly
// on any mesh (the large-strain patch test): no order of convergence to
// observe, the error is Newton's tolerance.
struct ElementKind {
  const char* name;
  int order;
};
const ElementKind kElements[] = {{"P1", 1}, {"P2-P1", 2}};

Mesh cube_of(const ElementKind& element, int cells) {
  const Mesh linear = unit_cube(cells);
  return element.order == 2 ? to_quadratic(linear) : linear;
}

HyperelasticOptions options_of(const ElementKind& element, int steps) {
  HyperelasticOptions options;
  options.steps = steps;
  options.mixed = element.order == 2;
  return options;
}

TEST(Hyperelastic, UniaxialStretchToTwiceTheLengthMatchesTheClosedForm) {
  const double lambda1 = 2.0;  // 100% stretch
  for (const ElementKind& element : kElements) {
    const Mesh mesh = cube_of(element, 2);
    const LoadPath path = [&](int step) {
      LoadState state;
      state.forces = Eigen::VectorXd::Zero(mesh.num_dofs());
      for (int v = 0; v < mesh.num_nodes(); ++v)
        for (int a = 0; a < 3; ++a) {
          if (mesh.nodes(v, a) < 1e-12) state.held.hold(3 * v + a, 0.0);
          if (a == 0 && mesh.nodes(v, 0) > 1.0 - 1e-12)
            state.held.hold(3 * v, (lambda1 - 1.0) * step / 10.0);
        }
      return state;
    };
    for (Hyperelastic kind : kKinds) {
      const std::string label = std::string(element.name) + ", " + to_string(kind);
      const HyperelasticMaterial m = material(kind);
      HyperelasticSolution solution;
      const linalg::Status status =
          solve_hyperelastic(mesh, m, path, options_of(element, 10), &solution);
      ASSERT_TRUE(status.ok) << label << ": " << status.message;
      ASSERT_EQ(solution.path.size(), 10u);
      const Uniaxial exact = closed_form_uniaxial(m, lambda1);
      // The lateral stretch at the corner (1, 1, 1), and the pulling force
      // (the reactions Newton converged with: the mixed form's include p).
      int corner = 0;
      for (int v = 0; v < mesh.num_nodes(); ++v)
        if ((mesh.nodes.row(v).array() > 1.0 - 1e-12).all()) corner = v;
      EXPECT_NEAR(1.0 + solution.u[3 * corner + 1], exact.lateral, 1e-8) << label;
      EXPECT_NEAR(1.0 + solution.u[3 * corner + 2], exact.lateral, 1e-8) << label;
      double pull = 0.0;
      for (int v = 0; v < mesh.num_nodes(); ++v)
        if (mesh.nodes(v, 0) > 1.0 - 1e-12) pull += solution.forces[3 * v];
      EXPECT_NEAR(pull, exact.force, 1e-8 * exact.force) << label;
      // Far from the small-strain answer E (lambda1 - 1): the nominal stress
      // of a neo-Hookean solid softens in tension.
      EXPECT_LT(exact.force, 0.7 * m.young) << label;
    }
  }
}

TEST(Hyperelastic, SimpleShearGivesShearStressMuGamma) {
  // Every boundary node on the simple shear x += gamma y; the interior nodes
  // free. They stay on it, and the force on the top face y = 1 along x is
  // P12 = mu gamma (both forms: J = 1), the normal one P22: 0 for the
  // compressible form, -mu gamma^2 / 3 for the nearly incompressible one.
  const double gamma = 0.5;
  for (const ElementKind& element : kElements) {
    const Mesh mesh = cube_of(element, element.order == 2 ? 2 : 3);
    const auto on_boundary = [&](int v) {
      return (mesh.nodes.row(v).array() < 1e-12).any() ||
             (mesh.nodes.row(v).array() > 1.0 - 1e-12).any();
    };
    const LoadPath path = [&](int step) {
      LoadState state;
      state.forces = Eigen::VectorXd::Zero(mesh.num_dofs());
      for (int v = 0; v < mesh.num_nodes(); ++v)
        if (on_boundary(v))
          for (int a = 0; a < 3; ++a)
            state.held.hold(3 * v + a, a == 0 ? gamma * mesh.nodes(v, 1) * step / 4.0 : 0.0);
      return state;
    };
    for (Hyperelastic kind : kKinds) {
      const std::string label = std::string(element.name) + ", " + to_string(kind);
      const HyperelasticMaterial m = material(kind);
      HyperelasticSolution solution;
      ASSERT_TRUE(solve_hyperelastic(mesh, m, path, options_of(element, 4), &solution).ok) << label;
      for (int v = 0; v < mesh.num_nodes(); ++v)
        EXPECT_NEAR(solution.u[3 * v], gamma * mesh.nodes(v, 1), 1e-9) << label;
      double shear = 0.0, normal = 0.0;
      for (int v = 0; v < mesh.num_nodes(); ++v)
        if (mesh.nodes(v, 1) > 1.0 - 1e-12)
          shear += solution.forces[3 * v], normal += solution.forces[3 * v + 1];
      const double mu = m.shear_modulus();
      EXPECT_NEAR(shear, mu * gamma, 1e-9 * mu) << label;
      const double expected_normal =
          kind == Hyperelastic::NeoHookean ? 0.0 : -mu * gamma * gamma / 3.0;
      EXPECT_NEAR(normal, expected_normal, 1e-9 * mu) << label;
    }
  }
}

TEST(Hyperelastic, AnUnsolvableStepIsAStatusNamingIt) {
  // No supports: the tangent is singular on every free unknown.
  const Mesh mesh = unit_cube(1);
  const LoadPath path = [&](int) {
    LoadState state;
    state.forces = Eigen::VectorXd::Constant(mesh.num_dofs(), 1.0);
    return state;
  };
  HyperelasticOptions options;
  options.steps = 2;
  options.max_step_cuts = 1;
  HyperelasticSolution solution;
  const linalg::Status status =
      solve_hyperelastic(mesh, material(Hyperelastic::NeoHookean), path, options, &solution);
  ASSERT_FALSE(status.ok);
  EXPECT_EQ(status.message.rfind("fem: step 1: ", 0), 0u) << status.message;
  EXPECT_TRUE(solution.u.allFinite());
}

}  // namespace
}  // namespace fiberfluid::fem

// SPDX-License-Identifier: GPL-3.0-or-later
// The Newton scheme's equations: the tangent against central finite
// differences for every law, the reference tangent against the paper's A, and
// the parameter derivatives.
#include "fiberfluid/model/equilibrium.hpp"

#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include <algorithm>
#include <random>

#include "fiberfluid/geom/area_vectors.hpp"
#include "fiberfluid/geom/generators.hpp"
#include "fiberfluid/geom/horizon.hpp"
#include "fiberfluid/geom/mesh_io.hpp"
#include "fiberfluid/model/assembly.hpp"
#include "fiberfluid/model/fiber_network.hpp"
#include "fiberfluid/model/fiber_system.hpp"
#include "fiberfluid/model/loads.hpp"
#include "fiberfluid/model/reference/dense_assembly.hpp"
#include "fiberfluid/util/error.hpp"
#include "model/model_fixtures.hpp"
#include "test_support.hpp"

namespace fiberfluid::model {
namespace {

using namespace fiberfluid::model::reference;  // the oracle

using testing::small_sphere;

std::vector<FiberLaw> every_law() {
  return {FiberLaw::constant(3000.0), FiberLaw::exponential(3000.0, 4.0),
          FiberLaw::bilinear(3000.0, 1500.0),
          FiberLaw::tabulated({-0.5, -0.1, 0.0, 0.05, 0.2, 1.0},
                              {-900.0, -250.0, 0.0, 150.0, 800.0, 9000.0})};
}

using testing::random_state;
using testing::stored_product_matches;

using testing::finite_difference_tangent;

// The exact hydrostatic load's tangent (its faces turning and its pressures
// changing with depth), with both kinematics.
TEST(Equilibrium, TheExactHydrostaticLoadsTangentMatchesCentralDifferences) {
  for (FiberKinematics kinematics : kAllKinematics) {
    SCOPED_TRACE(kinematics_name(kinematics));
    const Model m =
        small_sphere(FiberLaw::exponential(3000.0, 4.0), kinematics, Load::Integration::Exact);
    const Equilibrium eq(m);
    const Eigen::VectorXd x = random_state(m, 8);
    const std::vector<double> factors = {0.7, 0.4};
    const Eigen::MatrixXd J = eq.tangent(x, factors);
    const Eigen::MatrixXd fd = finite_difference_tangent(eq, x, factors);
    EXPECT_LT((J - fd).norm() / fd.norm(), 1e-6);
    const Eigen::VectorXd v = random_state(m, 18, 1.0);
    EXPECT_LT((eq.tangent_product(x, factors, v) - J * v).norm(), 1e-10 * (J * v).norm());
    // The paper's scheme and Newton's put the same exact load on the reference.
    const Eigen::VectorXd zero = Eigen::VectorXd::Zero(m.num_unknowns());
    const Eigen::MatrixXd S =
        eq.area_constant() * geom::summed_face_area_vectors(m.surface.V, m.surface.F);
    const Eigen::VectorXd B = load_vector(m, m.surface.V, S, factors);
    const Eigen::VectorXd F = eq.external_forces(zero, factors);
    EXPECT_LT((B - F).norm(), 1e-12 * F.norm());
  }
}

TEST(Equilibrium, TangentMatchesCentralDifferencesForEveryLawAndKinematics) {
  for (FiberKinematics kinematics : kAllKinematics)
    for (const FiberLaw& law : every_law()) {
      SCOPED_TRACE(kinematics_name(kinematics));
      const Model m = small_sphere(law, kinematics);
      const Equilibrium eq(m);
      for (unsigned seed : {1u, 2u, 3u}) {
        const Eigen::VectorXd x = random_state(m, seed);
        const std::vector<double> factors = {0.7, 0.4};
        const Eigen::MatrixXd J = eq.tangent(x, factors);
        const Eigen::MatrixXd fd = finite_difference_tangent(eq, x, factors);
        const double error = (J - fd).norm() / fd.norm();
        EXPECT_LT(error, 1e-6) << law.name() << " seed " << seed;
        // The matrix-free product is the same operator.
        const Eigen::VectorXd v = random_state(m, seed + 10, 1.0);
        EXPECT_LT((eq.tangent_product(x, factors, v) - J * v).norm(), 1e-10 * (J * v).norm())
            << law.name();
        EXPECT_TRUE(stored_product_matches(eq.linearize(x, factors).apply(v), J, v)) << law.name();
      }
    }
}

// A horizon of 1.2 (the sphere's radius is 1) with the conical influence
// 1 - L / 1.2: every pair's weight and every count change with L, and the
// tangent, the matrix-free product and the stored operator stay one operator.
TEST(Equilibrium, TangentMatchesCentralDifferencesWithAConicalInfluence) {
  for (FiberKinematics kinematics : kAllKinematics)
    for (const FiberLaw& law : {FiberLaw::constant(3000.0), FiberLaw::exponential(3000.0, 4.0)}) {
      SCOPED_TRACE(kinematics_name(kinematics));
      Model m = small_sphere(law, kinematics);
      m.fibers = std::make_shared<const geom::FiberMask>(geom::horizon_fibers(m.surface, 1.2));
      m.influence = {Influence::Kind::Conical, 1.2};
      const Equilibrium eq(m);
      const Eigen::VectorXd x = random_state(m, 5);
      const std::vector<double> factors = {0.7, 0.4};
      const Eigen::MatrixXd J = eq.tangent(x, factors);
      const Eigen::MatrixXd fd = finite_difference_tangent(eq, x, factors);
      EXPECT_LT((J - fd).norm() / fd.norm(), 1e-6) << law.name();
      const Eigen::VectorXd v = random_state(m, 15, 1.0);
      EXPECT_LT((eq.tangent_product(x, factors, v) - J * v).norm(), 1e-10 * (J * v).norm());
      EXPECT_TRUE(stored_product_matches(eq.linearize(x, factors).apply(v), J, v));
      // The influence changes the answer: not the constant influence's residual.
      Model constant = m;
      constant.influence = {};
      EXPECT_GT((Equilibrium(constant).residual(x, factors) - eq.residual(x, factors)).norm(),
                1e-3 * eq.residual(x, factors).norm());
    }
}

// With a conical influence the three places that weigh the pairs agree: the
// Newton kernels (DeformedPairs, by each row's reference length), the
// linear system's rows (PairFactors) and its tiled product (BulkPairs). For
// a constant law the vector spring's forces are K u with the same K.
TEST(Equilibrium, AConicalInfluenceWeighsAlikeInEveryKernel) {
  Model m = small_sphere(FiberLaw::constant(3000.0));
  m.fibers = std::make_shared<const geom::FiberMask>(geom::horizon_fibers(m.surface, 1.2));
  m.influence = {Influence::Kind::Conical, 1.2};
  const Equilibrium eq(m);
  const Eigen::VectorXd x = random_state(m, 9, 0.2);
  const int n = m.num_vertices();
  const Eigen::MatrixXd U = displacements(m, x);
  const FiberSystem system(m, m.surface.V, BoundaryMethod::Elimination, 1e9);
  std::vector<int> all(static_cast<size_t>(n));
  for (int v = 0; v < n; ++v) all[static_cast<size_t>(v)] = v;
  const Eigen::MatrixXd rows = system.unreduced_rows(all, U, 0.0);
  const Eigen::MatrixXd bulk = system.bulk_product(U);
  const Eigen::MatrixXd surface = system.surface_laplacian() * U;
  const Eigen::MatrixXd forces = eq.fiber_forces(x);
  for (int a = 0; a < 3; ++a) {
    const Eigen::VectorXd tiled =
        system.young(a) * bulk.col(a) + system.surface_tension() * surface.col(a);
    EXPECT_LT((forces.col(a) - rows.col(a)).norm(), 1e-11 * rows.col(a).norm()) << a;
    EXPECT_LT((tiled - rows.col(a)).norm(), 1e-11 * rows.col(a).norm()) << a;
  }
}

// The factors of a conical influence, by hand on four points along the axes:
// each count is the sum of its pairs' omega = 1 - L / delta, each factor
// omega_ij / (c_i + c_j), and a pair beyond the horizon weighs nothing.
TEST(PairFactors, AConicalInfluenceWeighsEachPairAndEachCount) {
  Eigen::MatrixXd S(4, 3);
  S << 0, 0, 0, 1, 0, 0, 0, 2, 0, 0, 0, 3;
  const Influence conical{Influence::Kind::Conical, 4.0};
  const PairFactors factors(nullptr, ConnectionCount::Symmetric, 4, conical, &S);
  const auto omega = [&](int i, int j) { return 1.0 - (S.row(i) - S.row(j)).norm() / 4.0; };
  const std::vector<double> counts = factors.vertex_counts();
  for (int i = 0; i < 4; ++i) {
    double expected = 0.0;
    for (int j = 0; j < 4; ++j)
      if (j != i) expected += omega(i, j);
    EXPECT_NEAR(counts[static_cast<size_t>(i)], expected, 1e-15);
  }
  std::vector<double> row(4);
  factors.row(1, row.data());
  EXPECT_EQ(row[1], 0.0);
  for (int j : {0, 2, 3})
    EXPECT_NEAR(row[static_cast<size_t>(j)],
                omega(1, j) / (counts[1] + counts[static_cast<size_t>(j)]), 1e-15);
  // A pair beyond the horizon weighs nothing.
  const PairFactors short_reach(nullptr, ConnectionCount::Symmetric, 4,
                                {Influence::Kind::Conical, 2.5}, &S);
  short_reach.row(0, row.data());
  EXPECT_EQ(row[3], 0.0);  // |s_0 - s_3| = 3 > 2.5
  EXPECT_GT(row[2], 0.0);  // 2 < 2.5
}

// The area count: c_i = sum_j omega_ij |S_j| / |S_i|, the area the fibers at
// i reach in units of its own. Where every vertex has the same area it is the
// symmetric count n_i; where areas differ, each pair's weight makes the force
// on i |S_i| times the area-weighted mean over what its fibers reach.
TEST(PairFactors, TheAreaCountWeighsEachPartnerByItsArea) {
  Eigen::MatrixXd S(4, 3);
  S << 0, 0, 0, 1, 0, 0, 0, 2, 0, 0, 0, 3;
  Eigen::VectorXd area(4);
  area << 1.0, 2.0, 0.5, 4.0;
  const Influence conical{Influence::Kind::Conical, 4.0};
  const PairFactors factors(nullptr, ConnectionCount::Area, 4, conical, &S, area);
  const auto omega = [&](int i, int j) { return 1.0 - (S.row(i) - S.row(j)).norm() / 4.0; };
  const std::vector<double> counts = factors.vertex_counts();
  for (int i = 0; i < 4; ++i) {
    double expected = 0.0;
    for (int j = 0; j < 4; ++j)
      if (j != i) expected += omega(i, j) * area[j] / area[i];
    EXPECT_NEAR(counts[static_cast<size_t>(i)], expected, 1e-14);
  }
  std::vector<double> row(4);
  factors.row(2, row.data());
  for (int j : {0, 1, 3})
    EXPECT_NEAR(row[static_cast<size_t>(j)],
                omega(2, j) / (counts[2] + counts[static_cast<size_t>(j)]), 1e-15);
  EXPECT_NEAR(factors.factor(2, 3), row[3], 1e-15);
  // Equal areas: the symmetric count, pair for pair (with and without a mask).
  const Eigen::VectorXd equal = Eigen::VectorXd::Constant(4, 0.7);
  const PairFactors by_area(nullptr, ConnectionCount::Area, 4, Influence{}, &S, equal);
  for (double c : by_area.vertex_counts()) EXPECT_NEAR(c, 3.0, 1e-14);
  // Without the areas it cannot count.
  EXPECT_THROW(PairFactors(nullptr, ConnectionCount::Area, 4, Influence{}, &S),
               std::invalid_argument);
  // A vertex whose area vectors cancel cannot be weighed: named, not divided by.
  Eigen::VectorXd flat = equal;
  flat[2] = 0.0;
  try {
    PairFactors(nullptr, ConnectionCount::Area, 4, Influence{}, &S, flat);
    ADD_FAILURE() << "no error for a vertex without area";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("vertex 2 has no area vector"), std::string::npos)
        << e.what();
  }
}

// On a real mesh the model's factors count by its reference |S_i|, and the
// residual, tangent and the linear system agree on them (one PairFactors).
TEST(PairFactors, TheAreaCountOfAModelUsesItsReferenceAreas) {
  Model m;
  m.surface = geom::cylinder(0.02, 0.18, 9, 8);
  m.connection_count = ConnectionCount::Area;
  const PairFactors factors(m);
  const Eigen::VectorXd area = geom::vertex_area_vectors(m.surface.V, m.surface.F).magnitude;
  const std::vector<double> counts = factors.vertex_counts();
  for (int i : {0, 17, m.num_vertices() - 1}) {
    double expected = 0.0;
    for (int j = 0; j < m.num_vertices(); ++j)
      if (j != i) expected += area[j] / area[i];
    EXPECT_NEAR(counts[static_cast<size_t>(i)], expected, 1e-12 * expected);
  }
}

TEST(Equilibrium, TangentMatchesCentralDifferencesIn2D) {
  for (FiberKinematics kinematics : kAllKinematics) {
    SCOPED_TRACE(kinematics_name(kinematics));
    Model m = testing::paper_rectangle_model();
    m.material.kinematics = kinematics;
    m.surface = geom::polygon(
        (Eigen::MatrixXd(6, 2) << 15, 20, 18, 0, 15, -20, -15, -20, -18, 0, -15, 20).finished());
    m.material.law = FiberLaw::exponential(360.0, 3.0);
    m.material.surface_tension = 20.0;
    Load gravity;
    gravity.kind = Load::Kind::Hydrostatic;
    gravity.acceleration = {0.0, -9.81, 0.0};
    gravity.density = 2.0;
    // Both forms of the load in 2D: the exact one (on segments) with central fibers.
    gravity.integration = kinematics == FiberKinematics::Central ? Load::Integration::Exact
                                                                 : Load::Integration::Vertex;
    m.loads.push_back(gravity);
    const Equilibrium eq(m);
    const Eigen::VectorXd x = random_state(m, 5, 1.0);
    const std::vector<double> factors = {0.5, 0.5, 1.0};
    const Eigen::MatrixXd fd = finite_difference_tangent(eq, x, factors);
    EXPECT_LT((eq.tangent(x, factors) - fd).norm() / fd.norm(), 1e-6);
    const Eigen::VectorXd v = random_state(m, 6, 1.0);
    const Eigen::VectorXd Jv = eq.tangent(x, factors) * v;
    EXPECT_LT((eq.tangent_product(x, factors, v) - Jv).norm(), 1e-10 * Jv.norm());
    EXPECT_TRUE(
        stored_product_matches(eq.linearize(x, factors).apply(v), eq.tangent(x, factors), v));
  }
}

TEST(Equilibrium, ReferenceTangentIsThePapersMatrix) {
  for (Model m : {testing::paper_rectangle_model(), testing::paper_sphere_model()}) {
    m.material.axis_factors = {1.0, 2.0, 3.0};
    const Equilibrium eq(m);
    const Eigen::VectorXd zero = Eigen::VectorXd::Zero(m.num_unknowns());
    const std::vector<double> no_load(m.loads.size(), 0.0);
    const Eigen::MatrixXd A = system_matrix(m, m.surface.V);
    const Eigen::MatrixXd J = eq.tangent(zero, no_load);
    EXPECT_LT((J - A).cwiseAbs().maxCoeff(), 1e-12 * A.cwiseAbs().maxCoeff());
    EXPECT_EQ(eq.residual(zero, no_load).norm(), 0.0);
  }
}

TEST(Equilibrium, CoincidentVerticesAreNamed) {
  Model m = small_sphere(FiberLaw::constant(3000.0));
  m.surface.V.row(30) = m.surface.V.row(4);
  try {
    const Equilibrium eq(m);
    ADD_FAILURE() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("vertices 4 and 30 coincide"), std::string::npos)
        << e.what();
  }
}

TEST(Equilibrium, ConstantLawFiberForcesAreKu) {
  const Model m = small_sphere(FiberLaw::constant(3000.0));
  const Equilibrium eq(m);
  const Eigen::VectorXd x = random_state(m, 9, 0.2);
  const Eigen::MatrixXd A = system_matrix(m, m.surface.V);
  const Eigen::MatrixXd forces = eq.fiber_forces(x);
  const int n = m.num_vertices();
  for (int a = 0; a < 3; ++a) {
    const Eigen::VectorXd Ku = A.block(a * n, 0, n, 3 * n) * x.head(3 * n);
    EXPECT_LT((forces.col(a) - Ku).norm(), 1e-11 * Ku.norm());
  }
}

TEST(Equilibrium, ParameterDerivativesMatchCentralDifferences) {
  for (FiberKinematics kinematics : kAllKinematics)
    for (const FiberLaw& law : every_law()) {
      SCOPED_TRACE(kinematics_name(kinematics));
      Model m = small_sphere(law, kinematics);
      const Eigen::VectorXd x = random_state(m, 4);
      const std::vector<double> factors = {0.7, 0.4};
      std::vector<std::string> names = law.parameter_names();
      names.insert(names.end(), {"gamma", "factor_y"});
      const Eigen::MatrixXd D = Equilibrium(m).parameter_derivatives(x, names);
      for (size_t k = 0; k < names.size(); ++k) {
        auto with = [&](double delta) {
          Model changed = m;
          if (names[k] == "gamma")
            changed.material.surface_tension += delta;
          else if (names[k] == "factor_y")
            changed.material.axis_factors.y() += delta;
          else
            changed.material.law.set_parameter(names[k], law.parameter(names[k]) + delta);
          return Equilibrium(changed).residual(x, factors);
        };
        const double h =
            1e-5 * std::max(1.0, std::abs(names[k] == "gamma"      ? 500.0
                                          : names[k] == "factor_y" ? 0.8
                                                                   : law.parameter(names[k])));
        const Eigen::VectorXd fd = (with(h) - with(-h)) / (2.0 * h);
        EXPECT_LT((D.col(static_cast<Eigen::Index>(k)) - fd).norm(), 1e-6 * fd.norm() + 1e-12)
            << law.name() << " " << names[k];
      }
    }
  EXPECT_THROW(Equilibrium(small_sphere(FiberLaw::constant(1.0)))
                   .parameter_derivatives(Eigen::VectorXd::Zero(127), {"beta"}),
               std::invalid_argument);
}

}  // namespace
}  // namespace fiberfluid::model

namespace fiberfluid::model {
namespace {

// The equations are a sum of named terms, one per load; a load of a kind no
// term knows is an error, never silently another kind.
TEST(EquilibriumTerms, EachLoadIsATermAndAnUnknownKindIsAnError) {
  Model m = small_sphere(FiberLaw::constant(3000.0));
  const std::vector<std::string> expected = {
      "bulk fibers", "surface tension", "pressure and volume", "hydrostatic load", "point load"};
  EXPECT_EQ(Equilibrium(m).term_names(), expected);
  m.loads[0].kind = static_cast<Load::Kind>(7);
  EXPECT_THROW(Equilibrium{m}, std::invalid_argument);
  const std::vector<double> factors(m.loads.size(), 1.0);
  EXPECT_THROW(load_vector(m, m.surface.V, m.surface.V, factors), std::invalid_argument);
}

// The loads' residual is minus the external force, term by term: the
// residual without loads plus the external forces gives the residual.
TEST(EquilibriumTerms, ExternalForcesAreTheLoadTermsAlone) {
  const Model m = small_sphere(FiberLaw::exponential(3000.0, 4.0));
  const Equilibrium eq(m);
  const Eigen::VectorXd x = random_state(m, 4);
  const std::vector<double> factors = {0.7, 0.4}, none = {0.0, 0.0};
  const Eigen::VectorXd loaded = eq.residual(x, factors), unloaded = eq.residual(x, none);
  const Eigen::VectorXd F = eq.external_forces(x, factors);
  EXPECT_GT(F.norm(), 0.0);
  EXPECT_LT((unloaded - F - loaded).norm(), 1e-12 * loaded.norm());
}

}  // namespace
}  // namespace fiberfluid::model

namespace fiberfluid::model {
namespace {

// The exact form sums to the fluid's weight rho a V on every shipped mesh;
// the paper's vertex form to 3 C0 times it.
TEST(ExactHydrostaticLoad, SumsToTheWeightOnEveryShippedMesh) {
  const Eigen::Vector3d a(0.3, -1.2, -9.81);
  const double density = 1000.0;
  for (const char* name :
       {"cube.obj", "icosahedron.obj", "liver.obj", "sphere_02b.obj", "torus.obj", "Bunny.stl"}) {
    SCOPED_TRACE(name);
    const geom::Surface s = geom::read_surface(testing::data_mesh(name)).surface;
    const Eigen::VectorXd q =
        density * a.norm() * hydrostatic_depths(s.V, a);  // full load, depth below the top
    const Eigen::Vector3d total = exact_pressure_forces(s.V, s.F, q).colwise().sum();
    const Eigen::Vector3d weight = density * geom::enclosed_volume(s.V, s.F) * a;
    EXPECT_LT((total - weight).norm(), 1e-12 * weight.norm());
  }
}

// The fibers one by one (the fibers .vtu): every pair's and every edge's force,
// added on its two ends, gives fiber_forces at each vertex, for both
// kinematics, every pair kept or a horizon's (as a table and as lists), with
// the axis factors.
TEST(FiberReadings, EachFibersForceAddsUpToTheFiberForces) {
  for (FiberKinematics kinematics : kAllKinematics)
    for (int storage : {-1, 0, 1}) {  // no horizon, a table, lists
      const bool horizon = storage >= 0;
      SCOPED_TRACE(std::string(kinematics_name(kinematics)) + " " + std::to_string(storage));
      Model m = small_sphere(FiberLaw::exponential(3000.0, 4.0), kinematics);
      if (horizon)
        m.fibers = std::make_shared<const geom::FiberMask>(geom::horizon_fibers(
            m.surface, 0.8, storage == 0 ? geom::MaskStorage::Dense : geom::MaskStorage::Sparse));
      const Equilibrium eq(m);
      EXPECT_EQ(eq.sparse_fibers(), storage == 1);
      const Eigen::VectorXd x = random_state(m, 21, 0.2);
      const int n = m.num_vertices();
      std::vector<std::pair<int, int>> pairs;
      for (int i = 0; i < n; ++i)
        for (int j = i + 1; j < n; ++j) pairs.emplace_back(i, j);
      const std::vector<FiberReading> bulk = eq.bulk_fiber_readings(x, pairs),
                                      edges = eq.surface_fiber_readings(x);
      EXPECT_EQ(edges.size(), static_cast<size_t>(geom::unique_edges(m.surface).rows()));
      Eigen::MatrixXd sum = Eigen::MatrixXd::Zero(n, 3);
      int unloaded = 0;
      for (const std::vector<FiberReading>* readings : {&bulk, &edges})
        for (const FiberReading& f : *readings) {
          sum.row(f.i) += f.force.transpose();
          sum.row(f.j) -= f.force.transpose();
          unloaded += f.force.isZero(0.0);
        }
      const Eigen::MatrixXd expected = -eq.fiber_forces(x);
      EXPECT_LT((sum - expected).norm(), 1e-12 * expected.norm());
      // A horizon's pairs beyond it read no force (and every kept one does).
      if (horizon)
        EXPECT_EQ(unloaded, static_cast<int>(pairs.size() - m.fibers->num_kept()));
      else
        EXPECT_EQ(unloaded, 0);
      // The strain and the tension of one fiber, by hand: a central fiber
      // pulls along itself, a vector spring also across.
      const auto loaded = std::find_if(bulk.begin(), bulk.end(),
                                       [](const FiberReading& r) { return !r.force.isZero(0.0); });
      ASSERT_NE(loaded, bulk.end());
      const FiberReading& f = *loaded;
      const Eigen::MatrixXd X = positions(m, x);
      const Eigen::Vector3d towards_j = (X.row(f.j) - X.row(f.i)).transpose();
      const double L = (m.surface.V.row(f.i) - m.surface.V.row(f.j)).norm();
      EXPECT_NEAR(f.strain, towards_j.norm() / L - 1.0, 1e-14);
      EXPECT_NEAR(f.tension, f.force.dot(towards_j.normalized()), 1e-12 * f.force.norm());
      if (kinematics == FiberKinematics::Central) {
        EXPECT_NEAR(f.force.cwiseQuotient(m.material.axis_factors)
                        .normalized()
                        .cross(towards_j.normalized())
                        .norm(),
                    0.0, 1e-12);
        EXPECT_EQ(f.tension > 0.0, f.strain > 0.0);
      }
    }
}

}  // namespace
}  // namespace fiberfluid::model

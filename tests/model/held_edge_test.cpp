// SPDX-License-Identifier: GPL-3.0-or-later
// A support's split edge (held_edge.hpp): its edge vertices and ghosts, the
// split's fibers cancelling where a ghost moves as its vertex does, its
// tangent and parameter derivatives against central differences (with the
// mean count and a mirror layer), the clamp's reaction balancing the load,
// and the mean count's weights against their definition.
#include "fiberfluid/model/held_edge.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <memory>
#include <set>

#include "fiberfluid/geom/area_vectors.hpp"
#include "fiberfluid/geom/generators.hpp"
#include "fiberfluid/geom/horizon.hpp"
#include "fiberfluid/model/assembly.hpp"
#include "fiberfluid/model/equilibrium.hpp"
#include "fiberfluid/model/mirror_layer.hpp"
#include "fiberfluid/model/pair_kernels.hpp"
#include "fiberfluid/model/pair_stencil.hpp"
#include "fiberfluid/solve/stepping.hpp"
#include "model/model_fixtures.hpp"

namespace fiberfluid::model {
namespace {

using testing::random_displacements;

std::vector<int> at_x_zero(const Model& m) {
  std::vector<int> held;
  for (int v = 0; v < m.num_vertices(); ++v)
    if (m.surface.V(v, 0) < 1e-9) held.push_back(v);
  return held;
}

struct Options {
  bool split = true, layer = false;
  ConnectionCount count = ConnectionCount::Mean;
  Load::Integration integration = Load::Integration::Vertex;
};

// A 6 x 2 x 2 cm block (6 x 2 x 2 cells) held whole at x = 0, central or
// vector fibers within 2.5 cm fading conically, under its fluid's weight
// along -z and -y.
Model held_block(const FiberLaw& law, FiberKinematics kinematics, Options o = {}) {
  Model m;
  m.surface = geom::box({0.0, 0.0, 0.0}, {0.06, 0.02, 0.02}, Eigen::Vector3i(6, 2, 2));
  m.material.law = law;
  m.material.kinematics = kinematics;
  m.material.axis_factors = {1.0, 0.8, 1.3};
  m.material.surface_tension = 5.0;
  const double horizon = 0.025;
  m.fibers = std::make_shared<const geom::FiberMask>(geom::horizon_fibers(m.surface, horizon));
  m.influence = {Influence::Kind::Conical, horizon};
  m.connection_count = o.count;
  m.constraint_groups = {"clamp"};
  const std::vector<int> held = at_x_zero(m);
  for (int v : held)
    for (int a = 0; a < 3; ++a) m.constraints.push_back({v, a, 0.0, {}, 0});
  if (o.split) m.held_edges.push_back({0, held});
  if (o.layer) {
    MirrorLayer mirror;
    mirror.depth = horizon;
    EXPECT_TRUE(find_clamp_plane(m.surface.V, held, &mirror).ok);
    m.mirror_layers.push_back(mirror);
  }
  Load gravity;
  gravity.kind = Load::Kind::Hydrostatic;
  gravity.acceleration = {0.0, -3.0, -9.81};
  gravity.density = 1000.0;
  gravity.integration = o.integration;
  m.loads = {gravity};
  return m;
}

// The end face's 3 x 3 grid at x = 0: its 8 border vertices have faces on
// the block's sides (free vertices), its centre has none.
TEST(HeldEdge, ItsVerticesAreTheHeldBorderEachWithAFreeNeighbourAlongAnEdge) {
  const Model m = held_block(FiberLaw::constant(2e4), FiberKinematics::Central);
  const std::vector<EdgeVertex> edge = held_edge_vertices(m, at_x_zero(m));
  ASSERT_EQ(edge.size(), 8u);
  for (const EdgeVertex& e : edge) {
    SCOPED_TRACE(e.vertex);
    EXPECT_LT(m.surface.V(e.vertex, 0), 1e-9);
    EXPECT_NEAR(m.surface.V(e.neighbour, 0), 0.01, 1e-12);  // the next station
    EXPECT_NEAR((m.surface.V.row(e.neighbour) - m.surface.V.row(e.vertex)).norm(), 0.01, 1e-12);
    // A corner of the end face has two side faces' worth of free area, a
    // side's middle one: never the end face's share.
    EXPECT_GT(e.free_share, 0.3);
    EXPECT_LT(e.free_share, 0.9);
    EXPECT_FALSE(e.free_faces.empty());
    const bool centre = std::abs(m.surface.V(e.vertex, 1) - 0.01) < 1e-9 &&
                        std::abs(m.surface.V(e.vertex, 2) - 0.01) < 1e-9;
    EXPECT_FALSE(centre);
  }
  EXPECT_EQ(held_edge_of(m, 0), &m.held_edges[0]);
  EXPECT_EQ(held_edge_of(m, 1), nullptr);
}

// Where every edge vertex moves as its neighbour does, each ghost sits at
// its vertex: the split's fibers then pull on the same points as the bulk
// fibers they replace, so the residual differs from the held edge's only at
// the edge vertices and their neighbours (between which the split moves the
// ghosts' forces and pressure).
TEST(HeldEdge, WhereAGhostSitsAtItsVertexTheSplitOnlyMovesForcesToTheNeighbour) {
  for (FiberKinematics kinematics : kAllKinematics) {
    SCOPED_TRACE(kinematics_name(kinematics));
    const Model split = held_block(FiberLaw::exponential(2e4, -2.5), kinematics);
    const Model held = held_block(FiberLaw::exponential(2e4, -2.5), kinematics, {false});
    Eigen::VectorXd x = random_displacements(split, 5, 0.002);
    const int n = split.num_vertices();
    std::set<int> moved;
    for (const EdgeVertex& e : held_edge_vertices(split, split.held_edges[0].held)) {
      for (int a = 0; a < 3; ++a) x[split.dof(e.vertex, a)] = x[split.dof(e.neighbour, a)];
      moved.insert({e.vertex, e.neighbour});
    }
    const std::vector<double> factors = {0.7};
    const Eigen::VectorXd difference =
        Equilibrium(split).residual(x, factors) - Equilibrium(held).residual(x, factors);
    const double scale = Equilibrium(held).residual(x, factors).head(3 * n).norm();
    double elsewhere = 0.0, at_edge = 0.0;
    for (int v = 0; v < n; ++v)
      for (int a = 0; a < 3; ++a)
        (moved.count(v) ? at_edge : elsewhere) += std::abs(difference[split.dof(v, a)]);
    EXPECT_LT(elsewhere, 1e-12 * scale);
    EXPECT_GT(at_edge, 1e-3 * scale);                              // the split is in there
    EXPECT_LT(std::abs(difference[split.pressure_dof()]), 1e-15);  // no volume swept
  }
}

// The split's part of the tangent (the tangent less the held edge's) at the
// load factor f, and by central differences.
struct SplitPart {
  Eigen::MatrixXd exact, differences;
};
SplitPart split_part(const Model& split, const Model& held, const Eigen::VectorXd& x, double f) {
  const std::vector<double> factors = {f};
  const Equilibrium with(split), without(held);
  return {with.tangent(x, factors) - without.tangent(x, factors),
          testing::finite_difference_tangent(with, x, factors, 1e-7, 1e-2) -
              testing::finite_difference_tangent(without, x, factors, 1e-7, 1e-2)};
}

// The ghosts' share of the fluid's weight, alone: the split's part at a load
// factor less its part at none, in both of the load's forms.
TEST(HeldEdge, TheGhostsShareOfTheLoadHasItsExactTangent) {
  for (Load::Integration integration : {Load::Integration::Vertex, Load::Integration::Exact}) {
    SCOPED_TRACE(integration == Load::Integration::Exact ? "exact" : "vertex");
    Options o;
    o.integration = integration;
    Model split = held_block(FiberLaw::constant(2e4), FiberKinematics::Central, o);
    o.split = false;
    Model held = held_block(FiberLaw::constant(2e4), FiberKinematics::Central, o);
    for (Model* m : {&split, &held}) {  // the fluid's top at the clamp's far side
      m->loads[0].acceleration = {-9.81, -3.0, 2.0};
      m->loads[0].density = 1e4;
    }
    const Eigen::VectorXd x = random_displacements(split, 11, 0.002);
    const SplitPart loaded = split_part(split, held, x, 0.8);
    const SplitPart unloaded = split_part(split, held, x, 0.0);
    const Eigen::MatrixXd load = loaded.exact - unloaded.exact;
    const Eigen::MatrixXd load_fd = loaded.differences - unloaded.differences;
    ASSERT_GT(load.norm(), 1e-3 * loaded.exact.norm());  // the share is in there
    EXPECT_LT((load - load_fd).norm() / load_fd.norm(), 1e-5);
    const Eigen::VectorXd v = random_displacements(split, 13, 1.0);
    const Equilibrium eq(split);
    const Eigen::MatrixXd J = eq.tangent(x, {0.8});
    EXPECT_LT((eq.tangent_product(x, {0.8}, v) - J * v).norm(), 1e-10 * (J * v).norm());
  }
}

TEST(HeldEdge, TangentAndParameterDerivativesMatchCentralDifferences) {
  for (bool layer : {false, true})
    for (FiberKinematics kinematics : kAllKinematics)
      for (const FiberLaw& law : {FiberLaw::constant(2e4), FiberLaw::exponential(2e4, -2.5)}) {
        SCOPED_TRACE(std::string(kinematics_name(kinematics)) + " " + law.name() +
                     (layer ? " with its mirror layer" : ""));
        const Model m = held_block(law, kinematics, {true, layer});
        const Equilibrium eq(m);
        const Eigen::VectorXd x = random_displacements(m, 3, 0.002);
        const std::vector<double> factors = {0.6};
        testing::expect_tangent_matches_differences(eq, x, factors,
                                                    random_displacements(m, 7, 1.0));
        // The split's own part, far smaller than the bulk's, on its own; the
        // pressure row (the ghosts' volume) alone too.
        const Model held = held_block(law, kinematics, {false, layer});
        const SplitPart part = split_part(m, held, x, factors[0]);
        EXPECT_LT((part.exact - part.differences).norm() / part.differences.norm(), 1e-5);
        const Eigen::Index p = m.pressure_dof();
        EXPECT_LT(
            (part.exact.row(p) - part.differences.row(p)).norm() / part.differences.row(p).norm(),
            1e-5);
        testing::expect_parameter_derivatives_match_differences(m, x, factors);
      }
}

TEST(HeldEdge, TheClampsReactionBalancesTheLoadAndTheVolumeIsKept) {
  const Model m =
      held_block(FiberLaw::exponential(2e4, -2.0), FiberKinematics::Central, {true, true});
  const solve::SteppingSummary run = testing::expect_reaction_balances_load(m, 3);
  ASSERT_TRUE(run.success);
  // The volume row with the ghosts' sweep: the enclosed volume plus what the
  // ghosts' areas sweep is the reference volume.
  const Eigen::MatrixXd U = displacements(m, run.unknowns);
  const Eigen::MatrixXd X = m.surface.V + U;
  const geom::VertexAreaVectors reference = geom::vertex_area_vectors(m.surface.V, m.surface.F);
  double swept = 0.0;
  for (const EdgeVertex& e : held_edge_vertices(m, m.held_edges[0].held)) {
    Eigen::Vector3d S = Eigen::Vector3d::Zero();
    const Eigen::MatrixXd A = geom::face_area_vectors(X, m.surface.F);
    for (int f : e.free_faces) S += A.row(f).transpose();
    swept += reference.C * S.dot((U.row(e.neighbour) - U.row(e.vertex)).transpose());
  }
  const double V0 = geom::enclosed_volume(m.surface.V, m.surface.F);
  const double V = geom::enclosed_volume(X, m.surface.F);
  EXPECT_NE(swept, 0.0);
  EXPECT_NEAR(3.0 * reference.C * (V - V0) + swept, 0.0, 1e-9 * V0);
}

// The mean count (ConnectionCount::Mean) by its definition: M_i = sum_j
// kept_ij omega_ij |S_j| the area i's fibers reach, w_ij = 2 kept_ij omega_ij
// |S_i| |S_j| / ((M_i + M_j) L_ij); the tiled kernels and the factors' rows
// both give it.
TEST(MeanCount, TheKernelsAndTheFactorsGiveTheWeightsOfItsDefinition) {
  const geom::Surface surface = geom::icosphere(3, 2.0);
  const Eigen::VectorXd area = geom::vertex_area_vectors(surface.V, surface.F).magnitude;
  const double horizon = 1.5;
  const geom::FiberMask mask = geom::horizon_fibers(surface, horizon);
  const Influence conical{Influence::Kind::Conical, horizon};
  const int n = static_cast<int>(surface.V.rows());
  const PairFactors factors(&mask, ConnectionCount::Mean, n, conical, &surface.V, area);
  ASSERT_TRUE(factors.mean_count());
  Eigen::VectorXd reached = Eigen::VectorXd::Zero(n);
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j)
      if (i != j && mask.kept(i, j))
        reached[i] += conical((surface.V.row(i) - surface.V.row(j)).norm()) * area[j];
  Eigen::MatrixXd W = Eigen::MatrixXd::Zero(n, n);
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) {
      if (i == j || !mask.kept(i, j)) continue;
      const double L = (surface.V.row(i) - surface.V.row(j)).norm();
      W(i, j) = 2.0 * conical(L) * area[i] * area[j] / ((reached[i] + reached[j]) * L);
    }
  const BulkPairs pairs(surface.V, area, factors);
  const Eigen::VectorXd sums = W.rowwise().sum();
  EXPECT_LT((pairs.row_sums() - sums).cwiseAbs().maxCoeff(), 1e-13 * sums.cwiseAbs().maxCoeff());
  std::vector<double> h(static_cast<size_t>(n));
  double worst = 0.0;
  for (int i = 0; i < n; ++i) {
    factors.row(i, h.data());
    for (int j = 0; j < n; ++j) {
      const double w = i == j ? 0.0
                              : bulk_weight(h[static_cast<size_t>(j)], area[i], area[j],
                                            (surface.V.row(i) - surface.V.row(j)).norm());
      worst = std::max(worst, std::abs(w - W(i, j)));
      if (i != j) {
        EXPECT_DOUBLE_EQ(factors.factor(i, j), h[static_cast<size_t>(j)]);
      }
    }
  }
  EXPECT_LT(worst, 1e-13 * W.maxCoeff());
  // The area count is not the mean: on this icosphere the valence-5 vertices
  // are smaller than their neighbours.
  const PairFactors by_area(&mask, ConnectionCount::Area, n, conical, &surface.V, area);
  EXPECT_GT((BulkPairs(surface.V, area, by_area).row_sums() - sums).cwiseAbs().maxCoeff(),
            1e-4 * sums.cwiseAbs().maxCoeff());
}

}  // namespace
}  // namespace fiberfluid::model

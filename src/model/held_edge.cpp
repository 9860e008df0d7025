// SPDX-License-Identifier: GPL-3.0-or-later
#include "fiberfluid/model/held_edge.hpp"

#include <Eigen/Geometry>
#include <limits>

#include "fiberfluid/geom/area_vectors.hpp"
#include "fiberfluid/model/loads.hpp"
#include "fiberfluid/model/pair_stencil.hpp"
#include "fiberfluid/model/point_fibers.hpp"

namespace fiberfluid::model {

namespace {

// A_f at x (3D: half the cross product of two edges; 2D: the edge's outward
// normal times its length), padded to 3.
Eigen::Vector3d face_area_vector(const Eigen::MatrixXd& X, const Eigen::MatrixXi& F, int f) {
  if (X.cols() == 3) {
    const Eigen::Vector3d a = X.row(F(f, 0)), b = X.row(F(f, 1)), c = X.row(F(f, 2));
    return 0.5 * (b - a).cross(c - a);
  }
  const Eigen::Vector3d d = padded_row(X, F(f, 1)) - padded_row(X, F(f, 0));
  return {d.y(), -d.x(), 0.0};
}

std::vector<char> held_mask(int num_vertices, const std::vector<int>& held) {
  std::vector<char> mask(static_cast<size_t>(num_vertices), 0);
  for (int v : held) mask[static_cast<size_t>(v)] = 1;
  return mask;
}

}  // namespace

std::vector<EdgeVertex> held_edge_vertices(const Model& model, const std::vector<int>& held) {
  const Eigen::MatrixXd& V = model.surface.V;
  const Eigen::MatrixXi& F = model.surface.F;
  const int n = model.num_vertices();
  const std::vector<char> is_held = held_mask(n, held);
  const Eigen::VectorXd face_area = geom::face_area_vectors(V, F).rowwise().norm();
  std::vector<double> all(static_cast<size_t>(n), 0.0);
  std::vector<EdgeVertex> at(static_cast<size_t>(n));
  std::vector<double> nearest(static_cast<size_t>(n), std::numeric_limits<double>::infinity());
  for (Eigen::Index f = 0; f < F.rows(); ++f) {
    bool free_face = false;
    for (Eigen::Index a = 0; a < F.cols(); ++a) free_face |= !is_held[static_cast<size_t>(F(f, a))];
    for (Eigen::Index a = 0; a < F.cols(); ++a) {
      const int j = F(f, a);
      EdgeVertex& e = at[static_cast<size_t>(j)];
      all[static_cast<size_t>(j)] += face_area[f];
      if (!is_held[static_cast<size_t>(j)] || !free_face) continue;
      e.free_share += face_area[f];
      e.free_faces.push_back(static_cast<int>(f));
      for (Eigen::Index b = 0; b < F.cols(); ++b) {  // the nearest free vertex along an edge
        const int k = F(f, b);
        if (is_held[static_cast<size_t>(k)]) continue;
        const double distance = (V.row(j) - V.row(k)).norm();
        if (distance < nearest[static_cast<size_t>(j)])
          nearest[static_cast<size_t>(j)] = distance, e.neighbour = k;
      }
    }
  }
  std::vector<EdgeVertex> edge;
  for (int j : held) {
    EdgeVertex e = at[static_cast<size_t>(j)];
    if (e.free_faces.empty() || !(all[static_cast<size_t>(j)] > 0.0)) continue;
    e.vertex = j;
    e.free_share /= all[static_cast<size_t>(j)];
    edge.push_back(std::move(e));
  }
  return edge;
}

const HeldEdge* held_edge_of(const Model& model, int group) {
  for (const HeldEdge& edge : model.held_edges)
    if (edge.group == group) return &edge;
  return nullptr;
}

std::vector<OffsetFiber> held_edge_fibers(const Model& model, const HeldEdge& edge,
                                          const PairFactors& factors,
                                          const Eigen::VectorXd& area0) {
  const Eigen::MatrixXd& V = model.surface.V;
  const int n = model.num_vertices();
  // Each vertex as points of area: itself (its held share for an edge vertex)
  // and, for an edge vertex, its ghost (its free share, moving with k).
  struct Point {
    int vertex;
    Eigen::Vector3d offset;  // from the vertex it moves with
    double share;
  };
  std::vector<std::vector<Point>> points(static_cast<size_t>(n));
  for (int v = 0; v < n; ++v) points[static_cast<size_t>(v)] = {{v, Eigen::Vector3d::Zero(), 1.0}};
  std::vector<char> is_edge(static_cast<size_t>(n), 0);
  std::vector<int> edge_vertices;
  for (const EdgeVertex& e : held_edge_vertices(model, edge.held)) {
    points[static_cast<size_t>(e.vertex)] = {
        {e.vertex, Eigen::Vector3d::Zero(), 1.0 - e.free_share},
        {e.neighbour, padded_row(V, e.vertex) - padded_row(V, e.neighbour), e.free_share}};
    is_edge[static_cast<size_t>(e.vertex)] = 1;
    edge_vertices.push_back(e.vertex);
  }
  std::vector<OffsetFiber> fibers;
  for (int j : edge_vertices)
    for (int i = 0; i < n; ++i) {
      if (i == j || (is_edge[static_cast<size_t>(i)] && i > j)) continue;  // each pair once
      const double h = factors.factor(i, j);
      if (!(h > 0.0)) continue;
      const double length = (padded_row(V, i) - padded_row(V, j)).norm();
      const double w = bulk_weight(h, area0[i], area0[j], length);
      fibers.push_back({i, j, Eigen::Vector3d::Zero(), length, -w});
      for (const Point& a : points[static_cast<size_t>(i)])
        for (const Point& b : points[static_cast<size_t>(j)]) {
          if (a.vertex == b.vertex) continue;  // both move with one vertex: no strain
          fibers.push_back(
              {a.vertex, b.vertex, b.offset - a.offset, length, a.share * b.share * w});
        }
    }
  return fibers;
}

namespace {

// The ghosts' shares of the fluid: P S^g_j(x) moved from j to k, and
// S^g_j . (u_k - u_j) in the volume row.
class HeldEdgeFluidTerm final : public EquilibriumTerm {
 public:
  HeldEdgeFluidTerm(const TermContext& c, const HeldEdge& edge)
      : c_(c), edge_(held_edge_vertices(c.model, edge.held)) {}
  const char* name() const override { return "split edge's share of the fluid"; }
  Role role() const override { return Role::Fluid; }

  void add_residual(const TermState& s, Eigen::VectorXd& R) const override {
    for (const EdgeVertex& e : edge_) {
      const Eigen::Vector3d S = ghost_area_vector(s.X, e);
      const Eigen::Vector3d swept = padded_row(s.U, e.neighbour) - padded_row(s.U, e.vertex);
      for (int a = 0; a < dim(); ++a) {
        R[dof(e.neighbour, a)] += s.P * S[a];
        R[dof(e.vertex, a)] -= s.P * S[a];
      }
      R[pressure()] += S.dot(swept);
    }
  }

  void add_tangent(const TermState& s, TangentSink& J) const override {
    const Eigen::MatrixXi& F = c_.model.surface.F;
    for (const EdgeVertex& e : edge_) {
      const Eigen::Vector3d S = ghost_area_vector(s.X, e);
      const Eigen::Vector3d swept = padded_row(s.U, e.neighbour) - padded_row(s.U, e.vertex);
      for (int a = 0; a < dim(); ++a) {
        J.add(dof(e.neighbour, a), pressure(), S[a]);
        J.add(dof(e.vertex, a), pressure(), -S[a]);
        J.add(pressure(), dof(e.neighbour, a), S[a]);
        J.add(pressure(), dof(e.vertex, a), -S[a]);
      }
      for (int f : e.free_faces)  // S^g's turning with the face's corners
        for (int corner = 0; corner < F.cols(); ++corner) {
          const Eigen::Matrix3d dS = c_.C0 * face_area_derivative(s.X, F, f, corner);
          const int v = F(f, corner);
          for (int b = 0; b < dim(); ++b) {
            for (int a = 0; a < dim(); ++a) {
              J.add(dof(e.neighbour, a), dof(v, b), s.P * dS(a, b));
              J.add(dof(e.vertex, a), dof(v, b), -s.P * dS(a, b));
            }
            J.add(pressure(), dof(v, b), swept.dot(dS.col(b)));
          }
        }
    }
  }

  void add_tangent_product(const TermState& s, const Eigen::VectorXd& v, const Eigen::MatrixXd& W,
                           Eigen::VectorXd& out) const override {
    const Eigen::MatrixXi& F = c_.model.surface.F;
    for (const EdgeVertex& e : edge_) {
      const Eigen::Vector3d S = ghost_area_vector(s.X, e);
      const Eigen::Vector3d swept = padded_row(s.U, e.neighbour) - padded_row(s.U, e.vertex);
      Eigen::Vector3d rate = Eigen::Vector3d::Zero();
      for (int f : e.free_faces) rate += c_.C0 * face_area_rate(s.X, F, f, W);
      for (int a = 0; a < dim(); ++a) {
        const double value = S[a] * v[pressure()] + s.P * rate[a];
        out[dof(e.neighbour, a)] += value;
        out[dof(e.vertex, a)] -= value;
      }
      out[pressure()] +=
          S.dot(padded_row(W, e.neighbour) - padded_row(W, e.vertex)) + swept.dot(rate);
    }
  }

 private:
  // S^g_j(x): C0 times j's free faces' area vectors at x.
  Eigen::Vector3d ghost_area_vector(const Eigen::MatrixXd& X, const EdgeVertex& e) const {
    const Eigen::MatrixXi& F = c_.model.surface.F;
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    for (int f : e.free_faces) sum += face_area_vector(X, F, f);
    return c_.C0 * sum;
  }
  int dim() const { return c_.model.dim(); }
  Eigen::Index dof(int vertex, int axis) const { return c_.model.dof(vertex, axis); }
  Eigen::Index pressure() const { return c_.model.pressure_dof(); }

  const TermContext& c_;
  std::vector<EdgeVertex> edge_;
};

// The ghosts' shares of a hydrostatic load (loads.hpp): the force on j
// from j's free faces, G_j = q_j C0 sum_f A_f(x) in the vertex form or
// sum_f w_jf A_f(x) in the exact one (ExactFaceShares), moved from j to k.
class HeldEdgeLoadTerm final : public EquilibriumTerm {
 public:
  HeldEdgeLoadTerm(const TermContext& c, const HeldEdge& edge, size_t load)
      : c_(c),
        edge_(held_edge_vertices(c.model, edge.held)),
        load_(load),
        level_(hydrostatic_level(c.model.surface.V, c.model.loads[load].acceleration)) {}
  const char* name() const override { return "split edge's share of a hydrostatic load"; }
  Role role() const override { return Role::Load; }

  void add_residual(const TermState& s, Eigen::VectorXd& R) const override {
    if (inactive(s)) return;
    const Field q = field(s);
    for (const EdgeVertex& e : edge_) {
      const Eigen::Vector3d G = share(s.X, q, e);
      for (int a = 0; a < dim(); ++a) {  // minus the force: a load's residual
        R[dof(e.neighbour, a)] -= G[a];
        R[dof(e.vertex, a)] += G[a];
      }
    }
  }

  void add_tangent(const TermState& s, TangentSink& J) const override {
    if (inactive(s)) return;
    const Field q = field(s);
    const Eigen::MatrixXi& F = c_.model.surface.F;
    for (const EdgeVertex& e : edge_)
      for (int f : e.free_faces) {
        const Eigen::Vector3d A = face_area_vector(s.X, F, f);
        for (int corner = 0; corner < F.cols(); ++corner) {
          const int v = F(f, corner);
          // dG/dx_v: the face's turning times j's weight, and A_f times the weight's rate.
          const Eigen::Matrix3d dG =
              weight(q, e.vertex, f) * face_area_derivative(s.X, F, f, corner) +
              A * q.gradient.transpose() * weight_rate(q, e.vertex, v);
          for (int a = 0; a < dim(); ++a)
            for (int b = 0; b < dim(); ++b) {
              J.add(dof(e.neighbour, a), dof(v, b), -dG(a, b));
              J.add(dof(e.vertex, a), dof(v, b), dG(a, b));
            }
        }
      }
  }

  void add_tangent_product(const TermState& s, const Eigen::VectorXd&, const Eigen::MatrixXd& W,
                           Eigen::VectorXd& out) const override {
    if (inactive(s)) return;
    const Field q = field(s);
    const Eigen::MatrixXi& F = c_.model.surface.F;
    for (const EdgeVertex& e : edge_) {
      Eigen::Vector3d rate = Eigen::Vector3d::Zero();
      for (int f : e.free_faces) {
        double weight_change = 0.0;  // sum_v dw_jf/dx_v . w_v
        for (int corner = 0; corner < F.cols(); ++corner) {
          const int v = F(f, corner);
          weight_change += weight_rate(q, e.vertex, v) * q.gradient.dot(padded_row(W, v));
        }
        rate += weight(q, e.vertex, f) * face_area_rate(s.X, F, f, W) +
                face_area_vector(s.X, F, f) * weight_change;
      }
      for (int a = 0; a < dim(); ++a) {
        out[dof(e.neighbour, a)] -= rate[a];
        out[dof(e.vertex, a)] += rate[a];
      }
    }
  }

 private:
  // The pressures at a state: q_i per vertex with the exact form's weights
  // (ExactFaceShares), and their gradient dq/dx (the same at every vertex).
  struct Field {
    ExactFaceShares shares;
    Eigen::Vector3d gradient;
  };
  const Load& load() const { return c_.model.loads[load_]; }
  bool exact() const { return load().integration == Load::Integration::Exact; }
  bool inactive(const TermState& s) const {
    return s.factors[load_] == 0.0 || load().acceleration.norm() == 0.0;
  }
  Field field(const TermState& s) const {
    const double per_depth = hydrostatic_pressure_per_depth(load(), s.factors[load_]);
    return {ExactFaceShares(c_.model.surface.F,
                            per_depth * hydrostatic_heads(s.X, load().acceleration, level_)),
            per_depth * load().acceleration / load().acceleration.norm()};
  }
  // j's weight on face f: q_j C0 (vertex form) or w_jf (exact form).
  double weight(const Field& q, int j, int f) const {
    return exact() ? q.shares.w(j, f) : c_.C0 * q.shares.q[j];
  }
  // d(weight)/dq_v for a corner v of the face (times the gradient: d/dx_v).
  double weight_rate(const Field& q, int j, int v) const {
    if (!exact()) return v == j ? c_.C0 : 0.0;
    return q.shares.per_pressure * (v == j ? 2.0 : 1.0);
  }
  // G_j: the load's force on j from its free faces.
  Eigen::Vector3d share(const Eigen::MatrixXd& X, const Field& q, const EdgeVertex& e) const {
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    for (int f : e.free_faces)
      sum += weight(q, e.vertex, f) * face_area_vector(X, c_.model.surface.F, f);
    return sum;
  }
  int dim() const { return c_.model.dim(); }
  Eigen::Index dof(int vertex, int axis) const { return c_.model.dof(vertex, axis); }

  const TermContext& c_;
  std::vector<EdgeVertex> edge_;
  size_t load_;
  double level_;
};

}  // namespace

std::vector<std::unique_ptr<EquilibriumTerm>> make_held_edge_terms(const TermContext& context,
                                                                   const HeldEdge& edge) {
  std::vector<std::unique_ptr<EquilibriumTerm>> terms;
  std::vector<PointFiber> fibers;
  for (const OffsetFiber& f :
       held_edge_fibers(context.model, edge, context.pair_factors, context.area0))
    fibers.push_back({f.i, f.p, /*mirrored=*/false, f.offset, f.length, f.weight});
  terms.push_back(make_point_fiber_term(context, std::move(fibers), "split edge's fibers",
                                        EquilibriumTerm::Role::Fibers));
  terms.push_back(std::make_unique<HeldEdgeFluidTerm>(context, edge));
  for (size_t l = 0; l < context.model.loads.size(); ++l)
    if (context.model.loads[l].kind == Load::Kind::Hydrostatic)
      terms.push_back(std::make_unique<HeldEdgeLoadTerm>(context, edge, l));
  return terms;
}

}  // namespace fiberfluid::model

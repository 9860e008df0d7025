// SPDX-License-Identifier: GPL-3.0-or-later
#include "fiberfluid/model/terms.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include "fiberfluid/geom/area_vectors.hpp"
#include "fiberfluid/geom/fiber_mask.hpp"
#include "fiberfluid/model/assembly.hpp"
#include "fiberfluid/model/fiber_reading.hpp"
#include "fiberfluid/model/loads.hpp"
#include "fiberfluid/model/pair_kernels.hpp"
#include "fiberfluid/model/pair_stencil.hpp"

namespace fiberfluid::model {

TermState::TermState(const TermContext& c, const Eigen::VectorXd& x_,
                     const std::vector<double>& factors_)
    : x(x_),
      factors(factors_),
      X(positions(c.model, x_)),
      U(displacements(c.model, x_)),
      S(c.C0 * geom::summed_face_area_vectors(X, c.model.surface.F)),
      P(x_[c.model.pressure_dof()]) {}

namespace {

Eigen::Matrix3d cross_matrix(const Eigen::Vector3d& w) {
  Eigen::Matrix3d m;
  m << 0, -w.z(), w.y(), w.z(), 0, -w.x(), -w.y(), w.x(), 0;
  return m;
}

}  // namespace

// 3D: A_f = (x0 x x1 + x1 x x2 + x2 x x0) / 2, so dA_f/dx_k = [x_{k+2} - x_{k+1}]_x / 2.
// 2D: A_f = (d_y, -d_x), d = x_1 - x_0.
Eigen::Matrix3d face_area_derivative(const Eigen::MatrixXd& X, const Eigen::MatrixXi& F,
                                     Eigen::Index f, int k) {
  if (X.cols() == 3) {
    const Eigen::Vector3d next = X.row(F(f, (k + 1) % 3)), after = X.row(F(f, (k + 2) % 3));
    return 0.5 * cross_matrix(after - next);
  }
  Eigen::Matrix3d m = Eigen::Matrix3d::Zero();
  m(0, 1) = 1.0;
  m(1, 0) = -1.0;
  return k == 1 ? m : Eigen::Matrix3d(-m);
}

namespace {

// The terms c_i S_i(x) (pressure: c = P; hydrostatic load: c = -q) have the
// geometric tangent c_i dS_i/dx_v = c_i C0 sum over faces f at i and v of
// dA_f/dx_v. J += it.
void add_area_vector_tangent(const TermContext& ctx, const Eigen::MatrixXd& X,
                             const Eigen::VectorXd& c, TangentSink& J) {
  const int n = ctx.model.num_vertices(), dim = ctx.model.dim();
  const Eigen::MatrixXi& F = ctx.model.surface.F;
  for (Eigen::Index f = 0; f < F.rows(); ++f)
    for (int k = 0; k < F.cols(); ++k) {
      const Eigen::Matrix3d dA = ctx.C0 * face_area_derivative(X, F, f, k);
      const int v = F(f, k);
      for (int corner = 0; corner < F.cols(); ++corner) {
        const int i = F(f, corner);
        for (int a = 0; a < dim; ++a)
          for (int b = 0; b < dim; ++b) J.add(a * n + i, b * n + v, c[i] * dA(a, b));
      }
    }
}

}  // namespace

// face_area_derivative applied directly: in 3D sum_k (x_{k+2} - x_{k+1}) x
// w_k / 2, in 2D the rotated w_1 - w_0.
Eigen::Vector3d face_area_rate(const Eigen::MatrixXd& X, const Eigen::MatrixXi& F, Eigen::Index f,
                               const Eigen::MatrixXd& W) {
  Eigen::Vector3d dA = Eigen::Vector3d::Zero();
  if (X.cols() == 3) {
    for (int k = 0; k < 3; ++k) {
      const Eigen::Vector3d next = X.row(F(f, (k + 1) % 3)), after = X.row(F(f, (k + 2) % 3));
      dA += 0.5 * (after - next).cross(padded_row(W, F(f, k)));
    }
  } else {
    const Eigen::Vector3d dw = padded_row(W, F(f, 1)) - padded_row(W, F(f, 0));
    dA = Eigen::Vector3d(dw.y(), -dw.x(), 0.0);
  }
  return dA;
}

namespace {

// The same applied to W (#V by dim): row i is c_i dS_i/dx W; #V by 3.
Eigen::MatrixXd area_vector_product(const TermContext& ctx, const Eigen::MatrixXd& X,
                                    const Eigen::VectorXd& c, const Eigen::MatrixXd& W) {
  const Eigen::MatrixXi& F = ctx.model.surface.F;
  Eigen::MatrixXd out = Eigen::MatrixXd::Zero(X.rows(), 3);
  for (Eigen::Index f = 0; f < F.rows(); ++f) {
    // The face's rate, spread over the corners with their c_i.
    const Eigen::Vector3d dA = face_area_rate(X, F, f, W);
    for (int corner = 0; corner < F.cols(); ++corner)
      out.row(F(f, corner)) += ctx.C0 * c[F(f, corner)] * dA.transpose();
  }
  return out;
}

// ---- Surface tension -----------------------------------------------------------

// The surface fibers: each mesh edge i-k a fiber of weight gamma b_ik (paper
// Eq. 7) and modulus 1, with the material's kinematics. For the paper's
// vector spring that is the Laplacian gamma B u, applied as the sparse
// product (bit for bit the paper's); any other kinematics goes through its
// policy edge by edge (so that a central body's skin rotates freely too).
class SurfaceTensionTerm final : public EquilibriumTerm {
 public:
  explicit SurfaceTensionTerm(const TermContext& c) : c_(c) {}
  const char* name() const override { return "surface tension"; }
  Role role() const override { return Role::Fibers; }
  void add_residual(const TermState& s, Eigen::VectorXd& R) const override {
    if (paper_spring()) return add_rows(gamma() * (c_.surface * s.U), R);
    add_edge_forces(s, gamma(), R);
  }
  void add_tangent(const TermState& s, TangentSink& J) const override {
    const int n = c_.model.num_vertices(), dim = c_.model.dim();
    if (paper_spring()) {
      for (int col = 0; col < c_.surface.outerSize(); ++col)
        for (Eigen::SparseMatrix<double>::InnerIterator it(c_.surface, col); it; ++it)
          for (int a = 0; a < dim; ++a)
            J.add(a * n + it.row(), a * n + it.col(), gamma() * it.value());
      return;
    }
    for_each_edge(s, gamma(),
                  [&](auto policy, int i, int k, const PairCoefficients& c,
                      const Eigen::Vector3d& b, const Eigen::Vector3d& d) {
                    using K = decltype(policy);
                    for (int a = 0; a < dim; ++a)
                      for (int e = 0; e < dim; ++e) {
                        const double entry = pair_tangent_entry<K>(c, a == e, b[a], d[a], b[e]);
                        J.add(a * n + i, e * n + i, entry);
                        J.add(a * n + i, e * n + k, -(entry));
                      }
                  });
  }
  void add_tangent_product(const TermState& s, const Eigen::VectorXd&, const Eigen::MatrixXd& W,
                           Eigen::VectorXd& out) const override {
    if (paper_spring()) return add_rows(gamma() * (c_.surface * W), out);
    const int n = c_.model.num_vertices(), dim = c_.model.dim();
    for_each_edge(s, gamma(),
                  [&](auto policy, int i, int k, const PairCoefficients& c,
                      const Eigen::Vector3d& b, const Eigen::Vector3d& d) {
                    using K = decltype(policy);
                    const Eigen::Vector3d v = padded_row(W, i) - padded_row(W, k);
                    const double b_dot_v = b.dot(v);
                    for (int a = 0; a < dim; ++a)
                      out[a * n + i] += pair_tangent<K>(c, v[a], b_dot_v, b[a], d[a]);
                  });
  }
  void add_parameter_derivative(const TermState& s, const MaterialParameter& p,
                                Eigen::Ref<Eigen::VectorXd> column) const override {
    if (p.kind != MaterialParameter::Kind::SurfaceTension) return;
    Eigen::VectorXd R = Eigen::VectorXd::Zero(column.size());
    if (paper_spring())
      add_rows(c_.surface * s.U, R);
    else
      add_edge_forces(s, 1.0, R);  // the forces are linear in gamma
    column += R;
  }
  // Each edge's reading (i < k), sorted by its ends.
  std::vector<FiberReading> readings(const TermState& s) const {
    std::vector<FiberReading> out;
    const Eigen::Vector3d no_factors = Eigen::Vector3d::Ones();
    const Eigen::MatrixXd& V0 = c_.model.surface.V;
    for_each_edge(
        s, gamma(),
        [&](auto policy, int i, int k, const PairCoefficients& c, const Eigen::Vector3d& b,
            const Eigen::Vector3d& d) {
          if (i > k) return;
          const double L = (padded_row(V0, i) - padded_row(V0, k)).norm();
          out.push_back(detail::read_fiber<decltype(policy)>(i, k, c, b, d, L, no_factors));
        });
    std::sort(out.begin(), out.end(), [](const FiberReading& p, const FiberReading& q) {
      return std::make_pair(p.i, p.j) < std::make_pair(q.i, q.j);
    });
    return out;
  }

 private:
  double gamma() const { return c_.model.material.surface_tension; }
  bool paper_spring() const {
    return c_.model.material.kinematics == FiberKinematics::VectorSpring;
  }
  void add_rows(const Eigen::MatrixXd& rows, Eigen::VectorXd& out) const {
    const int n = c_.model.num_vertices();
    for (int a = 0; a < c_.model.dim(); ++a) out.segment(a * n, n) += rows.col(a);
  }
  // body(policy, i, k, coefficients, b = x_i - x_k, d = u_i - u_k) for each
  // edge seen from each of its ends, with weight scale * b_ik.
  template <class Body>
  void for_each_edge(const TermState& s, double scale, Body&& body) const {
    const Eigen::MatrixXd& V0 = c_.model.surface.V;
    with_kinematics(c_.model.material.kinematics, [&](auto policy) {
      using K = decltype(policy);
      for (int col = 0; col < c_.surface.outerSize(); ++col)
        for (Eigen::SparseMatrix<double>::InnerIterator it(c_.surface, col); it; ++it) {
          const int i = static_cast<int>(it.row()), k = static_cast<int>(it.col());
          if (i == k) continue;
          const Eigen::Vector3d b = padded_row(s.X, i) - padded_row(s.X, k),
                                d = padded_row(s.U, i) - padded_row(s.U, k);
          const double L = (padded_row(V0, i) - padded_row(V0, k)).norm(), r = b.norm();
          body(policy, i, k, K::coefficients(-scale * it.value(), 1.0, 0.0, r, L), b, d);
        }
    });
  }
  void add_edge_forces(const TermState& s, double scale, Eigen::VectorXd& R) const {
    const int n = c_.model.num_vertices(), dim = c_.model.dim();
    for_each_edge(s, scale,
                  [&](auto policy, int i, int, const PairCoefficients& c, const Eigen::Vector3d& b,
                      const Eigen::Vector3d& d) {
                    using K = decltype(policy);
                    for (int a = 0; a < dim; ++a) R[a * n + i] += pair_force<K>(c, b[a], d[a]);
                  });
  }
  const TermContext& c_;
};

// ---- Pressure and volume -------------------------------------------------------

class PressureVolumeTerm final : public EquilibriumTerm {
 public:
  explicit PressureVolumeTerm(const TermContext& c) : c_(c) {}
  const char* name() const override { return "pressure and volume"; }
  Role role() const override { return Role::Fluid; }
  void add_residual(const TermState& s, Eigen::VectorXd& R) const override {
    const int n = c_.model.num_vertices(), dim = c_.model.dim();
    for (int a = 0; a < dim; ++a) R.segment(a * n, n) += s.P * s.S.col(a);
    R[c_.model.pressure_dof()] +=
        dim * c_.C0 * (geom::enclosed_volume(s.X, c_.model.surface.F) - c_.volume0);
  }
  void add_tangent(const TermState& s, TangentSink& J) const override {
    const int n = c_.model.num_vertices(), dim = c_.model.dim(), p = c_.model.pressure_dof();
    add_area_vector_tangent(c_, s.X, Eigen::VectorXd::Constant(n, s.P), J);
    for (int i = 0; i < n; ++i)
      for (int a = 0; a < dim; ++a) {
        J.add(a * n + i, p, s.S(i, a));  // dR_i/dP
        J.add(p, a * n + i, s.S(i, a));  // dg/dx_i = S_i(x)
      }
  }
  void add_tangent_product(const TermState& s, const Eigen::VectorXd& v, const Eigen::MatrixXd& W,
                           Eigen::VectorXd& out) const override {
    const int n = c_.model.num_vertices(), dim = c_.model.dim(), p = c_.model.pressure_dof();
    const Eigen::MatrixXd geometric =
        area_vector_product(c_, s.X, Eigen::VectorXd::Constant(n, s.P), W);
    double volume_rate = 0.0;
    for (int i = 0; i < n; ++i)
      for (int a = 0; a < dim; ++a) {
        out[a * n + i] += geometric(i, a) + s.S(i, a) * v[p];
        volume_rate += s.S(i, a) * W(i, a);
      }
    out[p] += volume_rate;
  }

 private:
  const TermContext& c_;
};

// ---- Loads ---------------------------------------------------------------------

// A force on one vertex, lambda F: dead (no tangent).
class PointLoadTerm final : public EquilibriumTerm {
 public:
  PointLoadTerm(const TermContext& c, size_t index) : c_(c), index_(index) {}
  const char* name() const override { return "point load"; }
  Role role() const override { return Role::Load; }
  void add_residual(const TermState& s, Eigen::VectorXd& R) const override {
    const Load& load = c_.model.loads[index_];
    for (int a = 0; a < c_.model.dim(); ++a)
      R[c_.model.dof(load.vertex, a)] -= s.factors[index_] * load.force[a];
  }
  void add_tangent(const TermState&, TangentSink&) const override {}
  void add_tangent_product(const TermState&, const Eigen::VectorXd&, const Eigen::MatrixXd&,
                           Eigen::VectorXd&) const override {}

 private:
  const TermContext& c_;
  size_t index_;
};

// The fluid's weight, q_i(x) S_i(x) outward (loads.hpp), a follower load:
// q_i = lambda rho |a| h_i with h_i the depth of x_i below the highest
// reference point, so dq_i/dx_i = lambda rho a (the same for every i).
class HydrostaticLoadTerm final : public EquilibriumTerm {
 public:
  HydrostaticLoadTerm(const TermContext& c, size_t index)
      : c_(c),
        index_(index),
        level_(hydrostatic_level(c.model.surface.V, c.model.loads[index].acceleration)) {}
  const char* name() const override { return "hydrostatic load"; }
  Role role() const override { return Role::Load; }
  void add_residual(const TermState& s, Eigen::VectorXd& R) const override {
    if (inactive(s)) return;
    const Eigen::VectorXd q = pressures(s);
    const int n = c_.model.num_vertices();
    if (exact()) {
      const Eigen::MatrixXd forces = exact_pressure_forces(s.X, c_.model.surface.F, q);
      for (int a = 0; a < c_.model.dim(); ++a) R.segment(a * n, n) -= forces.col(a);
      return;
    }
    for (int a = 0; a < c_.model.dim(); ++a) R.segment(a * n, n) -= q.cwiseProduct(s.S.col(a));
  }
  void add_tangent(const TermState& s, TangentSink& J) const override {
    if (inactive(s)) return;
    const int n = c_.model.num_vertices(), dim = c_.model.dim();
    if (exact()) return add_exact_tangent(s, J);
    add_area_vector_tangent(c_, s.X, -pressures(s), J);
    const Eigen::Vector3d gradient = pressure_gradient(s);
    for (int i = 0; i < n; ++i)
      for (int a = 0; a < dim; ++a)
        for (int b = 0; b < dim; ++b) J.add(a * n + i, b * n + i, -(s.S(i, a) * gradient[b]));
  }
  void add_tangent_product(const TermState& s, const Eigen::VectorXd&, const Eigen::MatrixXd& W,
                           Eigen::VectorXd& out) const override {
    if (inactive(s)) return;
    const int n = c_.model.num_vertices(), dim = c_.model.dim();
    if (exact()) return add_exact_tangent_product(s, W, out);
    const Eigen::MatrixXd geometric = area_vector_product(c_, s.X, -pressures(s), W);
    const Eigen::Vector3d gradient = pressure_gradient(s);
    for (int i = 0; i < n; ++i) {
      const double along = gradient.head(dim).dot(W.row(i).transpose());
      for (int a = 0; a < dim; ++a) out[a * n + i] += geometric(i, a) - s.S(i, a) * along;
    }
  }

 private:
  const Load& load() const { return c_.model.loads[index_]; }
  bool exact() const { return load().integration == Load::Integration::Exact; }
  // What both exact-form tangents read at a state: the corners' shares of
  // the faces' area vectors (loads.hpp), the pressures' gradient and the
  // faces' area vectors.
  struct ExactState {
    ExactFaceShares shares;
    Eigen::Vector3d g;
    Eigen::MatrixXd A;
  };
  ExactState exact_state(const TermState& s) const {
    const Eigen::MatrixXi& F = c_.model.surface.F;
    return {ExactFaceShares(F, pressures(s)), pressure_gradient(s),
            geom::face_area_vectors(s.X, F)};
  }
  // J -= d(sum_f A_f w_if)/dx: the face's turning (dA_f/dx_v) and its pressures' change.
  void add_exact_tangent(const TermState& s, TangentSink& J) const {
    const int n = c_.model.num_vertices(), dim = c_.model.dim();
    const Eigen::MatrixXi& F = c_.model.surface.F;
    const ExactState e = exact_state(s);
    for (Eigen::Index f = 0; f < F.rows(); ++f)
      for (Eigen::Index k = 0; k < F.cols(); ++k) {
        const int v = F(f, k);
        const Eigen::Matrix3d dA = face_area_derivative(s.X, F, f, static_cast<int>(k));
        for (Eigen::Index corner = 0; corner < F.cols(); ++corner) {
          const int i = F(f, corner);
          const double w = e.shares.w(i, f), dw = e.shares.per_pressure * (i == v ? 2.0 : 1.0);
          for (int a = 0; a < dim; ++a)
            for (int b = 0; b < dim; ++b)
              J.add(a * n + i, b * n + v, -(w * dA(a, b) + e.A(f, a) * dw * e.g[b]));
        }
      }
  }
  void add_exact_tangent_product(const TermState& s, const Eigen::MatrixXd& W,
                                 Eigen::VectorXd& out) const {
    const int n = c_.model.num_vertices(), dim = c_.model.dim();
    const Eigen::MatrixXi& F = c_.model.surface.F;
    const ExactState e = exact_state(s);
    const Eigen::VectorXd rate = W * e.g.head(dim);  // g . w_v per vertex
    for (Eigen::Index f = 0; f < F.rows(); ++f) {
      double rate_sum = 0.0;
      for (Eigen::Index k = 0; k < F.cols(); ++k) rate_sum += rate[F(f, k)];
      const Eigen::Vector3d dA = face_area_rate(s.X, F, f, W);
      for (Eigen::Index corner = 0; corner < F.cols(); ++corner) {
        const int i = F(f, corner);
        const double dw = e.shares.per_pressure * (rate[i] + rate_sum);
        for (int a = 0; a < dim; ++a) out[a * n + i] -= e.shares.w(i, f) * dA[a] + e.A(f, a) * dw;
      }
    }
  }
  bool inactive(const TermState& s) const {
    return s.factors[index_] == 0.0 || load().acceleration.norm() == 0.0;
  }
  Eigen::VectorXd pressures(const TermState& s) const {
    return hydrostatic_pressure_per_depth(load(), s.factors[index_]) *
           hydrostatic_heads(s.X, load().acceleration, level_);
  }
  Eigen::Vector3d pressure_gradient(const TermState& s) const {
    const Eigen::Vector3d direction = load().acceleration / load().acceleration.norm();
    return hydrostatic_pressure_per_depth(load(), s.factors[index_]) * direction;
  }

  const TermContext& c_;
  size_t index_;
  double level_;
};

}  // namespace

std::unique_ptr<EquilibriumTerm> make_load_term(const TermContext& c, size_t index) {
  switch (c.model.loads[index].kind) {
    case Load::Kind::Point:
      return std::make_unique<PointLoadTerm>(c, index);
    case Load::Kind::Hydrostatic:
      return std::make_unique<HydrostaticLoadTerm>(c, index);
  }
  throw std::invalid_argument("load " + std::to_string(index) + " is of an unknown kind");
}

std::vector<FiberReading> surface_fiber_readings(const TermContext& c, const TermState& s) {
  return SurfaceTensionTerm(c).readings(s);
}

std::vector<std::unique_ptr<EquilibriumTerm>> make_surface_and_load_terms(const TermContext& c) {
  std::vector<std::unique_ptr<EquilibriumTerm>> terms;
  terms.push_back(std::make_unique<SurfaceTensionTerm>(c));
  terms.push_back(std::make_unique<PressureVolumeTerm>(c));
  for (size_t l = 0; l < c.model.loads.size(); ++l) terms.push_back(make_load_term(c, l));
  return terms;
}

}  // namespace fiberfluid::model

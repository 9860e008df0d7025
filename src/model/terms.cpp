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

// Where each vertex's partners start in a sparse mask's pairs listed row by
// row (the listed coefficients' layout), N + 1 entries.
std::vector<size_t> list_offsets(const geom::FiberMask& mask) {
  std::vector<size_t> offsets(static_cast<size_t>(mask.num_vertices()) + 1, 0);
  for (int i = 0; i < mask.num_vertices(); ++i)
    offsets[static_cast<size_t>(i) + 1] =
        offsets[static_cast<size_t>(i)] + mask.neighbours(i).size();
  return offsets;
}

// A fiber's reading from its force coefficients (pair_stencil.hpp): the
// residual's part on i is m (c1 g), the force the fiber exerts on i its
// opposite. b = x_i - x_j, d = u_i - u_j, L its reference length.
template <class K>
FiberReading read_fiber(int i, int j, const PairCoefficients& c, const Eigen::Vector3d& b,
                        const Eigen::Vector3d& d, double L, const Eigen::Vector3d& m) {
  FiberReading out;
  out.i = i;
  out.j = j;
  const double r = b.norm();
  out.strain = fiber_strain(r, L);
  Eigen::Vector3d residual;
  for (int a = 0; a < 3; ++a) residual[a] = m[a] * pair_force<K>(c, b[a], d[a]);
  out.force = -residual;
  out.tension = residual.dot(b) / r;  // the force on i along x_j - x_i
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
    for_each_edge(s, gamma(),
                  [&](auto policy, int i, int k, const PairCoefficients& c,
                      const Eigen::Vector3d& b, const Eigen::Vector3d& d) {
                    if (i > k) return;
                    const double L = (padded_row(V0, i) - padded_row(V0, k)).norm();
                    out.push_back(read_fiber<decltype(policy)>(i, k, c, b, d, L, no_factors));
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

// ---- Bulk fibers ---------------------------------------------------------------

namespace {

// The bulk fibers at X, U as the tiled kernels visit them.
DeformedPairs deformed_pairs(const TermContext& c, const Eigen::MatrixXd& X,
                             const Eigen::MatrixXd& U) {
  return DeformedPairs(c.model.surface.V, X, U, c.area0, c.pair_factors, c.model.material.law,
                       c.model.material.kinematics);
}

// Column pointers of the reference, current and displacement rows (three
// each; the third is all zeros in 2D).
struct Columns {
  const double* s[3];
  const double* x[3];
  const double* u[3];
  std::vector<double> zeros;

  Columns(const Eigen::MatrixXd& S, const Eigen::MatrixXd& X, const Eigen::MatrixXd& U)
      : zeros(static_cast<size_t>(S.rows()), 0.0) {
    for (int a = 0; a < 3; ++a) {
      const bool has = a < S.cols();
      s[a] = has ? S.col(a).data() : zeros.data();
      x[a] = has ? X.col(a).data() : zeros.data();
      u[a] = has ? U.col(a).data() : zeros.data();
    }
  }
};

// One row's pair state for dR/dtheta: h, L, r, strain, Y, Y' for every j.
struct RowState {
  std::vector<double> h, L, r, e, Y, Yp, dY;
  explicit RowState(size_t n) : h(n), L(n), r(n), e(n), Y(n), Yp(n), dY(n) {}
};

void fill_row(const TermContext& c, int i, const Columns& col, RowState& row) {
  const size_t n = static_cast<size_t>(c.model.num_vertices()), u = static_cast<size_t>(i);
  c.pair_factors.row(i, row.h.data());
  double *L = row.L.data(), *r = row.r.data(), *e = row.e.data();
  const double *s0 = col.s[0], *s1 = col.s[1], *s2 = col.s[2];
  const double *x0 = col.x[0], *x1 = col.x[1], *x2 = col.x[2];
#pragma omp simd
  for (size_t j = 0; j < n; ++j) {
    // j == i: h = 0 makes the pair vanish; lengths 1 there only avoid 0/0.
    L[j] = j == u ? 1.0 : pair_length(s0[u] - s0[j], s1[u] - s1[j], s2[u] - s2[j]);
    r[j] = j == u ? 1.0 : pair_length(x0[u] - x0[j], x1[u] - x1[j], x2[u] - x2[j]);
    e[j] = fiber_strain(r[j], L[j]);
  }
  c.model.material.law.evaluate(e, n, row.Y.data(), row.Yp.data());
}

}  // namespace

void BulkFiberTerm::coefficients(const Eigen::MatrixXd& X, const Eigen::MatrixXd& U,
                                 Eigen::MatrixXf* c1, Eigen::MatrixXf* c2) const {
  deformed_pairs(c_, X, U).coefficients(c1, c2);
}

void BulkFiberTerm::add_residual(const TermState& s, Eigen::VectorXd& R) const {
  const int n = c_.model.num_vertices();
  const Eigen::Vector3d m = c_.model.material.axis_factors;
  const Eigen::MatrixXd bulk = deformed_pairs(c_, s.X, s.U).forces();
  for (int a = 0; a < c_.model.dim(); ++a) R.segment(a * n, n) += m[a] * bulk.col(a);
}

void BulkFiberTerm::add_residual_and_coefficients(const TermState& s, Eigen::VectorXd& R,
                                                  Eigen::MatrixXf* c1, Eigen::MatrixXf* c2) const {
  const int n = c_.model.num_vertices();
  const Eigen::Vector3d m = c_.model.material.axis_factors;
  const Eigen::MatrixXd bulk = deformed_pairs(c_, s.X, s.U).forces_and_coefficients(c1, c2);
  for (int a = 0; a < c_.model.dim(); ++a) R.segment(a * n, n) += m[a] * bulk.col(a);
}

void BulkFiberTerm::add_tangent_product(const TermState& s, const Eigen::VectorXd&,
                                        const Eigen::MatrixXd& W, Eigen::VectorXd& out) const {
  const int n = c_.model.num_vertices();
  const Eigen::Vector3d m = c_.model.material.axis_factors;
  const Eigen::MatrixXd bulk = deformed_pairs(c_, s.X, s.U).tangent_product(W);
  for (int a = 0; a < c_.model.dim(); ++a) out.segment(a * n, n) += m[a] * bulk.col(a);
}

void BulkFiberTerm::add_tangent(const TermState& s, TangentSink& J) const {
  if (sparse()) {
    std::vector<double> c1, c2;
    listed_coefficients(s.X, s.U, &c1, &c2);
    return add_listed_blocks(s.X, s.U, c1, c2, J);
  }
  Eigen::MatrixXd c1, c2;  // in double: the dense tangent is exact
  deformed_pairs(c_, s.X, s.U).coefficients(&c1, &c2);
  if (J.dense() != nullptr) return add_dense_blocks(s.X, s.U, c1, c2, *J.dense());
  // Every pair kept (or a dense mask) into a sparse tangent: N^2 entries.
  const int n = c_.model.num_vertices();
  Eigen::MatrixXd bulk = Eigen::MatrixXd::Zero(c_.model.num_unknowns(), c_.model.num_unknowns());
  add_dense_blocks(s.X, s.U, c1, c2, bulk);
  for (Eigen::Index col = 0; col < c_.model.dim() * n; ++col)
    for (Eigen::Index row = 0; row < c_.model.dim() * n; ++row)
      if (bulk(row, col) != 0.0) J.add(row, col, bulk(row, col));
}

bool BulkFiberTerm::sparse() const {
  return c_.pair_factors.mask() != nullptr && c_.pair_factors.mask()->sparse();
}

void BulkFiberTerm::listed_coefficients(const Eigen::MatrixXd& X, const Eigen::MatrixXd& U,
                                        std::vector<double>* c1, std::vector<double>* c2) const {
  deformed_pairs(c_, X, U).listed_coefficients(c1, c2);
}

std::vector<FiberReading> BulkFiberTerm::readings(
    const TermState& s, const std::vector<std::pair<int, int>>& pairs) const {
  // Each pair's c1, from the kernels that the residual uses.
  std::vector<double> force_coefficient(pairs.size(), 0.0);
  std::vector<double> c1, c2;
  if (sparse()) {
    listed_coefficients(s.X, s.U, &c1, &c2);
    const geom::FiberMask& mask = *c_.pair_factors.mask();
    const std::vector<size_t> offsets = list_offsets(mask);
    for (size_t p = 0; p < pairs.size(); ++p) {
      const auto [i, j] = pairs[p];
      const std::vector<int>& partners = mask.neighbours(i);
      const auto at = std::lower_bound(partners.begin(), partners.end(), j);
      if (at != partners.end() && *at == j)  // not listed: pruned
        force_coefficient[p] =
            c1[offsets[static_cast<size_t>(i)] + static_cast<size_t>(at - partners.begin())];
    }
  } else {
    Eigen::MatrixXd dense_c1, dense_c2;
    deformed_pairs(c_, s.X, s.U).coefficients(&dense_c1, &dense_c2);  // double: exact readings
    for (size_t p = 0; p < pairs.size(); ++p) {  // stored once: row max(i, j), column min
      const auto [i, j] = pairs[p];
      force_coefficient[p] = dense_c1(std::max(i, j), std::min(i, j));
    }
  }
  std::vector<FiberReading> out(pairs.size());
  const Eigen::MatrixXd& V0 = c_.model.surface.V;
  const Eigen::Vector3d m = c_.model.material.axis_factors;
  with_kinematics(c_.model.material.kinematics, [&](auto policy) {
    using K = decltype(policy);
    for (size_t p = 0; p < pairs.size(); ++p) {
      const auto [i, j] = pairs[p];
      out[p] =
          read_fiber<K>(i, j, {force_coefficient[p], 0.0}, padded_row(s.X, i) - padded_row(s.X, j),
                        padded_row(s.U, i) - padded_row(s.U, j),
                        (padded_row(V0, i) - padded_row(V0, j)).norm(), m);
    }
  });
  return out;
}

template <class Body>
void BulkFiberTerm::for_each_listed_row(const std::vector<double>& c1,
                                        const std::vector<double>& c2, Body&& body) const {
  const geom::FiberMask& mask = *c_.pair_factors.mask();
  const int n = c_.model.num_vertices();
  const std::vector<size_t> offsets = list_offsets(mask);
#pragma omp parallel for schedule(dynamic, 64)
  for (int i = 0; i < n; ++i)
    body(i, mask.neighbours(i), c1.data() + offsets[static_cast<size_t>(i)],
         c2.data() + offsets[static_cast<size_t>(i)]);
}

void BulkFiberTerm::add_listed_blocks(const Eigen::MatrixXd& X, const Eigen::MatrixXd& U,
                                      const std::vector<double>& C1, const std::vector<double>& C2,
                                      TangentSink& J) const {
  const int n = c_.model.num_vertices(), dim = c_.model.dim();
  const Eigen::Vector3d m = c_.model.material.axis_factors;
  // Row i's entries: -m_a T_ab(i, j) at (a i, b j) for each partner j, and
  // their sum with the sign turned at (a i, b i); rows gathered per thread.
  std::vector<std::vector<Eigen::Triplet<double>>> rows(static_cast<size_t>(n));
  with_kinematics(c_.model.material.kinematics, [&](auto policy) {
    using K = decltype(policy);
    for_each_listed_row(
        C1, C2, [&](int i, const std::vector<int>& partners, const double* c1, const double* c2) {
          std::vector<Eigen::Triplet<double>>& out = rows[static_cast<size_t>(i)];
          out.reserve(partners.size() * dim * dim + dim * dim);
          double diagonal[3][3] = {{0, 0, 0}, {0, 0, 0}, {0, 0, 0}};
          for (size_t q = 0; q < partners.size(); ++q) {
            const int j = partners[q];
            const PairCoefficients c{c1[q], c2[q]};
            for (int a = 0; a < dim; ++a)
              for (int b = 0; b < dim; ++b) {
                const double t = pair_tangent_entry<K>(c, a == b, X(i, a) - X(j, a),
                                                       U(i, a) - U(j, a), X(i, b) - X(j, b));
                diagonal[a][b] += t;
                out.emplace_back(a * n + i, b * n + j, -m[a] * t);
              }
          }
          for (int a = 0; a < dim; ++a)
            for (int b = 0; b < dim; ++b)
              out.emplace_back(a * n + i, b * n + i, m[a] * diagonal[a][b]);
        });
  });
  for (const auto& row : rows)
    for (const Eigen::Triplet<double>& t : row) J.add(t.row(), t.col(), t.value());
}

void BulkFiberTerm::add_listed_product(const Eigen::MatrixXd& X, const Eigen::MatrixXd& U,
                                       const std::vector<double>& C1, const std::vector<double>& C2,
                                       const Eigen::MatrixXd& W, Eigen::VectorXd& out) const {
  const int n = c_.model.num_vertices(), dim = c_.model.dim();
  const Eigen::Vector3d m = c_.model.material.axis_factors;
  with_kinematics(c_.model.material.kinematics, [&](auto policy) {
    using K = decltype(policy);
    for_each_listed_row(
        C1, C2, [&](int i, const std::vector<int>& partners, const double* c1, const double* c2) {
          double product[3] = {0.0, 0.0, 0.0};
          for (size_t q = 0; q < partners.size(); ++q) {
            const int j = partners[q];
            Eigen::Vector3d b = Eigen::Vector3d::Zero(), v = Eigen::Vector3d::Zero(),
                            d = Eigen::Vector3d::Zero();
            for (int a = 0; a < dim; ++a) {
              b[a] = X(i, a) - X(j, a);
              v[a] = W(i, a) - W(j, a);
              d[a] = U(i, a) - U(j, a);
            }
            const double b_dot_v = b.dot(v);
            for (int a = 0; a < dim; ++a)
              product[a] += pair_tangent<K>({c1[q], c2[q]}, v[a], b_dot_v, b[a], d[a]);
          }
          for (int a = 0; a < dim; ++a) out[a * n + i] += m[a] * product[a];
        });
  });
}

void BulkFiberTerm::add_dense_blocks(const Eigen::MatrixXd& X, const Eigen::MatrixXd& U,
                                     const Eigen::MatrixXd& C1, const Eigen::MatrixXd& C2,
                                     Eigen::MatrixXd& J) const {
  const int n = c_.model.num_vertices(), dim = c_.model.dim();
  const Eigen::Vector3d m = c_.model.material.axis_factors;
  // For j != i: J(a i, b j) = -m_a T_ab(i, j) (the stencil's
  // pair_tangent_entry), and each diagonal block is minus the sum of its
  // row's off-diagonal ones. The coefficients are symmetric, stored once
  // (the lower triangle: column min(i, j), row max(i, j)).
  const auto pair = [&](int i, int j) -> PairCoefficients {
    const int low = std::min(i, j), high = std::max(i, j);
    return {C1(high, low), C2(high, low)};
  };
  with_kinematics(c_.model.material.kinematics, [&](auto policy) {
    using K = decltype(policy);
    // T_ab of the pair (i, j) with its coefficients c.
    const auto block = [&](int i, int j, const PairCoefficients& c, int a, int b) {
      return pair_tangent_entry<K>(c, a == b, X(i, a) - X(j, a), U(i, a) - U(j, a),
                                   X(i, b) - X(j, b));
    };
#pragma omp parallel for schedule(dynamic, 16)
    for (int j = 0; j < n; ++j)
      for (int a = 0; a < dim; ++a)
        for (int b = 0; b < dim; ++b) {
          double* column = J.col(b * n + j).data() + a * n;
          for (int i = 0; i < n; ++i)
            if (i != j) column[i] += -m[a] * block(i, j, pair(i, j), a, b);
        }
#pragma omp parallel for schedule(dynamic, 16)
    for (int i = 0; i < n; ++i)
      for (int a = 0; a < dim; ++a)
        for (int b = 0; b < dim; ++b) {
          double sum = 0.0;
          for (int j = 0; j < n; ++j)
            if (j != i) sum += block(i, j, pair(i, j), a, b);
          J(a * n + i, b * n + i) += m[a] * sum;
        }
  });
}

void BulkFiberTerm::add_stored_product(const Eigen::MatrixXd& X, const Eigen::MatrixXd& U,
                                       const Eigen::MatrixXf& C1, const Eigen::MatrixXf& C2,
                                       const Eigen::MatrixXd& W, Eigen::VectorXd& out) const {
  const int n = c_.model.num_vertices(), dim = c_.model.dim();
  const Eigen::Vector3d m = c_.model.material.axis_factors;
  const Eigen::MatrixXd product =
      stored_tangent_product(c_.model.material.kinematics, X, U, C1, C2, W);
  for (int a = 0; a < dim; ++a) out.segment(a * n, n) += m[a] * product.col(a);
}

void BulkFiberTerm::add_parameter_derivative(const TermState& s, const MaterialParameter& p,
                                             Eigen::Ref<Eigen::VectorXd> column) const {
  if (p.kind == MaterialParameter::Kind::SurfaceTension) return;
  const int n = c_.model.num_vertices(), dim = c_.model.dim();
  const Eigen::Vector3d m = c_.model.material.axis_factors;
  const FiberLaw& law = c_.model.material.law;
  // factor_a: the fiber force of that axis over its factor; a law parameter:
  // m_a times the force's derivative in it.
  const int axis = p.kind == MaterialParameter::Kind::AxisFactor ? p.index : -1;
  const Columns col(c_.model.surface.V, s.X, s.U);
  with_kinematics(c_.model.material.kinematics, [&](auto policy) {
    using K = decltype(policy);
#pragma omp parallel
    {
      RowState row(static_cast<size_t>(n));
#pragma omp for schedule(dynamic, 16)
      for (int i = 0; i < n; ++i) {
        fill_row(c_, i, col, row);
        if (axis < 0) law.evaluate_derivative(p.index, row.e.data(), row.e.size(), row.dY.data());
        const auto u = static_cast<size_t>(i);
        double sum[3] = {0.0, 0.0, 0.0};
        for (size_t j = 0; j < static_cast<size_t>(n); ++j) {
          if (row.h[j] == 0.0) continue;
          const double a =
              bulk_weight(row.h[j], c_.area0[i], c_.area0[static_cast<Eigen::Index>(j)], row.L[j]);
          const PairCoefficients pc = K::coefficients(a, row.Y[j], row.Yp[j], row.r[j], row.L[j]);
          const double dY = axis >= 0 ? 0.0 : row.dY[j];
          for (int k = 0; k < 3; ++k) {
            const double b = col.x[k][u] - col.x[k][j], d = col.u[k][u] - col.u[k][j];
            sum[k] += axis >= 0 ? pair_force<K>(pc, b, d)
                                : pair_parameter_force<K>(a, dY, row.r[j], row.L[j], b, d);
          }
        }
        if (axis >= 0)
          column[axis * n + i] += sum[axis];
        else
          for (int a = 0; a < dim; ++a) column[a * n + i] += m[a] * sum[a];
      }
    }
  });
}

}  // namespace fiberfluid::model

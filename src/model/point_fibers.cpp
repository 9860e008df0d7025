// SPDX-License-Identifier: GPL-3.0-or-later
#include "fiberfluid/model/point_fibers.hpp"

#include "fiberfluid/model/pair_stencil.hpp"

namespace fiberfluid::model {

namespace {

class PointFiberTerm final : public EquilibriumTerm {
 public:
  PointFiberTerm(const TermContext& c, std::vector<PointFiber> fibers, const char* name, Role role,
                 int support_group)
      : c_(c), fibers_(std::move(fibers)), name_(name), role_(role), group_(support_group) {}

  const char* name() const override { return name_; }
  Role role() const override { return role_; }
  int support_group() const override { return group_; }

  // The force on i is f, on p sign f (b moves with sign x_p).
  void add_residual(const TermState& s, Eigen::VectorXd& R) const override {
    const Eigen::Vector3d m = c_.model.material.axis_factors;
    for_each_fiber(s, [&](auto policy, const PointFiber& f, const State& st) {
      using K = decltype(policy);
      for (int a = 0; a < dim(); ++a) {
        const double force = m[a] * pair_force<K>(st.coefficients, st.b[a], st.d[a]);
        R[dof(f.i, a)] += force;
        R[dof(f.p, a)] += st.sign * force;
      }
    });
  }

  void add_tangent(const TermState& s, TangentSink& J) const override {
    const Eigen::Vector3d m = c_.model.material.axis_factors;
    for_each_fiber(s, [&](auto policy, const PointFiber& f, const State& st) {
      using K = decltype(policy);
      for (int a = 0; a < dim(); ++a)
        for (int e = 0; e < dim(); ++e) {
          const double entry =
              m[a] * pair_tangent_entry<K>(st.coefficients, a == e, st.b[a], st.d[a], st.b[e]);
          J.add(dof(f.i, a), dof(f.i, e), entry);
          J.add(dof(f.i, a), dof(f.p, e), st.sign * entry);
          J.add(dof(f.p, a), dof(f.i, e), st.sign * entry);
          J.add(dof(f.p, a), dof(f.p, e), entry);
        }
    });
  }

  void add_tangent_product(const TermState& s, const Eigen::VectorXd& /*v*/,
                           const Eigen::MatrixXd& W, Eigen::VectorXd& out) const override {
    const Eigen::Vector3d m = c_.model.material.axis_factors;
    for_each_fiber(s, [&](auto policy, const PointFiber& f, const State& st) {
      using K = decltype(policy);
      const Eigen::Vector3d w = padded_row(W, f.i) + st.sign * padded_row(W, f.p);
      const double b_dot_w = st.b.dot(w);
      for (int a = 0; a < dim(); ++a) {
        const double value =
            m[a] * pair_tangent<K>(st.coefficients, w[a], b_dot_w, st.b[a], st.d[a]);
        out[dof(f.i, a)] += value;
        out[dof(f.p, a)] += st.sign * value;
      }
    });
  }

  void add_parameter_derivative(const TermState& s, const MaterialParameter& p,
                                Eigen::Ref<Eigen::VectorXd> column) const override {
    if (p.kind == MaterialParameter::Kind::SurfaceTension) return;
    const Eigen::Vector3d m = c_.model.material.axis_factors;
    const FiberLaw& law = c_.model.material.law;
    for_each_fiber(s, [&](auto policy, const PointFiber& f, const State& st) {
      using K = decltype(policy);
      for (int a = 0; a < dim(); ++a) {
        double value = 0.0;
        if (p.kind == MaterialParameter::Kind::AxisFactor) {  // the force over its factor
          if (a != p.index) continue;
          value = pair_force<K>(st.coefficients, st.b[a], st.d[a]);
        } else {
          value = m[a] * pair_parameter_force<K>(f.weight, law.modulus_derivative(p.index, st.e),
                                                 st.r, f.length, st.b[a], st.d[a]);
        }
        column[dof(f.i, a)] += value;
        column[dof(f.p, a)] += st.sign * value;
      }
    });
  }

 private:
  struct State {
    Eigen::Vector3d b, d;  // x_i minus the far point, u_i minus its displacement
    double sign = -1.0;    // +1 mirrored, -1 carried
    double r = 0.0, e = 0.0;
    PairCoefficients coefficients{0.0, 0.0};
  };

  int dim() const { return c_.model.dim(); }
  Eigen::Index dof(int vertex, int axis) const { return c_.model.dof(vertex, axis); }

  // body(policy, fiber, state) for each fiber at the state s.
  template <class Body>
  void for_each_fiber(const TermState& s, Body&& body) const {
    const FiberLaw& law = c_.model.material.law;
    with_kinematics(c_.model.material.kinematics, [&](auto policy) {
      State st;
      for (const PointFiber& f : fibers_) {
        using K = decltype(policy);
        st.sign = f.mirrored ? 1.0 : -1.0;
        st.b = padded_row(s.X, f.i) + st.sign * padded_row(s.X, f.p) - f.offset;
        st.d = padded_row(s.U, f.i) + st.sign * padded_row(s.U, f.p);
        st.r = st.b.norm();
        st.e = fiber_strain(st.r, f.length);
        st.coefficients =
            K::coefficients(f.weight, law.modulus(st.e), law.slope(st.e), st.r, f.length);
        body(policy, f, st);
      }
    });
  }

  const TermContext& c_;
  std::vector<PointFiber> fibers_;
  const char* name_;
  Role role_;
  int group_;
};

}  // namespace

std::unique_ptr<EquilibriumTerm> make_point_fiber_term(const TermContext& context,
                                                       std::vector<PointFiber> fibers,
                                                       const char* name, EquilibriumTerm::Role role,
                                                       int support_group) {
  return std::make_unique<PointFiberTerm>(context, std::move(fibers), name, role, support_group);
}

}  // namespace fiberfluid::model

// SPDX-License-Identifier: GPL-3.0-or-later
#include "model/equilibrium.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <stdexcept>

#include "geom/area_vectors.hpp"
#include "geom/error.hpp"
#include "model/assembly.hpp"
#include "model/pair_stencil.hpp"

namespace fiberfluid::model {
namespace {

Eigen::Vector3d row3(const Eigen::MatrixXd& M, Eigen::Index i) {
  Eigen::Vector3d v = Eigen::Vector3d::Zero();
  v.head(M.cols()) = M.row(i).transpose();
  return v;
}

Eigen::Matrix3d cross_matrix(const Eigen::Vector3d& w) {
  Eigen::Matrix3d m;
  m << 0, -w.z(), w.y(), w.z(), 0, -w.x(), -w.y(), w.x(), 0;
  return m;
}

// dA_f/dx_v for the k-th corner of face f (dim x dim, padded to 3x3). 3D:
// A_f = (x0 x x1 + x1 x x2 + x2 x x0) / 2, so dA_f/dx_k = [x_{k+2} - x_{k+1}]_x / 2.
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

}  // namespace

struct Equilibrium::Hydrostatics {
  Eigen::VectorXd q;                                 // q_i
  Eigen::Vector3d gradient = Eigen::Vector3d::Zero();  // dq_i/dx_i, the same for every i
};

Equilibrium::Equilibrium(const Model& model)
    : model_(model),
      factors_(model.fibers.get(), model.connection_count, model.num_vertices()) {
  const Eigen::MatrixXd& V = model.surface.V;
  const geom::VertexAreaVectors areas = geom::vertex_area_vectors(V, model.surface.F);
  area0_ = areas.magnitude;
  C0_ = areas.C;
  volume0_ = geom::enclosed_volume(V, model.surface.F);
  // Two coincident vertices would make a fiber of zero length: sorted by
  // their coordinates, equal ones are neighbours (N log N, not N^2).
  std::vector<int> order(static_cast<size_t>(V.rows()));
  std::iota(order.begin(), order.end(), 0);
  const auto before = [&V](int a, int b) {
    for (Eigen::Index c = 0; c < V.cols(); ++c)
      if (V(a, c) != V(b, c)) return V(a, c) < V(b, c);
    return false;
  };
  std::sort(order.begin(), order.end(), before);
  for (size_t k = 1; k < order.size(); ++k)
    if (V.row(order[k - 1]) == V.row(order[k]))
      throw InputError("vertices " + std::to_string(std::min(order[k - 1], order[k])) + " and " +
                       std::to_string(std::max(order[k - 1], order[k])) +
                       " coincide: the fiber between them has zero length");
  surface_ = surface_tension_laplacian(V, area0_, geom::unique_edges(model.surface));
  for (const Load& load : model.loads) {
    double level = 0.0;
    const double magnitude = load.acceleration.norm();
    if (load.kind == Load::Kind::Hydrostatic && magnitude > 0.0)
      level = (V * (load.acceleration.head(model.dim()) / magnitude)).minCoeff();
    levels_.push_back(level);
  }
}

Eigen::MatrixXd Equilibrium::current_area_vectors(const Eigen::MatrixXd& X) const {
  return C0_ * geom::summed_face_area_vectors(X, model_.surface.F);
}

Equilibrium::Hydrostatics Equilibrium::hydrostatics(const Eigen::MatrixXd& X,
                                                    const std::vector<double>& factors) const {
  Hydrostatics h;
  h.q = Eigen::VectorXd::Zero(X.rows());
  for (size_t l = 0; l < model_.loads.size(); ++l) {
    const Load& load = model_.loads[l];
    const double magnitude = load.acceleration.norm();
    if (load.kind != Load::Kind::Hydrostatic || magnitude == 0.0 || factors[l] == 0.0) continue;
    const Eigen::Vector3d direction = load.acceleration / magnitude;
    const double scale = factors[l] * load.density * magnitude;
    h.q += scale * ((X * direction.head(X.cols())).array() - levels_[l]).matrix();
    h.gradient += scale * direction;
  }
  return h;
}

// Column pointers of the reference, current and displacement vectors (three
// each; the third is all zeros in 2D).
struct Equilibrium::Columns {
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

void Equilibrium::bulk_row(int i, const Columns& c, std::vector<double>* scratch) const {
  const size_t n = static_cast<size_t>(model_.num_vertices()), u = static_cast<size_t>(i);
  double* h = scratch[0].data();   // h_ij
  double* L = scratch[1].data();   // reference lengths
  double* r = scratch[2].data();   // current lengths
  double* Y = scratch[3].data();   // Y(e_ij)
  double* Yp = scratch[4].data();  // Y'(e_ij)
  factors_.row(i, h);
  const double *s0 = c.s[0], *s1 = c.s[1], *s2 = c.s[2];
  const double *x0 = c.x[0], *x1 = c.x[1], *x2 = c.x[2];
#pragma omp simd
  for (size_t j = 0; j < n; ++j) {
    // j == i: h = 0 makes the pair vanish; lengths 1 there only avoid 0/0.
    const double a0 = s0[u] - s0[j], a1 = s1[u] - s1[j], a2 = s2[u] - s2[j];
    const double b0 = x0[u] - x0[j], b1 = x1[u] - x1[j], b2 = x2[u] - x2[j];
    L[j] = j == u ? 1.0 : pair_length(a0, a1, a2);
    r[j] = j == u ? 1.0 : pair_length(b0, b1, b2);
  }
  const FiberLaw& law = model_.material.law;
  if (!law.is_constant()) {
    double* strain = scratch[5].data();
#pragma omp simd
    for (size_t j = 0; j < n; ++j) strain[j] = fiber_strain(r[j], L[j]);
  }
  law.evaluate(scratch[5].data(), n, Y, Yp);
}

// Runs bulk_row over every row on the OpenMP threads, each with its own
// scratch arrays, and hands visit(i, scratch) the results.
template <class Visit>
void Equilibrium::parallel_rows(const Columns& columns, Visit&& visit) const {
  const int n = model_.num_vertices();
#pragma omp parallel
  {
    std::vector<double> scratch[6];
    for (auto& v : scratch) v.resize(static_cast<size_t>(n));
#pragma omp for schedule(dynamic, 16)
    for (int i = 0; i < n; ++i) {
      bulk_row(i, columns, scratch);
      visit(i, scratch);
    }
  }
}

DeformedPairs Equilibrium::bulk_pairs(const Eigen::MatrixXd& X, const Eigen::MatrixXd& U) const {
  return DeformedPairs(model_.surface.V, X, U, area0_, factors_, model_.material.law,
                       model_.material.kinematics);
}

Eigen::MatrixXd Equilibrium::fiber_forces(const Eigen::VectorXd& x) const {
  const Eigen::MatrixXd X = positions(model_, x), U = displacements(model_, x);
  const int n = model_.num_vertices(), dim = model_.dim();
  const Eigen::Vector3d m = model_.material.axis_factors;
  const Eigen::MatrixXd bulk = bulk_pairs(X, U).forces();
  Eigen::MatrixXd forces(n, dim);
  for (int a = 0; a < dim; ++a) forces.col(a) = m[a] * bulk.col(a);
  return forces + model_.material.surface_tension * (surface_ * U);
}

Eigen::VectorXd Equilibrium::external_forces(const Eigen::VectorXd& x,
                                             const std::vector<double>& factors) const {
  const Eigen::MatrixXd X = positions(model_, x);
  const int n = model_.num_vertices(), dim = model_.dim();
  const Eigen::VectorXd q = hydrostatics(X, factors).q;
  const Eigen::MatrixXd S = current_area_vectors(X);
  Eigen::VectorXd F = Eigen::VectorXd::Zero(num_unknowns());
  for (int a = 0; a < dim; ++a) F.segment(a * n, n) = q.cwiseProduct(S.col(a));
  for (size_t l = 0; l < model_.loads.size(); ++l) {
    const Load& load = model_.loads[l];
    if (load.kind == Load::Kind::Point)
      for (int a = 0; a < dim; ++a) F[model_.dof(load.vertex, a)] += factors[l] * load.force[a];
  }
  return F;
}

Eigen::VectorXd Equilibrium::residual(const Eigen::VectorXd& x,
                                      const std::vector<double>& factors) const {
  const Eigen::MatrixXd X = positions(model_, x);
  const int n = model_.num_vertices(), dim = model_.dim();
  const double P = x[model_.pressure_dof()];
  const Eigen::MatrixXd S = current_area_vectors(X);
  const Eigen::MatrixXd fibers = fiber_forces(x);
  const Eigen::VectorXd external = external_forces(x, factors);
  Eigen::VectorXd R(num_unknowns());
  for (int a = 0; a < dim; ++a)
    R.segment(a * n, n) = fibers.col(a) + P * S.col(a) - external.segment(a * n, n);
  R[model_.pressure_dof()] =
      dim * C0_ * (geom::enclosed_volume(X, model_.surface.F) - volume0_);
  return R;
}

Eigen::MatrixXd Equilibrium::tangent(const Eigen::VectorXd& x,
                                     const std::vector<double>& factors) const {
  const TangentOperator op = linearize(x, factors);
  const Eigen::MatrixXd& X = op.X_;
  const Eigen::MatrixXd& U = op.U_;
  const int n = model_.num_vertices(), dim = model_.dim(), p = model_.pressure_dof();
  const Eigen::Vector3d m = model_.material.axis_factors;
  Eigen::MatrixXd J = Eigen::MatrixXd::Zero(num_unknowns(), num_unknowns());
  // Bulk blocks, column by column (the pair coefficients are symmetric, so
  // column j of the stored arrays runs over i): for j != i,
  //   J(a i, b j) = -m_a T_ab(i, j)   (the stencil's pair_tangent_entry),
  // and each diagonal block is minus the sum of its row's off-diagonal ones.
  with_kinematics(model_.material.kinematics, [&](auto policy) {
    using K = decltype(policy);
    // T_ab of the pair (i, j) with its coefficients c.
    const auto block = [&](int i, int j, const PairCoefficients& c, int a, int b) {
      return pair_tangent_entry<K>(c, a == b, X(i, a) - X(j, a), U(i, a) - U(j, a),
                                   X(i, b) - X(j, b));
    };
#pragma omp parallel for schedule(dynamic, 16)
    for (int j = 0; j < n; ++j) {
      const double* c1 = op.weighted_modulus_.col(j).data();
      const double* c2 = op.weighted_slope_.col(j).data();
      for (int a = 0; a < dim; ++a)
        for (int b = 0; b < dim; ++b) {
          double* column = J.col(b * n + j).data() + a * n;
          for (int i = 0; i < n; ++i)
            if (i != j) column[i] = -m[a] * block(i, j, {c1[i], c2[i]}, a, b);
        }
    }
#pragma omp parallel for schedule(dynamic, 16)
    for (int i = 0; i < n; ++i) {
      const double* c1 = op.weighted_modulus_.col(i).data();
      const double* c2 = op.weighted_slope_.col(i).data();
      for (int a = 0; a < dim; ++a)
        for (int b = 0; b < dim; ++b) {
          double sum = 0.0;  // c1_ii = c2_ii = 0: the pair (i, i) adds nothing
          for (int j = 0; j < n; ++j) sum += block(i, j, {c1[j], c2[j]}, a, b);
          J(a * n + i, b * n + i) = m[a] * sum;
        }
    }
  });
  const double gamma = model_.material.surface_tension;
  for (int col = 0; col < surface_.outerSize(); ++col)
    for (Eigen::SparseMatrix<double>::InnerIterator it(surface_, col); it; ++it)
      for (int a = 0; a < dim; ++a) J(a * n + it.row(), a * n + it.col()) += gamma * it.value();

  // Pressure and follower loads: (P - q_i) S_i(x), with dS_i/dx_v = C0 dA_f/dx_v
  // summed over the faces f at both i and v, and dq_i/dx_i = the gradient.
  const Hydrostatics hydro = hydrostatics(X, factors);
  const Eigen::VectorXd c = x[p] - hydro.q.array();
  const Eigen::MatrixXd S = current_area_vectors(X);
  const Eigen::MatrixXi& F = model_.surface.F;
  for (Eigen::Index f = 0; f < F.rows(); ++f)
    for (int k = 0; k < F.cols(); ++k) {
      const Eigen::Matrix3d dA = C0_ * face_area_derivative(X, F, f, k);
      const int v = F(f, k);
      for (int corner = 0; corner < F.cols(); ++corner) {
        const int i = F(f, corner);
        for (int a = 0; a < dim; ++a)
          for (int b = 0; b < dim; ++b) J(a * n + i, b * n + v) += c[i] * dA(a, b);
      }
    }
  for (int i = 0; i < n; ++i)
    for (int a = 0; a < dim; ++a) {
      for (int b = 0; b < dim; ++b) J(a * n + i, b * n + i) -= S(i, a) * hydro.gradient[b];
      J(a * n + i, p) = S(i, a);
      J(p, a * n + i) = S(i, a);
    }
  return J;
}

Eigen::VectorXd Equilibrium::tangent_product(const Eigen::VectorXd& x,
                                             const std::vector<double>& factors,
                                             const Eigen::VectorXd& v) const {
  const Eigen::MatrixXd X = positions(model_, x), U = displacements(model_, x);
  const Eigen::MatrixXd W = displacements(model_, v);
  const int n = model_.num_vertices(), dim = model_.dim();
  const Eigen::Vector3d m = model_.material.axis_factors;
  Eigen::VectorXd out = Eigen::VectorXd::Zero(num_unknowns());
  const Eigen::MatrixXd bulk = bulk_pairs(X, U).tangent_product(W);
  for (int a = 0; a < dim; ++a) out.segment(a * n, n) = m[a] * bulk.col(a);
  add_non_bulk_product(x, factors, X, v, out);
  return out;
}

void Equilibrium::add_non_bulk_product(const Eigen::VectorXd& x,
                                       const std::vector<double>& factors,
                                       const Eigen::MatrixXd& X, const Eigen::VectorXd& v,
                                       Eigen::VectorXd& out) const {
  const int n = model_.num_vertices(), dim = model_.dim(), p = model_.pressure_dof();
  const Eigen::MatrixXd W = displacements(model_, v);
  const Eigen::MatrixXd surface = model_.material.surface_tension * (surface_ * W);
  const Hydrostatics hydro = hydrostatics(X, factors);
  const Eigen::VectorXd c = x[p] - hydro.q.array();
  const Eigen::MatrixXd S = current_area_vectors(X);
  const Eigen::MatrixXi& F = model_.surface.F;
  Eigen::MatrixXd geometric = Eigen::MatrixXd::Zero(n, 3);
  for (Eigen::Index f = 0; f < F.rows(); ++f) {
    // sum_v dA_f/dx_v w_v, then spread over the corners with their c_i.
    Eigen::Vector3d dA = Eigen::Vector3d::Zero();
    for (int k = 0; k < F.cols(); ++k)
      dA += face_area_derivative(X, F, f, k) * row3(W, F(f, k));
    for (int corner = 0; corner < F.cols(); ++corner)
      geometric.row(F(f, corner)) += C0_ * c[F(f, corner)] * dA.transpose();
  }
  double volume_rate = 0.0;
  for (int i = 0; i < n; ++i) {
    const double along = hydro.gradient.head(dim).dot(W.row(i).transpose());
    for (int a = 0; a < dim; ++a) {
      out[a * n + i] += surface(i, a) + geometric(i, a) - S(i, a) * along + S(i, a) * v[p];
      volume_rate += S(i, a) * W(i, a);
    }
  }
  out[p] = volume_rate;
}

double TangentOperator::bytes_for(int num_vertices) {
  return 2.0 * 8.0 * num_vertices * static_cast<double>(num_vertices);
}

TangentOperator Equilibrium::linearize(const Eigen::VectorXd& x,
                                       const std::vector<double>& factors) const {
  TangentOperator op;
  linearize(x, factors, op);
  return op;
}

void Equilibrium::linearize(const Eigen::VectorXd& x, const std::vector<double>& factors,
                            TangentOperator& op) const {
  op.equilibrium_ = this;
  op.x_ = x;
  op.factors_ = factors;
  op.X_ = positions(model_, x);
  op.U_ = displacements(model_, x);
  bulk_pairs(op.X_, op.U_).coefficients(&op.weighted_modulus_, &op.weighted_slope_);
}

Eigen::VectorXd TangentOperator::apply(const Eigen::VectorXd& v) const {
  const model::Model& model = equilibrium_->model();
  const int n = model.num_vertices(), dim = model.dim();
  const Eigen::Vector3d m = model.material.axis_factors;
  const Eigen::MatrixXd W = displacements(model, v);
  const std::vector<double> zeros(static_cast<size_t>(n), 0.0);
  const double *x[3], *d[3], *w[3];
  for (int a = 0; a < 3; ++a) {
    x[a] = a < dim ? X_.col(a).data() : zeros.data();
    d[a] = a < dim ? U_.col(a).data() : zeros.data();
    w[a] = a < dim ? W.col(a).data() : zeros.data();
  }
  Eigen::VectorXd out = Eigen::VectorXd::Zero(v.size());
  with_kinematics(model.material.kinematics, [&](auto policy) {
    using K = decltype(policy);
#pragma omp parallel for schedule(dynamic, 16)
    for (int i = 0; i < n; ++i) {
      const double* c1 = weighted_modulus_.col(i).data();
      const double* c2 = weighted_slope_.col(i).data();
      const auto u = static_cast<size_t>(i);
      double p0 = 0.0, p1 = 0.0, p2 = 0.0;
#pragma omp simd reduction(+ : p0, p1, p2)
      for (size_t j = 0; j < static_cast<size_t>(n); ++j) {
        const PairCoefficients c{c1[j], c2[j]};
        const double b0 = x[0][u] - x[0][j], b1 = x[1][u] - x[1][j], b2 = x[2][u] - x[2][j];
        const double v0 = w[0][u] - w[0][j], v1 = w[1][u] - w[1][j], v2 = w[2][u] - w[2][j];
        const double b_dot_v = b0 * v0 + b1 * v1 + b2 * v2;
        p0 += pair_tangent<K>(c, v0, b_dot_v, b0, d[0][u] - d[0][j]);
        p1 += pair_tangent<K>(c, v1, b_dot_v, b1, d[1][u] - d[1][j]);
        p2 += pair_tangent<K>(c, v2, b_dot_v, b2, d[2][u] - d[2][j]);
      }
      const double product[3] = {p0, p1, p2};
      for (int a = 0; a < dim; ++a) out[a * n + i] = m[a] * product[a];
    }
  });
  equilibrium_->add_non_bulk_product(x_, factors_, X_, v, out);
  return out;
}

Eigen::MatrixXd Equilibrium::parameter_derivatives(const Eigen::VectorXd& x,
                                                   const std::vector<std::string>& names) const {
  const Eigen::MatrixXd X = positions(model_, x), U = displacements(model_, x);
  const int n = model_.num_vertices(), dim = model_.dim();
  const Eigen::Vector3d m = model_.material.axis_factors;
  const FiberLaw& law = model_.material.law;
  Eigen::MatrixXd D = Eigen::MatrixXd::Zero(num_unknowns(), static_cast<Eigen::Index>(names.size()));
  for (size_t k = 0; k < names.size(); ++k) {
    const std::string& name = names[k];
    const auto column = static_cast<Eigen::Index>(k);
    if (name == "gamma") {
      const Eigen::MatrixXd L = surface_ * U;
      for (int a = 0; a < dim; ++a) D.col(column).segment(a * n, n) = L.col(a);
      continue;
    }
    int axis = -1;  // factor_x: the fiber force of that axis over its factor
    if (name.rfind("factor_", 0) == 0 && name.size() == 8) axis = name[7] - 'x';
    if (axis >= dim) axis = -1;
    // The law's parameter, resolved once (throws for an unknown name), not per pair.
    const int parameter = axis < 0 ? law.parameter_index(name) : -1;
    const Columns columns(model_.surface.V, X, U);
    with_kinematics(model_.material.kinematics, [&](auto policy) {
      using K = decltype(policy);
      parallel_rows(columns, [&](int i, const std::vector<double>* scratch) {
        // From the row's h, L, r, Y: the bulk force before the axis factors
        // (its derivative in factor_a), or m_a times the force's derivative
        // in the law's parameter.
        const double *h = scratch[0].data(), *L = scratch[1].data(), *r = scratch[2].data();
        const double *Y = scratch[3].data(), *Yp = scratch[4].data();
        const auto u = static_cast<size_t>(i);
        double sum[3] = {0.0, 0.0, 0.0};
        for (size_t j = 0; j < static_cast<size_t>(n); ++j) {
          if (h[j] == 0.0) continue;
          const double a = bulk_weight(h[j], area0_[i], area0_[static_cast<Eigen::Index>(j)], L[j]);
          const PairCoefficients c = K::coefficients(a, Y[j], Yp[j], r[j], L[j]);
          const double dY = axis >= 0 ? 0.0 : law.modulus_derivative(parameter, fiber_strain(r[j], L[j]));
          for (int k = 0; k < 3; ++k) {
            const double b = columns.x[k][u] - columns.x[k][j], d = columns.u[k][u] - columns.u[k][j];
            sum[k] += axis >= 0 ? pair_force<K>(c, b, d) : pair_parameter_force<K>(a, dY, r[j], L[j], b, d);
          }
        }
        if (axis >= 0)
          D(axis * n + i, column) = sum[axis];
        else
          for (int a = 0; a < dim; ++a) D(a * n + i, column) = m[a] * sum[a];
      });
    });
  }
  return D;
}

std::vector<std::string> material_parameter_names(const Material& material, int dim) {
  std::vector<std::string> names = material.law.parameter_names();
  names.push_back("gamma");
  for (int a = 0; a < dim; ++a) names.push_back(std::string("factor_") + "xyz"[a]);
  return names;
}

bool is_material_parameter(const Material& material, const std::string& name) {
  const std::vector<std::string> names = material_parameter_names(material, 3);
  return std::find(names.begin(), names.end(), name) != names.end();
}

double Equilibrium::relative_norm(const Eigen::VectorXd& reduced, double force_scale) const {
  const Eigen::Index m = reduced.size() - 1;
  const double force = reduced.head(m).norm() / std::max(force_scale, 1e-300);
  const double volume = reduced[m] / volume_scale();
  return std::hypot(force, volume);
}

std::shared_ptr<const FiberSystem> Equilibrium::linear_system(const Eigen::MatrixXd& X,
                                                              const DofMap& dofs,
                                                              BoundaryMethod method,
                                                              double penalty,
                                                              bool strained) const {
  return std::make_shared<const FiberSystem>(model_, X, dofs, method, penalty,
                                             strained ? &X : nullptr);
}

Eigen::VectorXd Equilibrium::load_vector(const Eigen::MatrixXd& X,
                                         const std::vector<double>& factors) const {
  return right_hand_side(model_, X, factors);
}

}  // namespace fiberfluid::model

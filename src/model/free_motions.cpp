// SPDX-License-Identifier: GPL-3.0-or-later
#include "fiberfluid/model/free_motions.hpp"

#include <Eigen/Geometry>
#include <Eigen/SVD>
#include <cmath>
#include <cstdio>

#include "fiberfluid/geom/area_vectors.hpp"
#include "fiberfluid/model/loads.hpp"

namespace fiberfluid::model {
namespace {

// The body's rigid modes: per mode (columns: translations x, y(, z), then
// rotations about x, y, z through the centroid, their arm scaled by the
// body's size so that every column has the same scale), the displacement of
// vertex i along axis a at row a * N + i.
struct RigidModes {
  Eigen::MatrixXd modes;
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();
  double size = 1.0;
};

RigidModes rigid_modes(const Model& model) {
  const Eigen::MatrixXd& V = model.surface.V;
  const int n = model.num_vertices(), dim = model.dim();
  RigidModes r;
  r.centre.head(dim) = V.colwise().mean().transpose();
  r.size = std::max((V.colwise().maxCoeff() - V.colwise().minCoeff()).norm(), 1e-300);
  const int rotations = dim == 3 ? 3 : 1;
  r.modes = Eigen::MatrixXd::Zero(dim * n, dim + rotations);
  for (int a = 0; a < dim; ++a) r.modes.block(a * n, a, n, 1).setOnes();
  for (int k = 0; k < rotations; ++k) {
    const Eigen::Vector3d axis = Eigen::Vector3d::Unit(dim == 3 ? k : 2);
    for (int i = 0; i < n; ++i) {
      Eigen::Vector3d arm = Eigen::Vector3d::Zero();
      arm.head(dim) = V.row(i).transpose() - r.centre.head(dim);
      const Eigen::Vector3d v = axis.cross(arm) / r.size;
      for (int a = 0; a < dim; ++a) r.modes(a * n + i, dim + k) = v[a];
    }
  }
  return r;
}

// Rows, one per held motion, in the modes' coordinates.
Eigen::MatrixXd held_rows(const Model& model, const RigidModes& r) {
  const int n = model.num_vertices(), dim = model.dim();
  const Eigen::Index m = r.modes.cols();
  std::vector<Eigen::RowVectorXd> rows;
  for (const Constraint& c : model.constraints) rows.push_back(r.modes.row(c.axis * n + c.vertex));
  // A mirror layer's support holds every axis of its vertices: its rows are in already.
  for (const Paddle& p : model.paddles) {
    for (Eigen::Index k = 0; k < m; ++k) {
      const bool translation = k < dim;
      const int axis =
          translation ? static_cast<int>(k) : (dim == 3 ? static_cast<int>(k) - dim : 2);
      // Frictionless: its own translation, and the tilts about the other axes.
      // Coulomb counts as frictionless: its hold across the axis is bounded.
      const bool held = p.sticking() || (translation ? axis == p.axis : axis != p.axis);
      if (held) rows.push_back(Eigen::RowVectorXd::Unit(m, k));
    }
  }
  Eigen::MatrixXd C(static_cast<Eigen::Index>(rows.size()), m);
  for (size_t k = 0; k < rows.size(); ++k) C.row(static_cast<Eigen::Index>(k)) = rows[k];
  return C;
}

std::string vector_text(const Eigen::Vector3d& v) {
  char buffer[96];
  std::snprintf(buffer, sizeof buffer, "(%.4g, %.4g, %.4g)", std::abs(v[0]) < 1e-12 ? 0.0 : v[0],
                std::abs(v[1]) < 1e-12 ? 0.0 : v[1], std::abs(v[2]) < 1e-12 ? 0.0 : v[2]);
  return buffer;
}

std::string direction_text(const Eigen::Vector3d& d) {
  for (int a = 0; a < 3; ++a)
    if (std::abs(std::abs(d[a]) - 1.0) < 1e-9) return std::string(1, static_cast<char>('x' + a));
  return vector_text(d);
}

}  // namespace

std::string FreeMotion::describe() const {
  if (rotation.isZero()) return "translation along " + direction_text(translation);
  std::string text =
      "rotation about the axis " + direction_text(rotation) + " through " + vector_text(point);
  if (!translation.isZero()) text += " with a translation along " + direction_text(translation);
  return text;
}

std::vector<FreeMotion> free_rigid_motions(const Model& model) {
  const int dim = model.dim(), n = model.num_vertices();
  if (n == 0) return {};
  const RigidModes r = rigid_modes(model);
  const Eigen::MatrixXd C = held_rows(model, r);
  const Eigen::Index m = r.modes.cols();
  // The modes no held row sees: the null space of C (every mode when nothing is held).
  Eigen::MatrixXd null_space;
  if (C.rows() == 0) {
    null_space = Eigen::MatrixXd::Identity(m, m);
  } else {
    const Eigen::JacobiSVD<Eigen::MatrixXd> svd(C, Eigen::ComputeFullV);
    const Eigen::VectorXd& s = svd.singularValues();
    const double tolerance = 1e-9 * std::max(1.0, s.size() > 0 ? s[0] : 0.0);
    Eigen::Index rank = 0;
    while (rank < s.size() && s[rank] > tolerance) ++rank;
    null_space = svd.matrixV().rightCols(m - rank);
  }
  if (null_space.cols() == 0) return {};
  // Translations first where the null space holds them: the free translation
  // directions are those of its translation part with no rotation.
  const Eigen::MatrixXd rotation_part = null_space.bottomRows(m - dim);
  const Eigen::JacobiSVD<Eigen::MatrixXd> split(rotation_part, Eigen::ComputeFullV);
  const Eigen::MatrixXd basis = null_space * split.matrixV().rowwise().reverse();

  // The loads at full schedule at the reference, to see which motions they drive.
  const geom::VertexAreaVectors area = geom::vertex_area_vectors(model.surface.V, model.surface.F);
  const Eigen::VectorXd F =
      load_vector(model, model.surface.V, area.S, std::vector<double>(model.loads.size(), 1.0))
          .head(dim * n);
  const double load_scale = std::max(F.cwiseAbs().sum(), 1e-300);

  std::vector<FreeMotion> motions;
  for (Eigen::Index k = 0; k < basis.cols(); ++k) {
    const Eigen::VectorXd coefficients = basis.col(k);
    FreeMotion motion;
    Eigen::Vector3d t = Eigen::Vector3d::Zero(), w = Eigen::Vector3d::Zero();
    t.head(dim) = coefficients.head(dim);
    if (dim == 3)
      w = coefficients.tail(3) / r.size;
    else
      w[2] = coefficients[2] / r.size;
    if (w.norm() * r.size < 1e-9 * t.norm()) w.setZero();
    if (!w.isZero()) {
      // v(s) = t + w x (s - c) = w x (s - p) + (t . w^) w^, p = c + w x t / |w|^2.
      motion.rotation = w.normalized();
      motion.point = r.centre + w.cross(t) / w.squaredNorm();
      const Eigen::Vector3d along = t.dot(motion.rotation) * motion.rotation;
      if (along.norm() > 1e-9 * w.norm() * r.size) motion.translation = along.normalized();
    } else {
      motion.translation = t.normalized();
    }
    const Eigen::VectorXd field = r.modes * coefficients;
    motion.driven =
        std::abs(F.dot(field)) / (load_scale * std::max(field.cwiseAbs().maxCoeff(), 1e-300));
    motions.push_back(motion);
  }
  return motions;
}

std::pair<int, int> gauge_unknown(const Model& model, const FreeMotion& motion) {
  const int n = model.num_vertices(), dim = model.dim();
  std::vector<char> held(static_cast<size_t>(dim * n), 0);
  for (const Constraint& c : model.constraints)
    held[static_cast<size_t>(c.axis * n + c.vertex)] = 1;
  std::pair<int, int> best{-1, -1};
  double largest = 0.0;
  for (int i = 0; i < n; ++i) {
    Eigen::Vector3d s = Eigen::Vector3d::Zero();
    s.head(dim) = model.surface.V.row(i).transpose();
    const Eigen::Vector3d v = motion.translation + motion.rotation.cross(s - motion.point);
    for (int a = 0; a < dim; ++a)
      if (!held[static_cast<size_t>(a * n + i)] && std::abs(v[a]) > largest * (1.0 + 1e-12)) {
        largest = std::abs(v[a]);
        best = {i, a};
      }
  }
  return best;
}

}  // namespace fiberfluid::model

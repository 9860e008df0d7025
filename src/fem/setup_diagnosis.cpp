// SPDX-License-Identifier: GPL-3.0-or-later
#include "fiberfluid/fem/setup_diagnosis.hpp"

#include <Eigen/Dense>
#include <cmath>
#include <iomanip>
#include <set>
#include <sstream>
#include <string>

#include "fiberfluid/geom/surface.hpp"

namespace fiberfluid::fem {
namespace {

// The body's rigid motions (translations, then rotations about its centroid)
// at the held unknowns: a free rigid motion is a null vector of this matrix.
Eigen::MatrixXd held_rigid_modes(const Mesh& mesh, const std::set<int>& held) {
  const int dim = mesh.dim;
  const int modes = dim == 3 ? 6 : 3;
  const Eigen::RowVectorXd centre = mesh.nodes.colwise().mean();
  Eigen::MatrixXd R = Eigen::MatrixXd::Zero(static_cast<Eigen::Index>(held.size()), modes);
  Eigen::Index row = 0;
  for (const int dof : held) {
    const int node = dof / dim, axis = dof % dim;
    const Eigen::RowVectorXd p = mesh.nodes.row(node) - centre;
    R(row, axis) = 1.0;
    if (dim == 2) {
      R(row, 2) = axis == 0 ? -p[1] : p[0];  // e_z x p
    } else {
      // Column 3 + r is the rotation about axis r: (e_r x p)[axis].
      for (int r = 0; r < 3; ++r) {
        const int a = (r + 1) % 3, b = (r + 2) % 3;  // (e_r x p) = p_a e_b - p_b e_a
        if (axis == b) R(row, 3 + r) = p[a];
        if (axis == a) R(row, 3 + r) = -p[b];
      }
    }
    ++row;
  }
  return R;
}

const char* rigid_mode_name(int mode) {
  static const char* names[] = {"a translation along x", "a translation along y",
                                "a translation along z", "a rotation about x",
                                "a rotation about y",    "a rotation about z"};
  return names[mode];
}

}  // namespace

WorstElement worst_tetrahedron(const Mesh& mesh) {
  WorstElement worst;
  if (mesh.dim != 3 || mesh.elements.cols() < 4) return worst;
  for (Eigen::Index e = 0; e < mesh.elements.rows(); ++e) {
    Eigen::Vector3d c[4];
    for (int k = 0; k < 4; ++k) c[k] = mesh.nodes.row(mesh.elements(e, k)).transpose();
    const double volume = (c[1] - c[0]).cross(c[2] - c[0]).dot(c[3] - c[0]) / 6.0;
    double squares = 0.0;
    for (int i = 0; i < 4; ++i)
      for (int j = i + 1; j < 4; ++j) squares += (c[j] - c[i]).squaredNorm();
    const double l_rms = std::sqrt(squares / 6.0);
    const double quality = l_rms > 0.0 ? 6.0 * std::sqrt(2.0) * volume / std::pow(l_rms, 3) : 0.0;
    if (quality < worst.quality) worst = {static_cast<int>(e), quality};
  }
  return worst;
}

Status diagnose_singular_setup(const Mesh& mesh, double poisson,
                               const std::vector<int>& held_dofs) {
  const std::set<int> held(held_dofs.begin(), held_dofs.end());
  const int modes = mesh.dim == 3 ? 6 : 3;
  std::ostringstream why;
  if (static_cast<int>(held.size()) < modes) {
    why << "too few supports: " << held.size() << " unknowns held, and a " << mesh.dim
        << "D body needs at least " << modes << " to stop its rigid motions";
    return Status::failure(why.str());
  }
  const Eigen::MatrixXd R = held_rigid_modes(mesh, held);
  // Scale-free: rotations are in lengths, so compare against the body's size.
  const double size = geom::bounding_box_diagonal(mesh.nodes);
  Eigen::MatrixXd scaled = R;
  scaled.rightCols(modes - mesh.dim) /= size > 0.0 ? size : 1.0;
  const Eigen::JacobiSVD<Eigen::MatrixXd> svd(scaled, Eigen::ComputeFullV);
  const Eigen::VectorXd& sigma = svd.singularValues();
  if (sigma[modes - 1] <= 1e-9 * sigma[0]) {
    const Eigen::VectorXd free_motion = svd.matrixV().col(modes - 1);
    Eigen::Index mode = 0;
    free_motion.cwiseAbs().maxCoeff(&mode);
    why << "too few supports: the " << held.size() << " held unknowns leave "
        << rigid_mode_name(mesh.dim == 3 ? static_cast<int>(mode)
                                         : (mode == 2 ? 5 : static_cast<int>(mode)))
        << " free";
    return Status::failure(why.str());
  }
  const WorstElement worst = worst_tetrahedron(mesh);
  if (worst.element >= 0 && worst.quality < 1e-3) {
    why << "tetrahedron " << worst.element << " is flat (shape quality " << worst.quality
        << ", 1 for a regular one): an element size larger than the body's thickness, or a "
           "surface too thin for its mesh";
    return Status::failure(why.str());
  }
  if (1.0 - 2.0 * poisson < 1e-12) {
    why << "nu = " << std::setprecision(17) << poisson << std::setprecision(6) << " is within "
        << (0.5 - poisson) << " of 1/2: the bulk stiffness is "
        << (1.0 + poisson) / (1.5 * (1.0 - 2.0 * poisson))
        << " times the shear stiffness, beyond double precision's 16 digits (use the "
           "neo_hookean_incompressible material, or nu up to 0.4999)";
    return Status::failure(why.str());
  }
  return {};
}

}  // namespace fiberfluid::fem

// SPDX-License-Identifier: GPL-3.0-or-later
#include "fiberfluid/geom/area_vectors.hpp"

#include <cmath>

#include <Eigen/Geometry>

namespace fiberfluid::geom {

Eigen::MatrixXd face_area_vectors(const Eigen::MatrixXd& V, const Eigen::MatrixXi& F) {
  Eigen::MatrixXd A(F.rows(), V.cols());
  for (Eigen::Index f = 0; f < F.rows(); ++f) {
    if (V.cols() == 3) {
      const Eigen::Vector3d a = V.row(F(f, 0)), b = V.row(F(f, 1)), c = V.row(F(f, 2));
      A.row(f) = 0.5 * (b - a).cross(c - a);
    } else {
      const Eigen::Vector2d d = V.row(F(f, 1)) - V.row(F(f, 0));
      A.row(f) << d.y(), -d.x();  // right of the direction of travel: outward for CCW
    }
  }
  return A;
}

Eigen::MatrixXd summed_face_area_vectors(const Eigen::MatrixXd& V, const Eigen::MatrixXi& F) {
  const Eigen::MatrixXd A = face_area_vectors(V, F);
  Eigen::MatrixXd sum = Eigen::MatrixXd::Zero(V.rows(), V.cols());
  for (Eigen::Index f = 0; f < F.rows(); ++f)
    for (Eigen::Index k = 0; k < F.cols(); ++k) sum.row(F(f, k)) += A.row(f);
  return sum;
}

VertexAreaVectors vertex_area_vectors(const Eigen::MatrixXd& V, const Eigen::MatrixXi& F) {
  VertexAreaVectors out;
  const Eigen::MatrixXd sum = summed_face_area_vectors(V, F);
  out.surface_area = face_area_vectors(V, F).rowwise().norm().sum();
  const double denominator = sum.rowwise().norm().sum();
  out.C = denominator > 0.0 ? out.surface_area / denominator : 0.0;
  out.S = out.C * sum;
  out.magnitude = out.S.rowwise().norm();
  return out;
}

double surface_area(const Eigen::MatrixXd& V, const Eigen::MatrixXi& F) {
  return face_area_vectors(V, F).rowwise().norm().sum();
}

double enclosed_volume(const Eigen::MatrixXd& V, const Eigen::MatrixXi& F) {
  if (F.rows() == 0 || V.rows() == 0) return 0.0;
  // Summed about the centre of the faces' bounding box, not the origin: for
  // a body far from the origin the terms about the origin are huge and
  // cancel (a unit cube at 1e8 loses every digit). For a closed surface the
  // sum does not depend on the point. Vertices in no face are left out: one
  // far away would move the centre as far.
  Eigen::RowVectorXd low = Eigen::RowVectorXd::Constant(V.cols(), HUGE_VAL), high = -low;
  for (Eigen::Index f = 0; f < F.rows(); ++f)
    for (Eigen::Index k = 0; k < F.cols(); ++k) {
      low = low.cwiseMin(V.row(F(f, k)));
      high = high.cwiseMax(V.row(F(f, k)));
    }
  const Eigen::RowVectorXd centre = 0.5 * (low + high);
  double volume = 0.0;
  for (Eigen::Index f = 0; f < F.rows(); ++f) {
    if (V.cols() == 3) {
      const Eigen::Vector3d a = V.row(F(f, 0)) - centre, b = V.row(F(f, 1)) - centre,
                            c = V.row(F(f, 2)) - centre;
      volume += a.dot(b.cross(c)) / 6.0;
    } else {
      const Eigen::Vector2d a = V.row(F(f, 0)) - centre, b = V.row(F(f, 1)) - centre;
      volume += 0.5 * (a.x() * b.y() - b.x() * a.y());
    }
  }
  return volume;
}

}  // namespace fiberfluid::geom

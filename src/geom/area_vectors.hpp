// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once

#include <Eigen/Core>

namespace fiberfluid::geom {

// Outward face area vectors A_f (paper Eq. 1). 3D: half the cross product of
// two edges, |A_f| = triangle area. 2D: the edge's outward normal times its
// length, for a counter-clockwise polygon.
// V: #V by dim positions; F: #F by dim indices. Returns #F by dim.
Eigen::MatrixXd face_area_vectors(const Eigen::MatrixXd& V, const Eigen::MatrixXi& F);

// Sum of the area vectors of the faces touching each vertex: #V by dim.
// Equals dim times the gradient of the enclosed volume (area in 2D).
Eigen::MatrixXd summed_face_area_vectors(const Eigen::MatrixXd& V, const Eigen::MatrixXi& F);

// Vertex area vectors S_i = C sum_{f at i} A_f (paper Eq. 2), with C chosen so
// that sum_i |S_i| equals the surface area (perimeter in 2D).
struct VertexAreaVectors {
  Eigen::MatrixXd S;          // #V by dim
  Eigen::VectorXd magnitude;  // #V, |S_i|
  double C = 0.0;             // the normalisation constant
  double surface_area = 0.0;  // sum_f |A_f|
};
VertexAreaVectors vertex_area_vectors(const Eigen::MatrixXd& V, const Eigen::MatrixXi& F);

// Sum of face areas (perimeter in 2D).
double surface_area(const Eigen::MatrixXd& V, const Eigen::MatrixXi& F);

// Signed enclosed volume (signed area in 2D); positive for outward faces.
double enclosed_volume(const Eigen::MatrixXd& V, const Eigen::MatrixXi& F);

// The barycentric coordinates of p (projected on the triangle's plane) in
// the triangle (a, b, c): weights summing to 1 with p = w0 a + w1 b + w2 c.
inline Eigen::Vector3d barycentric_coordinates(const Eigen::Vector3d& p, const Eigen::Vector3d& a,
                                               const Eigen::Vector3d& b, const Eigen::Vector3d& c) {
  const Eigen::Vector3d u = b - a, v = c - a, w = p - a;
  const double uu = u.dot(u), uv = u.dot(v), vv = v.dot(v), wu = w.dot(u), wv = w.dot(v);
  const double det = uu * vv - uv * uv;
  const double s = (vv * wu - uv * wv) / det, t = (uu * wv - uv * wu) / det;
  return {1.0 - s - t, s, t};
}

}  // namespace fiberfluid::geom

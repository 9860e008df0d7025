// SPDX-License-Identifier: GPL-3.0-or-later
// A scan's distances and their Jacobian: the sensitivities chained through
// each closest point's direction, and the alignment's columns (Ceres' Jets
// for the rotation's derivatives, kept inside this file).
#include <ceres/jet.h>
#include <ceres/rotation.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

#include "fiberfluid/fit/residuals/blocks.hpp"
#include "fiberfluid/geom/area_vectors.hpp"
#include "fiberfluid/model/assembly.hpp"
#include "fiberfluid/util/error.hpp"

namespace fiberfluid::fit {
namespace {

using Jet = ceres::Jet<double, 3>;

// The rigid alignment of the targets, T(p) = R(omega) p + t, with the
// derivatives of its action on one point by the rotation vector (Jets).
// A similarity: distances in the target's frame are 1/scale of the body's.
struct Alignment {
  Eigen::Vector3d rotation = Eigen::Vector3d::Zero(), translation = Eigen::Vector3d::Zero();
  double scale = 1.0;

  // T(p) = s R p + t and dT(p)/domega (3 x 3).
  Eigen::Vector3d apply(const Eigen::Vector3d& p, Eigen::Matrix3d* d_rotation) const {
    const Eigen::Vector3d q = scale * rotate(rotation, p, d_rotation) + translation;
    if (d_rotation) *d_rotation *= scale;
    return q;
  }
  // T^-1(x) = R^T (x - t) / s, with d/domega (3 x 3); d/dt is -R^T / s.
  Eigen::Vector3d inverse(const Eigen::Vector3d& x, Eigen::Matrix3d* d_rotation) const {
    Eigen::Matrix3d d;
    const Eigen::Vector3d q = rotate(-rotation, x - translation, &d) / scale;
    if (d_rotation) *d_rotation = -d / scale;  // the rotation vector enters with a minus sign
    return q;
  }
  Eigen::Matrix3d inverse_rotation() const {
    Eigen::Matrix3d R;
    for (int a = 0; a < 3; ++a) {
      Eigen::Vector3d e = Eigen::Vector3d::Unit(a);
      R.col(a) = rotate(-rotation, e, nullptr);
    }
    return R;
  }

  static Eigen::Vector3d rotate(const Eigen::Vector3d& omega, const Eigen::Vector3d& p,
                                Eigen::Matrix3d* d_omega) {
    Jet w[3], pt[3], out[3];
    for (int a = 0; a < 3; ++a) {
      w[a] = Jet(omega[a], a);
      pt[a] = Jet(p[a]);
    }
    ceres::AngleAxisRotatePoint(w, pt, out);
    Eigen::Vector3d q;
    for (int a = 0; a < 3; ++a) {
      q[a] = out[a].a;
      if (d_omega) d_omega->row(a) = out[a].v.transpose();
    }
    return q;
  }
};

// The unit direction of the distance from c to q; at zero distance, the
// normal of the triangle (or nothing, for a point cloud).
Eigen::Vector3d direction(const Eigen::Vector3d& q, const Eigen::Vector3d& c, const Target& target,
                          int primitive) {
  const Eigen::Vector3d d = q - c;
  const double norm = d.norm();
  if (norm > 0.0) return d / norm;
  if (target.is_point_cloud()) return Eigen::Vector3d::Zero();
  const Eigen::Vector3i t = target.triangles.row(primitive).transpose();
  const Eigen::Vector3d a = target.points.row(t[0]), b = target.points.row(t[1]),
                        e = target.points.row(t[2]);
  return (b - a).cross(e - a).normalized();
}

Eigen::Vector3d bounding_low(const Eigen::MatrixXd& P) {
  return P.colwise().minCoeff().transpose();
}
Eigen::Vector3d bounding_high(const Eigen::MatrixXd& P) {
  return P.colwise().maxCoeff().transpose();
}

// The scan, checked against the run and the body: a step the run has, near
// the body and of its size (a scan may be unregistered, not in other units).
const MeasuredStep& checked(const MeasuredStep& scan, const model::Model& model, int steps,
                            double length) {
  if (scan.step < 1 || scan.step > steps)
    throw InputError(scan.target.label + ": tied to load step " + std::to_string(scan.step) +
                     ", but the run has steps 1.." + std::to_string(steps));
  const Eigen::MatrixXd& V = model.surface.V;
  const Eigen::Vector3d low = bounding_low(V), high = bounding_high(V);
  const Eigen::Vector3d margin = Eigen::Vector3d::Constant(0.5 * length);
  const Eigen::Vector3d t_low = bounding_low(scan.target.points),
                        t_high = bounding_high(scan.target.points);
  if (((t_low.array() > (high + margin).array()) || (t_high.array() < (low - margin).array()))
          .any())
    throw InputError(scan.target.label +
                     ": the target does not overlap the body (its bounding box "
                     "lies more than half the body's length away): wrong units or another "
                     "specimen?");
  const double size = (t_high - t_low).maxCoeff();
  if (size > 10.0 * length || size < 0.01 * length) {
    std::ostringstream why;
    why << scan.target.label << ": the target is " << size / length << " times the body's size ("
        << size << " against " << length << " m): wrong units? (give the scan's \"units\" "
        << "or \"scale\")";
    throw InputError(why.str());
  }
  return scan;
}

}  // namespace

ScanDistances::ScanDistances(const MeasuredStep& scan, size_t index, const model::Model& model,
                             int steps, const std::vector<int>& counted, bool symmetric,
                             double length)
    : scan_(checked(scan, model, steps, length)),
      index_(index),
      counted_(counted),
      symmetric_(symmetric),
      length_(length),
      distance_(scan_.target) {}

int ScanDistances::rows() const {
  return static_cast<int>(counted_.size()) +
         (symmetric_ ? static_cast<int>(scan_.target.points.rows()) : 0);
}

std::string ScanDistances::evaluate(const ForwardRun& run, const std::map<int, StepReadings>&,
                                    Eigen::Index row, Evaluation& e) const {
  const ParameterMap& map = run.map;
  const Eigen::VectorXd& dvalue = run.dvalue;
  const bool with_jacobian = run.with_jacobian;
  const int nv = run.model.num_vertices();
  Alignment align;
  map.alignment(run.values, &align.rotation, &align.translation, &align.scale);
  const Eigen::Matrix3d R_inverse = align.inverse_rotation();
  // Adds the alignment's columns: d residual / d (rotation, translation) =
  // n . dq (dq in the body's frame), and d residual / d scale.
  auto add_alignment = [&](Eigen::Index r, const Eigen::Vector3d& n,
                           const Eigen::Matrix3d& dq_domega, const Eigen::Matrix3d& dq_dt,
                           double d_scale) {
    for (int a = 0; a < 3; ++a) {
      const int rotation = map.alignment_index(a), translation = map.alignment_index(3 + a);
      if (rotation >= 0) e.jacobian(r, rotation) += n.dot(dq_domega.col(a)) * dvalue[rotation];
      if (translation >= 0) e.jacobian(r, translation) += n.dot(dq_dt.col(a)) * dvalue[translation];
    }
    const int s = map.alignment_index(6);
    if (s >= 0) e.jacobian(r, s) += d_scale * dvalue[s];
  };

  const int step = scan_.step;
  const Eigen::MatrixXd X = model::positions(run.model, run.states.at(step));
  if (e.positions.size() <= index_) e.positions.resize(index_ + 1);
  e.positions[index_] = X;
  const auto sensitivity = run.sensitivities.find(step);
  const Eigen::MatrixXd* S =
      sensitivity != run.sensitivities.end() ? &sensitivity->second : nullptr;
  const Target& target = scan_.target;
  // Forward: each counted vertex, taken into the target's frame, to the target.
  Eigen::MatrixXd queries(static_cast<Eigen::Index>(counted_.size()), 3);
  std::vector<Eigen::Matrix3d> dq_domega(counted_.size());
  for (size_t c = 0; c < counted_.size(); ++c)
    queries.row(static_cast<Eigen::Index>(c)) =
        align.inverse(X.row(counted_[c]).transpose(), &dq_domega[c]).transpose();
  const std::vector<TargetDistance::Closest> hits = distance_.closest(queries);
  // The distance in the body's frame: s times the one in the target's
  // (T is a similarity), so that both directions measure alike.
  for (size_t c = 0; c < counted_.size(); ++c, ++row) {
    const Eigen::Vector3d q = queries.row(static_cast<Eigen::Index>(c)).transpose();
    e.residuals[row] = align.scale * hits[c].distance;
    if (!with_jacobian) continue;
    const Eigen::Vector3d n = direction(q, hits[c].point, target, hits[c].primitive);
    if (S)
      e.jacobian.row(row) += n.transpose() * R_inverse * run.vertex_sensitivity(*S, counted_[c]);
    add_alignment(row, n, align.scale * dq_domega[c], -R_inverse, hits[c].distance - n.dot(q));
  }
  if (!symmetric_) return "";
  // Symmetric: each target point, taken into the body's frame, to the simulated surface.
  const Target simulated = make_target("the simulated surface", X, run.model.surface.F);
  if (simulated.triangles.rows() != run.model.surface.F.rows() || simulated.points.rows() != nv)
    return "a simulated face collapsed to zero area";
  const TargetDistance to_simulated(simulated);
  const Eigen::Index np = target.points.rows();
  Eigen::MatrixXd moved(np, 3);
  std::vector<Eigen::Matrix3d> dp_domega(static_cast<size_t>(np));
  for (Eigen::Index j = 0; j < np; ++j)
    moved.row(j) = align.apply(target.points.row(j).transpose(), &dp_domega[static_cast<size_t>(j)])
                       .transpose();
  const std::vector<TargetDistance::Closest> back = to_simulated.closest(moved);
  for (Eigen::Index j = 0; j < np; ++j, ++row) {
    const TargetDistance::Closest& hit = back[static_cast<size_t>(j)];
    e.residuals[row] = hit.distance;
    if (!with_jacobian) continue;
    const Eigen::Vector3d p = moved.row(j).transpose();
    const Eigen::Vector3d n = direction(p, hit.point, simulated, hit.primitive);
    // make_target keeps every vertex of a closed surface in order, so the
    // simulated triangle's corners are model vertices.
    const Eigen::Vector3i corners = simulated.triangles.row(hit.primitive).transpose();
    const Eigen::Vector3d b =
        geom::barycentric_coordinates(hit.point, X.row(corners[0]).transpose(),
                                      X.row(corners[1]).transpose(), X.row(corners[2]).transpose());
    if (S)
      for (int k = 0; k < 3; ++k)
        e.jacobian.row(row) -= b[k] * n.transpose() * run.vertex_sensitivity(*S, corners[k]);
    add_alignment(row, n, dp_domega[static_cast<size_t>(j)], Eigen::Matrix3d::Identity(),
                  n.dot(p - align.translation) / align.scale);  // dT(p)/ds = R p
  }
  return "";
}

void ScanDistances::describe(const Evaluation& e, Eigen::Index row, FitResult& result) const {
  const Eigen::Index nv = e.positions.at(index_).rows();
  Eigen::VectorXd per_vertex =
      Eigen::VectorXd::Constant(nv, std::numeric_limits<double>::quiet_NaN());
  Eigen::VectorXd counted(static_cast<Eigen::Index>(counted_.size()));
  for (size_t c = 0; c < counted_.size(); ++c, ++row) {
    per_vertex[counted_[c]] = e.residuals[row];
    counted[static_cast<Eigen::Index>(c)] = e.residuals[row];
  }
  if (result.vertex_distances.size() <= index_) {
    result.vertex_distances.resize(index_ + 1);
    result.statistics.resize(index_ + 1);
  }
  result.vertex_distances[index_] = per_vertex;
  result.statistics[index_] = distance_statistics(counted, length_);
}

}  // namespace fiberfluid::fit

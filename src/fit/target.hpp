// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "fiberfluid/geom/target.hpp"

namespace fiberfluid::fit {

// A target surface and its closest points are geometry (geom/target.hpp).
using geom::make_target;
using geom::read_target;
using geom::Target;
using geom::TargetDistance;

// The distance statistics of the calibration (the method paper's liver
// check reports the standard deviation as a share of the organ's length).
struct DistanceStatistics {
  int count = 0;
  double mean = 0.0, rms = 0.0, standard_deviation = 0.0, largest = 0.0;
  double length = 0.0;  // the body's length (bounding-box diagonal) the shares refer to
  double share(double value) const { return length > 0.0 ? value / length : 0.0; }
};
DistanceStatistics distance_statistics(const Eigen::VectorXd& distances, double length);

}  // namespace fiberfluid::fit

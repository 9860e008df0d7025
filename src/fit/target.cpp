// SPDX-License-Identifier: GPL-3.0-or-later
#include "fiberfluid/fit/target.hpp"

#include <cmath>
#include <sstream>

#include "fiberfluid/util/error.hpp"

namespace fiberfluid::fit {

DistanceStatistics distance_statistics(const Eigen::VectorXd& d, double length) {
  DistanceStatistics s;
  s.count = static_cast<int>(d.size());
  s.length = length;
  if (d.size() == 0) return s;
  s.mean = d.mean();
  s.rms = std::sqrt(d.squaredNorm() / static_cast<double>(d.size()));
  s.standard_deviation =
      std::sqrt((d.array() - s.mean).square().sum() / static_cast<double>(d.size()));
  s.largest = d.maxCoeff();
  return s;
}

}  // namespace fiberfluid::fit

// SPDX-License-Identifier: GPL-3.0-or-later
#include "fiberfluid/model/line_measure.hpp"

#include <cmath>

#include "fiberfluid/model/pair_stencil.hpp"

namespace fiberfluid::model {

LineMeasure::LineMeasure(const Eigen::MatrixXd& reference, const Eigen::MatrixXd& area_vectors) {
  for (int a = 0; a < 3; ++a) {
    s_[a].assign(static_cast<size_t>(reference.rows()), 0.0);
    area_[a].assign(static_cast<size_t>(reference.rows()), 0.0);
    if (a >= reference.cols()) continue;
    for (Eigen::Index i = 0; i < reference.rows(); ++i) {
      s_[a][static_cast<size_t>(i)] = reference(i, a);
      area_[a][static_cast<size_t>(i)] = area_vectors(i, a);
    }
  }
}

double LineMeasure::operator()(size_t i, size_t j) const {
  double d_si = 0.0, d_sj = 0.0, squared = 0.0;
  for (int a = 0; a < 3; ++a) {
    const double d = s_[a][j] - s_[a][i];
    d_si += d * area_[a][i];
    d_sj += d * area_[a][j];
    squared += d * d;
  }
  return line_measure(d_si, d_sj, std::sqrt(squared));
}

}  // namespace fiberfluid::model

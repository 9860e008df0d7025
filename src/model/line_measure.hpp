// SPDX-License-Identifier: GPL-3.0-or-later
// The line measure of bulk fibers (FiberWeights::Lines): weights under which
// a body of fibers is a material.
//
// A fiber between surface vertices i and j stands for the straight lines
// through the body that cross the surface at i's patch and at j's
// (pair_stencil.hpp, line_measure): under an affine deformation every line is
// strained by its direction alone, so each vertex's fibers pull it by the
// network's stress (material_response.hpp) times its area vector, the patch
// test of a continuum, whatever the body's shape.
//
// On a mesh the measure is a quadrature that lumps a patch's lines onto one
// fiber. It is coarse where patches are close and not grazing: across a
// body's edge (a cylinder's rim, a cube's edges), where a vertex misses its
// traction by a quarter at any resolution (docs/model.md, "The line measure").
#pragma once

#include <Eigen/Core>
#include <vector>

namespace fiberfluid::model {

class LineMeasure {
 public:
  // `reference` and `area_vectors` (the vertex area vectors S_i): #V by 3.
  LineMeasure(const Eigen::MatrixXd& reference, const Eigen::MatrixXd& area_vectors);
  // m_ij = line_measure(d . S_i, d . S_j, |d|), d = s_j - s_i (pair_stencil.hpp).
  double operator()(size_t i, size_t j) const;

 private:
  std::vector<double> s_[3], area_[3];  // by columns: the layout the pair loops read
};

}  // namespace fiberfluid::model

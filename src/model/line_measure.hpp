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
//
// A rest tension T0 (a law's, FiberLaw::rest_tension) needs more: the body at
// rest is an equilibrium only if its fibers' tensions sum at each vertex to
// an isotropic stress times S_i, sum_j m_ij T0 n_ij = -(5/3) T0 S_i, which
// the lumped measure misses at the edges, so the body would move under no
// load. Each fiber's rest tension is therefore T0 (1 + (g_i - g_j) . n_ij),
// with one vector g_i per vertex solving those 3N equations exactly (a
// weighted graph Laplacian with blocks m n n^T, symmetric and positive
// semi-definite, its right side summing to zero on a closed surface). The
// factor is symmetric (n_ji = -n_ij) and the force stays along the fiber, so
// the body stays free of forces under rigid motions.
#pragma once

#include <Eigen/Core>
#include <vector>

#include "fiberfluid/geom/fiber_mask.hpp"

namespace fiberfluid::model {

// How the rest tensions were balanced: the largest vertex misfit of
// sum_j m T0 n + (5/3) T0 S_i, over (5/3) T0 |S_i|, before and after, the
// range of the factors, and the conjugate-gradient iterations.
struct RestBalance {
  double largest_before = 0.0, largest_after = 0.0;
  double least_factor = 1.0, largest_factor = 1.0;
  int iterations = 0;
};

// The isotropic stress of a network whose every fiber has the tension 1:
// 5 <d d> = 5/3 I (material_response.hpp).
inline constexpr double kRestStress = 5.0 / 3.0;
// The fluid's pressure that balances a rest tension T0 at rest, -(5/3) T0:
// where a run with such a law starts.
inline double rest_pressure(double rest_tension) { return -kRestStress * rest_tension; }

class LineMeasure {
 public:
  // `reference` and `area_vectors` (the vertex area vectors S_i): #V by 3.
  // With `balance_rest`, solves for the rest tensions' factors over the
  // kept pairs of `fibers` (null: every pair).
  LineMeasure(const Eigen::MatrixXd& reference, const Eigen::MatrixXd& area_vectors,
              const geom::FiberMask* fibers = nullptr, bool balance_rest = false);
  // One pair's measure m_ij = line_measure(d . S_i, d . S_j, |d|),
  // d = s_j - s_i (pair_stencil.hpp), and the factor of its rest tension,
  // 1 + (g_i - g_j) . n_ij (1 unbalanced): both from one difference d, as
  // the pair loops need them.
  struct Pair {
    double measure, rest_factor;
  };
  Pair pair(size_t i, size_t j) const;
  double operator()(size_t i, size_t j) const { return pair(i, j).measure; }
  double rest_factor(size_t i, size_t j) const { return pair(i, j).rest_factor; }
  bool balances_rest() const { return !rest_[0].empty(); }
  const RestBalance& rest_balance() const { return balance_; }

 private:
  void balance_rest_tensions(const geom::FiberMask* fibers);

  std::vector<double> s_[3], area_[3];  // by columns: the layout the pair loops read
  std::vector<double> rest_[3];         // g_i by columns (empty: not balanced)
  RestBalance balance_;
};

}  // namespace fiberfluid::model

// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once

// The accuracy metrics of Alterovitz and Goldberg (the benchmarks paper,
// docs: benchmarks.md) between a reference deformed mesh M, an approximation
// M' and the undeformed mesh M0: the relative energy norm E_n, the surface
// error E_s (exact, CGAL Booleans) and the interior error E_i.

#include <Eigen/Core>
#include <string>

#include "fiberfluid/geom/surface.hpp"

namespace fiberfluid::metrics {

// E_n = |u' - u| / |u|: plain Euclidean norms of the stacked nodal
// displacements (the paper calls it an energy norm and writes no matrix).
// Both #nodes by dim; throws InputError on a size mismatch or u = 0.
double relative_energy_norm(const Eigen::MatrixXd& u_reference, const Eigen::MatrixXd& u);

// The measure enclosed by a closed surface: the area inside a 2D polygon,
// the volume inside a 3D triangle mesh (signed: positive when outward).
double enclosed_measure(const geom::Surface& surface);

// Throws InputError naming `what`, the vertex and the axis unless every
// coordinate is finite and at most 1e50 in magnitude (the exact Booleans
// multiply up to six of them; distances square them), and the body's extent
// keeps six digits of its distance from the origin. The metrics below check
// their inputs with it.
void require_representable(const geom::Surface& surface, const std::string& what);

// |Int(A) xor Int(B)|, exactly: CGAL's 2D Boolean operations on polygons, or
// its 3D corefinement (|A| + |B| - 2 |A and B|) on closed triangle meshes.
// Throws InputError naming `what_a` / `what_b` when a surface does not bound
// a solid (open, self-intersecting, a polygon that is not simple).
double symmetric_difference_measure(const geom::Surface& a, const geom::Surface& b,
                                    const std::string& what_a = "A",
                                    const std::string& what_b = "B");

// E_s = |Int(M) xor Int(M')| / |Int(M)|; the labels name the surfaces in errors.
double surface_error(const geom::Surface& reference, const geom::Surface& approximation,
                     const std::string& what_reference = "the reference",
                     const std::string& what_approximation = "the approximation");

// Each node's share of the body's measure for E_i. For a surface-only model
// (no interior nodes) the share of the boundary: |S_i|, the magnitude of the
// model's normalised area vector (model.md: the summed area vectors of the
// faces at vertex i, scaled by C so that sum |S_i| is the surface's area).
// Where the surface curves this differs from a third of the areas around
// the vertex (3D) or half the lengths of its edges (2D).
Eigen::VectorXd boundary_node_measures(const geom::Surface& surface);

// E_i = sum_i w_i |p_i - p'_i| / |Int(M0)|^(1/d): the integral over M0 of the
// displacement error, lumped onto nodes with weights w (#nodes).
double interior_error(const Eigen::MatrixXd& reference, const Eigen::MatrixXd& approximation,
                      const Eigen::VectorXd& weights, double undeformed_measure, int dim);

}  // namespace fiberfluid::metrics

// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once

#include <Eigen/Core>

#include "fiberfluid/geom/surface.hpp"
#include "fiberfluid/util/names.hpp"

namespace fiberfluid::geom {

// Closed, outward-oriented surfaces for tests and experiments.
// Platonic solids are centred at the origin with the given circumradius.
Surface tetrahedron(double radius = 1.0);
Surface octahedron(double radius = 1.0);
Surface icosahedron(double radius = 1.0);

// Icosahedron subdivided `subdivisions` times, each new midpoint pushed to the
// sphere: 10 * 4^s + 2 vertices (s = 2: 162, s = 3: 642).
Surface icosphere(int subdivisions, double radius = 1.0);

// Axis-aligned box from `min` to `max` with n(a) segments along axis a;
// cube() is the unit-edge box centred at the origin with one segment.
Surface box(const Eigen::Vector3d& min, const Eigen::Vector3d& max,
            const Eigen::Vector3i& segments = Eigen::Vector3i::Ones());
Surface cube(double edge = 1.0);

// Half-ellipsoid on the plane z = 0, closed by a flat wall there: a
// subdivided sphere whose lower half is laid flat onto the disk (azimuthal
// equidistant map, so the wall is evenly meshed), then scaled by the
// semi-axes. The wall vertices have z = 0 exactly.
// The icosahedron's sphere (the default) has no circle of edges at z = 0, so
// its rim zig-zags by up to half an edge: faces there slant between the wall
// and the shell and the rim is slightly concave. The octahedron's equator is
// a loop of edges at every subdivision, so its rim is the ellipse itself, a
// crease the mesh follows exactly (what a resolution study needs: model.md).
enum class DomeBase { Icosahedron, Octahedron };
inline constexpr auto kDomeBaseNames = names_of<DomeBase>(
    {{DomeBase::Icosahedron, "icosahedron"}, {DomeBase::Octahedron, "octahedron"}});
Surface dome(const Eigen::Vector3d& semi_axes, int subdivisions,
             DomeBase base = DomeBase::Icosahedron);

// Closed cylinder along the x axis from x = 0 to x = length, of radius r:
// `along` segments along it, `around` around it, each end cap a disk of
// `cap_rings` concentric rings (0: about as many as keep its triangles the
// size of the wall's) around a centre vertex.
Surface cylinder(double radius, double length, int along, int around, int cap_rings = 0);

// Torus around the z axis: tube centre radius R, tube radius r, with
// `around` segments along the ring and `tube` around the tube (genus 1).
Surface torus(double R, double r, int around, int tube);

// 2D: closed polygon through `points` (#P by 2), in either winding; the edges
// are oriented counter-clockwise (outward normals to the right).
Surface polygon(const Eigen::MatrixXd& points);

// 2D: axis-aligned rectangle from `min` to `max`, with nx and ny segments on
// its horizontal and vertical sides, counter-clockwise from the lower left.
Surface rectangle(const Eigen::Vector2d& min, const Eigen::Vector2d& max, int nx = 1, int ny = 1);

}  // namespace fiberfluid::geom

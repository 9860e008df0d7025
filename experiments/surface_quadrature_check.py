#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-3.0-or-later
"""Is the central fibers' one-point quadrature second order away from supports? (issue 44)

An independent check, in numpy, of the sum the bulk fibers make at one vertex: the linearised
force density (1/|S_i|) sum_j w_ij n_ij n_ij . (u_j - u_i) of central fibers with the default
settings (the area count c_i = sum_j omega_ij |S_j| / |S_i|, the conical influence
omega = 1 - L/delta, w_ij = omega_ij (|S_i| + |S_j|) / ((c_i + c_j) L_ij); docs/model.md) for a
smooth field u = (0, x z, z^2) on a whole unit sphere (the octahedron subdivided, every
midpoint pushed to the sphere, as geom::dome's base), at the pole. No wall, no support, no
load: the quadrature alone. Prints the density at each level, the ratios of successive
differences (4 for second order), and the integral the sums approximate.
Usage: /usr/bin/python3 experiments/surface_quadrature_check.py [--levels 6] [--horizon 1.2]
       [--areas barycentric|area-vector]
"""
import argparse

import numpy as np


def octahedron():
    V = np.array([[1, 0, 0], [-1, 0, 0], [0, 1, 0], [0, -1, 0], [0, 0, 1], [0, 0, -1]], float)
    F = np.array([[0, 2, 4], [2, 1, 4], [1, 3, 4], [3, 0, 4], [2, 0, 5], [1, 2, 5], [3, 1, 5],
                  [0, 3, 5]])
    return V, F


def subdivided(V, F):
    vertices, middle = list(V), {}

    def midpoint(a, b):
        key = (min(a, b), max(a, b))
        if key not in middle:
            p = vertices[a] + vertices[b]
            vertices.append(p / np.linalg.norm(p))
            middle[key] = len(vertices) - 1
        return middle[key]

    faces = []
    for a, b, c in F:
        ab, bc, ca = midpoint(a, b), midpoint(b, c), midpoint(c, a)
        faces += [[a, ab, ca], [b, bc, ab], [c, ca, bc], [ab, bc, ca]]
    return np.array(vertices), np.array(faces)


def vertex_areas(V, F, kind):
    A = 0.5 * np.cross(V[F[:, 1]] - V[F[:, 0]], V[F[:, 2]] - V[F[:, 0]])
    face = np.linalg.norm(A, axis=1)
    if kind == "barycentric":
        areas = np.zeros(len(V))
        for k in range(3):
            np.add.at(areas, F[:, k], face / 3)
        return areas
    S = np.zeros_like(V)  # the paper's area vectors, scaled so that they sum to the area
    for k in range(3):
        np.add.at(S, F[:, k], A)
    lengths = np.linalg.norm(S, axis=1)
    return lengths * face.sum() / lengths.sum()


def influence(V, i, horizon):
    lengths = np.linalg.norm(V - V[i], axis=1)
    omega = np.clip(1 - lengths / horizon, 0, None)
    omega[i] = 0
    return omega, lengths


def smooth_field(P):
    """u = (0, x z, z^2) at the points P (rows)."""
    return np.stack([0 * P[:, 0], P[:, 0] * P[:, 2], P[:, 2] ** 2], 1)


def force_density(V, areas, i, horizon):
    omega, lengths = influence(V, i, horizon)
    partners = np.nonzero(omega > 0)[0]
    count_i = (omega * areas).sum() / areas[i]
    counts = np.array([(influence(V, j, horizon)[0] * areas).sum() / areas[j] for j in partners])
    n = (V[partners] - V[i]) / lengths[partners, None]
    u = smooth_field(V)
    along = np.sum(n * (u[partners] - u[i]), 1)
    w = omega[partners] * (areas[i] + areas[partners]) / ((count_i + counts) * lengths[partners])
    return (w[:, None] * n * along[:, None]).sum(0) / areas[i]


def continuum_pole_density(horizon, n=500):
    """The same density as an integral over the sphere, (1/M) int omega/r n n . (u(y) - u(x)) dA
    with M = int omega dA (on a whole sphere every count is the same), by the midpoint rule in
    the angles about the pole: the integrand is bounded there (u(y) - u(x) = O(r))."""
    theta = (np.arange(n) + 0.5) * np.pi / n
    phi = (np.arange(2 * n) + 0.5) * np.pi / n
    T, P = np.meshgrid(theta, phi, indexing="ij")
    Y = np.stack([np.sin(T) * np.cos(P), np.sin(T) * np.sin(P), np.cos(T)], -1).reshape(-1, 3)
    dA = (np.sin(T) * (np.pi / n) ** 2).reshape(-1)
    pole = np.array([0.0, 0.0, 1.0])
    r = np.linalg.norm(Y - pole, axis=1)
    omega = np.clip(1 - r / horizon, 0, None)
    n_ = (Y - pole) / r[:, None]
    u = smooth_field(Y) - smooth_field(pole[None, :])
    along = np.sum(n_ * u, 1)
    return ((omega / r * along * dA)[:, None] * n_).sum(0)[2] / (omega * dA).sum()


def pole_densities(levels, horizon, kind):
    """(vertices, z force density at the pole) at subdivisions 2 to `levels`."""
    V, F = octahedron()
    densities = []
    for level in range(1, levels + 1):
        V, F = subdivided(V, F)
        if level >= 2:
            pole = int(np.argmax(V[:, 2]))
            densities.append((len(V), force_density(V, vertex_areas(V, F, kind), pole, horizon)[2]))
    return densities


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--levels", type=int, default=6)
    parser.add_argument("--horizon", type=float, default=1.2)
    parser.add_argument("--areas", choices=["barycentric", "area-vector"], default="barycentric")
    args = parser.parse_args()
    values = []
    for vertices, value in pole_densities(args.levels, args.horizon, args.areas):
        values.append(value)
        line = "%6d vertices: force density at the pole (z) %.6f" % (vertices, value)
        if len(values) >= 3:
            ratio = (values[-3] - values[-2]) / (values[-2] - values[-1])
            line += "   difference ratio %.2f" % ratio
        print(line, flush=True)
    print("the integral itself: %.6f" % continuum_pole_density(args.horizon))


if __name__ == "__main__":
    main()

#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-3.0-or-later
"""Does the held rim set the dome's first order? A small independent model (issue 44).

The dome of `experiments/dome_mesh_study.json` in numpy, linear and without fluid: the octahedron's
sphere (radius 1) with its lower half pressed flat onto z = 0 and held there, the bulk fibers'
weights with the default settings (the area count, the conical influence, horizon 1.2; as
`surface_quadrature_check.py`), and a load q = z along each free vertex's area vector (scalar:
q |S_i|). Two kernels: "scalar" (w_ij (u_j - u_i), a bar's nonlocal diffusion) and "central"
(w_ij n n^T (u_j - u_i), the central fibers linearised).

Two rims:
- "held": a rim vertex is held whole, so the shell's share of its area takes the wall's zero
  while the nonlocal solution jumps there (docs/model.md, A sphere under gravity).
- "split": each rim vertex j keeps its wall share (1 - s_j) of area, held, and its shell share
  s_j (the share of its faces' area on faces with a free vertex) becomes a ghost point at s_j
  that moves with j's nearest free neighbour along an edge. The ghost takes part in every sum
  a vertex does (its fibers to free, held and ghost points, its share of load), and its
  equation is added to the neighbour's: the energy with u_ghost = u_neighbour. So the jump's
  quadrature is one-sided on each side of the rim.

Prints the pole's displacement and the largest one per level, and the ratios of successive
differences (4 for second order). Scalar: under 10 s to subdivision 5; central: under a minute.

The count ("area", fiberfluid's default, or "mean"; bulk_weights) decides the central kernel's
pole: with the area count the octahedron's pole, which has four neighbours and 2/3 of their
area, sits about 1.3% below its rings at every level; with the mean it does not.
Usage: /usr/bin/python3 experiments/dome_rim_model.py [--kernel scalar|central]
       [--rim held|split] [--count area|mean] [--levels 2,3,4,5]
"""
import argparse
import os
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from surface_quadrature_check import octahedron, subdivided, vertex_areas  # noqa: E402

HORIZON = 1.2


def dome(level):
    """The dome at subdivision `level`: (vertices, faces), the lower half flattened onto z = 0."""
    V, F = octahedron()
    for _ in range(level):
        V, F = subdivided(V, F)
    V = V.copy()
    V[V[:, 2] < 0, 2] = 0.0
    return V, F


def bulk_weights(X, areas, count="area"):
    """The bulk weights, with M_i = sum_j omega_ij |S_j| the area vertex i's fibers reach:
    "area" (fiberfluid's area count, c_i = M_i / |S_i|):
        w_ij = omega (|S_i| + |S_j|) / ((c_i + c_j) L_ij)
             = omega |S_i| |S_j| / (M_ij L_ij),  M_ij = (M_i |S_j| + M_j |S_i|) / (|S_i| + |S_j|),
    a mean of M_i and M_j weighted by the other end's area, so by the mesh where the areas
    differ (a vertex with four neighbours has 2/3 of its neighbours' area);
    "mean": the same with M_ij = (M_i + M_j) / 2, a kernel that does not depend on the mesh."""
    L = np.linalg.norm(X[:, None, :] - X[None, :, :], axis=2)
    omega = np.clip(1 - L / HORIZON, 0, None)
    np.fill_diagonal(omega, 0)
    reach = (omega * areas[None, :]).sum(1)
    np.fill_diagonal(L, 1.0)
    if count == "mean":
        W = omega * areas[:, None] * areas[None, :] / (0.5 * (reach[:, None] + reach[None, :]) * L)
    else:
        counts = reach / areas
        W = omega * (areas[:, None] + areas[None, :]) / ((counts[:, None] + counts[None, :]) * L)
    np.fill_diagonal(W, 0)
    return W


def face_area_vectors(X, F):
    return 0.5 * np.cross(X[F[:, 1]] - X[F[:, 0]], X[F[:, 2]] - X[F[:, 0]])


def rim_ghosts(X, F, held):
    """Per rim vertex j (held, with a face that has a free vertex): its shell share s_j and its
    nearest free neighbour along an edge."""
    face = np.linalg.norm(face_area_vectors(X, F), axis=1)
    on_shell = ~np.all(held[F], axis=1)
    every, shell = np.zeros(len(X)), np.zeros(len(X))
    for k in range(3):
        np.add.at(every, F[:, k], face)
        np.add.at(shell, F[:, k], face * on_shell)
    ghosts = []
    for j in np.nonzero(held & (shell > 0))[0]:
        star = np.unique(F[np.any(F == j, axis=1)])
        free = star[~held[star]]
        nearest = free[np.argmin(np.linalg.norm(X[free] - X[j], axis=1))]
        ghosts.append((j, shell[j] / every[j], nearest))
    return ghosts


def points(X, F, held, split):
    """The quadrature points: (vertex whose position and weights it has, share of that vertex's
    area, the unknown it moves with or -1 if held)."""
    free = np.nonzero(~held)[0]
    unknown = -np.ones(len(X), dtype=int)
    unknown[free] = np.arange(len(free))
    vertex, share, moves_with = list(range(len(X))), [1.0] * len(X), list(unknown)
    if split:
        for j, s, neighbour in rim_ghosts(X, F, held):
            share[j] = 1.0 - s
            vertex.append(j)
            share.append(s)
            moves_with.append(unknown[neighbour])
    return np.array(vertex), np.array(share), np.array(moves_with), len(free)


def solve(level, kernel, split, count="area"):
    """The displacement at every vertex of the dome at `level` (#V by 3; scalar: in column 2)."""
    X, F = dome(level)
    held = X[:, 2] <= 1e-12
    areas = vertex_areas(X, F, "area-vector")
    vertex, share, moves_with, num_free = points(X, F, held, split)
    W = bulk_weights(X, areas, count)[np.ix_(vertex, vertex)] * share[:, None] * share[None, :]
    W[vertex[:, None] == vertex[None, :]] = 0  # a ghost and its own vertex: no length
    dim = 3 if kernel == "central" else 1
    K = np.zeros((dim * num_free, dim * num_free))
    a, b = np.nonzero(np.triu(W, 1))
    moving = moves_with[a] != moves_with[b]  # a ghost and its neighbour move as one
    a, b = a[moving], b[moving]
    ua, ub = moves_with[a], moves_with[b]
    if kernel == "central":
        d = X[vertex[b]] - X[vertex[a]]
        n = d / np.linalg.norm(d, axis=1)[:, None]
        blocks = W[a, b][:, None, None] * n[:, :, None] * n[:, None, :]
    else:
        blocks = W[a, b][:, None, None]
    for p, q, sign in ((ua, ua, 1), (ub, ub, 1), (ua, ub, -1), (ub, ua, -1)):
        both = (p >= 0) & (q >= 0)
        for r in range(dim):
            for c in range(dim):
                np.add.at(K, (dim * p[both] + r, dim * q[both] + c), sign * blocks[both, r, c])
    # The load q = z along the area vector, each point with its share of its vertex's.
    S = np.zeros_like(X)
    face_vectors = face_area_vectors(X, F)
    for k in range(3):
        np.add.at(S, F[:, k], face_vectors / 3)
    load = np.zeros(dim * num_free)
    for v, s, u in zip(vertex, share, moves_with):
        if u < 0:
            continue
        force = s * X[v, 2] * (S[v] if dim == 3 else np.linalg.norm(S[v], keepdims=True))
        load[dim * u:dim * u + dim] += force
    U = np.zeros((len(X), 3))
    U[~held, 3 - dim:] = np.linalg.solve(K, load).reshape(-1, dim)
    return X, U


def study(levels, kernel, split, count="area"):
    """(pole, largest) displacement per level."""
    figures = []
    for level in levels:
        X, U = solve(level, kernel, split, count)
        magnitude = np.linalg.norm(U, axis=1)
        figures.append((magnitude[np.argmax(X[:, 2])], magnitude.max()))
    return figures


def pole_increments(level, kernel, split, count="area"):
    """u_z's drops from the pole along the meridian y = 0, ring by ring (a smooth top: 1, 3, 5)."""
    X, U = solve(level, kernel, split, count)
    meridian = np.nonzero((np.abs(X[:, 1]) < 1e-12) & (X[:, 0] >= -1e-12) & (X[:, 2] > 0.5))[0]
    meridian = meridian[np.argsort(-X[meridian, 2])]
    return -np.diff(U[meridian, 2])


def ratios(series):
    return [(a - b) / (b - c) for a, b, c in zip(series, series[1:], series[2:])]


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--kernel", choices=["scalar", "central"], default="scalar")
    parser.add_argument("--rim", choices=["held", "split"], default="split")
    parser.add_argument("--count", choices=["area", "mean"], default="area")
    parser.add_argument("--levels", default="2,3,4,5")
    args = parser.parse_args()
    levels = [int(level) for level in args.levels.split(",")]
    figures = study(levels, args.kernel, args.rim == "split", args.count)
    for level, (pole, largest) in zip(levels, figures):
        print("subdivision %d: pole %.6f, largest %.6f" % (level, pole, largest), flush=True)
    for name, column in (("pole", 0), ("largest", 1)):
        series = [f[column] for f in figures]
        print("%s: difference ratios %s" % (name, ", ".join("%.2f" % r for r in ratios(series))))


if __name__ == "__main__":
    main()

#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-3.0-or-later
"""Experiments for mpi_test.sh's ranks-disagree case (issue 43), in WORK:
A/exp.json a small sweep on a mesh file (A/ball.obj); B/exp.json the same
with another gamma; C/exp.json with one variant fewer; D/exp.json the same
file as A's beside a mesh with one vertex moved by a micrometre.
Usage: disagree.py WORK
"""
import json
import os
import sys

work = sys.argv[1]


def ball(moved):
    """An octahedron (a closed, outward mesh), one vertex moved by `moved` m."""
    v = [(1, 0, 0), (-1, 0, 0), (0, 1, 0), (0, -1, 0), (0, 0, 1), (0, 0, -1)]
    v[0] = (1 + moved, 0, 0)
    f = [(0, 2, 4), (2, 1, 4), (1, 3, 4), (3, 0, 4), (2, 0, 5), (1, 2, 5), (3, 1, 5), (0, 3, 5)]
    lines = ["v %.17g %.17g %.17g" % p for p in v]
    lines += ["f %d %d %d" % (a + 1, b + 1, c + 1) for a, b, c in f]
    return "\n".join(lines) + "\n"


experiment = {
    "name": "disagree",
    "surface": {"file": "ball.obj"},
    "material": {"Y": 300000, "gamma": 100},
    "supports": [{"where": "z >= 0.9"}],
    "loads": [{"type": "gravity", "acceleration": [0, 0, -10], "density": 1000}],
    "stepping": {"steps": 2},
    "variants": [{"name": "soft", "material": {"Y": 200000}}, {"name": "stiff"}],
}
for folder, change, moved in (("A", None, 0.0), ("B", "gamma", 0.0), ("C", "variants", 0.0),
                              ("D", None, 1e-6)):
    e = json.loads(json.dumps(experiment))
    if change == "gamma":
        e["material"]["gamma"] = 110
    if change == "variants":
        e["variants"] = e["variants"][:1]
    os.makedirs(os.path.join(work, folder), exist_ok=True)
    with open(os.path.join(work, folder, "exp.json"), "w") as out:
        json.dump(e, out, indent=1)
    with open(os.path.join(work, folder, "ball.obj"), "w") as out:
        out.write(ball(moved))

#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-3.0-or-later
"""Plots a fiberfluid summary.json: the deformed surface beside its reference
(when final.obj is there), and per load step the largest displacement and the
pressure of every run. For a sweep with a round trip, also Eq. 9 against n.

    /usr/bin/python3 experiments/plot.py out/sphere/summary.json out/sphere/plot.png
"""
import json
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def read_obj(path):
    vertices, faces = [], []
    with open(path) as f:
        for line in f:
            words = line.split()
            if not words:
                continue
            if words[0] == "v":
                vertices.append([float(w) for w in words[1:4]])
            elif words[0] in ("f", "l"):
                faces.append([int(w.split("/")[0]) - 1 for w in words[1:]])
    return vertices, faces


def draw_surface(ax, vertices, faces, colour, label):
    xs = [v[0] for v in vertices]
    ys = [v[1] for v in vertices]
    zs = [v[2] for v in vertices]
    if faces and len(faces[0]) == 3:
        ax.plot_trisurf(xs, ys, zs, triangles=faces, color=colour, alpha=0.35,
                        edgecolor="k", linewidth=0.1, label=label)
    else:
        for a, b in faces:
            ax.plot([xs[a], xs[b]], [ys[a], ys[b]], [zs[a], zs[b]], color=colour)


def main(summary_path, png_path):
    with open(summary_path) as f:
        summary = json.load(f)
    runs = summary.get("runs", [])
    folder = os.path.dirname(summary_path)
    final_obj = os.path.join(folder, "final.obj")
    sweep = len(runs) > 1
    panels = 2 + (1 if os.path.exists(final_obj) else 0) + (1 if sweep else 0)
    fig = plt.figure(figsize=(5 * panels, 4.5))
    k = 1
    if os.path.exists(final_obj):
        ax = fig.add_subplot(1, panels, k, projection="3d")
        k += 1
        v_final, faces = read_obj(final_obj)
        draw_surface(ax, v_final, faces, "tab:red", "deformed")
        ax.set_title("deformed surface (final.obj)")
        ax.set_box_aspect([max(v[a] for v in v_final) - min(v[a] for v in v_final)
                           for a in range(3)])
    for key, label in (("max_displacement", "largest |u|"), ("pressure", "pressure P")):
        ax = fig.add_subplot(1, panels, k)
        k += 1
        for run in runs:
            steps = [s["step"] for s in run["steps"]]
            values = [s[key] for s in run["steps"]]
            ax.plot(steps, values, marker="." if len(steps) < 50 else None,
                    label=run["variant"] or summary["experiment"])
        ax.set_xlabel("load step")
        ax.set_ylabel(label)
        ax.grid(True, alpha=0.3)
        if sweep:
            ax.legend(fontsize=7)
    if sweep:
        ax = fig.add_subplot(1, panels, k)
        by_kind = {}
        for run in runs:
            n = run["stepping"]["steps"] // 2
            kind = "A rebuilt" if run["stepping"]["rebuild_matrix"] else "A constant"
            by_kind.setdefault(kind, []).append((n, run["final"]["mean_displacement_over_diagonal"]))
        for kind, points in by_kind.items():
            points.sort()
            ax.loglog([p[0] for p in points], [p[1] for p in points], marker="o", label=kind)
        ax.loglog([1, 10, 100], [0.03, 0.003, 0.0003], "k--", marker="s", label="paper (breasts)")
        ax.set_xlabel("steps each way n")
        ax.set_ylabel("Eq. 9 after the round trip")
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=8)
    fig.suptitle(summary["experiment"])
    fig.tight_layout()
    fig.savefig(png_path, dpi=110)


if __name__ == "__main__":
    if len(sys.argv) != 3:
        sys.exit(__doc__)
    main(sys.argv[1], sys.argv[2])

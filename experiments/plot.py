#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-3.0-or-later
"""Plots a fiberfluid result folder (SI units throughout).

    /usr/bin/python3 experiments/plot.py out/sphere/summary.json out/sphere/plot.png

Panels: the deformed surface coloured by |u| with the undeformed outline drawn
over it (for a sweep, the variant that moved most); per load step the largest
displacement and the pressure of every run, one curve per variant; the
reactions of the supports; for paddle experiments, the force of each moving
paddle against its travel (the force-compression curve), one curve per variant;
and for a round-trip sweep, Eq. 9 against n for each scheme.

Given a mesh study's study.json (fiberfluid study mesh) instead: each figure
against the relative element size h, with its Richardson-extrapolated value
at h = 0 and the error estimate drawn as a band.
"""
import csv
import json
import os
import sys

try:
    import matplotlib
except ImportError:  # another python3 first on PATH (pyenv, a venv): Debian's has it (install-deps)
    if os.path.exists("/usr/bin/python3") and os.path.realpath(sys.executable) != "/usr/bin/python3":
        os.execv("/usr/bin/python3", ["/usr/bin/python3"] + sys.argv)
    sys.exit("needs matplotlib (Debian: apt-get install python3-matplotlib)")

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
from matplotlib import cm, colors  # noqa: E402
from mpl_toolkits.mplot3d.art3d import Line3DCollection, Poly3DCollection  # noqa: E402


def read_obj_faces(path):
    faces = []
    with open(path) as f:
        for line in f:
            words = line.split()
            if words and words[0] in ("f", "l"):
                faces.append([int(w.split("/")[0]) - 1 for w in words[1:]])
    return faces


def read_vertices_csv(path):
    """Reference positions and displacements per vertex, from vertices.csv."""
    with open(path, newline="") as f:
        rows = list(csv.DictReader(f))
    axes = [a for a in "xyz" if f"{a}_m" in rows[0]]
    reference = [[float(r[f"{a}_m"]) for a in axes] for r in rows]
    displacement = [[float(r[f"u{a}_m"]) for a in axes] for r in rows]
    magnitude = [float(r["u_magnitude_m"]) for r in rows]
    return reference, displacement, magnitude


def draw_deformed(fig, position, run_folder, title):
    reference, displacement, magnitude = read_vertices_csv(os.path.join(run_folder, "vertices.csv"))
    faces = read_obj_faces(os.path.join(run_folder, "final.obj"))
    deformed = [[s + u for s, u in zip(p, d)] for p, d in zip(reference, displacement)]
    norm = colors.Normalize(vmin=0.0, vmax=max(max(magnitude), 1e-300))
    colour_map = cm.viridis
    three_d = len(reference[0]) == 3
    if three_d:
        ax = fig.add_subplot(*position, projection="3d")
        face_u = [sum(magnitude[i] for i in f) / len(f) for f in faces]
        ax.add_collection3d(Poly3DCollection([[deformed[i] for i in f] for f in faces],
                                             facecolors=colour_map(norm(face_u)),
                                             edgecolor="none", alpha=0.9))
        ax.add_collection3d(Line3DCollection([[reference[i] for i in f] + [reference[f[0]]]
                                              for f in faces],
                                             colors="0.35", linewidths=0.25))
        everything = reference + deformed
        low = [min(p[a] for p in everything) for a in range(3)]
        high = [max(p[a] for p in everything) for a in range(3)]
        ax.set_xlim(low[0], high[0])
        ax.set_ylim(low[1], high[1])
        ax.set_zlim(low[2], high[2])
        ax.set_box_aspect([max(h - l, 1e-12) for l, h in zip(low, high)])
        ax.set_xlabel("x [m]")
        ax.set_ylabel("y [m]")
        ax.set_zlabel("z [m]")
    else:
        ax = fig.add_subplot(*position)
        for a, b in faces:
            ax.plot([reference[a][0], reference[b][0]], [reference[a][1], reference[b][1]],
                    color="0.5", linestyle="--", linewidth=1)
            mean_u = 0.5 * (magnitude[a] + magnitude[b])
            ax.plot([deformed[a][0], deformed[b][0]], [deformed[a][1], deformed[b][1]],
                    color=colour_map(norm(mean_u)), linewidth=2.5)
        ax.set_aspect("equal")
        ax.set_xlabel("x [m]")
        ax.set_ylabel("y [m]")
    fig.colorbar(cm.ScalarMappable(norm=norm, cmap=colour_map), ax=ax, shrink=0.7,
                 pad=0.15 if three_d else 0.05,
                 label="|u| [m]")
    ax.set_title(title + "\n(grey: undeformed outline)", fontsize=9)


def draw_paddle_forces(ax, runs):
    """Force on the body along each moving paddle's axis against its travel."""
    for run in runs:
        for label, first in run["steps"][-1]["paddles"].items():
            if first["travel"] == 0:
                continue  # a fixed paddle: its force is the other's, less the supports'
            axis = "xyz".index(run["paddle_axes"][label]) if "paddle_axes" in run else None
            travel = [0.0] + [abs(s["paddles"][label]["travel"]) for s in run["steps"]]
            force = [0.0] + [abs(s["paddles"][label]["force"][axis]) if axis is not None
                             else sum(c * c for c in s["paddles"][label]["force"]) ** 0.5
                             for s in run["steps"]]
            name = (run["variant"] + ": " if run["variant"] else "") + label
            ax.plot([1000 * t for t in travel], force, marker=".", label=name)
    ax.set_xlabel("paddle travel [mm]")
    ax.set_ylabel("paddle force on the body [N]")
    ax.set_title("force-compression")
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=7)


def run_folder(folder, run):
    return os.path.join(folder, run["variant"]) if run["variant"] else folder


def plot_study(study, png_path):
    figures = study["figures"]
    h = study["relative_sizes"]
    n = len(figures)
    cols = min(3, n)
    rows = (n + cols - 1) // cols
    fig, axes = plt.subplots(rows, cols, figsize=(4.6 * cols, 3.6 * rows), squeeze=False)
    for ax, (name, f) in zip(axes.flat, sorted(figures.items())):
        ax.plot(h[: len(f["values"])], f["values"], "o-", label="levels")
        if f.get("observed_order") is not None:
            x = f["extrapolated"]
            ax.plot([0.0], [x], "s", color="C3", label=f"extrapolated (order {f['observed_order']:.2f})")
            ax.axhspan(x - f["error_estimate"], x + f["error_estimate"], color="C3", alpha=0.15)
        else:
            ax.set_title((f["trend"] or "fewer than 3 levels") + ": no order", fontsize=8, loc="right")
        ax.set_xlim(left=-0.04)
        ax.set_xlabel("element size, relative to the coarsest")
        ax.set_ylabel(name, fontsize=8)
        ax.legend(fontsize=7)
    for ax in list(axes.flat)[n:]:
        ax.axis("off")
    fig.suptitle(os.path.basename(study["experiment"]) + ": mesh study (" + study["refined"] + ")")
    fig.tight_layout()
    fig.savefig(png_path, dpi=110)


def main(summary_path, png_path):
    with open(summary_path) as f:
        summary = json.load(f)
    if "relative_sizes" in summary:  # a mesh study
        plot_study(summary, png_path)
        return
    folder = os.path.dirname(summary_path) or "."
    runs = [r for r in summary.get("runs", []) if r["steps"]]
    if not runs:
        sys.exit(f"{summary_path}: no load steps to plot")
    sweep = len(summary.get("runs", [])) > 1
    # A round trip: every load back to zero at the end of every run.
    round_trip = sweep and all(
        r["success"] and r["steps"][-1]["load_factors"] and
        not any(r["steps"][-1]["load_factors"].values()) for r in runs)
    drawable = [r for r in runs if r["success"] and
                os.path.exists(os.path.join(run_folder(folder, r), "vertices.csv")) and
                os.path.exists(os.path.join(run_folder(folder, r), "final.obj"))]
    paddles = [r for r in runs if r["steps"][-1].get("paddles")]
    # Arc length: the load factor is an unknown; its curve against the
    # displacement shows a limit point where it turns.
    by_arc = [r for r in runs
              if r["stepping"].get("newton", {}).get("control") == "arc_length"]
    panels = ((1 if drawable else 0) + 3 + (1 if paddles else 0) + (1 if round_trip else 0)
              + (1 if by_arc else 0))
    fig = plt.figure(figsize=(4.8 * panels, 4.5))
    k = 1
    if drawable:
        shown = max(drawable, key=lambda r: r["steps"][-1]["max_displacement"])
        title = "deformed surface" + (f", variant {shown['variant']}" if shown["variant"] else "")
        draw_deformed(fig, (1, panels, k), run_folder(folder, shown), title)
        k += 1
    for key, label in (("max_displacement", "largest displacement |u| [m]"),
                       ("pressure", "pressure P [Pa]")):
        ax = fig.add_subplot(1, panels, k)
        k += 1
        for run in runs:
            steps = [s["step"] for s in run["steps"]]
            ax.plot(steps, [s[key] for s in run["steps"]], marker="." if len(steps) < 50 else None,
                    label=run["variant"] or summary["experiment"])
        ax.set_xlabel("load step")
        ax.set_ylabel(label)
        ax.grid(True, alpha=0.3)
        if sweep:
            ax.legend(fontsize=7)
    ax = fig.add_subplot(1, panels, k)
    k += 1
    for run in runs:
        for group in run["steps"][-1].get("reactions", {}):
            magnitudes = [sum(c * c for c in s["reactions"][group]) ** 0.5 for s in run["steps"]]
            name = (run["variant"] + ": " if run["variant"] else "") + group
            ax.plot([s["step"] for s in run["steps"]], magnitudes, label=name)
    ax.set_xlabel("load step")
    ax.set_ylabel("support reaction |R| [N]")
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=7)
    if paddles:
        draw_paddle_forces(fig.add_subplot(1, panels, k), paddles)
        k += 1
    if by_arc:
        ax = fig.add_subplot(1, panels, k)
        k += 1
        for run in by_arc:
            factors = [max(s["load_factors"].values()) for s in run["steps"]]
            ax.plot([s["max_displacement"] for s in run["steps"]], factors, marker=".",
                    label=run["variant"] or summary["experiment"])
            if run.get("limit_load_factor") is not None:
                ax.axhline(run["limit_load_factor"], color="k", ls="--", lw=0.8,
                           label="limit load %.4g" % run["limit_load_factor"])
        ax.set_xlabel("largest displacement |u| [m]")
        ax.set_ylabel("load factor [-]")
        ax.set_title("load path (arc length)")
        ax.grid(True, alpha=0.3)
        ax.legend(fontsize=7)
    if round_trip:
        ax = fig.add_subplot(1, panels, k)
        by_kind = {}
        for run in runs:
            n = run["stepping"]["steps"] // 2
            if run["stepping"].get("scheme") == "newton":
                kind = "Newton"
            else:
                kind = "incremental, A rebuilt" if run["stepping"]["rebuild_matrix"] \
                    else "incremental, A constant"
            error = max(run["final"]["mean_displacement_over_diagonal"], 1e-17)  # log scale
            by_kind.setdefault(kind, []).append((n, error))
        for kind, points in by_kind.items():
            points.sort()
            ax.loglog([p[0] for p in points], [p[1] for p in points], marker="o", label=kind)
        ax.loglog([1, 10, 100], [0.03, 0.003, 0.0003], "k--", marker="s", label="paper (breasts)")
        ax.set_xlabel("steps each way n")
        ax.set_ylabel("Eq. 9 after the round trip [-]")
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=8)
    fig.suptitle(summary["experiment"] + ("" if summary.get("success", True) else " (FAILED)"))
    fig.tight_layout()
    fig.savefig(png_path, dpi=110)


if __name__ == "__main__":
    if len(sys.argv) != 3:
        sys.exit(__doc__)
    main(sys.argv[1], sys.argv[2])

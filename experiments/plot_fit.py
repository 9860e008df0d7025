#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-3.0-or-later
"""Pictures of a fit (the output folder of `fiberfluid fit`):
  fit_convergence.png  the cost per iteration and each parameter's path (relative to its final value)
  fit_distance.png     the simulated surface at each target's step, coloured by its distance to
                       the target (as the method paper's Fig. 1 shows its liver)
  fit_material_K.png   a material test's measured and fitted nominal stress against stretch,
                       per test (fit_other_K.csv of a "material_test" target)
Usage: /usr/bin/python3 experiments/plot_fit.py OUT_DIR
"""
import json
import os
import re
import sys

try:
    import matplotlib
except ImportError:  # another python3 first on PATH (pyenv, a venv): Debian's has it (install-deps)
    if os.path.exists("/usr/bin/python3") and os.path.realpath(sys.executable) != "/usr/bin/python3":
        os.execv("/usr/bin/python3", ["/usr/bin/python3"] + sys.argv)
    sys.exit("needs matplotlib (Debian: apt-get install python3-matplotlib)")

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from mpl_toolkits.mplot3d.art3d import Poly3DCollection  # noqa: E402


def read_vtu(path):
    text = open(path).read()
    points = triangles = None
    fields = {}
    for header, body in re.findall(r"<DataArray([^>]*)>(.*?)</DataArray>", text, re.S):
        values = body.split()
        name = re.search(r'Name="([^"]*)"', header)
        if name is None and 'NumberOfComponents="3"' in header:
            points = np.array(values, float).reshape(-1, 3)
        elif name and name.group(1) == "connectivity":
            triangles = np.array(values, int).reshape(-1, 3)
        elif name:
            fields[name.group(1)] = np.array(values, float)
    return points, triangles, fields


def convergence(fit, path):
    its = fit["iterations"]
    if not its:
        return
    names = [p["name"] for p in fit["parameters"]]
    fig, (a, b) = plt.subplots(1, 2, figsize=(11, 4))
    a.semilogy([i["iteration"] for i in its], [max(i["cost"], 1e-300) for i in its], "o-")
    a.set_xlabel("iteration")
    a.set_ylabel("cost, 1/2 sum d^2 (m^2)")
    a.set_title(f"{fit['experiment']}: {fit['method']}")
    a.grid(True, which="both", alpha=0.3)
    for p in fit["parameters"]:
        # Relative to the fitted value; one fitted at 0 (a bound) relative to its largest.
        scale = p["value"] or max(abs(i["values"][p["name"]]) for i in its) or 1.0
        values = [i["values"][p["name"]] / scale for i in its]
        b.plot([i["iteration"] for i in its], values, "o-", label=p["name"])
    b.axhline(1.0, color="k", lw=0.5)
    b.set_xlabel("iteration")
    b.set_ylabel("value / fitted value (or / largest, fitted at 0)")
    b.legend()
    b.grid(True, alpha=0.3)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def distance(folder, fit, path):
    files = sorted(f for f in os.listdir(folder) if re.fullmatch(r"fit_target_\d+\.vtu", f))
    if not files:
        return
    fig = plt.figure(figsize=(6 * len(files), 5.5))
    top = max(t["distance"]["largest"] or 0.0 for t in fit["targets"]) * 1e3 or 1.0
    for k, name in enumerate(files):
        X, T, fields = read_vtu(os.path.join(folder, name))
        d = fields["distance_to_target"] * 1e3
        ax = fig.add_subplot(1, len(files), k + 1, projection="3d")
        faces = Poly3DCollection(X[T], cmap="viridis", edgecolor="none")
        faces.set_array(d[T].mean(axis=1))
        faces.set_clim(0.0, top)
        ax.add_collection3d(faces)
        for axis, set_lim in enumerate((ax.set_xlim, ax.set_ylim, ax.set_zlim)):
            set_lim(X[:, axis].min(), X[:, axis].max())
        ax.set_box_aspect(np.ptp(X, axis=0))
        target = fit["targets"][k]
        sd = target["distance"]["share_of_length"]["standard_deviation"]
        ax.set_title(f"step {target['step']}: sd {100 * sd:.2f}% of the length", fontsize=10)
        ax.set_axis_off()
        fig.colorbar(faces, ax=ax, shrink=0.6, label="distance to the target (mm)")
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def material_tests(folder, fit):
    """One picture per material-test target: measured points, the fitted law's curve through them."""
    written = []
    for k, target in enumerate(fit.get("other_targets", [])):
        rows_path = os.path.join(folder, "fit_other_%d.csv" % k)
        if target.get("type") != "material_test" or not os.path.exists(rows_path):
            continue
        tests = {}
        with open(rows_path) as rows:
            next(rows)
            for line in rows:
                test, stretch, measured, fitted, _ = line.strip().split(",")
                tests.setdefault(test, []).append((float(stretch), float(measured), float(fitted)))
        fig, ax = plt.subplots(figsize=(6, 4.5))
        for test, points in sorted(tests.items()):
            points.sort()
            stretch, measured, fitted = (np.array(c) for c in zip(*points))
            line = ax.plot(stretch, fitted / 1e6, "-", label="%s, fitted" % test)[0]
            ax.plot(stretch, measured / 1e6, "o", color=line.get_color(), label="%s, measured" % test)
        rms = target["figures"].get("rms_relative_misfit", float("nan"))
        ax.set_xlabel("stretch")
        ax.set_ylabel("nominal stress (MPa)")
        ax.set_title("%s: rms relative misfit %.1f%%" % (target.get("label", ""), 100 * rms))
        ax.legend()
        fig.tight_layout()
        path = os.path.join(folder, "fit_material_%d.png" % k)
        fig.savefig(path, dpi=120)
        plt.close(fig)
        written.append(path)
    return written


def main():
    if len(sys.argv) != 2:
        sys.exit(__doc__)
    folder = sys.argv[1]
    fit = json.load(open(os.path.join(folder, "fit.json")))
    convergence(fit, os.path.join(folder, "fit_convergence.png"))
    distance(folder, fit, os.path.join(folder, "fit_distance.png"))
    written = material_tests(folder, fit)
    print("plots:", os.path.join(folder, "fit_convergence.png"), os.path.join(folder, "fit_distance.png"),
          *written)


if __name__ == "__main__":
    main()

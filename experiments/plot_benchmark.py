#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-3.0-or-later
"""Pictures of an accuracy benchmark (the output folder of `fiberfluid run` on a
"kind": "benchmark" experiment), in the layout of Alterovitz and Goldberg's
Figs. 5-11: one panel per metric (E_n, E_s, E_i), one curve per solver, error
against time, every solver measured against the implicit Newmark reference.
  benchmark.png   the three panels for the FEM solvers (linear axes) and, when the
                  fiber model ran, a second row with it (log axes)
Usage: /usr/bin/python3 experiments/plot_benchmark.py OUT_DIR [OUT_DIR ...]
"""
import csv
import json
import math
import os
import sys
from collections import OrderedDict

try:
    import matplotlib
except ImportError:  # another python3 first on PATH (pyenv, a venv): Debian's has it (install-deps)
    if os.path.exists("/usr/bin/python3") and os.path.realpath(sys.executable) != "/usr/bin/python3":
        os.execv("/usr/bin/python3", ["/usr/bin/python3"] + sys.argv)
    sys.exit("needs matplotlib (Debian: apt-get install python3-matplotlib)")

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

METRICS = [("E_n", "relative energy norm error E_n"),
           ("E_s", "surface error E_s"),
           ("E_i", "interior error E_i")]


def read_series(folder):
    series = OrderedDict()
    with open(os.path.join(folder, "metrics.csv")) as f:
        for row in csv.DictReader(f):
            s = series.setdefault(row["series"], {"t": [], "E_n": [], "E_s": [], "E_i": []})
            s["t"].append(float(row["time_s"]))
            for key, _ in METRICS:
                s[key].append(float(row[key]) if row[key] else math.nan)
    return series


def draw(ax, series, status, key, title, log):
    tops = []
    for label, s in series.items():
        points = [(t, v) for t, v in zip(s["t"], s[key]) if not math.isnan(v) and (v > 0 or not log)]
        if not points:
            continue
        t, v = zip(*points)
        ok = status.get(label, {}).get("ok", True)
        name = label if ok else f"{label} (diverged at {s['t'][-1]:.2f} s)"
        style = "--" if label == "fiber-model" else "-"
        ax.plot(t, v, style, label=name, linewidth=1.3)
        if ok:  # E_n starts huge where the reference has barely moved: scale to t >= 0.5 s
            late = [y for x, y in zip(t, v) if x >= 0.5]
            tops.append(max(late) if late and max(v) > 3 * max(late) else max(v))
    if log:
        ax.set_yscale("log")
    elif tops:  # a diverging solver would flatten the others
        ax.set_ylim(0.0, 1.15 * max(tops))
    ax.set_title(title)
    ax.set_xlabel("time (s)")
    ax.set_ylabel(key + (" (log scale)" if log else ""))
    ax.grid(alpha=0.3)


def plot(folder):
    info = json.load(open(os.path.join(folder, "benchmark.json")))
    series = read_series(folder)
    status = {s["label"]: s for s in info["series"]}
    fem = OrderedDict((k, v) for k, v in series.items() if k != "fiber-model")
    # The paper's layout: the FEM solvers, linear axes; below, when the fiber
    # model ran, every series on log axes (its errors are far larger).
    rows = 2 if len(fem) < len(series) else 1
    fig, axes = plt.subplots(rows, 3, figsize=(16, 4.6 * rows), squeeze=False)
    for col, (key, title) in enumerate(METRICS):
        draw(axes[0][col], fem, status, key, title, log=False)
        if rows == 2:
            draw(axes[1][col], series, status, key, title + ", with the fiber model", log=True)
    m = info["material"]
    mesh = info["mesh"]
    fig.suptitle(f"{info['scene']}, {m['label']} (E = {m['E']:g} Pa, nu = {m['nu']:g}), "
                 f"{mesh['elements']} elements, h = {info['time']['step']:.4g} s; "
                 "every solver against implicit Newmark")
    for row in axes:
        row[0].legend(fontsize=8)
    fig.tight_layout()
    out = os.path.join(folder, "benchmark.png")
    fig.savefig(out, dpi=100)
    plt.close(fig)
    print(out)


if __name__ == "__main__":
    if len(sys.argv) < 2:
        sys.exit(__doc__)
    for folder in sys.argv[1:]:
        plot(folder)

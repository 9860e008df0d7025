#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-3.0-or-later
"""Plots a prediction with its 95% band (fiberfluid predict), against a measurement if given.

    /usr/bin/python3 experiments/plot_prediction.py out/prediction [--measured CSV] [-o PNG]

Reads DIR/steps.csv (of the first run). With paddles: the force of the first moving paddle
against its travel, as a push (N) against a travel (mm), the band drawn around it; else every
banded column against the load step. A measured CSV (lines starting with # are comments) gives
its travel in the first column named travel* or compression* (mm) and its force in mean_N,
force or force_N (N); its sd_N, when it has one, is drawn as error bars. Writes
DIR/prediction.png unless -o names another file.
"""
import argparse
import csv
import os
import sys
from pathlib import Path

try:
    import matplotlib
except ImportError:  # another python3 first on PATH (pyenv, a venv): Debian's has it (install-deps)
    if os.path.exists("/usr/bin/python3") and os.path.realpath(sys.executable) != "/usr/bin/python3":
        os.execv("/usr/bin/python3", ["/usr/bin/python3"] + sys.argv)
    sys.exit("needs matplotlib (Debian: apt-get install python3-matplotlib)")

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def read_rows(path):
    with open(path) as f:
        lines = [line for line in f if line.strip() and not line.startswith("#")]
    return list(csv.DictReader(lines))


def steps_file(folder):
    direct = folder / "steps.csv"
    if direct.exists():
        return direct
    for sub in sorted(p for p in folder.iterdir() if p.is_dir()):  # a sweep: its first variant
        if (sub / "steps.csv").exists():
            return sub / "steps.csv"
    sys.exit(f"{folder}: no steps.csv (a folder `fiberfluid predict` wrote?)")


def measured_curve(path):
    rows = read_rows(path)
    if not rows:
        sys.exit(f"{path}: no rows")
    names = list(rows[0].keys())
    travel = next((n for n in names if n.lower().startswith(("travel", "compression"))), None)
    force = next((n for n in ("mean_N", "force", "force_N") if n in names), None)
    if travel is None or force is None:
        sys.exit(f"{path}: expected a travel (travel*, compression*) and a force (mean_N, force, "
                 f"force_N) column; it has {', '.join(names)}")
    sd = "sd_N" if "sd_N" in names else None
    x = [float(r[travel]) for r in rows]
    y = [float(r[force]) for r in rows]
    e = [float(r[sd]) for r in rows] if sd else None
    return x, y, e


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("folder", help="the folder fiberfluid predict wrote")
    parser.add_argument("--measured", help="a measured force curve (CSV)")
    parser.add_argument("-o", "--output", help="the PNG to write (default DIR/prediction.png)")
    args = parser.parse_args()
    folder = Path(args.folder)
    rows = read_rows(steps_file(folder))
    names = list(rows[0].keys()) if rows else []
    banded = [n[: -len("_lower95")] for n in names if n.endswith("_lower95")]
    if not banded:
        sys.exit(f"{folder}: steps.csv has no band columns (COLUMN_lower95): not a prediction")
    fig, ax = plt.subplots(figsize=(6.4, 4.4))
    paddles = [n for n in banded if n.startswith("paddle_") and "_force_" in n]
    moving = []
    for n in paddles:
        label = n[len("paddle_"): n.index("_force_")]
        travel = f"paddle_{label}_travel_m"
        if travel in names and any(abs(float(r[travel])) > 0 for r in rows):
            moving.append((n, travel, label))
    if moving:
        label, travel = moving[0][2], moving[0][1]
        # Of that paddle's force components, the one along its axis: the largest.
        column = max((c for c, _, lab in moving if lab == label),
                     key=lambda c: sum(abs(float(r[c])) for r in rows))
        x = [0.0] + [abs(float(r[travel])) * 1e3 for r in rows]
        sign = -1.0 if sum(float(r[column]) for r in rows) < 0 else 1.0
        y = [0.0] + [sign * float(r[column]) for r in rows]
        lo = [0.0] + [sign * float(r[column + ("_upper95" if sign < 0 else "_lower95")]) for r in rows]
        hi = [0.0] + [sign * float(r[column + ("_lower95" if sign < 0 else "_upper95")]) for r in rows]
        ax.fill_between(x, lo, hi, color="tab:red", alpha=0.25, lw=0, label="95% band")
        ax.plot(x, y, "-", color="tab:red", label="predicted")
        ax.set_xlabel(f"paddle {label}: travel (mm)")
        ax.set_ylabel("push on the body (N)")
        if args.measured:
            mx, my, me = measured_curve(args.measured)
            if me:
                ax.errorbar(mx, my, yerr=me, fmt="o", ms=3, color="k", elinewidth=0.8,
                            label="measured (mean, sd)")
            else:
                ax.plot(mx, my, "o", ms=3, color="k", label="measured")
    else:
        steps = [int(float(r["step"])) for r in rows]
        for n in banded:
            y = [float(r[n]) for r in rows]
            ax.plot(steps, y, "-", label=n)
            ax.fill_between(steps, [float(r[n + "_lower95"]) for r in rows],
                            [float(r[n + "_upper95"]) for r in rows], alpha=0.25, lw=0)
        ax.set_xlabel("load step")
    ax.set_title("Prediction at the fitted values, 95% band from the fit")
    ax.legend(loc="upper left")
    fig.tight_layout()
    out = Path(args.output) if args.output else folder / "prediction.png"
    fig.savefig(out, dpi=120)
    print(f"plot: {out}")


if __name__ == "__main__":
    main()

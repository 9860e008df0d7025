#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-3.0-or-later
"""Fits that start far away (issue 42): the bending phantom, with its mirror
layer and gripped without it, fitted for Y and gamma to a noisy scan of its
own final surface (truth Y = 100 kPa, gamma = 0.001 N/m), started at five
times Y and at a fifth of it.

Runs experiments/fit_bending_phantom.json and fit_bending_phantom_gripped.json
with the start of Y replaced, and prints per fit: its status, Y and gamma with
their 95% intervals, whether each holds the truth, the forward runs (and how
many were warm-started), and the wall time.

    /usr/bin/python3 experiments/phantom_fits_benchmark.py build-release/src/app/fiberfluid
"""
import argparse
import json
import subprocess
import tempfile
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
FITS = ["fit_bending_phantom.json", "fit_bending_phantom_gripped.json"]
TRUTH = {"Y": 100000.0, "gamma": 0.001}


def with_start(name, start_y, folder):
    """The experiment with Y started at start_y, its target paths made absolute."""
    experiment = json.loads((HERE / name).read_text())
    experiment["material"]["Y"] = start_y
    for target in experiment["fit"]["targets"]:
        target["file"] = str((HERE / target["file"]).resolve())
    path = Path(folder) / name
    path.write_text(json.dumps(experiment, indent=1))
    return path


def interval(parameter):
    """The value and its 95% interval (null in fit.json: none, or not finite)."""
    low, high = parameter["interval_95"]
    if low is None or high is None:
        return f"{parameter['value']:.4g} (no finite interval)"
    holds = low <= TRUTH[parameter["name"]] <= high
    return f"{parameter['value']:.4g} ({low:.3g} .. {high:.3g}) {'holds' if holds else 'MISSES'}"


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("fiberfluid")
    args = parser.parse_args()
    print("| fit | start Y | status | Y (95%) | gamma (95%) | forward runs (warm) | s |")
    print("|---|---|---|---|---|---|---|")
    for name in FITS:
        for start_y in (5 * TRUTH["Y"], TRUTH["Y"] / 5):
            with tempfile.TemporaryDirectory() as folder:
                experiment = with_start(name, start_y, folder)
                out = Path(folder) / "out"
                began = time.monotonic()
                subprocess.run([args.fiberfluid, "fit", str(experiment), "-o", str(out), "-q"],
                               stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
                seconds = time.monotonic() - began
                result = out if out.exists() else Path(str(out) + ".failed")
                fit = json.loads((result / "fit.json").read_text())
            by_name = {p["name"]: p for p in fit["parameters"]}
            print(f"| {name} | {start_y:g} | {fit['status']} | {interval(by_name['Y'])} | "
                  f"{interval(by_name['gamma'])} | {fit['forward_runs']} "
                  f"({fit.get('warm_started_runs', 0)}) | {seconds:.0f} |")


if __name__ == "__main__":
    main()

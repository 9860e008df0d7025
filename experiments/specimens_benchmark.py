#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-3.0-or-later
"""Real specimens, start to finish (issue 42): the compressed cylinder and the
bending phantom, as a researcher runs them.

Runs experiments/compression_cylinder.json (frictionless and sticking platens,
20 mm of travel in 40 steps) and experiments/bending_phantom.json (10 steps of
gravity), each alone and, with --busy, beside one busy process, and prints per
run: the steps reached, the run's time, its slowest step, Newton iterations,
tangent factorisations, and the estimate printed before the run against the
time measured (issue 42 asks for a factor of 3 at most).

    /usr/bin/python3 experiments/specimens_benchmark.py build-release/src/app/fiberfluid [--busy]
"""
import argparse
import json
import subprocess
import sys
import tempfile
from pathlib import Path

HERE = Path(__file__).resolve().parent
EXPERIMENTS = ["compression_cylinder.json", "bending_phantom.json", "bending_phantom_gripped.json"]


def runs(summary, name):
    for run in summary["runs"]:
        steps = run["steps"]
        yield {
            "run": run["variant"] or name,
            "steps": len(steps),
            "seconds": run["seconds"]["total"],
            "slowest": max((s["seconds"] for s in steps), default=float("nan")),
            "newton": run["newton_iterations"],
            "factorisations": run["factorizations"],
            "estimate": run["estimate"]["seconds"],
            "message": run["message"],
        }


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("fiberfluid")
    parser.add_argument("--busy", action="store_true", help="also beside one busy process")
    args = parser.parse_args()
    print("| experiment | run | beside | steps | run s | slowest step s | Newton iterations "
          "| factorisations | estimate s | measured / estimate |")
    print("|---|---|---|---|---|---|---|---|---|---|")
    for beside in ["alone", "busy"] if args.busy else ["alone"]:
        busy = (subprocess.Popen([sys.executable, "-c", "while True: pass"])
                if beside == "busy" else None)
        try:
            for name in EXPERIMENTS:
                with tempfile.TemporaryDirectory() as folder:
                    out = Path(folder) / "out"
                    subprocess.run([args.fiberfluid, "run", str(HERE / name), "-o", str(out),
                                    "-q", "-j", "1"], stdout=subprocess.DEVNULL,
                                   stderr=subprocess.DEVNULL)
                    result = out if out.exists() else Path(str(out) + ".failed")
                    summary = json.loads((result / "summary.json").read_text())
                for r in runs(summary, Path(name).stem):
                    print(f"| {name} | {r['run']} | {beside} | {r['steps']} | {r['seconds']:.1f} | "
                          f"{r['slowest']:.1f} | {r['newton']} | {r['factorisations']} | "
                          f"{r['estimate']:.1f} | {r['seconds'] / r['estimate']:.2f} |"
                          + (f" {r['message']}" if r["message"] else ""))
        finally:
            if busy:
                busy.kill()
                busy.wait()


if __name__ == "__main__":
    main()

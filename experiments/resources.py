#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-3.0-or-later
"""The resource estimate against what runs take (issue 11).

Runs the fiberfluid command on cases of growing size, one process each, and
prints per case the estimate it printed before starting (summary.json:
runs[0].estimate) beside the measured wall time of the whole process and its
peak resident memory (summary.json: peak_resident_bytes), with their ratios.

    python3 experiments/resources.py BUILD_DIR OUT_DIR
"""
import json
import pathlib
import subprocess
import sys
import time

SPHERE = {
    "material": {"Y": 20000, "gamma": 1},
    "supports": [{"where": "z >= 0.04"}],
    "loads": [{"type": "gravity", "acceleration": [0, 0, -9.81], "density": 1000}],
    "output": {"vtk": False},
}


def sphere(subdivisions, solver="auto", steps=10, scheme="incremental"):
    return dict(SPHERE, name=f"sphere{subdivisions}_{solver}_{scheme}",
                surface={"generator": "icosphere", "subdivisions": subdivisions, "radius": 0.05},
                stepping={"steps": steps, "solver": solver, "scheme": scheme})


def horizon_sphere(subdivisions):
    """Fibers within a tenth of the radius (issue 29), one Newton load step."""
    return dict(sphere(subdivisions, steps=1, scheme="newton"),
                name=f"sphere{subdivisions}_horizon",
                material={"Y": 200000, "gamma": 1}, fibers={"horizon": 0.005})


CASES = [
    ("sphere 642, auto", sphere(3)),
    ("sphere 2562, auto", sphere(4)),
    ("sphere 10242, auto", sphere(5)),
    ("sphere 2562, dense-lu", sphere(4, "dense-lu", steps=3)),
    ("sphere 10242, pcg", sphere(5, "pcg", steps=3)),
    ("sphere 642, newton", sphere(3, scheme="newton", steps=5)),
    ("sphere 10242, horizon", horizon_sphere(5)),
    ("sphere 40962, horizon", horizon_sphere(6)),
    ("liver 139, pruned", "liver_gravity"),
    ("bunny 1366, pruned", "bunny_gravity"),
]


def gib(b):
    return f"{b / 2**30:.3g} GiB" if b >= 2**30 else f"{b / 2**20:.3g} MiB"


def main():
    build, out = pathlib.Path(sys.argv[1]), pathlib.Path(sys.argv[2])
    root = pathlib.Path(__file__).resolve().parent.parent
    binary = build / "src" / "app" / "fiberfluid"
    out.mkdir(parents=True, exist_ok=True)
    print(f"{'case':24} {'solver':15} {'est. memory':>12} {'peak RSS':>10} {'ratio':>6}"
          f" {'est. time':>10} {'wall time':>10} {'ratio':>6}")
    for label, config in CASES:
        if isinstance(config, str):  # an experiment of the repository
            path = root / "experiments" / (config + ".json")
        else:
            path = out / (config["name"] + ".json")
            path.write_text(json.dumps(config))
        folder = out / path.stem
        start = time.monotonic()
        done = subprocess.run([str(binary), "run", str(path), "-q", "-o", str(folder)],
                              capture_output=True, text=True)
        wall = time.monotonic() - start
        if done.returncode != 0:
            print(f"{label:24} failed: {done.stderr.strip()[-200:]}")
            continue
        summary = json.loads((folder / "summary.json").read_text())
        estimate = summary["runs"][0]["estimate"]
        peak = summary["peak_resident_bytes"]
        print(f"{label:24} {estimate['solver']:15} {gib(estimate['peak_bytes']):>12} {gib(peak):>10}"
              f" {estimate['peak_bytes'] / peak:6.2f} {estimate['seconds']:9.2f}s {wall:9.2f}s"
              f" {estimate['seconds'] / wall:6.2f}")


if __name__ == "__main__":
    main()

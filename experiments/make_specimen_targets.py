#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-3.0-or-later
"""Makes the synthetic measurements of the real-specimen experiments (issue 42, data/targets/).

Runs experiments/compression_cylinder.json (the silicone cylinder pressed 20 mm between
platens, Y = 100 kPa) and writes its frictionless variant's upper platen force against travel as
a test machine would log it, with Gaussian noise of 0.2 N:
  compression_force.csv             all 40 rows (travel in mm, downwards; push in N)
  compression_force_first_half.csv  the rows up to 10 mm: what experiments/fit_compression_half.json
                                    fits, the rest being what its prediction is checked against
and runs experiments/bending_phantom.json (Y = 100 kPa, gamma = 0.001 N/m) for a scan of its
final surface, as make_synthetic_targets.py makes its scans (every triangle split in four,
vertices shuffled, Gaussian noise of 0.5 mm per coordinate):
  phantom_step10_scan.obj           what experiments/fit_bending_phantom.json fits
and the same for experiments/bending_phantom_gripped.json (no mirror layer, gripped 6 mm):
  phantom_gripped_step10_scan.obj   what experiments/fit_bending_phantom_gripped.json fits
Usage: /usr/bin/python3 experiments/make_specimen_targets.py [FIBERFLUID [TARGET ...]]
TARGET: compression, phantom, phantom_gripped (default all; each keeps its own noise seed, so
remaking one leaves the others as they were).
"""
import os
import subprocess
import sys
import tempfile

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from make_synthetic_targets import read_vtu, resampled_scan, write_obj  # noqa: E402

ROOT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..")
FORCE_NOISE = 0.2  # N
SEED = 20261127


def read_steps(path):
    with open(path) as f:
        header = f.readline().strip().split(",")
        return [dict(zip(header, line.strip().split(","))) for line in f if line.strip()]


def make_compression(binary, out_dir):
    rng = np.random.default_rng(SEED)
    with tempfile.TemporaryDirectory() as tmp:
        subprocess.run([binary, "run", os.path.join(ROOT, "experiments/compression_cylinder.json"),
                        "-o", os.path.join(tmp, "c"), "-q"], check=True, stdout=subprocess.DEVNULL)
        rows = read_steps(os.path.join(tmp, "c", "frictionless", "steps.csv"))
    lines = ["%s,%.6f,%.4f\n" % (r["step"], -1e3 * float(r["paddle_upper_travel_m"]),
                                 -float(r["paddle_upper_force_x_N"]) + rng.normal(0.0, FORCE_NOISE))
             for r in rows]
    comment = ("# experiments/compression_cylinder.json, frictionless platens: the upper platen's "
               f"travel (mm, downwards) and its push on the cylinder (N), Gaussian noise {FORCE_NOISE} N")
    with open(os.path.join(out_dir, "compression_force.csv"), "w") as f:
        f.write(comment + ", per load step\nstep,travel,force\n" + "".join(lines))
    with open(os.path.join(out_dir, "compression_force_first_half.csv"), "w") as f:
        f.write(comment + ", the first 20 steps (to 10 mm)\nstep,travel,force\n" +
                "".join(lines[:len(lines) // 2]))


def make_scan(binary, out_dir, experiment, target, seed):
    with tempfile.TemporaryDirectory() as tmp:
        subprocess.run([binary, "run", os.path.join(ROOT, "experiments", experiment),
                        "-o", os.path.join(tmp, "p"), "-q"], check=True, stdout=subprocess.DEVNULL)
        points, triangles = read_vtu(os.path.join(tmp, "p", "vtk", "step_0010.vtu"))
    scan, faces = resampled_scan(points, triangles, np.random.default_rng(seed))
    write_obj(os.path.join(out_dir, target), scan, faces,
              f"experiments/{experiment} at load step 10: resampled (midpoint subdivision, "
              "shuffled), Gaussian noise 0.5 mm per coordinate")


def main():
    binary = sys.argv[1] if len(sys.argv) > 1 else os.path.join(ROOT, "build-release/src/app/fiberfluid")
    wanted = set(sys.argv[2:]) or {"compression", "phantom", "phantom_gripped"}
    out_dir = os.path.join(ROOT, "data", "targets")
    if "compression" in wanted:
        make_compression(binary, out_dir)
    if "phantom" in wanted:
        make_scan(binary, out_dir, "bending_phantom.json", "phantom_step10_scan.obj", SEED + 1)
    if "phantom_gripped" in wanted:
        make_scan(binary, out_dir, "bending_phantom_gripped.json",
                  "phantom_gripped_step10_scan.obj", SEED + 2)
    print("targets in", out_dir)


if __name__ == "__main__":
    main()

#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-3.0-or-later
"""The treecode product's effect on a whole run (issue 12): the sphere
experiment (gravity, 10 load steps, pcg) with the exact bulk product and with
the treecode at several tolerances, and the final displacements' difference.
Prints a Markdown table.

    python3 experiments/scaling/treecode_displacements.py BUILD_DIR \
        [--subdivisions 4,5,6] [--tolerances 1e-3,1e-4,1e-6]
"""
import argparse
import json
import math
import os
import struct
import subprocess
import tempfile


def run(binary, subdivisions, tolerance, save):
    command = [binary, "--subdivisions", str(subdivisions), "--solver", "pcg", "--save", save]
    if tolerance:
        command += ["--treecode", str(tolerance)]
    out = subprocess.run(command, capture_output=True, text=True, check=True)
    return json.loads(out.stdout.strip().splitlines()[-1])


def load(path):
    data = open(path, "rb").read()
    return struct.unpack("%dd" % (len(data) // 8), data)


def displacement_difference(approximate, exact, n):
    """max_i |du_i| / max_i |u_i| over the vertices, and the relative 2-norm."""
    largest_difference = largest = squared_difference = squared = 0.0
    for i in range(n):
        du = math.sqrt(sum((approximate[k * n + i] - exact[k * n + i]) ** 2 for k in range(3)))
        u = math.sqrt(sum(exact[k * n + i] ** 2 for k in range(3)))
        largest_difference, largest = max(largest_difference, du), max(largest, u)
        squared_difference += du * du
        squared += u * u
    return largest_difference / largest, math.sqrt(squared_difference / squared)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("build")
    parser.add_argument("--subdivisions", default="4,5,6")
    parser.add_argument("--tolerances", default="1e-3,1e-4,1e-6")
    args = parser.parse_args()
    binary = os.path.join(args.build, "experiments", "scaling", "fiberfluid_scaling")
    print("| vertices | tolerance | max |du| / max |u| | relative 2-norm | pressure difference "
          "| pcg iterations (exact) | run s | exact run s |")
    print("|---|---|---|---|---|---|---|---|")
    with tempfile.TemporaryDirectory() as scratch:
        for subdivisions in (int(s) for s in args.subdivisions.split(",")):
            exact_file = os.path.join(scratch, "exact.bin")
            exact = run(binary, subdivisions, None, exact_file)
            u_exact = load(exact_file)
            n = exact["vertices"]
            for tolerance in (float(t) for t in args.tolerances.split(",")):
                file = os.path.join(scratch, "treecode.bin")
                approximate = run(binary, subdivisions, tolerance, file)
                u = load(file)
                worst, relative = displacement_difference(u, u_exact, n)
                pressure = abs(u[-1] - u_exact[-1]) / abs(u_exact[-1])
                print(f"| {n} | {tolerance:g} | {worst:.2e} | {relative:.2e} | {pressure:.2e} "
                      f"| {approximate['pcg_iterations']} ({exact['pcg_iterations']}) "
                      f"| {approximate['run_s']:.2f} | {exact['run_s']:.2f} |", flush=True)


if __name__ == "__main__":
    main()

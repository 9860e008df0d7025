#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-3.0-or-later
"""Makes the synthetic scans of fit_synthetic_liver and fit_remeshed_liver (data/targets/).

Runs experiments/fit_synthetic_liver_truth.json (known parameters), takes its
deformed surfaces at load steps 4, 7 and 10, and writes for each:
  liver_step{K}_exact.obj      the same mesh, exact (17 digits): a same-mesh, noise-free target
  liver_step{K}_scan.obj       a different mesh with no vertex correspondence: every
                               triangle split in four at its edge midpoints (so the
                               surface is the same), the vertices shuffled, and
                               Gaussian noise of 0.5 mm (standard deviation per
                               coordinate) added, as a scanner would.
It also runs fit_remeshed_liver_truth.json (the same liver on a finer mesh) and
writes its deformed surfaces (liver_fine_step{K}.obj) and its upper paddle's
force curve (liver_fine_force.csv); and fit_paddles_liver_truth.json (the
liver between paddles alone) for a scan of its last step
(liver_paddles_step10_scan.obj, resampled with 0.5 mm noise as above) and its
upper paddle's force curve with 0.1 N of noise (liver_paddles_force.csv, travel
in mm).
Usage: /usr/bin/python3 experiments/make_synthetic_targets.py [build-release/src/app/fiberfluid]
"""
import os
import re
import subprocess
import sys
import tempfile

import numpy as np

ROOT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..")
NOISE = 0.5e-3  # m
SEED = 20161122
PADDLES_SEED = 20261126  # its own stream: the older targets keep theirs
FORCE_NOISE = 0.1  # N


def read_vtu(path):
    """Points (deformed positions) and triangles of a fiberfluid .vtu."""
    text = open(path).read()
    arrays = re.findall(r"<DataArray([^>]*)>(.*?)</DataArray>", text, re.S)
    points = triangles = None
    for header, body in arrays:
        values = body.split()
        if "Name=" not in header and 'NumberOfComponents="3"' in header:
            points = np.array(values, float).reshape(-1, 3)
        if 'Name="connectivity"' in header:
            triangles = np.array(values, int).reshape(-1, 3)
    return points, triangles


def write_obj(path, vertices, faces, comment):
    with open(path, "w") as f:
        f.write(f"# {comment}\n")
        for v in vertices:
            f.write("v %.17g %.17g %.17g\n" % tuple(v))
        for t in faces:
            f.write("f %d %d %d\n" % tuple(t + 1))


def subdivide(vertices, faces):
    """Each triangle into four at its edge midpoints; unused vertices dropped."""
    used = np.unique(faces)
    index = {v: k for k, v in enumerate(used)}
    out = [vertices[v] for v in used]
    midpoint = {}

    def middle(a, b):
        key = (min(a, b), max(a, b))
        if key not in midpoint:
            midpoint[key] = len(out)
            out.append(0.5 * (vertices[a] + vertices[b]))
        return midpoint[key]

    new_faces = []
    for a, b, c in faces:
        ab, bc, ca = middle(a, b), middle(b, c), middle(c, a)
        A, B, C = index[a], index[b], index[c]
        new_faces += [[A, ab, ca], [ab, B, bc], [ca, bc, C], [ab, bc, ca]]
    return np.array(out), np.array(new_faces)


def resampled_scan(points, triangles, rng):
    """A scan of a surface: every triangle split in four at its edge midpoints (the same
    surface), the vertices shuffled (no correspondence) and Gaussian noise added."""
    fine, fine_faces = subdivide(points, triangles)
    order = rng.permutation(len(fine))
    inverse = np.empty_like(order)
    inverse[order] = np.arange(len(order))
    return fine[order] + rng.normal(0.0, NOISE, fine.shape), inverse[fine_faces]


def read_steps(folder):
    """steps.csv of a run: one dict per load step."""
    with open(os.path.join(folder, "steps.csv")) as f:
        header = f.readline().strip().split(",")
        return [dict(zip(header, l.strip().split(","))) for l in f if l.strip()]


def main():
    binary = sys.argv[1] if len(sys.argv) > 1 else os.path.join(ROOT, "build-release/src/app/fiberfluid")
    truth = os.path.join(ROOT, "experiments/fit_synthetic_liver_truth.json")
    out_dir = os.path.join(ROOT, "data/targets")
    os.makedirs(out_dir, exist_ok=True)
    rng = np.random.default_rng(SEED)
    with tempfile.TemporaryDirectory() as tmp:
        subprocess.run([binary, "run", truth, "-o", os.path.join(tmp, "truth"), "-q"], check=True,
                       stdout=subprocess.DEVNULL)
        for step in (4, 7, 10):
            points, triangles = read_vtu(os.path.join(tmp, "truth", "vtk", "step_%04d.vtu" % step))
            if step == 10:  # the .vtu's 12 digits: take the exact final.obj instead
                final = [l.split()[1:] for l in open(os.path.join(tmp, "truth", "final.obj"))
                         if l.startswith("v ")]
                exact = np.array(final, float)
                assert np.abs(exact - points).max() < 1e-9
                points = exact
            write_obj(os.path.join(out_dir, f"liver_step{step}_exact.obj"), points, triangles,
                      f"fit_synthetic_liver_truth.json at load step {step}: same mesh, exact")
            scan, scan_faces = resampled_scan(points, triangles, rng)
            write_obj(os.path.join(out_dir, f"liver_step{step}_scan.obj"), scan, scan_faces,
                      f"fit_synthetic_liver_truth.json at load step {step}: resampled (midpoint "
                      f"subdivision, shuffled), Gaussian noise {NOISE * 1e3} mm per coordinate")
        # The same liver on a finer mesh, and its own deformed surfaces.
        lines = open(os.path.join(ROOT, "data/meshes/liver.obj")).read().split("\n")
        rest = np.array([l.split()[1:4] for l in lines if l.startswith("v ")], float)
        faces = np.array([[int(w.split("/")[0]) - 1 for w in l.split()[1:4]]
                          for l in lines if l.startswith("f ")])
        fine, fine_faces = subdivide(rest, faces)
        write_obj(os.path.join(out_dir, "liver_fine.obj"), fine, fine_faces,
                  "data/meshes/liver.obj (SOFA, LGPL-2.1-or-later) with every triangle split in four")
        fine_truth = os.path.join(ROOT, "experiments/fit_remeshed_liver_truth.json")
        subprocess.run([binary, "run", fine_truth, "-o", os.path.join(tmp, "fine"), "-q"], check=True,
                       stdout=subprocess.DEVNULL)
        for step in (4, 7, 10):
            points, triangles = read_vtu(os.path.join(tmp, "fine", "vtk", "step_%04d.vtu" % step))
            write_obj(os.path.join(out_dir, f"liver_fine_step{step}.obj"), points, triangles,
                      f"fit_remeshed_liver_truth.json at load step {step} (the finer liver): exact")
        # Its upper paddle's force curve: the distance travelled and the push on the liver.
        rows = read_steps(os.path.join(tmp, "fine"))
        with open(os.path.join(out_dir, "liver_fine_force.csv"), "w") as f:
            f.write("# fit_remeshed_liver_truth.json (the finer liver): the upper paddle's travel "
                    "(m, downwards) and its push on the liver (N), per load step: exact\n")
            f.write("step,travel,force\n")
            for r in rows:
                f.write("%s,%.17g,%.17g\n" % (r["step"], -float(r["paddle_upper_travel_m"]),
                                             -float(r["paddle_upper_force_y_N"])))
        # The liver between paddles alone: a scan of its last step and a noisy force curve.
        paddles = np.random.default_rng(PADDLES_SEED)
        subprocess.run([binary, "run", os.path.join(ROOT, "experiments/fit_paddles_liver_truth.json"),
                        "-o", os.path.join(tmp, "paddles"), "-q"], check=True, stdout=subprocess.DEVNULL)
        points, triangles = read_vtu(os.path.join(tmp, "paddles", "vtk", "step_0010.vtu"))
        scan, scan_faces = resampled_scan(points, triangles, paddles)
        write_obj(os.path.join(out_dir, "liver_paddles_step10_scan.obj"), scan, scan_faces,
                  "fit_paddles_liver_truth.json at load step 10: resampled (midpoint subdivision, "
                  f"shuffled), Gaussian noise {NOISE * 1e3} mm per coordinate")
        rows = read_steps(os.path.join(tmp, "paddles"))
        with open(os.path.join(out_dir, "liver_paddles_force.csv"), "w") as f:
            f.write("# fit_paddles_liver_truth.json: the upper paddle's travel (mm, downwards) and "
                    f"its push on the liver (N) with Gaussian noise of {FORCE_NOISE} N, per load step\n")
            f.write("step,travel,force\n")
            for r in rows:
                push = -float(r["paddle_upper_force_y_N"]) + paddles.normal(0.0, FORCE_NOISE)
                f.write("%s,%.6f,%.4f\n" % (r["step"], -1e3 * float(r["paddle_upper_travel_m"]), push))
        subprocess.run([binary, "run", os.path.join(ROOT, "experiments/sphere.json"), "-o",
                        os.path.join(tmp, "sphere"), "-q"], check=True, stdout=subprocess.DEVNULL)
        with open(os.path.join(tmp, "sphere", "final.obj")) as f:
            body = f.read()
        with open(os.path.join(out_dir, "sphere_final.obj"), "w") as f:
            f.write("# experiments/sphere.json (the paper's sphere) after its 10 steps: exact\n" + body)
    print("targets in", out_dir)


if __name__ == "__main__":
    main()

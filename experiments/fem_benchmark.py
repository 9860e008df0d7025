#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-3.0-or-later
"""The accuracy benchmarks' performance (issue 10): wall time per simulated
second of each solver on each scene, at the default mesh and at a mesh 4x finer
per axis, with CHOLMOD and with the paper's Gauss-Seidel; the fiber model's run
on the same scenes; and the time CGAL Mesh_3 takes to fill the liver and the
bunny with tetrahedra. Prints markdown tables.
Usage: /usr/bin/python3 experiments/fem_benchmark.py BUILD_DIR   (a Release build)
"""
import json
import os
import subprocess
import sys
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))
SOLVERS = ["explicit", "explicit-lumped", "implicit-lumped", "quasi-static"]
# The fiber model with the Y and gamma the benchmark experiments fitted
# (benchmark_block_mp1.json and benchmark_rod.json), so that no fit is timed.
SCENES = [
    ("block-needle MP1", "benchmark_block_mp1.json", [8, 8], {"Y": 200, "gamma": 3.555}),
    ("bending-rod MP3", "benchmark_rod.json", [4, 2, 2], {"Y": 0.007, "gamma": 44.19, "scheme": "newton", "steps": 5}),
]


def run(cli, document, folder):
    path = os.path.join(folder, "experiment.json")
    json.dump(document, open(path, "w"))
    out = os.path.join(folder, "out")
    subprocess.run([cli, "run", path, "-o", out, "-q"], check=True, stdout=subprocess.DEVNULL)
    return json.load(open(os.path.join(out, "benchmark.json"))), json.load(open(os.path.join(out, "summary.json")))


def scenes(cli, folder):
    print("| scene | mesh | nodes | linear solver | solver | s per simulated s | note |")
    print("|---|---|---|---|---|---|---|")
    for name, experiment, cells, fiber in SCENES:
        base = json.load(open(os.path.join(HERE, experiment)))
        base.pop("expected", None)
        base.pop("compare_materials", None)
        base["solvers"] = SOLVERS
        for factor in (1, 4):
            for linear in ("cholesky", "gauss-seidel"):
                doc = dict(base)
                doc["mesh"] = dict(base.get("mesh", {}), cells=[c * factor for c in cells])
                doc["linear_solver"] = {"method": linear, "tolerance": 1e-10}
                doc["fiber_model"] = fiber
                info, _ = run(cli, doc, folder)
                duration = info["time"]["duration"]
                mesh = "x".join(str(c * factor) for c in cells)
                rows = [("implicit-newmark (reference)", info["reference"]["seconds"], "", info["reference"]["gauss_seidel_sweeps"])]
                rows += [(s["label"], s["seconds"], "" if s["ok"] else "diverged: " + s["message"], s["gauss_seidel_sweeps"]) for s in info["series"]]
                for label, seconds, note, sweeps in rows:
                    if label == "fiber-model" and linear != "cholesky":
                        continue  # the fiber model has its own solver
                    if sweeps:
                        note = (note + "; " if note else "") + f"{sweeps} sweeps"
                    print(f"| {name} | {mesh} | {info['mesh']['nodes']} | {linear if label != 'fiber-model' else '-'} | "
                          f"{label} | {seconds / duration:.3g} | {note} |")
                sys.stdout.flush()


def mesher(cli, folder):
    print()
    print("| surface | vertices | tetrahedra | nodes | Mesh_3 s | FEM solve s | rest E_s |")
    print("|---|---|---|---|---|---|---|")
    # The set-ups of liver_gravity.json and bunny_gravity.json with a FEM
    # reference (the bunny's pruning takes most of its run, outside these times).
    for name, experiment, size in [("liver (SOFA), 26 cm, edge 1.5 cm", "liver_gravity.json", 0.015),
                                   ("liver, edge 0.75 cm", "liver_gravity.json", 0.0075),
                                   ("bunny (Stanford), 8 cm, edge 0.5 cm", "bunny_gravity.json", 0.005),
                                   ("bunny, edge 0.25 cm", "bunny_gravity.json", 0.0025)]:
        doc = json.load(open(os.path.join(HERE, experiment)))
        doc.pop("expected", None)
        doc["surface"]["file"] = os.path.join(HERE, doc["surface"]["file"])
        doc["output"] = {"vtk": False, "obj": False}
        doc.setdefault("fibers", {})["write"] = "none"
        doc["fem_reference"] = {"E": 100000, "nu": 0.45, "size": size}
        path = os.path.join(folder, "mesher.json")
        json.dump(doc, open(path, "w"))
        out = os.path.join(folder, "mesher_out")
        subprocess.run([cli, "run", path, "-o", out, "-q"], check=True, stdout=subprocess.DEVNULL)
        summary = json.load(open(os.path.join(out, "summary.json")))
        f = summary["figures"]
        print(f"| {name} | {summary['surface']['used_vertices']} | {int(f['fem_reference.tetrahedra'])} | "
              f"{int(f['fem_reference.nodes'])} | {f['fem_reference.mesh_seconds']:.2f} | "
              f"{f['fem_reference.solve_seconds']:.2f} | {f.get('fem_reference.rest_surface_error', float('nan')):.4f} |")
        sys.stdout.flush()


def main():
    if len(sys.argv) != 2:
        sys.exit(__doc__)
    cli = os.path.join(sys.argv[1], "src", "app", "fiberfluid")
    with tempfile.TemporaryDirectory() as folder:
        scenes(cli, folder)
        mesher(cli, folder)


if __name__ == "__main__":
    main()

#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-3.0-or-later
"""Drives fiberfluid from Python: a sweep over Young's modulus of the liver,
built as a dict, run in parallel, and the largest displacement against Y.

    PYTHONPATH=build-release/src/python /usr/bin/python3 experiments/python_sweep.py [out.png]
"""
import json
import os
import sys

import fiberfluid

HERE = os.path.dirname(os.path.abspath(__file__))

with open(os.path.join(HERE, "liver_gravity.json")) as f:
    document = json.load(f)
document["name"] = "liver_python_sweep"
document["expected"] = []
moduli = [5e3, 1e4, 2e4, 4e4, 8e4, 1.6e5]
document["variants"] = [{"name": f"Y{y:g}", "material": {"Y": y}} for y in moduli]

result = fiberfluid.Experiment.from_dict(document, folder=HERE).run()
if not result["success"]:
    sys.exit("\n".join(run["message"] for run in result["runs"] if not run["success"]))

print("Y [Pa]      largest |u| [m]   support reaction y [N]")
for y, run in zip(moduli, result["runs"]):
    reaction = run["steps"]["reactions"]["support_0"][-1]
    print(f"{y:<11g} {run['figures']['max_displacement']:<17.6g} {reaction[1]:.6g}")

if len(sys.argv) > 1:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(5, 4))
    ax.loglog(moduli, [run["figures"]["max_displacement"] for run in result["runs"]], "o-")
    ax.set_xlabel("Young's modulus Y [Pa]")
    ax.set_ylabel("largest displacement |u| [m]")
    ax.grid(True, which="both", alpha=0.3)
    ax.set_title("liver under gravity")
    fig.tight_layout()
    fig.savefig(sys.argv[1], dpi=110)
    print("plot:", sys.argv[1])

#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-3.0-or-later
"""Scaling benchmark (issue 3): the sphere experiment on icospheres of 162 to
40962 vertices, every backend where it fits, one process per case. Prints a
table, writes scaling.csv and scaling.png (time against N, log-log) into the
output folder, and checks every backend's answer against dense-lu's.

    python3 experiments/scaling/run.py BUILD_DIR OUT_DIR [--max-subdivisions 6]
"""
import argparse
import csv
import json
import os
import subprocess
import sys

import numpy as np

BACKENDS = ["dense-lu", "block-cholesky", "cholmod", "pcg"]
# The largest subdivision level each backend runs at (memory and time on a
# 2-core, 24 GiB machine): dense-lu at 10242 needs 15 GiB and an hour.
LIMITS = {"dense-lu": 4, "block-cholesky": 5, "cholmod": 5, "pcg": 6}


def run_case(binary, subdivisions, backend, save):
    out = subprocess.run([binary, "--subdivisions", str(subdivisions), "--solver", backend,
                          "--save", save], capture_output=True, text=True)
    lines = [l for l in out.stdout.splitlines() if l.startswith("{")]
    if not lines:
        return {"vertices": 10 * 4 ** subdivisions + 2, "solver": backend, "success": False,
                "message": out.stderr.strip()[-300:]}
    return json.loads(lines[-1])


def main():
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("build")
    parser.add_argument("out")
    parser.add_argument("--max-subdivisions", type=int, default=6)
    args = parser.parse_args()
    binary = os.path.join(args.build, "experiments", "scaling", "fiberfluid_scaling")
    os.makedirs(args.out, exist_ok=True)

    peak = json.loads(subprocess.run([binary, "--gemm-peak"], capture_output=True,
                                     text=True).stdout)["gemm_gflops"]
    rows = []
    for s in range(2, args.max_subdivisions + 1):
        reference, row_reference = None, ""
        for backend in BACKENDS:
            if s > LIMITS[backend]:
                continue
            save = os.path.join(args.out, f"u_{s}_{backend}.bin")
            row = run_case(binary, s, backend, save)
            if row["success"]:
                u = np.fromfile(save, dtype=np.float64)
                # The reference answer: dense-lu's, or block-cholesky's where
                # dense-lu does not fit.
                if reference is None and backend in ("dense-lu", "block-cholesky"):
                    reference, row_reference = u, backend
                # Displacements only (the last unknown is P).
                row["difference_vs_reference"] = (
                    float(np.linalg.norm(u[:-1] - reference[:-1]) / np.linalg.norm(reference[:-1]))
                    if reference is not None else float("nan"))
                row["reference"] = row_reference if reference is not None else ""
                os.remove(save)
            rows.append(row)
            print(f"  {row['vertices']:6d} {backend:15s} "
                  + (f"run {row['run_s']:9.3f} s" if row["success"] else row["message"]),
                  file=sys.stderr, flush=True)

    dense = {r["vertices"]: r["run_s"] for r in rows if r["solver"] == "dense-lu" and r["success"]}
    for r in rows:
        r["speedup_vs_dense_lu"] = (dense[r["vertices"]] / r["run_s"]
                                    if r["success"] and r["vertices"] in dense else float("nan"))
        r["gemm_peak_gflops"] = peak

    fields = ["vertices", "solver", "success", "assemble_s", "factorize_s", "solve_s", "run_s",
              "slowest_step_s", "peak_mib", "factorization_gflops", "gemm_peak_gflops",
              "pcg_iterations", "speedup_vs_dense_lu", "difference_vs_reference", "reference",
              "max_displacement", "message"]
    with open(os.path.join(args.out, "scaling.csv"), "w", newline="") as f:
        writer = csv.DictWriter(f, fieldnames=fields, extrasaction="ignore")
        writer.writeheader()
        writer.writerows(rows)

    print(f"dgemm peak of this machine: {peak:.1f} GFLOP/s")
    print("| N | backend | assemble s | factorize s | solve s | 10-step run s | slowest step s "
          "| peak MiB | factor GFLOP/s | pcg its | speed-up vs dense-lu | rel. diff (reference) |")
    print("|---|---|---|---|---|---|---|---|---|---|---|---|")
    for r in rows:
        if not r["success"]:
            print(f"| {r['vertices']} | {r['solver']} | failed: {r['message']} |")
            continue
        gf = f"{r['factorization_gflops']:.1f}" if r["factorization_gflops"] > 0 else ""
        print(f"| {r['vertices']} | {r['solver']} | {r['assemble_s']:.3f} | {r['factorize_s']:.3f} "
              f"| {r['solve_s']:.3f} | {r['run_s']:.3f} | {r['slowest_step_s']:.3f} "
              f"| {r['peak_mib']:.0f} | {gf} | {r['pcg_iterations'] or ''} "
              f"| {r['speedup_vs_dense_lu']:.1f} | {r['difference_vs_reference']:.1e} "
              f"({r.get('reference', '')}) |")

    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(7, 5))
    for backend in BACKENDS:
        pts = [(r["vertices"], r["run_s"]) for r in rows if r["solver"] == backend and r["success"]]
        if pts:
            ax.loglog(*zip(*pts), marker="o", label=backend)
    ax.set_xlabel("vertices N")
    ax.set_ylabel("10-step run (s)")
    ax.set_title("sphere experiment, this machine (2 cores)")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend()
    fig.tight_layout()
    fig.savefig(os.path.join(args.out, "scaling.png"), dpi=110)


if __name__ == "__main__":
    main()

#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-3.0-or-later
"""Old against new, on the same machine in one run (issue 12): the pair
kernels (fiberfluid_kernels) and whole runs of the sphere experiment
(fiberfluid_scaling) from two Release builds, alternating old and new so that
both see the same machine, the best of --repeat kept. Prints markdown tables.

    python3 experiments/scaling/compare.py OLD_BUILD NEW_BUILD [--subdivisions 5]
        [--runs dense-lu:4,block-cholesky:4,pcg:6] [--repeat 2]

An old build: git worktree add /tmp/old REV && cmake -S /tmp/old -B /tmp/old/build-release
-DCMAKE_BUILD_TYPE=Release -DFIBERFLUID_BUILD_TESTS=OFF && cmake --build /tmp/old/build-release
--target fiberfluid_kernels fiberfluid_scaling
"""
import argparse
import json
import os
import subprocess


def kernels(build, subdivisions):
    binary = os.path.join(build, "experiments/scaling/fiberfluid_kernels")
    out = subprocess.run([binary, "--subdivisions", str(subdivisions), "--repeat", "3"],
                         capture_output=True, text=True, check=True)
    rows = [json.loads(l) for l in out.stderr.splitlines() if l.startswith("{")]
    return {r["kernel"]: r for r in rows}


def whole_run(build, subdivisions, solver):
    binary = os.path.join(build, "experiments/scaling/fiberfluid_scaling")
    out = subprocess.run([binary, "--subdivisions", str(subdivisions), "--solver", solver,
                          "--save", "/tmp/fiberfluid_compare.bin"],
                         capture_output=True, text=True)
    lines = [l for l in out.stdout.splitlines() if l.startswith("{")]
    return json.loads(lines[-1]) if lines else None


def best(a, b, key):
    if a is None:
        return b
    return a if a[key] <= b[key] else b


def main():
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("old")
    parser.add_argument("new")
    parser.add_argument("--subdivisions", type=int, default=5)
    parser.add_argument("--runs", default="dense-lu:4,block-cholesky:4")
    parser.add_argument("--repeat", type=int, default=2)
    args = parser.parse_args()

    found = {"old": {}, "new": {}}
    for _ in range(args.repeat):
        for label, build in (("old", args.old), ("new", args.new)):
            for name, row in kernels(build, args.subdivisions).items():
                found[label][name] = best(found[label].get(name), row, "seconds")
    new_rows = found["new"]
    peak = max(r["gemm_peak_gflops"] for r in list(new_rows.values()) + list(found["old"].values()))
    print(f"pair kernels, {args.subdivisions} subdivisions, dgemm peak of this run {peak:.1f} GFLOP/s\n")
    print("| kernel | old s | new s | speed-up | new nominal GFLOP/s (% peak) | new executed GFLOP/s (% peak) |")
    print("|---|---|---|---|---|---|")
    for name, new in new_rows.items():
        old = found["old"].get(name)
        old_s = f"{old['seconds']:.4f}" if old else "-"
        ratio = f"{old['seconds'] / new['seconds']:.1f}x" if old else "-"
        nominal = new.get("nominal_gflops", new.get("gflops", 0.0))
        executed = new.get("executed_gflops", nominal)
        print(f"| {name} | {old_s} | {new['seconds']:.4f} | {ratio} | {nominal:.1f} ({100 * nominal / peak:.0f}%) "
              f"| {executed:.1f} ({100 * executed / peak:.0f}%) |")

    runs = {}
    for spec in filter(None, args.runs.split(",")):
        solver, level = spec.split(":")
        for _ in range(args.repeat):
            for label, build in (("old", args.old), ("new", args.new)):
                r = whole_run(build, int(level), solver)
                if r and r.get("success"):
                    runs[(label, spec)] = best(runs.get((label, spec)), r, "run_s")
    if runs:
        print("\n| run | vertices | old run s | new run s | old factorise s | new factorise s "
              "| old solves s | new solves s | old slowest step s | new slowest step s |")
        print("|---|---|---|---|---|---|---|---|---|---|")
        for spec in filter(None, args.runs.split(",")):
            o, n = runs.get(("old", spec)), runs.get(("new", spec))
            if not o or not n:
                continue
            print(f"| {spec} | {n['vertices']} | {o['run_s']:.3f} | {n['run_s']:.3f} | {o['factorize_s']:.3f} "
                  f"| {n['factorize_s']:.3f} | {o['solve_s']:.3f} | {n['solve_s']:.3f} "
                  f"| {o['slowest_step_s']:.3f} | {n['slowest_step_s']:.3f} |")
        for label in ("old", "new"):
            lu, bc = runs.get((label, "dense-lu:4")), runs.get((label, "block-cholesky:4"))
            if lu and bc:
                print(f"\n{label}: block-cholesky against dense-lu, 2,562 vertices, whole run "
                      f"{lu['run_s'] / bc['run_s']:.1f}x, factorisation {lu['factorize_s'] / bc['factorize_s']:.1f}x")


if __name__ == "__main__":
    main()

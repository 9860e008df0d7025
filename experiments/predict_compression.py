#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-3.0-or-later
"""The fitted law's prediction for the rest of a compression test (issue 42, README's walk-through).

Reads the law fitted by `fiberfluid fit experiments/fit_compression_half.json -o FIT` (FIT/fit.json:
Y0 and beta of an exponential law, fitted to the platen force up to 10 mm), runs the same
cylinder with it over the whole test (experiments/compression_cylinder.json's frictionless
platens, 20 mm in 40 steps), and sets the simulated force beside the whole measurement
(data/targets/compression_force.csv). Writes OUT/prediction.csv (travel, measured, simulated)
and OUT/prediction.png (measured against predicted force, the fitted half shaded), and prints
the misfit of the fitted half and of the predicted one.

    /usr/bin/python3 experiments/predict_compression.py FIT OUT [--fiberfluid build-release/src/app/fiberfluid]
"""
import argparse
import json
import os
import subprocess
import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent


def read_csv(path):
    with open(path) as f:
        lines = [line.strip() for line in f if line.strip() and not line.startswith("#")]
    header = lines[0].split(",")
    return [dict(zip(header, line.split(","))) for line in lines[1:]]


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("fit", help="the fit's output folder (with fit.json)")
    parser.add_argument("out", help="folder for the prediction")
    parser.add_argument("--fiberfluid", default=str(ROOT / "build-release/src/app/fiberfluid"))
    args = parser.parse_args()
    fitted = {p["name"]: p["value"] for p in json.loads((Path(args.fit) / "fit.json").read_text())["parameters"]}
    experiment = json.loads((HERE / "compression_cylinder.json").read_text())
    for key in ("variants", "expected", "description"):
        experiment.pop(key, None)
    experiment["name"] = "predict_compression"
    experiment["material"] = {"law": {"type": "exponential", "Y0": fitted["Y0"], "beta": fitted["beta"]},
                              "gamma": experiment["material"]["gamma"]}
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    (out / "experiment.json").write_text(json.dumps(experiment, indent=1))
    run = out / "run"
    subprocess.run([args.fiberfluid, "run", str(out / "experiment.json"), "-o", str(run), "-q"],
                   check=True, stdout=subprocess.DEVNULL)
    simulated = {int(r["step"]): -float(r["paddle_upper_force_x_N"]) for r in read_csv(run / "steps.csv")}
    measured = read_csv(ROOT / "data/targets/compression_force.csv")
    fitted_rows = len(read_csv(ROOT / "data/targets/compression_force_first_half.csv"))
    rows = [(float(m["travel"]), float(m["force"]), simulated[int(m["step"])]) for m in measured]
    with open(out / "prediction.csv", "w") as f:
        f.write("travel_mm,measured_N,simulated_N,fitted\n")
        for k, (travel, force, model) in enumerate(rows):
            f.write(f"{travel:.6f},{force:.4f},{model:.6f},{int(k < fitted_rows)}\n")

    def rms(part):
        return (sum((m - s) ** 2 for _, m, s in part) / len(part)) ** 0.5
    print(f"fitted law: Y0 = {fitted['Y0']:.6g} Pa, beta = {fitted['beta']:.4g}")
    print(f"fitted half (to {rows[fitted_rows - 1][0]:g} mm): rms misfit {rms(rows[:fitted_rows]):.3f} N "
          f"of forces up to {max(m for _, m, _ in rows[:fitted_rows]):.1f} N")
    print(f"predicted half (to {rows[-1][0]:g} mm): rms misfit {rms(rows[fitted_rows:]):.3f} N "
          f"of forces up to {max(m for _, m, _ in rows):.1f} N; at the end measured "
          f"{rows[-1][1]:.1f} N, predicted {rows[-1][2]:.1f} N")
    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        print("no matplotlib: prediction.png not drawn", file=sys.stderr)
        return
    fig, ax = plt.subplots(figsize=(6.4, 4.4))
    ax.axvspan(0, rows[fitted_rows - 1][0], color="0.92", label="fitted")
    ax.plot([r[0] for r in rows], [r[1] for r in rows], "o", ms=3.5, color="k", label="measured")
    ax.plot([r[0] for r in rows], [r[2] for r in rows], "-", color="tab:red",
            label=f"predicted: Y0 = {fitted['Y0'] / 1e3:.1f} kPa, beta = {fitted['beta']:.2f}")
    ax.set_xlabel("platen travel (mm)")
    ax.set_ylabel("platen force (N)")
    ax.set_title("Silicone cylinder, 50 x 30 mm: law fitted to the first half")
    ax.legend(loc="upper left")
    fig.tight_layout()
    fig.savefig(out / "prediction.png", dpi=120)
    print(f"plot: {out / 'prediction.png'}")


if __name__ == "__main__":
    main()

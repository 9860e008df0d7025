#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-3.0-or-later
"""Exits 0 when two output folders of fiberfluid hold the same results, bit
for bit: the same files, byte-equal, except what measures the run rather than
the model (wall times, peak memory, which MPI rank ran a variant), which is
left out of the comparison. Prints every difference otherwise.

    same_outputs.py A B
"""
import csv
import json
import pathlib
import sys

# What differs between two runs of the same model: CSV columns and JSON keys.
RUN_COLUMNS = {"seconds", "rank"}
# (openmp_threads: the threads of the process, which the ranks share out.)
RUN_KEYS = {"seconds", "pruning_seconds", "peak_resident_bytes", "openmp_threads", "rank"}


def without_run_keys(value):
    if isinstance(value, dict):
        return {k: without_run_keys(v) for k, v in value.items() if k not in RUN_KEYS}
    if isinstance(value, list):
        return [without_run_keys(v) for v in value]
    return value


def csv_rows(path):
    with open(path, newline="") as f:
        rows = list(csv.reader(f))
    keep = [k for k, name in enumerate(rows[0]) if name not in RUN_COLUMNS] if rows else []
    return [[row[k] for k in keep] for row in rows]


def same_file(a, b):
    if a.suffix == ".csv":
        return csv_rows(a) == csv_rows(b)
    if a.suffix == ".json":
        # Floats as written (nlohmann's shortest round trip): equal text, equal bits.
        load = lambda p: json.loads(p.read_text(), parse_float=str)
        return without_run_keys(load(a)) == without_run_keys(load(b))
    return a.read_bytes() == b.read_bytes()


def main(a, b):
    a, b = pathlib.Path(a), pathlib.Path(b)
    files = lambda root: {p.relative_to(root) for p in root.rglob("*") if p.is_file()}
    in_a, in_b = files(a), files(b)
    problems = [f"only in {a}: {p}" for p in sorted(in_a - in_b)]
    problems += [f"only in {b}: {p}" for p in sorted(in_b - in_a)]
    problems += [f"differs: {p}" for p in sorted(in_a & in_b) if not same_file(a / p, b / p)]
    for line in problems:
        print(line)
    if not in_a:
        print(f"{a} holds no files")
        return 1
    print(f"{len(in_a & in_b)} files compared: " + ("the same" if not problems else "DIFFERENT"))
    return 1 if problems else 0


if __name__ == "__main__":
    if len(sys.argv) != 3:
        sys.exit(__doc__)
    sys.exit(main(sys.argv[1], sys.argv[2]))

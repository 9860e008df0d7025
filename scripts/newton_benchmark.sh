#!/usr/bin/env bash
# The Newton benchmark (issues 8 and 25): the sphere experiment at half its
# gravity with an exponential law on icospheres of 642, 2562 and 10242
# vertices, 10 load steps, Newton-Krylov with a block-cholesky preconditioner,
# and the paper's incremental run of the same mesh and backend right after it.
# Builds Release and prints a table (Newton iterations per step, GMRES
# iterations per solve, time per step, peak memory, and Newton's time over the
# incremental run's, measured one after the other).
#   scripts/newton_benchmark.sh [--max-subdivisions 5]
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/build-release.sh
max=5
if [[ "${1:-}" == "--max-subdivisions" ]]; then max="$2"; fi
scaling=build-release/experiments/scaling/fiberfluid_scaling
printf '| vertices | steps | newton iterations / step | gmres iterations / solve | preconditioner factorizations | s / step | whole run s | peak MiB | incremental s | newton / incremental |\n'
printf '|---|---|---|---|---|---|---|---|---|---|\n'
for sub in $(seq 3 "$max"); do
  newton=$("$scaling" --subdivisions "$sub" --newton exponential --solver block-cholesky \
             --gravity-scale 0.5 | grep '^{' || true)
  incremental=$("$scaling" --subdivisions "$sub" --solver block-cholesky --gravity-scale 0.5 |
                  grep '^{' || true)
  /usr/bin/python3 - "$newton" "$incremental" <<'PY'
import json, sys
r = json.loads(sys.argv[1])
i = json.loads(sys.argv[2]) if sys.argv[2] else {"success": False}
if not r["success"]:
    print(f'| {r["vertices"]} | failed: {r["message"]} |')
else:
    base = f'{i["run_s"]:.2f} | {r["run_s"] / i["run_s"]:.1f}x' if i["success"] else "failed | -"
    print(f'| {r["vertices"]} | {r["steps"]} | {r["newton_iterations_per_step"]:.1f} | '
          f'{r["krylov_iterations_per_solve"]:.1f} | {r["factorizations"]} | '
          f'{r["run_s"] / r["steps"]:.2f} | {r["run_s"]:.1f} | {r["peak_mib"]:.0f} | {base} |')
PY
done

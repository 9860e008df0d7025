#!/usr/bin/env bash
# Installs the built fiberfluid into a scratch prefix, builds examples/cpp
# against that prefix as a separate project, and runs it.
#   tests/install/build_example.sh BUILD_DIR SOURCE_DIR
set -euo pipefail
build="$1" source="$2"
scratch="$(mktemp -d)"
trap 'rm -rf "$scratch"' EXIT
cmake --install "$build" --prefix "$scratch/prefix" >/dev/null
# Only PREFIX/include is on the include path: headers are <fiberfluid/...>, and a
# generic name such as util/error.hpp cannot clash with another library's.
if grep -q 'include/fiberfluid' "$scratch"/prefix/lib*/cmake/fiberfluid/fiberfluidTargets.cmake; then
  echo "the installed package puts include/fiberfluid on the include path"; exit 1
fi
cmake -S "$source/examples/cpp" -B "$scratch/build" -DCMAKE_BUILD_TYPE=Release \
      -DCMAKE_PREFIX_PATH="$scratch/prefix" >/dev/null
cmake --build "$scratch/build" -j2 >/dev/null
output="$("$scratch/build/sag_sphere")"
echo "$output"
# Four times the modulus sags about a quarter as far; the cap carries the
# fluid's load (rho g V is about 5 N) upward in both.
awk '/^soft:/ {soft = $4; soft_r = $9} /^stiff:/ {stiff = $4; stiff_r = $9}
     END {ratio = stiff / soft
          if (!(ratio > 0.2 && ratio < 0.3 && soft_r > 4 && stiff_r > 4)) {
            print "unexpected figures: ratio " ratio ", reactions " soft_r " " stiff_r; exit 1 } }' \
    <<<"$output"

# The installed command draws its plot with the installed script (run --plot),
# and the script is a command of its own.
cat > "$scratch/tiny.json" <<'JSON'
{"name": "tiny", "surface": {"generator": "icosphere", "subdivisions": 1},
 "material": {"Y": 3000, "gamma": 3000}, "supports": [{"where": "z >= 0.8"}],
 "loads": [{"type": "gravity", "acceleration": [0, 0, -10]}], "stepping": {"steps": 2}}
JSON
test -x "$scratch/prefix/bin/fiberfluid-plot"
test -f "$scratch/prefix/share/fiberfluid/plot.py"
(cd "$scratch" && "$scratch/prefix/bin/fiberfluid" run tiny.json -o out -q --plot) | grep -q "plot: "
test -s "$scratch/out/plot.png"
echo "installed run --plot: $scratch/out/plot.png written"
# A fit's and a benchmark's plot scripts are commands too (with any python3 first on PATH).
for command in fiberfluid-plot-fit fiberfluid-plot-benchmark; do
  { "$scratch/prefix/bin/$command" 2>&1 || true; } | grep -q "Usage:" ||
    { echo "$command does not start"; exit 1; }
done

# The installed Python module, found by the interpreter under the prefix.
if [ -n "${FIBERFLUID_PYTHON:-}" ]; then
  # Where this interpreter looks under /usr/local (Debian: lib/python3.X/dist-packages),
  # taken under the scratch prefix.
  local_dir="$("$FIBERFLUID_PYTHON" -c \
    "import sys; print([p for p in sys.path if p.startswith('/usr/local/')][0][len('/usr/local/'):])")"
  module_dir="$scratch/prefix/$local_dir"
  ls "$module_dir"/fiberfluid*.so >/dev/null
  PYTHONPATH="$module_dir" "$FIBERFLUID_PYTHON" -c \
    "import fiberfluid; s = fiberfluid.schema(); assert s['title'] == 'fiberfluid experiment'; print('installed module:', fiberfluid.__file__)"
fi

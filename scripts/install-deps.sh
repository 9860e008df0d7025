#!/usr/bin/env bash
# Installs the Debian packages fiberfluid builds with (as root, or with sudo).
# Does nothing when they are all present already.
set -euo pipefail

packages=(
  build-essential cmake
  libeigen3-dev libopenblas-dev liblapack-dev libsuitesparse-dev libcgal-dev libgmp-dev libmpfr-dev
  nlohmann-json3-dev libcli11-dev libgtest-dev
  libceres-dev libnlopt-dev                  # calibration (src/fit)
  zlib1g-dev                                 # compressed VTK output
  python3 python3-matplotlib python3-numpy   # plots and the scaling driver
  python3-dev pybind11-dev python3-pytest    # the Python module and its tests
  python3-meshio                             # an independent reader of the .vtu files (tests)
  python3-jsonschema                         # an independent validator of the experiment schema (tests)
  clang libclang-rt-14-dev libomp-dev        # the libFuzzer targets (scripts/fuzz.sh)
)

missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
[ ${#missing[@]} -eq 0 ] && exit 0

sudo_cmd=()
[ "$(id -u)" -ne 0 ] && sudo_cmd=(sudo)
echo "installing: ${missing[*]}"
"${sudo_cmd[@]}" apt-get update -qq
DEBIAN_FRONTEND=noninteractive "${sudo_cmd[@]}" apt-get install -y -qq --no-install-recommends "${missing[@]}"

#!/usr/bin/env bash
# Installs the Debian packages fiberfluid builds with (as root, or with sudo),
# and selects OpenBLAS's OpenMP build for BLAS and LAPACK (one thread pool for
# the pair kernels and the factorisations: OpenBLAS's pthreads build keeps a
# pool of its own that spins against OpenMP's; CMakeLists.txt checks it).
# Does nothing when all is in place already.
set -euo pipefail

packages=(
  build-essential cmake
  libeigen3-dev libopenblas-openmp-dev liblapack-dev libsuitesparse-dev libcgal-dev libgmp-dev libmpfr-dev
  nlohmann-json3-dev libcli11-dev libgtest-dev
  libceres-dev libnlopt-dev                  # calibration (src/fit)
  zlib1g-dev                                 # compressed VTK output
  libopenmpi-dev openmpi-bin                 # mpirun -np N fiberfluid run|fit (optional in the build)
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
sudo_cmd=()
[ "$(id -u)" -ne 0 ] && sudo_cmd=(sudo)
if [ ${#missing[@]} -gt 0 ]; then
  echo "installing: ${missing[*]}"
  "${sudo_cmd[@]}" apt-get update -qq
  DEBIAN_FRONTEND=noninteractive "${sudo_cmd[@]}" apt-get install -y -qq --no-install-recommends "${missing[@]}"
fi

# Every BLAS and LAPACK alternative (libblas.so.3, liblapack.so.3,
# libopenblas.so.0, their headers and pkg-config files) to OpenBLAS's OpenMP
# build, where another package's pulled in the pthreads build with a higher
# priority.
for name in $(update-alternatives --get-selections | awk '{print $1}' | grep -E 'blas|lapack'); do
  current="$(update-alternatives --query "$name" | sed -n 's/^Value: //p')"
  openmp="$(update-alternatives --query "$name" | sed -n 's/^Alternative: //p' | grep -m1 '/openblas-openmp/' || true)"
  if [ -n "$openmp" ] && [ "$current" != "$openmp" ]; then
    echo "selecting OpenBLAS's OpenMP build: $name -> $openmp"
    "${sudo_cmd[@]}" update-alternatives --set "$name" "$openmp" >/dev/null
  fi
done

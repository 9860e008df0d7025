// SPDX-License-Identifier: GPL-3.0-or-later
#include "fiberfluid/experiment/write/build_info.hpp"

#include <CGAL/version.h>
#include <SuiteSparse_config.h>
#include <dlfcn.h>
#include <nlopt.h>
#include <omp.h>

#include <ceres/version.h>
#include <Eigen/Core>

#include "fiberfluid/util/omp_wait_policy.hpp"

namespace fiberfluid::experiment {

namespace {

std::string dotted(int major, int minor, int patch) {
  return std::to_string(major) + "." + std::to_string(minor) + "." + std::to_string(patch);
}

// The BLAS this process runs, asked at run time (the library the loader
// found, not the one the build saw): OpenBLAS names its version and its
// threading (openblas_get_parallel: 0 none, 1 pthreads, 2 OpenMP).
std::string blas_in_use() {
  using Config = char* (*)();
  using Parallel = int (*)();
  const auto config = reinterpret_cast<Config>(dlsym(RTLD_DEFAULT, "openblas_get_config"));
  const auto parallel = reinterpret_cast<Parallel>(dlsym(RTLD_DEFAULT, "openblas_get_parallel"));
  if (config == nullptr || parallel == nullptr) return "not OpenBLAS (threading unknown)";
  static const char* const kThreading[] = {"serial", "pthreads", "OpenMP"};
  const int p = parallel();
  return std::string(config()) + " (threading: " + (p >= 0 && p <= 2 ? kThreading[p] : "?") + ")";
}

}  // namespace

std::string program_version() { return FIBERFLUID_VERSION; }

std::vector<std::pair<std::string, std::string>> build_info() {
  int nlopt_major = 0, nlopt_minor = 0, nlopt_patch = 0;
  nlopt_version(&nlopt_major, &nlopt_minor, &nlopt_patch);
  return {
      {"version", FIBERFLUID_VERSION},
      {"compiler", FIBERFLUID_COMPILER},
      {"build_type", FIBERFLUID_BUILD_TYPE},
      {"sanitizers", FIBERFLUID_SANITIZERS},
      {"openmp_threads", std::to_string(omp_get_max_threads())},
      {"openmp_wait_policy", util::omp_wait_policy()},
      {"lapack", FIBERFLUID_LAPACK},
      {"blas", blas_in_use()},
      {"blas_threading_at_build", FIBERFLUID_BLAS_THREADING},
      {"suitesparse",
       dotted(SUITESPARSE_MAIN_VERSION, SUITESPARSE_SUB_VERSION, SUITESPARSE_SUBSUB_VERSION) +
           " (CHOLMOD, UMFPACK)"},
      {"eigen", dotted(EIGEN_WORLD_VERSION, EIGEN_MAJOR_VERSION, EIGEN_MINOR_VERSION)},
      {"cgal", CGAL_VERSION_STR},
      {"ceres", CERES_VERSION_STRING},
      {"nlopt", dotted(nlopt_major, nlopt_minor, nlopt_patch)},
  };
}

}  // namespace fiberfluid::experiment

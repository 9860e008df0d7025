# SPDX-License-Identifier: GPL-3.0-or-later
# Which threading the BLAS and LAPACK in use run on, read from where their
# files lead (Debian keeps OpenBLAS's builds in openblas-openmp/,
# openblas-pthread/ and openblas-serial/ behind its alternatives): the
# libraries the project links (LAPACK_LIBRARIES) and the libblas.so.3 and
# liblapack.so.3 that CHOLMOD and Ceres load beside them.
#
# OpenBLAS's OpenMP build runs on the OpenMP threads of the pair kernels: one
# thread pool. Its pthreads build keeps a pool of its own, and on a small
# machine the two spin against each other (the memory-bound solves 2 to 3x
# slower, docs/performance.md): a configure error, unless
# FIBERFLUID_ALLOW_PTHREADS_BLAS is ON. scripts/install-deps.sh selects the
# OpenMP build.
#
# Sets FIBERFLUID_BLAS_THREADING to OpenMP, pthreads, serial or unknown.
option(FIBERFLUID_ALLOW_PTHREADS_BLAS "Build with OpenBLAS's pthreads build (two thread pools)" OFF)

function(fiberfluid_blas_threading out)
  set(files ${LAPACK_LIBRARIES})
  list(FILTER files INCLUDE REGEX "^/")
  if(files)
    list(GET files 0 first)
    get_filename_component(dir "${first}" DIRECTORY)
    foreach(name libblas.so.3 liblapack.so.3)
      if(EXISTS "${dir}/${name}")
        list(APPEND files "${dir}/${name}")
      endif()
    endforeach()
  endif()
  set(found "")
  foreach(file IN LISTS files)
    get_filename_component(real "${file}" REALPATH)
    if(real MATCHES "/openblas-openmp/")
      list(APPEND found OpenMP)
    elseif(real MATCHES "/openblas-pthread/")
      list(APPEND found pthreads)
    elseif(real MATCHES "/openblas-serial/")
      list(APPEND found serial)
    else()
      list(APPEND found unknown)
    endif()
    message(STATUS "BLAS/LAPACK: ${file} -> ${real}")
  endforeach()
  list(REMOVE_DUPLICATES found)
  list(FIND found pthreads pthreads_at)
  if(pthreads_at GREATER -1)
    set(threading pthreads)
  elseif(found STREQUAL "OpenMP")
    set(threading OpenMP)
  elseif(found STREQUAL "serial")
    set(threading serial)
  else()
    set(threading unknown)
  endif()
  set(${out} ${threading} PARENT_SCOPE)
endfunction()

fiberfluid_blas_threading(FIBERFLUID_BLAS_THREADING)
message(STATUS "BLAS/LAPACK threading: ${FIBERFLUID_BLAS_THREADING}")
if(FIBERFLUID_BLAS_THREADING STREQUAL "pthreads" AND NOT FIBERFLUID_ALLOW_PTHREADS_BLAS)
  message(FATAL_ERROR
    "BLAS/LAPACK is OpenBLAS's pthreads build, whose threads spin against OpenMP's: "
    "run scripts/install-deps.sh (it installs and selects libopenblas-openmp-dev), or "
    "configure with -DFIBERFLUID_ALLOW_PTHREADS_BLAS=ON to build with it anyway")
endif()

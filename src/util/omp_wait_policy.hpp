// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once

#include <string>

namespace fiberfluid::util {

// How this process's OpenMP threads wait between parallel regions.
//
// libgomp's default spins up to 300,000 times at every barrier before it
// sleeps. Alone on a machine that is the fastest wait; beside other work it
// is the slowest by far: a thread spins on the core that the thread it waits
// for needs (a cantilever of central fibers beside one busy process: 2.4
// times its one-thread time; issue 42 saw 20 times). Passive waiting costs a
// futex wake per region instead.
//
// libgomp reads OMP_WAIT_POLICY and GOMP_SPINCOUNT once, in its constructor,
// before main, and offers no call to change them later (and libc's own start-up
// sets `environ` back after an ELF pre-initialiser, so none can set them
// either). A program therefore calls this first in main: where the user set
// neither, it starts itself again (execv of /proc/self/exe, the same
// arguments, pid and descriptors) with OMP_WAIT_POLICY=passive and
// FIBERFLUID_WAIT_POLICY=default; it returns where the user chose, where the
// restart already happened, or where the restart is not possible (the
// program then runs with libgomp's default). Call it before MPI_Init and
// before any thread starts.
void wait_passively_unless_chosen(char** argv);

// What the process runs with, for summaries and --version:
// "passive (fiberfluid's default)", "OMP_WAIT_POLICY=active (the user's)",
// "GOMP_SPINCOUNT=1000 (the user's)" or "libgomp's default (spins, then sleeps)".
std::string omp_wait_policy();

}  // namespace fiberfluid::util

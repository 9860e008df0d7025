// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once

// The ranks of an MPI run (mpirun, srun), or one rank. The program stays the
// same program: built without MPI, or started without a launcher, it is one
// rank and nothing here calls MPI. Under a launcher, rank 0 reads, checks and
// writes; work items (a sweep's variants, a multi-start fit's starts, a
// calibration's specimens) are dealt out one at a time to whichever rank
// asks next, so that variants of different cost keep every rank busy
// (the master-worker pattern; Gropp, Lusk and Skjellum, "Using MPI", 3rd ed.,
// MIT Press 2014, section 3.6).

#include <string>
#include <vector>

#include "fiberfluid/util/work_dealer.hpp"

namespace fiberfluid::parallel {

// What the build has: "Open MPI 4.1.4" (the library's own version string,
// first line), or "none (built without MPI)".
std::string mpi_description();

// True when the process was started by an MPI launcher (its environment
// says so: Open MPI's, PMIx's or PMI's rank variables).
bool launched_by_mpi();

class Ranks {
 public:
  // Initialises MPI when the build has it and a launcher started the process;
  // else one rank. One object per process, for its lifetime.
  Ranks(int* argc, char*** argv);
  // Waits (without spinning) until every rank is here, then finalises MPI.
  ~Ranks();
  Ranks(const Ranks&) = delete;
  Ranks& operator=(const Ranks&) = delete;

  int rank() const { return rank_; }
  int size() const { return size_; }
  bool root() const { return rank_ == 0; }
  // "" unless a launcher started this process as one of several ranks and
  // the build has no MPI: then why it cannot take part (each process would
  // run the whole experiment alone).
  const std::string& problem() const { return problem_; }
  // Ranks on this machine (they share its cores).
  int local_size() const { return local_size_; }
  // OpenMP threads of this rank: OMP_NUM_THREADS when set, else this
  // machine's cores shared out among its ranks (set in the constructor).
  int threads() const;

  // True on every rank when `ok` is true on every rank: a step that may fail
  // on some ranks (reading the experiment, preparing the output folder) ends
  // in agreement, so no rank waits for work that will never be dealt.
  bool all_ok(bool ok) const;

  // Deals work items out (util/work_dealer.hpp's WorkDealer, over the
  // ranks). Every rank calls it with the same count. Items 0..count-1 are dealt out
  // one at a time: rank 0 computes items too (when MPI lets a second thread
  // answer the others), the others ask for the next when done. Stops dealing
  // after Ctrl-C (util/run_control.hpp) or when `deliver` throws; the first
  // exception is rethrown on rank 0 once every rank has stopped.
  void deal(size_t count, const WorkCompute& compute, const WorkDeliver& deliver) const;
  // This object's deal as a WorkDealer (it must outlive the dealer).
  WorkDealer dealer() const;

  // Element-wise sum of `values` over the ranks, on every rank.
  void sum(std::vector<double>& values) const;
  // `bytes` of rank 0, on every rank.
  void broadcast(std::string& bytes) const;
  // The ranks (on every rank) whose `digest` differs from rank 0's: empty
  // when every rank holds the same (the same experiment and surface).
  std::vector<int> differing_from_root(const std::string& digest) const;
  // Ends every rank of the job at once with `status` (MPI_Abort): after a
  // failure on one rank that the others cannot learn of, so that none waits
  // for it for ever. Returns only with one rank (it does nothing then).
  void end_job(int status) const;

 private:
  int rank_ = 0, size_ = 1, local_size_ = 1;
  bool initialised_ = false;
  bool second_thread_ = false;  // MPI may be called from a thread other than main's
  std::string problem_;
};

}  // namespace fiberfluid::parallel

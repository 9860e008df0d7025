// SPDX-License-Identifier: GPL-3.0-or-later
#include "fiberfluid/parallel/ranks.hpp"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <limits>
#include <mutex>
#include <stdexcept>
#include <thread>

#include "fiberfluid/util/run_control.hpp"

#include <omp.h>
#include <sched.h>

#ifdef FIBERFLUID_HAVE_MPI
#include <mpi.h>
#endif

namespace fiberfluid::parallel {

bool launched_by_mpi() {
  for (const char* name : {"OMPI_COMM_WORLD_SIZE", "PMIX_RANK", "PMI_RANK", "PMI_SIZE"})
    if (std::getenv(name) != nullptr) return true;
  return false;
}

int Ranks::threads() const { return omp_get_max_threads(); }

WorkDealer Ranks::dealer() const {
  return [this](size_t count, const WorkCompute& compute, const WorkDeliver& deliver) {
    deal(count, compute, deliver);
  };
}

#ifndef FIBERFLUID_HAVE_MPI

std::string mpi_description() { return "none (built without MPI)"; }

Ranks::Ranks(int*, char***) {
  for (const char* name : {"OMPI_COMM_WORLD_SIZE", "PMI_SIZE", "PMIX_SIZE"})
    if (const char* size = std::getenv(name); size != nullptr && std::atoi(size) > 1)
      problem_ = std::string("started as one of ") + size +
                 " MPI ranks, but this fiberfluid was built without MPI (--version says "
                 "\"mpi: none\"): install Open MPI (scripts/install-deps.sh) and build again, "
                 "or run it without mpirun";
}
Ranks::~Ranks() = default;
bool Ranks::all_ok(bool ok) const { return ok; }
void Ranks::sum(std::vector<double>&) const {}
void Ranks::broadcast(std::string&) const {}
std::vector<int> Ranks::differing_from_root(const std::string&) const { return {}; }
void Ranks::end_job(int) const {}

void Ranks::deal(size_t count, const WorkCompute& compute, const WorkDeliver& deliver) const {
  deal_in_order(count, compute, deliver);
}

#else

namespace {

enum Tag : int {
  kAsk = 1,     // worker to rank 0: nothing yet, give me an item
  kResult = 2,  // worker to rank 0: an item's index, then its bytes; give me the next
  kItem = 3,    // rank 0 to worker: the next index, or -1: no more
  // worker to rank 0: asked to stop (a signal on this rank alone) while
  // computing an item, whose result is therefore not one: the job stops.
  kInterrupted = 4,
};

// Waiting on a message by polling with a sleep: a blocking MPI call spins
// on its core, which the ranks' own threads need.
void nap() { std::this_thread::sleep_for(std::chrono::milliseconds(1)); }

void wait_quietly(MPI_Request* request) {
  for (int done = 0;;) {
    MPI_Test(request, &done, MPI_STATUS_IGNORE);
    if (done) return;
    nap();
  }
}

std::int64_t receive_item() {
  std::int64_t item = -1;
  MPI_Request request;
  MPI_Irecv(&item, 1, MPI_INT64_T, 0, kItem, MPI_COMM_WORLD, &request);
  wait_quietly(&request);
  return item;
}

// A worker rank: asks, computes, sends the result with the next request.
void work(const WorkCompute& compute) {
  MPI_Send(nullptr, 0, MPI_BYTE, 0, kAsk, MPI_COMM_WORLD);
  for (std::int64_t item = receive_item(); item >= 0; item = receive_item()) {
    std::string message(sizeof item, '\0');
    std::memcpy(message.data(), &item, sizeof item);
    message += compute(static_cast<size_t>(item));
    if (cancel_requested()) {  // the result was cut short: it is no result
      MPI_Send(nullptr, 0, MPI_BYTE, 0, kInterrupted, MPI_COMM_WORLD);
      continue;
    }
    if (message.size() > static_cast<size_t>(std::numeric_limits<int>::max()))
      throw std::length_error("a work item's result is over 2 GiB, more than one MPI message");
    MPI_Send(message.data(), static_cast<int>(message.size()), MPI_BYTE, 0, kResult,
             MPI_COMM_WORLD);
  }
}

// Rank 0's dealer: answers every worker's request with the next item until
// none is left (or dealing stopped), delivering the results that come with
// the requests.
class Dealer {
 public:
  Dealer(size_t count, int workers, const WorkDeliver& deliver)
      : count_(count), workers_(workers), deliver_(deliver) {}

  // The next item for anyone, or -1.
  std::int64_t next() {
    if (stopped_ || cancel_requested()) return -1;
    const size_t item = next_++;
    return item < count_ ? static_cast<std::int64_t>(item) : -1;
  }

  void deliver(size_t item, int rank, std::string&& bytes) {
    if (stopped_) return;
    try {
      deliver_(item, rank, std::move(bytes));
    } catch (...) {
      const std::lock_guard<std::mutex> lock(mutex_);
      if (!error_) error_ = std::current_exception();
      stopped_ = true;
    }
  }

  void answer_workers() {
    for (int left = workers_; left > 0;) {
      int waiting = 0;
      MPI_Status status;
      MPI_Iprobe(MPI_ANY_SOURCE, MPI_ANY_TAG, MPI_COMM_WORLD, &waiting, &status);
      if (!waiting) {
        nap();
        continue;
      }
      int size = 0;
      MPI_Get_count(&status, MPI_BYTE, &size);
      std::string message(static_cast<size_t>(size), '\0');
      MPI_Recv(message.data(), size, MPI_BYTE, status.MPI_SOURCE, status.MPI_TAG, MPI_COMM_WORLD,
               MPI_STATUS_IGNORE);
      if (status.MPI_TAG == kResult) {
        std::int64_t item = -1;
        std::memcpy(&item, message.data(), sizeof item);
        deliver(static_cast<size_t>(item), status.MPI_SOURCE, message.substr(sizeof item));
      }
      // One rank stopped is the whole job stopped, as Ctrl-C on rank 0 is:
      // no rank's cut-short work is reported as a failure of its own.
      if (status.MPI_TAG == kInterrupted) request_cancel();
      const std::int64_t item = next();
      MPI_Send(&item, 1, MPI_INT64_T, status.MPI_SOURCE, kItem, MPI_COMM_WORLD);
      if (item < 0) --left;
    }
  }

  void rethrow() const {
    if (error_) std::rethrow_exception(error_);
  }

 private:
  const size_t count_;
  const int workers_;
  const WorkDeliver& deliver_;
  std::atomic<size_t> next_{0};
  std::atomic<bool> stopped_{false};
  std::mutex mutex_;
  std::exception_ptr error_;
};

}  // namespace

std::string mpi_description() {
  char text[MPI_MAX_LIBRARY_VERSION_STRING];
  int length = 0;
  MPI_Get_library_version(text, &length);
  std::string version(text, static_cast<size_t>(length));
  const size_t end = version.find_first_of(",\n");
  return version.substr(0, end);
}

Ranks::Ranks(int* argc, char*** argv) {
  if (!launched_by_mpi()) return;
  int provided = MPI_THREAD_SINGLE;
  MPI_Init_thread(argc, argv, MPI_THREAD_SERIALIZED, &provided);
  initialised_ = true;
  second_thread_ = provided >= MPI_THREAD_SERIALIZED;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank_);
  MPI_Comm_size(MPI_COMM_WORLD, &size_);
  MPI_Comm local;
  MPI_Comm_split_type(MPI_COMM_WORLD, MPI_COMM_TYPE_SHARED, rank_, MPI_INFO_NULL, &local);
  MPI_Comm_size(local, &local_size_);
  MPI_Comm_free(&local);
  // Ranks on one machine share its cores, unless the launcher or the user
  // chose the threads (srun --cpus-per-task sets OMP_NUM_THREADS in the
  // usual sbatch script).
  if (std::getenv("OMP_NUM_THREADS") == nullptr && local_size_ > 1) {
    int cores = static_cast<int>(std::thread::hardware_concurrency()) / local_size_;
    cpu_set_t mine;  // a rank the launcher bound to fewer cores gets no more threads
    if (sched_getaffinity(0, sizeof mine, &mine) == 0) cores = std::min(cores, CPU_COUNT(&mine));
    omp_set_num_threads(std::max(1, cores));
  }
}

Ranks::~Ranks() {
  if (!initialised_) return;
  MPI_Request request;
  MPI_Ibarrier(MPI_COMM_WORLD, &request);
  wait_quietly(&request);
  MPI_Finalize();
}

bool Ranks::all_ok(bool ok) const {
  if (size_ == 1) return ok;
  int mine = ok ? 1 : 0, all = 0;
  MPI_Request request;
  MPI_Iallreduce(&mine, &all, 1, MPI_INT, MPI_MIN, MPI_COMM_WORLD, &request);
  wait_quietly(&request);
  return all == 1;
}

void Ranks::sum(std::vector<double>& values) const {
  if (size_ == 1) return;
  MPI_Request request;
  MPI_Iallreduce(MPI_IN_PLACE, values.data(), static_cast<int>(values.size()), MPI_DOUBLE, MPI_SUM,
                 MPI_COMM_WORLD, &request);
  wait_quietly(&request);
}

void Ranks::broadcast(std::string& bytes) const {
  if (size_ == 1) return;
  std::uint64_t size = bytes.size();
  MPI_Bcast(&size, 1, MPI_UINT64_T, 0, MPI_COMM_WORLD);
  bytes.resize(size);
  MPI_Request request;
  MPI_Ibcast(bytes.data(), static_cast<int>(size), MPI_BYTE, 0, MPI_COMM_WORLD, &request);
  wait_quietly(&request);
}

std::vector<int> Ranks::differing_from_root(const std::string& digest) const {
  if (size_ == 1) return {};
  std::string root_digest = digest;
  broadcast(root_digest);
  std::vector<double> differs(static_cast<size_t>(size_), 0.0);
  differs[static_cast<size_t>(rank_)] = root_digest == digest ? 0.0 : 1.0;
  sum(differs);
  std::vector<int> ranks;
  for (int r = 0; r < size_; ++r)
    if (differs[static_cast<size_t>(r)] > 0.0) ranks.push_back(r);
  return ranks;
}

void Ranks::end_job(int status) const {
  if (size_ > 1) MPI_Abort(MPI_COMM_WORLD, status);
}

void Ranks::deal(size_t count, const WorkCompute& compute, const WorkDeliver& deliver) const {
  if (size_ == 1) return deal_in_order(count, compute, deliver);
  if (!root()) {
    work(compute);
    return;
  }
  Dealer dealer(count, size_ - 1, deliver);
  if (!second_thread_) {  // rank 0 only deals
    dealer.answer_workers();
  } else {
    std::thread answering([&dealer] { dealer.answer_workers(); });
    for (std::int64_t item = dealer.next(); item >= 0; item = dealer.next())
      dealer.deliver(static_cast<size_t>(item), 0, compute(static_cast<size_t>(item)));
    answering.join();
  }
  dealer.rethrow();
}

#endif

}  // namespace fiberfluid::parallel

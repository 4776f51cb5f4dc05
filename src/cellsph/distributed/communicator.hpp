#pragma once
// The processes of one run (issue 49, docs/distributed.md): who this rank is, how many there are, and the
// collective operations the distributed run needs, behind an interface that includes no MPI header. Built
// with Open MPI where CMake finds it (option CELLSPH_MPI); without it, and in a process that no MPI
// launcher started, there is one rank and every collective is the identity, so the single-process paths
// need no branch.
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "cellsph/core/exact_sum.hpp"

namespace cellsph::distributed {

// Whether the library was built with MPI (CELLSPH_MPI on and Open MPI found).
bool built_with_mpi();

// Whether an MPI launcher started this process (mpirun, mpiexec, srun: their environment variables).
bool launched_by_mpi_launcher();

// The MPI library's own version line ("Open MPI v4.1.4, ..."), or "" without MPI.
std::string mpi_library_version();

// Starts MPI for the lifetime of the object when the library was built with it and a launcher started the
// process (a plain `cellsph run` stays a single process without MPI's start-up); ends it in the destructor.
// One per process, before any Communicator is used.
class MpiSession {
 public:
  MpiSession(int* argc, char*** argv);
  ~MpiSession();
  MpiSession(const MpiSession&) = delete;
  MpiSession& operator=(const MpiSession&) = delete;
  bool active() const { return active_; }

 private:
  bool active_ = false;
};

// The ranks of the run (MPI_COMM_WORLD once an MpiSession is active; one rank otherwise). Every call below
// is collective: every rank makes it, in the same order.
class Communicator {
 public:
  int rank() const;
  int size() const;
  // Element-wise sums of integers over the ranks, in place (exact: no order to depend on).
  void sum_in_place(std::int64_t* values, int count) const;
  // The largest value over the ranks.
  double max(double value) const;
  // The exact sum of every rank's accumulator, the same on every rank (core/exact_sum.hpp).
  ExactSum sum(const ExactSum& local) const;
  // Every rank's values concatenated in rank order, on every rank.
  std::vector<std::int64_t> all_gather(const std::vector<std::int64_t>& local) const;
  // Bytes for every rank exchanged (to_rank[r]: what this rank sends rank r; size() entries): what every
  // rank sent this one, concatenated in rank order; from[r] the bytes that came from rank r. A message to
  // one rank must stay under 2 GiB (MPI's int counts): a larger one is refused with a SimulationError.
  std::vector<std::byte> all_to_all(const std::vector<std::vector<std::byte>>& to_rank,
                                    std::vector<std::size_t>& from) const;
  void barrier() const;
  // Ends every rank of the run with `code` (MPI_Abort): for an error on one rank that the others cannot
  // know of, which would leave them waiting in the next collective. Without MPI: std::exit(code).
  [[noreturn]] void abort(int code) const;
};

// The run's communicator.
Communicator world();

}  // namespace cellsph::distributed

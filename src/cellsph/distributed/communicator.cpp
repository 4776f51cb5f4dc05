// The only file that includes MPI's header (docs/distributed.md). Compiled with CELLSPH_HAVE_MPI where
// CMake found MPI (CMakeLists.txt); otherwise every call is the single-process identity.
#include "cellsph/distributed/communicator.hpp"

#include <cstdlib>
#include <limits>
#include <string>

#include "cellsph/core/error.hpp"

#if defined(CELLSPH_HAVE_MPI)
#include <mpi.h>
#endif

namespace cellsph::distributed {

#if defined(CELLSPH_HAVE_MPI)
namespace {
bool g_active = false;  // an MpiSession initialised MPI in this process
}  // namespace
#endif

bool built_with_mpi() {
#if defined(CELLSPH_HAVE_MPI)
  return true;
#else
  return false;
#endif
}

bool launched_by_mpi_launcher() {
  for (const char* v : {"OMPI_COMM_WORLD_SIZE", "PMI_SIZE", "PMIX_RANK", "MPI_LOCALNRANKS"})
    if (std::getenv(v) != nullptr) return true;
  return false;
}

std::string mpi_library_version() {
#if defined(CELLSPH_HAVE_MPI)
  char text[MPI_MAX_LIBRARY_VERSION_STRING];
  int length = 0;
  MPI_Get_library_version(text, &length);
  std::string s(text, static_cast<std::size_t>(length));
  while (!s.empty() && (s.back() == '\n' || s.back() == ' ' || s.back() == '\0')) s.pop_back();
  return s;
#else
  return "";
#endif
}

MpiSession::MpiSession([[maybe_unused]] int* argc, [[maybe_unused]] char*** argv) {
#if defined(CELLSPH_HAVE_MPI)
  int initialised = 0;
  MPI_Initialized(&initialised);
  if (initialised || !launched_by_mpi_launcher()) return;
  int provided = 0;
  // Funneled: OpenMP threads compute, the main thread alone talks to MPI.
  MPI_Init_thread(argc, argv, MPI_THREAD_FUNNELED, &provided);
  // An error in a collective throws nothing and returns a code; the default handler (abort the whole job
  // with a message) is the behaviour a failed rank must have: never a hang.
  MPI_Comm_set_errhandler(MPI_COMM_WORLD, MPI_ERRORS_ARE_FATAL);
  active_ = g_active = true;
#endif
}

MpiSession::~MpiSession() {
#if defined(CELLSPH_HAVE_MPI)
  if (active_) {
    MPI_Finalize();
    g_active = false;
  }
#endif
}

int Communicator::rank() const {
#if defined(CELLSPH_HAVE_MPI)
  if (g_active) {
    int r = 0;
    MPI_Comm_rank(MPI_COMM_WORLD, &r);
    return r;
  }
#endif
  return 0;
}

int Communicator::size() const {
#if defined(CELLSPH_HAVE_MPI)
  if (g_active) {
    int n = 1;
    MPI_Comm_size(MPI_COMM_WORLD, &n);
    return n;
  }
#endif
  return 1;
}

void Communicator::sum_in_place([[maybe_unused]] std::int64_t* values, [[maybe_unused]] int count) const {
#if defined(CELLSPH_HAVE_MPI)
  if (g_active) MPI_Allreduce(MPI_IN_PLACE, values, count, MPI_INT64_T, MPI_SUM, MPI_COMM_WORLD);
#endif
}

double Communicator::max(double value) const {
#if defined(CELLSPH_HAVE_MPI)
  if (g_active) MPI_Allreduce(MPI_IN_PLACE, &value, 1, MPI_DOUBLE, MPI_MAX, MPI_COMM_WORLD);
#endif
  return value;
}

ExactSum Communicator::sum(const ExactSum& local) const {
  ExactSum s = local;
  s.normalize();  // every digit below 2^32 (the top one signed): the sum over ranks cannot overflow
  std::int64_t buffer[ExactSum::kDigits + 1];
  for (int k = 0; k < ExactSum::kDigits; ++k) buffer[k] = s.digits()[k];
  buffer[ExactSum::kDigits] = 0;
  // Infinities and NaN as bits: one rank's flag is set on the sum if any rank's is (a sum of 0/1 per bit).
  std::int64_t flags[3] = {s.special() & 1, (s.special() >> 1) & 1, (s.special() >> 2) & 1};
  sum_in_place(buffer, ExactSum::kDigits);
  sum_in_place(flags, 3);
  ExactSum r;
  for (int k = 0; k < ExactSum::kDigits; ++k) r.digits()[k] = buffer[k];
  r.set_special(
      static_cast<std::uint32_t>((flags[0] > 0 ? 1 : 0) | (flags[1] > 0 ? 2 : 0) | (flags[2] > 0 ? 4 : 0)));
  r.normalize();
  return r;
}

std::vector<std::int64_t> Communicator::all_gather(const std::vector<std::int64_t>& local) const {
#if defined(CELLSPH_HAVE_MPI)
  if (g_active) {
    const int n = size();
    int mine = static_cast<int>(local.size());
    std::vector<int> counts(static_cast<std::size_t>(n)), offsets(static_cast<std::size_t>(n), 0);
    MPI_Allgather(&mine, 1, MPI_INT, counts.data(), 1, MPI_INT, MPI_COMM_WORLD);
    for (int r = 1; r < n; ++r)
      offsets[static_cast<std::size_t>(r)] =
          offsets[static_cast<std::size_t>(r - 1)] + counts[static_cast<std::size_t>(r - 1)];
    std::vector<std::int64_t> all(static_cast<std::size_t>(offsets.back() + counts.back()));
    MPI_Allgatherv(local.data(), mine, MPI_INT64_T, all.data(), counts.data(), offsets.data(), MPI_INT64_T,
                   MPI_COMM_WORLD);
    return all;
  }
#endif
  return local;
}

std::vector<std::byte> Communicator::all_to_all(const std::vector<std::vector<std::byte>>& to_rank,
                                                std::vector<std::size_t>& from) const {
  const int n = size();
  CELLSPH_CHECK(static_cast<int>(to_rank.size()) == n,
                "all_to_all: " << to_rank.size() << " messages for " << n << " ranks");
#if defined(CELLSPH_HAVE_MPI)
  if (g_active) {
    const auto un = static_cast<std::size_t>(n);
    std::vector<int> send_counts(un), send_offsets(un, 0), recv_counts(un), recv_offsets(un, 0);
    std::vector<std::byte> send;
    for (std::size_t r = 0; r < un; ++r) {
      if (to_rank[r].size() > static_cast<std::size_t>(std::numeric_limits<int>::max()))
        throw SimulationError("rank " + std::to_string(rank()) + " has " + std::to_string(to_rank[r].size()) +
                              " bytes for rank " + std::to_string(r) + ": over MPI's 2 GiB a message");
      send_counts[r] = static_cast<int>(to_rank[r].size());
      send_offsets[r] = static_cast<int>(send.size());
      send.insert(send.end(), to_rank[r].begin(), to_rank[r].end());
    }
    MPI_Alltoall(send_counts.data(), 1, MPI_INT, recv_counts.data(), 1, MPI_INT, MPI_COMM_WORLD);
    std::size_t total = 0;
    from.assign(un, 0);
    for (std::size_t r = 0; r < un; ++r) {
      recv_offsets[r] = static_cast<int>(total);
      from[r] = static_cast<std::size_t>(recv_counts[r]);
      total += from[r];
    }
    if (total > static_cast<std::size_t>(std::numeric_limits<int>::max()))
      throw SimulationError("rank " + std::to_string(rank()) + " receives " + std::to_string(total) +
                            " bytes: over MPI's 2 GiB in one exchange");
    std::vector<std::byte> received(total);
    MPI_Alltoallv(send.data(), send_counts.data(), send_offsets.data(), MPI_BYTE, received.data(),
                  recv_counts.data(), recv_offsets.data(), MPI_BYTE, MPI_COMM_WORLD);
    return received;
  }
#endif
  from.assign(1, to_rank[0].size());
  return to_rank[0];
}

void Communicator::barrier() const {
#if defined(CELLSPH_HAVE_MPI)
  if (g_active) MPI_Barrier(MPI_COMM_WORLD);
#endif
}

void Communicator::abort(int code) const {
#if defined(CELLSPH_HAVE_MPI)
  if (g_active) MPI_Abort(MPI_COMM_WORLD, code);
#endif
  std::exit(code);
}

Communicator world() {
  return {};
}

}  // namespace cellsph::distributed

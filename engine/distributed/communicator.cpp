// MPI calls of a distributed run (docs/theory.md §25): the only file that includes mpi.h.
#include "engine/distributed/communicator.hpp"

#include <fmt/core.h>
#include <mpi.h>
#include <cstdlib>
#include <limits>
#include <numeric>

#include "engine/base/errors.hpp"

namespace dhpd::distributed {
namespace {
void check(int status, const char* call) {
  if (status != MPI_SUCCESS)
    throw EngineError(fmt::format("{} failed (MPI error {})", call, status));
}
int as_int(std::size_t n, const char* what) {
  if (n > static_cast<std::size_t>(std::numeric_limits<int>::max()))
    throw EngineError(fmt::format("{}: {} values are more than one MPI message holds", what, n));
  return static_cast<int>(n);
}
}  // namespace

MpiSession::MpiSession(int& argc, char**& argv) {
  int provided = 0;
  // Each rank runs OpenMP threads, but only its main thread calls MPI.
  check(MPI_Init_thread(&argc, &argv, MPI_THREAD_FUNNELED, &provided), "MPI_Init_thread");
}

MpiSession::~MpiSession() {
  int finalized = 0;
  MPI_Finalized(&finalized);
  if (!finalized) MPI_Finalize();
}

bool MpiSession::launched_by_mpirun() {
  for (const char* name : {"OMPI_COMM_WORLD_SIZE", "PMI_SIZE", "PMIX_RANK", "SLURM_NTASKS"})
    if (std::getenv(name)) return true;
  return false;
}

std::shared_ptr<const Communicator> Communicator::world() {
  int initialized = 0;
  MPI_Initialized(&initialized);
  if (!initialized) return std::shared_ptr<const Communicator>(new Communicator(0, 1));
  int rank = 0, size = 1;
  check(MPI_Comm_rank(MPI_COMM_WORLD, &rank), "MPI_Comm_rank");
  check(MPI_Comm_size(MPI_COMM_WORLD, &size), "MPI_Comm_size");
  return std::shared_ptr<const Communicator>(new Communicator(rank, size));
}

void Communicator::broadcast(std::int64_t& value) const {
  if (size_ == 1) return;
  check(MPI_Bcast(&value, 1, MPI_INT64_T, 0, MPI_COMM_WORLD), "MPI_Bcast");
}

void Communicator::broadcast(std::vector<double>& values) const {
  if (size_ == 1) return;
  check(MPI_Bcast(values.data(), as_int(values.size(), "broadcast"), MPI_DOUBLE, 0, MPI_COMM_WORLD),
        "MPI_Bcast");
}

std::int64_t Communicator::sum(std::int64_t value) const {
  if (size_ == 1) return value;
  std::int64_t out = 0;
  check(MPI_Allreduce(&value, &out, 1, MPI_INT64_T, MPI_SUM, MPI_COMM_WORLD), "MPI_Allreduce");
  return out;
}

double Communicator::max(double value) const {
  if (size_ == 1) return value;
  double out = 0.0;
  check(MPI_Allreduce(&value, &out, 1, MPI_DOUBLE, MPI_MAX, MPI_COMM_WORLD), "MPI_Allreduce");
  return out;
}

namespace {
/// all_gather of one value type; one rank copies `mine` (MPI may not be initialised then).
template <class T>
void gather_into(const std::vector<T>& mine, const std::vector<int>& counts, std::vector<T>& all,
                 int rank, MPI_Datatype type) {
  if (counts.size() == 1) {
    all = mine;
    return;
  }
  std::vector<int> offsets(counts.size(), 0);
  std::exclusive_scan(counts.begin(), counts.end(), offsets.begin(), 0);
  const auto r = static_cast<std::size_t>(rank);
  if (counts.at(r) != as_int(mine.size(), "all_gather") ||
      all.size() != static_cast<std::size_t>(offsets.back() + counts.back()))
    throw EngineError("Communicator::all_gather: the counts do not match the buffers");
  check(MPI_Allgatherv(mine.data(), counts[r], type, all.data(), counts.data(), offsets.data(),
                       type, MPI_COMM_WORLD),
        "MPI_Allgatherv");
}
}  // namespace

void Communicator::all_gather(const std::vector<double>& mine, const std::vector<int>& counts,
                              std::vector<double>& all) const {
  gather_into(mine, counts, all, rank_, MPI_DOUBLE);
}

void Communicator::all_gather(const std::vector<std::int32_t>& mine, const std::vector<int>& counts,
                              std::vector<std::int32_t>& all) const {
  gather_into(mine, counts, all, rank_, MPI_INT32_T);
}

void Communicator::all_gather(const std::vector<std::uint8_t>& mine, const std::vector<int>& counts,
                              std::vector<std::uint8_t>& all) const {
  gather_into(mine, counts, all, rank_, MPI_UINT8_T);
}

std::vector<std::int64_t> Communicator::all_gather(std::int64_t value) const {
  std::vector<std::int64_t> out(static_cast<std::size_t>(size_), value);
  if (size_ == 1) return out;
  check(MPI_Allgather(&value, 1, MPI_INT64_T, out.data(), 1, MPI_INT64_T, MPI_COMM_WORLD),
        "MPI_Allgather");
  return out;
}

void Communicator::abort(int code) const {
  MPI_Abort(MPI_COMM_WORLD, code);
  std::abort();  // MPI_Abort does not return; this keeps [[noreturn]] honest
}

}  // namespace dhpd::distributed

// The ranks of a distributed run (docs/theory.md §25): a thin layer over MPI, so that mpi.h is
// included only by communicator.cpp and the rest of the engine sees plain C++ calls.
#pragma once
#include <cstdint>
#include <memory>
#include <vector>

namespace dhpd::distributed {

/// MPI's lifetime in a process: initialised by the constructor, finalised by the destructor.
/// Only a process started by mpirun (or srun) creates one; a plain `dhpd run` never touches MPI.
class MpiSession {
 public:
  MpiSession(int& argc, char**& argv);
  ~MpiSession();
  MpiSession(const MpiSession&) = delete;
  MpiSession& operator=(const MpiSession&) = delete;
  /// Whether the environment says this process is one rank of an MPI launch (the variables
  /// OpenMPI, MPICH/Hydra, PMIx and Slurm set).
  static bool launched_by_mpirun();
};

/// The ranks of MPI_COMM_WORLD. Every call is collective unless said otherwise: each rank must
/// make the same calls in the same order.
class Communicator {
 public:
  /// The world communicator (an MpiSession must be alive).
  static std::shared_ptr<const Communicator> world();
  /// One rank without MPI (a process mpirun did not start: MPI is never called).
  static std::shared_ptr<const Communicator> solo() {
    return std::shared_ptr<const Communicator>(new Communicator(0, 1));
  }
  int rank() const { return rank_; }
  int size() const { return size_; }
  bool root() const { return rank_ == 0; }

  /// Rank 0's value on every rank.
  void broadcast(std::int64_t& value) const;
  void broadcast(std::vector<double>& values) const;  ///< sizes must already agree
  /// Σ over ranks (integers: exact, the same on every rank).
  std::int64_t sum(std::int64_t value) const;
  /// The largest value over ranks.
  double max(double value) const;
  /// Every rank's `mine` concatenated in rank order into `all`, whose size must be the sum of
  /// `counts` (counts[r]: the values rank r sends; the same vector on every rank).
  void all_gather(const std::vector<double>& mine, const std::vector<int>& counts,
                  std::vector<double>& all) const;
  void all_gather(const std::vector<std::int32_t>& mine, const std::vector<int>& counts,
                  std::vector<std::int32_t>& all) const;
  void all_gather(const std::vector<std::uint8_t>& mine, const std::vector<int>& counts,
                  std::vector<std::uint8_t>& all) const;
  /// Every rank's one value, in rank order.
  std::vector<std::int64_t> all_gather(std::int64_t value) const;
  /// Stops every rank at once (after an error one rank met alone), with `code`.
  [[noreturn]] void abort(int code) const;

 private:
  Communicator(int rank, int size) : rank_(rank), size_(size) {}
  int rank_ = 0, size_ = 1;
};

}  // namespace dhpd::distributed

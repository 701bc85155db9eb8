// Which rank owns which particle (docs/theory.md §25.2): Zoltan's geometric partitioners, each
// particle weighted by the bond entries its row holds (the work of its force pass).
#pragma once
#include <cstdint>
#include <memory>
#include <string_view>
#include <vector>

#include "engine/distributed/communicator.hpp"

namespace dhpd::distributed {

/// Zoltan's recursive coordinate bisection (cuts along axes) or Hilbert space-filling curve.
enum class PartitionMethod { Rcb, Hsfc };
/// "rcb" / "hsfc".
std::string_view name_of(PartitionMethod m);

/// When ranks take new owners (docs/theory.md §25.3). Imbalance: new particles go where the kept
/// cuts put them, and Zoltan cuts again once the largest rank's work exceeds the mean by
/// kRepartitionImbalance; Events: Zoltan cuts after every refinement event; Steps: before every
/// step as well (a stress test of the cuts, not a setting for production).
enum class RepartitionPolicy { Imbalance, Events, Steps };
inline constexpr double kRepartitionImbalance = 1.1;

/// The owner of every particle, with what the cut cost.
struct Partition {
  std::vector<std::int32_t> owner;  ///< rank per slot
  /// Largest rank weight over the mean (1 is perfect balance).
  double imbalance = 1.0;
  double seconds = 0.0;  ///< wall time of the Zoltan call (this rank's)
  PartitionMethod method = PartitionMethod::Rcb;
};

/// Largest rank's Σ weight over the mean.
double imbalance_of(const std::vector<std::int32_t>& owner, const std::vector<double>& weight,
                    int ranks);

/// A Zoltan instance of the communicator's ranks, keeping the cuts of its last partition.
class Partitioner {
 public:
  Partitioner(std::shared_ptr<const Communicator> comm, PartitionMethod method);
  ~Partitioner();
  Partitioner(const Partitioner&) = delete;
  Partitioner& operator=(const Partitioner&) = delete;
  PartitionMethod method() const { return method_; }

  /// Partitions the particles with positions `xyz` (3 per particle, the same on every rank) and
  /// weights `weight`. Collective; every rank gets the same owners. Each rank hands Zoltan the
  /// slots [r·n/P, (r+1)·n/P) and the answer is gathered, so the result depends only on the
  /// inputs and the rank count.
  Partition partition(int dim, const std::vector<double>& xyz, const std::vector<double>& weight);
  /// The rank the last partition's cuts give a point (no communication; the same on every rank).
  std::int32_t assign(const double xyz[3]) const;

 private:
  struct Zoltan;
  std::shared_ptr<const Communicator> comm_;
  PartitionMethod method_;
  std::unique_ptr<Zoltan> zoltan_;
};

}  // namespace dhpd::distributed

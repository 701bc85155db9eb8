// Replicated data, shared force pass (docs/theory.md §25.1): every rank holds the whole state and
// integrates every particle with the same arithmetic; rank r computes the force pass of the rows
// it owns, and every rank then receives the owned rows' results. A row's force, breaks and damage
// depend only on the positions (the same bits on every rank), so the run gives the serial run's
// bits for any rank count.
#pragma once
#include <cstdint>
#include <memory>
#include <vector>

#include "engine/discretization/bonds.hpp"
#include "engine/discretization/particles.hpp"
#include "engine/distributed/communicator.hpp"
#include "engine/distributed/partition.hpp"

namespace dhpd {
struct BondConstants;
}

namespace dhpd::distributed {

/// `width` values per particle at data[width·i ...] (a per-particle tensor, or 1 for a field).
struct FieldView {
  double* data;
  int width;
};

/// What rank 0 asks the other ranks to do next (they wait for it in Simulation::serve).
enum class Command : std::int64_t {
  Step = 1,
  StepWithEnergy = 2,
  ShareBonds = 3,
  Edit = 4,  ///< the caller's edit of the discretisation (a refinement check), on every rank
  Stop = 5
};

class ForceShare {
 public:
  ForceShare(std::shared_ptr<const Communicator> comm, PartitionMethod method,
             RepartitionPolicy policy);
  const Communicator& comm() const { return *comm_; }
  RepartitionPolicy policy() const { return policy_; }
  PartitionMethod method() const { return partitioner_.method(); }
  /// This rank's rows, ascending.
  const std::vector<std::int32_t>& owned() const { return owned_; }
  /// The owner of every slot.
  const std::vector<std::int32_t>& owner() const { return owner_; }

  /// Zoltan cuts the particles anew (collective): positions `xyz` (3 per slot), weights, ids.
  void repartition(int dim, const std::vector<double>& xyz, const std::vector<double>& weight,
                   const std::vector<std::int32_t>& id);
  /// After an edit appended slots [old_size, n): they go where the kept cuts put them (the slots
  /// below keep their owner: a parent's first child takes its slot), and Zoltan cuts anew when
  /// the policy says so or the imbalance exceeds kRepartitionImbalance. Collective.
  void after_edit(std::size_t old_size, int dim, const std::vector<double>& xyz,
                  const std::vector<double>& weight, const std::vector<std::int32_t>& id);
  /// The slots were renumbered: new slot k holds what slot order[k] held.
  void renumbered(const std::vector<std::int32_t>& order);

  /// Rank 0 tells the others what comes next; the others receive it (collective).
  Command announce(Command c) const;

  /// After a force pass over the owned rows: every rank gets every owned row's force density
  /// (the first `dim` axes), and, when given, its damage and row energy. Returns the sum of
  /// `broken` over ranks (each rank's bonds broken by its rows).
  std::int64_t share_pass(int dim, VectorArray& force, std::vector<double>* damage,
                          std::vector<double>* row_energy, std::int64_t broken);
  /// Every rank gets each owned row's value of every field (each sized to the store), and the
  /// sum of `broken` over ranks.
  std::int64_t share_values(const std::vector<FieldView>& fields, std::int64_t broken);
  /// share_pass for the rows of `rows` alone (a time level's rows, the same list on every rank):
  /// each rank computed the ones it owns (owned_of).
  std::int64_t share_rows(const std::vector<std::int32_t>& rows, int dim, VectorArray& force,
                          std::vector<double>* damage, std::int64_t broken);
  /// The rows of `rows` this rank owns, in their order.
  void owned_of(const std::vector<std::int32_t>& rows, std::vector<std::int32_t>& out) const;
  /// Every rank gets every row's bond flags from the rank that owns the row; entries whose flags
  /// changed get their stiffness derived again.
  void share_bond_states(BondRows& rows, const BondConstants& c);

  /// What the decomposition did so far (the summary and `dhpd bench --mpi` report it).
  struct Stats {
    std::int64_t values_shared = 0;  ///< values gathered (8 or 1 bytes each)
    double exchange_seconds = 0.0;   ///< in the gathers, waiting for the slowest rank included
    std::int64_t repartitions = 0;   ///< Zoltan cuts, the first included
    std::int64_t moved = 0;          ///< particles that changed owner at the cuts after the first
    double partition_seconds = 0.0;  ///< in Zoltan
    double imbalance = 1.0;          ///< largest rank's bond entries over the mean, now
  };
  const Stats& stats() const { return stats_; }

 private:
  /// owner_ changed: the owned rows and the gather order follow.
  void owners_changed(const std::vector<double>& weight);
  std::shared_ptr<const Communicator> comm_;
  Partitioner partitioner_;
  RepartitionPolicy policy_;
  std::vector<std::int32_t> owner_, owned_;
  std::vector<std::int32_t> owner_of_id_;   ///< by particle id (−1: no such particle now)
  std::vector<std::int32_t> gather_order_;  ///< rank 0's rows, then rank 1's, ...
  std::vector<int> rows_per_rank_;
  std::vector<double> send_, receive_;
  std::vector<std::uint8_t> flags_send_, flags_receive_;
  std::vector<std::vector<std::int32_t>> by_rank_;  ///< share_rows scratch
  Stats stats_;
};

}  // namespace dhpd::distributed

// A run on several MPI ranks: replicated data with a shared force pass (docs/theory.md §25).
#include <fmt/core.h>

#include "engine/base/errors.hpp"
#include "engine/physics/bond_loops.hpp"
#include "engine/simulation.hpp"

namespace dhpd {

void Simulation::distribute(std::shared_ptr<const distributed::Communicator> comm,
                            distributed::PartitionMethod method,
                            distributed::RepartitionPolicy policy) {
  if (comm->size() == 1) return;
  const std::size_t n = p_.size();
  if (n < static_cast<std::size_t>(comm->size()))
    throw InputError(fmt::format(
        "{} ranks for {} particles: every rank needs at least one particle (use -np {} or fewer)",
        comm->size(), n, n));
  auto t = timers_.scope(Phase::Search);
  share_ = std::make_unique<distributed::ForceShare>(std::move(comm), method, policy);
  const auto in = partition_input();
  share_->repartition(p_.dim(), in.xyz, in.weight, in.id);
}

Simulation::PartitionInput Simulation::partition_input() const {
  const std::size_t n = p_.size();
  PartitionInput in;
  in.xyz.resize(3 * n);
  in.weight.resize(n);
  in.id.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    for (int a = 0; a < 3; ++a) in.xyz[3 * i + a] = p_.position[a][i];
    in.weight[i] = 1.0 + bonds_.rows.count[i];  // the row's entries, and the particle's own work
    in.id[i] = p_.id[i];
  }
  return in;
}

void Simulation::distributed_forces(bool with_fracture, std::vector<double>* row_energy,
                                    const SideTask* side) {
  const auto& rows = share_->owned();
  std::int64_t broke = 0;
  if (with_fracture)
    broke = force_and_break(bonds_, p_, bond_constants(), row_energy, &kernel_points_, side, &rows);
  else
    internal_force_density(bonds_, p_, &rows, row_energy, &kernel_points_, side);
  broken_ += share_->share_pass(p_.dim(), p_.force_density, with_fracture ? &p_.damage : nullptr,
                                row_energy, broke);
}

void Simulation::distributed_state_forces(bool with_fracture) {
  const auto& rows = share_->owned();
  const std::int64_t broke = with_fracture ? break_bonds(bonds_, p_, bond_constants(), &rows) : 0;
  state_->forces(bonds_, p_, &rows, [&] {
    std::vector<distributed::FieldView> fields;
    for (auto* field : state_->pass_fields()) fields.push_back({field->data(), 1});
    if (with_fracture) fields.push_back({p_.damage.data(), 1});
    broken_ += share_->share_values(fields, broke);
  });
  share_->share_pass(p_.dim(), p_.force_density, nullptr, nullptr, 0);
}

void Simulation::distributed_correspondence_forces() {
  correspondence_->forces(bonds_, p_, &share_->owned(), [&] {
    std::vector<distributed::FieldView> fields;
    for (const auto& [data, width] : correspondence_->pass_fields())
      fields.push_back({data, width});
    share_->share_values(fields, 0);
  });
  share_->share_pass(p_.dim(), p_.force_density, nullptr, nullptr, 0);
}

void Simulation::serve(const std::function<void()>& edit, const EditTask* between_relaxations) {
  if (!share_ || share_->comm().root()) return;
  using distributed::Command;
  for (;;) {
    const Command c = share_->announce(Command::Stop);  // rank 0's word
    if (c == Command::Stop) return;
    if (c == Command::ShareBonds) {
      bonds_shared_ = false;
      share_bond_states();
      continue;
    }
    try {
      if (c == Command::Edit) {
        if (!edit) throw EngineError("rank 0 announced an edit this rank has no editor for");
        edit();
        continue;
      }
      step({.strain_energy = c == Command::StepWithEnergy,
            .between_relaxations = between_relaxations});
    } catch (const InstabilityError&) {
      // The same bits on rank 0 met the same check: it reports, this rank waits for its word.
    } catch (const StoppedByRankZero&) {
      // Rank 0 refused what it was about to do (this rank's state is unchanged): its word next.
    }
  }
}

void Simulation::announce_edit() {
  if (!share_ || !share_->comm().root()) return;
  share_bond_states();
  share_->announce(distributed::Command::Edit);
}

bool Simulation::agree(bool verdict) const {
  if (!share_) return verdict;
  std::int64_t value = verdict ? 1 : 0;
  share_->comm().broadcast(value);
  return value != 0;
}

void Simulation::release_ranks() {
  if (!share_ || !share_->comm().root() || released_) return;
  released_ = true;
  share_->announce(distributed::Command::Stop);
}

void Simulation::share_bond_states() {
  if (!share_ || bonds_shared_) return;
  if (share_->comm().root()) share_->announce(distributed::Command::ShareBonds);
  share_->share_bond_states(bonds_, bond_constants());
  bonds_shared_ = true;
}

}  // namespace dhpd

// Replicated data with a shared force pass (docs/theory.md §25.1).
#include "engine/distributed/force_share.hpp"

#include <algorithm>
#include <chrono>

#include "engine/base/errors.hpp"
#include "engine/physics/interactions.hpp"

namespace dhpd::distributed {
namespace {
double seconds_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}
}  // namespace

ForceShare::ForceShare(std::shared_ptr<const Communicator> comm, PartitionMethod method,
                       RepartitionPolicy policy)
    : comm_(comm), partitioner_(std::move(comm), method), policy_(policy) {}

void ForceShare::repartition(int dim, const std::vector<double>& xyz,
                             const std::vector<double>& weight,
                             const std::vector<std::int32_t>& id) {
  auto p = partitioner_.partition(dim, xyz, weight);
  std::int32_t largest = 0;
  for (const auto i : id) largest = std::max(largest, i);
  std::vector<std::int32_t> by_id(static_cast<std::size_t>(largest) + 1, -1);
  std::int64_t moved = 0;
  for (std::size_t i = 0; i < id.size(); ++i) {
    const auto k = static_cast<std::size_t>(id[i]);
    if (k < owner_of_id_.size() && owner_of_id_[k] >= 0 && owner_of_id_[k] != p.owner[i]) ++moved;
    by_id[k] = p.owner[i];
  }
  if (stats_.repartitions > 0) stats_.moved += moved;
  ++stats_.repartitions;
  stats_.partition_seconds += p.seconds;
  owner_of_id_ = std::move(by_id);
  owner_ = std::move(p.owner);
  owners_changed(weight);
}

void ForceShare::after_edit(std::size_t old_size, int dim, const std::vector<double>& xyz,
                            const std::vector<double>& weight,
                            const std::vector<std::int32_t>& id) {
  const std::size_t n = weight.size();
  if (policy_ != RepartitionPolicy::Imbalance || old_size > owner_.size()) {
    repartition(dim, xyz, weight, id);
    return;
  }
  owner_.resize(n);
  for (std::size_t i = old_size; i < n; ++i) owner_[i] = partitioner_.assign(&xyz[3 * i]);
  if (imbalance_of(owner_, weight, comm_->size()) > kRepartitionImbalance) {
    repartition(dim, xyz, weight, id);
    return;
  }
  std::int32_t largest = 0;
  for (const auto i : id) largest = std::max(largest, i);
  owner_of_id_.assign(static_cast<std::size_t>(largest) + 1, -1);
  for (std::size_t i = 0; i < n; ++i) owner_of_id_[static_cast<std::size_t>(id[i])] = owner_[i];
  owners_changed(weight);
}

void ForceShare::renumbered(const std::vector<std::int32_t>& order) {
  std::vector<std::int32_t> owner(order.size());
  std::vector<double> weight(order.size(), 1.0);  // the imbalance is kept as it was
  for (std::size_t k = 0; k < order.size(); ++k)
    owner[k] = owner_.at(static_cast<std::size_t>(order[k]));
  owner_ = std::move(owner);
  const double imbalance = stats_.imbalance;
  owners_changed(weight);
  stats_.imbalance = imbalance;
}

void ForceShare::owners_changed(const std::vector<double>& weight) {
  const auto ranks = static_cast<std::size_t>(comm_->size());
  rows_per_rank_.assign(ranks, 0);
  std::vector<std::vector<std::int32_t>> by_rank(ranks);
  for (std::size_t i = 0; i < owner_.size(); ++i)
    by_rank[static_cast<std::size_t>(owner_[i])].push_back(static_cast<std::int32_t>(i));
  gather_order_.clear();
  for (std::size_t r = 0; r < ranks; ++r) {
    rows_per_rank_[r] = static_cast<int>(by_rank[r].size());
    gather_order_.insert(gather_order_.end(), by_rank[r].begin(), by_rank[r].end());
  }
  owned_ = std::move(by_rank[static_cast<std::size_t>(comm_->rank())]);
  stats_.imbalance = imbalance_of(owner_, weight, comm_->size());
}

Command ForceShare::announce(Command c) const {
  auto value = static_cast<std::int64_t>(c);
  comm_->broadcast(value);
  return static_cast<Command>(value);
}

std::int64_t ForceShare::share_pass(int dim, VectorArray& force, std::vector<double>* damage,
                                    std::vector<double>* row_energy, std::int64_t broken) {
  std::vector<FieldView> fields;
  for (int a = 0; a < dim; ++a) fields.push_back({force[a].data(), 1});
  if (damage) fields.push_back({damage->data(), 1});
  if (row_energy) {
    row_energy->resize(force[0].size());
    fields.push_back({row_energy->data(), 1});
  }
  return share_values(fields, broken);
}

std::int64_t ForceShare::share_values(const std::vector<FieldView>& fields, std::int64_t broken) {
  // Each rank's block: its count, then per owned row the values of each field.
  std::size_t width = 0;
  for (const auto& f : fields) width += static_cast<std::size_t>(f.width);
  send_.clear();
  send_.push_back(static_cast<double>(broken));  // exact: far below 2^53
  for (const auto i : owned_)
    for (const auto& f : fields)
      for (int c = 0; c < f.width; ++c)
        send_.push_back(
            f.data[static_cast<std::size_t>(f.width) * static_cast<std::size_t>(i) + c]);
  std::vector<int> counts(rows_per_rank_.size());
  for (std::size_t r = 0; r < counts.size(); ++r)
    counts[r] = 1 + static_cast<int>(width) * rows_per_rank_[r];
  receive_.resize(gather_order_.size() * width + counts.size());
  const auto start = std::chrono::steady_clock::now();
  comm_->all_gather(send_, counts, receive_);
  stats_.exchange_seconds += seconds_since(start);
  stats_.values_shared += static_cast<std::int64_t>(receive_.size());
  std::int64_t total = 0;
  std::size_t at = 0, row = 0;
  for (std::size_t r = 0; r < counts.size(); ++r) {
    total += static_cast<std::int64_t>(receive_[at++]);
    for (int k = 0; k < rows_per_rank_[r]; ++k, ++row) {
      const auto i = static_cast<std::size_t>(gather_order_[row]);
      for (const auto& f : fields)
        for (int c = 0; c < f.width; ++c)
          f.data[static_cast<std::size_t>(f.width) * i + c] = receive_[at++];
    }
  }
  return total;
}

void ForceShare::owned_of(const std::vector<std::int32_t>& rows,
                          std::vector<std::int32_t>& out) const {
  out.clear();
  for (const auto i : rows)
    if (owner_[static_cast<std::size_t>(i)] == comm_->rank()) out.push_back(i);
}

std::int64_t ForceShare::share_rows(const std::vector<std::int32_t>& rows, int dim,
                                    VectorArray& force, std::vector<double>* damage,
                                    std::int64_t broken) {
  const auto ranks = static_cast<std::size_t>(comm_->size());
  by_rank_.resize(ranks);
  for (auto& list : by_rank_) list.clear();
  for (const auto i : rows)
    by_rank_[static_cast<std::size_t>(owner_[static_cast<std::size_t>(i)])].push_back(i);
  const int width = dim + (damage ? 1 : 0);
  send_.clear();
  send_.push_back(static_cast<double>(broken));
  for (const auto i : by_rank_[static_cast<std::size_t>(comm_->rank())]) {
    for (int a = 0; a < dim; ++a) send_.push_back(force[a][i]);
    if (damage) send_.push_back((*damage)[i]);
  }
  std::vector<int> counts(ranks);
  for (std::size_t r = 0; r < ranks; ++r)
    counts[r] = 1 + width * static_cast<int>(by_rank_[r].size());
  receive_.resize(rows.size() * static_cast<std::size_t>(width) + ranks);
  const auto start = std::chrono::steady_clock::now();
  comm_->all_gather(send_, counts, receive_);
  stats_.exchange_seconds += seconds_since(start);
  stats_.values_shared += static_cast<std::int64_t>(receive_.size());
  std::int64_t total = 0;
  std::size_t at = 0;
  for (std::size_t r = 0; r < ranks; ++r) {
    total += static_cast<std::int64_t>(receive_[at++]);
    for (const auto i : by_rank_[r]) {
      for (int a = 0; a < dim; ++a) force[a][i] = receive_[at++];
      if (damage) (*damage)[i] = receive_[at++];
    }
  }
  return total;
}

void ForceShare::share_bond_states(BondRows& b, const BondConstants& c) {
  if (b.rows.rows() != owner_.size())
    throw EngineError("ForceShare: the rows changed since the partition");
  flags_send_.clear();
  for (const auto i : owned_)
    flags_send_.insert(flags_send_.end(), b.flags.begin() + b.begin(i), b.flags.begin() + b.end(i));
  std::vector<int> counts(rows_per_rank_.size(), 0);
  std::size_t row = 0;
  for (std::size_t r = 0; r < counts.size(); ++r)
    for (int k = 0; k < rows_per_rank_[r]; ++k, ++row)
      counts[r] += b.rows.count[static_cast<std::size_t>(gather_order_[row])];
  std::size_t total = 0;
  for (const auto n : counts) total += static_cast<std::size_t>(n);
  flags_receive_.resize(total);
  const auto start = std::chrono::steady_clock::now();
  comm_->all_gather(flags_send_, counts, flags_receive_);
  stats_.exchange_seconds += seconds_since(start);
  stats_.values_shared += static_cast<std::int64_t>(total);
  std::size_t at = 0;
  for (const auto i32 : gather_order_) {
    const auto i = static_cast<std::size_t>(i32);
    for (auto k = b.begin(i); k < b.end(i); ++k, ++at)
      if (b.flags[k] != flags_receive_[at]) {
        b.flags[k] = flags_receive_[at];
        b.stiffness[k] = entry_stiffness(b, c, i, k);
      }
  }
}

}  // namespace dhpd::distributed

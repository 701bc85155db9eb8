// Zoltan's geometric partitioning of the particles (docs/theory.md §25.2): the only file that
// includes zoltan.h.
#include "engine/distributed/partition.hpp"

#include <fmt/core.h>
#include <mpi.h>
#include <zoltan.h>
#include <algorithm>
#include <chrono>
#include <numeric>

#include "engine/base/errors.hpp"

namespace dhpd::distributed {
namespace {

/// What Zoltan's query functions read: this rank's slots [begin, end).
struct Objects {
  int dim;
  std::size_t begin, end;
  const std::vector<double>* xyz;
  const std::vector<double>* weight;
};

int object_count(void* data, int* ierr) {
  const auto* o = static_cast<Objects*>(data);
  *ierr = ZOLTAN_OK;
  return static_cast<int>(o->end - o->begin);
}

void object_list(void* data, int, int, ZOLTAN_ID_PTR global, ZOLTAN_ID_PTR local, int weights,
                 float* w, int* ierr) {
  const auto* o = static_cast<Objects*>(data);
  for (std::size_t i = o->begin; i < o->end; ++i) {
    const auto k = i - o->begin;
    global[k] = static_cast<ZOLTAN_ID_TYPE>(i);
    local[k] = static_cast<ZOLTAN_ID_TYPE>(k);
    if (weights > 0) w[k] = static_cast<float>((*o->weight)[i]);
  }
  *ierr = ZOLTAN_OK;
}

int geometry_dim(void* data, int* ierr) {
  *ierr = ZOLTAN_OK;
  return static_cast<Objects*>(data)->dim;
}

void geometry(void* data, int, int, int count, ZOLTAN_ID_PTR global, ZOLTAN_ID_PTR, int dim,
              double* out, int* ierr) {
  const auto* o = static_cast<Objects*>(data);
  for (int k = 0; k < count; ++k)
    for (int a = 0; a < dim; ++a)
      out[k * dim + a] = (*o->xyz)[3 * static_cast<std::size_t>(global[k]) + a];
  *ierr = ZOLTAN_OK;
}

void zoltan_check(int status, const char* call) {
  if (status != ZOLTAN_OK && status != ZOLTAN_WARN)
    throw EngineError(fmt::format("Zoltan: {} failed (status {})", call, status));
}

void set_parameters(Zoltan_Struct* zz, PartitionMethod m) {
  for (const auto& [key, value] : {std::pair{"DEBUG_LEVEL", "0"},
                                   {"LB_METHOD", m == PartitionMethod::Rcb ? "RCB" : "HSFC"},
                                   {"LB_APPROACH", "PARTITION"},
                                   {"NUM_GID_ENTRIES", "1"},
                                   {"NUM_LID_ENTRIES", "1"},
                                   {"OBJ_WEIGHT_DIM", "1"},
                                   {"RETURN_LISTS", "EXPORT"},
                                   {"IMBALANCE_TOL", "1.02"},
                                   {"KEEP_CUTS", "1"}})
    zoltan_check(Zoltan_Set_Param(zz, key, value), key);
}
}  // namespace

struct Partitioner::Zoltan {
  Zoltan_Struct* zz = nullptr;
  ~Zoltan() { Zoltan_Destroy(&zz); }
};

std::string_view name_of(PartitionMethod m) {
  return m == PartitionMethod::Rcb ? "rcb" : "hsfc";
}

double imbalance_of(const std::vector<std::int32_t>& owner, const std::vector<double>& weight,
                    int ranks) {
  std::vector<double> load(static_cast<std::size_t>(ranks), 0.0);
  for (std::size_t i = 0; i < owner.size(); ++i) {
    const auto o = owner[i];
    if (o < 0 || o >= ranks)
      throw EngineError(fmt::format("particle {} is on rank {} of {}", i, o, ranks));
    load[static_cast<std::size_t>(o)] += weight[i];
  }
  const double total = std::accumulate(load.begin(), load.end(), 0.0);
  return total > 0 ? *std::max_element(load.begin(), load.end()) * ranks / total : 1.0;
}

Partitioner::Partitioner(std::shared_ptr<const Communicator> comm, PartitionMethod method)
    : comm_(std::move(comm)), method_(method), zoltan_(std::make_unique<Zoltan>()) {
  if (comm_->size() == 1) return;
  float version = 0.0f;
  zoltan_check(Zoltan_Initialize(0, nullptr, &version), "Zoltan_Initialize");
  zoltan_->zz = Zoltan_Create(MPI_COMM_WORLD);
  if (!zoltan_->zz) throw EngineError("Zoltan_Create failed");
  set_parameters(zoltan_->zz, method_);
}

Partitioner::~Partitioner() = default;

Partition Partitioner::partition(int dim, const std::vector<double>& xyz,
                                 const std::vector<double>& weight) {
  const std::size_t n = weight.size();
  const auto ranks = static_cast<std::size_t>(comm_->size());
  Partition out;
  out.method = method_;
  if (ranks == 1) {
    out.owner.assign(n, 0);
    return out;
  }
  const auto start = std::chrono::steady_clock::now();
  const auto r = static_cast<std::size_t>(comm_->rank());
  Objects o{dim, r * n / ranks, (r + 1) * n / ranks, &xyz, &weight};
  Zoltan_Struct* zz = zoltan_->zz;
  Zoltan_Set_Num_Obj_Fn(zz, object_count, &o);
  Zoltan_Set_Obj_List_Fn(zz, object_list, &o);
  Zoltan_Set_Num_Geom_Fn(zz, geometry_dim, &o);
  Zoltan_Set_Geom_Multi_Fn(zz, geometry, &o);
  int changes = 0, gid = 0, lid = 0, imports = 0, exports = 0;
  ZOLTAN_ID_PTR import_global = nullptr, import_local = nullptr, export_global = nullptr,
                export_local = nullptr;
  int *import_procs = nullptr, *import_parts = nullptr, *export_procs = nullptr,
      *export_parts = nullptr;
  zoltan_check(Zoltan_LB_Partition(zz, &changes, &gid, &lid, &imports, &import_global,
                                   &import_local, &import_procs, &import_parts, &exports,
                                   &export_global, &export_local, &export_procs, &export_parts),
               "Zoltan_LB_Partition");
  std::vector<std::int32_t> mine(o.end - o.begin, comm_->rank());
  for (int k = 0; k < exports; ++k)
    mine[static_cast<std::size_t>(export_local[k])] = export_parts[k];
  Zoltan_LB_Free_Part(&import_global, &import_local, &import_procs, &import_parts);
  Zoltan_LB_Free_Part(&export_global, &export_local, &export_procs, &export_parts);
  std::vector<int> counts(ranks);
  for (std::size_t k = 0; k < ranks; ++k)
    counts[k] = static_cast<int>((k + 1) * n / ranks - k * n / ranks);
  out.owner.assign(n, 0);
  comm_->all_gather(mine, counts, out.owner);
  out.imbalance = imbalance_of(out.owner, weight, comm_->size());
  out.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return out;
}

std::int32_t Partitioner::assign(const double xyz[3]) const {
  if (comm_->size() == 1) return 0;
  double point[3] = {xyz[0], xyz[1], xyz[2]};
  int proc = 0, part = 0;
  zoltan_check(Zoltan_LB_Point_PP_Assign(zoltan_->zz, point, &proc, &part),
               "Zoltan_LB_Point_PP_Assign");
  return part;
}

}  // namespace dhpd::distributed

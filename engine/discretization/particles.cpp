// Field registry of the particle store.
#include "engine/discretization/particles.hpp"

#include <type_traits>

namespace dhpd {

std::size_t ParticleStore::bytes() const {
  std::size_t total = 0;
  // fields() hands out writable pointers; here they are only read.
  for (const auto& f : const_cast<ParticleStore*>(this)->fields())
    std::visit(
        [&](const auto* arr) {
          using T = std::remove_cv_t<std::remove_pointer_t<decltype(arr)>>;
          if constexpr (std::is_same_v<T, VectorArray>) {
            for (const auto& c : *arr) total += c.capacity() * sizeof(double);
          } else {
            total += arr->capacity() * sizeof(typename T::value_type);
          }
        },
        f.data);
  return total;
}

std::vector<FieldInfo> ParticleStore::fields() {
  using G = FieldGroup;
  using S = SplitRule;
  using E = Export;
  // Exported fields first, in the order frames hold them.
  return {
      {"displacement", G::State, S::Copy, E::Always, "m", "displacement u = y - X", &displacement},
      {"velocity", G::State, S::Copy, E::Always, "m/s", "velocity", &velocity},
      {"damage", G::State, S::Copy, E::Always, "1",
       "broken share of the own bonds' volume (0 intact, 1 every bond broken)", &damage},
      {"horizon", G::Geometry, S::FromPattern, E::Always, "m", "horizon radius delta", &horizon},
      {"volume", G::Geometry, S::Shared, E::Always, "m^3",
       "particle volume (2D: area x thickness; 1D: length x area)", &volume},
      {"spacing", G::Geometry, S::FromPattern, E::Always, "m",
       "particle spacing dx (lattice spacing, or a mesh node's equivalent diameter)", &spacing},
      {"material", G::Geometry, S::Copy, E::Always, "-",
       "material index, in the order of the scene's materials", &material},
      {"id", G::Geometry, S::FromPattern, E::Always, "-",
       "particle id, unique through the run (a split makes new ones)", &id},
      {"level", G::Geometry, S::FromPattern, E::Always, "-",
       "refinement level: 0 for the scene's particles, +1 per split", &level},
      {"parent_id", G::Geometry, S::FromPattern, E::Always, "-",
       "id of the particle this one was split from (-1 for the scene's)", &parent_id},
      {"force_density", G::State, S::Reset, E::OnRequest, "N/m^3",
       "internal plus external force per unit volume", &force_density},
      {"no_fail", G::Geometry, S::Copy, E::OnRequest, "-",
       "1 where the own bonds never break (no_fail regions)", &no_fail},
      {"reference_position", G::Geometry, S::FromPattern, E::Never, "m",
       "reference position X (a frame's points)", &reference_position},
      {"density", G::Geometry, S::Copy, E::Never, "kg/m^3", "mass density", &density},
      {"radius", G::Geometry, S::FromPattern, E::Never, "m",
       "radius of the interval, disk or ball of the particle's cell measure", &radius},
      {"position", G::State, S::FromPattern, E::Never, "m", "current position y = X + u",
       &position},
  };
}

void ParticleStore::resize(std::size_t n) {
  for (auto& f : fields()) {
    std::visit(
        [n](auto* arr) {
          using T = std::remove_pointer_t<decltype(arr)>;
          if constexpr (std::is_same_v<T, VectorArray>) {
            for (auto& c : *arr) c.resize(n, 0.0);
          } else {
            arr->resize(n, 0);
          }
        },
        f.data);
  }
}

ParticleStore gather(ParticleStore& p, const std::vector<std::int32_t>& indices) {
  ParticleStore out(p.dim());
  out.resize(indices.size());
  auto src = p.fields();
  auto dst = out.fields();
  for (std::size_t f = 0; f < src.size(); ++f)
    std::visit(
        [&](auto* from) {
          using T = std::remove_pointer_t<decltype(from)>;
          T* to = std::get<T*>(dst[f].data);
          auto copy = [&](auto& o, const auto& in) {
            for (std::size_t k = 0; k < indices.size(); ++k)
              o[k] = in[static_cast<std::size_t>(indices[k])];
          };
          if constexpr (std::is_same_v<T, VectorArray>) {
            for (int a = 0; a < 3; ++a) copy((*to)[a], (*from)[a]);
          } else {
            copy(*to, *from);
          }
        },
        src[f].data);
  return out;
}

void permute_slots(ParticleStore& p, const std::vector<std::int32_t>& order,
                   const std::vector<std::int32_t>& moved) {
  for (auto& field : p.fields())
    std::visit(
        [&](auto* data) {
          using T = std::remove_pointer_t<decltype(data)>;
          if constexpr (std::is_same_v<T, VectorArray>) {
            for (int a = 0; a < 3; ++a) move_slots((*data)[a], order, moved);
          } else {
            move_slots(*data, order, moved);
          }
        },
        field.data);
}

}  // namespace dhpd

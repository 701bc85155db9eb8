// Field registry of the particle store.
#include "engine/discretization/particles.hpp"

#include <type_traits>

namespace dhpd {

std::vector<FieldInfo> ParticleStore::fields() {
  using G = FieldGroup;
  using S = SplitRule;
  return {
      {"reference_position", G::Geometry, S::FromPattern, &reference_position},
      {"volume", G::Geometry, S::DivideByChildren, &volume},
      {"spacing", G::Geometry, S::FromPattern, &spacing},
      {"horizon", G::Geometry, S::FromPattern, &horizon},
      {"density", G::Geometry, S::Copy, &density},
      {"radius", G::Geometry, S::FromPattern, &radius},
      {"material", G::Geometry, S::Copy, &material},
      {"id", G::Geometry, S::FromPattern, &id},
      {"level", G::Geometry, S::FromPattern, &level},
      {"parent_id", G::Geometry, S::FromPattern, &parent_id},
      {"no_fail", G::Geometry, S::Copy, &no_fail},
      {"position", G::State, S::FromPattern, &position},
      {"displacement", G::State, S::Copy, &displacement},
      {"velocity", G::State, S::Copy, &velocity},
      {"force_density", G::State, S::Reset, &force_density},
      {"damage", G::State, S::Copy, &damage},
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

}  // namespace dhpd

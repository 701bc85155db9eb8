// Fictitious boundary layers (the Euler–Lagrange paper eqs. 27–32; the horizon-size paper eqs.
// 29–35; docs/theory.md §23): particles outside a flat face of the body, mirrored from the body's
// particles within one horizon of it, whose displacements follow the face's boundary condition
// before every force pass. They take part in the forces on the body; they are not integrated.
#pragma once
#include <array>
#include <cstdint>
#include <optional>
#include <vector>

#include "engine/discretization/particles.hpp"
#include "engine/discretization/section.hpp"
#include "engine/physics/material_law.hpp"
#include "geometry/vec.hpp"

namespace dhpd {

/// One layer, as the scene gives it: the face (axis, side) and its rule.
struct FictitiousLayerSpec {
  int axis = 0;
  int side = 1;  ///< +1: the body's largest coordinate along `axis`; −1: its smallest
  enum class Rule { Displacement, Traction };
  Rule rule = Rule::Displacement;
  /// Displacement: U* of each component (fixed: all 0); a component not given mirrors freely.
  std::array<std::optional<double>, 3> displacement;
  geometry::Vec3 traction{0, 0, 0};  ///< Traction: force per area on the face, Pa
  std::size_t condition = 0;         ///< its index in the scene's boundary conditions
  /// Generation indices of its particles in the setup's points (appended after the body's), and
  /// of the body particle each mirrors.
  std::vector<std::int32_t> points, mirrors;
};

/// A layer bound to slots: per layer particle its mirror, its boundary particle (the body particle
/// nearest the face on its line) and that particle's neighbours along each transverse axis on the
/// face (−1 where there is none), for the traction rule's tangential derivatives.
struct ResolvedLayer {
  FictitiousLayerSpec spec;
  std::vector<std::int32_t> particle, mirror, boundary;
  std::vector<std::array<std::int32_t, 6>> beside;  ///< (−, +) along each axis of the face
};

/// Binds `spec` to the slots of `p` (ids are generation indices).
ResolvedLayer resolve_layer(const FictitiousLayerSpec& spec, const ParticleStore& p);

/// Sets the layer's displacements (positions follow) from the body's at load factor `lambda`:
/// displacement rule u_f = 2λU* − u_m (a free component u_f = u_m); traction rule u_f = u_b +
/// (∂u/∂n)(x_f − x_b) with ∂u/∂n from Hooke's law and the face's traction (docs/theory.md §23).
void apply_layer(const ResolvedLayer& layer, double lambda, const std::vector<Material>& materials,
                 const Section& section, ParticleStore& p);

}  // namespace dhpd

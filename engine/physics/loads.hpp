// Initial conditions, prescribed motion and boundary tractions, resolved to particle lists.
#pragma once
#include <array>
#include <cstdint>
#include <optional>
#include <vector>

#include "engine/discretization/particles.hpp"
#include "geometry/shapes.hpp"

namespace dhpd {

using geometry::Vec3;

struct InitialCondition {
  geometry::Shape region;
  std::optional<Vec3> velocity;
  std::optional<Vec3> displacement;
  std::optional<Vec3> strain;  ///< u_a += strain_a · (X_a − origin_a): a uniform stretch
  Vec3 origin{0, 0, 0};
  /// Optional envelope exp(−|X − center|² / width²) multiplying velocity and displacement.
  std::optional<double> gaussian_width;
  Vec3 gaussian_center{0, 0, 0};
  int gaussian_axis = -1;  ///< ≥ 0: exp(−(X_a − center_a)² / width²), a plane pulse along axis a
};

/// A prescribed value over time (docs/theory.md §11): piecewise linear through (t, value) points
/// with increasing t, constant before the first and after the last. Empty: not time-dependent.
struct TimeFunction {
  std::vector<std::pair<double, double>> points;
  bool empty() const { return points.empty(); }
  double at(double t) const;
  bool operator==(const TimeFunction&) const = default;
};

struct BoundaryCondition {
  enum class Kind { Velocity, Fixed, Traction, Displacement };
  Kind kind = Kind::Fixed;
  geometry::Shape region;
  std::array<std::optional<double>, 3> velocity;  ///< prescribed components (Velocity)
  /// Prescribed components (Displacement), m: held there (dynamics), or reached in proportion to
  /// the load factor (statics, docs/theory.md §22).
  std::array<std::optional<double>, 3> displacement;
  /// Velocity or Displacement: per component, its value as a function of time (its entry above
  /// then holds the value at t = 0); in statics, of the load factor.
  std::array<TimeFunction, 3> in_time;
  Vec3 traction{0, 0, 0};  ///< Pa, spread as a body force over the layer (Traction)
  int normal_axis = 0;     ///< axis normal to the loaded face (Traction)
  /// ≥ 0: the condition acts through a fictitious layer outside the body's face on this axis (at
  /// its `layer_side`: +1 largest, −1 smallest coordinate; docs/theory.md §23), not on a region.
  int layer_axis = -1;
  int layer_side = 0;
};

/// ResolvedLoads::mask of a component held at a prescribed displacement (any non-zero value means
/// prescribed; 1 is a prescribed velocity, zero for fixed conditions).
inline constexpr std::uint8_t kHeldAt = 2;

/// Boundary conditions bound to particle indices for one particle numbering.
struct ResolvedLoads {
  std::vector<std::int32_t> prescribed;           ///< particles with prescribed velocity
  std::vector<std::array<std::uint8_t, 3>> mask;  ///< which components are prescribed
  std::vector<Vec3> prescribed_velocity;
  /// Per prescribed entry: the displacement its components are held at under the full load (0
  /// for fixed and velocity conditions).
  std::vector<Vec3> prescribed_displacement;
  /// Per prescribed entry: the boundary condition it comes from (−1: a fictitious layer's).
  std::vector<std::int32_t> condition;
  std::vector<std::int32_t> loaded;  ///< particles carrying a body force
  std::vector<Vec3> body_force;      ///< N/m³
  /// Per condition: the body force of a traction (fixed when resolved: the loaded layer keeps its
  /// depth when its cells are refined), zero for the others.
  std::vector<Vec3> condition_body_force;
};

/// Particles of `p` inside `region` (reference positions).
std::vector<std::int32_t> select(const ParticleStore& p, const geometry::Shape& region);

void apply_initial_condition(const InitialCondition& ic, ParticleStore& p);

/// Resolves every boundary condition; throws InputError naming the condition that selects nothing.
ResolvedLoads resolve_loads(const std::vector<BoundaryCondition>& bcs, const ParticleStore& p);

/// After an edit of the discretisation: particle successor[k] takes over the entries (a
/// traction's body force, a prescribed velocity) of the particle that had slot predecessor[k],
/// so refinement changes neither the total force of a traction nor which material is held. A
/// slot that is its own successor keeps its entries, which now mean the particle there.
void inherit_loads(ResolvedLoads& loads, const std::vector<std::int32_t>& successor,
                   const std::vector<std::int32_t>& predecessor);

/// Renumbers every entry: particle i becomes new_index[i].
void renumber_loads(ResolvedLoads& loads, const std::vector<std::int32_t>& new_index);

/// Sets the prescribed components' displacement to `factor` × their prescribed displacement, or
/// for a component with a function of time to its value at `time` (positions follow); velocity
/// conditions are left alone.
void apply_prescribed_displacement(const ResolvedLoads& loads,
                                   const std::vector<BoundaryCondition>& conditions, double factor,
                                   double time, ParticleStore& p);

/// The velocity each time-dependent component is held at over the step from t to t + dt: for a
/// displacement (u(t + dt) − u(t))/dt, so the step lands on u(t + dt); for a velocity v(t + dt/2).
void update_prescribed_velocity(ResolvedLoads& loads,
                                const std::vector<BoundaryCondition>& conditions, double t,
                                double dt);

/// The force the components that boundary condition `condition` holds take from their supports:
/// −Σ V f over those components (f the force density with body forces), N. Its particles are
/// those it held at the start and their children (a child may lie just outside the region).
Vec3 reaction_force(const ResolvedLoads& loads, const ParticleStore& p, std::int32_t condition);

/// Per particle of `n`: bit a set when axis a has a prescribed velocity.
std::vector<std::uint8_t> prescribed_axes(const ResolvedLoads& loads, std::size_t n);

}  // namespace dhpd

// The stepper's boundary conditions (docs/theory.md §11, §22, §23): prescribed velocities, the
// fictitious layers, reactions, sectional forces and the supports' work in the energy ledger.
#include <cmath>

#include "engine/simulation.hpp"

namespace dhpd {

void Simulation::enforce_prescribed_velocity() {
  for (std::size_t k = 0; k < loads_.prescribed.size(); ++k) {
    const auto i = loads_.prescribed[k];
    for (int a = 0; a < p_.dim(); ++a)
      if (loads_.mask[k][a]) p_.velocity[a][i] = loads_.prescribed_velocity[k][a];
  }
}

void Simulation::resolve_layers() {
  for (const auto& spec : setup_.layers) {
    layers_.push_back(resolve_layer(spec, p_));
    for (const auto i : layers_.back().particle) p_.no_fail[i] = 1;
  }
}

bool Simulation::apply_layers() {
  for (const auto& layer : layers_)
    apply_layer(layer, load_factor(), setup_.materials, setup_.section, p_);
  return !layers_.empty();
}

Vec3 Simulation::force_across(int axis, double at) const {
  Vec3 f{0, 0, 0};
  for (std::size_t i = 0; i < p_.size(); ++i)
    if (p_.reference_position[axis][i] < at)
      for (int a = 0; a < p_.dim(); ++a) f[a] += p_.volume[i] * p_.force_density[a][i];
  const double lambda = load_factor();
  for (std::size_t k = 0; k < loads_.loaded.size(); ++k) {
    const auto i = static_cast<std::size_t>(loads_.loaded[k]);
    if (p_.reference_position[axis][i] < at)
      for (int a = 0; a < p_.dim(); ++a) f[a] -= p_.volume[i] * lambda * loads_.body_force[k][a];
  }
  return f;
}

Vec3 Simulation::layer_reaction(std::size_t k) const {
  Vec3 r{0, 0, 0};
  for (const auto i : layers_.at(k).particle)
    for (int a = 0; a < p_.dim(); ++a) r[a] -= p_.volume[i] * p_.force_density[a][i];
  return r;
}

double Simulation::boundary_power() const {
  // A prescribed constant velocity needs a reaction −f_int (per volume) on each constrained
  // component; its power is that reaction times the velocity. (A static run integrates its held
  // components' work itself, held_work; fictitious layers' particles have no velocity.)
  double power = 0.0;
  if (setup_.statics) return power;
  for (std::size_t k = 0; k < loads_.prescribed.size(); ++k) {
    const auto i = loads_.prescribed[k];
    for (int a = 0; a < p_.dim(); ++a)
      if (loads_.mask[k][a])
        power -= p_.force_density[a][i] * p_.volume[i] * loads_.prescribed_velocity[k][a];
  }
  return power;
}

double Simulation::held_kinetic_energy() const {
  double energy = 0.0;
  for (std::size_t k = 0; k < loads_.prescribed.size(); ++k) {
    const auto i = loads_.prescribed[k];
    for (int a = 0; a < p_.dim(); ++a)
      if (loads_.mask[k][a])
        energy +=
            0.5 * p_.density[i] * p_.volume[i] * std::pow(loads_.prescribed_velocity[k][a], 2);
  }
  return energy;
}

Simulation::HeldState Simulation::held_state(std::size_t first) const {
  HeldState h;
  h.first = first;
  for (std::size_t k = first; k < loads_.prescribed.size(); ++k) {
    const auto i = loads_.prescribed[k];
    for (int a = 0; a < p_.dim(); ++a) {
      h.reaction.push_back(-p_.volume[i] * p_.force_density[a][i]);
      h.displacement.push_back(p_.displacement[a][i]);
    }
  }
  return h;
}

double Simulation::held_work(const HeldState& before) const {
  double work = 0.0;
  std::size_t c = 0;
  for (std::size_t k = before.first; k < loads_.prescribed.size(); ++k) {
    const auto i = loads_.prescribed[k];
    for (int a = 0; a < p_.dim(); ++a, ++c)
      if (loads_.mask[k][a])
        work += 0.5 * (before.reaction[c] - p_.volume[i] * p_.force_density[a][i]) *
                (p_.displacement[a][i] - before.displacement[c]);
  }
  return work;
}

}  // namespace dhpd

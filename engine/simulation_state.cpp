// The ordinary state-based family in the stepper (docs/theory.md §20): its constants for the
// current rows and its stable step.
#include <optional>

#include "engine/physics/stable_step.hpp"
#include "engine/physics/state_interfaces.hpp"
#include "engine/simulation.hpp"

namespace dhpd {

OrdinaryStateInputs Simulation::state_inputs() const {
  return {setup_.section,   setup_.model,      setup_.partial_volume,
          setup_.influence, &setup_.materials, setup_.surface_correction};
}

void Simulation::build_state_model() {
  if (setup_.family == ModelFamily::Correspondence)
    correspondence_.emplace(bonds_, p_, state_inputs());
  if (setup_.family != ModelFamily::OrdinaryState) return;
  state_.emplace(bonds_, p_, state_inputs());
}

InterfaceCorrection Simulation::correct_interfaces(const std::vector<std::int32_t>& region,
                                                   std::optional<OrdinaryState>* built) {
  if (setup_.family == ModelFamily::OrdinaryState)
    return correct_state_interfaces(bonds_, p_, state_inputs(), region, built);
  return correct_level_interfaces(bonds_, p_, setup_.partial_volume, C_, region);
}

double Simulation::state_lanczos_dt(const ParticleStore& masses) const {
  if (correspondence_) {
    Correspondence model = *correspondence_;  // its passes overwrite the state they keep
    const auto apply = [&](const std::vector<double>& u, std::vector<double>& out) {
      model.stiffness_times(bonds_, masses, u, out);
    };
    return lanczos_stable_step(apply, masses, 80, 1e-4, &particle_dt_).dt;
  }
  // The classical variable-horizon and multi-horizon operators are not symmetric (unbalanced
  // pairs): their step is that of the dual-horizon model on the same particles, which they equal
  // where horizons agree.
  std::optional<OrdinaryState> dual;
  if (!conserves_momentum(setup_.model))
    dual.emplace(
        bonds_, p_,
        OrdinaryStateInputs{setup_.section, ForceModel::DualHorizon, setup_.partial_volume,
                            setup_.influence, &setup_.materials, setup_.surface_correction});
  OrdinaryState model = dual ? std::move(*dual) : *state_;
  const auto apply = [&](const std::vector<double>& u, std::vector<double>& out) {
    model.stiffness_times(bonds_, masses, u, out);
  };
  return lanczos_stable_step(apply, masses, 80, 1e-4, &particle_dt_).dt;
}

}  // namespace dhpd

// Reading `model` (docs/scenes.md, `model`; docs/theory.md §4–5, §20): one word (the bond-based
// family with that horizon rule) or {family, horizon, influence, surface_correction}, and what the
// state-based family refuses.
#include <fmt/format.h>

#include <string>
#include <vector>

#include "tools/scene/detail.hpp"

namespace dhpd::scene::detail {
namespace {

/// `horizon` of `model` (or `model` itself as one word): how horizons of different sizes meet.
ForceModel read_horizon_model(const Cursor& c) {
  return named_choice(
      c, std::vector<ForceModel>{ForceModel::DualHorizon, ForceModel::ConstantHorizon,
                                 ForceModel::ClassicalVariable, ForceModel::MultiHorizon});
}

/// Multi-horizon PD is defined here for the bond-based family in 1D (docs/theory.md §24).
void check_multi_horizon(const Cursor& c, const Scene& s) {
  if (s.model != ForceModel::MultiHorizon) return;
  if (s.dimension != 1)
    c.fail(fmt::format("multi-horizon is defined in 1D only (this scene is {}D): in 2D and 3D "
                       "eq. 7 of CMES 2019 asks one scalar α per interaction horizon to match a "
                       "vector integral (docs/theory.md §24)",
                       s.dimension),
           "dual-horizon, constant-horizon, classical-variable");
  if (s.family == ModelFamily::Correspondence)
    c.fail("multi-horizon is offered for the bond-based and ordinary state-based families",
           "dual-horizon, constant-horizon (or family: bond or ordinary-state)");
}

}  // namespace

/// `model`: one word (the bond-based family with that horizon rule) or
/// {family, horizon, influence} (docs/scenes.md).
void read_model(const MapView& top, Scene& s) {
  const auto model = top.get("model");
  if (!model) return;
  s.model_where = model->where();
  if (!model->node().IsMap()) {
    s.model = read_horizon_model(*model);
    check_multi_horizon(*model, s);
    return;
  }
  const MapView map(*model, {"family", "horizon", "influence", "surface_correction"});
  if (const auto family = map.get("family"))
    s.family = named_choice(*family,
                            std::vector<ModelFamily>{ModelFamily::Bond, ModelFamily::OrdinaryState,
                                                     ModelFamily::Correspondence});
  if (const auto horizon = map.get("horizon")) {
    s.model = read_horizon_model(*horizon);
    if (s.family == ModelFamily::Correspondence && s.model == ForceModel::ClassicalVariable)
      horizon->fail(
          "the correspondence family is offered with dual (or one constant) horizons only",
          "dual-horizon, constant-horizon");
  }
  if (const auto horizon = map.get("horizon")) check_multi_horizon(*horizon, s);
  if (const auto surface = map.get("surface_correction")) {
    if (s.family != ModelFamily::OrdinaryState)
      surface->fail("surface_correction applies to the ordinary state-based family only",
                    "family: ordinary-state");
    s.surface_correction = surface->boolean();
    if (s.surface_correction && s.model == ForceModel::MultiHorizon)
      surface->fail(
          "multi-horizon's α already carries the material a finer particle's horizon misses "
          "at a zone interface; surface factors would count it again (docs/theory.md §24)",
          "false (the default with multi-horizon)");
  }
  if (s.model == ForceModel::MultiHorizon) s.surface_correction = false;
  if (const auto influence = map.get("influence")) {
    if (s.family == ModelFamily::Bond)
      influence->fail("influence applies to the state-based family only", "family: ordinary-state");
    s.influence = named_choice(
        *influence, std::vector<Influence>{Influence::Constant, Influence::InverseDistance});
  }
}

/// What the ordinary state-based family does not offer (yet): a per-particle stable-step bound,
/// time levels (docs/theory.md §20.3).
void check_state_family(const MapView& top, const Scene& s) {
  if (s.family == ModelFamily::Bond) return;
  if (s.family == ModelFamily::Correspondence && s.effects.fracture)
    MapView(top.require("model"), {})
        .require("family")
        .fail(
            "the correspondence family is elastic: it has no bond breaking (effects.fracture is "
            "true)",
            "ordinary-state or bond, or effects.fracture: false");
  const MapView time(top.require("time"), {});
  if (const auto step = time.get("stable_step");
      step && s.time.stable_step != StableStepEstimate::Lanczos)
    step->fail(
        "the per-particle bound is derived for bond-based PD; the state-based family takes "
        "the Lanczos estimate of its own stiffness",
        "lanczos");
  if (const auto multirate = time.get("multirate"); multirate && *s.time.multirate)
    multirate->fail(
        "the state-based family takes one global step: a pair's force depends on "
        "the dilatation of whole horizons",
        "false");
}

}  // namespace dhpd::scene::detail

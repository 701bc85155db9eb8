// Reading `effects.refinement` (docs/scenes.md; docs/theory.md §13): triggers, buffer, level limit,
// check interval and static zones, with the checks that need the body and the model.
#include <fmt/format.h>

#include "tools/scene/detail.hpp"

namespace dhpd::scene::detail {
namespace {

const char* part_kind_word(PartKind k) {
  return k == PartKind::Mesh ? "a mesh part" : "a points-file part";
}

/// A threshold in (0, 1]: damage and stretch relative to s0 cannot be reached above 1.
double fraction_up_to_one(const Cursor& c, std::string_view what) {
  const double v = positive_number(c);
  if (v > 1.0)
    c.fail(fmt::format("{} is a fraction, got {} (a particle never reaches it)", what, c.text()),
           "0 < value <= 1");
  return v;
}

refine::Triggers read_triggers(const Cursor& c) {
  const MapView m(c, {"damage", "energy", "stretch", "near_crack", "near_precrack"});
  refine::Triggers t;
  if (const auto v = m.get("damage")) t.damage = fraction_up_to_one(*v, "damage");
  if (const auto v = m.get("energy")) t.energy = positive_number(*v);
  if (const auto v = m.get("stretch")) t.stretch = fraction_up_to_one(*v, "stretch (of s0)");
  if (const auto v = m.get("near_crack")) {
    if (!t.stretch)
      v->fail("near_crack limits the stretch trigger, which is not given", "stretch with it");
    t.near_crack = positive_number(*v);
  }
  if (const auto v = m.get("near_precrack")) {
    if (!t.near_crack)
      v->fail("near_precrack widens near_crack around pre-cracks, but near_crack is not given",
              "near_crack (and stretch) with it");
    t.near_precrack = positive_number(*v);
  }
  if (!t.any()) c.fail("trigger needs at least one threshold", "damage, energy, stretch");
  return t;
}

/// Refinement splits lattice cells; an irregular part or a single-horizon model cannot split.
void check_refinable(const Cursor& c, const Scene& s) {
  for (std::size_t p = 0; p < s.body.size(); ++p)
    if (s.body[p].kind != PartKind::Lattice)
      c.fail(
          fmt::format("refinement splits lattice particles only, but body.{} is {} (line {}); "
                      "use lattice parts or set refinement: false",
                      p, part_kind_word(s.body[p].kind), s.body[p].where.line));
  if (s.model == ForceModel::ConstantHorizon)
    c.fail(
        "refinement needs per-particle horizons; model constant-horizon uses one horizon for "
        "the whole body",
        "model dual-horizon or classical-variable");
  if (s.model == ForceModel::MultiHorizon)
    c.fail(
        "refinement is not offered with model multi-horizon: its α are fixed once at the start "
        "(CMES 2019 §2.2)",
        "model dual-horizon or classical-variable");
  if (s.family == ModelFamily::Correspondence)
    c.fail(
        "refinement is not available with the correspondence family: its level interfaces "
        "carry a force layer that no correction removes yet (docs/theory.md §21.3)",
        "model family bond or ordinary-state, or refinement: false");
}

}  // namespace

std::optional<RefinementSpec> read_refinement(const Cursor& c, const Scene& s) {
  RefinementSpec r;
  r.where = c.where();
  r.settings.trigger = refine::default_triggers();
  if (c.node().IsScalar()) {  // `refinement: true`: every default
    if (!c.boolean()) return std::nullopt;
    check_refinable(c, s);
    return r;
  }
  const MapView m(c,
                  {"trigger", "buffer", "max_level", "check_every", "zones", "mapping", "within"});
  // Zones alone refine once, at the start; the default triggers come only with no zones.
  if (m.get("zones") && !m.get("trigger")) r.settings.trigger = {};
  if (const auto v = m.get("trigger")) r.settings.trigger = read_triggers(*v);
  if (const auto v = m.get("buffer")) r.settings.buffer = non_negative_number(*v);
  if (const auto v = m.get("max_level"))
    r.settings.max_level = static_cast<int>(positive_integer(*v));
  if (r.settings.max_level > 8) m.get("max_level")->fail("max_level must be <= 8", "1 to 8");
  if (const auto v = m.get("check_every")) r.settings.check_every = positive_integer(*v);
  if (const auto v = m.get("mapping"))
    r.settings.mapping = static_cast<refine::StateMapping>(
        v->choice({std::begin(refine::kStateMappingNames), std::end(refine::kStateMappingNames)}));
  if (const auto v = m.get("zones"))
    for (const auto& z : read_regions(*v, s.dimension)) r.settings.zones.push_back(z.shape);
  if (const auto v = m.get("within"))
    for (const auto& z : read_regions(*v, s.dimension)) r.settings.within.push_back(z.shape);
  check_refinable(c, s);
  return r;
}

}  // namespace dhpd::scene::detail

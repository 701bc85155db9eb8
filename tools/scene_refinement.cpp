// Reading `effects.refinement` (cases/README.md; dhpd.md §8): triggers, buffer, level limit,
// check interval and static zones, with the checks that need the body and the model.
#include <fmt/format.h>

#include "tools/scene_detail.hpp"

namespace dhpd::scene::detail {
namespace {

const char* part_kind_word(PartKind k) {
  return k == PartKind::Mesh ? "a mesh part" : "a points-file part";
}

refine::Triggers read_triggers(const Cursor& c) {
  const MapView m(c, {"damage", "energy", "stretch"});
  refine::Triggers t;
  if (const auto v = m.get("damage")) t.damage = positive_number(*v);
  if (const auto v = m.get("energy")) t.energy = positive_number(*v);
  if (const auto v = m.get("stretch")) t.stretch = positive_number(*v);
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
}

}  // namespace

std::optional<RefinementSpec> read_refinement(const Cursor& c, const Scene& s) {
  if (c.node().IsScalar()) {
    if (!c.boolean()) return std::nullopt;
    c.fail("refinement: true says nothing about where to refine; give a map",
           "false, or {trigger: {damage, energy, stretch}, buffer, max_level, check_every, zones, "
           "mapping}");
  }
  const MapView m(c, {"trigger", "buffer", "max_level", "check_every", "zones", "mapping"});
  RefinementSpec r;
  r.where = c.where();
  if (const auto v = m.get("trigger")) r.settings.trigger = read_triggers(*v);
  if (const auto v = m.get("buffer")) r.settings.buffer = non_negative_number(*v);
  if (const auto v = m.get("max_level"))
    r.settings.max_level = static_cast<int>(positive_integer(*v));
  if (r.settings.max_level > 8) m.get("max_level")->fail("max_level must be <= 8", "1 to 8");
  if (const auto v = m.get("check_every")) r.settings.check_every = positive_integer(*v);
  if (const auto v = m.get("mapping"))
    r.settings.mapping = static_cast<StateMapping>(
        v->choice({std::begin(kStateMappingNames), std::end(kStateMappingNames)}));
  if (const auto v = m.get("zones"))
    for (const auto& z : read_regions(*v, s.dimension)) r.settings.zones.push_back(z.shape);
  if (!r.settings.trigger.any() && r.settings.zones.empty())
    c.fail("refinement needs a trigger or zones", "trigger, zones");
  check_refinable(c, s);
  return r;
}

}  // namespace dhpd::scene::detail

// The stepper's stretch watch against the refinement trigger's own scan (docs/theory.md §13.1): on
// a plate of two spacings pulled until bonds break, with one global step and with time levels,
// triggered() reading the last step's hits gives the verdicts of the scan after every step.
#include <gtest/gtest.h>

#include <algorithm>
#include <vector>

#include "engine/simulation.hpp"
#include "refine/triggers.hpp"
#include "tests/support/setups.hpp"

namespace dhpd {
namespace {

TEST(StretchWatch, TriggersReadFromTheStepsGiveTheScansVerdicts) {
  for (const bool multirate : {false, true}) {
    auto s = test::fracturing_plate();
    s.multirate = multirate;
    Simulation sim(s);
    refine::Triggers t;
    t.stretch = 0.6;
    const std::uint64_t key = 7;
    sim.watch_stretch(refine::stretch_limits(sim, *t.stretch, 1), key);
    EXPECT_EQ(sim.stretch_watch_hits(key), nullptr);  // no step has watched yet
    std::int64_t flagged = 0;
    for (int step = 0; step < 150; ++step) {
      sim.step();
      ASSERT_NE(sim.stretch_watch_hits(key), nullptr);
      EXPECT_EQ(sim.stretch_watch_hits(key + 1), nullptr);  // another rule's limits
      const auto with = refine::triggered(sim, t, {1, nullptr, sim.stretch_watch_hits(key)});
      const auto scan = refine::triggered(sim, t, {1, nullptr, nullptr});
      ASSERT_EQ(with, scan) << "step " << step << (multirate ? " with time levels" : "");
      flagged += std::count(with.begin(), with.end(), 1);
    }
    EXPECT_GT(flagged, 0);
    EXPECT_GT(sim.broken_bonds(), 0);
    EXPECT_EQ(sim.time_levels() != nullptr, multirate);
    sim.compact();  // renumbered: the limits were by index
    EXPECT_FALSE(sim.watching_stretch(key));
    EXPECT_EQ(sim.stretch_watch_hits(key), nullptr);
  }
}

}  // namespace
}  // namespace dhpd

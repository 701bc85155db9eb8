// End-to-end: time levels (docs/theory.md §19) in a run's outputs, asked for and by default.
#include <fmt/format.h>

#include "tests/support/cli.hpp"

namespace {

using namespace dhpd::cli_test;  // NOLINT: the fixture's helpers

// time.multirate on a plate with a patch of half spacing: frames carry each particle's time level,
// summary.json counts the particles per level and the bonds evaluated per level, and one global
// step would have evaluated every bond twice per step.
TEST_F(CliTest, MultirateRunReportsItsLevels) {
  const auto dir = run_plate(
      "result", {},
      {"body=[{shape: box, min: [0, 0], max: [0.01, 0.005], spacing: 0.0005, material: glass}, "
       "{shape: box, min: [0.004, 0.001], max: [0.006, 0.004], spacing: 0.00025, material: glass}]",
       "time.multirate=true", "effects.fracture=false"});
  const auto summary = read_json(dir / "summary.json");
  const auto& levels = summary.at("time_levels");
  const auto particles = levels.at("particles").get<std::vector<std::int64_t>>();
  ASSERT_EQ(particles.size(), 2u);
  EXPECT_EQ(particles[0] + particles[1], summary.at("particles_end").get<std::int64_t>());
  const auto steps = summary.at("steps").get<std::int64_t>();
  const auto bonds = summary.at("bonds").get<std::int64_t>();
  EXPECT_EQ(levels.at("one_step_bond_evaluations").get<std::int64_t>(), 2 * steps * bonds);
  const auto evaluated = levels.at("bond_evaluations").get<std::vector<std::int64_t>>();
  ASSERT_EQ(evaluated.size(), 2u);
  EXPECT_EQ(evaluated[1] % (2 * steps), 0) << "each level-1 bond twice per step";
  EXPECT_GT(levels.at("saving").get<double>(), 1.0);
  const auto pvd = dhpd::io::read_pvd((dir / "plate.pvd").string());
  const auto frame = dhpd::io::read_frame((dir / pvd.back().second).string());
  ASSERT_EQ(frame.fields.count("time_level"), 1u);
  std::int64_t fine = 0;
  for (const double l : frame.fields.at("time_level").second) fine += l == 1.0 ? 1 : 0;
  EXPECT_EQ(fine, particles[1]);
  // history.csv: particles per level after the momentum, one column per allowed level.
  const auto history = read_text(dir / "history.csv");
  const auto header = history.substr(0, history.find('\n'));
  EXPECT_NE(header.find("momentum_z,particles_level_0,particles_level_1,"), std::string::npos);
  EXPECT_NE(header.find(",particles_level_7"), std::string::npos) << "time.max_levels columns";
  const auto last = history.substr(history.rfind('\n', history.size() - 2) + 1);
  EXPECT_NE(last.find(fmt::format(",{},{},0,0,0,0,0,0\n", particles[0], particles[1])),
            std::string::npos)
      << last;
}
TEST_F(CliTest, LevelsAreShownByDefaultOnlyWhereTheSceneCanHaveThem) {
  // A plate with a fine patch and time.multirate unset: levels pay there, and the outputs show
  // them; the same plate at one spacing shows none (history.csv keeps its columns).
  const std::string patch =
      "body=[{shape: box, min: [0, 0], max: [0.02, 0.01], spacing: 0.0005, material: glass}, "
      "{shape: box, min: [0.009, 0.004], max: [0.011, 0.006], spacing: 0.00025, material: glass}]";
  const auto dir = run_plate("patch", {}, {patch, "effects.fracture=false"});
  const auto levels = read_json(dir / "summary.json").at("time_levels").at("particles");
  EXPECT_EQ(levels.size(), 2u);
  // run.log says what the finest particles step at (dt there is dt0).
  EXPECT_NE(read_text(dir / "run.log")
                .find(fmt::format(
                    "dhpd: 2 time levels (docs/theory.md §19): particles {} / {}; steps dt0 = ",
                    levels[0].get<std::int64_t>(), levels[1].get<std::int64_t>())),
            std::string::npos);
  const auto history = read_text(dir / "history.csv");
  EXPECT_NE(history.find("particles_level_0"), std::string::npos);
  const auto plain = run_plate("plain", {}, {"effects.fracture=false"});
  EXPECT_FALSE(read_json(plain / "summary.json").contains("time_levels"));
  const auto plain_history = read_text(plain / "history.csv");
  EXPECT_EQ(plain_history.substr(0, plain_history.find('\n')).find("particles_level"),
            std::string::npos);
}

}  // namespace

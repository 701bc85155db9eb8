// End-to-end: good runs write every output; overrides, effects, threads, instability, every case.
#include <fmt/format.h>

#include "tests/support/cli.hpp"

namespace {

using namespace dhpd::cli_test;  // NOLINT: the fixture's helpers
void expect_frames(const fs::path& dir, const std::vector<std::int64_t>& steps) {
  const auto pvd = dhpd::io::read_pvd((dir / "plate.pvd").string());
  ASSERT_EQ(pvd.size(), steps.size());
  for (std::size_t k = 0; k < pvd.size(); ++k) {
    if (k > 0) {
      EXPECT_GT(pvd[k].first, pvd[k - 1].first);
    }
    const auto frame = dhpd::io::read_frame((dir / pvd[k].second).string());
    EXPECT_EQ(frame.step, steps[k]) << pvd[k].second;
    EXPECT_EQ(frame.time, pvd[k].first) << pvd[k].second;  // bit for bit
  }
  EXPECT_EQ(pvd.front().first, 0.0);
}

void expect_last_frame_fields(const fs::path& dir) {
  const auto pvd = dhpd::io::read_pvd((dir / "plate.pvd").string());
  ASSERT_FALSE(pvd.empty());
  const auto frame = dhpd::io::read_frame((dir / pvd.back().second).string());
  EXPECT_EQ(frame.points.size(), 3u * kPlateParticles);
  const std::vector<std::pair<std::string, int>> expected{
      {"displacement", 3}, {"velocity", 3}, {"damage", 1},
      {"horizon", 1},      {"volume", 1},   {"spacing", 1},
      {"material", 1},     {"id", 1},       {"strain_energy_density", 1},
      {"bond_count", 1}};
  for (const auto& [name, components] : expected) {
    const auto it = frame.fields.find(name);
    ASSERT_NE(it, frame.fields.end()) << name;
    EXPECT_EQ(it->second.first, components) << name;
    EXPECT_EQ(it->second.second.size(), static_cast<std::size_t>(components * kPlateParticles))
        << name;
  }
  auto ids = frame.fields.at("id").second;
  std::sort(ids.begin(), ids.end());
  for (int i = 0; i < kPlateParticles; ++i) EXPECT_EQ(ids[i], i);
  const auto& damage = frame.fields.at("damage").second;
  EXPECT_GT(*std::max_element(damage.begin(), damage.end()), 0.0);  // the plate is breaking
  for (const double d : damage) EXPECT_TRUE(d >= 0.0 && d <= 1.0) << d;
}

void expect_history(const fs::path& dir, const json& summary) {
  const auto h = read_history(dir / "history.csv");
  EXPECT_EQ(h.header, kHistoryHeader);
  EXPECT_EQ(h.column(0), (std::vector<long long>{0, 10, 20, 30, 40, 50, 60}));
  for (const auto& row : h.rows) {
    ASSERT_EQ(row.size(), 12u);
    EXPECT_EQ(row[3], std::to_string(kPlateParticles));
  }
  EXPECT_EQ(h.column(5).back(), summary.at("broken_bonds").get<long long>());
}

void expect_resolved_scene(const fs::path& dir) {
  const std::string text = read_text(dir / "scene.resolved.yaml");
  const auto split = text.find("\n---\n");
  ASSERT_NE(split, std::string::npos) << text;
  const auto resolved = dhpd::scene::parse_scene(text.substr(0, split + 1), "scene.resolved.yaml");
  const auto original = dhpd::scene::parse_scene(kPlate, "plate.yaml");
  EXPECT_EQ(resolved.name, original.name);
  EXPECT_EQ(resolved.dimension, original.dimension);
  ASSERT_EQ(resolved.body.size(), 1u);
  EXPECT_EQ(resolved.body[0].spacing, original.body[0].spacing);
  EXPECT_EQ(resolved.materials[0].law.E, original.materials[0].law.E);
  EXPECT_EQ(resolved.time.steps, original.time.steps);
  EXPECT_EQ(resolved.output.every, original.output.every);
  EXPECT_EQ(resolved.output.fields, original.output.fields);
  EXPECT_EQ(resolved.cracks.size(), 1u);
  EXPECT_EQ(resolved.boundary_conditions.size(), 2u);
  EXPECT_TRUE(resolved.effects.fracture);
  const auto derived = YAML::Load(text.substr(split + 5));
  EXPECT_EQ(derived["derived"]["particles"].as<int>(), kPlateParticles);
  EXPECT_EQ(derived["derived"]["steps"].as<int>(), 60);
}

TEST_F(CliTest, GoodRunWritesEveryOutput) {
  const auto dir = run_plate("result", {});
  EXPECT_FALSE(fs::exists(dir_ / "out"));  // -o wins over output.directory
  const auto summary = read_json(dir / "summary.json");
  EXPECT_EQ(summary.at("status"), "completed");
  EXPECT_EQ(summary.at("steps"), 60);
  EXPECT_EQ(summary.at("particles_start"), kPlateParticles);
  EXPECT_EQ(summary.at("particles_end"), kPlateParticles);
  EXPECT_TRUE(has_effect(summary, "elasticity"));
  EXPECT_TRUE(has_effect(summary, "fracture"));
  EXPECT_TRUE(summary.at("seconds_per_phase").contains("forces"));
  EXPECT_GT(summary.at("broken_bonds").get<long long>(), 0);
  expect_frames(dir, {0, 20, 40, 60});
  expect_last_frame_fields(dir);
  expect_history(dir, summary);
  expect_resolved_scene(dir);
}

TEST_F(CliTest, FieldsListsEveryFieldAFrameCanHold) {
  // `dhpd fields` names each field once with a unit; a run asking for every optional one writes
  // each with one value (or three) per particle: the list and the frames come from one registry.
  const auto f = dhpd({"fields"});
  ASSERT_EQ(f.code, 0) << f.err;
  std::istringstream lines(f.out);
  std::string line;
  std::getline(lines, line);  // header
  std::vector<std::string> always, optional;
  while (std::getline(lines, line)) {
    std::istringstream words(line);
    std::string name, unit, when;
    words >> name >> unit >> when;
    if (when != "always" && when != "on") continue;  // the closing note
    EXPECT_FALSE(unit.empty()) << line;
    (when == "always" ? always : optional).push_back(name);
  }
  EXPECT_EQ(always.size(), 10u);
  EXPECT_EQ(optional.size(), 11u);
  std::string list;
  for (const auto& n : optional) list += (list.empty() ? "" : ",") + n;
  const auto dir =
      run_plate("result", {}, {"time.steps=10", "output.every=10", "output.fields=[" + list + "]"});
  const auto pvd = dhpd::io::read_pvd((dir / "plate.pvd").string());
  ASSERT_FALSE(pvd.empty());
  const auto frame = dhpd::io::read_frame((dir / pvd.back().second).string());
  EXPECT_EQ(frame.fields.size(), always.size() + optional.size());
  for (const auto& names : {always, optional})
    for (const auto& name : names) {
      const auto it = frame.fields.find(name);
      ASSERT_NE(it, frame.fields.end()) << name;
      EXPECT_EQ(it->second.second.size(),
                static_cast<std::size_t>(it->second.first * kPlateParticles))
          << name;
    }
}

TEST_F(CliTest, SetOverridesChangeTheRun) {
  const auto dir = run_plate("result", {}, {"time.steps=20", "output.every=10"});
  expect_frames(dir, {0, 10, 20});
  EXPECT_EQ(read_json(dir / "summary.json").at("steps"), 20);
  EXPECT_EQ(read_history(dir / "history.csv").column(0), (std::vector<long long>{0, 10, 20}));
  const std::string resolved = read_text(dir / "scene.resolved.yaml");
  EXPECT_NE(resolved.find("steps: 20"), std::string::npos) << resolved;
}

// output.probes: the particle nearest to each point, its u and v as history columns. `top` is
// in the band pulled at 2 m/s (so v_y = 2 and u_y = 2 t at every row), `bottom` in the held one.
TEST_F(CliTest, ProbesFollowTheirParticleInTheHistory) {
  const auto dir = run_plate(
      "probed", {},
      {"output.probes=[{name: top, at: [0.0051, 0.0049]}, {name: bottom, at: [0.002, 0.0]}]"});
  const auto h = read_history(dir / "history.csv");
  EXPECT_EQ(h.header, std::string(kHistoryHeader) +
                          ",top_ux,top_uy,top_vx,top_vy,bottom_ux,bottom_uy,bottom_vx,bottom_vy");
  ASSERT_EQ(h.rows.size(), 7u);
  for (const auto& row : h.rows) {
    ASSERT_EQ(row.size(), 20u);
    const double time = std::stod(row[1]);
    EXPECT_EQ(std::stod(row[15]), 2.0);
    EXPECT_NEAR(std::stod(row[13]), 2.0 * time, 1e-12 * (1.0 + 2.0 * time));
    for (std::size_t k = 16; k < 20; ++k) EXPECT_EQ(std::stod(row[k]), 0.0) << k;
  }
  const std::string resolved = read_text(dir / "scene.resolved.yaml");
  EXPECT_NE(resolved.find("- {name: top, at: [0.0051, 0.0049]}"), std::string::npos) << resolved;
}

TEST_F(CliTest, FractureOffIsNamedAndCostsNothing) {
  const auto dir = run_plate("result", {}, {"effects.fracture=false"});
  const auto summary = read_json(dir / "summary.json");
  EXPECT_TRUE(has_effect(summary, "elasticity"));
  EXPECT_FALSE(has_effect(summary, "fracture"));
  EXPECT_EQ(summary.at("seconds_per_phase").at("fracture").get<double>(), 0.0);
  EXPECT_EQ(summary.at("broken_bonds"), 0);
  const auto broken = read_history(dir / "history.csv").column(5);
  EXPECT_EQ(broken.size(), 7u);
  for (const auto b : broken) EXPECT_EQ(b, 0);
}

TEST_F(CliTest, AdaptiveRunLogsEventsAndFramesCarryLevels) {
  const auto dir =
      run_plate("result", {},
                {"effects.refinement={trigger: {damage: 0.02}, buffer: 1.0, check_every: 10}",
                 "model=dual-horizon"});
  const auto summary = read_json(dir / "summary.json");
  EXPECT_TRUE(has_effect(summary, "refinement"));
  const auto events = summary.at("refinement_events").get<long long>();
  EXPECT_GT(events, 0);
  const auto end = summary.at("particles_end").get<long long>();
  EXPECT_GT(end, kPlateParticles);
  const auto csv = read_text(dir / "refinement.csv");
  EXPECT_EQ(
      csv.rfind("generation,step,time,parents,children,dropped,particles,bonds,rows_rebuilt,"
                "bonds_rebuilt,rows_touched,started_broken,started_overstretched,mapping_energy,"
                "reduced_fits,dt,seconds,resorted,"
                "resort_seconds\n",
                0),
      0u)
      << csv;
  EXPECT_EQ(std::count(csv.begin(), csv.end(), '\n'), events + 1);
  const auto particles = read_history(dir / "history.csv").column(3);
  EXPECT_EQ(particles.front(), kPlateParticles);
  EXPECT_EQ(particles.back(), end);
  const auto pvd = dhpd::io::read_pvd((dir / "plate.pvd").string());
  const auto frame = dhpd::io::read_frame((dir / pvd.back().second).string());
  EXPECT_EQ(frame.points.size(), 3u * static_cast<std::size_t>(end));
  const auto& level = frame.fields.at("level").second;
  const auto& parent = frame.fields.at("parent_id").second;
  EXPECT_EQ(level.size(), static_cast<std::size_t>(end));
  EXPECT_EQ(*std::max_element(level.begin(), level.end()), 1.0);
  EXPECT_EQ(*std::min_element(parent.begin(), parent.end()), -1.0);
}

TEST_F(CliTest, ThreadCountDoesNotChangeTheOutput) {
  const auto one = run_plate("t1", {"-t", "1"});
  const auto two = run_plate("t2", {"-t", "2"});
  EXPECT_EQ(read_json(one / "summary.json").at("threads"), 1);
  EXPECT_EQ(read_json(two / "summary.json").at("threads"), 2);
  const std::string history = read_text(one / "history.csv");
  EXPECT_GT(history.size(), 100u);
  EXPECT_EQ(history, read_text(two / "history.csv"));
  const auto a = dhpd::io::read_frame((one / "plate_000003.vtu").string());
  const auto b = dhpd::io::read_frame((two / "plate_000003.vtu").string());
  EXPECT_EQ(a.points, b.points);
  EXPECT_EQ(a.fields, b.fields);
}

TEST_F(CliTest, ExactPartialVolumeRunsAndWritesTheQuadratureField) {
  const auto dir = run_plate(
      "exact", {}, {"partial_volume=exact", "output.fields=[quadrature]", "time.steps=20"});
  const std::string text = read_text(dir / "scene.resolved.yaml");
  ASSERT_NE(text.find("partial_volume: exact\n"), std::string::npos) << text;
  const auto resolved = dhpd::scene::parse_scene(text.substr(0, text.find("\n---\n") + 1), "r");
  EXPECT_EQ(resolved.partial_volume, dhpd::PartialVolume::Exact);
  const auto frame = dhpd::io::read_frame((dir / "plate_000001.vtu").string());
  const auto& q = frame.fields.at("quadrature").second;
  ASSERT_EQ(q.size(), static_cast<std::size_t>(kPlateParticles));
  // Interior particles are within 1.5 % of 1; edge and corner particles see less of a horizon.
  EXPECT_NEAR(*std::max_element(q.begin(), q.end()), 1.0, 0.015);
  EXPECT_GT(*std::min_element(q.begin(), q.end()), 0.2);
}

TEST_F(CliTest, OverflowingRunStopsWithExitThree) {
  // A dt above the stable step is refused, so blow the state up instead: a velocity pulse of
  // 1e150 m/s has a finite kinetic energy, but the forces of the first step overflow. The
  // non-finite state is caught in the step itself, before anything of it is written.
  const auto o =
      dhpd({"run", "plate.yaml", "-o", "result", "-q"},
           {"effects.fracture=false", "output.history_every=5",
            "initial_conditions=[{region: {shape: box, min: [0, 0], max: [0.01, 0.005]}, "
            "velocity: [1.0e150, 0], gaussian: {center: [0.005, 0.0025], width: 0.001}}]"});
  EXPECT_EQ(o.code, 3) << o.err;
  const std::string message = "the state became non-finite (NaN/Inf) at step 1";
  EXPECT_EQ(o.err.rfind("dhpd: unstable run stopped: " + message, 0), 0u) << o.err;
  const auto dir = dir_ / "result";
  const auto summary = read_json(dir / "summary.json");
  EXPECT_EQ(summary.at("status"), "unstable");
  EXPECT_EQ(summary.at("steps"), 0);  // steps completed before the failing one
  EXPECT_EQ(summary.at("message").get<std::string>().rfind(message, 0), 0u);
  const auto h = read_history(dir / "history.csv");
  EXPECT_EQ(h.header, kHistoryHeader);
  EXPECT_EQ(h.column(0), std::vector<long long>{0});  // nothing of the blown-up state
  EXPECT_EQ(dhpd::io::read_pvd((dir / "plate.pvd").string()).size(), 1u);
  EXPECT_TRUE(fs::exists(dir / "scene.resolved.yaml"));
}

// ---- crack measurements ----

TEST_F(CliTest, MeasurementsTakenDuringTheNextForcePassEqualMeasurementsTakenAtOnce) {
  // With a thread per core, frames and crack measurements go to one thread of the next step's
  // force pass (the damage copied first); with one thread they are taken at once. The results are
  // the same for any thread count, so the files must be too, byte for byte.
  const auto cores = std::thread::hardware_concurrency();
  if (cores < 2) GTEST_SKIP() << "one core: nothing is handed to a force pass";
  const std::string scene = std::string(DHPD_SOURCE_DIR) + "/cases/branching_plate_uniform.yaml";
  const std::vector<std::string> sets = {"body.0.spacing=0.001", "measure.every=1",
                                         "time.end=2.5e-5"};
  const auto all =
      dhpd({"run", scene, "-o", "all", "-q", "--threads", std::to_string(cores)}, sets);
  ASSERT_EQ(all.code, 0) << all.err;
  const auto one = dhpd({"run", scene, "-o", "one", "-q", "--threads", "1"}, sets);
  ASSERT_EQ(one.code, 0) << one.err;
  const auto cracks = read_text(dir_ / "all" / "cracks.csv");
  EXPECT_GT(std::count(cracks.begin(), cracks.end(), '\n'), 100);
  EXPECT_EQ(cracks, read_text(dir_ / "one" / "cracks.csv"));
  EXPECT_EQ(read_json(dir_ / "all" / "summary.json").at("cracks"),
            read_json(dir_ / "one" / "summary.json").at("cracks"));
  for (const auto* frame : {"branching_plate_uniform_000005.vtu", "branching_plate_uniform.pvd"})
    EXPECT_EQ(read_text(dir_ / "all" / frame), read_text(dir_ / "one" / frame)) << frame;
}

TEST_F(CliTest, MeasuredRunWritesCracksAndRayleighSpeed) {
  // The shipped plate at 1 mm spacing (4,000 particles), measured every 10 steps instead of the
  // case's every step (speeds over 5 measurements): the crack starts and branches.
  const auto o = dhpd({"run", std::string(DHPD_SOURCE_DIR) + "/cases/branching_plate_uniform.yaml",
                       "-o", "measured", "-q"},
                      {"body.0.spacing=0.001", "measure.every=10", "measure.smoothing=5"});
  ASSERT_EQ(o.code, 0) << o.err;
  const auto dir = dir_ / "measured";
  const auto summary = read_json(dir / "summary.json");
  const auto csv = read_history(dir / "cracks.csv");  // the same layout as history.csv
  EXPECT_EQ(csv.header, "step,time,tip,x,y,z,distance,path_length,speed,angle_deg,branches");
  const long long steps = summary.at("steps").get<long long>();
  std::vector<long long> expected;  // every 10 steps from step 0, and the last step
  for (long long k = 0; k < steps; k += 10) expected.push_back(k);
  expected.push_back(steps);
  EXPECT_EQ(csv.column(0), expected);
  for (const auto& row : csv.rows) {
    ASSERT_EQ(row.size(), 11u);
    EXPECT_EQ(row[2], "notch");
  }
  EXPECT_GT(std::stod(csv.rows.back()[6]), 0.02);  // the crack has run more than 20 mm

  ASSERT_EQ(summary.at("cracks").size(), 1u);
  const auto& crack = summary.at("cracks")[0];
  EXPECT_EQ(crack.at("name"), "notch");
  ASSERT_TRUE(crack.at("initiation_time").is_number()) << crack;
  EXPECT_GT(crack.at("initiation_time").get<double>(), 0.0);
  EXPECT_LT(crack.at("initiation_time").get<double>(), summary.at("end_time").get<double>());
  EXPECT_TRUE(crack.at("max_speed").is_number());
  EXPECT_TRUE(crack.at("branch_times").is_array());
  EXPECT_EQ(crack.at("tip")[0].get<double>(), std::stod(csv.rows.back()[3]));  // the last row
  const double nu = 1.0 / 3.0, mu = 72.0e9 / (2.0 * (1.0 + nu));
  const double c_r = (0.87 + 1.12 * nu) / (1.0 + nu) * std::sqrt(mu / 2440.0);
  EXPECT_NEAR(summary.at("rayleigh_speed").get<double>(), c_r, 1e-12 * c_r);
  EXPECT_EQ(summary.at("published").at("notch").at("branch_times"), json::parse("[2.45e-5]"));

  const std::string text = read_text(dir / "scene.resolved.yaml");
  const auto resolved = dhpd::scene::parse_scene(text.substr(0, text.find("\n---\n") + 1), "r");
  ASSERT_TRUE(resolved.measure.has_value());
  ASSERT_EQ(resolved.measure->settings.tips.size(), 1u);
  EXPECT_EQ(resolved.measure->settings.tips[0].at, (dhpd::geometry::Vec3{0.05, 0.02, 0}));
  EXPECT_EQ(resolved.measure->settings.every, 10);
}

TEST_F(CliTest, RunWithoutMeasureWritesNoCracks) {
  const auto dir = run_plate("result", {}, {"time.steps=10"});
  EXPECT_FALSE(fs::exists(dir / "cracks.csv"));
  const auto summary = read_json(dir / "summary.json");
  EXPECT_FALSE(summary.contains("cracks"));
  EXPECT_FALSE(summary.contains("rayleigh_speed"));
  EXPECT_EQ(read_text(dir / "scene.resolved.yaml").find("measure"), std::string::npos);
}

// ---- dhpd check and the shipped cases ----

/// The particle count `dhpd check` prints ("  particles: N"), or -1.
/// The particle count `dhpd check` printed: the built body's when it was built, else the estimate.
long long checked_particles(const std::string& out) {
  const auto derived = out.find("derived:");
  const auto at = out.find("particles: ", derived == std::string::npos ? 0 : derived);
  return at == std::string::npos ? -1 : std::stoll(out.substr(at + 11));
}

TEST_F(CliTest, CheckPrintsDerivedQuantities) {
  const auto o =
      dhpd({"check", std::string(DHPD_SOURCE_DIR) + "/cases/branching_plate_uniform.yaml"});
  EXPECT_EQ(o.code, 0) << o.err;
  EXPECT_EQ(o.err, "");
  EXPECT_NE(o.out.find("particles: 16000\n"), std::string::npos) << o.out;
  for (const char* key : {"stable_dt: ", "micromodulus_C: ", "critical_stretch_s0: ",
                          "rayleigh_speed: ", "estimated_memory_mb: "})
    EXPECT_NE(o.out.find(key), std::string::npos) << key << " missing in\n" << o.out;
  EXPECT_EQ(checked_particles(o.out), 16000);
  EXPECT_FALSE(fs::exists(dir_ / "out"));  // check writes nothing
}

std::vector<std::string> case_files() {
  std::vector<std::string> files;
  for (const auto& entry : fs::directory_iterator(fs::path(DHPD_SOURCE_DIR) / "cases"))
    if (entry.path().extension() == ".yaml") files.push_back(entry.path().string());
  std::sort(files.begin(), files.end());
  return files;
}

TEST(CliCases, CasesDirectoryIsNotEmpty) {
  EXPECT_GE(case_files().size(), 4u);
}

class CliCase : public CliTest, public ::testing::WithParamInterface<std::string> {};

TEST_P(CliCase, RunsFiveSteps) {
  // Overriding time.steps drops the case's time.end, and output.every its output.frames.
  const auto scene = dhpd::scene::load_scene(GetParam());
  const std::vector<std::string> sets{"time.steps=5", "output.every=5"};

  const auto c = dhpd({"check", GetParam()}, sets);
  ASSERT_EQ(c.code, 0) << c.err;
  const long long particles = checked_particles(c.out);
  EXPECT_GT(particles, 0) << c.out;
  // The verification-size cases (262,144 particles, 2.3 GB) are checked, not run, here.
  if (particles > 100000) GTEST_SKIP() << particles << " particles: run it by hand";

  const auto r = dhpd({"run", GetParam(), "-o", "result", "-q"}, sets);
  ASSERT_EQ(r.code, 0) << r.err;
  const auto summary = read_json(dir_ / "result" / "summary.json");
  EXPECT_EQ(summary.at("status"), "completed");
  EXPECT_EQ(summary.at("steps"), 5);
  EXPECT_EQ(summary.at("particles_start").get<long long>(), particles);
  EXPECT_EQ(read_history(dir_ / "result" / "history.csv").column(0).back(), 5);
  EXPECT_FALSE(fs::exists(dir_ / scene.output.directory));
}

INSTANTIATE_TEST_SUITE_P(Shipped, CliCase, ::testing::ValuesIn(case_files()), [](const auto& info) {
  std::string name = fs::path(info.param).stem().string();
  for (char& c : name)
    if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
  return name;
});

}  // namespace

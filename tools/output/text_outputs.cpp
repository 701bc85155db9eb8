// history.csv, summary.json and the terminal progress line.
#include "tools/output/text_outputs.hpp"

#include "engine/base/errors.hpp"

#include <fmt/format.h>
#include <unistd.h>
#include <algorithm>
#include <cerrno>
#include <cstring>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <stdexcept>
#include <system_error>

namespace dhpd::io {
namespace {

namespace fs = std::filesystem;

constexpr const char* kHistoryHeader =
    "step,time,dt,particles,bonds,broken_bonds,kinetic_energy,strain_energy,external_work,"
    "momentum_x,momentum_y,momentum_z";

}  // namespace

void write_text_atomically(const std::string& path, const std::string& text) {
  const fs::path final_path(path);
  const fs::path tmp = fs::path(final_path).concat(".tmp");
  std::error_code ec;
  {
    errno = 0;
    std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
    out << text;
    out.close();
    if (!out) {
      const std::string reason = errno ? std::strerror(errno) : "the stream failed";
      fs::remove(tmp, ec);
      throw IoError(fmt::format("cannot write '{}': {}", path, reason));
    }
  }
  fs::rename(tmp, final_path, ec);
  if (ec) {
    fs::remove(tmp, ec);
    throw IoError(fmt::format("cannot rename '{}' to '{}': {}", tmp.string(), path, ec.message()));
  }
}

std::uint64_t bytes_written(std::ofstream& out) {
  const auto at = out.tellp();
  if (at < 0) throw std::runtime_error("cannot tell the length of a CSV file");
  return static_cast<std::uint64_t>(at);
}

std::ofstream open_csv(const std::string& path, const char* header, const char* what, bool append) {
  errno = 0;
  std::ofstream out(path, append ? std::ios::app | std::ios::ate : std::ios::trunc);
  if (!out)
    throw IoError(fmt::format("cannot open {} file '{}': {}", what, path, std::strerror(errno)));
  if (append) return out;
  out << header << '\n';
  out.flush();
  if (!out)
    throw IoError(fmt::format("cannot write {} file '{}': {}", what, path, std::strerror(errno)));
  return out;
}

void write_row(std::ofstream& out, const std::string& row, const char* what) {
  errno = 0;
  out << row;
  out.flush();
  if (!out)
    throw IoError(fmt::format("cannot write a row of {}.csv: {}", what,
                              errno ? std::strerror(errno) : "the stream failed"));
}

namespace {

constexpr const char* kRefinementHeader =
    "generation,step,time,parents,children,dropped,particles,bonds,rows_rebuilt,bonds_rebuilt,"
    "rows_touched,started_broken,started_overstretched,mapping_energy,reduced_fits,dt,seconds,"
    "resorted,resort_seconds";

constexpr const char* kCracksHeader =
    "step,time,tip,x,y,z,distance,path_length,speed,angle_deg,branches";

nlohmann::ordered_json optional_number(const std::optional<double>& v) {
  return v ? nlohmann::ordered_json(*v) : nlohmann::ordered_json(nullptr);
}

nlohmann::ordered_json published_json(const measure::Published& v) {
  using Kind = measure::Published::Kind;
  if (v.kind == Kind::Number)
    return v.integer ? nlohmann::ordered_json(static_cast<std::int64_t>(v.number))
                     : nlohmann::ordered_json(v.number);
  if (v.kind == Kind::List) return nlohmann::ordered_json(v.list);
  nlohmann::ordered_json map = nlohmann::ordered_json::object();
  for (std::size_t k = 0; k < v.keys.size(); ++k) map[v.keys[k]] = published_json(v.values[k]);
  return map;
}

nlohmann::ordered_json crack_json(const measure::CrackSummary& c) {
  nlohmann::ordered_json j;
  j["name"] = c.name;
  j["initiation_time"] = optional_number(c.initiation_time);
  j["angle_deg"] = optional_number(c.angle_deg);
  j["initial_angle_deg"] = optional_number(c.initial_angle_deg);
  j["max_speed"] = optional_number(c.max_speed);
  j["mean_speed"] = optional_number(c.mean_speed);
  j["branch_times"] = c.branch_times;
  j["branch_speeds"] = c.branch_speeds;
  j["branch_positions"] = c.branch_positions;
  j["most_branches"] = c.most_branches;
  j["tip"] = c.tip;
  return j;
}

}  // namespace

namespace {
std::string history_header(int level_columns, const std::vector<std::string>& probe_columns) {
  std::string header = kHistoryHeader;
  for (int l = 0; l < level_columns; ++l) header += fmt::format(",particles_level_{}", l);
  for (const auto& column : probe_columns) header += "," + column;
  return header;
}
}  // namespace

HistoryWriter::HistoryWriter(const std::string& path, bool append, int level_columns,
                             std::vector<std::string> probe_columns)
    : out_(open_csv(path, history_header(level_columns, probe_columns).c_str(), "history", append)),
      level_columns_(level_columns),
      probe_columns_(probe_columns.size()) {}

void HistoryWriter::write(const HistoryRow& row) {
  auto text = fmt::format(
      "{},{:.17g},{:.17g},{},{},{},{:.17g},{:.17g},{:.17g},{:.17g},{:.17g},{:.17g}", row.step,
      row.time, row.dt, row.particles, row.bonds, row.broken_bonds, row.kinetic_energy,
      row.strain_energy, row.external_work, row.momentum[0], row.momentum[1], row.momentum[2]);
  for (int l = 0; l < level_columns_; ++l) {
    const auto k = static_cast<std::size_t>(l);
    text += fmt::format(",{}", k < row.particles_per_level.size() ? row.particles_per_level[k] : 0);
  }
  for (std::size_t k = 0; k < probe_columns_; ++k)
    text += fmt::format(",{:.17g}", k < row.probe_values.size() ? row.probe_values[k] : 0.0);
  write_row(out_, text + "\n", "history");
}

RefinementWriter::RefinementWriter(const std::string& path, bool append)
    : out_(open_csv(path, kRefinementHeader, "refinement", append)) {}

void RefinementWriter::write(const RefinementRow& r) {
  write_row(out_,
            fmt::format("{},{},{:.17g},{},{},{},{},{},{},{},{},{},{},{:.17g},{},{:.17g},{:.6g},{},"
                        "{:.6g}\n",
                        r.generation, r.step, r.time, r.parents, r.children, r.dropped, r.particles,
                        r.bonds, r.rows_rebuilt, r.bonds_rebuilt, r.rows_touched, r.started_broken,
                        r.started_overstretched, r.mapping_energy, r.reduced_fits, r.dt, r.seconds,
                        r.resorted, r.resort_seconds),
            "refinement");
}

CrackWriter::CrackWriter(const std::string& path, std::vector<std::string> tip_names, bool append)
    : out_(open_csv(path, kCracksHeader, "cracks", append)), names_(std::move(tip_names)) {}

void CrackWriter::write(const measure::TipRow& r) {
  write_row(
      out_,
      fmt::format("{},{:.17g},{},{:.17g},{:.17g},{:.17g},{:.17g},{:.17g},{:.17g},{:.17g},{}\n",
                  r.step, r.time, names_.at(r.tip), r.x[0], r.x[1], r.x[2], r.distance,
                  r.path_length, r.speed, r.angle_deg, r.branches),
      "cracks");
}

void write_summary(const std::string& path, const Summary& s) {
  nlohmann::ordered_json j;
  j["scene"] = s.scene_name;
  j["scene_file"] = s.scene_file;
  j["status"] = s.status;
  j["message"] = s.message;
  j["wall_seconds"] = s.wall_seconds;
  j["steps"] = s.steps;
  j["end_time"] = s.end_time;
  j["dt"] = s.dt;
  j["critical_dt"] = s.critical_dt;
  j["particles_start"] = s.particles_start;
  j["particles_end"] = s.particles_end;
  j["bonds"] = s.bonds;
  j["broken_bonds"] = s.broken_bonds;
  j["refinement_events"] = s.refinement_events;
  j["bond_updates_per_second"] = s.bond_updates_per_second;
  j["particle_steps_per_second"] = s.particle_steps_per_second;
  j["threads"] = s.threads;
  j["ranks"] = s.ranks;
  if (s.ranks > 1)
    j["distribution"] = {{"partitioner", s.partitioner},
                         {"imbalance", s.imbalance},
                         {"values_shared", s.values_shared},
                         {"repartitions", s.repartitions},
                         {"particles_moved", s.moved}};
  j["version"] = s.version;
  j["commit"] = s.commit;
  j["command_line"] = s.command_line;
  j["peak_memory_mb"] = s.peak_memory_mb;
  const auto& a = s.allocated;
  const double n = static_cast<double>(std::max<std::int64_t>(s.particles_end, 1));
  j["allocated_bytes"] = {{"total", a.total},
                          {"particle_fields", a.particles},
                          {"bond_rows", a.bonds},
                          {"other", a.other}};
  j["bytes_per_particle"] = static_cast<double>(a.total) / n;
  j["bytes_per_directed_bond"] =
      static_cast<double>(a.total) / static_cast<double>(std::max<std::int64_t>(s.bonds, 1));
  j["warnings"] = s.warnings;
  j["active_effects"] = s.active_effects;
  nlohmann::ordered_json phases = nlohmann::ordered_json::object();
  for (const PhaseSeconds& p : s.phases) phases[p.name] = p.seconds;
  j["seconds_per_phase"] = phases;
  nlohmann::ordered_json materials = nlohmann::ordered_json::object();
  for (const MaterialCount& m : s.materials)
    materials[m.name] = {{"particles", m.particles},
                         {"bonds", m.bonds},
                         {"broken_bonds", m.broken_bonds},
                         {"damaged_particles", m.damaged_particles}};
  j["materials"] = materials;
  if (const auto& t = s.time_levels) {
    std::int64_t evaluated = 0;
    for (const auto e : t->evaluated) evaluated += e;
    j["time_levels"] = {
        {"particles", t->particles},
        {"bond_evaluations", t->evaluated},
        {"one_step_bond_evaluations", t->one_step},
        {"saving",
         evaluated > 0 ? static_cast<double>(t->one_step) / static_cast<double>(evaluated) : 1.0}};
  }
  if (s.cracks) {
    j["rayleigh_speed"] = s.cracks->rayleigh_speed;
    nlohmann::ordered_json cracks = nlohmann::ordered_json::array();
    for (const auto& c : s.cracks->cracks) cracks.push_back(crack_json(c));
    j["cracks"] = cracks;
    if (s.cracks->published) j["published"] = published_json(*s.cracks->published);
  }
  write_text_atomically(path, j.dump(2) + "\n");
}

Progress::Progress(std::int64_t total_steps, bool enabled, std::int64_t first_step,
                   std::optional<double> end_time)
    : total_(total_steps), enabled_(enabled), first_(first_step), end_time_(end_time) {}

std::string Progress::eta(std::int64_t step, double time, double elapsed_seconds) {
  if (!end_time_) {
    if (step >= total_) return "0";
    if (step <= first_) return "--";
    return fmt::format("{:.0f}", elapsed_seconds / static_cast<double>(step - first_) *
                                     static_cast<double>(total_ - step));
  }
  if (time >= *end_time_) return "0";
  // The rate of the last window of at least 2 s (the whole run until then).
  if (rate_time_ < 0.0) {
    rate_time_ = time, rate_wall_ = elapsed_seconds;
    return "--";
  }
  if (elapsed_seconds - rate_wall_ >= 2.0 || rate_ == 0.0) {
    if (elapsed_seconds > rate_wall_ && time > rate_time_)
      rate_ = (time - rate_time_) / (elapsed_seconds - rate_wall_);
    if (elapsed_seconds - rate_wall_ >= 2.0) rate_time_ = time, rate_wall_ = elapsed_seconds;
  }
  return rate_ > 0.0 ? fmt::format("{:.0f}", (*end_time_ - time) / rate_) : "--";
}

void Progress::update(std::int64_t step, double time, std::int64_t broken_bonds,
                      double elapsed_seconds) {
  if (!enabled_) return;
  const bool last = end_time_ ? time >= *end_time_ : step >= total_;
  if (last_print_ >= 0.0 && elapsed_seconds - last_print_ < 0.25 && !last) return;
  last_print_ = elapsed_seconds;
  const std::string left = eta(step, time, elapsed_seconds);
  // "\x1b[K" clears whatever a previous, longer line left behind.
  if (end_time_)
    fmt::print(stderr, "\rstep {}  t={:.3e} / {:.3e} s ({:.0f} %)  ETA {} s  broken {}\x1b[K", step,
               time, *end_time_, 100.0 * std::min(1.0, time / *end_time_), left, broken_bonds);
  else
    fmt::print(stderr, "\rstep {}/{}  t={:.3e} s  ETA {} s  broken {}\x1b[K", step, total_, time,
               left, broken_bonds);
  std::fflush(stderr);
}

void Progress::finish() {
  if (enabled_ && last_print_ >= 0.0) {
    fmt::print(stderr, "\n");
    std::fflush(stderr);
  }
  last_print_ = -1.0;
}

bool Progress::wanted() {
  return isatty(STDERR_FILENO) != 0 && std::getenv("CI") == nullptr;
}

}  // namespace dhpd::io

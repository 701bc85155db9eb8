// A scene's cost before anything is allocated (docs/scenes.md, "Resources"): particles from
// lattice counts (exact for small lattices and points files, sampled otherwise), bonds from the
// lattice offsets inside one interior horizon, memory from what the state stores per particle and
// per bond, the stable step from the same offsets (docs/theory.md §9).
#include "tools/scene/estimate.hpp"

#include <fmt/format.h>
#include <yaml-cpp/yaml.h>
#include <algorithm>
#include <array>
#include <cmath>
#include <fstream>
#include <sstream>

#include "engine/base/errors.hpp"
#include "engine/checkpoint/checkpoint.hpp"
#include "engine/discretization/bonds.hpp"
#include "engine/physics/material_law.hpp"
#include "tools/scene/build.hpp"

namespace dhpd::scene {

namespace {

/// Lattices up to this many cells in all are counted point by point (a fraction of a second).
constexpr double kExactCells = 4e6;
/// Samples per axis when a shape's share of its bounding box is estimated.
constexpr int kSamples[4] = {0, 4096, 96, 24};

/// One interior particle's horizon on a lattice of unit spacing: its bonds and Σ β/|ξ|.
struct HorizonSums {
  double bonds = 0, beta_over_length = 0;
  std::vector<std::array<int, 3>> offsets;  ///< the lattice offsets of the bonds
};

HorizonSums interior_horizon(int dim, double factor, PartialVolume rule) {
  // r_j in cells: half a cell for linear, the equal-measure radius for exact (as the bond builder).
  const double r = rule == PartialVolume::Exact ? (dim == 1   ? 0.5
                                                   : dim == 2 ? 1.0 / std::sqrt(M_PI)
                                                              : std::cbrt(0.75 / M_PI))
                                                : 0.5;
  const int reach = static_cast<int>(std::ceil(factor + r)) + 1;
  HorizonSums h;
  const int ny = dim >= 2 ? reach : 0, nz = dim == 3 ? reach : 0;
  for (int i = -reach; i <= reach; ++i)
    for (int j = -ny; j <= ny; ++j)
      for (int k = -nz; k <= nz; ++k) {
        const double d = std::sqrt(double(i * i + j * j + k * k));
        if (d == 0.0) continue;
        const double beta = partial_volume_factor(rule, dim, d, factor, r);
        if (beta <= 0.0) continue;
        h.bonds += 1.0;
        h.beta_over_length += beta / d;
        h.offsets.push_back({i, j, k});
      }
  return h;
}

/// Samples of the bounding box of `shape`: the share inside it (weighted by `density`, 1 for a
/// lattice), and in `zoned` the share inside it and a zone.
template <class Density>
double inside_share(const geometry::Shape& shape, int dim,
                    const std::vector<geometry::Shape>& zones, double& zoned, Density density) {
  const auto box = shape.bounds(dim);
  const int n = kSamples[dim];
  double in = 0, in_zone = 0, all = 0;
  const int ny = dim >= 2 ? n : 1, nz = dim == 3 ? n : 1;
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < ny; ++j)
      for (int k = 0; k < nz; ++k) {
        geometry::Vec3 x{0, 0, 0};
        const int idx[3] = {i, j, k};
        for (int a = 0; a < dim; ++a)
          x[a] = box.min[a] + (idx[a] + 0.5) / n * (box.max[a] - box.min[a]);
        all += 1;
        if (!shape.contains(x, dim)) continue;
        const double w = density(x);
        in += w;
        for (const auto& z : zones)
          if (z.contains(x, dim)) {
            in_zone += w;
            break;
          }
      }
  zoned = all > 0 ? in_zone / all : 0.0;
  return all > 0 ? in / all : 0.0;
}

double box_measure(const geometry::Shape& shape, int dim) {
  const auto box = shape.bounds(dim);
  double m = 1.0;
  for (int a = 0; a < dim; ++a) m *= box.max[a] - box.min[a];
  return m;
}

/// Data lines of a points file (no parsing: the loader checks them).
double points_in_file(const std::string& path) {
  std::ifstream in(path);
  std::string line;
  double n = 0;
  while (std::getline(in, line)) {
    const auto first = line.find_first_not_of(" \t\r");
    if (first != std::string::npos && line[first] != '#') n += 1;
  }
  return n;
}

struct Counts {
  double particles = 0, zoned = 0, finest = HUGE_VAL, coarsest = 0;
  double bonds = -1;  ///< from the lattice parts' boxes, when every part is a lattice
  bool exact = false;
};

/// Bonds of a lattice part: the pairs of an n1 × n2 × n3 box at each offset, Π (n_a − |k_a|),
/// times the share of the box the shape fills (exact for a box without pre-cracks).
double lattice_bonds(const std::array<std::int64_t, 3>& n, const HorizonSums& sums, double share) {
  double pairs = 0;
  for (const auto& k : sums.offsets) {
    double p = 1;
    for (int a = 0; a < 3; ++a) p *= std::max<double>(0.0, double(n[a]) - std::abs(k[a]));
    pairs += p;
  }
  return pairs * share;
}

Counts count_particles(const Scene& s, const std::vector<geometry::Shape>& zones,
                       const HorizonSums& sums) {
  const int dim = s.dimension;
  Counts c;
  c.bonds = 0;
  for (const auto& part : s.body) {
    if (part.kind != PartKind::Lattice) {
      c.bonds = -1;
      break;
    }
    const auto n = geometry::lattice_cells({part.shape, part.spacing, 0}, dim);
    double zoned = 0;
    const double share =
        inside_share(part.shape, dim, {}, zoned, [](const geometry::Vec3&) { return 1.0; });
    c.bonds += lattice_bonds(n, sums, share);
  }
  double cells = 0;
  bool meshes = false;
  for (const auto& part : s.body) {
    meshes = meshes || part.kind == PartKind::Mesh;
    if (part.kind == PartKind::Lattice) {
      const auto n = geometry::lattice_cells({part.shape, part.spacing, 0}, dim);
      cells += double(n[0]) * double(n[1]) * double(n[2]);
    }
  }
  if (!meshes && cells <= kExactCells) {
    const auto pts = body_points(s);
    c.exact = true;
    c.particles = static_cast<double>(pts.size());
    for (std::size_t i = 0; i < pts.size(); ++i) {
      c.finest = std::min(c.finest, pts.spacing[i]);
      c.coarsest = std::max(c.coarsest, pts.spacing[i]);
      for (const auto& z : zones)
        if (z.contains(pts.position[i], dim)) {
          c.zoned += 1;
          break;
        }
    }
    return c;
  }
  for (const auto& part : s.body) {
    double zoned = 0, n = 0, h = part.spacing;
    if (part.kind == PartKind::PointsFile) {
      n = points_in_file(part.points_file);
      h = 0;  // unknown until read
    } else if (part.kind == PartKind::Mesh) {
      // A mesh node per about h^dim / 2.7 of area (2D) or h^dim / 1.15 of volume (3D), h the
      // mesh size where the node is (measured on the ungraded meshes of cases/kw_irregular).
      const double per = dim == 2 ? 2.7 : 1.15;
      const auto& mesh = part.mesh;
      h = mesh.size;
      const double share = inside_share(
          part.shape, dim, zones, zoned,
          [&](const geometry::Vec3& x) { return per * std::pow(mesh.size / mesh.at(x), dim); });
      n = box_measure(part.shape, dim) / std::pow(h, dim) * share;
      zoned *= box_measure(part.shape, dim) / std::pow(h, dim);
    } else {
      const double share =
          inside_share(part.shape, dim, zones, zoned, [](const geometry::Vec3&) { return 1.0; });
      n = box_measure(part.shape, dim) / std::pow(h, dim) * share;
      zoned *= box_measure(part.shape, dim) / std::pow(h, dim);
    }
    c.particles += n;
    c.zoned += zoned;
    if (h > 0) c.finest = std::min(c.finest, h), c.coarsest = std::max(c.coarsest, h);
  }
  return c;
}

/// The stable step of an interior particle of spacing h (docs/theory.md eq. 9.1): the smallest
/// over the materials; DH-PD rows hold each bond twice (own and dual), classical ones 2C once.
double interior_stable_dt(const Scene& s, const SimulationSetup& probe, double h, double h_max,
                          const HorizonSums& sums) {
  const double horizon = s.horizon_factor * (s.model == ForceModel::ConstantHorizon ? h_max : h);
  const double volume = probe.section.volume_of_cell(std::pow(h, s.dimension));
  double dt = HUGE_VAL;
  for (const auto& m : s.materials) {
    const double C = micromodulus(m.law, probe.section, horizon);
    const double stiffness = 2.0 * C * volume * sums.beta_over_length / h;
    dt = std::min(dt, std::sqrt(2.0 * m.law.rho / stiffness));
  }
  return dt;
}

}  // namespace

double run_bytes(double n, double b, ForceModel model, bool refines) {
  const auto per = state_bytes(model);
  // Per particle beside the state: the guard's copy of the state fields (displacement, velocity,
  // force density, position: 12 doubles; damage), the kernel's packed y and V (4 doubles), the
  // k-d tree of the bond search (its points and index, about 6 doubles).
  constexpr double kStateFields = 13 * 8.0, kPacked = 4 * 8.0, kSearch = 6 * 8.0;
  constexpr double kFlagBytes = 1.0;  // the guard's copy of the rows' flags, per entry
  double bytes =
      n * (per.per_particle + kStateFields + kPacked + kSearch) + b * (per.per_bond + kFlagBytes);
  if (refines) bytes += n * per.per_particle + b * kFlagBytes;  // the whole copy before an event
  return bytes;
}

ResourceEstimate estimate_resources(const Scene& s) {
  const int dim = s.dimension;
  const bool refined = s.refinement.has_value();
  const auto& settings = refined ? s.refinement->settings : refine::Settings{};
  const int levels = refined ? settings.max_level : 0;
  const double split = std::pow(2.0, dim);
  const auto sums = interior_horizon(dim, s.horizon_factor, s.partial_volume);
  const Counts c =
      count_particles(s, refined ? settings.zones : std::vector<geometry::Shape>{}, sums);
  ResourceEstimate e;
  e.exact_particles = c.exact && (!refined || settings.zones.empty());
  // The zones' particles split down to max_level at the start.
  const double zone_levels = refined && !settings.zones.empty() ? levels : 0;
  e.particles = c.particles + c.zoned * (std::pow(split, zone_levels) - 1.0);
  // Bonds: the lattice boxes' pairs (boundaries counted), else an interior horizon per particle;
  // the zones' particles add their split share at the interior count.
  const double base_bonds = c.bonds >= 0 ? c.bonds : c.particles * sums.bonds;
  e.bonds = base_bonds + (e.particles - c.particles) * sums.bonds;
  auto bytes = [&](double n, double b) { return run_bytes(n, b, s.model, refined); };
  e.bytes = bytes(e.particles, e.bonds);
  const bool triggers = refined && settings.trigger.any();
  e.particles_worst = triggers ? c.particles * std::pow(split, levels) : e.particles;
  e.bonds_worst = base_bonds * (e.particles_worst / std::max(c.particles, 1.0));
  e.bytes_worst = bytes(e.particles_worst, e.bonds_worst);
  SimulationSetup probe;
  probe.section = {dim, s.plane, s.thickness, s.area};
  const double finest = std::isfinite(c.finest) ? c.finest : 0.0;
  if (finest > 0) {
    const double h = finest / std::pow(2.0, zone_levels);
    e.stable_dt = interior_stable_dt(s, probe, h, c.coarsest, sums);
    // A static run's dt is its load increment (docs/theory.md §22).
    e.dt = s.statics ? 1.0 / static_cast<double>(s.time.steps.value_or(1))
                     : s.time.dt.value_or(s.time.safety * e.stable_dt);
    const double worst_dt =
        s.time.dt ? *s.time.dt : e.dt / std::pow(2.0, triggers ? levels - zone_levels : 0);
    e.steps = s.time.steps ? double(*s.time.steps) : std::ceil(*s.time.end / e.dt);
    e.steps_worst = s.time.steps ? double(*s.time.steps) : std::ceil(*s.time.end / worst_dt);
  }
  return e;
}

double memory_budget_bytes(std::optional<double> max_memory_mb) {
  if (max_memory_mb) return *max_memory_mb * 1e6;
  std::ifstream in("/proc/meminfo");
  std::string key;
  double kb = 0;
  while (in >> key >> kb) {
    if (key == "MemAvailable:") return kb * 1024.0;
    in.ignore(256, '\n');
  }
  return HUGE_VAL;
}

void refuse_if_too_big(const Scene& s, const ResourceEstimate& e, double budget, bool given) {
  if (e.bytes <= budget) return;
  throw InputError(fmt::format(
      "{}: the scene needs about {:.3g} GB ({:.3g} particles, {:.3g} bonds; the state twice: "
      "the run keeps its last good copy), more than the {:.3g} GB {} (allowed: a scene that "
      "fits: a coarser spacing, a smaller body or horizon factor{})",
      s.file, e.bytes / 1e9, e.particles, e.bonds, budget / 1e9,
      given ? "--max-memory allows" : "this machine has available",
      given ? ", or a larger --max-memory" : ", or --max-memory MB when you know better"));
}

std::string estimate_yaml(const ResourceEstimate& e, double budget) {
  YAML::Emitter out;
  out << YAML::BeginMap << YAML::Key << "estimate" << YAML::Value << YAML::BeginMap;
  out << YAML::Key << "particles" << YAML::Value << std::llround(e.particles);
  out << YAML::Key << "particles_counted" << YAML::Value
      << (e.exact_particles ? "exactly" : "from the shapes' measures (sampled)");
  out << YAML::Key << "bonds" << YAML::Value << std::llround(e.bonds);
  out << YAML::Key << "memory_mb" << YAML::Value << std::llround(e.bytes / 1e6);
  out << YAML::Key << "stable_dt" << YAML::Value << fmt::format("{:.4g}", e.stable_dt);
  out << YAML::Key << "dt" << YAML::Value << fmt::format("{:.4g}", e.dt);
  out << YAML::Key << "steps" << YAML::Value << std::llround(e.steps);
  if (e.particles_worst > e.particles) {
    out << YAML::Key << "refinement_worst_case" << YAML::Value << YAML::BeginMap;
    out << YAML::Key << "what" << YAML::Value << "every particle split down to max_level";
    out << YAML::Key << "particles" << YAML::Value << std::llround(e.particles_worst);
    out << YAML::Key << "memory_mb" << YAML::Value << std::llround(e.bytes_worst / 1e6);
    out << YAML::Key << "steps" << YAML::Value << std::llround(e.steps_worst);
    out << YAML::EndMap;
  }
  if (std::isfinite(budget))
    out << YAML::Key << "memory_budget_mb" << YAML::Value << std::llround(budget / 1e6);
  out << YAML::EndMap << YAML::EndMap;
  return std::string(out.c_str()) + "\n";
}

}  // namespace dhpd::scene

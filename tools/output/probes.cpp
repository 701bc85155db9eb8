// Probes: the particle nearest to a point, found by a scan of the reference positions (a row costs
// N distance evaluations per probe, taken at history rows only).
#include "tools/output/probes.hpp"

#include <limits>

namespace dhpd::io {

std::vector<std::string> probe_columns(const std::vector<Probe>& probes, int dim) {
  static constexpr const char* kAxes[] = {"x", "y", "z"};
  std::vector<std::string> columns;
  for (const auto& probe : probes)
    for (const char* field : {"u", "v"})
      for (int a = 0; a < dim; ++a) columns.push_back(probe.name + "_" + field + kAxes[a]);
  return columns;
}

std::size_t nearest_particle(const ParticleStore& p, const geometry::Vec3& at) {
  std::size_t best = 0;
  double best_d2 = std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < p.size(); ++i) {
    double d2 = 0.0;
    for (int a = 0; a < p.dim(); ++a) {
      const double d = p.reference_position[a][i] - at[a];
      d2 += d * d;
    }
    if (d2 < best_d2 || (d2 == best_d2 && p.id[i] < p.id[best])) best = i, best_d2 = d2;
  }
  return best;
}

std::vector<double> probe_values(const ParticleStore& p, const std::vector<Probe>& probes) {
  std::vector<double> values;
  for (const auto& probe : probes) {
    const std::size_t i = nearest_particle(p, probe.at);
    for (const auto* field : {&p.displacement, &p.velocity})
      for (int a = 0; a < p.dim(); ++a) values.push_back((*field)[a][i]);
  }
  return values;
}

}  // namespace dhpd::io

// Per-particle output arrays of a frame, by name from the engine's field list
// (engine/output_fields.hpp), built once per frame (never in the time loop).
#include "tools/output/frame_fields.hpp"

#include <variant>

#include "engine/output_fields.hpp"

namespace dhpd::io {

std::vector<double> frame_points(const Simulation& sim) {
  const auto& X = sim.particles().reference_position;
  std::vector<double> out(3 * X[0].size());
  for (std::size_t i = 0; i < X[0].size(); ++i)
    for (int a = 0; a < 3; ++a) out[3 * i + a] = X[a][i];
  return out;
}

std::vector<PointField> frame_fields(Simulation& sim, const std::vector<std::string>& names) {
  std::vector<PointField> out;
  out.reserve(names.size());
  for (const auto& n : names) {
    auto v = output_values(sim, n);
    std::visit(
        [&](auto& values) {
          out.push_back({n, v.components, std::move(values)});
        },
        v.values);
  }
  return out;
}

}  // namespace dhpd::io

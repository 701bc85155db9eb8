// Per-particle output arrays of a frame, by name from the engine's field list
// (engine/output_fields.hpp), built once per frame (never in the time loop).
#include "tools/output/frame_fields.hpp"

#include <variant>

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

FrameCopy::FrameCopy(Simulation& sim, const std::vector<std::string>& names, FrameArrays reuse)
    : points(std::move(reuse.points)),
      store_(sim.particles()),
      size_(static_cast<std::int64_t>(sim.particles().size())) {
  points.resize(3 * sim.particles().size());  // copy() writes every value
  points_to_ = points.data();
  fields.reserve(names.size());
  for (std::size_t k = 0; k < names.size(); ++k) {
    const auto& n = names[k];
    const auto f = exported_store_field(sim.particles(), n);
    auto old = k < reuse.fields.size() && reuse.fields[k].name == n
                   ? std::move(reuse.fields[k].values)
                   : decltype(PointField::values){};
    auto v = f ? blank_values(*f, sim.particles().size(), std::move(old)) : output_values(sim, n);
    std::visit(
        [&](auto& values) {
          if (f) sources_.push_back({*f, values.data()});
          fields.push_back({n, v.components, std::move(values)});  // the buffer moves along
        },
        v.values);
  }
}

void FrameCopy::copy(std::int64_t begin, std::int64_t end) {
  if (finished_.load(std::memory_order_relaxed)) return;
  const auto& X = store_.reference_position;
  for (std::int64_t i = begin; i < end; ++i)
    for (int a = 0; a < 3; ++a) points_to_[3 * i + a] = X[a][i];
  for (const auto& s : sources_) copy_values(s.field, s.to, begin, end);
  copied_.fetch_add(end - begin, std::memory_order_relaxed);
}

void FrameCopy::finish() {
  if (finished_.load(std::memory_order_relaxed)) return;
  if (copied_.load(std::memory_order_relaxed) != size_) {
    copied_.store(0, std::memory_order_relaxed);
    copy(0, size_);
  }
  finished_.store(true, std::memory_order_relaxed);
}

}  // namespace dhpd::io

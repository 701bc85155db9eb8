// Fictitious boundary layers (docs/theory.md §23): the displacement rule of the horizon-size paper
// eqs. 29–31 (u_f = 2U* − u), and the traction rule of its eqs. 32–35 written for any section
// through Hooke's law (the same formulas in plane stress).
#include "engine/physics/fictitious_layer.hpp"

#include <algorithm>
#include <map>
#include <utility>

namespace dhpd {
namespace {

/// The coordinates of slot i along the face's axes (all but `normal`), as a key.
std::array<double, 3> face_key(const ParticleStore& p, std::int32_t i, int normal, int skip = -1) {
  std::array<double, 3> key{0, 0, 0};
  for (int a = 0; a < p.dim(); ++a)
    if (a != normal && a != skip) key[a] = p.reference_position[a][static_cast<std::size_t>(i)];
  return key;
}

/// Per layer particle, the mirrored body particle nearest the face on its line.
std::vector<std::int32_t> boundary_of(const ResolvedLayer& l, const ParticleStore& p) {
  const int n = l.spec.axis;
  std::map<std::array<double, 3>, std::int32_t> nearest;
  for (const auto m : l.mirror) {
    const auto key = face_key(p, m, n);
    const auto it = nearest.find(key);
    const auto depth = [&](std::int32_t i) {
      return l.spec.side * -p.reference_position[n][static_cast<std::size_t>(i)];
    };
    if (it == nearest.end() || depth(m) < depth(it->second)) nearest[key] = m;
  }
  std::vector<std::int32_t> out;
  for (const auto f : l.particle) out.push_back(nearest.at(face_key(p, f, n)));
  return out;
}

/// For each boundary particle, its neighbours on the face along each face axis (−1: none).
void find_beside(ResolvedLayer& l, const ParticleStore& p) {
  const int n = l.spec.axis;
  std::vector<std::int32_t> face(l.boundary);
  std::sort(face.begin(), face.end());
  face.erase(std::unique(face.begin(), face.end()), face.end());
  std::map<std::int32_t, std::array<std::int32_t, 6>> beside;
  for (const auto b : face) beside[b].fill(-1);
  for (int t = 0; t < p.dim(); ++t) {
    if (t == n) continue;
    auto line = face;  // by the other face axes, then along t
    std::sort(line.begin(), line.end(), [&](std::int32_t a, std::int32_t b) {
      const auto ka = face_key(p, a, n, t), kb = face_key(p, b, n, t);
      if (ka != kb) return ka < kb;
      return p.reference_position[t][static_cast<std::size_t>(a)] <
             p.reference_position[t][static_cast<std::size_t>(b)];
    });
    for (std::size_t k = 0; k + 1 < line.size(); ++k)
      if (face_key(p, line[k], n, t) == face_key(p, line[k + 1], n, t)) {
        beside[line[k]][2 * t + 1] = line[k + 1];
        beside[line[k + 1]][2 * t] = line[k];
      }
  }
  for (const auto b : l.boundary) l.beside.push_back(beside.at(b));
}

/// ∂u_a/∂x_t at boundary particle k's slot from its neighbours on the face (0 with none).
double tangential(const ParticleStore& p, const std::array<std::int32_t, 6>& beside, std::int32_t b,
                  int a, int t) {
  std::int32_t lo = beside[2 * t], hi = beside[2 * t + 1];
  if (lo < 0 && hi < 0) return 0.0;
  if (lo < 0) lo = b;
  if (hi < 0) hi = b;
  const auto L = static_cast<std::size_t>(lo), H = static_cast<std::size_t>(hi);
  return (p.displacement[a][H] - p.displacement[a][L]) /
         (p.reference_position[t][H] - p.reference_position[t][L]);
}

/// Lamé's λ of the section (plane stress: E ν/(1 − ν²); 1D: 0) and μ (1D: E/2, so λ + 2μ = E).
std::pair<double, double> lame(const Material& m, const Section& s) {
  const double E = m.E, nu = poisson_ratio(m, s);
  if (s.dim == 1) return {0.0, 0.5 * E};
  const double mu = E / (2.0 * (1.0 + nu));
  if (s.dim == 2 && s.plane == PlaneMode::Stress) return {E * nu / (1.0 - nu * nu), mu};
  return {E * nu / ((1.0 + nu) * (1.0 - 2.0 * nu)), mu};
}

}  // namespace

ResolvedLayer resolve_layer(const FictitiousLayerSpec& spec, const ParticleStore& p) {
  std::int32_t largest = 0;
  for (std::size_t i = 0; i < p.size(); ++i) largest = std::max(largest, p.id[i]);
  std::vector<std::int32_t> slot(static_cast<std::size_t>(largest) + 1, -1);
  for (std::size_t i = 0; i < p.size(); ++i)
    slot[static_cast<std::size_t>(p.id[i])] = static_cast<std::int32_t>(i);
  ResolvedLayer l;
  l.spec = spec;
  for (std::size_t k = 0; k < spec.points.size(); ++k) {
    l.particle.push_back(slot.at(static_cast<std::size_t>(spec.points[k])));
    l.mirror.push_back(slot.at(static_cast<std::size_t>(spec.mirrors[k])));
  }
  l.boundary = boundary_of(l, p);
  find_beside(l, p);
  return l;
}

void apply_layer(const ResolvedLayer& l, double lambda, const std::vector<Material>& materials,
                 const Section& section, ParticleStore& p) {
  const int dim = p.dim(), n = l.spec.axis;
  for (std::size_t k = 0; k < l.particle.size(); ++k) {
    const auto f = static_cast<std::size_t>(l.particle[k]);
    if (l.spec.rule == FictitiousLayerSpec::Rule::Displacement) {
      const auto m = static_cast<std::size_t>(l.mirror[k]);
      for (int a = 0; a < dim; ++a) {
        const auto& held = l.spec.displacement[a];
        p.displacement[a][f] =
            held ? 2.0 * lambda * *held - p.displacement[a][m] : p.displacement[a][m];
      }
    } else {
      const auto b = l.boundary[k];
      const auto B = static_cast<std::size_t>(b);
      const auto [lam, mu] = lame(materials.at(static_cast<std::size_t>(p.material[B])), section);
      // σ·n̂ = t with n̂ = side e_n: σ_an = side t_a (scaled by the load factor).
      double trace = 0.0;
      for (int t = 0; t < dim; ++t)
        if (t != n) trace += tangential(p, l.beside[k], b, t, t);
      std::array<double, 3> gradient{0, 0, 0};  // ∂u_a/∂x_n
      gradient[n] = (l.spec.side * lambda * l.spec.traction[n] - lam * trace) / (lam + 2.0 * mu);
      for (int t = 0; t < dim; ++t)
        if (t != n)
          gradient[t] =
              l.spec.side * lambda * l.spec.traction[t] / mu - tangential(p, l.beside[k], b, n, t);
      const double step = p.reference_position[n][f] - p.reference_position[n][B];
      for (int a = 0; a < dim; ++a)
        p.displacement[a][f] = p.displacement[a][B] + gradient[a] * step;
    }
    for (int a = 0; a < dim; ++a)
      p.position[a][f] = p.reference_position[a][f] + p.displacement[a][f];
  }
}

}  // namespace dhpd

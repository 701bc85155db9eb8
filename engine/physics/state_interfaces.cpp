// Consistent level interfaces for the ordinary state-based family (docs/theory.md §20.6): the
// minimum-change deviatoric factors from a matrix-free conjugate gradient on J W⁻¹ Jᵀ μ = −F.
#include "engine/physics/state_interfaces.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <optional>

#include "engine/base/parallel.hpp"
#include "engine/physics/state_interface_system.hpp"

namespace dhpd {

using namespace state_interface_detail;

std::vector<double> state_strain_forces(const BondRows& rows, const ParticleStore& p,
                                        const OrdinaryState& model) {
  const int n = model.dimension(), c = strain_count(n);
  const StrainStates states(rows, p, model);
  std::vector<double> out(p.size() * static_cast<std::size_t>(c * n), 0.0);
  for_each_particle(p.size(), [&](std::size_t i) {
    strain_force_of(rows, p, model, states, i, &out[i * static_cast<std::size_t>(c * n)]);
  });
  return out;
}

namespace {

/// Makes each owner's ν change none of its dilatations (θ stays the trace of every uniform
/// strain, which the solve's weighted rows only approach): the W_ν-smallest change of ν with
/// Σ_b h w ν |ξ|² n·ε^q·n = 0 for every q, a c×c system per owner.
void keep_dilatations(const StateSystem& sys, std::vector<double>& x) {
  const std::size_t U = sys.unknowns.size();
  const int c = sys.strains;
  using Small = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, 6, 6>;
  using SmallVector = Eigen::Matrix<double, Eigen::Dynamic, 1, 0, 6, 1>;
  for (const auto& o : sys.owners) {
    Small gram = Small::Zero(c, c);
    SmallVector change = SmallVector::Zero(c);
    const auto row = [&](const Unknown& u, int q) { return u.H * u.length * u.length * u.s[q]; };
    for (auto b = o.first_unknown; b < o.last_unknown; ++b) {
      const auto& u = sys.unknowns[static_cast<std::size_t>(b)];
      for (int q = 0; q < c; ++q) {
        change[q] += row(u, q) * x[U + static_cast<std::size_t>(b)];
        for (int r = 0; r < c; ++r) gram(q, r) += row(u, q) * row(u, r) / u.dilatation_weight;
      }
    }
    const SmallVector y = gram.ldlt().solve(change);
    if (!y.allFinite()) continue;
    for (auto b = o.first_unknown; b < o.last_unknown; ++b) {
      const auto& u = sys.unknowns[static_cast<std::size_t>(b)];
      double shift = 0.0;
      for (int q = 0; q < c; ++q) shift += row(u, q) * y[q];
      x[U + static_cast<std::size_t>(b)] -= shift / u.dilatation_weight;
    }
  }
}

/// The first Tikhonov weight of the state-based solve: 10× §14's. With 1e-3 the events of
/// Kalthoff–Winkler 2D adaptive took 500 iterations each (0.43 s) and mostly fell back to 0.1;
/// with 1e-2, 180 (the run 20 s instead of 44 s, the same cracks within 2.5°).
constexpr double kStateDamping = 1e-2;

/// Solves for the factors with the weakest damping whose factors stay within the bounds but for
/// a few (kClippedShare), as §14 does, and writes them: φ = 1 + λ to rows.factor, ψ = 1 + ν to
/// rows.dilatation_factor.
void solve_and_write(const StateSystem& sys, BondRows& rows, InterfaceCorrection& out) {
  const auto arena = static_cast<std::size_t>(rows.rows.arena);
  if (rows.factor.empty()) rows.factor.assign(arena, 1.0f);
  if (rows.dilatation_factor.empty()) rows.dilatation_factor.assign(arena, 1.0f);
  const auto solve = [&](double gamma, std::vector<double>& x) {
    StateSolver solver(sys, gamma);
    Eigen::VectorXd mu;
    const int iterations = solver.solve(mu);
    x = solver.factors(mu);
    return iterations;
  };
  auto x = least_damped_changes({kStateDamping, 1e-1}, kSmallestStateFactor, kLargestStateFactor,
                                solve, out.iterations);
  keep_dilatations(sys, x);
  const std::size_t U = sys.unknowns.size();
  for (std::size_t b = 0; b < x.size(); ++b) {
    const double factor = clipped_factor(x[b], kSmallestStateFactor, kLargestStateFactor, out);
    x[b] = std::clamp(x[b], kSmallestStateFactor - 1.0, kLargestStateFactor - 1.0);  // for F + J x
    const auto entry = static_cast<std::size_t>(sys.unknowns[b % U].entry);
    (b < U ? rows.factor : rows.dilatation_factor)[entry] = static_cast<float>(factor);
  }
  // What is left at the constrained particles: F + J x (linear in x but for the product of ν
  // with λ's change of α, a second-order term).
  Eigen::VectorXd after = sys.forces;
  StateSolver(sys, 0.0).add_forward(x, after);
  double largest = 0.0;
  for (std::size_t k = 0; k < sys.particles.size(); ++k)
    if (sys.constrained[k]) largest = std::max(largest, sys.block(after, k).norm());
  out.residual = sys.before > 0.0 ? largest / sys.before : 0.0;
}

}  // namespace

InterfaceCorrection correct_state_interfaces(BondRows& rows, const ParticleStore& p,
                                             const OrdinaryStateInputs& in,
                                             const std::vector<std::int32_t>& region,
                                             std::optional<OrdinaryState>* built) {
  InterfaceCorrection out;
  const auto constrained = reset_interface_region(rows, p, in.rule, region);
  OrdinaryState model(rows, p, in);  // the region's factors at 1, the others kept
  if (!constrained.empty()) {
    const StateSystem sys(rows, p, model, constrained);
    out.particles = constrained.size();
    out.bonds = sys.unknowns.size();
    if (!sys.unknowns.empty()) {
      solve_and_write(sys, rows, out);
      for (const auto& u : sys.unknowns)  // the solved factors on the model's weights
        model.scale_bond(rows, static_cast<std::size_t>(sys.particles[u.owner]), u.entry);
    }
  }
  if (built) built->emplace(std::move(model));
  return out;
}

}  // namespace dhpd

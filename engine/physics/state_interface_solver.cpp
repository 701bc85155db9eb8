// The state-based level-interface solve (docs/theory.md §20.6): J and Jᵀ applied matrix-free
// per owner, and the block-Jacobi conjugate gradient on (J W⁻¹ Jᵀ + R) μ = rhs.
#include "engine/physics/conjugate_gradient.hpp"
#include "engine/physics/state_interface_system.hpp"

namespace dhpd::state_interface_detail {

StateSolver::StateSolver(const StateSystem& sys, double gamma)
    : sys_(sys), reg_(sys.particles.size()), inv_(sys.particles.size()) {
  const int n = sys.size;
  for (std::size_t k = 0; k < sys.particles.size(); ++k) {
    const Block& D = sys.diag[k];
    reg_[k] = gamma * (D + (D.trace() / n) * Block::Identity(n, n));
    inv_[k] = sys.touched[k] ? Block((D + reg_[k]).ldlt().solve(Block::Identity(n, n)))
                             : Block::Zero(n, n);
  }
  theta_reg_.resize(sys.theta_diag.size());
  for (std::size_t r = 0; r < theta_reg_.size(); ++r)
    theta_reg_[r] = 2.0 * gamma * sys.theta_diag[r];
}

void StateSolver::add_forward(const std::vector<double>& x, Eigen::VectorXd& y) const {
  const int n = sys_.dim, c = sys_.strains;
  const std::size_t U = sys_.unknowns.size();
  const double nd = n;
  for (std::size_t oi = 0; oi < sys_.owners.size(); ++oi) {
    const auto& o = sys_.owners[oi];
    double dtheta[6] = {}, dS[6] = {};
    for (auto b = o.first_unknown; b < o.last_unknown; ++b) {
      const auto& u = sys_.unknowns[static_cast<std::size_t>(b)];
      const double l2 = u.length * u.length;
      const double lambda = x[static_cast<std::size_t>(b)], nu = x[U + static_cast<std::size_t>(b)];
      for (int q = 0; q < c; ++q) {
        dtheta[q] += nd / o.m * u.H * nu * l2 * u.s[q];
        dS[q] += u.G * lambda * l2 * u.d[q];
      }
    }
    double dalpha[6] = {}, dbeta[6] = {};
    for (int q = 0; q < c; ++q) {
      dS[q] -= dtheta[q] / nd * o.second;
      dalpha[q] = nd / o.m * (o.kappa * dtheta[q] - o.Q * dS[q] / nd);
      dbeta[q] = o.Q * dtheta[q] / nd;
      y[sys_.theta_row(oi) + q] += o.theta_weight * dtheta[q];
    }
    auto yo = sys_.block(y, static_cast<std::size_t>(o.local));
    for (auto e = o.first; e < o.last; ++e) {
      const auto& pe = sys_.partners[static_cast<std::size_t>(e)];
      auto yj = sys_.block(y, static_cast<std::size_t>(pe.local));
      for (int q = 0; q < c; ++q) {
        const double t = pe.coefficient * dalpha[q] - pe.deviatoric * dbeta[q];
        for (int a = 0; a < n; ++a) {
          yo[q * n + a] += t * pe.n[a];
          yj[q * n + a] -= t * pe.n[a];
        }
      }
    }
    for (auto b = o.first_unknown; b < o.last_unknown; ++b) {
      const auto& u = sys_.unknowns[static_cast<std::size_t>(b)];
      auto yj = sys_.block(y, static_cast<std::size_t>(u.other));
      const double lambda = x[static_cast<std::size_t>(b)], nu = x[U + static_cast<std::size_t>(b)];
      const double deviatoric = o.volume * u.G * lambda * o.Q * u.length;
      for (int q = 0; q < c; ++q) {
        const double t = deviatoric * u.d[q] + u.dilatation * nu * o.alpha[q];
        for (int a = 0; a < n; ++a) {
          yo[q * n + a] += t * u.n[a];
          yj[q * n + a] -= t * u.n[a];
        }
      }
    }
  }
}

void StateSolver::adjoint(const Eigen::VectorXd& mu, std::vector<double>& g) const {
  const int n = sys_.dim, c = sys_.strains;
  const std::size_t U = sys_.unknowns.size();
  const double nd = n;
  g.assign(2 * U, 0.0);
  for (std::size_t oi = 0; oi < sys_.owners.size(); ++oi) {
    const auto& o = sys_.owners[oi];
    const auto mo = sys_.block(mu, static_cast<std::size_t>(o.local));
    double reach[6] = {}, reach_g[6] = {};  // Σ_e V_o |ξ| (h w, g w) n_e · (μ_o^q − μ_e^q)
    for (auto e = o.first; e < o.last; ++e) {
      const auto& pe = sys_.partners[static_cast<std::size_t>(e)];
      const auto mj = sys_.block(mu, static_cast<std::size_t>(pe.local));
      for (int q = 0; q < c; ++q)
        for (int a = 0; a < n; ++a) {
          const double along = pe.n[a] * (mo[q * n + a] - mj[q * n + a]);
          reach[q] += pe.coefficient * along;
          reach_g[q] += pe.deviatoric * along;
        }
    }
    // The coefficients of dθ^q and of λ's part of dS^q in ⟨μ, J x⟩.
    double on_theta[6] = {}, on_S[6] = {};
    for (int q = 0; q < c; ++q) {
      on_theta[q] = nd / o.m * (o.kappa + o.Q * o.second / (nd * nd)) * reach[q] -
                    o.Q / nd * reach_g[q] + o.theta_weight * mu[sys_.theta_row(oi) + q];
      on_S[q] = -o.Q / o.m * reach[q];
    }
    for (auto b = o.first_unknown; b < o.last_unknown; ++b) {
      const auto& u = sys_.unknowns[static_cast<std::size_t>(b)];
      const auto mj = sys_.block(mu, static_cast<std::size_t>(u.other));
      const double l2 = u.length * u.length;
      double lambda = 0.0, nu = 0.0;
      for (int q = 0; q < c; ++q) {
        double along = 0.0;
        for (int a = 0; a < n; ++a) along += u.n[a] * (mo[q * n + a] - mj[q * n + a]);
        lambda += u.d[q] * (on_S[q] * u.G * l2 + o.volume * u.G * o.Q * u.length * along);
        nu += on_theta[q] * nd / o.m * u.H * l2 * u.s[q] + u.dilatation * o.alpha[q] * along;
      }
      g[static_cast<std::size_t>(b)] = lambda;
      g[U + static_cast<std::size_t>(b)] = nu;
    }
  }
}

std::vector<double> StateSolver::factors(const Eigen::VectorXd& mu) const {
  std::vector<double> g;
  adjoint(mu, g);
  const std::size_t U = sys_.unknowns.size();
  for (std::size_t b = 0; b < U; ++b) {
    g[b] /= sys_.unknowns[b].weight;
    g[U + b] /= sys_.unknowns[b].dilatation_weight;
  }
  return g;
}

void StateSolver::apply(const Eigen::VectorXd& x, Eigen::VectorXd& y) const {
  y.setZero(x.size());
  for (std::size_t k = 0; k < sys_.particles.size(); ++k)
    if (sys_.touched[k]) sys_.block(y, k) = reg_[k] * sys_.block(x, k);
  const auto rows = static_cast<Eigen::Index>(theta_reg_.size());
  y.tail(rows) =
      Eigen::Map<const Eigen::VectorXd>(theta_reg_.data(), rows).cwiseProduct(x.tail(rows));
  add_forward(factors(x), y);
}

int StateSolver::solve(Eigen::VectorXd& mu) const {
  const auto rows = static_cast<Eigen::Index>(theta_reg_.size());
  const auto precondition = [&](const Eigen::VectorXd& in, Eigen::VectorXd& out) {
    out.setZero(in.size());
    for (std::size_t k = 0; k < sys_.particles.size(); ++k)
      if (sys_.touched[k]) sys_.block(out, k) = inv_[k] * sys_.block(in, k);
    for (Eigen::Index r = 0; r < rows; ++r) {
      const auto t = static_cast<std::size_t>(r);
      const double d = sys_.theta_diag[t] + theta_reg_[t];
      out[in.size() - rows + r] = d > 0.0 ? in[in.size() - rows + r] / d : 0.0;
    }
  };
  return preconditioned_cg(
      sys_.rhs, mu, [&](const Eigen::VectorXd& in, Eigen::VectorXd& out) { apply(in, out); },
      precondition);
}

}  // namespace dhpd::state_interface_detail

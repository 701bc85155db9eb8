// The preconditioned conjugate gradient both level-interface corrections solve with
// (docs/theory.md §14, §20.6): to 10⁻³ of the right-hand side, at most 2,000 iterations.
#pragma once
#include <Eigen/Dense>

namespace dhpd {

/// Solves A x = rhs from x = 0 for a symmetric positive (semi-)definite A given as
/// apply(in, out): out = A in, preconditioned by precondition(in, out): out = M⁻¹ in. Returns
/// the iterations taken.
template <class Apply, class Precondition>
int preconditioned_cg(const Eigen::VectorXd& rhs, Eigen::VectorXd& x, Apply&& apply,
                      Precondition&& precondition) {
  x.setZero(rhs.size());
  Eigen::VectorXd r = rhs, z(rhs.size()), q(rhs.size());
  precondition(r, z);
  Eigen::VectorXd dir = z;
  double rz = r.dot(z);
  const double stop = 1e-3 * rhs.norm();
  int it = 0;
  for (; it < 2000 && r.norm() > stop; ++it) {
    apply(dir, q);
    const double alpha = rz / dir.dot(q);
    x += alpha * dir;
    r -= alpha * q;
    precondition(r, z);
    const double rz_next = r.dot(z);
    dir = z + (rz_next / rz) * dir;
    rz = rz_next;
  }
  return it;
}

}  // namespace dhpd

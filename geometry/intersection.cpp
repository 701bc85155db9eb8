// Ball–ball overlap measures (CMAME 2017 App. A, eqs. A.2 and A.3; docs/theory.md §7). The case is
// decided with CGAL's interval arithmetic and, when an interval straddles zero, exact rationals.
#include "geometry/intersection.hpp"

#include <CGAL/Exact_rational.h>
#include <CGAL/Interval_nt.h>

#include <algorithm>
#include <cmath>
#include <numbers>

namespace dhpd::geometry {
namespace {

constexpr double pi = std::numbers::pi;

/// Sign of a − (b + c), exact for the given doubles: an interval filter, then rationals.
int sign_of_gap(double a, double b, double c) {
  using Interval = CGAL::Interval_nt<>;
  const auto filtered = CGAL::sign(Interval(a) - (Interval(b) + Interval(c)));
  if (CGAL::is_certain(filtered)) return static_cast<int>(CGAL::get_certain(filtered));
  using Exact = CGAL::Exact_rational;
  return static_cast<int>(CGAL::sign(Exact(a) - (Exact(b) + Exact(c))));
}

double clamped_acos(double x) {
  return std::acos(std::clamp(x, -1.0, 1.0));
}

}  // namespace

BallOverlap classify_overlap(double d, double R, double r) {
  if (sign_of_gap(d, R, r) >= 0) return BallOverlap::Disjoint;
  // d ≤ |R − r| ⇔ d + r ≤ R or d + R ≤ r, i.e. R − (d + r) ≥ 0 or r − (d + R) ≥ 0.
  if (sign_of_gap(R, d, r) >= 0 || sign_of_gap(r, d, R) >= 0) return BallOverlap::Inside;
  return BallOverlap::Partial;
}

double ball_measure(int dim, double radius) {
  if (dim == 1) return 2.0 * radius;
  if (dim == 2) return pi * radius * radius;
  return 4.0 / 3.0 * pi * radius * radius * radius;
}

double interval_overlap_length(double d, double R, double r) {
  switch (classify_overlap(d, R, r)) {
    case BallOverlap::Disjoint:
      return 0.0;
    case BallOverlap::Inside:
      return 2.0 * std::min(R, r);
    default:
      // Partial: the particle's inner end d − r lies in the horizon, its outer end beyond R.
      return R + r - d;
  }
}

double disk_intersection_area(double d, double R, double r) {
  const auto overlap = classify_overlap(d, R, r);
  if (overlap == BallOverlap::Disjoint) return 0.0;
  const double smaller = ball_measure(2, std::min(R, r));
  if (overlap == BallOverlap::Inside) return smaller;
  const double a = r * r * clamped_acos((d * d + r * r - R * R) / (2.0 * d * r));
  const double b = R * R * clamped_acos((d * d + R * R - r * r) / (2.0 * d * R));
  const double k = (-d + r + R) * (d + r - R) * (d - r + R) * (d + r + R);
  return std::clamp(a + b - 0.5 * std::sqrt(std::max(k, 0.0)), 0.0, smaller);
}

double ball_intersection_volume(double d, double R, double r) {
  const auto overlap = classify_overlap(d, R, r);
  if (overlap == BallOverlap::Disjoint) return 0.0;
  const double smaller = ball_measure(3, std::min(R, r));
  if (overlap == BallOverlap::Inside) return smaller;
  // Eq. A.3 with d² + 2dr − 3r² + 2dR + 6rR − 3R² written as d² + 2d(R + r) − 3(R − r)², which
  // keeps the equal-radii case free of cancellation.
  const double gap = R + r - d;
  const double v =
      pi * gap * gap * (d * d + 2.0 * d * (R + r) - 3.0 * (R - r) * (R - r)) / (12.0 * d);
  return std::clamp(v, 0.0, smaller);
}

double ball_intersection_measure(int dim, double d, double R, double r) {
  if (dim == 1) return interval_overlap_length(d, R, r);
  if (dim == 2) return disk_intersection_area(d, R, r);
  return ball_intersection_volume(d, R, r);
}

double partial_volume_fraction(int dim, double d, double R, double r) {
  const double f = ball_intersection_measure(dim, d, R, r) / ball_measure(dim, r);
  return std::clamp(f, 0.0, 1.0);
}

}  // namespace dhpd::geometry

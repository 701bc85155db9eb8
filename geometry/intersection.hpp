// Overlap of a horizon ball (radius R) and a particle ball (radius r) whose centres are d apart:
// interval length (1D), disk area (2D), ball volume (3D); CMAME 2017 App. A eqs. A.2, A.3.
#pragma once

namespace dhpd::geometry {

/// How two balls of radii R and r at centre distance d lie, decided exactly for the given doubles.
enum class BallOverlap {
  Disjoint,  ///< d ≥ R + r (touching from outside counts: the overlap has zero measure)
  Inside,   ///< d ≤ |R − r|: the smaller ball lies in the larger one (touching from inside too)
  Partial,  ///< |R − r| < d < R + r
};

/// Requires d ≥ 0, R > 0, r > 0.
BallOverlap classify_overlap(double d, double R, double r);

/// Length 2ρ, area πρ² or volume 4/3 πρ³ of a ball of radius ρ in `dim` dimensions.
double ball_measure(int dim, double radius);

/// |[−R, R] ∩ [d − r, d + r]|.
double interval_overlap_length(double d, double R, double r);
/// Area of the intersection of two disks (eq. A.2 in the partial case).
double disk_intersection_area(double d, double R, double r);
/// Volume of the intersection of two balls (eq. A.3 in the partial case).
double ball_intersection_volume(double d, double R, double r);
/// One of the three above, by dimension.
double ball_intersection_measure(int dim, double d, double R, double r);

/// |ball(r) ∩ ball(R)| / |ball(r)| in [0, 1]: the share of a particle of radius r at distance d
/// that lies inside a horizon of radius R.
double partial_volume_fraction(int dim, double d, double R, double r);

}  // namespace dhpd::geometry

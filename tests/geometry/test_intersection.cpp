// Ball overlap measures of exact partial volumes (CMAME 2017 App. A, eqs. A.2, A.3; docs/theory.md
// §7): the closed forms, their degenerate cases, continuity, exact classification and Monte Carlo
// agreement.
#include <gtest/gtest.h>

#include <cfloat>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <random>
#include <utility>

#include "geometry/intersection.hpp"

namespace dhpd {
namespace {

using geometry::ball_intersection_measure;
using geometry::ball_measure;
using geometry::BallOverlap;
using geometry::classify_overlap;
using geometry::partial_volume_fraction;
constexpr double pi = std::numbers::pi;

TEST(Intersection, UnitCaseMatchesTheClosedForms) {
  const double A = geometry::disk_intersection_area(1, 1, 1);
  const double V = geometry::ball_intersection_volume(1, 1, 1);
  // R = r = d = 1: both acos terms are π/3, the root is √3: A = 2π/3 − √3/2; V = 5π/12.
  const long double pil = 3.141592653589793238462643383279502884L;
  const long double A_ref = 2.0L * pil / 3.0L - std::sqrt(3.0L) / 2.0L;
  const long double V_ref = 5.0L * pil / 12.0L;
  std::printf("A = %.16f (reference %.18Lf), V = %.16f (reference %.18Lf)\n", A, A_ref, V, V_ref);
  EXPECT_NEAR(A, 1.2283696986, 1e-10);
  EXPECT_NEAR(V, 1.3089969390, 1e-10);
  EXPECT_NEAR(A, static_cast<double>(A_ref), 1e-12);
  EXPECT_NEAR(V, static_cast<double>(V_ref), 1e-12);
  EXPECT_DOUBLE_EQ(geometry::interval_overlap_length(1, 1, 1), 1.0);
}

struct Degenerate {
  const char* name;
  double d, R, r;
  double share_of_smaller;  ///< expected overlap / measure of the smaller ball
};

TEST(Intersection, DegenerateCasesInEveryDimension) {
  const std::vector<Degenerate> cases{{"disjoint", 3.0, 1.0, 1.0, 0.0},
                                      {"tangent outside", 2.0, 1.5, 0.5, 0.0},
                                      {"tangent inside", 1.0, 1.5, 0.5, 1.0},
                                      {"contained", 0.3, 2.0, 0.5, 1.0},
                                      {"equal radii, d = 0", 0.0, 0.7, 0.7, 1.0},
                                      {"r > R, d = 0", 0.0, 0.5, 1.5, 1.0},
                                      {"r > R, horizon inside", 0.4, 0.5, 1.5, 1.0},
                                      {"r > R, tangent inside", 1.0, 0.5, 1.5, 1.0},
                                      {"r > R, disjoint", 2.5, 0.5, 1.5, 0.0}};
  for (int dim : {1, 2, 3})
    for (const auto& c : cases) {
      const double smaller = ball_measure(dim, std::min(c.R, c.r));
      const double m = ball_intersection_measure(dim, c.d, c.R, c.r);
      EXPECT_NEAR(m / smaller, c.share_of_smaller, 1e-15) << c.name << ", " << dim << "D";
      const double f = partial_volume_fraction(dim, c.d, c.R, c.r);
      EXPECT_NEAR(f, c.share_of_smaller * smaller / ball_measure(dim, c.r), 1e-15) << c.name;
    }
  EXPECT_EQ(classify_overlap(2.0, 1.5, 0.5), BallOverlap::Disjoint);
  EXPECT_EQ(classify_overlap(1.0, 1.5, 0.5), BallOverlap::Inside);
  EXPECT_EQ(classify_overlap(1.0, 0.5, 1.5), BallOverlap::Inside);
  EXPECT_EQ(classify_overlap(1.2, 1.5, 0.5), BallOverlap::Partial);
  EXPECT_DOUBLE_EQ(partial_volume_fraction(1, 1.0, 1.0, 0.5), 0.5);  // half the interval inside
  EXPECT_DOUBLE_EQ(partial_volume_fraction(2, 0.0, 1.0, 2.0), 0.25);
}

/// Just past each boundary the measure is continuous: tiny outside, almost the smaller inside.
TEST(Intersection, ContinuousAcrossTheCaseBoundaries) {
  for (int dim : {1, 2, 3})
    for (const auto& [R, r] : {std::pair{1.5, 0.5}, std::pair{0.5, 1.5}, std::pair{1.0, 1.0}}) {
      const double smaller = ball_measure(dim, std::min(R, r));
      const double eps = 1e-9;
      EXPECT_LT(ball_intersection_measure(dim, R + r - eps, R, r) / smaller, 1e-8) << dim;
      EXPECT_GT(ball_intersection_measure(dim, R + r - eps, R, r), 0.0) << dim;
      const double inner = std::abs(R - r) + eps;
      EXPECT_NEAR(ball_intersection_measure(dim, inner, R, r) / smaller, 1.0, 1e-7) << dim;
    }
}

/// The case is decided exactly: d one ulp either side of R + r (rounded), compared with a long
/// double sum that is exact for radii of similar size.
TEST(Intersection, ClassificationIsExactNearTangency) {
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> u(0.5, 1.0);
  int checked = 0;
  for (int k = 0; k < 2000; ++k) {
    const double R = u(rng), r = u(rng);
    const long double sum = static_cast<long double>(R) + static_cast<long double>(r);
    for (const double d : {std::nextafter(R + r, 0.0), R + r, std::nextafter(R + r, 9.0)}) {
      const bool disjoint = static_cast<long double>(d) >= sum;
      EXPECT_EQ(classify_overlap(d, R, r) == BallOverlap::Disjoint, disjoint) << R << " " << r;
      ++checked;
    }
  }
  static_assert(LDBL_MANT_DIG >= 64, "the reference sum needs extended precision");
  EXPECT_EQ(checked, 6000);
}

/// Lens as two circular segments / two spherical caps (an independent form of eqs. A.2, A.3).
double segments_and_caps(int dim, double d, double R, double r) {
  const double x = (d * d + R * R - r * r) / (2 * d);  // horizon centre to the radical plane
  const double y = d - x;
  if (dim == 2)
    return R * R * std::acos(x / R) - x * std::sqrt(R * R - x * x) + r * r * std::acos(y / r) -
           y * std::sqrt(r * r - y * y);
  const double h1 = R - x, h2 = r - y;
  return pi * h1 * h1 * (3 * R - h1) / 3 + pi * h2 * h2 * (3 * r - h2) / 3;
}

TEST(Intersection, PartialCaseAgreesWithSegmentsAndCaps) {
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  for (int k = 0; k < 400; ++k) {
    const int dim = 2 + k % 2;
    const double R = 0.2 + 2 * u(rng), r = 0.2 + 2 * u(rng);
    const double d = std::abs(R - r) + (R + r - std::abs(R - r)) * (0.001 + 0.998 * u(rng));
    const double ref = segments_and_caps(dim, d, R, r);
    const double got = ball_intersection_measure(dim, d, R, r);
    EXPECT_NEAR(got, ref, 1e-12 * ball_measure(dim, std::min(R, r))) << dim << "D " << d;
  }
}

/// Share of N uniform samples of ball(X_j, r) that fall inside ball(0, R), with its 1σ.
std::pair<double, double> monte_carlo_fraction(int dim, double d, double R, double r, int n,
                                               std::mt19937_64& rng) {
  // Uniform in [−1, 1) from the top 53 bits (cheaper than uniform_real_distribution).
  auto u = [&rng] { return static_cast<double>(rng() >> 11) * 0x1p-52 - 1.0; };
  int inside = 0;
  for (int k = 0; k < n;) {
    double x[3] = {0, 0, 0}, q = 0;
    for (int a = 0; a < dim; ++a) x[a] = u(), q += x[a] * x[a];
    if (q > 1.0) continue;  // rejection: uniform in the unit ball
    ++k;
    const double px = d + r * x[0], py = r * x[1], pz = r * x[2];
    inside += px * px + py * py + pz * pz <= R * R;
  }
  const double p = double(inside) / n;
  return {p, std::sqrt(p * (1 - p) / n)};
}

TEST(Intersection, AgreesWithMonteCarlo) {
  std::mt19937_64 rng(2024);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const int samples = 400000;
  double worst = 0;
  for (int k = 0; k < 50; ++k) {
    const int dim = 2 + k % 2;
    const double R = 0.3 + 2 * u(rng), r = 0.3 + 2 * u(rng);
    const double d = (R + r) * 1.1 * u(rng);
    const auto [p, sigma] = monte_carlo_fraction(dim, d, R, r, samples, rng);
    const double f = partial_volume_fraction(dim, d, R, r);
    // 4σ of the estimator, σ taken at the exact p (the estimate is exact when p is 0 or 1).
    const double tol = 4 * std::sqrt(f * (1 - f) / samples) + 1e-12;
    EXPECT_NEAR(p, f, tol) << dim << "D d=" << d << " R=" << R << " r=" << r << " σ=" << sigma;
    if (f > 0 && f < 1) worst = std::max(worst, std::abs(p - f) / std::sqrt(f * (1 - f) / samples));
  }
  std::printf("Monte Carlo (50 configurations, %d samples each): worst deviation %.3f sigma\n",
              samples, worst);
}
}  // namespace
}  // namespace dhpd

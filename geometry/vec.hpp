// The one 3-vector type of the library (positions, offsets, loads; not the hot loops, which run
// on structure-of-arrays). Its operators live in its namespace, so argument-dependent lookup finds
// them wherever a Vec3 is used: no using-declarations needed.
#pragma once
#include <array>
#include <cmath>

namespace dhpd::geometry {

/// x, y, z (unused components are 0 in 1D and 2D). An aggregate: Vec3{x, y, z}.
struct Vec3 : std::array<double, 3> {};

inline Vec3 operator-(const Vec3& a, const Vec3& b) {
  return {a[0] - b[0], a[1] - b[1], a[2] - b[2]};
}
inline Vec3 operator+(const Vec3& a, const Vec3& b) {
  return {a[0] + b[0], a[1] + b[1], a[2] + b[2]};
}
inline Vec3 operator*(double s, const Vec3& a) {
  return {s * a[0], s * a[1], s * a[2]};
}
inline Vec3 operator*(const Vec3& a, double s) {
  return s * a;
}
inline Vec3 operator-(const Vec3& a) {
  return {-a[0], -a[1], -a[2]};
}
inline Vec3& operator+=(Vec3& a, const Vec3& b) {
  for (int k = 0; k < 3; ++k) a[k] += b[k];
  return a;
}
inline Vec3& operator-=(Vec3& a, const Vec3& b) {
  for (int k = 0; k < 3; ++k) a[k] -= b[k];
  return a;
}
inline double dot(const Vec3& a, const Vec3& b) {
  return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}
inline Vec3 cross(const Vec3& a, const Vec3& b) {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}
inline double norm(const Vec3& a) {
  return std::sqrt(dot(a, a));
}

}  // namespace dhpd::geometry

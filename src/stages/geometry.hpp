// Small vector helpers on Point3 shared by the stages (internal header).
#pragma once
#include <cmath>
#include <cstdio>
#include <string>

#include "partet/mesh_types.hpp"

namespace partet {

constexpr double kPi = 3.14159265358979323846;

inline Point3 sub(const Point3& a, const Point3& b) { return {a[0] - b[0], a[1] - b[1], a[2] - b[2]}; }
inline double dot(const Point3& a, const Point3& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
inline Point3 cross(const Point3& a, const Point3& b) {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}
inline double norm(const Point3& a) { return std::sqrt(dot(a, a)); }
inline double distance(const Point3& a, const Point3& b) { return norm(sub(a, b)); }

// Signed volume of tet abcd (positive when positively oriented) in long double: its range does
// not underflow at any double input's scale. (check.cpp keeps its own, to stay independent.)
inline long double tet_volume_precise(const Point3& a, const Point3& b, const Point3& c, const Point3& d) {
  long double u[3], v[3], w[3];
  for (int k = 0; k < 3; ++k) {
    u[k] = static_cast<long double>(b[k]) - a[k];
    v[k] = static_cast<long double>(c[k]) - a[k];
    w[k] = static_cast<long double>(d[k]) - a[k];
  }
  return (u[0] * (v[1] * w[2] - v[2] * w[1]) - u[1] * (v[0] * w[2] - v[2] * w[0]) +
          u[2] * (v[0] * w[1] - v[1] * w[0])) / 6;
}

// "(x, y, z)" with enough digits to read back the same doubles.
inline std::string coordinates_text(const Point3& p) {
  char text[96];
  std::snprintf(text, sizeof text, "(%.17g, %.17g, %.17g)", p[0], p[1], p[2]);
  return text;
}

}  // namespace partet

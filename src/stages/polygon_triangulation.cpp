#include "stages/polygon_triangulation.hpp"

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>

#include <algorithm>
#include <array>
#include <cmath>

namespace partet {
namespace {

using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using Polygon = std::vector<std::size_t>;

// Newell's normal: robust for non-planar and non-convex polygons.
Point3 newell_normal(const std::vector<Point3>& corners) {
  double nx = 0, ny = 0, nz = 0;
  for (std::size_t i = 0; i < corners.size(); ++i) {
    const Point3& a = corners[i];
    const Point3& b = corners[(i + 1) % corners.size()];
    nx += (a[1] - b[1]) * (a[2] + b[2]);
    ny += (a[2] - b[2]) * (a[0] + b[0]);
    nz += (a[0] - b[0]) * (a[1] + b[1]);
  }
  return {nx, ny, nz};
}

using Flat = std::vector<Kernel::Point_2>;
using Corner = std::array<std::size_t, 3>;  // positions in the polygon

// The polygon projected to the plane of its dominant normal component, counter-clockwise.
// Empty when the polygon has no area.
Flat flatten(const std::vector<Point3>& corners) {
  const Point3 normal = newell_normal(corners);
  const double components[3] = {std::abs(normal[0]), std::abs(normal[1]), std::abs(normal[2])};
  const int drop = static_cast<int>(std::max_element(components, components + 3) - components);
  if (components[drop] == 0) return {};
  // Dropping coordinate `drop` keeps (drop+1, drop+2) as a right-handed pair, so the polygon is
  // counterclockwise in 2D exactly when the normal's dropped component is positive.
  const bool flip = normal[drop] < 0;
  Flat flat;
  for (const Point3& p : corners) {
    const double u = p[(drop + 1) % 3], v = p[(drop + 2) % 3];
    flat.emplace_back(u, flip ? -v : v);
  }
  return flat;
}

bool is_convex(const Flat& flat) {
  const std::size_t k = flat.size();
  for (std::size_t i = 0; i < k; ++i)
    if (CGAL::orientation(flat[(i + k - 1) % k], flat[i], flat[(i + 1) % k]) != CGAL::LEFT_TURN) return false;
  return true;
}

// abc is a left turn with no other remaining corner inside or on it (a corner on the ear's
// boundary blocks it too: clipping would create a T-junction).
bool is_ear(const Flat& flat, std::size_t a, std::size_t b, std::size_t c, const std::vector<std::size_t>& remaining) {
  if (CGAL::orientation(flat[a], flat[b], flat[c]) != CGAL::LEFT_TURN) return false;
  for (std::size_t other : remaining) {
    if (other == a || other == b || other == c) continue;
    if (CGAL::orientation(flat[a], flat[b], flat[other]) != CGAL::RIGHT_TURN &&
        CGAL::orientation(flat[b], flat[c], flat[other]) != CGAL::RIGHT_TURN &&
        CGAL::orientation(flat[c], flat[a], flat[other]) != CGAL::RIGHT_TURN)
      return false;
  }
  return true;
}

// Walks around the polygon clipping ears; a full round without one means there is none.
bool clip_ears(const Flat& flat, std::vector<Corner>& out) {
  std::vector<std::size_t> remaining(flat.size());
  for (std::size_t i = 0; i < remaining.size(); ++i) remaining[i] = i;
  std::size_t i = 0, misses = 0;
  while (remaining.size() > 3) {
    const std::size_t n = remaining.size();
    if (misses >= n) return false;
    i %= n;
    const std::size_t a = remaining[(i + n - 1) % n], b = remaining[i], c = remaining[(i + 1) % n];
    if (is_ear(flat, a, b, c, remaining)) {
      out.push_back({a, b, c});
      remaining.erase(remaining.begin() + static_cast<std::ptrdiff_t>(i));
      misses = 0;
      if (i > 0) --i;  // the previous corner may have just become an ear
    } else {
      ++i;
      ++misses;
    }
  }
  if (CGAL::orientation(flat[remaining[0]], flat[remaining[1]], flat[remaining[2]]) != CGAL::LEFT_TURN) return false;
  out.push_back({remaining[0], remaining[1], remaining[2]});
  return true;
}

}  // namespace

bool triangulate_polygon(const Polygon& polygon, const std::vector<Point3>& points, std::vector<Triangle>& triangles) {
  Polygon sorted = polygon;
  std::sort(sorted.begin(), sorted.end());
  if (std::adjacent_find(sorted.begin(), sorted.end()) != sorted.end()) return false;
  std::vector<Point3> corners;
  for (std::size_t index : polygon) corners.push_back(points[index]);
  const Flat flat = flatten(corners);
  if (flat.empty()) return false;
  std::vector<Corner> ears;
  if (is_convex(flat)) {
    for (std::size_t i = 1; i + 1 < flat.size(); ++i) ears.push_back({0, i, i + 1});
  } else if (!clip_ears(flat, ears)) {
    return false;
  }
  for (const Corner& e : ears)
    triangles.push_back({static_cast<std::int32_t>(polygon[e[0]]), static_cast<std::int32_t>(polygon[e[1]]),
                         static_cast<std::int32_t>(polygon[e[2]])});
  return true;
}

}  // namespace partet

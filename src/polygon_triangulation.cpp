#include "polygon_triangulation.hpp"

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>

#include <algorithm>
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

}  // namespace

// Triangulates a polygon with more than three corners, keeping its orientation. Convex
// polygons get a fan; others are ear-clipped in the plane of their dominant normal component.
// Returns false if no valid triangulation was found.
bool triangulate_polygon(const Polygon& polygon, const std::vector<Point3>& points,
                         std::vector<Triangle>& triangles) {
  const std::size_t k = polygon.size();
  Polygon sorted = polygon;
  std::sort(sorted.begin(), sorted.end());
  if (std::adjacent_find(sorted.begin(), sorted.end()) != sorted.end()) return false;

  std::vector<Point3> corners;
  for (std::size_t index : polygon) corners.push_back(points[index]);
  const Point3 normal = newell_normal(corners);
  double components[3] = {std::abs(normal[0]), std::abs(normal[1]), std::abs(normal[2])};
  int drop = static_cast<int>(std::max_element(components, components + 3) - components);
  if (components[drop] == 0) return false;
  const double sign[3] = {normal[0], normal[1], normal[2]};
  // Dropping coordinate `drop` keeps (drop+1, drop+2) as a right-handed pair, so the polygon is
  // counterclockwise in 2D exactly when the normal's dropped component is positive.
  const bool flip = sign[drop] < 0;
  std::vector<Kernel::Point_2> flat;
  for (const Point3& p : corners) {
    double u = p[(drop + 1) % 3], v = p[(drop + 2) % 3];
    flat.emplace_back(u, flip ? -v : v);
  }

  auto emit = [&](std::size_t a, std::size_t b, std::size_t c) {
    triangles.push_back({static_cast<std::int32_t>(polygon[a]),
                         static_cast<std::int32_t>(polygon[b]),
                         static_cast<std::int32_t>(polygon[c])});
  };

  bool convex = true;
  for (std::size_t i = 0; i < k && convex; ++i)
    convex = CGAL::orientation(flat[(i + k - 1) % k], flat[i], flat[(i + 1) % k]) ==
             CGAL::LEFT_TURN;
  if (convex) {
    for (std::size_t i = 1; i + 1 < k; ++i) emit(0, i, i + 1);
    return true;
  }

  auto is_ear = [&](std::size_t a, std::size_t b, std::size_t c,
                    const std::vector<std::size_t>& remaining) {
    if (CGAL::orientation(flat[a], flat[b], flat[c]) != CGAL::LEFT_TURN) return false;
    for (std::size_t other : remaining) {
      if (other == a || other == b || other == c) continue;
      // A corner on the ear's boundary blocks it too: clipping would create a T-junction.
      if (CGAL::orientation(flat[a], flat[b], flat[other]) != CGAL::RIGHT_TURN &&
          CGAL::orientation(flat[b], flat[c], flat[other]) != CGAL::RIGHT_TURN &&
          CGAL::orientation(flat[c], flat[a], flat[other]) != CGAL::RIGHT_TURN)
        return false;
    }
    return true;
  };
  std::vector<std::size_t> remaining(k);
  for (std::size_t i = 0; i < k; ++i) remaining[i] = i;
  // Walk around the polygon clipping ears; a full round without one means there is none.
  std::size_t i = 0, misses = 0;
  while (remaining.size() > 3) {
    const std::size_t n = remaining.size();
    if (misses >= n) return false;
    i %= n;
    std::size_t a = remaining[(i + n - 1) % n], b = remaining[i], c = remaining[(i + 1) % n];
    if (is_ear(a, b, c, remaining)) {
      emit(a, b, c);
      remaining.erase(remaining.begin() + static_cast<std::ptrdiff_t>(i));
      misses = 0;
      if (i > 0) --i;  // the previous corner may have just become an ear
    } else {
      ++i;
      ++misses;
    }
  }
  if (CGAL::orientation(flat[remaining[0]], flat[remaining[1]], flat[remaining[2]]) !=
      CGAL::LEFT_TURN)
    return false;
  emit(remaining[0], remaining[1], remaining[2]);
  return true;
}

}  // namespace partet

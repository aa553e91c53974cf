#include "partet/partition.hpp"

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Exact_rational.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <string>
#include <unordered_map>

#include "geometry.hpp"
#include "partet/errors.hpp"

namespace partet {
namespace {

using K = CGAL::Exact_predicates_inexact_constructions_kernel;

K::Plane_3 to_cgal(const CutPlane& plane) {
  return K::Plane_3(plane.normal[0], plane.normal[1], plane.normal[2], -plane.offset);
}

K::Point_3 to_cgal(const Point3& p) { return K::Point_3(p[0], p[1], p[2]); }

std::vector<char> used_vertices(const SurfaceMesh& surface) {
  std::vector<char> used(surface.points.size(), 0);
  for (const auto& t : surface.triangles)
    for (auto v : t) used[v] = 1;
  return used;
}

Point3 main_axis(const SurfaceMesh& surface, const std::vector<char>& used) {
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  std::size_t n = 0;
  for (std::size_t i = 0; i < surface.points.size(); ++i) {
    if (!used[i]) continue;
    mean += Eigen::Vector3d(surface.points[i][0], surface.points[i][1], surface.points[i][2]);
    ++n;
  }
  mean /= static_cast<double>(n);
  Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
  for (std::size_t i = 0; i < surface.points.size(); ++i) {
    if (!used[i]) continue;
    Eigen::Vector3d d =
        Eigen::Vector3d(surface.points[i][0], surface.points[i][1], surface.points[i][2]) - mean;
    cov += d * d.transpose();
  }
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver(cov);
  Eigen::Vector3d axis = solver.eigenvectors().col(2).normalized();  // largest eigenvalue
  // Fix the sign so the axis (and so the piece order) does not depend on the solver.
  int largest = 0;
  for (int i = 1; i < 3; ++i)
    if (std::abs(axis[i]) > std::abs(axis[largest])) largest = i;
  if (axis[largest] < 0) axis = -axis;
  return {axis[0], axis[1], axis[2]};
}

}  // namespace

int piece_of_point(const std::vector<CutPlane>& planes, const Point3& p) {
  // Planes are sorted along the axis: binary search on the exact side test.
  const K::Point_3 q = to_cgal(p);
  int lo = 0, hi = static_cast<int>(planes.size());
  while (lo < hi) {
    int mid = (lo + hi) / 2;
    if (to_cgal(planes[mid]).oriented_side(q) == CGAL::ON_POSITIVE_SIDE)
      lo = mid + 1;
    else
      hi = mid;
  }
  return lo;
}

Point3 cut_axis(const SurfaceMesh& surface, CutAxis mode) {
  const Point3 pca = main_axis(surface, used_vertices(surface));
  if (mode == CutAxis::pca) return pca;
  // The coordinate axis closest to the PCA axis: crossings then lie exactly on the plane (one
  // coordinate equals the plane's offset), so every cap is exactly planar.
  int largest = 0;
  for (int i = 1; i < 3; ++i)
    if (std::abs(pca[i]) > std::abs(pca[largest])) largest = i;
  Point3 axis{0, 0, 0};
  axis[largest] = 1;
  return axis;
}

std::vector<CutPlane> choose_cut_planes(const SurfaceMesh& surface, int k, CutAxis mode,
                                        const std::vector<int>& shifts) {
  if (k < 1) throw OptionError("the number of pieces must be at least 1 (got " + std::to_string(k) + ")");
  if (k == 1) return {};
  const auto used = used_vertices(surface);
  const Point3 axis = cut_axis(surface, mode);

  std::vector<Point3> pts;
  for (std::size_t i = 0; i < surface.points.size(); ++i)
    if (used[i]) pts.push_back(surface.points[i]);
  std::vector<double> proj(pts.size());
  for (std::size_t i = 0; i < pts.size(); ++i) proj[i] = dot(axis, pts[i]);
  std::vector<std::size_t> order(pts.size());
  for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
    return proj[a] < proj[b] || (proj[a] == proj[b] && a < b);
  });
  const std::size_t n = pts.size();

  // A gap m lies between sorted vertices m-1 and m. It is usable when the plane through the
  // middle of it passes through no vertex, which is decided exactly (the projections are rounded).
  auto plane_in_gap = [&](std::size_t m, CutPlane& plane) {
    const double lo = proj[order[m - 1]], hi = proj[order[m]];
    if (!(lo < hi)) return false;
    plane = {axis, lo + (hi - lo) / 2};
    if (!(plane.offset > lo && plane.offset < hi)) return false;
    const auto cp = to_cgal(plane);
    // Vertices whose rounded projection is close to the plane: check exactly.
    const double slack = 1e-9 * (std::abs(lo) + std::abs(hi) + (hi - lo)) + 1e-300;
    for (std::size_t r = m; r-- > 0;) {
      if (proj[order[r]] < plane.offset - slack) break;
      if (cp.oriented_side(to_cgal(pts[order[r]])) != CGAL::ON_NEGATIVE_SIDE) return false;
    }
    for (std::size_t r = m; r < n; ++r) {
      if (proj[order[r]] > plane.offset + slack) break;
      if (cp.oriented_side(to_cgal(pts[order[r]])) != CGAL::ON_POSITIVE_SIDE) return false;
    }
    return true;
  };

  // All usable gaps, in order along the axis. A gap narrower than 1e-9 of the model's extent
  // (e.g. a face that is flat up to rounding noise) would give a needle-thin piece: not usable.
  const double min_width = 1e-9 * (proj[order[n - 1]] - proj[order[0]]);
  std::vector<std::size_t> usable;
  std::vector<CutPlane> usable_plane;
  for (std::size_t m = 1; m < n; ++m) {
    if (!(proj[order[m]] - proj[order[m - 1]] > min_width)) continue;
    CutPlane plane{};
    if (plane_in_gap(m, plane)) {
      usable.push_back(m);
      usable_plane.push_back(plane);
    }
  }
  // Fewer distinct cut positions than planes asked for: use them all (the caller warns).
  if (usable.size() + 1 < static_cast<std::size_t>(k)) k = static_cast<int>(usable.size()) + 1;
  std::vector<CutPlane> planes;
  std::size_t next_usable = 0;  // planes take strictly increasing usable gaps
  for (int j = 1; j < k; ++j) {
    const std::size_t target = (n * static_cast<std::size_t>(j) + k / 2) / static_cast<std::size_t>(k);
    // Leave enough usable gaps for the planes still to come.
    const std::size_t last_allowed = usable.size() - static_cast<std::size_t>(k - 1 - j) - 1;
    // Among the gaps near the ideal one, take the widest: a plane far from every vertex cuts no
    // triangle close to a corner, which avoids slivers and near-degenerate crossings in the
    // pieces TetGen gets. The window keeps pieces within a few percent of equal. A retry
    // (shift s > 0) takes the (s+1)-th widest instead, in a window 1 + 2s times as wide.
    const int shift = j - 1 < static_cast<int>(shifts.size()) ? shifts[j - 1] : 0;
    // Each retry also widens the window, so a plane that keeps failing moves further away.
    const std::size_t window =
        std::max<std::size_t>(2, n / (static_cast<std::size_t>(k) * 25)) * (1 + 2 * static_cast<std::size_t>(shift));
    std::vector<std::pair<double, std::size_t>> candidates;  // (-width, index into usable)
    for (std::size_t u = next_usable; u <= last_allowed; ++u) {
      const std::size_t m = usable[u];
      if (m + window < target) continue;
      if (m > target + window) break;
      candidates.push_back({-(proj[order[m]] - proj[order[m - 1]]), u});
    }
    std::sort(candidates.begin(), candidates.end());
    std::size_t chosen;
    if (!candidates.empty()) {
      chosen = candidates[static_cast<std::size_t>(shift) % candidates.size()].second;
    } else {
      // No usable gap near the ideal position: the nearest one that still leaves room.
      auto it = std::lower_bound(usable.begin() + static_cast<long>(next_usable),
                                 usable.begin() + static_cast<long>(last_allowed) + 1, target);
      chosen = static_cast<std::size_t>(it - usable.begin());
      if (chosen > last_allowed) chosen = last_allowed;
      if (chosen > next_usable && target - usable[chosen - 1] < usable[chosen] - target) --chosen;
    }
    planes.push_back(usable_plane[chosen]);
    next_usable = chosen + 1;
  }
  return planes;
}

SplitSurface split_at_planes(const SurfaceMesh& surface, const std::vector<CutPlane>& planes) {
  SplitSurface split;
  split.points = surface.points;
  split.input_vertex_count = static_cast<std::int32_t>(surface.points.size());
  split.piece_count = static_cast<int>(planes.size()) + 1;

  std::vector<std::int32_t> vertex_piece(surface.points.size(), 0);
  if (!planes.empty()) {
    const auto used = used_vertices(surface);
    for (std::size_t i = 0; i < surface.points.size(); ++i)
      if (used[i]) vertex_piece[i] = piece_of_point(planes, surface.points[i]);
  }

  // Cut vertex for (edge, plane), created once: key = (min vertex, max vertex, plane).
  struct Key {
    std::int32_t a, b, plane;
    bool operator==(const Key& o) const { return a == o.a && b == o.b && plane == o.plane; }
  };
  struct KeyHash {
    std::size_t operator()(const Key& k) const {
      std::uint64_t h = (static_cast<std::uint64_t>(static_cast<std::uint32_t>(k.a)) << 32) ^
                        static_cast<std::uint32_t>(k.b);
      h ^= static_cast<std::uint64_t>(k.plane) * 0x9E3779B97F4A7C15ull;
      h ^= h >> 29;
      h *= 0xBF58476D1CE4E5B9ull;
      return static_cast<std::size_t>(h ^ (h >> 32));
    }
  };
  std::unordered_map<Key, std::int32_t, KeyHash> cut_vertex;

  auto crossing = [&](std::int32_t p, std::int32_t q, int plane_index) {
    const Key key{std::min(p, q), std::max(p, q), plane_index};
    auto it = cut_vertex.find(key);
    if (it != cut_vertex.end()) return it->second;
    // Exact intersection of segment ab with the plane, rounded to double once. Always computed
    // from the lower vertex id so both triangles of the edge get the same point.
    using Q = CGAL::Exact_rational;
    const Point3& a = surface.points[key.a];
    const Point3& b = surface.points[key.b];
    const CutPlane& pl = planes[plane_index];
    Q na(0), nba(0);
    for (int i = 0; i < 3; ++i) {
      na += Q(pl.normal[i]) * Q(a[i]);
      nba += Q(pl.normal[i]) * (Q(b[i]) - Q(a[i]));
    }
    const Q t = (Q(pl.offset) - na) / nba;
    Point3 x;
    for (int i = 0; i < 3; ++i) x[i] = CGAL::to_double(Q(a[i]) + t * (Q(b[i]) - Q(a[i])));
    const auto id = static_cast<std::int32_t>(split.points.size());
    split.points.push_back(x);
    split.cut_vertex_edge.push_back({key.a, key.b});
    split.cut_vertex_plane.push_back(plane_index);
    cut_vertex.emplace(key, id);
    return id;
  };

  split.triangles.reserve(surface.triangles.size() + surface.triangles.size() / 8);
  std::vector<std::int32_t> polygon;
  for (std::size_t f = 0; f < surface.triangles.size(); ++f) {
    const Triangle& tri = surface.triangles[f];
    const int s0 = vertex_piece[tri[0]], s1 = vertex_piece[tri[1]], s2 = vertex_piece[tri[2]];
    const int lo = std::min({s0, s1, s2}), hi = std::max({s0, s1, s2});
    if (lo == hi) {
      split.triangles.push_back(tri);
      split.piece.push_back(lo);
      split.parent.push_back(static_cast<std::int32_t>(f));
      continue;
    }
    // The triangle clipped to slab s is a convex polygon whose corners, in boundary order, are
    // the triangle corners inside the slab and the crossings with the slab's two planes.
    for (int s = lo; s <= hi; ++s) {
      polygon.clear();
      for (int e = 0; e < 3; ++e) {
        const std::int32_t p = tri[e], q = tri[(e + 1) % 3];
        const int sp = vertex_piece[p], sq = vertex_piece[q];
        if (sp == s) polygon.push_back(p);
        if (sp < sq) {
          for (int j = sp; j < sq; ++j)
            if (j == s - 1 || j == s) polygon.push_back(crossing(p, q, j));
        } else {
          for (int j = sp - 1; j >= sq; --j)
            if (j == s - 1 || j == s) polygon.push_back(crossing(p, q, j));
        }
      }
      // No three corners are collinear (at most two lie on any triangle edge or plane), so a
      // fan gives valid triangles. Fan from an original corner when there is one: its chords
      // then stay on the planes' sides.
      std::size_t start = 0;
      for (std::size_t i = 0; i < polygon.size(); ++i)
        if (!split.is_cut_vertex(polygon[i])) {
          start = i;
          break;
        }
      const std::size_t m = polygon.size();
      for (std::size_t i = 1; i + 1 < m; ++i) {
        split.triangles.push_back(
            {polygon[start], polygon[(start + i) % m], polygon[(start + i + 1) % m]});
        split.piece.push_back(s);
        split.parent.push_back(static_cast<std::int32_t>(f));
      }
    }
  }
  return split;
}

}  // namespace partet

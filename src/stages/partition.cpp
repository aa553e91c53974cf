#include "stages/partition.hpp"

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Exact_rational.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <string>
#include <unordered_map>

#include "common/keyed_sort.hpp"
#include "common/parallel.hpp"
#include "partet/errors.hpp"
#include "stages/geometry.hpp"
#include "stages/topology.hpp"

namespace partet {
namespace {

using K = CGAL::Exact_predicates_inexact_constructions_kernel;

K::Plane_3 to_cgal(const CutPlane& plane) {
  return K::Plane_3(plane.normal[0], plane.normal[1], plane.normal[2], -plane.offset);
}

K::Point_3 to_cgal(const Point3& p) { return K::Point_3(p[0], p[1], p[2]); }

std::vector<char> used_vertices(const SurfaceMesh& surface) {
  return partet::used_vertices(surface.points.size(), surface.triangles);
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
    Eigen::Vector3d d = Eigen::Vector3d(surface.points[i][0], surface.points[i][1], surface.points[i][2]) - mean;
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
  // Planes are sorted along the axis. A coordinate-axis plane's side is the coordinate compared
  // with the offset, exactly; otherwise binary search on the exact side test.
  if (!planes.empty()) {
    const Point3& n = planes[0].normal;
    for (int axis = 0; axis < 3; ++axis)
      if (n[axis] == 1 && n[(axis + 1) % 3] == 0 && n[(axis + 2) % 3] == 0)
        return static_cast<int>(std::lower_bound(planes.begin(), planes.end(), p[axis],
                                                 [](const CutPlane& plane, double x) { return plane.offset < x; }) -
                                planes.begin());
  }
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

std::vector<CutAxis> coordinate_axes_by_closeness(const SurfaceMesh& surface) {
  const Point3 pca = main_axis(surface, used_vertices(surface));
  std::vector<int> order{0, 1, 2};
  std::stable_sort(order.begin(), order.end(), [&](int a, int b) { return std::abs(pca[a]) > std::abs(pca[b]); });
  std::vector<CutAxis> axes;
  for (int i : order) axes.push_back(i == 0 ? CutAxis::x : i == 1 ? CutAxis::y : CutAxis::z);
  return axes;
}

const char* axis_name(CutAxis axis) {
  switch (axis) {
    case CutAxis::x:
      return "x";
    case CutAxis::y:
      return "y";
    case CutAxis::z:
      return "z";
    case CutAxis::pca:
      return "pca";
    default:
      return "auto";
  }
}

Point3 cut_axis(const SurfaceMesh& surface, CutAxis mode) {
  if (mode == CutAxis::x) return {1, 0, 0};
  if (mode == CutAxis::y) return {0, 1, 0};
  if (mode == CutAxis::z) return {0, 0, 1};
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

namespace {

// The used vertices in order along the cut axis.
struct AxisOrder {
  const SurfaceMesh& surface;
  const AxisVertices& along;
  const Point3& axis() const { return along.axis; }
  double at(std::size_t r) const { return along.sorted[r].first; }  // rounded projection
  const Point3& point(std::size_t r) const { return surface.points[along.sorted[r].second]; }
  std::size_t size() const { return along.sorted.size(); }
};

// A gap m lies between sorted vertices m-1 and m. It is usable when the plane through the
// middle of it passes through no vertex, which is decided exactly (the projections are rounded).
bool plane_in_gap(const AxisOrder& a, std::size_t m, CutPlane& plane) {
  const double lo = a.at(m - 1), hi = a.at(m);
  if (!(lo < hi)) return false;
  plane = {a.axis(), lo + (hi - lo) / 2};
  if (!(plane.offset > lo && plane.offset < hi)) return false;
  const auto cp = to_cgal(plane);
  // Vertices whose rounded projection is close to the plane: check exactly.
  const double slack = 1e-9 * (std::abs(lo) + std::abs(hi) + (hi - lo)) + 1e-300;
  for (std::size_t r = m; r-- > 0;) {
    if (a.at(r) < plane.offset - slack) break;
    if (cp.oriented_side(to_cgal(a.point(r))) != CGAL::ON_NEGATIVE_SIDE) return false;
  }
  for (std::size_t r = m; r < a.size(); ++r) {
    if (a.at(r) > plane.offset + slack) break;
    if (cp.oriented_side(to_cgal(a.point(r))) != CGAL::ON_POSITIVE_SIDE) return false;
  }
  return true;
}

struct Gap {
  std::size_t m;  // between sorted vertices m-1 and m
  CutPlane plane;
};

// All usable gaps, in order along the axis. A gap narrower than 1e-9 of the model's extent
// (e.g. a face that is flat up to rounding noise) would give a needle-thin piece: not usable.
std::vector<Gap> usable_gaps(const AxisOrder& a) {
  const std::size_t n = a.size();
  const double min_width = 1e-9 * (a.at(n - 1) - a.at(0));
  std::vector<Gap> gaps;
  for (std::size_t m = 1; m < n; ++m) {
    if (!(a.at(m) - a.at(m - 1) > min_width)) continue;
    CutPlane plane{};
    if (plane_in_gap(a, m, plane)) gaps.push_back({m, plane});
  }
  return gaps;
}

// A plane candidate: a usable gap, its width and its clearance.
struct Candidate {
  std::size_t gap;  // index into the usable gaps
  double width;
  double clearance = 1;  // min over the input edges it crosses of min(t, 1-t), t along the edge
};

// The candidates for a plane whose ideal position is between sorted vertices target-1 and
// target: the widest usable gaps near it (a plane far from every vertex cuts no triangle close
// to a corner, which avoids slivers and near-degenerate crossings in the pieces TetGen gets).
// The window keeps pieces within a few percent of equal; a retry (shift s > 0) widens it
// 1 + 2s times, so a plane that keeps failing moves further away.
std::vector<Candidate> candidates_near(const AxisOrder& a, const std::vector<Gap>& gaps, std::size_t target,
                                       std::size_t last, std::size_t base_window, int shift) {
  constexpr std::size_t kTried = 16;
  const std::size_t window = base_window * (1 + 2 * static_cast<std::size_t>(shift));
  std::vector<Candidate> candidates;
  for (std::size_t u = 0; u <= last; ++u) {
    const std::size_t m = gaps[u].m;
    if (m + window < target) continue;
    if (m > target + window) break;
    candidates.push_back({u, a.at(m) - a.at(m - 1)});
  }
  std::stable_sort(candidates.begin(), candidates.end(),
                   [](const Candidate& x, const Candidate& y) { return x.width > y.width; });
  if (candidates.size() > kTried + static_cast<std::size_t>(shift))
    candidates.resize(kTried + static_cast<std::size_t>(shift));
  return candidates;
}

// Measures every candidate's clearance in one pass over the input edges: a cut vertex close to
// an edge's end (relative to that edge's length) lies close to an input vertex and to the cut
// vertices of its neighbouring edges, which TetGen may merge or fail to recover.
void measure_clearance(const AxisOrder& a, const std::vector<Gap>& gaps,
                       std::vector<std::vector<Candidate>>& candidates) {
  std::vector<std::pair<double, Candidate*>> at;  // by plane offset
  for (auto& list : candidates)
    for (auto& c : list) at.push_back({gaps[c.gap].plane.offset, &c});
  std::sort(at.begin(), at.end(), [](const auto& x, const auto& y) { return x.first < y.first; });
  if (at.empty()) return;
  // The candidates below each vertex, found in one walk along the axis. No offset equals a
  // vertex's projection (a plane lies strictly inside its gap), so an edge from p to q (p < q)
  // crosses exactly the candidates from below[p] to below[q], and most edges cross none.
  std::vector<std::uint32_t> below(a.surface.points.size(), 0);
  std::size_t passed = 0;
  for (const auto& [x, v] : a.along.sorted) {
    while (passed < at.size() && at[passed].first < x) ++passed;
    below[v] = static_cast<std::uint32_t>(passed);
  }
  // In a closed oriented surface each edge runs once each way: count it where it runs upwards.
  for (const Triangle& t : a.surface.triangles)
    for (int e = 0; e < 3; ++e) {
      std::int32_t u = t[e], w = t[(e + 1) % 3];
      if (u > w || below[u] == below[w]) continue;
      double p = dot(a.axis(), a.surface.points[u]), q = dot(a.axis(), a.surface.points[w]);
      if (p > q) std::swap(p, q), std::swap(u, w);
      for (std::uint32_t c = below[u]; c < below[w]; ++c) {
        const double s = (at[c].first - p) / (q - p);
        at[c].second->clearance = std::min(at[c].second->clearance, std::min(s, 1 - s));
      }
    }
}

// The candidate to use: the widest with a clearance of at least kGoodClearance, else the one
// with the best clearance. Only gaps from `first` on (after the previous plane's) and not in
// `taken` qualify; -1 when none does.
long pick_candidate(std::vector<Candidate> candidates, std::size_t first, const std::vector<std::size_t>& taken) {
  constexpr double kGoodClearance = 0.05;
  candidates.erase(std::remove_if(candidates.begin(), candidates.end(),
                                  [&](const Candidate& c) {
                                    return c.gap < first || std::find(taken.begin(), taken.end(), c.gap) != taken.end();
                                  }),
                   candidates.end());
  if (candidates.empty()) return -1;
  std::stable_sort(candidates.begin(), candidates.end(), [](const Candidate& x, const Candidate& y) {
    const bool good_x = x.clearance >= kGoodClearance, good_y = y.clearance >= kGoodClearance;
    if (good_x != good_y) return good_x;
    return good_x ? x.width > y.width : x.clearance > y.clearance;
  });
  return static_cast<long>(candidates.front().gap);
}

// A plane's pick after s retries: level t (its window widened for the t-th retry) gives the
// best gap none of the levels before it gave, so each retry moves the plane to a gap not tried
// yet (on CAD parts many vertices share a position, and the best gap of a wider window is
// often one already tried). -1 when no level has a gap left.
long pick_after_retries(const std::vector<std::vector<Candidate>>& levels, std::size_t first) {
  std::vector<std::size_t> taken;
  long picked = -1;
  for (const std::vector<Candidate>& level : levels) {
    const long next = pick_candidate(level, first, taken);
    if (next < 0) break;
    picked = next;
    taken.push_back(static_cast<std::size_t>(next));
  }
  return picked;
}

// No usable gap near the ideal position: the nearest one that still leaves room.
std::size_t nearest_gap(const std::vector<Gap>& gaps, std::size_t target, std::size_t first, std::size_t last) {
  auto it = std::lower_bound(gaps.begin() + static_cast<long>(first), gaps.begin() + static_cast<long>(last) + 1,
                             target, [](const Gap& g, std::size_t t) { return g.m < t; });
  std::size_t chosen = static_cast<std::size_t>(it - gaps.begin());
  if (chosen > last) chosen = last;
  if (chosen > first && target - gaps[chosen - 1].m < gaps[chosen].m - target) --chosen;
  return chosen;
}

}  // namespace

AxisVertices sort_vertices_along(const SurfaceMesh& surface, const Point3& axis) {
  AxisVertices along(axis);
  const auto used = used_vertices(surface);
  along.sorted.reserve(static_cast<std::size_t>(std::count(used.begin(), used.end(), 1)));
  for (std::size_t i = 0; i < surface.points.size(); ++i)
    if (used[i]) along.sorted.push_back(keyed(dot(axis, surface.points[i]), i));
  // Sorting (projection, index) pairs side by side is several times faster than sorting
  // indices that look their projections up.
  sort_keyed(along.sorted, usable_cpus());
  return along;
}

std::vector<CutPlane> choose_cut_planes(const SurfaceMesh& surface, int k, CutAxis mode, const std::vector<int>& shifts,
                                        const std::vector<double>& fractions) {
  if (k < 1) throw OptionError("the number of pieces must be at least 1 (got " + std::to_string(k) + ")");
  if (k == 1) return {};
  return choose_cut_planes(surface, sort_vertices_along(surface, cut_axis(surface, mode)), k, shifts, fractions);
}

std::vector<CutPlane> choose_cut_planes(const SurfaceMesh& surface, const AxisVertices& along, int k,
                                        const std::vector<int>& shifts, const std::vector<double>& fractions) {
  if (k < 1) throw OptionError("the number of pieces must be at least 1 (got " + std::to_string(k) + ")");
  if (k == 1) return {};
  const AxisOrder a{surface, along};
  const std::vector<Gap> gaps = usable_gaps(a);
  // Fewer distinct cut positions than planes asked for: use them all (the caller warns).
  if (gaps.size() + 1 < static_cast<std::size_t>(k)) k = static_cast<int>(gaps.size()) + 1;
  const std::size_t n = a.size();
  const std::size_t base_window = std::max<std::size_t>(2, n / (static_cast<std::size_t>(k) * 25));
  const bool given = fractions.size() + 1 == static_cast<std::size_t>(k);
  auto target_of = [&](int j) {
    if (given) return std::min(n - 1, std::max<std::size_t>(1, static_cast<std::size_t>(fractions[j - 1] * n + 0.5)));
    return (n * static_cast<std::size_t>(j) + k / 2) / static_cast<std::size_t>(k);
  };
  auto shift_of = [&](int j) { return j - 1 < static_cast<int>(shifts.size()) ? shifts[j - 1] : 0; };
  // Leave enough usable gaps for the planes still to come.
  auto last_of = [&](int j) { return gaps.size() - static_cast<std::size_t>(k - 1 - j) - 1; };
  // Per plane, a candidate list per level: the first attempt's window, then each retry's.
  std::vector<std::vector<Candidate>> candidates;
  std::vector<std::size_t> levels_from(static_cast<std::size_t>(k) + 1, 0);
  for (int j = 1; j < k; ++j) {
    levels_from[j] = candidates.size();
    for (int t = 0; t <= shift_of(j); ++t)
      candidates.push_back(candidates_near(a, gaps, target_of(j), last_of(j), base_window, t));
  }
  levels_from[k] = candidates.size();
  measure_clearance(a, gaps, candidates);
  std::vector<CutPlane> planes;
  std::size_t first = 0;  // planes take strictly increasing usable gaps
  for (int j = 1; j < k; ++j) {
    const long picked = pick_after_retries(
        std::vector<std::vector<Candidate>>(candidates.begin() + static_cast<long>(levels_from[j]),
                                            candidates.begin() + static_cast<long>(levels_from[j + 1])),
        first);
    const std::size_t chosen =
        picked >= 0 ? static_cast<std::size_t>(picked) : nearest_gap(gaps, target_of(j), first, last_of(j));
    planes.push_back(gaps[chosen].plane);
    first = chosen + 1;
  }
  return planes;
}

namespace {

// Exact intersection of segment ab with the plane, rounded to double once.
// Terms that are exactly zero are left out (a coordinate plane's normal has two), and so are the
// coordinates whose exact value is known: the plane's own on a coordinate plane (its offset),
// and those along which the edge does not move. Rational arithmetic is most of a partition's
// time otherwise.
Point3 exact_crossing(const Point3& a, const Point3& b, const CutPlane& plane) {
  using Q = CGAL::Exact_rational;
  Q na(0), nba(0);
  int nonzero = 0, along = -1;
  for (int i = 0; i < 3; ++i) {
    if (plane.normal[i] == 0) continue;
    ++nonzero, along = i;
    na += Q(plane.normal[i]) * Q(a[i]);
    nba += Q(plane.normal[i]) * (Q(b[i]) - Q(a[i]));
  }
  const Q t = (Q(plane.offset) - na) / nba;
  Point3 x;
  for (int i = 0; i < 3; ++i) {
    if (nonzero == 1 && i == along && plane.normal[i] == 1)
      x[i] = plane.offset + 0.0;  // a + t (b - a) = offset along the normal (+ 0.0: never -0.0)
    else if (a[i] == b[i])
      x[i] = a[i] + 0.0;
    else
      x[i] = CGAL::to_double(Q(a[i]) + t * (Q(b[i]) - Q(a[i])));
  }
  return x;
}

// The cut vertex of each (input edge, plane), created once and appended to split.points.
class CutVertices {
 public:
  CutVertices(const SurfaceMesh& surface, const std::vector<CutPlane>& planes, SplitSurface& split)
      : surface_(surface), planes_(planes), split_(split) {}

  std::int32_t at(std::int32_t p, std::int32_t q, int plane) {
    const Key key{std::min(p, q), std::max(p, q), plane};
    auto it = ids_.find(key);
    if (it != ids_.end()) return it->second;
    // Always computed from the lower vertex id, so both triangles of the edge get the same point.
    const auto id = static_cast<std::int32_t>(split_.points.size());
    split_.points.push_back(exact_crossing(surface_.points[key.a], surface_.points[key.b], planes_[plane]));
    split_.cut_vertex_edge.push_back({key.a, key.b});
    split_.cut_vertex_plane.push_back(plane);
    ids_.emplace(key, id);
    return id;
  }

 private:
  struct Key {
    std::int32_t a, b, plane;
    bool operator==(const Key& o) const { return a == o.a && b == o.b && plane == o.plane; }
  };
  struct KeyHash {
    std::size_t operator()(const Key& k) const {
      std::uint64_t h =
          (static_cast<std::uint64_t>(static_cast<std::uint32_t>(k.a)) << 32) ^ static_cast<std::uint32_t>(k.b);
      h ^= static_cast<std::uint64_t>(k.plane) * 0x9E3779B97F4A7C15ull;
      h ^= h >> 29;
      h *= 0xBF58476D1CE4E5B9ull;
      return static_cast<std::size_t>(h ^ (h >> 32));
    }
  };
  const SurfaceMesh& surface_;
  const std::vector<CutPlane>& planes_;
  SplitSurface& split_;
  std::unordered_map<Key, std::int32_t, KeyHash> ids_;
};

// The triangle clipped to slab s: a convex polygon whose corners, in boundary order, are the
// triangle corners inside the slab and the crossings with the slab's two planes.
void slab_polygon(const Triangle& tri, int s, const std::vector<std::int32_t>& vertex_piece, CutVertices& cuts,
                  std::vector<std::int32_t>& polygon) {
  polygon.clear();
  for (int e = 0; e < 3; ++e) {
    const std::int32_t p = tri[e], q = tri[(e + 1) % 3];
    const int sp = vertex_piece[p], sq = vertex_piece[q];
    if (sp == s) polygon.push_back(p);
    if (sp < sq) {
      for (int j = sp; j < sq; ++j)
        if (j == s - 1 || j == s) polygon.push_back(cuts.at(p, q, j));
    } else {
      for (int j = sp - 1; j >= sq; --j)
        if (j == s - 1 || j == s) polygon.push_back(cuts.at(p, q, j));
    }
  }
}

// No three corners of a slab polygon are collinear (at most two lie on any triangle edge or
// plane), so a fan gives valid triangles. Fan from an original corner when there is one: its
// chords then stay on the planes' sides.
void add_fan(const std::vector<std::int32_t>& polygon, int s, std::int32_t parent, SplitSurface& split) {
  std::size_t start = 0;
  for (std::size_t i = 0; i < polygon.size(); ++i)
    if (!split.is_cut_vertex(polygon[i])) {
      start = i;
      break;
    }
  const std::size_t m = polygon.size();
  for (std::size_t i = 1; i + 1 < m; ++i) {
    split.triangles.push_back({polygon[start], polygon[(start + i) % m], polygon[(start + i + 1) % m]});
    split.piece.push_back(s);
    split.parent.push_back(parent);
  }
}

}  // namespace

SplitSurface split_at_planes(const SurfaceMesh& surface, const std::vector<CutPlane>& planes) {
  SplitSurface split;
  // Room for the cut vertices, the caps' points and, once the points move into the merged mesh,
  // the Steiner points and what healing adds (Welder::finish): a vector that outgrows its
  // capacity is copied into one twice its size, and reserved pages cost nothing until written.
  split.points.reserve(surface.points.size() + surface.points.size() / 4 + 4096);
  split.points.assign(surface.points.begin(), surface.points.end());
  split.input_vertex_count = static_cast<std::int32_t>(surface.points.size());
  split.piece_count = static_cast<int>(planes.size()) + 1;

  std::vector<std::int32_t> vertex_piece(surface.points.size(), 0);
  if (!planes.empty()) {
    const auto used = used_vertices(surface);
    for (std::size_t i = 0; i < surface.points.size(); ++i)
      if (used[i]) vertex_piece[i] = piece_of_point(planes, surface.points[i]);
  }

  CutVertices cuts(surface, planes, split);
  const std::size_t room = surface.triangles.size() + surface.triangles.size() / 8;
  split.triangles.reserve(room);
  split.piece.reserve(room);
  split.parent.reserve(room);
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
    for (int s = lo; s <= hi; ++s) {
      slab_polygon(tri, s, vertex_piece, cuts, polygon);
      add_fan(polygon, s, static_cast<std::int32_t>(f), split);
    }
  }
  return split;
}

void keep_seam_triangles(SplitSurface& split) {
  std::size_t kept = 0;
  for (std::size_t t = 0; t < split.triangles.size(); ++t) {
    const Triangle& tri = split.triangles[t];
    if (!split.is_cut_vertex(tri[0]) && !split.is_cut_vertex(tri[1]) && !split.is_cut_vertex(tri[2])) continue;
    split.triangles[kept] = tri;
    split.parent[kept] = split.parent[t];
    ++kept;
  }
  split.triangles.resize(kept);
  split.parent.resize(kept);
  split.triangles.shrink_to_fit();
  split.parent.shrink_to_fit();
  std::vector<std::int32_t>().swap(split.piece);
}

}  // namespace partet

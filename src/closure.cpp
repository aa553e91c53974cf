#include "partet/closure.hpp"

#include <CGAL/Constrained_Delaunay_triangulation_2.h>
#include <CGAL/Constrained_triangulation_face_base_2.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Triangulation_face_base_with_info_2.h>
#include <CGAL/Triangulation_vertex_base_with_info_2.h>

#include <algorithm>
#include <cmath>
#include <deque>
#include <map>
#include <string>

#include "geometry.hpp"
#include "partet/errors.hpp"

namespace partet {
namespace {

using K = CGAL::Exact_predicates_inexact_constructions_kernel;
using Vb = CGAL::Triangulation_vertex_base_with_info_2<std::int32_t, K>;
struct FaceInfo {
  int nesting = -1;  // number of loops crossed from the outside; odd = inside the solid
};
using Fbi = CGAL::Triangulation_face_base_with_info_2<FaceInfo, K>;
using Fb = CGAL::Constrained_triangulation_face_base_2<K, Fbi>;
using Tds = CGAL::Triangulation_data_structure_2<Vb, Fb>;
// Crossing loops are an error, never silently resolved with new inexact vertices.
using CDT = CGAL::Constrained_Delaunay_triangulation_2<K, Tds, CGAL::No_constraint_intersection_tag>;

struct PlaneFrame {
  Point3 origin, u, v;  // u x v = plane normal
};

PlaneFrame frame_of(const CutPlane& plane) {
  const Point3& n = plane.normal;
  // A coordinate-axis normal gets the other two axes as (u, v): 2D coordinates and lifted
  // points are then exact (no rounding at all).
  for (int i = 0; i < 3; ++i)
    if (n[i] == 1 && n[(i + 1) % 3] == 0 && n[(i + 2) % 3] == 0) {
      PlaneFrame f{{0, 0, 0}, {0, 0, 0}, {0, 0, 0}};
      f.origin[i] = plane.offset;
      f.u[(i + 1) % 3] = 1;
      f.v[(i + 2) % 3] = 1;
      return f;
    }
  // Any vector not parallel to n, then Gram-Schmidt.
  Point3 a = std::abs(n[0]) < 0.9 ? Point3{1, 0, 0} : Point3{0, 1, 0};
  Point3 u = cross(a, n);
  const double len = std::sqrt(u[0] * u[0] + u[1] * u[1] + u[2] * u[2]);
  for (auto& c : u) c /= len;
  Point3 v = cross(n, u);
  return {{n[0] * plane.offset, n[1] * plane.offset, n[2] * plane.offset}, u, v};
}

void mark_nesting(CDT& cdt) {
  for (auto f = cdt.all_faces_begin(); f != cdt.all_faces_end(); ++f) f->info().nesting = -1;
  // Breadth-first from the infinite face; crossing a constrained edge increments the level.
  std::deque<CDT::Face_handle> border{cdt.infinite_face()};
  int level = 0;
  while (!border.empty()) {
    std::deque<CDT::Face_handle> next;
    while (!border.empty()) {
      auto start = border.front();
      border.pop_front();
      if (start->info().nesting != -1) continue;
      std::deque<CDT::Face_handle> queue{start};
      start->info().nesting = level;
      while (!queue.empty()) {
        auto f = queue.front();
        queue.pop_front();
        for (int i = 0; i < 3; ++i) {
          auto g = f->neighbor(i);
          if (g->info().nesting != -1) continue;
          if (f->is_constrained(i)) {
            next.push_back(g);
          } else {
            g->info().nesting = level;
            queue.push_back(g);
          }
        }
      }
    }
    border.swap(next);
    ++level;
  }
}

bool in_domain(const CDT& cdt, CDT::Face_handle f) { return !cdt.is_infinite(f) && f->info().nesting % 2 == 1; }

K::Point_2 to_2d(const PlaneFrame& frame, const Point3& p) {
  const double x = p[0] - frame.origin[0], y = p[1] - frame.origin[1], z = p[2] - frame.origin[2];
  return K::Point_2(x * frame.u[0] + y * frame.u[1] + z * frame.u[2], x * frame.v[0] + y * frame.v[1] + z * frame.v[2]);
}

Point3 lift(const PlaneFrame& frame, const K::Point_2& p) {
  const double x = p.x(), y = p.y();
  return {frame.origin[0] + x * frame.u[0] + y * frame.v[0], frame.origin[1] + x * frame.u[1] + y * frame.v[1],
          frame.origin[2] + x * frame.u[2] + y * frame.v[2]};
}

using Chord = std::array<std::int32_t, 2>;

// Border chords of each plane, oriented as the piece below traverses them.
std::vector<std::vector<Chord>> border_chords(const SplitSurface& split, std::size_t plane_count) {
  std::vector<std::vector<Chord>> chords(plane_count);
  for (std::size_t t = 0; t < split.triangles.size(); ++t) {
    const auto& tri = split.triangles[t];
    const int piece = split.piece[t];
    if (piece >= static_cast<int>(plane_count)) continue;
    for (int e = 0; e < 3; ++e) {
      const std::int32_t a = tri[e], b = tri[(e + 1) % 3];
      if (!split.is_cut_vertex(a) || !split.is_cut_vertex(b)) continue;
      const std::int32_t ia = a - split.input_vertex_count, ib = b - split.input_vertex_count;
      if (split.cut_vertex_plane[ia] == piece && split.cut_vertex_plane[ib] == piece) chords[piece].push_back({a, b});
    }
  }
  return chords;
}

// Inserts the border vertices (sorted by id, so the triangulation is built the same way every
// time) and the chords as constraints. Returns the border's total length.
double insert_border(CDT& cdt, const std::vector<Chord>& chords, const std::vector<Point3>& points,
                     const PlaneFrame& frame, std::size_t j) {
  std::vector<std::int32_t> ids;
  for (const auto& c : chords) ids.insert(ids.end(), {c[0], c[1]});
  std::sort(ids.begin(), ids.end());
  ids.erase(std::unique(ids.begin(), ids.end()), ids.end());
  std::map<std::int32_t, CDT::Vertex_handle> handle;
  double border_length = 0;
  try {
    for (auto id : ids) {
      const auto before = cdt.number_of_vertices();
      auto vh = cdt.insert(to_2d(frame, points[id]));
      if (cdt.number_of_vertices() == before)
        throw PartitionError(
            FailureKind::other, -1,
            "cut plane " + std::to_string(j) + ": two border points coincide in the plane (near-degenerate crossing)");
      vh->info() = id;
      handle[id] = vh;
    }
    for (const auto& c : chords) {
      cdt.insert_constraint(handle[c[0]], handle[c[1]]);
      border_length += distance(points[c[0]], points[c[1]]);
    }
  } catch (const CDT::Intersection_of_constraints_exception&) {
    throw PartitionError(FailureKind::self_intersection, -1,
                         "cut plane " + std::to_string(j) +
                             ": the surface's border loops cross or touch on the plane (self-intersecting input?)");
  }
  return border_length;
}

// A point encroaches on a constrained edge of face g or its neighbours when it lies inside the
// edge's diametral circle: a point there would make a sliver against the border.
bool encroaches(const CDT& cdt, CDT::Face_handle g, const K::Point_2& p) {
  for (int n = -1; n < 3; ++n) {
    const CDT::Face_handle h = n < 0 ? g : g->neighbor(n);
    if (cdt.is_infinite(h)) continue;
    for (int i = 0; i < 3; ++i) {
      if (!h->is_constrained(i)) continue;
      const auto& a = h->vertex(CDT::cw(i))->point();
      const auto& b = h->vertex(CDT::ccw(i))->point();
      if ((p - a) * (p - b) <= 0) return true;
    }
  }
  return false;
}

// Inserts p into the domain unless it falls outside, encroaches or coincides; the new point is
// appended to `points` (so it gets a global id). Returns whether it was inserted.
bool insert_interior_point(CDT& cdt, const K::Point_2& p, const PlaneFrame& frame, std::vector<Point3>& points) {
  const CDT::Face_handle g = cdt.locate(p);
  if (g == CDT::Face_handle() || !in_domain(cdt, g) || encroaches(cdt, g, p)) return false;
  const int nesting = g->info().nesting;
  const auto before = cdt.number_of_vertices();
  auto vh = cdt.insert(p, g);
  if (cdt.number_of_vertices() == before) return false;  // coincides with an existing point
  // The new faces fill a region bounded by unconstrained edges: same nesting as before.
  auto fc = cdt.incident_faces(vh), done = fc;
  do {
    fc->info().nesting = nesting;
  } while (++fc != done);
  vh->info() = static_cast<std::int32_t>(points.size());
  points.push_back(lift(frame, p));
  return true;
}

// Refinement by size that never splits a border chord (both pieces must keep matching): a too
// large face gets its centroid unless that encroaches on a border chord. (Circumcenters give
// rounder triangles but land arbitrarily close to other points, which TetGen then merges.)
void refine_cap(CDT& cdt, std::size_t chord_count, double border_length, double density, const PlaneFrame& frame,
                std::vector<Point3>& points) {
  const double target = border_length / static_cast<double>(chord_count) / density;
  const double max_area = 2.0 * std::sqrt(3.0) / 4.0 * target * target;
  const std::size_t budget = 50 * chord_count + 1000;  // bounds the work on odd inputs
  std::size_t inserted = 0;
  for (int round = 0; round < 64 && inserted < budget; ++round) {
    std::vector<std::array<K::Point_2, 3>> large;
    for (auto f = cdt.finite_faces_begin(); f != cdt.finite_faces_end(); ++f) {
      if (!in_domain(cdt, f)) continue;
      const auto& a = f->vertex(0)->point();
      const auto& b = f->vertex(1)->point();
      const auto& c = f->vertex(2)->point();
      if (std::abs(CGAL::area(a, b, c)) > max_area) large.push_back({a, b, c});
    }
    const std::size_t before = inserted;
    for (const auto& t : large) {
      if (inserted >= budget) break;
      if (insert_interior_point(cdt, CGAL::centroid(t[0], t[1], t[2]), frame, points)) ++inserted;
    }
    if (inserted == before) break;
  }
}

// The domain's triangles in a deterministic order, independent of CGAL's internal face order.
// Counter-clockwise in (u, v) means the normal is +axis: outward for the piece below.
std::vector<Triangle> domain_triangles(const CDT& cdt) {
  std::vector<Triangle> triangles;
  for (auto f = cdt.finite_faces_begin(); f != cdt.finite_faces_end(); ++f) {
    if (!in_domain(cdt, f)) continue;
    triangles.push_back({f->vertex(0)->info(), f->vertex(1)->info(), f->vertex(2)->info()});
  }
  for (auto& t : triangles) std::rotate(t.begin(), std::min_element(t.begin(), t.end()), t.end());
  std::sort(triangles.begin(), triangles.end());
  return triangles;
}

// Every chord must be closed by a cap triangle traversing it the other way; otherwise the
// loops are not properly nested (e.g. an orientation or intersection problem).
void check_cap_closes_loops(const std::vector<Triangle>& cap, const std::vector<Chord>& chords, std::size_t j) {
  std::vector<Chord> cap_edges;
  for (const auto& t : cap)
    for (int e = 0; e < 3; ++e) cap_edges.push_back({t[(e + 1) % 3], t[e]});
  std::sort(cap_edges.begin(), cap_edges.end());
  for (const auto& c : chords)
    if (!std::binary_search(cap_edges.begin(), cap_edges.end(), c))
      throw PartitionError(
          FailureKind::other, -1,
          "cut plane " + std::to_string(j) +
              ": the cap does not close the border loops (inconsistent orientation or crossing loops)");
}

}  // namespace

CapBuilder::CapBuilder(SplitSurface& split, const std::vector<CutPlane>& planes, double density)
    : split_(split), planes_(planes), density_(density) {
  if (!(density >= 0) || !std::isfinite(density)) throw OptionError("the cap density must be a finite number >= 0");
  chords_ = border_chords(split, planes.size());
}

Cap CapBuilder::build(int plane) {
  const auto j = static_cast<std::size_t>(plane);
  const std::vector<Chord>& chords = chords_[j];
  Cap cap;
  cap.plane = plane;
  if (chords.empty()) return cap;  // the plane passes between shells: both sides are closed already
  const PlaneFrame frame = frame_of(planes_[j]);
  CDT cdt;
  const double border_length = insert_border(cdt, chords, split_.points, frame, j);
  mark_nesting(cdt);
  const auto first_interior = static_cast<std::int32_t>(split_.points.size());
  if (density_ > 0) refine_cap(cdt, chords.size(), border_length, density_, frame, split_.points);
  cap.interior_point_count = static_cast<std::int32_t>(split_.points.size()) - first_interior;
  cap.triangles = domain_triangles(cdt);
  check_cap_closes_loops(cap.triangles, chords, j);
  return cap;
}

std::vector<Cap> build_caps(SplitSurface& split, const std::vector<CutPlane>& planes, double density) {
  CapBuilder builder(split, planes, density);
  std::vector<Cap> caps;
  for (std::size_t j = 0; j < planes.size(); ++j) caps.push_back(builder.build(static_cast<int>(j)));
  return caps;
}

}  // namespace partet

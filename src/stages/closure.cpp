#include "stages/closure.hpp"

#include <CGAL/Constrained_Delaunay_triangulation_2.h>
#include <CGAL/Constrained_triangulation_face_base_2.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Triangulation_face_base_with_info_2.h>
#include <CGAL/Triangulation_vertex_base_with_info_2.h>

#include <algorithm>
#include <cmath>
#include <deque>
#include <limits>
#include <unordered_map>
#include <string>

#include "stages/geometry.hpp"
#include "stages/topology.hpp"
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

// Inserts the border vertices (by local id, which follows the global id, so the triangulation is
// built the same way every time) and the chords as constraints. Returns the border's total length.
double insert_border(CDT& cdt, const CapBorder& border, const PlaneFrame& frame) {
  const int j = border.plane;
  std::vector<CDT::Vertex_handle> handle(border.points.size());
  double border_length = 0;
  try {
    for (std::size_t id = 0; id < border.points.size(); ++id) {
      const auto before = cdt.number_of_vertices();
      auto vh = cdt.insert(to_2d(frame, border.points[id]));
      if (cdt.number_of_vertices() == before)
        throw PartitionError(
            FailureKind::other, -1,
            "cut plane " + std::to_string(j) + ": two border points coincide in the plane (near-degenerate crossing)");
      vh->info() = static_cast<std::int32_t>(id);
      handle[id] = vh;
    }
    for (const auto& c : border.chords) {
      cdt.insert_constraint(handle.at(c[0]), handle.at(c[1]));
      border_length += distance(border.points[c[0]], border.points[c[1]]);
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
// appended to `points` (its id: first_id + its position there). `hint` is a face near p (walks
// start there). Returns the new vertex, or a null handle.
CDT::Vertex_handle insert_interior_point(CDT& cdt, const K::Point_2& p, CDT::Face_handle hint, const PlaneFrame& frame,
                                         std::size_t first_id, std::vector<Point3>& points) {
  const CDT::Face_handle g = cdt.locate(p, hint);
  if (g == CDT::Face_handle() || !in_domain(cdt, g) || encroaches(cdt, g, p)) return {};
  const int nesting = g->info().nesting;
  const auto before = cdt.number_of_vertices();
  auto vh = cdt.insert(p, g);
  if (cdt.number_of_vertices() == before) return {};  // coincides with an existing point
  // The new faces fill a region bounded by unconstrained edges: same nesting as before.
  auto fc = cdt.incident_faces(vh), done = fc;
  do {
    fc->info().nesting = nesting;
  } while (++fc != done);
  vh->info() = static_cast<std::int32_t>(first_id + points.size());
  points.push_back(lift(frame, p));
  return vh;
}

// The border chords in a uniform grid of square cells, to find the chords near a point.
class ChordGrid {
 public:
  ChordGrid(const CDT& cdt, double cell) : cell_(cell) {
    for (auto v = cdt.finite_vertices_begin(); v != cdt.finite_vertices_end(); ++v) {
      lo_x_ = std::min(lo_x_, v->point().x());
      lo_y_ = std::min(lo_y_, v->point().y());
      hi_x_ = std::max(hi_x_, v->point().x());
      hi_y_ = std::max(hi_y_, v->point().y());
    }
    columns_ = static_cast<long>((hi_x_ - lo_x_) / cell_) + 1;
    rows_ = static_cast<long>((hi_y_ - lo_y_) / cell_) + 1;
    for (auto e = cdt.finite_edges_begin(); e != cdt.finite_edges_end(); ++e) {
      if (!cdt.is_constrained(*e)) continue;
      const K::Point_2& a = e->first->vertex(CDT::cw(e->second))->point();
      const K::Point_2& b = e->first->vertex(CDT::ccw(e->second))->point();
      segments_.push_back({a, b});
      for (long r = row(std::min(a.y(), b.y())); r <= row(std::max(a.y(), b.y())); ++r)
        for (long c = column(std::min(a.x(), b.x())); c <= column(std::max(a.x(), b.x())); ++c)
          cells_[r * columns_ + c].push_back(segments_.size() - 1);
    }
  }
  double lo_x() const { return lo_x_; }
  double lo_y() const { return lo_y_; }
  double hi_x() const { return hi_x_; }
  double hi_y() const { return hi_y_; }

  // Calls f(x_lo, y_lo, x_hi, y_hi) for every cell holding a chord or next to one (each once):
  // together they cover every point closer than one cell to the border.
  template <class F>
  void for_each_cell_near_border(F f) const {
    std::vector<long> near;
    for (const auto& [index, chords] : cells_) {
      const long r0 = index / columns_, c0 = index % columns_;
      for (long r = std::max(r0 - 1, 0L); r <= std::min(r0 + 1, rows_ - 1); ++r)
        for (long c = std::max(c0 - 1, 0L); c <= std::min(c0 + 1, columns_ - 1); ++c) near.push_back(r * columns_ + c);
    }
    std::sort(near.begin(), near.end());
    near.erase(std::unique(near.begin(), near.end()), near.end());
    for (long index : near) {
      const double x = lo_x_ + static_cast<double>(index % columns_) * cell_;
      const double y = lo_y_ + static_cast<double>(index / columns_) * cell_;
      f(x, y, std::nextafter(x + cell_, x), std::nextafter(y + cell_, y));
    }
  }

  // True when a chord passes closer than `distance` (at most one cell) to p.
  bool near(const K::Point_2& p, double distance) const {
    const double d2 = distance * distance;
    const long r0 = row(p.y()), c0 = column(p.x());
    for (long r = std::max(r0 - 1, 0L); r <= std::min(r0 + 1, rows_ - 1); ++r)
      for (long c = std::max(c0 - 1, 0L); c <= std::min(c0 + 1, columns_ - 1); ++c) {
        auto it = cells_.find(r * columns_ + c);
        if (it == cells_.end()) continue;
        for (std::size_t s : it->second)
          if (CGAL::squared_distance(p, K::Segment_2(segments_[s][0], segments_[s][1])) < d2) return true;
      }
    return false;
  }

 private:
  long row(double y) const { return std::clamp(static_cast<long>((y - lo_y_) / cell_), 0L, rows_ - 1); }
  long column(double x) const { return std::clamp(static_cast<long>((x - lo_x_) / cell_), 0L, columns_ - 1); }

  double cell_;
  double lo_x_ = std::numeric_limits<double>::max(), lo_y_ = std::numeric_limits<double>::max();
  double hi_x_ = std::numeric_limits<double>::lowest(), hi_y_ = std::numeric_limits<double>::lowest();
  long columns_ = 1, rows_ = 1;
  std::vector<std::array<K::Point_2, 2>> segments_;
  std::unordered_map<long, std::vector<std::size_t>> cells_;
};

// A triangular lattice: rows `row_height` apart, odd rows shifted by half a spacing. The lattice
// with twice the spacing and the same origin is a subset of it, so levels nest.
struct Lattice {
  double x0, y0, spacing;
  double row_height() const { return spacing * std::sqrt(3.0) / 2; }
  K::Point_2 at(long row, long column) const {
    const double shift = (row % 2 != 0) ? spacing / 2 : 0.0;
    return {x0 + shift + static_cast<double>(column) * spacing, y0 + static_cast<double>(row) * row_height()};
  }
  // Calls f(point) for the lattice points in [x_lo, x_hi] x [y_lo, y_hi].
  template <class F>
  void for_each_in(double x_lo, double y_lo, double x_hi, double y_hi, F f) const {
    const long r_lo = std::max(0L, static_cast<long>(std::ceil((y_lo - y0) / row_height())));
    const long r_hi = static_cast<long>(std::floor((y_hi - y0) / row_height()));
    for (long r = r_lo; r <= r_hi; ++r) {
      const double shift = (r % 2 != 0) ? spacing / 2 : 0.0;
      const long c_lo = std::max(0L, static_cast<long>(std::ceil((x_lo - x0 - shift) / spacing)));
      const long c_hi = static_cast<long>(std::floor((x_hi - x0 - shift) / spacing));
      for (long c = c_lo; c <= c_hi; ++c) f(at(r, c));
    }
  }
};

// Where the cap's interior points go: a graded lattice. Its spacing is `base` next to the border
// and grows with the distance d to the border, to about d / kGrading: level l (spacing
// base * 2^l) fills the band base * kGrading * 2^l <= d < base * kGrading * 2^(l+1). The levels
// nest, so no two points are closer than `base`, and neighbouring bands differ by a factor 2.
// The points number about (border points) x density x kGrading x 2 plus a coarse core, instead
// of growing with the cap's area: caps of large models stay cheap for TetGen too. No point goes
// closer than base/2 to the border (a border chord is never split, so both pieces keep
// matching, and points near it would make slivers).
std::vector<K::Point_2> graded_cap_points(const CDT& cdt, double base, std::size_t budget) {
  constexpr double kGrading = 2.0;
  const ChordGrid outline(cdt, base);
  const double width = outline.hi_x() - outline.lo_x(), height = outline.hi_y() - outline.lo_y();
  // The top level covers the core, up to the largest distance from the border: half the
  // bounding box's diagonal at most. Its lattice spans the whole bounding box (a few points).
  const double deepest = std::hypot(width, height) / 2;
  int top = 0;
  while (kGrading * 2 * base * std::ldexp(1.0, top) < deepest) ++top;
  std::vector<K::Point_2> points;
  for (int level = 0; level <= top; ++level) {
    const Lattice lattice{outline.lo_x(), outline.lo_y(), base * std::ldexp(1.0, level)};
    const double inner = level == 0 ? base / 2 : kGrading * lattice.spacing;  // the band [inner, outer)
    const double outer = kGrading * 2 * lattice.spacing;
    const ChordGrid grid(cdt, outer);
    auto keep = [&](const K::Point_2& p) {
      if (grid.near(p, inner) || (level < top && !grid.near(p, outer))) return;
      points.push_back(p);
    };
    if (level == top)
      lattice.for_each_in(outline.lo_x(), outline.lo_y(), outline.hi_x(), outline.hi_y(), keep);
    else
      grid.for_each_cell_near_border([&](double x_lo, double y_lo, double x_hi, double y_hi) {
        lattice.for_each_in(x_lo, y_lo, x_hi, y_hi, keep);
      });
  }
  // Row by row, so each insertion starts its walk next to the previous point.
  std::sort(points.begin(), points.end(),
            [](const K::Point_2& a, const K::Point_2& b) { return a.y() != b.y() ? a.y() < b.y() : a.x() < b.x(); });
  points.erase(std::unique(points.begin(), points.end()), points.end());
  if (points.size() > budget) points.resize(budget);
  return points;
}

// Fills the cap's interior with a graded triangular lattice (graded_cap_points), joined to the
// border by the constrained triangulation. The lattice spacing next to the border is the mean
// border edge length / density.
void refine_cap(CDT& cdt, const CapBorder& border, double border_length, const PlaneFrame& frame,
                std::vector<Point3>& points) {
  const std::size_t chord_count = border.chords.size();
  const double base = border_length / static_cast<double>(chord_count) / border.density;
  const std::size_t budget = 50 * chord_count + 1000;  // bounds the work on odd inputs
  CDT::Face_handle hint = cdt.infinite_face()->neighbor(0);
  for (const K::Point_2& p : graded_cap_points(cdt, base, budget))
    if (auto v = insert_interior_point(cdt, p, hint, frame, border.points.size(), points); v != CDT::Vertex_handle())
      hint = v->face();
}

// The domain's triangles in a deterministic order, independent of CGAL's internal face order.
// Counter-clockwise in (u, v) means the normal is +axis: outward for the piece below.
std::vector<Triangle> domain_triangles(const CDT& cdt) {
  std::vector<Triangle> triangles;
  for (auto f = cdt.finite_faces_begin(); f != cdt.finite_faces_end(); ++f) {
    if (!in_domain(cdt, f)) continue;
    triangles.push_back({f->vertex(0)->info(), f->vertex(1)->info(), f->vertex(2)->info()});
  }
  sort_triangles(triangles);
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

CapShape triangulate_cap(const CapBorder& border) {
  CapShape shape;
  shape.plane = border.plane;
  if (border.chords.empty()) return shape;  // the plane passes between shells: both sides are closed already
  const PlaneFrame frame = frame_of(border.cut);
  CDT cdt;
  const double border_length = insert_border(cdt, border, frame);
  mark_nesting(cdt);
  if (border.density > 0) refine_cap(cdt, border, border_length, frame, shape.interior_points);
  shape.triangles = domain_triangles(cdt);
  check_cap_closes_loops(shape.triangles, border.chords, static_cast<std::size_t>(border.plane));
  return shape;
}

CapBuilder::CapBuilder(SplitSurface& split, const std::vector<CutPlane>& planes, double density)
    : split_(split), planes_(planes), density_(density) {
  if (!(density >= 0) || !std::isfinite(density)) throw OptionError("the cap density must be a finite number >= 0");
  chords_ = border_chords(split, planes.size());
}

std::vector<std::int32_t> CapBuilder::border_ids(int plane) const {
  std::vector<std::int32_t> ids;
  for (const auto& c : chords_.at(static_cast<std::size_t>(plane))) ids.insert(ids.end(), {c[0], c[1]});
  std::sort(ids.begin(), ids.end());
  ids.erase(std::unique(ids.begin(), ids.end()), ids.end());
  return ids;
}

CapBorder CapBuilder::border(int plane) const {
  const auto j = static_cast<std::size_t>(plane);
  CapBorder border;
  border.plane = plane;
  border.cut = planes_.at(j);
  border.density = density_;
  border.global_ids = border_ids(plane);
  const auto local = [&](std::int32_t id) {
    return static_cast<std::int32_t>(std::lower_bound(border.global_ids.begin(), border.global_ids.end(), id) -
                                     border.global_ids.begin());
  };
  border.points.reserve(border.global_ids.size());
  for (auto id : border.global_ids) border.points.push_back(split_.points[id]);
  border.chords.reserve(chords_[j].size());
  for (const auto& c : chords_[j]) border.chords.push_back({local(c[0]), local(c[1])});
  return border;
}

Cap CapBuilder::place(int plane, CapShape&& shape) {
  if (shape.plane != plane)
    throw InternalError("the cap of plane " + std::to_string(shape.plane) + " was placed as plane " + std::to_string(plane));
  const std::vector<std::int32_t> global_ids = border_ids(plane);
  const auto border_count = static_cast<std::int32_t>(global_ids.size());
  const auto interior_count = static_cast<std::int32_t>(shape.interior_points.size());
  Cap cap;
  cap.plane = plane;
  const auto first_interior = static_cast<std::int32_t>(split_.points.size());
  cap.triangles = std::move(shape.triangles);
  for (Triangle& t : cap.triangles)
    for (auto& v : t) {
      if (v < 0 || v >= border_count + interior_count)
        throw InternalError("the cap of plane " + std::to_string(plane) + " names a point it does not have");
      v = v < border_count ? global_ids[static_cast<std::size_t>(v)] : first_interior + (v - border_count);
    }
  split_.points.insert(split_.points.end(), shape.interior_points.begin(), shape.interior_points.end());
  cap.interior_point_count = interior_count;
  split_.cap_point_plane.insert(split_.cap_point_plane.end(), static_cast<std::size_t>(interior_count), plane);
  return cap;
}

}  // namespace partet

// Surface closure: build_caps triangulates the cross-section of the solid on every cut plane.
#include <gtest/gtest.h>

#include <map>

#include <algorithm>
#include <cmath>
#include <limits>
#include <set>
#include <string>
#include <vector>

#include "stages/closure.hpp"
#include "partet/errors.hpp"
#include "stages/generate.hpp"
#include "stages/partition.hpp"
#include "stages/piece.hpp"
#include "stage_helpers.hpp"
#include "stage_batches.hpp"

namespace partet {
namespace {

using namespace partet::test;

constexpr double kPi = 3.14159265358979323846;

struct Closed {
  SurfaceMesh input;
  std::vector<CutPlane> planes;
  SplitSurface split;
  std::size_t points_before_caps = 0;  // split.points.size() before build_caps
  std::vector<Cap> caps;
  int axis = -1;
};

Closed close_surface(const SurfaceMesh& input, int k, double density) {
  Closed c;
  c.input = input;
  c.planes = choose_cut_planes(input, k);
  c.split = split_at_planes(input, c.planes);
  c.points_before_caps = c.split.points.size();
  c.caps = build_caps(c.split, c.planes, density);
  c.axis = c.planes.empty() ? -1 : coordinate_axis_of(c.planes[0].normal);
  return c;
}

// Plane a point lies on by construction: cut vertices and cap interior points; -1 for input
// vertices.
std::vector<int> plane_of_points(const Closed& c) {
  std::vector<int> plane(c.split.points.size(), -1);
  for (std::int32_t i = 0; i < c.split.cut_vertex_count(); ++i)
    plane[c.split.input_vertex_count + i] = c.split.cut_vertex_plane[i];
  std::size_t next = c.points_before_caps;
  for (const Cap& cap : c.caps)
    for (std::int32_t i = 0; i < cap.interior_point_count; ++i) plane[next++] = cap.plane;
  EXPECT_EQ(next, c.split.points.size()) << "interior points are not appended cap by cap";
  return plane;
}

double cap_area(const Closed& c, const Cap& cap) {
  long double sum = 0;
  for (const auto& t : cap.triangles) sum += projected_area(c.split.points, t, c.axis);
  return static_cast<double>(sum);
}

// Directed border chords of plane j as the piece below traverses them.
std::set<std::pair<std::int32_t, std::int32_t>> chords_below(const Closed& c, int j) {
  std::set<std::pair<std::int32_t, std::int32_t>> chords;
  for (std::size_t t = 0; t < c.split.triangles.size(); ++t) {
    if (c.split.piece[t] != j) continue;
    const auto& tri = c.split.triangles[t];
    for (int e = 0; e < 3; ++e) {
      const auto a = tri[e], b = tri[(e + 1) % 3];
      if (c.split.is_cut_vertex(a) && c.split.is_cut_vertex(b) &&
          c.split.cut_vertex_plane[a - c.split.input_vertex_count] == j &&
          c.split.cut_vertex_plane[b - c.split.input_vertex_count] == j)
        chords.insert({a, b});
    }
  }
  return chords;
}

// Everything a cap must satisfy: on its plane, counter-clockwise seen from +axis, covering
// exactly the cross-section, its border being exactly the reversed chords of the piece below.
void expect_valid_caps(const Closed& c) {
  ASSERT_EQ(c.caps.size(), c.planes.size());
  ASSERT_GE(c.axis, 0);
  const auto plane = plane_of_points(c);
  for (std::size_t j = 0; j < c.caps.size(); ++j) {
    SCOPED_TRACE("plane " + std::to_string(j));
    const Cap& cap = c.caps[j];
    EXPECT_EQ(cap.plane, static_cast<int>(j));
    ASSERT_FALSE(cap.triangles.empty());
    for (const auto& t : cap.triangles) {
      for (auto v : t) {
        ASSERT_GE(v, c.split.input_vertex_count) << "an input vertex in a cap";
        ASSERT_LT(v, static_cast<std::int32_t>(c.split.points.size()));
        EXPECT_EQ(plane[v], static_cast<int>(j));
        EXPECT_EQ(c.split.points[v][c.axis], c.planes[j].offset);
      }
      EXPECT_GT(projected_area(c.split.points, t, c.axis), 0) << "cap triangle not counter-clockwise";
    }
    // The cap's border edges (no reverse inside the cap) are the chords of the piece below,
    // reversed; nothing else.
    std::set<std::pair<std::int32_t, std::int32_t>> edges, border;
    for (const auto& t : cap.triangles)
      for (int e = 0; e < 3; ++e) EXPECT_TRUE(edges.insert({t[e], t[(e + 1) % 3]}).second);
    for (const auto& e : edges)
      if (!edges.count({e.second, e.first})) border.insert({e.second, e.first});
    EXPECT_EQ(border, chords_below(c, static_cast<int>(j)));

    const double area = cap_area(c, cap);
    const double section = cross_section_area(c.input.points, c.input.triangles, c.axis, c.planes[j].offset);
    EXPECT_GT(section, 0);
    EXPECT_NEAR(area, section, 1e-9 * section);
  }
}

TEST(BuildCaps, SphereThroughTheCentre) {
  const Closed c = close_surface(generate_surface("sphere", 4000), 2, 0.0);
  expect_valid_caps(c);
  ASSERT_EQ(c.caps.size(), 1u);
  const double d = c.planes[0].offset;
  EXPECT_LT(std::abs(d), 0.05);
  const double area = cap_area(c, c.caps[0]);
  EXPECT_NEAR(area, kPi * (1 - d * d), 0.01 * kPi);
  EXPECT_LT(area, kPi * (1 - d * d));  // a polygon inscribed in the circle
  EXPECT_EQ(border_loop_count(c.caps[0].triangles), 1);
  // Density 0: only border vertices, so a triangulated disk with V - E + F = 1 and F = V - 2.
  EXPECT_EQ(c.caps[0].interior_point_count, 0);
  EXPECT_EQ(c.split.points.size(), c.points_before_caps);
  std::set<std::int32_t> vertices;
  for (const auto& t : c.caps[0].triangles) vertices.insert(t.begin(), t.end());
  EXPECT_EQ(c.caps[0].triangles.size() + 2, vertices.size());
  EXPECT_EQ(vertices.size(), chords_below(c, 0).size());
}

TEST(BuildCaps, DensityAddsInteriorPointsOnThePlane) {
  const SurfaceMesh s = generate_surface("sphere", 3000);
  const Closed c0 = close_surface(s, 3, 0.0);
  const Closed c1 = close_surface(s, 3, 1.0);
  const Closed c3 = close_surface(s, 3, 3.0);
  expect_valid_caps(c0);
  expect_valid_caps(c1);
  expect_valid_caps(c3);
  for (std::size_t j = 0; j < 2; ++j) {
    SCOPED_TRACE("plane " + std::to_string(j));
    EXPECT_EQ(c0.caps[j].interior_point_count, 0);
    EXPECT_GT(c1.caps[j].interior_point_count, 0);
    EXPECT_GT(c3.caps[j].interior_point_count, c1.caps[j].interior_point_count);
    EXPECT_GT(c3.caps[j].triangles.size(), c1.caps[j].triangles.size());
    EXPECT_GT(c1.caps[j].triangles.size(), c0.caps[j].triangles.size());
    // The same cross-section whatever the density.
    const double a0 = cap_area(c0, c0.caps[j]);
    EXPECT_NEAR(cap_area(c3, c3.caps[j]), a0, 1e-12 * a0);
    // Interior points are new, distinct from every other point, and strictly inside the cap.
    std::set<Point3> border;
    for (std::size_t v = 0; v < c3.points_before_caps; ++v) border.insert(c3.split.points[v]);
    for (std::size_t v = c3.points_before_caps; v < c3.split.points.size(); ++v)
      EXPECT_TRUE(border.insert(c3.split.points[v]).second) << "duplicate point " << v;
  }
  // The partition (input and cut vertices) does not depend on the density.
  EXPECT_EQ(c0.points_before_caps, c3.points_before_caps);
  std::size_t interior = 0;
  for (const auto& cap : c3.caps) interior += cap.interior_point_count;
  EXPECT_EQ(c3.split.points.size(), c3.points_before_caps + interior);
  // The spacing next to the border is the mean border edge / density: about density times as
  // many points along the border (the core is graded, so not density^2).
  EXPECT_GT(c3.caps[0].interior_point_count, 1.4 * c1.caps[0].interior_point_count);
}

TEST(BuildCaps, InteriorPointsAreSpacedAndKeepAMarginFromTheBorder) {
  // A long box: its caps are squares far larger than the border spacing, so the interior is
  // graded (coarser away from the border).
  const SurfaceMesh s = generate_surface("sphere", 20000);
  for (double density : {0.25, 1.0}) {
    SCOPED_TRACE("density " + std::to_string(density));
    const Closed c = close_surface(s, 2, density);
    const Cap& cap = c.caps[0];
    const int axis = c.axis;
    ASSERT_GE(axis, 0);
    const int u = (axis + 1) % 3, v = (axis + 2) % 3;
    // Border chords of the cap: its edges used by one cap triangle only.
    std::map<std::pair<std::int32_t, std::int32_t>, int> edge_use;
    for (const auto& t : cap.triangles)
      for (int e = 0; e < 3; ++e) ++edge_use[{std::min(t[e], t[(e + 1) % 3]), std::max(t[e], t[(e + 1) % 3])}];
    double border_length = 0;
    std::vector<std::pair<Point3, Point3>> chords;
    for (const auto& [edge, uses] : edge_use)
      if (uses == 1) {
        chords.push_back({c.split.points[edge.first], c.split.points[edge.second]});
        border_length += norm(sub(chords.back().first, chords.back().second));
      }
    const double base = border_length / static_cast<double>(chords.size()) / density;
    const std::size_t first = c.points_before_caps, last = first + static_cast<std::size_t>(cap.interior_point_count);
    ASSERT_GT(last, first + 10);
    auto distance2d = [&](const Point3& a, const Point3& b) { return std::hypot(a[u] - b[u], a[v] - b[v]); };
    auto segment_distance = [&](const Point3& p, const Point3& a, const Point3& b) {
      const double ax = b[u] - a[u], ay = b[v] - a[v], px = p[u] - a[u], py = p[v] - a[v];
      const double t = std::clamp((px * ax + py * ay) / (ax * ax + ay * ay), 0.0, 1.0);
      return std::hypot(px - t * ax, py - t * ay);
    };
    double closest_pair = std::numeric_limits<double>::infinity(), closest_border = closest_pair, widest = 0;
    for (std::size_t i = first; i < last; ++i) {
      const Point3& p = c.split.points[i];
      for (std::size_t j = i + 1; j < last; ++j) closest_pair = std::min(closest_pair, distance2d(p, c.split.points[j]));
      double to_border = std::numeric_limits<double>::infinity();
      for (const auto& [a, b] : chords) to_border = std::min(to_border, segment_distance(p, a, b));
      closest_border = std::min(closest_border, to_border);
      widest = std::max(widest, to_border);
    }
    EXPECT_GE(closest_pair, base * (1 - 1e-9));
    EXPECT_GE(closest_border, base / 2 * (1 - 1e-9));
    // Graded: far fewer points than a uniform lattice of the border spacing would need.
    const double uniform = cap_area(c, cap) / (std::sqrt(3.0) / 2 * base * base);
    if (widest > 8 * base) EXPECT_LT(cap.interior_point_count, 0.6 * uniform);
  }
}

TEST(BuildCaps, DensityMustBeFiniteAndNonNegative) {
  const SurfaceMesh s = generate_surface("sphere", 300);
  const auto planes = choose_cut_planes(s, 2);
  for (double density :
       {-1.0, -1e-300, std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::infinity()}) {
    SplitSurface split = split_at_planes(s, planes);
    EXPECT_THROW(build_caps(split, planes, density), OptionError) << density;
  }
}

TEST(BuildCaps, KOneHasNoCaps) {
  const SurfaceMesh s = generate_surface("sphere", 300);
  SplitSurface split = split_at_planes(s, {});
  EXPECT_TRUE(build_caps(split, {}, 1.0).empty());
  EXPECT_EQ(split.points.size(), s.points.size());
}

TEST(BuildCaps, TorusCutThroughTheHoleHasTwoLoops) {
  // The torus (major radius 1, tube radius 0.4) lies flat across the main axis, so the median
  // plane cuts both sides of the ring: two disks of radius ~0.4 (longer if the plane is
  // oblique to the tube).
  const SurfaceMesh s = generate_surface("torus", 3000);
  for (double density : {0.0, 1.0}) {
    SCOPED_TRACE("density " + std::to_string(density));
    const Closed c = close_surface(s, 2, density);
    expect_valid_caps(c);
    const Cap& cap = c.caps[0];
    EXPECT_EQ(border_loop_count(cap.triangles), 2);
    std::set<std::int32_t> vertices;
    std::set<std::pair<std::int32_t, std::int32_t>> edges;
    for (const auto& t : cap.triangles) {
      vertices.insert(t.begin(), t.end());
      for (int e = 0; e < 3; ++e) edges.insert({std::min(t[e], t[(e + 1) % 3]), std::max(t[e], t[(e + 1) % 3])});
    }
    const long euler =
        static_cast<long>(vertices.size()) - static_cast<long>(edges.size()) + static_cast<long>(cap.triangles.size());
    EXPECT_EQ(euler, 2) << "two disks";
    const double disk = kPi * 0.4 * 0.4;
    const double area = cap_area(c, cap);
    EXPECT_GT(area, 2 * disk * 0.95);
    EXPECT_LT(area, 2 * disk * 1.3);
  }
  // With more planes, the outer ones cut a single arc of the ring: one loop each.
  const Closed c4 = close_surface(s, 4, 1.0);
  expect_valid_caps(c4);
  std::vector<int> loops;
  for (const auto& cap : c4.caps) loops.push_back(border_loop_count(cap.triangles));
  EXPECT_EQ(loops.front(), 1);
  EXPECT_EQ(loops[1], 2);
  EXPECT_EQ(loops.back(), 1);
}

TEST(BuildCaps, NestedShellsGiveACapWithAHoleAndAnIsland) {
  // Radii 1 (outer), 0.6 (cavity), 0.3 (island), all centred at the origin: the section
  // through the centre is an annulus 0.6..1 plus a disk of radius 0.3.
  const SurfaceMesh s = generate_surface("nested", 6000);
  for (double density : {0.0, 2.0}) {
    SCOPED_TRACE("density " + std::to_string(density));
    const Closed c = close_surface(s, 2, density);
    expect_valid_caps(c);
    const Cap& cap = c.caps[0];
    const double d = c.planes[0].offset;
    ASSERT_LT(std::abs(d), 0.1);
    EXPECT_EQ(border_loop_count(cap.triangles), 3);
    const double exact = kPi * ((1 - d * d) - (0.36 - d * d) + (0.09 - d * d));
    EXPECT_NEAR(cap_area(c, cap), exact, 0.04 * exact);
    // No cap triangle inside the cavity ring (between radius 0.3 and the cavity shell).
    for (const auto& t : cap.triangles) {
      Point3 centroid{0, 0, 0};
      for (auto v : t)
        for (int i = 0; i < 3; ++i) centroid[i] += c.split.points[v][i] / 3;
      const double r = norm(centroid);
      EXPECT_FALSE(r > 0.31 && r < 0.55) << "cap triangle in the cavity at radius " << r;
    }
  }
}

TEST(BuildCaps, AllShapesSeveralPlanes) {
  for (const char* name : {"sphere", "torus", "genus3", "nested"}) {
    for (int k : {3, 6}) {
      SCOPED_TRACE(std::string(name) + " k=" + std::to_string(k));
      const Closed c = close_surface(generate_surface(name, 2500), k, 1.0);
      expect_valid_caps(c);
    }
  }
}

// Both sides of a cut see the same cap: the piece below with the cap's orientation, the piece
// above reversed, and every piece is closed.
void expect_pieces_share_caps(const Closed& c) {
  const auto pieces = assemble_pieces(c.split, c.caps);
  ASSERT_EQ(pieces.size(), c.planes.size() + 1);
  const auto plane = plane_of_points(c);
  for (const auto& piece : pieces) {
    SCOPED_TRACE("piece " + std::to_string(piece.index));
    EXPECT_NO_THROW(check_piece_topology(piece));
    EXPECT_EQ(closed_oriented_problem(piece.triangles), "");
    // Triangles of the piece lying on plane j (all three vertices on it), in global ids.
    std::vector<std::vector<Triangle>> on_plane(c.planes.size());
    for (const auto& t : piece.triangles) {
      const Triangle g{piece.global_ids[t[0]], piece.global_ids[t[1]], piece.global_ids[t[2]]};
      const int j = plane[g[0]];
      if (j >= 0 && plane[g[1]] == j && plane[g[2]] == j) on_plane[j].push_back(g);
    }
    for (std::size_t j = 0; j < c.planes.size(); ++j) {
      std::vector<Triangle> expected;
      if (static_cast<int>(j) == piece.index) expected = c.caps[j].triangles;
      if (static_cast<int>(j) + 1 == piece.index)
        for (const auto& t : c.caps[j].triangles) expected.push_back({t[0], t[2], t[1]});
      EXPECT_EQ(canonical_set(on_plane[j]), canonical_set(expected)) << "plane " << j;
    }
  }
}

TEST(BuildCaps, PiecesShareTheCapsWithOppositeOrientation) {
  for (const char* name : {"sphere", "torus", "nested", "genus3"}) {
    for (double density : {0.0, 1.5}) {
      SCOPED_TRACE(std::string(name) + " density " + std::to_string(density));
      expect_pieces_share_caps(close_surface(generate_surface(name, 2000), 4, density));
    }
  }
}

TEST(BuildCaps, PcaAxisCapsClosePieces) {
  const SurfaceMesh s = generate_surface("genus3", 2000);
  const auto planes = choose_cut_planes(s, 3, CutAxis::pca);
  SplitSurface split = split_at_planes(s, planes);
  const auto caps = build_caps(split, planes, 1.0);
  ASSERT_EQ(caps.size(), 2u);
  for (const auto& cap : caps) {
    EXPECT_GT(cap.interior_point_count, 0);
    for (const auto& t : cap.triangles) {
      // Normal along +axis (the orientation for the piece below).
      const Point3 n = triangle_normal(split.points, t);
      EXPECT_GT(dot(n, planes[0].normal), 0.999 * norm(n));
      for (auto v : t) {
        const double off = dot(planes[cap.plane].normal, split.points[v]) - planes[cap.plane].offset;
        EXPECT_LE(std::abs(off), 1e-14);
      }
    }
  }
  for (const auto& piece : assemble_pieces(split, caps)) {
    EXPECT_NO_THROW(check_piece_topology(piece));
    EXPECT_EQ(closed_oriented_problem(piece.triangles), "");
  }
}

// An axis-aligned box [lo, hi] with outward triangles.
void add_box(SurfaceMesh& s, const Point3& lo, const Point3& hi) {
  const auto base = static_cast<std::int32_t>(s.points.size());
  for (int i = 0; i < 8; ++i)
    s.points.push_back({(i & 1) ? hi[0] : lo[0], (i & 2) ? hi[1] : lo[1], (i & 4) ? hi[2] : lo[2]});
  auto quad = [&](int a, int b, int c, int d) {
    s.triangles.push_back({base + a, base + b, base + c});
    s.triangles.push_back({base + a, base + c, base + d});
  };
  quad(0, 2, 3, 1);
  quad(4, 5, 7, 6);
  quad(0, 1, 5, 4);
  quad(2, 6, 7, 3);
  quad(0, 4, 6, 2);
  quad(1, 3, 7, 5);
}

TEST(BuildCaps, CrossingLoopsThrow) {
  // Two long boxes that overlap (a self-intersecting input): their sections on the plane x = 2
  // are overlapping squares whose borders cross.
  SurfaceMesh s;
  add_box(s, {0, 0, 0}, {4, 1, 1});
  add_box(s, {0, 0.3, 0.6}, {4, 1.3, 1.6});
  const auto planes = choose_cut_planes(s, 2);
  ASSERT_EQ(planes.size(), 1u);
  ASSERT_EQ(planes[0].normal, (Point3{1, 0, 0}));
  SplitSurface split = split_at_planes(s, planes);
  try {
    build_caps(split, planes, 1.0);
    ADD_FAILURE() << "crossing loops accepted";
  } catch (const PartitionError& e) {
    // Crossing loops are how a self-intersecting input shows on a cut: the retry policy checks
    // the whole input for self-intersections on this kind.
    EXPECT_EQ(e.failure.kind, FailureKind::self_intersection);
  }
}

TEST(BuildCaps, SeparateBoxesGiveTwoLoops) {
  // The same boxes apart: a valid cap of two squares.
  SurfaceMesh s;
  add_box(s, {0, 0, 0}, {4, 1, 1});
  add_box(s, {0, 1.5, 0.6}, {4, 2.5, 1.6});
  Closed c;
  c.input = s;
  c.planes = choose_cut_planes(s, 2);
  c.split = split_at_planes(s, c.planes);
  c.points_before_caps = c.split.points.size();
  c.caps = build_caps(c.split, c.planes, 0.0);
  c.axis = 0;
  expect_valid_caps(c);
  EXPECT_EQ(border_loop_count(c.caps[0].triangles), 2);
  EXPECT_DOUBLE_EQ(cap_area(c, c.caps[0]), 2.0);
  expect_pieces_share_caps(c);
}

TEST(BuildCaps, PlaneBetweenTwoShellsNeedsNoCap) {
  // two_spheres has equally many vertices in both shells, so the balanced median plane lies in
  // the empty space between them. The pieces are then the two spheres themselves, already
  // closed: an empty cap is the right answer, not an error.
  const SurfaceMesh s = generate_surface("two_spheres", 1000);
  const auto planes = choose_cut_planes(s, 2);
  SplitSurface split = split_at_planes(s, planes);
  ASSERT_EQ(split.cut_vertex_count(), 0) << "fixture: the plane no longer falls between the shells";
  std::vector<Cap> caps;
  ASSERT_NO_THROW(caps = build_caps(split, planes, 1.0));
  ASSERT_EQ(caps.size(), 1u);
  EXPECT_TRUE(caps[0].triangles.empty());
  for (const auto& piece : assemble_pieces(split, caps)) EXPECT_NO_THROW(check_piece_topology(piece));
}

TEST(BuildCaps, ACapBuiltFromItsBorderAloneIsTheSameCap) {
  // Another rank builds a cap from its border only (CapBorder: its chords and their points); the
  // cap placed from that shape must be the one built with the whole split surface at hand, with
  // the same interior points and numbering, whatever order the shapes were triangulated in.
  const SurfaceMesh s = generate_surface("torus", 4000);
  const auto planes = choose_cut_planes(s, 4);
  SplitSurface here = split_at_planes(s, planes);
  SplitSurface elsewhere = here;
  const std::vector<Cap> built = build_caps(here, planes, 1.5);
  CapBuilder builder(elsewhere, planes, 1.5);
  std::vector<CapShape> shapes(planes.size());
  for (std::size_t j = planes.size(); j-- > 0;) {  // triangulated in reverse: out of order
    const CapBorder border = builder.border(static_cast<int>(j));
    EXPECT_TRUE(std::is_sorted(border.global_ids.begin(), border.global_ids.end()));
    EXPECT_EQ(border.points.size(), border.global_ids.size());
    shapes[j] = triangulate_cap(border);
  }
  ASSERT_EQ(planes.size(), 3u);
  for (std::size_t j = 0; j < planes.size(); ++j) {
    const Cap cap = builder.place(static_cast<int>(j), std::move(shapes[j]));
    EXPECT_EQ(cap.triangles, built[j].triangles) << "plane " << j;
    EXPECT_EQ(cap.interior_point_count, built[j].interior_point_count) << "plane " << j;
    EXPECT_GT(cap.interior_point_count, 0);
  }
  EXPECT_EQ(elsewhere.points, here.points);
  EXPECT_EQ(elsewhere.cap_point_plane, here.cap_point_plane);
}

TEST(BuildCaps, AShapeThatDoesNotFitItsPlaneIsRefused) {
  const SurfaceMesh s = generate_surface("sphere", 2000);
  const auto planes = choose_cut_planes(s, 3);
  SplitSurface split = split_at_planes(s, planes);
  CapBuilder builder(split, planes, 1.0);
  EXPECT_THROW(builder.place(1, triangulate_cap(builder.border(0))), InternalError);
  CapShape wrong = triangulate_cap(builder.border(0));
  wrong.triangles.push_back({0, 1, 1 << 20});  // a point the border does not have
  EXPECT_THROW(builder.place(0, std::move(wrong)), InternalError);
}

TEST(BuildCaps, CrossingLoopsThrowFromTheBorderAlone) {
  SurfaceMesh s;
  add_box(s, {0, 0, 0}, {4, 1, 1});
  add_box(s, {0, 0.3, 0.6}, {4, 1.3, 1.6});
  const auto planes = choose_cut_planes(s, 2);
  SplitSurface split = split_at_planes(s, planes);
  const CapBorder border = CapBuilder(split, planes, 1.0).border(0);
  try {
    triangulate_cap(border);
    ADD_FAILURE() << "crossing loops accepted";
  } catch (const PartitionError& e) {
    EXPECT_EQ(e.failure.kind, FailureKind::self_intersection);
    EXPECT_NE(e.failure.message.find("cut plane 0"), std::string::npos) << e.failure.message;
  }
}

}  // namespace
}  // namespace partet

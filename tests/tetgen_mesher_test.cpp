// TetGen wrapper: mesh_closed_surface fills a closed surface without changing its boundary;
// tetrahedralize_piece checks and meshes one piece. (Runs in child processes: piece_runner_test.)
#include <gtest/gtest.h>

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>

#include <algorithm>
#include <set>
#include <string>
#include <vector>

#include "stages/check.hpp"
#include "stages/closure.hpp"
#include "partet/errors.hpp"
#include "stages/generate.hpp"
#include "stages/partition.hpp"
#include "stages/piece.hpp"
#include "mesher/tetgen_mesher.hpp"
#include "stages/validate.hpp"
#include "stage_helpers.hpp"
#include "test_support.hpp"
#include "stage_batches.hpp"

namespace partet {
namespace {

using K = CGAL::Exact_predicates_inexact_constructions_kernel;
using namespace partet::test;

TetgenOptions in_process() { return TetgenOptions{}; }

// All points of a local mesh: the surface points, then the Steiner points.
std::vector<Point3> all_points(const std::vector<Point3>& surface_points, const LocalTetMesh& m) {
  std::vector<Point3> p = surface_points;
  p.insert(p.end(), m.steiner_points.begin(), m.steiner_points.end());
  return p;
}

int count_non_positive(const std::vector<Point3>& p, const std::vector<Tet>& tets) {
  int bad = 0;
  for (const auto& t : tets) {
    const K::Point_3 a(p[t[0]][0], p[t[0]][1], p[t[0]][2]), b(p[t[1]][0], p[t[1]][1], p[t[1]][2]),
        c(p[t[2]][0], p[t[2]][1], p[t[2]][2]), d(p[t[3]][0], p[t[3]][1], p[t[3]][2]);
    if (CGAL::orientation(a, b, c, d) != CGAL::POSITIVE) ++bad;
  }
  return bad;
}

// The properties every result of mesh_closed_surface must have.
void expect_fills_surface(const SurfaceMesh& s, const LocalTetMesh& m) {
  const auto points = all_points(s.points, m);
  ASSERT_FALSE(m.tets.empty());
  ASSERT_EQ(m.neighbours.size(), m.tets.size());
  // Valid indices; every Steiner point used.
  std::vector<char> used(points.size(), 0);
  for (const auto& t : m.tets)
    for (auto v : t) {
      ASSERT_GE(v, 0);
      ASSERT_LT(v, static_cast<std::int32_t>(points.size()));
      used[v] = 1;
    }
  for (std::size_t v = s.points.size(); v < points.size(); ++v) EXPECT_TRUE(used[v]) << "unused Steiner point " << v;
  // Steiner points are new points.
  std::set<Point3> distinct(s.points.begin(), s.points.end());
  for (const auto& q : m.steiner_points) EXPECT_TRUE(distinct.insert(q).second) << "Steiner point on a surface point";

  EXPECT_EQ(count_non_positive(points, m.tets), 0);
  EXPECT_EQ(neighbour_problem(m.tets, m.neighbours), "");
  // The boundary is exactly the input, with the same orientation.
  std::vector<Triangle> boundary;
  for (std::size_t t = 0; t < m.tets.size(); ++t)
    for (int j = 0; j < 4; ++j)
      if (m.neighbours[t][j] < 0) boundary.push_back(outward_face(m.tets[t], j));
  EXPECT_EQ(canonical_set(boundary), canonical_set(s.triangles));
  // Volume.
  const double volume = enclosed_volume(s);
  EXPECT_NEAR(total_tet_volume(points, m.tets), volume, 1e-9 * volume);
}

TEST(MeshClosedSurface, Sphere) {
  const SurfaceMesh s = generate_surface("sphere", 1500);
  expect_fills_surface(s, mesh_closed_surface(s.points, s.triangles, in_process()));
}

TEST(MeshClosedSurface, TorusAndGenus3) {
  for (const char* name : {"torus", "genus3"}) {
    SCOPED_TRACE(name);
    const SurfaceMesh s = generate_surface(name, 2000);
    expect_fills_surface(s, mesh_closed_surface(s.points, s.triangles, in_process()));
  }
}

TEST(MeshClosedSurface, NestedCavityStaysEmpty) {
  const SurfaceMesh s = generate_surface("nested", 3000);
  const auto shell = vertex_components(s.points.size(), s.triangles);
  ASSERT_EQ(*std::max_element(shell.begin(), shell.end()), 2);  // outer 0, cavity 1, island 2
  const LocalTetMesh m = mesh_closed_surface(s.points, s.triangles, in_process());
  // Total volume = outer - cavity + island (enclosed_volume counts the cavity negative).
  expect_fills_surface(s, m);
  // Tets touch shells (0, 1) between outer shell and cavity, or only shell 2 in the island;
  // a tet joining the island to another shell would lie in the cavity or cross it.
  const auto points = all_points(s.points, m);
  std::size_t island_tets = 0;
  double island_volume = 0;
  for (const auto& t : m.tets) {
    std::set<int> shells;
    for (auto v : t)
      if (v < static_cast<std::int32_t>(s.points.size())) shells.insert(shell[v]);
    if (shells.count(2)) {
      EXPECT_EQ(shells.size(), 1u) << "a tet joins the island to another shell";
      ++island_tets;
      island_volume += tet_volume(points[t[0]], points[t[1]], points[t[2]], points[t[3]]);
    }
    EXPECT_FALSE(shells.empty()) << "a tet of Steiner points only";
  }
  EXPECT_GT(island_tets, 0u);
  std::vector<Triangle> island_tris;
  for (const auto& t : s.triangles)
    if (shell[t[0]] == 2) island_tris.push_back(t);
  const double expected_island = enclosed_volume(SurfaceMesh{s.points, island_tris});
  EXPECT_NEAR(island_volume, expected_island, 1e-9);
  // No tet centroid inside the cavity gap (radius between the island's 0.3 and the cavity's
  // inscribed polyhedron, ~0.57 and more).
  for (const auto& t : m.tets) {
    Point3 c{0, 0, 0};
    for (auto v : t)
      for (int i = 0; i < 3; ++i) c[i] += points[v][i] / 4;
    const double r = norm(c);
    EXPECT_FALSE(r > 0.301 && r < 0.55) << "tet in the cavity at radius " << r;
  }
}

TEST(MeshClosedSurface, TwoSpheresBothFilled) {
  const SurfaceMesh s = generate_surface("two_spheres", 2000);
  const auto shell = vertex_components(s.points.size(), s.triangles);
  const LocalTetMesh m = mesh_closed_surface(s.points, s.triangles, in_process());
  expect_fills_surface(s, m);
  const auto points = all_points(s.points, m);
  double volume[2] = {0, 0};
  for (const auto& t : m.tets) {
    std::set<int> shells;
    for (auto v : t)
      if (v < static_cast<std::int32_t>(s.points.size())) shells.insert(shell[v]);
    ASSERT_EQ(shells.size(), 1u) << "a tet spans the gap between the spheres";
    volume[*shells.begin()] += tet_volume(points[t[0]], points[t[1]], points[t[2]], points[t[3]]);
  }
  const double each = enclosed_volume(s) / 2;
  EXPECT_NEAR(volume[0], each, 1e-9);
  EXPECT_NEAR(volume[1], each, 1e-9);
}

TEST(MeshClosedSurface, QualityAddsSteinerPointsAndKeepsTheBoundary) {
  const SurfaceMesh s = generate_surface("sphere", 800);
  const LocalTetMesh plain = mesh_closed_surface(s.points, s.triangles, in_process());
  TetgenOptions options;
  options.quality = "1.5";
  const LocalTetMesh m = mesh_closed_surface(s.points, s.triangles, options);
  expect_fills_surface(s, m);
  EXPECT_GT(m.steiner_points.size(), plain.steiner_points.size());
  EXPECT_GT(m.tets.size(), plain.tets.size());
  // Steiner points are strictly inside the unit sphere (no boundary Steiner points with -Y).
  for (const auto& q : m.steiner_points) EXPECT_LT(norm(q), 1.0);
}

// With points allowed on the surface (TetGen -p without -Y) and a quality bound that coarse
// triangles cannot meet, TetGen splits input triangles: the result passes the check that allows
// split faces (parts tile the triangles they split, facing the same way), fails the exact one,
// keeps the cavity of a nested surface empty, and a surface point moved off its triangle is found.
TEST(MeshClosedSurface, PointsOnTheSurfaceSplitTrianglesWhenAllowed) {
  for (const char* name : {"torus", "nested"}) {
    SCOPED_TRACE(name);
    const SurfaceMesh s = generate_surface(name, std::string(name) == "torus" ? 320 : 1200);
    TetgenOptions options;
    options.quality = "1.2";
    options.boundary_points = true;
    const LocalTetMesh m = mesh_closed_surface(s.points, s.triangles, options);
    TetMesh mesh{all_points(s.points, m), m.tets, m.neighbours, {}};
    const CheckReport split = check_mesh(s, mesh, BoundaryRule::split_allowed);
    EXPECT_TRUE(split.ok()) << (split.ok() ? "" : split.violations.front());
    EXPECT_GT(split.split_input_faces, 0);
    EXPECT_GT(split.boundary_faces, static_cast<std::int64_t>(s.triangles.size()));
    const CheckReport exact = check_mesh(s, mesh);
    ASSERT_FALSE(exact.ok());
    EXPECT_TRUE(contains(exact.violations.front(), "input triangles are not boundary faces"));
    // A point TetGen put on the surface, moved outwards off it.
    std::int32_t on_surface = -1;
    for (std::size_t t = 0; t < mesh.tets.size() && on_surface < 0; ++t)
      for (int j = 0; j < 4; ++j)
        if (mesh.neighbours[t][j] < 0)
          for (std::int32_t v : outward_face(mesh.tets[t], j))
            if (v >= static_cast<std::int32_t>(s.points.size())) on_surface = v;
    ASSERT_GE(on_surface, 0);
    for (double& c : mesh.points[on_surface]) c *= 1.001;
    const CheckReport moved = check_mesh(s, mesh, BoundaryRule::split_allowed);
    EXPECT_TRUE(std::any_of(moved.violations.begin(), moved.violations.end(),
                            [](const std::string& v) { return v.find("neither input triangles nor parts") != v.npos; }));
  }
}

TEST(MeshClosedSurface, SingleTetrahedron) {
  SurfaceMesh s;
  s.points = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  s.triangles = {{1, 2, 3}, {0, 3, 2}, {0, 1, 3}, {0, 2, 1}};
  const LocalTetMesh m = mesh_closed_surface(s.points, s.triangles, in_process());
  ASSERT_EQ(m.tets.size(), 1u);
  EXPECT_TRUE(m.steiner_points.empty());
  EXPECT_EQ(m.neighbours[0], (Tet{-1, -1, -1, -1}));
  expect_fills_surface(s, m);
}

SurfaceMesh open_sphere() {
  SurfaceMesh s = generate_surface("sphere", 500);
  s.triangles.erase(s.triangles.begin() + 17);
  return s;
}

TEST(MeshClosedSurface, OpenSurfaceThrows) {
  const SurfaceMesh s = open_sphere();
  try {
    mesh_closed_surface(s.points, s.triangles, in_process(), 5);
    ADD_FAILURE() << "open surface accepted";
  } catch (const MeshingError& e) {
    EXPECT_EQ(e.failure.piece, 5);
    EXPECT_EQ(e.failure.kind, FailureKind::tetgen_error);
    EXPECT_NE(std::string(e.what()).find("piece 5"), std::string::npos) << e.what();
  }
}

TEST(MeshClosedSurface, InsideOutThrows) {
  SurfaceMesh s = generate_surface("sphere", 500);
  for (auto& t : s.triangles) std::swap(t[1], t[2]);
  EXPECT_THROW(mesh_closed_surface(s.points, s.triangles, in_process()), MeshingError);
}

TEST(MeshClosedSurface, DuplicateTriangleThrows) {
  SurfaceMesh s = generate_surface("sphere", 200);
  s.triangles.push_back(s.triangles[3]);
  EXPECT_THROW(mesh_closed_surface(s.points, s.triangles, in_process()), MeshingError);
}

TEST(MeshClosedSurface, EmptySurfaceThrows) {
  EXPECT_THROW(mesh_closed_surface({}, {}, in_process()), MeshingError);
  EXPECT_THROW(mesh_closed_surface({{0, 0, 0}}, {}, in_process()), MeshingError);
}

TEST(TetrahedralizePiece, PiecesOfATorus) {
  const SurfaceMesh s = generate_surface("torus", 2000);
  const auto planes = choose_cut_planes(s, 3);
  SplitSurface split = split_at_planes(s, planes);
  const auto caps = build_caps(split, planes, 1.0);
  const auto pieces = assemble_pieces(split, caps);
  double volume = 0;
  for (const auto& piece : pieces) {
    SCOPED_TRACE("piece " + std::to_string(piece.index));
    const PieceTetMesh r = tetrahedralize_piece(piece, in_process());
    EXPECT_EQ(r.index, piece.index);
    EXPECT_EQ(r.surface_point_count, static_cast<std::int32_t>(piece.points.size()));
    const SurfaceMesh surface{piece.points, piece.triangles};
    expect_fills_surface(surface, r.mesh);
    volume += total_tet_volume(all_points(piece.points, r.mesh), r.mesh.tets);
  }
  EXPECT_NEAR(volume, enclosed_volume(s), 1e-9 * enclosed_volume(s));
}

TEST(TetrahedralizePiece, RejectsOpenAndSelfIntersectingPieces) {
  PieceSurface open;
  open.index = 3;
  const SurfaceMesh s = open_sphere();
  open.points = s.points;
  open.triangles = s.triangles;
  for (std::size_t i = 0; i < s.points.size(); ++i) open.global_ids.push_back(static_cast<std::int32_t>(i));
  try {
    tetrahedralize_piece(open, in_process());
    ADD_FAILURE() << "open piece accepted";
  } catch (const MeshingError& e) {
    EXPECT_EQ(e.failure.kind, FailureKind::bad_surface);
    EXPECT_EQ(e.failure.piece, 3);
  }

  // Two overlapping tetrahedra: closed and oriented, but self-intersecting.
  PieceSurface two;
  two.index = 4;
  two.points = {{0, 0, 0},       {2, 0, 0},       {0, 2, 0},       {0, 0, 2},
                {0.3, 0.3, 0.3}, {2.3, 0.3, 0.3}, {0.3, 2.3, 0.3}, {0.3, 0.3, 2.3}};
  two.global_ids = {0, 1, 2, 3, 4, 5, 6, 7};
  for (int base : {0, 4})
    for (const Triangle& t : {Triangle{1, 2, 3}, Triangle{0, 3, 2}, Triangle{0, 1, 3}, Triangle{0, 2, 1}})
      two.triangles.push_back({t[0] + base, t[1] + base, t[2] + base});
  try {
    tetrahedralize_piece(two, in_process());
    ADD_FAILURE() << "self-intersecting piece accepted";
  } catch (const MeshingError& e) {
    EXPECT_EQ(e.failure.kind, FailureKind::self_intersection);
    EXPECT_NE(std::string(e.what()).find("piece 4"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace partet

// check_mesh and mesh_quality on small hand-built meshes: a valid cube must pass and each kind
// of damage must be reported.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <string>
#include <vector>

#include "stages/check.hpp"

namespace partet {
namespace {

double det6(const Point3& a, const Point3& b, const Point3& c, const Point3& d) {
  double u[3], v[3], w[3];
  for (int k = 0; k < 3; ++k) {
    u[k] = b[k] - a[k];
    v[k] = c[k] - a[k];
    w[k] = d[k] - a[k];
  }
  return u[0] * (v[1] * w[2] - v[2] * w[1]) - u[1] * (v[0] * w[2] - v[2] * w[0]) + u[2] * (v[0] * w[1] - v[1] * w[0]);
}

// Unit cube corners: index = x + 2y + 4z.
std::vector<Point3> cube_points() {
  std::vector<Point3> p;
  for (int i = 0; i < 8; ++i) p.push_back({double(i & 1), double((i >> 1) & 1), double((i >> 2) & 1)});
  return p;
}

// The 12 outward triangles, each square split along the diagonal from its smallest to its
// largest corner index (the diagonal the Kuhn split below uses).
SurfaceMesh cube_surface() {
  SurfaceMesh s;
  s.points = cube_points();
  auto quad = [&](int a, int b, int c, int d) {
    s.triangles.push_back({a, b, c});
    s.triangles.push_back({a, c, d});
  };
  quad(0, 2, 3, 1);  // z = 0
  quad(4, 5, 7, 6);  // z = 1
  quad(0, 1, 5, 4);  // y = 0
  quad(2, 6, 7, 3);  // y = 1
  quad(0, 4, 6, 2);  // x = 0
  quad(1, 3, 7, 5);  // x = 1
  return s;
}

// Kuhn split of the cube cell with corners base + {0..7} (same index scheme): six tets along
// the 0-7 diagonal, each made positive. Conforming across translated cells.
void add_kuhn_cell(std::vector<Tet>& tets, const std::vector<Point3>& points,
                   const std::array<std::int32_t, 8>& corner) {
  int axes[3] = {1, 2, 4};
  std::sort(axes, axes + 3);
  do {
    Tet t{corner[0], corner[axes[0]], corner[axes[0] + axes[1]], corner[7]};
    if (det6(points[t[0]], points[t[1]], points[t[2]], points[t[3]]) < 0) std::swap(t[2], t[3]);
    tets.push_back(t);
  } while (std::next_permutation(axes, axes + 3));
}

TetMesh cube_mesh() {
  TetMesh m;
  m.points = cube_points();
  add_kuhn_cell(m.tets, m.points, {0, 1, 2, 3, 4, 5, 6, 7});
  return m;
}

bool has_violation(const CheckReport& r, const std::string& fragment) {
  return std::any_of(r.violations.begin(), r.violations.end(),
                     [&](const std::string& v) { return v.find(fragment) != std::string::npos; });
}

std::string all_violations(const CheckReport& r) {
  std::string s;
  for (const auto& v : r.violations) s += v + "\n";
  return s;
}

// An n x n x n grid of unit cells, Kuhn split; cells for which skip(i,j,k) is true are left out.
template <class Skip>
TetMesh grid_mesh(int n, Skip skip) {
  TetMesh m;
  auto id = [&](int i, int j, int k) { return std::int32_t(i + (n + 1) * (j + (n + 1) * k)); };
  for (int k = 0; k <= n; ++k)
    for (int j = 0; j <= n; ++j)
      for (int i = 0; i <= n; ++i) m.points.push_back({double(i), double(j), double(k)});
  for (int k = 0; k < n; ++k)
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i) {
        if (skip(i, j, k)) continue;
        std::array<std::int32_t, 8> c;
        for (int b = 0; b < 8; ++b) c[b] = id(i + (b & 1), j + ((b >> 1) & 1), k + ((b >> 2) & 1));
        add_kuhn_cell(m.tets, m.points, c);
      }
  return m;
}

// Faces in exactly one tet, oriented out of it, as a surface sharing the mesh's points.
SurfaceMesh boundary_of(const TetMesh& m) {
  std::map<std::array<std::int32_t, 3>, std::vector<Triangle>> faces;
  for (const Tet& t : m.tets)
    for (int j = 0; j < 4; ++j) {
      Triangle f = outward_face(t, j);
      std::array<std::int32_t, 3> key = f;
      std::sort(key.begin(), key.end());
      faces[key].push_back(f);
    }
  SurfaceMesh s;
  s.points = m.points;
  for (auto& [key, list] : faces)
    if (list.size() == 1) s.triangles.push_back(list[0]);
  return s;
}

TEST(CheckMesh, CubeSurfaceIsOutward) {
  SurfaceMesh s = cube_surface();
  for (const Triangle& t : s.triangles) {
    // Outward: the centre is behind every triangle, so (centre, a, b, c) is positive, just as
    // a positive tet's first vertex is behind its outward face (1, 2, 3).
    EXPECT_GT(det6({0.5, 0.5, 0.5}, s.points[t[0]], s.points[t[1]], s.points[t[2]]), 0);
  }
}

TEST(CheckMesh, ValidCubePasses) {
  CheckReport r = check_mesh(cube_surface(), cube_mesh());
  EXPECT_TRUE(r.ok()) << all_violations(r);
  EXPECT_EQ(r.vertices, 8);
  EXPECT_EQ(r.tets, 6);
  EXPECT_EQ(r.boundary_faces, 12);
  EXPECT_NEAR(r.tet_volume, 1.0, 1e-15);
  EXPECT_NEAR(r.surface_volume, 1.0, 1e-15);
  EXPECT_EQ(r.euler_mesh, 1);
  EXPECT_EQ(r.euler_expected, 1);
  EXPECT_GT(r.quality.amips_avg, 3.0);
}

TEST(CheckMesh, InvertedTet) {
  TetMesh m = cube_mesh();
  std::swap(m.tets[2][0], m.tets[2][1]);
  CheckReport r = check_mesh(cube_surface(), m);
  EXPECT_TRUE(has_violation(r, "1 tets are not positively oriented (1 inverted, 0 flat), first: tet 2"))
      << all_violations(r);
}

TEST(CheckMesh, FlatTet) {
  TetMesh m = cube_mesh();
  m.points.push_back({0.5, 0.5, 0});
  m.tets.push_back({0, 1, 2, 8});  // four points in the plane z = 0
  CheckReport r = check_mesh(cube_surface(), m);
  EXPECT_TRUE(has_violation(r, "(0 inverted, 1 flat), first: tet 6")) << all_violations(r);
}

TEST(CheckMesh, MissingTet) {
  TetMesh m = cube_mesh();
  m.tets.pop_back();
  CheckReport r = check_mesh(cube_surface(), m);
  EXPECT_TRUE(has_violation(r, "differs from the volume enclosed")) << all_violations(r);
  EXPECT_TRUE(has_violation(r, "input triangles are not boundary faces")) << all_violations(r);
  EXPECT_TRUE(has_violation(r, "boundary faces of the mesh are not input triangles")) << all_violations(r);
}

TEST(CheckMesh, DuplicatedTet) {
  TetMesh m = cube_mesh();
  m.tets.push_back(m.tets[0]);
  CheckReport r = check_mesh(cube_surface(), m);
  EXPECT_TRUE(has_violation(r, "triangles are in more than two tets")) << all_violations(r);
}

TEST(CheckMesh, OverlappingTets) {
  // A second tet on tet 0's boundary face (1,3,7) with its apex inside the cube, i.e. on the
  // same side as tet 0: the face is then in two tets that overlap.
  TetMesh m = cube_mesh();
  ASSERT_EQ(m.tets[0], (Tet{0, 1, 3, 7}));
  m.points.push_back({0.9, 0.1, 0.1});
  Tet t{1, 3, 7, 8};
  if (det6(m.points[t[0]], m.points[t[1]], m.points[t[2]], m.points[t[3]]) < 0) std::swap(t[2], t[3]);
  m.tets.push_back(t);
  CheckReport r = check_mesh(cube_surface(), m);
  EXPECT_TRUE(has_violation(r, "1 triangles have both their tets on the same side (overlap)")) << all_violations(r);
}

TEST(CheckMesh, UnusedVertex) {
  TetMesh m = cube_mesh();
  m.points.push_back({5, 5, 5});
  CheckReport r = check_mesh(cube_surface(), m);
  EXPECT_TRUE(has_violation(r, "1 vertices are in no tet, first: vertex 8")) << all_violations(r);
  EXPECT_EQ(r.violations.size(), 1u) << all_violations(r);
}

TEST(CheckMesh, DuplicateVertex) {
  TetMesh m = cube_mesh();
  m.points.push_back({-0.0, 0, 0});  // -0 is the same coordinate as +0
  // Let one tet use the copy, so it is a duplicate and not merely unused.
  for (std::int32_t& v : m.tets[0])
    if (v == 0) v = 8;
  CheckReport r = check_mesh(cube_surface(), m);
  EXPECT_TRUE(has_violation(r, "1 duplicate vertices (identical coordinates), first: vertices 0 and 8"))
      << all_violations(r);
}

TEST(CheckMesh, MovedInputVertex) {
  TetMesh m = cube_mesh();
  m.points[7][2] = std::nextafter(1.0, 2.0);
  CheckReport r = check_mesh(cube_surface(), m);
  EXPECT_TRUE(has_violation(r, "input vertex 7 is missing from the mesh (coordinates changed?)")) << all_violations(r);
}

TEST(CheckMesh, ReversedInputIsWronglyOriented) {
  SurfaceMesh s = cube_surface();
  for (Triangle& t : s.triangles) std::swap(t[1], t[2]);
  CheckReport r = check_mesh(s, cube_mesh());
  EXPECT_TRUE(has_violation(r, "12 input triangles are boundary faces with the wrong orientation"))
      << all_violations(r);
  EXPECT_TRUE(has_violation(r, "differs from the volume enclosed")) << all_violations(r);
}

TEST(CheckMesh, IndexOutOfRange) {
  TetMesh m = cube_mesh();
  m.tets[1][3] = 42;
  CheckReport r = check_mesh(cube_surface(), m);
  ASSERT_EQ(r.violations.size(), 1u);
  EXPECT_TRUE(has_violation(r, "out of range, first: tet 1"));
}

TEST(CheckMesh, GridPasses) {
  TetMesh m = grid_mesh(3, [](int, int, int) { return false; });
  CheckReport r = check_mesh(boundary_of(m), m);
  EXPECT_TRUE(r.ok()) << all_violations(r);
  EXPECT_EQ(r.tets, 27 * 6);
  EXPECT_NEAR(r.tet_volume, 27.0, 1e-12);
  EXPECT_EQ(r.euler_mesh, 1);
}

// A cube [0,3]^3 with the cavity [1,2]^3: the input is the outer surface plus the inner cube's
// surface facing into the void.
SurfaceMesh cube_with_cavity_surface() {
  TetMesh solid = grid_mesh(3, [](int, int, int) { return false; });
  TetMesh centre = grid_mesh(3, [](int i, int j, int k) { return !(i == 1 && j == 1 && k == 1); });
  SurfaceMesh outer = boundary_of(solid), inner = boundary_of(centre);
  for (Triangle t : inner.triangles) outer.triangles.push_back({t[0], t[2], t[1]});
  return outer;
}

TEST(CheckMesh, CavityPasses) {
  TetMesh m = grid_mesh(3, [](int i, int j, int k) { return i == 1 && j == 1 && k == 1; });
  CheckReport r = check_mesh(cube_with_cavity_surface(), m);
  EXPECT_TRUE(r.ok()) << all_violations(r);
  EXPECT_NEAR(r.surface_volume, 26.0, 1e-12);
  EXPECT_EQ(r.euler_mesh, 2);  // a sphere's worth: outer and inner sphere boundaries
  EXPECT_EQ(r.euler_expected, 2);
}

TEST(CheckMesh, FilledCavityFails) {
  TetMesh m = grid_mesh(3, [](int, int, int) { return false; });
  CheckReport r = check_mesh(cube_with_cavity_surface(), m);
  EXPECT_TRUE(has_violation(r, "tet volume 27 differs from the volume enclosed by the input")) << all_violations(r);
  EXPECT_TRUE(has_violation(r, "input triangles are not boundary faces")) << all_violations(r);
}

// Regular tet with unit edges, positively oriented.
std::array<Point3, 4> regular_tet() {
  return {Point3{0, 0, 0}, Point3{1, 0, 0}, Point3{0.5, std::sqrt(3.0) / 2, 0},
          Point3{0.5, std::sqrt(3.0) / 6, std::sqrt(2.0 / 3.0)}};
}

TEST(Quality, AmipsRegularTetIsThree) {
  auto p = regular_tet();
  EXPECT_NEAR(amips_energy(p[0], p[1], p[2], p[3]), 3.0, 1e-12);
}

TEST(Quality, AmipsIsScaleAndTranslationInvariant) {
  auto p = regular_tet();
  p[3][2] *= 0.3;  // not regular, so invariance is not trivially 3 = 3
  double e = amips_energy(p[0], p[1], p[2], p[3]);
  EXPECT_GT(e, 3.0);
  auto q = p;
  for (auto& x : q)
    for (int k = 0; k < 3; ++k) x[k] = 1000 * x[k] + 17;
  EXPECT_NEAR(amips_energy(q[0], q[1], q[2], q[3]), e, 1e-9 * e);
  for (auto& x : q)
    for (int k = 0; k < 3; ++k) x[k] = 1e-4 * x[k];
  EXPECT_NEAR(amips_energy(q[0], q[1], q[2], q[3]), e, 1e-9 * e);
}

TEST(Quality, AmipsGrowsAsTetFlattens) {
  auto p = regular_tet();
  double previous = 3.0;
  for (double squash : {0.5, 0.1, 0.01}) {
    auto q = p;
    q[3][2] *= squash;
    double e = amips_energy(q[0], q[1], q[2], q[3]);
    EXPECT_GT(e, previous);
    previous = e;
  }
  p[3][2] = 0;
  EXPECT_TRUE(std::isinf(amips_energy(p[0], p[1], p[2], p[3])));
  std::swap(p[0], p[1]);
  EXPECT_TRUE(std::isinf(amips_energy(p[0], p[1], p[2], p[3])));
}

TEST(Quality, RegularTetDihedralAngles) {
  auto p = regular_tet();
  TetMesh m;
  m.points.assign(p.begin(), p.end());
  m.tets.push_back({0, 1, 2, 3});
  MeshQuality q = mesh_quality(m);
  double expected = std::acos(1.0 / 3.0) * 180 / 3.14159265358979323846;  // 70.5288 deg
  EXPECT_NEAR(expected, 70.5288, 1e-4);
  EXPECT_NEAR(q.min_dihedral_deg, expected, 1e-9);
  EXPECT_NEAR(q.max_dihedral_deg, expected, 1e-9);
  EXPECT_NEAR(q.amips_avg, 3.0, 1e-12);
  EXPECT_NEAR(q.amips_max, 3.0, 1e-12);
  EXPECT_EQ(q.below_5deg, 0);
  EXPECT_EQ(q.above_175deg, 0);
}

TEST(Quality, CubeDihedralAngles) {
  MeshQuality q = mesh_quality(cube_mesh());
  // Kuhn tets have dihedral angles of 45, 60 and 90 degrees.
  EXPECT_NEAR(q.min_dihedral_deg, 45, 1e-9);
  EXPECT_NEAR(q.max_dihedral_deg, 90, 1e-9);
}

TEST(Quality, SliverIsCounted) {
  // A sliver: four nearly coplanar points forming a square, which has angles near 0 and 180.
  TetMesh m;
  m.points = {{0, 0, 0}, {1, 1, 0}, {1, 0, 0.01}, {0, 1, 0.01}};
  if (det6(m.points[0], m.points[1], m.points[2], m.points[3]) < 0) std::swap(m.points[2], m.points[3]);
  m.tets.push_back({0, 1, 2, 3});
  MeshQuality q = mesh_quality(m);
  EXPECT_EQ(q.below_5deg, 1);
  EXPECT_EQ(q.above_175deg, 1);
  EXPECT_LT(q.min_dihedral_deg, 5);
  EXPECT_GT(q.max_dihedral_deg, 175);
}

}  // namespace
}  // namespace partet

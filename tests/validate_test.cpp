#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <functional>
#include <string>
#include <utility>

#include "partet/errors.hpp"
#include "stages/generate.hpp"
#include "io/read_surface.hpp"
#include "stages/validate.hpp"
#include "test_support.hpp"
#include "stage_batches.hpp"

namespace partet {
namespace {

using test::contains;
using test::input_error;

// A tetrahedron with outward faces, its first corner at `origin`.
SurfaceMesh tetrahedron(const Point3& origin = {0, 0, 0}, double size = 1) {
  SurfaceMesh tet;
  tet.points = {origin,
                {origin[0] + size, origin[1], origin[2]},
                {origin[0], origin[1] + size, origin[2]},
                {origin[0], origin[1], origin[2] + size}};
  tet.triangles = {{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 3}};
  return tet;
}

SurfaceMesh unit_cube(const Point3& origin = {0, 0, 0}) {
  SurfaceMesh cube;
  for (int i = 0; i < 8; ++i)
    cube.points.push_back({origin[0] + (i & 1), origin[1] + ((i >> 1) & 1), origin[2] + (i >> 2)});
  cube.triangles = {{0, 2, 3}, {0, 3, 1}, {4, 5, 7}, {4, 7, 6}, {0, 1, 5}, {0, 5, 4},
                    {2, 6, 7}, {2, 7, 3}, {0, 4, 6}, {0, 6, 2}, {1, 3, 7}, {1, 7, 5}};
  return cube;
}

// Both surfaces in one soup, b's indices shifted behind a's.
SurfaceMesh combined(SurfaceMesh a, const SurfaceMesh& b) {
  const auto base = static_cast<std::int32_t>(a.points.size());
  a.points.insert(a.points.end(), b.points.begin(), b.points.end());
  for (const Triangle& t : b.triangles) a.triangles.push_back({t[0] + base, t[1] + base, t[2] + base});
  return a;
}

TEST(Validate, AcceptsClosedSurfaces) {
  EXPECT_NO_THROW(validate_surface(tetrahedron()));
  EXPECT_NO_THROW(validate_surface(unit_cube()));
  EXPECT_NO_THROW(validate_surface(generate_surface("sphere", 5000)));
  EXPECT_NO_THROW(validate_surface(combined(unit_cube(), unit_cube({2, 0, 0}))));
}

TEST(Validate, UnreferencedVerticesAreAllowed) {
  SurfaceMesh cube = unit_cube();
  cube.points.push_back({0.5, 0.5, 0.5});
  cube.points.push_back({0, 0, 0});  // even at the position of a used vertex
  EXPECT_NO_THROW(validate_surface(cube));
}

TEST(Validate, EmptySurface) {
  EXPECT_TRUE(contains(input_error([] { validate_topology(SurfaceMesh{}); }), "input is empty"));
}

TEST(Validate, IndexOutOfRange) {
  SurfaceMesh tet = tetrahedron();
  tet.triangles[2][1] = 9;
  EXPECT_TRUE(contains(input_error([&] { validate_topology(tet); }),
                       "face 2 refers to vertex 9, but there are only 4 vertices"));
}

TEST(Validate, OpenSurface) {
  SurfaceMesh sphere = generate_surface("sphere", 1000);
  const Triangle removed = sphere.triangles[7];
  sphere.triangles.erase(sphere.triangles.begin() + 7);
  std::string message = input_error([&] { validate_surface(sphere); });
  EXPECT_TRUE(contains(message, "input is not closed: 3 border edges, first at vertex "));
  const std::string vertex = message.substr(message.rfind(' ') + 1);
  EXPECT_TRUE(vertex == std::to_string(removed[0]) || vertex == std::to_string(removed[1]) ||
              vertex == std::to_string(removed[2]))
      << message;
}

TEST(Validate, FlippedFace) {
  SurfaceMesh sphere = generate_surface("sphere", 1000);
  std::swap(sphere.triangles[42][1], sphere.triangles[42][2]);
  std::string message = input_error([&] { validate_surface(sphere); });
  EXPECT_TRUE(contains(message, "input is not consistently oriented: faces "));
  EXPECT_TRUE(contains(message, "(3 such edges)"));
  EXPECT_TRUE(contains(message, " 42 ")) << "the flipped face is named";
}

// The edges are gathered a range of vertices at a time (to bound the memory): the faces across
// the edges and the first problem named must not depend on the range.
TEST(Validate, FacesAcrossEdgesDoNotDependOnTheRange) {
  const SurfaceMesh surface = generate_surface("genus3", 4000);
  const std::vector<std::int32_t> across = faces_across_edges(surface, "input");
  ASSERT_EQ(across.size(), 3 * surface.triangles.size());
  for (std::size_t corner = 0; corner < across.size(); ++corner) {
    const Triangle& t = surface.triangles[corner / 3];
    const std::int32_t a = t[corner % 3], b = t[(corner % 3 + 1) % 3];
    ASSERT_GE(across[corner], 0);
    const Triangle& g = surface.triangles[static_cast<std::size_t>(across[corner])];
    ASSERT_NE(static_cast<std::size_t>(across[corner]), corner / 3);
    ASSERT_TRUE(std::count(g.begin(), g.end(), a) == 1 && std::count(g.begin(), g.end(), b) == 1) << corner;
  }
  for (std::size_t range : {std::size_t(1), std::size_t(5), std::size_t(64), std::size_t(1000)})
    EXPECT_TRUE(faces_across_edges(surface, "input", range) == across) << range << " corners per range";

  SurfaceMesh open = surface, flipped = surface, crowded = surface;
  open.triangles.erase(open.triangles.begin() + 1234);
  std::swap(flipped.triangles[777][1], flipped.triangles[777][2]);
  std::swap(flipped.triangles[3001][0], flipped.triangles[3001][2]);
  crowded.triangles.push_back(crowded.triangles[10]);
  crowded.triangles.push_back({crowded.triangles[10][0], crowded.triangles[10][2], crowded.triangles[10][1]});
  for (const SurfaceMesh* broken : {&open, &flipped, &crowded}) {
    const std::string expected = input_error([&] { faces_across_edges(*broken, "input"); });
    ASSERT_FALSE(expected.empty());
    for (std::size_t range : {std::size_t(1), std::size_t(7), std::size_t(500)})
      EXPECT_EQ(input_error([&] { faces_across_edges(*broken, "input", range); }), expected) << range;
  }
}

TEST(Validate, EdgeSharedByFourFaces) {
  // Two tetrahedra hinged on the edge between vertices 0 and 1.
  SurfaceMesh hinged = tetrahedron();
  hinged.points.push_back({0, -1, 0});
  hinged.points.push_back({0, 0, -1});
  // Corners 0, 1, 4, 5 form a tetrahedron mirrored through y and z; keep it outward.
  for (Triangle t : tetrahedron().triangles) {
    for (std::int32_t& v : t) v = v == 2 ? 4 : v == 3 ? 5 : v;
    hinged.triangles.push_back({t[0], t[2], t[1]});
  }
  std::string message = input_error([&] { validate_topology(hinged); });
  EXPECT_TRUE(contains(message,
                       "input is not manifold: 1 edge shared by more than two faces, first "
                       "between vertices 0 and 1"));
}

// Two apexes over a ring of n vertices: each apex has n faces around it, far more than the few
// a vertex usually has (the edges are found per vertex).
SurfaceMesh double_cone(int n) {
  SurfaceMesh cone;
  const double pi = std::acos(-1.0);
  for (int i = 0; i < n; ++i) cone.points.push_back({std::cos(2 * pi * i / n), std::sin(2 * pi * i / n), 0});
  cone.points.push_back({0, 0, 1});
  cone.points.push_back({0, 0, -1});
  for (int i = 0; i < n; ++i) {
    cone.triangles.push_back({i, (i + 1) % n, n});
    cone.triangles.push_back({(i + 1) % n, i, n + 1});
  }
  return cone;
}

TEST(Validate, VerticesWithManyFaces) {
  SurfaceMesh cone = double_cone(200000);
  EXPECT_NO_THROW(validate_topology(cone));
  // The apex numbered first and last: the same verdicts whatever the numbering.
  std::swap(cone.points.front(), cone.points[200000]);
  for (Triangle& t : cone.triangles)
    for (std::int32_t& v : t) v = v == 0 ? 200000 : v == 200000 ? 0 : v;
  EXPECT_NO_THROW(validate_topology(cone));
  std::swap(cone.triangles[7][1], cone.triangles[7][2]);
  const std::string message = input_error([&] { validate_topology(cone); });
  EXPECT_TRUE(contains(message, "input is not consistently oriented: faces ")) << message;
  EXPECT_TRUE(contains(message, "(3 such edges)")) << message;
}

TEST(Validate, NonManifoldVertex) {
  // Two tetrahedra touching at one vertex, which is shared by index.
  SurfaceMesh touching = tetrahedron();
  touching.points.push_back({-1, 0, 0});
  touching.points.push_back({0, -1, 0});
  touching.points.push_back({0, 0, -1});
  touching.triangles.push_back({0, 4, 5});  // the mirror image, with reversed faces
  touching.triangles.push_back({0, 6, 4});
  touching.triangles.push_back({0, 5, 6});
  touching.triangles.push_back({4, 6, 5});
  EXPECT_NO_THROW(check_no_self_intersections(touching));
  EXPECT_TRUE(contains(input_error([&] { validate_topology(touching); }),
                       "input is not manifold: vertex 0 joins 2 separate fans of faces"));
}

TEST(Validate, DuplicateVertices) {
  // The same touching tetrahedra, but with the shared corner stored twice.
  SurfaceMesh mirrored = tetrahedron();
  for (Point3& p : mirrored.points)
    for (double& c : p) c = -c;
  for (Triangle& t : mirrored.triangles) std::swap(t[1], t[2]);
  SurfaceMesh touching = combined(tetrahedron(), mirrored);
  EXPECT_TRUE(contains(input_error([&] { validate_topology(touching); }),
                       "input has duplicate vertices: vertices 0 and 4 are both at (0, 0, 0)"));
}

TEST(Validate, RepeatedVertexInFace) {
  SurfaceMesh tet = tetrahedron();
  tet.triangles[3] = {1, 2, 1};
  EXPECT_TRUE(
      contains(input_error([&] { validate_topology(tet); }), "input has a degenerate face: face 3 repeats vertex 1"));
}

TEST(Validate, CollinearFace) {
  SurfaceMesh tet = tetrahedron();
  tet.points[3] = {0.5, 0.5, 0};  // on the segment between vertices 1 and 2
  EXPECT_TRUE(contains(input_error([&] { validate_topology(tet); }),
                       "input has a degenerate face: face 3 has collinear corners"));
  // Exact: a tiny offset is not collinear.
  tet.points[3] = {0.5, std::nextafter(0.5, 1.0), 0};
  EXPECT_NO_THROW(validate_topology(tet));
}

TEST(Validate, OverlappingSpheresSelfIntersect) {
  SurfaceMesh a = generate_surface("sphere", 500);
  SurfaceMesh b = a;
  for (Point3& p : b.points) p[0] += 0.5;
  SurfaceMesh both = combined(a, b);
  EXPECT_NO_THROW(validate_topology(both));
  std::string message = input_error([&] { validate_surface(both); });
  EXPECT_TRUE(contains(message, "input self-intersects: faces "));
  EXPECT_TRUE(contains(message, " intersecting pairs)"));
  // The same pair every time, whatever order the boxes are visited in.
  EXPECT_EQ(message, input_error([&] { check_no_self_intersections(both); }));
  EXPECT_TRUE(
      contains(input_error([&] { check_no_self_intersections(both, "piece 3"); }), "piece 3 self-intersects: faces "));
}

TEST(Validate, NestedDisjointShellsDoNotIntersect) {
  SurfaceMesh cube = unit_cube();
  SurfaceMesh inner = unit_cube({0.25, 0.25, 0.25});
  for (Point3& p : inner.points)
    for (int i = 0; i < 3; ++i) p[i] = 0.25 + (p[i] - 0.25) * 0.5;
  EXPECT_NO_THROW(check_no_self_intersections(combined(cube, inner)));
}

TEST(Validate, FoldedAndTouchingFaces) {
  // Two faces on one edge, both far corners on the same side in the same plane: they overlap.
  SurfaceMesh folded;
  folded.points = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {1, 1, 0}};
  folded.triangles = {{0, 1, 2}, {0, 1, 3}};
  EXPECT_TRUE(contains(input_error([&] { check_no_self_intersections(folded); }),
                       "input self-intersects: faces 0 and 1 intersect (1 intersecting pair)"));
  // Sharing one vertex, with the other face passing through.
  SurfaceMesh pierced;
  pierced.points = {{0, 0, 0}, {2, 0, 0}, {0, 2, 0}, {1, 0.5, -1}, {0.5, 1, 1}};
  pierced.triangles = {{0, 1, 2}, {0, 3, 4}};
  EXPECT_TRUE(contains(input_error([&] { check_no_self_intersections(pierced); }), "faces 0 and 1 intersect"));
  // A vertex of one face touching the inside of another face, without sharing an index.
  SurfaceMesh touching;
  touching.points = {{0, 0, 0}, {2, 0, 0}, {0, 2, 0}, {0.5, 0.5, 0}, {0.5, 0.5, 1}, {1, 0, 1}};
  touching.triangles = {{0, 1, 2}, {3, 4, 5}};
  EXPECT_TRUE(contains(input_error([&] { check_no_self_intersections(touching); }), "faces 0 and 1 intersect"));
}

TEST(Validate, InsideOut) {
  SurfaceMesh sphere = generate_surface("sphere", 1000);
  for (Triangle& t : sphere.triangles) std::swap(t[1], t[2]);
  std::string message = input_error([&] { validate_surface(sphere); });
  EXPECT_TRUE(contains(message, "input is inside out: normals point inwards (enclosed volume -"));
  EXPECT_TRUE(contains(message, "< 0); flip the face orientation"));
}

TEST(Validate, EnclosedVolume) {
  EXPECT_DOUBLE_EQ(enclosed_volume(unit_cube()), 1.0);
  EXPECT_DOUBLE_EQ(enclosed_volume(tetrahedron()), 1.0 / 6.0);
  // Far from the origin the terms would cancel without a local origin.
  EXPECT_NEAR(enclosed_volume(unit_cube({1e7, -3e7, 5e6})), 1.0, 1e-9);
  SurfaceMesh cavity = unit_cube({0.25, 0.25, 0.25});
  for (Point3& p : cavity.points)
    for (int i = 0; i < 3; ++i) p[i] = 0.25 + (p[i] - 0.25) * 0.5;
  for (Triangle& t : cavity.triangles) std::swap(t[1], t[2]);
  EXPECT_DOUBLE_EQ(enclosed_volume(combined(unit_cube(), cavity)), 1.0 - 0.125);
}

// The shared set's deliberately broken models (see shared/meshes/MANIFEST.md).
class SharedMeshes : public ::testing::Test {
 protected:
  void SetUp() override {
    if (!std::filesystem::is_directory(dir_ + "/invalid")) GTEST_SKIP() << "no shared meshes at " << dir_;
  }
  std::string dir_ = PARTET_MESHES_DIR;
};

TEST_F(SharedMeshes, SelfIntersectingNeptune) {
  SurfaceMesh surface = read_surface(dir_ + "/invalid/neptune_selfintersecting.off");
  EXPECT_NO_THROW(validate_topology(surface));
  std::string message = input_error([&] { validate_surface(surface); });
  EXPECT_TRUE(contains(message, "input self-intersects: faces "));
  EXPECT_TRUE(contains(message, "(37 intersecting pairs)"));
}

TEST_F(SharedMeshes, OpenBunny) {
  SurfaceMesh surface = read_surface(dir_ + "/invalid/bunny_open.off");
  EXPECT_TRUE(contains(input_error([&] { validate_surface(surface); }),
                       "input is not closed: 223 border edges, first at vertex "));
}

TEST_F(SharedMeshes, CowWithNonManifoldVertex) {
  SurfaceMesh surface = read_surface(dir_ + "/invalid/cow_nonmanifold_vertex.off");
  EXPECT_TRUE(contains(input_error([&] { validate_surface(surface); }), "input is not manifold: vertex "));
  EXPECT_TRUE(contains(input_error([&] { validate_surface(surface); }), " joins 2 separate fans of faces"));
}

TEST_F(SharedMeshes, ValidModelsPass) {
  for (const char* name : {"tiny_torus", "spot_lowres", "three_holes", "two_cubes", "nested_blub_3", "lever"}) {
    SCOPED_TRACE(name);
    SurfaceMesh surface = read_surface(dir_ + "/" + name + ".off");
    EXPECT_NO_THROW(validate_surface(surface));
  }
}

}  // namespace
}  // namespace partet

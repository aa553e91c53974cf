// Thin and degenerate cases for the whole pipeline, on hand-built surfaces: cuts across edges
// nearly parallel to the plane, sub-0.1-degree slivers, triangles crossed by several planes,
// more pieces than the geometry allows. Each result must pass partet's independent check.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "stages/check.hpp"
#include "stages/partition.hpp"
#include "job/pipeline.hpp"
#include "stages/validate.hpp"
#include "stage_batches.hpp"

namespace partet {
namespace {

MeshOptions pieces(int k) {
  MeshOptions options;
  options.pieces = k;
  return options;
}

void expect_valid_mesh(const SurfaceMesh& input, int k) {
  SCOPED_TRACE("k=" + std::to_string(k));
  const MeshResult result = mesh_surface(input, pieces(k));
  const CheckReport report = check_mesh(input, result.mesh);
  std::string violations;
  for (const auto& v : report.violations) violations += v + "\n";
  EXPECT_TRUE(report.ok()) << violations;
}

// An octahedron whose four equatorial vertices sit at x = +-eps: with every gap used, one plane
// passes between them and cuts four edges almost parallel to it.
SurfaceMesh flat_octahedron(double eps) {
  SurfaceMesh s;
  s.points = {{-1, 0, 0}, {1, 0, 0}, {-eps, 1, 0}, {eps, 0, 1}, {-eps, -1, 0}, {eps, 0, -1}};
  // Faces around the axis; orientation fixed below by the enclosed volume.
  const int ring[4] = {2, 3, 4, 5};
  for (int i = 0; i < 4; ++i) {
    const int a = ring[i], b = ring[(i + 1) % 4];
    s.triangles.push_back({1, a, b});
    s.triangles.push_back({0, b, a});
  }
  if (enclosed_volume(s) < 0)
    for (auto& t : s.triangles) std::swap(t[1], t[2]);
  return s;
}

// A 3 x 1 x 1 box whose bottom face has a vertex 1e-4 away from an edge: that face is split into
// three coplanar triangles, one with angles of about 0.005 degrees, which the cuts cross.
SurfaceMesh cube_with_sliver() {
  SurfaceMesh s;
  s.points = {{0, 0, 0}, {3, 0, 0}, {3, 1, 0}, {0, 1, 0}, {0, 0, 1}, {3, 0, 1}, {3, 1, 1}, {0, 1, 1}, {1.11, 1e-4, 0}};
  s.triangles = {{0, 2, 1}, {0, 3, 2}, {4, 5, 6}, {4, 6, 7}, {0, 1, 5}, {0, 5, 4},
                 {1, 2, 6}, {1, 6, 5}, {2, 3, 7}, {2, 7, 6}, {3, 0, 4}, {3, 4, 7}};
  // Split bottom triangle (0, 2, 1), which has the edge 0-1, at point 8 near that edge.
  s.triangles[0] = {0, 2, 8};
  s.triangles.push_back({2, 1, 8});
  s.triangles.push_back({1, 0, 8});
  return s;
}

TEST(DegenerateCases, CutAcrossEdgesNearlyParallelToThePlane) {
  const SurfaceMesh s = flat_octahedron(1e-7);
  ASSERT_NO_THROW(validate_surface(s));
  // Gaps along x: -1 | -eps | +eps | 1. Six vertices, three usable gaps, so four pieces use the
  // 2e-7-wide middle gap.
  const auto planes = choose_cut_planes(s, 4);
  ASSERT_EQ(planes.size(), 3u);
  EXPECT_EQ(planes[1].offset, 0.0);
  for (int k : {2, 3, 4}) expect_valid_mesh(s, k);
}

TEST(DegenerateCases, SliverBelowATenthOfADegree) {
  const SurfaceMesh s = cube_with_sliver();
  ASSERT_NO_THROW(validate_surface(s));
  // The sliver's smallest angle.
  const auto& a = s.points[1];
  const auto& b = s.points[0];
  const auto& p = s.points[8];
  const double angle = std::atan2(p[1], p[0] - b[0]) * 180 / M_PI;
  ASSERT_LT(angle, 0.1);
  (void)a;
  // Along x the vertices sit at 0, 1.11 and 3: the planes cut the sliver.
  EXPECT_EQ(choose_cut_planes(s, 3).size(), 2u);
  for (int k : {2, 3}) expect_valid_mesh(s, k);
}

// A cone: a ring of n vertices in a tilted plane (all at different x) and an apex far along x.
// The planes fall between ring vertices, so each long side triangle is crossed by many planes.
SurfaceMesh long_cone(int n) {
  SurfaceMesh s;
  s.points.push_back({0, 0, 0});   // base centre (on the ring's plane)
  s.points.push_back({10, 0, 0});  // apex
  for (int i = 0; i < n; ++i) {
    const double t = 2 * M_PI * i / n + 0.1;
    s.points.push_back({0.5 * std::cos(t) + 0.01 * std::sin(t), std::sin(t), std::cos(t)});
  }
  for (int i = 0; i < n; ++i) {
    const int a = 2 + i, b = 2 + (i + 1) % n;
    s.triangles.push_back({1, a, b});
    s.triangles.push_back({0, b, a});
  }
  if (enclosed_volume(s) < 0)
    for (auto& t : s.triangles) std::swap(t[1], t[2]);
  return s;
}

TEST(DegenerateCases, TrianglesCutByManyPlanes) {
  const SurfaceMesh s = long_cone(24);
  ASSERT_NO_THROW(validate_surface(s));
  const auto planes = choose_cut_planes(s, 8);
  ASSERT_EQ(planes.size(), 7u);
  const SplitSurface split = split_at_planes(s, planes);
  // Some side triangle (apex + two ring vertices) is crossed by at least four planes.
  std::vector<int> fragments(s.triangles.size(), 0);
  for (auto parent : split.parent) ++fragments[parent];
  EXPECT_GE(*std::max_element(fragments.begin(), fragments.end()), 5);
  for (int k : {2, 4, 8, 16, 25}) expect_valid_mesh(s, k);
}

TEST(DegenerateCases, MorePiecesThanTheGeometryAllows) {
  // 26 vertices: at most 26 pieces; asking for 50 uses every gap, and the result is valid.
  const SurfaceMesh s = long_cone(24);
  expect_valid_mesh(s, 50);
}

}  // namespace
}  // namespace partet

// Element quality figures and the seam zone.
#include "partet/quality.hpp"

#include <gtest/gtest.h>

#include <cmath>

namespace partet {
namespace {

// A regular tet (edge 2*sqrt(2)), positively oriented.
TetMesh regular_tet() {
  TetMesh mesh;
  mesh.points = {{1, 1, 1}, {1, -1, -1}, {-1, 1, -1}, {-1, -1, 1}};
  mesh.tets = {{0, 2, 1, 3}};
  mesh.neighbours = {{-1, -1, -1, -1}};
  return mesh;
}

TEST(Quality, RegularTetHasTheIdealFigures) {
  const MeshQuality q = mesh_quality(regular_tet());
  EXPECT_EQ(q.tets, 1);
  EXPECT_NEAR(q.amips_avg, 3.0, 1e-12);
  EXPECT_NEAR(q.amips_max, 3.0, 1e-12);
  const double dihedral = std::acos(1.0 / 3.0) * 180 / M_PI;  // 70.53 deg
  EXPECT_NEAR(q.min_dihedral_deg, dihedral, 1e-9);
  EXPECT_NEAR(q.max_dihedral_deg, dihedral, 1e-9);
  EXPECT_NEAR(q.radius_edge_avg, std::sqrt(6.0) / 4, 1e-12);
  EXPECT_EQ(q.below_5deg, 0);
  // All six angles in TetGen's 70-80 deg bin.
  EXPECT_EQ(q.dihedral_histogram[7], 6);
}

TEST(Quality, FlatTetIsInfinitelyBad) {
  EXPECT_TRUE(std::isinf(amips_energy({0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {1, 1, 0})));
  // A sliver: four nearly coplanar points, positively oriented.
  TetMesh mesh = regular_tet();
  mesh.points = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {1, 1, 0.01}};
  mesh.tets = {{0, 1, 2, 3}};
  const MeshQuality q = mesh_quality(mesh);
  EXPECT_GT(q.amips_max, 50);
  EXPECT_LT(q.min_dihedral_deg, 5);
  EXPECT_GT(q.max_dihedral_deg, 175);
  EXPECT_EQ(q.below_5deg, 1);
  EXPECT_EQ(q.above_175deg, 1);
}

TEST(Quality, SubsetAndSeamZone) {
  // Two tets apart along x; the plane x = 0.5 crosses the first, x = 3 touches neither.
  TetMesh mesh;
  mesh.points = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}, {5, 0, 0}, {6, 0, 0}, {5, 1, 0}, {5, 0, 1}};
  mesh.tets = {{0, 1, 2, 3}, {4, 5, 6, 7}};
  mesh.neighbours = {{-1, -1, -1, -1}, {-1, -1, -1, -1}};
  const std::vector<CutPlane> planes = {{{1, 0, 0}, 0.5}, {{1, 0, 0}, 3}};
  const std::vector<char> zone = seam_zone(mesh, planes);
  EXPECT_EQ(zone, (std::vector<char>{1, 0}));
  const MeshQuality first = mesh_quality(mesh, [&](std::size_t t) { return zone[t] != 0; });
  EXPECT_EQ(first.tets, 1);
  EXPECT_EQ(mesh_quality(mesh).tets, 2);
  // A plane through a vertex touches the tet.
  EXPECT_EQ(seam_zone(mesh, {{{1, 0, 0}, 6}}), (std::vector<char>{0, 1}));
}

}  // namespace
}  // namespace partet

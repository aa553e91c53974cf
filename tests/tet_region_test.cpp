// Replacing a region of a tet mesh in place: the new tets take the region's slots (then new ones
// at the end), leftover slots take the last tets, and every neighbour relation, piece mark and
// point stays right; Replacement says where everything went.
#include <gtest/gtest.h>

#include <algorithm>
#include <map>
#include <vector>

#include "stage_helpers.hpp"
#include "stages/tet_region.hpp"
#include "stages/topology.hpp"

namespace partet {
namespace {

using namespace partet::test;

// The unit cube's corners, 0..7 = (x, y, z) bits.
std::vector<Point3> cube_corners() {
  std::vector<Point3> p;
  for (int i = 0; i < 8; ++i) p.push_back({double(i & 1), double((i >> 1) & 1), double((i >> 2) & 1)});
  return p;
}

Tet positive(const std::vector<Point3>& p, Tet t) {
  if (tet_volume(p[t[0]], p[t[1]], p[t[2]], p[t[3]]) < 0) std::swap(t[0], t[1]);
  return t;
}

// The cube as its central tet {1, 2, 4, 7} and four corner tets, and pieces 0, 1, 2, 3, 4.
// With a centre point (index 8) the central tet is split in four around it, first in the list.
TetMesh cube(bool split_centre) {
  TetMesh mesh;
  mesh.points = cube_corners();
  std::vector<Tet> centre{{1, 2, 4, 7}};
  if (split_centre) {
    mesh.points.push_back({0.5, 0.5, 0.5});
    centre = {{8, 2, 4, 7}, {1, 8, 4, 7}, {1, 2, 8, 7}, {1, 2, 4, 8}};
  }
  for (const Tet& t : centre) mesh.tets.push_back(positive(mesh.points, t));
  for (const Tet& t : std::vector<Tet>{{0, 1, 2, 4}, {3, 1, 2, 7}, {5, 1, 4, 7}, {6, 2, 4, 7}})
    mesh.tets.push_back(positive(mesh.points, t));
  mesh.neighbours = compute_neighbours(mesh.tets);
  mesh.piece.assign(centre.size(), 0);
  for (std::int32_t p = 1; p <= 4; ++p) mesh.piece.push_back(p);
  return mesh;
}

// The corner tets' pieces by their sorted vertex set.
std::map<Tet, std::int32_t> pieces_by_tet(const TetMesh& mesh) {
  std::map<Tet, std::int32_t> piece;
  for (std::size_t t = 0; t < mesh.tets.size(); ++t) {
    Tet key = mesh.tets[t];
    std::sort(key.begin(), key.end());
    piece[key] = mesh.piece[t];
  }
  return piece;
}

void expect_consistent(const TetMesh& mesh) {
  EXPECT_EQ(mesh.neighbours, compute_neighbours(mesh.tets));
  EXPECT_EQ(neighbour_problem(mesh.tets, mesh.neighbours), "");
  EXPECT_EQ(mesh.piece.size(), mesh.tets.size());
  EXPECT_NEAR(total_tet_volume(mesh.points, mesh.tets), 1.0, 1e-12);
  for (const Tet& t : mesh.tets)
    EXPECT_GT(tet_volume(mesh.points[t[0]], mesh.points[t[1]], mesh.points[t[2]], mesh.points[t[3]]), 0);
}

TEST(ReplaceRegion, FewerTetsFillTheRegionAndMoveTheLastTetsIntoItsSlots) {
  TetMesh mesh = cube(true);
  const TetMesh before = mesh;
  std::vector<char> in_region{1, 1, 1, 1, 0, 0, 0, 0};
  RegionMesh centre;
  centre.ids = {1, 2, 4, 7};
  centre.mesh.tets = {positive(mesh.points, {0, 1, 2, 3})};
  centre.mesh.neighbours = {{-1, -1, -1, -1}};
  const Replacement where = replace_region(mesh, in_region, {centre});

  ASSERT_EQ(mesh.tets.size(), 5u);
  expect_consistent(mesh);
  EXPECT_EQ(mesh.points.size(), before.points.size());  // the centre point is unused, not dropped here
  EXPECT_EQ(where.new_tets, (std::vector<std::int32_t>{0}));
  EXPECT_EQ(mesh.piece[0], -1);
  // Three corner tets moved into slots 1-3, each with its piece.
  ASSERT_EQ(where.moved.size(), 3u);
  for (const auto& [from, to] : where.moved) {
    EXPECT_EQ(mesh.tets[to], before.tets[from]);
    EXPECT_EQ(mesh.piece[to], before.piece[from]);
  }
  std::map<Tet, std::int32_t> expected = pieces_by_tet(before), got = pieces_by_tet(mesh);
  for (const auto& [tet, piece] : got)
    if (piece >= 0) EXPECT_EQ(expected.at(tet), piece);
}

// Region slots near the end: the last kept tet moves into the first vacant slot, and the vacant
// slots then left at the end are dropped, never the slot just filled.
TEST(ReplaceRegion, VacantSlotsAtTheEndAreDroppedAndTheOthersFilled) {
  const TetMesh split = cube(true);  // centre tets 0-3, corner tets 4-7
  TetMesh mesh = split;
  const std::vector<std::size_t> order{0, 4, 5, 6, 1, 2, 3, 7};  // centre tets at slots 0, 4, 5, 6
  for (std::size_t slot = 0; slot < order.size(); ++slot) {
    mesh.tets[slot] = split.tets[order[slot]];
    mesh.piece[slot] = split.piece[order[slot]];
  }
  mesh.neighbours = compute_neighbours(mesh.tets);
  const TetMesh before = mesh;
  RegionMesh centre;
  centre.ids = {1, 2, 4, 7};
  centre.mesh.tets = {positive(mesh.points, {0, 1, 2, 3})};
  centre.mesh.neighbours = {{-1, -1, -1, -1}};
  const Replacement where = replace_region(mesh, {1, 0, 0, 0, 1, 1, 1, 0}, {centre});

  ASSERT_EQ(mesh.tets.size(), 5u);
  expect_consistent(mesh);
  EXPECT_EQ(where.new_tets, (std::vector<std::int32_t>{0}));
  EXPECT_EQ(where.moved, (std::vector<std::pair<std::int32_t, std::int32_t>>{{7, 4}}));
  EXPECT_EQ(mesh.tets[4], before.tets[7]);
  EXPECT_EQ(mesh.piece[4], before.piece[7]);
  for (std::size_t t = 1; t < 4; ++t) EXPECT_EQ(mesh.tets[t], before.tets[t]);
}

TEST(ReplaceRegion, MoreTetsFillTheRegionThenGoAtTheEnd) {
  TetMesh mesh = cube(false);
  const TetMesh before = mesh;
  std::vector<char> in_region{1, 0, 0, 0, 0};
  // The central tet split around a new Steiner point (local id 4).
  RegionMesh centre;
  centre.ids = {1, 2, 4, 7};
  centre.mesh.steiner_points = {{0.5, 0.5, 0.5}};
  std::vector<Point3> local{mesh.points[1], mesh.points[2], mesh.points[4], mesh.points[7], {0.5, 0.5, 0.5}};
  for (const Tet& t : std::vector<Tet>{{4, 1, 2, 3}, {0, 4, 2, 3}, {0, 1, 4, 3}, {0, 1, 2, 4}})
    centre.mesh.tets.push_back(positive(local, t));
  centre.mesh.neighbours = compute_neighbours(centre.mesh.tets, 5);
  const Replacement where = replace_region(mesh, in_region, {centre});

  ASSERT_EQ(mesh.tets.size(), 8u);
  ASSERT_EQ(mesh.points.size(), 9u);
  EXPECT_EQ(mesh.points[8], (Point3{0.5, 0.5, 0.5}));
  expect_consistent(mesh);
  EXPECT_EQ(where.new_tets, (std::vector<std::int32_t>{0, 5, 6, 7}));
  EXPECT_TRUE(where.moved.empty());
  for (auto t : where.new_tets) EXPECT_EQ(mesh.piece[t], -1);
  for (std::size_t t = 1; t < 5; ++t) {
    EXPECT_EQ(mesh.tets[t], before.tets[t]);
    EXPECT_EQ(mesh.piece[t], before.piece[t]);
  }
}

TEST(ReplaceRegion, AMeshWithoutPiecesStaysWithout) {
  TetMesh mesh = cube(true);
  mesh.piece.clear();
  RegionMesh centre;
  centre.ids = {1, 2, 4, 7};
  centre.mesh.tets = {positive(mesh.points, {0, 1, 2, 3})};
  centre.mesh.neighbours = {{-1, -1, -1, -1}};
  replace_region(mesh, {1, 1, 1, 1, 0, 0, 0, 0}, {centre});
  EXPECT_TRUE(mesh.piece.empty());
  EXPECT_EQ(mesh.neighbours, compute_neighbours(mesh.tets));
}

}  // namespace
}  // namespace partet

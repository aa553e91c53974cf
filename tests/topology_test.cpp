// The topology kernel: neighbours from tets, joining open faces, tet regions, local numbering.
#include <gtest/gtest.h>

#include <vector>

#include "partet/errors.hpp"
#include "stages/generate.hpp"
#include "mesher/tetgen_mesher.hpp"
#include "stage_helpers.hpp"
#include "stages/topology.hpp"

namespace partet {
namespace {

using namespace partet::test;

TEST(ComputeNeighbours, TwoTetsShareAFace) {
  // Tets (0,1,2,3) and (1,2,3,4) share face {1,2,3}, opposite vertex 0 and vertex 4.
  const std::vector<Tet> tets = {{0, 1, 2, 3}, {4, 3, 2, 1}};
  const auto nb = compute_neighbours(tets);
  ASSERT_EQ(nb.size(), 2u);
  EXPECT_EQ(nb[0], (Tet{1, -1, -1, -1}));
  EXPECT_EQ(nb[1], (Tet{0, -1, -1, -1}));
  EXPECT_EQ(neighbour_problem(tets, nb), "");
}

TEST(ComputeNeighbours, EmptyAndIsolated) {
  EXPECT_TRUE(compute_neighbours({}).empty());
  const auto nb = compute_neighbours({{0, 1, 2, 3}, {4, 5, 6, 7}});
  EXPECT_EQ(nb[0], (Tet{-1, -1, -1, -1}));
  EXPECT_EQ(nb[1], (Tet{-1, -1, -1, -1}));
}

TEST(ComputeNeighbours, FaceInThreeTetsThrowsOrStaysOpen) {
  const std::vector<Tet> tets = {{0, 1, 2, 3}, {4, 3, 2, 1}, {1, 2, 3, 5}};
  EXPECT_THROW(compute_neighbours(tets), InternalError);
  const auto nb = compute_neighbours(tets, 6, CrowdedFace::leave_open);
  EXPECT_EQ(nb[0][0], -1);
  EXPECT_EQ(nb[1][0], -1);
  EXPECT_EQ(nb[2][3], -1);
}

TEST(ComputeNeighbours, MatchesTetGenOnARealMesh) {
  const SurfaceMesh s = generate_surface("torus", 1500);
  const LocalTetMesh m = mesh_closed_surface(s.points, s.triangles, TetgenOptions{});
  EXPECT_EQ(compute_neighbours(m.tets), m.neighbours);
}

TEST(ConnectOpenFaces, RejoinsASplitMesh) {
  const SurfaceMesh s = generate_surface("sphere", 800);
  const LocalTetMesh m = mesh_closed_surface(s.points, s.triangles, TetgenOptions{});
  // Cut every neighbour relation between the first and second half of the tets.
  std::vector<Tet> nb = m.neighbours;
  const auto half = static_cast<std::int32_t>(m.tets.size() / 2);
  std::vector<std::int32_t> touched;
  for (std::int32_t t = 0; t < static_cast<std::int32_t>(m.tets.size()); ++t)
    for (auto& n : nb[t])
      if (n >= 0 && (n < half) != (t < half)) {
        n = -1;
        if (touched.empty() || touched.back() != t) touched.push_back(t);
      }
  ASSERT_FALSE(touched.empty());
  std::vector<Tet> all = nb;
  connect_open_faces(m.tets, all);
  EXPECT_EQ(all, m.neighbours);
  connect_open_faces(m.tets, nb, &touched);
  EXPECT_EQ(nb, m.neighbours);
}

TEST(LabelTetRegions, SplitsAtBlockedFaces) {
  // Three tets in a row: 0-1 and 1-2 share faces. Blocking the faces of tet 1 gives 3 regions;
  // excluding tet 1 gives 2 and leaves it -1.
  const std::vector<Tet> neighbours = {{1, -1, -1, -1}, {0, 2, -1, -1}, {1, -1, -1, -1}};
  std::vector<std::int32_t> label;
  EXPECT_EQ(label_tet_regions(
                neighbours, [](std::size_t) { return true; }, [](std::size_t, int) { return true; }, label),
            1);
  EXPECT_EQ(label, (std::vector<std::int32_t>{0, 0, 0}));
  const auto not_a_face_of_tet_1 = [&](std::size_t t, int j) { return t != 1 && neighbours[t][j] != 1; };
  EXPECT_EQ(label_tet_regions(
                neighbours, [](std::size_t) { return true; }, not_a_face_of_tet_1, label),
            3);
  EXPECT_EQ(label_tet_regions(
                neighbours, [](std::size_t t) { return t != 1; }, [](std::size_t, int) { return true; }, label),
            2);
  EXPECT_EQ(label, (std::vector<std::int32_t>{0, -1, 1}));
}

// Without the array over every vertex: triangles and tets numbered alike, ids ascending, and
// every corner lifted back to its original id.
TEST(LocalNumbering, RenumberWithoutScratch) {
  std::vector<Triangle> faces = {{9, 4, 7}, {7, 4, 12}};
  EXPECT_EQ(renumber_locally(faces), (std::vector<std::int32_t>{4, 7, 9, 12}));
  EXPECT_EQ(faces, (std::vector<Triangle>{{2, 0, 1}, {1, 0, 3}}));

  const std::vector<Tet> original = {{70000, 3, 512, 9}, {9, 3, 1 << 20, 70000}, {512, 5, 3, 9}};
  std::vector<Tet> tets = original;
  const std::vector<std::int32_t> ids = renumber_locally(tets);
  EXPECT_EQ(ids, (std::vector<std::int32_t>{3, 5, 9, 512, 70000, 1 << 20}));
  for (std::size_t t = 0; t < tets.size(); ++t)
    for (int j = 0; j < 4; ++j) EXPECT_EQ(ids.at(static_cast<std::size_t>(tets[t][j])), original[t][j]);
}

TEST(LocalNumbering, RenumberAndLiftBack) {
  std::vector<Triangle> faces = {{9, 4, 7}, {7, 4, 12}};
  std::vector<std::int32_t> scratch(20, -1);
  const auto ids = renumber_locally(faces, scratch);
  EXPECT_EQ(ids, (std::vector<std::int32_t>{4, 7, 9, 12}));
  EXPECT_EQ(faces, (std::vector<Triangle>{{2, 0, 1}, {1, 0, 3}}));
  EXPECT_EQ(scratch, std::vector<std::int32_t>(20, -1));

  EXPECT_EQ(compact_ids({1, 0, 1, 1, 0}), (std::vector<std::int32_t>{0, -1, 1, 2, -1}));

  LocalTetMesh local;
  local.steiner_points = {{5, 5, 5}};
  local.tets = {{0, 1, 2, 4}, {0, 1, 4, 3}};
  local.neighbours = {{-1, -1, 1, -1}, {-1, -1, 0, -1}};
  std::vector<Point3> points(13);
  std::vector<Tet> tets = {{0, 0, 0, 0}}, neighbours = {{-1, -1, -1, -1}};
  EXPECT_EQ(append_local_mesh(local, ids, points, tets, neighbours), 1);
  EXPECT_EQ(points.size(), 14u);
  EXPECT_EQ(points[13], (Point3{5, 5, 5}));
  EXPECT_EQ(tets[1], (Tet{4, 7, 9, 13}));
  EXPECT_EQ(tets[2], (Tet{4, 7, 13, 12}));
  EXPECT_EQ(neighbours[1], (Tet{-1, -1, 2, -1}));
  EXPECT_EQ(neighbours[2], (Tet{-1, -1, 1, -1}));
}

}  // namespace
}  // namespace partet

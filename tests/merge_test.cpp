// Merge: weld joins the pieces' tet meshes at the caps (neighbours: topology_test).
#include <gtest/gtest.h>

#include <set>
#include <string>
#include <vector>

#include "job/pipeline.hpp"
#include "partet/errors.hpp"
#include "stage_batches.hpp"
#include "stage_helpers.hpp"
#include "stages/assembly_numbering.hpp"
#include "stages/generate.hpp"
#include "stages/merge.hpp"
#include "stages/topology.hpp"
#include "stages/validate.hpp"

namespace partet {
namespace {

using namespace partet::test;

struct Welded {
  SurfaceMesh input;
  PreparedPieces prepared;
  std::vector<PieceTetMesh> results;
  TetMesh mesh;
};

Welded weld_shape(const std::string& name, int faces, int k, double density = 1.0, const std::string& quality = "") {
  Welded w;
  MeshOptions options;
  options.pieces = k;
  options.density = density;
  options.tetgen.quality = quality;
  w.input = generate_surface(name, faces);
  w.prepared = prepare_pieces(w.input, options);
  for (const auto& piece : w.prepared.pieces) w.results.push_back(tetrahedralize_piece(piece, options.tetgen));
  w.mesh = weld(w.prepared.split, w.prepared.pieces, std::vector<PieceTetMesh>(w.results));
  return w;
}

void expect_valid_weld(const Welded& w) {
  const TetMesh& mesh = w.mesh;
  // Sizes: all global points, then every piece's Steiner points in piece order.
  std::size_t steiner = 0, tets = 0;
  for (const auto& r : w.results) {
    steiner += r.mesh.steiner_points.size();
    tets += r.mesh.tets.size();
  }
  ASSERT_EQ(mesh.points.size(), w.prepared.split.points.size() + steiner);
  ASSERT_EQ(mesh.tets.size(), tets);
  for (std::size_t v = 0; v < w.prepared.split.points.size(); ++v)
    ASSERT_EQ(mesh.points[v], w.prepared.split.points[v]);
  std::size_t next = w.prepared.split.points.size();
  for (const auto& r : w.results)
    for (const auto& q : r.mesh.steiner_points) EXPECT_EQ(mesh.points[next++], q);

  // Tets map through the pieces' global ids: same coordinates as in the piece.
  std::size_t t = 0;
  std::size_t steiner_base = w.prepared.split.points.size();
  for (std::size_t p = 0; p < w.results.size(); ++p) {
    const auto& r = w.results[p];
    const auto& piece = w.prepared.pieces[p];
    for (const auto& local : r.mesh.tets) {
      for (int j = 0; j < 4; ++j) {
        const auto v = local[j];
        const Point3& expected =
            v < r.surface_point_count ? piece.points[v] : r.mesh.steiner_points[v - r.surface_point_count];
        ASSERT_EQ(mesh.points[mesh.tets[t][j]], expected);
        if (v >= r.surface_point_count)
          EXPECT_EQ(mesh.tets[t][j], static_cast<std::int32_t>(steiner_base + v - r.surface_point_count));
      }
      ++t;
    }
    steiner_base += r.mesh.steiner_points.size();
  }

  // Neighbours symmetric, and exactly what compute_neighbours finds from the tets alone.
  EXPECT_EQ(neighbour_problem(mesh.tets, mesh.neighbours), "");
  EXPECT_EQ(mesh.neighbours, compute_neighbours(mesh.tets));

  // The open faces are the split input triangles: every cap face got its neighbour.
  EXPECT_EQ(canonical_set(open_faces(mesh)), canonical_set(w.prepared.split.triangles));

  const double volume = enclosed_volume(w.input);
  EXPECT_NEAR(total_tet_volume(mesh.points, mesh.tets), volume, 1e-9 * volume);
}

// The sizes past int32: points always refused (tets name them in int32), tets only where the mesh
// is held in one process (a mesh left on its ranks checks with tets 0: its rows are 64-bit).
TEST(Weld, SizesPastInt32AreRefusedWithTheirReason) {
  const std::size_t past = std::size_t{1} << 31, most = past - 1;
  EXPECT_NO_THROW(check_int32_sizes(most, most));
  EXPECT_NO_THROW(check_int32_sizes(0, most));
  const auto message = [](std::size_t tets, std::size_t points) {
    try {
      check_int32_sizes(tets, points);
    } catch (const MeshingError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_NE(message(0, past).find("more than 2^31 points"), std::string::npos) << message(0, past);
  EXPECT_NE(message(0, past).find("several ranks"), std::string::npos) << message(0, past);
  EXPECT_NE(message(past, most).find("more than 2^31 tetrahedra"), std::string::npos) << message(past, most);
  EXPECT_NE(message(past, most).find("several ranks"), std::string::npos) << message(past, most);
}

// A bulk keeps 32-bit ids however many points the mesh has: numbered, the split surface's points
// that stay keep theirs (fewer below a point that goes), its own Steiner points that stay follow
// them, and its ids name the mesh's points, here past 2^31.
TEST(Weld, ABulkNumberedPastTwoToThe31PointsKeepsCompactIds) {
  BulkNumbering share;
  share.split_points = 10, share.dropped_split = std::make_shared<const std::vector<std::int32_t>>(std::vector<std::int32_t>{3});
  share.first_steiner = std::int64_t{3} << 31, share.dropped_steiner = {1};
  EXPECT_EQ(share.kept_split(), 9);
  // As the rank that split the piece numbered it: its Steiner point i is 20 + i.
  TetBlock bulk;
  bulk.steiner_points = {{0, 0, 0}, {1, 1, 1}, {2, 2, 2}};
  bulk.tets = {{0, 2, 20, 22}, {4, 9, 22, 5}};
  number_bulk(bulk, share, 20);
  EXPECT_TRUE(bulk.numbered);
  EXPECT_EQ(bulk.tets, (std::vector<Tet>{{0, 2, 9, 10}, {3, 8, 10, 4}}));
  EXPECT_EQ(bulk.steiner_points, (std::vector<Point3>{{0, 0, 0}, {2, 2, 2}}));
  const std::int64_t first = std::int64_t{3} << 31;  // 6442450944
  EXPECT_EQ(bulk.ids(bulk.tets[0]), (GlobalTet{0, 2, first, first + 1}));
  EXPECT_EQ(bulk.ids(bulk.tets[1]), (GlobalTet{3, 8, first + 1, 4}));
  // Numbered once: a second call changes nothing.
  number_bulk(bulk, share, 20);
  EXPECT_EQ(bulk.tets, (std::vector<Tet>{{0, 2, 9, 10}, {3, 8, 10, 4}}));
  // A tet using a point that goes.
  TetBlock wrong;
  wrong.steiner_points = bulk.steiner_points;
  wrong.tets = {{0, 3, 20, 21}};
  EXPECT_THROW(number_bulk(wrong, share, 20), InternalError);
}

TEST(Weld, PiecesOfGeneratedShapes) {
  for (const char* name : {"sphere", "torus", "genus3", "nested"}) {
    for (int k : {1, 2, 4}) {
      SCOPED_TRACE(std::string(name) + " k=" + std::to_string(k));
      expect_valid_weld(weld_shape(name, 1500, k));
    }
  }
}

TEST(Weld, WithSteinerPointsAndDenseCaps) {
  const Welded w = weld_shape("torus", 1000, 3, 2.0, "1.5");
  std::size_t steiner = 0;
  for (const auto& r : w.results) steiner += r.mesh.steiner_points.size();
  EXPECT_GT(steiner, 0u);
  expect_valid_weld(w);
}

TEST(Weld, CapFacesJoinTetsOfNeighbouringPieces) {
  const Welded w = weld_shape("sphere", 1500, 3);
  // Tet index ranges of the pieces.
  std::vector<std::size_t> first{0};
  for (const auto& r : w.results) first.push_back(first.back() + r.mesh.tets.size());
  auto piece_of_tet = [&](std::int32_t t) {
    int p = 0;
    while (static_cast<std::size_t>(t) >= first[p + 1]) ++p;
    return p;
  };
  std::set<std::pair<int, int>> pairs;
  std::size_t cross = 0;
  for (std::size_t t = 0; t < w.mesh.tets.size(); ++t)
    for (int j = 0; j < 4; ++j) {
      const auto u = w.mesh.neighbours[t][j];
      if (u < 0) continue;
      const int a = piece_of_tet(static_cast<std::int32_t>(t)), b = piece_of_tet(u);
      if (a != b) {
        EXPECT_EQ(std::abs(a - b), 1) << "tets of non-adjacent pieces are neighbours";
        pairs.insert({std::min(a, b), std::max(a, b)});
        ++cross;
      }
    }
  EXPECT_EQ(pairs, (std::set<std::pair<int, int>>{{0, 1}, {1, 2}}));
  // Each cap triangle is crossed once from each side.
  EXPECT_EQ(cross, 2 * static_cast<std::size_t>(w.prepared.cap_triangles));
}

void expect_same_mesh(const TetMesh& a, const TetMesh& b) {
  EXPECT_EQ(a.points, b.points);
  EXPECT_EQ(a.tets, b.tets);
  EXPECT_EQ(a.neighbours, b.neighbours);
  EXPECT_EQ(a.piece, b.piece);
}

// Results welded as they arrive, in any order, give the mesh of welding them in piece order.
TEST(Welder, ArrivalOrderDoesNotMatter) {
  const Welded w = weld_shape("torus", 3000, 4, 1.0, "1.5");
  for (const std::vector<int>& order : {std::vector<int>{3, 1, 0, 2}, std::vector<int>{2, 3, 1, 0}}) {
    Welder welder(w.prepared.split, w.prepared.pieces);
    for (int p : order) {
      EXPECT_FALSE(welder.has(p));
      welder.add(PieceTetMesh(w.results[p]));
      EXPECT_TRUE(welder.has(p));
    }
    expect_same_mesh(welder.finish(w.prepared.split.points), w.mesh);
  }
}

// A retry keeps the pieces it does not change: a welded piece comes back exactly as it was.
TEST(Welder, TakeBackRestoresTheResult) {
  const Welded w = weld_shape("torus", 3000, 3, 1.0, "1.5");
  Welder welder(w.prepared.split, w.prepared.pieces);
  for (const auto& r : w.results) welder.add(PieceTetMesh(r));
  for (int p = 0; p < 3; ++p) {
    const PieceTetMesh back = welder.take_back(p);
    EXPECT_EQ(back.index, w.results[p].index);
    EXPECT_EQ(back.surface_point_count, w.results[p].surface_point_count);
    EXPECT_EQ(back.mesh.steiner_points, w.results[p].mesh.steiner_points);
    EXPECT_EQ(back.mesh.tets, w.results[p].mesh.tets);
    EXPECT_EQ(back.mesh.neighbours, w.results[p].mesh.neighbours);
    EXPECT_FALSE(welder.has(p));
  }
}

TEST(Welder, MismatchedMissingOrRepeatedResultThrows) {
  const Welded w = weld_shape("sphere", 500, 2);
  {
    Welder welder(w.prepared.split, w.prepared.pieces);
    PieceTetMesh wrong = w.results[0];
    wrong.surface_point_count += 1;  // not piece 0's surface
    EXPECT_THROW(welder.add(std::move(wrong)), InternalError);
    PieceTetMesh unknown = w.results[0];
    unknown.index = 7;
    EXPECT_THROW(welder.add(std::move(unknown)), InternalError);
  }
  {
    Welder welder(w.prepared.split, w.prepared.pieces);
    welder.add(PieceTetMesh(w.results[1]));
    EXPECT_THROW(welder.add(PieceTetMesh(w.results[1])), InternalError);
    EXPECT_THROW(welder.finish(w.prepared.split.points), InternalError);  // piece 0 never came
  }
  {
    Welder welder(w.prepared.split, w.prepared.pieces);
    for (const auto& r : w.results) welder.add(PieceTetMesh(r));
    EXPECT_THROW(welder.finish({}), InternalError);  // not the split surface's points
  }
}

}  // namespace
}  // namespace partet
